//! A result's layout ([`afmdyn::layout::Layout`], the library's declaration of its variables
//! for NetCDF and Python) as JSON: `{name: {"dims", "shape", "units", "long_name", "values"}}`,
//! each variable's values row-major over its dimensions (flat), NaN and ±∞ as `null`, further
//! attributes (a sign convention, CF flags) under `"attrs"` when it has any. Serialised
//! straight to text, without a [`serde_json::Value`] per number.

use afmdyn::layout::{Attr, Layout, Values, Variable};
use serde::ser::{Serialize, SerializeMap, Serializer};

/// The variables of a layout as a JSON object, by name (module docs).
pub struct LayoutJson<'a>(pub &'a Layout);

/// One variable with its shape.
struct VariableJson<'a> {
    v: &'a Variable,
    shape: Vec<usize>,
}

/// A variable's values.
struct ValuesJson<'a>(&'a Values);

/// A variable's further attributes.
struct AttrsJson<'a>(&'a [(String, Attr)]);

impl Serialize for LayoutJson<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(self.0.variables.len()))?;
        for v in &self.0.variables {
            // a variable over an undeclared dimension (none in the library's layouts) has no
            // shape to give: its values' count
            let shape = self.0.shape(v).unwrap_or_else(|_| vec![v.values.len()]);
            m.serialize_entry(&v.name, &VariableJson { v, shape })?;
        }
        m.end()
    }
}

impl Serialize for VariableJson<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let v = self.v;
        let mut m = s.serialize_map(None)?;
        m.serialize_entry("dims", &v.dims)?;
        m.serialize_entry("shape", &self.shape)?;
        m.serialize_entry("units", &v.units)?;
        m.serialize_entry("long_name", &v.long_name)?;
        m.serialize_entry("values", &ValuesJson(&v.values))?;
        if !v.attrs.is_empty() {
            m.serialize_entry("attrs", &AttrsJson(&v.attrs))?;
        }
        m.end()
    }
}

impl Serialize for ValuesJson<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        // serde_json writes a non-finite float as null
        match self.0 {
            Values::F64(v) => v.serialize(s),
            Values::I32(v) => v.serialize(s),
            Values::Bool(v) => v.serialize(s),
            Values::Text(v) => v.serialize(s),
            Values::C64(v) => v.serialize(s),
        }
    }
}

impl Serialize for AttrsJson<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for (k, a) in self.0 {
            match a {
                Attr::I32(v) => m.serialize_entry(k, v)?,
                Attr::Text(t) => m.serialize_entry(k, t)?,
            }
        }
        m.end()
    }
}
