//! Pseudo-arclength continuation of period-n orbits of the stroboscopic map in Ω or any α, with
//! detection and location of folds, period doublings, Neimark–Sacker and grazing points, and
//! branch switching at a period doubling onto the period-2n branch.
//!
//! Unknowns y = (z, p) ∈ R^{2N+1}; F(z, p) = Pⁿ(z; p) − z = 0 augmented by the arclength
//! condition tᵀ(y − y_pred) = 0 (Keller 1977; Seydel, *Practical Bifurcation and Stability
//! Analysis*, 3rd ed., Springer 2010, ch. 4). ∂F/∂z = M − I with M the monodromy matrix;
//! ∂F/∂p from the parameter sensitivity along the same flow where the integrator provides it
//! (the exact propagator for Ω, α2, α5: [`StroboscopicMap::with_param_derivative`]), else by central
//! differences of the map, by flows without the variational equations. Test functions
//! between accepted points: dp/ds (fold), det(M + I) (period doubling), the number of complex
//! multipliers outside the unit circle (Neimark–Sacker) and the number of switchings per cycle
//! (grazing); each sign change is located on the arclength step, by bisection for the counts
//! and by the Illinois secant for the two smooth test functions.

use crate::analysis::progress::Progress;
use crate::analysis::shooting::{
    floquet_stability, section_points, shoot_with, Instability, ShootingOptions,
};
use crate::error::SimError;
use crate::integrate::{build, Integrator, IntegratorOptions};
use crate::maps::flow::FlowMap;
use crate::maps::StroboscopicMap;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

mod switching;
pub use switching::{
    continue_with_switching, continue_with_switching_with, period_doubling_starts,
    switch_at_period_doubling,
};

/// A continuation run.
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuationSpec {
    /// Parameters (the continued one is overwritten).
    pub base: Params,
    /// Continued parameter.
    pub param: SweepParam,
    /// Start value.
    pub from: f64,
    /// The run stops when the parameter leaves [min(from, to), max(from, to)].
    pub to: f64,
    /// Period n of the orbit.
    pub period: usize,
    /// Initial arclength step.
    pub ds: f64,
    /// Smallest step before giving up.
    pub ds_min: f64,
    /// Largest step.
    pub ds_max: f64,
    /// Cap on the number of points.
    pub max_points: usize,
    /// Work budget of one branch: adaptive integrator steps ([`Integrator::work`]) over all its
    /// flows (corrector, ∂F/∂p, event location); the exact propagator's steps are not counted.
    /// The branch ends with [`BranchEnd::Budget`] once it is spent.
    pub max_work: u64,
    /// Newton options (also for the corrector).
    pub newton: ShootingOptions,
    /// Integrator of the stroboscopic map (default: auto, exact for the linear law).
    pub integrator: IntegratorOptions,
    /// Parameter values of the parent branch's period doublings (a period-2n branch): a fold
    /// located at one of them, where the half-cycles nearly coincide, is the pitchfork junction
    /// with the parent — the branch is labelled a period doubling there and ends.
    pub junctions: Vec<f64>,
    /// The parameter range the branch may visit (default: between `from` and `to`); the branch
    /// starts towards `to`.
    pub range: Option<(f64, f64)>,
}

impl ContinuationSpec {
    /// Defaults for a run from `from` to `to`.
    pub fn new(base: Params, param: SweepParam, from: f64, to: f64, period: usize) -> Self {
        let span = (to - from).abs().max(1e-6);
        ContinuationSpec {
            base,
            param,
            from,
            to,
            period,
            ds: span / 200.0,
            ds_min: span * 1e-9,
            ds_max: span / 50.0,
            max_points: 5000,
            max_work: WORK_BUDGET,
            newton: ShootingOptions::default(),
            integrator: IntegratorOptions::default(),
            junctions: Vec::new(),
            range: None,
        }
    }
}

