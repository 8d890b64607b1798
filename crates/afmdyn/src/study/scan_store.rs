//! The resumable store of a PI-scanned image (feature `files`): a [`TaskStore`] of lines in the
//! directory `afmdyn image --feedback pi --out DIR` names — `.image.run.json` (the ledger: the
//! scan's fingerprint, its probe, sample map, request and settings) and `.image.lines.jsonl`
//! (one checksummed line per finished scan line, its trace and retrace under `"line"`, CBOR:
//! every float bit for bit), as [`super::task_store`] describes. A resumed scan computes only
//! the lines not stored, and only for the same request.

use super::task_store::{Encoding, Lines, TaskFiles, TaskStore};
use crate::analysis::am_loop::ScanLine;
use crate::io::dir_lock::DirLock;

/// The scan's files.
pub(crate) const SCAN_FILES: TaskFiles = TaskFiles {
    ledger: ".image.run.json",
    records: ".image.lines.jsonl",
    key: "line",
    prefix: "",
    encoding: Encoding::Cbor,
};

/// A PI scan's store: its lines by number.
pub(crate) type ScanStore<'a> = TaskStore<'a, Lines<ScanLine>>;

/// The scan store of the directory `lock` holds.
pub(crate) fn scan_store(lock: &DirLock) -> ScanStore<'_> {
    TaskStore::new(lock, Lines::of(SCAN_FILES))
}
