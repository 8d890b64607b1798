//! A basin map's results as the front ends show them: its JSON document (`afmdyn basins
//! --json`, Python's `summary`), `basins.csv`, its caveats and the per-cell arrays of
//! `basins.nc` and Python's dataset ([`BasinArrays`]).

use crate::analysis::basin_entropy::{basin_entropy, uncertainty_exponent};
use crate::analysis::basins::{BasinMap, BasinSpec, Decided, StateCoord};
use crate::layout::{Attr, Layout, Variable};
use crate::model::CantileverModel;
use serde_json::{json, Value};

/// Side of the boxes of the basin entropy, in cells ([`basin_entropy`]; Daza et al. use 5).
pub(crate) const ENTROPY_BOX: usize = 5;

/// The document of a basin map (`afmdyn basins --json`): axes, labels (ny rows of nx ids),
/// attractors (period, multipliers, stability, λ₁, Poincaré states, X_max, min V_T, contacts),
/// basin fractions, failed cells, how the cells were decided, the drive periods run, basin
/// entropy S_b and boundary basin entropy S_bb (boxes of `ENTROPY_BOX`² cells; null when no
/// box fits) and the uncertainty exponent (null when no cell is uncertain).
pub(crate) fn document(spec: &BasinSpec, map: &BasinMap) -> Value {
    let nx = spec.xs.len();
    let labels = map.labels();
    let entropy = basin_entropy(&labels, nx, ENTROPY_BOX);
    let count = |d: Decided| map.cells.iter().filter(|c| c.decided == d).count();
    json!({
        "params": spec.params,
        "x": {"name": spec.x.to_string(), "values": spec.xs},
        "y": {"name": spec.y.to_string(), "values": spec.ys},
        "base": spec.base.iter().copied().collect::<Vec<f64>>(),
        "labels": labels.chunks(nx).collect::<Vec<_>>(),
        "attractors": map.attractors.iter().enumerate().map(|(i, s)| json!({
            "id": i,
            "period": s.period(),
            "multipliers": map.orbits[i].as_ref().map(|o| o.multipliers.iter()
                .map(|m| [m.re, m.im]).collect::<Vec<_>>()),
            "stable": map.orbits[i].as_ref().map(|o| o.stable),
            "lyapunov": map.lyapunov[i],
            "poincare": {"state": s.poincare.iter()
                .map(|q| q.state.iter().copied().collect::<Vec<f64>>())
                .collect::<Vec<_>>()},
            "x_max": s.stats.x_max,
            "v_t_min": s.stats.v_t_min,
            "contacts_per_period": s.stats.contacts_per_period,
        })).collect::<Vec<_>>(),
        "basin_fractions": map.basin_fractions(),
        "failed": labels.iter().filter(|&&l| l < 0).count(),
        "decided": {
            "near": count(Decided::Near),
            "recurrence": count(Decided::Recurrence),
            "grid": count(Decided::Grid),
            "steady": count(Decided::Steady),
            "failed": count(Decided::Failed),
        },
        "first_stride": spec.first_stride(),
        "periods": map.cells.iter().map(|c| c.periods as u64).sum::<u64>(),
        "basin_entropy": entropy.map(|e| e.basin_entropy),
        "boundary_basin_entropy": entropy.map(|e| e.boundary_basin_entropy),
        "uncertainty_exponent": uncertainty_exponent(&labels, nx).map(|u| u.0),
        "warnings": warnings(spec, map),
    })
}

/// `basins.csv`: a header and one line per cell, row by row (`ix,iy,x,y,label,decided,periods`;
/// `decided` as [`Decided::name`]).
pub(crate) fn csv_text(spec: &BasinSpec, map: &BasinMap) -> String {
    let nx = spec.xs.len();
    let mut text = String::from("ix,iy,x,y,label,decided,periods\n");
    for (k, c) in map.cells.iter().enumerate() {
        let (ix, iy) = (k % nx, k / nx);
        text.push_str(&format!(
            "{ix},{iy},{},{},{},{},{}\n",
            spec.xs[ix],
            spec.ys[iy],
            c.label,
            c.decided.name(),
            c.periods
        ));
    }
    text
}

/// The caveats of a basin map (the `warnings` of its document): attractors that are
/// nonperiodic with λ₁ ≤ 0 — quasi-periodic, or starts still converging at the transient cap
/// whose cells carry a label that is not an attractor's.
pub(crate) fn warnings(spec: &BasinSpec, map: &BasinMap) -> Vec<String> {
    let model = CantileverModel::new(&spec.params).ok();
    let cap = model.as_ref().map(|m| spec.steady.cap(m));
    map.attractors
        .iter()
        .zip(&map.lyapunov)
        .enumerate()
        .filter_map(|(i, (s, l))| match (s.period(), l) {
            (None, Some(l)) if *l <= 0.0 => {
                let cells = map.cells.iter().filter(|c| c.label == i as i64).count();
                Some(warning!(
                    "basins.nonperiodic",
                    "Raise max_periods: λ₁ then tells a quasi-periodic attractor (≈ 0) \
                     from one still settling (< 0).",
                    "attractor {i} ({cells} cells) is nonperiodic with λ₁ = {l:.3e} ≤ 0 after \
                     the transient cap of {} drive periods: quasi-periodic, or still settling; \
                     raise max_periods to tell",
                    cap.map_or("?".into(), |c| c.to_string())
                ))
            }
            _ => None,
        })
        .collect()
}

