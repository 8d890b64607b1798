//! Parameter sweeps of the steady state: bifurcation diagrams by continuation (forward and
//! backward, revealing hysteresis) and seeded multistart, in parallel (rayon), streaming each
//! finished point to a sink so that no sweep is held in memory.

#[cfg(not(feature = "parallel"))]
use super::sequential::*;
use super::steady::{steady_state, SteadyOptions, SteadyState};
use crate::error::SimError;
use crate::integrate::{build, IntegratorOptions};
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use nalgebra::DVector;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
#[cfg(feature = "parallel")]
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};
use std::fmt;
use std::str::FromStr;
use std::sync::atomic::{AtomicBool, Ordering};

/// Scale A of random initial states: a_j ~ U(−A, A)·β₁²/β_j², ȧ_j ~ U(−A, A)·β₁² (every mode
/// gets a comparable share of energy; A = 0.6 gap units covers the paper's amplitudes 0.1–1.5).
pub const RANDOM_AMPLITUDE: f64 = 0.6;

/// Largest number of sweep points, values × (2 for continuation + random starts): each point is
/// a steady-state computation, and the bookkeeping of a run (resume set, output index) grows
/// with it. Checked before anything is allocated.
pub const MAX_SWEEP_POINTS: usize = 1_000_000;

/// A reproducible random initial state for sample `index` of the stream `seed`.
pub fn random_state(model: &CantileverModel, seed: u64, index: u64) -> DVector<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let n = model.modes();
    let shapes = model.galerkin().shapes();
    let b1 = shapes.modes()[0].beta.powi(2);
    let mut z = DVector::zeros(2 * n);
    for (j, m) in shapes.modes().iter().enumerate() {
        let scale = b1 / m.beta.powi(2);
        z[j] = rng.random_range(-RANDOM_AMPLITUDE..RANDOM_AMPLITUDE) * scale;
        z[n + j] = rng.random_range(-RANDOM_AMPLITUDE..RANDOM_AMPLITUDE) * b1;
    }
    z
}

/// How a sweep point was reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Branch {
    /// Continuation with increasing parameter.
    Forward,
    /// Continuation with decreasing parameter.
    Backward,
    /// Random start number k.
    Start(u32),
}

impl fmt::Display for Branch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Branch::Forward => f.write_str("forward"),
            Branch::Backward => f.write_str("backward"),
            Branch::Start(k) => write!(f, "start-{k}"),
        }
    }
}

impl FromStr for Branch {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "forward" => Ok(Branch::Forward),
            "backward" => Ok(Branch::Backward),
            _ => s
                .strip_prefix("start-")
                .and_then(|k| k.parse().ok())
                .map(Branch::Start)
                .ok_or_else(|| format!("unknown branch '{s}'")),
        }
    }
}

/// A sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSpec {
    /// Parameters held fixed (the swept one is overwritten).
    pub base: Params,
    /// The swept parameter.
    pub param: SweepParam,
    /// Its values, in increasing order of index.
    pub values: Vec<f64>,
    /// Forward and backward continuation.
    pub continuation: bool,
    /// Random starts per value.
    pub starts: u32,
    /// Seed of the random starts.
    pub seed: u64,
    /// Steady-state options.
    pub steady: SteadyOptions,
    /// Integrator.
    pub integrator: IntegratorOptions,
}

impl SweepSpec {
    /// `steps` evenly spaced values from `from` to `to` inclusive.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] for non-finite bounds or `steps == 0`.
    pub fn linspace(from: f64, to: f64, steps: usize) -> Result<Vec<f64>, SimError> {
        crate::error::finite("from", from)?;
        crate::error::finite("to", to)?;
        if steps == 0 || steps > MAX_SWEEP_POINTS {
            return Err(SimError::out_of_range(
                "steps",
                steps,
                "must be in 1..=1000000",
            ));
        }
        if steps == 1 {
            return Ok(vec![from]);
        }
        Ok((0..steps)
            .map(|i| from + (to - from) * i as f64 / (steps - 1) as f64)
            .collect())
    }

    /// Check every value gives valid parameters.
    ///
    /// # Errors
    /// The [`SimError::Params`] of the first invalid value.
    pub fn validate(&self) -> Result<(), SimError> {
        for &v in &self.values {
            self.base.with(self.param, v).validate()?;
        }
        if !self.continuation && self.starts == 0 {
            return Err(SimError::out_of_range(
                "starts",
                0,
                "must be >= 1 when continuation is off",
            ));
        }
        let per_value = usize::from(self.continuation) * 2 + self.starts as usize;
        match self.values.len().checked_mul(per_value) {
            Some(n) if n <= MAX_SWEEP_POINTS => Ok(()),
            _ => Err(SimError::out_of_range(
                "sweep points",
                format!(
                    "{} values × {per_value} ({} starts{})",
                    self.values.len(),
                    self.starts,
                    if self.continuation {
                        " + forward + backward"
                    } else {
                        ""
                    }
                ),
                "must be <= 1000000 in all (fewer steps or starts)",
            )),
        }
    }
}

