//! Basins of attraction over a plane of initial conditions (issue 30): every cell of a grid of
//! initial states at τ = 0 gets the id of the attractor its trajectory reaches, without running
//! every start to convergence.
//!
//! A start iterates the stroboscopic map P (one drive period) and stops as soon as
//!
//! 1. **near**: `NEAR_HITS` consecutive returns lie within `near_tol` (relative to 1 + |p|)
//!    of the section points of one known *periodic* attractor — a stable orbit's neighbourhood,
//!    where the trajectory converges to it; or
//! 2. **recurrence**: `basin_hits` consecutive returns fall in cells of the state space
//!    (boxes of side `cell` in each modal coordinate, `cell`·Ω in each velocity) already
//!    labelled with one attractor by earlier trajectories of the task — the recurrence idea of
//!    Datseris & Wagemakers, "Effortless estimation of basins of attraction", Chaos 32, 023104
//!    (2022), after Nusse & Yorke;
//!
//! otherwise, after `discover_after` returns, the steady state is searched as
//! [`steady_state`] does and matched against the known attractors (a new one is added). How
//! each cell was decided is recorded. Every return of a labelled trajectory labels its cell.
//!
//! **Two passes** (when the map's plane is the whole stroboscopic section: N = 1, one position
//! coordinate and one velocity, and `stride` > 1). The first pass maps the coarse grid of every
//! `stride`-th row and column (and the last ones) as above. In the second pass every other
//! start knows all the first pass's attractors from its first return, and stops as soon as a
//! return lands in a coarse cell whose four corners carry one label — the cell method of Nusse
//! & Yorke, *Dynamics: Numerical Explorations* (Springer, 1994, ch. 7), with the interior test
//! of the four corners as the guard against basin boundaries finer than the coarse grid
//! (decision `grid`). A return in a mixed cell is tested again at the next return; near and
//! recurrence decide as in the first pass.
//!
//! A task is one row of a pass (cells in order of x): pure in (spec, row, the first pass's
//! result), so any thread count gives the same map; the attractors of the rows are matched in
//! row order (the first pass's rows, then the second's) into global ids.

use super::attractors::{polish_steady, same_attractor, same_orbit};
use super::bifurcation::mix64;
use super::lyapunov::largest_exponent;
#[cfg(not(feature = "parallel"))]
use super::sequential::*;
use super::shooting::PeriodicOrbit;
use super::steady::{steady_state, SteadyOptions, SteadyState};
use crate::error::SimError;
use crate::integrate::{advance, build, Integrator, IntegratorOptions};
use crate::model::CantileverModel;
use crate::params::Params;
use nalgebra::DVector;
#[cfg(feature = "parallel")]
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fmt;
use std::str::FromStr;
use std::sync::atomic::{AtomicBool, Ordering};

mod rows;
use rows::{coarse_grid, coarse_indices, merge_pass, run_row, strides, CoarseGrid};

/// Consecutive returns near a known periodic attractor that decide a start.
pub(crate) const NEAR_HITS: usize = 3;
/// Default relative distance that counts as near a periodic attractor's section point.
pub const DEFAULT_NEAR_TOL: f64 = 0.02;
/// Default side of the recurrence test's state-space cells (g0).
pub const DEFAULT_CELL: f64 = 0.01;
/// Default consecutive returns in labelled cells that decide a start. (On the impact
/// oscillator N = 1, r = 0.8, Ω = 2 over a 100 × 100 grid: cells of 0.02 with 8 or 16 hits
/// mislabelled 0.7 % of the cells where two basins interleave; 0.01 with 16, none.)
pub const DEFAULT_BASIN_HITS: usize = 16;
/// Default returns tested before the steady-state search takes over.
pub const DEFAULT_DISCOVER_AFTER: usize = 200;
/// Consecutive returns in coarse cells whose four corners share one label that decide a start
/// of a later pass (one return decides when the 3 × 3 coarse cells around it share the label).
pub(crate) const GRID_HITS: usize = 2;
/// Default stride of the first pass's coarse grid: 0, automatic (`BasinSpec::first_stride`).
pub const DEFAULT_STRIDE: usize = 0;
/// Fewest nodes per axis of the first pass's coarse grid chosen automatically. (On the impact
/// oscillator N = 1, r = 0.8, Ω = 2 at 100 × 100, a first grid of 13 × 13 (stride 8) held no
/// node in the 8 % basin, and 7 % of the labels were wrong; 25 × 25 (stride 4): 99.7 % right.)
pub(crate) const MIN_COARSE_NODES: usize = 25;

