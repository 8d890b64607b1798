//! The exact propagator's propagation paths (issue 11): the modal (eigenbasis) grid steps and
//! the fixed-size dense kernel against the dense Φ_s path, the fallback to the dense path for an
//! ill-conditioned eigenvector basis, `advance` against the observed step loop, and the reuse
//! of earlier builds.
//!
//! The reference is the dense path: Φ_s = e^{A_s h} by scaling and squaring, an independent
//! computation from the eigendecomposition the modal path uses. Orbits are taken on stable
//! periodic attractors (Ω = 3.5 and 5) so that round-off differences decay instead of growing as
//! they would on the chaotic attractor at Ω = 2.6.

use super::common;

use afmdyn::galerkin::Region;
use afmdyn::integrate::exact::{ExactOptions, ExactPropagator, Propagation, PropagatorCache};
use afmdyn::integrate::{
    advance, advance_dyn, advance_observed, Integrator, Observed, Observer, Spans, Step,
    SwitchEvent,
};
use afmdyn::model::weighted_displacement;
use afmdyn::SimError;
use afmdyn::{CantileverModel, Params};
use common::{events_until, harmonic_response};
use nalgebra::DVector;

fn prop(
    m: &CantileverModel,
    propagation: Propagation,
    cache: Option<&PropagatorCache>,
) -> ExactPropagator {
    ExactPropagator::try_with(
        m,
        ExactOptions {
            propagation,
            cache: cache.cloned(),
            ..ExactOptions::default()
        },
    )
    .unwrap()
}

/// The default parameters with `modes` modes, and their model.
fn default_model(modes: usize) -> (Params, CantileverModel) {
    let p = Params {
        modes,
        ..Params::default()
    };
    (p, CantileverModel::new(&p).unwrap())
}

/// The paths the tests on the chaotic attractor run: dense (N = 3) and modal (N = 3, 10).
const PATHS: [(usize, Propagation); 3] = [
    (3, Propagation::Dense),
    (3, Propagation::Auto),
    (10, Propagation::Auto),
];

/// Relative difference ‖a − b‖∞ / (1 + ‖b‖∞).
fn rel(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).amax() / (1.0 + b.amax())
}

/// Run both propagators from (0, z0) to `tau_end`, comparing every event (time, direction,
/// state) and the final state to `tol` relative; returns the number of events.
fn compare_runs(
    a: &mut ExactPropagator,
    b: &mut ExactPropagator,
    z0: &DVector<f64>,
    tau_end: f64,
    tol: f64,
) -> usize {
    a.reset(0.0, z0).unwrap();
    b.reset(0.0, z0).unwrap();
    let ea: Vec<SwitchEvent> = events_until(a, tau_end);
    let eb: Vec<SwitchEvent> = events_until(b, tau_end);
    assert_eq!(ea.len(), eb.len(), "event counts differ");
    for (x, y) in ea.iter().zip(&eb) {
        assert_eq!((x.from, x.to), (y.from, y.to));
        assert!(
            (x.tau - y.tau).abs() <= tol * (1.0 + y.tau.abs()),
            "event at {} vs {}",
            x.tau,
            y.tau
        );
        assert!(rel(&x.state, &y.state) <= tol, "event state");
    }
    let d = rel(a.state(), b.state());
    assert!(d <= tol, "final states differ by {d:e}");
    ea.len()
}

/// Modal grid steps (N = 3, 8 and 10, the automatic choice) agree with the dense Φ_s path to
/// 1e-12 over 40 periods of an impacting period-1 orbit: every switching and the final state.
#[test]
fn modal_path_agrees_with_the_dense_path() {
    for (modes, omega) in [(3usize, 3.5), (3, 5.0), (8, 3.5), (10, 3.5)] {
        let p = Params {
            modes,
            omega,
            ..Params::default()
        };
        let m = CantileverModel::new(&p).unwrap();
        let mut dense = prop(&m, Propagation::Dense, None);
        let mut modal = prop(&m, Propagation::Auto, None);
        assert_eq!(dense.modal_regions(), [false, false]);
        assert_eq!(modal.modal_regions(), [true, true], "N = {modes}");
        let events = compare_runs(&mut dense, &mut modal, &m.rest(), 40.0 * p.period(), 1e-12);
        assert!(
            events >= 40,
            "N = {modes}, Ω = {omega}: {events} switchings"
        );
    }
}

