//! The one bounded reader of input files: a file is read with at most a limit kept in memory
//! (`Read::take`), so `/dev/zero`, a pipe or a huge file is refused after the limit, not read
//! until memory runs out; every refusal names the file.

/// Largest text input file (a probe file, a `--config` file) read, in bytes: 1 MiB, a
/// thousand times a probe file; larger input (`/dev/zero`) is refused after reading this much.
pub const MAX_INPUT_TEXT_BYTES: u64 = 1024 * 1024;
/// Largest CSV input file (`afmdyn continue --overlay bifurcation.csv`) read, in bytes:
/// 256 MiB, about a million rows of a bifurcation sweep.
pub const MAX_INPUT_CSV_BYTES: u64 = 256 * 1024 * 1024;
/// The text of the input file `path`, read with at most `limit` bytes kept in memory
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
    let mut bytes = Vec::new();
    file.take(limit + 1).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > limit {
        return Err(InputFileError::TooLarge {
            path: name(),
            limit,
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
    #[error("{path}: larger than {limit} bytes, the limit of this input (is it the right file?)")]
    TooLarge {
        /// The file.
        path: String,
        /// The limit in bytes.
        limit: u64,
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