/// A coordinate of the initial state: modal `a_j`, `ȧ_j` (j from 1), or the tip deflection
/// W(1,0) and velocity (set through mode 1, the other modes as the base state has them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StateCoord {
    /// a_j (1-based).
    A(usize),
    /// ȧ_j (1-based).
    ADot(usize),
    /// W(1,0) = Σ φ_j(1) a_j.
    W,
    /// ∂W(1,0)/∂τ.
    WDot,
}

impl FromStr for StateCoord {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim().to_ascii_lowercase();
        let index = |rest: &str| rest.parse::<usize>().ok().filter(|&j| j >= 1);
        match s.as_str() {
            "w" => Ok(StateCoord::W),
            "wdot" | "w_dot" => Ok(StateCoord::WDot),
            _ => {
                if let Some(j) = s
                    .strip_prefix("adot")
                    .or_else(|| s.strip_prefix("a_dot"))
                    .and_then(index)
                {
                    Ok(StateCoord::ADot(j))
                } else if let Some(j) = s.strip_prefix('a').and_then(index) {
                    Ok(StateCoord::A(j))
                } else {
                    Err(format!("'{s}': expected a1…aN, adot1…adotN, w or wdot"))
                }
            }
        }
    }
}

impl fmt::Display for StateCoord {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StateCoord::A(j) => write!(f, "a{j}"),
            StateCoord::ADot(j) => write!(f, "adot{j}"),
            StateCoord::W => f.write_str("w"),
            StateCoord::WDot => f.write_str("wdot"),
        }
    }
}

impl StateCoord {
    /// Whether the coordinate exists for N modes.
    pub(crate) fn fits(self, modes: usize) -> bool {
        match self {
            StateCoord::A(j) | StateCoord::ADot(j) => (1..=modes).contains(&j),
            _ => true,
        }
    }

    /// Set this coordinate of `z` to `v` (W and Ẇ through mode 1: a₁ = (v − Σ_{j≥2} φ_j(1) a_j)/φ₁(1)).
    pub fn set(self, model: &CantileverModel, z: &mut DVector<f64>, v: f64) {
        let n = model.modes();
        let phi = model.tip();
        let through_mode_1 = |z: &mut DVector<f64>, off: usize| {
            let rest: f64 = (1..n).map(|j| phi[j] * z[off + j]).sum();
            z[off] = (v - rest) / phi[0];
        };
        match self {
            StateCoord::A(j) => z[j - 1] = v,
            StateCoord::ADot(j) => z[n + j - 1] = v,
            StateCoord::W => through_mode_1(z, 0),
            StateCoord::WDot => through_mode_1(z, n),
        }
    }
}

/// A basin map.
#[derive(Debug, Clone, PartialEq)]
pub struct BasinSpec {
    /// The model.
    pub params: Params,
    /// The x coordinate (columns) and its values.
    pub x: StateCoord,
    /// x values.
    pub xs: Vec<f64>,
    /// The y coordinate (rows).
    pub y: StateCoord,
    /// y values.
    pub ys: Vec<f64>,
    /// The other coordinates of every initial state (length 2N; rest: zeros).
    pub base: DVector<f64>,
    /// Relative distance to a periodic attractor's section point that counts as near.
    pub near_tol: f64,
    /// Side of the state-space cells of the recurrence test (g0; ×Ω for velocities).
    pub cell: f64,
    /// Consecutive returns in cells labelled with one attractor that decide a start (0: no
    /// recurrence test).
    pub basin_hits: usize,
    /// Returns tested before the steady-state search takes over.
    pub discover_after: usize,
    /// Stride of the first pass's coarse grid (every `stride`-th row and column, halved pass by
    /// pass); 1: one pass; 0: automatic (`BasinSpec::first_stride`). Used where the map's
    /// plane is the whole section (N = 1, a position and a velocity).
    pub stride: usize,
    /// The steady-state search (its `max_periods` caps the whole start).
    pub steady: SteadyOptions,
    /// Clustering tolerance of two steady states.
    pub cluster_tol: f64,
    /// Integrator.
    pub integrator: IntegratorOptions,
}

