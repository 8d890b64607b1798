//! Basins of attraction over a plane of initial conditions (issue 30): every cell of a grid of
//! initial states at τ = 0 gets the id of the attractor its trajectory reaches, without running
//! every start to convergence.
//!
//! A start iterates the stroboscopic map P (one drive period) and stops as soon as
//!
//! 1. **near**: [`NEAR_HITS`] consecutive returns lie within `near_tol` (relative to 1 + |p|)
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
//! A task is one row of the map (cells in order of x): pure in (spec, row), so any thread count
//! gives the same map; the attractors of the rows are matched in row order into global ids.

use super::attractors::{polish_steady, same_attractor};
use super::lyapunov::largest_exponent;
#[cfg(not(feature = "parallel"))]
use super::sequential::*;
use super::shooting::PeriodicOrbit;
use super::steady::{steady_state, SteadyOptions, SteadyState};
use crate::error::SimError;
use crate::integrate::{advance, build, IntegratorOptions};
use crate::model::CantileverModel;
use crate::params::Params;
use nalgebra::DVector;
#[cfg(feature = "parallel")]
use rayon::prelude::*;
use std::collections::HashMap;
use std::fmt;
use std::str::FromStr;

/// Consecutive returns near a known periodic attractor that decide a start.
pub const NEAR_HITS: usize = 3;
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
    pub fn fits(self, modes: usize) -> bool {
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
    /// The steady-state search (its `max_periods` caps the whole start).
    pub steady: SteadyOptions,
    /// Clustering tolerance of two steady states.
    pub cluster_tol: f64,
    /// Integrator.
    pub integrator: IntegratorOptions,
}

/// Largest number of cells of a basin map.
pub const MAX_BASIN_CELLS: usize = 4_000_000;

impl BasinSpec {
    /// Check the options (the one place of their limits).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the option.
    pub fn validate(&self) -> Result<(), SimError> {
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
        if self.basin_hits > 10_000 || self.discover_after > 1_000_000 {
            return Err(SimError::out_of_range(
                "basin_hits",
                self.basin_hits,
                "basin_hits must be <= 10000 and discover_after <= 1000000",
            ));
        }
        self.steady.validate()
    }

    /// The value of a coordinate of the state `z` (to place a section point on the map).
    pub fn coordinate(model: &CantileverModel, c: StateCoord, z: &DVector<f64>) -> f64 {
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
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Decided {
    /// Near a known periodic attractor.
    Near,
    /// Recurrence in labelled cells.
    Recurrence,
    /// By the steady-state search (a nonperiodic motion up to its cap is a nonperiodic
    /// attractor).
    Steady,
    /// The run failed or diverged (label −2).
    Failed,
}

impl Decided {
    /// `near`, `recurrence`, `steady`, `failed`.
    pub fn name(self) -> &'static str {
        match self {
            Decided::Near => "near",
            Decided::Recurrence => "recurrence",
            Decided::Steady => "steady",
            Decided::Failed => "failed",
        }
    }
}

/// One cell of a basin map.
#[derive(Debug, Clone, PartialEq)]
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
    /// [`LYAPUNOV_PERIODS`] drive periods); `None` for a periodic one or a failed run.
    pub lyapunov: Vec<Option<f64>>,
}

/// Drive periods of the λ₁ estimate of a nonperiodic attractor of a basin map.
pub const LYAPUNOV_PERIODS: usize = 500;

impl BasinMap {
    /// The labels, row-major.
    pub fn labels(&self) -> Vec<i64> {
        self.cells.iter().map(|c| c.label).collect()
    }

    /// The basin fraction of each attractor: its share of all cells (failed cells included in
    /// the total, so the fractions add up to 1 less the failed share).
    pub fn basin_fractions(&self) -> Vec<f64> {
        let n = self.cells.len().max(1) as f64;
        (0..self.attractors.len())
            .map(|i| self.cells.iter().filter(|c| c.label == i as i64).count() as f64 / n)
            .collect()
    }
}

struct Row {
    cells: Vec<BasinCell>,
    attractors: Vec<SteadyState>,
}

type CellKey = Vec<i64>;

fn cell_key(z: &DVector<f64>, n: usize, h: f64, omega: f64) -> CellKey {
    z.iter()
        .enumerate()
        .map(|(i, v)| {
            let side = if i < n { h } else { h * omega };
            (v / side).floor() as i64
        })
        .collect()
}

fn near(spec: &BasinSpec, known: &[SteadyState], z: &DVector<f64>) -> Option<usize> {
    known.iter().position(|a| {
        a.period().is_some()
            && a.poincare
                .iter()
                .any(|p| (z - &p.state).norm() <= spec.near_tol * (1.0 + p.state.norm()))
    })
}

