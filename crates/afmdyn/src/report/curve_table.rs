//! The table of a stepped curve (`approach.csv`/`.npy`, `resonance.csv`/`.npy`; feature
//! `files`): one row per point of both sweeps and of every continued branch, its columns named
//! as the JSON document ([`CURVE_COLUMNS`] after the abscissa, then afmdyn's own) or, on
//! request, first as dForce 2.0's `zcdom` table — declared here once, for every front end that
//! writes the table.

use super::{
    component_columns, component_noise_columns, component_row, curve_column_index, curve_row,
    noise_row, CurveUnits, UnitKind, CURVE_COLUMNS, NOISE_COLUMNS,
};
use crate::analysis::continuation::BranchEvent;
use crate::analysis::lock_in_noise::LockInNoise;
use crate::analysis::observables::Observables;
use crate::analysis::stepped::SteppedCurve;
use crate::layout::files::Column;
use crate::params::Params;

/// The abscissa of a curve's table and the names of its two sweeps.
#[derive(Debug, Clone)]
pub(crate) struct CurveAxis {
    /// The abscissa's name in the JSON document (`z_c`, `frequency_hz`, `omega`).
    pub name: &'static str,
    /// Its meaning, with the unit (the axis label of the plots).
    pub label: String,
    /// The names of the two sweeps (`approach`/`retract`, `up`/`down`).
    pub sweeps: (&'static str, &'static str),
}

/// The rows and columns of the table of `c`: abscissa values `x(value)` in `u`'s unit, the
/// observables in `u`'s units, at the drive of `base`; with `dforce` the columns of dForce
/// 2.0's `zcdom` table first and in its order, else named and ordered as the JSON document.
pub(crate) fn curve_table(
    c: &SteppedCurve,
    x: &dyn Fn(f64) -> f64,
    u: &CurveUnits,
    base: &Params,
    axis: &CurveAxis,
    dforce: bool,
) -> (Vec<Vec<f64>>, Vec<Column>) {
    let mut cols = columns(axis, u);
    // the per-component columns of a multifrequency drive, last in either layout
    let count = c.components();
    for (name, kind, what) in component_columns(count) {
        cols.push(Column::new(name, u.unit(kind), what));
    }
    // with a temperature the lock-ins' σ_A and σ_φ, after them (NaN on the branches)
    if c.noise.is_some() {
        for c in NOISE_COLUMNS {
            cols.push(Column::new(c.name, u.unit(c.kind), c.long_name));
        }
        for (name, kind, what) in component_noise_columns(count) {
            cols.push(Column::new(name, u.unit(kind), what));
        }
    }
    if dforce {
        (rows(c, x, u, base), cols)
    } else {
        json_layout(rows(c, x, u, base), cols, axis.name)
    }
}

/// The code of a branch event in the table's `event` column.
fn event_code(e: Option<BranchEvent>) -> f64 {
    match e {
        None => 0.0,
        Some(BranchEvent::Fold) => 1.0,
        Some(BranchEvent::Grazing) => 2.0,
        Some(BranchEvent::PeriodDoubling) => 3.0,
        Some(BranchEvent::NeimarkSacker) => 4.0,
    }
}

/// The leading columns of the table: dForce 2.0's `zcdom` table (Gisbert & Garcia, *Soft
/// Matter* 19 (2023) 5857; the header of its `zcdom*.csv`), in its order, with afmdyn's
/// definitions and SI units (dForce writes nm, pN, 1e-20 J).
const DFORCE: [&str; 9] = [
    "Amplitude",
    "Phase",
    "Distance_min",
    "Force_max",
    "Energy_diss",
    "Virial1",
    "Deflection",
    "Contact_time",
    "Power_diss",
];

/// A sweep point or branch point as the table has it: its abscissa `x`, its observables at
/// the drive frequency `omega`, and its `sweep`, `stable`, `period` and `event` columns.
struct TablePoint<'a> {
    x: f64,
    observables: &'a Observables,
    omega: f64,
    sweep: f64,
    stable: bool,
    period: Option<usize>,
    event: Option<BranchEvent>,
}

/// The numeric row of a point, in the order of [`columns`].
fn row(point: &TablePoint, u: &CurveUnits) -> Vec<f64> {
    let TablePoint {
        x,
        observables: o,
        omega,
        sweep: code,
        stable,
        period,
        event,
    } = *point;
    let period_s = std::f64::consts::TAU / omega * u.time;
    // the library's values of the observables in u's units (one derivation: curve_row), in
    // the order of this file's columns
    let c = curve_row(o, u);
    let at = |name: &str| c[curve_column_index(name).expect("a curve column")];
    let mut r = vec![
        x,
        at("amplitude"),
        at("phase_deg"),
        at("min_distance"),
        at("peak_force").max(-at("min_force")),
        at("energy_dissipated"),
        at("virial"),
        at("mean_deflection"),
        o.contact_time * u.time,
        at("energy_dissipated") / period_s,
        code,
        at("amplitude_ratio"),
        at("peak_force"),
        at("min_force"),
        at("indentation"),
        at("contact_fraction"),
        at("harmonic_distortion"),
        at("higher_mode_fraction"),
    ];
    r.push(if stable { 1.0 } else { 0.0 });
    r.push(period.map_or(f64::NAN, |n| n as f64));
    r.push(event_code(event));
    r.extend(component_row(o, u));
    r
}

