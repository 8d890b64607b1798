//! The measured contraction of a settling point's stroboscopic returns ([`super::settle`]):
//! whether the returns' period test could still succeed before the free decay's wait ends, or
//! the motion shows no approach to a period of at most `max_period` and its time average may
//! be taken as soon as its windows agree.
//!
//! **The rule.** Over each run of returns z_0, z_1, … (one per drive period) the spread of lag
//! m (1 ≤ m ≤ `max_period`) is s_m = max_k ‖z_k − z_{k−m}‖ / (1 + ‖z_k‖), the quantity the
//! period test compares with its tolerance `tol` (`crate::analysis::period::close`). A
//! motion going to a period-m orbit has returns whose lag-m differences contract
//! geometrically, by a ratio r = s_m(now)/s_m(before) over the D drive periods between two
//! runs' starts; at that ratio they fall below `tol` after
//!
//!   P_m = D ln(s_m/tol) / ln(1/r)
//!
//! more periods (the geometric series of the differences still ahead: their sum, the
//! transient left, is at most s_m/(1 − r^{m/D}), and each is r^{P/D} of the last after P
//! periods). When no lag's P_m falls within what is left of the free decay's wait (ln(1/tol)
//! Q/π periods at resonance, `crate::analysis::steady::decay_periods`) in [`STALLED_RUNS`]
//! successive runs, the period test cannot succeed before that wait ends, and the wait is
//! over: the returns' differences have stopped contracting (the irregular taps and missed taps
//! of a grazing JKR contact, whose returns stay ~1e-4 apart however long the motion runs) or
//! contract too slowly. A lag whose spread is within `tol`, or whose contraction cannot be
//! measured (a spread of zero or not finite, a first run), keeps the wait: it ends at the free
//! decay as before. A point whose windows agreed while only unmeasured runs (not a first run)
//! kept the wait — had they counted as stalled, it would have been settled there — is flagged
//! ([`super::CurvePoint::free_decay_wait`]) and counted in the curve's warnings
//! ([`super::SteppedCurve::warnings`]): its values are right, it only took longer. On the issue
//! 60 image line (RTESPA-300, Q = 500, over E_s = 100 MPa, W = 0.05 J/m²) the transient reaches
//! the floor of ~1e-4 within the Newton attempts' 1 000 periods, and the wait ends with the
//! windows' agreement instead of at the free decay's 2 930 periods: the line's averaged points
//! take about half the periods (3 080 before) and the line 2.6 s of CPU instead of 5.8 s, 1.8×
//! the line with a DMT stripe (docs/contact-laws.md).

use nalgebra::DVector;
use std::collections::VecDeque;

/// Successive runs of returns whose contraction must end the wait (module docs) before a
/// motion is settled by its time average early: two, so that one run whose spreads happen to
/// stall while the taps lock into a period does not (on the issue 60 line, a period-7 orbit
/// found 27 periods after one stalled run).
pub const STALLED_RUNS: usize = 2;

/// How long [`super::settle`] waits before a motion may be settled by its time average.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SettleWait {
    /// Until the slowest free mode has decayed by the period test's tolerance, or earlier
    /// when the returns' measured contraction shows the period test cannot succeed before
    /// then (module docs).
    #[default]
    Contraction,
    /// Until the slowest free mode has decayed by the period test's tolerance
    /// (`crate::analysis::steady::decay_periods`) whatever the returns do.
    FreeDecay,
}

/// The spreads s_m of one run of returns (module docs), m = 1..=`max_period`.
#[derive(Debug, Clone)]
pub(crate) struct Spread {
    recent: VecDeque<DVector<f64>>,
    max_period: usize,
    spreads: Vec<f64>,
}

impl Spread {
    /// A run starting at the return `first`.
    pub(crate) fn new(max_period: usize, first: &DVector<f64>) -> Self {
        let mut recent = VecDeque::with_capacity(max_period + 1);
        recent.push_back(first.clone());
        Spread {
            recent,
            max_period,
            spreads: vec![0.0; max_period],
        }
    }