/// Run row `iy` of the map.
fn run_row(spec: &BasinSpec, model: &CantileverModel, iy: usize) -> Row {
    let n = model.modes();
    let (h, omega, period) = (spec.cell, spec.params.omega, model.period());
    let mut known: Vec<SteadyState> = Vec::new();
    let mut labelled: HashMap<CellKey, usize> = HashMap::new();
    let mut cells = Vec::with_capacity(spec.xs.len());
    for &xv in &spec.xs {
        let mut z0 = spec.base.clone();
        spec.x.set(model, &mut z0, xv);
        spec.y.set(model, &mut z0, spec.ys[iy]);
        let mut visited: Vec<CellKey> = Vec::new();
        let outcome = (|| -> Result<(usize, Decided, usize), SimError> {
            let mut integ = build(model, spec.integrator, 0.0, &z0)?;
            let (mut near_run, mut cell_run) = ((usize::MAX, 0), (usize::MAX, 0));
            for k in 1..=spec.discover_after.min(spec.steady.max_periods) {
                advance(integ.as_mut(), k as f64 * period)?;
                let z = integ.state();
                match near(spec, &known, z) {
                    Some(a) if a == near_run.0 => near_run.1 += 1,
                    Some(a) => near_run = (a, 1),
                    None => near_run = (usize::MAX, 0),
                }
                if near_run.1 >= NEAR_HITS {
                    return Ok((near_run.0, Decided::Near, k));
                }
                let key = cell_key(z, n, h, omega);
                match labelled.get(&key) {
                    Some(&a) if a == cell_run.0 => cell_run.1 += 1,
                    Some(&a) => cell_run = (a, 1),
                    None => cell_run = (usize::MAX, 0),
                }
                visited.push(key);
                if spec.basin_hits > 0 && cell_run.1 >= spec.basin_hits {
                    return Ok((cell_run.0, Decided::Recurrence, k));
                }
            }
            let done = visited.len();
            let opts = SteadyOptions {
                max_periods: spec.steady.max_periods.saturating_sub(done).max(1),
                ..spec.steady
            };
            // a motion without a period up to the cap is a nonperiodic attractor (chaotic or
            // quasi-periodic; matched by its X_max and V_T range, as the census does)
            let s = steady_state(integ.as_mut(), &opts)?;
            let ran = done + s.transient_periods;
            let id = match known
                .iter()
                .position(|a| same_attractor(a, &s, spec.cluster_tol))
            {
                Some(i) => i,
                None => {
                    // the attractor's own section points label their cells
                    for p in &s.poincare {
                        visited.push(cell_key(&p.state, n, h, omega));
                    }
                    known.push(s);
                    known.len() - 1
                }
            };
            Ok((id, Decided::Steady, ran))
        })();
        let cell = match outcome {
            Ok((id, decided, periods)) => {
                for key in visited {
                    labelled.entry(key).or_insert(id);
                }
                BasinCell {
                    label: id as i64,
                    decided,
                    periods,
                }
            }
            Err(_) => BasinCell {
                label: -2,
                decided: Decided::Failed,
                periods: 0,
            },
        };
        cells.push(cell);
    }
    Row {
        cells,
        attractors: known,
    }
}

/// The basin map of `spec`: rows in parallel (rayon), their attractors matched in row order.
///
/// # Errors
/// [`SimError`] for invalid parameters or coordinates outside N modes.
pub fn basins(spec: &BasinSpec) -> Result<BasinMap, SimError> {
    let model = CantileverModel::new(&spec.params)?;
    let n = model.modes();
    for (name, c) in [("x", spec.x), ("y", spec.y)] {
        if !c.fits(n) {
            return Err(SimError::out_of_range(
                name,
                c,
                "must be a coordinate of the N modes (a1…aN, adot1…adotN, w, wdot)",
            ));
        }
    }
    if spec.base.len() != 2 * n {
        return Err(SimError::StateLength {
            name: "base",
            expected: 2 * n,
            got: spec.base.len(),
        });
    }
    spec.validate()?;
    let rows: Vec<Row> = (0..spec.ys.len())
        .into_par_iter()
        .with_max_len(1)
        .map(|iy| run_row(spec, &model, iy))
        .collect();
    let mut attractors: Vec<SteadyState> = Vec::new();
    let mut cells = Vec::with_capacity(spec.xs.len() * spec.ys.len());
    for row in rows {
        let ids: Vec<i64> = row
            .attractors
            .into_iter()
            .map(|a| {
                match attractors
                    .iter()
                    .position(|b| same_attractor(b, &a, spec.cluster_tol))
                {
                    Some(i) => i as i64,
                    None => {
                        attractors.push(a);
                        attractors.len() as i64 - 1
                    }
                }
            })
            .collect();
        cells.extend(row.cells.into_iter().map(|mut c| {
            if c.label >= 0 {
                c.label = ids[c.label as usize];
            }
            c
        }));
    }
    // polish: shooting for the periodic attractors, λ₁ for the others
    let polished: Vec<(SteadyState, Option<PeriodicOrbit>, Option<f64>)> = attractors
        .into_par_iter()
        .with_max_len(1)
        .map(|mut s| {
            let orbit = polish_steady(&model, spec.integrator, &mut s);
            let lyapunov = s
                .period()
                .is_none()
                .then(|| largest_exponent(&model, s.end_state(), LYAPUNOV_PERIODS, spec.integrator))
                .flatten()
                .map(|l| l.0);
            (s, orbit, lyapunov)
        })
        .collect();
    let mut map = BasinMap {
        cells,
        attractors: Vec::new(),
        orbits: Vec::new(),
        lyapunov: Vec::new(),
    };
    for (s, o, l) in polished {
        map.attractors.push(s);
        map.orbits.push(o);
        map.lyapunov.push(l);
    }
    Ok(map)
}
