//! `peakforce`: the summary of a steady off-resonance tap (its channels, the DMT fit beside
//! the true modulus, the orbit's stability), its tables `peakforce-cycle.csv` and
//! `peakforce-curve.csv`, its document `peakforce.json` and the figures of force against
//! distance and against time.

use super::{lines, numeric_csv, tail, with_document, Destination, Files};
use crate::analysis::peakforce::{SteadyTap, TapNoise};
use crate::layout::columns::{self, columns, Column};
use crate::layout::figure::{Series, Style};
use crate::params::Params;
use crate::report::{CurveUnits, Presentation, TextUnits};
use serde_json::Value;

/// What a sweep's columns ([`COLUMNS`]) are read through: the document's units and the factor
/// from the fitted Hertz group to the reported modulus (the reduced modulus in Pa with a probe
/// and a law with a tip radius, else 1).
pub(crate) struct Frame {
    /// The document's units.
    pub u: CurveUnits,
    /// Reported modulus per unit of the Hertz group.
    pub modulus_scale: f64,
}

/// The channels of a sweep, one entry per value (missing where the point failed): the
/// document's `sweep.channels` and `sweep.units`, the layout's variables and the columns of the
/// table `peakforce-sweep.csv` after the swept value, in this order (the layout lists
/// `modulus_dmt` last, [`sweep_layout`]).
pub(crate) const COLUMNS: [Column<Frame, SweepTap>; 10] = columns! {
    "peak_force", Force, true, "peak force",
        Opt(|f, t| Some(t.tap.as_ref()?.channels.peak_force * f.u.force));
    "adhesion", Force, true, "adhesion (most negative force)",
        Opt(|f, t| Some(t.tap.as_ref()?.channels.adhesion * f.u.force));
    "deformation", Length, true, "largest indentation",
        Opt(|f, t| Some(t.tap.as_ref()?.channels.deformation * f.u.length));
    "dissipation", Energy, true, "tip-sample work per cycle",
        Opt(|f, t| Some(t.tap.as_ref()?.channels.dissipation * f.u.energy));
    "contact_time", Own("s", "τ"), true, "time in contact per cycle",
        Opt(|f, t| Some(t.tap.as_ref()?.channels.contact_time * f.u.time));
    "snap_off_time", Own("s", "τ"), true, "snap-off from the largest separation",
        Opt(|f, t| Some(t.tap.as_ref()?.channels.snap_off_time * f.u.time));
    "ringing_amplitude", Length, true, "ringing after snap-off",
        Opt(|f, t| Some(t.tap.as_ref()?.channels.ringing_amplitude * f.u.length));
    "modulus_dmt", Own("Pa", "α4 (Hertz group)"), true, "fitted DMT modulus of the retract (PF-QNM)",
        Opt(|f, t| Some(t.tap.as_ref()?.fit?.hertz_group * f.modulus_scale));
    "taps_per_cycle", Fixed("1"), true, "contacts per modulation period",
        Opt(|_, t| Some(t.tap.as_ref()?.channels.taps_per_cycle));
    "z_c", Length, true, "mean rest separation",
        Opt(|f, t| Some(t.params.rest_distance() * f.u.length));
};

/// The channels a sweep with a temperature adds after [`COLUMNS`]: the tap's thermal noise
/// (`crate::analysis::peakforce::tap_noise`).
pub(crate) const NOISE_COLUMNS: [Column<Frame, SweepTap>; 2] = columns! {
    "peak_force_noise", Force, true, "peak force's thermal noise per cycle (σ)",
        Opt(|f, t| Some(t.noise?.peak_force * f.u.force));
    "deformation_noise", Length, true, "deformation's thermal noise per cycle (σ)",
        Opt(|f, t| Some(t.noise?.deformation * f.u.length));
};

/// The names of a sweep's channels ([`COLUMNS`]), in the order of its table.
pub(crate) fn channel_names() -> Vec<&'static str> {
    columns::names(&COLUMNS)
}

/// One value of a PeakForce sweep: its place, the model it was computed on (α5 is the tap's:
/// the feedback's with a setpoint), and the steady tap or why it failed.
#[derive(Debug, Clone)]
pub struct SweepTap {
    /// Place of the value in the sweep (0-based).
    pub index: usize,
    /// The model's parameters of this tap (α5 found by the feedback with a setpoint).
    pub params: Params,
    /// The steady tap (`None` when the point failed).
    pub tap: Option<SteadyTap>,
    /// Steady taps computed for this value (1 without a setpoint).
    pub evaluations: usize,
    /// Why the point failed (`None` when it was computed).
    pub message: Option<String>,
    /// The tap's thermal noise (with a temperature).
    pub noise: Option<TapNoise>,
}

