//! The sweep's records and checkpoints: a resume computes exactly the points not stored and
//! ends with the rows of an uninterrupted sweep; another request is refused naming the field.

use super::*;
use crate::analysis::bifurcation::Branch;
use crate::analysis::bifurcation::SweepSpec;
use crate::analysis::progress::Progress;
use crate::params::Params;
use crate::request::sweep::point_count;
use crate::request::sweep::SweepRecord;
use crate::request::sweep::{order_key, PointStatus, HEADER};
use crate::request::BifurcationRequest;
use crate::study::checkpoint::*;
use crate::study::{execute, MemoryStore, Opened, Store, StudyError};
use std::collections::HashSet;
use std::sync::Mutex;

fn request() -> BifurcationRequest {
    let mut r = BifurcationRequest {
        from: 2.4,
        to: 2.9,
        steps: 4,
        starts: 1,
        ..BifurcationRequest::default()
    };
    r.steady.max_periods = Some(300);
    r
}

fn spec(r: &BifurcationRequest) -> SweepSpec {
    r.spec(&Params::default()).expect("valid sweep")
}

fn lines(records: &[SweepRecord]) -> Vec<String> {
    records.iter().map(SweepRecord::csv_line).collect()
}

/// A store that notes the keys of the points appended to `inner`.
struct Noting<'a, C> {
    inner: &'a mut C,
    computed: Vec<(usize, Branch)>,
}

impl<C: Store<SweepStudy>> Store<SweepStudy> for Noting<'_, C> {
    fn open(&mut self, s: &SweepStudy, resume: bool) -> Result<Opened<Resume>, CheckpointError> {
        self.inner.open(s, resume)
    }

    fn append(&mut self, record: Vec<SweepRecord>) -> Result<(), CheckpointError> {
        self.computed.push((record[0].index, record[0].branch));
        self.inner.append(record)
    }

    fn finish(&mut self, s: &SweepStudy) -> Result<(), CheckpointError> {
        self.inner.finish(s)
    }
}

/// Run what `store` leaves to do (the one executor, resuming); the keys of the points computed.
fn resume_into<C: Store<SweepStudy>>(
    store: &mut C,
    r: &BifurcationRequest,
) -> Result<Vec<(usize, Branch)>, CheckpointError> {
    let study = SweepStudy::new(r, spec(r));
    let mut noting = Noting {
        inner: store,
        computed: Vec::new(),
    };
    execute(&study, &mut noting, true, None, &Progress::new()).map_err(|e| match e {
        StudyError::Store(e) => e,
        e => panic!("{e}"),
    })?;
    Ok(noting.computed)
}

/// A sweep's store in memory.
type SweepMemory = MemoryStore<Vec<SweepRecord>>;

/// The records of a store, point after point.
fn flat(store: SweepMemory) -> Vec<SweepRecord> {
    store.records.into_iter().flatten().collect()
}

/// An uninterrupted sweep: the store before `finish` (points in the order they finished) and
/// the finished records.
fn uninterrupted(r: &BifurcationRequest) -> (SweepMemory, Vec<SweepRecord>) {
    let mut store = SweepMemory::default();
    let s = SweepStudy::new(r, spec(r));
    let Opened::Run(resume) = Store::open(&mut store, &s, false).unwrap() else {
        panic!("a new sweep runs")
    };
    let sink = Mutex::new(Vec::new());
    s.run(
        &resume,
        &|rec| sink.lock().unwrap().push(rec),
        &AtomicBool::new(false),
    )
    .unwrap();
    for rec in sink.into_inner().unwrap() {
        Store::<SweepStudy>::append(&mut store, rec).unwrap();
    }
    let unfinished = store.clone();
    Store::finish(&mut store, &s).unwrap();
    (unfinished, flat(store))
}

#[test]
fn records_are_in_the_one_order_and_read_back_from_their_csv_lines() {
    let r = request();
    let (_, records) = uninterrupted(&r);
    let keys: Vec<_> = records.iter().map(order_key).collect();
    let mut sorted = keys.clone();
    sorted.sort();
    assert_eq!(keys, sorted, "by index, then forward, backward, start k");
    assert_eq!(
        keys.iter()
            .map(|k| (k.0, k.1))
            .collect::<HashSet<_>>()
            .len(),
        point_count(&spec(&r))
    );
    for rec in &records {
        let line = rec.csv_line();
        assert_eq!(line.split(',').count(), HEADER.len());
        let back = SweepRecord::parse_csv(&line).unwrap();
        assert_eq!(back.csv_line(), line);
        assert_eq!(back.state, rec.state, "states read back exactly");
    }
}

#[test]
fn a_failed_point_is_one_row_with_its_message_and_codes() {
    let p = SweepPoint {
        index: 3,
        value: 2.5,
        branch: Branch::Start(2),
        result: Err("no convergence,\nafter 300 periods".into()),
    };
    let rows = records(crate::SweepParam::Omega, &p);
    assert_eq!(rows.len(), 1);
    assert_eq!(
        rows[0].csv_line(),
        "omega,2.5,3,start-2,error,,0,1,,,,,,,,,no convergence  after 300 periods,"
    );
    assert_eq!(rows[0].status.code(), -2);
    // not a converged point of the diagram (the door's `converged`)
    let c = crate::request::run::Analysis::convergence(&BifurcationRequest::default(), &rows);
    assert_eq!((c.settled, c.of, c.part), (0, 1, "points"));
    assert_eq!(crate::request::sweep::branch_code(p.branch), 4.0);
    let back = SweepRecord::parse_csv(&rows[0].csv_line()).unwrap();
    assert_eq!(back.status, PointStatus::Error);
    assert!(back.w_tip.is_nan() && back.transient_periods.is_none());
    assert_eq!(
        end_state(&rows),
        None,
        "a failed point does not carry a chain"
    );
    let err = SweepRecord::parse_csv("omega,x,3").unwrap_err();
    assert!(err.contains("3 cells"), "{err}");
}

