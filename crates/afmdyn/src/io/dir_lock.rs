//! The lock of an output directory (feature `files`): one run writes a directory at a time,
//! whatever front end started it (`afmdyn … --out DIR`, Python's `store=DIR`).
//!
//! The lock is an advisory file lock (`flock`, [`std::fs::File::try_lock`]) on
//! `DIR/.afmdyn.lock`, held by this process, so the kernel releases it when the process ends,
//! however it ends: a killed run never leaves a stale lock. The file records the holder's
//! process id, for the message of the run that is refused. On a file system without advisory
//! locks the directory is used unlocked ([`DirLock::is_locked`] is false) rather than not at
//! all.
//!
//! A file is written as its temporary sibling `.NAME.partial.EXT` (`partial_path`) and
//! renamed into place. A run killed outright (a second Ctrl-C, SIGKILL) leaves that sibling;
//! the next run on the directory, holding the lock so that no other run is writing it,
//! removes the stale siblings of its own outputs ([`DirLock::remove_partials`]) — never those
//! of other outputs (a bifurcation's `.bifurcation.partial.csv` is its checkpoint).

use std::fs::{self, File};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Name of the lock file in a locked directory.
pub(crate) const LOCK_FILE: &str = ".afmdyn.lock";

/// The temporary sibling `path` is written as before it is renamed into place:
/// `DIR/NAME.EXT` → `DIR/.NAME.partial.EXT` (`DIR/.NAME.partial` without an extension; the
/// extension stays last, for the writers that choose a format by it).
pub(crate) fn partial_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("out");
    path.with_file_name(match path.extension().and_then(|s| s.to_str()) {
        Some(ext) => format!(".{stem}.partial.{ext}"),
        None => format!(".{stem}.partial"),
    })
}

/// Why a directory could not be locked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LockError {
    /// Another run holds the lock.
    #[error("output directory {dir} is in use by another afmdyn run{holder}")]
    InUse {
        /// The directory.
        dir: String,
        /// " (process PID)" when the holder recorded its id, else empty.
        holder: String,
    },
    /// The directory or its lock file cannot be created or written.
    #[error("cannot {action} {path}: {message}")]
    Io {
        /// What failed ("create", "open", "write").
        action: &'static str,
        /// The path.
        path: String,
        /// The system's message.
        message: String,
    },
}

fn io(action: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> LockError {
    let path = path.display().to_string();
    move |e| LockError::Io {
        action,
        path,
        message: e.to_string(),
    }
}

/// A locked directory (see the module docs); the lock is released when this is dropped.
#[derive(Debug)]
pub struct DirLock {
    dir: PathBuf,
    _file: File,
    locked: bool,
}

impl DirLock {
    /// Create `dir` if needed and lock it.
    ///
    /// # Errors
    /// [`LockError::InUse`] when another run holds it; [`LockError::Io`] when the directory or
    /// its lock file cannot be created or written.
    pub fn acquire(dir: &Path) -> Result<DirLock, LockError> {
        fs::create_dir_all(dir).map_err(io("create", dir))?;
        let path = dir.join(LOCK_FILE);
        let mut file = fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(io("open", &path))?;
        let locked = match file.try_lock() {
            Ok(()) => true,
            Err(fs::TryLockError::WouldBlock) => {
                // the holder's line, read through the bounded reader (a lock file that is
                // not one names no process)
                let holder = super::input::read_text(&path, super::input::InputKind::Lock)
                    .unwrap_or_default();
                let holder = holder
                    .split_whitespace()
                    .next()
                    .filter(|p| p.chars().all(|c| c.is_ascii_digit()))
                    .map_or(String::new(), |p| format!(" (process {p})"));
                return Err(LockError::InUse {
                    dir: dir.display().to_string(),
                    holder,
                });
            }
            Err(fs::TryLockError::Error(_)) => false,
        };
        file.set_len(0).map_err(io("write", &path))?;
        writeln!(file, "{} afmdyn", std::process::id()).map_err(io("write", &path))?;
        Ok(DirLock {
            dir: dir.to_path_buf(),
            _file: file,
            locked,
        })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Remove the stale temporary siblings (`partial_path`) of `outputs`, the names of the
    /// files a run writes in the directory (`timeseries.npy`, `events.csv`, …), which a run
    /// killed before it could clean up left behind. Call it holding the lock (no other run
    /// is then writing them). Returns the files removed.
    ///
    /// # Errors
    /// [`LockError::Io`] naming a file that exists but cannot be removed.
    pub fn remove_partials(&self, outputs: &[&str]) -> Result<Vec<PathBuf>, LockError> {
        remove_partials_in(&self.dir, outputs)
    }

    /// Whether the lock is held (false on a file system without advisory locks, where the
    /// directory is used unlocked and concurrent runs are not detected).
    pub fn is_locked(&self) -> bool {
        self.locked
    }
}

/// [`DirLock::remove_partials`] in `dir`, for a writer that holds no [`DirLock`] itself (its
/// caller holds the directory's lock).
///
/// # Errors
/// [`LockError::Io`] naming a file that exists but cannot be removed.
pub(crate) fn remove_partials_in(dir: &Path, outputs: &[&str]) -> Result<Vec<PathBuf>, LockError> {
    let mut removed = Vec::new();
    for name in outputs {
        let tmp = partial_path(&dir.join(name));
        match fs::remove_file(&tmp) {
            Ok(()) => removed.push(tmp),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(io("remove", &tmp)(e)),
        }
    }
    Ok(removed)
}

/// A lock error as the library's error ([`crate::error::SimError::File`]).
impl From<LockError> for crate::error::SimError {
    fn from(e: LockError) -> Self {
        crate::error::SimError::File(e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_on_the_same_directory_is_refused_until_the_first_is_dropped() {
        let dir = std::env::temp_dir().join(format!("afmdyn-lock-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        let first = DirLock::acquire(&dir).unwrap();
        if first.is_locked() {
            let err = DirLock::acquire(&dir).unwrap_err();
            assert_eq!(
                err.to_string(),
                format!(
                    "output directory {} is in use by another afmdyn run (process {})",
                    dir.display(),
                    std::process::id()
                )
            );
        }
        drop(first);
        assert!(DirLock::acquire(&dir).is_ok());
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn stale_partials_of_the_named_outputs_are_removed_and_no_other_file() {
        let dir = std::env::temp_dir().join(format!("afmdyn-partials-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        let lock = DirLock::acquire(&dir).unwrap();
        for name in [
            ".a.partial.csv",
            ".b.npy.partial.json",
            ".c.partial",
            ".d.partial.csv",
        ] {
            fs::write(dir.join(name), "x").unwrap();
        }
        fs::write(dir.join("a.csv"), "result").unwrap();
        let removed = lock
            .remove_partials(&["a.csv", "b.npy.json", "c", "e.csv"])
            .unwrap();
        assert_eq!(removed.len(), 3, "{removed:?}");
        let mut left: Vec<String> = fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, [".afmdyn.lock", ".d.partial.csv", "a.csv"]);
        drop(lock);
        fs::remove_dir_all(&dir).unwrap();
    }
}