/// Default [`ContinuationSpec::max_work`]: 10⁸ adaptive steps per branch. The default
/// three-mode branches from Ω = 5 to 1 take 1.4·10⁷ (Hertz, 1340 points) and 3.0·10⁷ (DMT,
/// 2295 points); the budget ends a branch that winds on without end (an undamped beam, say)
/// after a bounded, reproducible amount of work, with a warning naming where it stopped.
pub const WORK_BUDGET: u64 = 100_000_000;

/// Why a branch ended.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "reason")]
pub enum BranchEnd {
    /// The parameter left the range: the branch is complete.
    Range,
    /// The branch closed on its first point (an isola).
    Closed,
    /// A period-2n branch merged into its period-n parent.
    Merged,
    /// The corrector failed down to the smallest arclength step at this parameter value (a
    /// singular point the predictor cannot pass, or the orbit ceased to exist).
    StepFloor {
        /// Parameter value of the last point.
        value: f64,
    },
    /// [`ContinuationSpec::max_points`] points.
    MaxPoints {
        /// Parameter value of the last point.
        value: f64,
    },
    /// [`ContinuationSpec::max_work`] adaptive steps spent.
    Budget {
        /// Parameter value of the last point.
        value: f64,
        /// Steps spent.
        steps: u64,
    },
}

impl BranchEnd {
    /// Whether the branch covers what was asked (range left, closed or merged).
    pub fn complete(&self) -> bool {
        self.cause().is_none()
    }

    /// Why an early end came, as a clause ("its work budget of adaptive steps", …); `None` for
    /// a complete branch.
    pub fn cause(&self) -> Option<&'static str> {
        match self {
            BranchEnd::Range | BranchEnd::Closed | BranchEnd::Merged => None,
            BranchEnd::StepFloor { .. } => Some(
                "the corrector failed down to the smallest arclength step (a singular point, \
                 or the orbit ceases to exist there)",
            ),
            BranchEnd::MaxPoints { .. } => Some("its cap of points"),
            BranchEnd::Budget { .. } => Some("its work budget of adaptive steps"),
        }
    }

    /// A one-line warning for a branch that ended early, naming the parameter `param` at which
    /// it stopped, the [`BranchEnd::cause`] and what to change; `None` for a complete branch.
    pub fn warning(&self, param: SweepParam, period: usize) -> Option<String> {
        let cause = self.cause()?;
        let p = param.name();
        let at = |x: f64| {
            format!(
                "the period-{period} branch ended at {p} = {}",
                crate::error::number(x)
            )
        };
        Some(match *self {
            BranchEnd::Budget { value, steps } => format!(
                "{} after {steps} adaptive steps ({cause}); narrow --from/--to, or continue from \
                 there with --from",
                at(value)
            ),
            BranchEnd::MaxPoints { value } => {
                format!(
                    "{} after {cause}; continue from there with --from",
                    at(value)
                )
            }
            BranchEnd::StepFloor { value } => format!("{}: {cause}", at(value)),
            BranchEnd::Range | BranchEnd::Closed | BranchEnd::Merged => unreachable!("complete"),
        })
    }
}

/// A continued branch: its points in arclength order and why it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// The points, located bifurcations labelled.
    pub points: Vec<BranchPoint>,
    /// Why the branch ended.
    pub end: BranchEnd,
}

impl std::ops::Deref for Branch {
    type Target = Vec<BranchPoint>;
    fn deref(&self) -> &Vec<BranchPoint> {
        &self.points
    }
}

impl std::ops::DerefMut for Branch {
    fn deref_mut(&mut self) -> &mut Vec<BranchPoint> {
        &mut self.points
    }
}

impl<'a> IntoIterator for &'a Branch {
    type Item = &'a BranchPoint;
    type IntoIter = std::slice::Iter<'a, BranchPoint>;
    fn into_iter(self) -> Self::IntoIter {
        self.points.iter()
    }
}

