//! Quasi-periodic steady states as invariant circles (`analysis::torus`, issue 63): at a
//! commensurate ratio the circle is the periodic orbit to round-off; at the lever's true mode
//! ratio 6.27 = 627/100 the circle on 26 or 37 nodes agrees with the exact 100-period orbit;
//! far from the sample each component's amplitude and phase are the closed-form free response.

use afmdyn::analysis::approach::approach_spec;
use afmdyn::analysis::observables::{observe_orbit, Observables};
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::analysis::stepped::torus::TorusOptions;
use afmdyn::analysis::stepped::{stepped_sweep, Spacing};
use afmdyn::analysis::torus::{
    continue_circle, invariant_circle, observe_circle, CircleOptions, InvariantCircle,
};
use afmdyn::integrate::{build, IntegratorKind, IntegratorOptions};
use afmdyn::maps::flow::flow_state;
use afmdyn::maps::StroboscopicMap;
use afmdyn::probe::Probe;
use afmdyn::{CantileverModel, Params};
use nalgebra::DVector;

use super::common;
use common::opts;

/// The eigenmode lever of `common::bimodal_lever` (k = [40, 1571] N/m, f₁ = 300 kHz, Q =
/// [60, 300], free amplitudes [10, 1] nm over polystyrene with DMT) with its second mode and
/// drive at `f2` (Hz) and the rest separation z_c = `zc` A₀₁.
fn lever(f2: &str, zc: f64) -> Params {
    lever_a2(f2, zc, "1e-9")
}

/// [`lever`] with the second free amplitude `a2` (m).
fn lever_a2(f2: &str, zc: f64, a2: &str) -> Params {
    let text = common::bimodal_lever(f2, "60, 300", f2)
        .replace("[10e-9, 1e-9]", &format!("[10e-9, {a2}]"));
    let mut p = Probe::parse(&text, "test").unwrap().params;
    p.alpha5 = zc;
    p
}

/// The state at τ = 0 after `periods` drive periods from rest (a multiple of the drive's
/// period, so the second drive is back at phase 0).
fn settled(model: &CantileverModel, periods: usize) -> DVector<f64> {
    let mut it =
        afmdyn::integrate::build(model, opts(IntegratorKind::Auto, 1e-10), 0.0, &model.rest())
            .unwrap();
    let t = periods as f64 * std::f64::consts::TAU / model.omega();
    flow_state(it.as_mut(), 0.0, &model.rest(), t).unwrap()
}

/// The largest difference of the two components' amplitudes, each over its free amplitude,
/// and of their phases (rad).
fn components_differ(a: &Observables, b: &Observables) -> (f64, f64) {
    a.components
        .iter()
        .zip(&b.components)
        .fold((0.0f64, 0.0f64), |(da, dp), (x, y)| {
            (
                da.max((x.amplitude - y.amplitude).abs() / x.free_amplitude),
                dp.max((x.phase - y.phase).abs()),
            )
        })
}

/// The N = 3 beam of `examples/probe-beam-dmt.toml` with Q = [60, 300, 300] and a second drive
/// of 0.5 nm at 6.27 f₁ (1.881 MHz).
fn beam_params() -> Params {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/probe-beam-dmt.toml"
    ))
    .unwrap()
    .replace("quality_factor = 400 ", "quality_factors = [60, 300, 300] ")
    .replace(
        "free_amplitude = 10e-9 ",
        "free_amplitude = [10e-9, 0.5e-9] ",
    )
    .replace("\nfrequency = 300e3 ", "\nfrequency = [300e3, 1.881e6] ");
    Probe::parse(&text, "beam").unwrap().params
}

fn integ() -> afmdyn::IntegratorOptions {
    opts(IntegratorKind::Auto, 1e-12)
}