/// A grazing contact — the tip dips 1e-6 below the sample for a sliver far shorter than a grid
/// step (the construction of `integrators.rs`) — is found by both paths at the same time.
#[test]
fn modal_path_finds_the_same_grazing_contact() {
    for modes in [3usize, 8] {
        let p0 = Params {
            modes,
            alpha5: 10.0,
            ..Params::default()
        };
        let m0 = CantileverModel::new(&p0).unwrap();
        // amplitude of the free periodic tip motion (V_T − α5) from its minimum on a fine grid
        let n = 4096;
        let r_amp = -(0..n)
            .map(|k| {
                let t = p0.period() * k as f64 / n as f64;
                m0.v_t(t, &harmonic_response(&m0, Region::Free, t)) - 10.0
            })
            .fold(f64::INFINITY, f64::min);
        let p = Params {
            alpha5: r_amp - 1e-6,
            ..p0
        };
        let m = CantileverModel::new(&p).unwrap();
        let z0 = harmonic_response(&m, Region::Free, 0.0);
        let mut dense = prop(&m, Propagation::Dense, None);
        let mut modal = prop(&m, Propagation::Auto, None);
        assert!(modal.modal_regions()[0]);
        let events = compare_runs(&mut dense, &mut modal, &z0, 3.0 * p.period(), 1e-12);
        assert!(events >= 2, "N = {modes}: grazing contact missed");
    }
}

/// Critical damping of the single mode (α3² = 4 k m, a double eigenvalue with one eigenvector)
/// makes the eigenvector basis of the free region singular: modal propagation is refused there
/// and the dense path used, while the contact region (stiffer, not critical) stays modal; the
/// run agrees with the all-dense one.
#[test]
fn ill_conditioned_basis_falls_back_to_dense() {
    let p0 = Params {
        modes: 1,
        ..Params::default()
    };
    let m0 = CantileverModel::new(&p0).unwrap();
    assert_eq!(
        prop(&m0, Propagation::Auto, None).modal_regions(),
        [true, true]
    );
    let g = m0.galerkin().region(Region::Free);
    let (k, mass) = (g.stiffness[(0, 0)], g.mass[(0, 0)]);
    let p = Params {
        alpha3: 2.0 * (k * mass).sqrt(),
        omega: 3.5,
        ..p0
    };
    let m = CantileverModel::new(&p).unwrap();
    // the free region's state matrix has a double eigenvalue −α3/(2m)
    let a = &m.dynamics(Region::Free).a;
    let disc = (a[(1, 1)] * a[(1, 1)] + 4.0 * a[(1, 0)]) / (a[(1, 1)] * a[(1, 1)]);
    assert!(disc.abs() < 1e-12, "not critically damped: {disc:e}");
    let mut modal = prop(&m, Propagation::Auto, None);
    assert_eq!(modal.modal_regions(), [false, true]);
    let mut dense = prop(&m, Propagation::Dense, None);
    compare_runs(&mut dense, &mut modal, &m.rest(), 20.0 * p.period(), 1e-12);
}

/// `advance` (the plain state formed only at events and at the end; whole grid steps that pass
/// the certified test in one tight loop) reaches bit for bit the state of the observed step
/// loop, on the modal path (N = 3 and 10) and the dense one (N = 3), on the chaotic attractor at
/// Ω = 2.6 — ending off the grid, on a grid point inside a period and at a period end; its last
/// step (dense output, step Jacobian) is the step loop's, and the next steps continue
/// identically.
#[test]
fn advance_equals_the_step_loop() {
    for (modes, path) in PATHS {
        let (p, m) = default_model(modes);
        let steps = prop(&m, path, None).steps_per_period() as f64;
        for periods in [30.5, 30.0 + 7.0 / steps, 30.0] {
            let mut a = prop(&m, path, None);
            let mut b = prop(&m, path, None);
            assert_eq!(a.modal_regions()[0], path == Propagation::Auto);
            a.reset(0.0, &m.rest()).unwrap();
            b.reset(0.0, &m.rest()).unwrap();
            let tau_end = periods * p.period();
            advance(&mut a, tau_end).unwrap();
            advance_dyn(&mut b, tau_end, &mut |_, _, _| Ok(())).unwrap();
            let at = format!("N = {modes}, {path:?}, {periods} periods");
            assert_eq!(a.tau(), b.tau(), "{at}");
            assert_eq!(a.region(), b.region(), "{at}");
            assert_eq!(a.state(), b.state(), "{at}");
            // the same last step: dense output inside it and its Jacobian
            let mid = tau_end - 0.3 * p.period() / steps;
            assert_eq!(a.dense_state(mid), b.dense_state(mid), "{at}");
            assert_eq!(a.dense_v_t(mid), b.dense_v_t(mid), "{at}");
            assert_eq!(
                a.last_step_jacobian().unwrap(),
                b.last_step_jacobian().unwrap(),
                "{at}"
            );
            // and the next steps continue identically
            for _ in 0..3 {
                a.step(f64::INFINITY).unwrap();
                b.step(f64::INFINITY).unwrap();
                assert_eq!(a.state(), b.state(), "{at}");
            }
            advance(&mut a, tau_end + 5.0 * p.period()).unwrap();
            advance_dyn(&mut b, tau_end + 5.0 * p.period(), &mut |_, _, _| Ok(())).unwrap();
            assert_eq!(a.state(), b.state(), "{at}");
        }
    }
}

