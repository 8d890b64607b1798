//! `fit`: the summary of a force-curve fit (each estimate with its standard error and 95 %
//! interval, χ²/dof, the warnings), its table `fit-curve.csv` (tip position, force, fit,
//! residual, and time for the `sls` law), its document `fit.json` and the figures of the fit
//! beside the data (against time too, for `sls`) and of the residuals.

use super::peakforce::rows;
use super::{lines, numeric_csv, tail, with_document, Destination, Files};
use crate::layout::figure::{Series, Style};
use crate::report::{Presentation, TextUnits};
use serde_json::Value;

/// The variables of a dynamic fit's curve (name, unit, label): the columns of its table and
/// Dataset, those of the channels fitted.
pub(crate) const CURVE_VARIABLES: [(&str, &str, &str); 16] = [
    ("z", "m", "piezo position"),
    ("amplitude", "m", "amplitude, measured"),
    ("amplitude_fit", "m", "amplitude, fitted"),
    ("amplitude_residual", "m", "measured − fitted amplitude"),
    ("phase", "deg", "phase, measured"),
    ("phase_fit", "deg", "phase, fitted"),
    ("phase_residual", "deg", "measured − fitted phase"),
    ("amplitude_2", "m", "second component's amplitude, measured"),
    (
        "amplitude_2_fit",
        "m",
        "second component's amplitude, fitted",
    ),
    (
        "amplitude_2_residual",
        "m",
        "measured − fitted second amplitude",
    ),
    ("phase_2", "deg", "second component's phase, measured"),
    ("phase_2_fit", "deg", "second component's phase, fitted"),
    ("phase_2_residual", "deg", "measured − fitted second phase"),
    ("frequency_shift", "Hz", "frequency shift, measured"),
    ("frequency_shift_fit", "Hz", "frequency shift, fitted"),
    (
        "frequency_shift_residual",
        "Hz",
        "measured − fitted frequency shift",
    ),
];

/// The columns of the fitted curve's table (`fit-curve.csv`, Python's Dataset variables).
pub(crate) const CURVE_COLUMNS: [&str; 4] = ["tip_position", "force", "fit", "residual"];

/// The summary line of the estimate `e` of `name` in `unit`: value ± standard error and the
/// 95 % interval, the error's two digits setting the decimals of every number where it has
/// them ([`crate::report::si_with_error`]).
fn estimate_line(name: &str, e: &Value, unit: &str, text: TextUnits) -> String {
    let num = |x: &Value| x.as_f64().unwrap_or(f64::NAN);
    let rounded = crate::report::si_with_error(
        num(&e["value"]),
        num(&e["standard_error"]),
        unit,
        text.plain,
    );
    let v = |x: &Value| match (x.as_f64(), &rounded) {
        (None, _) => "—".into(),
        (Some(x), Some(f)) => f(x),
        (Some(x), None) => text.value(x, unit),
    };
    format!(
        "{name} = {} ± {} (95 % interval [{}, {}])",
        v(&e["value"]),
        v(&e["standard_error"]),
        v(&e["interval"][0]),
        v(&e["interval"][1]),
    )
}

/// The parameters a fit held, at their values (`held: baseline = 0 N, …`), so that no held
/// one passes for fitted; `None` when every parameter was fitted.
fn held_line(document: &Value, text: TextUnits) -> Option<String> {
    let held: Vec<String> = document["parameters"]
        .as_object()?
        .iter()
        .filter(|(_, q)| q["fitted"] == Value::Bool(false))
        .map(|(name, q)| {
            let unit = document["units"][name.as_str()].as_str().unwrap_or("");
            let value = q["value"].as_f64().unwrap_or(f64::NAN);
            format!("{name} = {}", text.value(value, unit))
        })
        .collect();
    (!held.is_empty()).then(|| format!("held: {}", held.join(", ")))
}

