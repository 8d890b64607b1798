//! The one bounded reader of input files: every file a front end names (a probe, a config, a
//! sample map and its height map, an overlay, a curve to invert, a store read back) is read
//! here, with a cap per [`InputKind`]. A regular file larger than its cap is refused from its
//! length before any of it is read; anything else (`/dev/zero`, a pipe) is read through
//! `Read::take(cap + 1)` and refused once it passes the cap, a kind read line by line also once
//! a line passes its `InputKind::line_cap` (a CSV parser holds a line whole), and a store's
//! file at its first NUL byte (`InputKind::refuses_nul`: `/dev/zero` and a sparse file are
//! refused at once, before any memory is taken). Every refusal names the file, the cap and the
//! kind.

#[cfg(feature = "files")]
use std::io::Read;

/// Largest text input file (a probe file, a `--config` file) read, in bytes: 1 MiB, a
/// thousand times a probe file; larger input (`/dev/zero`) is refused after reading this much.
pub const MAX_INPUT_TEXT_BYTES: u64 = 1024 * 1024;
/// Largest CSV input file (`afmdyn continue --overlay bifurcation.csv`) read, in bytes:
/// 256 MiB, about a million rows of a bifurcation sweep.
pub const MAX_INPUT_CSV_BYTES: u64 = 256 * 1024 * 1024;
/// Largest JSON document read back (`afmdyn reconstruct --fm fm.json`, `--am approach.json`), in
/// bytes: 256 MiB, parsed as it is read (never held as text).
pub const MAX_INPUT_DOCUMENT_BYTES: u64 = 256 * 1024 * 1024;
/// Largest file of records of a store read back (`--resume`: a sweep's partial and finished
/// CSV, a study's records), in bytes: 128 GiB, above the largest store a request may make — a
/// sweep of [`crate::analysis::bifurcation::MAX_SWEEP_POINTS`] (10⁶) points of up to
/// [`crate::analysis::period::MAX_PERIOD`] (64) rows of at most 2 KiB (a 20-mode state in full
/// precision) is 128 GiB at most, a chart of 10⁶ cells with 64 attractors of 2 KiB 128 GiB.
/// Stores are streamed line by line, never held whole.
pub const MAX_STORE_BYTES: u64 = 128 * 1024 * 1024 * 1024;
/// Largest line of a study's records (`.chart.tiles.jsonl`, `.image.lines.jsonl`, …), in
/// bytes: 1 GiB, above the largest record — a chart tile of
/// [`crate::request::chart::MAX_CHART_TILE`] (10⁴) cells with
/// [`crate::request::chart::MAX_CHART_SLOTS`] (64) attractors of at most 1.5 KiB of JSON each,
/// 0.9 GiB (a PI scan's line of 2 × 4096 pixels takes a few MiB).
#[cfg(feature = "files")]
pub(crate) const MAX_STORE_LINE_BYTES: u64 = 1024 * 1024 * 1024;
/// Largest ledger of a store read back (`.bifurcation.run.json`, `.chart.run.json`, …), in
/// bytes: 513 MiB, the largest fingerprint a request stores — a PI scan's holds its sample map,
/// whose height map of 4096 × 4096 values takes at most the 512 MiB of its CSV
/// ([`super::caps::MAX_CSV_BYTES`]), and 1 MiB ([`MAX_INPUT_TEXT_BYTES`]) for the probe and
/// the request. Parsed as it is read (never held as text).
pub const MAX_LEDGER_BYTES: u64 = super::caps::MAX_CSV_BYTES + MAX_INPUT_TEXT_BYTES;
/// Largest lock file of a store read (its holder's process id, when a run finds the store
/// locked), in bytes: 4 KiB (the lock holds one short line, `12345 afmdyn`).
pub const MAX_LOCK_BYTES: u64 = 4096;
/// Longest line of a CSV input, in bytes: 1 MiB, eight times a row of 4096 full-precision
/// heights; a CSV parser holds a line whole, so a file without line ends (`/dev/zero`) is
/// refused after this much.
pub const MAX_CSV_LINE_BYTES: u64 = 1024 * 1024;

