//! Parameter sweeps of the steady state: bifurcation diagrams by continuation (forward and
//! backward, revealing hysteresis) and seeded multistart, in parallel (rayon), streaming each
//! finished point to a sink so that no sweep is held in memory.

#[cfg(not(feature = "parallel"))]
use super::sequential::*;
use super::steady::{steady_state_of, SteadyOptions, SteadyState};
use crate::error::{in_range, SimError};
use crate::integrate::IntegratorOptions;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use nalgebra::DVector;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
#[cfg(feature = "parallel")]
use rayon::{join, prelude::*};
use std::collections::{HashMap, HashSet};
use std::fmt;
use std::str::FromStr;
use std::sync::atomic::{AtomicBool, Ordering};

/// Scale A of random initial states: a_j ~ U(−A, A)·β₁²/β_j², ȧ_j ~ U(−A, A)·β₁² (every mode
/// gets a comparable share of energy; A = 0.6 gap units covers the paper's amplitudes 0.1–1.5).
pub(crate) const RANDOM_AMPLITUDE: f64 = 0.6;

/// Largest number of sweep points, values × (2 for continuation + random starts): each point is
/// a steady-state computation, and the bookkeeping of a run (resume set, output index) grows
/// with it. Checked before anything is allocated.
pub const MAX_SWEEP_POINTS: usize = 1_000_000;

/// A reproducible random initial state for sample `index` of the stream `seed`.
pub(crate) fn random_state(model: &CantileverModel, seed: u64, index: u64) -> DVector<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let n = model.modes();
    let shapes = model.galerkin().shapes();
    let b1 = shapes.modes()[0].beta.powi(2);
    // the law's internal states at rest
    let mut z = model.rest();
    for (j, m) in shapes.modes().iter().enumerate() {
        let scale = b1 / m.beta.powi(2);
        z[j] = rng.random_range(-RANDOM_AMPLITUDE..RANDOM_AMPLITUDE) * scale;
        z[n + j] = rng.random_range(-RANDOM_AMPLITUDE..RANDOM_AMPLITUDE) * b1;
    }
    z
}

/// A reproducible random initial state of random start `start` at the swept value `value`:
/// the stream is keyed by the sweep's seed, the value's bits and the start number, so the same
/// parameter point gets the same starts in any sweep that contains it, whatever its range,
/// order of execution or thread count.
pub(crate) fn start_state(
    model: &CantileverModel,
    seed: u64,
    value: f64,
    start: u32,
) -> DVector<f64> {
    random_state(model, seed, mix64(value.to_bits()) ^ u64::from(start))
}

/// The splitmix64 finaliser (Steele, Lea & Flood, OOPSLA 2014): a bijection of u64 whose
/// outputs differ in about half their bits for inputs one bit apart.
pub(crate) fn mix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
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
        in_range("steps", steps, 1..=MAX_SWEEP_POINTS)?;
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
            Some(n) if n <= MAX_SWEEP_POINTS => crate::integrate::check_buildable_over(
                &self.base,
                self.param,
                &self.values,
                self.integrator.clone(),
            ),
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
    /// The end state of every written continuation point that did not fail, by (index,
    /// branch): where its chain segment goes on.
    pub chain: HashMap<(usize, Branch), DVector<f64>>,
}

fn solve_point(spec: &SweepSpec, value: f64, z0: &DVector<f64>) -> Result<SteadyState, SimError> {
    let p = spec.base.with(spec.param, value);
    steady_state_of(
        &CantileverModel::new(&p)?,
        spec.integrator.clone(),
        z0,
        &spec.steady,
    )
}

/// One task of a planned sweep ([`SweepPlan`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum SweepTask {
    /// Stage 0: the coarse continuation of a branch over the first value of each of its
    /// chunks, whose end states seed the chunks.
    Coarse(Branch),
    /// Stage 1: the continuation of a branch over chunk k of its values, from the coarse
    /// pass's state at the chunk's first value (chunk 0: from rest).
    Segment(Branch, usize),
    /// Stage 1: random start s at value index i.
    Start(usize, u32),
}

/// The seeds of the chain segments: for each branch, the initial state of each chunk (the
/// coarse pass's end state at the chunk's first value; rest for chunk 0 and where the coarse
/// point failed and no earlier one succeeded).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Seeds {
    forward: Vec<DVector<f64>>,
    backward: Vec<DVector<f64>>,
}

