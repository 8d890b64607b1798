//! The exact-sensitivity tests' helpers (`fit_dynamic.rs`, `fit_bimodal.rs`, `fit_jkr.rs`): an example
//! probe's model parameters, a tight Newton, and a model parameter moved or read by its
//! [`OrbitParam`].

use afmdyn::analysis::fit::sensitivity::OrbitParam;
use afmdyn::analysis::shooting::ShootingOptions;
use afmdyn::contact::ContactLaw;
use afmdyn::probe::Probe;
use afmdyn::Params;
use std::path::Path;

/// The model parameters of `examples/<name>`.
pub fn probe(name: &str) -> Params {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name);
    Probe::load(&path).expect("example probe").params
}

/// Newton on the orbit to 1e-12, at most 40 iterations.
pub fn newton() -> ShootingOptions {
    ShootingOptions {
        tol: 1e-12,
        max_iter: 40,
        ..ShootingOptions::default()
    }
}

/// The model's parameters with p moved to `value`.
pub fn with(base: &Params, p: OrbitParam, value: f64) -> Params {
    let mut q = *base;
    match p {
        OrbitParam::Gap => q.alpha5 = value,
        OrbitParam::ContactStiffness => q.alpha4 = value,
        OrbitParam::Damping => q.alpha6 = value,
        OrbitParam::Hamaker => match &mut q.contact_law {
            ContactLaw::Dmt { hamaker, .. } => *hamaker = value,
            _ => panic!("H̃ of a law without it"),
        },
        OrbitParam::DriveAmplitude => q.alpha2 = value,
        OrbitParam::DriveFrequency => q.omega = value,
        OrbitParam::LeverDamping => q.alpha3 = value,
        OrbitParam::ComponentForce => {
            if let Some(c) = q.drive_components.iter_mut().flatten().next() {
                c.force = value;
            }
        }
        OrbitParam::Adhesion => match &mut q.contact_law {
            ContactLaw::Jkr { adhesion } => *adhesion = value,
            _ => panic!("P̃ of a law without it"),
        },
    }
    q
}

/// The value of p in `base`.
pub fn value_of(base: &Params, p: OrbitParam) -> f64 {
    match p {
        OrbitParam::Gap => base.alpha5,
        OrbitParam::ContactStiffness => base.alpha4,
        OrbitParam::Damping => base.alpha6,
        OrbitParam::Hamaker => match base.contact_law {
            ContactLaw::Dmt { hamaker, .. } => hamaker,
            _ => panic!("H̃ of a law without it"),
        },
        OrbitParam::DriveAmplitude => base.alpha2,
        OrbitParam::DriveFrequency => base.omega,
        OrbitParam::LeverDamping => base.alpha3,
        OrbitParam::ComponentForce => base.components().next().map_or(f64::NAN, |c| c.force),
        OrbitParam::Adhesion => match base.contact_law {
            ContactLaw::Jkr { adhesion } => adhesion,
            _ => panic!("P̃ of a law without it"),
        },
    }
}
