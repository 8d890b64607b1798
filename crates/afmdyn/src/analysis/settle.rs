//! Settling on a stable periodic orbit from a transient by Newton shooting: the early decision
//! shared by the stepped sweeps ([`super::stepped::settle`]) and every steady-state search on
//! a slowly decaying cantilever ([`super::steady::steady_state`]).
//!
//! A lever of quality factor Q takes ~Q ln(1/tol)/π drive periods for its returns to repeat
//! to the tolerance tol (≈ 2 900 periods at Q = 500, tol = 1e-8). So every
//! `SettleOptions::chunk_periods` periods Newton's method is tried from the current state
//! (undamped, [`ShootingStrategy::Undamped`]: from a transient far from the orbit the damped
//! iteration's halvings rarely converge and each costs a flow, and the next attempt starts
//! nearer); a *stable* orbit it finds is accepted only once the trajectory is seen to go to it
//! — it has come closer over two further chunks and is within `SettleOptions::settled` of it,
//! or has arrived on it, or (where `SettleOptions::linear` allows it) has twice come closer
//! at the rate |μ₁|^chunk of the orbit's leading Floquet multiplier — so it is the attractor
//! the motion goes to, not another orbit Newton happened to reach from a state on the way.
//! (Newton's method for periodic orbits: Seydel, *Practical Bifurcation and Stability
//! Analysis*, 3rd ed., Springer 2010, §7.3.)
//!
//! How near is near enough depends on what else is there: on a lightly damped lever the basins
//! of coexisting orbits wind round each other, and a transient far from every orbit is the free
//! oscillation, decaying at the rate e^{−π/Q} that is also |μ₁| of every orbit with a complex
//! pair of multipliers. A start is decided there only within `CENSUS_SETTLED`, which the
//! measurement quoted with it shows to be safe by a factor of 10 on the RTESPA-300 probe; a
//! stepped sweep, whose transient starts on the previous value's orbit, keeps `SETTLED` and
//! the rate test.

use super::shooting::{shoot, ShootingOptions, ShootingStrategy};
use crate::error::SimError;
use crate::integrate::{advance, Integrator};
use crate::maps::{DiscreteMap, StroboscopicMap};
use nalgebra::{Complex, DMatrix, DVector};

/// Chunks of [`SettleOptions::chunk_periods`] during which Newton is retried before the
/// motion is left to classification by integration alone.
pub(crate) const NEWTON_CHUNKS: usize = 40;

/// Relative distance (to 1 + ‖z‖) within which a transient that keeps approaching a stable
/// orbit is taken to have reached it in a stepped sweep (which starts from the previous
/// value's orbit).
pub(crate) const SETTLED: f64 = 5e-2;

/// Relative distance within which a transient from an arbitrary start that keeps approaching
/// a stable orbit is taken to go to it ([`super::steady::steady_state`]). On the RTESPA-300
/// probe (Q = 500, two coexisting period-1 orbits 0.2 apart in relative distance; 64 starts,
/// `examples/high_q.rs`): accepted at 5e-2 … 1.4e-1 by the rate test, 13 of 40 starts went to
/// the other orbit; at 1e-2 every start was decided right, at 1e-3 (a factor 10 of margin)
/// too, after 1 868 drive periods on average against 2 849 for the returns to repeat to 1e-8.
pub(crate) const CENSUS_SETTLED: f64 = 1e-3;

/// Options of [`newton_from_transient`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SettleOptions {
    /// Newton shooting from the transient (undamped, for each period tried).
    pub newton: ShootingOptions,
    /// Drive periods between Newton attempts (≥ 1).
    pub chunk_periods: usize,
    /// Largest period tried when the period is not given.
    pub max_period: usize,
    /// Most chunks between two Newton attempts (the wait grows 1.5-fold after a failed one).
    pub max_wait: usize,
    /// Relative distance (to 1 + ‖z*‖) within which a transient that keeps approaching the
    /// orbit z* is taken to have reached it ([`SETTLED`] in a stepped sweep).
    pub settled: f64,
    /// Whether a transient that twice comes closer at the rate of the orbit's leading
    /// multiplier is taken to go to it, at any distance. Unsafe on a lightly damped lever: far
    /// from every orbit the transient is the free oscillation, which decays at that same rate
    /// (|μ₁| = e^{−π/Q} for any orbit with a complex pair) whichever attractor it goes to.
    pub linear: bool,
}

