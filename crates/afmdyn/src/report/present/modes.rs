//! `modes`, its Fig. 3 sweep, `units` and `cantilevers`: their text summaries, the sweep's
//! table and figures.

use crate::eigen::RegionSpectrum;
use crate::params::Params;
use crate::report::{Presentation, TextUnits};
use crate::units::{PhysicalModel, Scales};

/// A mode's quality factor Q = 1/(2ζ) from its damping ratio, 6 significant digits ("∞"
/// undamped, "-" where the mode has no eigenvalue).
fn quality_factor(zeta: Option<f64>) -> String {
    match zeta {
        Some(z) if z > 0.0 => crate::error::number(0.5 / z),
        Some(_) => "∞".into(),
        None => "-".into(),
    }
}

/// The spectra of the free and contact systems: one table each, in Hz and 1/s with a probe,
/// else in the model's units.
pub(crate) fn modes(
    p: &Params,
    free: &RegionSpectrum,
    contact: &RegionSpectrum,
    u: TextUnits,
) -> Presentation {
    let mut s = Presentation::default();
    if u.si() {
        s.line(format!(
            "N = {}, {} structure (SI: the probe's scales; natural frequencies in Hz)",
            p.modes,
            p.structure.name()
        ));
    } else {
        s.line(format!(
            "N = {}, α1 = {}, α3 = {}, α4 = {}, α6 = {} (dimensionless, eq. 5 time scale)",
            p.modes, p.alpha1, p.alpha3, p.alpha4, p.alpha6
        ));
    }
    // SI: the natural frequency and the damped one Im λ/2π, the decay rate Re λ in 1/s
    let (heads, widths) = if u.si() {
        (
            ["i", "f (undamped)", "Im λ/2π", "Re λ", "ζ", "Q"],
            [4, 16, 16, 18, 10, 10],
        )
    } else {
        (
            ["i", "ω (undamped)", "Re λ", "Im λ", "ζ", "Q"],
            [4, 14, 14, 14, 10, 10],
        )
    };
    let row = |cells: [String; 6]| {
        let padded: Vec<String> = cells
            .iter()
            .zip(widths)
            .map(|(c, w)| format!("{c:>w$}"))
            .collect();
        padded.join(" ")
    };
    for (name, r) in [("free (region I)", free), ("contact (region II)", contact)] {
        s.line(format!("\n{name}"));
        s.line(row(heads.map(String::from)));
        for (i, w) in r.omega.iter().enumerate() {
            let e = r.eigenvalues.get(i);
            let (re, im) = match (u.si(), e) {
                (true, Some(e)) => (u.rate(e.re), u.frequency(e.im)),
                (true, None) => ("-".into(), "-".into()),
                (false, _) => {
                    let part = |f: fn(&crate::eigen::DampedEigenvalue) -> f64| {
                        format!("{:.6}", e.map_or(f64::NAN, f))
                    };
                    (part(|e| e.re), part(|e| e.im))
                }
            };
            let (second, third) = if u.si() { (im, re) } else { (re, im) };
            let omega = if u.si() {
                u.frequency(*w)
            } else {
                format!("{w:.6}")
            };
            s.line(row([
                (i + 1).to_string(),
                omega,
                second,
                third,
                format!("{:.5}", e.map_or(f64::NAN, |e| e.zeta)),
                quality_factor(e.map(|e| e.zeta)),
            ]));
        }
    }
    s
}

/// The α1 values of the Fig. 3 sweep: 0 to 0.5 by 0.05.
pub(crate) fn fig3_alpha1() -> Vec<f64> {
    (0..=10).map(|i| 0.05 * i as f64).collect()
}

/// The α4 values of the Fig. 3 sweep: 0 to 200 by 2.
pub(crate) fn fig3_alpha4() -> Vec<f64> {
    (0..=100).map(|i| 2.0 * i as f64).collect()
}

