//! Profile-likelihood intervals of the dynamic AM fit (issue 62: "profile-likelihood intervals
//! for each fitted parameter (up to 4)", "a flat profile" warning) and the cancellation of a
//! dynamic fit, on short synthetic approaches of the example point mass
//! (`examples/probe-point-mass-dmt.toml`) made with the library, seeded Gaussian noise:
//! - each end of a profile interval satisfies its defining identity, Δχ² = 3.841 of a refit
//!   with the parameter held there (recomputed here from the fit's estimates, not the walk's
//!   neighbour), within the secant walk's tolerance;
//! - where the parameters are well identified the profile and Wald intervals agree within a
//!   tolerance derived from the model's curvature along the profile's path (they coincide for a
//!   model linear in its parameters, Bates & Watts 1988 §2.3);
//! - a parameter the data do not constrain gets the flat-profile warning;
//! - a cancelled fit returns `SimError::Cancelled` after at most one more model evaluation,
//!   whether the flag is set during the minimisation or during the profiles' refits, and every
//!   evaluation is counted in the run's `Progress`.

use afmdyn::analysis::fit::am_curve::{AmCurveModel, AmParam, AmProbe};
use afmdyn::analysis::fit::least_squares::minimize;
use afmdyn::analysis::fit::profile::{MAX_SECANT_STEPS, SECANT_TOLERANCE};
use afmdyn::analysis::fit::{
    fit_cancellable, CurveModel, FitOutcome, Observations, Parameter, ProfileEnd, ProfileWalk,
};
use afmdyn::analysis::progress::Progress;
use afmdyn::probe::Probe;
use afmdyn::request::fit_dynamic::am_probe as am_probe_of;
use afmdyn::SimError;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use super::common;
use common::am_synthetic::synthetic_with_noise;

/// The 95 % quantile of χ²₁ (the profile's threshold), written out here: 1.959964² = 3.841459.
const THRESHOLD: f64 = 3.841_458_820_694_124;

/// The standard normal's 97.5 % quantile, √3.841459.
const Z_95: f64 = 1.959_963_984_540_054;

/// The secant walk's tolerance on r = √Δχ² at an end, in half-widths: |Δχ² − 3.841| ≤ 0.05 is
/// |r − 1.96| ≤ 0.05/(2 × 1.96) = 0.0128, 0.65 % of 1.96.
const WALK: f64 = 0.0065;

const SECANT: ProfileWalk = ProfileWalk::Secant {
    max_steps: MAX_SECANT_STEPS,
};

/// The example point mass as the dynamic fit's probe.
fn am_probe() -> AmProbe {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-point-mass-dmt.toml");
    let p = Probe::load(&path).expect("example probe");
    am_probe_of(&p).expect("the fit's probe")
}

/// A synthetic curve: the model of `rows` rows from z_c = `from` to `to` (A₀) with the truth
/// (the probe's E, H, R and z_offset = 1 nm), the data with noise σ = `sigma` (amplitude m,
/// phase deg) and the σ column, and the truth of `params`.
struct Curve {
    model: AmCurveModel,
    y: Vec<f64>,
    sigma: Vec<f64>,
    truth: Vec<f64>,
}

fn synthetic(
    rows: usize,
    range: (f64, f64),
    params: Vec<AmParam>,
    channels: (bool, bool),
    noise: (f64, f64),
    seed: u64,
) -> Curve {
    let (model, y, sigma, truth) =
        synthetic_with_noise(am_probe(), rows, range, params, channels, noise, seed);
    Curve {
        model,
        y,
        sigma,
        truth,
    }
}

/// The fit's parameters, started at the truth (the minimum the data make, not a local one):
/// one-sided bounds as the door's.
fn parameters(c: &Curve) -> Vec<Parameter> {
    let probe = &c.model.probe;
    c.model
        .params
        .iter()
        .zip(&c.truth)
        .map(|(p, &t)| {
            let (lower, upper, scale) = match p {
                AmParam::YoungsModulus => (1e5, f64::INFINITY, probe.youngs_modulus),
                AmParam::Hamaker => (0.0, f64::INFINITY, probe.hamaker),
                AmParam::ZOffset => (-5e-9, 5e-9, 1e-9),
                AmParam::TipRadius => (1e-10, f64::INFINITY, probe.radius),
                AmParam::Damping => (0.0, f64::INFINITY, probe.params.alpha6 / probe.damping_unit),
                AmParam::QualityFactor => (0.0, f64::INFINITY, probe.quality_factor),
                AmParam::FreeAmplitude => (1e-12, f64::INFINITY, probe.length_m),
                AmParam::AdhesionEnergy => (0.0, f64::INFINITY, probe.adhesion_energy()),
                AmParam::Viscosity => (0.0, f64::INFINITY, probe.viscosity()),
            };
            Parameter {
                name: p.name().into(),
                start: t,
                lower,
                upper,
                scale,
            }
        })
        .collect()
}

