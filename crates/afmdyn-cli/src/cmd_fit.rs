//! `afmdyn fit`: a measured quasi-static force curve fitted with the probe's contact law
//! (Hertz, DMT, JKR, or the SLS on a curve with times and a dwell), with its contact point and
//! baseline — estimates, standard errors, 95 %
//! profile-likelihood intervals, correlations, χ²/dof, residuals and identifiability
//! warnings (with `--profiles`, an AM curve's intervals are the profile likelihood's too).
//! The request, the preprocessing, the fit and the document are the library's
//! ([`afmdyn::request::FitRequest`], [`afmdyn::analysis::fit`]), and so are its summary, table,
//! figures and `fit.json` ([`afmdyn::report::present::fit`]); this front end maps the flags.

use crate::args::ModelArgs;
use crate::cmd_approach::files;
use crate::cmd_simulate::Files;
use crate::door;
use crate::error::CliError;
use crate::flags_afm::FitFlags;
use afmdyn::request::run::Request;
use afmdyn::request::Params;
use afmdyn::request::Resolved;
use clap::Args;
use std::path::PathBuf;

/// `afmdyn fit` flags.
#[derive(Debug, Args)]
pub struct FitArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// The request's flags: --data, --fit, --segment, --range, --approach-rows, --profiles
    #[command(flatten)]
    request: FitFlags,
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
    // a range may carry a unit with a probe (SI)
    let request = a.request.request(a.model.probe.is_some())?;
    let (params, probe) = a
        .model
        .resolve_for(Params::default(), request.probe_needs())?;
    let model = Resolved { params, probe };
    let exit = door::Exit {
        json: a.json,
        out: (a.files != Files::None).then_some(a.out.as_path()),
        files: files(a.files),
        unit: "model evaluations",
        ..door::Exit::default()
    };
    door::run(&request, &model, exit).map(|_| ())
}