    /// Account for the next return.
    pub(crate) fn push(&mut self, z: &DVector<f64>) {
        let scale = 1.0 + z.norm();
        for (j, past) in self.recent.iter().rev().enumerate() {
            let d = (z - past).norm() / scale;
            // NaN keeps the spread unmeasurable (it is not > the spread)
            if d > self.spreads[j] || d.is_nan() {
                self.spreads[j] = d;
            }
        }
        if self.recent.len() == self.max_period {
            self.recent.pop_front();
        }
        self.recent.push_back(z.clone());
    }

    /// s_m for m = 1..=`max_period` (0 for a lag longer than the run).
    pub(crate) fn spreads(&self) -> &[f64] {
        &self.spreads
    }
}

/// What one run's spreads say of the wait for the period test (module docs), lag by lag.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Verdict {
    /// No lag reaches `tol` in time: the wait may end.
    Over,
    /// A lag is within `tol`, or its measured contraction reaches it in time: the wait goes on.
    Keep,
    /// No lag keeps the wait by its measured contraction, but one cannot be measured (a spread
    /// of zero or not finite): the wait goes on, to the free decay.
    Unmeasured,
}

/// The verdict of a run (module docs): each lag m whose spread went from `before[m−1]` to
/// `now[m−1]` over `distance` drive periods is within `tol`, reaches it within `left` more
/// periods at that ratio (both keep the wait), does not (over), or cannot be measured (a
/// spread of zero or not finite); the run keeps the wait if one lag does, else it is
/// unmeasured if one lag is, else over.
pub(crate) fn verdict(before: &[f64], now: &[f64], distance: f64, tol: f64, left: f64) -> Verdict {
    let mut unmeasured = false;
    for (&a, &b) in before.iter().zip(now) {
        if b.is_finite() && b <= tol {
            return Verdict::Keep;
        }
        if !(a.is_finite() && b.is_finite() && a > 0.0) {
            unmeasured = true;
            continue;
        }
        let ratio = b / a;
        // a lag that does not contract never reaches tol
        if ratio < 1.0 && distance * (b / tol).ln() / (1.0 / ratio).ln() <= left {
            return Verdict::Keep;
        }
    }
    if unmeasured {
        Verdict::Unmeasured
    } else {
        Verdict::Over
    }
}

/// The account of one settling point's runs ([`super::settle`]): whether their measured
/// contraction ended the wait ([`STALLED_RUNS`] runs in a row over), and whether runs whose
/// contraction could not be measured ([`Verdict::Unmeasured`]) kept it where the windows of
/// the time average had agreed: had they counted as over, the wait would have ended there
/// ([`ContractionWait::held`]).
#[derive(Debug, Clone, Default)]
pub(crate) struct ContractionWait {
    /// The previous run's spreads.
    before: Option<Vec<f64>>,
    /// Runs in a row whose contraction ended the wait.
    stalled: usize,
    /// Runs in a row whose contraction ended the wait or could not be measured.
    stalled_or_unmeasured: usize,
    /// The windows agreed before the free decay's wait ended where only unmeasured runs kept
    /// it.
    held: bool,
}

impl ContractionWait {
    /// Account for a run whose spreads are `now` (its [`Verdict`] against the previous run's:
    /// none for a first run, nor without `measure`, [`SettleWait::FreeDecay`]); `distance`,
    /// `tol` and `left` as in [`verdict`].
    pub(crate) fn run(&mut self, now: Vec<f64>, measure: bool, distance: f64, tol: f64, left: f64) {
        if let (true, Some(b)) = (measure, &self.before) {
            match verdict(b, &now, distance, tol, left) {
                Verdict::Over => {
                    self.stalled += 1;
                    self.stalled_or_unmeasured += 1;
                }
                Verdict::Unmeasured => {
                    self.stalled = 0;
                    self.stalled_or_unmeasured += 1;
                }
                Verdict::Keep => {
                    self.stalled = 0;
                    self.stalled_or_unmeasured = 0;
                }
            }
        }
        self.before = Some(now);
    }

    /// The runs' measured contraction ended the wait.
    pub(crate) fn over(&self) -> bool {
        self.stalled >= STALLED_RUNS
    }