impl Seeds {
    /// The seeds from the coarse passes' results ([`SweepPlan::coarse`] of the forward and
    /// the backward branch), as an executor that runs the passes as tasks of its own
    /// assembles them.
    #[cfg(feature = "files")]
    pub(crate) fn new(forward: Vec<DVector<f64>>, backward: Vec<DVector<f64>>) -> Seeds {
        Seeds { forward, backward }
    }

    fn of(&self, branch: Branch) -> &[DVector<f64>] {
        match branch {
            Branch::Backward => &self.backward,
            _ => &self.forward,
        }
    }
}

/// A sweep planned as independent tasks (issue 29): the forward and backward continuation
/// chains are cut into chunks of consecutive values, each chunk a task seeded by a coarse
/// continuation over the chunks' first values (stage 0, two short sequential tasks); every
/// random start is a task. Each task is a pure function of the spec, the task and the seeds,
/// so every executor and any thread count gives the same points bit for bit.
///
/// A chunk's first point starts from the coarse pass's steady state at that value, not from
/// the fine chain's state at the value before: the two agree wherever the branch the chain
/// follows still exists one chunk length further on (the coarse step is `chunk` values), and
/// may differ within a chunk length of a fold, where a fine chain would hold on to the
/// vanishing branch a little longer.
///
/// Chunks per branch: ⌈√n⌉ for n values (20 of 20 values at the default 400: 40 chain tasks
/// plus the random starts), so the sequential coarse pass is √n points against the 2n of the
/// chains: an Amdahl bound of 2n/(√n + 2n/T) on T threads (≈ 28× on 64 threads at n = 400).
#[derive(Debug, Clone, Copy)]
pub(crate) struct SweepPlan<'a> {
    spec: &'a SweepSpec,
    chunk: usize,
    chunks: usize,
}

