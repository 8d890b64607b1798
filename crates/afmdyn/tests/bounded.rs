//! Reproductions of issue 27 ("every accepted input answers in bounded time, every refusal
//! speaks the user's units"), each now a test: the library's answer to inputs at the edges of
//! what validation accepts.

use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::steady::{steady_state, SteadyOptions};
use afmdyn::contact::ContactLaw;
use afmdyn::integrate::{build, IntegratorKind, IntegratorOptions};
use afmdyn::request::{AttractorsRequest, ContinuationRequest, LyapunovRequest, OrbitRequest};
use afmdyn::CantileverModel;
use afmdyn::{Params, SimError, SweepParam};

/// A branch continued from the largest Ω the model accepts (1e5) needs ∂Pⁿ/∂Ω at its first
/// point: a central difference there evaluated Ω = 1.000001e5, which the validation refuses,
/// so the run ended with an error about a value the user never gave. One-sided at the edge.
#[test]
fn continuation_from_the_largest_omega_does_not_step_outside_the_range() {
    let base = Params {
        contact_law: ContactLaw::Hertz,
        ..Params::default()
    };
    let request = ContinuationRequest {
        param: SweepParam::Omega,
        from: 1e5,
        to: 0.99e5,
        ..ContinuationRequest::default()
    };
    let branches = request.run(&base, &Progress::new()).unwrap();
    assert!(branches[0].len() > 2, "{} points", branches[0].len());
    assert!(branches[0].iter().all(|b| b.value <= 1e5));
}

/// With the Hertz law pressed 1e6 g₀ into the sample every random start of the adaptive
/// integrator runs into its budget while it integrates (the force grows too stiff to resolve):
/// the census used to return no attractor and exit 0; now it is a failure (exit 1, Python's
/// SimulationError) that names the count and the first start's error. (The default integrator,
/// Taylor series in the contact, resolves this motion: see
/// `a_motion_too_stiff_to_resolve_ends_with_a_budget_error`.) At Ω = 1e-3 the step budget is
/// exceeded before any run: one input error (exit 2), checked in validation.
#[test]
fn an_attractor_census_whose_every_start_fails_is_a_failure() {
    let params = Params {
        alpha5: -1e6,
        contact_law: ContactLaw::Hertz,
        ..Params::default()
    };
    let mut request = AttractorsRequest {
        samples: 4,
        ..AttractorsRequest::default()
    };
    request.integrator.integrator = IntegratorKind::Adaptive;
    let err = request.run(&params, &Progress::new()).unwrap_err();
    assert!(
        matches!(err, SimError::EveryRunFailed { runs: 4, .. }),
        "{err}"
    );
    assert!(!err.is_input_error());
    assert!(
        err.to_string().starts_with(
            "every one of the 4 random starts failed; the first: adaptive integrator: more \
             than 1e5 steps"
        ),
        "{err}"
    );
    let slow = Params {
        omega: 1e-3,
        contact_law: ContactLaw::Hertz,
        ..Params::default()
    };
    let err = request.run(&slow, &Progress::new()).unwrap_err();
    assert!(
        matches!(err, SimError::Budget { .. }) && err.is_input_error(),
        "{err}"
    );
}

/// A DMT adhesion force beyond floating point (ã₀ = 1e-300) is refused naming ã₀ and why; it
/// used to reach the ODE crate ("Initial step size (0.0) cannot be zero").
#[test]
fn a_dmt_adhesion_force_beyond_floating_point_is_refused() {
    let params = Params {
        contact_law: ContactLaw::Dmt {
            hamaker: 1e-5,
            intermolecular_distance: 1e-300,
        },
        ..Params::default()
    };
    let err = params.validate().unwrap_err().to_string();
    assert_eq!(
        err,
        "intermolecular_distance (DMT ã₀) = 1e-300: must satisfy H̃/ã₀² ≤ 1e12 (the adhesion \
         force at contact; raise ã₀ or lower H̃)"
    );
}