/// The Fig. 3 sweep's table (`fig3.csv`) and its two figures (`fig3a`, `fig3b`: ω₁/ω₀₁ and
/// ω₂/ω₀₂ over α4, a line for every other α1) at `modes` modes; no summary (the front end
/// says where it wrote them).
#[cfg(feature = "files")]
pub(crate) fn fig3(modes: usize, pts: &[crate::eigen::Fig3Point]) -> Presentation {
    use crate::layout::figure::{Figure, Plot, Series, Style};
    use crate::layout::files::f;
    let mut s = Presentation::default();
    s.csv(
        "fig3.csv",
        &crate::report::csv_columns::FIG3.map(|c| c.0),
        pts.iter()
            .map(|q| vec![f(q.alpha1), f(q.alpha4), f(q.ratio1), f(q.ratio2)])
            .collect(),
    );
    let alpha1 = fig3_alpha1();
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
            title: format!("{title} (N = {modes})"),
            x_label: "contact stiffness α4".into(),
            y_label: if which == 1 {
                "ω₁/ω₀₁".into()
            } else {
                "ω₂/ω₀₂".into()
            },
            series,
            shade: vec![],
        };
        s.figure(stem, Plot::Lines(fig));
    }
    s
}

/// `units --config`: the dimensionless set of a physical model (eq. 7) and its scales (eq. 5).
pub(crate) fn units(model: &PhysicalModel, p: &Params, sc: &Scales) -> Presentation {
    let mut s = Presentation::default();
    let k1 = model.contact_stiffness;
    s.line("dimensionless parameters (eq. 7):");
    s.line(format!("  N  = {}", p.modes));
    s.line(format!("  α1 = {:.6e}  tip-mass ratio M/(mL)", p.alpha1));
    s.line(format!("  α2 = {:.6e}  drive amplitude f/g0", p.alpha2));
    s.line(format!("  α3 = {:.6e}  beam damping", p.alpha3));
    s.line(format!(
        "  α4 = {:.6e}  contact stiffness K1 L³/(EI)  (K1 = {:.6e} N/m)",
        p.alpha4, k1
    ));
    s.line(format!("  α5 = {:.6e}  gap g1/g0", p.alpha5));
    s.line(format!("  α6 = {:.6e}  contact damping", p.alpha6));
    s.line(format!("  Ω  = {:.6e}  drive frequency", p.omega));
    s.line("scales (eq. 5):");
    s.line(format!("  one unit of τ = {:.6e} s", sc.time_s));
    s.line(format!("  one unit of W = {:.6e} m", sc.length_m));
    s.line(format!(
        "  spring constant 3EI/L³ = {:.6e} N/m",
        sc.spring_constant
    ));
    s.line(format!(
        "  first natural frequency f₁ = {:.6e} Hz with the tip mass ({:.6e} Hz without)",
        sc.first_frequency_hz, sc.bare_first_frequency_hz
    ));
    s
}

/// `cantilevers`: the library of cantilevers, one line each, and how to use them.
pub(crate) fn cantilevers() -> Presentation {
    let mut s = Presentation::default();
    s.line(format!(
        "{:<16} {:<44} {:>9} {:>9} {:>6} {:>6}",
        "name", "maker", "k (N/m)", "f0 (kHz)", "Q", "R (nm)"
    ));
    for c in crate::cantilevers::cantilevers() {
        s.line(format!(
            "{:<16} {:<44} {:>9} {:>9} {:>6} {:>6}",
            c.name,
            c.maker,
            c.spring_constant,
            c.resonance_frequency / 1e3,
            format!("{}{}", c.quality_factor, if c.q_typical { "*" } else { "" }),
            (c.radius * 1e9 * 10.0).round() / 10.0
        ));
    }
    s.line(
        "* Q typical of the lever class in air, not a datasheet value. Nominal values: calibrate \
         k, f0 and Q on the instrument. Use: --cantilever NAME --probe SAMPLE.toml (a probe \
         file with [sample] and [drive]); sources: --json",
    );
    s
}
