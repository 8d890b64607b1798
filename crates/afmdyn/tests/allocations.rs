//! The adaptive integrator takes its steps without heap traffic: a counting global allocator
//! (per thread, so that other tests of this binary do not interfere) sees no allocation in a
//! step that ends without an event, with and without the variational equations, for every
//! nonlinear tip–sample law. (A located event allocates: its record carries the state.)
//!
//! The same allocator also keeps the live heap bytes and their peak (over all threads), against
//! which a request's declared memory ([`afmdyn::request::Request::cost`]) is checked.

use afmdyn::integrate::adaptive::Adaptive;
use afmdyn::integrate::taylor::Taylor;
use afmdyn::integrate::Integrator;
use afmdyn::{CantileverModel, ContactLaw, Params};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

/// Live heap bytes and their peak since [`reset_peak`], over all threads.
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grow(bytes: usize) {
    let now = LIVE.fetch_add(bytes, Ordering::Relaxed) + bytes;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

fn shrink(bytes: usize) {
    LIVE.fetch_sub(bytes, Ordering::Relaxed);
}

/// Start a peak measurement: the live bytes now.
fn reset_peak() -> usize {
    let now = LIVE.load(Ordering::Relaxed);
    PEAK.store(now, Ordering::Relaxed);
    now
}

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    // `try_with`: the counter may already be gone while the thread shuts down
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: every call is forwarded to the system allocator unchanged; only a counter is touched.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        grow(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        grow(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        shrink(layout.size());
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // the old block and the new one may both be live while it is copied
        grow(new_size);
        shrink(layout.size());
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

/// Steps of 20 drive periods of the default three-mode cantilever tapping the sample: the
/// event-free steps after the first period allocate nothing — the adaptive integrator's, and the
/// Taylor integrator's for the laws it carries.
#[test]
fn event_free_steps_allocate_nothing() {
    for law in [
        ContactLaw::Hertz,
        ContactLaw::Dmt {
            hamaker: 1e-5,
            intermolecular_distance: 0.01,
        },
        ContactLaw::Impact { restitution: 0.8 },
    ] {
        for variational in [false, true] {
            let m = CantileverModel::new(&Params {
                contact_law: law,
                ..Params::default()
            })
            .unwrap();
            let mut integrators: Vec<Box<dyn Integrator>> =
                vec![Box::new(Adaptive::new(&m, 1e-10))];
            if law.restitution().is_none() {
                integrators.push(Box::new(Taylor::new(&m, 1e-10).unwrap()));
            }
            for mut it in integrators {
                it.set_variational(variational);
                it.reset(0.0, &m.rest()).unwrap();
                let t = m.period();
                let (mut free_steps, mut events, mut allocating) = (0, 0, 0);
                while it.tau() < 20.0 * t {
                    let before = allocations();
                    let step = it.step(20.0 * t).unwrap();
                    let n = allocations() - before;
                    if it.tau() < t {
                        continue;
                    }
                    match step.event {
                        Some(_) => events += 1,
                        None => {
                            free_steps += 1;
                            if n > 0 {
                                allocating += 1;
                            }
                        }
                    }
                }
                assert!(
                    events >= 19,
                    "{law:?}: the tip taps every period ({events} events)"
                );
                assert!(free_steps > 60, "{law:?}: {free_steps} steps");
                assert_eq!(
                allocating, 0,
                "{law:?} {}, variational {variational}: {allocating} of {free_steps} event-free steps allocated",
                it.name()
            );
            }
        }
    }
}

/// The peak heap bytes of `f` above what was live before it, and its result.
fn peak_of<T>(f: impl FnOnce() -> T) -> (f64, T) {
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let base = reset_peak();
    let out = f();
    (
        PEAK.load(Ordering::Relaxed).saturating_sub(base) as f64,
        out,
    )
}

/// A request's declared memory bounds what it allocates, and is not far above it where the
/// request's memory is its result: `converge` (every run's samples) and `approach` with traces.
#[test]
fn declared_memory_bounds_the_measured_peak() {
    use afmdyn::analysis::progress::Progress;
    use afmdyn::request::{run, ApproachRequest, ConvergeRequest, CurveRequest, Request, Resolved};
    let model = Resolved::plain(Params::default());
    let converge = ConvergeRequest {
        max_modes: 3,
        periods: 200,
        samples_per_period: 1000,
        ..ConvergeRequest::default()
    };
    let declared = converge.cost(&model).unwrap().bytes;
    let (peak, out) = peak_of(|| run(&converge, &model, &Progress::new()));
    out.unwrap();
    assert!(
        peak <= declared && peak >= declared / 3.0,
        "converge: peak {peak:.3e} B, declared {declared:.3e} B"
    );
    let approach = ApproachRequest {
        curve: CurveRequest {
            points: Some(60),
            branches: false,
            traces: Some(2000),
            ..CurveRequest::default()
        },
        ..ApproachRequest::default()
    };
    let declared = approach.cost(&model).unwrap().bytes;
    let (peak, out) = peak_of(|| run(&approach, &model, &Progress::new()));
    out.unwrap();
    assert!(
        peak <= declared && peak >= declared / 3.0,
        "approach: peak {peak:.3e} B, declared {declared:.3e} B"
    );
}