/// The steady state a transient settles on.
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    /// Period n, `None` for a motion that is not period-n.
    pub period: Option<usize>,
    /// State at drive phase 0, shape `[2N]` (the last recorded state of a non-periodic motion).
    pub state: DVector<f64>,
    /// Floquet multipliers, decreasing modulus (empty for a non-periodic motion).
    pub multipliers: Vec<Complex<f64>>,
    /// Monodromy matrix, 2N×2N (`None` for a non-periodic motion).
    pub monodromy: Option<DMatrix<f64>>,
    /// Stable (an attractor).
    pub stable: bool,
}

/// What [`newton_from_transient`] reached.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Settling {
    /// The stable orbit the transient was seen to go to (`None`: not within the budget).
    pub found: Option<Found>,
    /// The transient's state at the end (τ a multiple of the drive period, shape `[2N]`).
    pub state: DVector<f64>,
    /// Drive periods integrated.
    pub periods: usize,
}

/// A stable orbit found by Newton from a transient, and how the transient approaches it.
struct Candidate {
    period: usize,
    state: DVector<f64>,
    multipliers: Vec<Complex<f64>>,
    monodromy: DMatrix<f64>,
    /// Distance of the transient from the orbit at the last check.
    distance: f64,

    /// Consecutive checks at which the distance decreased.
    approaches: usize,
    /// Consecutive checks at which it decreased at the rate of the leading multiplier.
    linear: usize,
}

impl Candidate {
    fn found(self) -> Found {
        Found {
            period: Some(self.period),
            state: self.state,
            multipliers: self.multipliers,
            monodromy: Some(self.monodromy),
            stable: true,
        }
    }
}

/// The periods Newton tries from a transient whose period is not known: 1, then the shift n
/// (2 ≤ n ≤ `max_period`, n ≤ half the returns) at which the newest return comes closest to
/// an earlier one, the smallest n within twice the least distance (a period-n cycle being
/// approached repeats best at its period; its multiples repeat no better).
pub(crate) fn period_guesses(returns: &[DVector<f64>], max_period: usize) -> Vec<usize> {
    let mut out = vec![1];
    let Some(last) = returns.len().checked_sub(1) else {
        return out;
    };
    let d: Vec<f64> = (1..=max_period.min(returns.len() / 2))
        .map(|n| (&returns[last] - &returns[last - n]).norm())
        .collect();
    let least = d.iter().copied().fold(f64::INFINITY, f64::min);
    if let Some(i) = d.iter().position(|&x| x <= 2.0 * least) {
        if i > 0 {
            out.push(i + 1);
        }
    }
    out
}

