//! [`MemoryStore`]: a study's finished tasks kept in memory (a run that writes no files; a
//! page's bifurcation sweep run chunk by chunk, each chunk a resume of the one before).

use super::{Opened, Resumes, Store, Study};
use crate::study::checkpoint::{same_request, CheckpointError, Ledger};

/// The finished tasks of a study, in the order they finished until the study finishes (then in
/// its one order, [`Study::order`]), and the ledger of the run that made them: a resume of the
/// same request goes on after them, of another is refused, as a file store's.
#[derive(Debug, Clone, PartialEq)]
pub struct MemoryStore<R> {
    /// The ledger (`None`: none recorded).
    pub ledger: Option<Ledger>,
    /// The finished tasks.
    pub records: Vec<R>,
}

impl<R> Default for MemoryStore<R> {
    fn default() -> Self {
        MemoryStore {
            ledger: None,
            records: Vec::new(),
        }
    }
}

impl<S> Store<S> for MemoryStore<S::Record>
where
    S: Study + ?Sized,
    S::Done: Resumes<S::Record>,
{
    fn open(&mut self, study: &S, resume: bool) -> Result<Opened<S::Done>, CheckpointError> {
        if resume {
            match &self.ledger {
                None if !self.records.is_empty() => {
                    return Err(CheckpointError::Unrecorded {
                        store: "the store".into(),
                        ledger: "its ledger".into(),
                    })
                }
                None => {}
                Some(ledger) => {
                    same_request(&ledger.fingerprint, study.fingerprint(), "")?;
                    if ledger.finished {
                        return Ok(Opened::Finished);
                    }
                    let mut gathered = Default::default();
                    for r in &self.records {
                        S::Done::gather(&mut gathered, r);
                    }
                    return Ok(Opened::Run(S::Done::done(gathered)));
                }
            }
        }
        self.records.clear();
        self.ledger = Some(Ledger {
            fingerprint: study.fingerprint().clone(),
            finished: false,
        });
        Ok(Opened::Run(S::Done::default()))
    }

    fn append(&mut self, record: S::Record) -> Result<(), CheckpointError> {
        self.records.push(record);
        Ok(())
    }

    fn finish(&mut self, study: &S) -> Result<(), CheckpointError> {
        study.order(&mut self.records);
        self.ledger = Some(Ledger {
            fingerprint: study.fingerprint().clone(),
            finished: true,
        });
        Ok(())
    }
}
