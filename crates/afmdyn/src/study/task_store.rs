//! A study's resumable store of tasks (feature `files`): a directory, locked by [`DirLock`],
//! holding, for a study whose tasks are numbered and whose records serialize ([`TaskFiles`]
//! names the files; the chart's are shown):
//!
//! - the ledger (`.chart.run.json`): `{"args": fingerprint, "finished": bool, "format": 2}`;
//! - the records (`.chart.tiles.jsonl`), one line per finished task, appended and flushed as
//!   each finishes: `{"cells": record, "task": t, "crc32": "89abcdef"}` (the record under the
//!   study's key, as JSON or, for records whose floats may be NaN or ±∞, which JSON cannot
//!   hold, as a string of its CBOR encoding in base64 — [`Encoding`]; a killed run leaves at
//!   most a cut last line, dropped on resume). `crc32` is the CRC-32 (zlib's) of the line's
//!   text before `,"crc32":`, 8 lowercase hex digits.
//!
//! Reading the records (a resume, the files written from the store) refuses, naming the file
//! and the line, a complete line whose checksum does not match or that cannot be read — a
//! damaged store never becomes a result. A store whose ledger has no `format` was written by
//! an earlier version, without checksums: refused too (rerun without resuming).
//!
//! A resumed study computes only the tasks not stored, and only for the request that made the
//! store (its fingerprint); a finished one computes nothing. The command line's
//! `afmdyn chart --out DIR` keeps its store there ([`super::chart_store`]); the files
//! a user reads (`chart.csv`, `chart.nc`, the maps) are written from it.

use crate::io::dir_lock::DirLock;
use crate::io::input::InputKind;
use crate::request::checkpoint::{same_request, CheckpointError, Ledger};
use crate::request::checkpoint_file::{crc_hex, io, open_store, read_failed, read_ledger};
use crate::request::checkpoint_file::{write_atomic, START_OVER};
use base64::engine::general_purpose::STANDARD as BASE64;
use base64::Engine;
use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_json::{json, Value};
use std::collections::{BTreeMap, BTreeSet, HashSet};
use std::fs::{self, File, OpenOptions};
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::marker::PhantomData;
use std::path::PathBuf;

use super::{Opened, Store, Study};

/// The store's layout (the ledger's `format`): 2 since the lines carry checksums.
pub(crate) const FORMAT: u64 = 2;
/// What ends a record's line before its checksum.
const CRC_KEY: &str = ",\"crc32\":\"";

/// The files and keys of one kind of study's store.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct TaskFiles {
    /// The ledger's file name.
    pub ledger: &'static str,
    /// The records' file name.
    pub records: &'static str,
    /// The key of a line's record.
    pub key: &'static str,
    /// The prefix of the fingerprint's fields that a mismatch's message leaves out
    /// (`"chart."`), if any.
    pub prefix: &'static str,
    /// How a line holds its record.
    pub encoding: Encoding,
}

/// How a store's line holds its record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Encoding {
    /// JSON (readable; for records whose floats are all finite: JSON has no NaN or ±∞).
    Json,
    /// A string: the record's CBOR encoding (RFC 8949, by `ciborium`) in standard base64 —
    /// every f64 bit for bit, NaN and ±∞ included (a periodic orbit's grazing distance is +∞
    /// when it never comes near the sample).
    Cbor,
}

/// A study's store of records `R` in the directory its lock holds.
#[derive(Debug)]
pub(crate) struct TaskStore<'a, R> {
    files: TaskFiles,
    lock: &'a DirLock,
    writer: Option<BufWriter<File>>,
    /// The tasks stored (their records stay in the file: memory does not grow with the study).
    tasks: BTreeSet<usize>,
    /// With [`TaskStore::keeping`]: a copy of the stored records, and whether it holds every
    /// one (after a new run's start, or once a resumed store's records were read).
    kept: Option<(BTreeMap<usize, R>, bool)>,
    record: PhantomData<fn() -> R>,
}

