//! `afmdyn approach`, `bimodal` (the approach–retract curve over the rest distance z_c) and
//! `afmdyn resonance` (amplitude and phase against the drive frequency): stepped sweeps both
//! ways plus branch continuation ([`afmdyn::analysis::stepped`]), run as resumable studies
//! into the `--out` directory's store ([`CurveStudy`]); their summary, tables, traces and
//! figures are the library's ([`afmdyn::report::present::curves`]).

use crate::args::ModelArgs;
use crate::cmd_simulate::Files;
use crate::door::{self, Exit, Resume};
use crate::error::CliError;
use crate::flags::{ApproachFlags, BimodalFlags, ResonanceFlags};
use afmdyn::report::present;
use afmdyn::request::Bimodal;
use afmdyn::request::Params;
use afmdyn::request::SteppedCurve;
use afmdyn::request::{CurveRequest, Resolved};
use afmdyn::study::stored::Resumable;
use clap::Args;
use std::path::{Path, PathBuf};

/// The output flags shared by `approach`, `bimodal` and `resonance` (the command line's own;
/// the request's flags are generated: [`crate::flags`]).
#[derive(Debug, Args)]
pub struct CurveArgs {
    /// Files written: all (data and plots), data (no plots) or none (only the summary)
    #[arg(long, value_enum, default_value = "all")]
    files: Files,
    /// Name and order the CSV/NPY columns as dForce 2.0's zcdom table (zc, Amplitude, Phase,
    /// Distance_min, Force_max, Energy_diss, Virial1, …) for scripts written for it; the
    /// default names them as the JSON document (z_c, amplitude, phase_deg, …)
    #[arg(long)]
    dforce_columns: bool,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
    /// Continue an interrupted curve from its last stored point; refused unless the other
    /// arguments are those of the interrupted run (recorded in OUT/.curve.run.json)
    #[arg(long)]
    resume: bool,
    /// Testing: abort the process, as if killed, after this many points are stored
    #[arg(long, hide = true)]
    abort_after: Option<usize>,
}

/// `afmdyn approach` flags.
#[derive(Debug, Args)]
pub struct ApproachArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: ApproachFlags,
    #[command(flatten)]
    curve: CurveArgs,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/approach")]
    out: PathBuf,
}

/// `afmdyn bimodal` flags: those of `approach` with the averaged and exact measures; the
/// probe's `[drive]` gives two or more components (`free_amplitude = [A01, A02]`,
/// `frequency = [f1, f2]`).
#[derive(Debug, Args)]
pub struct BimodalArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: BimodalFlags,
    #[command(flatten)]
    curve: CurveArgs,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/bimodal")]
    out: PathBuf,
}

/// `afmdyn resonance` flags.
#[derive(Debug, Args)]
pub struct ResonanceArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: ResonanceFlags,
    #[command(flatten)]
    curve: CurveArgs,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/resonance")]
    out: PathBuf,
}

/// The library's choice of files for `--files`.
pub(crate) fn files(f: Files) -> present::Files {
    match f {
        Files::All => present::Files::All,
        Files::Data => present::Files::Data,
        Files::None => present::Files::None,
    }
}

/// Run the curve through the door: resumable into the store of the output directory, or in
/// memory without files (nothing to resume from).
fn go<A: Resumable<Output = SteppedCurve>>(
    args: &CurveArgs,
    (out, stem): (&Path, &'static str),
    request: &A,
    model: &Resolved,
) -> Result<(), CliError> {
    let exit = Exit {
        json: args.json,
        out: (args.files != Files::None).then_some(out),
        files: files(args.files),
        unit: "points",
        dforce_columns: args.dforce_columns,
    };
    if exit.out.is_none() {
        if args.resume {
            return Err(CliError::Input(
                "--resume: --files none keeps no store to resume; use --files data or all".into(),
            ));
        }
        return door::run(request, model, exit).map(drop);
    }
    let how = Resume {
        resume: args.resume,
        abort_after: args.abort_after,
        what: stem,
    };
    door::run_stored(request, model, exit, how)
}

/// The model of the flags, with the request's `--from`/`--to` checked finite.
fn setup(model: &ModelArgs, curve: &CurveRequest) -> Result<Resolved, CliError> {
    let (params, probe) = model.resolve(Params::default())?;
    check_finite("--from", curve.from)?;
    check_finite("--to", curve.to)?;
    Ok(Resolved { params, probe })
}

fn check_finite(name: &str, v: Option<f64>) -> Result<(), CliError> {
    match v {
        Some(x) if !x.is_finite() => Err(CliError::Input(format!(
            "{name} = {x}: must be a finite number"
        ))),
        _ => Ok(()),
    }
}

/// Run `afmdyn approach`.
pub fn approach(a: &ApproachArgs) -> Result<(), CliError> {
    let request = a.request.request(a.model.probe.is_some())?;
    let model = setup(&a.model, &request.curve)?;
    go(&a.curve, (&a.out, "approach"), &request, &model)
}

/// Run `afmdyn bimodal`: the approach curve of a multifrequency drive
/// ([`afmdyn::request::curves::check_bimodal`]), its files `bimodal.*`.
pub fn bimodal(a: &BimodalArgs) -> Result<(), CliError> {
    let request = Bimodal(a.request.request(a.model.probe.is_some())?);
    let model = setup(&a.model, &request.0.curve)?;
    go(&a.curve, (&a.out, "bimodal"), &request, &model)
}

/// Run `afmdyn resonance`.
pub fn resonance(a: &ResonanceArgs) -> Result<(), CliError> {
    let request = a.request.request(a.model.probe.is_some())?;
    let model = setup(&a.model, &request.curve)?;
    go(&a.curve, (&a.out, "resonance"), &request, &model)
}
