//! Files written atomically: every finished file goes to a temporary name in the same
//! directory and is renamed into place, so a partial file is never mistaken for a finished one
//! (a `Stream` dropped unfinished removes its temporary file), and every I/O error names its
//! path ([`FileError`]). The tables: streamed CSV (`csv_stream`, `csv_line` with every
//! number in its shortest round-trip form, `f`) and streamed 2-D float64 NPY arrays
//! ([`NpyStream`], the NPY format of numpy's `format.py`, byte for byte `npyz`'s writer) with
//! their self-describing header files (`X.npy.json`: shape, dtype, each column's unit and
//! meaning, [`Column`]).

use serde::Serialize;
use std::fmt::Display;
use std::fs::{self, File};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// A failed file operation, as one readable line naming the path ("cannot write DIR/x.csv: No
/// space left on device").
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("{0}")]
pub struct FileError(pub String);

/// An I/O failure on `path` ([`FileError`]): "cannot {verb} {path}: {cause}", the cause without
/// the operating system's ` (os error N)`.
pub fn io_error(verb: &str, path: &Path, e: impl Display) -> FileError {
    FileError(format!(
        "cannot {verb} {}: {}",
        path.display(),
        without_errno(&e.to_string())
    ))
}

/// An operating system's message without its ` (os error N)`: `No space left on device`.
pub(crate) fn without_errno(text: &str) -> &str {
    match text.rfind(" (os error ") {
        Some(i) if text.ends_with(')') => &text[..i],
        _ => text,
    }
}

/// Temporary sibling of `path` keeping its extension (plotters picks the format from it):
/// [`crate::io::dir_lock::partial_path`].
pub(crate) fn temp_path(path: &Path) -> PathBuf {
    crate::io::dir_lock::partial_path(path)
}

/// Write `path` atomically with `write` filling a temporary file. On failure the temporary
/// file is removed.
///
/// # Errors
/// What `write` returns; a [`FileError`] (converted) when the file cannot be renamed.
pub(crate) fn atomic<F, E>(path: &Path, write: F) -> Result<(), E>
where
    F: FnOnce(&Path) -> Result<(), E>,
    E: From<FileError>,
{
    let tmp = temp_path(path);
    if let Err(e) = write(&tmp) {
        let _ = fs::remove_file(&tmp);
        return Err(e);
    }
    fs::rename(&tmp, path).map_err(|e| io_error("finish", path, e).into())
}

/// Write bytes atomically.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    atomic(path, |tmp| {
        let w = |e| io_error("write", path, e);
        let mut f = File::create(tmp).map_err(w)?;
        f.write_all(bytes).map_err(w)?;
        f.sync_all().map_err(w)
    })
}

/// A file written progressively (streamed) to its temporary name and renamed into place by
/// [`Stream::finish`]; dropped unfinished, the temporary file is removed.
pub(crate) struct Stream<W> {
    path: PathBuf,
    tmp: PathBuf,
    inner: Option<W>,
    /// Renamed into place (else the temporary file is removed when dropped).
    done: bool,
}

impl<W> Stream<W> {
    /// Open `path`'s temporary file and wrap the buffered file with `make`.
    pub(crate) fn create(
        path: &Path,
        make: impl FnOnce(BufWriter<File>) -> std::io::Result<W>,
    ) -> Result<Self, FileError> {
        let tmp = temp_path(path);
        let file = File::create(&tmp).map_err(|e| io_error("create", path, e))?;
        let inner = make(BufWriter::new(file)).map_err(|e| io_error("write", path, e))?;
        Ok(Stream {
            path: path.to_path_buf(),
            tmp,
            inner: Some(inner),
            done: false,
        })
    }

    /// The writer; errors from it should go through [`Stream::err`].
    pub(crate) fn get(&mut self) -> &mut W {
        self.inner.as_mut().expect("open stream")
    }

    /// A write error on this file.
    pub(crate) fn err(&self, e: impl Display) -> FileError {
        io_error("write", &self.path, e)
    }