/// At f₂/f₁ = 25/4 the drive repeats every 4 periods: the circle takes those 4 nodes, its
/// closure is the periodic orbit's, and its state and observables are the orbit's to round-off.
#[test]
fn at_a_commensurate_ratio_the_circle_is_the_periodic_orbit() {
    let model = CantileverModel::new(&lever("1.875e6", 0.8)).unwrap();
    assert_eq!(model.params().common_periods(), 4);
    let guess = settled(&model, 400);
    let mut it = build(&model, IntegratorOptions::default(), 0.0, &model.rest()).unwrap();
    let map = &mut StroboscopicMap::new(it.as_mut(), 1);
    let orbit = shoot(map, &guess, &ShootingOptions::default()).unwrap();
    assert!(orbit.stable);
    let circle = invariant_circle(&model, integ(), &guess, &CircleOptions::default()).unwrap();
    assert!(circle.nodes.exact);
    assert_eq!(circle.nodes.len(), 4);
    let scale = orbit.state.amax();
    assert!(
        (&circle.states[0] - &orbit.state).amax() < 1e-9 * scale,
        "{} vs {}",
        circle.states[0],
        orbit.state
    );
    let largest = orbit.multipliers[0].norm();
    assert!(
        (circle.contraction - largest.powf(0.25)).abs() < 1e-6,
        "{}",
        circle.contraction
    );
    let a = observe_orbit(&model, integ(), &orbit, 2).unwrap();
    let b = observe_circle(&model, integ(), &circle, 2).unwrap();
    assert!(a.contact_fraction > 0.0, "the orbit taps");
    let (da, dp) = components_differ(&a, &b);
    assert!(da < 1e-9 && dp < 1e-8, "{da:e} {dp:e}");
}