/// One finished sweep point.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepPoint {
    /// Index into [`SweepSpec::values`].
    pub index: usize,
    /// Parameter value.
    pub value: f64,
    /// How it was reached.
    pub branch: Branch,
    /// Steady state, or the error message (a failed point never aborts the sweep).
    pub result: Result<SteadyState, String>,
}

/// What an interrupted sweep already finished.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Resume {
    /// (index, branch) pairs already written.
    pub done: HashSet<(usize, Branch)>,
    /// For each continuation branch, the last finished index and its end state.
    pub chain: HashMap<Branch, (usize, DVector<f64>)>,
}

fn solve_point(spec: &SweepSpec, value: f64, z0: &DVector<f64>) -> Result<SteadyState, SimError> {
    let p = spec.base.with(spec.param, value);
    let model = CantileverModel::new(&p)?;
    let mut integ = build(&model, spec.integrator, 0.0, z0)?;
    steady_state(integ.as_mut(), &spec.steady)
}

enum Task {
    Chain(Branch),
    Start(usize, u32),
}

/// Run the sweep; `sink` receives each point as soon as it is finished (from worker threads).
/// Points listed in `resume.done` are skipped; continuation chains restart from their saved
/// state.
pub fn run_sweep(spec: &SweepSpec, resume: &Resume, sink: &(dyn Fn(SweepPoint) + Sync)) {
    run_sweep_cancellable(spec, resume, sink, &AtomicBool::new(false));
}

/// [`run_sweep`] that stops early once `cancel` is set: no new point is started (points
/// already running finish and reach `sink`), so a front end can interrupt a long sweep.
pub fn run_sweep_cancellable(
    spec: &SweepSpec,
    resume: &Resume,
    sink: &(dyn Fn(SweepPoint) + Sync),
    cancel: &AtomicBool,
) {
    // tasks by index (chains first, then the starts value by value), never all in memory
    let chains = if spec.continuation { 2 } else { 0 };
    let starts = spec.starts as usize;
    let total = chains + spec.values.len() * starts;
    let task = |k: usize| {
        if k < chains {
            Task::Chain(if k == 0 {
                Branch::Forward
            } else {
                Branch::Backward
            })
        } else {
            let j = k - chains;
            Task::Start(j / starts, (j % starts) as u32)
        }
    };
    let dim = 2 * spec.base.modes;
    (0..total)
        .into_par_iter()
        .with_max_len(1)
        .map(task)
        .filter(
            |t| !matches!(*t, Task::Start(i, s) if resume.done.contains(&(i, Branch::Start(s)))),
        )
        .for_each(|task| match task {
            Task::Chain(branch) => {
                let order: Vec<usize> = match branch {
                    Branch::Backward => (0..spec.values.len()).rev().collect(),
                    _ => (0..spec.values.len()).collect(),
                };
                let mut z = DVector::zeros(dim);
                if let Some((_, saved)) = resume.chain.get(&branch) {
                    z = saved.clone();
                }
                for i in order {
                    if cancel.load(Ordering::Relaxed) {
                        return;
                    }
                    if resume.done.contains(&(i, branch)) {
                        continue;
                    }
                    let value = spec.values[i];
                    let result = solve_point(spec, value, &z).map_err(|e| e.to_string());
                    if let Ok(s) = &result {
                        z = s.end_state().clone();
                    }
                    sink(SweepPoint {
                        index: i,
                        value,
                        branch,
                        result,
                    });
                }
            }
            Task::Start(i, s) => {
                if cancel.load(Ordering::Relaxed) {
                    return;
                }
                let value = spec.values[i];
                let p = spec.base.with(spec.param, value);
                let result = CantileverModel::new(&p)
                    .map_err(SimError::from)
                    .and_then(|m| {
                        let z0 = random_state(&m, spec.seed, (i as u64) << 20 | s as u64);
                        solve_point(spec, value, &z0)
                    })
                    .map_err(|e| e.to_string());
                sink(SweepPoint {
                    index: i,
                    value,
                    branch: Branch::Start(s),
                    result,
                });
            }
        });
}
