//! Fitting measured curves (issue 62): weighted least squares by Levenberg–Marquardt with
//! standard errors, correlations, profile-likelihood intervals and identifiability warnings
//! (`least_squares`, `estimates`, [`profile`]), and the quasi-static force-curve fit of the
//! registry's contact laws ([`force_curve`]; the standard linear solid's in time,
//! `sls_curve`); start values from a grid (`start`). The
//! dynamic fits' models: the stepped AM approach (`am_curve`) and the FM loop's Δf curve
//! (`fm_curve`) and the bimodal channels (`bimodal_curve`), with the exact orbit
//! sensitivities of [`sensitivity`].

pub(crate) mod am_curve;
pub(crate) mod bimodal_curve;
pub(crate) mod contact_rows;
pub(crate) mod estimates;
pub(crate) mod fm_curve;
pub mod force_curve;
pub(crate) mod least_squares;
pub mod map;
pub(crate) mod orbit_param;
pub mod profile;
pub mod sensitivity;
pub(crate) mod sensitivity_jkr;
pub(crate) mod sls_curve;
pub mod start;

pub use estimates::{fit_cancellable, fit_with, Estimate, FitOutcome};
pub use least_squares::{CurveModel, Minimum, Observations, Parameter};
pub use profile::{Profile, ProfileEnd, ProfileWalk};