/// What an input file is, and so its cap ([`InputKind::cap`]) and the name its refusals give it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// A probe file (TOML; `--probe`, Python's `probe=path`).
    Probe,
    /// A `--config` file (TOML).
    Config,
    /// A sample map (TOML; `afmdyn image --sample`, Python's `sample=path`).
    SampleMap,
    /// A bifurcation CSV drawn over a continuation (`afmdyn continue --overlay`).
    Overlay,
    /// A sample map's height map CSV (`height_map = "h.csv"`).
    HeightMapCsv,
    /// A sample map's height map NPY (`height_map = "h.npy"`).
    HeightMapNpy,
    /// A frequency-shift curve CSV (`afmdyn reconstruct --fm curve.csv`).
    CurveCsv,
    /// A curve's JSON document (`afmdyn reconstruct --fm fm.json`, `--am approach.json`).
    CurveDocument,
    /// A force map (`afmdyn fit-map --data map.csv`, a long-format CSV, or the NetCDF file
    /// `afmdyn.export_map` writes): streamed, so its cap is a store's.
    ForceMap,
    /// A CSV file of a sweep's store read back (`--resume`: `.bifurcation.partial.csv`, and
    /// `bifurcation.csv` when the sweep finished).
    Store,
    /// A study's records read back (`--resume`: `.chart.tiles.jsonl`, `.image.lines.jsonl`,
    /// …: one JSON line per finished task).
    StoreRecords,
    /// A store's ledger read back (`--resume`: `.bifurcation.run.json`, `.chart.run.json`,
    /// …: the fingerprint of the request that made the store).
    StoreLedger,
    /// A store's lock file, read for the process holding it.
    Lock,
}

impl InputKind {
    /// The largest file of this kind read, in bytes.
    pub const fn cap(self) -> u64 {
        match self {
            InputKind::Probe | InputKind::Config | InputKind::SampleMap => MAX_INPUT_TEXT_BYTES,
            InputKind::Overlay | InputKind::CurveCsv => MAX_INPUT_CSV_BYTES,
            InputKind::HeightMapCsv => super::caps::MAX_CSV_BYTES,
            InputKind::HeightMapNpy => super::caps::MAX_NPY_BYTES,
            InputKind::CurveDocument => MAX_INPUT_DOCUMENT_BYTES,
            InputKind::Store | InputKind::StoreRecords | InputKind::ForceMap => MAX_STORE_BYTES,
            InputKind::StoreLedger => MAX_LEDGER_BYTES,
            InputKind::Lock => MAX_LOCK_BYTES,
        }
    }

    /// The longest line read, in bytes, for a kind read line by line (CSV:
    /// [`MAX_CSV_LINE_BYTES`]; a study's records: [`MAX_STORE_LINE_BYTES`]).
    #[cfg(feature = "files")]
    pub(crate) const fn line_cap(self) -> Option<u64> {
        match self {
            InputKind::Overlay
            | InputKind::HeightMapCsv
            | InputKind::CurveCsv
            | InputKind::ForceMap
            | InputKind::Store => Some(MAX_CSV_LINE_BYTES),
            InputKind::StoreRecords => Some(MAX_STORE_LINE_BYTES),
            _ => None,
        }
    }

    /// Whether a NUL byte refuses the file at once: a store afmdyn wrote is text (CSV, JSON)
    /// and never holds one, while `/dev/zero` and a sparse file are nothing else.
    #[cfg(feature = "files")]
    pub(crate) const fn refuses_nul(self) -> bool {
        matches!(
            self,
            InputKind::Store | InputKind::StoreRecords | InputKind::StoreLedger | InputKind::Lock
        )
    }

    /// The kind as its refusals name it ("a probe file").
    pub const fn name(self) -> &'static str {
        match self {
            InputKind::Probe => "a probe file",
            InputKind::Config => "a config file",
            InputKind::SampleMap => "a sample map",
            InputKind::Overlay => "an overlay CSV",
            InputKind::HeightMapCsv => "a height map CSV",
            InputKind::HeightMapNpy => "a height map NPY",
            InputKind::CurveCsv => "a curve CSV",
            InputKind::CurveDocument => "a curve document",
            InputKind::ForceMap => "a force map",
            InputKind::Store => "a store's CSV",
            InputKind::StoreRecords => "a store's records",
            InputKind::StoreLedger => "a store's ledger",
            InputKind::Lock => "a store's lock",
        }
    }
}

