//! The request layer every front end shares (the command line, Python, later WebAssembly and
//! Dask): what a user asks of an analysis, by name, with its defaults and every limit.
//!
//! - [`model`]: the model values of a request ([`ModelSpec`]: α1…α6, Ω, N, the tip–sample law,
//!   and with a probe file the SI values z_c and drive frequency), resolved into [`Params`]
//!   in one precedence; and the one table of their names, aliases, units, ranges and help
//!   ([`MODEL_PARAMETERS`]).
//! - [`analyses`]: one request per analysis (`simulate`, `converge`, `bifurcation`,
//!   `attractors`, `orbit`, `continuation`, `lyapunov`, `observe`) with `validate`, and `run`
//!   where the analysis is one library call.
//! - [`chart`](mod@chart): the two-parameter behaviour chart ([`ChartRequest`]), its limits,
//!   fingerprint and cost (it runs as a study of tiles, with its document and store, in the
//!   study layer).
//! - [`curves`]: the stepped curves (`approach`, `resonance`).
//! - [`run`](mod@run): [`run()`]`(analysis, model, progress)` → [`Document`], the typed result and
//!   its JSON document, for every analysis whose result is one value ([`Analysis`]).
//! - [`named`]: every analysis by its name ([`named::parse`]) as a [`named::NamedRequest`];
//!   the one door of Python and WebAssembly.
//! - [`limits`]: the limits beyond the model's ranges, each with its reason, and the budgets of
//!   a request's cost ([`limits::Cost`]), which `costs` estimates before it runs.
//! - [`sweep`]: the records of a bifurcation sweep (columns, codes, the one row order) and the
//!   fingerprint of its request.
//!
//! A front end maps its spelling of a name to a request field and nothing else; errors name
//! the library's parameter (`samples_per_period`) and a front end respells them
//! ([`crate::SimError::spelled`]: `--samples-per-period`).
//!
//! [`Params`]: crate::Params

