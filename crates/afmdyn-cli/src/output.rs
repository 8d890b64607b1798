//! Output files: every finished file is written to a temporary name in the same directory and
//! renamed into place, so a partial file is never mistaken for a finished one.

use crate::error::CliError;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Create the output directory.
pub fn ensure_dir(dir: &Path) -> Result<(), CliError> {
    fs::create_dir_all(dir)
        .map_err(|e| CliError::Io(format!("cannot create {}: {e}", dir.display())))
}

/// Temporary sibling of `path` keeping its extension (plotters picks the format from it).
pub fn temp_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("out");
    let name = match path.extension().and_then(|s| s.to_str()) {
        Some(ext) => format!(".{stem}.partial.{ext}"),
        None => format!(".{stem}.partial"),
    };
    path.with_file_name(name)
}

/// Write `path` atomically with `write` filling a temporary file.
pub fn atomic<F>(path: &Path, write: F) -> Result<(), CliError>
where
    F: FnOnce(&Path) -> Result<(), CliError>,
{
    let tmp = temp_path(path);
    write(&tmp)?;
    fs::rename(&tmp, path)
        .map_err(|e| CliError::Io(format!("cannot finish {}: {e}", path.display())))
}

/// Write bytes atomically.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    atomic(path, |tmp| {
        let mut f = fs::File::create(tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        Ok(())
    })
}

/// A CSV table written atomically.
pub fn write_csv(
    path: &Path,
    header: &[&str],
    rows: impl IntoIterator<Item = Vec<String>>,
) -> Result<(), CliError> {
    atomic(path, |tmp| {
        let mut w = csv::Writer::from_path(tmp)?;
        w.write_record(header)?;
        for r in rows {
            w.write_record(&r)?;
        }
        w.flush()?;
        Ok(())
    })
}

/// A 2-D float array (rows × cols) as NPY, written atomically and streamed row by row.
pub fn write_npy(
    path: &Path,
    cols: usize,
    rows: impl IntoIterator<Item = Vec<f64>>,
    nrows: usize,
) -> Result<(), CliError> {
    use npyz::WriterBuilder;
    atomic(path, |tmp| {
        let file = std::io::BufWriter::new(fs::File::create(tmp)?);
        let mut w = npyz::WriteOptions::new()
            .default_dtype()
            .shape(&[nrows as u64, cols as u64])
            .writer(file)
            .begin_nd()?;
        let mut count = 0;
        for r in rows {
            if r.len() != cols {
                return Err(CliError::Io(format!(
                    "npy row of {} values, expected {cols}",
                    r.len()
                )));
            }
            for v in r {
                w.push(&v)?;
            }
            count += 1;
        }
        if count != nrows {
            return Err(CliError::Io(format!(
                "npy: {count} rows written, {nrows} announced"
            )));
        }
        w.finish()?;
        Ok(())
    })
}

/// Format a float for CSV (shortest round-trip representation).
pub fn f(v: f64) -> String {
    format!("{v}")
}
