//! A result table declared once: its columns, each with its name, where its unit comes from,
//! its long name and how its value is taken from a result's row. From that one declaration
//! come a JSON document's arrays ([`arrays`]) and its `units` object ([`units`]), the
//! [`Layout`](super::Layout)'s variables ([`variables`]: Python's Dataset, NetCDF) and a
//! table's columns and rows ([`names`], [`rows`]: the CSV file).
//!
//! A row is read through a frame `C` (the factors that turn the model's values into the
//! reported units, a reference point), so a column's value is a plain function of the two.

use super::{Values, Variable};
use serde_json::{Map, Value};

/// The names of the units of a result's kinds of quantity in one system of units (SI with a
/// probe, the model's without).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct UnitNames {
    /// Whether these are SI names ([`Unit::Own`] takes its first name then).
    pub si: bool,
    /// Lengths.
    pub length: &'static str,
    /// Forces.
    pub force: &'static str,
    /// Energies.
    pub energy: &'static str,
    /// Frequencies.
    pub frequency: &'static str,
}

/// Where a column's unit comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Unit {
    /// The result's length unit.
    Length,
    /// The result's force unit.
    Force,
    /// The result's energy unit.
    Energy,
    /// The result's frequency unit.
    Frequency,
    /// A unit of its own, the same in both systems (`"1"` a pure number, `""` a flag).
    Fixed(&'static str),
    /// A unit of its own in each system: (SI, the model's).
    Own(&'static str, &'static str),
}

impl UnitNames {
    /// The names of a system of units (`si` whether SI): length, force, energy, frequency.
    pub(crate) const fn new(
        si: bool,
        [length, force, energy, frequency]: [&'static str; 4],
    ) -> Self {
        UnitNames {
            si,
            length,
            force,
            energy,
            frequency,
        }
    }

    /// SI's names (m, N, J, Hz) when `si`, else the model's as the FM and PeakForce documents
    /// write them (g0, F, F·g0, Ω).
    pub(crate) const fn si_or_model(si: bool) -> Self {
        match si {
            true => UnitNames::new(true, ["m", "N", "J", "Hz"]),
            false => UnitNames::new(false, ["g0", "F", "F·g0", "Ω"]),
        }
    }
}

impl Unit {
    /// The unit's name among `names`.
    pub(crate) fn name(self, names: &UnitNames) -> &'static str {
        match self {
            Unit::Length => names.length,
            Unit::Force => names.force,
            Unit::Energy => names.energy,
            Unit::Frequency => names.frequency,
            Unit::Fixed(u) => u,
            Unit::Own(si, model) => {
                if names.si {
                    si
                } else {
                    model
                }
            }
        }
    }
}

/// How a column's value is taken from a row `R` read through a frame `C`; the variant is the
/// kind of the values.
pub(crate) enum Get<C, R> {
    /// A number.
    F64(fn(&C, &R) -> f64),
    /// A flag (a table's 1/0).
    Bool(fn(&C, &R) -> bool),
    /// A count (a layout's 32-bit integer).
    Count(fn(&C, &R) -> usize),
    /// A number that may be missing (`null` in the document, NaN in the layout and the table).
    Opt(fn(&C, &R) -> Option<f64>),
}

/// One column of a result table.
pub(crate) struct Column<C, R> {
    /// Its name: the document's key, the variable's and the table column's.
    pub name: &'static str,
    /// Where its unit comes from.
    pub unit: Unit,
    /// Whether the document's `units` object names it ([`units`]).
    pub listed: bool,
    /// What it is, in words (the variable's long name).
    pub long_name: &'static str,
    /// How its value is taken from a row.
    pub get: Get<C, R>,
}

/// The columns of a result table, one per line — `name, unit, listed, long name, get;` (the
/// fields of a [`Column`], `unit` a [`Unit`] and `get` a [`Get`] named without their enum) —
/// as an array in that order.
macro_rules! columns {
    ($($name:literal, $unit:expr, $listed:expr, $long:expr, $get:expr;)*) => {{
        use $crate::layout::columns::{Column, Get::*, Unit::*};
        [$(Column { name: $name, unit: $unit, listed: $listed, long_name: $long, get: $get }),*]
    }};
}
pub(crate) use columns;

/// The values of `column` over `rows` as a JSON array (NaN as `null`).
fn array<C, R>(column: &Column<C, R>, frame: &C, rows: &[R]) -> Value {
    match column.get {
        Get::F64(f) => rows.iter().map(|r| f(frame, r)).collect::<Vec<_>>().into(),
        Get::Bool(f) => rows.iter().map(|r| f(frame, r)).collect::<Vec<_>>().into(),
        Get::Count(f) => rows.iter().map(|r| f(frame, r)).collect::<Vec<_>>().into(),
        Get::Opt(f) => serde_json::json!(rows.iter().map(|r| f(frame, r)).collect::<Vec<_>>()),
    }
}

/// The document's arrays: one per column, keyed by its name, one entry per row.
pub(crate) fn arrays<C, R>(columns: &[Column<C, R>], frame: &C, rows: &[R]) -> Map<String, Value> {
    let named = columns
        .iter()
        .map(|c| (c.name.into(), array(c, frame, rows)));
    named.collect()
}

/// The document's `units` object: the unit of each column it names ([`Column::listed`]).
pub(crate) fn units<C, R>(columns: &[Column<C, R>], names: &UnitNames) -> Map<String, Value> {
    let listed = columns.iter().filter(|c| c.listed);
    listed
        .map(|c| (c.name.into(), c.unit.name(names).into()))
        .collect()
}