/// The table's rows: the two sweeps' points, then every branch's.
fn rows(c: &SteppedCurve, x: &dyn Fn(f64) -> f64, u: &CurveUnits, base: &Params) -> Vec<Vec<f64>> {
    let omega = |v: f64| base.with(c.param, v).omega;
    let mut out = Vec::new();
    let noise = |s: Option<&LockInNoise>| noise_row(s, c.components(), u).into_iter().map(|v| v.1);
    for (k, (code, sweep)) in [(0.0, &c.first), (1.0, &c.second)].into_iter().enumerate() {
        for (i, p) in sweep.iter().enumerate() {
            let point = TablePoint {
                x: x(p.value),
                observables: &p.observables,
                omega: omega(p.value),
                sweep: code,
                stable: p.stable,
                period: p.period,
                event: None,
            };
            let mut r = row(&point, u);
            if let Some(n) = &c.noise {
                r.extend(noise(n[k].get(i)));
            }
            out.push(r);
        }
    }
    for (k, b) in c.branches.iter().enumerate() {
        for s in b {
            let bp = &s.point;
            let point = TablePoint {
                x: x(bp.value),
                observables: &s.observables,
                omega: omega(bp.value),
                sweep: 2.0 + k as f64,
                stable: bp.stable,
                period: Some(bp.period),
                event: bp.event,
            };
            let mut r = row(&point, u);
            if c.noise.is_some() {
                r.extend(noise(None));
            }
            out.push(r);
        }
    }
    out
}

/// The table's columns in dForce's layout, named and described.
fn columns(l: &CurveAxis, u: &CurveUnits) -> Vec<Column> {
    // the library's columns (name, unit, meaning: report::CURVE_COLUMNS) by name
    let lib = |name: &str| {
        let c = CURVE_COLUMNS[curve_column_index(name).expect("a curve column")];
        (u.unit(c.kind), c.long_name)
    };
    let force = u.unit(UnitKind::Force);
    let (time, power) = if u.si {
        ("s", "W")
    } else {
        ("tau", "F~ g0 / tau")
    };
    let x_unit = match (l.name, u.si, u.hz_per_omega.is_some()) {
        ("z_c", true, _) => "m",
        ("z_c", false, _) => "g0",
        (_, _, true) => "Hz",
        _ => "1",
    };
    let meaning = [
        lib("amplitude"),
        lib("phase_deg"),
        lib("min_distance"),
        (
            force,
            "largest |tip–sample force| (dForce's definition; see peak_force)",
        ),
        lib("energy_dissipated"),
        lib("virial"),
        lib("mean_deflection"),
        (time, "time in contact per period"),
        (power, "dissipated power: Energy_diss per period / period"),
    ];
    let x_name = if l.name == "z_c" { "zc" } else { l.name };
    let mut cols = vec![Column::new(x_name, x_unit, l.label.clone())];
    for (name, (unit, what)) in DFORCE.iter().zip(meaning) {
        cols.push(Column::new(*name, unit, what));
    }
    cols.push(Column::new(
        "sweep",
        "1",
        format!("0 {}, 1 {}, 2 + k branch k", l.sweeps.0, l.sweeps.1),
    ));
    for name in [
        "amplitude_ratio",
        "peak_force",
        "min_force",
        "indentation",
        "contact_fraction",
        "harmonic_distortion",
        "higher_mode_fraction",
    ] {
        let (unit, what) = lib(name);
        cols.push(Column::new(name, unit, what));
    }
    cols.extend([
        Column::new("stable", "1", "1 stable (Floquet), 0 unstable"),
        Column::new(
            "period",
            "drive periods",
            "period n of the orbit (NaN: not period-n)",
        ),
        Column::new(
            "event",
            "1",
            "0 none, 1 fold, 2 grazing, 3 period doubling, 4 Neimark–Sacker",
        ),
    ]);
    cols
}

/// The table's columns named and ordered as the JSON document ([`CURVE_COLUMNS`] after the
/// abscissa), then afmdyn's own: (name, index in the dForce layout of [`row`]/[`columns`]).
const JSON_LAYOUT: [(&str, usize); 20] = [
    ("amplitude", 1),
    ("amplitude_ratio", 11),
    ("phase_deg", 2),
    ("mean_deflection", 7),
    ("peak_force", 12),
    ("min_force", 13),
    ("indentation", 14),
    ("contact_fraction", 15),
    ("min_distance", 3),
    ("energy_dissipated", 5),
    ("virial", 6),
    ("harmonic_distortion", 16),
    ("higher_mode_fraction", 17),
    ("stable", 18),
    ("period", 19),
    ("sweep", 10),
    ("event", 20),
    ("contact_time", 8),
    ("max_abs_force", 4),
    ("power_dissipated", 9),
];

/// `table` and `cols` (dForce's layout) in the JSON layout ([`JSON_LAYOUT`]; the abscissa
/// keeps its place and takes the JSON's name `x_json`).
fn json_layout(
    table: Vec<Vec<f64>>,
    cols: Vec<Column>,
    x_json: &str,
) -> (Vec<Vec<f64>>, Vec<Column>) {
    let mut named = vec![Column::new(x_json, cols[0].unit, cols[0].meaning.clone())];
    named.extend(
        JSON_LAYOUT
            .iter()
            .map(|(name, k)| Column::new(*name, cols[*k].unit, cols[*k].meaning.clone())),
    );
    // columns past the dForce layout's (the drive components') keep their order, last
    let extra = JSON_LAYOUT.len() + 1;
    named.extend(cols.into_iter().skip(extra));
    let rows = table
        .into_iter()
        .map(|r| {
            let tail = r[extra..].to_vec();
            std::iter::once(r[0])
                .chain(JSON_LAYOUT.iter().map(|(_, k)| r[*k]))
                .chain(tail)
                .collect()
        })
        .collect();
    (rows, named)
}