fn obs(c: &Curve) -> Observations<'_> {
    Observations {
        y: &c.y,
        sigma: Some(&c.sigma),
    }
}

/// E, H and z_offset from 30 rows of amplitude and phase on the repulsive branch below the
/// approach's fold (z_c = 7.5 → 3 nm), at a fifth of scripts/perf-fit-dynamic.sh's noise
/// (σ = 4 pm, 0.02°): well identified.
fn well_identified() -> Curve {
    synthetic(
        30,
        (0.75, 0.3),
        vec![AmParam::YoungsModulus, AmParam::Hamaker, AmParam::ZOffset],
        (true, true),
        (4e-12, 0.02),
        62,
    )
}

/// Δχ² of a refit with parameter `j` held at `x`, the others refitted from the fit's
/// estimates `values` (not from the walk's neighbouring point), σ given (s² = 1).
fn delta_chi2_at(c: &Curve, out: &FitOutcome, j: usize, x: f64) -> f64 {
    let params = parameters(c);
    let mut held = vec![None; params.len()];
    held[j] = Some(x);
    let m = minimize(&c.model, &obs(c), &params, &out.values, &held);
    m.chi2 - out.chi2
}

/// The profile's ends are where Δχ² = 3.841 (recomputed by an independent refit), and they
/// are the Wald ends p̂ ± 1.96 SE moved by the model's nonlinearity, which the profile at the
/// Wald ends measures.
///
/// The tolerance: for a model linear in its parameters the profile is the parabola
/// Δχ²(x) = ((x − p̂)/SE)² and r = √Δχ² = |x − p̂|/SE is linear: the profile and Wald ends
/// coincide (profile.rs's unit test, to 1e-9). A nonlinear model bends r; to first order in
/// the bend r stays linear between p̂ and the end, so an independent refit at the Wald end,
/// Δχ²_w = r_w², predicts the profile end beyond the Wald end by (1.96/r_w − 1) half-widths
/// (1.96 SE). The test allows the second-order rest half the first-order offset, plus the
/// secant walk's tolerance on r (0.65 % of the half-width), and asks z_offset to be well
/// identified (a predicted offset below 0.15).
#[test]
fn profile_ends_are_the_crossings_and_the_wald_ends_of_a_well_identified_fit() {
    let c = well_identified();
    let params = parameters(&c);
    let fixed = vec![None; params.len()];
    let progress = Progress::new();
    let out =
        fit_cancellable(&c.model, &obs(&c), &params, &fixed, Some(SECANT), &progress).expect("fit");
    eprintln!(
        "χ²/dof {:.3}, {} evaluations, {:?}",
        out.chi2_dof, out.evaluations, out.warnings
    );
    // every evaluation is counted in the run's progress
    assert_eq!(progress.done(), out.evaluations);
    assert!(out.chi2_dof < 2.0, "χ²/dof {}", out.chi2_dof);
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    let se: Vec<f64> = out.estimates.iter().map(|e| e.standard_error).collect();
    for (j, e) in out.estimates.iter().enumerate() {
        let pr = e.profile.as_ref().expect("profiled");
        let (ProfileEnd::Crossing(lo), ProfileEnd::Crossing(hi)) = (pr.lower, pr.upper) else {
            panic!("{}: ends {:?}, {:?}", e.name, pr.lower, pr.upper);
        };
        assert_eq!(e.interval, [lo, hi]);
        // the defining identity, recomputed from the estimates
        for x in [lo, hi] {
            let d = delta_chi2_at(&c, &out, j, x);
            eprintln!("{}: Δχ²({x:.6e}) = {d:.4}", e.name);
            assert!(
                (d - THRESHOLD).abs() <= SECANT_TOLERANCE + 1e-3,
                "{}: Δχ² = {d} at the end {x:e}",
                e.name
            );
        }
        // the profile at the Wald ends, refitted from the estimates: for a locally linear
        // model Δχ² = 3.841 there; else, with r = √Δχ² linear in x between the estimate and
        // the end, the end is at |x − p̂| = 1.96 SE × 1.96/r_w, beyond the Wald end by
        // (1.96/r_w − 1) half-widths
        let half = Z_95 * se[j];
        for (side, (end, wald)) in [(lo, e.wald[0]), (hi, e.wald[1])].into_iter().enumerate() {
            let d_w = delta_chi2_at(&c, &out, j, wald);
            let predicted = Z_95 / d_w.sqrt() - 1.0;
            let measured = (end - wald).abs() / half
                * if (end - e.value).abs() >= (wald - e.value).abs() {
                    1.0
                } else {
                    -1.0
                };
            let tol = 0.5 * predicted.abs() + WALK;
            eprintln!(
                "{} {}: Δχ² at the Wald end {d_w:.4}: the end beyond it by {measured:.4} \
                 half-widths, {predicted:.4} predicted; Wald and profile agree within {:.4}",
                e.name,
                ["lower", "upper"][side],
                predicted.abs() + tol
            );
            assert!(
                (measured - predicted).abs() <= tol,
                "{} {}: the end off the Wald end by {measured} half-widths, {predicted} predicted",
                e.name,
                ["lower", "upper"][side]
            );
            if e.name == "z_offset" {
                assert!(
                    predicted.abs() < 0.15,
                    "z_offset not well identified: {predicted}"
                );
            }
        }
        assert!(pr.refits <= 2 * MAX_SECANT_STEPS, "{}", e.name);
    }
}

