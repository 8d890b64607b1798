//! The rows of a basin map: each cell's start integrated until it is decided (a known
//! attractor, a cell already decided, a new steady state), on coarse grids of decreasing
//! stride, and the merge of a pass's rows (module docs of [`super`]).

use super::*;

pub(super) fn cell_key(z: &DVector<f64>, n: usize, h: f64, omega: f64) -> CellKey {
    let (mut lo, mut hi) = (0u64, 0x5851_F42D_4C95_7F2Du64);
    for (i, v) in z.iter().enumerate() {
        let side = if i < n { h } else { h * omega };
        let k = (v / side).floor() as i64 as u64;
        lo = mix64(lo ^ k);
        hi = mix64(hi.rotate_left(17) ^ k);
    }
    (u128::from(hi) << 64) | u128::from(lo)
}

pub(super) fn near(spec: &BasinSpec, known: &[SteadyState], z: &DVector<f64>) -> Option<usize> {
    let close = |p: &DVector<f64>| {
        let d2: f64 = z.iter().zip(p.iter()).map(|(a, b)| (a - b) * (a - b)).sum();
        d2.sqrt() <= spec.near_tol * (1.0 + p.norm())
    };
    known
        .iter()
        .position(|a| a.period().is_some() && a.poincare.iter().any(|p| close(&p.state)))
}

/// The first pass's labels on its coarse grid (rows `ys`, columns `xs`: indices into the
/// map's values), for the second pass's lookup.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(super) struct CoarseGrid {
    xs: Vec<usize>,
    ys: Vec<usize>,
    /// Labels, row-major over (ys, xs); −2 failed.
    labels: Vec<i64>,
}

/// The coarse indices: every `stride`-th of `0..n` and the last.
pub(super) fn coarse_indices(n: usize, stride: usize) -> Vec<usize> {
    let mut v: Vec<usize> = (0..n).step_by(stride.max(1)).collect();
    if v.last() != Some(&(n - 1)) {
        v.push(n - 1);
    }
    v
}

/// The interval `j` with `v` between `values[idx[j]]` and `values[idx[j + 1]]` (values
/// monotone, increasing or decreasing); `None` outside.
pub(super) fn bracket(values: &[f64], idx: &[usize], v: f64) -> Option<usize> {
    let at = |j: usize| values[idx[j]];
    (0..idx.len().saturating_sub(1)).find(|&j| {
        let (lo, hi) = (at(j).min(at(j + 1)), at(j).max(at(j + 1)));
        lo <= v && v <= hi
    })
}

impl CoarseGrid {
    /// The label of the coarse cell holding the state `z` when its four corners share one
    /// (≥ 0), and whether the 4 × 4 nodes of the 3 × 3 cells around it share it too.
    pub(super) fn lookup(
        &self,
        spec: &BasinSpec,
        model: &CantileverModel,
        z: &DVector<f64>,
    ) -> Option<(usize, bool)> {
        let xv = BasinSpec::coordinate(model, spec.x, z);
        let yv = BasinSpec::coordinate(model, spec.y, z);
        let i = bracket(&spec.xs, &self.xs, xv)?;
        let j = bracket(&spec.ys, &self.ys, yv)?;
        let (nx, ny) = (self.xs.len(), self.ys.len());
        let l = self.labels[j * nx + i];
        let uniform = |reach: usize| {
            let rows = j.saturating_sub(reach)..=(j + 1 + reach).min(ny - 1);
            let cols = i.saturating_sub(reach)..=(i + 1 + reach).min(nx - 1);
            rows.flat_map(|r| cols.clone().map(move |c| (r, c)))
                .all(|(r, c)| self.labels[r * nx + c] == l)
        };
        (l >= 0 && uniform(0)).then(|| (l as usize, uniform(1)))
    }
}

/// Whether the map's plane is the whole stroboscopic section: N = 1, one position coordinate
/// (a1, w) and one velocity (ȧ1, ẇ), so that every return is a point of the map.
pub(super) fn plane_is_the_section(spec: &BasinSpec) -> bool {
    let position = |c: StateCoord| matches!(c, StateCoord::A(_) | StateCoord::W);
    spec.params.modes == 1 && position(spec.x) != position(spec.y)
}

/// A row's (ix, cell) pairs and the attractors found beyond the initial ones.
pub(super) type RowCells = (Vec<(usize, BasinCell)>, Vec<SteadyState>);

