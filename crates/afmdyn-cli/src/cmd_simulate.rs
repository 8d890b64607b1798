//! `afmdyn simulate` and `afmdyn converge`.

use crate::args::ModelArgs;
use crate::door::{self, Exit};
use crate::error::CliError;
use crate::flags::{ConvergeFlags, SimulateFlags};
use afmdyn::request::simulate_stream::SimulateStream;
use afmdyn::request::Params;
use afmdyn::request::Resolved;
use clap::{Args, ValueEnum};
use std::path::PathBuf;

/// Which files a run writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Files {
    /// Data files and plots.
    All,
    /// Data files only (no plots).
    Data,
    /// Nothing: only the summary on stdout.
    None,
}

/// `afmdyn simulate` flags.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: SimulateFlags,
    /// Initial modal state "a1,..,aN;adot1,..,adotN" (default: rest); |z| < 1e12
    #[arg(long, allow_hyphen_values = true)]
    initial_modal: Option<String>,
    /// Files written: all (data and plots), data (no plots) or none (only the summary)
    #[arg(long, value_enum, default_value = "all")]
    files: Files,
    /// Also write the time series as CSV (timeseries.csv); by default only timeseries.npy
    #[arg(long)]
    csv: bool,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/simulate")]
    out: PathBuf,
    /// Print one JSON summary instead of text
    #[arg(long)]
    json: bool,
    /// Drive periods held in memory at once (testing the streaming; default from the samples)
    #[arg(long, hide = true)]
    chunk_periods: Option<usize>,
}

fn parse_list(s: &str, flag: &str, what: &'static str) -> Result<Vec<f64>, CliError> {
    if s.trim().is_empty() {
        return Ok(vec![]);
    }
    s.split(',')
        .map(|t| {
            t.trim()
                .parse::<f64>()
                .map_err(|_| CliError::Input(format!("--{flag}: cannot read '{t}' in the {what}")))
        })
        .collect()
}

/// The `--initial-modal "a1,..,aN;adot1,..,adotN"` flag as the library's 2N values for N =
/// `modes` (its syntax only: the magnitudes are checked by
/// [`afmdyn::request::analyses::initial_state`]).
pub(crate) fn parse_initial(
    spec: &Option<String>,
    modes: usize,
) -> Result<Option<Vec<f64>>, CliError> {
    parse_modal_state("initial-modal", spec, modes)
}

/// A modal state flag `--<flag> "a1,..,aN;adot1,..,adotN"` as 2N values (syntax only).
pub(crate) fn parse_modal_state(
    flag: &str,
    spec: &Option<String>,
    modes: usize,
) -> Result<Option<Vec<f64>>, CliError> {
    let Some(s) = spec else {
        return Ok(None);
    };
    let (a, ad) = s.split_once(';').ok_or_else(|| {
        CliError::Input(format!("--{flag}: expected \"a1,..,aN;adot1,..,adotN\""))
    })?;
    let mut z = parse_list(a, flag, "displacements")?;
    let ad = parse_list(ad, flag, "velocities")?;
    if z.len() != modes || ad.len() != modes {
        return Err(CliError::Input(format!(
            "--{flag}: expected {modes} displacements and {modes} velocities (N = \
             {modes}), got {} and {}",
            z.len(),
            ad.len()
        )));
    }
    z.extend(ad);
    Ok(Some(z))
}

/// Run `afmdyn simulate` through the door: the library checks its cost, records it in chunks
/// of whole periods streamed to the files (memory does not grow with the length of the run)
/// and presents it (spectrum, figures, summary).
pub fn simulate(a: &SimulateArgs) -> Result<(), CliError> {
    let (params, probe) = a.model.resolve(Params::default())?;
    let request = a
        .request
        .request(parse_initial(&a.initial_modal, params.modes)?);
    let run = SimulateStream {
        request,
        dir: (a.files != Files::None).then(|| a.out.clone()),
        figures: a.files == Files::All,
        csv: a.csv,
        chunk_periods: a.chunk_periods,
    };
    let (json, out, unit) = (a.json, run.dir.as_deref(), "periods");
    // SIGINT/SIGTERM cancel the run at its next chunk; its partial files are removed
    crate::error::stop_on_signal();
    match door::run(
        &run,
        &Resolved { params, probe },
        Exit {
            json,
            out,
            unit,
            ..Exit::default()
        },
    ) {
        Err(_) if crate::error::interrupted().is_err() => Err(CliError::Interrupted),
        done => done.map(|_| ()),
    }
}

/// `afmdyn converge` flags.
#[derive(Debug, Args)]
pub struct ConvergeArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: ConvergeFlags,
    /// Output directory
    #[arg(long, default_value = "afmdyn-out/converge")]
    out: PathBuf,
    /// Print one JSON summary
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn converge` through the door.
pub fn converge(a: &ConvergeArgs) -> Result<(), CliError> {
    let (params, probe) = a
        .model
        .resolve(afmdyn::request::analyses::converge_defaults())?;
    let exit = Exit {
        json: a.json,
        out: Some(&a.out),
        unit: "mode counts",
        ..Exit::default()
    };
    door::run(&a.request.request(), &Resolved { params, probe }, exit).map(drop)
}
