//! The file store of a sweep's checkpoint (feature `files`): a directory holding
//!
//! - `.bifurcation.run.json`, the ledger: `{"args": fingerprint, "finished": bool}`;
//! - `.bifurcation.partial.csv`, the rows of an unfinished sweep in the order the points
//!   finished, appended and flushed point by point (a killed run leaves at most one point in
//!   part, dropped on resume). Its header is [`HEADER`] and a last column `crc32`; each row
//!   ends with the CRC-32 (ISO-HDLC, the one of zlib and `crc32fast`; 8 lowercase hex digits)
//!   of the row's text before that column. A resume refuses, naming the file and the line, a
//!   header that is not this one (a store written before the checksums is named as such:
//!   rerun without resuming) and a complete line whose checksum does not match (a record
//!   changed after it was written) — never resuming into a corrupt result;
//! - `bifurcation.csv`, the rows of the finished sweep in the one order (without the
//!   checksums).
//!
//! The layout is the command line's `afmdyn bifurcation --out DIR`; Python's
//! `afmdyn.bifurcation(store=DIR)` uses the same, so either resumes the other's sweep.

use super::checkpoint::CheckpointError;
use crate::analysis::bifurcation::Branch;
use crate::io::dir_lock::partial_path;
use crate::io::input::{open_existing, refusal, Bounded, InputFileError, InputKind};
use crate::layout::files::{io_error, Column, FileError, NpyStream};
use crate::params::SweepParam;
use crate::request::sweep::{branch_code, status_code, SweepRecord, HEADER, NUMERIC_COLUMNS};
use crate::request::sweep::{COL_BRANCH, COL_INDEX, COL_PERIOD, COL_POINT, COL_POINTS, COL_STATUS};
use crate::request::sweep::{COL_TAU, COL_VALUE, COL_W_TIP, COL_X_MAX};
use serde_json::Value;
use std::collections::HashSet;
use std::fs::{self, File};
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

/// The finished rows.
pub(crate) const FINAL_CSV: &str = "bifurcation.csv";
/// The rows of an unfinished sweep.
pub(crate) const PARTIAL_CSV: &str = ".bifurcation.partial.csv";
/// The ledger.
pub(crate) const LEDGER: &str = ".bifurcation.run.json";
/// The finished rows while they are being sorted.
const SORTED_CSV: &str = ".bifurcation.sorted.csv";
/// The last column of the checkpoint's rows: the CRC-32 of the row's text before it.
pub(crate) const CRC_COLUMN: &str = "crc32";
/// What a damaged store's message tells the user to do.
pub(crate) const START_OVER: &str = "rerun without --resume to start over";

/// The checkpoint's header: [`HEADER`] and [`CRC_COLUMN`].
pub(crate) fn partial_header() -> String {
    format!("{},{CRC_COLUMN}", HEADER.join(","))
}

/// The CRC-32 of `text` as the stores write it: 8 lowercase hex digits.
pub(crate) fn crc_hex(text: &str) -> String {
    format!("{:08x}", crc32fast::hash(text.as_bytes()))
}

/// A row as the checkpoint stores it: the row and, in the last column, its checksum.
pub(crate) fn sealed(row: &str) -> String {
    format!("{row},{}", crc_hex(row))
}

/// The row of a stored line whose checksum matches (`None`: no checksum, or another one).
pub(crate) fn unsealed(line: &str) -> Option<&str> {
    let (row, crc) = line.rsplit_once(',')?;
    (crc_hex(row) == crc).then_some(row)
}

/// A refusal of the bounded reader ([`crate::io::input`]) as the store's error: the file is
/// not what the store wrote, or larger than the cap of its kind ([`CheckpointError::Corrupt`]
/// naming the file and the cap); the store is left as it is.
pub(crate) fn refused(path: &Path, e: InputFileError) -> CheckpointError {
    match e {
        InputFileError::Io { message, .. } => CheckpointError::Io {
            action: "read",
            path: path.display().to_string(),
            message,
        },
        e => {
            let name = path.display().to_string();
            let text = e.to_string();
            let message = text
                .strip_prefix(&format!("{name}: "))
                .unwrap_or(&text)
                .to_string();
            corrupt(path, format!("{message}; {START_OVER}"))
        }
    }
}

/// A read error of a [`Bounded`] store file: its refusal ([`refused`]), or the system's.
pub(crate) fn read_failed(path: &Path, e: std::io::Error) -> CheckpointError {
    match refusal(&e) {
        Some(r) => refused(path, r.clone()),
        None => io("read", path)(e),
    }
}