/// Largest number of cells of a basin map.
pub(crate) const MAX_BASIN_CELLS: usize = 4_000_000;

impl BasinSpec {
    /// Check the options (the one place of their limits).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the option (`x`, `y` for a coordinate outside the N
    /// modes); [`SimError::StateLength`] for a base state of another length than 2N + m (m the
    /// law's internal states).
    pub fn validate(&self) -> Result<(), SimError> {
        let n = self.params.modes;
        for (name, c) in [("x", self.x), ("y", self.y)] {
            if !c.fits(n) {
                return Err(SimError::out_of_range(
                    name,
                    c,
                    "must be a coordinate of the N modes (a1…aN, adot1…adotN, w, wdot)",
                ));
            }
        }
        // (a, ȧ) and the law's internal states
        let dim = self.params.state_dim();
        if self.base.len() != dim {
            return Err(SimError::StateLength {
                name: "base",
                expected: dim,
                got: self.base.len(),
            });
        }
        if self.xs.is_empty() || self.ys.is_empty() {
            return Err(SimError::out_of_range("steps", 0, "must be >= 1"));
        }
        if self.xs.len().saturating_mul(self.ys.len()) > MAX_BASIN_CELLS {
            return Err(SimError::out_of_range(
                "cells",
                format!("{} × {}", self.xs.len(), self.ys.len()),
                "must be <= 4000000 in all",
            ));
        }
        if !(self.near_tol.is_finite() && self.near_tol > 0.0 && self.near_tol <= 1.0) {
            return Err(SimError::out_of_range(
                "near_tol",
                self.near_tol,
                "must be in (0, 1]",
            ));
        }
        if !(self.cell.is_finite() && self.cell > 0.0) {
            return Err(SimError::out_of_range(
                "cell",
                self.cell,
                "must be finite and > 0",
            ));
        }
        if !(self.cluster_tol.is_finite() && self.cluster_tol > 0.0) {
            return Err(SimError::out_of_range(
                "cluster_tol",
                self.cluster_tol,
                "must be finite and > 0",
            ));
        }
        if self.stride > 1000 {
            return Err(SimError::out_of_range(
                "stride",
                self.stride,
                "must be in 0..=1000 (0: automatic)",
            ));
        }
        if self.basin_hits > 10_000 || self.discover_after > 1_000_000 {
            return Err(SimError::out_of_range(
                "basin_hits",
                self.basin_hits,
                "basin_hits must be <= 10000 and discover_after <= 1000000",
            ));
        }
        self.steady.validate()?;
        crate::integrate::check_buildable(&self.params, self.integrator.clone())
    }

    /// The stride of the first pass: `stride`, or when 0 the largest power of two that leaves
    /// the coarse grid at least `MIN_COARSE_NODES` nodes per axis (1 for a map of fewer).
    pub(crate) fn first_stride(&self) -> usize {
        if self.stride > 0 {
            return self.stride;
        }
        let n = self.xs.len().min(self.ys.len());
        let mut s = 1;
        while n / (2 * s) >= MIN_COARSE_NODES {
            s *= 2;
        }
        s
    }

    /// The value of a coordinate of the state `z` (to place a section point on the map).
    pub(crate) fn coordinate(model: &CantileverModel, c: StateCoord, z: &DVector<f64>) -> f64 {
        let n = model.modes();
        match c {
            StateCoord::A(j) => z[j - 1],
            StateCoord::ADot(j) => z[n + j - 1],
            StateCoord::W => model.w_tip(z),
            StateCoord::WDot => model.w_tip_dot(z),
        }
    }
}

/// How a cell was decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Decided {
    /// Near a known periodic attractor.
    Near,
    /// Recurrence in labelled cells.
    Recurrence,
    /// A return inside a coarse cell of the first pass whose four corners share one label.
    Grid,
    /// By the steady-state search (a nonperiodic motion up to its cap is a nonperiodic
    /// attractor).
    Steady,
    /// The run failed or diverged (label −2).
    Failed,
}

impl Decided {
    /// Every decision, in the order of their codes 1, 2, ….
    pub(crate) const ALL: [Decided; 5] = [
        Decided::Near,
        Decided::Recurrence,
        Decided::Grid,
        Decided::Steady,
        Decided::Failed,
    ];

