//! The file store of a sweep's checkpoint (feature `files`): a directory holding
//!
//! - `.bifurcation.run.json`, the ledger: `{"args": fingerprint, "finished": bool}`;
//! - `.bifurcation.partial.csv`, the rows of an unfinished sweep in the order the points
//!   finished, appended and flushed point by point (a killed run leaves at most one point in
//!   part, dropped on resume);
//! - `bifurcation.csv`, the rows of the finished sweep in the one order.
//!
//! The layout is the command line's `afmdyn bifurcation --out DIR`; Python's
//! `afmdyn.bifurcation(store=DIR)` uses the same, so either resumes the other's sweep.

use super::checkpoint::{end_state, Checkpoint, CheckpointError, DonePoint, Ledger, StoreStatus};
use super::dir_lock::DirLock;
use super::sweep::{SweepRecord, COL_INDEX, COL_POINT, COL_POINTS, HEADER};
use crate::analysis::bifurcation::Branch;
use serde_json::{json, Value};
use std::fs::{self, File, OpenOptions};
use std::io::{BufRead, BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The finished rows.
pub const FINAL_CSV: &str = "bifurcation.csv";
/// The rows of an unfinished sweep.
pub const PARTIAL_CSV: &str = ".bifurcation.partial.csv";
/// The ledger.
pub const LEDGER: &str = ".bifurcation.run.json";
/// The finished rows while they are being sorted.
const SORTED_CSV: &str = ".bifurcation.sorted.csv";

/// A sweep's checkpoint in a directory (see the module), which the caller holds locked.
#[derive(Debug)]
pub struct FileCheckpoint<'a> {
    lock: &'a DirLock,
    dir: PathBuf,
    writer: Option<BufWriter<File>>,
}

fn io<'a>(
    action: &'static str,
    path: &'a Path,
) -> impl FnOnce(std::io::Error) -> CheckpointError + 'a {
    move |e| CheckpointError::Io {
        action,
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Write `bytes` to `path` through a temporary file renamed into place (`.NAME.partial.EXT`).
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), CheckpointError> {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("out");
    let tmp = path.with_file_name(match path.extension().and_then(|s| s.to_str()) {
        Some(ext) => format!(".{stem}.partial.{ext}"),
        None => format!(".{stem}.partial"),
    });
    let written = File::create(&tmp)
        .and_then(|mut f| f.write_all(bytes).and_then(|_| f.sync_all()))
        .map_err(io("write", path));
    if let Err(e) = written {
        let _ = fs::remove_file(&tmp);
        return Err(e);
    }
    fs::rename(&tmp, path).map_err(io("finish", path))
}

/// A point's rows in the partial file: key, byte range, lines.
type Group = ((usize, Branch), Range<u64>, Vec<String>);

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

/// The header and the complete points of a rows file, in file order. A killed run may leave
/// a cut row (without its newline) or a point in part at the end: they are not listed.
fn groups(path: &Path) -> Result<(String, Vec<Group>), CheckpointError> {
    let mut reader = BufReader::new(File::open(path).map_err(io("read", path))?);
    let (mut header, mut groups, mut group) = (String::new(), Vec::new(), Vec::<String>::new());
    let (mut start, mut pos) = (0u64, 0u64);
    let mut close = |group: &mut Vec<String>, range: Range<u64>| {
        if let Some(key) = group.first().and_then(|g| row_key(g)) {
            if complete(group) {
                groups.push((key, range, std::mem::take(group)));
            }
        }
        group.clear();
    };
    let mut buf = Vec::new();
    loop {
        buf.clear();
        let n = reader
            .read_until(b'\n', &mut buf)
            .map_err(io("read", path))? as u64;
        if n == 0 || buf.last() != Some(&b'\n') {
            break; // the end, or a cut row without its newline
        }
        let line = String::from_utf8_lossy(&buf[..buf.len() - 1]).to_string();
        if header.is_empty() {
            header = line;
            pos += n;
            start = pos;
            continue;
        }
        if !group.is_empty() && group.first().and_then(|g| row_key(g)) != row_key(&line) {
            close(&mut group, start..pos);
            start = pos;
        }
        group.push(line);
        pos += n;
    }
    close(&mut group, start..pos);
    Ok((header, groups))
}

