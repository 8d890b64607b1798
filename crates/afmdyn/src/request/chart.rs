//! `chart`: a behaviour chart over two model parameters (issue 29), the same request for
//! every front end (`afmdyn chart`, Python's `afmdyn.chart` and `afmdyn.dask.chart`).
//!
//! An axis is any real model parameter of [`crate::request::model::MODEL_PARAMETERS`] by its name or the paper's
//! alias (`omega`, `alpha2` / `drive_amplitude`, `restitution`, `hamaker`, …), and with a
//! probe file the SI quantities `z_c` (m) and `drive_frequency` (Hz); every cell's parameters
//! resolve through [`ModelSpec::resolve`] like a single run's. The chart's cells and tasks are
//! [`crate::analysis::chart`]'s; this module holds the request, its limits, its fingerprint
//! (what a resumed chart must match); the one layout of its results is
//! `crate::report::chart_layout`'s ([`ChartArrays`], the variables of `chart.nc` and of
//! Python's `xarray.Dataset`; [`CSV_HEADER`], the rows of `chart.csv`), read through the
//! chart's axes and length unit where the chart runs.

use super::analyses::{IntegratorRequest, SteadyRequest};
use super::model::{parameter, ModelSpec, ValueKind};
use crate::analysis::bifurcation::SweepSpec;
use crate::analysis::chart::{CellParams, ChartSpec};
use crate::error::{in_range, SimError};
use crate::params::Params;
use crate::probe::Probe;
use serde_json::{json, Value};

pub use crate::report::chart_layout::{ChartArrays, CSV_COLUMNS, CSV_HEADER};

/// Largest number of cells of a chart (x_steps × y_steps).
pub(crate) const MAX_CHART_CELLS: usize = 1_000_000;
/// Largest number of random starts per cell.
pub const MAX_CHART_STARTS: u32 = 1000;
/// Largest number of steady-state runs from random starts in a chart (cells × starts).
pub(crate) const MAX_CHART_RUNS: usize = 10_000_000;
/// Largest tile (cells per task).
pub const MAX_CHART_TILE: usize = 10_000;
/// Largest number of attractor slots per cell in the result arrays.
pub const MAX_CHART_SLOTS: usize = 64;
/// Largest number of drive periods of a λ₁ estimate.
pub const MAX_CHART_LYAPUNOV_PERIODS: usize = 1_000_000;

request! {
    /// `chart`: period, λ₁, X_max, contacts and basin fractions of every attractor over a grid of
    /// two parameters.
    pub struct ChartRequest {
        /// The x parameter (columns): a real model parameter's name or alias (`-` read as `_`).
        pub x: String = "omega".into(),
        /// First x value (in the parameter's unit: dimensionless, m for z_c, Hz for
        /// drive_frequency).
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = { "axis": "x" })))]
        pub x_from: f64 = 2.6,
        /// Last x value.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = { "axis": "x" })))]
        pub x_to: f64 = 3.0,
        /// Number of x values, ≥ 1.
        pub x_steps: usize = 9,
        /// The y parameter (rows).
        pub y: String = "drive_amplitude".into(),
        /// First y value.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = { "axis": "y" })))]
        pub y_from: f64 = 0.1,
        /// Last y value.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = { "axis": "y" })))]
        pub y_to: f64 = 0.12,
        /// Number of y values, ≥ 1.
        pub y_steps: usize = 2,
        /// Random starts per cell, 1..=[`MAX_CHART_STARTS`].
        constants(MAX_CHART_STARTS)
        pub starts: u32 = 4,
        /// Seed of the random starts.
        pub seed: u64 = super::DEFAULT_SEED,
        /// Cells per task (continuation runs along x within a tile), 1..=[`MAX_CHART_TILE`].
        constants(MAX_CHART_TILE)
        pub tile: usize = 8,
        /// Clustering tolerance of two steady states, > 0.
        pub cluster_tol: f64 = super::DEFAULT_CLUSTER_TOL,
        /// Drive periods of the λ₁ estimate of each nonperiodic attractor (0: none),
        /// ≤ [`MAX_CHART_LYAPUNOV_PERIODS`].
        constants(MAX_CHART_LYAPUNOV_PERIODS)
        pub lyapunov_periods: usize = 500,
        /// Attractor slots per cell in the arrays of the results ([`ChartArrays`]: `chart.nc`,
        /// Python's dataset, the Dask store), 1..=[`MAX_CHART_SLOTS`]: a cell with more keeps its
        /// first ones (most random starts first) there, and its `attractors` count tells how many
        /// it has; the CSV and JSON list every one.
        constants(MAX_CHART_SLOTS)
        pub max_attractors: usize = 8,
        /// Worker threads, 1..=[`MAX_THREADS`](super::limits::MAX_THREADS); `None`: all cores.
        constants(MAX_THREADS in super::limits)
        pub threads: Option<usize>;
        flatten steady: SteadyRequest, integrator: IntegratorRequest,
    }
}

