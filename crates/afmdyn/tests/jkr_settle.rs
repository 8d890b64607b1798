//! Intermittent tapping on a compliant, adhesive JKR sample (issue 60, B11 and A4): a stiff
//! lever (40 N/m, 300 kHz, Q = 400, A₀ = 10 nm) over E_s = 100 MPa, W = 0.05 J/m², R = 10 nm.
//! Below z_c ≈ A₀ the orbit is not followed by Newton from the point before, and the
//! transient's stroboscopic returns spiral in too slowly for a period of at most 16 drive
//! periods to show within the cap of 20 000 periods; such a point is settled by its windowed
//! time average ([`afmdyn::analysis::stepped::settle`]), labelled `averaged`, and a warning
//! says so.

use afmdyn::analysis::approach::{approach_retract, approach_spec};
use afmdyn::analysis::observables::{observe_tapered, ObservableOptions};
use afmdyn::analysis::stepped::{Reached, Spacing, AVERAGE_TOL};
use afmdyn::integrate::{advance, build};
use afmdyn::probe::Probe;
use afmdyn::{CantileverModel, Params};

/// The JKR probe (lengths in units of A₀ = 10 nm).
fn params() -> Params {
    let text = "model = \"point-mass\"\n[cantilever]\nspring_constant = 40\nresonance_frequency = \
                300e3\nquality_factor = 400\n[tip]\nradius = 10e-9\n[sample]\nlaw = \"jkr\"\n\
                youngs_modulus = 100e6\npoisson_ratio = 0.33\nadhesion_energy = 0.05\n\
                z_c = 8e-9\n[drive]\nfree_amplitude = 10e-9\n";
    Probe::parse(text, "<test>")
        .unwrap_or_else(|e| panic!("{e}"))
        .params
}

/// The approach from z_c = 1.0 A₀ to 0.9 A₀ (three points): the points in intermittent
/// tapping are `averaged`, with no period, and the curve warns of them; each one's amplitude
/// agrees with the time average of a long direct simulation from its state (2 000 periods
/// more of transient, then a Hann² window of 4 000 periods) to the windows' tolerance
/// [`AVERAGE_TOL`] (1e-3) relative, and its phase to 1e-3 rad.
#[test]
fn an_intermittent_jkr_point_is_averaged_and_agrees_with_a_long_simulation() {
    let mut spec = approach_spec(params(), 1.0, 0.9, Spacing::Points(3)).expect("spec");
    spec.branches = false;
    let curve = approach_retract(&spec).expect("approach");
    let averaged: Vec<_> = curve
        .first
        .iter()
        .chain(&curve.second)
        .filter(|p| p.reached == Reached::Averaged)
        .collect();
    assert!(
        averaged.len() >= 2,
        "averaged points: {:?}",
        curve.first.iter().map(|p| p.reached).collect::<Vec<_>>()
    );
    assert!(
        curve
            .warnings
            .iter()
            .any(|w| w.contains("averaged (no short period found)")),
        "{:?}",
        curve.warnings
    );
    for p in averaged {
        assert_eq!(p.period, None);
        assert!(p.multipliers.is_empty() && p.monodromy.is_none());
        let model = CantileverModel::new(&spec.base.with(spec.param, p.value)).expect("model");
        let mut it = build(&model, spec.integrator.clone(), 0.0, &p.state).expect("integrator");
        advance(it.as_mut(), 2000.0 * model.period()).expect("transient");
        let long = observe_tapered(
            it.as_mut(),
            &ObservableOptions {
                periods: 4000,
                harmonics: spec.observables.harmonics,
            },
        )
        .expect("long window");
        let rel = (p.observables.amplitude - long.amplitude).abs() / long.amplitude;
        assert!(
            rel <= AVERAGE_TOL,
            "value {}: averaged A = {}, long simulation {} (relative {rel:e})",
            p.value,
            p.observables.amplitude,
            long.amplitude
        );
        let dphi = (p.observables.phase - long.phase).abs();
        assert!(
            dphi <= 1e-3,
            "value {}: phase differs by {dphi} rad",
            p.value
        );
    }
}