    /// Close the writer with `close` and rename the file into place.
    pub(crate) fn finish(
        mut self,
        close: impl FnOnce(W) -> Result<(), String>,
    ) -> Result<(), FileError> {
        let inner = self.inner.take().expect("open stream");
        close(inner).map_err(|e| io_error("write", &self.path, e))?;
        fs::rename(&self.tmp, &self.path).map_err(|e| io_error("finish", &self.path, e))?;
        self.done = true;
        Ok(())
    }
}

impl<W> Drop for Stream<W> {
    fn drop(&mut self) {
        if !self.done {
            self.inner = None;
            let _ = fs::remove_file(&self.tmp);
        }
    }
}

/// A streamed CSV table.
pub(crate) type CsvStream = Stream<csv::Writer<BufWriter<File>>>;

/// Start a streamed CSV table with its header row.
pub(crate) fn csv_stream(path: &Path, header: &[&str]) -> Result<CsvStream, FileError> {
    let mut s = Stream::create(path, |f| Ok(csv::Writer::from_writer(f)))?;
    s.get()
        .write_record(header)
        .map_err(|e| io_error("write", path, e))?;
    Ok(s)
}

/// Append one row to a streamed CSV table.
pub(crate) fn csv_row<I, T>(s: &mut CsvStream, row: I) -> Result<(), FileError>
where
    I: IntoIterator<Item = T>,
    T: AsRef<[u8]>,
{
    let r = s.get().write_record(row);
    r.map_err(|e| s.err(e))
}

/// Finish a streamed CSV table.
pub(crate) fn csv_finish(s: CsvStream) -> Result<(), FileError> {
    s.finish(|mut w| {
        w.flush().map_err(|e| e.to_string())?;
        let f = w.into_inner().map_err(|e| e.error().to_string())?;
        f.into_inner()
            .map_err(|e| e.error().to_string())?
            .sync_all()
            .map_err(|e| e.to_string())
    })
}

/// A CSV table written atomically.
pub fn write_csv(
    path: &Path,
    header: &[&str],
    rows: impl IntoIterator<Item = Vec<String>>,
) -> Result<(), FileError> {
    let mut s = csv_stream(path, header)?;
    for r in rows {
        csv_row(&mut s, &r)?;
    }
    csv_finish(s)
}

/// One column of a numeric table, as documented in its header file.
#[derive(Debug, Clone, Serialize)]
pub struct Column {
    /// Column name (as in the CSV header).
    pub name: String,
    /// Unit.
    pub unit: &'static str,
    /// Meaning.
    pub meaning: String,
}

impl Column {
    /// A column.
    pub(crate) fn new(
        name: impl Into<String>,
        unit: &'static str,
        meaning: impl Into<String>,
    ) -> Self {
        Column {
            name: name.into(),
            unit,
            meaning: meaning.into(),
        }
    }
}

/// The header file `X.npy.json` of `X.npy`: shape, dtype and the meaning and unit of each
/// column, so that the array is self-describing (`docs/outputs.md` has the same tables).
pub(crate) fn write_npy_header(npy: &Path, rows: u64, columns: &[Column]) -> Result<(), FileError> {
    let name = npy
        .file_name()
        .and_then(|s| s.to_str())
        .unwrap_or("data.npy");
    let doc = serde_json::json!({
        "file": name,
        "dtype": "float64 (little-endian)",
        "shape": [rows, columns.len()],
        "columns": columns,
    });
    let text = serde_json::to_string_pretty(&doc).expect("json") + "\n";
    write_bytes(&npy.with_file_name(format!("{name}.json")), text.as_bytes())
}

/// A streamed 2-D float64 NPY array (rows of `cols` values; the row count is written into the
/// header at the end). The file is that of `npyz`'s `begin_2d` writer byte for byte (format
/// version 1.0, the shape's row count in a field of 20 characters padded with spaces, the
/// header padded to 64 bytes: the NPY format, numpy's `format.py`), the values written as
/// little-endian bytes through one buffer instead of one call per value
/// (`npy_stream_is_npyz_byte_for_byte`).
pub struct NpyStream {
    stream: Stream<NpyFile>,
    cols: usize,
    rows: u64,
    columns: Vec<Column>,
    npy: PathBuf,
}

/// The open file of an [`NpyStream`] and its buffer of encoded values.
pub(crate) struct NpyFile {
    file: BufWriter<File>,
    buf: Vec<u8>,
}

