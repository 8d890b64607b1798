//! The resumable store of a chart (feature `files`): a directory, locked by [`DirLock`], holding
//!
//! - `.chart.run.json`, the ledger: `{"args": fingerprint, "finished": bool, "format": 2}`;
//! - `.chart.tiles.jsonl`, one line per finished task (tile), appended and flushed as each
//!   finishes: `{"cells": [ChartCell, …], "task": t, "crc32": "89abcdef"}` (a killed run
//!   leaves at most a cut last line, dropped on resume). `crc32` is the CRC-32 (zlib's) of the
//!   line's text before `,"crc32":`, 8 lowercase hex digits.
//!
//! Reading the tiles (a resume, the files written from the store) refuses, naming the file
//! and the line, a complete line whose checksum does not match or that cannot be read — a
//! damaged store never becomes a chart. A store whose ledger has no `format` was written by
//! an earlier version, without checksums: refused too (rerun without resuming).
//!
//! A resumed chart computes only the tasks not stored, and only for the request that made the
//! store ([`super::chart::fingerprint`]); a finished one computes nothing. The command line's
//! `afmdyn chart --out DIR` keeps its store there; the files a user reads (`chart.csv`,
//! `chart.nc`, the maps) are written from it.

use super::checkpoint::{CheckpointError, Ledger};
use super::checkpoint_file::{crc_hex, write_atomic, START_OVER};
use super::dir_lock::DirLock;
use super::sweep::first_difference;
use crate::analysis::chart::ChartCell;
use serde::Deserialize;
use serde_json::{json, Value};
use std::collections::{BTreeMap, BTreeSet, HashSet};
use std::fs::{self, File, OpenOptions};
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

/// The ledger.
pub const LEDGER: &str = ".chart.run.json";
/// The finished tasks.
pub const TILES: &str = ".chart.tiles.jsonl";
/// The store's layout (the ledger's `format`): 2 since the lines carry checksums.
pub const FORMAT: u64 = 2;
/// What ends a tile's line before its checksum.
const CRC_KEY: &str = ",\"crc32\":\"";

#[derive(Deserialize)]
struct Line {
    task: usize,
    cells: Vec<ChartCell>,
}

fn io<'p>(
    action: &'static str,
    path: &'p Path,
) -> impl FnOnce(std::io::Error) -> CheckpointError + 'p {
    move |e| CheckpointError::Io {
        action,
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// A chart's store in the directory its lock holds.
#[derive(Debug)]
pub struct ChartStore<'a> {
    lock: &'a DirLock,
    writer: Option<BufWriter<File>>,
    /// The tasks stored (their cells stay in the file: memory does not grow with the chart).
    tasks: BTreeSet<usize>,
}