/// A parameter the data do not constrain: E from 20 rows of amplitude and phase where the
/// tip never touches (z_c = 13 → 10 nm, A₀ = 10 nm; the orbits do not feel E, its
/// sensitivity is exactly 0): its profile does not rise within the walk's refits and the fit
/// warns of a flat profile, while H (the van der Waals force's) crosses on both sides.
#[test]
fn an_unconstrained_parameter_has_a_flat_profile() {
    let c = synthetic(
        20,
        (1.4, 1.1),
        vec![AmParam::YoungsModulus, AmParam::Hamaker],
        (true, true),
        (2e-11, 0.1),
        7,
    );
    let params = parameters(&c);
    let progress = Progress::new();
    let out = fit_cancellable(
        &c.model,
        &obs(&c),
        &params,
        &[None; 2],
        Some(SECANT),
        &progress,
    )
    .expect("fit");
    eprintln!("χ²/dof {:.3}, {:?}", out.chi2_dof, out.warnings);
    for e in &out.estimates {
        eprintln!(
            "{} {:e} ± {:e} {:?}",
            e.name,
            e.value,
            e.standard_error,
            e.profile
                .as_ref()
                .map(|p| (p.lower, p.upper, p.points.clone()))
        );
    }
    let flat = |name: &str| {
        out.warnings
            .iter()
            .any(|w| w.starts_with(name) && w.contains("flat profile"))
    };
    assert!(flat("sample.youngs_modulus"), "{:?}", out.warnings);
    assert!(!flat("sample.hamaker"), "{:?}", out.warnings);
    let e = &out.estimates[0];
    let pr = e.profile.as_ref().expect("profiled");
    eprintln!("E: {:?} {:?}, points {:?}", pr.lower, pr.upper, pr.points);
    assert!(
        matches!(pr.upper, ProfileEnd::Flat(_)),
        "upper end {:?}",
        pr.upper
    );
    // E moves nothing: every point walked is at the fit's χ²
    assert!(
        pr.points.iter().all(|(_, d)| d.abs() < 1e-6),
        "{:?}",
        pr.points
    );
    let h = out.estimates[1].profile.as_ref().expect("profiled");
    assert!(
        matches!(
            (h.lower, h.upper),
            (ProfileEnd::Crossing(_), ProfileEnd::Crossing(_))
        ),
        "H: {:?}, {:?}",
        h.lower,
        h.upper
    );
}

/// A model that counts its evaluations and cancels the run at the `at`-th: the fit's
/// observer.
struct CancelAt<'a> {
    inner: &'a AmCurveModel,
    count: AtomicUsize,
    at: usize,
    progress: &'a Progress,
}

impl CurveModel for CancelAt<'_> {
    fn points(&self) -> usize {
        self.inner.points()
    }
    fn evaluate(&self, p: &[f64], values: &mut [f64], jacobian: Option<&mut [f64]>) {
        self.evaluate_cancellable(p, values, jacobian, &AtomicBool::new(false));
    }
    fn evaluate_cancellable(
        &self,
        p: &[f64],
        values: &mut [f64],
        jacobian: Option<&mut [f64]>,
        cancel: &AtomicBool,
    ) {
        let k = self.count.fetch_add(1, Ordering::Relaxed) + 1;
        self.inner.evaluate_cancellable(p, values, jacobian, cancel);
        if k == self.at {
            self.progress.cancel();
        }
    }
}

