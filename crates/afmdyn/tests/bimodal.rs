//! Multifrequency (bimodal) AFM: the drive as a sum of components at commensurate
//! frequencies (`[drive] free_amplitude = [A01, A02]`, `frequency = [f1, f2]`), the steady
//! state a periodic orbit of the common period, each component's amplitude, phase, virial and
//! dissipated energy by demodulation (Lozano & García, Phys. Rev. Lett. 100, 076102 (2008);
//! García & Proksch, Eur. Polym. J. 49, 1897 (2013)).

use afmdyn::analysis::observables::observe_orbit;
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::integrate::{IntegratorKind, IntegratorOptions};
use afmdyn::probe::Probe;
use afmdyn::CantileverModel;

const EIGENMODES: &str = r#"
model = "eigenmodes"
[cantilever]
spring_constant = [40.0, 1571.0]
resonance_frequency = [300e3, 1.88e6]
quality_factor = [400, 2507]
[tip]
radius = 10e-9
[sample]
law = "dmt"
youngs_modulus = 4e9
poisson_ratio = 0.33
hamaker = 6.6e-20
z_c = 8e-9
[drive]
free_amplitude = [10e-9, 1e-9]
frequency = [300e3, 1.88e6]
"#;

fn integ() -> IntegratorOptions {
    IntegratorOptions {
        kind: IntegratorKind::Auto,
        tolerance: 1e-12,
        ..IntegratorOptions::default()
    }
}

/// Far from the sample each component's amplitude is its free amplitude and its phase the
/// free response's (≤ 1e-6), the primary's 90° at resonance.
#[test]
fn far_from_the_sample_each_component_is_free() {
    let probe = Probe::parse(EIGENMODES, "test").unwrap();
    assert_eq!(probe.components.len(), 1);
    assert_eq!(probe.components[0].ratio, [94, 15]);
    let mut p = probe.params;
    p.alpha5 = p.alpha5_for_rest_distance(1e-6 / probe.scales.length_m);
    assert_eq!(p.common_periods(), 15);
    let model = CantileverModel::new(&p).unwrap();
    let orbit = shoot(
        &model,
        &nalgebra::DVector::zeros(4),
        1,
        &ShootingOptions::default(),
    )
    .unwrap();
    let o = observe_orbit(&model, integ(), &orbit, 3).unwrap();
    assert_eq!(o.components.len(), 2);
    for c in &o.components {
        eprintln!("{c:?}");
        assert!((c.amplitude / c.free_amplitude - 1.0).abs() < 1e-6);
        assert!((c.phase - c.free_phase).abs() < 1e-6);
    }
    assert!((o.components[0].free_amplitude - 1.0).abs() < 1e-12);
    assert!((o.components[1].free_amplitude - 0.1).abs() < 1e-12);
}
