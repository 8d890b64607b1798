//! A study's resumable store of tasks (feature `files`): [`TaskStore`], a directory locked by
//! [`DirLock`] holding a ledger and a records file, the records written as a [`Codec`] says.
//!
//! - the ledger: `{"args": fingerprint, "finished": bool}` (and `"format": 2` for the JSON
//!   lines), written atomically;
//! - the records, appended and flushed as each task finishes, so that a killed run leaves at
//!   most a cut last record, dropped on resume. [`Lines`]: one line per finished task (the
//!   chart's `.chart.tiles.jsonl`: `{"cells": record, "task": t, "crc32": "89abcdef"}`, the
//!   record under the study's key, as JSON or, for records whose floats may be NaN or ±∞,
//!   which JSON cannot hold, as a string of its CBOR encoding in base64 — [`Encoding`]).
//!   `crc32` is the CRC-32 (zlib's) of the line's text before `,"crc32":`, 8 lowercase hex
//!   digits. A bifurcation sweep's codec (`super::sweep::SweepRows`) writes its checkpoint's
//!   CSV rows instead, each sealed by the same checksum, and puts them in the one order in
//!   `bifurcation.csv` when the sweep finishes.
//!
//! Reading the records (a resume, the files written from the store) refuses, naming the file
//! and the line, a complete record whose checksum does not match or that cannot be read — a
//! damaged store never becomes a result. A store written by an earlier version, without
//! checksums, is refused too (rerun without resuming).
//!
//! A resumed study computes only the tasks not stored, and only for the request that made the
//! store (its fingerprint); a finished one computes nothing. The command line's
//! `afmdyn chart --out DIR` keeps its store there ([`super::chart_store`]); the files
//! a user reads (`chart.csv`, `chart.nc`, the maps) are written from it.

use crate::io::dir_lock::DirLock;
use crate::io::input::InputKind;
use crate::study::checkpoint::{same_request, CheckpointError, Ledger};
use crate::study::checkpoint_file::{crc_hex, io, open_store, read_failed, read_ledger};
use crate::study::checkpoint_file::{write_atomic, START_OVER};
use base64::engine::general_purpose::STANDARD as BASE64;
use base64::Engine;
use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_json::{json, Value};
use std::fs::{self, File, OpenOptions};
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::marker::PhantomData;
use std::path::{Path, PathBuf};

use super::{Opened, Resumes, Store, Study};

/// The JSON lines' layout (the ledger's `format`): 2 since the lines carry checksums.
pub(crate) const FORMAT: u64 = 2;
/// What ends a record's line before its checksum.
const CRC_KEY: &str = ",\"crc32\":\"";

/// The files of a store and how its ledger reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Layout {
    /// The ledger's file name.
    pub ledger: &'static str,
    /// The records' file name.
    pub records: &'static str,
    /// The prefix of the fingerprint's fields that a mismatch's message leaves out
    /// (`"chart."`), if any.
    pub prefix: &'static str,
    /// The ledger's `format`: a ledger without it, beside records, was written by an earlier
    /// version and is refused (`None`: the ledger has no `format`).
    pub format: Option<u64>,
    /// The file the finished records are put in, when the records file is removed as the
    /// study finishes (`None`: the records file stays).
    pub finished: Option<&'static str>,
    /// Whether a message names the ledger by its path (else by its file name).
    pub ledger_by_path: bool,
}