/// A fit cancelled during the minimisation, or during the profiles' refits, returns
/// `Cancelled` after at most one more evaluation (here none: each evaluation checks the flag
/// before it starts); and a model evaluation started with the flag set stops before its first
/// row (its values NaN).
#[test]
fn a_cancelled_dynamic_fit_stops_within_one_evaluation() {
    let c = synthetic(
        16,
        (0.75, 0.3),
        vec![AmParam::YoungsModulus, AmParam::ZOffset],
        (true, false),
        (2e-11, 0.1),
        3,
    );
    let params = parameters(&c);
    let fixed = [None; 2];
    let run = |at: usize| {
        let progress = Progress::new();
        let model = CancelAt {
            inner: &c.model,
            count: AtomicUsize::new(0),
            at,
            progress: &progress,
        };
        let r = fit_cancellable(&model, &obs(&c), &params, &fixed, Some(SECANT), &progress);
        (r, model.count.load(Ordering::Relaxed), progress.done())
    };
    let (whole, total, done) = run(usize::MAX);
    let whole = whole.expect("fit");
    assert_eq!((total, done), (whole.evaluations, whole.evaluations));
    let in_profiles = whole
        .estimates
        .iter()
        .map(|e| e.profile.as_ref().unwrap().evaluations);
    let profiled: usize = in_profiles.sum();
    eprintln!("{total} evaluations, {profiled} in the profiles");
    assert!(profiled > 4, "{profiled}");
    // in the minimiser (its 3rd evaluation), in the first profile, in the last refit
    for at in [3, total - profiled + 2, total - 2] {
        let (r, count, _) = run(at);
        assert!(matches!(r, Err(SimError::Cancelled)), "at {at}: {r:?}");
        assert!(count <= at + 1, "cancelled at {at}, {count} evaluations");
    }
    // the flag set before an evaluation: no row is stepped, the values are NaN
    let mut v = vec![0.0; c.model.points()];
    c.model
        .evaluate_cancellable(&c.truth, &mut v, None, &AtomicBool::new(true));
    assert!(v.iter().all(|x| x.is_nan()), "{v:?}");
    c.model.evaluate(&c.truth, &mut v, None);
    assert!(v.iter().all(|x| x.is_finite()), "{v:?}");
}

/// The declared cost of a dynamic fit (held against the budget before it runs) counts the
/// profiles' refits: with `profiles` the work grows by 2 × [`MAX_SECANT_STEPS`] refits of the
/// other parameters per fitted parameter, each at most the refits' limit of evaluations
/// (`least_squares::max_evaluations` at `REFIT_PATIENCE`), over the fit's own z_offset grid (13), minimiser and 2
/// evaluations; every evaluation the same stepped approach of the rows. The 100-row point-mass
/// fit with profiles is admitted; a 2000-row one is refused, advising fewer rows or no profiles.
#[test]
fn the_declared_cost_counts_the_profiles_refits() {
    use afmdyn::analysis::fit::least_squares::{max_evaluations, PATIENCE};
    use afmdyn::analysis::fit::profile::REFIT_PATIENCE;
    use afmdyn::request::fit::FitRequest;
    use afmdyn::request::{admit, Request, Resolved};
    let dir = std::env::temp_dir().join(format!("afmdyn-fit-cost-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("am.csv");
    let mut text = String::from("z,amplitude\n");
    for i in 0..100 {
        text += &format!("{:e},{:e}\n", 7.5e-9 - 4.5e-11 * i as f64, 8e-9);
    }
    std::fs::write(&path, text).expect("csv");
    let p = Probe::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-point-mass-dmt.toml"),
    )
    .expect("probe");
    let resolved = Resolved {
        params: p.params,
        probe: Some(p),
    };
    let request = |profiles: Option<bool>| FitRequest {
        data: Some(path.display().to_string()),
        fit: vec![
            "sample.youngs_modulus".into(),
            "sample.hamaker".into(),
            "z_offset".into(),
        ],
        profiles,
        ..FitRequest::default()
    };
    let without = request(None).cost(&resolved).expect("cost");
    let with = request(Some(true)).cost(&resolved).expect("cost");
    assert_eq!(request(Some(false)).cost(&resolved).expect("cost"), without);
    admit(&request(Some(true)), &resolved).expect("admitted");
    // 2000 rows with profiles are beyond the budget: refused before running, the advice
    // naming the rows and the profiles (not points or periods)
    let mut text = String::from("z,amplitude\n");
    for i in 0..2000 {
        text += &format!("{:e},{:e}\n", 7.5e-9 - 2.25e-12 * i as f64, 8e-9);
    }
    std::fs::write(&path, text).expect("csv");
    let e = request(Some(true)).cost(&resolved).unwrap_err().to_string();
    assert!(e.contains("rows") && e.contains("without profiles"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
    let fit = (13 + max_evaluations(3, PATIENCE) + 2) as f64;
    let refits = (3 * 2 * MAX_SECANT_STEPS) as f64 * max_evaluations(2, REFIT_PATIENCE) as f64;
    eprintln!(
        "declared work: {:.3e} mode-periods, {:.3e} with profiles",
        without.work, with.work
    );
    assert!(without.work > 0.0);
    let ratio = with.work / without.work;
    assert!(
        (ratio - (fit + refits) / fit).abs() <= 1e-12 * ratio,
        "{ratio} against {}",
        (fit + refits) / fit
    );
}
