//! `afmdyn modes` and `afmdyn units`.

use crate::args::{read_toml, ModelArgs};
use crate::error::CliError;
use crate::output::{f, write_csv, OutDir, TextUnits};
use crate::plot::{save, Figure, Series, Style};
use afmdyn::analysis::progress::Progress;
use afmdyn::eigen::fig3_sweep;
use afmdyn::request::{self, Document, ModesRequest, Resolved};
use afmdyn::units::{
    beam_damping_from_q, contact_stiffness, material, Cantilever, ContactStiffness, Material,
    PhysicalModel, SILICON_TIP,
};
use afmdyn::Params;
use clap::Args;
use serde::Deserialize;
use serde_json::json;
use std::path::PathBuf;

/// `afmdyn modes` flags.
#[derive(Debug, Args)]
pub struct ModesArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Print one JSON document instead of a table
    #[arg(long)]
    json: bool,
    /// Run a sweep instead: `fig3` (ω₁/ω₀₁ and ω₂/ω₀₂ over α1 × α4, paper Fig. 3)
    #[arg(long, value_parser = ["fig3"])]
    sweep: Option<String>,
    /// Output directory of the sweep
    #[arg(long, default_value = "afmdyn-out/modes")]
    out: PathBuf,
}

/// Run `afmdyn modes`.
pub fn modes(a: &ModesArgs) -> Result<(), CliError> {
    let (p, probe) = a.model.resolve(Params::default())?;
    if a.sweep.is_some() {
        return fig3(a, &p);
    }
    let u = TextUnits::of(probe.as_ref());
    let Document {
        output: (free, contact),
        json,
    } = request::run(
        &ModesRequest {},
        &Resolved { params: p, probe },
        &Progress::new(),
    )?;
    if a.json {
        outln!("{json}");
        return Ok(());
    }
    if u.si() {
        outln!(
            "N = {}, {} structure (SI: the probe's scales; natural frequencies in Hz)",
            p.modes,
            p.structure.name()
        );
    } else {
        outln!(
            "N = {}, α1 = {}, α3 = {}, α4 = {}, α6 = {} (dimensionless, eq. 5 time scale)",
            p.modes,
            p.alpha1,
            p.alpha3,
            p.alpha4,
            p.alpha6
        );
    }
    for (name, r) in [
        ("free (region I)", &free),
        ("contact (region II)", &contact),
    ] {
        outln!("\n{name}");
        if u.si() {
            // SI: the natural frequency and the damped one Im λ/2π, the decay rate Re λ in 1/s
            outln!(
                "{:>4} {:>16} {:>16} {:>18} {:>10}",
                "i",
                "f (undamped)",
                "Im λ/2π",
                "Re λ",
                "ζ"
            );
            for (i, w) in r.omega.iter().enumerate() {
                let e = r.eigenvalues.get(i);
                outln!(
                    "{:>4} {:>16} {:>16} {:>18} {:>10.5}",
                    i + 1,
                    u.frequency(*w),
                    e.map_or("-".into(), |e| u.frequency(e.im)),
                    e.map_or("-".into(), |e| u.rate(e.re)),
                    e.map_or(f64::NAN, |e| e.zeta)
                );
            }
            continue;
        }
        outln!(
            "{:>4} {:>14} {:>14} {:>14} {:>10}",
            "i",
            "ω (undamped)",
            "Re λ",
            "Im λ",
            "ζ"
        );
        for (i, w) in r.omega.iter().enumerate() {
            let e = r.eigenvalues.get(i);
            outln!(
                "{:>4} {:>14.6} {:>14.6} {:>14.6} {:>10.5}",
                i + 1,
                w,
                e.map_or(f64::NAN, |e| e.re),
                e.map_or(f64::NAN, |e| e.im),
                e.map_or(f64::NAN, |e| e.zeta)
            );
        }
    }
    Ok(())
}