/// Run the cells `columns` of row `iy`, knowing the attractors `initial` (their labels are
/// their indices) and, in the second pass, the first pass's `grid`.
pub(super) fn run_row(
    spec: &BasinSpec,
    model: &CantileverModel,
    iy: usize,
    columns: &[usize],
    initial: &[SteadyState],
    grid: Option<&CoarseGrid>,
    cancel: &AtomicBool,
) -> Result<RowCells, SimError> {
    let n = model.modes();
    let (h, omega, period) = (spec.cell, spec.params.omega, model.period());
    let mut known: Vec<SteadyState> = initial.to_vec();
    let mut labelled: HashMap<CellKey, usize> = HashMap::new();
    let mut cells = Vec::with_capacity(columns.len());
    // one integrator per row, reset to each start (building one costs more than the few
    // periods most starts of the second pass run)
    let mut integrator: Option<Box<dyn Integrator>> = None;
    let cap = spec.steady.cap(model);
    for &ix in columns {
        if cancel.load(Ordering::Relaxed) {
            return Err(SimError::Cancelled);
        }
        let xv = spec.xs[ix];
        let mut z0 = spec.base.clone();
        spec.x.set(model, &mut z0, xv);
        spec.y.set(model, &mut z0, spec.ys[iy]);
        let mut visited: Vec<CellKey> = Vec::new();
        let outcome = (|| -> Result<(usize, Decided, usize), SimError> {
            let integ = match integrator.as_mut() {
                Some(it) => {
                    it.reset(0.0, &z0)?;
                    it
                }
                None => integrator.insert(build(model, spec.integrator.clone(), 0.0, &z0)?),
            };
            let (mut near_run, mut cell_run) = ((usize::MAX, 0), (usize::MAX, 0));
            let mut grid_run = (usize::MAX, 0);
            for k in 1..=spec.discover_after.min(cap) {
                advance(integ.as_mut(), k as f64 * period)?;
                let z = integ.state();
                match grid.and_then(|g| g.lookup(spec, model, z)) {
                    Some((a, true)) => return Ok((a, Decided::Grid, k)),
                    Some((a, false)) if a == grid_run.0 => grid_run.1 += 1,
                    Some((a, false)) => grid_run = (a, 1),
                    None => grid_run = (usize::MAX, 0),
                }
                if grid_run.1 >= GRID_HITS {
                    return Ok((grid_run.0, Decided::Grid, k));
                }
                match near(spec, &known, z) {
                    Some(a) if a == near_run.0 => near_run.1 += 1,
                    Some(a) => near_run = (a, 1),
                    None => near_run = (usize::MAX, 0),
                }
                if near_run.1 >= NEAR_HITS {
                    return Ok((near_run.0, Decided::Near, k));
                }
                let key = cell_key(z, n, h, omega);
                match labelled.get(&key) {
                    Some(&a) if a == cell_run.0 => cell_run.1 += 1,
                    Some(&a) => cell_run = (a, 1),
                    None => cell_run = (usize::MAX, 0),
                }
                visited.push(key);
                if spec.basin_hits > 0 && cell_run.1 >= spec.basin_hits {
                    return Ok((cell_run.0, Decided::Recurrence, k));
                }
            }
            let done = visited.len();
            let opts = SteadyOptions {
                max_periods: Some(cap.saturating_sub(done).max(1)),
                ..spec.steady
            };
            // a motion without a period up to the cap is a nonperiodic attractor (chaotic or
            // quasi-periodic; matched by its X_max and V_T range, as the census does)
            let s = steady_state(integ.as_mut(), &opts)?;
            let ran = done + s.transient_periods;
            let id = match known
                .iter()
                .position(|a| same_attractor(a, &s, spec.cluster_tol))
            {
                Some(i) => i,
                None => {
                    // the attractor's own section points label their cells
                    for p in &s.poincare {
                        visited.push(cell_key(&p.state, n, h, omega));
                    }
                    known.push(s);
                    known.len() - 1
                }
            };
            Ok((id, Decided::Steady, ran))
        })();
        let cell = match outcome {
            Ok((id, decided, periods)) => {
                for key in visited {
                    labelled.entry(key).or_insert(id);
                }
                BasinCell {
                    label: id as i64,
                    decided,
                    periods,
                }
            }
            Err(_) => BasinCell {
                label: -2,
                decided: Decided::Failed,
                periods: 0,
            },
        };
        cells.push((ix, cell));
    }
    Ok((cells, known.split_off(initial.len())))
}

/// Match the new attractors of a pass's `rows` (in row order) into `attractors` and put their
/// cells, with global labels, into `slots` (row-major, nx wide): the one merge of a pass, for
/// the run ([`run_passes`]) and for the map made from its rows ([`basin_map`]).
pub(super) fn merge_pass(
    spec: &BasinSpec,
    rows: impl Iterator<Item = BasinRow>,
    attractors: &mut Vec<SteadyState>,
    slots: &mut [Option<BasinCell>],
) {
    let nx = spec.xs.len();
    let first = attractors.len();
    for row in rows {
        let ids: Vec<i64> = row
            .attractors
            .into_iter()
            .map(|a| {
                match attractors
                    .iter()
                    .position(|b| same_attractor(b, &a, spec.cluster_tol))
                {
                    Some(i) => i as i64,
                    None => {
                        attractors.push(a);
                        attractors.len() as i64 - 1
                    }
                }
            })
            .collect();
        for (ix, mut c) in row.cells {
            if c.label >= first as i64 {
                c.label = ids[c.label as usize - first];
            }
            slots[row.iy * nx + ix] = Some(c);
        }
    }
}

/// The passes' strides: the coarsest, halved pass by pass, then every cell (one pass where the
/// plane is not the whole section).
pub(super) fn strides(spec: &BasinSpec) -> Vec<usize> {
    let mut strides = Vec::new();
    if plane_is_the_section(spec) {
        let mut s = spec.first_stride();
        while s > 1 {
            strides.push(s);
            s /= 2;
        }
    }
    strides.push(1);
    strides
}

/// The labels of a pass's coarse grid (−2 where no cell was run).
pub(super) fn coarse_grid(
    nx: usize,
    ny: usize,
    stride: usize,
    slots: &[Option<BasinCell>],
) -> CoarseGrid {
    let (cx, cy) = (coarse_indices(nx, stride), coarse_indices(ny, stride));
    let labels = cy
        .iter()
        .flat_map(|&iy| cx.iter().map(move |&ix| (iy, ix)))
        .map(|(iy, ix)| slots[iy * nx + ix].as_ref().map_or(-2, |c| c.label))
        .collect();
    CoarseGrid {
        xs: cx,
        ys: cy,
        labels,
    }
}
