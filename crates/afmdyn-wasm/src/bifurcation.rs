//! A bifurcation diagram computed in chunks, so that a page draws its points as they come and a
//! new request can drop the old one between chunks: [`BifurcationSession`] holds the sweep
//! ([`afmdyn::study::sweep::SweepStudy`]) and its store in memory, and each
//! [`BifurcationSession::next`] runs the library's executor on it until a given number of
//! further points is stored — a resumed run of the same sweep, so the chunks together are the
//! one uninterrupted sweep (each chain goes on from its last stored state).

use afmdyn::request::sweep::SweepRecord;
use afmdyn::request::BifurcationRequest;
use afmdyn::study::sweep::SweepStudy;
use afmdyn::study::{execute, MemoryStore, Observer, Outcome, StudyError};
use serde_json::{json, Value};
use std::collections::HashSet;
use std::sync::atomic::{AtomicBool, Ordering};

/// Stops a run once `limit` points are stored.
struct Chunk {
    cancel: AtomicBool,
    limit: usize,
}

impl Observer for Chunk {
    fn start(&self, _total: u64, _done: u64) {}
    fn stored(&self, _units: u64, count: usize) {
        if count >= self.limit {
            self.cancel.store(true, Ordering::Relaxed);
        }
    }
    fn cancel_flag(&self) -> &AtomicBool {
        &self.cancel
    }
}

/// A row of the sweep as JSON: the columns of `bifurcation.csv`
/// ([`afmdyn::request::sweep::COLUMNS`]) by name, NaN as null.
fn row(r: &SweepRecord) -> Value {
    let num = |v: f64| if v.is_finite() { json!(v) } else { Value::Null };
    json!({
        "param": r.param.name(),
        "value": r.value,
        "index": r.index,
        "branch": r.branch.to_string(),
        "status": r.status.name(),
        "period": (r.status.code() > 0).then(|| r.status.code()),
        "point": r.point,
        "points": r.points,
        "tau": num(r.tau),
        "v_t": num(r.v_t),
        "w_tip": num(r.w_tip),
        "x_max": num(r.x_max),
        "v_t_min": num(r.v_t_min),
        "contact_fraction": num(r.contact_fraction),
        "contacts_per_period": num(r.contacts_per_period),
        "transient_periods": r.transient_periods,
        "message": r.message,
        "state": r.state,
    })
}

/// The columns of `bifurcation.csv` ([`afmdyn::request::sweep::COLUMNS`]), in its order, as a
/// JSON array of `{"name", "unit", "meaning"}`: the keys of [`BifurcationSession::next`]'s
/// rows, for a page that writes them as the command line does.
pub fn columns() -> Value {
    Value::Array(
        afmdyn::request::sweep::COLUMNS
            .iter()
            .map(|c| json!({"name": c.name, "unit": c.unit, "meaning": c.meaning}))
            .collect(),
    )
}

/// A bifurcation sweep computed chunk by chunk (module docs).
pub struct BifurcationSession {
    study: SweepStudy,
    store: MemoryStore<Vec<SweepRecord>>,
    /// The points handed out: (value index, branch).
    sent: HashSet<(usize, String)>,
    total: usize,
    finished: bool,
}

impl BifurcationSession {
    /// The sweep of `input` (`{"model", "probe", "request"}` as [`crate::run_json`]'s; the
    /// request the keywords of `afmdyn bifurcation`, its defaults the paper's Fig. 5 sweep).
    ///
    /// # Errors
    /// As [`crate::run_json`]'s model; the request's validation errors.
    pub fn new(input: &str) -> Result<BifurcationSession, String> {
        let (model, request) = crate::resolve(input, "bifurcation")?;
        let request: BifurcationRequest = crate::request(request)?;
        let spec = request.spec(&model.params).map_err(|e| e.to_string())?;
        let total = afmdyn::request::sweep::point_count(&spec);
        Ok(BifurcationSession {
            study: SweepStudy::new(&request, spec),
            store: MemoryStore::default(),
            sent: HashSet::new(),
            total,
            finished: false,
        })
    }

    /// The sweep's points (values × branches).
    pub fn total(&self) -> usize {
        self.total
    }

    /// Whether every point has been handed out.
    pub fn finished(&self) -> bool {
        self.finished
    }

    /// Compute at least `points` further points (fewer at the end): their rows as a JSON array
    /// (each point's Poincaré points; a failed point one row with its message).
    ///
    /// # Errors
    /// `points` = 0.
    pub fn next(&mut self, points: usize) -> Result<String, String> {
        if points == 0 {
            return Err("points = 0: must be at least 1".into());
        }
        if !self.finished {
            let chunk = Chunk {
                cancel: AtomicBool::new(false),
                limit: points,
            };
            match execute(&self.study, &mut self.store, true, None, &chunk) {
                Ok(Outcome::Cancelled) => {}
                Ok(_) => self.finished = true,
                Err(StudyError::Sim(e)) => return Err(e.to_string()),
                Err(StudyError::Store(e)) => return Err(e.to_string()),
            }
        }
        let mut rows = Vec::new();
        for p in &self.store.records {
            let Some(first) = p.first() else { continue };
            if self.sent.insert((first.index, first.branch.to_string())) {
                rows.extend(p.iter().map(row));
            }
        }
        Ok(Value::Array(rows).to_string())
    }
}
