//! `afmdyn image`: the AM-AFM image of a heterogeneous sample under an ideal amplitude feedback,
//! or scanned in the time domain under a lock-in and a PI z controller (`--feedback pi`).
//! The request, its limits, cost, run, document and presentation are the library's
//! ([`afmdyn::request::image_job::ImageJob`], an `Analysis`); this front end reads the two
//! files, maps the flags, and runs it through the door ([`door::run`]) — a PI scan with files
//! into the output directory's store (resumable), held to the budgets first
//! ([`afmdyn::request::run::admit`]). It writes `image.json` (a summary), `image.nc` (the maps),
//! the maps' figures and the line profile, as `--files` asks.

use crate::args::Dim;
use crate::cmd_approach::files;
use crate::cmd_simulate::Files;
use crate::door::{self, Exit, Resume};
use crate::error::CliError;
use crate::flags_afm::{ImageFlags, ImageOptionsFlags, PiScanFlags};
use afmdyn::request::image::SampleMap;
use afmdyn::request::image_job::{ImageJob, ImageMode};
use afmdyn::request::image_options::ImageFeedback;
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
    /// The image request's flags: --setpoint, --pixels, --lines, --curve-points
    #[command(flatten)]
    request: ImageFlags,
    /// The image's options: --mode, --feedback, --threads, --setpoint-study
    #[command(flatten)]
    options: ImageOptionsFlags,
    /// The PI scan's flags: --scan-rate, --gains, --time-constant, --temperature, --seed
    #[command(flatten)]
    scan: PiScanFlags,
    /// PI scan: continue an interrupted scan; refused unless the other arguments are those of
    /// the interrupted run (recorded in OUT/.image.run.json)
    #[arg(long)]
    resume: bool,
    /// Testing: abort the process, as if killed, after this many lines are stored
    #[arg(long, hide = true)]
    abort_after: Option<usize>,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/image")]
    out: PathBuf,
    /// Files written: all (data and plots), data (no plots) or none (only the summary)
    #[arg(long, value_enum, default_value = "all")]
    files: Files,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn image`.
pub fn image_cmd(a: &ImageArgs) -> Result<(), CliError> {
    let options = a.options.request()?;
    // what else was given, for the library's one check of how the options combine
    let given: Vec<(&'static str, String)> = [
        (
            "scan_rate",
            a.scan.scan_rate.as_ref().map(|q| q.to_string()),
        ),
        (
            "gains",
            a.scan
                .gains
                .as_ref()
                .map(|g| g.iter().map(f64::to_string).collect::<Vec<_>>().join(",")),
        ),
        (
            "time_constant",
            a.scan.time_constant.as_ref().map(|q| q.to_string()),
        ),
        ("temperature", a.scan.temperature.map(|t| t.to_string())),
        ("seed", (a.scan.seed != 0).then(|| a.scan.seed.to_string())),
        (
            "curve_points",
            a.request.curve_points.map(|n| n.to_string()),
        ),
        ("resume", a.resume.then(|| "true".to_string())),
    ]
    .into_iter()
    .filter_map(|(k, v)| v.map(|v| (k, v)))
    .collect();
    options.check(&given)?;
    let mode = options.mode;
    // the setpoint: a ratio A_sp/A0 (AM) or a peak force (PeakForce); the probe file is SI
    let setpoint_dim = match mode {
        ImageMode::Am => None,
        ImageMode::Peakforce => Some(Dim::Force),
    };
    let request =
        (a.request.request(true, setpoint_dim)?).with_temperature(mode, a.scan.temperature);
    let pi = match options.feedback {
        ImageFeedback::Ideal => None,
        ImageFeedback::Pi => Some(a.scan.request(true)?),
    };
    let text = crate::args::probe_text(&a.probe, a.cantilever.as_deref(), a.medium.as_deref())?;
    let table = afmdyn::probe::Probe::table(&text, &a.probe.display().to_string())?;
    // a sample map's refusals (its file, its height map's) name the option
    let map = SampleMap::load(&a.sample).map_err(|e| match e {
        afmdyn::error::SimError::Probe(m) => CliError::Input(format!("--sample {m}")),
        e => e.into(),
    })?;
    match mode {
        ImageMode::Am => request.validate(&map)?,
        ImageMode::Peakforce => request.validate_grid(&map)?,
    }
    let study = options.study()?;
    let job = ImageJob {
        mode,
        probe: table,
        sample: map,
        request,
        feedback: pi,
        study,
        threads: options.threads,
    };
    let model = job.model()?;
    let out = (a.files != Files::None).then_some(a.out.as_path());
    let exit = Exit {
        json: a.json,
        out,
        files: files(a.files),
        unit: if job.feedback.is_some() || mode == ImageMode::Peakforce {
            "lines"
        } else {
            "points"
        },
        ..Exit::default()
    };
    if job.feedback.is_none() || out.is_none() {
        if a.resume {
            return Err(CliError::Input(
                "--resume: --files none keeps no store to resume; use --files data or all".into(),
            ));
        }
        return door::run(&job, &model, exit).map(|_| ());
    }
    // a PI scan with files: its lines in the output directory's store (resumable)
    let how = Resume {
        resume: a.resume,
        abort_after: a.abort_after,
        what: "image",
    };
    door::run_stored(&job, &model, exit, how)
}
