//! The library's files below every request: the one bounded reader of input files
//! (`input`: a cap per [`InputKind`]), the lock of an output directory ([`dir_lock`], feature
//! `files`) and the height map files of a sample map ([`height_map`]).
//!
//! This module knows no request, analysis, report, study or probe: those import it (a probe
//! file is read by [`input::read_text`], a study's store is locked by [`dir_lock::DirLock`]),
//! never the other way round.

pub(crate) mod caps;
#[cfg(feature = "files")]
pub mod curve_file;
#[cfg(feature = "files")]
pub mod dir_lock;
pub mod force_map;
pub mod height_map;
pub mod input;

#[cfg(feature = "files")]
pub use input::{open, open_existing, read_bytes, read_input, read_text, Bounded};
pub use input::{refusal, InputFileError, InputKind, MAX_INPUT_CSV_BYTES, MAX_INPUT_TEXT_BYTES};