/// At every step of [`advance_observed`]: the tip values and the displacement bound read before
/// the plain state is formed, and the step itself.
#[derive(Default)]
struct Probe {
    steps: Vec<Step>,
    /// Largest relative difference of [W, Ẇ, V_T, V̇_T] from those formed from the state.
    worst_tip: f64,
    /// Steps whose W differs in its bits from the one formed (read from the modal coordinates).
    modal_reads: usize,
    /// Smallest bound / formed Σ c_j |a_j| (≥ 1 for a sound bound), over the tightest bound
    /// and the loosest the integrator may return.
    tightest: f64,
    /// Steps where the loosest bound (the stint's, in a modal region) differs from the tightest.
    loose_reads: usize,
    /// Steps where the loosest bound is below the tightest (never, for the bounds of one state).
    loose_below: usize,
    weights: Vec<f64>,
}

impl Observer for Probe {
    fn step(&mut self, it: &mut Observed<'_>, st: &Step) -> Result<(), SimError> {
        let tip = it.tip_values();
        let bound = it.displacement_bound(&self.weights, 0.0);
        let loose = it.displacement_bound(&self.weights, f64::INFINITY);
        let tau = it.tau();
        let z = it.state().clone();
        let formed = it.system().tip_values(tau, &z);
        for (a, b) in tip.iter().zip(formed) {
            self.worst_tip = self.worst_tip.max((a - b).abs() / (1.0 + b.abs()));
        }
        self.modal_reads += usize::from(tip[0].to_bits() != formed[0].to_bits());
        let sum = weighted_displacement(&self.weights, z.as_slice());
        self.tightest = self.tightest.min(bound.min(loose) * (1.0 + 1e-9) / sum);
        self.loose_reads += usize::from(loose != bound);
        self.loose_below += usize::from(loose < bound);
        self.steps.push(st.clone());
        Ok(())
    }
}

/// [`advance_observed`] takes the steps of the observed step loop ([`advance_dyn`]) bit for bit
/// and ends at its state, though the plain state is formed only when the observer asks; what
/// it reads before that — the tip values (eq. 8 and 9) and the bound of Σ c_j |a_j| — agree
/// with the state formed: the tip values to round-off, the bound never below the sum (so the
/// body-contact test it spares gives the same answer), neither the tightest nor the one formed
/// once per stint. Modal (N = 1, 3, 10, 20) and dense paths, on the attractor at Ω = 2.6 over
/// 10 periods, and a motion that never touches the sample (α2 = 0.01 and a gap α5 = 1: one
/// stint over all 10 periods, whose bound is formed again after each period).
#[test]
fn observed_steps_read_the_modal_coordinates_soundly() {
    for (modes, path, (alpha2, alpha5)) in [
        (1usize, Propagation::Auto, (0.1, 0.0)),
        (3, Propagation::Auto, (0.1, 0.0)),
        (3, Propagation::Dense, (0.1, 0.0)),
        (10, Propagation::Auto, (0.1, 0.0)),
        (20, Propagation::Auto, (0.1, 0.0)),
        (10, Propagation::Auto, (0.01, 1.0)),
    ] {
        let p = Params {
            modes,
            alpha2,
            alpha5,
            ..Params::default()
        };
        let m = CantileverModel::new(&p).unwrap();
        let (mut a, mut b) = (prop(&m, path, None), prop(&m, path, None));
        for x in [&mut a, &mut b] {
            x.reset(0.0, &m.rest()).unwrap();
            advance(x, 40.0 * p.period()).unwrap();
        }
        let tau_end = 50.0 * p.period();
        let mut want = Vec::new();
        advance_dyn(&mut b, tau_end, &mut |_, st, _| {
            want.push(st.clone());
            Ok(())
        })
        .unwrap();
        let mut probe = Probe {
            tightest: f64::INFINITY,
            weights: (1..=modes).map(|j| 1.0 / j as f64).collect(),
            ..Probe::default()
        };
        advance_observed(&mut a, tau_end, &mut probe).unwrap();
        let at = format!("N = {modes}, {path:?}, α2 = {alpha2}");
        assert_eq!(probe.steps, want, "{at}");
        assert_eq!(a.state(), b.state(), "{at}");
        let touching = probe.steps.iter().any(|s| s.event.is_some());
        assert_eq!(touching, alpha5 == 0.0, "{at}");
        // (7e-14 at N = 20: sin Ωτ from the grid's table against sin of Ωτ ≈ 300 formed)
        assert!(
            probe.worst_tip <= 1e-12,
            "{at}: tip values {}",
            probe.worst_tip
        );
        assert!(
            probe.tightest >= 1.0,
            "{at}: bound / sum {}",
            probe.tightest
        );
        assert_eq!(probe.loose_below, 0, "{at}");
        if path == Propagation::Auto {
            assert!(
                probe.modal_reads > 0,
                "{at}: read from the modal coordinates"
            );
            assert!(probe.loose_reads > 0, "{at}: the stint's bound");
        }
    }
}