    /// The decision's code in `basins.nc`: its place in `Self::ALL`, from 1.
    pub fn code(self) -> i32 {
        Self::ALL
            .iter()
            .position(|&d| d == self)
            .map_or(0, |i| i as i32 + 1)
    }

    /// `near`, `recurrence`, `grid`, `steady`, `failed`.
    pub fn name(self) -> &'static str {
        match self {
            Decided::Near => "near",
            Decided::Recurrence => "recurrence",
            Decided::Grid => "grid",
            Decided::Steady => "steady",
            Decided::Failed => "failed",
        }
    }
}

/// One cell of a basin map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BasinCell {
    /// Attractor id (index into [`BasinMap::attractors`]); −2 failed (diverged, chattering, a
    /// budget).
    pub label: i64,
    /// How it was decided.
    pub decided: Decided,
    /// Drive periods the start ran.
    pub periods: usize,
}

/// A basin map: cells row by row (y slowest) and the attractors found.
#[derive(Debug, Clone, PartialEq)]
pub struct BasinMap {
    /// nx × ny cells, row-major.
    pub cells: Vec<BasinCell>,
    /// The attractors, in the order first found (row by row); a periodic one's Poincaré
    /// points polished by shooting.
    pub attractors: Vec<SteadyState>,
    /// Each periodic attractor's orbit from Newton shooting (Floquet multipliers, stability);
    /// `None` for a nonperiodic one or where shooting failed.
    pub orbits: Vec<Option<PeriodicOrbit>>,
    /// Each nonperiodic attractor's largest Lyapunov exponent λ₁ (per unit τ, over
    /// `LYAPUNOV_PERIODS` drive periods); `None` for a periodic one or a failed run.
    pub lyapunov: Vec<Option<f64>>,
}

/// Drive periods of the λ₁ estimate of a nonperiodic attractor of a basin map.
pub(crate) const LYAPUNOV_PERIODS: usize = super::attractors::CENSUS_LYAPUNOV_PERIODS;

impl BasinMap {
    /// The labels, row-major.
    pub fn labels(&self) -> Vec<i64> {
        self.cells.iter().map(|c| c.label).collect()
    }

    /// The basin fraction of each attractor: its share of all cells (failed cells included in
    /// the total, so the fractions add up to 1 less the failed share).
    pub(crate) fn basin_fractions(&self) -> Vec<f64> {
        let n = self.cells.len().max(1) as f64;
        (0..self.attractors.len())
            .map(|i| self.cells.iter().filter(|c| c.label == i as i64).count() as f64 / n)
            .collect()
    }
}

/// One finished row of a pass: its cells and the attractors found there beyond those the pass
/// began with (a cell's label indexes the pass's initial ones, then these): what a run shows
/// row by row (`run_passes`) and what a stored run's map is assembled from (`basin_map`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BasinRow {
    /// The pass (0 the coarsest; one pass where the plane is not the whole section).
    pub pass: usize,
    /// The row index iy.
    pub iy: usize,
    /// (ix, cell) of the cells run in this pass.
    pub cells: Vec<(usize, BasinCell)>,
    /// The attractors found beyond the pass's initial ones.
    pub attractors: Vec<SteadyState>,
}

/// A state-space cell of the recurrence test: the box indices ⌊z_i / side_i⌋ hashed into 128
/// bits (two splitmix64 streams; a collision among the ~10⁷ cells of a large map has
/// probability ~10⁻²⁴), so that a return costs no allocation.
type CellKey = u128;

/// The attractors of a run in the order first found and its cells (row-major, `None` where
/// no pass ran the cell: a run cut short).
type Merged = (Vec<SteadyState>, Vec<Option<BasinCell>>);

/// Where a pass of a basin map starts: the attractors the passes before it found (in the
/// order first found: a cell's label indexes them) and the coarse grid of the last of them,
/// and the rows it runs — what each row of the pass needs, and all of it (a row is a pure
/// function of it: any executor gives the same map).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct PassStart {
    /// The pass (0 the coarsest).
    pub pass: usize,
    /// The attractors found by the passes before.
    initial: Vec<SteadyState>,
    /// The coarse grid of the pass before (`None` for the first).
    grid: Option<CoarseGrid>,
    /// The rows to run: (iy, the columns not yet run), rows stored already left out.
    pub rows: Vec<(usize, Vec<usize>)>,
}

