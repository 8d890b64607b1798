//! Height maps read from files (feature `files`): a sample map's `height_map = "h.csv"` or
//! `"h.npy"` ([`crate::request::image::SampleMap`]), with the limits and refusals of the inline array.
//!
//! - **CSV** (`.csv`): rows of comma-separated heights in m, no header, rows from y = 0 to
//!   Ly and columns from x = 0 to Lx (the `csv` crate; spaces around a value are ignored, blank
//!   lines skipped). A file larger than [`MAX_CSV_BYTES`], or with a line longer than
//!   `super::input::MAX_CSV_LINE_BYTES` (`/dev/zero`), is refused, and no more is read.
//! - **NPY** (`.npy`, NumPy's `np.save`): a 2-D float64 array (`<f8` or `>f8`, C or Fortran
//!   order), `[row][column]` as the CSV (the `npyz` crate). The file is at most
//!   [`MAX_NPY_BYTES`], its header at most [`MAX_NPY_HEADER_BYTES`], and the dtype and shape
//!   are checked before the values are read.
//!
//! Both: at most [`MAX_PIXELS`] × [`MAX_PIXELS`] values, rows of one length, each finite and
//! within ±`MAX_HEIGHT` (10 µm). Errors are [`SimError::Probe`] naming `height_map`, the
//! file and the problem (the row and column of a bad value).

#[cfg(feature = "files")]
use super::input::{Bounded, InputFileError, InputKind};
#[cfg(feature = "files")]
use crate::error::SimError;
#[cfg(feature = "files")]
use std::io::Read;
#[cfg(feature = "files")]
use std::path::{Path, PathBuf};

pub use super::caps::{MAX_CSV_BYTES, MAX_NPY_BYTES, MAX_NPY_HEADER_BYTES, MAX_PIXELS};

/// Largest true height of a domain or a height map's value, either sign (m): 10 µm, a
/// topography the z piezo follows.
pub const MAX_HEIGHT: f64 = 1e-5;

/// The heights of the file `file` (the value of `height_map`), a relative path taken from
/// `base` (the sample file's directory; `None`: the current directory), `[row][column]`.
///
/// # Errors
/// [`SimError::Probe`] naming `height_map` and the file: an extension other than `.csv` or
/// `.npy`; a file that cannot be read, is too large or is not CSV/NPY; more than 4096 rows or
/// columns, no values, rows of different lengths; a value that is not a number, not finite or
/// beyond ±10 µm (with its row and column); an NPY array that is not 2-D float64.
#[cfg(feature = "files")]
pub fn read(file: &str, base: Option<&Path>) -> Result<Vec<Vec<f64>>, SimError> {
    let path = base.map_or_else(|| PathBuf::from(file), |b| b.join(file));
    let err = |problem: String| {
        SimError::Probe(format!(
            "height_map = \"{file}\" ({}): {problem}",
            path.display()
        ))
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let open = || std::fs::File::open(&path).map_err(|e| err(crate::error::io_message(&e)));
    // a regular file larger than the format's limit is refused before any of it is read
    let sized = |limit: u64, what: &str| -> Result<std::fs::File, SimError> {
        let file = open()?;
        match file.metadata() {
            Ok(m) if m.is_file() && m.len() > limit => Err(err(format!(
                "{} bytes: larger than {limit} bytes, the limit of {what} height map (4096 × \
                 4096 heights)",
                m.len()
            ))),
            _ => Ok(file),
        }
    };
    let rows = match ext.as_deref() {
        Some("csv") => csv_rows(Bounded::new(
            sized(MAX_CSV_BYTES, "a CSV")?,
            &path,
            InputKind::HeightMapCsv,
        ))
        .map_err(err)?,
        Some("npy") => npy_rows(Bounded::new(
            sized(MAX_NPY_BYTES, "an NPY")?,
            &path,
            InputKind::HeightMapNpy,
        ))
        .map_err(err)?,
        _ => {
            return Err(err(
                "must be a .csv file (rows of heights in m) or a .npy file (a 2-D float64 \
                 array), or the rows inline [[h, …], …]"
                    .into(),
            ))
        }
    };
    if rows.is_empty() {
        return Err(err("holds no heights".into()));
    }
    Ok(rows)
}

/// A height at (row, column), both from 1: finite and within ±10 µm.
#[cfg(feature = "files")]
fn check(h: f64, row: usize, col: usize) -> Result<f64, String> {
    if !h.is_finite() {
        return Err(format!(
            "row {row}, column {col}: {h} is not a finite height (m)"
        ));
    }
    if h.abs() > MAX_HEIGHT {
        return Err(format!(
            "row {row}, column {col}: {h:e} m: heights must be within ±10 µm"
        ));
    }
    Ok(h)
}

/// The rows of a CSV height map, streamed: at most [`MAX_CSV_BYTES`], 4096 rows of 4096
/// values, each row as long as the first.
#[cfg(feature = "files")]
fn csv_rows(file: Bounded) -> Result<Vec<Vec<f64>>, String> {
    let too_large = || format!("larger than {MAX_CSV_BYTES} bytes (4096 × 4096 heights)");
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(file);
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut record = csv::StringRecord::new();
    loop {
        match reader.read_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => {
                return Err(match e.kind() {
                    csv::ErrorKind::Io(io) => match super::input::refusal(io) {
                        Some(InputFileError::LineTooLong { limit, .. }) => format!(
                            "a line longer than {limit} bytes: not a CSV height map (a row of \
                             4096 heights is far shorter)"
                        ),
                        Some(_) => too_large(),
                        None => format!("cannot be read: {e}"),
                    },
                    csv::ErrorKind::Utf8 { .. } => format!("not UTF-8 text: {e}"),
                    _ => format!("cannot be read: {e}"),
                })
            }
        }
        if reader.position().byte() > MAX_CSV_BYTES {
            return Err(too_large());
        }
        let row = rows.len() + 1;
        if row > MAX_PIXELS {
            return Err(format!("more than {MAX_PIXELS} rows"));
        }
        if record.len() > MAX_PIXELS {
            return Err(format!(
                "row {row} has {} values: at most {MAX_PIXELS} per row",
                record.len()
            ));
        }
        if let Some(first) = rows.first() {
            if record.len() != first.len() {
                return Err(format!(
                    "row {row} has {} values, row 1 has {}: every row must be as long",
                    record.len(),
                    first.len()
                ));
            }
        }
        let mut hs = Vec::with_capacity(record.len());
        for (c, cell) in record.iter().enumerate() {
            let h: f64 = cell.parse().map_err(|_| {
                format!(
                    "row {row}, column {}: '{cell}' is not a number (a height in m)",
                    c + 1
                )
            })?;
            hs.push(check(h, row, c + 1)?);
        }
        rows.push(hs);
    }
    if reader.position().byte() > MAX_CSV_BYTES {
        return Err(too_large());
    }
    Ok(rows)
}