/// A build that reuses earlier builds (same matrices; or the same region matrices after a
/// change of Ω, α2 and α5) propagates bit for bit as a fresh build; a change of Ω alone keeps
/// the spectral data and redoes the grid exponential and the forcing data, a change of α2 or
/// α5 redoes the forcing data only, a change of α4 redoes all three.
#[test]
fn reused_builds_propagate_as_fresh_ones() {
    let p = Params {
        alpha1: 0.137,
        ..Params::default()
    };
    let cache = PropagatorCache::new();
    let reused = |q: Params| {
        let m = CantileverModel::new(&q).unwrap();
        prop(&m, Propagation::Auto, Some(&cache)).reused()
    };
    assert_eq!(reused(p), (false, false, false));
    assert_eq!(reused(p), (true, true, true));
    assert_eq!(reused(Params { omega: 2.61, ..p }), (true, false, false));
    assert_eq!(reused(Params { alpha2: 0.11, ..p }), (true, true, false));
    assert_eq!(reused(Params { alpha5: 0.02, ..p }), (true, true, false));
    assert_eq!(reused(Params { alpha4: 21.0, ..p }), (false, false, false));
    // forcing data above 2 MiB (N = 20 at 7000 steps per period: 2.2 MiB) is not kept
    let big = CantileverModel::new(&Params { modes: 20, ..p }).unwrap();
    let opts = ExactOptions {
        min_steps_per_period: 7000,
        cache: Some(cache.clone()),
        ..ExactOptions::default()
    };
    let _ = ExactPropagator::try_with(&big, opts.clone()).unwrap();
    let again = ExactPropagator::try_with(&big, opts).unwrap();
    assert_eq!(again.steps_per_period(), 7000);
    assert_eq!(again.reused(), (true, true, false));

    for q in [
        p,
        Params {
            omega: 2.7,
            alpha2: 0.12,
            alpha5: -0.01,
            ..p
        },
    ] {
        let m = CantileverModel::new(&q).unwrap();
        let mut fresh = prop(&m, Propagation::Auto, None);
        let _ = prop(&m, Propagation::Auto, Some(&cache));
        let mut reused = prop(&m, Propagation::Auto, Some(&cache));
        for it in [&mut fresh, &mut reused] {
            it.reset(0.0, &m.rest()).unwrap();
            advance(it, 20.0 * q.period()).unwrap();
        }
        assert_eq!(fresh.state(), reused.state());
        assert_eq!(
            fresh.transition(Region::Contact, 0.1),
            reused.transition(Region::Contact, 0.1)
        );
    }
}

