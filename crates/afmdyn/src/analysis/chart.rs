//! Two-parameter behaviour charts (issue 29): over a grid of two parameters (x, y), every
//! attractor each cell's starts reach, with its period n or, for a nonperiodic motion, its
//! largest Lyapunov exponent λ₁ (chaos λ₁ > 0, quasi-periodicity λ₁ ≈ 0), X_max, contacts per
//! period and basin fraction among the random starts.
//!
//! A chart is planned as independent tasks ([`ChartPlan`]): a task is a *tile*, up to
//! [`ChartSpec::tile`] consecutive cells of one row (one y value). In a tile each cell gets
//!
//! 1. its K random starts (`cell_start`, keyed by the seed and the cell's x and y, never by
//!    execution order), and
//! 2. continuation from its neighbours along x: a forward pass seeds each cell with the
//!    attractors of the cell to its left, a backward pass with those of the cell to its right
//!    (what a forward and a backward sweep reveal in a bifurcation diagram: coexisting
//!    branches, hysteresis).
//!
//! The runs of a cell are clustered into attractors by
//! [`super::attractors::same_attractor`]. A tile is a pure function of the
//! spec and its number, so every executor and any thread count gives the same cells bit for
//! bit. Continuation does not cross tile edges (nor rows): a wider tile follows branches
//! further at the price of fewer, longer tasks.

use super::attractors::same_attractor;
use super::bifurcation::{mix64, random_state};
use super::lyapunov::largest_exponent;
use super::steady::{steady_state_of, SteadyOptions, SteadyState};
use crate::error::SimError;
use crate::integrate::IntegratorOptions;
use crate::model::CantileverModel;
use crate::params::Params;
use nalgebra::DVector;
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use std::sync::atomic::{AtomicBool, Ordering};

/// The parameters of a cell from its coordinates (x, y): what the chart's axes mean. The
/// request layer implements it (an α, Ω or an SI probe quantity on each axis).
pub trait CellParams: Sync {
    /// The parameters at (x, y).
    ///
    /// # Errors
    /// [`SimError`] for a value out of its range.
    fn params(&self, x: f64, y: f64) -> Result<Params, SimError>;
}

/// A chart: its axes' values and the options of every cell.
#[derive(Debug, Clone, PartialEq)]
pub struct ChartSpec {
    /// Values of the x parameter (columns).
    pub x: Vec<f64>,
    /// Values of the y parameter (rows).
    pub y: Vec<f64>,
    /// Random starts per cell (K ≥ 1).
    pub starts: u32,
    /// Seed of the random starts.
    pub seed: u64,
    /// Cells per task (a tile of one row).
    pub tile: usize,
    /// Clustering tolerance of [`same_attractor`].
    pub cluster_tol: f64,
    /// Drive periods of the λ₁ estimate of a nonperiodic attractor (0: not estimated).
    pub lyapunov_periods: usize,
    /// Steady-state search of every run.
    pub steady: SteadyOptions,
    /// Integrator.
    pub integrator: IntegratorOptions,
}

/// How an attractor of a cell was first found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Origin {
    /// From a random start of the cell.
    Start,
    /// From an attractor of the cell to the left (forward pass).
    Left,
    /// From an attractor of the cell to the right (backward pass).
    Right,
}

/// One attractor of a cell. Lengths in units of the gap g0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChartAttractor {
    /// Period n in drive periods; `None`: nonperiodic up to the largest period searched.
    pub period: Option<usize>,
    /// Largest Lyapunov exponent λ₁ per unit τ of a nonperiodic attractor (`None` for a
    /// periodic one, or when not estimated or its run failed).
    pub lyapunov: Option<f64>,
    /// The error of λ₁: its uncertainty over the blocks plus its convergence estimate
    /// ([`super::lyapunov::LyapunovSpectrum`]); `None` with `lyapunov`.
    pub lyapunov_error: Option<f64>,
    /// Largest tip deflection W(1,τ) over the recorded steady state (g0).
    pub x_max: f64,
    /// Smallest V_T over the recorded steady state (g0; ≤ 0: contact).
    pub v_t_min: f64,
    /// Contact entries (impacts) per drive period.
    pub contacts_per_period: f64,
    /// Fraction of the time in contact.
    pub contact_fraction: f64,
    /// Random starts of the cell that reached it.
    pub count: u32,
    /// `count` / K: its basin fraction among the random starts (0 for an attractor found
    /// only by continuation).
    pub fraction: f64,
    /// How it was first found.
    pub origin: Origin,
    /// Modal state (a_1…a_N, ȧ_1…ȧ_N) at its last Poincaré point (τ a multiple of 2π/Ω):
    /// where continuation into the next cell starts.
    pub state: Vec<f64>,
}