/// The number of passes of `spec` (one where the plane is not the whole section).
pub(crate) fn passes(spec: &BasinSpec) -> usize {
    strides(spec).len()
}

/// The start of pass `pass` of `spec` from the finished rows `rows` (in any order; those of
/// later passes are ignored, those of this pass are not run again): the passes before merged
/// in their order — the merge of [`basin_map`] —, the last one's coarse grid, and the rows
/// left to run.
pub(crate) fn pass_start(spec: &BasinSpec, rows: &[BasinRow], pass: usize) -> PassStart {
    let (nx, ny) = (spec.xs.len(), spec.ys.len());
    let strides = strides(spec);
    let (attractors, slots) = merge_passes(spec, rows.iter().filter(|r| r.pass < pass).cloned());
    let grid = pass
        .checked_sub(1)
        .map(|before| coarse_grid(nx, ny, strides[before], &slots));
    let stride = strides.get(pass).copied().unwrap_or(1);
    let (cx, cy) = (coarse_indices(nx, stride), coarse_indices(ny, stride));
    let todo = cy
        .iter()
        .filter(|&&iy| !rows.iter().any(|r| r.pass == pass && r.iy == iy))
        .map(|&iy| {
            let columns = cx
                .iter()
                .copied()
                .filter(|&ix| slots[iy * nx + ix].is_none())
                .collect();
            (iy, columns)
        })
        .filter(|(_, columns): &(usize, Vec<usize>)| !columns.is_empty())
        .collect();
    PassStart {
        pass,
        initial: attractors,
        grid,
        rows: todo,
    }
}

/// Run row `iy` of the pass that `start` begins, its cells `columns`.
///
/// # Errors
/// [`SimError::Cancelled`] once `cancel` is set.
pub(crate) fn run_pass_row(
    spec: &BasinSpec,
    model: &CantileverModel,
    start: &PassStart,
    iy: usize,
    columns: &[usize],
    cancel: &AtomicBool,
) -> Result<BasinRow, SimError> {
    let (cells, found) = run_row(
        spec,
        model,
        iy,
        columns,
        &start.initial,
        start.grid.as_ref(),
        cancel,
    )?;
    Ok(BasinRow {
        pass: start.pass,
        iy,
        cells,
        attractors: found,
    })
}

/// Run every pass of `spec` (rows in parallel on the current rayon pool), showing each finished
/// row to `sink` from the worker threads; each pass begins with the attractors and the coarse
/// grid of the ones before it (`pass_start`). The rows in `stored` (a resumed run's, as
/// `sink` saw them) are not run again but merged in their place, so a resumed run makes the
/// map an uninterrupted one makes. Stops starting rows once `cancel` is set. Returns every
/// row, `stored` first, from which [`basin_map`] makes the map.
///
/// # Errors
/// [`SimError::Cancelled`] once `cancel` is set.
pub(crate) fn run_passes(
    spec: &BasinSpec,
    model: &CantileverModel,
    stored: &[BasinRow],
    sink: &(dyn Fn(&BasinRow) + Sync),
    cancel: &AtomicBool,
) -> Result<Vec<BasinRow>, SimError> {
    let mut rows = stored.to_vec();
    // each row watches the caller's cancel flag too (`crate::analysis::progress`)
    let watched = crate::error::watched();
    for pass in 0..passes(spec) {
        let start = pass_start(spec, &rows, pass);
        let done: Vec<BasinRow> = (&start.rows)
            .into_par_iter()
            .with_max_len(1)
            .map(|(iy, columns)| {
                let row = crate::error::watching(watched.clone(), || {
                    run_pass_row(spec, model, &start, *iy, columns, cancel)
                })?;
                sink(&row);
                Ok(row)
            })
            .collect::<Result<_, SimError>>()?;
        rows.extend(done);
    }
    Ok(rows)
}

/// The basin map of `spec`: rows in parallel (rayon, the current pool), their attractors
/// matched in row order.
///
/// # Errors
/// [`SimError`] for invalid parameters or coordinates outside N modes.
pub fn basins(spec: &BasinSpec) -> Result<BasinMap, SimError> {
    spec.validate()?;
    let model = CantileverModel::new(&spec.params)?;
    let never = AtomicBool::new(false);
    let rows = run_passes(spec, &model, &[], &|_| (), &never)?;
    basin_map(spec, rows)
}