/// `impl Request for TYPE` of a request whose methods are one expression each: its name, its
/// `COST_ADVICE` and `probe_needs` where they are not the trait's defaults, and the bodies of
/// `validate`, `cost` and (where it is not the model's parameters) `computed_at`, each over
/// the request and its model (`|r, model|`); `[TYPE, NAME; …]` first, several requests sharing
/// the bodies.
macro_rules! impl_request {
    ([] $($rest:tt)*) => {};
    ([$t:ty, $name:literal $(; $ts:ty, $names:literal)*] $($rest:tt)*) => {
        impl_request! { $t, $name; $($rest)* }
        impl_request! { [$($ts, $names);*] $($rest)* }
    };
    (
        $(#[$attr:meta])*
        $t:ty, $name:literal $(, advice = $advice:expr)? $(, needs = $needs:ident)?;
        validate |$vr:pat_param, $vm:pat_param| $validate:expr;
        cost |$cr:pat_param, $cm:pat_param| $cost:expr
        $(; computed_at |$ar:pat_param, $am:pat_param| $at:expr)? $(;)?
    ) => {
        $(#[$attr])*
        impl $crate::request::run::Request for $t {
            $(const COST_ADVICE: &'static str = $advice;)?
            fn validate(
                &self,
                model: &$crate::request::run::Resolved,
            ) -> Result<(), $crate::error::SimError> {
                let ($vr, $vm) = (self, model);
                $validate
            }
            fn name(&self) -> &'static str {
                $name
            }
            $(fn probe_needs(&self) -> $crate::probe::ProbeNeeds {
                $crate::probe::ProbeNeeds::$needs
            })?
            fn cost(
                &self,
                model: &$crate::request::run::Resolved,
            ) -> Result<$crate::request::limits::Cost, $crate::error::SimError> {
                let ($cr, $cm) = (self, model);
                $cost
            }
            $(fn computed_at(
                &self,
                model: &$crate::request::run::Resolved,
            ) -> Result<$crate::params::Params, $crate::error::SimError> {
                let ($ar, $am) = (self, model);
                $at
            })?
        }
    };
}

/// A request declared once, each field with its default beside it: the struct with the derives
/// and serde attributes every request shares (`Debug`, `Clone`, `PartialEq`, serde's
/// `Serialize` and `Deserialize` with `default` and `deny_unknown_fields`, and with the
/// `schema` feature `schemars::JsonSchema`), and its `impl Default`.
///
/// A field is `$(#[attr])* $(constants(NAME, …))? pub name: Type $(= default)?`: without
/// `= default` it takes its type's `Default::default()`; `constants(NAME, …)` lists the
/// constants its doc cites (limits, defaults) under the schema's `x-constants`
/// (`{"NAME": NAME, …}`; `NAME in path` for one not in scope, `{"NAME": path::NAME}`). After
/// a `;`, `flatten name: Type, …` are the last fields: requests whose fields are the request's
/// own (`#[serde(flatten)]`, default `Type::default()`: the steady-state search, the
/// integrator, a start, a curve). Attributes before `pub struct` follow
/// the shared ones (the doc, `#[derive(Copy)]`, schemars attributes of the whole struct); a
/// doc of `default` itself follows the struct, as `/// … impl Default;`.
macro_rules! request {
    (
        $(#[$attr:meta])*
        pub struct $name:ident {
            $(
                $(#[$fattr:meta])*
                $(constants($($c:ident $(in $($m:ident)::+)?),+))?
                pub $field:ident: $ty:ty $(= $default:expr)?
            ),* $(,)?
            $(; flatten $($flat:ident: $fty:ty),+ $(,)?)?
        }
        $($(#[$dattr:meta])+ impl Default;)?
    ) => {
        #[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
        #[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
        #[serde(default, deny_unknown_fields)]
        $(#[$attr])*
        pub struct $name {
            $(
                $(#[$fattr])*
                $(#[cfg_attr(
                    feature = "schema",
                    schemars(extend("x-constants" = { $(stringify!($c): $($($m::)+)? $c),+ }))
                )])?
                pub $field: $ty,
            )*
            $($(
                #[doc = concat!("The flattened [`", stringify!($fty), "`].")]
                #[serde(flatten)]
                pub $flat: $fty,
            )+)?
        }

        impl Default for $name {
            $($(#[$dattr])+)?
            fn default() -> Self {
                Self { $($field: request!(@default $($default)?),)* $($($flat: Default::default(),)+)? }
            }
        }
    };
    (@default) => { Default::default() };
    (@default $default:expr) => { $default };
}

pub mod analyses;
pub mod basins;
pub mod calibrate;
pub mod chart;
pub(crate) mod costs;
pub mod curves;
#[cfg(feature = "files")]
pub(crate) use crate::io::dir_lock;
pub mod fm;
#[cfg(feature = "files")]
pub use crate::io::height_map as height_map_file;
pub mod fit;
pub(crate) mod fit_dynamic;
pub mod fit_map;
pub(crate) mod fit_result;
pub mod image;
pub mod image_job;
pub mod image_options;
pub mod image_peakforce;
pub mod image_scan;
pub mod keywords;
pub mod limits;
pub mod model;
mod model_of;
pub mod modes;
pub mod named;
pub mod peakforce;
pub(crate) mod peakforce_sweep;
pub mod quantity;
pub mod thermal;

pub mod reconstruct;
pub(crate) mod reconstruct_document;
pub mod run;
pub mod simulate;
#[cfg(feature = "files")]
pub mod simulate_stream;
pub mod sweep;

pub use analyses::{
    AttractorsRequest, BifurcationRequest, ContinuationRequest, ConvergeRequest,
    GlobalContinuationRequest, IntegratorRequest, LyapunovRequest, ObserveRequest, OrbitRequest,
    SeriesStore, SimulateRequest, StartRequest, SteadyRequest,
};
pub use basins::{BasinArrays, BasinsRequest};
pub use calibrate::CalibrateRequest;
pub use chart::{Chart, ChartArrays, ChartModel, ChartRequest};
pub use curves::{approach_request, resonance_request, CurveRequest};
#[cfg(feature = "files")]
pub use dir_lock::{DirLock, LockError};
pub use fit::FitRequest;
pub use fit_map::FitMapRequest;
pub use fm::FmRequest;
pub use model::{parameter, ModelSpec, ParamInfo, MODEL_PARAMETERS};
pub use modes::{CantileversRequest, Fig3Request, ModesRequest, UnitsRequest};
pub use peakforce::{PeakForceRequest, PeakForceSweep, PeakForceSweepParam};
pub use reconstruct::ReconstructRequest;
pub use run::{
    admit, run, run_admitted, Analysis, ApproachRequest, Bimodal, Destination, Document,
    Presenting, Request, Resolved, ResonanceRequest,
};
pub use thermal::ThermalRequest;

// the door's vocabulary, for the front ends that go through it: the progress and cancel flag a
// run counts in, the results the curve and reconstruction requests return, the integrators a
// request names, and the contact laws' registry with the force's sign convention
pub use crate::analysis::progress::Progress;
pub use crate::analysis::stepped::SteppedCurve;
pub use crate::contact::{LawGroups, LawKind, FORCE_SIGN, GROUPS, LAWS};
pub use crate::integrate::IntegratorKind;
pub use crate::params::{Excitation, Params, SweepParam};

/// The default relative distance within which two Poincaré point sets are one attractor
/// (`cluster_tol` of the census, its global continuation, the basin map and the chart).
pub(crate) const DEFAULT_CLUSTER_TOL: f64 = 1e-5;
/// The default seed of the random initial states (`seed` of the sweep, the census, its global
/// continuation and the chart).
pub(crate) const DEFAULT_SEED: u64 = 1;