/// The chart axes that are values of the probe file (SI): name, TOML section, key, unit. A
/// cell's probe is the file with that value replaced, resolved again (every scale follows: the
/// free amplitude A₀ is the length unit g₀).
pub(crate) const PROBE_AXES: [(&str, &str, &str, &str); 5] = [
    ("free_amplitude", "drive", "free_amplitude", "m"),
    ("sample_modulus", "sample", "youngs_modulus", "Pa"),
    ("quality_factor", "cantilever", "quality_factor", "1"),
    ("spring_constant", "cantilever", "spring_constant", "N/m"),
    ("tip_radius", "tip", "radius", "m"),
];

fn probe_axis(
    name: &str,
) -> Option<&'static (&'static str, &'static str, &'static str, &'static str)> {
    PROBE_AXES.iter().find(|a| a.0 == name)
}

/// The canonical name of a chart axis (`alpha2`, `drive-amplitude` → `drive_amplitude`).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `field` for a name that is neither a real model parameter
/// nor one of the probe values of `PROBE_AXES`.
pub fn axis_name(field: &'static str, key: &str) -> Result<&'static str, SimError> {
    let key = key.trim().to_ascii_lowercase().replace('-', "_");
    if let Some(a) = probe_axis(&key) {
        return Ok(a.0);
    }
    match parameter(&key) {
        Some(info) if info.kind == ValueKind::Real => Ok(info.name),
        _ => Err(SimError::out_of_range(
            field,
            key,
            "must be a real model parameter: omega, tip_mass_ratio (alpha1), drive_amplitude \
             (alpha2), beam_damping (alpha3), contact_stiffness (alpha4), gap (alpha5), \
             contact_damping (alpha6), restitution, hamaker, intermolecular_distance; or with a \
             probe z_c (m), drive_frequency (Hz), free_amplitude (m), sample_modulus (Pa), \
             quality_factor, spring_constant (N/m), tip_radius (m)",
        )),
    }
}

/// The parameters of a chart's cells: the request's model values with the two axes set.
#[derive(Debug, Clone, PartialEq)]
pub struct ChartModel {
    /// The model values of the request (flags, config file).
    pub base: ModelSpec,
    /// The defaults below them (the paper's set).
    pub defaults: Params,
    /// The probe file, if any.
    pub probe: Option<Probe>,
    /// The probe file's table, when an axis is one of its values (`PROBE_AXES`).
    pub probe_table: Option<toml::Table>,
    /// The x parameter's name.
    pub x: &'static str,
    /// The y parameter's name.
    pub y: &'static str,
}

impl ChartModel {
    /// Metres per unit length of the cell at (`x`, `y`) under the probe: its free amplitude A₀
    /// (g₀ = A₀ for both structural models), the axis value where an axis is `free_amplitude`;
    /// `None` without a probe (lengths stay in g₀).
    pub(crate) fn length_m(&self, x: f64, y: f64) -> Option<f64> {
        let probe = self.probe.as_ref()?;
        Some(if self.x == "free_amplitude" {
            x
        } else if self.y == "free_amplitude" {
            y
        } else {
            probe.scales.length_m
        })
    }
}

impl CellParams for ChartModel {
    fn params(&self, x: f64, y: f64) -> Result<Params, SimError> {
        let mut v = serde_json::to_value(self.base).unwrap_or_else(|_| json!({}));
        let mut table = None;
        for (key, value) in [(self.x, x), (self.y, y)] {
            if let Some(&(name, section, k, _)) = probe_axis(key) {
                let t = table.get_or_insert_with(|| self.probe_table.clone().unwrap_or_default());
                match t.get_mut(section).and_then(toml::Value::as_table_mut) {
                    Some(sec) => {
                        sec.insert(k.into(), toml::Value::Float(value));
                    }
                    None => {
                        return Err(SimError::out_of_range(
                            if key == self.x { "x" } else { "y" },
                            name,
                            "needs a probe file with the section of this value",
                        ))
                    }
                }
                continue;
            }
            if let Some(map) = v.as_object_mut() {
                // the paper's alias would clash with the name set here
                if let Some(alias) = parameter(key).and_then(|p| p.alias) {
                    map.remove(alias);
                }
                map.insert(key.into(), json!(value));
            }
        }
        let spec: ModelSpec = serde_json::from_value(v)
            .map_err(|_| SimError::out_of_range("x", format!("{x}"), "must be a finite number"))?;
        match table {
            Some(t) => {
                let probe = Probe::from_table(&t, "probe")
                    .map_err(|e| SimError::Probe(format!("the probe at x = {x}, y = {y}: {e}")))?;
                spec.resolve(self.defaults, Some(&probe))
            }
            None => spec.resolve(self.defaults, self.probe.as_ref()),
        }
    }
}

/// A validated chart: its spec, its cell parameters, its fingerprint.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    /// The chart's values and options.
    pub spec: ChartSpec,
    /// Attractor slots per cell of its arrays.
    pub slots: usize,
    /// The cells' parameters.
    pub model: ChartModel,
    /// What a resumed chart must match (`fingerprint`).
    pub fingerprint: Value,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
}

