//! `afmdyn orbit`, `afmdyn continue` and `afmdyn lyapunov`.

use crate::args::ModelArgs;
use crate::cmd_analysis::{COL_VALUE, COL_W_TIP};
use crate::cmd_simulate::parse_initial;
use crate::door::{self, Exit};
use crate::error::CliError;
use crate::flags::{ContinueFlags, LyapunovFlags, OrbitFlags, SteadyFlags};
use crate::plot::{Series, Style};
use afmdyn::request::Params;
use afmdyn::request::Resolved;
use afmdyn::request::StartRequest;
use clap::Args;
use std::path::{Path, PathBuf};

/// Initial-state flags of the orbit commands.
#[derive(Debug, Clone, Args)]
pub struct StartArgs {
    /// Initial modal state "a1,..,aN;adot1,..,adotN" (default: the steady state reached from rest)
    #[arg(long, allow_hyphen_values = true)]
    initial_modal: Option<String>,
    #[command(flatten)]
    steady: SteadyFlags,
}

impl StartArgs {
    /// The library's start: the given state, or the steady state reached from rest.
    fn request(&self, modes: usize) -> Result<StartRequest, CliError> {
        Ok(StartRequest {
            initial: parse_initial(&self.initial_modal, modes)?,
            steady: self.steady.request(),
        })
    }
}

/// `afmdyn orbit` flags.
#[derive(Debug, Args)]
pub struct OrbitArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    start: StartArgs,
    #[command(flatten)]
    request: OrbitFlags,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn orbit`.
pub fn orbit(a: &OrbitArgs) -> Result<(), CliError> {
    let (params, probe) = a.model.resolve(Params::default())?;
    let request = a.request.request(a.start.request(params.modes)?);
    let exit = Exit {
        json: a.json,
        out: None,
        unit: "orbits",
        ..Exit::default()
    };
    door::run(&request, &Resolved { params, probe }, exit).map(drop)
}

/// `afmdyn continue` flags.
#[derive(Debug, Args)]
pub struct ContinueArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    start: StartArgs,
    #[command(flatten)]
    request: ContinueFlags,
    /// Draw the branches over this bifurcation.csv (from `afmdyn bifurcation`)
    #[arg(long, value_name = "CSV")]
    overlay: Option<PathBuf>,
    /// Output directory
    #[arg(long, default_value = "afmdyn-out/continue")]
    out: PathBuf,
    /// Print one JSON summary
    #[arg(long)]
    json: bool,
}

/// The overlay CSV read and checked before any computation: readable, at most
/// [`afmdyn::io::MAX_INPUT_CSV_BYTES`] of UTF-8 in lines of at most
/// [`afmdyn::io::input::MAX_CSV_LINE_BYTES`], with `value` and `w_tip`
/// columns; its (value, w_tip) pairs. Every failure is bad input (exit code 2) naming the file.
fn read_overlay(path: &Path) -> Result<Vec<(f64, f64)>, CliError> {
    let bad = |m: String| CliError::Input(format!("--overlay {m}"));
    let text = afmdyn::io::read_text(path, afmdyn::io::InputKind::Overlay)
        .map_err(|e| bad(e.to_string()))?;
    let csv_error = |e: csv::Error| {
        bad(format!(
            "{}: {}",
            path.display(),
            e.to_string().replace('\n', " ")
        ))
    };
    let mut rd = csv::Reader::from_reader(text.as_bytes());
    let header = rd.headers().map_err(csv_error)?;
    let names: Vec<&str> = header.iter().collect();
    if names.get(COL_VALUE) != Some(&"value") || names.get(COL_W_TIP) != Some(&"w_tip") {
        return Err(bad(format!(
            "{}: not a bifurcation.csv of `afmdyn bifurcation` (expected columns value and \
             w_tip)",
            path.display()
        )));
    }
    let mut points = Vec::new();
    for r in rd.records() {
        let r = r.map_err(csv_error)?;
        if let (Some(Ok(v)), Some(Ok(w))) = (
            r.get(COL_VALUE).map(str::parse::<f64>),
            r.get(COL_W_TIP).map(str::parse::<f64>),
        ) {
            points.push((v, w));
        }
    }
    Ok(points)
}

/// Run `afmdyn continue`.
pub fn continuation(a: &ContinueArgs) -> Result<(), CliError> {
    let (params, probe) = a.model.resolve(Params::default())?;
    let request = a.request.request(a.start.request(params.modes)?);
    request.validate(&params)?;
    let underlay = match &a.overlay {
        Some(o) => read_overlay(o)?,
        None => Vec::new(),
    };
    let exit = Exit {
        json: a.json,
        out: Some(&a.out),
        unit: "branch points",
        ..Exit::default()
    };
    // the sweep's points below the branches
    let decorate = |shown: &mut afmdyn::report::Presentation| {
        if let Some(series) = shown
            .series_mut("continuation")
            .filter(|_| !underlay.is_empty())
        {
            let points = underlay.clone();
            let style = Style::Dots;
            let label = "bifurcation sweep".into();
            series.insert(
                0,
                Series {
                    label,
                    points,
                    style,
                    color: 7,
                },
            );
        }
    };
    door::run_with(&request, &Resolved { params, probe }, exit, decorate).map(drop)
}

/// `afmdyn lyapunov` flags.
#[derive(Debug, Args)]
pub struct LyapunovArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Initial modal state "a1,..,aN;adot1,..,adotN" (default: rest)
    #[arg(long, allow_hyphen_values = true)]
    initial_modal: Option<String>,
    #[command(flatten)]
    request: LyapunovFlags,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn lyapunov`.
pub fn lyapunov(a: &LyapunovArgs) -> Result<(), CliError> {
    let (params, probe) = a.model.resolve(Params::default())?;
    let request = a
        .request
        .request(parse_initial(&a.initial_modal, params.modes)?);
    let exit = Exit {
        json: a.json,
        out: None,
        unit: "periods",
        ..Exit::default()
    };
    door::run(&request, &Resolved { params, probe }, exit).map(drop)
}
