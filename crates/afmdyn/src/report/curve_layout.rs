//! The layout of a stepped curve ([`curve_layout`]: `approach`, `bimodal`, `resonance`), laid
//! out from its JSON document (the command line's `--json`, already in SI with a probe): what
//! Python's `afmdyn.approach` and `afmdyn.resonance` return as a dataset.

use crate::layout::{Layout, Values, Variable};
use crate::report::{CURVE_COLUMNS, NOISE_COLUMNS};
use serde_json::Value;
use std::collections::HashMap;

/// The abscissae of the curves in order of preference: (key, kind of unit, long name).
const ABSCISSAE: [(&str, &str, &str); 3] = [
    (
        "z_c",
        "length",
        "rest distance z_c of the tip above the sample",
    ),
    ("frequency_hz", "Hz", "drive frequency"),
    ("omega", "Ω", "dimensionless drive frequency Ω"),
];

/// The traces of a curve: (key, kind of unit, long name).
const TRACES: [(&str, &str, &str); 3] = [
    ("deflection", "length", "tip deflection W(1,tau)"),
    (
        "distance",
        "length",
        "tip-sample distance V_T (<= 0 in contact)",
    ),
    (
        "force",
        "force",
        "tip-sample force F_c (> 0 repulsive, < 0 attractive)",
    ),
];

const STABLE: &str = "every Floquet multiplier inside the unit circle";

fn list(v: &Value) -> &[Value] {
    v.as_array().map_or(&[], Vec::as_slice)
}

fn number(v: &Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

/// Numbers (lists of them flattened, row-major), `null` as NaN.
fn numbers(v: &Value) -> Vec<f64> {
    list(v)
        .iter()
        .flat_map(|x| match x {
            Value::Array(row) => row.iter().map(number).collect(),
            x => vec![number(x)],
        })
        .collect()
}

/// A grid value's key (0 and -0 one key, as Python's dict of floats has it).
fn key(v: f64) -> u64 {
    if v == 0.0 {
        0
    } else {
        v.to_bits()
    }
}

fn text(v: &Value) -> String {
    v.as_str().unwrap_or_default().to_string()
}

/// The unit of a `kind` of quantity in a document's `units` (the kind itself where they do not
/// name it), `1` for a pure number (`None`).
fn unit(units: &Value, kind: Option<&str>) -> String {
    match kind {
        None => "1".to_string(),
        Some(k) => units
            .get(k)
            .and_then(Value::as_str)
            .unwrap_or(k)
            .to_string(),
    }
}

/// A curve's column: (key, kind of unit or none, long name).
type Column = (String, Option<String>, String);

/// A curve's abscissa: (key, unit, long name).
type Abscissa<'a> = (&'a str, &'a str, &'a str);

/// The layout of a stepped curve's document `doc`.
///
/// Dimensions: the abscissa (`z_c`, `frequency_hz` or `omega`: the values of the first sweep,
/// in its order) and `sweep` (`approach`/`retract` or `up`/`down`); the columns of both sweeps
/// over (sweep, abscissa) with `stable`, `period` (NaN when not period-n) and `reached`. The
/// branches concatenated along `branch_point` (`branch` is the branch index, `event` "" where
/// none); with traces, `trace_deflection`, `trace_distance`, `trace_force` over (`trace`,
/// `trace_time` in drive periods), and `trace_<abscissa>` over `trace`. Every unit is the
/// document's (`units`), `1` for a pure number.
pub(crate) fn curve_layout(doc: &Value) -> Layout {
    let units = &doc["units"];
    let sweeps = if doc.get("approach").is_some() {
        ["approach", "retract"]
    } else {
        ["up", "down"]
    };
    let first = &doc[sweeps[0]];
    let (x, x_kind, x_name) = ABSCISSAE
        .into_iter()
        .find(|(k, ..)| first.get(*k).is_some())
        .unwrap_or(ABSCISSAE[0]);
    let x_unit = unit(units, Some(x_kind));
    let abscissa = (x, x_unit.as_str(), x_name);
    let grid = numbers(&first[x]);
    // the curve's columns; with a temperature σ_A and σ_φ of the lock-in; under a
    // multifrequency drive each component's (amplitude_i, phase_i_deg, …) too
    let noise = first.get(NOISE_COLUMNS[0].name).is_some();
    let mut columns: Vec<Column> = (CURVE_COLUMNS.iter())
        .chain(NOISE_COLUMNS.iter().filter(|_| noise))
        .map(|c| {
            let kind = c.kind.key().map(Into::into);
            (c.name.into(), kind, c.long_name.into())
        })
        .collect();
    for c in list(&doc["drive_components"]["columns"]) {
        let kind = c[1].as_str().map(Into::into);
        columns.push((text(&c[0]), kind, text(&c[2])));
    }
    let sweep = Values::Text(sweeps.map(Into::into).into());
    let mut vars = vec![
        Variable::new(x, &[x], &x_unit, x_name, Values::F64(grid.clone())),
        Variable::new("sweep", &["sweep"], "", "sweep", sweep),
    ];
    vars.extend(sweep_variables(doc, sweeps, x, &grid, &columns));
    let branches = branch_variables(doc, abscissa, &columns);
    let mut dims = vec![(x, grid.len()), ("sweep", 2), ("branch_point", branches.1)];
    vars.extend(branches.0);
    let traces = &doc["traces"];
    if traces.is_object() {
        let (trace_vars, trace_dims) = trace_variables(traces, units, abscissa);
        dims.extend(trace_dims);
        vars.extend(trace_vars);
    }
    Layout::new("stepped curve", &dims, vars)
}