impl ChartRequest {
    /// The validated chart of the model values `base` over `defaults` (with the probe file's
    /// text `probe`): axis names and limits checked, and every cell on the chart's edges
    /// resolved (a parameter's range is an interval, so an invalid value inside a valid edge
    /// cannot occur).
    ///
    /// # Errors
    /// [`SimError::NotFinite`] naming a model value that is not a finite number;
    /// [`SimError::OutOfRange`] naming the option (`x`, `x_steps`, `starts`, `tile`, …),
    /// [`SimError::Budget`] or [`SimError::Unsupported`] for an integrator that cannot be built
    /// at a corner of the chart ([`crate::integrate::check_buildable`]);
    /// [`SimError::Params`] (or the out-of-range error of `z_c`, `drive_frequency`) for an
    /// axis value out of its parameter's range.
    pub fn chart(
        &self,
        base: ModelSpec,
        defaults: Params,
        probe: Option<&str>,
    ) -> Result<Chart, SimError> {
        base.check_finite()?;
        let x = axis_name("x", &self.x)?;
        let y = axis_name("y", &self.y)?;
        let (table, probe) = read_probe(probe)?;
        for (field, name) in [("x", x), ("y", y)] {
            if probe.is_none() && probe_axis(name).is_some() {
                return Err(SimError::out_of_range(
                    field,
                    name,
                    "needs a probe file (a value of the probe, in SI)",
                ));
            }
        }
        let uses_table = probe_axis(x).is_some() || probe_axis(y).is_some();
        if x == y {
            return Err(SimError::out_of_range(
                "y",
                y,
                "must differ from the x parameter",
            ));
        }
        self.check_options()?;
        let xs = SweepSpec::linspace(self.x_from, self.x_to, self.x_steps)?;
        let ys = SweepSpec::linspace(self.y_from, self.y_to, self.y_steps)?;
        let model = ChartModel {
            base,
            defaults,
            probe,
            probe_table: table.filter(|_| uses_table),
            x,
            y,
        };
        for &xv in &xs {
            model.params(xv, ys[0])?;
        }
        for &yv in &ys {
            model.params(xs[0], yv)?;
        }
        model.params(xs[xs.len() - 1], ys[ys.len() - 1])?;
        let spec = ChartSpec {
            x: xs,
            y: ys,
            starts: self.starts,
            seed: self.seed,
            tile: self.tile,
            cluster_tol: self.cluster_tol,
            lyapunov_periods: self.lyapunov_periods,
            steady: self.steady.options()?,
            integrator: self.integrator.options(1)?,
        };
        // the integrator's up-front budgets (steps per period, support of the law) at the
        // corners, as the attractor census checks them: an input error before any cell runs,
        // not every cell failing alike
        for (xv, yv) in super::costs::corners(&spec) {
            crate::integrate::check_buildable(&model.params(xv, yv)?, spec.integrator.clone())?;
        }
        let fingerprint = fingerprint(self, &model);
        let chart = Chart {
            spec,
            slots: self.max_attractors,
            model,
            fingerprint,
            threads: self.threads,
        };
        // held to the budgets of a request here, where every front end builds its chart
        super::costs::check_cost("chart", chart_cost(&chart)?)?;
        Ok(chart)
    }