/// What kind of motion an attractor of a chart is, from its period and λ₁.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionKind {
    /// A period-n orbit.
    Periodic(usize),
    /// Nonperiodic with λ₁ > 2 × its error: chaos.
    Chaotic,
    /// Nonperiodic with |λ₁| ≤ 2 × its error: quasi-periodic (or undecided).
    Quasiperiodic,
    /// Nonperiodic with λ₁ < −2 × its error: a motion still converging (to a periodic orbit
    /// of period > 64, or one the transient cap `max_periods` did not reach — high-Q
    /// cantilevers settle over ~Q periods).
    Unsettled,
    /// Nonperiodic without a λ₁ estimate.
    Nonperiodic,
}

impl MotionKind {
    /// The numeric code of the result arrays: n ≥ 1 is not used here (see `period`); 1
    /// periodic, 2 chaotic, 3 quasi-periodic, 4 unsettled, 5 nonperiodic without λ₁ (0: an
    /// empty slot).
    pub fn code(self) -> i32 {
        match self {
            MotionKind::Periodic(_) => 1,
            MotionKind::Chaotic => 2,
            MotionKind::Quasiperiodic => 3,
            MotionKind::Unsettled => 4,
            MotionKind::Nonperiodic => 5,
        }
    }

    /// `periodic`, `chaotic`, `quasiperiodic`, `unsettled` or `nonperiodic`.
    pub fn name(self) -> &'static str {
        match self {
            MotionKind::Periodic(_) => "periodic",
            MotionKind::Chaotic => "chaotic",
            MotionKind::Quasiperiodic => "quasiperiodic",
            MotionKind::Unsettled => "unsettled",
            MotionKind::Nonperiodic => "nonperiodic",
        }
    }
}

impl ChartAttractor {
    /// Its kind of motion: the period, or the sign of λ₁ against twice its error.
    pub fn motion(&self) -> MotionKind {
        match (self.period, self.lyapunov, self.lyapunov_error) {
            (Some(n), _, _) => MotionKind::Periodic(n),
            (None, Some(l), Some(e)) if l > 2.0 * e => MotionKind::Chaotic,
            (None, Some(l), Some(e)) if l < -2.0 * e => MotionKind::Unsettled,
            (None, Some(_), Some(_)) => MotionKind::Quasiperiodic,
            _ => MotionKind::Nonperiodic,
        }
    }
}

/// One cell of a chart.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChartCell {
    /// Column (index into x).
    pub ix: usize,
    /// Row (index into y).
    pub iy: usize,
    /// x value.
    pub x: f64,
    /// y value.
    pub y: f64,
    /// Its attractors, most random starts first (then in the order found).
    pub attractors: Vec<ChartAttractor>,
    /// Runs of the cell that failed (random starts and continuation seeds).
    pub failures: u32,
    /// The first failure's message (the cell's parameters', when they are invalid).
    pub message: Option<String>,
}

/// The random initial state of start `k` of the cell at (x, y), keyed by the seed and the
/// cell's coordinates (the same cell gets the same starts in every chart that contains it).
pub(crate) fn cell_start(
    model: &CantileverModel,
    seed: u64,
    x: f64,
    y: f64,
    k: u32,
) -> DVector<f64> {
    let key = mix64(x.to_bits()) ^ mix64(y.to_bits()).rotate_left(17) ^ u64::from(k);
    random_state(model, seed, key)
}