/// The basin map of `spec` from the stored rows of every pass (in any order, as a run's
/// [`run_passes`] showed them): the rows matched pass by pass in row order — the run's own
/// merge — then polished and relabelled as [`basins`] does.
///
/// # Errors
/// [`SimError`] for invalid parameters; [`SimError::Cancelled`] when a cell is missing (a run
/// that was cut short).
pub(crate) fn basin_map(spec: &BasinSpec, rows: Vec<BasinRow>) -> Result<BasinMap, SimError> {
    let model = CantileverModel::new(&spec.params)?;
    basin_map_of(spec, &model, merge_passes(spec, rows.into_iter()))
}

/// The rows of the passes (in any order) merged pass by pass in row order ([`merge_pass`]):
/// the attractors in the order first found and the cells.
fn merge_passes(spec: &BasinSpec, rows: impl Iterator<Item = BasinRow>) -> Merged {
    let (nx, ny) = (spec.xs.len(), spec.ys.len());
    let mut rows: Vec<BasinRow> = rows.collect();
    rows.sort_by_key(|r| (r.pass, r.iy));
    let mut attractors: Vec<SteadyState> = Vec::new();
    let mut slots: Vec<Option<BasinCell>> = vec![None; nx * ny];
    let mut rows = rows.into_iter().peekable();
    for pass in 0..passes(spec) {
        let mut of_pass = Vec::new();
        while let Some(r) = rows.next_if(|r| r.pass == pass) {
            of_pass.push(r);
        }
        merge_pass(spec, of_pass.into_iter(), &mut attractors, &mut slots);
    }
    (attractors, slots)
}

/// The map of merged passes: the attractors polished (shooting for the periodic ones, λ₁ for
/// the others, in parallel on the current rayon pool) and merged where their polished orbits
/// coincide, the cells relabelled.
///
/// # Errors
/// [`SimError::Cancelled`] when a cell is missing (a run that was cut short).
fn basin_map_of(
    spec: &BasinSpec,
    model: &CantileverModel,
    (attractors, slots): Merged,
) -> Result<BasinMap, SimError> {
    if slots.iter().any(Option::is_none) {
        return Err(SimError::Cancelled);
    }
    let cells: Vec<BasinCell> = slots.into_iter().flatten().collect();
    // polish: shooting for the periodic attractors, λ₁ for the others
    let watched = crate::error::watched();
    let polished: Vec<(SteadyState, Option<PeriodicOrbit>, Option<f64>)> = attractors
        .into_par_iter()
        .with_max_len(1)
        .map(|mut s| {
            // under this run's cancel flag (not a flag of the thread that runs it)
            crate::error::watching(watched.clone(), || {
                let orbit = polish_steady(model, spec.integrator.clone(), &mut s);
                let lyapunov = s
                    .period()
                    .is_none()
                    .then(|| {
                        largest_exponent(
                            model,
                            s.end_state(),
                            LYAPUNOV_PERIODS,
                            spec.integrator.clone(),
                        )
                    })
                    .flatten()
                    .map(|l| l.0);
                (s, orbit, lyapunov)
            })
        })
        .collect();
    let mut map = BasinMap {
        cells,
        attractors: Vec::new(),
        orbits: Vec::new(),
        lyapunov: Vec::new(),
    };
    // one orbit, one attractor: an attractor whose polished orbit is an earlier one's takes its
    // id (found from returns that repeat to tol, its points lie up to tol/(1 − |μ₁|) off the
    // orbit, more than cluster_tol on a lightly damped lever), as the census merges its clusters
    let mut ids = Vec::with_capacity(polished.len());
    for (s, o, l) in polished {
        let same =
            map.attractors.iter().zip(&map.orbits).position(|(a, ao)| {
                same_orbit((a, ao.is_some()), (&s, o.is_some()), spec.cluster_tol)
            });
        match same {
            Some(i) => ids.push(i as i64),
            None => {
                ids.push(map.attractors.len() as i64);
                map.attractors.push(s);
                map.orbits.push(o);
                map.lyapunov.push(l);
            }
        }
    }
    for c in &mut map.cells {
        if c.label >= 0 {
            c.label = ids[c.label as usize];
        }
    }
    Ok(map)
}
