//! Ideal peak-force feedback: the mean rest separation z_c (α5) at which the steady tap's peak
//! force equals a setpoint, as an instrument's feedback holds it.
//!
//! The peak force falls as z_c grows (the sample reaches less far into the tip). The root of
//! g(α5) = F_peak(α5) − F_set is bracketed from α5 = α2 (the sample's lowest point at the
//! rest position of the tip: no repulsive contact quasi-statically) downward in doubling
//! steps, then found by the Illinois variant of false position (Dowell & Jarratt, *BIT* 11
//! (1971) 168), which keeps the bracket; a point whose tap does not settle (it grazes) closes
//! the bracket from the far side, and the next point bisects it. A setpoint that no z_c reaches
//! within the bracket's budget is refused with [`SimError::OutOfRange`] naming `setpoint`.

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
    let mut search = Search {
        base,
        setpoint,
        opts,
        evaluations: 0,
        start: DVector::zeros(base.state_dim()),
    };
    let far = search.far_end()?;
    let best = if far.1 == 0.0 {
        far
    } else {
        let (lo, hi) = search.bracket(far)?;
        let best = search.false_position(lo, hi)?;
        if best.1.abs() > opts.tol * setpoint {
            return Err(refused(
                setpoint,
                "the peak force jumps across it (a fold of the steady taps: bistable tapping)",
            ));
        }
        best
    };
    Ok(SetpointTap {
        alpha5: best.0,
        tap: best.2,
        evaluations: search.evaluations,
    })
}

/// A tap of the search: (α5, F_peak − F_set, the steady tap).
type Point = (f64, f64, SteadyTap);

/// The steady taps of a setpoint's search: each started from the last one's state, counted.
struct Search<'a> {
    base: &'a Params,
    setpoint: f64,
    opts: &'a SetpointOptions,
    evaluations: usize,
    start: DVector<f64>,
}

impl Search<'_> {
    /// F_peak − F_set and the steady tap at `a5`, from the last tap's state.
    fn eval(&mut self, a5: f64) -> Result<(f64, SteadyTap), SimError> {
        let model = CantileverModel::new(&self.base.with(SweepParam::Alpha5, a5))?;
        self.evaluations += 1;
        let tap = steady_tap_from(&model, &self.opts.tap, &self.start)?;
        self.start.copy_from(&tap.state);
        Ok((tap.channels.peak_force - self.setpoint, tap))
    }

    /// The upper end of the bracket: no repulsive contact (the far side of the root). At
    /// α5 = α2 the sample's highest point just reaches the tip's rest position, where the tap
    /// may graze and not settle: a point whose tap does not settle is passed over, a little
    /// farther out; then farther out in doubling steps while the peak force exceeds the
    /// setpoint.
    fn far_end(&mut self) -> Result<Point, SimError> {
        let unit = self.base.alpha2.max(1e-3);
        let mut hi = unit;
        let mut far = 0;
        let (mut g_hi, mut tap_hi) = loop {
            match self.eval(hi) {
                Err(SimError::NoConvergence { .. }) if far < UNSETTLED_SKIPS => {
                    far += 1;
                    hi += 0.05 * unit;
                    self.start.fill(0.0);
                }
                other => break other?,
            }
        };
        let mut up = 0;
        while g_hi > 0.0 {
            up += 1;
            if up > BRACKET_STEPS {
                return Err(refused(
                    self.setpoint,
                    "even the farthest z_c tried exceeds it",
                ));
            }
            hi += unit * f64::from(1u32 << up.min(30));
            (g_hi, tap_hi) = self.eval(hi)?;
        }
        Ok((hi, g_hi, tap_hi))
    }

    /// The bracket (lo, hi) of the root: downward from the far end `far` in doubling steps
    /// until the peak force exceeds the setpoint, a tap that does not settle (grazing, or a
    /// motion that does not repeat) passed over.
    fn bracket(&mut self, far: Point) -> Result<(Point, Point), SimError> {
        let step0 = 0.05 * self.base.alpha2.max(1e-3);
        let (mut hi, mut g_hi, mut tap_hi) = far;
        let (mut lo, mut g_lo, mut tap_lo) = (hi, g_hi, tap_hi.clone());
        let mut k = 0;
        while g_lo < 0.0 {
            if k >= BRACKET_STEPS {
                return Err(refused(
                    self.setpoint,
                    "the peak force stays below it down to the deepest z_c tried",
                ));
            }
            hi = lo;
            g_hi = g_lo;
            tap_hi = tap_lo.clone();
            lo -= step0 * f64::from(1u32 << k);
            k += 1;
            match self.eval(lo) {
                Ok(v) => (g_lo, tap_lo) = v,
                Err(SimError::NoConvergence { .. }) => {
                    lo = hi;
                    self.start.fill(0.0);
                }
                Err(e) => return Err(e),
            }
        }
        Ok(((lo, g_lo, tap_lo), (hi, g_hi, tap_hi)))
    }

    /// Illinois false position on the bracket [lo, hi] (g(lo) ≥ 0 > g(hi)): the tap nearest
    /// the setpoint once it is within the tolerance or the bracket has closed.
    fn false_position(&mut self, lo: Point, hi: Point) -> Result<Point, SimError> {
        let (setpoint, tol) = (self.setpoint, self.opts.tol);
        let (mut lo, mut g_lo, tap_lo) = lo;
        let (mut hi, mut g_hi, tap_hi) = hi;
        let mut side = 0i8;
        let mut bisect = false;
        let mut best = if g_lo.abs() < g_hi.abs() {
            (lo, g_lo, tap_lo)
        } else {
            (hi, g_hi, tap_hi)
        };
        for _ in 0..SETPOINT_ITERATIONS {
            if best.1.abs() <= tol * setpoint || (hi - lo).abs() <= 1e-13 * (1.0 + hi.abs()) {
                break;
            }
            let x = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
            let x = if x > lo && x < hi && !bisect {
                x
            } else {
                0.5 * (lo + hi)
            };
            let (g, tap) = match self.eval(x) {
                Ok(v) => v,
                // a tap that does not settle grazes the sample: on the far (low-force) side;
                // the ends' values are unchanged, so the next point bisects (a false position
                // from them would fall beside this one)
                Err(SimError::NoConvergence { .. }) => {
                    hi = x;
                    bisect = true;
                    self.start.copy_from(&best.2.state);
                    continue;
                }
                Err(e) => return Err(e),
            };
            bisect = false;
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
        Ok(best)
    }
}

fn refused(setpoint: f64, why: &str) -> SimError {
    SimError::out_of_range(
        "setpoint",
        setpoint,
        format!("no z_c gives this peak force: {why}"),
    )
}