/// The layout's variables: one per column over `dims`, in the columns' order, with its unit
/// and long name.
pub(crate) fn variables<C, R>(
    columns: &[Column<C, R>],
    frame: &C,
    rows: &[R],
    dims: &[&str],
    names: &UnitNames,
) -> Vec<Variable> {
    let values = |get: &Get<C, R>| match *get {
        Get::F64(f) => Values::F64(rows.iter().map(|r| f(frame, r)).collect()),
        Get::Bool(f) => Values::Bool(rows.iter().map(|r| f(frame, r)).collect()),
        Get::Count(f) => Values::I32(rows.iter().map(|r| f(frame, r) as i32).collect()),
        Get::Opt(f) => Values::F64(
            rows.iter()
                .map(|r| f(frame, r).unwrap_or(f64::NAN))
                .collect(),
        ),
    };
    let variable = |c: &Column<C, R>| {
        let unit = c.unit.name(names);
        Variable::new(c.name, dims, unit, c.long_name, values(&c.get))
    };
    columns.iter().map(variable).collect()
}

/// The table's column names, in order.
pub(crate) fn names<C, R>(columns: &[Column<C, R>]) -> Vec<&'static str> {
    columns.iter().map(|c| c.name).collect()
}

/// The document's maps over a grid of `shape` (lines, pixels): one per column, keyed by its
/// name, as nested arrays `[line][pixel]` of the `rows` (the grid's cells, line by line).
pub(crate) fn grids<C, R>(
    columns: &[Column<C, R>],
    frame: &C,
    rows: &[R],
    (lines, pixels): (usize, usize),
) -> Map<String, Value> {
    let grid = |c: &Column<C, R>| {
        let Value::Array(flat) = array(c, frame, rows) else {
            unreachable!("a column's values are an array")
        };
        let line = |j: usize| Value::Array(flat[j * pixels..(j + 1) * pixels].to_vec());
        (c.name.into(), Value::Array((0..lines).map(line).collect()))
    };
    columns.iter().map(grid).collect()
}

/// The cells (line, pixel) of a grid of `shape` (lines, pixels), line by line: the rows of
/// its maps ([`grids`], and a layout's variables over (y, x)).
pub(crate) fn cells((lines, pixels): (usize, usize)) -> Vec<(usize, usize)> {
    (0..lines)
        .flat_map(|j| (0..pixels).map(move |i| (j, i)))
        .collect()
}

impl<C, R> Column<C, R> {
    /// Its value at `row` as a number (flags as 1/0, NaN where missing).
    pub(crate) fn number(&self, frame: &C, row: &R) -> f64 {
        match self.get {
            Get::F64(f) => f(frame, row),
            Get::Bool(f) => f64::from(u8::from(f(frame, row))),
            Get::Count(f) => f(frame, row) as f64,
            Get::Opt(f) => f(frame, row).unwrap_or(f64::NAN),
        }
    }
}

/// The table's rows, one per row, in the columns' order (flags as 1/0).
pub(crate) fn rows<C, R>(columns: &[Column<C, R>], frame: &C, rows: &[R]) -> Vec<Vec<f64>> {
    let row = |r: &R| columns.iter().map(|c| c.number(frame, r)).collect();
    rows.iter().map(row).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Point {
        x: f64,
        on: bool,
        n: usize,
    }

    const NAMES: UnitNames = UnitNames::new(true, ["m", "N", "J", "Hz"]);

    const COLUMNS: [Column<f64, Point>; 4] = columns! {
        "x", Length, true, "position", F64(|scale, p| p.x * scale);
        "on", Fixed(""), false, "flag", Bool(|_, p| p.on);
        "n", Own("1 (SI)", "1"), true, "count", Count(|_, p| p.n);
        "y", Force, false, "force", Opt(|_, p| p.on.then_some(p.x));
    };

    fn points() -> [Point; 2] {
        let p = |x, on, n| Point { x, on, n };
        [p(1.0, true, 3), p(f64::NAN, false, 4)]
    }

    #[test]
    fn one_declaration_gives_every_form_of_the_table() {
        let p = points();
        let doc = Value::Object(arrays(&COLUMNS, &2.0, &p));
        let expected = serde_json::json!({"x": [2.0, null], "on": [true, false], "n": [3, 4],
                                          "y": [1.0, null]});
        assert_eq!(doc, expected);
        let u = Value::Object(units(&COLUMNS, &NAMES));
        assert_eq!(u, serde_json::json!({"x": "m", "n": "1 (SI)"}));
        let model = UnitNames { si: false, ..NAMES };
        assert_eq!(Unit::Own("a", "b").name(&model), "b");
        let vars = variables(&COLUMNS, &2.0, &p, &["i"], &model);
        let described: Vec<_> = vars
            .iter()
            .map(|v| (v.name.as_str(), v.units.as_str()))
            .collect();
        assert_eq!(described, [("x", "m"), ("on", ""), ("n", "1"), ("y", "N")]);
        assert_eq!(vars[1].values, Values::Bool(vec![true, false]));
        assert_eq!(vars[2].values, Values::I32(vec![3, 4]));
        assert!(matches!(&vars[3].values, Values::F64(y) if y[0] == 1.0 && y[1].is_nan()));
        assert_eq!(names(&COLUMNS), ["x", "on", "n", "y"]);
        let table = rows(&COLUMNS, &2.0, &p);
        assert_eq!(table[0], [2.0, 1.0, 3.0, 1.0]);
        assert!(table[1][0].is_nan() && table[1][1..3] == [0.0, 4.0] && table[1][3].is_nan());
        let grid = Value::Object(grids(&COLUMNS[..2], &2.0, &p, (2, 1)));
        assert_eq!(
            grid,
            serde_json::json!({"x": [[2.0], [null]], "on": [[true], [false]]})
        );
    }
}
