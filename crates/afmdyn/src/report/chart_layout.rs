//! The one layout of a chart's results (issue 29): [`ChartArrays`], the variables of
//! `chart.nc` and of Python's `xarray.Dataset`, and [`CSV_COLUMNS`] / [`csv_lines`], the rows of
//! `chart.csv` (the request is `crate::request::chart`'s).

use crate::analysis::chart::{ChartCell, ChartSpec};
use crate::layout::{Layout, Variable};

/// A chart axis as its files name it: the parameter's name, its symbol and its unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct ChartAxis<'a> {
    /// The parameter's name (`omega`, `free_amplitude`).
    pub(crate) name: &'a str,
    /// Its symbol (`Ω`; the name where it has none).
    pub(crate) symbol: &'a str,
    /// Its unit (`"1"` dimensionless).
    pub(crate) unit: &'a str,
}

/// The columns of `chart.csv` with their unit and meaning (the book's reference of the CSV
/// files shows them): one row per attractor of a cell (one row, with `attractor` empty, for a
/// cell without any).
#[rustfmt::skip]
pub const CSV_COLUMNS: [(&str, &str, &str); 18] = [
    ("ix", "–", "column of the cell"),
    ("iy", "–", "row of the cell"),
    ("x", "the x axis' unit", "the cell's value of the x parameter"),
    ("y", "the y axis' unit", "the cell's value of the y parameter"),
    ("attractor", "–", "index of the attractor in the cell (empty for a cell with none)"),
    ("status", "–", "periodic; a nonperiodic one by λ₁ against twice its error: chaotic (above), quasiperiodic (within: quasi-periodic, or settling too slowly to tell), unsettled (below: still converging after max_periods); nonperiodic without λ₁; none"),
    ("period", "drive periods", "n of a period-n attractor (empty otherwise)"),
    ("lyapunov", "1/τ", "λ₁ of a nonperiodic attractor (empty otherwise)"),
    ("lyapunov_error", "1/τ", "its error: the uncertainty over 10 blocks plus the convergence estimate (empty otherwise)"),
    ("x_max", "g0; m with a probe", "largest W(1,τ) over the recorded steady state (with a probe each row in its cell's length unit A₀, which follows a free_amplitude axis)"),
    ("v_t_min", "g0; m with a probe", "smallest V_T over the recorded steady state"),
    ("contacts_per_period", "1/period", "contact entries and impacts per drive period"),
    ("contact_fraction", "1", "fraction of the time in contact"),
    ("count", "–", "random starts that reached it"),
    ("fraction", "1", "that count over the number of starts (0 for one found only by continuation)"),
    ("origin", "–", "start, left or right: how it was first found"),
    ("failures", "–", "runs of the cell that failed"),
    ("message", "–", "the first failed run's message"),
];

/// The names of [`CSV_COLUMNS`], the header of `chart.csv`.
pub const CSV_HEADER: [&str; 18] = {
    let mut names = [""; 18];
    let mut i = 0;
    while i < names.len() {
        names[i] = CSV_COLUMNS[i].0;
        i += 1;
    }
    names
};

/// The rows of a cell as CSV lines of [`CSV_HEADER`] (numbers in Rust's shortest round-trip
/// form; messages with commas and newlines replaced by spaces). The lengths `x_max` and
/// `v_t_min` are in g₀ × `length`: 1, or the metres per g₀ of the cell with a probe (the
/// length unit changes from cell to cell along a `free_amplitude` axis).
pub(crate) fn csv_lines(length: f64, cell: &ChartCell) -> Vec<String> {
    let message = cell
        .message
        .as_deref()
        .unwrap_or("")
        .replace(['\n', ',', '\r'], " ");
    let head = format!("{},{},{},{}", cell.ix, cell.iy, cell.x, cell.y);
    if cell.attractors.is_empty() {
        return vec![format!("{head},,none,,,,,,,,,,{},{message}", cell.failures)];
    }
    cell.attractors
        .iter()
        .enumerate()
        .map(|(k, a)| {
            let origin = match a.origin {
                crate::analysis::chart::Origin::Start => "start",
                crate::analysis::chart::Origin::Left => "left",
                crate::analysis::chart::Origin::Right => "right",
            };
            format!(
                "{head},{k},{},{},{},{},{},{},{},{},{},{},{origin},{},{message}",
                a.motion().name(),
                a.period.map_or(String::new(), |n| n.to_string()),
                a.lyapunov.map_or(String::new(), |l| l.to_string()),
                a.lyapunov_error.map_or(String::new(), |l| l.to_string()),
                a.x_max * length,
                a.v_t_min * length,
                a.contacts_per_period,
                a.contact_fraction,
                a.count,
                a.fraction,
                cell.failures,
            )
        })
        .collect()
}