/// How a [`TaskStore`] writes and reads its records.
pub(crate) trait Codec {
    /// One finished task, as the store keeps it.
    type Record;
    /// The store's files.
    fn layout(&self) -> Layout;
    /// The first line of a new records file, if any.
    fn header(&self) -> Option<String> {
        None
    }
    /// `record` as the records file holds it: its lines, each with its newline.
    ///
    /// # Errors
    /// The encoder's message.
    fn encode(&self, record: &Self::Record) -> Result<String, String>;
    /// Every complete record of the records file `path` handed to `each`, in file order, the
    /// file cut back to them so that appends follow a whole record.
    ///
    /// # Errors
    /// [`CheckpointError::Corrupt`] naming the line that is not as written;
    /// [`CheckpointError::Io`].
    fn read(&self, path: &Path, each: &mut dyn FnMut(Self::Record)) -> Result<(), CheckpointError>;
    /// Put the records of the finished study in the store's directory `dir` where its reader
    /// finds them (nothing by default).
    ///
    /// # Errors
    /// [`CheckpointError::Io`], and as [`Codec::read`].
    fn finish(&self, _dir: &Path) -> Result<(), CheckpointError> {
        Ok(())
    }
}

/// A study's store of its records in the directory its lock holds, written by the codec `C`.
#[derive(Debug)]
pub(crate) struct TaskStore<'a, C: Codec> {
    codec: C,
    lock: &'a DirLock,
    writer: Option<BufWriter<File>>,
    /// With [`TaskStore::keeping`]: a copy of the stored records (in the order stored), and
    /// whether it holds every one (after a new run's start, or once a resume read them).
    kept: Option<(Vec<C::Record>, bool)>,
}

impl<'a, C: Codec> TaskStore<'a, C> {
    /// The store of the directory `lock` holds, written by `codec`.
    pub(crate) fn new(lock: &'a DirLock, codec: C) -> TaskStore<'a, C> {
        TaskStore {
            codec,
            lock,
            writer: None,
            kept: None,
        }
    }

    /// The store keeping a copy of its records in memory, so that its records are handed back
    /// without reading and decoding the file again — for a study whose records a resume reads
    /// anyway (a chain's), not for one whose records must stay on disk.
    pub(crate) fn keeping(mut self) -> TaskStore<'a, C> {
        self.kept = Some((Vec::new(), false));
        self
    }

    /// The store's directory.
    pub(crate) fn dir(&self) -> &Path {
        self.lock.path()
    }

    fn path(&self, name: &str) -> PathBuf {
        self.lock.path().join(name)
    }

    fn ledger(&self) -> Result<Option<Ledger>, CheckpointError> {
        let layout = self.codec.layout();
        let Some(v) = read_ledger(&self.path(layout.ledger))? else {
            return Ok(None);
        };
        let records = self.path(layout.records);
        if let Some(format) = layout.format {
            if v.get("format").and_then(Value::as_u64) != Some(format) && records.exists() {
                return Err(CheckpointError::Corrupt {
                    path: records.display().to_string(),
                    message: format!(
                        "written by an earlier version of afmdyn (its lines carry no \
                         checksums); {START_OVER}"
                    ),
                });
            }
        }
        Ok(Some(Ledger {
            fingerprint: v.get("args").cloned().unwrap_or(Value::Null),
            finished: v.get("finished").and_then(Value::as_bool).unwrap_or(false),
        }))
    }

    fn write_ledger(&self, fingerprint: &Value, finished: bool) -> Result<(), CheckpointError> {
        let layout = self.codec.layout();
        let mut doc = json!({"args": fingerprint, "finished": finished});
        if let Some(format) = layout.format {
            doc["format"] = json!(format);
        }
        write_atomic(&self.path(layout.ledger), format!("{doc:#}\n").as_bytes())
    }

