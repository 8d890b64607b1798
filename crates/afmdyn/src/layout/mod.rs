//! A result's layout: its dimensions and variables, each with its units and long name (CF
//! conventions), declared once by the library for every writer — the command line's NetCDF
//! file ([`netcdf`], feature `files`), the Python `xarray.Dataset` and the Dask Zarr store.
//!
//! The layouts of the results are declared beside them (a chart's, a basin map's, a sweep's);
//! the ideal-feedback image's is `crate::report::image_layout`.
//!
//! Values are row-major over the variable's dimensions (the last one fastest), as NetCDF,
//! NumPy and xarray store them.

pub(crate) mod columns;
pub mod figure;
#[cfg(feature = "files")]
pub mod files;
#[cfg(feature = "files")]
pub mod netcdf;

use serde::Serialize;

/// The values of a variable, row-major over its dimensions.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// 64-bit floats.
    F64(Vec<f64>),
    /// 32-bit integers (codes, counts, periods).
    I32(Vec<i32>),
    /// Flags (NetCDF: bytes 0/1).
    Bool(Vec<bool>),
    /// Words, one per entry (event names); not written to NetCDF 3 ([`netcdf::write`] refuses
    /// them).
    Text(Vec<String>),
    /// Complex numbers (re, im): Floquet multipliers; not written to NetCDF 3.
    C64(Vec<(f64, f64)>),
}

impl Values {
    /// The number of values.
    pub fn len(&self) -> usize {
        match self {
            Values::F64(v) => v.len(),
            Values::I32(v) => v.len(),
            Values::Bool(v) => v.len(),
            Values::Text(v) => v.len(),
            Values::C64(v) => v.len(),
        }
    }

    /// No values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The kind of the values, as [`Layout::description`] names it: `"float"`, `"int"`,
    /// `"bool"`, `"text"` or `"complex"`.
    pub fn kind(&self) -> &'static str {
        match self {
            Values::F64(_) => "float",
            Values::I32(_) => "int",
            Values::Bool(_) => "bool",
            Values::Text(_) => "text",
            Values::C64(_) => "complex",
        }
    }
}

/// A further attribute of a variable (e.g. CF `flag_values` and `flag_meanings`); serialised
/// as its value (a list of integers or a string).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Attr {
    /// A list of integers.
    I32(Vec<i32>),
    /// A string.
    Text(String),
}

/// One variable: name, dimensions (declared in its [`Layout`]), units, long name, values and
/// further attributes.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// Its name (`x`, `period`, …); a variable named as a dimension is that dimension's
    /// coordinate.
    pub name: String,
    /// Its dimensions, outermost first.
    pub dims: Vec<String>,
    /// Its units (`"1"` dimensionless, `"g0"`, `"m"`, `"Hz"`, …).
    pub units: String,
    /// What it is, in words.
    pub long_name: String,
    /// Its values, row-major over `dims`.
    pub values: Values,
    /// Further attributes.
    pub attrs: Vec<(String, Attr)>,
}

impl Variable {
    /// A variable of `values` over `dims` with no further attributes.
    pub(crate) fn new(
        name: &str,
        dims: &[&str],
        units: &str,
        long_name: impl Into<String>,
        values: Values,
    ) -> Variable {
        Variable {
            name: name.into(),
            dims: dims.iter().map(|d| d.to_string()).collect(),
            units: units.into(),
            long_name: long_name.into(),
            values,
            attrs: Vec::new(),
        }
    }

    /// A float variable.
    pub(crate) fn f64(
        name: &str,
        dims: &[&str],
        units: &str,
        long_name: impl Into<String>,
        values: &[f64],
    ) -> Variable {
        Variable::new(name, dims, units, long_name, Values::F64(values.to_vec()))
    }

    /// An integer variable.
    pub(crate) fn i32(
        name: &str,
        dims: &[&str],
        units: &str,
        long_name: impl Into<String>,
        values: &[i32],
    ) -> Variable {
        Variable::new(name, dims, units, long_name, Values::I32(values.to_vec()))
    }

    /// This variable with the further attribute `key`.
    pub fn with(mut self, key: &str, attr: Attr) -> Variable {
        self.attrs.push((key.into(), attr));
        self
    }
}

/// A result's layout: a title, its dimensions (name, length) and its variables.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// What the result is (the NetCDF global `title`).
    pub title: String,
    /// The dimensions, each with its length.
    pub dims: Vec<(String, usize)>,
    /// The variables.
    pub variables: Vec<Variable>,
}

impl Layout {
    /// A layout of `variables` over `dims`.
    pub(crate) fn new(
        title: impl Into<String>,
        dims: &[(&str, usize)],
        variables: Vec<Variable>,
    ) -> Self {
        Layout {
            title: title.into(),
            dims: dims.iter().map(|(n, l)| (n.to_string(), *l)).collect(),
            variables,
        }
    }

