//! The adaptive integrator takes its steps without heap traffic: a counting global allocator
//! (per thread, so that other tests of this binary do not interfere) sees no allocation in a
//! step that ends without an event, with and without the variational equations, for every
//! nonlinear tip–sample law. (A located event allocates: its record carries the state.)

use afmdyn::integrate::adaptive::Adaptive;
use afmdyn::integrate::taylor::Taylor;
use afmdyn::integrate::Integrator;
use afmdyn::{CantileverModel, ContactLaw, Params};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

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
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
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