impl<'a> IntoIterator for &'a mut Branch {
    type Item = &'a mut BranchPoint;
    type IntoIter = std::slice::IterMut<'a, BranchPoint>;
    fn into_iter(self) -> Self::IntoIter {
        self.points.iter_mut()
    }
}

/// A labelled point of a branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BranchEvent {
    /// Fold (limit point): dp/ds changes sign.
    Fold,
    /// Period doubling: a multiplier through −1.
    PeriodDoubling,
    /// Neimark–Sacker: a complex pair through the unit circle.
    NeimarkSacker,
    /// Grazing: the number of switchings per cycle changes.
    Grazing,
}

impl BranchEvent {
    /// Its name in every output (JSON, CSV, Python): `fold`, `period-doubling`,
    /// `neimark-sacker`, `grazing`.
    pub fn name(self) -> &'static str {
        match self {
            BranchEvent::Fold => "fold",
            BranchEvent::PeriodDoubling => "period-doubling",
            BranchEvent::NeimarkSacker => "neimark-sacker",
            BranchEvent::Grazing => "grazing",
        }
    }
}

/// One point of a branch.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchPoint {
    /// Arclength.
    pub s: f64,
    /// Parameter value.
    pub value: f64,
    /// Period n.
    pub period: usize,
    /// States at the n section points (τ = kT).
    pub section: Vec<DVector<f64>>,
    /// Floquet multipliers, decreasing modulus.
    pub multipliers: Vec<Complex<f64>>,
    /// Stable.
    pub stable: bool,
    /// Type of the critical multiplier.
    pub critical: Instability,
    /// Switchings per cycle.
    pub switchings: usize,
    /// Distance to grazing.
    pub grazing_distance: f64,
    /// Label when this point locates a bifurcation.
    pub event: Option<BranchEvent>,
}

struct Solver {
    spec: ContinuationSpec,
    /// Propagators of the last few parameter values (p and p ± δ for ∂F/∂p).
    cache: Vec<(f64, Box<dyn Integrator>)>,
    /// Work of the propagators dropped from the cache.
    retired: u64,
}

impl Solver {
    fn new(spec: &ContinuationSpec) -> Result<Self, SimError> {
        Ok(Solver {
            spec: spec.clone(),
            cache: Vec::new(),
            retired: 0,
        })
    }

    /// Adaptive steps spent so far ([`Integrator::work`] of every propagator built).
    fn work(&self) -> u64 {
        self.retired + self.cache.iter().map(|(_, i)| i.work()).sum::<u64>()
    }

    fn at(&mut self, p: f64) -> Result<&mut dyn Integrator, SimError> {
        let i = match self.cache.iter().position(|(v, _)| *v == p) {
            Some(i) => i,
            None => {
                let model = CantileverModel::new(&self.spec.base.with(self.spec.param, p))?;
                if self.cache.len() == 6 {
                    self.retired += self.cache.remove(0).1.work();
                }
                let integ = build(&model, self.spec.integrator.clone(), 0.0, &model.rest())?;
                self.cache.push((p, integ));
                self.cache.len() - 1
            }
        };
        Ok(self.cache[i].1.as_mut())
    }

    /// Pⁿ(z) with its monodromy matrix and, where the integrator provides it, ∂Pⁿ/∂p; the
    /// distance to grazing only when `watched` (else NaN).
    fn map(&mut self, z: &DVector<f64>, p: f64, watched: bool) -> Result<FlowMap, SimError> {
        let (n, param) = (self.spec.period, self.spec.param);
        StroboscopicMap::new(self.at(p)?, n)
            .with_param_derivative(param)
            .watch_grazing(watched)
            .apply(z)
    }

    /// The distance to grazing of Pⁿ(z) (as the watched [`Solver::map`] reports it: the same
    /// steps and searches).
    fn grazing(&mut self, z: &DVector<f64>, p: f64) -> Result<f64, SimError> {
        let n = self.spec.period;
        StroboscopicMap::new(self.at(p)?, n).grazing_distance(z)
    }