impl<'a> SweepPlan<'a> {
    /// The plan of `spec`.
    pub(crate) fn new(spec: &'a SweepSpec) -> SweepPlan<'a> {
        let n = spec.values.len().max(1);
        let chunks = ((n as f64).sqrt().ceil() as usize).clamp(1, n);
        let chunk = n.div_ceil(chunks);
        SweepPlan {
            spec,
            chunk,
            chunks: n.div_ceil(chunk),
        }
    }

    /// Chunks per continuation branch (0 without continuation).
    pub(crate) fn chunks(&self) -> usize {
        if self.spec.continuation && !self.spec.values.is_empty() {
            self.chunks
        } else {
            0
        }
    }

    /// The tasks of `stage` (0: the coarse passes; 1: the chain segments, then the random
    /// starts value by value); no tasks beyond stage 1.
    pub(crate) fn tasks(&self, stage: usize) -> Vec<SweepTask> {
        let branches = [Branch::Forward, Branch::Backward];
        match stage {
            0 if self.chunks() > 1 => branches.map(SweepTask::Coarse).to_vec(),
            1 => {
                let segments = branches
                    .iter()
                    .flat_map(|&b| (0..self.chunks()).map(move |k| SweepTask::Segment(b, k)));
                let starts = (0..self.spec.values.len())
                    .flat_map(|i| (0..self.spec.starts).map(move |s| SweepTask::Start(i, s)));
                segments.chain(starts).collect()
            }
            _ => Vec::new(),
        }
    }

    /// The value indices of `branch` in its order of continuation (increasing forward,
    /// decreasing backward), chunk `k` of them.
    pub(crate) fn chunk_indices(&self, branch: Branch, k: usize) -> Vec<usize> {
        let n = self.spec.values.len();
        let lo = (k * self.chunk).min(n);
        let hi = ((k + 1) * self.chunk).min(n);
        match branch {
            Branch::Backward => (lo..hi).map(|j| n - 1 - j).collect(),
            _ => (lo..hi).collect(),
        }
    }

    /// The coarse pass of `branch` (stage 0): continuation over the first value of each chunk
    /// from rest; returns the seed of every chunk. Stops early (with rest for the chunks not
    /// reached) once `cancel` is set.
    pub(crate) fn coarse(&self, branch: Branch, cancel: &AtomicBool) -> Vec<DVector<f64>> {
        let dim = self.spec.base.state_dim();
        let mut z = DVector::zeros(dim);
        let mut seeds = vec![DVector::zeros(dim); self.chunks()];
        for (k, seed) in seeds.iter_mut().enumerate() {
            if cancel.load(Ordering::Relaxed) {
                break;
            }
            let Some(&i) = self.chunk_indices(branch, k).first() else {
                break;
            };
            if k > 0 {
                if let Ok(s) = solve_point(self.spec, self.spec.values[i], &z) {
                    z = s.end_state().clone();
                }
            }
            *seed = z.clone();
        }
        seeds
    }

    /// The seeds of every chunk (both coarse passes, in parallel), computed only where a
    /// chunk after the first still needs its seed (a resumed sweep whose chunks have all
    /// started needs none).
    pub(crate) fn seeds(&self, resume: &Resume, cancel: &AtomicBool) -> Seeds {
        let needs = |b: Branch| {
            (1..self.chunks()).any(|k| {
                self.chunk_indices(b, k)
                    .iter()
                    .all(|&i| !resume.chain.contains_key(&(i, b)))
                    && self
                        .chunk_indices(b, k)
                        .iter()
                        .any(|&i| !resume.done.contains(&(i, b)))
            })
        };
        let dim = self.spec.base.state_dim();
        let pass = |b: Branch| {
            if needs(b) {
                self.coarse(b, cancel)
            } else {
                vec![DVector::zeros(dim); self.chunks()]
            }
        };
        let (forward, backward) = join(|| pass(Branch::Forward), || pass(Branch::Backward));
        Seeds { forward, backward }
    }

    /// Run one stage-1 task: each of its points not in `resume` goes to `sink` as soon as it
    /// is finished. A chain segment goes on from the stored state of its done points. A
    /// coarse task does nothing here (see `SweepPlan::coarse`).
    pub(crate) fn run_task(
        &self,
        task: SweepTask,
        seeds: &Seeds,
        resume: &Resume,
        sink: &(dyn Fn(SweepPoint) + Sync),
        cancel: &AtomicBool,
    ) {
        let spec = self.spec;
        match task {
            SweepTask::Coarse(_) => {}
            SweepTask::Segment(branch, k) => {
                let mut z = seeds
                    .of(branch)
                    .get(k)
                    .cloned()
                    .unwrap_or_else(|| DVector::zeros(spec.base.state_dim()));
                for i in self.chunk_indices(branch, k) {
                    if cancel.load(Ordering::Relaxed) {
                        return;
                    }
                    if resume.done.contains(&(i, branch)) {
                        if let Some(saved) = resume.chain.get(&(i, branch)) {
                            z = saved.clone();
                        }
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
            SweepTask::Start(i, s) => {
                if cancel.load(Ordering::Relaxed) || resume.done.contains(&(i, Branch::Start(s))) {
                    return;
                }
                let value = spec.values[i];
                let p = spec.base.with(spec.param, value);
                let result = CantileverModel::new(&p)
                    .map_err(SimError::from)
                    .and_then(|m| {
                        let z0 = start_state(&m, spec.seed, value, s);
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
        }
    }
}

/// Run the sweep; `sink` receives each point as soon as it is finished (from worker threads).
/// Points listed in `resume.done` are skipped; continuation chains restart from their saved
/// state.
pub fn run_sweep(spec: &SweepSpec, resume: &Resume, sink: &(dyn Fn(SweepPoint) + Sync)) {
    run_sweep_cancellable(spec, resume, sink, &AtomicBool::new(false));
}

/// [`run_sweep`] that stops early once `cancel` is set: no new point is started (points
/// already running finish and reach `sink`), so a front end can interrupt a long sweep.
///
/// The local executor of a [`SweepPlan`]: the coarse passes, then every stage-1 task on the
/// current rayon pool (one task per work item, no shared lock: points go straight to `sink`).
pub(crate) fn run_sweep_cancellable(
    spec: &SweepSpec,
    resume: &Resume,
    sink: &(dyn Fn(SweepPoint) + Sync),
    cancel: &AtomicBool,
) {
    let plan = SweepPlan::new(spec);
    let seeds = plan.seeds(resume, cancel);
    // each task watches the caller's cancel flag too (`crate::analysis::progress`)
    let watched = crate::error::watched();
    plan.tasks(1)
        .into_par_iter()
        .with_max_len(1)
        .for_each(|task| {
            crate::error::watching(watched.clone(), || {
                plan.run_task(task, &seeds, resume, sink, cancel)
            })
        });
}