/// Bytes gathered before they are written.
const NPY_BUFFER: usize = 1 << 20;

/// The little-endian bytes of `values` (NPY's `<f8`): the values' own bytes on a little-endian
/// machine, no copy.
fn le_bytes(values: &[f64]) -> std::borrow::Cow<'_, [u8]> {
    if cfg!(target_endian = "little") {
        std::borrow::Cow::Borrowed(bytemuck::cast_slice(values))
    } else {
        std::borrow::Cow::Owned(values.iter().flat_map(|v| v.to_le_bytes()).collect())
    }
}
/// The width of the row count's field in the header (npyz's placeholder).
const NPY_ROWS_FIELD: usize = 20;

/// The header of a C-ordered 2-D `<f8` NPY array of `cols` columns whose row count is `rows`
/// (spaces-padded to [`NPY_ROWS_FIELD`]), and the offset of the row count in it.
fn npy_header(rows: &str, cols: usize) -> (Vec<u8>, usize) {
    let mut text = b"{'descr': '<f8', 'fortran_order': False, 'shape': (".to_vec();
    let at = 10 + text.len();
    text.extend(npy_shape(rows, cols));
    // magic (6) + version (2) + length (2) + text + newline: a multiple of 64
    let pad = 63 - (text.len() + 10) % 64;
    text.extend(std::iter::repeat_n(b' ', pad));
    text.push(b'\n');
    let mut out = vec![0x93];
    out.extend(b"NUMPY");
    out.extend([1, 0]);
    out.extend((text.len() as u16).to_le_bytes());
    out.extend(text);
    (out, at)
}

/// "ROWS, COLS), }" padded with spaces for the rows' field.
fn npy_shape(rows: &str, cols: usize) -> Vec<u8> {
    let mut s = format!("{rows}, {cols}), }}").into_bytes();
    s.extend(std::iter::repeat_n(b' ', NPY_ROWS_FIELD - rows.len()));
    s
}

impl NpyStream {
    /// Start `path` with the given columns (its header file is written by [`NpyStream::finish`]).
    pub fn create(path: &Path, columns: Vec<Column>) -> Result<Self, FileError> {
        let cols = columns.len();
        let stream = Stream::create(path, |mut file| {
            let (header, _) = npy_header(&"*".repeat(NPY_ROWS_FIELD), cols);
            file.write_all(&header)?;
            Ok(NpyFile {
                file,
                buf: Vec::with_capacity(NPY_BUFFER + 4096),
            })
        })?;
        Ok(NpyStream {
            stream,
            cols,
            rows: 0,
            columns,
            npy: path.to_path_buf(),
        })
    }

    /// Append one row.
    pub fn push(&mut self, row: &[f64]) -> Result<(), FileError> {
        if row.len() != self.cols {
            return Err(self.stream.err(format!(
                "row of {} values, expected {}",
                row.len(),
                self.cols
            )));
        }
        self.push_rows(row)
    }

    /// Append whole rows, one after the other in `values` (a multiple of the columns).
    pub(crate) fn push_rows(&mut self, values: &[f64]) -> Result<(), FileError> {
        if !values.len().is_multiple_of(self.cols.max(1)) {
            return Err(self.stream.err(format!(
                "{} values are not whole rows of {}",
                values.len(),
                self.cols
            )));
        }
        let bytes = le_bytes(values);
        let f = self.stream.get();
        // gathered while small, else written with what is gathered (a chunk of rows: straight
        // from the caller's buffer)
        if f.buf.len() + bytes.len() < NPY_BUFFER {
            f.buf.extend_from_slice(&bytes);
        } else {
            let r = f
                .file
                .write_all(&f.buf)
                .and_then(|()| f.file.write_all(&bytes));
            f.buf.clear();
            r.map_err(|e| self.stream.err(e))?;
        }
        self.rows += (values.len() / self.cols.max(1)) as u64;
        Ok(())
    }