/// The two `sweeps` of `doc` on the `grid` of the abscissa `x` (the first sweep's values):
/// the `columns`, `stable`, `period` and `reached` over (sweep, abscissa), NaN (false, "")
/// where a sweep has no point.
fn sweep_variables(
    doc: &Value,
    sweeps: [&str; 2],
    x: &str,
    grid: &[f64],
    columns: &[Column],
) -> Vec<Variable> {
    let units = &doc["units"];
    let index: HashMap<u64, usize> = grid.iter().enumerate().map(|(i, v)| (key(*v), i)).collect();
    let on_grid = |col: &str, put: &mut dyn FnMut(usize, &Value)| {
        for (s, name) in sweeps.iter().enumerate() {
            let sweep = &doc[*name];
            for (v, at) in list(&sweep[col]).iter().zip(list(&sweep[x])) {
                if let Some(i) = index.get(&key(number(at))) {
                    put(s * grid.len() + i, v);
                }
            }
        }
    };
    let size = 2 * grid.len();
    let grid_f64 = |col: &str| {
        let mut out = vec![f64::NAN; size];
        on_grid(col, &mut |i, v| out[i] = number(v));
        Values::F64(out)
    };
    let xdims = ["sweep", x];
    let mut vars: Vec<Variable> = columns
        .iter()
        .map(|(col, kind, long)| {
            let unit = unit(units, kind.as_deref());
            Variable::new(col, &xdims, &unit, long.as_str(), grid_f64(col))
        })
        .collect();
    let mut stable = vec![false; size];
    on_grid("stable", &mut |i, v| {
        stable[i] = v.as_bool().unwrap_or(false)
    });
    let mut reached = vec![String::new(); size];
    on_grid("reached", &mut |i, v| reached[i] = text(v));
    let period = "n of the period-n motion (NaN: not periodic)";
    let how = "how the point's steady state was reached";
    vars.extend([
        Variable::new("stable", &xdims, "", STABLE, Values::Bool(stable)),
        Variable::new("period", &xdims, "1", period, grid_f64("period")),
        Variable::new("reached", &xdims, "", how, Values::Text(reached)),
    ]);
    vars
}

/// The branches of `doc` concatenated along `branch_point`: the branch index, the abscissa,
/// the `columns`, `stable`, `period` and `event`; and the number of points.
fn branch_variables(
    doc: &Value,
    (x, x_unit, x_name): Abscissa,
    columns: &[Column],
) -> (Vec<Variable>, usize) {
    let units = &doc["units"];
    let branches = list(&doc["branches"]);
    let along =
        |col: &str| -> Vec<&Value> { branches.iter().flat_map(|b| list(&b[col])).collect() };
    let floats = |col: &str| Values::F64(along(col).into_iter().map(number).collect());
    let ids = branches.iter().enumerate();
    let ids: Vec<i32> = ids
        .flat_map(|(i, b)| std::iter::repeat_n(i as i32, list(&b[x]).len()))
        .collect();
    let points = ids.len();
    let bp = ["branch_point"];
    let mut vars = vec![
        Variable::new("branch", &bp, "", "branch index", Values::I32(ids)),
        Variable::new(&format!("branch_{x}"), &bp, x_unit, x_name, floats(x)),
    ];
    for (col, kind, long) in columns {
        let unit = unit(units, kind.as_deref());
        let name = format!("branch_{col}");
        vars.push(Variable::new(&name, &bp, &unit, long.as_str(), floats(col)));
    }
    let flags = along("stable")
        .into_iter()
        .map(|v| v.as_bool().unwrap_or(false));
    let orbit = "n of the period-n orbit";
    let events = Values::Text(along("event").into_iter().map(text).collect());
    let event = "event at the point (fold, period-doubling, grazing, ...)";
    vars.extend([
        Variable::new(
            "branch_stable",
            &bp,
            "",
            STABLE,
            Values::Bool(flags.collect()),
        ),
        Variable::new("branch_period", &bp, "1", orbit, floats("period")),
        Variable::new("branch_event", &bp, "", event, events),
    ]);
    (vars, points)
}