/// The circle at the true ratio 6.27 = 627/100 on `nodes` nodes against the exact 100-period
/// orbit: the largest difference of the components' amplitudes (over each free amplitude)
/// and phases (rad), and the circle.
fn against_the_orbit(model: &CantileverModel, nodes: usize) -> (f64, f64, InvariantCircle) {
    assert_eq!(model.params().common_periods(), 100);
    let guess = settled(model, 400);
    let mut it = build(model, IntegratorOptions::default(), 0.0, &model.rest()).unwrap();
    let map = &mut StroboscopicMap::new(it.as_mut(), 1);
    let orbit = shoot(map, &guess, &ShootingOptions::default()).unwrap();
    assert!(orbit.stable);
    let exact = observe_orbit(model, integ(), &orbit, 2).unwrap();
    let circle = invariant_circle(
        model,
        integ(),
        &guess,
        &CircleOptions {
            nodes,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(!circle.nodes.exact);
    let torus = observe_circle(model, integ(), &circle, 2).unwrap();
    let (da, dp) = components_differ(&exact, &torus);
    (da, dp, circle)
}

/// At the lever's true ratio 6.27 = 627/100 the exact periodic orbit spans 100 periods; the
/// circle on the 37 nodes of the convergent 10/37 of 0.27 reproduces its components'
/// amplitudes to 1e-7 of each free amplitude and their phases to 1e-7 rad, in the repulsive
/// regime (z_c = 0.5 A₀₁, one touch per period at every phase of the second drive) and in the
/// attractive regime without contact (z_c = 1.12 A₀₁; the van der Waals force alone), where
/// 11 nodes (the convergent 3/11) already agree to 1e-9.
#[test]
fn at_the_true_mode_ratio_the_circle_matches_the_100_period_orbit() {
    for (zc, a2, nodes, tol) in [(0.5, "0.5e-9", 30, 1e-7), (1.12, "0.5e-9", 10, 1e-9)] {
        let model = CantileverModel::new(&lever_a2("1.881e6", zc, a2)).unwrap();
        let (da, dp, circle) = against_the_orbit(&model, nodes);
        assert!(circle.stable && circle.smooth, "z_c = {zc}: {circle:?}");
        assert!(
            da < tol && dp < tol,
            "z_c = {zc}, {} nodes: amplitudes {da:e}, phases {dp:e}",
            circle.nodes.len()
        );
    }
}

/// Where the circle crosses a grazing bifurcation — at z_c = 1.05 A₀₁ with A₀₂ = 1 nm the tip
/// touches the sample in some phases of the second drive and not in others (2 or 0
/// switchings per period) — the circle says it is not smooth, and its error at 37 nodes is
/// the algebraic one (above 1e-7, below 1e-4 of A₀).
#[test]
fn a_circle_through_a_grazing_says_so() {
    let model = CantileverModel::new(&lever("1.881e6", 1.05)).unwrap();
    let (da, _, circle) = against_the_orbit(&model, 30);
    assert!(!circle.smooth, "{:?}", circle.switchings);
    let (lo, hi) = circle
        .switchings
        .iter()
        .fold((usize::MAX, 0), |(l, h), &s| (l.min(s), h.max(s)));
    assert!(lo < hi, "{:?}", circle.switchings);
    assert!(da > 1e-7 && da < 1e-4, "{da:e}");
}

/// The N = 3 beam (base-driven, the paper's model) with a second drive at 6.27 f₁ near its
/// second mode (6.267 f₁ for the uniform beam): the circle on the 63 nodes of the
/// semiconvergent 17/63 of 0.27 matches the 100-period orbit to 1e-7 in the repulsive regime
/// (its harmonics in the second drive's phase decay more slowly than the eigenmode model's:
/// 37 nodes agree to 1.4e-6).
#[test]
fn on_the_beam_the_circle_matches_the_100_period_orbit() {
    let mut p = beam_params();
    p.alpha5 = 0.5;
    let model = CantileverModel::new(&p).unwrap();
    let (da, dp, circle) = against_the_orbit(&model, 38);
    assert_eq!(circle.nodes.len(), 63);
    assert!(circle.stable && circle.smooth, "{circle:?}");
    assert!(da < 1e-7 && dp < 1e-7, "amplitudes {da:e}, phases {dp:e}");
}

/// Far from the sample the motion is the linear free response: each component's amplitude
/// and phase are the closed form's (|H(ω_c)| F_c and its lag), at an incommensurate ratio.
#[test]
fn far_from_the_sample_the_circle_is_the_free_response() {
    let model = CantileverModel::new(&lever("1.881e6", 50.0)).unwrap();
    let guess = settled(&model, 400);
    let circle = invariant_circle(&model, integ(), &guess, &CircleOptions::default()).unwrap();
    let o = observe_circle(&model, integ(), &circle, 2).unwrap();
    assert_eq!(o.contact_fraction, 0.0);
    for c in &o.components {
        assert!(
            (c.amplitude - c.free_amplitude).abs() < 1e-9 * c.free_amplitude,
            "{c:?}"
        );
        assert!((c.phase - c.free_phase).abs() < 1e-8, "{c:?}");
    }
    for m in &o.mode_balance {
        assert!(m.residual.abs() < 1e-9 * m.drive.abs().max(1e-12), "{m:?}");
    }
}

/// A step of an approach curve: the circle at z_c = 0.5 A₀₁ continued from the one at 0.51
/// (Broyden's updates from its map's Jacobian, flows without the variational equations) is
/// the circle a Newton solve finds there, to the solves' tolerance.
#[test]
fn a_continued_circle_is_the_circle() {
    let opts = CircleOptions::default();
    let before = CantileverModel::new(&lever_a2("1.881e6", 0.51, "0.5e-9")).unwrap();
    let guess = settled(&before, 400);
    let previous = invariant_circle(&before, integ(), &guess, &opts).unwrap();
    let model = CantileverModel::new(&lever_a2("1.881e6", 0.5, "0.5e-9")).unwrap();
    let fresh = invariant_circle(&model, integ(), &guess, &opts).unwrap();
    let continued = continue_circle(
        &model,
        integ(),
        &previous.states[0],
        &previous.jacobian,
        &opts,
    )
    .unwrap();
    assert_eq!(fresh.nodes, continued.nodes);
    let scale = fresh.states[0].amax();
    for (a, b) in fresh.states.iter().zip(&continued.states) {
        assert!((a - b).amax() < 1e-9 * scale, "{a} {b}");
    }
    assert!((fresh.contraction - continued.contraction).abs() < 1e-9);
    assert_eq!(fresh.smooth, continued.smooth);
}

/// The approach curve of `p` from `from` to `to` (`points` values, A₀₁ units) measured on
/// invariant circles of `nodes` nodes against the same curve on the exact orbits of the
/// common period (no branches): the points on circles, the points in all (both sweeps), and
/// the largest difference of the components' amplitudes (over each free amplitude) and
/// phases (rad) over the points on circles.
fn curve_against_exact(
    p: Params,
    from: f64,
    to: f64,
    points: usize,
    nodes: usize,
) -> (usize, usize, f64, f64) {
    let mut exact = approach_spec(p, from, to, Spacing::Points(points)).unwrap();
    exact.branches = false;
    let mut torus = exact.clone();
    torus.torus = Some(TorusOptions { nodes });
    let a = stepped_sweep(&exact).unwrap();
    let b = stepped_sweep(&torus).unwrap();
    assert!(
        b.warnings.iter().any(|w| w.contains("invariant circle")),
        "{:?}",
        b.warnings
    );
    let pairs: Vec<_> = a
        .first
        .iter()
        .chain(&a.second)
        .zip(b.first.iter().chain(&b.second))
        .collect();
    let mut on = 0;
    let (mut da, mut dp) = (0.0f64, 0.0f64);
    for (x, y) in &pairs {
        assert_eq!(x.value, y.value);
        assert!(x.circle.is_none() && x.fallback.is_none());
        if y.fallback.is_none() {
            assert!(y.circle.is_some());
            on += 1;
            let (a, p) = components_differ(&x.observables, &y.observables);
            (da, dp) = (da.max(a), dp.max(p));
        }
    }
    (on, pairs.len(), da, dp)
}

/// A stepped approach at the lever's true ratio 6.27 = 627/100 on invariant circles (the
/// default's 37 nodes on the eigenmode lever; 26 leave 2.5e-6 in the repulsive regime)
/// against the same curve on the exact 100-period orbits: every point but the start on the
/// circle, each component's amplitude within 1e-7 of its free amplitude and its phase within
/// 1e-7 rad, in the repulsive regime and in the attractive regime without contact.
#[test]
fn a_curve_on_circles_matches_the_exact_curve_on_the_eigenmode_lever() {
    for (from, to) in [(0.53, 0.47), (1.15, 1.1)] {
        let p = lever_a2("1.881e6", from, "0.5e-9");
        let (on, all, da, dp) = curve_against_exact(p, from, to, 4, TorusOptions::default().nodes);
        // the first point starts from rest: in contact Newton does not find the circle from
        // there, and the transient settles on the exact orbit
        assert!(on + 1 >= all, "z_c {from} → {to}: {on} of {all}");
        assert!(
            da < 1e-7 && dp < 1e-7,
            "z_c {from} → {to}: amplitudes {da:e}, phases {dp:e}"
        );
    }
}

/// The N = 3 beam at 6.27 (its second mode at 6.267 f₁) in the repulsive regime: its circle
/// needs the 63 nodes of the semiconvergent 17/63 for 1e-7 (as the single circle's test).
#[test]
fn a_curve_on_circles_matches_the_exact_curve_on_the_beam() {
    let mut p = beam_params();
    p.alpha5 = 0.53;
    let (on, all, da, dp) = curve_against_exact(p, 0.53, 0.47, 3, 38);
    assert_eq!(on, all);
    assert!(da < 1e-7 && dp < 1e-7, "amplitudes {da:e}, phases {dp:e}");
}

/// A curve on invariant circles is a different run from the same curve on exact orbits: the
/// store's fingerprint names the circles, so neither resumes the other's points; a curve whose
/// drive repeats quickly (25/4) has the fingerprint it had before circles existed.
#[test]
fn a_store_on_circles_is_not_resumed_by_exact_orbits() {
    use afmdyn::request::run::{ApproachRequest, Resolved};
    use afmdyn::study::stepped::CurveStudy;
    let fingerprint = |f2: &str, exact: bool| {
        let request = ApproachRequest {
            exact,
            ..ApproachRequest::default()
        };
        let model = Resolved::plain(lever(f2, 1.1));
        CurveStudy::approach(&request, &model).unwrap().fingerprint
    };
    let circles = fingerprint("1.881e6", false);
    let exact = fingerprint("1.881e6", true);
    assert!(circles.get("invariant_circles").is_some(), "{circles}");
    assert!(exact.get("invariant_circles").is_none(), "{exact}");
    assert_ne!(circles, exact);
    assert!(fingerprint("1.875e6", false)
        .get("invariant_circles")
        .is_none());
}
