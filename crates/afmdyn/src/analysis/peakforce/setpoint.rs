//! Ideal peak-force feedback: the mean rest separation z_c (α5) at which the steady tap's peak
//! force equals a setpoint, as an instrument's feedback holds it.
//!
//! The peak force falls as z_c grows (the sample reaches less far into the tip). The root of
//! g(α5) = F_peak(α5) − F_set is bracketed from α5 = α2 (the sample's lowest point at the
//! rest position of the tip: no repulsive contact quasi-statically) downward in doubling
//! steps, then found by the Illinois variant of false position (Dowell & Jarratt, *BIT* 11
//! (1971) 168), which keeps the bracket. A setpoint that no z_c reaches within the bracket's
//! budget is refused with [`SimError::OutOfRange`] naming `setpoint`.

use super::{steady_tap_from, PeakForceOptions, SteadyTap};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use nalgebra::DVector;

/// Relative tolerance of the setpoint: |F_peak − F_set| ≤ this × F_set.
pub const SETPOINT_TOL: f64 = 1e-6;
/// Doublings of the downward step that brackets the setpoint before it is refused.
pub const BRACKET_STEPS: usize = 12;
/// Points passed over at the bracket's far end whose tap does not settle (each 0.05 α2
/// farther out).
pub(crate) const UNSETTLED_SKIPS: usize = 4;
/// Iterations of false position.
pub const SETPOINT_ITERATIONS: usize = 80;

/// Options of [`peak_force_setpoint`].
#[derive(Debug, Clone)]
pub struct SetpointOptions {
    /// Relative tolerance on the peak force ([`SETPOINT_TOL`]).
    pub tol: f64,
    /// The steady tap's options.
    pub tap: PeakForceOptions,
}

impl Default for SetpointOptions {
    fn default() -> Self {
        SetpointOptions {
            tol: SETPOINT_TOL,
            tap: PeakForceOptions::default(),
        }
    }
}

/// The steady tap at the setpoint and the α5 that gives it.
#[derive(Debug, Clone)]
pub struct SetpointTap {
    /// α5 (the gap at rest; the rest distance is [`Params::rest_distance`]).
    pub alpha5: f64,
    /// The steady tap there.
    pub tap: SteadyTap,
    /// Steady taps computed (bracket and iterations).
    pub evaluations: usize,
}

/// The α5 of `base` at which the peak force is `setpoint` (model units F̃, > 0), and the tap
/// there (module docs).
///
/// # Errors
/// [`SimError::OutOfRange`] for a setpoint that is not finite and > 0, or that no α5 in the
/// bracket reaches; [`SimError`] from the taps.
pub fn peak_force_setpoint(
    base: &Params,
    setpoint: f64,
    opts: &SetpointOptions,
) -> Result<SetpointTap, SimError> {
    if !(setpoint.is_finite() && setpoint > 0.0) {
        return Err(SimError::out_of_range(
            "setpoint",
            setpoint,
            "must be a finite peak force > 0",
        ));
    }
    let mut evaluations = 0;
    let mut start = DVector::zeros(base.state_dim());
    let mut eval = |a5: f64, start: &mut DVector<f64>| -> Result<(f64, SteadyTap), SimError> {
        let model = CantileverModel::new(&base.with(SweepParam::Alpha5, a5))?;
        evaluations += 1;
        let tap = steady_tap_from(&model, &opts.tap, start)?;
        start.copy_from(&tap.state);
        Ok((tap.channels.peak_force - setpoint, tap))
    };
    // the upper end: no repulsive contact (the far side of the root). At α5 = α2 the sample's
    // highest point just reaches the tip's rest position, where the tap may graze and not
    // settle: a point whose tap does not settle is passed over, a little farther out
    let mut hi = base.alpha2.max(1e-3);
    let mut far = 0;
    let (mut g_hi, mut tap_hi) = loop {
        match eval(hi, &mut start) {
            Err(SimError::NoConvergence { .. }) if far < UNSETTLED_SKIPS => {
                far += 1;
                hi += 0.05 * base.alpha2.max(1e-3);
                start.fill(0.0);
            }
            other => break other?,
        }
    };
    let mut up = 0;
    while g_hi > 0.0 {
        up += 1;
        if up > BRACKET_STEPS {
            return Err(refused(setpoint, "even the farthest z_c tried exceeds it"));
        }
        hi += base.alpha2.max(1e-3) * f64::from(1u32 << up.min(30));
        (g_hi, tap_hi) = eval(hi, &mut start)?;
    }
    if g_hi == 0.0 {
        return Ok(SetpointTap {
            alpha5: hi,
            tap: tap_hi,
            evaluations,
        });
    }
    // downward in doubling steps until the peak force exceeds the setpoint
    let step0 = 0.05 * base.alpha2.max(1e-3);
    let (mut lo, mut g_lo, mut tap_lo) = (hi, g_hi, tap_hi.clone());
    let mut k = 0;
    while g_lo < 0.0 {
        if k >= BRACKET_STEPS {
            return Err(refused(
                setpoint,
                "the peak force stays below it down to the deepest z_c tried",
            ));
        }
        hi = lo;
        g_hi = g_lo;
        tap_hi = tap_lo.clone();
        lo -= step0 * f64::from(1u32 << k);
        k += 1;
        // a tap that does not settle (grazing, or a motion that does not repeat) is passed
        // over: the bracket steps on
        match eval(lo, &mut start) {
            Ok(v) => (g_lo, tap_lo) = v,
            Err(SimError::NoConvergence { .. }) => {
                lo = hi;
                start.fill(0.0);
            }
            Err(e) => return Err(e),
        }
    }
    // Illinois false position on [lo, hi]: g(lo) ≥ 0 > g(hi)
    let mut side = 0i8;
    let mut best = if g_lo.abs() < g_hi.abs() {
        (lo, g_lo, tap_lo.clone())
    } else {
        (hi, g_hi, tap_hi.clone())
    };
    for _ in 0..SETPOINT_ITERATIONS {
        if best.1.abs() <= opts.tol * setpoint || (hi - lo).abs() <= 1e-13 * (1.0 + hi.abs()) {
            break;
        }
        let x = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
        let x = if x > lo && x < hi { x } else { 0.5 * (lo + hi) };
        let (g, tap) = match eval(x, &mut start) {
            Ok(v) => v,
            // a tap that does not settle grazes the sample: on the far (low-force) side
            Err(SimError::NoConvergence { .. }) => {
                hi = x;
                start.copy_from(&best.2.state);
                continue;
            }
            Err(e) => return Err(e),
        };
        if g.abs() < best.1.abs() {
            best = (x, g, tap);
        }
        if g >= 0.0 {
            lo = x;
            g_lo = g;
            if side == -1 {
                g_hi *= 0.5;
            }
            side = -1;
        } else {
            hi = x;
            g_hi = g;
            if side == 1 {
                g_lo *= 0.5;
            }
            side = 1;
        }
    }
    if best.1.abs() > opts.tol * setpoint {
        return Err(refused(
            setpoint,
            "the peak force jumps across it (a fold of the steady taps: bistable tapping)",
        ));
    }
    Ok(SetpointTap {
        alpha5: best.0,
        tap: best.2,
        evaluations,
    })
}

fn refused(setpoint: f64, why: &str) -> SimError {
    SimError::out_of_range(
        "setpoint",
        setpoint,
        format!("no z_c gives this peak force: {why}"),
    )
}
