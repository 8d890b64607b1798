//! `afmdyn orbit`, `afmdyn continue` and `afmdyn lyapunov`.

use crate::args::ModelArgs;
use crate::cmd_analysis::{SteadyArgs, COL_VALUE, COL_W_TIP};
use crate::cmd_simulate::parse_initial;
use crate::door::{self, Exit};
use crate::error::CliError;
use crate::output::{f, write_csv, OutDir};
use crate::plot::{save, Figure, Series, Style};
use crate::progress;
use afmdyn::analysis::continuation::BranchPoint;
use afmdyn::request::{ContinuationRequest, LyapunovRequest, OrbitRequest, StartRequest};
use afmdyn::request::{Document, Resolved};
use afmdyn::{CantileverModel, Params, SweepParam};
use clap::Args;
use std::path::{Path, PathBuf};

/// Initial-state flags of the orbit commands.
#[derive(Debug, Clone, Args)]
pub struct StartArgs {
    /// Initial modal state "a1,..,aN;adot1,..,adotN" (default: the steady state reached from rest)
    #[arg(long, allow_hyphen_values = true)]
    initial_modal: Option<String>,
    #[command(flatten)]
    steady: SteadyArgs,
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
    /// Period n of the orbit (default: the period of the steady state reached, else 1)
    #[arg(long)]
    period: Option<usize>,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn orbit`.
pub fn orbit(a: &OrbitArgs) -> Result<(), CliError> {
    let (params, probe) = a.model.resolve(Params::default())?;
    let request = OrbitRequest {
        period: a.period,
        start: a.start.request(params.modes)?,
    };
    let exit = Exit {
        json: a.json,
        out: None,
        unit: "orbits",
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
    /// Continued parameter: omega or alpha1..alpha6
    #[arg(long, default_value = "omega")]
    param: SweepParam,
    /// Start value
    #[arg(long, default_value_t = ContinuationRequest::default().from, allow_negative_numbers = true)]
    from: f64,
    /// End of the range
    #[arg(long, default_value_t = ContinuationRequest::default().to, allow_negative_numbers = true)]
    to: f64,
    /// Period n of the branch (default: the period of the steady state at --from)
    #[arg(long)]
    period: Option<usize>,
    /// At each period doubling, switch to the period-2n branch and continue it too, recursively
    /// up to period 8n (the period-doubling cascade)
    #[arg(long)]
    switch: bool,
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

fn branch_rows(model: &CantileverModel, id: usize, br: &[BranchPoint]) -> Vec<Vec<String>> {
    br.iter()
        .map(|b| {
            vec![
                id.to_string(),
                b.period.to_string(),
                f(b.s),
                f(b.value),
                b.stable.to_string(),
                f(b.multipliers[0].norm()),
                b.critical.name().to_string(),
                b.section
                    .iter()
                    .map(|z| format!("{}", model.w_tip(z)))
                    .collect::<Vec<_>>()
                    .join(" "),
                b.switchings.to_string(),
                f(b.grazing_distance),
                b.event.map_or(String::new(), |e| e.name().to_string()),
            ]
        })
        .collect()
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
    let (base, probe) = a.model.resolve(Params::default())?;
    let request = ContinuationRequest {
        param: a.param,
        from: a.from,
        to: a.to,
        period: a.period,
        switch: a.switch,
        start: a.start.request(base.modes)?,
    };
    request.validate(&base)?;
    let underlay = match &a.overlay {
        Some(o) => read_overlay(o)?,
        None => Vec::new(),
    };
    let out = OutDir::lock(&a.out)?;
    let u = crate::output::units_of(probe.as_ref());
    let model = Resolved {
        params: base,
        probe,
    };
    let Document {
        output: branches,
        json,
    } = progress::run(&request, &model, "branch points")?;
    let model = CantileverModel::new(&base.with(a.param, a.from))?;
    let n = branches[0].first().map_or(1, |b| b.period);
    write_csv(
        &out.join("continuation.csv"),
        &[
            "branch",
            "period",
            "s",
            "value",
            "stable",
            "max_multiplier",
            "critical",
            "w_tip_section",
            "switchings",
            "grazing_distance",
            "event",
        ],
        branches
            .iter()
            .enumerate()
            .flat_map(|(i, b)| branch_rows(&model, i, b)),
    )?;
    // plot: section points of each branch, stable solid, unstable dashed (as dots)
    let mut series = Vec::new();
    // a colour per branch, avoiding the events' (3) and the sweep underlay's (7)
    const BRANCH_COLORS: [usize; 8] = [0, 1, 2, 4, 5, 6, 8, 9];
    for (ib, b) in branches.iter().enumerate() {
        let i = BRANCH_COLORS[ib % BRANCH_COLORS.len()];
        let first_series = series.len();
        let np = b.first().map_or(0, |x| x.section.len());
        for k in 0..np {
            let mut run: Vec<(f64, f64)> = Vec::new();
            let mut stable = b.first().is_some_and(|x| x.stable);
            for x in b {
                let pt = (x.value, model.w_tip(&x.section[k.min(x.section.len() - 1)]));
                if x.stable != stable && !run.is_empty() {
                    run.push(pt);
                    series.push(Series {
                        label: String::new(),
                        points: std::mem::take(&mut run),
                        style: if stable { Style::Line } else { Style::Dashed },
                        color: i,
                    });
                    stable = x.stable;
                }
                run.push(pt);
            }
            if !run.is_empty() {
                series.push(Series {
                    label: String::new(),
                    points: run,
                    style: if stable { Style::Line } else { Style::Dashed },
                    color: i,
                });
            }
        }
        if let (Some(sr), Some(x)) = (series.get_mut(first_series), b.first()) {
            sr.label = if ib == 0 {
                format!("period-{n} branch (solid stable, dashed unstable)")
            } else {
                format!(
                    "period-{} branch from {} = {:.4}",
                    x.period,
                    a.param.symbol(),
                    x.value
                )
            };
        }
    }
    let events: Vec<(f64, f64)> = branches
        .iter()
        .flat_map(|b| {
            b.iter()
                .filter(|x| x.event.is_some())
                .map(|x| (x.value, model.w_tip(&x.section[0])))
        })
        .collect();
    series.push(Series {
        label: "fold / period doubling / NS / grazing".into(),
        points: events,
        style: Style::Points,
        color: 3,
    });
    if !underlay.is_empty() {
        series.insert(
            0,
            Series {
                label: "bifurcation sweep".into(),
                points: underlay,
                style: Style::Dots,
                color: 7,
            },
        );
    }
    // the periods the branches have (with --switch, the doubled branches too)
    let mut periods: Vec<usize> = branches
        .iter()
        .filter_map(|b| b.first().map(|x| x.period))
        .collect();
    periods.sort_unstable();
    periods.dedup();
    let title = match periods.as_slice() {
        [p] => format!("Continuation of period-{p} orbits in {}", a.param.symbol()),
        [] => format!("Continuation of period-{n} orbits in {}", a.param.symbol()),
        ps => format!(
            "Continuation of periodic orbits in {} (periods {})",
            a.param.symbol(),
            ps.iter()
                .map(|p| p.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    save(
        out.path(),
        "continuation",
        &Figure {
            y_min_span: 0.0,
            title,
            x_label: format!("{} ({})", a.param.symbol(), a.param.name()),
            y_label: "W(1,τ) at τ = 2πk/Ω".into(),
            series,
            shade: vec![],
        },
    )?;
    for w in afmdyn::report::continuation_warnings(a.param, &branches) {
        errln!("afmdyn: warning: {w}");
    }
    if a.json {
        outln!("{json}");
    } else {
        outln!(
            "{} branch(es), {} points; located:",
            branches.len(),
            branches.iter().map(|b| b.len()).sum::<usize>()
        );
        for b in branches.iter().flatten().filter(|b| b.event.is_some()) {
            // with a probe Ω reads as the drive frequency and α5 as the rest distance z_c
            let at = match (u.si(), a.param) {
                (true, SweepParam::Omega) => u.drive(b.value),
                (true, SweepParam::Alpha5) => format!(
                    "z_c = {}",
                    u.length(base.with(SweepParam::Alpha5, b.value).rest_distance())
                ),
                _ => format!("{} = {:.6}", a.param.name(), b.value),
            };
            outln!(
                "  {:<16} at {at} (period {})",
                format!("{:?}", b.event.expect("event")),
                b.period
            );
        }
        outln!("outputs in {}", out.path().display());
    }
    Ok(())
}

/// `afmdyn lyapunov` flags.
#[derive(Debug, Args)]
pub struct LyapunovArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Initial modal state "a1,..,aN;adot1,..,adotN" (default: rest)
    #[arg(long, allow_hyphen_values = true)]
    initial_modal: Option<String>,
    /// Drive periods discarded first [default: derived from the model's slowest free decay,
    /// as the steady-state searches' --max-periods: 1500 for the paper's beam]
    #[arg(long)]
    transient: Option<usize>,
    /// Drive periods averaged
    #[arg(long, default_value_t = LyapunovRequest::default().periods)]
    periods: usize,
    /// Blocks for the uncertainty
    #[arg(long, default_value_t = LyapunovRequest::default().blocks)]
    blocks: usize,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn lyapunov`.
pub fn lyapunov(a: &LyapunovArgs) -> Result<(), CliError> {
    let (params, probe) = a.model.resolve(Params::default())?;
    let request = LyapunovRequest {
        initial: parse_initial(&a.initial_modal, params.modes)?,
        transient: a.transient,
        periods: a.periods,
        blocks: a.blocks,
    };
    let exit = Exit {
        json: a.json,
        out: None,
        unit: "periods",
    };
    door::run(&request, &Resolved { params, probe }, exit).map(drop)
}
