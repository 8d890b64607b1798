//! # afmdyn — multi-modal tapping-mode AFM dynamics with intermittent contact
//!
//! Implements the model of *Multi-modal analysis on the intermittent contact dynamics of atomic
//! force microscope* ("the paper", `shared/paper/multimodal-afm-intermittent-contact.md`):
//! an Euler–Bernoulli cantilever discretised into N clamped–free Galerkin modes (eq. 9), a tip
//! mass α1 (Dirac delta, couples the modes), a base drive α2 sin Ωτ, and a sample spring α4 and
//! damper α6 that act while the tip displacement V_T (eq. 8) is ≤ 0 (gap α5).
//!
//! The tree follows the paper:
//! `beam` (mode shapes) → `galerkin` (eqs. 10–18) → [`eigen`] (eqs. 19–23) and [`units`]
//! (eqs. 5, 7) → [`contact`] (tip–sample laws) → [`system`] (the hybrid-system interface,
//! saltation) → [`model`] (the cantilever–sample system) → [`tip_sample`] (what integrators and
//! analyses need of a probe over a sample) → [`integrate`] (exact propagation, RK4, the
//! adaptive DOP853 oracle, Taylor series, split) → [`maps`] (the flow map with its Jacobian and
//! saltation, the stroboscopic map) and [`trajectory`] (observables, stroboscopic Poincaré
//! section) → [`analysis`] (steady states, periods, bifurcation sweeps, attractors, mode
//! convergence);
//! [`request`] is what every front end hands the library (parameters by name, defaults, limits);
//! [`report`] builds the JSON result documents shared by the command line and Python;
//! [`study`] runs the analyses made of many tasks (one executor, one kind of store);
//! [`layout`] declares every result's variables once (NetCDF, Python datasets, Zarr).
//!
//! Time is the dimensionless τ of eq. 5 and displacements are in units of the beam gap g₀.
//! States are `z: [f64; 2N]` = (a, ȧ), modal coordinates and their τ-derivatives.
//!
//! ```
//! use afmdyn::analysis::steady::{steady_state, Motion, SteadyOptions};
//! use afmdyn::integrate::{build, IntegratorOptions};
//! use afmdyn::{CantileverModel, Params};
//!
//! // the paper's Figs. 5–14 set at Ω = 2.8 (eq. 26, α1 = 0.1, N = 3)
//! let params = Params { omega: 2.8, ..Params::default() };
//! let model = CantileverModel::new(&params)?;
//! let mut integ = build(&model, IntegratorOptions::default(), 0.0, &model.rest())?;
//! let orbit = steady_state(integ.as_mut(), &SteadyOptions::default())?;
//! assert_eq!(orbit.motion, Motion::Periodic { period: 2 });
//! assert!(orbit.stats.contact_fraction > 0.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## What is public
//!
//! * The front ends (the command line, Python, WebAssembly, `afmdyn-plot`) reach the library
//!   through [`request`] (the requests, their names, defaults and limits, the one door that
//!   admits and runs them), [`report`] (the result documents), [`layout`] (the result variables
//!   and files), [`study`] (the stores that resume), [`probe`], [`cantilevers`], [`units`],
//!   [`hydro`], [`io`] and [`error`].
//! * The model and the algorithms — [`params`], [`model`], [`contact`], [`integrate`], [`maps`],
//!   [`analysis`], [`trajectory`], [`system`], [`tip_sample`], `beam`, `galerkin`,
//!   [`eigen`] and the re-exports below — are public for use as a library (the example above),
//!   the examples and the benchmarks.
//! * The integration tests (`crates/afmdyn/tests/main.rs` and its modules) are compiled inside
//!   the crate, as the module `integration` of its test build: they reach `pub(crate)` items
//!   and so do not make an item public. Two stay binaries of their own, outside the crate:
//!   `tests/door.rs` (a counting global allocator: the door over every request) and
//!   `tests/toy_law.rs` (a law added as an outside user would).
//! * Everything else is `pub(crate)`: an item is public only when one of those names it or a
//!   public item's signature shows it.
//!
//! ## Features
//!
//! All three are on by default; the command line and the Python module use them.
//!
//! * `parallel` — the independent runs of [`analysis::bifurcation`] (sweep points, chains and
//!   random starts), [`analysis::attractors`] (random starts, polishing), charts and basin maps
//!   on rayon's thread pool ([`study::execute`] builds it). Without it the same code runs them
//!   one after another; every seed comes from the run's index, so the results are the same.
//! * `files` — the library's I/O: reading probe files (`Probe::load(path)`; [`probe::Probe::parse`]
//!   takes the TOML text and is always there), the studies' stores in locked directories
//!   (`study::checkpoint_file`, `study::chart_store`, `io::dir_lock`), the sample maps'
//!   height map files (`io::height_map`: CSV and NPY) and the result files: NetCDF
//!   (`layout::netcdf`), streamed CSV and NPY (`layout::files`).
//! * `schema` — JSON Schemas of the requests (`schemars::JsonSchema` on [`request`]'s types;
//!   `docs/schema/` holds them).
//!
//! With `--no-default-features` the library builds for `wasm32-unknown-unknown` (CI checks
//! `cargo build -p afmdyn --lib --target wasm32-unknown-unknown --no-default-features`).
#![warn(missing_docs)]

/// A warning of a result's document: `warning!("code", "what to do", "message {x}", args…)` is
/// `format!("message {x}", args…)`. The code and the advice are for the book's catalogue of
/// messages (`docs/reference/messages.md`), which `scripts/gen_reference.py` writes from these
/// invocations; it fails on a warning pushed without one.
macro_rules! warning {
    ($code:literal, $todo:literal, $($message:tt)+) => {{
        let _: [&str; 2] = [$code, $todo];
        #[allow(clippy::useless_format)]
        let message = format!($($message)+);
        message
    }};
}

pub mod analysis;
pub(crate) mod beam;
pub mod cantilevers;
pub mod contact;
pub mod eigen;
pub mod error;
pub(crate) mod galerkin;
pub mod hydro;
pub mod integrate;
pub mod io;
pub mod layout;
mod linalg;
pub mod maps;
pub mod model;
pub mod params;
pub mod probe;
pub mod report;
pub mod request;
pub(crate) mod roots;
pub mod study;
pub mod system;
pub mod tip_sample;
pub mod trajectory;
pub mod units;

pub use contact::{ContactLaw, LawKind};
pub use error::{ParamError, SimError, UnitsError};
pub use integrate::{Integrator, IntegratorKind, IntegratorOptions};
pub use model::CantileverModel;
pub use params::{Excitation, Hydrodynamic, Params, Structure, SweepParam};
pub use system::{EventKind, HybridSystem, Region};
pub use tip_sample::TipSampleSystem;

// the integration tests, inside the crate's test build (see "What is public"): their
// `afmdyn::` paths name this crate
#[cfg(test)]
extern crate self as afmdyn;
#[cfg(test)]
#[path = "../tests/main.rs"]
mod integration;
