//! PeakForce sweeps (issue 61 §2): the channels over z_c or the modulation frequency, each
//! tap continued from the previous tap's orbit, are the taps computed alone from rest (the
//! same periodic orbits, to Newton's tolerance), in fewer transient periods; the grid of
//! `--from/--to/--step`; the document's `sweep` block and its layout.

use afmdyn::analysis::peakforce::{steady_tap, PeakForceOptions};
use afmdyn::analysis::progress::Progress;
use afmdyn::params::{Excitation, Structure, SweepParam};
use afmdyn::request::{PeakForceRequest, PeakForceSweep, PeakForceSweepParam, Resolved};
use afmdyn::study::named::Datasets;
use afmdyn::{CantileverModel, ContactLaw, Params};

/// The point mass with a modulated sample (α2 = 1: g₀ = A_m), f₀/f_m = `ratio`, Q = 100,
/// Hertz group 20, rest gap `alpha5`.
fn point_mass(ratio: f64, alpha5: f64) -> Params {
    Params {
        modes: 1,
        alpha1: 0.0,
        alpha2: 1.0,
        alpha3: 0.01,
        alpha4: 20.0,
        alpha5,
        alpha6: 0.0,
        omega: 1.0 / ratio,
        contact_law: ContactLaw::Hertz,
        structure: Structure::PointMass,
        excitation: Excitation::Sample,
        ..Params::default()
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

/// Run `request` on `p` through the library's door: the result and its document.
fn run(
    request: &PeakForceRequest,
    p: Params,
) -> afmdyn::request::Document<afmdyn::study::PeakForceResult> {
    afmdyn::request::run::run(request, &Resolved::plain(p), &Progress::new()).unwrap()
}

#[test]
fn a_sweep_in_z_c_gives_the_taps_computed_alone() {
    let p = point_mass(100.0, 0.95);
    let values = vec![0.96, 0.94, 0.92];
    let request = PeakForceRequest {
        sweep: Some(PeakForceSweep {
            quantity: PeakForceSweepParam::ZC,
            values: values.clone(),
        }),
        ..PeakForceRequest::default()
    };
    let d = run(&request, p);
    let taps = d.output.sweep.as_ref().unwrap();
    assert_eq!(taps.len(), 3);
    let (mut chained, mut alone) = (0, 0);
    for (t, z) in taps.iter().zip(&values) {
        let q = p.with(SweepParam::Alpha5, p.alpha5_for_rest_distance(*z));
        let own = steady_tap(
            &CantileverModel::new(&q).unwrap(),
            &PeakForceOptions::default(),
        )
        .unwrap();
        let tap = t.tap.as_ref().unwrap();
        assert_eq!(tap.period, own.period);
        // a conservative law's dissipation is round-off in both
        let work = tap.channels.peak_force * tap.channels.deformation;
        assert!((tap.channels.dissipation - own.channels.dissipation).abs() <= 1e-10 * work);
        for (a, b) in [
            (tap.channels.peak_force, own.channels.peak_force),
            (tap.channels.deformation, own.channels.deformation),
            (tap.channels.contact_time, own.channels.contact_time),
        ] {
            assert!(close(a, b, 1e-6), "z_c = {z}: {a} continued vs {b} alone");
        }
        chained += tap.transient_periods;
        alone += own.transient_periods;
    }
    // continued from the neighbouring orbit: no longer a transient than from rest
    assert!(
        chained <= alone,
        "{chained} periods continued vs {alone} from rest"
    );
    // the document's block: the values and each channel over them, growing peak force
    let block = &d.json["sweep"];
    assert_eq!(block["quantity"], "z_c");
    let peak: Vec<f64> = block["channels"]["peak_force"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(peak.len(), 3);
    assert!(peak[0] < peak[1] && peak[1] < peak[2], "{peak:?}");
    // its layout: the sweep's dimension named after the quantity
    let (layouts, _) = request.datasets(&Resolved::plain(p), &d.output).unwrap();
    let sweep = layouts.iter().find(|(n, _)| n == "sweep").unwrap();
    assert!(format!("{:?}", sweep.1).contains("z_c"));
}

#[test]
fn a_sweep_in_the_modulation_frequency_gives_the_taps_computed_alone() {
    let p = point_mass(100.0, 0.95);
    let request = PeakForceRequest {
        sweep: Some(PeakForceSweep {
            quantity: PeakForceSweepParam::ModulationFrequency,
            values: vec![0.01, 0.02],
        }),
        ..PeakForceRequest::default()
    };
    let d = run(&request, p);
    let taps = d.output.sweep.as_ref().unwrap();
    for (t, omega) in taps.iter().zip([0.01, 0.02]) {
        let q = p.with(SweepParam::Omega, omega);
        let own = steady_tap(
            &CantileverModel::new(&q).unwrap(),
            &PeakForceOptions::default(),
        )
        .unwrap();
        let tap = t.tap.as_ref().unwrap();
        assert!(
            close(tap.channels.peak_force, own.channels.peak_force, 1e-6),
            "Ω = {omega}: {} vs {}",
            tap.channels.peak_force,
            own.channels.peak_force
        );
    }
    // the single tap's blocks are the first value's, at its frequency
    assert!(close(
        d.json["modulation"]["f0_over_fm"].as_f64().unwrap(),
        100.0,
        1e-12
    ));
}

#[test]
fn sweep_grids_and_refusals() {
    assert_eq!(
        PeakForceSweep::grid(1.0, 0.0, 0.25).unwrap(),
        vec![1.0, 0.75, 0.5, 0.25, 0.0]
    );
    assert_eq!(PeakForceSweep::grid(0.0, 1.0, 0.1).unwrap().len(), 11);
    assert!(PeakForceSweep::grid(0.0, 1.0, 0.0).is_err());
    assert!(PeakForceSweep::grid(0.0, 1.0, 1e-9).is_err());
    // a sweep in z_c with a setpoint, or a frequency not off resonance, is refused by name
    let p = point_mass(100.0, 0.95);
    let model = Resolved::plain(p);
    let with_setpoint = PeakForceRequest {
        setpoint: Some(1.0),
        sweep: Some(PeakForceSweep {
            quantity: PeakForceSweepParam::ZC,
            values: vec![0.9],
        }),
        ..PeakForceRequest::default()
    };
    assert!(with_setpoint
        .params(&model)
        .unwrap_err()
        .to_string()
        .contains("sweep"));
    let resonant = PeakForceRequest {
        sweep: Some(PeakForceSweep {
            quantity: PeakForceSweepParam::ModulationFrequency,
            values: vec![0.01, 0.9],
        }),
        ..PeakForceRequest::default()
    };
    assert!(resonant
        .params(&model)
        .unwrap_err()
        .to_string()
        .contains("sweep"));
}

/// Every value of a sweep is checked for what makes its channels misleading, not only the first
/// (issue 61, "a result that may be unsettled says so"): the sample held off the tip at
/// z_c = 1.5 and 1.2 g₀ (its lowest point z_c − A_m above the resting tip: no force at all),
/// in contact at 0.96; each value's warnings in `sweep.warnings`, one document warning
/// counting them with the values where they hold.
#[test]
fn every_value_of_a_sweep_is_checked_for_its_warnings() {
    let p = point_mass(100.0, 0.95);
    let request = PeakForceRequest {
        sweep: Some(PeakForceSweep {
            quantity: PeakForceSweepParam::ZC,
            values: vec![1.5, 1.2, 0.96],
        }),
        ..PeakForceRequest::default()
    };
    let d = run(&request, p);
    let per_value: Vec<Vec<String>> =
        serde_json::from_value(d.json["sweep"]["warnings"].clone()).unwrap();
    assert_eq!(per_value.len(), 3);
    for w in &per_value[..2] {
        assert!(
            w.iter().any(|m| m.contains("no repulsive contact")),
            "{per_value:?}"
        );
    }
    assert!(per_value[2].is_empty(), "{per_value:?}");
    let warnings: Vec<String> = serde_json::from_value(d.json["warnings"].clone()).unwrap();
    let counted: Vec<&String> = warnings
        .iter()
        .filter(|w| w.contains("no repulsive contact"))
        .collect();
    assert_eq!(counted.len(), 1, "{warnings:?}");
    assert!(
        counted[0].starts_with("at 2 of the sweep's 3 values (z_c = 1.5, 1.2 g0)"),
        "{}",
        counted[0]
    );
}