impl<'a> ChartStore<'a> {
    /// The store of the directory `lock` holds.
    pub fn new(lock: &'a DirLock) -> ChartStore<'a> {
        ChartStore {
            lock,
            writer: None,
            tasks: BTreeSet::new(),
        }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.lock.path().join(name)
    }

    fn ledger(&self) -> Result<Option<Ledger>, CheckpointError> {
        let path = self.path(LEDGER);
        let text = match fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(io("read", &path)(e)),
        };
        let v: Value = serde_json::from_str(&text).map_err(|e| CheckpointError::Corrupt {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        if v.get("format").and_then(Value::as_u64) != Some(FORMAT) && self.path(TILES).exists() {
            return Err(CheckpointError::Corrupt {
                path: self.path(TILES).display().to_string(),
                message: format!(
                    "written by an earlier version of afmdyn (its lines carry no checksums); \
                     {START_OVER}"
                ),
            });
        }
        Ok(Some(Ledger {
            fingerprint: v.get("args").cloned().unwrap_or(Value::Null),
            finished: v.get("finished").and_then(Value::as_bool).unwrap_or(false),
        }))
    }

    fn write_ledger(&self, fingerprint: &Value, finished: bool) -> Result<(), CheckpointError> {
        let doc = json!({"args": fingerprint, "finished": finished, "format": FORMAT});
        write_atomic(&self.path(LEDGER), format!("{doc:#}\n").as_bytes())
    }

    /// Open the store for the chart `fingerprint`. Without `resume` a new chart begins (the
    /// stored tasks are dropped). With `resume`: an empty store begins; a store of another
    /// request is refused; otherwise the stored tasks are kept. Returns the tasks done.
    ///
    /// # Errors
    /// [`CheckpointError::Mismatch`] naming the first field that differs,
    /// [`CheckpointError::Unrecorded`] for tasks without a ledger, and the files' errors.
    pub fn open(
        &mut self,
        fingerprint: &Value,
        resume: bool,
    ) -> Result<HashSet<usize>, CheckpointError> {
        let tiles_path = self.path(TILES);
        if resume {
            match self.ledger()? {
                None if tiles_path.exists() => {
                    return Err(CheckpointError::Unrecorded {
                        store: self.lock.path().display().to_string(),
                        ledger: LEDGER.into(),
                    })
                }
                None => {}
                Some(ledger) => {
                    let now: Value = serde_json::from_str(&fingerprint.to_string())
                        .unwrap_or_else(|_| fingerprint.clone());
                    if let Some((field, then, now)) = first_difference(&ledger.fingerprint, &now) {
                        let field = field.strip_prefix("chart.").unwrap_or(&field).to_string();
                        return Err(CheckpointError::Mismatch { field, then, now });
                    }
                    self.tasks = self.read_tiles(|_, _| {})?;
                    self.reopen_writer()?;
                    return Ok(self.tasks.iter().copied().collect());
                }
            }
        }
        self.tasks.clear();
        match fs::remove_file(&tiles_path) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(io("remove", &tiles_path)(e)),
        }
        self.write_ledger(fingerprint, false)?;
        self.reopen_writer()?;
        Ok(HashSet::new())
    }

    /// The stored tasks, each handed with its cells to `each`: every complete line (a cut last
    /// line is dropped, and the file cut back to the complete lines so that appends follow
    /// them).
    ///
    /// # Errors
    /// [`CheckpointError::Corrupt`] naming the line whose checksum does not match or which
    /// cannot be read; [`CheckpointError::Io`].
    fn read_tiles(
        &self,
        mut each: impl FnMut(usize, Vec<ChartCell>),
    ) -> Result<BTreeSet<usize>, CheckpointError> {
        let path = self.path(TILES);
        let mut tasks = BTreeSet::new();
        let file = match File::open(&path) {
            Ok(f) => f,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(tasks),
            Err(e) => return Err(io("read", &path)(e)),
        };
        let mut reader = BufReader::new(file);
        let (mut good, mut buf, mut number) = (0u64, Vec::new(), 0usize);
        let damaged = |number: usize, what: String| CheckpointError::Corrupt {
            path: path.display().to_string(),
            message: format!("line {number}: {what}; {START_OVER}"),
        };
        loop {
            buf.clear();
            let n = reader
                .read_until(b'\n', &mut buf)
                .map_err(io("read", &path))?;
            if n == 0 || buf.last() != Some(&b'\n') {
                break;
            }
            number += 1;
            let text = String::from_utf8_lossy(&buf[..n - 1]);
            let sealed = text.rfind(CRC_KEY).and_then(|at| {
                let crc = text[at + CRC_KEY.len()..].strip_suffix("\"}")?;
                Some((at, crc))
            });
            match sealed {
                Some((at, crc)) if crc_hex(&text[..at]) == crc => {}
                _ => {
                    return Err(damaged(
                        number,
                        "checksum mismatch (the line was changed after afmdyn wrote it)".into(),
                    ))
                }
            }
            let line = serde_json::from_str::<Line>(&text)
                .map_err(|e| damaged(number, format!("cannot be read ({e})")))?;
            if tasks.insert(line.task) {
                each(line.task, line.cells);
            }
            good += n as u64;
        }
        let f = OpenOptions::new()
            .write(true)
            .open(&path)
            .map_err(io("write", &path))?;
        if f.metadata().map_err(io("read", &path))?.len() != good {
            f.set_len(good).map_err(io("write", &path))?;
        }
        Ok(tasks)
    }

    fn reopen_writer(&mut self) -> Result<(), CheckpointError> {
        let path = self.path(TILES);
        let f = OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(io("write", &path))?;
        self.writer = Some(BufWriter::new(f));
        Ok(())
    }

    /// Store the cells of a finished task (one line, flushed).
    ///
    /// # Errors
    /// [`CheckpointError::Io`].
    pub fn append(&mut self, task: usize, cells: Vec<ChartCell>) -> Result<(), CheckpointError> {
        let path = self.path(TILES);
        let line = json!({"task": task, "cells": &cells}).to_string();
        // the object without its closing brace, then the checksum of that text
        let body = &line[..line.len() - 1];
        let line = format!("{body}{CRC_KEY}{}\"}}", crc_hex(body));
        if let Some(w) = self.writer.as_mut() {
            writeln!(w, "{line}")
                .and_then(|()| w.flush())
                .map_err(io("write", &path))?;
        }
        self.tasks.insert(task);
        Ok(())
    }

    /// Mark the chart finished.
    ///
    /// # Errors
    /// [`CheckpointError::Io`].
    pub fn finish(&mut self, fingerprint: &Value) -> Result<(), CheckpointError> {
        if let Some(w) = self.writer.as_mut() {
            let path = self.lock.path().join(TILES);
            w.flush().map_err(io("write", &path))?;
        }
        self.write_ledger(fingerprint, true)
    }

    /// Whether the stored chart finished.
    ///
    /// # Errors
    /// As the ledger's reading.
    pub fn finished(&self) -> Result<bool, CheckpointError> {
        Ok(self.ledger()?.is_some_and(|l| l.finished))
    }

    /// Every stored cell, in the order of the tasks (row by row, x increasing), read back
    /// from the store.
    ///
    /// # Errors
    /// [`CheckpointError::Io`].
    pub fn cells(&mut self) -> Result<Vec<ChartCell>, CheckpointError> {
        if let Some(w) = self.writer.as_mut() {
            let path = self.lock.path().join(TILES);
            w.flush().map_err(io("write", &path))?;
        }
        let mut tiles = BTreeMap::new();
        self.read_tiles(|t, cells| {
            tiles.insert(t, cells);
        })?;
        Ok(tiles.into_values().flatten().collect())
    }
}

impl crate::study::Store<super::Chart> for ChartStore<'_> {
    fn open(
        &mut self,
        chart: &super::Chart,
        resume: bool,
    ) -> Result<crate::study::Opened<HashSet<usize>>, CheckpointError> {
        let done = ChartStore::open(self, &chart.fingerprint, resume)?;
        if resume && self.finished()? {
            return Ok(crate::study::Opened::Finished);
        }
        Ok(crate::study::Opened::Run(done))
    }

    fn append(&mut self, (task, cells): (usize, Vec<ChartCell>)) -> Result<(), CheckpointError> {
        ChartStore::append(self, task, cells)
    }

    fn finish(&mut self, chart: &super::Chart) -> Result<(), CheckpointError> {
        ChartStore::finish(self, &chart.fingerprint)
    }
}
