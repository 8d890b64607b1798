//! What a probe file's key is when the file omits it: the one declaration of every key's
//! default, which `docs/schema/probe-keys.json` (`default`) and the book's probe keys give.
//! A numeric default is the value the reader uses: `tests/schema.rs` checks that a file
//! without the key reads as the same file with the key set to it.

use super::{DEFAULT_INTERMOLECULAR_DISTANCE, WATER_SURFACE_TENSION};
use crate::cantilevers::{SILICON_POISSON_RATIO, SILICON_YOUNGS_MODULUS};

/// Per key (`section.key`, the root's keys bare): the value the reader takes when the file
/// omits it, if it is a number, and the default in words (`required` where there is none).
#[rustfmt::skip]
pub const KEY_DEFAULTS: &[(&str, Option<f64>, &str)] = &[
    ("model", None, "required: beam, point-mass or eigenmodes"),
    ("modes", None, "required for the beam; 1 for the point mass; the eigenmode model's number of spring constants"),
    ("tip.radius", None, "required by the laws of Hertz's contact (hertz, dmt, electrostatic, jkr, capillary) with a shape that has a radius"),
    ("tip.youngs_modulus", Some(SILICON_YOUNGS_MODULUS), "130e9, silicon's (Hopcroft, Nix & Kenny 2010)"),
    ("tip.poisson_ratio", Some(SILICON_POISSON_RATIO), "0.27, silicon's"),
    ("tip.shape", None, "paraboloid"),
    ("tip.half_angle", None, "required by the cone and pyramid-4 shapes"),
    ("tip.face_angle", None, "required by the pyramid-3 shape"),
    ("cantilever.spring_constant", None, "required for a calibrated lever (eigenmodes: one per mode)"),
    ("cantilever.resonance_frequency", None, "required for a calibrated lever (eigenmodes: one per mode)"),
    ("cantilever.tip_mass_ratio", Some(0.0), "0 (no tip mass)"),
    ("cantilever.length", None, "required for a lever given by its geometry; a calibrated lever's plan (with width) is optional, for [medium]"),
    ("cantilever.width", None, "required for a lever given by its geometry; a calibrated lever's plan (with length) is optional, for [medium]"),
    ("cantilever.thickness", None, "required for a lever given by its geometry"),
    ("cantilever.youngs_modulus", None, "required for a lever given by its geometry"),
    ("cantilever.density", None, "required for a lever given by its geometry"),
    ("cantilever.tip_mass", Some(0.0), "0 (no tip mass)"),
    ("cantilever.quality_factor", None, "required (or the first of quality_factors)"),
    ("cantilever.quality_factors", None, "every mode damped by α3 = 1/Q₁ (the paper's eq. 12, s_j = 1)"),
    ("drive.mode", None, "tapping"),
    ("drive.free_amplitude", None, "required for tapping"),
    ("drive.frequency", None, "the lever's first resonance (in the medium, with one; an array's each component at its mode's)"),
    ("drive.excitation", None, "base"),
    ("drive.modulation_frequency", None, "required off resonance"),
    ("drive.modulation_amplitude", None, "required off resonance"),
    ("drive.modulated", None, "sample"),
    ("medium.name", None, "none: then density and viscosity are required"),
    ("medium.density", None, "the named medium's"),
    ("medium.viscosity", None, "the named medium's"),
    ("medium.calibrated_in", None, "air"),
    ("sample.law", None, "required"),
    ("sample.stiffness", None, "required"),
    ("sample.damping", Some(0.0), "0 (no damping)"),
    ("sample.z_c", None, "A₀, the free amplitude"),
    ("sample.youngs_modulus", None, "required"),
    ("sample.poisson_ratio", None, "required"),
    ("sample.hamaker", None, "required (jkr: or adhesion_energy)"),
    ("sample.intermolecular_distance", Some(DEFAULT_INTERMOLECULAR_DISTANCE), "0.165e-9 (Israelachvili 2011, §13.6)"),
    ("sample.viscosity", Some(0.0), "0 (no viscous loss)"),
    ("sample.bias_voltage", None, "required"),
    ("sample.contact_potential", Some(0.0), "0"),
    ("sample.adhesion_energy", None, "required (or hamaker, for W = H/(12πa₀²))"),
    ("sample.meniscus_volume", None, "required"),
    ("sample.surface_tension", Some(WATER_SURFACE_TENSION), "0.07197, water's at 25 °C (CRC Handbook)"),
    ("sample.contact_angle", Some(0.0), "0 (a fully wetting meniscus)"),
    ("sample.maxwell_stiffness", None, "required"),
    ("sample.relaxation_time", None, "required"),
    ("sample.restitution", None, "required"),
    ("feedback.time_constant", None, "a quarter of the lever's amplitude time 2Q/ω₀ (the image's sample file)"),
];
