//! The events along a branch ([`super::BranchEvent`]): the test functions of folds, period
//! doublings, Neimark–Sacker points and grazings between two points, and their location by
//! bracketing (module docs of [`super`]).

use super::solver::Solver;
use super::*;

/// Whether the chord of a step from `a` to `b` passes within half its length of `point` (the
/// closure test of an isola at its first point). Testing the step's end alone can miss: the
/// ends on either side of the point are each more than half their own step away when the
/// step length has grown.
pub(super) fn chord_passes(a: &DVector<f64>, b: &DVector<f64>, point: &DVector<f64>) -> bool {
    let (u, w) = (b - a, point - a);
    let along = (w.dot(&u) / u.norm_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
    (w - &u * along).norm() < 0.5 * u.norm()
}

/// Largest change of a Floquet multiplier allowed in one continuation step.
pub(crate) const MAX_MULTIPLIER_STEP: f64 = 0.25;

/// How far the multipliers moved: the largest distance from a multiplier of `b` to the nearest
/// of `a` (and vice versa).
pub(super) fn multiplier_shift(a: &[Complex<f64>], b: &[Complex<f64>]) -> f64 {
    let one_way = |x: &[Complex<f64>], y: &[Complex<f64>]| {
        x.iter()
            .map(|p| {
                y.iter()
                    .map(|q| (p - q).norm())
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max)
    };
    one_way(a, b).max(one_way(b, a))
}

/// Test functions of a point: (dp/ds, det(M + I), complex multipliers outside the circle, switchings).
pub(super) type Tests = (f64, f64, usize, usize);

/// The [`Tests`] of a point.
pub(super) fn tests(
    t: &DVector<f64>,
    m: &DMatrix<f64>,
    mu: &[Complex<f64>],
    switchings: usize,
) -> Tests {
    let dim = m.nrows();
    let pd = (m + DMatrix::identity(dim, dim)).determinant();
    let ns = mu
        .iter()
        .filter(|c| c.im.abs() > 1e-9 && c.norm() > 1.0)
        .count();
    (t[dim], pd, ns, switchings)
}

pub(super) fn changed(a: &Tests, b: &Tests) -> Option<BranchEvent> {
    if a.3 != b.3 {
        Some(BranchEvent::Grazing)
    } else if a.0.signum() != b.0.signum() {
        Some(BranchEvent::Fold)
    } else if a.1.signum() != b.1.signum() {
        Some(BranchEvent::PeriodDoubling)
    } else if a.2 != b.2 {
        Some(BranchEvent::NeimarkSacker)
    } else {
        None
    }
}

/// The test function of event `e` at `t`, signed so that it keeps the sign it has at the
/// reference point `a` until the event (integer counts: +1 while equal to a's count, else −1).
pub(super) fn which(e: BranchEvent, t: &Tests, a: &Tests) -> f64 {
    let same = |x: usize, y: usize| if x == y { 1.0 } else { -1.0 };
    match e {
        BranchEvent::Fold => t.0 * a.0.signum(),
        BranchEvent::PeriodDoubling => t.1 * a.1.signum(),
        BranchEvent::NeimarkSacker => same(t.2, a.2),
        BranchEvent::Grazing => same(t.3, a.3),
    }
}

/// Whether the test function of event `e` is a smooth function of the arclength (dp/ds and
/// det(M + I)) rather than a count.
pub(super) fn smooth(e: BranchEvent) -> bool {
    matches!(e, BranchEvent::Fold | BranchEvent::PeriodDoubling)
}

/// The bracket [a, b] of the arclength step that holds a sign change of an event's test
/// function (f(a) with the sign of the previous point, f(b) the other), shrunk by
/// [`Bracket::next`] and [`Bracket::update`]: for a smooth test function the next point is the
/// secant (regula falsi) point of the ends, the value at an end kept twice in a row halved
/// (the Illinois method: Dowell & Jarratt, *BIT* 11 (1971) 168, superlinear), else the
/// midpoint; either way a step that has not halved the bracket since the one before is
/// followed by a midpoint, so the bracket shrinks at least as fast as by bisection every
/// second step, also where the function jumps (a sign change of dp/ds at a non-smooth point).
#[derive(Debug, Clone, Copy)]
pub(super) struct Bracket {
    pub(super) a: f64,
    pub(super) b: f64,
    fa: f64,
    fb: f64,
    secant: bool,
    /// The end kept by the last update (−1: a, +1: b, 0: none yet).
    kept: i8,
    /// The widths before the last two updates (older first).
    widths: [f64; 2],
}

impl Bracket {
    pub(super) fn new(ds: f64, fa: f64, fb: f64, secant: bool) -> Self {
        Bracket {
            a: 0.0,
            b: ds,
            fa,
            fb,
            secant,
            kept: 0,
            widths: [f64::INFINITY; 2],
        }
    }

    pub(super) fn width(&self) -> f64 {
        self.b - self.a
    }

    /// The next point strictly inside (a, b).
    pub(super) fn next(&self) -> f64 {
        let (a, b, w) = (self.a, self.b, self.width());
        let halved = w <= 0.5 * self.widths[0];
        if self.secant && halved && self.fa.is_finite() && self.fb.is_finite() {
            let x = b - self.fb * w / (self.fb - self.fa);
            if x > a && x < b {
                return x;
            }
        }
        0.5 * (a + b)
    }

    /// Account for f(x) = `fx`; `true` when x became the a end (f with the sign of f(a)).
    pub(super) fn update(&mut self, x: f64, fx: f64) -> bool {
        self.widths = [self.widths[1], self.width()];
        let at_a = fx.signum() == self.fa.signum();
        if at_a {
            (self.a, self.fa) = (x, fx);
            if self.kept == 1 {
                self.fb *= 0.5;
            }
            self.kept = 1;
        } else {
            (self.b, self.fb) = (x, fx);
            if self.kept == -1 {
                self.fa *= 0.5;
            }
            self.kept = -1;
        }
        at_a
    }
}

/// The event `ev` located on the step of `ds` from the point `y` (arclength `s`, tangent `t`,
/// test functions `tf`) to one whose test functions are `tf_end`: the bracket of arclength
/// shrunk to 1e-7 (1 + |s|), by bisection for the counts and, for the smooth test functions,
/// by the secant through the bracket's ends (Illinois). The last point found past the event,
/// labelled with it; `None` where the corrector fails before one is.
///
/// # Errors
/// As [`Solver::tangent`] and [`point`].
pub(super) fn locate(
    solver: &mut Solver,
    ev: BranchEvent,
    (s, ds): (f64, f64),
    (y, t): (&DVector<f64>, &DVector<f64>),
    tf: &Tests,
    tf_end: &Tests,
) -> Result<Option<BranchPoint>, SimError> {
    let f0 = which(ev, tf, tf);
    let mut bracket = Bracket::new(ds, f0, which(ev, tf_end, tf), smooth(ev));
    let mut best: Option<BranchPoint> = None;
    for _ in 0..30 {
        let mid = bracket.next();
        let Ok((ym, mm, _, fpm)) = solver.correct(&(y + t * mid), t) else {
            break;
        };
        let tm = Solver::tangent(&mm.jacobian, &fpm, t)?;
        let mut pm = point(solver, s + mid, &ym, &mm)?;
        let fm = which(
            ev,
            &tests(&tm, &mm.jacobian, &pm.multipliers, mm.switchings),
            tf,
        );
        if !bracket.update(mid, fm) {
            pm.event = Some(ev);
            best = Some(pm);
        }
        if bracket.width() <= 1e-7 * (1.0 + s.abs()) {
            break;
        }
    }
    Ok(best)
}

pub(super) fn point(
    solver: &mut Solver,
    s: f64,
    y: &DVector<f64>,
    map: &FlowMap,
) -> Result<BranchPoint, SimError> {
    let dim = y.len() - 1;
    let z = y.rows(0, dim).into_owned();
    let p = y[dim];
    let n = solver.spec.period;
    let section = section_points(solver.at(p)?, &z, n)?;
    let (multipliers, stable, critical) = floquet_stability(&map.jacobian);
    Ok(BranchPoint {
        s,
        value: p,
        period: n,
        section,
        stable,
        critical,
        multipliers,
        switchings: map.switchings,
        grazing_distance: map.grazing_distance,
        event: None,
    })
}
