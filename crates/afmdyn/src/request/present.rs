//! The presentations of the requests' results ([`crate::report::Presentation`]): per family
//! of commands, the text summary, the tables, datasets and figures that every front end
//! writes as they are. Each [`super::Analysis::present`] calls its function here; a front end
//! that runs a study into its own store or streams a run to files calls them directly.

#[cfg(feature = "files")]
pub mod census;
pub(crate) mod orbits;
#[cfg(feature = "files")]
pub mod simulate;
pub mod sweeps;