impl<'a, R: Serialize + DeserializeOwned + Clone> TaskStore<'a, R> {
    /// The store of the directory `lock` holds, in `files`.
    pub(crate) fn new(lock: &'a DirLock, files: TaskFiles) -> TaskStore<'a, R> {
        TaskStore {
            files,
            lock,
            writer: None,
            tasks: BTreeSet::new(),
            kept: None,
            record: PhantomData,
        }
    }

    /// The store keeping a copy of its records in memory, so that [`TaskStore::records`]
    /// hands them back without reading and decoding the file again — for a study whose
    /// records a resume reads anyway (a chain's: [`StoredTasks`] for `Vec<R>`), not for one
    /// whose records must stay on disk.
    pub(crate) fn keeping(mut self) -> TaskStore<'a, R> {
        self.kept = Some((BTreeMap::new(), false));
        self
    }

    fn path(&self, name: &str) -> PathBuf {
        self.lock.path().join(name)
    }

    fn ledger(&self) -> Result<Option<Ledger>, CheckpointError> {
        let Some(v) = read_ledger(&self.path(self.files.ledger))? else {
            return Ok(None);
        };
        if v.get("format").and_then(Value::as_u64) != Some(FORMAT)
            && self.path(self.files.records).exists()
        {
            return Err(CheckpointError::Corrupt {
                path: self.path(self.files.records).display().to_string(),
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
        write_atomic(
            &self.path(self.files.ledger),
            format!("{doc:#}\n").as_bytes(),
        )
    }

    /// Open the store for the study of `fingerprint`. Without `resume` a new study begins (the
    /// stored tasks are dropped). With `resume`: an empty store begins; a store of another
    /// request is refused; otherwise the stored tasks are kept. Returns the tasks done.
    ///
    /// # Errors
    /// [`CheckpointError::Mismatch`] naming the first field that differs,
    /// [`CheckpointError::Unrecorded`] for tasks without a ledger, and the files' errors.
    pub(crate) fn open(
        &mut self,
        fingerprint: &Value,
        resume: bool,
    ) -> Result<HashSet<usize>, CheckpointError> {
        let tiles_path = self.path(self.files.records);
        if resume {
            match self.ledger()? {
                None if tiles_path.exists() => {
                    return Err(CheckpointError::Unrecorded {
                        store: self.lock.path().display().to_string(),
                        ledger: self.files.ledger.into(),
                    })
                }
                None => {}
                Some(ledger) => {
                    same_request(&ledger.fingerprint, fingerprint, self.files.prefix)?;
                    self.tasks = self.read_records(|_, _| {})?;
                    if let Some(k) = self.kept.as_mut() {
                        *k = (BTreeMap::new(), false);
                    }
                    self.reopen_writer()?;
                    return Ok(self.tasks.iter().copied().collect());
                }
            }
        }
        self.tasks.clear();
        if let Some(k) = self.kept.as_mut() {
            *k = (BTreeMap::new(), true);
        }
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
    fn read_records(
        &self,
        mut each: impl FnMut(usize, R),
    ) -> Result<BTreeSet<usize>, CheckpointError> {
        let path = self.path(self.files.records);
        let mut tasks = BTreeSet::new();
        let Some(file) = open_store(&path, InputKind::StoreRecords)? else {
            return Ok(tasks);
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
                .map_err(|e| read_failed(&path, e))?;
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
            let (task, record) = self
                .parse(&text)
                .map_err(|e| damaged(number, format!("cannot be read ({e})")))?;
            if tasks.insert(task) {
                each(task, record);
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

    /// A line's task and record.
    fn parse(&self, text: &str) -> Result<(usize, R), String> {
        let mut v: serde_json::Map<String, Value> =
            serde_json::from_str(text).map_err(|e| e.to_string())?;
        let task = serde_json::from_value(v.remove("task").unwrap_or(Value::Null))
            .map_err(|e| e.to_string())?;
        let record = v.remove(self.files.key).unwrap_or(Value::Null);
        let record = match self.files.encoding {
            Encoding::Json => serde_json::from_value(record).map_err(|e| e.to_string())?,
            Encoding::Cbor => from_cbor_text(record.as_str().ok_or("the record is not a string")?)?,
        };
        Ok((task, record))
    }

    /// The record as a line holds it ([`Encoding`]).
    fn encode(&self, record: &R) -> Result<Value, String> {
        match self.files.encoding {
            Encoding::Json => serde_json::to_value(record).map_err(|e| e.to_string()),
            Encoding::Cbor => Ok(Value::String(to_cbor_text(record)?)),
        }
    }

    fn reopen_writer(&mut self) -> Result<(), CheckpointError> {
        let path = self.path(self.files.records);
        let f = OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(io("write", &path))?;
        self.writer = Some(BufWriter::new(f));
        Ok(())
    }

    /// Store the record of a finished task (one line, flushed).
    ///
    /// # Errors
    /// [`CheckpointError::Io`].
    pub(crate) fn append(&mut self, task: usize, record: &R) -> Result<(), CheckpointError> {
        let path = self.path(self.files.records);
        let mut line = serde_json::Map::new();
        line.insert("task".into(), json!(task));
        line.insert(
            self.files.key.into(),
            self.encode(record).map_err(|message| CheckpointError::Io {
                action: "write",
                path: path.display().to_string(),
                message,
            })?,
        );
        let line = Value::Object(line).to_string();
        // the object without its closing brace, then the checksum of that text
        let body = &line[..line.len() - 1];
        let line = format!("{body}{CRC_KEY}{}\"}}", crc_hex(body));
        if let Some(w) = self.writer.as_mut() {
            writeln!(w, "{line}")
                .and_then(|()| w.flush())
                .map_err(io("write", &path))?;
        }
        self.tasks.insert(task);
        if let Some((kept, _)) = self.kept.as_mut() {
            kept.entry(task).or_insert_with(|| record.clone());
        }
        Ok(())
    }

    /// Mark the study finished.
    ///
    /// # Errors
    /// [`CheckpointError::Io`].
    pub(crate) fn finish(&mut self, fingerprint: &Value) -> Result<(), CheckpointError> {
        if let Some(w) = self.writer.as_mut() {
            let path = self.lock.path().join(self.files.records);
            w.flush().map_err(io("write", &path))?;
        }
        self.write_ledger(fingerprint, true)
    }

    /// Whether the stored study finished.
    ///
    /// # Errors
    /// As the ledger's reading.
    pub(crate) fn finished(&self) -> Result<bool, CheckpointError> {
        Ok(self.ledger()?.is_some_and(|l| l.finished))
    }

    /// Every stored record with its task, in the order of the tasks, read back from the store.
    ///
    /// # Errors
    /// [`CheckpointError::Io`]; [`CheckpointError::Corrupt`] for a damaged line.
    pub(crate) fn records(&mut self) -> Result<Vec<(usize, R)>, CheckpointError> {
        if let Some(w) = self.writer.as_mut() {
            let path = self.lock.path().join(self.files.records);
            w.flush().map_err(io("write", &path))?;
        }
        if let Some((kept, true)) = &self.kept {
            return Ok(kept.iter().map(|(t, r)| (*t, r.clone())).collect());
        }
        let mut records = BTreeMap::new();
        self.read_records(|t, r| {
            records.insert(t, r);
        })?;
        if let Some(k) = self.kept.as_mut() {
            *k = (records.clone(), true);
        }
        Ok(records.into_iter().collect())
    }
}

/// `value` as [`Encoding::Cbor`] text: its CBOR encoding in standard base64 (every f64 bit for
/// bit) — also how a task's input and result travel to and from a Dask worker.
///
/// # Errors
/// The encoder's message.
pub(crate) fn to_cbor_text<T: Serialize + ?Sized>(value: &T) -> Result<String, String> {
    let mut bytes = Vec::new();
    ciborium::into_writer(value, &mut bytes).map_err(|e| e.to_string())?;
    Ok(BASE64.encode(bytes))
}

/// The value of [`to_cbor_text`]'s `text`.
///
/// # Errors
/// The decoder's message (not base64, not CBOR, not a `T`).
pub(crate) fn from_cbor_text<T: DeserializeOwned>(text: &str) -> Result<T, String> {
    let bytes = BASE64.decode(text).map_err(|e| e.to_string())?;
    ciborium::from_reader(bytes.as_slice()).map_err(|e| e.to_string())
}

/// What a study resumed from a [`TaskStore`] skips, read back from it: the tasks stored
/// (`HashSet<usize>`: their records stay in the file, memory does not grow with the study) or
/// the records themselves in the order of the tasks (`Vec<R>`: a study whose later tasks start
/// from the earlier ones' results, as a basin map's passes do).
pub(crate) trait StoredTasks<R>: Sized {
    /// Read from `store`, just opened, whose stored tasks are `tasks`.
    ///
    /// # Errors
    /// As [`TaskStore::records`].
    fn stored(store: &mut TaskStore<'_, R>, tasks: HashSet<usize>)
        -> Result<Self, CheckpointError>;
}

impl<R> StoredTasks<R> for HashSet<usize> {
    fn stored(_: &mut TaskStore<'_, R>, tasks: HashSet<usize>) -> Result<Self, CheckpointError> {
        Ok(tasks)
    }
}

impl<R: Serialize + DeserializeOwned + Clone> StoredTasks<R> for Vec<R> {
    fn stored(store: &mut TaskStore<'_, R>, _: HashSet<usize>) -> Result<Self, CheckpointError> {
        Ok(store.records()?.into_iter().map(|(_, r)| r).collect())
    }
}

impl<R: Serialize + DeserializeOwned + Clone> StoredTasks<R> for super::Prefix<R> {
    fn stored(store: &mut TaskStore<'_, R>, _: HashSet<usize>) -> Result<Self, CheckpointError> {
        Ok(super::Prefix(
            store
                .records()?
                .into_iter()
                .enumerate()
                .take_while(|(k, (task, _))| k == task)
                .map(|(_, (_, r))| r)
                .collect(),
        ))
    }
}

impl<S, R> Store<S> for TaskStore<'_, R>
where
    S: Study<Record = (usize, R)> + ?Sized,
    S::Done: StoredTasks<R>,
    R: Serialize + DeserializeOwned + Clone + Send,
{
    fn open(&mut self, study: &S, resume: bool) -> Result<Opened<S::Done>, CheckpointError> {
        let tasks = TaskStore::open(self, study.fingerprint(), resume)?;
        let finished = resume && self.finished()?;
        let done = S::Done::stored(self, tasks)?;
        // a finished store that lost records (a line removed) runs them again: it loses
        // nothing, where the finished flag alone would hand on an incomplete result
        if finished && study.done_units(&done) >= study.units() {
            return Ok(Opened::Finished);
        }
        Ok(Opened::Run(done))
    }

    fn append(&mut self, (task, record): (usize, R)) -> Result<(), CheckpointError> {
        TaskStore::append(self, task, &record)
    }

    fn finish(&mut self, study: &S) -> Result<(), CheckpointError> {
        TaskStore::finish(self, study.fingerprint())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILES: TaskFiles = TaskFiles {
        ledger: ".t.run.json",
        records: ".t.jsonl",
        key: "lines",
        prefix: "t.",
        encoding: Encoding::Json,
    };

    /// Records read back as stored, in task order; a resume keeps them and names the tasks
    /// done; a cut last line is dropped; a changed line is refused naming its number; another
    /// fingerprint is refused naming the field without the prefix.
    #[test]
    fn records_round_trip_and_resume_only_the_same_study() {
        let dir = std::env::temp_dir().join(format!("afmdyn-task-store-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        let lock = DirLock::acquire(&dir).unwrap();
        let fp = json!({"t": {"n": 3}});
        let mut s: TaskStore<'_, Vec<String>> = TaskStore::new(&lock, FILES);
        assert!(s.open(&fp, false).unwrap().is_empty());
        s.append(2, &vec!["c".into()]).unwrap();
        s.append(0, &vec!["a".into(), "b".into()]).unwrap();
        assert!(!s.finished().unwrap());
        let got = s.records().unwrap();
        assert_eq!(
            got,
            vec![(0, vec!["a".into(), "b".into()]), (2, vec!["c".into()])]
        );
        // a cut last line (a killed run) is dropped on resume
        let path = dir.join(FILES.records);
        let mut text = fs::read_to_string(&path).unwrap();
        text.push_str("{\"lines\":[\"d\"],\"task\":1");
        fs::write(&path, &text).unwrap();
        let mut r: TaskStore<'_, Vec<String>> = TaskStore::new(&lock, FILES);
        let done = r.open(&fp, true).unwrap();
        assert_eq!(done, HashSet::from([0, 2]));
        r.finish(&fp).unwrap();
        assert!(r.finished().unwrap());
        // another request: refused naming the field (prefix left out)
        let err = r.open(&json!({"t": {"n": 4}}), true).unwrap_err();
        assert_eq!(
            err,
            CheckpointError::Mismatch {
                field: "n".into(),
                then: "3".into(),
                now: "4".into()
            }
        );
        // a changed line: refused naming it
        let text = fs::read_to_string(&path).unwrap().replace("\"c\"", "\"x\"");
        fs::write(&path, text).unwrap();
        let err = r.records().unwrap_err();
        assert!(
            matches!(&err, CheckpointError::Corrupt { message, .. } if message.starts_with("line 1: checksum")),
            "{err}"
        );
        drop(lock);
        fs::remove_dir_all(&dir).unwrap();
    }

    /// A CBOR store keeps every float bit for bit, NaN and ±∞ included (which JSON cannot),
    /// and a resume reads the records back.
    #[test]
    fn cbor_records_keep_non_finite_floats_bit_for_bit() {
        let dir = std::env::temp_dir().join(format!("afmdyn-task-cbor-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        let lock = DirLock::acquire(&dir).unwrap();
        let files = TaskFiles {
            encoding: Encoding::Cbor,
            ..FILES
        };
        let fp = json!({"t": 1});
        let record = vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -0.0,
            0.1 + 0.2,
            5e-324,
        ];
        let mut s: TaskStore<'_, Vec<f64>> = TaskStore::new(&lock, files);
        s.open(&fp, false).unwrap();
        s.append(0, &record).unwrap();
        let mut r: TaskStore<'_, Vec<f64>> = TaskStore::new(&lock, files);
        r.open(&fp, true).unwrap();
        let back = r.records().unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(back.len(), 1);
        assert_eq!(bits(&back[0].1), bits(&record));
        drop(lock);
        fs::remove_dir_all(&dir).unwrap();
    }

    /// A keeping store hands back the records the file holds (what a store that reads the file
    /// gives), on a new run and after a resume, without a second copy of any task.
    #[test]
    fn a_keeping_store_hands_back_what_the_file_holds() {
        let dir = std::env::temp_dir().join(format!("afmdyn-task-keep-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        let lock = DirLock::acquire(&dir).unwrap();
        let fp = json!({"t": 2});
        let mut s: TaskStore<'_, Vec<String>> = TaskStore::new(&lock, FILES).keeping();
        s.open(&fp, false).unwrap();
        s.append(1, &vec!["b".into()]).unwrap();
        s.append(0, &vec!["a".into()]).unwrap();
        let reading = |lock| -> Vec<(usize, Vec<String>)> {
            let mut r: TaskStore<'_, Vec<String>> = TaskStore::new(lock, FILES);
            r.records().unwrap()
        };
        assert_eq!(s.records().unwrap(), reading(&lock));
        let mut again: TaskStore<'_, Vec<String>> = TaskStore::new(&lock, FILES).keeping();
        again.open(&fp, true).unwrap();
        again.append(2, &vec!["c".into()]).unwrap();
        let got = again.records().unwrap();
        assert_eq!(got.len(), 3);
        assert_eq!(got, reading(&lock));
        drop(lock);
        fs::remove_dir_all(&dir).unwrap();
    }
}