    /// Open the store for the study of `fingerprint`. Without `resume` a new study begins (the
    /// stored records are dropped). With `resume`: an empty store begins; a store of another
    /// request is refused; otherwise what is done is gathered from the stored records — and
    /// when the ledger says finished and `complete(done)` ([`Opened::Finished`]: a finished
    /// store that lost a record runs it again), or the finished records were moved out of the
    /// records file ([`Layout::finished`]), nothing is left to do.
    ///
    /// # Errors
    /// [`CheckpointError::Mismatch`] naming the first field that differs,
    /// [`CheckpointError::Unrecorded`] for records without a ledger, and the files' errors.
    pub(crate) fn open<D: Resumes<C::Record>>(
        &mut self,
        fingerprint: &Value,
        resume: bool,
        complete: impl Fn(&D) -> bool,
    ) -> Result<Opened<D>, CheckpointError> {
        self.writer = None;
        let layout = self.codec.layout();
        let records = self.path(layout.records);
        let finished_file = layout.finished.map(|f| self.path(f));
        if resume {
            match self.ledger()? {
                None if records.exists() || finished_file.as_ref().is_some_and(|f| f.exists()) => {
                    let ledger = self.path(layout.ledger);
                    return Err(CheckpointError::Unrecorded {
                        store: self.dir().display().to_string(),
                        ledger: match layout.ledger_by_path {
                            true => ledger.display().to_string(),
                            false => layout.ledger.into(),
                        },
                    });
                }
                None => {}
                Some(ledger) if records.exists() => {
                    same_request(&ledger.fingerprint, fingerprint, layout.prefix)?;
                    let (mut gathered, mut kept) = (D::Gathered::default(), Vec::new());
                    let keep = self.kept.is_some();
                    self.codec.read(&records, &mut |r| {
                        D::gather(&mut gathered, &r);
                        if keep {
                            kept.push(r);
                        }
                    })?;
                    if let Some(k) = self.kept.as_mut() {
                        *k = (kept, true);
                    }
                    let done = D::done(gathered);
                    if ledger.finished && complete(&done) {
                        return Ok(Opened::Finished);
                    }
                    return Ok(Opened::Run(done));
                }
                Some(ledger) => {
                    same_request(&ledger.fingerprint, fingerprint, layout.prefix)?;
                    if ledger.finished && finished_file.is_some_and(|f| f.exists()) {
                        return Ok(Opened::Finished);
                    }
                }
            }
        }
        // a new run: the old records go first, then the ledger names it
        match fs::remove_file(&records) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(io("remove", &records)(e)),
        }
        if let Some(k) = self.kept.as_mut() {
            *k = (Vec::new(), true);
        }
        self.write_ledger(fingerprint, false)?;
        let mut w = self.writer()?;
        if let Some(header) = self.codec.header() {
            writeln!(w, "{header}")
                .and_then(|()| w.flush())
                .map_err(io("write", &records))?;
        }
        self.writer = Some(w);
        Ok(Opened::Run(D::done(Default::default())))
    }

    /// The records file opened for appending (created if missing).
    fn writer(&self) -> Result<BufWriter<File>, CheckpointError> {
        let path = self.path(self.codec.layout().records);
        let f = OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(io("write", &path))?;
        Ok(BufWriter::new(f))
    }

    /// Store the record of a finished task (flushed at once).
    ///
    /// # Errors
    /// [`CheckpointError::Io`].
    pub(crate) fn append(&mut self, record: C::Record) -> Result<(), CheckpointError> {
        let path = self.path(self.codec.layout().records);
        let text = self
            .codec
            .encode(&record)
            .map_err(|message| CheckpointError::Io {
                action: "write",
                path: path.display().to_string(),
                message,
            })?;
        if self.writer.is_none() {
            self.writer = Some(self.writer()?);
        }
        if let Some(w) = self.writer.as_mut() {
            w.write_all(text.as_bytes())
                .and_then(|()| w.flush())
                .map_err(io("write", &path))?;
        }
        if let Some((kept, _)) = self.kept.as_mut() {
            kept.push(record);
        }
        Ok(())
    }

    fn flush(&mut self) -> Result<(), CheckpointError> {
        if let Some(mut w) = self.writer.take() {
            let path = self.path(self.codec.layout().records);
            w.flush().map_err(io("write", &path))?;
        }
        Ok(())
    }

    /// Mark the study of `fingerprint` finished, its records where the codec puts them.
    ///
    /// # Errors
    /// [`CheckpointError::Io`], and the codec's.
    pub(crate) fn finish(&mut self, fingerprint: &Value) -> Result<(), CheckpointError> {
        self.flush()?;
        self.codec.finish(self.lock.path())?;
        self.write_ledger(fingerprint, true)
    }

    /// Every stored record in the order stored, read back from the store (or its copy).
    ///
    /// # Errors
    /// As [`Codec::read`].
    pub(crate) fn stored(&mut self) -> Result<Vec<C::Record>, CheckpointError>
    where
        C::Record: Clone,
    {
        self.flush()?;
        if let Some((kept, true)) = &self.kept {
            return Ok(kept.clone());
        }
        let mut records = Vec::new();
        let path = self.path(self.codec.layout().records);
        if path.exists() {
            self.codec.read(&path, &mut |r| records.push(r))?;
        }
        if let Some(k) = self.kept.as_mut() {
            *k = (records.clone(), true);
        }
        Ok(records)
    }
}