fn fig3(a: &ModesArgs, p: &Params) -> Result<(), CliError> {
    let alpha1: Vec<f64> = (0..=10).map(|i| 0.05 * i as f64).collect();
    let alpha4: Vec<f64> = (0..=100).map(|i| 2.0 * i as f64).collect();
    let out = OutDir::lock(&a.out)?;
    let pts = fig3_sweep(p.modes, &alpha1, &alpha4)?;
    write_csv(
        &out.join("fig3.csv"),
        &[
            "alpha1",
            "alpha4",
            "omega1_over_omega01",
            "omega2_over_omega02",
        ],
        pts.iter()
            .map(|q| vec![f(q.alpha1), f(q.alpha4), f(q.ratio1), f(q.ratio2)]),
    )?;
    for (stem, which, title) in [
        (
            "fig3a",
            1,
            "Fig. 3a: first natural frequency in contact, ω₁/ω₀₁",
        ),
        (
            "fig3b",
            2,
            "Fig. 3b: second natural frequency in contact, ω₂/ω₀₂",
        ),
    ] {
        let series = alpha1
            .iter()
            .enumerate()
            .filter(|(i, _)| i % 2 == 0)
            .map(|(k, &a1)| Series {
                label: format!("α1 = {a1:.2}"),
                points: pts
                    .iter()
                    .filter(|q| q.alpha1 == a1)
                    .map(|q| (q.alpha4, if which == 1 { q.ratio1 } else { q.ratio2 }))
                    .collect(),
                style: Style::Line,
                color: k / 2,
            })
            .collect();
        let fig = Figure {
            y_min_span: 0.0,
            title: format!("{title} (N = {})", p.modes),
            x_label: "contact stiffness α4".into(),
            y_label: if which == 1 {
                "ω₁/ω₀₁".into()
            } else {
                "ω₂/ω₀₂".into()
            },
            series,
            shade: vec![],
        };
        save(out.path(), stem, &fig)?;
    }
    if a.json {
        outln!("{}", json!({ "params": p, "points": pts, "out": a.out }));
    } else {
        outln!("wrote {} points to {}", pts.len(), out.path().display());
    }
    Ok(())
}

/// `afmdyn units` flags.
#[derive(Debug, Args)]
pub struct UnitsArgs {
    /// Physical model in the paper's terms (TOML, SI units: geometry, tip mass, C or Q₁,
    /// contact K₁ or Hertz, g₀, g₁, drive); see examples/probe.toml
    #[arg(
        long,
        value_name = "FILE.toml",
        required_unless_present = "probe",
        conflicts_with = "probe"
    )]
    config: Option<PathBuf>,
    /// Probe file (cantilever k, f0, Q or geometry; tip; sample law; drive A0, f; see
    /// examples/probe-beam-dmt.toml and docs/afm-workflow.md): print its dimensionless set and
    /// scales
    #[arg(long, value_name = "PROBE.toml")]
    probe: Option<PathBuf>,
    /// A cantilever of the library for the probe file (as every command's --cantilever)
    #[arg(long, value_name = "NAME", requires = "probe")]
    cantilever: Option<String>,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// A probe file: cantilever, tip, sample and drive, in SI units.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ProbeFile {
    modes: Option<usize>,
    length: f64,
    width: f64,
    thickness: f64,
    youngs_modulus: f64,
    density: f64,
    tip_mass: f64,
    beam_damping: Option<f64>,
    quality_factor: Option<f64>,
    contact_stiffness: Option<f64>,
    hertz: Option<HertzFile>,
    contact_damping: f64,
    drive_amplitude: f64,
    beam_gap: f64,
    tip_gap: f64,
    drive_frequency_hz: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct HertzFile {
    tip_radius: f64,
    indentation: f64,
    tip_youngs_modulus: Option<f64>,
    tip_poisson_ratio: Option<f64>,
    sample: Option<String>,
    sample_youngs_modulus: Option<f64>,
    sample_poisson_ratio: Option<f64>,
}

