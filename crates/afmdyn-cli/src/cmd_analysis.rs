//! `afmdyn bifurcation` and `afmdyn attractors`.

use crate::args::ModelArgs;
use crate::door::{self, Exit, Resume};
use crate::error::CliError;
use crate::flags::{AttractorsFlags, AttractorsSweepFlags, BifurcationFlags};
use afmdyn::request::GlobalContinuationRequest;
use afmdyn::request::{Params, Resolved, SweepParam};
use afmdyn::study::stored::SweepInto;
use clap::Args;
use std::path::PathBuf;

/// `afmdyn bifurcation` flags.
#[derive(Debug, Args)]
pub struct BifurcationArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: BifurcationFlags,
    /// Continue an interrupted sweep; refused unless the other arguments are those of the
    /// interrupted run (recorded in OUT/.bifurcation.run.json)
    #[arg(long)]
    resume: bool,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out")]
    out: PathBuf,
    /// Testing: abort the process, as if killed, after this many points are written
    #[arg(long, hide = true)]
    abort_after: Option<usize>,
    /// Print one JSON summary
    #[arg(long)]
    json: bool,
}

/// Column positions in the library's sweep records (also read by `afmdyn continue --overlay`).
pub(crate) use afmdyn::request::sweep::{COL_VALUE, COL_W_TIP};

/// Run `afmdyn bifurcation` through the door: its cost checked by the library, the sweep run
/// resumably into the store in `--out`, its diagrams streamed from the store's CSV by the
/// library's presentation.
pub fn bifurcation(a: &BifurcationArgs) -> Result<(), CliError> {
    let (params, probe) = a.model.resolve(Params::default())?;
    let exit = Exit {
        json: a.json,
        out: Some(&a.out),
        unit: "points",
        ..Exit::default()
    };
    let how = Resume {
        resume: a.resume,
        abort_after: a.abort_after,
        what: "sweep",
    };
    let request = SweepInto(a.request.request());
    door::run_stored(&request, &Resolved { params, probe }, exit, how)
}

/// `afmdyn attractors` flags.
#[derive(Debug, Args)]
pub struct AttractorsArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: AttractorsFlags,
    /// Continue the attractors over this parameter (omega, alpha1..alpha6): a census at every
    /// value, seeded from the previous value's attractors and matched to them (global
    /// continuation); needs --from and --to
    #[arg(long, requires_all = ["from", "to"])]
    sweep: Option<SweepParam>,
    /// First value of --sweep
    #[arg(long, allow_negative_numbers = true, requires = "sweep")]
    from: Option<f64>,
    /// Last value of --sweep
    #[arg(long, allow_negative_numbers = true, requires = "sweep")]
    to: Option<f64>,
    #[command(flatten)]
    sweep_flags: AttractorsSweepFlags,
    /// Continue an interrupted --sweep; refused unless the other arguments are those of the
    /// interrupted run (recorded in OUT/.continuation.run.json)
    #[arg(long, requires = "sweep")]
    resume: bool,
    /// Testing: abort the process, as if killed, after this many values of --sweep are stored
    #[arg(long, hide = true, requires = "sweep")]
    abort_after: Option<usize>,
    /// Output directory
    #[arg(long, default_value = "afmdyn-out/attractors")]
    out: PathBuf,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn attractors`: the census through the door (or its global continuation over
/// `--sweep`, run resumably into the store in `--out`), presented by the library.
pub fn attractors(a: &AttractorsArgs) -> Result<(), CliError> {
    let (params, probe) = a.model.resolve(Params::default())?;
    let model = Resolved { params, probe };
    let request = a.request.request();
    let exit = Exit {
        json: a.json,
        out: Some(&a.out),
        unit: "starts",
        ..Exit::default()
    };
    let Some(param) = a.sweep else {
        return door::run(&request, &model, exit).map(drop);
    };
    let sweep = GlobalContinuationRequest {
        param,
        values: None,
        from: a.from.unwrap_or(f64::NAN),
        to: a.to.unwrap_or(f64::NAN),
        steps: a.sweep_flags.steps,
        match_tol: a.sweep_flags.match_tol,
        samples: request.samples,
        seed: request.seed,
        cluster_tol: request.cluster_tol,
        steady: request.steady,
        integrator: request.integrator,
    };
    let how = Resume {
        resume: a.resume,
        abort_after: a.abort_after,
        what: "attractors --sweep",
    };
    door::run_stored(&sweep, &model, exit, how)
}
