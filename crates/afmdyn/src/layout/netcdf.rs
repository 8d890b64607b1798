//! The one NetCDF writer (feature `files`): a [`Layout`] written as a NetCDF 3 file (64-bit
//! offsets; what xarray, netCDF4 and ncdump read), each variable with its `units` and
//! `long_name` (CF conventions) and further attributes, the global `title` and `source`
//! (afmdyn and its version), through a temporary file renamed into place.
//!
//! NetCDF 3 has no zero-length fixed dimension (only its one unlimited dimension may be empty,
//! and only as a variable's first): a dimension of length 0 (a continuation that found no
//! attractor) is left out with the variables over it, which hold no value, and the global
//! attribute `empty_dimensions` names it.

use super::{Attr, Layout, Values};
use std::path::Path;
use thiserror::Error;

/// A NetCDF file that could not be written.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("cannot write {path}: {message}")]
pub struct WriteError {
    /// The file.
    pub path: String,
    /// What went wrong (an inconsistent layout, or the system's message).
    pub message: String,
}

/// Write `layout` to `path`.
///
/// # Errors
/// [`WriteError`] naming the path: an inconsistent layout (a dimension not declared, values of
/// another length) or a failed write (the temporary file is removed).
pub fn write(path: &Path, layout: &Layout) -> Result<(), WriteError> {
    use netcdf3::{DataSet, FileWriter, Version};
    let e = |m: String| WriteError {
        path: path.display().to_string(),
        message: m,
    };
    layout.check().map_err(e)?;
    let d = |r: Result<(), netcdf3::error::InvalidDataSet>| r.map_err(|x| e(format!("{x:?}")));
    let mut ds = DataSet::new();
    let empty: Vec<&str> = layout
        .dims
        .iter()
        .filter(|(_, len)| *len == 0)
        .map(|(n, _)| n.as_str())
        .collect();
    let written: Vec<_> = layout
        .variables
        .iter()
        .filter(|v| !v.dims.iter().any(|d| empty.contains(&d.as_str())))
        .collect();
    for (name, len) in layout.dims.iter().filter(|(_, len)| *len > 0) {
        d(ds.add_fixed_dim(name, *len))?;
    }
    for v in &written {
        let dims: Vec<&str> = v.dims.iter().map(String::as_str).collect();
        match v.values {
            Values::F64(_) => d(ds.add_var_f64(&v.name, &dims))?,
            Values::I32(_) => d(ds.add_var_i32(&v.name, &dims))?,
            Values::Bool(_) => d(ds.add_var_i8(&v.name, &dims))?,
            Values::Text(_) | Values::C64(_) => {
                return Err(e(format!(
                    "variable {}: words and complex numbers are not written to NetCDF 3",
                    v.name
                )))
            }
        }
        d(ds.add_var_attr_string(&v.name, "units", v.units.as_str()))?;
        d(ds.add_var_attr_string(&v.name, "long_name", v.long_name.as_str()))?;
        for (key, a) in &v.attrs {
            match a {
                Attr::I32(x) => d(ds.add_var_attr_i32(&v.name, key, x.clone()))?,
                Attr::Text(s) => d(ds.add_var_attr_string(&v.name, key, s.as_str()))?,
            }
        }
    }
    d(ds.add_global_attr_string("title", layout.title.as_str()))?;
    d(ds.add_global_attr_string("source", format!("afmdyn {}", env!("CARGO_PKG_VERSION"))))?;
    if !empty.is_empty() {
        d(ds.add_global_attr_string("empty_dimensions", empty.join(" ")))?;
    }
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".partial");
    let tmp = std::path::PathBuf::from(tmp);
    // an I/O failure in words ("no space left on device"), not as `IOErrorKind(StorageFull)`
    let w = |x: netcdf3::error::WriteError| match x {
        netcdf3::error::WriteError::IOErrorKind(k) => e(crate::error::io_kind_message(k)),
        x => e(format!("{x:?}")),
    };
    let written = (|| {
        let mut f = FileWriter::open(&tmp).map_err(w)?;
        f.set_def(&ds, Version::Offset64Bit, 0).map_err(w)?;
        for v in &written {
            match &v.values {
                Values::F64(x) => f.write_var_f64(&v.name, x).map_err(w)?,
                Values::I32(x) => f.write_var_i32(&v.name, x).map_err(w)?,
                Values::Bool(x) => {
                    let bytes: Vec<i8> = x.iter().map(|&b| i8::from(b)).collect();
                    f.write_var_i8(&v.name, &bytes).map_err(w)?
                }
                // refused when the variables were defined
                Values::Text(_) | Values::C64(_) => {}
            }
        }
        f.close().map_err(w)
    })();
    if let Err(err) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(err);
    }
    std::fs::rename(&tmp, path).map_err(|x| e(x.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::Variable;

    /// The file read back by the `netcdf3` reader holds the layout's values and attributes.
    #[test]
    fn a_layout_reads_back() {
        let dir = std::env::temp_dir().join(format!("afmdyn-nc-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.nc");
        let layout = Layout::new(
            "a test",
            &[("y", 2), ("x", 3)],
            vec![
                Variable::f64("x", &["x"], "m", "x", &[1.0, 2.0, 3.0]),
                Variable::i32("code", &["y", "x"], "1", "a code", &[1, 2, 3, 4, 5, 6])
                    .with("flag_values", Attr::I32(vec![1, 2])),
            ],
        );
        write(&path, &layout).unwrap();
        let mut r = netcdf3::FileReader::open(&path).unwrap();
        let ds = r.data_set();
        assert_eq!(
            ds.get_global_attr_as_string("title").as_deref(),
            Some("a test")
        );
        assert_eq!(
            ds.get_var_attr_as_string("code", "long_name").as_deref(),
            Some("a code")
        );
        assert_eq!(r.read_var_i32("code").unwrap(), vec![1, 2, 3, 4, 5, 6]);
        assert_eq!(r.read_var_f64("x").unwrap(), vec![1.0, 2.0, 3.0]);
        // an inconsistent layout is refused naming the file
        let bad = Layout::new(
            "t",
            &[("x", 2)],
            vec![Variable::f64("x", &["x"], "m", "x", &[1.0])],
        );
        let err = write(&path, &bad).unwrap_err();
        assert!(err.to_string().contains("t.nc") && err.message.contains("1 values"));
        // a zero-length dimension: its variables are left out and named in the attributes
        let empty = Layout::new(
            "e",
            &[("value", 2), ("id", 0)],
            vec![
                Variable::f64("value", &["value"], "1", "v", &[1.0, 2.0]),
                Variable::f64("fraction", &["value", "id"], "1", "f", &[]),
            ],
        );
        write(&path, &empty).unwrap();
        let mut r = netcdf3::FileReader::open(&path).unwrap();
        assert_eq!(
            r.data_set()
                .get_global_attr_as_string("empty_dimensions")
                .as_deref(),
            Some("id")
        );
        assert!(r.data_set().get_var("fraction").is_none());
        assert_eq!(r.read_var_f64("value").unwrap(), vec![1.0, 2.0]);
        // flags are bytes 0/1; words are refused naming the variable
        let flags = Variable::new(
            "stable",
            &["value"],
            "1",
            "s",
            Values::Bool(vec![true, false]),
        );
        write(
            &path,
            &Layout::new("b", &[("value", 2)], vec![flags.clone()]),
        )
        .unwrap();
        let mut r = netcdf3::FileReader::open(&path).unwrap();
        assert_eq!(r.read_var_i8("stable").unwrap(), vec![1, 0]);
        let words = Values::Text(vec!["fold".into(), String::new()]);
        let words = Variable::new("event", &["value"], "1", "e", words);
        let err = write(
            &path,
            &Layout::new("w", &[("value", 2)], vec![flags, words]),
        );
        assert!(err.unwrap_err().message.contains("variable event"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
