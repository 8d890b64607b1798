//! The resumable store of a chart (feature `files`): a `TaskStore` of tiles in the directory
//! `afmdyn chart --out DIR` names — `.chart.run.json` (the ledger) and `.chart.tiles.jsonl`
//! (one checksummed line per finished tile, its cells under `"cells"`), as
//! `super::task_store` describes.

use super::task_store::{Encoding, Lines, TaskFiles, TaskStore};
use crate::analysis::chart::ChartCell;
use crate::io::dir_lock::DirLock;

/// The chart's files.
pub(crate) const CHART_FILES: TaskFiles = TaskFiles {
    ledger: ".chart.run.json",
    records: ".chart.tiles.jsonl",
    key: "cells",
    prefix: "chart.",
    encoding: Encoding::Json,
};

/// A chart's store: its tiles' cells by task.
pub(crate) type ChartStore<'a> = TaskStore<'a, Lines<Vec<ChartCell>>>;

/// The chart store of the directory `lock` holds.
pub(crate) fn chart_store(lock: &DirLock) -> ChartStore<'_> {
    TaskStore::new(lock, Lines::of(CHART_FILES))
}
