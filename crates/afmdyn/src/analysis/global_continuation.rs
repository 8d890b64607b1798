//! Global continuation of attractors and their basin fractions over a parameter (issue 30), after
//! the "seed, continue, match" scheme of Datseris, Rossi & Wagemakers, "Framework for global
//! stability analysis of dynamical systems", Chaos 33, 073151 (2023) (Attractors.jl's
//! `global_continuation` with `AttractorSeedContinueMatch`):
//!
//! 1. at every value of the parameter, in order, an attractor census ([`super::attractors`])
//!    runs `samples` random starts — keyed by (seed, the value's bits, k) as a sweep's random
//!    starts are (`start_state`), so a value gets the same starts in any range containing it —
//!    *and* one start from the last section point of every attractor of the previous value (a
//!    *seed*; it finds attractors whose basin the random starts miss, and follows each through
//!    the step);
//! 2. the basin fractions count the random starts only (an attractor reached only from a seed
//!    has fraction 0: its basin is below the sample's resolution, 1/samples);
//! 3. the attractors are *matched* to those of the previous value: every pair of the same
//!    period class whose set distance d (below) is ≤ `match_tol` is a candidate, and the pairs
//!    are taken greedily by increasing d, each attractor at most once (the matching of
//!    Attractors.jl's `MatchBySSSetDistance` with a finite threshold). A matched attractor
//!    keeps the previous id; the others get new ids, in the census' order (most frequent
//!    first). An id therefore never comes back once its attractor is lost.
//!
//! d is the symmetric Hausdorff distance between the two sets of Poincaré points, each
//! distance relative, |x − y| / (1 + |y|); a period-n orbit and its period-2n daughter are of
//! one class (a period-doubling continues the id), as are two nonperiodic motions; a periodic
//! and a nonperiodic attractor are matched only when d ≤ `match_tol` too.

use super::attractors::{census, Attractor, AttractorSpec};
use super::bifurcation::start_state;
use super::progress::Progress;
use super::steady::SteadyState;
use crate::error::{in_range, SimError};
use crate::model::CantileverModel;
use crate::params::SweepParam;
use nalgebra::DVector;
use std::sync::atomic::AtomicBool;

/// Largest number of parameter values of a global continuation.
pub const MAX_CONTINUATION_VALUES: usize = 10_000;
/// Largest number of runs (values × samples) of a global continuation.
pub(crate) const MAX_CONTINUATION_RUNS: usize = 2_000_000;
/// Default relative set distance within which two attractors at consecutive values are one.
pub(crate) const DEFAULT_MATCH_TOL: f64 = 0.1;

/// A global continuation.
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalContinuationSpec {
    /// The census at every value (its `params` are the base; `samples` random starts, `seed`).
    pub census: AttractorSpec,
    /// The continued parameter.
    pub param: SweepParam,
    /// Its values, in the order continued.
    pub values: Vec<f64>,
    /// Largest relative set distance of two attractors at consecutive values that are one.
    pub match_tol: f64,
}

impl GlobalContinuationSpec {
    /// Check the options (the census' through [`AttractorSpec::validate`]) and every value's
    /// parameters.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `values` (1..=[`MAX_CONTINUATION_VALUES`], finite),
    /// `samples` (values × samples ≤ `MAX_CONTINUATION_RUNS`) or `match_tol` (finite, ≥ 0);
    /// [`SimError::Params`] for a value outside the parameter's range.
    pub fn validate(&self) -> Result<(), SimError> {
        in_range("steps", self.values.len(), 1..=MAX_CONTINUATION_VALUES)?;
        if self
            .values
            .len()
            .saturating_mul(self.census.samples.saturating_add(1))
            > MAX_CONTINUATION_RUNS
        {
            return Err(SimError::out_of_range(
                "samples",
                self.census.samples,
                "values × (samples + 1) must be <= 2000000",
            ));
        }
        if !(self.match_tol.is_finite() && self.match_tol >= 0.0) {
            return Err(SimError::out_of_range(
                "match_tol",
                self.match_tol,
                "must be finite and >= 0",
            ));
        }
        self.census.validate()?;
        for &v in &self.values {
            self.census.params.with(self.param, v).validate()?;
        }
        crate::integrate::check_buildable_over(
            &self.census.params,
            self.param,
            &self.values,
            self.census.integrator.clone(),
        )
    }
}