/// A chart's results as arrays: per cell (y, x) and per attractor slot (y, x, attractor), the
/// attractor slots of a cell in its order
/// (`crate::request::ChartRequest::max_attractors` of them,
/// empty ones padded: period 0, NaN). Row-major, y slowest. The one layout of `chart.nc`, of
/// Python's `xarray.Dataset` and of the Dask store's regions.
#[derive(Debug, Clone, PartialEq)]
pub struct ChartArrays {
    /// x values.
    pub x: Vec<f64>,
    /// y values.
    pub y: Vec<f64>,
    /// Attractor slots per cell (≥ 1).
    pub slots: usize,
    /// (y, x): attractors found.
    pub attractors: Vec<i32>,
    /// (y, x): failed runs.
    pub failures: Vec<i32>,
    /// (y, x, attractor): period n; −1 nonperiodic; 0 empty slot.
    pub period: Vec<i32>,
    /// (y, x, attractor): the kind of motion ([`crate::analysis::chart::MotionKind::code`]:
    /// 1 periodic, 2 chaotic, 3 quasi-periodic, 4 unsettled, 5 nonperiodic without λ₁; 0 empty
    /// slot).
    pub motion: Vec<i32>,
    /// (y, x, attractor): λ₁ (NaN: periodic, not estimated, or empty).
    pub lyapunov: Vec<f64>,
    /// (y, x, attractor): the error of λ₁ (NaN with it).
    pub lyapunov_error: Vec<f64>,
    /// (y, x, attractor): X_max (g0).
    pub x_max: Vec<f64>,
    /// (y, x, attractor): smallest V_T (g0).
    pub v_t_min: Vec<f64>,
    /// (y, x, attractor): contacts per period.
    pub contacts_per_period: Vec<f64>,
    /// (y, x, attractor): fraction of the time in contact.
    pub contact_fraction: Vec<f64>,
    /// (y, x, attractor): basin fraction among the random starts.
    pub fraction: Vec<f64>,
    /// (y, x): the dominant attractor's period (the first slot's), −1 nonperiodic, 0 none.
    pub dominant_period: Vec<i32>,
}

impl ChartArrays {
    /// The chart's layout over the axes `x` and `y` (`chart.nc`, Python's dataset, the Dask
    /// Zarr store): coordinates `x` and `y` in their axes' units (named by the axes), per cell
    /// (y, x) `attractors`, `failures`, `dominant_period`, and per attractor slot
    /// (y, x, attractor) `period`, `motion`, `lyapunov`, `lyapunov_error`, `x_max`, `v_t_min`,
    /// `contacts_per_period`, `contact_fraction`, `fraction`.
    pub(crate) fn layout_over(&self, x: ChartAxis<'_>, y: ChartAxis<'_>) -> Layout {
        let (x_name, y_name) = (x.name, y.name);
        let (cell, slot): (&[&str], &[&str]) = (&["y", "x"], &["y", "x", "attractor"]);
        let a = self;
        Layout::new(
            format!("afmdyn behaviour chart over {x_name} and {y_name}"),
            &[("x", a.x.len()), ("y", a.y.len()), ("attractor", a.slots)],
            vec![
                Variable::f64("x", &["x"], x.unit, x_name, &a.x),
                Variable::f64("y", &["y"], y.unit, y_name, &a.y),
                Variable::i32(
                    "attractors",
                    cell,
                    "1",
                    "attractors found in the cell",
                    &a.attractors,
                ),
                Variable::i32(
                    "failures",
                    cell,
                    "1",
                    "runs of the cell that failed",
                    &a.failures,
                ),
                Variable::i32(
                    "dominant_period",
                    cell,
                    "drive periods",
                    "period of the attractor most random starts reached; -1 nonperiodic, 0 none",
                    &a.dominant_period,
                ),
                Variable::i32(
                    "period",
                    slot,
                    "drive periods",
                    "period n; -1 nonperiodic; 0 empty slot",
                    &a.period,
                ),
                Variable::i32(
                    "motion",
                    slot,
                    "code",
                    "1 periodic, 2 chaotic, 3 quasi-periodic, 4 unsettled (lyapunov < 0), 5 \
                     nonperiodic without lyapunov; 0 empty slot",
                    &a.motion,
                ),
                Variable::f64(
                    "lyapunov",
                    slot,
                    "1/tau",
                    "largest Lyapunov exponent of a nonperiodic attractor",
                    &a.lyapunov,
                ),
                Variable::f64(
                    "lyapunov_error",
                    slot,
                    "1/tau",
                    "its error: uncertainty over the blocks plus convergence estimate",
                    &a.lyapunov_error,
                ),
                Variable::f64(
                    "x_max",
                    slot,
                    "g0",
                    "largest tip deflection W(1,tau) over the steady state",
                    &a.x_max,
                ),
                Variable::f64(
                    "v_t_min",
                    slot,
                    "g0",
                    "smallest V_T over the steady state",
                    &a.v_t_min,
                ),
                Variable::f64(
                    "contacts_per_period",
                    slot,
                    "1/period",
                    "contact entries (impacts) per drive period",
                    &a.contacts_per_period,
                ),
                Variable::f64(
                    "contact_fraction",
                    slot,
                    "1",
                    "fraction of the time in contact",
                    &a.contact_fraction,
                ),
                Variable::f64(
                    "fraction",
                    slot,
                    "1",
                    "basin fraction among the random starts",
                    &a.fraction,
                ),
            ],
        )
    }