    /// ∂Pⁿ/∂p at (z, p): that of `map` when known, else central differences.
    fn dp_of(&mut self, map: &FlowMap, z: &DVector<f64>, p: f64) -> Result<DVector<f64>, SimError> {
        match &map.param_derivative {
            Some(d) => Ok(d.clone()),
            None => self.dp(z, p),
        }
    }

    /// Pⁿ(z) alone, by a flow without the variational equations
    /// ([`StroboscopicMap::image`]).
    fn map_state(&mut self, z: &DVector<f64>, p: f64) -> Result<DVector<f64>, SimError> {
        let n = self.spec.period;
        StroboscopicMap::new(self.at(p)?, n).image(z)
    }

    /// ∂Pⁿ/∂p by central differences of flows without the variational equations (two flows
    /// whose steps are chosen alike, each a seventh of a variational flow at N = 3 for the
    /// adaptive integrator); one-sided (first order) at the edge of the parameter's valid
    /// range, so that a branch continued up to a limit (Ω = 1e5, say) never evaluates the
    /// model at a value the user did not give and the validation refuses.
    fn dp(&mut self, z: &DVector<f64>, p: f64) -> Result<DVector<f64>, SimError> {
        let d = 1e-6 * p.abs().max(1.0);
        let valid = |q: f64| self.spec.base.with(self.spec.param, q).validate().is_ok();
        match (valid(p + d), valid(p - d)) {
            (false, true) => {
                let here = self.map_state(z, p)?;
                let minus = self.map_state(z, p - d)?;
                Ok((here - minus) / d)
            }
            (true, false) => {
                let plus = self.map_state(z, p + d)?;
                let here = self.map_state(z, p)?;
                Ok((plus - here) / d)
            }
            _ => {
                let plus = self.map_state(z, p + d)?;
                let minus = self.map_state(z, p - d)?;
                Ok((plus - minus) / (2.0 * d))
            }
        }
    }

    /// Bordered Jacobian [[M − I, F_p], [tᵀ]].
    fn bordered(m: &DMatrix<f64>, fp: &DVector<f64>, t: &DVector<f64>) -> DMatrix<f64> {
        let dim = m.nrows();
        let mut j = DMatrix::zeros(dim + 1, dim + 1);
        j.view_mut((0, 0), (dim, dim))
            .copy_from(&(m - DMatrix::identity(dim, dim)));
        j.view_mut((0, dim), (dim, 1)).copy_from(fp);
        j.view_mut((dim, 0), (1, dim + 1)).copy_from(&t.transpose());
        j
    }

    /// Unit tangent of the branch from the bordered system with ∂F/∂p = `fp`, oriented along
    /// `t_old`.
    fn tangent(
        m: &DMatrix<f64>,
        fp: &DVector<f64>,
        t_old: &DVector<f64>,
    ) -> Result<DVector<f64>, SimError> {
        let dim = m.nrows();
        let mut rhs = DVector::zeros(dim + 1);
        rhs[dim] = 1.0;
        let t = Self::bordered(m, fp, t_old)
            .lu()
            .solve(&rhs)
            .ok_or(SimError::NoConvergence {
                what: "continuation tangent",
                iterations: 0,
                residual: f64::NAN,
            })?;
        Ok(t.normalize())
    }