/// The dense output of every step — the tip series the switching search builds, or the one
/// built on demand (centred at the middle of a whole modal grid step, from the modal
/// coordinates there; from the start otherwise) — is the tip of the dense state formed in plain
/// coordinates (`dense_state`, e^{A t} from the eigendecomposition or Φ): W, ∂W/∂τ and V_T
/// (eq. 8) to 1e-13, at five points of each step over two periods on the attractor (whole
/// and partial grid steps, steps cut by a switching, and the last step of a run of
/// `advance`), modal (N = 3, 10) and dense (N = 3).
#[test]
fn dense_tip_is_the_tip_of_the_dense_state() {
    for (modes, path) in PATHS {
        let (p, m) = default_model(modes);
        let mut a = prop(&m, path, None);
        a.reset(0.0, &m.rest()).unwrap();
        let at = format!("N = {modes}, {path:?}");
        let mut worst = 0.0f64;
        let mut check = |a: &mut ExactPropagator, tau0: f64, tau1: f64| {
            for f in [0.0, 0.25, 0.5, 0.75, 1.0] {
                let tau = tau0 + f * (tau1 - tau0);
                let z = a.dense_state(tau);
                let want = [m.w_tip(&z), m.w_tip_dot(&z), m.v_t(tau, &z)];
                let (w, v) = (a.dense_tip(tau), a.dense_v_t(tau));
                for (x, y) in [w[0], w[1], v[0]].into_iter().zip(want) {
                    worst = worst.max((x - y).abs() / (1.0 + y.abs()));
                }
            }
        };
        let mut steps = 0;
        for period in 30..32 {
            // the last step of a run of whole grid steps
            advance(&mut a, period as f64 * p.period()).unwrap();
            let (tau1, h) = (a.tau(), p.period() / a.steps_per_period() as f64);
            check(&mut a, tau1 - h, tau1);
            while a.tau() < (period as f64 + 1.0) * p.period() {
                let st = a.step_deferred(f64::INFINITY).unwrap();
                check(&mut a, st.tau0, st.tau1);
                steps += 1;
            }
        }
        assert!(steps > 60, "{at}: {steps} steps");
        // (measured: at most 5e-14 with the centred series of whole modal steps, 2e-14 when
        // every series started from the step's start)
        assert!(worst <= 1e-13, "{at}: {worst}");
    }
}

/// The dense output at a step's end is the step's end values (W from the modal coordinates,
/// V_T of the switching test: `tip_values`) up to the time resolution of the step at τ — the
/// local time τ1 − τ0 against the exact grid step h differ by about an ulp of τ — also at
/// τ ≈ 4 300 (2 000 periods): the harmonic part of W is turned from the series' centre by
/// Ωu, as the V_T of the series, not taken from sin Ωτ of the large τ (whose rounding made W
/// 1.9e-11 off there, and 2.6e-13 at τ ≈ 64). N = 3 on the period-1 orbit at Ω = 2.94.
#[test]
fn dense_output_ends_at_the_step_end_values() {
    for (periods, tol) in [(30usize, 1e-13), (2000, 1e-11)] {
        let p = Params {
            modes: 3,
            omega: 2.94,
            ..Params::default()
        };
        let m = CantileverModel::new(&p).unwrap();
        let mut a = prop(&m, Propagation::Auto, None);
        a.reset(0.0, &m.rest()).unwrap();
        advance(&mut a, periods as f64 * p.period()).unwrap();
        let (mut worst_w, mut worst_v, mut steps) = (0.0f64, 0.0f64, 0);
        for _ in 0..300 {
            let st = a.step_deferred(f64::INFINITY).unwrap();
            if st.event.is_some() {
                continue;
            }
            let end = a.tip_values();
            worst_w = worst_w.max((a.dense_tip(st.tau1)[0] - end[0]).abs());
            worst_v = worst_v.max((a.dense_v_t(st.tau1)[0] - end[2]).abs());
            steps += 1;
        }
        let at = format!("{periods} periods");
        assert!(steps > 200, "{at}: {steps} steps without an event");
        assert!(worst_w <= tol, "{at}: W {worst_w:e}");
        assert!(worst_v <= tol, "{at}: V_T {worst_v:e}");
    }
}

/// A step of the step loop as `spans_are_the_steps_of_step_deferred` compares it: its end, the
/// state formed there, its event, its Jacobian, its energy-rate integrals and whether the beam
/// body touches the substrate there.
struct LoopStep {
    tau: f64,
    z: DVector<f64>,
    event: Option<SwitchEvent>,
    jac: nalgebra::DMatrix<f64>,
    rates: [f64; 3],
    touches: bool,
}