    /// The length of dimension `name`.
    pub fn dim(&self, name: &str) -> Option<usize> {
        self.dims.iter().find(|(n, _)| n == name).map(|&(_, l)| l)
    }

    /// The shape of `v` (its dimensions' lengths).
    ///
    /// # Errors
    /// A message naming a dimension the layout does not declare.
    pub fn shape(&self, v: &Variable) -> Result<Vec<usize>, String> {
        v.dims
            .iter()
            .map(|d| {
                self.dim(d)
                    .ok_or_else(|| format!("{}: dimension {d} is not declared", v.name))
            })
            .collect()
    }

    /// Every variable over declared dimensions, with as many values as its shape holds.
    ///
    /// # Errors
    /// A message naming the first variable that is not.
    pub fn check(&self) -> Result<(), String> {
        for v in &self.variables {
            let n: usize = self.shape(v)?.iter().product();
            if n != v.values.len() {
                return Err(format!(
                    "{}: {} values for a shape of {n}",
                    v.name,
                    v.values.len()
                ));
            }
        }
        Ok(())
    }

    /// The variable `name`.
    pub fn variable(&self, name: &str) -> Option<&Variable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// The layout without its values or lengths: what every writer and front end takes from
    /// it (names, dimensions, units, long names, kinds and attributes), as data
    /// (`docs/schema/layouts/*.json`, the Python docstrings' "Returns").
    pub fn description(&self) -> LayoutDescription {
        LayoutDescription {
            title: self.title.clone(),
            dims: self.dims.iter().map(|(n, _)| n.clone()).collect(),
            variables: self
                .variables
                .iter()
                .map(|v| VariableDescription {
                    name: v.name.clone(),
                    dims: v.dims.clone(),
                    units: v.units.clone(),
                    long_name: v.long_name.clone(),
                    kind: v.values.kind(),
                    attrs: v.attrs.clone(),
                })
                .collect(),
        }
    }
}

/// A [`Layout`] without its values ([`Layout::description`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LayoutDescription {
    /// [`Layout::title`].
    pub title: String,
    /// The names of [`Layout::dims`], in order.
    pub dims: Vec<String>,
    /// Each variable's description, in order.
    pub variables: Vec<VariableDescription>,
}

/// A [`Variable`] without its values.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VariableDescription {
    /// [`Variable::name`].
    pub name: String,
    /// [`Variable::dims`].
    pub dims: Vec<String>,
    /// [`Variable::units`].
    pub units: String,
    /// [`Variable::long_name`].
    pub long_name: String,
    /// [`Values::kind`] of its values.
    pub kind: &'static str,
    /// [`Variable::attrs`], as (key, value) pairs.
    pub attrs: Vec<(String, Attr)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_variable_must_fill_its_shape() {
        let ok = Layout::new(
            "t",
            &[("y", 2), ("x", 3)],
            vec![Variable::f64("a", &["y", "x"], "1", "a", &[0.0; 6])],
        );
        assert_eq!(ok.check(), Ok(()));
        assert_eq!(ok.shape(&ok.variables[0]), Ok(vec![2, 3]));
        let short = Layout::new(
            "t",
            &[("y", 2), ("x", 3)],
            vec![Variable::i32("a", &["y", "x"], "1", "a", &[0; 5])],
        );
        assert_eq!(short.check(), Err("a: 5 values for a shape of 6".into()));
        let undeclared = Layout::new(
            "t",
            &[("y", 2)],
            vec![Variable::i32("a", &["z"], "1", "a", &[0; 2])],
        );
        assert!(undeclared
            .check()
            .unwrap_err()
            .contains("z is not declared"));
    }

    #[test]
    fn a_description_is_the_layout_without_its_values() {
        let flags = Attr::I32(vec![0, 1]);
        let layout = Layout::new(
            "t",
            &[("y", 2), ("x", 3)],
            vec![
                Variable::f64("a", &["y", "x"], "m", "height", &[0.0; 6]),
                Variable::i32("c", &["y", "x"], "1", "code", &[0; 6]).with("flag_values", flags),
                Variable::new("w", &["x"], "", "word", Values::Text(vec!["".into(); 3])),
            ],
        );
        let d = layout.description();
        assert_eq!(
            (d.title.as_str(), d.dims.clone()),
            ("t", vec!["y".into(), "x".into()])
        );
        for (v, e) in layout.variables.iter().zip(&d.variables) {
            assert_eq!((&v.name, &v.dims, &v.units), (&e.name, &e.dims, &e.units));
            assert_eq!((&v.long_name, &v.attrs), (&e.long_name, &e.attrs));
        }
        let kinds: Vec<_> = d.variables.iter().map(|v| v.kind).collect();
        assert_eq!(kinds, ["float", "int", "text"]);
        let json = serde_json::to_value(&d).unwrap();
        assert_eq!(
            json["variables"][1]["attrs"],
            serde_json::json!([["flag_values", [0, 1]]])
        );
        assert!(json["variables"][0].get("values").is_none());
    }
}