    /// Newton corrector from the predictor; returns the converged y, its map, the iterations
    /// and ∂F/∂p at the last iterate (reused for the next tangent).
    #[allow(clippy::type_complexity)]
    fn correct(
        &mut self,
        y_pred: &DVector<f64>,
        t: &DVector<f64>,
    ) -> Result<(DVector<f64>, FlowMap, usize, DVector<f64>), SimError> {
        let dim = y_pred.len() - 1;
        let mut y = y_pred.clone();
        // ∂F/∂p of the previous iterate (finite differences are not redone at convergence)
        let mut fp_prev: Option<DVector<f64>> = None;
        // the iterates skip the grazing searches (a fifth of a map) except the one expected to
        // converge, after a correction that Newton's quadratic rate makes the last; the
        // converged point gets its distance to grazing from one pass otherwise
        let mut last_delta = f64::INFINITY;
        for it in 0..10 {
            let (z, p) = (y.rows(0, dim).into_owned(), y[dim]);
            let watched = last_delta <= 1e-7 * (1.0 + y.norm());
            let mut map = self.map(&z, p, watched)?;
            let f = &map.state - &z;
            let arc = t.dot(&(&y - y_pred));
            let res = f.norm();
            if res <= self.spec.newton.tol * (1.0 + z.norm())
                && arc.abs() <= 1e-12 * (1.0 + y.norm())
            {
                if !watched {
                    map.grazing_distance = self.grazing(&z, p)?;
                }
                let fp = match (&map.param_derivative, fp_prev) {
                    (Some(d), _) => d.clone(),
                    (None, Some(fp)) => fp,
                    (None, None) => self.dp(&z, p)?,
                };
                return Ok((y, map, it, fp));
            }
            let fp = self.dp_of(&map, &z, p)?;
            let mut g = DVector::zeros(dim + 1);
            g.rows_mut(0, dim).copy_from(&f);
            g[dim] = arc;
            let delta = Self::bordered(&map.jacobian, &fp, t)
                .lu()
                .solve(&(-g))
                .ok_or(SimError::NoConvergence {
                    what: "continuation corrector",
                    iterations: it,
                    residual: res,
                })?;
            last_delta = delta.norm();
            y += delta;
            fp_prev = Some(fp);
            if !y.iter().all(|v| v.is_finite()) {
                break;
            }
        }
        Err(SimError::NoConvergence {
            what: "continuation corrector",
            iterations: 10,
            residual: f64::NAN,
        })
    }
}