/// The store file `path` of `kind` opened through the bounded reader, `None` when it does not
/// exist.
///
/// # Errors
/// [`refused`]: larger than the kind's cap, or unreadable.
pub(crate) fn open_store(path: &Path, kind: InputKind) -> Result<Option<Bounded>, CheckpointError> {
    open_existing(path, kind).map_err(|e| refused(path, e))
}

/// The ledger `path` of a store, parsed as it is read through the bounded reader
/// ([`InputKind::StoreLedger`]); `None` when there is none.
///
/// # Errors
/// [`CheckpointError::Corrupt`] naming the file and the cap: larger than the cap, or not a
/// ledger (not JSON, a NUL byte); [`CheckpointError::Io`].
pub(crate) fn read_ledger(path: &Path) -> Result<Option<Value>, CheckpointError> {
    let Some(file) = open_store(path, InputKind::StoreLedger)? else {
        return Ok(None);
    };
    serde_json::from_reader(BufReader::new(file))
        .map(Some)
        .map_err(|e| {
            if e.is_io() {
                return read_failed(path, e.into());
            }
            corrupt(
                path,
                format!(
                    "not {} (JSON of at most {} bytes): {e}; {START_OVER}",
                    InputKind::StoreLedger.name(),
                    InputKind::StoreLedger.cap()
                ),
            )
        })
}

fn corrupt(path: &Path, message: String) -> CheckpointError {
    CheckpointError::Corrupt {
        path: path.display().to_string(),
        message,
    }
}

/// Each row of the store's CSV `path` (its finished rows), read through the bounded reader: a
/// read failure as the store's error (the reader's refusal naming the file and its cap, as
/// [`refused`]), `each`'s as it is.
///
/// # Errors
/// As said.
pub(crate) fn each_row<E: From<CheckpointError>>(
    path: &Path,
    each: &mut dyn FnMut(&csv::StringRecord) -> Result<(), E>,
) -> Result<(), E> {
    let file = crate::io::open(path, InputKind::Store).map_err(|e| refused(path, e))?;
    let mut reader = csv::Reader::from_reader(file);
    for r in reader.records() {
        let r = r.map_err(|e| {
            if let csv::ErrorKind::Io(io) = e.kind() {
                if let Some(r) = refusal(io) {
                    return refused(path, r.clone());
                }
            }
            CheckpointError::Io {
                action: "read",
                path: path.display().to_string(),
                message: crate::layout::files::without_errno(&e.to_string()).to_string(),
            }
        })?;
        each(&r)?;
    }
    Ok(())
}

/// A bifurcation diagram's points read from its store's CSV, chunk by chunk.
impl crate::layout::figure::PointSource for crate::report::present::sweeps::StoredDiagram {
    fn feed(
        &self,
        draw: &mut crate::layout::figure::PointSink<'_>,
    ) -> Result<(), crate::layout::figure::FeedError> {
        use crate::layout::figure::FeedError;
        let mut chunk = Vec::with_capacity(4096);
        each_row(&self.csv, &mut |r| -> Result<(), FeedError> {
            chunk.extend(crate::report::present::sweeps::diagram_point(
                crate::report::present::sweeps::SweepRow::from_csv(r),
                self.column,
                self.by_branch,
            ));
            if chunk.len() == chunk.capacity() {
                draw(&chunk).map_err(FeedError::Io)?;
                chunk.clear();
            }
            Ok(())
        })?;
        draw(&chunk).map_err(FeedError::Io)
    }
}

/// A store's error feeding a figure: a store not as written, or past its cap, is refused (bad
/// input); any other is a read failure.
impl From<CheckpointError> for crate::layout::figure::FeedError {
    fn from(e: CheckpointError) -> Self {
        match e {
            CheckpointError::Corrupt { .. } => Self::Refused(e.to_string()),
            e => Self::Io(e.to_string()),
        }
    }
}

/// An I/O error of the store file `path` while doing `action`, as the store's error.
pub(crate) fn io<'a>(
    action: &'static str,
    path: &'a Path,
) -> impl FnOnce(std::io::Error) -> CheckpointError + 'a {
    move |e| CheckpointError::Io {
        action,
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Write `bytes` to `path` through a temporary file renamed into place ([`partial_path`]).
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), CheckpointError> {
    let tmp = partial_path(path);
    let written = File::create(&tmp)
        .and_then(|mut f| f.write_all(bytes).and_then(|_| f.sync_all()))
        .map_err(io("write", path));
    if let Err(e) = written {
        let _ = fs::remove_file(&tmp);
        return Err(e);
    }
    fs::rename(&tmp, path).map_err(io("finish", path))
}