/// The presentation of a fit's `document` (`study::fit::document`): the summary,
/// and with `files` the table, the figures (all files) and the document `fit.json`.
pub(crate) fn fit(document: &mut Value, text: TextUnits, to: Destination<'_>) -> Presentation {
    let mut p = tail();
    let units = document["units"].clone();
    if let Some(est) = document["estimates"].as_object() {
        for (name, e) in est {
            let unit = units[name.as_str()].as_str().unwrap_or("");
            p.line(estimate_line(name, e, unit, text));
        }
    }
    if let Some(line) = held_line(document, text) {
        p.line(line);
    }
    // a force curve names its segment; a dynamic curve its kind (AM, with the bimodal
    // channels, or FM)
    let dynamic = document["kind"]
        .as_str()
        .filter(|k| matches!(*k, "am" | "fm"));
    let segment = match (document["segment"].as_str(), dynamic) {
        (Some("whole"), _) => "whole curve".into(),
        (Some(s), _) => s.to_string(),
        (None, Some(k)) => format!("{} curve", k.to_uppercase()),
        (None, None) => "curve".into(),
    };
    p.line(format!(
        "{} law on {} rows of the {segment}: χ²/dof = {:.4e}; {}",
        document["law"].as_str().unwrap_or(""),
        document["rows_fitted"].as_u64().unwrap_or(0),
        document["chi2_dof"].as_f64().unwrap_or(f64::NAN),
        document["noise"].as_str().unwrap_or(""),
    ));
    if to.files == Files::None {
        return p;
    }
    if dynamic.is_some() {
        am_files(&mut p, document, to.files);
        with_document(&mut p, document, ("fit.json", "fit-curve.csv"), to.dir);
        return p;
    }
    // a time-dependent law's curve (sls) carries the rows' times: a column and a figure more
    let timed = document["curve"]["time"].is_array();
    let mut columns = CURVE_COLUMNS.to_vec();
    if timed {
        columns.push("time");
    }
    let curve = rows(document, "curve", &columns);
    numeric_csv(&mut p, "fit-curve.csv", &columns, &curve);
    if to.files == Files::All {
        let against = |x: usize, label: &str, col: usize, style: Style, color: usize| Series {
            label: label.into(),
            points: curve
                .iter()
                .map(|r| (r[x], r[col]))
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect(),
            style,
            color,
        };
        let series = |label: &str, col: usize, style: Style, color: usize| {
            against(0, label, col, style, color)
        };
        p.figure(
            "fit-curve",
            lines(
                "Force curve: the data and the fit",
                ("tip position (m)".into(), "force (N)".into()),
                vec![
                    // the data drawn over the fit line, not hidden behind it
                    series("fit", 2, Style::Line, 1),
                    series("data", 1, Style::Dots, 0),
                ],
            ),
        );
        p.figure(
            "fit-residual",
            lines(
                "Force curve: residuals (data − fit)",
                ("tip position (m)".into(), "residual (N)".into()),
                vec![series("", 3, Style::Line, 0)],
            ),
        );
        if timed {
            p.figure(
                "fit-force-time",
                lines(
                    "Force against time: the data and the fit (approach, dwell, retract)",
                    ("time (s)".into(), "force (N)".into()),
                    vec![
                        against(4, "fit", 2, Style::Line, 1),
                        against(4, "data", 1, Style::Dots, 0),
                    ],
                ),
            );
        }
    }
    with_document(&mut p, document, ("fit.json", "fit-curve.csv"), to.dir);
    p
}

/// The table and figures of a dynamic (AM or FM) fit ([`crate::request::fit_dynamic`]): the columns
/// of the channels fitted, each channel's data and fit against z, and its residuals.
fn am_files(p: &mut Presentation, document: &Value, files: Files) {
    let columns: Vec<&str> = CURVE_VARIABLES
        .iter()
        .map(|v| v.0)
        .filter(|k| document["curve"][k].is_array())
        .collect();
    let curve = rows(document, "curve", &columns);
    numeric_csv(p, "fit-curve.csv", &columns, &curve);
    if files != Files::All {
        return;
    }
    let col = |k: &str| columns.iter().position(|c| *c == k);
    let series = |label: &str, c: usize, style: Style, color: usize| Series {
        label: label.into(),
        points: curve
            .iter()
            .map(|r| (r[0], r[c]))
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect(),
        style,
        color,
    };
    let kind = if document["kind"] == "fm" { "FM" } else { "AM" };
    for (channel, unit) in [
        ("amplitude", "m"),
        ("phase", "deg"),
        ("amplitude_2", "m"),
        ("phase_2", "deg"),
        ("frequency_shift", "Hz"),
    ] {
        let (Some(d), Some(f), Some(r)) = (
            col(channel),
            col(&format!("{channel}_fit")),
            col(&format!("{channel}_residual")),
        ) else {
            continue;
        };
        p.figure(
            &format!("fit-{channel}"),
            lines(
                &format!(
                    "{kind} curve: the {}, data and fit",
                    channel.replace('_', " ")
                ),
                ("z (m)".into(), format!("{channel} ({unit})")),
                vec![
                    // the data drawn over the fit line (issue 77: hidden behind it)
                    series("fit", f, Style::Line, 1),
                    series("data", d, Style::Dots, 0),
                ],
            ),
        );
        p.figure(
            &format!("fit-{channel}-residual"),
            lines(
                &format!(
                    "{kind} curve: {} residuals (data − fit)",
                    channel.replace('_', " ")
                ),
                ("z (m)".into(), format!("residual ({unit})")),
                vec![series("", r, Style::Line, 0)],
            ),
        );
    }
}