impl<'a> FileCheckpoint<'a> {
    /// The store in the directory `lock` holds ([`DirLock::acquire`] creates and locks it, so
    /// that no two runs write one store).
    pub fn new(lock: &'a DirLock) -> FileCheckpoint<'a> {
        FileCheckpoint {
            lock,
            dir: lock.path().to_path_buf(),
            writer: None,
        }
    }

    /// The lock the store is written under.
    pub fn lock(&self) -> &DirLock {
        self.lock
    }

    /// The finished rows, `DIR/bifurcation.csv`.
    pub fn final_csv(&self) -> PathBuf {
        self.dir.join(FINAL_CSV)
    }

    fn partial(&self) -> PathBuf {
        self.dir.join(PARTIAL_CSV)
    }

    fn ledger_path(&self) -> PathBuf {
        self.dir.join(LEDGER)
    }

    fn write_ledger(&self, fingerprint: &Value, finished: bool) -> Result<(), CheckpointError> {
        let doc = json!({ "args": fingerprint, "finished": finished });
        let text = serde_json::to_string_pretty(&doc).unwrap_or_default() + "\n";
        write_atomic(&self.ledger_path(), text.as_bytes())
    }

    /// The finished rows, read back in their order.
    ///
    /// # Errors
    /// [`CheckpointError::Io`], or [`CheckpointError::Corrupt`] naming the line that cannot
    /// be read.
    pub fn records(&self) -> Result<Vec<SweepRecord>, CheckpointError> {
        let path = self.final_csv();
        let text = fs::read_to_string(&path).map_err(io("read", &path))?;
        text.lines()
            .enumerate()
            .skip(1)
            .map(|(i, l)| {
                SweepRecord::parse_csv(l).map_err(|message| CheckpointError::Corrupt {
                    path: path.display().to_string(),
                    message: format!("line {}: {message}", i + 1),
                })
            })
            .collect()
    }
}

impl Checkpoint for FileCheckpoint<'_> {
    fn status(&mut self) -> Result<StoreStatus, CheckpointError> {
        let path = self.ledger_path();
        let ledger = match fs::read_to_string(&path) {
            Ok(t) => {
                let doc: Value =
                    serde_json::from_str(&t).map_err(|e| CheckpointError::Corrupt {
                        path: path.display().to_string(),
                        message: e.to_string(),
                    })?;
                Some(Ledger {
                    fingerprint: doc["args"].clone(),
                    finished: doc["finished"] == json!(true),
                })
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => return Err(io("read", &path)(e)),
        };
        Ok(StoreStatus {
            ledger,
            partial: self.partial().exists(),
            complete: self.final_csv().exists(),
        })
    }

    fn begin(&mut self, fingerprint: &Value) -> Result<(), CheckpointError> {
        self.writer = None;
        // the old rows go first, then the ledger names the new run
        let partial = self.partial();
        if partial.exists() {
            fs::remove_file(&partial).map_err(io("remove", &partial))?;
        }
        self.write_ledger(fingerprint, false)?;
        let mut f = File::create(&partial).map_err(io("create", &partial))?;
        writeln!(f, "{}", HEADER.join(",")).map_err(io("write", &partial))
    }

    fn done(&mut self) -> Result<Vec<DonePoint>, CheckpointError> {
        self.writer = None;
        let partial = self.partial();
        let (header, groups) = groups(&partial)?;
        let mut text = header + "\n";
        let mut done = Vec::with_capacity(groups.len());
        for ((index, branch), _, lines) in groups {
            let state = lines
                .last()
                .and_then(|l| SweepRecord::parse_csv(l).ok())
                .and_then(|r| end_state(std::slice::from_ref(&r)));
            done.push(DonePoint {
                index,
                branch,
                state,
            });
            for l in lines {
                text.push_str(&l);
                text.push('\n');
            }
        }
        // keep only the complete points, so that new rows follow a whole line
        write_atomic(&partial, text.as_bytes())?;
        Ok(done)
    }

    fn append(&mut self, point: &[SweepRecord]) -> Result<(), CheckpointError> {
        let partial = self.partial();
        if self.writer.is_none() {
            let file = OpenOptions::new()
                .append(true)
                .open(&partial)
                .map_err(io("open", &partial))?;
            self.writer = Some(BufWriter::new(file));
        }
        let mut text = String::new();
        for r in point {
            text.push_str(&r.csv_line());
            text.push('\n');
        }
        let w = self.writer.as_mut().ok_or_else(|| CheckpointError::Io {
            action: "open",
            path: partial.display().to_string(),
            message: "no writer".into(),
        })?;
        w.write_all(text.as_bytes())
            .and_then(|_| w.flush())
            .map_err(io("write", &partial))
    }

    /// Sort the points by key (copying their rows by byte range, never all in memory) into
    /// `bifurcation.csv`, remove the partial rows, mark the ledger finished.
    fn finish(&mut self, fingerprint: &Value) -> Result<(), CheckpointError> {
        let partial = self.partial();
        if let Some(mut w) = self.writer.take() {
            w.flush().map_err(io("write", &partial))?;
        }
        let final_csv = self.final_csv();
        let (header, mut groups) = groups(&partial)?;
        groups.sort_by_key(|g| g.0);
        let mut src = File::open(&partial).map_err(io("read", &partial))?;
        let sorted = self.dir.join(SORTED_CSV);
        {
            let wr = io("write", &final_csv);
            let mut out = BufWriter::new(File::create(&sorted).map_err(io("write", &final_csv))?);
            let mut copy = || -> std::io::Result<()> {
                writeln!(out, "{header}")?;
                let mut buf = Vec::new();
                for (_, range, _) in &groups {
                    buf.resize((range.end - range.start) as usize, 0);
                    src.seek(SeekFrom::Start(range.start))?;
                    src.read_exact(&mut buf)?;
                    out.write_all(&buf)?;
                }
                out.flush()?;
                out.get_ref().sync_all()
            };
            copy().map_err(wr)?;
        }
        fs::rename(&sorted, &final_csv).map_err(io("finish", &final_csv))?;
        fs::remove_file(&partial).map_err(io("remove", &partial))?;
        self.write_ledger(fingerprint, true)
    }

    fn names(&self) -> (String, String) {
        (
            self.dir.display().to_string(),
            self.ledger_path().display().to_string(),
        )
    }
}
