//! `continue`: the branches' table (`continuation.csv`), their figure (`continuation`: the
//! section points of each branch over the parameter, stable solid, unstable dashed, the
//! located events) and the text summary of the events.

use crate::analysis::continuation::{Branch, BranchPoint};
use crate::error::SimError;
use crate::layout::figure::{Figure, Plot, Series, Style};
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use crate::report::{Presentation, TextUnits};

/// The header of `continuation.csv`.
pub const CSV_HEADER: [&str; 11] = [
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
];

/// A colour per branch, avoiding the events' (3) and a sweep underlay's (7).
const BRANCH_COLORS: [usize; 8] = [0, 1, 2, 4, 5, 6, 8, 9];

fn branch_rows(model: &CantileverModel, id: usize, br: &[BranchPoint]) -> Vec<Vec<String>> {
    use crate::layout::files::f;
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

/// The series of one branch's section points: a run per section point and stability.
fn branch_series(model: &CantileverModel, b: &[BranchPoint], color: usize) -> Vec<Series> {
    let mut series = Vec::new();
    let np = b.first().map_or(0, |x| x.section.len());
    for k in 0..np {
        let mut run: Vec<(f64, f64)> = Vec::new();
        let mut stable = b.first().is_some_and(|x| x.stable);
        let style = |stable: bool| if stable { Style::Line } else { Style::Dashed };
        for x in b {
            let pt = (x.value, model.w_tip(&x.section[k.min(x.section.len() - 1)]));
            if x.stable != stable && !run.is_empty() {
                run.push(pt);
                series.push(Series {
                    label: String::new(),
                    points: std::mem::take(&mut run),
                    style: style(stable),
                    color,
                });
                stable = x.stable;
            }
            run.push(pt);
        }
        if !run.is_empty() {
            series.push(Series {
                label: String::new(),
                points: run,
                style: style(stable),
                color,
            });
        }
    }
    series
}

/// The figure of the branches continued in `param` from `from` on `base`.
fn figure(model: &CantileverModel, param: SweepParam, branches: &[Branch]) -> Figure {
    let n = branches[0].first().map_or(1, |b| b.period);
    let mut series = Vec::new();
    for (ib, b) in branches.iter().enumerate() {
        let first = series.len();
        series.extend(branch_series(
            model,
            b,
            BRANCH_COLORS[ib % BRANCH_COLORS.len()],
        ));
        if let (Some(sr), Some(x)) = (series.get_mut(first), b.first()) {
            sr.label = if ib == 0 {
                format!("period-{n} branch (solid stable, dashed unstable)")
            } else {
                format!(
                    "period-{} branch from {} = {:.4}",
                    x.period,
                    param.symbol(),
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
    // the periods the branches have (with switching, the doubled branches too)
    let mut periods: Vec<usize> = branches
        .iter()
        .filter_map(|b| b.first().map(|x| x.period))
        .collect();
    periods.sort_unstable();
    periods.dedup();
    let title = match periods.as_slice() {
        [p] => format!("Continuation of period-{p} orbits in {}", param.symbol()),
        [] => format!("Continuation of period-{n} orbits in {}", param.symbol()),
        ps => format!(
            "Continuation of periodic orbits in {} (periods {})",
            param.symbol(),
            ps.iter()
                .map(|p| p.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    Figure {
        y_min_span: 0.0,
        title,
        x_label: format!("{} ({})", param.symbol(), param.name()),
        y_label: "W(1,τ) at τ = 2πk/Ω".into(),
        series,
        shade: vec![],
    }
}

/// The presentation of `branches` continued in `param` from `from` on `base`: the table, the
/// figure (a sweep's underlay may go first, series 0, drawn below) and the located events,
/// the drive in Hz and α5 as z_c with a probe.
///
/// # Errors
/// [`SimError`] when the parameters at `from` do not build a model.
pub(crate) fn continuation(
    base: &Params,
    param: SweepParam,
    from: f64,
    branches: &[Branch],
    u: TextUnits,
) -> Result<Presentation, SimError> {
    let model = CantileverModel::new(&base.with(param, from))?;
    let mut s = Presentation::default();
    s.csv(
        "continuation.csv",
        &CSV_HEADER,
        branches
            .iter()
            .enumerate()
            .flat_map(|(i, b)| branch_rows(&model, i, b))
            .collect(),
    );
    s.figure("continuation", Plot::Lines(figure(&model, param, branches)));
    s.line(format!(
        "{} branch(es), {} points; located:",
        branches.len(),
        branches.iter().map(|b| b.len()).sum::<usize>()
    ));
    for b in branches.iter().flatten().filter(|b| b.event.is_some()) {
        // with a probe Ω reads as the drive frequency and α5 as the rest distance z_c
        let at = match (u.si(), param) {
            (true, SweepParam::Omega) => u.drive(b.value),
            (true, SweepParam::Alpha5) => format!(
                "z_c = {}",
                u.length(base.with(SweepParam::Alpha5, b.value).rest_distance())
            ),
            _ => format!("{} = {:.6}", param.name(), b.value),
        };
        s.line(format!(
            "  {:<16} at {at} (period {})",
            format!("{:?}", b.event.expect("event")),
            b.period
        ));
    }
    Ok(s)
}
