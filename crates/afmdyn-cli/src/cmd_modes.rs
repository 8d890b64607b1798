//! `afmdyn modes` and `afmdyn units`.

use crate::args::{read_toml, ModelArgs};
use crate::error::CliError;
use crate::output::{f, write_csv, OutDir};
use crate::plot::{save, Figure, Series, Style};
use afmdyn::analysis::progress::Progress;
use afmdyn::eigen::fig3_sweep;
use afmdyn::request::{self, Document, ModesRequest, Resolved};
use afmdyn::units::PhysicalFile;
use afmdyn::Params;
use clap::Args;
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
    let u = crate::output::units_of(probe.as_ref());
    let Document {
        output: (free, contact),
        json,
    } = request::run(
        &ModesRequest {},
        &Resolved { params: p, probe },
        &Progress::new(),
    )?;
    crate::output::print_warnings(&json)?;
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
                "{:>4} {:>16} {:>16} {:>18} {:>10} {:>10}",
                "i",
                "f (undamped)",
                "Im λ/2π",
                "Re λ",
                "ζ",
                "Q"
            );
            for (i, w) in r.omega.iter().enumerate() {
                let e = r.eigenvalues.get(i);
                outln!(
                    "{:>4} {:>16} {:>16} {:>18} {:>10.5} {:>10}",
                    i + 1,
                    u.frequency(*w),
                    e.map_or("-".into(), |e| u.frequency(e.im)),
                    e.map_or("-".into(), |e| u.rate(e.re)),
                    e.map_or(f64::NAN, |e| e.zeta),
                    quality_factor(e.map(|e| e.zeta))
                );
            }
            continue;
        }
        outln!(
            "{:>4} {:>14} {:>14} {:>14} {:>10} {:>10}",
            "i",
            "ω (undamped)",
            "Re λ",
            "Im λ",
            "ζ",
            "Q"
        );
        for (i, w) in r.omega.iter().enumerate() {
            let e = r.eigenvalues.get(i);
            outln!(
                "{:>4} {:>14.6} {:>14.6} {:>14.6} {:>10.5} {:>10}",
                i + 1,
                w,
                e.map_or(f64::NAN, |e| e.re),
                e.map_or(f64::NAN, |e| e.im),
                e.map_or(f64::NAN, |e| e.zeta),
                quality_factor(e.map(|e| e.zeta))
            );
        }
    }
    Ok(())
}

/// A mode's quality factor Q = 1/(2ζ) from its damping ratio, 6 significant digits ("∞"
/// undamped, "-" where the mode has no eigenvalue).
fn quality_factor(zeta: Option<f64>) -> String {
    match zeta {
        Some(z) if z > 0.0 => afmdyn::error::number(0.5 / z),
        Some(_) => "∞".into(),
        None => "-".into(),
    }
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
    /// The fluid around the lever, over the probe's [medium]: water, air or none (as every
    /// command's --medium)
    #[allow(rustdoc::broken_intra_doc_links)]
    #[arg(long, value_name = "NAME", requires = "probe")]
    medium: Option<String>,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn units`.
pub fn units(a: &UnitsArgs) -> Result<(), CliError> {
    if let Some(path) = &a.probe {
        let (_, pr) = afmdyn::probe::Probe::source_text(
            afmdyn::probe::ProbeSource::Path(path),
            a.cantilever.as_deref(),
            a.medium.as_deref(),
        )?;
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
    let pf: PhysicalFile = read_toml(config)?;
    let model = pf.resolve()?;
    let k1 = model.contact_stiffness;
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
