//! The exact propagator's cache, owned by whoever builds the propagators: a
//! [`PropagatorCache`] is a handle (cloning it shares the tables) carried by
//! [`crate::integrate::IntegratorOptions::cache`], so every build of one request — the points of
//! a sweep, the cells of a chart, the starts of a basin map or a census, the corrections of a
//! continuation — shares one set of tables, and nothing is shared between requests unless the
//! caller hands the same handle on. No process-wide state: a run's memory ends with its
//! request.
//!
//! Three tables, each of at most [`CAPACITY`] entries, the least recently used dropped first:
//!
//! - **spectral data** of both regions (`Spectral`: energy transforms, Ã_s, ‖Ã_s‖₂, the
//!   eigendecomposition, the tip moment rows, the LU of A_s), keyed by the state dimension and
//!   the exact bits of A_s, M and K_s of both regions (`spectral::matrix_key`; the tip row
//!   φ(1) is fixed by N and the structure, which K_s tells apart). At most 12 d² + 132 d + 160
//!   numbers per region (d = 2N) and a key of 2(d² + 2N²) + 1 words: 0.42 MiB an entry at
//!   N = 20 ([`crate::params::MAX_MODES`]), 3.4 MiB in all;
//! - **grid exponentials** Φ_s = T⁻¹ e^{Ã_s h} T of both regions, keyed as the spectral data
//!   and the bits of the grid step h: 2 d² numbers an entry, 63 KiB at N = 20, 0.5 MiB in all;
//! - **forcing data** (both regions' particular solutions, sin/cos of Ωτ on the grid and at its
//!   middles), keyed by the bits of everything they read (`forcing::forcing_key`), stored only
//!   while (4N + 2)(m + 1) numbers fit `forcing::FORCING_KEEP_BYTES` = 2 MiB: at most about
//!   4 MiB an entry and 32 MiB in all.
//!
//! **Results do not depend on the cache**: every value is computed from its keyed bits alone,
//! by the same operations in the same order on one thread, so a hit returns the very bits a
//! miss computes (a poisoned lock counts as a miss). The test `forcing_cache_tells_gaps_apart`
//! holds two builds that differ only in α5 to it, and `a_cache_is_shared_by_its_clones_only`
//! the ownership.

use super::forcing::Forcing;
use super::spectral::{GridExp, Spectral};
use crate::error::SimError;
use std::sync::{Arc, Mutex};

/// Entries kept per table (least recently used dropped first).
pub(crate) const CAPACITY: usize = 8;

/// One table: (key, value) entries, the most recently used last.
type Table<V> = Mutex<Vec<(Vec<u64>, Arc<V>)>>;

/// The three tables of a [`PropagatorCache`].
#[derive(Default)]
pub(super) struct Tables {
    pub(super) spectral: Table<[Spectral; 2]>,
    pub(super) grid_exp: Table<GridExp>,
    pub(super) forcing: Table<Forcing>,
}

/// The exact propagator's cache (see the module doc): a handle; clones share the tables.
#[derive(Clone, Default)]
pub struct PropagatorCache(Arc<Tables>);

impl PropagatorCache {
    /// A new, empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// The entries held: (spectral data, grid exponentials, forcing data), each at most
    /// `CAPACITY`.
    pub fn len(&self) -> (usize, usize, usize) {
        fn n<V>(t: &Table<V>) -> usize {
            t.lock().map_or(0, |e| e.len())
        }
        let t = &*self.0;
        (n(&t.spectral), n(&t.grid_exp), n(&t.forcing))
    }

    /// No entry held.
    pub fn is_empty(&self) -> bool {
        self.len() == (0, 0, 0)
    }

    /// The tables.
    pub(super) fn tables(&self) -> &Tables {
        &self.0
    }
}

/// Two handles are equal when they share their tables.
impl PartialEq for PropagatorCache {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl std::fmt::Debug for PropagatorCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (s, g, c) = self.len();
        write!(f, "PropagatorCache({s} spectral, {g} grid, {c} forcing)")
    }
}

/// The value for `key` in `table` (none: no cache), or `make()` (then stored), and whether it
/// was cached. A poisoned lock is a miss.
pub(super) fn cached<V>(
    table: Option<&Table<V>>,
    key: &[u64],
    make: impl FnOnce() -> Result<V, SimError>,
) -> Result<(Arc<V>, bool), SimError> {
    if let Some(Ok(mut entries)) = table.map(Mutex::lock) {
        if let Some(i) = entries.iter().position(|(k, _)| k.as_slice() == key) {
            let entry = entries.remove(i);
            let value = entry.1.clone();
            entries.push(entry);
            return Ok((value, true));
        }
    }
    let value = Arc::new(make()?);
    if let Some(Ok(mut entries)) = table.map(Mutex::lock) {
        if entries.len() >= CAPACITY {
            entries.remove(0);
        }
        entries.push((key.to_vec(), value.clone()));
    }
    Ok((value, false))
}