/// The columns of the cycle's table (`peakforce-cycle.csv`, Python's Dataset variables).
pub(crate) const CYCLE_COLUMNS: [&str; 4] = ["time", "deflection", "distance", "force"];
/// The columns of the force–distance curve's table (`peakforce-curve.csv`): approach and
/// retract side by side (the retract has as many points as the approach, or one more).
pub(crate) const CURVE_COLUMNS: [&str; 4] = [
    "approach_distance",
    "approach_force",
    "retract_distance",
    "retract_force",
];

/// The columns the curve's table adds with the instrument's filter (`filter_cutoff`): the
/// measured force k × deflection through it, approach and retract.
pub(crate) const FILTERED_COLUMNS: [&str; 2] =
    ["approach_filtered_force", "retract_filtered_force"];

/// A numeric array of the document at `block.name` (empty when absent).
fn column(doc: &Value, block: &str, name: &str) -> Vec<f64> {
    doc[block][name].as_array().map_or(Vec::new(), |a| {
        a.iter().map(|v| v.as_f64().unwrap_or(f64::NAN)).collect()
    })
}

/// The rows of one table of the document: `block`'s arrays in `columns` order, as long as the
/// longest (NaN beyond a shorter one).
pub(crate) fn rows(doc: &Value, block: &str, columns: &[&str]) -> Vec<Vec<f64>> {
    let cols: Vec<Vec<f64>> = columns.iter().map(|c| column(doc, block, c)).collect();
    let n = cols.iter().map(Vec::len).max().unwrap_or(0);
    (0..n)
        .map(|i| {
            cols.iter()
                .map(|c| c.get(i).copied().unwrap_or(f64::NAN))
                .collect()
        })
        .collect()
}

/// A sweep's table: the swept quantity's name, the rows, the column names.
type SweepTable = (String, Vec<Vec<f64>>, Vec<&'static str>);

/// A sweep's table from the document's `sweep` block: (the swept quantity's name, the rows —
/// the value, then the sweep's channels but the swept one, NaN where a point failed —, the
/// column names); `None` without a sweep.
fn sweep_table(doc: &Value) -> Option<SweepTable> {
    let block = doc.get("sweep").filter(|b| !b.is_null())?;
    let param = block["quantity"].as_str().unwrap_or("value").to_string();
    let values = column(doc, "sweep", "values");
    // the swept value first (a swept z_c is not repeated)
    let mut columns: Vec<&'static str> = vec![if param == "z_c" {
        "z_c"
    } else {
        "modulation_frequency"
    }];
    let channels = channel_names();
    columns.extend(channels.into_iter().filter(|c| *c != param));
    if block["channels"].get(NOISE_COLUMNS[0].name).is_some() {
        columns.extend(columns::names(&NOISE_COLUMNS));
    }
    let channels = rows(block, "channels", &columns[1..]);
    let table = values
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let mut r = vec![*v];
            r.extend(channels.get(i).cloned().unwrap_or_default());
            r
        })
        .collect();
    Some((param, table, columns))
}

/// The presentation of a steady tap's `document` ([`crate::request::peakforce::document`]):
/// the summary, and with `files` the two tables, the figures (all files) and the document
/// `peakforce.json`.
pub(crate) fn peakforce(
    document: &mut Value,
    text: TextUnits,
    to: Destination<'_>,
) -> Presentation {
    let mut p = tail();
    let sweep = sweep_table(document);
    summary(&mut p, document, text, sweep.as_ref());
    if to.files == Files::None {
        return p;
    }
    let cycle = rows(document, "cycle", &CYCLE_COLUMNS);
    let filtered = document["curve"].get(FILTERED_COLUMNS[0]).is_some();
    let curve_columns: Vec<&str> = if filtered {
        CURVE_COLUMNS
            .iter()
            .chain(&FILTERED_COLUMNS)
            .copied()
            .collect()
    } else {
        CURVE_COLUMNS.to_vec()
    };
    let curve = rows(document, "curve", &curve_columns);
    numeric_csv(&mut p, "peakforce-cycle.csv", &CYCLE_COLUMNS, &cycle);
    numeric_csv(&mut p, "peakforce-curve.csv", &curve_columns, &curve);
    if let Some((_, rows, columns)) = &sweep {
        numeric_csv(&mut p, "peakforce-sweep.csv", columns, rows);
    }
    if to.files == Files::All {
        figures(
            &mut p,
            document,
            text.si(),
            (&cycle, &curve, filtered),
            sweep.as_ref(),
        );
    }
    with_document(
        &mut p,
        document,
        ("peakforce.json", "peakforce-cycle.csv"),
        to.dir,
    );
    p
}

