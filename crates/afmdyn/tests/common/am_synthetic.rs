//! The dynamic fit's synthetic AM curves (`fit_dynamic.rs`, `fit_lever.rs`): an example
//! probe as the fit's probe, deterministic normal draws, a noisy curve made by the library's
//! own stepped approach at the probe's values (the truth), and the fit's start values.

use afmdyn::analysis::fit::am_curve::{AmCurveModel, AmParam, AmProbe};
use afmdyn::analysis::fit::{fit_with, CurveModel, FitOutcome, Observations, Parameter};
use afmdyn::probe::Probe;
use afmdyn::request::fit_dynamic::am_probe as am_probe_of;
use std::path::Path;

/// The example probe as the dynamic fit's probe.
pub fn am_probe(name: &str) -> AmProbe {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name);
    let p = Probe::load(&path).expect("example probe");
    am_probe_of(&p).expect("the fit's probe")
}

/// The probe's values of `params`, z_offset = `z_offset` (m): the truth of a synthetic curve.
pub fn truth(probe: &AmProbe, params: &[AmParam], z_offset: f64) -> Vec<f64> {
    params
        .iter()
        .map(|p| match p {
            AmParam::YoungsModulus => probe.youngs_modulus,
            AmParam::Hamaker => probe.hamaker,
            AmParam::ZOffset => z_offset,
            AmParam::TipRadius => probe.radius,
            AmParam::Damping => probe.params.alpha6 / probe.damping_unit,
            AmParam::QualityFactor => probe.quality_factor,
            AmParam::FreeAmplitude => probe.length_m,
        })
        .collect()
}

/// Standard normal draws (splitmix64 and Box–Muller: deterministic, no dependency).
pub struct Normal(pub u64);

impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    /// One N(0, 1) draw.
    pub fn draw(&mut self) -> f64 {
        let (u, v) = (self.uniform().max(1e-300), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// A synthetic AM approach of `rows` rows from z_c = `from` to `to` (units of A₀) with the
/// truth (E, H, z_offset = 1 nm): the model, the noisy data and σ (amplitude 0.02 nm, phase
/// 0.1°).
pub fn synthetic(
    name: &str,
    rows: usize,
    range: (f64, f64),
    params: Vec<AmParam>,
    channels: (bool, bool),
    seed: u64,
) -> (AmCurveModel, Vec<f64>, Vec<f64>, Vec<f64>) {
    synthetic_of(am_probe(name), rows, range, params, channels, seed)
}

/// [`synthetic`] under `probe`.
pub fn synthetic_of(
    probe: AmProbe,
    rows: usize,
    (from, to): (f64, f64),
    params: Vec<AmParam>,
    channels: (bool, bool),
    seed: u64,
) -> (AmCurveModel, Vec<f64>, Vec<f64>, Vec<f64>) {
    let g0 = probe.length_m;
    let z_offset = 1e-9;
    let z: Vec<f64> = (0..rows)
        .map(|i| g0 * (from + (to - from) * i as f64 / (rows - 1) as f64) - z_offset)
        .collect();
    let model = AmCurveModel::new(probe, z, channels, params.clone());
    let truth = truth(&probe, &params, z_offset);
    let mut y = vec![0.0; model.points()];
    model.evaluate(&truth, &mut y, None);
    let mut sigma = Vec::new();
    if channels.0 {
        sigma.extend(std::iter::repeat_n(2e-11, rows));
    }
    if channels.1 {
        sigma.extend(std::iter::repeat_n(0.1, rows));
    }
    let mut normal = Normal(seed);
    for (v, s) in y.iter_mut().zip(&sigma) {
        *v += s * normal.draw();
    }
    (model, y, sigma, truth)
}

/// The fit's parameters, started off the truth (E × 0.9, H × 1.1, z_offset 0.8 nm, R × 1.3): a
/// start far off (E × 0.6, z_offset 0) stalled at χ²/dof ≈ 185 with E = 2 GPa — the stepped
/// approach's first rows follow another branch there (a local minimum).
pub fn parameters(probe: &AmProbe, params: &[AmParam]) -> Vec<Parameter> {
    params
        .iter()
        .map(|p| {
            let (start, lower, upper, scale) = match p {
                // one-sided bounds: MINUIT's sine map of a two-sided range squashes a value
                // near its lower end (E = 4 GPa in [0.1 MPa, 1 TPa])
                AmParam::YoungsModulus => (
                    0.6 * probe.youngs_modulus,
                    1e5,
                    f64::INFINITY,
                    probe.youngs_modulus,
                ),
                AmParam::Hamaker => (1.1 * probe.hamaker, 0.0, f64::INFINITY, probe.hamaker),
                AmParam::ZOffset => (0.8e-9, -5e-9, 5e-9, 1e-9),
                AmParam::TipRadius => (1.3 * probe.radius, 1e-10, f64::INFINITY, probe.radius),
                AmParam::Damping => {
                    let c = probe.params.alpha6 / probe.damping_unit;
                    (0.7 * c, 0.0, f64::INFINITY, c)
                }
                AmParam::QualityFactor => {
                    let q = probe.quality_factor;
                    (0.8 * q, 0.0, f64::INFINITY, q)
                }
                AmParam::FreeAmplitude => {
                    let a0 = probe.length_m;
                    (0.95 * a0, 1e-12, f64::INFINITY, a0)
                }
            };
            Parameter {
                name: p.name().into(),
                start,
                lower,
                upper,
                scale,
            }
        })
        .collect()
}

/// The fit of `model` to `y` (σ `sigma`) from [`parameters`], without profiles.
pub fn run_fit(model: &AmCurveModel, y: &[f64], sigma: &[f64]) -> FitOutcome {
    let params = parameters(&model.probe, &model.params);
    let obs = Observations {
        y,
        sigma: Some(sigma),
    };
    let fixed = vec![None; params.len()];
    fit_with(model, &obs, &params, &fixed, false)
}