/// A point's rows in the partial file: key and rows (checked, without their checksums).
type Group = ((usize, Branch), Vec<String>);

/// Key of a row (one sweep point): (index, branch).
fn row_key(line: &str) -> Option<(usize, Branch)> {
    let mut cells = line.split(',').skip(COL_INDEX);
    let index = cells.next()?.parse().ok()?;
    let branch = cells.next()?.parse().ok()?;
    Some((index, branch))
}

/// All `points` rows of a point, in order, each with every column.
fn complete(g: &[String]) -> bool {
    let cells: Vec<Vec<&str>> = g.iter().map(|l| l.split(',').collect()).collect();
    cells.iter().all(|c| c.len() == HEADER.len())
        && cells[0][COL_POINTS].parse::<usize>().ok() == Some(cells.len())
        && cells
            .iter()
            .enumerate()
            .all(|(i, c)| c[COL_POINT].parse::<usize>().ok() == Some(i))
}

/// The complete points of a checkpoint, in file order, their rows checked against their
/// checksums. A killed run may leave a cut row (without its newline) or a point in part at
/// the end: they are not listed (and so computed again).
///
/// # Errors
/// [`CheckpointError::Corrupt`] naming the line: a first line that is not
/// [`partial_header`] (a store written before the checksums, or a removed or changed
/// header), a complete line whose checksum does not match, a point stored twice.
fn groups(path: &Path) -> Result<Vec<Group>, CheckpointError> {
    let file = open_store(path, InputKind::Store)?.ok_or_else(|| CheckpointError::Io {
        action: "read",
        path: path.display().to_string(),
        message: "No such file or directory".into(),
    })?;
    let mut reader = BufReader::new(file);
    let (mut groups, mut group) = (Vec::new(), Vec::<String>::new());
    let mut seen = HashSet::new();
    let mut close = |group: &mut Vec<String>, line: usize| -> Result<(), CheckpointError> {
        if let Some(key) = group.first().and_then(|g| row_key(g)) {
            if complete(group) {
                if !seen.insert(key) {
                    return Err(corrupt(
                        path,
                        format!(
                            "line {line}: point {} ({}) is stored twice; {START_OVER}",
                            key.0, key.1
                        ),
                    ));
                }
                groups.push((key, std::mem::take(group)));
            }
        }
        group.clear();
        Ok(())
    };
    let mut buf = Vec::new();
    let mut number = 0usize;
    loop {
        buf.clear();
        let n = reader
            .read_until(b'\n', &mut buf)
            .map_err(|e| read_failed(path, e))?;
        if n == 0 || buf.last() != Some(&b'\n') {
            break; // the end, or a cut row without its newline
        }
        number += 1;
        let line = String::from_utf8_lossy(&buf[..buf.len() - 1]);
        if number == 1 {
            if line == partial_header() {
                continue;
            }
            return Err(corrupt(
                path,
                if line == HEADER.join(",") {
                    format!(
                        "written by an earlier version of afmdyn (its rows carry no \
                         checksums); {START_OVER}"
                    )
                } else {
                    format!(
                        "line 1: the header is missing or changed (expected the columns {}); \
                         {START_OVER}",
                        partial_header()
                    )
                },
            ));
        }
        let Some(row) = unsealed(&line) else {
            return Err(corrupt(
                path,
                format!(
                    "line {number}: checksum mismatch (the row was changed after afmdyn wrote \
                     it); {START_OVER}"
                ),
            ));
        };
        if !group.is_empty() && group.first().and_then(|g| row_key(g)) != row_key(row) {
            close(&mut group, number - 1)?;
        }
        group.push(row.to_string());
    }
    close(&mut group, number)?;
    Ok(groups)
}

/// The finished rows of the store in `dir`, `DIR/bifurcation.csv`.
pub(crate) fn final_csv(dir: &Path) -> PathBuf {
    dir.join(FINAL_CSV)
}

/// Every complete point of the checkpoint `path` handed to `each` (its rows, in file order;
/// see [`groups`]), the file cut back to them so that new rows follow a whole line.
///
/// # Errors
/// As [`groups`]; [`CheckpointError::Corrupt`] for a row that cannot be read.
pub(crate) fn read_points(
    path: &Path,
    each: &mut dyn FnMut(Vec<SweepRecord>),
) -> Result<(), CheckpointError> {
    let groups = groups(path)?;
    let mut text = partial_header() + "\n";
    let mut points = Vec::with_capacity(groups.len());
    for (_, lines) in groups {
        let point = (lines.iter().map(|l| SweepRecord::parse_csv(l)))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|message| corrupt(path, format!("{message}; {START_OVER}")))?;
        points.push(point);
        for l in lines {
            text.push_str(&sealed(&l));
            text.push('\n');
        }
    }
    // keep only the complete points
    write_atomic(path, text.as_bytes())?;
    points.into_iter().for_each(each);
    Ok(())
}

