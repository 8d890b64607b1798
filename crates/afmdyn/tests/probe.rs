//! Probe files (SI) → the dimensionless set: closed forms for the point mass, agreement with the
//! independent geometry path of `units` for the beam, defining identities (f₀, k, Q₁, A₀) and
//! the error list.

use afmdyn::eigen::{damped_eigenvalues, natural_modes};
use afmdyn::probe::{Probe, ProbeError};
use afmdyn::units::{Cantilever, PhysicalModel};
use afmdyn::{CantileverModel, ContactLaw, Region, Structure};
use std::f64::consts::TAU;
use std::path::Path;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

const POINT_MASS_DMT: &str = r#"
model = "point-mass"
[cantilever]
spring_constant = 40.0
resonance_frequency = 300e3
quality_factor = 400
[tip]
radius = 10e-9
youngs_modulus = 130e9
poisson_ratio = 0.27
[sample]
law = "dmt"
youngs_modulus = 4e9
poisson_ratio = 0.33
hamaker = 6.6e-20
intermolecular_distance = 0.165e-9
viscosity = 2.0
z_c = 7e-9
[drive]
free_amplitude = 10e-9
frequency = 301e3
"#;

/// Point mass: every group against its closed form written out here (García & San Paulo 1999
/// scaling: τ = ω₀t, lengths of A₀, forces of kA₀).
#[test]
fn point_mass_groups_match_closed_forms() {
    let p = Probe::parse(POINT_MASS_DMT, "test").unwrap();
    let q = &p.params;
    assert_eq!(q.structure, Structure::PointMass);
    let (k, f0, qf, a0, f): (f64, f64, f64, f64, f64) = (40.0, 300e3, 400.0, 10e-9, 301e3);
    let om = f / f0;
    assert!(rel(q.omega, om) < 1e-14);
    assert!(rel(q.alpha3, 1.0 / qf) < 1e-14);
    // F0/(k A0) = |1 − Ω² + iΩ/Q| gives the free amplitude A0
    let f0_drive = ((1.0 - om * om).powi(2) + (om / qf).powi(2)).sqrt();
    assert!(rel(q.alpha2, f0_drive) < 1e-12, "{} {}", q.alpha2, f0_drive);
    let e_star = 1.0 / ((1.0 - 0.27f64.powi(2)) / 130e9 + (1.0 - 0.33f64.powi(2)) / 4e9);
    let r: f64 = 10e-9;
    let force = k * a0;
    assert!(
        rel(
            q.alpha4,
            4.0 / 3.0 * e_star * r.sqrt() * a0.powf(1.5) / force
        ) < 1e-12
    );
    let ContactLaw::Dmt {
        hamaker,
        intermolecular_distance,
    } = q.contact_law
    else {
        panic!("dmt expected")
    };
    assert!(rel(hamaker, 6.6e-20 * r / (6.0 * a0 * a0 * force)) < 1e-12);
    assert!(rel(intermolecular_distance, 0.165e-9 / a0) < 1e-12);
    // Kelvin–Voigt η√(Rδ)δ̇: force unit kA0, rate A0 ω0
    let w0 = TAU * f0;
    assert!(rel(q.alpha6, 2.0 * (r * a0).sqrt() * a0 * w0 / force) < 1e-12);
    // rest distance z_c = (α5 + ã0) A0
    assert!(rel(p.z_c_of(q), 7e-9) < 1e-12);
    assert!(rel(q.alpha5, 7e-9 / a0 - 0.165e-9 / a0) < 1e-12);
    // scales
    assert!(rel(p.scales.time_s, 1.0 / w0) < 1e-14);
    assert!(rel(p.scales.force_n, force) < 1e-14);
    assert!(rel(p.scales.frequency_hz(q.omega), f) < 1e-12);
}