    /// The windows of the time average agreed while the wait goes on: note whether only runs
    /// that could not be measured keep it.
    pub(crate) fn agreed(&mut self) {
        if !self.over() && self.stalled_or_unmeasured >= STALLED_RUNS {
            self.held = true;
        }
    }

    /// The point waited for the free decay because its returns' contraction could not be
    /// measured: [`ContractionWait::agreed`] found only unmeasured runs keeping the wait, and
    /// the measured contraction did not end it since.
    pub(crate) fn held(&self) -> bool {
        self.held && !self.over()
    }
}

/// The curve's warning for its points that waited for the free decay because their returns'
/// contraction could not be measured ([`ContractionWait::held`],
/// [`super::CurvePoint::free_decay_wait`]): correct, only slower. `None` when there are none.
pub(crate) fn free_decay_warning<'a>(
    points: impl Iterator<Item = &'a super::CurvePoint>,
) -> Option<String> {
    let k = points.filter(|p| p.free_decay_wait).count();
    (k > 0).then(|| {
        warning!(
            "curve.free-decay",
            "Nothing: those points are right, only slower to compute.",
            "{k} point(s) waited for the free decay (their returns' contraction could not be \
             measured): they were settled by their time average only after the slowest free \
             mode decayed to the period test's tolerance, not as soon as their windows agreed \
             (correct, only slower)"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn z(x: f64, y: f64) -> DVector<f64> {
        DVector::from_vec(vec![x, y])
    }

    /// The spread of lag m is the largest relative difference of returns m apart: on a
    /// period-2 sequence lag 2 is 0 and lag 1 its jump.
    #[test]
    fn spreads_of_a_period_two_sequence() {
        let mut s = Spread::new(3, &z(1.0, 0.0));
        for k in 1..10 {
            s.push(&z(if k % 2 == 0 { 1.0 } else { -1.0 }, 0.0));
        }
        assert_eq!(s.spreads()[1], 0.0);
        assert_eq!(s.spreads()[0], 1.0);
        assert_eq!(s.spreads()[2], 1.0);
    }

    /// A geometric contraction that reaches the tolerance within what is left keeps the wait;
    /// one that would take longer, a stalled spread and a growing one end it; a lag within
    /// the tolerance keeps it; an unmeasured lag (a spread of zero or not finite) keeps it as
    /// unmeasured, unless another lag keeps it by its contraction.
    #[test]
    fn the_wait_ends_only_when_no_lag_can_reach_the_tolerance() {
        use Verdict::{Keep, Over, Unmeasured};
        // 1e-3 → 3.7e-4 over 160 periods (free decay at Q = 500): 1e-8 after ~1 840 more
        let (a, b) = (1e-3, 1e-3 * (-1.0f64).exp());
        assert_eq!(verdict(&[a], &[b], 160.0, 1e-8, 2000.0), Keep);
        assert_eq!(verdict(&[a], &[b], 160.0, 1e-8, 1500.0), Over);
        assert_eq!(
            verdict(&[1e-4, 2e-4], &[1e-4, 3e-4], 160.0, 1e-8, 1e6),
            Over
        );
        assert_eq!(
            verdict(&[1e-4, 1e-4], &[1e-4, 1e-9], 160.0, 1e-8, 0.0),
            Keep
        );
        assert_eq!(
            verdict(&[1e-4, 0.0], &[1e-4, 1e-4], 160.0, 1e-8, 0.0),
            Unmeasured
        );
        let nan = [1e-4, f64::NAN];
        assert_eq!(verdict(&nan, &[1e-4, 1e-4], 160.0, 1e-8, 0.0), Unmeasured);
        assert_eq!(verdict(&[1e-4, 1e-4], &nan, 160.0, 1e-8, 0.0), Unmeasured);
        // a lag that keeps the wait by its contraction outweighs an unmeasured one
        assert_eq!(verdict(&[0.0, a], &[1e-4, b], 160.0, 1e-8, 2000.0), Keep);
    }

    /// The runs of one point (spreads of one lag, 160 periods apart, tolerance 1e-8): a stalled
    /// spread ends the wait after [`STALLED_RUNS`] runs; unmeasured runs (a spread that is not
    /// finite) keep it, and where the windows agree then the point is held by them alone — until
    /// the measured contraction ends the wait after all; a run whose contraction reaches the
    /// tolerance in time is no hold; a first run and the free decay's wait measure nothing.
    #[test]
    fn a_point_is_held_only_by_runs_that_could_not_be_measured() {
        let runs = |spreads: &[f64], measure: bool| {
            let mut w = ContractionWait::default();
            for &s in spreads {
                w.run(vec![s], measure, 160.0, 1e-8, 2000.0);
                w.agreed();
            }
            w
        };
        // stalled at 1e-4: over after the second verdict (the third run), no hold
        let w = runs(&[1e-4, 1e-4, 1e-4], true);
        assert!(w.over() && !w.held());
        assert!(!runs(&[1e-4, 1e-4], true).over());
        // a spread that is not finite between stalled ones: two unmeasured runs, not over,
        // held where the windows agreed
        let w = runs(&[1e-4, f64::NAN, 1e-4], true);
        assert!(!w.over() && w.held());
        // one stalled and one unmeasured run hold it too
        assert!(runs(&[1e-4, 1e-4, f64::NAN], true).held());
        // …until two measured stalled runs end the wait after all
        let w = runs(&[1e-4, f64::NAN, 1e-4, 1e-4, 1e-4], true);
        assert!(w.over() && !w.held());
        // a contraction that reaches the tolerance in time keeps the wait: no hold
        let fast = [1e-3, 1e-3 * (-1.0f64).exp(), 1e-3 * (-2.0f64).exp()];
        let w = runs(&fast, true);
        assert!(!w.over() && !w.held());
        // the free decay's wait measures nothing
        let w = runs(&[1e-4, f64::NAN, 1e-4, 1e-4], false);
        assert!(!w.over() && !w.held());
        // a first run has no verdict
        let w = runs(&[1e-4], true);
        assert!(!w.over() && !w.held());
    }

    /// The curve's warnings count the points that waited for the free decay (here flagged by
    /// hand on a sweep of a point mass far from the sample, which never does: no warning
    /// before), once; the store keeps the flag and omits it where false.
    #[test]
    fn the_curve_warns_once_of_the_points_that_waited_for_the_free_decay() {
        use super::super::{finish_curve, stepped_sweep, CurvePoint, SteppedCurve, SteppedSpec};
        use crate::analysis::progress::Progress;
        use crate::params::{Params, Structure, SweepParam};
        let p = Params {
            structure: Structure::PointMass,
            modes: 1,
            alpha1: 0.0,
            alpha3: 1.0 / 42.0,
            omega: 1.0,
            alpha5: 10.0,
            ..Params::default()
        };
        let mut spec = SteppedSpec::new(p, SweepParam::Alpha5, vec![10.0, 10.01, 10.02]);
        spec.branches = false;
        let curve = stepped_sweep(&spec).unwrap();
        let held = |c: &SteppedCurve| -> Vec<String> {
            c.warnings
                .iter()
                .filter(|w| w.contains("waited for the free decay"))
                .cloned()
                .collect()
        };
        assert!(held(&curve).is_empty(), "{:?}", curve.warnings);
        let (mut first, second) = (curve.first.clone(), curve.second.clone());
        assert!(first.iter().chain(&second).all(|p| !p.free_decay_wait));
        first[1].free_decay_wait = true;
        first[2].free_decay_wait = true;
        let c = finish_curve(&spec, first.clone(), second, &Progress::new()).unwrap();
        let w = held(&c);
        assert_eq!(w.len(), 1, "{:?}", c.warnings);
        assert!(
            w[0].starts_with(
                "2 point(s) waited for the free decay (their returns' contraction could not be \
                 measured)"
            ),
            "{}",
            w[0]
        );
        let stored = serde_json::to_string(&first[1]).unwrap();
        assert!(stored.contains("\"free_decay_wait\":true"), "{stored}");
        assert_eq!(
            serde_json::from_str::<CurvePoint>(&stored).unwrap(),
            first[1]
        );
        let plain = serde_json::to_string(&first[0]).unwrap();
        assert!(!plain.contains("free_decay_wait"), "{plain}");
        assert_eq!(
            serde_json::from_str::<CurvePoint>(&plain).unwrap(),
            first[0]
        );
    }
}
