//! The curve files `reconstruct` inverts (feature `files`), read through the bounded reader
//! ([`super::open`]): a JSON document (`afmdyn fm`'s `fm.json`, `afmdyn approach`'s
//! document; [`InputKind::CurveDocument`]) or a CSV whose header names its columns
//! ([`InputKind::CurveCsv`]). Every refusal names the file ([`InputFileError`]).

use super::{open, refusal, InputFileError, InputKind};
use serde_json::Value;
use std::io::BufRead;
use std::path::Path;

/// A curve file's content: a JSON document, or a CSV's columns by name.
#[derive(Debug, Clone)]
pub enum CurveFile {
    /// A JSON document (its first character that is not whitespace is `{`).
    Document(Value),
    /// A CSV's columns: the header's names (trimmed) and each column's numbers.
    Columns(Vec<String>, Vec<Vec<f64>>),
}

/// The content of `path`: a JSON document when it starts with `{` (after whitespace), else
/// the CSV's columns.
///
/// # Errors
/// [`InputFileError`] naming the file: refused by the bounded reader, unreadable, not JSON,
/// or a field that is not a number.
pub fn read_curve_file(path: &Path) -> Result<CurveFile, InputFileError> {
    let (mut reader, first) = open_document(path)?;
    let head = reader.fill_buf().map_err(|e| io_failure(path, &e))?;
    if is_binary(head) {
        return Err(invalid(
            path,
            "not a text curve (CSV or JSON) but a binary file, as an instrument's (JPK's \
             .jpk-force is a zip archive): the command line reads CSV or JSON curves; Python \
             reads an instrument's force curves through afmformats (afmdyn.fit(data=PATH))",
        ));
    }
    if first == Some(b'{') {
        return parse_document(path, reader).map(CurveFile::Document);
    }
    drop(reader);
    let (names, columns) = read_columns(path)?;
    Ok(CurveFile::Columns(names, columns))
}

/// Whether the first bytes `head` of a file are binary: a zip archive's signature or bytes that
/// are no UTF-8 (a character cut at the buffer's end aside). A stream of NUL bytes is text to
/// this test: the bounded reader refuses it at its line cap, naming the cap.
fn is_binary(head: &[u8]) -> bool {
    head.starts_with(b"PK\x03\x04")
        || std::str::from_utf8(head).is_err_and(|e| e.error_len().is_some())
}

/// The JSON document in `path`.
///
/// # Errors
/// [`InputFileError`] naming the file: refused by the bounded reader, unreadable or not JSON.
pub fn read_document(path: &Path) -> Result<Value, InputFileError> {
    let (reader, _) = open_document(path)?;
    parse_document(path, reader)
}

/// The file's content is not what was expected: `message` naming what.
fn invalid(path: &Path, message: impl std::fmt::Display) -> InputFileError {
    InputFileError::Invalid {
        path: path.display().to_string(),
        message: message.to_string(),
    }
}

/// An I/O failure reading `path`: the bounded reader's refusal, or the failure itself.
fn io_failure(path: &Path, e: &std::io::Error) -> InputFileError {
    match refusal(e) {
        Some(r) => r.clone(),
        None => invalid(path, e),
    }
}

/// The curve's columns by name from the CSV `path`.
fn read_columns(path: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), InputFileError> {
    let csv_error = |e: csv::Error| match e.kind() {
        csv::ErrorKind::Io(io) => io_failure(path, io),
        _ => invalid(path, e),
    };
    let file = open(path, InputKind::CurveCsv)?;
    let mut reader = csv::Reader::from_reader(file);
    let names: Vec<String> = reader
        .headers()
        .map_err(csv_error)?
        .iter()
        .map(|h| h.trim().to_string())
        .collect();
    // a name twice would leave which of its columns is read to the reader's order
    for (k, name) in names.iter().enumerate() {
        if let Some(j) = names[..k].iter().position(|n| n == name) {
            return Err(invalid(
                path,
                format!(
                    "the column {name:?} appears twice (columns {} and {}): name each once",
                    j + 1,
                    k + 1
                ),
            ));
        }
    }
    let mut columns = vec![Vec::new(); names.len()];
    for (line, record) in reader.records().enumerate() {
        let record = record.map_err(csv_error)?;
        for (k, field) in record.iter().enumerate().take(names.len()) {
            let v: f64 = field.trim().parse().map_err(|_| {
                let line = line + 2;
                invalid(
                    path,
                    format!("line {line}: {} = {field:?} is not a number", names[k]),
                )
            })?;
            columns[k].push(v);
        }
    }
    Ok((names, columns))
}

/// A JSON document parsed as it is read, from `reader` that has read none of it yet beyond
/// the whitespace [`first_byte`] skipped.
fn parse_document(path: &Path, reader: impl std::io::Read) -> Result<Value, InputFileError> {
    serde_json::from_reader(reader).map_err(|e| {
        if e.is_io() {
            return io_failure(path, &std::io::Error::from(e));
        }
        invalid(path, format!("not a JSON document: {e}"))
    })
}

/// The first byte of `reader` that is not ASCII whitespace, the whitespace before it consumed
/// (`None` at the end).
fn first_byte(reader: &mut impl BufRead) -> std::io::Result<Option<u8>> {
    loop {
        let buf = reader.fill_buf()?;
        if buf.is_empty() {
            return Ok(None);
        }
        match buf.iter().position(|b| !b.is_ascii_whitespace()) {
            Some(i) => {
                let b = buf[i];
                reader.consume(i);
                return Ok(Some(b));
            }
            None => {
                let n = buf.len();
                reader.consume(n);
            }
        }
    }
}

/// The bounded reader of the document `path` and its first byte that is not whitespace.
fn open_document(
    path: &Path,
) -> Result<(std::io::BufReader<super::Bounded>, Option<u8>), InputFileError> {
    let file = open(path, InputKind::CurveDocument)?;
    let mut reader = std::io::BufReader::new(file);
    let first = first_byte(&mut reader).map_err(|e| io_failure(path, &e))?;
    Ok((reader, first))
}