#[test]
fn a_resume_computes_exactly_the_points_not_stored() {
    let r = request();
    let (unfinished, reference) = uninterrupted(&r);
    let total = unfinished.records.len();
    for k in [0, 1, total / 2, total - 1, total] {
        // interrupted after k points, in the order they finished
        let mut store = SweepMemory {
            records: unfinished.records[..k].to_vec(),
            ..unfinished.clone()
        };
        let stored: HashSet<_> = store
            .records
            .iter()
            .map(|p| (p[0].index, p[0].branch))
            .collect();
        let computed = resume_into(&mut store, &r).unwrap();
        assert_eq!(
            computed.len(),
            total - k,
            "after {k}: each missing point once"
        );
        assert!(computed.iter().all(|c| !stored.contains(c)), "after {k}");
        assert_eq!(
            lines(&flat(store)),
            lines(&reference),
            "after {k}: the rows of the uninterrupted sweep"
        );
    }
}

#[test]
fn a_finished_store_computes_nothing() {
    let r = request();
    let mut store = SweepMemory::default();
    assert_eq!(
        resume_into(&mut store, &r).unwrap().len(),
        point_count(&spec(&r))
    );
    let before = store.clone();
    assert!(resume_into(&mut store, &r).unwrap().is_empty());
    assert_eq!(store, before);
}

#[test]
fn another_request_is_refused_naming_the_first_field_that_differs() {
    let r = request();
    let (unfinished, _) = uninterrupted(&r);
    let mut other = r.clone();
    other.steps = 5;
    other.starts = 2;
    let mut store = unfinished.clone();
    assert_eq!(
        resume_into(&mut store, &other).unwrap_err().to_string(),
        "steps = 4 in the interrupted run, 5 now"
    );
    assert_eq!(store, unfinished, "untouched");
    let mut other = r.clone();
    other.steady.max_periods = Some(200);
    assert_eq!(
        resume_into(&mut store, &other).unwrap_err(),
        CheckpointError::Mismatch {
            field: "max_periods".into(),
            then: "300".into(),
            now: "200".into()
        }
    );
    let p = Params {
        alpha4: 30.0,
        ..Params::default()
    };
    let study = SweepStudy::new(&r, r.spec(&p).unwrap());
    let err = Store::open(&mut store, &study, true).unwrap_err();
    assert_eq!(
        err.to_string(),
        "alpha4 = 20.0 in the interrupted run, 30.0 now"
    );
    // listed values instead of from/to/steps: named as such
    let mut listed = r.clone();
    listed.values = Some(vec![2.4, 2.5]);
    let study = SweepStudy::new(&listed, spec(&listed));
    let err = Store::open(&mut store, &study, true).unwrap_err();
    assert_eq!(
        err.to_string(),
        "from = 2.4 in the interrupted run, absent now"
    );
}

#[test]
fn records_without_a_ledger_are_not_resumed() {
    let (unfinished, _) = uninterrupted(&request());
    let mut store = SweepMemory {
        ledger: None,
        ..unfinished
    };
    assert!(matches!(
        resume_into(&mut store, &request()),
        Err(CheckpointError::Unrecorded { .. })
    ));
}

#[cfg(feature = "files")]
#[test]
fn the_file_store_resumes_a_killed_sweep_and_drops_a_cut_row() {
    use crate::io::dir_lock::DirLock;
    use crate::request::analyses::fingerprint;
    use crate::study::checkpoint_file::{final_rows, LEDGER, PARTIAL_CSV};
    use crate::study::task_store::TaskStore;
    let r = request();
    let (unfinished, reference) = uninterrupted(&r);
    let dir = std::env::temp_dir().join(format!("afmdyn-checkpoint-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let lock = DirLock::acquire(&dir).unwrap();
    let mut store = TaskStore::new(&lock, SweepRows);
    let s = spec(&r);
    let fp = fingerprint(&r, &s);
    assert!(
        matches!(
            store.open::<Resume>(&fp, true, |_| false).unwrap(),
            Opened::Run(_)
        ),
        "empty: begins"
    );
    let k = 5;
    for p in &unfinished.records[..k] {
        store.append(p.clone()).unwrap();
    }
    drop(store);
    drop(lock);
    // a kill in the middle of a write leaves a cut row
    let partial = dir.join(PARTIAL_CSV);
    let mut text = std::fs::read_to_string(&partial).unwrap();
    text.push_str("omega,2.5,1,start-0,peri");
    std::fs::write(&partial, text).unwrap();
    let lock = DirLock::acquire(&dir).unwrap();
    let mut store = TaskStore::new(&lock, SweepRows);
    let computed = resume_into(&mut store, &r).unwrap();
    assert_eq!(computed.len(), unfinished.records.len() - k);
    assert_eq!(lines(&final_rows(&dir).unwrap()), lines(&reference));
    assert!(!partial.exists());
    let ledger = std::fs::read_to_string(dir.join(LEDGER)).unwrap();
    assert!(ledger.contains("\"finished\": true"), "{ledger}");
    // finished: nothing to do; another request refused
    assert!(resume_into(&mut store, &r).unwrap().is_empty());
    let mut other = r.clone();
    other.seed = 7;
    assert_eq!(
        resume_into(&mut store, &other).unwrap_err().to_string(),
        "seed = 1 in the interrupted run, 7 now"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