/// The model built from the probe has the free amplitude A₀ (1 in units of g₀ = A₀) and, for
/// the point mass at Ω = 1, the phase lag 90°.
#[test]
fn free_amplitude_is_a0() {
    for text in [
        POINT_MASS_DMT.to_string(),
        POINT_MASS_DMT.replace("frequency = 301e3", "frequency = 300e3"),
        std::fs::read_to_string(repo("examples/probe-beam-dmt.toml")).unwrap(),
        std::fs::read_to_string(repo("examples/probe-geometry-hertz.toml")).unwrap(),
    ] {
        let p = Probe::parse(&text, "test").unwrap();
        let m = CantileverModel::new(&p.params).unwrap();
        let h = m.free_tip_response().unwrap();
        assert!(rel(h.norm(), 1.0) < 1e-12, "{}", h.norm());
        if p.params.structure == Structure::PointMass && p.params.omega == 1.0 {
            assert!((-h.arg() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        }
    }
}

/// A₀ without harmonic balance: the free motion from rest, integrated in time by the adaptive
/// integrator (Dormand–Prince, tolerance 1e-11) with the sample out of reach (linear law,
/// α5 = 1e3: no tip force without contact), settles on W(1,τ) = Im(H e^{i(Ωτ+ψ)}) with the H of
/// `free_tip_response` — amplitude A₀ = 1 and its phase. H is read off the first Fourier
/// coefficient, H = 2i ⟨W e^{−i(Ωτ+ψ)}⟩, over one period sampled at 64 points (exact for a
/// harmonic) after 3000 periods (Q = 400: the transient is down to e^{−π·3000/400} ≈ 6e-11).
#[test]
fn free_amplitude_from_time_integration() {
    use afmdyn::integrate::{advance, build, IntegratorKind, IntegratorOptions};
    use nalgebra::Complex;
    for text in [
        POINT_MASS_DMT.to_string(),
        std::fs::read_to_string(repo("examples/probe-beam-dmt.toml")).unwrap(),
    ] {
        let p = Probe::parse(&text, "test").unwrap();
        let params = afmdyn::Params {
            contact_law: ContactLaw::Linear,
            alpha5: 1e3,
            ..p.params
        };
        let m = CantileverModel::new(&params).unwrap();
        let h = m.free_tip_response().unwrap();
        let opts = IntegratorOptions {
            kind: IntegratorKind::Adaptive,
            tolerance: 1e-11,
            ..IntegratorOptions::default()
        };
        let mut integ = build(&m, opts, 0.0, &m.rest()).unwrap();
        let (period, samples) = (m.period(), 64);
        let start = 3000.0 * period;
        let mut sum = Complex::new(0.0, 0.0);
        for k in 0..samples {
            let tau = start + period * k as f64 / samples as f64;
            advance(integ.as_mut(), tau).unwrap();
            let w = m.w_tip(integ.state());
            let theta = params.omega * tau + params.drive_phase();
            sum += Complex::from_polar(w, -theta);
        }
        let h_time = Complex::new(0.0, 2.0) * sum / samples as f64;
        eprintln!(
            "{:?}: H = {h}, from time integration {h_time}",
            params.structure
        );
        assert!(rel(h.norm(), 1.0) < 1e-12);
        assert!((h_time - h).norm() < 1e-8, "{h_time} against {h}");
    }
}

fn repo(rel: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

/// Calibrated beam: the resolved model's first natural frequency is f₀ (tip mass included), its
/// first-mode stiffness at the tip is k, and its first damped mode has quality factor Q₁
/// (exactly for α1 = 0, where C = α3 I is proportional to M = I; to O(1/Q²) with a tip mass).
#[test]
fn calibrated_beam_reproduces_f0_k_q() {
    for (alpha1, q_tol) in [(0.0, 1e-12), (0.5, 1e-5)] {
        let text = format!(
            r#"model = "beam"
modes = 4
[cantilever]
spring_constant = 2.0
resonance_frequency = 70e3
quality_factor = 150
tip_mass_ratio = {alpha1}
[sample]
law = "linear"
stiffness = 5.0
damping = 1e-8
[drive]
free_amplitude = 20e-9
"#
        );
        let p = Probe::parse(&text, "test").unwrap();
        let g = afmdyn::galerkin::Galerkin::new(&p.params).unwrap();
        let free = g.region(Region::Free);
        let modes = natural_modes(free);
        let f1 = p.scales.frequency_hz(modes.omega[0]);
        assert!(rel(f1, 70e3) < 1e-12, "f1 = {f1}");
        let x1 = modes.vectors.column(0);
        let tip = g.tip().dot(&x1);
        // mass-normalised x1: k1 = ω1²/(φᵀx1)² in units of force/length
        let k1 = modes.omega[0].powi(2) / (tip * tip) * p.scales.force_n / p.scales.length_m;
        assert!(rel(k1, 2.0) < 1e-12, "k1 = {k1}");
        let lam = damped_eigenvalues(free)[0];
        let q = (lam.re * lam.re + lam.im * lam.im).sqrt() / (-2.0 * lam.re);
        assert!(rel(q, 150.0) < q_tol, "alpha1 = {alpha1}: Q = {q}");
        // the linear sample: α4 = K/(k/k̃1) with k̃1 = ω̃1²/(φᵀx1)²
        let k1_dimless = modes.omega[0].powi(2) / (tip * tip);
        assert!(rel(p.params.alpha4, 5.0 * k1_dimless / 2.0) < 1e-12);
        assert_eq!(p.params.alpha1, alpha1);
    }
}

/// Round trip against the independent path of `units`: a probe given by its geometry and the
/// same system given to [`PhysicalModel::to_params`] (eqs. 5 and 7) give the same α's.
#[test]
fn geometry_probe_matches_units_path() {
    let text = r#"model = "beam"
modes = 3
[cantilever]
length = 125e-6
width = 40e-6
thickness = 3.7e-6
youngs_modulus = 169e9
density = 2330.0
tip_mass = 5.0e-13
quality_factor = 400
[sample]
law = "linear"
stiffness = 12.0
damping = 1e-7
z_c = 3e-9
[drive]
free_amplitude = 10e-9
frequency = 250e3
"#;
    let p = Probe::parse(text, "test").unwrap();
    let cantilever = Cantilever {
        length: 125e-6,
        width: 40e-6,
        thickness: 3.7e-6,
        youngs_modulus: 169e9,
        density: 2330.0,
    };
    let mut phys = PhysicalModel {
        cantilever,
        modes: 3,
        tip_mass: 5.0e-13,
        beam_damping: 0.0,
        contact_stiffness: 12.0,
        contact_damping: 1e-7,
        drive_amplitude: p.params.alpha2 * 10e-9,
        beam_gap: 10e-9,
        tip_gap: 3e-9,
        drive_frequency_hz: 250e3,
    };
    phys.beam_damping = afmdyn::units::beam_damping_from_q(&phys, 400.0).unwrap();
    let u = phys.to_params().unwrap();
    let q = &p.params;
    for (name, a, b) in [
        ("alpha1", q.alpha1, u.alpha1),
        ("alpha2", q.alpha2, u.alpha2),
        ("alpha3", q.alpha3, u.alpha3),
        ("alpha4", q.alpha4, u.alpha4),
        ("alpha5", q.alpha5, u.alpha5),
        ("alpha6", q.alpha6, u.alpha6),
        ("omega", q.omega, u.omega),
    ] {
        assert!(rel(a, b) < 1e-12, "{name}: probe {a} vs units {b}");
    }
    // the geometry gives the static stiffness 3EI/L³ and a modal k about 3 % above it
    let c = &p.calibration;
    assert!(rel(c.static_spring_constant, cantilever.spring_constant()) < 1e-14);
    assert!(c.spring_constant > c.static_spring_constant);
}

/// Per-mode quality factors of the bare beam (α1 = 0) are reproduced by the modal damping profile.
#[test]
fn per_mode_quality_factors() {
    let text = r#"model = "beam"
modes = 3
[cantilever]
spring_constant = 40.0
resonance_frequency = 300e3
quality_factors = [400, 600, 900]
[sample]
law = "impact"
restitution = 0.8
[drive]
free_amplitude = 10e-9
"#;
    let p = Probe::parse(text, "test").unwrap();
    let g = afmdyn::galerkin::Galerkin::new(&p.params).unwrap();
    let eig = damped_eigenvalues(g.region(Region::Free));
    for (lam, want) in eig.iter().zip([400.0, 600.0, 900.0]) {
        let q = (lam.re * lam.re + lam.im * lam.im).sqrt() / (-2.0 * lam.re);
        // Re λ = −|λ|/(2Q) carries the eigensolver's round-off of |λ| amplified by 2Q
        assert!(rel(q, want) < 1e-9, "Q = {q}, want {want}");
    }
}

/// Every problem is listed at once, each naming its key and section.
#[test]
fn errors_list_every_problem() {
    let text = r#"model = "beam"
colour = "red"
[cantilever]
spring_constant = -1.0
quality_factor = 400
[tip]
radius = 10e-9
[sample]
law = "dmt"
youngs_modulus = 4e9
poisson_ratio = 0.7
"#;
    let Err(ProbeError::Invalid { problems, .. }) = Probe::parse(text, "p.toml") else {
        panic!("must fail")
    };
    let all = problems.join("\n");
    for needle in [
        "unknown key colour",
        "missing key modes",
        "[cantilever].spring_constant = -1",
        "missing key [cantilever].resonance_frequency",
        "[sample].poisson_ratio = 0.7",
        "missing key [sample].hamaker",
        "missing table [drive]",
    ] {
        assert!(all.contains(needle), "'{needle}' not in:\n{all}");
    }
    // the tip's E and ν and a₀ have documented defaults: never reported missing
    for default in [
        "[tip].youngs_modulus",
        "[tip].poisson_ratio",
        "intermolecular_distance",
    ] {
        assert!(!all.contains(default), "'{default}' in:\n{all}");
    }
    // one readable line
    let msg = Probe::parse(text, "p.toml").unwrap_err().to_string();
    assert!(!msg.contains('\n') && msg.starts_with("p.toml: "));
    // syntax errors name the file; unreadable files their path
    assert!(matches!(
        Probe::parse("model = ", "x.toml"),
        Err(ProbeError::Syntax { .. })
    ));
    assert!(matches!(
        Probe::load(Path::new("/nonexistent/probe.toml")),
        Err(ProbeError::Io { .. })
    ));
    // keys of another law are unknown for this one
    let wrong = POINT_MASS_DMT.replace("viscosity = 2.0", "restitution = 0.5");
    let e = Probe::parse(&wrong, "t").unwrap_err().to_string();
    assert!(e.contains("unknown key [sample].restitution"), "{e}");
}

/// The example probe files resolve.
#[test]
fn examples_resolve() {
    for f in [
        "examples/probe-beam-dmt.toml",
        "examples/probe-point-mass-dmt.toml",
        "examples/probe-geometry-hertz.toml",
    ] {
        let p = Probe::load(&repo(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        p.params.validate().unwrap();
    }
}

/// The beam with N = 1 and the point-mass model built from the same calibrated probe
/// (k, f₀, Q, A₀, DMT sample, z_c) tap alike. They differ only by the drive: the beam's base
/// moves by b sin Ωτ (b = α2 g₀) in the gap and its inertial drive carries the base-velocity
/// damping −α2α3∫φ cos Ωτ (eq. 14), while the point mass is force-driven with a fixed base. The
/// tip–sample distances therefore differ by at most b ≈ A₀/(Q φ₁(1)∫φ₁ β₁⁴/Ω²) ≈ A₀/(1.57 Q)
/// at resonance (0.16 % of A₀ at Q = 400); amplitude (in A₀), phase (rad) and peak force
/// (relative) agree to within b.
#[test]
fn beam_n1_matches_point_mass_within_the_base_drive() {
    use afmdyn::analysis::observables::{observe, ObservableOptions};
    use afmdyn::analysis::shooting::{shoot, ShootingOptions};
    use afmdyn::integrate::{advance_dyn, build, IntegratorKind, IntegratorOptions};
    use afmdyn::maps::StroboscopicMap;
    let opts = IntegratorOptions {
        kind: IntegratorKind::Adaptive,
        steps_per_period: 1,
        tolerance: 1e-13,
        ..Default::default()
    };
    let steady = |text: &str| {
        let p = Probe::parse(text, "test").unwrap();
        let model = CantileverModel::new(&p.params).unwrap();
        let mut it = build(&model, opts.clone(), 0.0, &model.rest()).unwrap();
        advance_dyn(it.as_mut(), 3000.0 * model.period(), &mut |_, _, _| Ok(())).unwrap();
        let guess = it.state().clone();
        let o = shoot(
            &mut StroboscopicMap::new(it.as_mut(), 1),
            &guess,
            &ShootingOptions {
                tol: 1e-11,
                ..ShootingOptions::default()
            },
        )
        .unwrap();
        it.reset(0.0, &o.state).unwrap();
        let obs = observe(it.as_mut(), &ObservableOptions::default()).unwrap();
        (p, obs)
    };
    let base = std::fs::read_to_string(repo("examples/probe-point-mass-dmt.toml")).unwrap();
    let beam_text = base.replace("model = \"point-mass\"", "model = \"beam\"\nmodes = 1");
    let (pm, o_pm) = steady(&base);
    let (bm, o_bm) = steady(&beam_text);
    let b = bm.params.alpha2; // base amplitude in units of g0 = A0
    assert!(b < 1.0 / 400.0, "b = {b}");
    let s_pm = &pm.scales;
    let s_bm = &bm.scales;
    let da = (o_bm.amplitude - o_pm.amplitude).abs();
    let dphi = (o_bm.phase - o_pm.phase).abs();
    let dforce = (o_bm.peak_force * s_bm.force_n - o_pm.peak_force * s_pm.force_n).abs()
        / (o_pm.peak_force * s_pm.force_n).abs();
    eprintln!(
        "A/A0: beam {:.6} point mass {:.6} (Δ {da:.2e}); phase {:.4}° vs {:.4}°; peak force \
         {:.4e} N vs {:.4e} N (rel Δ {dforce:.2e}); base b = {b:.2e}",
        o_bm.amplitude,
        o_pm.amplitude,
        o_bm.phase.to_degrees(),
        o_pm.phase.to_degrees(),
        o_bm.peak_force * s_bm.force_n,
        o_pm.peak_force * s_pm.force_n
    );
    // both tap: the sample is within the free amplitude
    assert!(o_pm.amplitude < 0.95 && o_pm.peak_force > 0.0);
    // measured: ΔA = 8.3e-4 A0, Δφ = 7.1e-4 rad, peak forces within 2e-7, b = 1.6e-3
    assert!(da <= b, "ΔA = {da:e} against b = {b:e}");
    assert!(dphi <= b, "Δφ = {dphi:e} rad against b = {b:e}");
    assert!(dforce <= b, "peak force differs by {dforce:e}");
}

/// The law's name is read in any case (issue 28: `law = "DMT"`, as the literature writes it,
/// was refused): the same parameters as `law = "dmt"`.
#[test]
fn law_names_are_read_in_any_case() {
    let lower = Probe::parse(POINT_MASS_DMT, "test").unwrap();
    for name in ["DMT", "Dmt", " dmt "] {
        let text = POINT_MASS_DMT.replace("law = \"dmt\"", &format!("law = \"{name}\""));
        assert_ne!(text, POINT_MASS_DMT);
        let p = Probe::parse(&text, "test").unwrap();
        assert_eq!(p.params, lower.params, "{name}");
    }
}

/// Issue 28 item 6: a tip section without E and ν is a silicon tip (Hopcroft et al. 2010:
/// 130 GPa; ν 0.27, the paper's, from the one materials table) and a DMT sample without a₀ has a₀ = 0.165 nm (Israelachvili 2011): the
/// parameters equal those of the file with the values written out.
#[test]
fn omitted_tip_constants_and_a0_take_their_documented_defaults() {
    let full = std::fs::read_to_string("../../examples/probe-point-mass-dmt.toml").unwrap();
    let mut lines: Vec<String> = full.lines().map(String::from).collect();
    let set = |lines: &mut Vec<String>, key: &str, value: &str| {
        for l in lines.iter_mut() {
            if l.trim_start().starts_with(&format!("{key} ")) && l.contains('=') {
                *l = format!("{key} = {value}");
            }
        }
    };
    // the written-out file with the defaults' values in the tip and for a₀
    let mut written = lines.clone();
    let mut in_tip = false;
    for l in written.iter_mut() {
        if l.starts_with('[') {
            in_tip = l.trim() == "[tip]";
        } else if in_tip && l.starts_with("youngs_modulus") {
            *l = "youngs_modulus = 130e9".into();
        } else if in_tip && l.starts_with("poisson_ratio") {
            *l = "poisson_ratio = 0.27".into();
        }
    }
    set(&mut written, "intermolecular_distance", "0.165e-9");
    // the same file without them
    let mut in_tip = false;
    lines.retain(|l| {
        if l.starts_with('[') {
            in_tip = l.trim() == "[tip]";
        }
        !(in_tip && (l.starts_with("youngs_modulus") || l.starts_with("poisson_ratio")))
            && !l.starts_with("intermolecular_distance")
    });
    let short = lines.join("\n");
    assert!(!short.contains("intermolecular_distance"));
    let a = Probe::parse(&written.join("\n"), "written.toml").unwrap();
    let b = Probe::parse(&short, "short.toml").unwrap();
    assert_eq!(a.params, b.params);
    assert_eq!(
        afmdyn::probe::DEFAULT_INTERMOLECULAR_DISTANCE,
        0.165e-9,
        "Israelachvili's D0"
    );
}

/// Issue 28 item 6: values a unit slip away from any probe (a tip radius of 10 m for 10 nm, a
/// sample modulus of 4 Pa for 4 GPa, f0 = 300 Hz for 300 kHz, H = 6.6 J) are refused with the
/// reading that was meant, all at once.
#[test]
fn unit_slips_are_refused_with_the_meant_reading() {
    let full = std::fs::read_to_string("../../examples/probe-point-mass-dmt.toml").unwrap();
    let mut text = String::new();
    let mut section = String::new();
    for l in full.lines() {
        if l.starts_with('[') {
            section = l.trim().to_string();
        }
        let key = l.split('=').next().unwrap_or("").trim();
        let line = match (section.as_str(), key) {
            ("[tip]", "radius") => "radius = 10".to_string(),
            ("[sample]", "youngs_modulus") => "youngs_modulus = 0.5".to_string(),
            ("[sample]", "hamaker") => "hamaker = 6.6".to_string(),
            ("[cantilever]", "resonance_frequency") => "resonance_frequency = 300".to_string(),
            ("[drive]", "free_amplitude") => "free_amplitude = 1e-30".to_string(),
            _ => l.to_string(),
        };
        text.push_str(&line);
        text.push('\n');
    }
    let Err(ProbeError::Invalid { problems, .. }) = Probe::parse(&text, "slips.toml") else {
        panic!("must fail")
    };
    let all = problems.join("\n");
    for needle in [
        "[tip].radius = 10 (m): longer than 100 µm for a tip radius; probe files are in metres: \
         10 nm is 10e-9",
        "[sample].youngs_modulus = 0.5 (Pa): below 1 Pa",
        "0.5 GPa is 0.5e9",
        "[sample].hamaker = 6.6 (J): above 1e-17 J",
        // (it was refused naming alpha5 = 7.8e21, a group the user never wrote)
        "[drive].free_amplitude = 1e-30 (m): below 1 pm",
        "[cantilever].resonance_frequency = 300 (Hz): below 1 kHz for a cantilever; \
         frequencies are in Hz: 300 kHz is 300e3",
    ] {
        assert!(all.contains(needle), "'{needle}' not in:\n{all}");
    }
    // the example itself passes every check
    assert!(Probe::parse(&full, "example.toml").is_ok());
}

/// Soft matter below 100 Pa is a sample, not a unit slip (issue 77: E = 50 Pa was refused as
/// "softer than any cell", and a fit held two gels nanite reads at 56 and 73 Pa at 100 Pa):
/// accepted down to 1 Pa, with a warning below the 10 Pa of the softest gels.
#[test]
fn soft_gels_are_samples() {
    let full = std::fs::read_to_string("../../examples/probe-point-mass-dmt.toml").unwrap();
    let at = |e: &str| {
        let mut section = "";
        let text: Vec<String> = full
            .lines()
            .map(|l| {
                if l.starts_with('[') {
                    section = l.trim();
                }
                match (section, l.split('=').next().unwrap_or("").trim()) {
                    ("[sample]", "youngs_modulus") => format!("youngs_modulus = {e}"),
                    _ => l.to_string(),
                }
            })
            .collect();
        Probe::parse(&text.join("\n"), "gel.toml")
    };
    let gel = at("50").expect("a 50 Pa gel is a sample");
    assert!(!gel.warnings().iter().any(|w| w.contains("youngs_modulus")));
    let slip = at("4").expect("4 Pa: accepted with a warning");
    let w = slip.warnings().join("\n");
    assert!(
        w.contains("youngs_modulus") && w.contains("4 GPa is 4e9"),
        "{w}"
    );
}

/// A tip radius below an atom is refused (issue 77: 1e-308 m was accepted while 2 m was not).
#[test]
fn a_tip_radius_below_an_atom_is_refused() {
    let full = std::fs::read_to_string("../../examples/probe-point-mass-dmt.toml").unwrap();
    let at = |r: &str| {
        let text: Vec<String> = full
            .lines()
            .map(|l| match l.split('=').next().unwrap_or("").trim() {
                "radius" => format!("radius = {r}"),
                _ => l.to_string(),
            })
            .collect();
        Probe::parse(&text.join("\n"), "radius.toml")
    };
    let Err(ProbeError::Invalid { problems, .. }) = at("1e-308") else {
        panic!("must fail")
    };
    let all = problems.join("\n");
    assert!(
        all.contains("[tip].radius = 1e-308 (m): below 0.1 nm"),
        "{all}"
    );
    assert!(at("2e-10").is_ok(), "0.2 nm is accepted (with a warning)");
}

/// The units of a recorded trajectory: the probe's scales in SI (a velocity is a length over
/// a time), the model's own without a probe (factors 1; the point mass's force unit k g0).
#[test]
fn series_units_are_the_probe_scales() {
    use afmdyn::report::SeriesUnits;
    let text = std::fs::read_to_string("../../examples/probe-point-mass-dmt.toml").unwrap();
    let probe = Probe::parse(&text, "pm.toml").unwrap();
    let s = &probe.scales;
    let si = SeriesUnits::new(&probe.params, Some(&probe));
    assert_eq!(si.t(2.0), 2.0 * s.time_s);
    assert_eq!(si.x(3.0), 3.0 * s.length_m);
    assert_eq!(si.v(1.0), s.length_m / s.time_s);
    assert_eq!(si.force(1.0), s.force_n);
    assert_eq!(si.energy(1.0), s.energy_j());
    assert_eq!(si.u.hz_per_omega, Some(s.frequency_hz(1.0)));
    assert_eq!((si.names().time, si.names().force), ("t", "N"));
    let plain = SeriesUnits::new(&probe.params, None);
    assert_eq!((plain.t(2.0), plain.x(3.0), plain.v(4.0)), (2.0, 3.0, 4.0));
    assert_eq!((plain.names().time, plain.names().force), ("tau", "k g0"));
}

/// Issue 42 §4: `static_spring_constant` was 0 for every probe given by its calibrated k (the
/// point mass's included). The point mass's static stiffness is its spring k; a calibrated
/// beam's is 3EI/L³ = 3k/k̃₁, which for the bare beam (α1 = 0, k̃₁ = β₁⁴/4 with β₁ = 1.8751…,
/// the clamped–free root; Meirovitch §7.4) is k · 12/β₁⁴ (the modal stiffness 3 % above it).
#[test]
fn static_spring_constant_is_reported_for_every_probe() {
    let pm = Probe::parse(POINT_MASS_DMT, "test").unwrap();
    assert_eq!(pm.calibration.static_spring_constant, 40.0);
    let text = r#"model = "beam"
modes = 4
[cantilever]
spring_constant = 2.0
resonance_frequency = 70e3
quality_factor = 150
tip_mass_ratio = 0.0
[sample]
law = "linear"
stiffness = 5.0
[drive]
free_amplitude = 20e-9
"#;
    let beam = Probe::parse(text, "test").unwrap();
    let b1 = afmdyn::beam::beta_root(1);
    let want = 2.0 * 12.0 / b1.powi(4);
    let got = beam.calibration.static_spring_constant;
    // the 4-mode Galerkin beam's first mode is the exact one: k̃₁ = β₁⁴/4 to round-off
    assert!(rel(got, want) < 1e-9, "static k = {got}, 3EI/L³ = {want}");
}

/// A probe that names a library lever but gives its own k or f0 far from the maker's nominal
/// values (assets/cantilevers.toml: AC160TS-R3, 26 N/m and 300 kHz; a factor of 3 in k and 1.5
/// in f0, the makers' spreads) keeps its own values and warns, naming the key and the lever;
/// within the spread it is a calibration and does not warn; without a name nothing is compared.
#[test]
fn a_named_lever_with_another_levers_calibration_warns() {
    let probe = |cantilever: &str| {
        let text = format!(
            "model = \"point-mass\"\n[cantilever]\n{cantilever}\n[tip]\nradius = 7e-9\n[sample]\nlaw = \"dmt\"\nyoungs_modulus = 1e9\n\
             hamaker = 6.4e-20\npoisson_ratio = 0.3\n[drive]\nfree_amplitude = 10e-9\n"
        );
        Probe::parse(&text, "test").unwrap()
    };
    // a ScanAsyst-like calibration (0.4 N/m, 70 kHz) under the name of a 26 N/m lever
    let p = probe(
        "name = \"AC160TS-R3\"\nspring_constant = 0.4\nresonance_frequency = 70e3\nquality_factor = 80",
    );
    assert!(
        rel(p.calibration.spring_constant, 0.4) < 1e-12,
        "the file's k is used"
    );
    let w = p.warnings().join("\n");
    assert!(
        w.contains("[cantilever].spring_constant") && w.contains("65.0× below AC160TS-R3"),
        "{w}"
    );
    assert!(
        w.contains("[cantilever].resonance_frequency") && w.contains("4.3× below"),
        "{w}"
    );
    // a calibration within the spread: 30 N/m and 280 kHz
    let p = probe("name = \"AC160TS-R3\"\nspring_constant = 30.0\nresonance_frequency = 280e3");
    assert!(
        !p.warnings().iter().any(|w| w.contains("nominal")),
        "{:?}",
        p.warnings()
    );
    // the library's own values
    let p = probe("name = \"AC160TS-R3\"");
    assert!(
        !p.warnings().iter().any(|w| w.contains("nominal")),
        "{:?}",
        p.warnings()
    );
    // no name: nothing to compare with
    let p = probe("spring_constant = 0.4\nresonance_frequency = 70e3\nquality_factor = 80");
    assert!(
        !p.warnings().iter().any(|w| w.contains("nominal")),
        "{:?}",
        p.warnings()
    );
}
