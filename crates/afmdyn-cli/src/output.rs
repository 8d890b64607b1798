//! Output files and text: the locked output directory ([`OutDir`]), the standard streams, the
//! SI text of the summaries; the files themselves are written atomically by the library
//! ([`afmdyn::layout::files`]: CSV and NPY streams; NetCDF through [`write_layout`]).

use crate::error::CliError;
use afmdyn::request::{DirLock, LockError};
use std::path::{Path, PathBuf};

/// A failed write to a standard stream: a closed pipe (`afmdyn … | head`) ends the run quietly
/// with status 141, as SIGPIPE ends other Unix tools; any other failure (`> /dev/full`) is
/// [`CliError::Io`] naming the stream and the cause, exit code 1.
fn stream_error(stream: &str, e: &std::io::Error) -> CliError {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(141);
    }
    CliError::Io(format!(
        "cannot write to {stream}: {}",
        afmdyn::error::io_message(e)
    ))
}

/// Write `args` to standard output and flush it, so that a failure shows here (every print
/// of the command line goes through this, by the `outln!` macro: `println!` would panic).
///
/// # Errors
/// [`CliError::Io`] naming standard output.
pub fn write_stdout(args: std::fmt::Arguments<'_>) -> Result<(), CliError> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| out.flush())
        .map_err(|e| stream_error("standard output", &e))
}

/// Write `args` to standard error (the `errln!` macro).
///
/// # Errors
/// [`CliError::Io`] naming standard error.
pub fn write_stderr(args: std::fmt::Arguments<'_>) -> Result<(), CliError> {
    use std::io::Write;
    let mut err = std::io::stderr().lock();
    err.write_fmt(args)
        .and_then(|()| err.flush())
        .map_err(|e| stream_error("standard error", &e))
}

/// A locked output directory: created if needed; a second run on the same directory fails at
/// once (the library's [`DirLock`]: an advisory file lock the kernel releases when the process
/// ends, however it ends).
#[derive(Debug)]
pub struct OutDir {
    lock: DirLock,
}

impl OutDir {
    /// Create and lock `dir`.
    ///
    /// # Errors
    /// [`CliError::Io`] when the directory cannot be created; [`CliError::Input`] when another
    /// run holds it.
    pub fn lock(dir: &Path) -> Result<OutDir, CliError> {
        let lock = DirLock::acquire(dir).map_err(|e| match e {
            LockError::InUse { .. } => CliError::Input(format!(
                "{e}; wait for it to finish or choose another --out"
            )),
            LockError::Io { .. } => CliError::Io(e.to_string()),
        })?;
        if !lock.is_locked() {
            // a file system without advisory locks: run unlocked rather than not at all
            errln!(
                "afmdyn: warning: cannot lock {}; concurrent runs on it are not detected",
                dir.display()
            );
        }
        Ok(OutDir { lock })
    }

    /// Remove the stale temporary files of `outputs` (files of this command in the directory)
    /// that a run killed outright left ([`DirLock::remove_partials`]).
    ///
    /// # Errors
    /// [`CliError::Io`] naming a file that cannot be removed.
    pub fn remove_partials(&self, outputs: &[&str]) -> Result<(), CliError> {
        self.lock
            .remove_partials(outputs)
            .map(|_| ())
            .map_err(|e| CliError::Io(e.to_string()))
    }

    /// The lock held on the directory.
    pub fn dir_lock(&self) -> &DirLock {
        &self.lock
    }

    /// `dir/name`.
    pub fn join(&self, name: impl AsRef<Path>) -> PathBuf {
        self.lock.path().join(name)
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        self.lock.path()
    }
}

/// Write the NetCDF file of `layout` ([`afmdyn::layout::netcdf`]).
///
/// # Errors
/// [`CliError::Io`] naming the path.
/// Every warning of a document (its `warnings` array) on stderr as `afmdyn: warning: …`, the
/// one place the command line prints a document's warnings (with `--json` too: stdout holds
/// the document, stderr its warnings).
///
/// # Errors
/// [`CliError`] when stderr cannot be written.
pub fn print_warnings(doc: &serde_json::Value) -> Result<(), CliError> {
    for w in doc["warnings"].as_array().into_iter().flatten() {
        errln!("afmdyn: warning: {}", w.as_str().unwrap_or_default());
    }
    Ok(())
}

pub fn write_layout(path: &Path, layout: &afmdyn::layout::Layout) -> Result<(), CliError> {
    afmdyn::layout::netcdf::write(path, layout).map_err(|e| CliError::Io(e.to_string()))
}

pub use afmdyn::report::TextUnits;

/// The text units of a run on `probe` (SI) or without one, in the process's display units.
pub fn units_of(probe: Option<&afmdyn::probe::Probe>) -> TextUnits {
    TextUnits::of(probe, crate::plot::plain_si())
}

/// How SI quantities are displayed in text and on plot axes (`--units`): prefixed as AFM
/// papers write them (nm, pN, kHz, aJ) or in plain SI units.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DisplayUnits {
    /// Prefixed units (the default): 8.03 nm, 6.9 nN, 300 kHz, 2.4 aJ.
    Afm,
    /// Plain SI units: 8.03e-9 m.
    Si,
}

/// Set the process's display units (once, from the command line): the plots' and the text's.
pub fn set_display_units(u: DisplayUnits) {
    crate::plot::set_plain_si(u == DisplayUnits::Si);
}