/// One value of a global continuation (serialized for its study's store: the next value
/// starts from it).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContinuationStep {
    /// The parameter's value.
    pub value: f64,
    /// The attractors with their ids (most random starts first); `basin_fraction` from the
    /// random starts only.
    pub attractors: Vec<(usize, Attractor)>,
    /// Runs that failed (random starts and seeds), their messages.
    pub failures: Vec<String>,
    /// The census's caveats ([`super::attractors::AttractorReport::warnings`]).
    pub warnings: Vec<String>,
}

/// The symmetric Hausdorff distance between two sets of Poincaré points, each distance
/// relative: max( max_x min_y |x − y|/(1 + |y|), max_y min_x |y − x|/(1 + |x|) ).
pub(crate) fn set_distance(a: &SteadyState, b: &SteadyState) -> f64 {
    let one_way = |p: &SteadyState, q: &SteadyState| {
        p.poincare
            .iter()
            .map(|x| {
                q.poincare
                    .iter()
                    .map(|y| (&x.state - &y.state).norm() / (1.0 + y.state.norm()))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max)
    };
    one_way(a, b).max(one_way(b, a))
}

/// Match the attractors `current` to `previous` (ids): candidate pairs within `tol`, greedily
/// by increasing set distance; unmatched ones get fresh ids from `next_id`. Returns the ids of
/// `current`, in its order.
fn match_ids(
    previous: &[(usize, Attractor)],
    current: &[Attractor],
    tol: f64,
    next_id: &mut usize,
) -> Vec<usize> {
    let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
    for (i, (_, p)) in previous.iter().enumerate() {
        for (j, c) in current.iter().enumerate() {
            let d = set_distance(&p.steady, &c.steady);
            if d <= tol {
                pairs.push((d, i, j));
            }
        }
    }
    // ties by index: the order is a function of the two censuses alone
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let (mut taken, mut ids) = (vec![false; previous.len()], vec![None; current.len()]);
    for (_, i, j) in pairs {
        if !taken[i] && ids[j].is_none() {
            taken[i] = true;
            ids[j] = Some(previous[i].0);
        }
    }
    ids.into_iter()
        .map(|id| {
            id.unwrap_or_else(|| {
                *next_id += 1;
                *next_id - 1
            })
        })
        .collect()
}

/// The global continuation of `spec`: one census per value, in order (its runs in parallel),
/// seeded from the previous value's attractors and matched to them. Counts the random starts
/// of each value in `progress` as the value is done.
///
/// # Errors
/// As [`GlobalContinuationSpec::validate`]; [`SimError::Cancelled`] once `progress` is
/// cancelled. Failing runs are reported per value in [`ContinuationStep::failures`].
pub fn global_continuation(
    spec: &GlobalContinuationSpec,
    progress: &Progress,
) -> Result<Vec<ContinuationStep>, SimError> {
    spec.validate()?;
    progress.add_total(spec.values.len() * spec.census.samples);
    let count = |_: &ContinuationStep| progress.advance(spec.census.samples);
    continue_values(spec, &[], progress.cancel_flag(), &count)
}

/// The global continuation of `spec` going on after the steps `stored` (the first values', as
/// a run that was cut short handed them to `sink`; none for a new run): each further value's
/// census (its runs in parallel) is seeded from the last step's
/// attractors, its ids matched to them and continued after the largest id so far — so that
/// the steps are those of an uninterrupted run — and handed to `sink` as it is done. Starts no
/// run once `cancel` is set. Returns every step, `stored` first.
///
/// # Errors
/// [`SimError::Cancelled`] once `cancel` is set; [`SimError::Params`] for a value's invalid
/// parameters.
pub(crate) fn continue_values(
    spec: &GlobalContinuationSpec,
    stored: &[ContinuationStep],
    cancel: &AtomicBool,
    sink: &dyn Fn(&ContinuationStep),
) -> Result<Vec<ContinuationStep>, SimError> {
    let mut steps: Vec<ContinuationStep> = stored.to_vec();
    // ids are never reused: the next one follows the largest given so far
    let mut next_id = steps
        .iter()
        .flat_map(|s| s.attractors.iter().map(|(id, _)| id + 1))
        .max()
        .unwrap_or(0);
    for &value in spec.values.iter().skip(stored.len()) {
        let params = spec.census.params.with(spec.param, value);
        let model = CantileverModel::new(&params)?;
        let starts: Vec<DVector<f64>> = (0..spec.census.samples)
            .map(|k| start_state(&model, spec.census.seed, value, k as u32))
            .collect();
        let previous: &[(usize, Attractor)] = steps.last().map_or(&[], |s| &s.attractors);
        let seeds: Vec<DVector<f64>> = previous
            .iter()
            .map(|(_, a)| a.steady.end_state().clone())
            .collect();
        let census_spec = AttractorSpec {
            params,
            ..spec.census.clone()
        };
        let found = census(&model, &census_spec, starts, &seeds, cancel, &|| {})?;
        let ids = match_ids(previous, &found.attractors, spec.match_tol, &mut next_id);
        let warnings = found.warnings();
        let step = ContinuationStep {
            value,
            attractors: ids.into_iter().zip(found.attractors).collect(),
            failures: found.failures,
            warnings,
        };
        sink(&step);
        steps.push(step);
    }
    Ok(steps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::steady::{Motion, OrbitStats, PoincarePoint};

    fn steady(points: &[[f64; 2]]) -> SteadyState {
        SteadyState {
            motion: Motion::Periodic {
                period: points.len(),
            },
            transient_periods: 0,
            poincare: points
                .iter()
                .map(|p| PoincarePoint {
                    tau: 0.0,
                    v_t: 0.0,
                    w_tip: p[0],
                    state: DVector::from_row_slice(p),
                })
                .collect(),
            stats: OrbitStats::default(),
        }
    }

    fn attractor(points: &[[f64; 2]]) -> Attractor {
        Attractor {
            steady: steady(points),
            initial: DVector::zeros(2),
            count: 1,
            basin_fraction: 0.0,
            orbit: None,
            lyapunov: None,
        }
    }

    #[test]
    fn set_distance_is_the_symmetric_hausdorff_distance() {
        let a = steady(&[[0.0, 0.0]]);
        let b = steady(&[[0.0, 0.0], [0.3, 0.4]]);
        // from b's point (0.3, 0.4) to a's (0, 0): 0.5/(1 + 0); the other way 0
        assert!((set_distance(&a, &b) - 0.5).abs() < 1e-15);
        assert!((set_distance(&b, &a) - 0.5).abs() < 1e-15);
        assert_eq!(set_distance(&a, &a), 0.0);
    }

    #[test]
    fn matching_takes_the_closest_pairs_and_gives_fresh_ids_to_the_rest() {
        let prev = vec![(4, attractor(&[[0.0, 0.0]])), (7, attractor(&[[1.0, 0.0]]))];
        // c0 near id 7, c1 near id 4 but also within tol of 7, c2 far from both
        let cur = [
            attractor(&[[1.01, 0.0]]),
            attractor(&[[0.02, 0.0]]),
            attractor(&[[5.0, 0.0]]),
        ];
        let mut next = 8;
        assert_eq!(match_ids(&prev, &cur, 0.6, &mut next), vec![7, 4, 8]);
        assert_eq!(next, 9);
        // two attractors near one previous one: the closer keeps the id
        let cur = [attractor(&[[0.05, 0.0]]), attractor(&[[0.01, 0.0]])];
        let mut next = 8;
        assert_eq!(match_ids(&prev[..1], &cur, 0.1, &mut next), vec![8, 4]);
    }
}
