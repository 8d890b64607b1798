//! The layout of a pseudo-arclength continuation ([`crate::analysis::continuation`]): one row
//! per branch point over every branch, declared once for the Python `xarray.Dataset` (and any
//! other writer).

use crate::analysis::continuation::{Branch, BranchPoint};
use crate::layout::{Layout, Values, Variable};
use crate::model::CantileverModel;
use crate::params::SweepParam;

/// The branches of `afmdyn continue` as a layout over the dimensions `point` (every branch
/// point, branch by branch), `k` (the section points of the longest period, NaN-padded) and
/// `multiplier` / `component` (2N): `branch` (0 the continued one), `period`, `s`
/// (arclength), `value` (of `param`), `stable`, `max_multiplier` (|μ| of the largest Floquet
/// multiplier), `critical` (how it is or would become unstable), `switchings`,
/// `grazing_distance` (g₀), `event` (`""` or the located bifurcation), `w_tip_section` (W(1,τ)
/// at the section points, g₀, from `model`'s tip row), `multipliers` (complex) and `state` (the
/// section point at τ = 0, (a, ȧ)).
pub(crate) fn continuation_layout(
    param: SweepParam,
    model: &CantileverModel,
    branches: &[Branch],
) -> Layout {
    let points: Vec<(usize, &_)> = branches
        .iter()
        .enumerate()
        .flat_map(|(i, b)| b.iter().map(move |p| (i, p)))
        .collect();
    // the state's modal part (a, ȧ) (a law's internal states are not listed); every Floquet
    // multiplier, one per state entry
    let dim = 2 * model.modes();
    let mults = model.dim();
    let width = points
        .iter()
        .map(|(_, b)| b.section.len())
        .max()
        .unwrap_or(1);
    let mut variables = point_variables(param, &points);
    variables.extend(section_variables(model, &points, width));
    Layout::new(
        format!("afmdyn continuation of period-n orbits in {}", param.name()),
        &[
            ("point", points.len()),
            ("k", width),
            ("multiplier", mults),
            ("component", dim),
        ],
        variables,
    )
}

/// Every branch point (branch index, point) with its branch, period, arclength, value of
/// `param`, stability, largest multiplier, critical multiplier, switchings, distance to
/// grazing and event, over `point`.
fn point_variables(param: SweepParam, points: &[(usize, &BranchPoint)]) -> Vec<Variable> {
    let col = |f: &dyn Fn(&BranchPoint) -> f64| points.iter().map(|&(_, b)| f(b)).collect();
    let int = |f: &dyn Fn(usize, &BranchPoint) -> usize| {
        points
            .iter()
            .map(|&(i, b)| i32::try_from(f(i, b)).unwrap_or(i32::MAX))
            .collect::<Vec<i32>>()
    };
    let text = |f: &dyn Fn(&BranchPoint) -> String| {
        Values::Text(points.iter().map(|&(_, b)| f(b)).collect())
    };
    let point: &[&str] = &["point"];
    let f64s = |name: &str, units: &str, long: String, values: Vec<f64>| {
        Variable::new(name, point, units, long, Values::F64(values))
    };
    let value = format!("{} ({})", param.symbol(), param.name());
    let stable = "stable (every Floquet multiplier inside the unit circle)";
    let critical = "how the orbit is or would become unstable";
    let event = |b: &BranchPoint| b.event.map_or(String::new(), |e| e.name().into());
    vec![
        Variable::i32(
            "branch",
            point,
            "1",
            "branch (0: the continued one)",
            &int(&|i, _| i),
        ),
        Variable::i32(
            "period",
            point,
            "drive periods",
            "period n",
            &int(&|_, b| b.period),
        ),
        f64s("s", "1", "arclength".into(), col(&|b| b.s)),
        f64s("value", "1", value, col(&|b| b.value)),
        Variable::new(
            "stable",
            point,
            "1",
            stable,
            Values::Bool(points.iter().map(|(_, b)| b.stable).collect()),
        ),
        f64s(
            "max_multiplier",
            "1",
            "largest |Floquet multiplier|".into(),
            col(&|b| b.multipliers[0].norm()),
        ),
        Variable::new(
            "critical",
            point,
            "1",
            critical,
            text(&|b| b.critical.name().into()),
        ),
        Variable::i32(
            "switchings",
            point,
            "1",
            "switchings per cycle",
            &int(&|_, b| b.switchings),
        ),
        f64s(
            "grazing_distance",
            "g0",
            "distance to grazing".into(),
            col(&|b| b.grazing_distance),
        ),
        Variable::new(
            "event",
            point,
            "1",
            "located bifurcation (\"\": none)",
            text(&event),
        ),
    ]
}

/// At every branch point: W(1,τ) at the section points `[point, k]` (`width` of them, NaN
/// beyond a point's period), the Floquet multipliers `[point, multiplier]` and the modal state
/// at τ = 0 `[point, component]`.
fn section_variables(
    model: &CantileverModel,
    points: &[(usize, &BranchPoint)],
    width: usize,
) -> Vec<Variable> {
    let (dim, mults, rows) = (2 * model.modes(), model.dim(), points.len());
    let mut w_section = Vec::with_capacity(rows * width);
    let mut multipliers = Vec::with_capacity(rows * mults);
    let mut state = Vec::with_capacity(rows * dim);
    for (_, b) in points {
        w_section.extend((0..width).map(|j| b.section.get(j).map_or(f64::NAN, |z| model.w_tip(z))));
        multipliers.extend((0..mults).map(|j| {
            b.multipliers
                .get(j)
                .map_or((f64::NAN, f64::NAN), |m| (m.re, m.im))
        }));
        state.extend(b.section[0].iter().take(dim));
    }
    vec![
        Variable::f64(
            "w_tip_section",
            &["point", "k"],
            "g0",
            "W(1,τ) at the section points",
            &w_section,
        ),
        Variable::new(
            "multipliers",
            &["point", "multiplier"],
            "1",
            "Floquet multipliers",
            Values::C64(multipliers),
        ),
        Variable::f64(
            "state",
            &["point", "component"],
            "g0, g0 per unit τ",
            "state at τ = 0 (a, ȧ)",
            &state,
        ),
    ]
}

#[cfg(test)]
mod tests {
    use crate::analysis::continuation::BranchEvent;
    use crate::analysis::shooting::Instability;

    /// The names of the CSV and the dataset are the JSON document's (serde's).
    #[test]
    fn names_are_the_json_names() {
        for e in [
            BranchEvent::Fold,
            BranchEvent::PeriodDoubling,
            BranchEvent::NeimarkSacker,
            BranchEvent::Grazing,
        ] {
            assert_eq!(serde_json::to_value(e).unwrap(), e.name());
        }
        for i in [
            Instability::Fold,
            Instability::PeriodDoubling,
            Instability::NeimarkSacker,
        ] {
            assert_eq!(serde_json::to_value(i).unwrap(), i.name());
        }
    }
}