    /// The chart's sizes and options: the threads, the steps of each axis, the cells, starts
    /// and runs in all, the tile, the clustering tolerance, the λ₁ periods, the attractors
    /// told apart, and the axes' finite ends.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] or [`SimError::NotFinite`] naming the first option that is
    /// not.
    fn check_options(&self) -> Result<(), SimError> {
        super::limits::check_threads(self.threads)?;
        in_range("x_steps", self.x_steps, 1..=MAX_CHART_CELLS)?;
        in_range("y_steps", self.y_steps, 1..=MAX_CHART_CELLS)?;
        let cells = self.x_steps.saturating_mul(self.y_steps);
        if cells > MAX_CHART_CELLS {
            return Err(SimError::out_of_range(
                "cells",
                format!("{} × {}", self.x_steps, self.y_steps),
                "must be <= 1000000 in all (fewer x_steps or y_steps)",
            ));
        }
        in_range("starts", self.starts, 1..=MAX_CHART_STARTS)?;
        if cells.saturating_mul(self.starts as usize) > MAX_CHART_RUNS {
            return Err(SimError::out_of_range(
                "starts",
                format!("{} × {cells} cells", self.starts),
                "must be <= 10000000 runs in all (fewer starts or cells)",
            ));
        }
        in_range("tile", self.tile, 1..=MAX_CHART_TILE)?;
        super::limits::positive("cluster_tol", self.cluster_tol, "must be finite and > 0")?;
        if self.lyapunov_periods != 0 {
            let (n, why) = (
                self.lyapunov_periods,
                "must be 0 (no λ₁) or in 10..=1000000",
            );
            crate::error::within("lyapunov_periods", n, 10..=MAX_CHART_LYAPUNOV_PERIODS, why)?;
        }
        in_range("max_attractors", self.max_attractors, 1..=MAX_CHART_SLOTS)?;
        crate::error::finite("x_from", self.x_from)?;
        crate::error::finite("x_to", self.x_to)?;
        crate::error::finite("y_from", self.y_from)?;
        crate::error::finite("y_to", self.y_to)?;
        Ok(())
    }
}

/// The probe file's text `probe` parsed: its table and the probe.
///
/// # Errors
/// [`SimError::Probe`] for a text that is not TOML or not a probe.
fn read_probe(probe: Option<&str>) -> Result<(Option<toml::Table>, Option<Probe>), SimError> {
    let table: Option<toml::Table> = match probe {
        Some(text) => Some(text.parse().map_err(|e: toml::de::Error| {
            SimError::Probe(format!("probe: {}", e.to_string().replace('\n', " ")))
        })?),
        None => None,
    };
    let probe = match &table {
        Some(t) => Some(Probe::from_table(t, "probe").map_err(|e| SimError::Probe(e.to_string()))?),
        None => None,
    };
    Ok((table, probe))
}

/// The fingerprint of a chart: everything that determines its cells (the library's version,
/// the model values, the probe, every chart option but the threads).
pub(crate) fn fingerprint(request: &ChartRequest, model: &ChartModel) -> Value {
    let mut r = serde_json::to_value(request).unwrap_or(Value::Null);
    if let Some(map) = r.as_object_mut() {
        map.remove("threads");
        map.insert("x".into(), json!(model.x));
        map.insert("y".into(), json!(model.y));
    }
    json!({
        "afmdyn": env!("CARGO_PKG_VERSION"),
        "chart": r,
        "model": model.base,
        "defaults": model.defaults,
        "probe": model.probe,
    })
}

/// The unit of a chart axis, for labels and the files' `units` attributes.
pub fn axis_unit(name: &str) -> &'static str {
    probe_axis(name).map_or_else(|| parameter(name).map_or("1", |p| p.unit), |a| a.3)
}

/// The cost of a chart ([`super::costs::chart_cost`] of its spec, slots and cells; its errors).
pub(crate) fn chart_cost(chart: &Chart) -> Result<super::limits::Cost, SimError> {
    super::costs::chart_cost(&chart.spec, chart.slots, &|x, y| chart.model.params(x, y))
}

impl_request! {
    /// A validated chart runs as an analysis ([`crate::request::run()`], Python's
    /// `afmdyn.chart`): its model is its own — [`ChartRequest::chart`] built it from the
    /// request's model values, defaults and probe, validated every option and held its cost to
    /// the budgets — so the `model` given here is not read (pass
    /// [`Resolved::plain`](super::run::Resolved::plain) of any parameters). Its study runs in
    /// memory on its threads.
    Chart, "chart";
    validate |_, _| Ok(());
    cost |r, _| chart_cost(r)
}
