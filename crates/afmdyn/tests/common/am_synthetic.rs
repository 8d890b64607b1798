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
            AmParam::AdhesionEnergy => probe.adhesion_energy(),
            AmParam::Viscosity => probe.viscosity(),
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
    range: (f64, f64),
    params: Vec<AmParam>,
    channels: (bool, bool),
    seed: u64,
) -> (AmCurveModel, Vec<f64>, Vec<f64>, Vec<f64>) {
    synthetic_with_noise(probe, rows, range, params, channels, (2e-11, 0.1), seed)
}

/// [`synthetic_of`] with the noise σ = (amplitude m, phase deg).
pub fn synthetic_with_noise(
    probe: AmProbe,
    rows: usize,
    (from, to): (f64, f64),
    params: Vec<AmParam>,
    channels: (bool, bool),
    (sa, sp): (f64, f64),
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
        sigma.extend(std::iter::repeat_n(sa, rows));
    }
    if channels.1 {
        sigma.extend(std::iter::repeat_n(sp, rows));
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
                AmParam::Viscosity => {
                    let eta = probe.viscosity();
                    (0.7 * eta, 0.0, f64::INFINITY, eta)
                }
                AmParam::AdhesionEnergy => {
                    let w = probe.adhesion_energy();
                    (1.3 * w, 0.0, f64::INFINITY, w)
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

/// The AM model's Jacobian at `truth` against central differences of its values (steps 1e-4
/// of each value), column by column: the parameter's name, the worst relative gap over the
/// rows (relative to the entry, or to 1e-3 of the channel's largest entry where it is
/// smaller), and the largest |∂φ/∂p| of the phase rows (0 without them), after asserting that the
/// Jacobian's evaluation has no warnings.
pub fn jacobian_gaps(model: &AmCurveModel, truth: &[f64]) -> Vec<(&'static str, f64, f64)> {
    let m = model.points();
    let n = truth.len();
    let mut v = vec![0.0; m];
    let mut jac = vec![0.0; m * n];
    model.evaluate(truth, &mut v, Some(&mut jac));
    assert!(model.warnings().is_empty(), "{:?}", model.warnings());
    let phase_rows = if model.channels.1 {
        m - model.z.len()..m
    } else {
        m..m
    };
    (0..n)
        .map(|k| {
            let h = 1e-4 * truth[k].abs();
            let (mut up, mut down) = (truth.to_vec(), truth.to_vec());
            up[k] += h;
            down[k] -= h;
            let (mut vu, mut vd) = (vec![0.0; m], vec![0.0; m]);
            model.evaluate(&up, &mut vu, None);
            model.evaluate(&down, &mut vd, None);
            let fd = |i: usize| (vu[i] - vd[i]) / (2.0 * h);
            // relative to the entry, or to 1e-3 of its channel's largest where the entry is
            // smaller (a free row feels Q₁ not at all: 0 against the integration's round-off)
            let rows = model.z.len();
            let largest = |c: usize| {
                (c * rows..(c + 1) * rows)
                    .map(|i| jac[i * n + k].abs())
                    .fold(0.0, f64::max)
            };
            let floors: Vec<f64> = (0..m / rows).map(|c| 1e-3 * largest(c)).collect();
            let worst = (0..m)
                .map(|i| {
                    let e = jac[i * n + k];
                    let scale = e.abs().max(fd(i).abs()).max(floors[i / rows]).max(1e-300);
                    (e - fd(i)).abs() / scale
                })
                .fold(0.0, f64::max);
            let phase_max = phase_rows
                .clone()
                .map(|i| jac[i * n + k].abs())
                .fold(0.0, f64::max);
            let name = model.params[k].name();
            eprintln!(
                "{name}: worst relative gap {worst:.2e} (row 0: jac {:.4e}, fd {:.4e}; largest \
                 |∂φ/∂p| {phase_max:.3e})",
                jac[k],
                fd(0)
            );
            (name, worst, phase_max)
        })
        .collect()
}

/// The synthetic curve `y` (σ `sigma`, the model's rows and channels) written as an AM CSV to a
/// fresh temporary directory named by `tag` and fitted through the door (`afmdyn fit`'s
/// request) for the parameters `fit` (the request's default when empty) under the probe `p`:
/// the document, or the request's error.
pub fn door(
    p: Probe,
    model: &AmCurveModel,
    y: &[f64],
    sigma: &[f64],
    fit: &[&str],
    tag: &str,
) -> Result<serde_json::Value, afmdyn::SimError> {
    use afmdyn::analysis::progress::Progress;
    use afmdyn::request::fit::FitRequest;
    use afmdyn::request::{run, Resolved};
    let dir = std::env::temp_dir().join(format!("afmdyn-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("am.csv");
    let m = model.z.len();
    // the channels' columns: values and σ of channel c at y[c m + i], sigma[c m + i]
    let names: Vec<&str> = [("amplitude", model.channels.0), ("phase", model.channels.1)]
        .into_iter()
        .filter_map(|(n, on)| on.then_some(n))
        .collect();
    let mut text = String::from("z");
    for n in &names {
        text += &format!(",{n}");
    }
    for n in &names {
        text += &format!(",sigma_{n}");
    }
    text.push('\n');
    for (i, z) in model.z.iter().enumerate() {
        text += &format!("{z:?}");
        for c in 0..names.len() {
            text += &format!(",{:?}", y[c * m + i]);
        }
        for c in 0..names.len() {
            text += &format!(",{:?}", sigma[c * m + i]);
        }
        text.push('\n');
    }
    std::fs::write(&path, text).expect("csv");
    let resolved = Resolved {
        params: p.params,
        probe: Some(p),
    };
    let mut request = FitRequest {
        data: Some(path.display().to_string()),
        ..FitRequest::default()
    };
    // none named: the request's default parameters
    if !fit.is_empty() {
        request.fit = fit.iter().map(|n| n.to_string()).collect();
    }
    let doc = run(&request, &resolved, &Progress::default()).map(|o| o.json);
    std::fs::remove_dir_all(&dir).ok();
    doc
}

/// A document's 95 % interval of `name`.
pub fn interval(doc: &serde_json::Value, name: &str) -> [f64; 2] {
    let e = &doc["estimates"][name];
    [
        e["interval"][0].as_f64().unwrap(),
        e["interval"][1].as_f64().unwrap(),
    ]
}

/// Print the fit's outcome under `what` and assert that each estimate's 95 % interval holds
/// its truth (`truth`, in the fit's order), that each standard error is below `se_share` of
/// the truth's magnitude when given (an estimate, not an unconstrained one), and that χ²/dof
/// lies in `chi2` (noise drawn from the σ given: near 1).
pub fn assert_recovered(
    out: &FitOutcome,
    truth: &[f64],
    what: &str,
    se_share: Option<f64>,
    chi2: std::ops::Range<f64>,
) {
    eprintln!(
        "{what}: {} evaluations ({}), χ²/dof {:.3}, {:?}",
        out.evaluations, out.termination, out.chi2_dof, out.warnings
    );
    for (e, t) in out.estimates.iter().zip(truth) {
        eprintln!(
            "{}: {:.6e} ± {:.3e} [{:.6e}, {:.6e}] (truth {t:.6e})",
            e.name, e.value, e.standard_error, e.interval[0], e.interval[1]
        );
        assert!(
            (e.interval[0]..=e.interval[1]).contains(t),
            "{what} {}: the interval misses the truth",
            e.name
        );
        if let Some(share) = se_share {
            assert!(e.standard_error < share * t.abs(), "{what} {}", e.name);
        }
    }
    assert!(
        chi2.contains(&out.chi2_dof),
        "{what}: χ²/dof {}",
        out.chi2_dof
    );
}
