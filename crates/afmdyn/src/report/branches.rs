//! The layout of a pseudo-arclength continuation ([`crate::analysis::continuation`]): one row
//! per branch point over every branch, declared once for the Python `xarray.Dataset` (and any
//! other writer).

use crate::analysis::continuation::Branch;
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
pub fn continuation_layout(
    param: SweepParam,
    model: &CantileverModel,
    branches: &[Branch],
) -> Layout {
    let points: Vec<(usize, &_)> = branches
        .iter()
        .enumerate()
        .flat_map(|(i, b)| b.iter().map(move |p| (i, p)))
        .collect();
    let rows = points.len();
    // the state's modal part (a, ȧ) (a law's internal states are not listed); every Floquet
    // multiplier, one per state entry
    let dim = 2 * model.modes();
    let mults = model.dim();
    let width = points
        .iter()
        .map(|(_, b)| b.section.len())
        .max()
        .unwrap_or(1);
    let col = |f: &dyn Fn(usize, &crate::analysis::continuation::BranchPoint) -> f64| {
        points.iter().map(|&(i, b)| f(i, b)).collect::<Vec<f64>>()
    };
    let int = |f: &dyn Fn(usize, &crate::analysis::continuation::BranchPoint) -> usize| {
        points
            .iter()
            .map(|&(i, b)| i32::try_from(f(i, b)).unwrap_or(i32::MAX))
            .collect::<Vec<i32>>()
    };
    let mut w_section = Vec::with_capacity(rows * width);
    let mut multipliers = Vec::with_capacity(rows * mults);
    let mut state = Vec::with_capacity(rows * dim);
    for (_, b) in &points {
        w_section.extend((0..width).map(|j| b.section.get(j).map_or(f64::NAN, |z| model.w_tip(z))));
        multipliers.extend((0..mults).map(|j| {
            b.multipliers
                .get(j)
                .map_or((f64::NAN, f64::NAN), |m| (m.re, m.im))
        }));
        state.extend(b.section[0].iter().take(dim));
    }
    let point: &[&str] = &["point"];
    Layout::new(
        format!("afmdyn continuation of period-n orbits in {}", param.name()),
        &[
            ("point", rows),
            ("k", width),
            ("multiplier", mults),
            ("component", dim),
        ],
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
            Variable::f64("s", point, "1", "arclength", &col(&|_, b| b.s)),
            Variable::f64(
                "value",
                point,
                "1",
                format!("{} ({})", param.symbol(), param.name()),
                &col(&|_, b| b.value),
            ),
            Variable::new(
                "stable",
                point,
                "1",
                "stable (every Floquet multiplier inside the unit circle)",
                Values::Bool(points.iter().map(|(_, b)| b.stable).collect()),
            ),
            Variable::f64(
                "max_multiplier",
                point,
                "1",
                "largest |Floquet multiplier|",
                &col(&|_, b| b.multipliers[0].norm()),
            ),
            Variable::new(
                "critical",
                point,
                "1",
                "how the orbit is or would become unstable",
                Values::Text(
                    points
                        .iter()
                        .map(|(_, b)| b.critical.name().into())
                        .collect(),
                ),
            ),
            Variable::i32(
                "switchings",
                point,
                "1",
                "switchings per cycle",
                &int(&|_, b| b.switchings),
            ),
            Variable::f64(
                "grazing_distance",
                point,
                "g0",
                "distance to grazing",
                &col(&|_, b| b.grazing_distance),
            ),
            Variable::new(
                "event",
                point,
                "1",
                "located bifurcation (\"\": none)",
                Values::Text(
                    points
                        .iter()
                        .map(|(_, b)| b.event.map_or(String::new(), |e| e.name().into()))
                        .collect(),
                ),
            ),
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
        ],
    )
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