/// The summary of a steady tap's `document` into `p`: its channels, the DMT fit beside the
/// true modulus, the orbit's stability and, with a `sweep`, its length.
fn summary(p: &mut Presentation, document: &Value, text: TextUnits, sweep: Option<&SweepTable>) {
    let si = text.si();
    let ch = &document["channels"];
    let num = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    let value = |v: f64, si_unit: &str, model_unit: &str| {
        if si {
            text.value(v, si_unit)
        } else {
            format!("{v:e} {model_unit}")
        }
    };
    // a dissipation within the cycle's energy balance residual is round-off, not a value
    // (issue 77: "dissipation -5.3e-12 aJ per cycle" on an elastic sample)
    let (dissipation, residual) = (
        num(&ch["dissipation"]),
        num(&document["balance"]["residual"]),
    );
    let dissipation = if dissipation.abs() <= residual {
        format!(
            "0 (within the energy balance's residual, {})",
            value(residual, "J", "F·g0")
        )
    } else {
        value(dissipation, "J", "F·g0")
    };
    p.line(format!(
        "steady tap at z_c = {}: peak force {}, adhesion {}, deformation {}, dissipation {} per \
         cycle",
        value(num(&document["z_c"]), "m", "g0"),
        value(num(&ch["peak_force"]), "N", "F"),
        value(num(&ch["adhesion"]), "N", "F"),
        value(num(&ch["deformation"]), "m", "g0"),
        dissipation,
    ));
    p.line(format!(
        "contact time {}, snap-off at {}, ringing {}",
        value(num(&ch["contact_time"]), "s", "τ"),
        value(num(&ch["snap_off_time"]), "s", "τ"),
        value(num(&ch["ringing_amplitude"]), "m", "g0"),
    ));
    let m = &document["modulus"];
    if let (Some(fit), Some(truth)) = (m["modulus_dmt"].as_f64(), m["true"].as_f64()) {
        p.line(format!(
            "modulus_dmt {} against the sample's {} (ratio {:.4})",
            value(fit, "Pa", "(α4)"),
            value(truth, "Pa", "(α4)"),
            fit / truth
        ));
    }
    let th = &document["thermal"];
    if th.is_object() {
        p.line(format!(
            "thermal noise at {} K, per cycle: σ(peak force) = {}, σ(deformation) = {}",
            num(&th["temperature"]),
            value(num(&th["peak_force_noise"]), "N", "F"),
            value(num(&th["deformation_noise"]), "m", "g0"),
        ));
        let sim = &th["simulated"];
        if sim.is_object() {
            let q = |k: &str, i: usize| num(&sim[k][i]);
            p.line(format!(
                "  simulated over {} cycles (seed {}): σ(peak force) = {} ± {}, 1–99 % {} to {}; \
                 σ(deformation) = {} ± {}",
                sim["cycles"],
                sim["seed"],
                value(num(&sim["peak_force_noise"]), "N", "F"),
                value(num(&sim["peak_force_noise_error"]), "N", "F"),
                value(q("peak_force_quantiles", 0), "N", "F"),
                value(q("peak_force_quantiles", 2), "N", "F"),
                value(num(&sim["deformation_noise"]), "m", "g0"),
                value(num(&sim["deformation_noise_error"]), "m", "g0"),
            ));
        }
    }
    let o = &document["orbit"];
    p.line(format!(
        "orbit: period {} modulation period(s), {}; largest Floquet multiplier |μ| = {:.3e}",
        o["period"].as_u64().unwrap_or(0),
        if o["stable"].as_bool().unwrap_or(false) {
            "stable"
        } else {
            "unstable"
        },
        o["multipliers"]
            .as_array()
            .and_then(|a| a.first())
            .map(|m| num(&m[0]).hypot(num(&m[1])))
            .unwrap_or(f64::NAN),
    ));
    if let Some((param, table, _)) = sweep {
        let failed = document["sweep"]["message"]
            .as_array()
            .map_or(0, |m| m.iter().filter(|x| !x.is_null()).count());
        p.line(format!(
            "sweep of {} values of {param}{}; the tap above is the first value computed",
            table.len(),
            if failed > 0 {
                format!(" ({failed} failed)")
            } else {
                String::new()
            }
        ));
    }
}