/// Relative distance within which a run that ends nonperiodic counts as converging to a known
/// periodic attractor.
pub(crate) const CONVERGING_TOL: f64 = 1e-3;

/// Whether `s`, a run that hit the transient cap without a period, is still converging to the
/// periodic attractor `a`: every recorded Poincaré point of `s` lies within [`CONVERGING_TOL`]
/// (relative to 1 + |z|) of a Poincaré point of `a`. Near a period doubling the orbit contracts
/// so slowly (|μ| → 1) that a run from a neighbouring cell's state, close to the orbit but not
/// on it, can use up the transient before its returns agree to the steady-state tolerance;
/// such a run is the same attractor, not a new nonperiodic one.
fn converging_to(s: &SteadyState, a: &SteadyState) -> bool {
    s.period().is_none()
        && a.period().is_some()
        && !s.poincare.is_empty()
        && s.poincare.iter().all(|p| {
            a.poincare
                .iter()
                .any(|q| (&p.state - &q.state).norm() <= CONVERGING_TOL * (1.0 + q.state.norm()))
        })
}

/// A chart planned as tiles (see the module).
pub struct ChartPlan<'a> {
    spec: &'a ChartSpec,
    cells: &'a dyn CellParams,
}

impl std::fmt::Debug for ChartPlan<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ChartPlan")
            .field("spec", self.spec)
            .finish_non_exhaustive()
    }
}

/// A cell while its tile runs.
struct Work {
    model: Option<CantileverModel>,
    found: Vec<(SteadyState, u32, Origin)>,
    failures: u32,
    message: Option<String>,
}