/// Sort the points of the finished sweep in `dir` by key into `bifurcation.csv` (their rows
/// checked and without their checksums) and remove the checkpoint's rows.
///
/// # Errors
/// As [`groups`]; [`CheckpointError::Io`].
pub(crate) fn sort_into_final(dir: &Path) -> Result<(), CheckpointError> {
    let (partial, final_csv) = (dir.join(PARTIAL_CSV), final_csv(dir));
    let mut groups = groups(&partial)?;
    groups.sort_by_key(|g| g.0);
    let sorted = dir.join(SORTED_CSV);
    {
        let wr = io("write", &final_csv);
        let mut out = BufWriter::new(File::create(&sorted).map_err(io("write", &final_csv))?);
        let mut copy = || -> std::io::Result<()> {
            writeln!(out, "{}", HEADER.join(","))?;
            for (_, lines) in &groups {
                for l in lines {
                    writeln!(out, "{l}")?;
                }
            }
            out.flush()?;
            out.get_ref().sync_all()
        };
        copy().map_err(wr)?;
    }
    fs::rename(&sorted, &final_csv).map_err(io("finish", &final_csv))?;
    fs::remove_file(&partial).map_err(io("remove", &partial))
}

/// Write `DIR/bifurcation.npy` and its `.npy.json` from the finished rows ([`final_csv`],
/// streamed): the columns [`NUMERIC_COLUMNS`], the branch and the status as their codes
/// ([`branch_code`], [`status_code`]), an empty cell (a failed point's numbers) as NaN;
/// `param` names the value's column. Returns the path.
///
/// # Errors
/// [`FileError`] naming the file that cannot be read or written.
pub(crate) fn write_npy(dir: &Path, param: SweepParam) -> Result<PathBuf, FileError> {
    let (csv_path, npy) = (final_csv(dir), dir.join("bifurcation.npy"));
    let rd = |e: csv::Error| io_error("read", &csv_path, e);
    let file =
        crate::io::open(&csv_path, InputKind::Store).map_err(|e| io_error("read", &csv_path, e))?;
    let mut reader = csv::Reader::from_reader(file);
    let columns = NUMERIC_COLUMNS
        .iter()
        .map(|c| match c.name {
            "value" => Column::new(c.name, c.unit, format!("{} ({})", c.meaning, param.name())),
            _ => Column::new(c.name, c.unit, c.meaning),
        })
        .collect();
    let mut s = NpyStream::create(&npy, columns)?;
    for r in reader.records() {
        let r = r.map_err(rd)?;
        let num = |i: usize| r[i].parse::<f64>().unwrap_or(f64::NAN);
        let branch: Branch = r[COL_BRANCH].parse().unwrap_or(Branch::Start(u32::MAX));
        s.push(&[
            num(COL_VALUE),
            num(COL_INDEX),
            branch_code(branch),
            status_code(&r[COL_STATUS], &r[COL_PERIOD]),
            num(COL_POINT),
            num(COL_TAU),
            num(COL_TAU + 1),
            num(COL_W_TIP),
            num(COL_X_MAX),
            num(COL_X_MAX + 1),
            num(COL_X_MAX + 2),
            num(COL_X_MAX + 3),
        ])?;
    }
    s.finish()?;
    Ok(npy)
}

/// The finished rows of the store in `dir`, read back in their order.
///
/// # Errors
/// [`CheckpointError::Io`], or [`CheckpointError::Corrupt`] naming the line that cannot
/// be read.
pub(crate) fn final_rows(dir: &Path) -> Result<Vec<SweepRecord>, CheckpointError> {
    let path = final_csv(dir);
    let file = open_store(&path, InputKind::Store)?.ok_or_else(|| CheckpointError::Io {
        action: "read",
        path: path.display().to_string(),
        message: "No such file or directory".into(),
    })?;
    BufReader::new(file)
        .lines()
        .enumerate()
        .skip(1)
        .map(|(i, l)| {
            let l = l.map_err(|e| read_failed(&path, e))?;
            SweepRecord::parse_csv(&l).map_err(|message| CheckpointError::Corrupt {
                path: path.display().to_string(),
                message: format!("line {}: {message}", i + 1),
            })
        })
        .collect()
}