    /// Finish the array and write its header file.
    pub fn finish(self) -> Result<(), FileError> {
        use std::io::{Seek, SeekFrom};
        let (rows, columns, npy, cols) = (self.rows, self.columns, self.npy, self.cols);
        self.stream.finish(|mut f| {
            let e = |e: std::io::Error| e.to_string();
            f.file.write_all(&f.buf).map_err(e)?;
            let (_, at) = npy_header("", cols);
            let end = f.file.stream_position().map_err(e)?;
            f.file.seek(SeekFrom::Start(at as u64)).map_err(e)?;
            f.file
                .write_all(&npy_shape(&rows.to_string(), cols))
                .map_err(e)?;
            f.file.seek(SeekFrom::Start(end)).map_err(e)?;
            f.file.flush().map_err(e)
        })?;
        write_npy_header(&npy, rows, &columns)
    }
}

/// Format a float for CSV: a shortest round-trip representation, in exponent form when
/// |v| < 1e-4 or ≥ 1e16 — the notation of `std_format` (SI values such as
/// 1.37e-19 J would otherwise print as 24 zeros and their digits), with the digits from `ryu`
/// (several times faster than the standard library's; a spectrum writes a million of them;
/// where two shortest forms exist it may pick the other). Where `ryu` chooses the other
/// notation (|v| near 1e-5), the standard formatting is used.
pub(crate) fn f(v: f64) -> String {
    let mut out = Vec::with_capacity(24);
    f_into(&mut out, v);
    String::from_utf8(out).expect("ASCII")
}

/// `v` with every digit it needs to read back: plain between 1e-4 and 1e16, else in scientific
/// notation (the library's `afmdyn::error::number` rounds for messages; data keep every digit).
fn std_format(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e16).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// [`f`] appended to `out` (no allocation but where the standard formatting is used).
pub(crate) fn f_into(out: &mut Vec<u8>, v: f64) {
    let a = v.abs();
    if !v.is_finite() || a == 0.0 {
        out.extend(std_format(v).as_bytes());
        return;
    }
    let mut buf = ryu::Buffer::new();
    let s = buf.format_finite(v);
    let sci = s.contains('e');
    if sci == (1e-4..1e16).contains(&a) {
        out.extend(std_format(v).as_bytes());
        return;
    }
    out.extend(s.strip_suffix(".0").unwrap_or(s).as_bytes());
}

/// A row of numbers (and words without commas, quotes or line breaks, which CSV writes as
/// they are) appended to `out` as [`csv_row`] writes it: fields joined by commas, ended by a
/// newline.
pub(crate) fn csv_line<'a>(out: &mut Vec<u8>, fields: impl IntoIterator<Item = Field<'a>>) {
    for (i, field) in fields.into_iter().enumerate() {
        if i > 0 {
            out.push(b',');
        }
        match field {
            Field::Num(v) => f_into(out, v),
            Field::Word(w) => {
                debug_assert!(!w.bytes().any(|b| matches!(b, b',' | b'"' | b'\n' | b'\r')));
                out.extend(w.as_bytes());
            }
        }
    }
    out.push(b'\n');
}

/// A field of [`csv_line`].
#[derive(Debug, Clone, Copy)]
pub(crate) enum Field<'a> {
    /// A number, formatted by [`f`].
    Num(f64),
    /// A word written as it is.
    Word(&'a str),
}

/// Append the lines in `bytes` (whole rows, from `csv_line`) to a streamed CSV table.
pub(crate) fn csv_lines(s: &mut CsvStream, bytes: &[u8]) -> Result<(), FileError> {
    // the csv writer's own buffer is written out first, so that the rows stay in order
    if bytes.is_empty() {
        return Ok(());
    }
    let w = s.inner.take().expect("open stream");
    let mut file = w.into_inner().map_err(|e| s.err(e.error()))?;
    file.write_all(bytes).map_err(|e| s.err(e))?;
    s.inner = Some(csv::Writer::from_writer(file));
    Ok(())
}

/// A file error as the library's error ([`crate::error::SimError::File`]), naming its path.
impl From<FileError> for crate::error::SimError {
    fn from(e: FileError) -> Self {
        crate::error::SimError::File(e.0)
    }
}

#[cfg(test)]
mod tests {
    use super::{f, std_format};