/// Whether the chord of a step from `a` to `b` passes within half its length of `point` (the
/// closure test of an isola at its first point). Testing the step's end alone can miss: the
/// ends on either side of the point are each more than half their own step away when the
/// step length has grown.
fn chord_passes(a: &DVector<f64>, b: &DVector<f64>, point: &DVector<f64>) -> bool {
    let (u, w) = (b - a, point - a);
    let along = (w.dot(&u) / u.norm_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
    (w - &u * along).norm() < 0.5 * u.norm()
}

/// Largest change of a Floquet multiplier allowed in one continuation step.
pub const MAX_MULTIPLIER_STEP: f64 = 0.25;

/// How far the multipliers moved: the largest distance from a multiplier of `b` to the nearest
/// of `a` (and vice versa).
fn multiplier_shift(a: &[Complex<f64>], b: &[Complex<f64>]) -> f64 {
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
fn tests(
    t: &DVector<f64>,
    m: &DMatrix<f64>,
    mu: &[Complex<f64>],
    switchings: usize,
) -> (f64, f64, usize, usize) {
    let dim = m.nrows();
    let pd = (m + DMatrix::identity(dim, dim)).determinant();
    let ns = mu
        .iter()
        .filter(|c| c.im.abs() > 1e-9 && c.norm() > 1.0)
        .count();
    (t[dim], pd, ns, switchings)
}

fn changed(a: &(f64, f64, usize, usize), b: &(f64, f64, usize, usize)) -> Option<BranchEvent> {
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
fn which(e: BranchEvent, t: &(f64, f64, usize, usize), a: &(f64, f64, usize, usize)) -> f64 {
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
fn smooth(e: BranchEvent) -> bool {
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
struct Bracket {
    a: f64,
    b: f64,
    fa: f64,
    fb: f64,
    secant: bool,
    /// The end kept by the last update (−1: a, +1: b, 0: none yet).
    kept: i8,
    /// The widths before the last two updates (older first).
    widths: [f64; 2],
}

impl Bracket {
    fn new(ds: f64, fa: f64, fb: f64, secant: bool) -> Self {
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

    fn width(&self) -> f64 {
        self.b - self.a
    }

    /// The next point strictly inside (a, b).
    fn next(&self) -> f64 {
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
    fn update(&mut self, x: f64, fx: f64) -> bool {
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

fn point(
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

/// Continue the period-n branch through the orbit found by shooting from `guess` at `from`.
/// Points are returned in arclength order; located bifurcations carry their label.
///
/// # Errors
/// [`SimError`] when the first orbit cannot be found or the parameters are invalid.
pub fn continue_branch(spec: &ContinuationSpec, guess: &DVector<f64>) -> Result<Branch, SimError> {
    continue_branch_with(spec, guess, &Progress::new())
}

/// [`continue_branch`] counting every branch point in `progress` (a branch's length is not
/// known ahead: the total is left as it is) and stopping when it is cancelled.
///
/// # Errors
/// As [`continue_branch`]; [`SimError::Cancelled`] once `progress` is cancelled.
pub fn continue_branch_with(
    spec: &ContinuationSpec,
    guess: &DVector<f64>,
    progress: &Progress,
) -> Result<Branch, SimError> {
    spec.base.with(spec.param, spec.from).validate()?;
    spec.base.with(spec.param, spec.to).validate()?;
    let mut solver = Solver::new(spec)?;
    let orbit = shoot_with(solver.at(spec.from)?, guess, spec.period, &spec.newton)?;
    let dim = orbit.state.len();
    let mut y = DVector::zeros(dim + 1);
    y.rows_mut(0, dim).copy_from(&orbit.state);
    y[dim] = spec.from;
    let dir = if spec.to >= spec.from { 1.0 } else { -1.0 };
    let mut t0 = DVector::zeros(dim + 1);
    t0[dim] = dir;
    let map = solver.map(&orbit.state, spec.from, true)?;
    let fp0 = solver.dp_of(&map, &orbit.state, spec.from)?;
    let mut t = Solver::tangent(&map.jacobian, &fp0, &t0)?;
    if t[dim] * dir < 0.0 {
        t = -t;
    }
    let (lo, hi) = spec
        .range
        .unwrap_or((spec.from.min(spec.to), spec.from.max(spec.to)));
    let mut s = 0.0;
    let mut ds = spec.ds;
    let mut out = vec![point(&mut solver, s, &y, &map)?];
    let mut tf = tests(&t, &map.jacobian, &out[0].multipliers, map.switchings);
    let mut mu_prev = out[0].multipliers.clone();
    let mut widest = 0.0f64;
    let first = y.clone();
    progress.tick();
    let end = loop {
        if out.len() >= spec.max_points {
            break BranchEnd::MaxPoints { value: y[dim] };
        }
        progress.check()?;
        let steps = solver.work();
        if steps > spec.max_work {
            break BranchEnd::Budget {
                value: y[dim],
                steps,
            };
        }
        let y_pred = &y + &t * ds;
        let (y_new, map_new, iters, fp_new) = match solver.correct(&y_pred, &t) {
            Ok(r) => r,
            Err(_) => {
                ds *= 0.5;
                if ds < spec.ds_min {
                    break BranchEnd::StepFloor { value: y[dim] };
                }
                continue;
            }
        };
        let t_new = Solver::tangent(&map_new.jacobian, &fp_new, &t)?;
        let mut pt = point(&mut solver, s + ds, &y_new, &map_new)?;
        let tf_new = tests(
            &t_new,
            &map_new.jacobian,
            &pt.multipliers,
            map_new.switchings,
        );
        // step control on the multipliers: a step may not move any multiplier by more than
        // MAX_MULTIPLIER_STEP, nor change the number of unstable multipliers without a located
        // event — else two crossings (of −1, say) could cancel in the test functions
        let event = changed(&tf, &tf_new);
        let unstable = |mu: &[Complex<f64>]| mu.iter().filter(|m| m.norm() > 1.0).count();
        if (multiplier_shift(&mu_prev, &pt.multipliers) > MAX_MULTIPLIER_STEP
            || (event.is_none() && unstable(&mu_prev) != unstable(&pt.multipliers)))
            && ds > 16.0 * spec.ds_min
        {
            ds *= 0.5;
            continue;
        }
        if let Some(ev) = event {
            // locate on the step from the previous point: the bracket [a, b] of arclength
            // shrunk to 1e-7 (1 + |s|), by bisection for the counts and, for the smooth test
            // functions, by the secant through the bracket's ends (Illinois)
            let f0 = which(ev, &tf, &tf);
            let mut bracket = Bracket::new(ds, f0, which(ev, &tf_new, &tf), smooth(ev));
            let mut best: Option<BranchPoint> = None;
            for _ in 0..30 {
                let mid = bracket.next();
                let Ok((ym, mm, _, fpm)) = solver.correct(&(&y + &t * mid), &t) else {
                    break;
                };
                let tm = Solver::tangent(&mm.jacobian, &fpm, &t)?;
                let mut pm = point(&mut solver, s + mid, &ym, &mm)?;
                let fm = which(
                    ev,
                    &tests(&tm, &mm.jacobian, &pm.multipliers, mm.switchings),
                    &tf,
                );
                if !bracket.update(mid, fm) {
                    pm.event = Some(ev);
                    best = Some(pm);
                }
                if bracket.width() <= 1e-7 * (1.0 + s.abs()) {
                    break;
                }
            }
            // a genuine fold has a multiplier +1; a sign change of dp/ds without one is the
            // tangent flipping across a non-smooth (grazing) point: retry with a smaller step
            let spurious_fold = ev == BranchEvent::Fold
                && best
                    .as_ref()
                    .is_none_or(|bp| bp.multipliers.iter().all(|m| (m - 1.0).norm() > 1e-2));
            if spurious_fold && ds > 16.0 * spec.ds_min {
                ds *= 0.25;
                continue;
            }
            if let Some(bp) = best {
                // the same event located again within the resolution of the location (next to
                // a junction the test function can change sign twice within 1e-4): keep one
                let again = out
                    .iter()
                    .rev()
                    .find(|b| b.event.is_some())
                    .is_some_and(|b| {
                        b.event == bp.event
                            && (b.value - bp.value).abs() < 1e-4 * (1.0 + b.value.abs())
                    });
                if !again {
                    out.push(bp);
                    progress.tick();
                }
            }
        }
        if !(lo..=hi).contains(&y_new[dim]) {
            break BranchEnd::Range;
        }
        // stop when the branch closes on itself (an isola back at its first point), or when a
        // period-2n branch has merged into a period-n orbit (its half-cycle repeats): beyond that
        // it would trace the period-n branch again
        let closed = out.len() > 10 && chord_passes(&y, &y_new, &first);
        let half = spec.period / 2;
        let half_gap = |b: &BranchPoint| {
            (&b.section[half] - &b.section[0]).norm() / (1.0 + b.section[0].norm())
        };
        // a fold at a parent's period doubling where the half-cycle nearly repeats is the tip of
        // the pitchfork at which the period-2n branch meets its parent (the gap closes like
        // √|Δp|): beyond it the branch is its own phase-shifted copy
        widest = widest.max(half_gap(&pt));
        let at_parent = out.last().is_some_and(|b| {
            b.event == Some(BranchEvent::Fold)
                && half_gap(b) < 0.05 * widest
                && spec
                    .junctions
                    .iter()
                    .any(|j| (j - b.value).abs() <= 1e-4 * (1.0 + j.abs()))
        });
        let merged =
            spec.period.is_multiple_of(2) && out.len() > 3 && (half_gap(&pt) < 1e-6 || at_parent);
        if merged && at_parent {
            // the junction is the parent's period doubling, seen from the period-2n branch; a
            // period doubling located within 1e-4 before it is the same point
            let k = out.len() - 1;
            let at = out[k].value;
            out[k].event = Some(BranchEvent::PeriodDoubling);
            for b in out[..k].iter_mut().rev().take(4) {
                if b.event == Some(BranchEvent::PeriodDoubling)
                    && (b.value - at).abs() < 1e-4 * (1.0 + at.abs())
                {
                    b.event = None;
                }
            }
        }
        s += ds;
        pt.s = s;
        out.push(pt);
        progress.tick();
        if closed {
            break BranchEnd::Closed;
        }
        if merged {
            break BranchEnd::Merged;
        }
        mu_prev = out.last().expect("a point").multipliers.clone();
        y = y_new;
        t = t_new;
        tf = tf_new;
        ds = if iters <= 2 {
            (ds * 1.5).min(spec.ds_max)
        } else if iters >= 5 {
            ds * 0.5
        } else {
            ds
        };
    };
    Ok(Branch { points: out, end })
}

#[cfg(test)]
mod tests {
    use super::{chord_passes, Bracket};
    use nalgebra::DVector;

    /// Shrink a bracket of [0, w] on f to `tol` as the continuation does; the evaluations and
    /// the final bracket.
    fn locate(f: impl Fn(f64) -> f64, w: f64, secant: bool, tol: f64) -> (usize, f64, f64) {
        let mut br = Bracket::new(w, f(0.0), f(w), secant);
        let mut evals = 0;
        while br.width() > tol && evals < 200 {
            let x = br.next();
            assert!(x > br.a && x < br.b, "{x} outside ({}, {})", br.a, br.b);
            br.update(x, f(x));
            evals += 1;
        }
        (evals, br.a, br.b)
    }

    /// The Illinois bracket holds the root of a smooth function, cos s − 0.3 on [0, 2] (root
    /// acos 0.3), and a fold-like quadratic zero-crossing t_p ∝ s* − s, within 1e-7 in far
    /// fewer evaluations than the 25 of bisection; on a jump (the sign change of dp/ds at a
    /// non-smooth point) it needs at most twice bisection's.
    #[test]
    fn the_illinois_bracket_converges_and_keeps_the_root() {
        let root = 0.3f64.acos();
        let (n, a, b) = locate(|s| s.cos() - 0.3, 2.0, true, 1e-7);
        assert!(a <= root && root <= b, "[{a}, {b}] misses {root}");
        assert!(n <= 10, "{n} evaluations");
        let (n, a, b) = locate(|s| (0.731 - s) * (1.0 + s * s), 1.0, true, 1e-7);
        assert!(a <= 0.731 && 0.731 <= b, "[{a}, {b}]");
        assert!(n <= 10, "{n} evaluations");
        let (bisect, _, _) = locate(|s| if s < 0.3 { 1.0 } else { -1.0 }, 2.0, false, 1e-7);
        let (n, a, b) = locate(|s| if s < 0.3 { 1.0 } else { -1.0 }, 2.0, true, 1e-7);
        assert!(a < 0.3 && 0.3 <= b, "[{a}, {b}]");
        assert!(n <= 2 * bisect, "{n} evaluations, bisection {bisect}");
    }

    /// The isola's first point at the origin, the last two steps of the loop ending 0.4 before
    /// it (a step of 0.5) and 0.6 after it (a step of 1): each end is more than half its own
    /// step away, the chord passes through it. A chord that passes 0.6 step lengths away, or
    /// whose ends both lie on one side beyond it, does not close.
    #[test]
    fn closure_on_the_chord() {
        let v = |x: f64, y: f64| DVector::from_vec(vec![x, y]);
        let first = v(0.0, 0.0);
        assert!(chord_passes(&v(-0.4, 0.0), &v(0.6, 0.0), &first));
        assert!(!chord_passes(&v(-0.4, 0.6), &v(0.6, 0.6), &first));
        assert!(!chord_passes(&v(0.6, 0.0), &v(1.6, 0.0), &first));
    }
}
