//! `basins`: the request of a basin map ([`crate::analysis::basins`]) that the command line
//! and Python share — its options with their limits, the worker threads, the JSON document
//! (`afmdyn basins --json`, Python's `summary`) and the per-cell arrays of `basins.nc` and
//! Python's dataset ([`BasinArrays`]). It runs as a study (`crate::study::basins`, which
//! holds its `Analysis`).

use super::analyses::{initial_state, IntegratorRequest, SteadyRequest};
use crate::analysis::basin_entropy::{basin_entropy, uncertainty_exponent};
use crate::analysis::basins::{
    BasinMap, BasinSpec, Decided, StateCoord, DEFAULT_BASIN_HITS, DEFAULT_CELL,
    DEFAULT_DISCOVER_AFTER, DEFAULT_NEAR_TOL, DEFAULT_STRIDE,
};
use crate::analysis::bifurcation::SweepSpec;
use crate::error::SimError;
use crate::layout::{Attr, Layout, Variable};
use crate::model::CantileverModel;
use crate::params::Params;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// Side of the boxes of the basin entropy, in cells ([`basin_entropy`]; Daza et al. use 5).
pub(crate) const ENTROPY_BOX: usize = 5;

/// `basins`: a basin map over two coordinates of the initial state at τ = 0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct BasinsRequest {
    /// x coordinate: `a1`…`aN`, `adot1`…`adotN`, `w` or `wdot` (the tip, set through mode 1).
    pub x: String,
    /// First x value (g0, or g0 per unit τ for a velocity).
    pub x_from: f64,
    /// Last x value.
    pub x_to: f64,
    /// Number of x values (columns).
    pub x_steps: usize,
    /// y coordinate, as `x`.
    pub y: String,
    /// First y value.
    pub y_from: f64,
    /// Last y value.
    pub y_to: f64,
    /// Number of y values (rows).
    pub y_steps: usize,
    /// The other coordinates of every start, 2N values (a1…aN, ȧ1…ȧN); `None`: the rest state.
    pub base: Option<Vec<f64>>,
    /// Relative distance to a periodic attractor's section point that counts as near, (0, 1].
    pub near_tol: f64,
    /// Side of the state-space cells of the recurrence test (g0; ×Ω for velocities), > 0.
    pub cell: f64,
    /// Consecutive returns in cells of one basin that decide a start (0: no recurrence test).
    pub basin_hits: usize,
    /// Returns tested before the steady-state search takes over.
    pub discover_after: usize,
    /// Stride of the first pass's coarse grid (0: automatic, 1: one pass).
    pub stride: usize,
    /// Relative tolerance for two steady states to be one attractor, > 0.
    pub cluster_tol: f64,
    /// Worker threads, 1..=[`MAX_THREADS`](super::limits::MAX_THREADS); `None`: all cores.
    #[cfg_attr(
        feature = "schema",
        schemars(extend("x-constants" = { "MAX_THREADS": super::limits::MAX_THREADS }))
    )]
    pub threads: Option<usize>,
    /// The steady-state search of a start the early tests leave undecided.
    #[serde(flatten)]
    pub steady: SteadyRequest,
    /// The integrator.
    #[serde(flatten)]
    pub integrator: IntegratorRequest,
}

impl Default for BasinsRequest {
    fn default() -> Self {
        BasinsRequest {
            x: "a1".into(),
            x_from: -0.6,
            x_to: 0.6,
            x_steps: 40,
            y: "adot1".into(),
            y_from: -1.2,
            y_to: 1.2,
            y_steps: 40,
            base: None,
            near_tol: DEFAULT_NEAR_TOL,
            cell: DEFAULT_CELL,
            basin_hits: DEFAULT_BASIN_HITS,
            discover_after: DEFAULT_DISCOVER_AFTER,
            stride: DEFAULT_STRIDE,
            cluster_tol: super::DEFAULT_CLUSTER_TOL,
            threads: None,
            steady: SteadyRequest::default(),
            integrator: IntegratorRequest::default(),
        }
    }
}

fn coord(name: &'static str, s: &str) -> Result<StateCoord, SimError> {
    s.parse()
        .map_err(|_| SimError::out_of_range(name, s, "must be a1…aN, adot1…adotN, w or wdot"))
}

impl BasinsRequest {
    /// The validated map of `params` ([`BasinSpec::validate`], the coordinates within the N
    /// modes, the base state's length and entries, the thread count).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the option; [`SimError::StateLength`] for a base of
    /// another length than 2N; [`SimError::Params`] for invalid parameters.
    pub fn spec(&self, params: &Params) -> Result<BasinSpec, SimError> {
        super::limits::check_threads(self.threads)?;
        let (x, y) = (coord("x", &self.x)?, coord("y", &self.y)?);
        let model = CantileverModel::new(params)?;
        let spec = BasinSpec {
            params: *params,
            x,
            xs: SweepSpec::linspace(self.x_from, self.x_to, self.x_steps)
                .map_err(|e| rename(e, ["x_from", "x_to", "x_steps"]))?,
            y,
            ys: SweepSpec::linspace(self.y_from, self.y_to, self.y_steps)
                .map_err(|e| rename(e, ["y_from", "y_to", "y_steps"]))?,
            base: initial_state(&model, self.base.as_deref()).map_err(|e| match e {
                SimError::StateLength { expected, got, .. } => SimError::StateLength {
                    name: "base (a1..aN, adot1..adotN)",
                    expected,
                    got,
                },
                SimError::OutOfRange { value, allowed, .. } => SimError::OutOfRange {
                    name: "base",
                    value,
                    allowed,
                },
                e => e,
            })?,
            near_tol: self.near_tol,
            cell: self.cell,
            basin_hits: self.basin_hits,
            discover_after: self.discover_after,
            stride: self.stride,
            steady: self.steady.options()?,
            cluster_tol: self.cluster_tol,
            integrator: self.integrator.options(1)?,
        };
        spec.validate()?;
        Ok(spec)
    }
}

/// An error of [`SweepSpec::linspace`] named after the axis' option (`from`, `to`, `steps`).
fn rename(e: SimError, [from, to, steps]: [&'static str; 3]) -> SimError {
    match e {
        SimError::OutOfRange {
            name,
            value,
            allowed,
        } => SimError::OutOfRange {
            name: match name {
                "from" => from,
                "to" => to,
                "steps" => steps,
                other => other,
            },
            value,
            allowed,
        },
        SimError::NotFinite { name, value } => SimError::NotFinite {
            name: if name == "from" { from } else { to },
            value,
        },
        e => e,
    }
}

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
                Some(format!(
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