impl<'a> ChartPlan<'a> {
    /// The plan of `spec` with the cell parameters of `cells`.
    pub fn new(spec: &'a ChartSpec, cells: &'a dyn CellParams) -> ChartPlan<'a> {
        ChartPlan { spec, cells }
    }

    fn tiles_per_row(&self) -> usize {
        self.spec.x.len().div_ceil(self.spec.tile.max(1))
    }

    /// The number of tasks (tiles): ⌈nx / tile⌉ per row, row after row.
    pub fn tasks(&self) -> usize {
        self.tiles_per_row() * self.spec.y.len()
    }

    /// The cells of task `t`: its row and its columns.
    pub fn tile(&self, t: usize) -> (usize, std::ops::Range<usize>) {
        let per_row = self.tiles_per_row().max(1);
        let (iy, k) = (t / per_row, t % per_row);
        let tile = self.spec.tile.max(1);
        let lo = (k * tile).min(self.spec.x.len());
        (iy, lo..((k + 1) * tile).min(self.spec.x.len()))
    }

    fn run(&self, w: &mut Work, z0: &DVector<f64>, origin: Origin) {
        let Some(model) = &w.model else { return };
        let r = steady_state_of(model, self.spec.integrator.clone(), z0, &self.spec.steady);
        match r {
            Err(e) => {
                w.failures += 1;
                w.message.get_or_insert_with(|| e.to_string());
            }
            Ok(s) => {
                let from_start = u32::from(origin == Origin::Start);
                let tol = self.spec.cluster_tol;
                match w.found.iter_mut().find(|(a, _, _)| {
                    same_attractor(a, &s, tol) || converging_to(&s, a) || converging_to(a, &s)
                }) {
                    Some((a, count, _)) => {
                        *count += from_start;
                        // a nonperiodic run found first gives way to the orbit it converges to
                        if converging_to(a, &s) {
                            *a = s;
                        }
                    }
                    None => w.found.push((s, from_start, origin)),
                }
            }
        }
    }

    /// Run task `t`: the cells of its tile in order of x, or `None` when `cancel` was set
    /// before it finished.
    pub fn run_task(&self, t: usize, cancel: &AtomicBool) -> Option<Vec<ChartCell>> {
        let spec = self.spec;
        let (iy, cols) = self.tile(t);
        let y = spec.y[iy];
        let mut work: Vec<Work> = cols
            .clone()
            .map(|ix| match self.cells.params(spec.x[ix], y) {
                Ok(p) => match CantileverModel::new(&p) {
                    Ok(m) => Work {
                        model: Some(m),
                        found: Vec::new(),
                        failures: 0,
                        message: None,
                    },
                    Err(e) => Work {
                        model: None,
                        found: Vec::new(),
                        failures: 0,
                        message: Some(SimError::from(e).to_string()),
                    },
                },
                Err(e) => Work {
                    model: None,
                    found: Vec::new(),
                    failures: 0,
                    message: Some(e.to_string()),
                },
            })
            .collect();
        let stopped = || cancel.load(Ordering::Relaxed);
        let states = |w: &Work, skip: Origin| -> Vec<DVector<f64>> {
            w.found
                .iter()
                .filter(|(_, _, o)| *o != skip)
                .map(|(s, _, _)| s.end_state().clone())
                .collect()
        };
        // forward: the cell's random starts, then the attractors of the cell to its left
        for j in 0..work.len() {
            let x = spec.x[cols.start + j];
            for k in 0..spec.starts {
                if stopped() {
                    return None;
                }
                if let Some(m) = &work[j].model {
                    let z0 = cell_start(m, spec.seed, x, y, k);
                    self.run(&mut work[j], &z0, Origin::Start);
                }
            }
            if j > 0 {
                for z0 in states(&work[j - 1], Origin::Right) {
                    if stopped() {
                        return None;
                    }
                    self.run(&mut work[j], &z0, Origin::Left);
                }
            }
        }
        // backward: the attractors of the cell to its right, except those it got from this one
        for j in (0..work.len().saturating_sub(1)).rev() {
            for z0 in states(&work[j + 1], Origin::Left) {
                if stopped() {
                    return None;
                }
                self.run(&mut work[j], &z0, Origin::Right);
            }
        }
        let cells = work
            .into_iter()
            .enumerate()
            .map(|(j, w)| self.cell(iy, cols.start + j, w))
            .collect();
        (!stopped()).then_some(cells)
    }

    fn cell(&self, iy: usize, ix: usize, w: Work) -> ChartCell {
        let spec = self.spec;
        let mut found = w.found;
        // most random starts first; the sort is stable: ties keep the order found
        found.sort_by_key(|(_, count, _)| std::cmp::Reverse(*count));
        let attractors = found
            .into_iter()
            .map(|(s, count, origin)| {
                let period = s.period();
                let lyapunov = match (&w.model, period) {
                    (Some(m), None) if spec.lyapunov_periods > 0 => largest_exponent(
                        m,
                        s.end_state(),
                        spec.lyapunov_periods,
                        spec.integrator.clone(),
                    ),
                    _ => None,
                };
                ChartAttractor {
                    period,
                    lyapunov: lyapunov.map(|l| l.0),
                    lyapunov_error: lyapunov.map(|l| l.1),
                    x_max: s.stats.x_max,
                    v_t_min: s.stats.v_t_min,
                    contacts_per_period: s.stats.contacts_per_period,
                    contact_fraction: s.stats.contact_fraction,
                    count,
                    fraction: f64::from(count) / f64::from(spec.starts.max(1)),
                    origin,
                    state: s.end_state().iter().copied().collect(),
                }
            })
            .collect();
        ChartCell {
            ix,
            iy,
            x: spec.x[ix],
            y: spec.y[iy],
            attractors,
            failures: w.failures,
            message: w.message,
        }
    }
}

/// The local executor: every task of `plan` not in `done`, on the current rayon pool (one
/// task per work item; no lock on the hot path: each finished tile goes straight to `sink`
/// with its task number). Stops starting tasks once `cancel` is set; a task cut short is not
/// sent.
pub fn run_chart(
    plan: &ChartPlan<'_>,
    done: &HashSet<usize>,
    sink: &(dyn Fn(usize, Vec<ChartCell>) + Sync),
    cancel: &AtomicBool,
) {
    let never: Result<(), std::convert::Infallible> = super::tasks::run_independent(
        plan.tasks(),
        done,
        &|t| Ok(plan.run_task(t, cancel)),
        sink,
        cancel,
    );
    match never {
        Ok(()) => {}
        Err(e) => match e {},
    }
}
