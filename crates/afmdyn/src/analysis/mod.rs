//! Analyses on the stroboscopic Poincaré map ([`crate::maps`]): steady states and their periods, parameter
//! sweeps (bifurcation diagrams), coexisting attractors and basins, mode convergence (Fig. 4);
//! beyond the paper: Newton shooting, Floquet multipliers,
//! pseudo-arclength continuation, Lyapunov exponents and the 0–1 test for chaos; the observables
//! of a steady state (harmonics and phase, forces, sample dissipation, virial, energy balances);
//! the amplitude spectrum of a time series; frequency-modulation AFM at constant amplitude as
//! exact periodic orbits ([`fm`]; its time-domain loop for comparison, [`fm_loop`]); force
//! reconstruction from FM-AFM frequency shifts ([`reconstruct`]: Sader–Jarvis) and from AM
//! amplitude and phase (`reconstruct_am`: the matrix method at each point's amplitude); the
//! exact inversion of the first-order FM relation ([`reconstruct_exact`]).

pub mod am_loop;
pub mod approach;
pub mod attractors;
pub(crate) mod basin_entropy;
pub mod basins;
pub mod bifurcation;
pub mod calibration;
pub mod chart;
pub mod continuation;
pub mod converge;
pub mod fit;
pub mod fm;
pub mod fm_loop;
pub mod global_continuation;
pub mod lock_in_noise;
pub mod lyapunov;
pub mod observables;
pub(crate) mod orbit_noise;
pub mod peakforce;
pub mod period;
pub mod progress;
pub mod reconstruct;
pub(crate) mod reconstruct_am;
pub mod reconstruct_exact;
pub mod resonance;
pub mod setpoint;
pub mod settle;
pub mod shooting;
pub(crate) mod spectrum;
pub mod steady;
pub mod stepped;
pub(crate) mod tasks;
pub mod thermal;
pub mod torus;
pub mod traces;

/// Check a relative tolerance `v` (an integrator's, a curve's loop conditions) in (0, 1e-3):
/// beyond 1e-3 a steady state is not resolved, and 0 or less is never met.
///
/// # Errors
/// [`crate::SimError::OutOfRange`] naming `name`.
pub(crate) fn tolerance(name: &'static str, v: f64) -> Result<(), crate::SimError> {
    if !(v.is_finite() && v > 0.0 && v < 1e-3) {
        return Err(crate::SimError::out_of_range(
            name,
            v,
            "must be in (0, 1e-3)",
        ));
    }
    Ok(())
}

/// Without the `parallel` feature: the few rayon adaptors the analyses call, on plain
/// iterators, so the same code runs its independent tasks one after another (each task's seed
/// comes from its index, so the results do not depend on the feature).
#[cfg(not(feature = "parallel"))]
mod sequential {
    /// `into_par_iter` is `into_iter`.
    pub(crate) trait IntoParallelIterator: IntoIterator + Sized {
        fn into_par_iter(self) -> Self::IntoIter {
            self.into_iter()
        }
    }
    impl<I: IntoIterator> IntoParallelIterator for I {}

    /// `par_iter_mut` is `iter_mut`.
    pub(crate) trait ParallelSliceMut<T> {
        fn par_iter_mut(&mut self) -> std::slice::IterMut<'_, T>;
    }
    impl<T> ParallelSliceMut<T> for [T] {
        fn par_iter_mut(&mut self) -> std::slice::IterMut<'_, T> {
            self.iter_mut()
        }
    }

    /// `with_max_len` (rayon's split granularity) has nothing to do.
    pub(crate) trait IndexedParallelIterator: Iterator + Sized {
        fn with_max_len(self, _max: usize) -> Self {
            self
        }
    }
    impl<I: Iterator> IndexedParallelIterator for I {}

    /// `join` runs `a`, then `b`.
    pub(crate) fn join<A, B, RA, RB>(a: A, b: B) -> (RA, RB)
    where
        A: FnOnce() -> RA,
        B: FnOnce() -> RB,
    {
        (a(), b())
    }
}
