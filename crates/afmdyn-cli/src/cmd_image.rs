//! `afmdyn image`: the AM-AFM image of a heterogeneous sample under an ideal amplitude feedback,
//! or scanned in the time domain under a lock-in and a PI z controller (`--feedback pi`).
//! The sample map, the operating points and the scan are the library's
//! ([`afmdyn::request::image`], [`afmdyn::request::image_scan`]); this front end reads the two
//! files, maps the flags, and writes `image.json`, `image.nc` (the library's layouts,
//! [`afmdyn::request::image_layout`]), the maps (height, phase, E_dis; the error image of a PI
//! scan) and the line profile.

use crate::door;
use crate::error::CliError;
use crate::output::{units_of, OutDir};
use afmdyn::request::image::{image, setpoint_study, study_ratios, ImageRequest, SampleMap};
use afmdyn::request::image_scan::{PiScan, ScanStudy};
use afmdyn::request::present;
use clap::Args;
use std::path::PathBuf;

/// `afmdyn image` flags.
#[derive(Debug, Args)]
pub struct ImageArgs {
    /// The probe file (SI): the lever, tip, drive and the background sample
    #[arg(long, value_name = "PROBE.toml")]
    probe: PathBuf,
    /// A cantilever of the library (`afmdyn cantilevers` lists them) for the probe file, as for
    /// every command taking --probe
    #[arg(long, value_name = "NAME")]
    cantilever: Option<String>,
    /// The fluid around the lever, over the probe file's [medium]: water, air or none, as for
    /// every command taking --probe
    #[allow(rustdoc::broken_intra_doc_links)]
    #[arg(long, value_name = "NAME")]
    medium: Option<String>,
    /// The sample map: size = [Lx, Ly] (m) and [[domain]] entries (name, x, y, height,
    /// [domain.sample])
    #[arg(long, value_name = "S.toml")]
    sample: PathBuf,
    /// Amplitude setpoint A_sp/A0 in (0, 1)
    #[arg(long)]
    setpoint: f64,
    /// Feedback: ideal (an operating point of the local material at every pixel) or pi (a
    /// time-domain scan, trace and retrace, under a lock-in and a PI z controller)
    #[arg(long, default_value = "ideal")]
    feedback: String,
    /// PI scan: lines (trace and retrace) per second, Hz (default: a pixel lasts 5 loop time
    /// constants 1/K_I)
    #[arg(long, value_name = "HZ")]
    scan_rate: Option<f64>,
    /// PI scan: the gains K_P (m/m) and K_I (1/s) (default: K_P = 0, K_I = 1/(4(τ_c + τ_L)),
    /// τ_c = 2Q/ω0)
    #[arg(
        long,
        value_name = "P,I",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    gains: Option<Vec<f64>>,
    /// PI scan: the lock-in's low-pass time constant, s (default: τ_c/4)
    #[arg(long, value_name = "S")]
    time_constant: Option<f64>,
    /// PI scan: worker threads, one line per task (default: all cores)
    #[arg(long)]
    threads: Option<usize>,
    /// PI scan: continue an interrupted scan; refused unless the other arguments are those of
    /// the interrupted run (recorded in OUT/.image.run.json)
    #[arg(long)]
    resume: bool,
    /// Testing: abort the process, as if killed, after this many lines are stored
    #[arg(long, hide = true)]
    abort_after: Option<usize>,
    /// Pixels per line [default: 64]
    #[arg(long)]
    pixels: Option<usize>,
    /// Lines (default: as many as pixels, 1 for a line map with Ly = 0)
    #[arg(long)]
    lines: Option<usize>,
    /// Points of each material's approach curve (the probe's default z_c range) [default: 120]
    #[arg(long)]
    curve_points: Option<usize>,
    /// Also the setpoint study FROM:TO:N (e.g. 0.2:0.95:16): every domain's apparent height,
    /// phase and E_dis at N setpoints, as a line engaged on the background meets it (the
    /// contrast inversion); "setpoint_study" in the document and two plots
    #[arg(long, value_name = "FROM:TO:N")]
    setpoint_study: Option<String>,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/image")]
    out: PathBuf,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn image`.
pub fn image_cmd(a: &ImageArgs) -> Result<(), CliError> {
    let pi = match a.feedback.as_str() {
        "ideal" => {
            for (set, flag) in [
                (a.scan_rate.is_some(), "--scan-rate"),
                (a.gains.is_some(), "--gains"),
                (a.time_constant.is_some(), "--time-constant"),
                (a.threads.is_some(), "--threads"),
                (a.resume, "--resume"),
            ] {
                if set {
                    return Err(CliError::Input(format!(
                        "{flag}: only with --feedback pi (the ideal feedback has no loop)"
                    )));
                }
            }
            None
        }
        "pi" => {
            if a.setpoint_study.is_some() {
                return Err(CliError::Input(
                    "--setpoint-study: only with --feedback ideal (a study of exact operating \
                     points)"
                        .into(),
                ));
            }
            Some(PiScan {
                scan_rate: a.scan_rate,
                gains: match a.gains.as_deref() {
                    None => None,
                    Some([p, i]) => Some((*p, *i)),
                    Some(g) => {
                        return Err(CliError::Input(format!(
                            "--gains {g:?}: must be two numbers P,I (K_P in m/m, K_I in 1/s)"
                        )))
                    }
                },
                time_constant: a.time_constant,
            })
        }
        other => {
            return Err(CliError::Input(format!(
                "feedback = {other}: must be ideal or pi"
            )))
        }
    };
    let text = crate::args::probe_text(&a.probe, a.cantilever.as_deref(), a.medium.as_deref())?;
    let table = afmdyn::probe::Probe::table(&text, &a.probe.display().to_string())?;
    // a sample map's refusals (its file, its height map's) name the option
    let map = SampleMap::load(&a.sample).map_err(|e| match e {
        afmdyn::SimError::Probe(m) => CliError::Input(format!("--sample {m}")),
        e => e.into(),
    })?;
    let req = ImageRequest::with(a.setpoint, a.pixels, a.lines, a.curve_points);
    req.validate(&map)?;
    let ratios = a.setpoint_study.as_deref().map(study_ratios).transpose()?;
    if let Some(scan) = pi {
        return pi_cmd(a, &table, &map, &req, &scan);
    }
    let out = OutDir::lock(&a.out)?;
    let img = image(&table, &map, &req)?;
    let study = match &ratios {
        Some(r) => Some(setpoint_study(&table, &map, r, req.curve_points)?),
        None => None,
    };
    let json = present::image::ideal_document(&img, a.setpoint, study.as_ref());
    let shown = present::image::ideal(&img, a.setpoint, study.as_ref(), &json, units_of(None));
    door::emit(Some(&out), &shown, &json, a.json)
}

/// `afmdyn image --feedback pi`: the scan's lines as a study on the worker threads, then its
/// presentation.
fn pi_cmd(
    a: &ImageArgs,
    table: &toml::Table,
    map: &SampleMap,
    req: &ImageRequest,
    scan: &PiScan,
) -> Result<(), CliError> {
    let study = ScanStudy::new(table, map, req, scan)?;
    let out = OutDir::lock(&a.out)?;
    let mut store = afmdyn::study::scan_store::scan_store(out.dir_lock());
    crate::progress::study(
        &study,
        &mut store,
        a.resume,
        a.threads,
        "lines",
        a.abort_after,
    )
    .map_err(|e| crate::error::study_error(e, "image"))?;
    let records = store
        .records()
        .map_err(|e| crate::error::store_error(e, "image"))?;
    let img = study.assemble(records)?;
    let json = img.document(a.setpoint);
    let shown = present::image::pi(&img, a.setpoint, &json, units_of(None));
    door::emit(Some(&out), &shown, &json, a.json)
}