/// The rows of an NPY height map: the header's length, then its dtype and shape, checked
/// before the values are read.
#[cfg(feature = "files")]
fn npy_rows(file: Bounded) -> Result<Vec<Vec<f64>>, String> {
    let not_npy = || "not an NPY file (NumPy's np.save)".to_string();
    let io = |e: std::io::Error| format!("not a readable NPY file: {e}");
    // the magic, the version and the header's length: npyz allocates the header as its length
    // says, so it is checked first
    let mut file = file;
    let mut pre = [0u8; 12];
    let mut got = 0;
    while got < pre.len() {
        match file.read(&mut pre[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(io(e)),
        }
    }
    if got < 10 || &pre[..6] != b"\x93NUMPY" {
        return Err(not_npy());
    }
    let header_len = match pre[6] {
        1 => usize::from(u16::from_le_bytes([pre[8], pre[9]])),
        2 | 3 if got == 12 => u32::from_le_bytes([pre[8], pre[9], pre[10], pre[11]]) as usize,
        _ => return Err(not_npy()),
    };
    if header_len > MAX_NPY_HEADER_BYTES {
        return Err(format!(
            "an NPY header of {header_len} bytes: at most {MAX_NPY_HEADER_BYTES}"
        ));
    }
    let reader = std::io::Cursor::new(pre[..got].to_vec()).chain(file.take(MAX_NPY_BYTES));
    let npy = npyz::NpyFile::new(std::io::BufReader::new(reader)).map_err(io)?;
    let shape = npy.shape().to_vec();
    let [rows, cols] = shape[..] else {
        return Err(format!(
            "a {}-D array of shape {shape:?}: must be 2-D (rows from y = 0, columns from x = 0)",
            shape.len()
        ));
    };
    if !(1..=MAX_PIXELS as u64).contains(&rows) || !(1..=MAX_PIXELS as u64).contains(&cols) {
        return Err(format!(
            "an array of shape ({rows}, {cols}): at most {MAX_PIXELS} × {MAX_PIXELS} heights, \
             at least one"
        ));
    }
    let float64 = matches!(
        npy.dtype(),
        npyz::DType::Plain(t) if t.type_char() == npyz::TypeChar::Float && t.size_field() == 8
    );
    if !float64 {
        return Err(format!(
            "dtype {}: must be float64 (a.astype(np.float64))",
            npy.dtype().descr()
        ));
    }
    let fortran = npy.order() == npyz::Order::Fortran;
    let (rows, cols) = (rows as usize, cols as usize);
    let values: Vec<f64> = npy.into_vec().map_err(|e| {
        format!("its {rows} × {cols} float64 values cannot be read (a truncated file?): {e}")
    })?;
    if values.len() != rows * cols {
        return Err(format!(
            "{} values for the shape ({rows}, {cols})",
            values.len()
        ));
    }
    (0..rows)
        .map(|j| {
            (0..cols)
                .map(|i| {
                    let k = if fortran { i * rows + j } else { j * cols + i };
                    check(values[k], j + 1, i + 1)
                })
                .collect()
        })
        .collect()
}