/// The distances about the contact of a tap's force curve (rows: approach distance and force,
/// retract distance and force): where |F| is at least 2 % of its largest, widened by a quarter
/// of that span below and one span above (the force's onset and the adhesion's tail); `None`
/// when that covers most of the modulation anyway (nothing to zoom on).
fn contact_window(curve: &[Vec<f64>]) -> Option<(f64, f64)> {
    let points = || {
        curve
            .iter()
            .flat_map(|r| [(r[0], r[1]), (r[2], r[3])])
            .filter(|(d, f)| d.is_finite() && f.is_finite())
    };
    let peak = points().map(|(_, f)| f.abs()).fold(0.0, f64::max);
    let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
    for (d, _) in points().filter(|(_, f)| f.abs() >= 0.02 * peak) {
        (a, b) = (a.min(d), b.max(d));
    }
    let (lo, hi) = points().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (d, _)| {
        (lo.min(d), hi.max(d))
    });
    let w = (b - a).max(1e-3 * (hi - lo));
    let window = (a - 0.25 * w, b + w);
    (peak > 0.0 && window.1 - window.0 < 0.5 * (hi - lo)).then_some(window)
}

/// The figures of a steady tap into `p` (in SI when `si`): force against distance (the
/// `curve`'s rows; the force through the instrument's filter too when `filtered`), the
/// `sweep`'s peak force and adhesion, and force against time (the `cycle`'s rows).
fn figures(
    p: &mut Presentation,
    document: &Value,
    si: bool,
    (cycle, curve, filtered): (&[Vec<f64>], &[Vec<f64>], bool),
    sweep: Option<&SweepTable>,
) {
    let (l, f, t) = if si {
        (" (m)", " (N)", " (s)")
    } else {
        (" (g0)", " (F)", " (τ)")
    };
    let series = |label: &str, pts: Vec<(f64, f64)>, color: usize| Series {
        label: label.into(),
        points: pts
            .into_iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect(),
        style: Style::Line,
        color,
    };
    // the distances shown: the contact's, as instruments show a force curve (the whole
    // modulation in the table)
    let (lo, hi) = contact_window(curve).unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
    let shown = |x: usize, y: usize| -> Vec<(f64, f64)> {
        let rows = curve.iter().map(|r| (r[x], r[y]));
        rows.filter(|(d, _)| (lo..=hi).contains(d)).collect()
    };
    let mut all = vec![
        series("approach", shown(0, 1), 0),
        series("retract", shown(2, 3), 1),
    ];
    if filtered {
        all.push(series("approach, k × deflection filtered", shown(0, 4), 2));
        all.push(series("retract, k × deflection filtered", shown(2, 5), 3));
    }
    let title = if hi.is_finite() {
        "PeakForce tapping: force against tip–sample distance, about the contact"
    } else {
        "PeakForce tapping: force against tip–sample distance"
    };
    p.figure(
        "peakforce-curve",
        lines(title, (format!("distance{l}"), format!("force{f}")), all),
    );
    if let Some((param, rows, _)) = sweep {
        let unit = document["sweep"]["unit"].as_str().unwrap_or("");
        // columns: the value, then the sweep's channels (peak_force, adhesion first)
        let peak = rows.iter().map(|r| (r[0], r[1])).collect();
        let adhesion = rows.iter().map(|r| (r[0], r[2])).collect();
        p.figure(
            "peakforce-sweep",
            lines(
                "PeakForce tapping: peak force and adhesion over the sweep",
                (format!("{param} ({unit})"), format!("force{f}")),
                vec![
                    series("peak force", peak, 0),
                    series("adhesion", adhesion, 1),
                ],
            ),
        );
    }
    let time = cycle.iter().map(|r| (r[0], r[3])).collect();
    p.figure(
        "peakforce-force-time",
        lines(
            "PeakForce tapping: force over one modulation period",
            (
                format!("time from the largest separation{t}"),
                format!("force{f}"),
            ),
            vec![series("", time, 0)],
        ),
    );
}

#[cfg(test)]
mod tests {
    /// The force curve is shown about the contact (issue 77 §12: a 300 nm modulation made the
    /// few-nm contact a vertical line): a Hertz contact F ∝ max(−d, 0)^{3/2} below d = 0 with
    /// a 1 nm adhesive well, over distances from −3 nm to 297 nm, is shown from below its
    /// deepest point to a few nm above the contact; a force over the whole range is not zoomed.
    #[test]
    fn the_force_curve_is_shown_about_the_contact() {
        let row = |d: f64| {
            let f = if d < 0.0 {
                (-d).powf(1.5)
            } else {
                -0.3 * (-d).exp()
            };
            vec![d, f, d, f]
        };
        let curve: Vec<Vec<f64>> = (0..=3000).map(|i| row(-3.0 + 0.1 * i as f64)).collect();
        let (lo, hi) = super::contact_window(&curve).expect("zoomed");
        assert!((-4.5..-3.0).contains(&lo), "{lo}");
        assert!(hi > 3.0 && hi < 15.0, "{hi}");
        let linear: Vec<Vec<f64>> = (0..=300)
            .map(|i| vec![i as f64, i as f64, i as f64, i as f64])
            .collect();
        assert_eq!(super::contact_window(&linear), None);
    }
}