/// The files and keys of one kind of study's JSON lines ([`Lines`]).
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

/// The JSON-lines codec: numbered records `R`, one checksummed line per task, in the files
/// of [`TaskFiles`] (see the module doc).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lines<R> {
    files: TaskFiles,
    record: PhantomData<fn() -> R>,
}

impl<R> Lines<R> {
    /// The codec of `files`.
    pub(crate) const fn of(files: TaskFiles) -> Lines<R> {
        Lines {
            files,
            record: PhantomData,
        }
    }

    /// A line's task and record.
    fn parse(&self, text: &str) -> Result<(usize, R), String>
    where
        R: DeserializeOwned,
    {
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
}

impl<R: Serialize + DeserializeOwned> Codec for Lines<R> {
    type Record = (usize, R);

    fn layout(&self) -> Layout {
        Layout {
            ledger: self.files.ledger,
            records: self.files.records,
            prefix: self.files.prefix,
            format: Some(FORMAT),
            finished: None,
            ledger_by_path: false,
        }
    }

    fn encode(&self, (task, record): &(usize, R)) -> Result<String, String> {
        let mut line = serde_json::Map::new();
        line.insert("task".into(), json!(task));
        let record = match self.files.encoding {
            Encoding::Json => serde_json::to_value(record).map_err(|e| e.to_string())?,
            Encoding::Cbor => Value::String(to_cbor_text(record)?),
        };
        line.insert(self.files.key.into(), record);
        let line = Value::Object(line).to_string();
        // the object without its closing brace, then the checksum of that text
        let body = &line[..line.len() - 1];
        Ok(format!("{body}{CRC_KEY}{}\"}}\n", crc_hex(body)))
    }

