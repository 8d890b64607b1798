//! The calibration's presentation: `spectrum.nc` (the measured PSD and the fitted oscillators
//! over `frequency`), `modes.nc` (each mode's estimates and standard errors), the figure
//! `calibration` (log₁₀ of both against frequency) and the summary, a line per mode.

use super::super::Presentation;
use crate::analysis::calibration::{Calibration, Measured, ModeCalibration};
use crate::layout::figure::{Figure, Plot, Series, Style};
use crate::layout::{Layout, Variable};
use serde_json::Value;

/// The layouts of `c`: `spectrum` over `frequency`, `modes` over `mode`.
pub(crate) fn layouts(c: &Calibration) -> Vec<(String, Layout)> {
    let f = ["frequency"];
    let spectrum = Layout::new(
        "measured thermal spectrum",
        &[("frequency", c.frequency.len())],
        vec![
            Variable::f64("frequency", &f, "Hz", "frequency", &c.frequency),
            Variable::f64("psd", &f, "m^2/Hz", "the measured one-sided PSD", &c.psd),
            Variable::f64(
                "fitted",
                &f,
                "m^2/Hz",
                "the oscillators fitted, in their bands",
                &c.fitted,
            ),
        ],
    );
    let d = ["mode"];
    let mut vars = vec![Variable::f64(
        "mode",
        &d,
        "1",
        "mode number",
        &col(
            c,
            |m| {
                Some(Measured {
                    value: m.mode as f64,
                    standard_error: 0.0,
                })
            },
            false,
        ),
    )];
    type Get = fn(&ModeCalibration) -> Option<Measured>;
    let fields: [(&str, &str, &str, Get); 6] = [
        ("frequency", "Hz", "resonance frequency", |m| {
            Some(m.frequency)
        }),
        ("quality_factor", "1", "quality factor", |m| {
            Some(m.quality_factor)
        }),
        (
            "spring_constant_thermal",
            "N/m",
            "the mode's effective spring constant, thermal method",
            |m| Some(m.spring_constant_thermal),
        ),
        (
            "spring_constant_sader",
            "N/m",
            "the mode's effective spring constant, Sader's method (NaN: no plan)",
            |m| m.spring_constant_sader,
        ),
        (
            "static_spring_constant_thermal",
            "N/m",
            "the static spring constant from this peak, thermal method",
            |m| Some(m.static_spring_constant_thermal),
        ),
        (
            "static_spring_constant_sader",
            "N/m",
            "the static spring constant from this peak, Sader's method (NaN: no plan)",
            |m| m.static_spring_constant_sader,
        ),
    ];
    for (name, unit, meaning, get) in fields {
        vars.push(Variable::f64(name, &d, unit, meaning, &col(c, get, false)));
        let se = format!("{name}_standard_error");
        vars.push(Variable::f64(
            &se,
            &d,
            unit,
            format!("standard error of {name}"),
            &col(c, get, true),
        ));
    }
    let modes = Layout::new("calibrated modes", &[("mode", c.modes.len())], vars);
    vec![("spectrum".into(), spectrum), ("modes".into(), modes)]
}

/// A column over the modes of `c`: `get`'s value, or its standard error when `se` (NaN where
/// `get` has none).
fn col(c: &Calibration, get: fn(&ModeCalibration) -> Option<Measured>, se: bool) -> Vec<f64> {
    (c.modes.iter())
        .map(|m| get(m).map_or(f64::NAN, |v| if se { v.standard_error } else { v.value }))
        .collect()
}

/// `value ± standard error` in three significant digits, or "—".
fn pm(m: Option<Measured>) -> String {
    m.map_or("—".into(), |m| {
        format!("{:.4e} ± {:.2e}", m.value, m.standard_error)
    })
}

/// The presentation of `c`, its `document` written as `calibration.json`.
pub(crate) fn calibrate(c: &Calibration, document: &Value) -> Presentation {
    let mut p = Presentation::default();
    let first = &c.modes[0];
    p.line(format!(
        "calibrate: T = {} K, static k = {} N/m (thermal, mode {}), {} N/m (Sader)",
        c.temperature,
        pm(Some(first.static_spring_constant_thermal)),
        first.mode,
        pm(first.static_spring_constant_sader),
    ));
    for m in &c.modes {
        p.line(format!(
            "mode {}: f = {} Hz, Q = {}, k = {} N/m (thermal), {} N/m (Sader)",
            m.mode,
            pm(Some(m.frequency)),
            pm(Some(m.quality_factor)),
            pm(Some(m.spring_constant_thermal)),
            pm(m.spring_constant_sader),
        ));
    }
    if let Some(s) = c.invols {
        p.line(format!(
            "InvOLS = {} m/V (the force curve's contact slope)",
            pm(Some(s))
        ));
    }
    for (name, layout) in layouts(c) {
        p.dataset(&format!("{name}.nc"), layout);
    }
    p.json("calibration.json", document.clone());
    let line = |label: &str, v: &[f64], color, style| Series {
        label: label.into(),
        points: (c.frequency.iter().zip(v))
            .filter(|(_, y)| **y > 0.0)
            .map(|(f, y)| (*f, y.log10()))
            .collect(),
        style,
        color,
    };
    p.figure(
        "calibration",
        Plot::Lines(Figure {
            title: format!("thermal spectrum and its fit at {} K", c.temperature),
            x_label: "frequency (Hz)".into(),
            y_label: "log10 of the PSD in m^2/Hz".into(),
            series: vec![
                line("measured", &c.psd, 0, Style::Line),
                line("fitted oscillators", &c.fitted, 1, Style::Line),
            ],
            shade: Vec::new(),
            y_min_span: 1.0,
        }),
    );
    p
}