/// Run `afmdyn units`.
pub fn units(a: &UnitsArgs) -> Result<(), CliError> {
    if let Some(path) = &a.probe {
        let origin = path.display().to_string();
        let text =
            crate::args::read_text(path).map_err(|e| CliError::Input(format!("probe {e}")))?;
        let text = match &a.cantilever {
            Some(name) => afmdyn::cantilevers::with_name(&text, name)
                .map_err(|e| CliError::Input(format!("{origin}: {e}")))?,
            None => text,
        };
        let pr = afmdyn::probe::Probe::parse(&text, &origin)?;
        let p = pr.params;
        let doc = json!({ "params": p, "si": afmdyn::report::si(&pr, &p, &json!({})) });
        if a.json {
            outln!("{doc}");
        } else {
            outln!("{}", serde_json::to_string_pretty(&doc).expect("json"));
        }
        return Ok(());
    }
    let Some(config) = &a.config else {
        return Err(CliError::Input("give --config or --probe".into()));
    };
    let pf: ProbeFile = read_toml(config)?;
    let k1 = match (pf.contact_stiffness, &pf.hertz) {
        (Some(k), None) => contact_stiffness(ContactStiffness::Direct(k))?,
        (None, Some(h)) => {
            let sample = match (&h.sample, h.sample_youngs_modulus, h.sample_poisson_ratio) {
                (Some(name), None, None) => material(name)?,
                (None, Some(e), Some(nu)) => Material { youngs_modulus: e, poisson_ratio: nu },
                _ => {
                    return Err(CliError::Input(
                        "hertz: give either sample = \"name\" or both sample_youngs_modulus and sample_poisson_ratio".into(),
                    ))
                }
            };
            let tip = Material {
                youngs_modulus: h.tip_youngs_modulus.unwrap_or(SILICON_TIP.youngs_modulus),
                poisson_ratio: h.tip_poisson_ratio.unwrap_or(SILICON_TIP.poisson_ratio),
            };
            contact_stiffness(ContactStiffness::Hertz {
                tip,
                sample,
                radius: h.tip_radius,
                indentation: h.indentation,
            })?
        }
        _ => {
            return Err(CliError::Input(
                "give exactly one of contact_stiffness or [hertz]".into(),
            ))
        }
    };
    let mut model = PhysicalModel {
        cantilever: Cantilever {
            length: pf.length,
            width: pf.width,
            thickness: pf.thickness,
            youngs_modulus: pf.youngs_modulus,
            density: pf.density,
        },
        modes: pf.modes.unwrap_or(3),
        tip_mass: pf.tip_mass,
        beam_damping: 0.0,
        contact_stiffness: k1,
        contact_damping: pf.contact_damping,
        drive_amplitude: pf.drive_amplitude,
        beam_gap: pf.beam_gap,
        tip_gap: pf.tip_gap,
        drive_frequency_hz: pf.drive_frequency_hz,
    };
    model.beam_damping = match (pf.beam_damping, pf.quality_factor) {
        (Some(c), None) => c,
        (None, Some(q)) => beam_damping_from_q(&model, q)?,
        _ => {
            return Err(CliError::Input(
                "give exactly one of beam_damping or quality_factor".into(),
            ))
        }
    };
    let p = model.to_params()?;
    let s = model.scales();
    if a.json {
        outln!("{}", json!({ "params": p, "scales": s, "physical": model }));
        return Ok(());
    }
    outln!("dimensionless parameters (eq. 7):");
    outln!("  N  = {}", p.modes);
    outln!("  α1 = {:.6e}  tip-mass ratio M/(mL)", p.alpha1);
    outln!("  α2 = {:.6e}  drive amplitude f/g0", p.alpha2);
    outln!("  α3 = {:.6e}  beam damping", p.alpha3);
    outln!(
        "  α4 = {:.6e}  contact stiffness K1 L³/(EI)  (K1 = {:.6e} N/m)",
        p.alpha4,
        k1
    );
    outln!("  α5 = {:.6e}  gap g1/g0", p.alpha5);
    outln!("  α6 = {:.6e}  contact damping", p.alpha6);
    outln!("  Ω  = {:.6e}  drive frequency", p.omega);
    outln!("scales (eq. 5):");
    outln!("  one unit of τ = {:.6e} s", s.time_s);
    outln!("  one unit of W = {:.6e} m", s.length_m);
    outln!("  spring constant 3EI/L³ = {:.6e} N/m", s.spring_constant);
    outln!(
        "  first natural frequency f₁ = {:.6e} Hz with the tip mass ({:.6e} Hz without)",
        s.first_frequency_hz,
        s.bare_first_frequency_hz
    );
    Ok(())
}

/// `afmdyn cantilevers` flags.
#[derive(Debug, Args)]
pub struct CantileversArgs {
    /// Print one JSON document (every entry with its source)
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn cantilevers`: the cantilever library, one line per cantilever.
pub fn cantilevers(a: &CantileversArgs) -> Result<(), CliError> {
    let all = afmdyn::cantilevers::cantilevers();
    if a.json {
        let doc = afmdyn::cantilevers::document();
        outln!("{doc}");
        return Ok(());
    }
    outln!(
        "{:<16} {:<44} {:>9} {:>9} {:>6} {:>6}",
        "name",
        "maker",
        "k (N/m)",
        "f0 (kHz)",
        "Q",
        "R (nm)"
    );
    for c in all {
        outln!(
            "{:<16} {:<44} {:>9} {:>9} {:>6} {:>6}",
            c.name,
            c.maker,
            c.spring_constant,
            c.resonance_frequency / 1e3,
            format!("{}{}", c.quality_factor, if c.q_typical { "*" } else { "" }),
            (c.radius * 1e9 * 10.0).round() / 10.0
        );
    }
    outln!(
        "* Q typical of the lever class in air, not a datasheet value. Nominal values: calibrate \
         k, f0 and Q on the instrument. Use: --cantilever NAME --probe SAMPLE.toml (a probe \
         file with [sample] and [drive]); sources: --json"
    );
    Ok(())
}