/// Inputs the validation accepts whose motion grows too stiff for the adaptive integrator (a
/// tip captured by a strong DMT adhesion, a tip resting 1e6 g₀ deep in the sample) ran for
/// minutes to hours (`orbit --contact-law dmt --hamaker 1e6` > 120 s; `--gap -1e6` 437 s).
/// Now the adaptive integrator ends at the first drive period that needs more than
/// [`afmdyn::params::ADAPTIVE_STEPS_PER_PERIOD`] steps, with a budget error naming what to
/// change — counted in steps, so the answer does not depend on the machine. The default
/// integrators (Taylor series, in the contact in its regularising time) resolve both motions
/// within the same budget: the orbit request answers with a period-1 orbit, in contact all the
/// time (no switching) for the tip deep in the sample.
#[test]
fn a_motion_too_stiff_to_resolve_ends_with_a_budget_error() {
    for params in [
        Params {
            contact_law: ContactLaw::Dmt {
                hamaker: 1e6,
                intermolecular_distance: 0.01,
            },
            ..Params::default()
        },
        Params {
            contact_law: ContactLaw::Hertz,
            alpha5: -1e6,
            ..Params::default()
        },
    ] {
        let model = CantileverModel::new(&params).unwrap();
        let opts = IntegratorOptions {
            kind: IntegratorKind::Adaptive,
            ..IntegratorOptions::default()
        };
        let mut it = build(&model, opts, 0.0, &model.rest()).unwrap();
        let err = steady_state(it.as_mut(), &SteadyOptions::default()).unwrap_err();
        assert!(matches!(err, SimError::Budget { .. }), "{err}");
        assert!(err.is_input_error());
        let msg = err.to_string();
        assert!(
            msg.starts_with("adaptive integrator: more than 1e5 steps within the drive period"),
            "{msg}"
        );
        assert!(msg.contains("soften the law"), "{msg}");
        let orbit = OrbitRequest::default().run(&params).unwrap();
        assert_eq!(orbit.period, 1, "{}", params.contact_law);
        assert!(orbit.multipliers.iter().all(|m| m.norm() < 1.0));
    }
}

/// The impact law with r = 0 (a plastic impact, a documented value): the default orbit and the
/// Lyapunov spectrum are computed (issue 27: both ended in "4096 switchings within 0e0"). A
/// plastic impact leaves the tip on the surface with V̇_T = 0; with V̈_T > 0 it lifts off, and
/// the higher modes bring it back within 1e-4 of τ — the re-impact is located there, not at
/// the start of the step again and again.
#[test]
fn a_plastic_impact_law_has_an_orbit_and_a_spectrum() {
    let params = Params {
        contact_law: ContactLaw::Impact { restitution: 0.0 },
        ..Params::default()
    };
    let o = OrbitRequest::default().run(&params).unwrap();
    assert!(o.switchings >= 2, "the orbit taps the sample");
    let l = LyapunovRequest {
        transient: Some(100),
        periods: 400,
        ..LyapunovRequest::default()
    }
    .run(&params, &Progress::new())
    .unwrap();
    assert!(l.exponents.iter().all(|x| x.is_finite()));
}

/// A probe file's refusals name the keys the user wrote (issue 27): a derived group out of
/// range says which keys it came from; a present but invalid `modes` is not also "missing"; a
/// refused entry of `quality_factors` still counts as written.
#[test]
fn probe_refusals_name_the_keys_written() {
    let pm = include_str!("../../../examples/probe-point-mass-dmt.toml");
    let beam = include_str!("../../../examples/probe-beam-dmt.toml");
    let with = |text: &str, key: &str, line: &str| -> String {
        let out: Vec<String> = text
            .lines()
            .map(|l| {
                if l.starts_with(&format!("{key} =")) {
                    line.to_string()
                } else {
                    l.to_string()
                }
            })
            .collect();
        let err = afmdyn::probe::Probe::parse(&out.join("\n"), "probe.toml").unwrap_err();
        err.to_string()
    };
    let cases = [
        (
            with(pm, "free_amplitude", "free_amplitude = 1e-30"),
            // refused as written (issue 28 item 6), before any group is derived from it
            "[drive].free_amplitude = 1e-30 (m): below 1 pm",
        ),
        (
            with(pm, "quality_factor", "quality_factor = 1e-6"),
            "from [cantilever] quality_factor",
        ),
        (
            with(pm, "resonance_frequency", "resonance_frequency = 1e15"),
            // refused as written, outside its physical range (probe::ranges)
            "[cantilever].resonance_frequency = 1000000000000000 (Hz): above 10 GHz",
        ),
    ];
    for (msg, needle) in &cases {
        assert!(msg.contains(needle), "{msg}");
    }
    let msg = with(pm, "free_amplitude", "free_amplitude = 1.0");
    assert!(
        msg.ends_with("[drive].free_amplitude = 1 (m): must be ≤ 1e-5 m (10 µm; tapping-mode amplitudes are nanometres)"),
        "{msg}"
    );
    let msg = with(beam, "modes", "modes = 0");
    assert_eq!(msg, "probe.toml: modes = 0: must be an integer in 1..=20");
    let msg = with(beam, "quality_factor", "quality_factors = [400, -1, 900]");
    assert_eq!(
        msg,
        "probe.toml: [cantilever].quality_factors[1] = -1: must be a number in (0, 1e7]"
    );
}