/// An input file opened by [`open`]: its bytes, at most the kind's cap (and, for kinds read
/// line by line, lines of at most `InputKind::line_cap`; for a store, no NUL byte:
/// `InputKind::refuses_nul`); past either, a read fails with an
/// [`std::io::Error`] carrying the [`InputFileError`] ([`refusal`] finds it).
#[cfg(feature = "files")]
#[derive(Debug)]
pub struct Bounded {
    file: std::io::Take<std::fs::File>,
    path: String,
    kind: InputKind,
    read: u64,
    line: u64,
}

#[cfg(feature = "files")]
impl Bounded {
    /// The bounded read of `file`, opened from `path` (which the refusals name) as `kind`; a
    /// caller that opens the file itself checks its length first, as [`open`] does.
    pub(crate) fn new(file: std::fs::File, path: &std::path::Path, kind: InputKind) -> Bounded {
        Bounded {
            file: file.take(kind.cap() + 1),
            path: path.display().to_string(),
            kind,
            read: 0,
            line: 0,
        }
    }
}

#[cfg(feature = "files")]
impl Read for Bounded {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.file.read(buf)?;
        self.read += n as u64;
        let cap = self.kind.cap();
        if self.read > cap {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                InputFileError::TooLarge {
                    path: self.path.clone(),
                    limit: cap,
                    kind: self.kind.name(),
                },
            ));
        }
        if self.kind.refuses_nul() {
            if let Some(at) = buf[..n].iter().position(|&b| b == 0) {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    InputFileError::Binary {
                        path: self.path.clone(),
                        offset: self.read - n as u64 + at as u64,
                        limit: cap,
                        kind: self.kind.name(),
                    },
                ));
            }
        }
        if let Some(limit) = self.kind.line_cap() {
            for &b in &buf[..n] {
                self.line = if b == b'\n' { 0 } else { self.line + 1 };
                if self.line > limit {
                    return Err(std::io::Error::new(
                        std::io::ErrorKind::InvalidData,
                        InputFileError::LineTooLong {
                            path: self.path.clone(),
                            limit,
                            kind: self.kind.name(),
                        },
                    ));
                }
            }
        }
        Ok(n)
    }
}

/// The refusal of a [`Bounded`] read inside an I/O error, if it is one.
pub fn refusal(e: &std::io::Error) -> Option<&InputFileError> {
    e.get_ref()
        .and_then(|inner| inner.downcast_ref::<InputFileError>())
}

/// Open the input file `path` of kind `kind` for a bounded read ([`Bounded`]): a regular file
/// larger than the kind's cap is refused here, before any of it is read.
///
/// # Errors
/// [`InputFileError::Io`] when it cannot be opened, [`InputFileError::TooLarge`] when it is a
/// regular file larger than the cap.
#[cfg(feature = "files")]
pub fn open(path: &std::path::Path, kind: InputKind) -> Result<Bounded, InputFileError> {
    let name = || path.display().to_string();
    let io = |e: std::io::Error| InputFileError::Io {
        path: name(),
        message: crate::error::io_message(&e),
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let cap = kind.cap();
    if let Ok(m) = file.metadata() {
        if m.is_file() && m.len() > cap {
            return Err(InputFileError::TooLarge {
                path: name(),
                limit: cap,
                kind: kind.name(),
            });
        }
    }
    Ok(Bounded::new(file, path, kind))
}

/// [`open`], or `None` when `path` does not exist (a store's file not yet written).
///
/// # Errors
/// As [`open`].
#[cfg(feature = "files")]
pub fn open_existing(
    path: &std::path::Path,
    kind: InputKind,
) -> Result<Option<Bounded>, InputFileError> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        _ => open(path, kind).map(Some),
    }
}

/// The bytes of the input file `path` of kind `kind`, at most its cap ([`open`]).
///
/// # Errors
/// As [`open`]; [`InputFileError::TooLarge`] when more than the cap is read.
#[cfg(feature = "files")]
pub fn read_bytes(path: &std::path::Path, kind: InputKind) -> Result<Vec<u8>, InputFileError> {
    let mut file = open(path, kind)?;
    let mut bytes = Vec::new();
    file.read_to_end(&mut bytes)
        .map_err(|e| match refusal(&e) {
            Some(r) => r.clone(),
            None => InputFileError::Io {
                path: path.display().to_string(),
                message: crate::error::io_message(&e),
            },
        })?;
    Ok(bytes)
}