/// The recorded cycles `traces` (their units in `units`): `trace_time` in drive periods, the
/// abscissa of each trace and the traces over (`trace`, `trace_time`); and those two dimensions.
fn trace_variables(
    traces: &Value,
    units: &Value,
    (x, x_unit, x_name): Abscissa,
) -> (Vec<Variable>, [(&'static str, usize); 2]) {
    let time = numbers(&traces["time_periods"]);
    let at = numbers(&traces[x]);
    let dims = [("trace", at.len()), ("trace_time", time.len())];
    let within = "time within the recorded cycle";
    let mut vars = vec![
        Variable::new(
            "trace_time",
            &["trace_time"],
            "drive periods",
            within,
            Values::F64(time),
        ),
        Variable::new(
            &format!("trace_{x}"),
            &["trace"],
            x_unit,
            x_name,
            Values::F64(at),
        ),
    ];
    for (var, kind, long) in TRACES {
        let values = Values::F64(numbers(&traces[var]));
        let name = format!("trace_{var}");
        let unit = unit(units, Some(kind));
        vars.push(Variable::new(
            &name,
            &["trace", "trace_time"],
            &unit,
            long,
            values,
        ));
    }
    (vars, dims)
}

/// The per-component observables of a multifrequency drive: (key, kind of unit, long name).
const COMPONENTS: [(&str, &str, &str); 8] = [
    (
        "amplitude",
        "length",
        "tip amplitude at the component's frequency",
    ),
    (
        "phase_deg",
        "phase",
        "phase lag behind the component's drive",
    ),
    (
        "free_amplitude",
        "length",
        "free amplitude at the component's frequency",
    ),
    ("free_phase_deg", "phase", "the free response's lag"),
    (
        "virial",
        "energy",
        "<F_ts z_i>, z_i the motion at the component's frequency",
    ),
    (
        "energy_dissipated",
        "energy",
        "energy dissipated per cycle of the component",
    ),
    (
        "closed_virial",
        "energy",
        "closed form -(k A A0/(2Q)) cos(phase)",
    ),
    (
        "closed_energy_dissipated",
        "energy",
        "closed form (pi k A^2/Q)[(A0/A) sin(phase) - f/f0]",
    ),
];

/// The observables beside the curve columns: (key, kind of unit or none, long name).
const OBSERVED: [(&str, Option<&str>, &str); 4] = [
    (
        "contact_time",
        Some("time"),
        "time in contact per drive period",
    ),
    (
        "mean_force",
        Some("force"),
        "time-averaged tip-sample force",
    ),
    (
        "impacts_per_period",
        None,
        "entries into contact (impacts) per drive period",
    ),
    (
        "impact_loss",
        Some("energy"),
        "kinetic energy lost in impacts per drive period",
    ),
];

/// The layout of an `observe` document `doc` (its `reported` block: SI with a probe, phases in
/// degrees), from the start `state` (a, ȧ) and the `period` n (`None`: not periodic).
///
/// Scalars: the curve columns, `contact_time`, `mean_force`, `impacts_per_period`,
/// `impact_loss`, `period` (NaN when not periodic); `harmonic_amplitude` and
/// `harmonic_phase_deg` over `harmonic` (n); the per-mode energy balance `mode_drive`,
/// `mode_beam_damping`, `mode_sample`, `mode_coupling`, `mode_energy_change`,
/// `mode_residual` over `mode`; `state` over `state_index`; under a multifrequency drive
/// `component_amplitude`, `component_phase_deg`, … and `component_ratio` over `component`
/// (1, 2, …).
pub(crate) fn observe_layout(doc: &Value, state: &[f64], period: Option<usize>) -> Layout {
    let r = &doc["reported"];
    let units = &r["units"];
    let scalar = |key: &str, kind: Option<&str>, long: &str| {
        let value = Values::F64(vec![number(&r[key])]);
        Variable::new(key, &[], &unit(units, kind), long, value)
    };
    let mut vars: Vec<Variable> = CURVE_COLUMNS
        .iter()
        .map(|c| scalar(c.name, c.kind.key(), c.long_name))
        .collect();
    vars.extend(
        OBSERVED
            .iter()
            .map(|(k, kind, long)| scalar(k, *kind, long)),
    );
    let (harmonics, n) = harmonic_variables(&r["harmonics"], units);
    vars.extend(harmonics);
    let (balance, modes) = mode_balance_variables(&r["mode_balance"], units);
    vars.extend(balance);
    let mut dims = vec![
        ("harmonic", n),
        ("mode", modes),
        ("state_index", state.len()),
    ];
    let comp = &r["components"];
    if comp.is_object() {
        let ratio = numbers(&comp["ratio"]);
        let ids = (1..=ratio.len() as i32).collect();
        dims.push(("component", ratio.len()));
        let cd = ["component"];
        vars.push(Variable::new(
            "component",
            &cd,
            "",
            "component",
            Values::I32(ids),
        ));
        for (key, kind, long) in COMPONENTS {
            let values = Values::F64(numbers(&comp[key]));
            let name = format!("component_{key}");
            vars.push(Variable::new(
                &name,
                &cd,
                &unit(units, Some(kind)),
                long,
                values,
            ));
        }
        let over = "frequency over the first's";
        vars.push(Variable::new(
            "component_ratio",
            &cd,
            "1",
            over,
            Values::F64(ratio),
        ));
    }
    let start = "state (a, da/dtau) at tau = 0 the observables start from";
    let values = Values::F64(state.to_vec());
    vars.push(Variable::new("state", &["state_index"], "", start, values));
    let n_of = "n of the period-n motion (NaN: not periodic)";
    let p = Values::F64(vec![period.map_or(f64::NAN, |n| n as f64)]);
    vars.push(Variable::new("period", &[], "1", n_of, p));
    Layout::new("observe", &dims, vars)
}

/// Integers (`null` and others as 0).
fn integers(v: &Value) -> Vec<i32> {
    list(v)
        .iter()
        .map(|x| x.as_i64().unwrap_or(0) as i32)
        .collect()
}

/// The harmonics `h` of an `observe` document: their orders n, amplitudes and phases over
/// `harmonic`; and how many.
fn harmonic_variables(h: &Value, units: &Value) -> (Vec<Variable>, usize) {
    let n = integers(&h["n"]);
    let count = n.len();
    let hd = ["harmonic"];
    let amp = "amplitude of harmonic n";
    let amplitude = Values::F64(numbers(&h["amplitude"]));
    let length = unit(units, Some("length"));
    let phase = Values::F64(numbers(&h["phase_deg"]));
    let ph = "phase of harmonic n";
    let deg = unit(units, Some("phase"));
    let vars = vec![
        Variable::new("harmonic", &hd, "", "harmonic", Values::I32(n)),
        Variable::new("harmonic_amplitude", &hd, &length, amp, amplitude),
        Variable::new("harmonic_phase_deg", &hd, &deg, ph, phase),
    ];
    (vars, count)
}

/// The per-mode energy balance `b` of an `observe` document over `mode`: the modes and each
/// term; and how many modes.
fn mode_balance_variables(b: &Value, units: &Value) -> (Vec<Variable>, usize) {
    let modes = integers(&b["mode"]);
    let count = modes.len();
    let mut vars = vec![Variable::new(
        "mode",
        &["mode"],
        "",
        "mode",
        Values::I32(modes),
    )];
    let energy = unit(units, Some("energy"));
    for term in [
        "drive",
        "beam_damping",
        "sample",
        "coupling",
        "energy_change",
        "residual",
    ] {
        let long = format!("energy balance of the mode per drive period: {term}");
        let values = Values::F64(numbers(&b[term]));
        let name = format!("mode_{term}");
        vars.push(Variable::new(&name, &["mode"], &energy, long, values));
    }
    (vars, count)
}
