//! `afmdyn fit`: a measured quasi-static force curve fitted with the probe's contact law
//! (Hertz, DMT, JKR, or the SLS on a curve with times and a dwell), with its contact point and
//! baseline — estimates, standard errors, 95 %
//! profile-likelihood intervals, correlations, χ²/dof, residuals and identifiability
//! warnings (with `--profiles`, an AM curve's intervals are the profile likelihood's too).
//! The request, the preprocessing, the fit and the document are the library's
//! ([`afmdyn::request::FitRequest`], [`afmdyn::analysis::fit`]), and so are its summary, table,
//! figures and `fit.json` ([`afmdyn::request::present::fit`]); this front end maps the flags.

use crate::args::ModelArgs;
use crate::cmd_approach::files;
use crate::cmd_simulate::Files;
use crate::door;
use crate::error::CliError;
use afmdyn::request::fit::FitSegment;
use afmdyn::request::{FitRequest, Resolved};
use afmdyn::Params;
use clap::Args;
use std::path::PathBuf;

/// `afmdyn fit` flags.
#[derive(Debug, Args)]
pub struct FitArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// The force curve: a CSV with the columns height (m, the piezo height, decreasing into
    /// the sample), force (N, repulsion positive) and optionally sigma (N) and time (s, which
    /// the sls law needs: its relaxation on a dwell); or an AM curve: the
    /// columns z (m, the piezo position, in the order stepped), amplitude (m) and/or phase
    /// (deg), optionally sigma_amplitude (m) and sigma_phase (deg); or an FM curve: the columns
    /// z (m) and frequency_shift (Hz), optionally sigma_frequency_shift (Hz), at the probe's
    /// free amplitude; or a bimodal curve (a probe with a second drive component): amplitude_2
    /// (m) and/or phase_2 (deg), with or without amplitude and phase, and their sigma_ columns
    #[arg(long, value_name = "FILE.csv")]
    data: PathBuf,
    /// The parameters fitted, by their probe keys, comma-separated: sample.youngs_modulus,
    /// tip.radius, contact_point, baseline, sample.hamaker (dmt), sample.adhesion_energy (jkr);
    /// sample.stiffness, sample.maxwell_stiffness, sample.relaxation_time (sls, whose default
    /// frees these three, contact_point and baseline);
    /// of an AM or FM curve sample.youngs_modulus, sample.hamaker (dmt), tip.radius and
    /// z_offset (always fitted) [AM/FM default: E, H (dmt), z_offset]
    #[arg(long, value_delimiter = ',', default_values_t = FitRequest::default().fit)]
    fit: Vec<String>,
    /// The segment fitted: approach (up to the lowest height), retract or whole (approach,
    /// dwell and retract) [default: approach; whole for the sls law]
    #[arg(long, value_parser = ["approach", "retract", "whole"])]
    segment: Option<String>,
    /// The range of tip positions fitted, LO,HI (m, after the contact-point offset)
    #[arg(
        long,
        value_name = "LO,HI",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    range: Option<Vec<f64>>,
    /// The number of rows of the approach (the rest is the retract), as the instrument
    /// recorded its segments [default: up to the lowest height, inclusive]
    #[arg(long, value_name = "N")]
    approach_rows: Option<usize>,
    /// Profile-likelihood intervals (Δχ² ≤ 3.84, up to 4 fitted parameters) for an AM curve
    /// too, where each profile point refits stepped approaches (at most 6 refits a side); a
    /// force curve has them by default [default: Wald intervals ±1.96 SE for an AM curve]
    #[arg(long, conflicts_with = "no_profiles")]
    profiles: bool,
    /// Wald intervals (±1.96 SE) for a force curve too, no profiles
    #[arg(long)]
    no_profiles: bool,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/fit")]
    out: PathBuf,
    /// Files written: all (data and plots), data (no plots) or none (only the summary)
    #[arg(long, value_enum, default_value = "all")]
    files: Files,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn fit`.
pub fn fit(a: &FitArgs) -> Result<(), CliError> {
    // (clap admits only these three)
    let segment = a.segment.as_deref().map(|s| match s {
        "retract" => FitSegment::Retract,
        "whole" => FitSegment::Whole,
        _ => FitSegment::Approach,
    });
    let range = match a.range.as_deref() {
        None => None,
        Some(&[lo, hi]) => Some([lo, hi]),
        Some(r) => {
            return Err(CliError::Input(format!(
                "--range: {} value(s) given; must be two, LO,HI (m)",
                r.len()
            )))
        }
    };
    let (params, probe) = a.model.resolve(Params::default())?;
    let request = FitRequest {
        data: Some(a.data.display().to_string()),
        fit: a.fit.clone(),
        segment,
        range,
        approach_rows: a.approach_rows,
        profiles: match (a.profiles, a.no_profiles) {
            (true, _) => Some(true),
            (_, true) => Some(false),
            _ => None,
        },
        ..FitRequest::default()
    };
    let model = Resolved { params, probe };
    let exit = door::Exit {
        json: a.json,
        out: (a.files != Files::None).then_some(a.out.as_path()),
        files: files(a.files),
        unit: "model evaluations",
    };
    door::run(&request, &model, exit).map(|_| ())
}