/// Integrate from `z0` (τ = 0) for at most `budget` drive periods, in chunks of
/// `opts.chunk_periods`, trying Newton (period `period`, or the [`period_guesses`] of the
/// chunk's returns) from the transient until it is seen to go to a stable orbit (module docs).
/// Without a `period` every return is also handed to `on_return`, which ends the run (no
/// orbit found, the state that return's) when it returns `true`: the caller's own test on the
/// returns (they repeat) decides whichever comes first.
/// After a failed attempt the next one waits 1.5 times as many chunks, at most
/// [`SettleOptions::max_wait`].
///
/// # Errors
/// [`SimError`] from the integrator (a failing Newton attempt is not an error).
pub(crate) fn newton_from_transient(
    integ: &mut dyn Integrator,
    z0: &DVector<f64>,
    period: Option<usize>,
    opts: &SettleOptions,
    budget: usize,
    on_return: &mut dyn FnMut(&DVector<f64>) -> bool,
) -> Result<Settling, SimError> {
    let drive = integ.system().period();
    let chunk = opts.chunk_periods.max(1);
    let mut x = z0.clone();
    let mut elapsed = 0usize;
    let mut candidate: Option<Candidate> = None;
    let mut returns: Vec<DVector<f64>> = Vec::new();
    let (mut chunks, mut next_try, mut wait) = (0usize, 1usize, 1.0f64);
    while elapsed < budget {
        integ.set_variational(false);
        integ.reset(0.0, &x)?;
        if period.is_some() {
            advance(integ, chunk as f64 * drive)?;
        } else {
            // the chunk's returns, for the period guesses
            returns.clear();
            returns.push(x.clone());
            for k in 1..=chunk {
                advance(integ, k as f64 * drive)?;
                returns.push(integ.state().clone());
                if on_return(integ.state()) {
                    return Ok(Settling {
                        found: None,
                        state: integ.state().clone(),
                        periods: elapsed + k,
                    });
                }
            }
        }
        elapsed += chunk;
        chunks += 1;
        x = integ.state().clone();
        if let Some(mut c) = candidate.take() {
            let d = (&x - &c.state).norm();
            let scale = 1.0 + c.state.norm();
            // the transient approaches the orbit at the rate of its leading multiplier
            // (per period n: a chunk of `chunk` drive periods is chunk/n applications of Pⁿ)
            let rate = c.multipliers[0].norm().powf(chunk as f64 / c.period as f64);
            let ratio = d / c.distance;
            let linear = ratio <= 1.0 && (ratio - rate).abs() <= 0.25 * (1.0 - rate) + 1e-3;
            if d <= 1e-9 * scale {
                return Ok(settled(c.found(), x, elapsed));
            }
            if d < c.distance {
                c.approaches += 1;
                c.linear = if linear { c.linear + 1 } else { 0 };
                c.distance = d;
                if (d <= opts.settled * scale && c.approaches >= 2)
                    || (opts.linear && c.linear >= 2)
                {
                    return Ok(settled(c.found(), x, elapsed));
                }
                candidate = Some(c);
                continue;
            }
        }
        if chunks < next_try {
            continue;
        }
        let tries = match period {
            Some(n) => vec![n],
            None => period_guesses(&returns, opts.max_period),
        };
        candidate = tries.into_iter().find_map(|n| {
            let undamped = ShootingOptions {
                period: n,
                strategy: ShootingStrategy::Undamped,
                ..opts.newton
            };
            match shoot(&mut StroboscopicMap::new(integ, 1), &x, &undamped) {
                Ok(o) if o.stable => Some(Candidate {
                    period: n,
                    distance: (&x - &o.state).norm(),
                    state: o.state,
                    multipliers: o.multipliers,
                    monodromy: o.monodromy,
                    approaches: 0,
                    linear: 0,
                }),
                _ => None,
            }
        });
        wait = if candidate.is_some() {
            1.0
        } else {
            (wait * 1.5).min(opts.max_wait as f64)
        };
        next_try = chunks + wait.round() as usize;
    }
    Ok(Settling {
        found: None,
        state: x,
        periods: elapsed,
    })
}

fn settled(found: Found, state: DVector<f64>, periods: usize) -> Settling {
    Settling {
        found: Some(found),
        state,
        periods,
    }
}

/// The smallest divisor d of an orbit's period n whose d-fold map already returns its state
/// (Pᵈ(z*) = z* to `tol` relative to 1 + ‖z*‖): Newton from a transient tried at a multiple
/// of the orbit's period finds the orbit all the same. `n` when no divisor does, or a flow
/// fails. On any [`DiscreteMap`] (Pᵈ by [`DiscreteMap::iterate`]; the steady-state search
/// gives the period-1 stroboscopic map of its integrator).
pub(crate) fn minimal_period(
    dmap: &mut dyn DiscreteMap,
    z: &DVector<f64>,
    n: usize,
    tol: f64,
) -> usize {
    for d in (1..n).filter(|d| n.is_multiple_of(*d)) {
        let Ok(state) = dmap.iterate(z, d) else {
            return n;
        };
        if (&state - z).norm() <= tol * (1.0 + z.norm()) {
            return d;
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Returns x_k = p_{k mod n} + c ρ^k rotating in from a period-n cycle: the guesses are 1
    /// and n (the shift at which the newest return comes closest), and 1 alone for n = 1.
    #[test]
    fn the_period_guesses_are_one_and_the_cycle_being_approached() {
        for n in [1usize, 2, 3, 5] {
            let returns: Vec<DVector<f64>> = (0..25)
                .map(|k| {
                    let phase = 2.0 * std::f64::consts::PI * (k % n) as f64 / n as f64;
                    let decay = 0.3 * 0.97f64.powi(k as i32);
                    DVector::from_vec(vec![
                        phase.cos() + decay * (0.1 * k as f64).cos(),
                        phase.sin() + decay * (0.1 * k as f64).sin(),
                    ])
                })
                .collect();
            let want = if n == 1 { vec![1] } else { vec![1, n] };
            assert_eq!(period_guesses(&returns, 16), want, "n = {n}");
        }
        assert_eq!(period_guesses(&[], 16), vec![1]);
    }
}
