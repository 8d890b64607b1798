//! [`MemoryStore`]: a study's finished tasks kept in memory (a run that writes no files).

use super::{Opened, Store, Study};
use crate::request::checkpoint::CheckpointError;

/// The finished tasks of one run, in the order they finished (a memory store never resumes:
/// every run begins anew). The records are put in the study's one order by their consumer.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MemoryStore<R> {
    /// The finished tasks.
    pub records: Vec<R>,
}

impl<R> Default for MemoryStore<R> {
    fn default() -> Self {
        MemoryStore {
            records: Vec::new(),
        }
    }
}

impl<S: Study + ?Sized> Store<S> for MemoryStore<S::Record> {
    fn open(&mut self, _study: &S, _resume: bool) -> Result<Opened<S::Done>, CheckpointError> {
        self.records.clear();
        Ok(Opened::Run(S::Done::default()))
    }

    fn append(&mut self, record: S::Record) -> Result<(), CheckpointError> {
        self.records.push(record);
        Ok(())
    }

    fn finish(&mut self, _study: &S) -> Result<(), CheckpointError> {
        Ok(())
    }
}