/// The per-cell and per-attractor arrays of a basin map: the one layout of `basins.nc` and of
/// Python's dataset (cells row-major, ny × nx).
#[derive(Debug, Clone, PartialEq)]
pub struct BasinArrays {
    /// Attractor id per cell (−2 failed).
    pub label: Vec<i32>,
    /// How each cell was decided: [`Decided::code`].
    pub decided: Vec<i32>,
    /// Drive periods each start ran.
    pub periods: Vec<i32>,
    /// Per attractor: period n (−1 nonperiodic).
    pub period: Vec<i32>,
    /// Per attractor: X_max (g0).
    pub x_max: Vec<f64>,
    /// Per attractor: min V_T (g0).
    pub v_t_min: Vec<f64>,
    /// Per attractor: basin fraction.
    pub basin_fraction: Vec<f64>,
    /// Per attractor: 1 stable periodic orbit, 0 unstable, NaN unknown (nonperiodic, no
    /// shooting).
    pub stable: Vec<f64>,
    /// Per attractor: λ₁ of a nonperiodic attractor (per unit τ), NaN otherwise.
    pub lyapunov: Vec<f64>,
}

impl BasinArrays {
    /// The map's layout (`basins.nc`, Python's dataset): coordinates `x`, `y` (the state's
    /// coordinates at τ = 0, in g0 or g0 per unit τ), per cell (y, x) `label`, `decided` (CF
    /// flag values and meanings), `periods`, and per attractor `period`, `x_max`, `v_t_min`,
    /// `basin_fraction`, `stable`, `lyapunov`.
    pub fn layout(&self, spec: &BasinSpec) -> Layout {
        let unit = |c: StateCoord| {
            if matches!(c, StateCoord::ADot(_) | StateCoord::WDot) {
                "g0 per unit tau"
            } else {
                "g0"
            }
        };
        let a = self;
        let (cell, att): (&[&str], &[&str]) = (&["y", "x"], &["attractor"]);
        let decided = Variable::i32("decided", cell, "1", "how the cell was decided", &a.decided)
            .with(
                "flag_values",
                Attr::I32(Decided::ALL.iter().map(|x| x.code()).collect()),
            )
            .with(
                "flag_meanings",
                Attr::Text(
                    Decided::ALL
                        .iter()
                        .map(|x| x.name())
                        .collect::<Vec<_>>()
                        .join(" "),
                ),
            );
        Layout::new(
            format!("afmdyn basins of attraction over {} and {}", spec.x, spec.y),
            &[
                ("x", spec.xs.len()),
                ("y", spec.ys.len()),
                ("attractor", a.period.len()),
            ],
            vec![
                Variable::f64(
                    "x",
                    &["x"],
                    unit(spec.x),
                    format!("{} at tau = 0", spec.x),
                    &spec.xs,
                ),
                Variable::f64(
                    "y",
                    &["y"],
                    unit(spec.y),
                    format!("{} at tau = 0", spec.y),
                    &spec.ys,
                ),
                Variable::i32("label", cell, "1", "attractor id; -2 failed", &a.label),
                decided,
                Variable::i32(
                    "periods",
                    cell,
                    "drive periods",
                    "drive periods the start ran",
                    &a.periods,
                ),
                Variable::i32(
                    "period",
                    att,
                    "drive periods",
                    "period n; -1 nonperiodic",
                    &a.period,
                ),
                Variable::f64(
                    "x_max",
                    att,
                    "g0",
                    "largest tip deflection W(1,tau)",
                    &a.x_max,
                ),
                Variable::f64("v_t_min", att, "g0", "smallest V_T", &a.v_t_min),
                Variable::f64(
                    "basin_fraction",
                    att,
                    "1",
                    "share of the map's cells",
                    &a.basin_fraction,
                ),
                Variable::f64(
                    "stable",
                    att,
                    "1",
                    "1 stable periodic orbit (shooting), 0 unstable, NaN unknown",
                    &a.stable,
                ),
                Variable::f64(
                    "lyapunov",
                    att,
                    "1/tau",
                    "largest Lyapunov exponent of a nonperiodic attractor",
                    &a.lyapunov,
                ),
            ],
        )
    }

    /// The arrays of `map`.
    pub(crate) fn new(map: &BasinMap) -> Self {
        let int = |v: usize| i32::try_from(v).unwrap_or(i32::MAX);
        BasinArrays {
            label: map.cells.iter().map(|c| c.label as i32).collect(),
            decided: map.cells.iter().map(|c| c.decided.code()).collect(),
            periods: map.cells.iter().map(|c| int(c.periods)).collect(),
            period: map
                .attractors
                .iter()
                .map(|s| s.period().map_or(-1, int))
                .collect(),
            x_max: map.attractors.iter().map(|s| s.stats.x_max).collect(),
            v_t_min: map.attractors.iter().map(|s| s.stats.v_t_min).collect(),
            basin_fraction: map.basin_fractions(),
            stable: map
                .orbits
                .iter()
                .map(|o| {
                    o.as_ref()
                        .map_or(f64::NAN, |o| f64::from(u8::from(o.stable)))
                })
                .collect(),
            lyapunov: map.lyapunov.iter().map(|l| l.unwrap_or(f64::NAN)).collect(),
        }
    }
}