    /// Every complete line (a cut last line is dropped, and the file cut back to the complete
    /// lines).
    fn read(&self, path: &Path, each: &mut dyn FnMut((usize, R))) -> Result<(), CheckpointError> {
        let Some(file) = open_store(path, InputKind::StoreRecords)? else {
            return Ok(());
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
                .map_err(|e| read_failed(path, e))?;
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
            let record = self
                .parse(&text)
                .map_err(|e| damaged(number, format!("cannot be read ({e})")))?;
            each(record);
            good += n as u64;
        }
        let f = OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(io("write", path))?;
        if f.metadata().map_err(io("read", path))?.len() != good {
            f.set_len(good).map_err(io("write", path))?;
        }
        Ok(())
    }
}

impl<R: Serialize + DeserializeOwned + Clone> TaskStore<'_, Lines<R>> {
    /// Every stored record with its task, in the order of the tasks (a task stored twice: its
    /// first record), read back from the store.
    ///
    /// # Errors
    /// [`CheckpointError::Io`]; [`CheckpointError::Corrupt`] for a damaged line.
    pub(crate) fn records(&mut self) -> Result<Vec<(usize, R)>, CheckpointError> {
        let mut records = self.stored()?;
        records.sort_by_key(|(t, _)| *t);
        records.dedup_by_key(|(t, _)| *t);
        Ok(records)
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

impl<S, C> Store<S> for TaskStore<'_, C>
where
    S: Study<Record = C::Record> + ?Sized,
    S::Done: Resumes<C::Record>,
    C: Codec + Send,
    C::Record: Send,
{
    fn open(&mut self, study: &S, resume: bool) -> Result<Opened<S::Done>, CheckpointError> {
        // a finished store that lost records (a line removed) runs them again: it loses
        // nothing, where the finished flag alone would hand on an incomplete result
        TaskStore::open(self, study.fingerprint(), resume, |done| {
            study.done_units(done) >= study.units()
        })
    }

    fn append(&mut self, record: C::Record) -> Result<(), CheckpointError> {
        TaskStore::append(self, record)
    }

    fn finish(&mut self, study: &S) -> Result<(), CheckpointError> {
        TaskStore::finish(self, study.fingerprint())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    /// Open `s` for `fp`: the tasks stored.
    fn open<R: Serialize + DeserializeOwned>(
        s: &mut TaskStore<'_, Lines<R>>,
        fp: &Value,
        resume: bool,
    ) -> Result<HashSet<usize>, CheckpointError> {
        match s.open(fp, resume, |_| false)? {
            Opened::Run(done) => Ok(done),
            Opened::Finished => Ok(HashSet::new()),
        }
    }

    /// Whether the stored study finished.
    fn finished<R: Serialize + DeserializeOwned>(s: &TaskStore<'_, Lines<R>>) -> bool {
        s.ledger().unwrap().is_some_and(|l| l.finished)
    }

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
        let mut s: TaskStore<'_, Lines<Vec<String>>> = TaskStore::new(&lock, Lines::of(FILES));
        assert!(open(&mut s, &fp, false).unwrap().is_empty());
        s.append((2, vec!["c".into()])).unwrap();
        s.append((0, vec!["a".into(), "b".into()])).unwrap();
        assert!(!finished(&s));
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
        let mut r: TaskStore<'_, Lines<Vec<String>>> = TaskStore::new(&lock, Lines::of(FILES));
        let done = open(&mut r, &fp, true).unwrap();
        assert_eq!(done, HashSet::from([0, 2]));
        r.finish(&fp).unwrap();
        assert!(finished(&r));
        // another request: refused naming the field (prefix left out)
        let err = open(&mut r, &json!({"t": {"n": 4}}), true).unwrap_err();
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
        let mut s: TaskStore<'_, Lines<Vec<f64>>> = TaskStore::new(&lock, Lines::of(files));
        open(&mut s, &fp, false).unwrap();
        s.append((0, record.clone())).unwrap();
        let mut r: TaskStore<'_, Lines<Vec<f64>>> = TaskStore::new(&lock, Lines::of(files));
        open(&mut r, &fp, true).unwrap();
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
        let mut s: TaskStore<'_, Lines<Vec<String>>> =
            TaskStore::new(&lock, Lines::of(FILES)).keeping();
        open(&mut s, &fp, false).unwrap();
        s.append((1, vec!["b".into()])).unwrap();
        s.append((0, vec!["a".into()])).unwrap();
        let reading = |lock| -> Vec<(usize, Vec<String>)> {
            let mut r: TaskStore<'_, Lines<Vec<String>>> = TaskStore::new(lock, Lines::of(FILES));
            r.records().unwrap()
        };
        assert_eq!(s.records().unwrap(), reading(&lock));
        let mut again: TaskStore<'_, Lines<Vec<String>>> =
            TaskStore::new(&lock, Lines::of(FILES)).keeping();
        open(&mut again, &fp, true).unwrap();
        again.append((2, vec!["c".into()])).unwrap();
        let got = again.records().unwrap();
        assert_eq!(got.len(), 3);
        assert_eq!(got, reading(&lock));
        drop(lock);
        fs::remove_dir_all(&dir).unwrap();
    }
}