/// The UTF-8 text of the input file `path` of kind `kind`, at most its cap ([`read_bytes`]).
///
/// # Errors
/// As [`read_bytes`]; [`InputFileError::NotText`] when it is not UTF-8.
#[cfg(feature = "files")]
pub fn read_text(path: &std::path::Path, kind: InputKind) -> Result<String, InputFileError> {
    let bytes = read_bytes(path, kind)?;
    String::from_utf8(bytes).map_err(|e| InputFileError::NotText {
        path: path.display().to_string(),
        offset: e.utf8_error().valid_up_to(),
    })
}

/// The text of the input file `path`, read with at most `limit` bytes kept in memory (a
/// regular file larger is refused from its length)
/// ([`MAX_INPUT_TEXT_BYTES`], [`MAX_INPUT_CSV_BYTES`]; `Read::take`, so `/dev/zero` is refused
/// after `limit` bytes, not read on).
///
/// # Errors
/// [`InputFileError`] naming the file: unreadable, larger than `limit`, or not UTF-8 text.
#[cfg(feature = "files")]
pub fn read_input(path: &std::path::Path, limit: u64) -> Result<String, InputFileError> {
    use std::io::Read;
    let name = || path.display().to_string();
    let io = |e: std::io::Error| InputFileError::Io {
        path: name(),
        message: crate::error::io_message(&e),
    };
    let file = std::fs::File::open(path).map_err(io)?;
    if let Ok(m) = file.metadata() {
        if m.is_file() && m.len() > limit {
            return Err(InputFileError::TooLarge {
                path: name(),
                limit,
                kind: "this input",
            });
        }
    }
    let mut bytes = Vec::new();
    file.take(limit + 1).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > limit {
        return Err(InputFileError::TooLarge {
            path: name(),
            limit,
            kind: "this input",
        });
    }
    String::from_utf8(bytes).map_err(|e| InputFileError::NotText {
        path: name(),
        offset: e.utf8_error().valid_up_to(),
    })
}

/// An input file that cannot be used ([`read_input`]); every message names the file.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InputFileError {
    /// The file cannot be opened or read.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// The operating system's reason.
        message: String,
    },
    /// The file is larger than the limit.
    #[error("{path}: larger than {limit} bytes, the limit of {kind} (is it the right file?)")]
    TooLarge {
        /// The file.
        path: String,
        /// The limit in bytes.
        limit: u64,
        /// What the file was read as ([`InputKind::name`], or "this input").
        kind: &'static str,
    },
    /// A line of a file read line by line is longer than its kind's `InputKind::line_cap`.
    #[error(
        "{path}: larger than {limit} bytes in one line, the line limit of {kind} (is it the right \
         file?)"
    )]
    LineTooLong {
        /// The file.
        path: String,
        /// The limit in bytes.
        limit: u64,
        /// What the file was read as ([`InputKind::name`]).
        kind: &'static str,
    },
    /// A store's file holds a NUL byte (`InputKind::refuses_nul`): it is not what afmdyn
    /// wrote (`/dev/zero`, a sparse or binary file).
    #[error(
        "{path}: a NUL byte after {offset} bytes: not {kind} (text of at most {limit} bytes; is \
         it the right file?)"
    )]
    Binary {
        /// The file.
        path: String,
        /// Bytes before the NUL byte.
        offset: u64,
        /// The kind's cap in bytes.
        limit: u64,
        /// What the file was read as ([`InputKind::name`]).
        kind: &'static str,
    },
    /// The file's content is not what its kind holds (a curve CSV's field that is not a
    /// number, a curve document that is not JSON).
    #[error("{path}: {message}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong with it.
        message: String,
    },
    /// The file is not UTF-8 text.
    #[error("{path}: not UTF-8 text (invalid byte after {offset} bytes)")]
    NotText {
        /// The file.
        path: String,
        /// Bytes of valid text before the first invalid one.
        offset: usize,
    },
}