    /// A row of `csv_line` is the row the csv crate writes for the same fields (`csv_row`).
    #[test]
    fn csv_lines_are_the_csv_crates_rows() {
        use super::{csv_line, f, Field};
        let values = [
            0.0,
            -0.0,
            1.0,
            -2.5,
            1e-5,
            3.25e-19,
            1e16,
            123456.789,
            f64::NAN,
            1.0 / 3.0,
        ];
        let mut ours = Vec::new();
        let mut theirs = csv::Writer::from_writer(Vec::new());
        for v in values {
            csv_line(
                &mut ours,
                [Field::Num(v), Field::Word("contact"), Field::Num(-v)],
            );
            theirs
                .write_record([f(v), "contact".to_string(), f(-v)])
                .unwrap();
        }
        assert_eq!(ours, theirs.into_inner().unwrap());
    }

    /// The streamed array is the file `npyz`'s own 2-D writer makes, byte for byte (an
    /// independent writer of the format), for a few shapes, rows pushed one by one and in
    /// blocks.
    #[test]
    fn npy_stream_is_npyz_byte_for_byte() {
        use super::{Column, NpyStream};
        use npyz::WriterBuilder;
        let dir = std::env::temp_dir().join(format!("afmdyn-npy-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (rows, cols) in [(0usize, 3usize), (1, 1), (7, 12), (1000, 5), (3, 40)] {
            let values: Vec<f64> = (0..rows * cols)
                .map(|i| (i as f64 * 0.37).sin() * 10f64.powi(i as i32 % 7 - 3))
                .collect();
            let mut expected = std::io::Cursor::new(Vec::new());
            {
                let mut w = npyz::WriteOptions::new()
                    .default_dtype()
                    .writer(&mut expected)
                    .begin_2d(cols as u64)
                    .unwrap();
                for v in &values {
                    w.push(v).unwrap();
                }
                w.finish().unwrap();
            }
            let columns: Vec<Column> = (0..cols)
                .map(|c| Column::new(format!("c{c}"), "1", "test"))
                .collect();
            let path = dir.join(format!("a{rows}x{cols}.npy"));
            let mut s = NpyStream::create(&path, columns).unwrap();
            let (one, block) = values.split_at((rows / 2) * cols);
            for r in one.chunks(cols) {
                s.push(r).unwrap();
            }
            s.push_rows(block).unwrap();
            s.finish().unwrap();
            assert_eq!(
                std::fs::read(&path).unwrap(),
                expected.into_inner(),
                "{rows} x {cols}"
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn csv_numbers_round_trip_and_small_ones_use_exponents() {
        for v in [
            0.0,
            1.0,
            -2.5,
            0.1,
            1e-4,
            3.3e-6,
            1.3749999999999996e-20,
            6.02e23,
            -7.5e-13,
            12345.678,
        ] {
            assert_eq!(f(v).parse::<f64>().unwrap().to_bits(), v.to_bits(), "{v}");
        }
        assert_eq!(f(1.375e-20), "1.375e-20");
        assert_eq!(f(0.25), "0.25");
        assert_eq!(f(0.0), "0");
        assert_eq!(f(3.0), "3");
        assert_eq!(f(f64::NAN), "NaN");
    }

    /// The fast path reads back to the same double and uses the notation of
    /// std_format (the standard library's formatting), with as many digits, over
    /// magnitudes from 1e-300 to 1e300 and the notation boundaries.
    #[test]
    fn csv_numbers_equal_the_standard_formatting() {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut values = vec![
            1e-4,
            9.999999999999999e-5,
            1e16,
            9.999999999999998e15,
            1e-5,
            5e-5,
        ];
        for _ in 0..200_000 {
            // xorshift: random bit patterns of finite doubles
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            if v.is_finite() {
                values.push(v);
            }
            let e = (x % 40) as i32 - 20;
            values.push((x >> 11) as f64 / (1u64 << 53) as f64 * 10f64.powi(e));
        }
        for v in values {
            let (fast, std) = (f(v), std_format(v));
            assert_eq!(fast.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{v:e}");
            assert_eq!(
                fast.contains('e'),
                std.contains('e'),
                "{v:e}: {fast} vs {std}"
            );
            assert_eq!(fast.len(), std.len(), "{v:e}: {fast} vs {std}");
        }
    }
}
