//! `fm`: the summary of a frequency-modulation curve, its table `fm.csv`, its document
//! `fm.json` and the frequency-shift figure.

use super::{lines, numeric_csv, tail, with_document, Destination, Files};
use crate::layout::figure::{Series, Style};
use crate::report::{Presentation, TextUnits};
use serde_json::Value;

/// The presentation of an FM curve's `document` (`study::fm::document`) and its
/// table (column names and rows, `study::fm::table`): the summary (Δf at both ends,
/// the largest excitation, unstable points and folds), and with `files` the table `fm.csv`,
/// the figure (all files) and the document `fm.json`; when the files go to `dir`, the document
/// records the table's path there (`"csv"`, in the document printed too).
pub(crate) fn fm(
    document: &mut Value,
    (columns, table): (Vec<&str>, Vec<Vec<f64>>),
    text: TextUnits,
    to: Destination<'_>,
) -> Presentation {
    let mut p = tail();
    let k = |name: &str| columns.iter().position(|c| *c == name).unwrap_or(0);
    let si = text.si();
    let value = |v: f64, si_unit: &str, model_unit: &str| {
        if si {
            text.value(v, si_unit)
        } else {
            format!("{} {model_unit}", crate::error::number(v))
        }
    };
    let at = |r: Option<&Vec<f64>>, k: usize| r.map_or(f64::NAN, |r| r[k]);
    let (first, last) = (table.first(), table.last());
    p.line(format!(
        "{} z_c values from {} to {}: Δf from {} to {}, excitation up to {:.4} × the free one; \
         {} unstable, {} folds",
        table.len(),
        value(at(first, k("z_c")), "m", "g0"),
        value(at(last, k("z_c")), "m", "g0"),
        value(at(first, k("frequency_shift")), "Hz", "Ω"),
        value(at(last, k("frequency_shift")), "Hz", "Ω"),
        table
            .iter()
            .map(|r| r[k("excitation")])
            .fold(f64::NAN, f64::max),
        table.iter().filter(|r| r[k("stable")] == 0.0).count(),
        document["folds"].as_array().map_or(0, Vec::len),
    ));
    if let (Some(t), Some(i)) = (
        document["thermal"]["temperature"].as_f64(),
        columns.iter().position(|c| *c == "frequency_shift_noise"),
    ) {
        let sigma: Vec<f64> = table.iter().map(|r| r[i]).collect();
        p.line(format!(
            "thermal noise at {t} K, loop bandwidth {}: σ(Δf) from {} to {}",
            text.value(
                document["thermal"]["bandwidth"]
                    .as_f64()
                    .unwrap_or(f64::NAN),
                "Hz"
            ),
            value(sigma.iter().copied().fold(f64::NAN, f64::min), "Hz", "Ω"),
            value(sigma.iter().copied().fold(f64::NAN, f64::max), "Hz", "Ω"),
        ));
    }
    if to.files == Files::None {
        return p;
    }
    numeric_csv(&mut p, "fm.csv", &columns, &table);
    if to.files == Files::All {
        let (x_unit, y_unit) = if si {
            (" (m)", " (Hz)")
        } else {
            (" (g0)", " (Ω)")
        };
        let (x, y) = (k("z_c"), k("frequency_shift"));
        let series = Series {
            label: String::new(),
            points: table.iter().map(|r| (r[x], r[y])).collect(),
            style: Style::Line,
            color: 0,
        };
        let labels = (
            format!("rest distance z_c{x_unit}"),
            format!("frequency shift Δf{y_unit}"),
        );
        let title = "FM-AFM: frequency shift at constant amplitude";
        p.figure("fm-frequency-shift", lines(title, labels, vec![series]));
    }
    with_document(&mut p, document, ("fm.json", "fm.csv"), to.dir);
    p
}