    /// The arrays of the region of `size` = (columns, rows) from the cell `origin` = (ix, iy)
    /// of the chart over `spec` with `slots` attractor slots per cell: a task's tile is the
    /// region ((lo, iy), (hi − lo, 1)); cells outside it are left out.
    pub(crate) fn region_of(
        (spec, slots): (&ChartSpec, usize),
        origin: (usize, usize),
        size: (usize, usize),
        cells: &[ChartCell],
    ) -> ChartArrays {
        let slots = slots.max(1);
        let (x0, y0) = origin;
        let x = &spec.x[x0.min(spec.x.len())..(x0 + size.0).min(spec.x.len())];
        let y = &spec.y[y0.min(spec.y.len())..(y0 + size.1).min(spec.y.len())];
        let (nx, ny) = (x.len(), y.len());
        let n = nx * ny;
        let mut a = ChartArrays {
            x: x.to_vec(),
            y: y.to_vec(),
            slots,
            attractors: vec![0; n],
            failures: vec![0; n],
            period: vec![0; n * slots],
            motion: vec![0; n * slots],
            lyapunov: vec![f64::NAN; n * slots],
            lyapunov_error: vec![f64::NAN; n * slots],
            x_max: vec![f64::NAN; n * slots],
            v_t_min: vec![f64::NAN; n * slots],
            contacts_per_period: vec![f64::NAN; n * slots],
            contact_fraction: vec![f64::NAN; n * slots],
            fraction: vec![f64::NAN; n * slots],
            dominant_period: vec![0; n],
        };
        let inside =
            |c: &&ChartCell| (x0..x0 + nx).contains(&c.ix) && (y0..y0 + ny).contains(&c.iy);
        for c in cells.iter().filter(inside) {
            let cell = (c.iy - y0) * nx + (c.ix - x0);
            a.attractors[cell] = c.attractors.len() as i32;
            a.failures[cell] = c.failures as i32;
            for (k, at) in c.attractors.iter().take(slots).enumerate() {
                let i = cell * slots + k;
                a.period[i] = at.period.map_or(-1, |p| p as i32);
                a.motion[i] = at.motion().code();
                a.lyapunov[i] = at.lyapunov.unwrap_or(f64::NAN);
                a.lyapunov_error[i] = at.lyapunov_error.unwrap_or(f64::NAN);
                a.x_max[i] = at.x_max;
                a.v_t_min[i] = at.v_t_min;
                a.contacts_per_period[i] = at.contacts_per_period;
                a.contact_fraction[i] = at.contact_fraction;
                a.fraction[i] = at.fraction;
            }
            a.dominant_period[cell] = a.period[cell * slots];
        }
        a
    }
}
