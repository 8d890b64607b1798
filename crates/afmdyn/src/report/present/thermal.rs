//! The thermal spectrum's presentation: `thermal.nc` (the PSDs over `frequency`),
//! `thermal_modes.csv` (each mode's share), the figure `thermal` (log₁₀ of both PSDs against
//! frequency) and the summary, a line per mode.

use super::super::Presentation;
use crate::analysis::thermal::ThermalSpectrum;
use crate::layout::figure::{Figure, Plot, Series, Style};
use crate::layout::{Layout, Variable};
use serde_json::Value;

/// The layouts of `s`: `thermal` over `frequency`, `modes` over `mode`.
pub(crate) fn layouts(s: &ThermalSpectrum) -> Vec<(String, Layout)> {
    let f = ["frequency"];
    let psd = Layout::new(
        "thermal spectrum",
        &[("frequency", s.frequency.len())],
        vec![
            Variable::f64("frequency", &f, "Hz", "frequency", &s.frequency),
            Variable::f64(
                "deflection",
                &f,
                "m^2/Hz",
                "the tip's deflection, one-sided PSD",
                &s.deflection,
            ),
            Variable::f64(
                "apparent_deflection",
                &f,
                "m^2/Hz",
                "the optical lever's apparent deflection, one-sided PSD",
                &s.apparent_deflection,
            ),
        ],
    );
    let d = ["mode"];
    let col = |g: fn(&crate::analysis::thermal::ThermalMode) -> f64| -> Vec<f64> {
        s.modes.iter().map(g).collect()
    };
    let modes = Layout::new(
        "thermal modes",
        &[("mode", s.modes.len())],
        vec![
            Variable::f64("mode", &d, "1", "mode number", &col(|m| m.mode as f64)),
            Variable::f64(
                "frequency",
                &d,
                "Hz",
                "undamped natural frequency",
                &col(|m| m.frequency),
            ),
            Variable::f64(
                "quality_factor",
                &d,
                "1",
                "quality factor (NaN: overdamped)",
                &col(|m| m.quality_factor.unwrap_or(f64::NAN)),
            ),
            Variable::f64(
                "effective_spring_constant",
                &d,
                "N/m",
                "the mode's stiffness at the tip",
                &col(|m| m.effective_spring_constant),
            ),
            Variable::f64(
                "mean_square_deflection",
                &d,
                "m^2",
                "⟨x²⟩ of the tip",
                &col(|m| m.mean_square_deflection),
            ),
            Variable::f64(
                "mean_square_apparent_deflection",
                &d,
                "m^2",
                "⟨z*²⟩ of the optical lever",
                &col(|m| m.mean_square_apparent_deflection),
            ),
            Variable::f64(
                "deflection_factor",
                &d,
                "1",
                "k_s⟨x²⟩/(k_B T)",
                &col(|m| m.deflection_factor),
            ),
            Variable::f64(
                "optical_lever_factor",
                &d,
                "1",
                "k_s⟨z*²⟩/(k_B T)",
                &col(|m| m.optical_lever_factor),
            ),
        ],
    );
    vec![("thermal".into(), psd), ("modes".into(), modes)]
}

/// The presentation of `s`, its `document` written as `thermal.json`.
pub(crate) fn thermal(s: &ThermalSpectrum, document: &Value) -> Presentation {
    let mut p = Presentation::default();
    p.line(format!(
        "thermal: T = {} K, static k = {:.4e} N/m, ⟨x²⟩ over {} modes = {:.4e} m² (√ = {:.4e} m)",
        s.temperature,
        s.spring_constant,
        s.modes.len(),
        s.mean_square_deflection,
        s.mean_square_deflection.sqrt()
    ));
    for m in &s.modes {
        p.line(format!(
            "mode {}: f = {:.6e} Hz, Q = {}, k = {:.4e} N/m, ⟨x²⟩ = {:.4e} m², ⟨z*²⟩ = {:.4e} m², \
             factors {:.4} (deflection), {:.4} (optical lever)",
            m.mode,
            m.frequency,
            m.quality_factor
                .map_or("overdamped".into(), |q| format!("{q:.4}")),
            m.effective_spring_constant,
            m.mean_square_deflection,
            m.mean_square_apparent_deflection,
            m.deflection_factor,
            m.optical_lever_factor,
        ));
    }
    for (name, layout) in layouts(s) {
        p.dataset(&format!("{name}.nc"), layout);
    }
    p.json("thermal.json", document.clone());
    let line = |label: &str, v: &[f64], color| Series {
        label: label.into(),
        points: (s.frequency.iter().zip(v))
            .filter(|(_, y)| **y > 0.0)
            .map(|(f, y)| (*f, y.log10()))
            .collect(),
        style: Style::Line,
        color,
    };
    p.figure(
        "thermal",
        Plot::Lines(Figure {
            title: format!("thermal spectrum at {} K", s.temperature),
            x_label: "frequency (Hz)".into(),
            y_label: "log10 of the PSD in m^2/Hz".into(),
            series: vec![
                line("deflection", &s.deflection, 0),
                line(
                    "apparent deflection (optical lever)",
                    &s.apparent_deflection,
                    1,
                ),
            ],
            shade: Vec::new(),
            y_min_span: 1.0,
        }),
    );
    p
}
