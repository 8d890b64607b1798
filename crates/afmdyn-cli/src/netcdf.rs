//! The one NetCDF 3 writer of the command line (`chart.nc`, `basins.nc`, `STEM-traces.nc`): a
//! file is a list of dimensions and of variables, each with its `units` and `long_name`
//! (CF conventions) and any further attributes, written atomically ([`crate::output::atomic`])
//! with the `title` and `source` global attributes.

use crate::error::CliError;
use crate::output::atomic;
use std::path::Path;

/// The values of a variable, row-major over its dimensions.
pub enum Values<'a> {
    /// 64-bit floats.
    F64(&'a [f64]),
    /// 32-bit integers (codes, counts, periods).
    I32(&'a [i32]),
}

/// A further attribute of a variable (e.g. CF `flag_values` and `flag_meanings`).
pub enum Attr {
    /// A list of integers.
    I32(Vec<i32>),
    /// A string.
    Text(String),
}

/// One variable: name, dimensions (declared in the file), units, long name, values, further
/// attributes.
pub struct Var<'a> {
    pub name: &'a str,
    pub dims: &'a [&'a str],
    pub units: &'a str,
    pub long_name: String,
    pub values: Values<'a>,
    pub attrs: Vec<(&'a str, Attr)>,
}

impl<'a> Var<'a> {
    /// A variable of `values` with no further attributes.
    fn new(
        name: &'a str,
        dims: &'a [&'a str],
        units: &'a str,
        long_name: impl Into<String>,
        values: Values<'a>,
    ) -> Self {
        Var {
            name,
            dims,
            units,
            long_name: long_name.into(),
            values,
            attrs: Vec::new(),
        }
    }

    /// A float variable.
    pub fn f64(
        name: &'a str,
        dims: &'a [&'a str],
        units: &'a str,
        long_name: impl Into<String>,
        values: &'a [f64],
    ) -> Self {
        Var::new(name, dims, units, long_name, Values::F64(values))
    }

    /// An integer variable.
    pub fn i32(
        name: &'a str,
        dims: &'a [&'a str],
        units: &'a str,
        long_name: impl Into<String>,
        values: &'a [i32],
    ) -> Self {
        Var::new(name, dims, units, long_name, Values::I32(values))
    }
}

/// Write `vars` over `dims` (name, length) to `path` (NetCDF 3, 64-bit offsets) with the global
/// `title` and the `source` (afmdyn and its version).
///
/// # Errors
/// [`CliError::Io`] naming the path: an inconsistent definition (a dimension not declared,
/// values of another length) or a failed write.
pub fn write(
    path: &Path,
    title: &str,
    dims: &[(&str, usize)],
    vars: &[Var<'_>],
) -> Result<(), CliError> {
    use netcdf3::{DataSet, FileWriter, Version};
    let e = |m: String| CliError::Io(format!("cannot write {}: {m}", path.display()));
    let d = |r: Result<(), netcdf3::error::InvalidDataSet>| r.map_err(|x| e(format!("{x:?}")));
    let mut ds = DataSet::new();
    for (name, len) in dims {
        d(ds.add_fixed_dim(*name, *len))?;
    }
    for v in vars {
        match v.values {
            Values::F64(_) => d(ds.add_var_f64(v.name, v.dims))?,
            Values::I32(_) => d(ds.add_var_i32(v.name, v.dims))?,
        }
        d(ds.add_var_attr_string(v.name, "units", v.units))?;
        d(ds.add_var_attr_string(v.name, "long_name", v.long_name.as_str()))?;
        for (key, a) in &v.attrs {
            match a {
                Attr::I32(x) => d(ds.add_var_attr_i32(v.name, key, x.clone()))?,
                Attr::Text(s) => d(ds.add_var_attr_string(v.name, key, s.as_str()))?,
            }
        }
    }
    d(ds.add_global_attr_string("title", title))?;
    d(ds.add_global_attr_string("source", format!("afmdyn {}", env!("CARGO_PKG_VERSION"))))?;
    atomic(path, |tmp| {
        // an I/O failure in words ("no space left on device"), not as `IOErrorKind(StorageFull)`
        let w = |x: netcdf3::error::WriteError| match x {
            netcdf3::error::WriteError::IOErrorKind(k) => e(afmdyn::error::io_kind_message(k)),
            x => e(format!("{x:?}")),
        };
        let mut f = FileWriter::open(tmp).map_err(w)?;
        f.set_def(&ds, Version::Offset64Bit, 0).map_err(w)?;
        for v in vars {
            match v.values {
                Values::F64(x) => f.write_var_f64(v.name, x).map_err(w)?,
                Values::I32(x) => f.write_var_i32(v.name, x).map_err(w)?,
            }
        }
        f.close().map_err(w)
    })
}