/// Spans (`Integrator::step_span`, `integrate/exact/span.rs`) are the steps of the step loop
/// run in one go: every span ends where a step of `Integrator::step` ends (the same time, bit
/// for bit), with the same event, and the run ends in the same state bit for bit; the span as
/// the last step gives the step loop's values at every step end inside it — the dense state
/// and tip (to 1e-12 of the state), the Jacobian (the product of the steps' Jacobians, to 1e-10) and the
/// energy-rate integrals (their sum over the steps, to 1e-11 of the terms' size) — and its
/// body-contact guard is sound: no step end inside a span of several steps has the body on
/// the substrate. On the attractor at N = 1, 3, 10 (no body contact, spans of up to a period),
/// and from a large start at N = 3 whose beam body touches the substrate before it decays
/// (the guard ends the spans there).
#[test]
fn spans_are_the_steps_of_step_deferred() {
    use afmdyn::model::BodyContactCheck;
    for (modes, touching) in [(1, false), (3, false), (10, false), (3, true)] {
        let (p, m) = default_model(modes);
        let period = p.period();
        let body = BodyContactCheck::new(&m, 64);
        let (z0, t0, periods) = if touching {
            let z = afmdyn::analysis::bifurcation::random_state(&m, 3, 1) * 40.0;
            (z, 0.0, 30.0)
        } else {
            (m.rest(), 40.0 * period, 10.0)
        };
        let (mut a, mut b) = (
            prop(&m, Propagation::Auto, None),
            prop(&m, Propagation::Auto, None),
        );
        for x in [&mut a, &mut b] {
            x.reset(0.0, &z0).unwrap();
            advance(x, t0).unwrap();
        }
        let end = t0 + periods * period;
        let mut steps = Vec::new();
        while b.tau() < end {
            let st = b.step(end).unwrap();
            steps.push(LoopStep {
                tau: b.tau(),
                z: b.state().clone(),
                event: st.event,
                jac: b.last_step_jacobian().unwrap(),
                rates: b.last_step_rate_integrals().unwrap(),
                touches: body.touches(b.tau(), b.state()),
            });
        }
        let at = format!("N = {modes}, touching {touching}");
        let (mut i, mut long_spans, mut guarded) = (0usize, 0usize, 0usize);
        let mut k = (t0 / period).round() as i64 + 1;
        while a.tau() < end {
            let section = k as f64 * period;
            let span = a.step_span(end.min(section), Some(&body)).unwrap();
            if a.tau() >= section {
                k += 1;
            }
            let first = i;
            while steps[i].tau < span.tau1 {
                i += 1;
            }
            let last = &steps[i];
            assert_eq!(last.tau, span.tau1, "{at}: span end");
            assert_eq!(last.event, span.event, "{at}: event");
            let inside = &steps[first..=i];
            long_spans += usize::from(inside.len() > 1);
            // the guard: no step end before the span's end touches
            for s in &inside[..inside.len() - 1] {
                assert!(!s.touches, "{at}: body contact at {} inside a span", s.tau);
            }
            guarded += usize::from(last.touches);
            // dense output at every step end of the span (before an event's jump)
            for s in inside {
                let z = s.event.as_ref().map_or(&s.z, |e| &e.state);
                let dense = a.dense_state(s.tau);
                assert!(
                    rel(&dense, z) <= 1e-12,
                    "{at}: dense state {}",
                    rel(&dense, z)
                );
                // (to round-off of the state: the tip is a sum of the state's entries)
                let tip = a.dense_tip(s.tau);
                for (got, want) in tip[..2].iter().zip([m.w_tip(z), m.w_tip_dot(z)]) {
                    assert!(
                        (got - want).abs() <= 1e-12 * (1.0 + z.amax()),
                        "{at}: dense tip {got} vs {want}"
                    );
                }
            }
            // the Jacobian and the rate integrals over the span
            let jac = inside
                .iter()
                .fold(nalgebra::DMatrix::identity(2 * modes, 2 * modes), |j, s| {
                    &s.jac * j
                });
            let got = a.last_step_jacobian().unwrap();
            let d = (&got - &jac).amax() / (1.0 + jac.amax());
            assert!(d <= 1e-10, "{at}: Jacobian {d:e}");
            let rates = a.last_step_rate_integrals().unwrap();
            for (r, got) in rates.iter().enumerate() {
                let want: f64 = inside.iter().map(|s| s.rates[r]).sum();
                let size: f64 = inside.iter().map(|s| s.rates[r].abs()).sum();
                assert!(
                    (got - want).abs() <= 1e-11 * (size + 1e-300),
                    "{at}: rate {r}: {got} vs {want}"
                );
            }
            i += 1;
        }
        a.form_state();
        assert_eq!(i, steps.len(), "{at}: steps");
        assert_eq!(a.state(), b.state(), "{at}: final state");
        assert!(long_spans > 0, "{at}: spans of several steps");
        assert_eq!(guarded > 0, touching, "{at}: body contact at span ends");
    }
}
