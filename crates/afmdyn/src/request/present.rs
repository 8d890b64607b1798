//! The presentations of the requests' results ([`crate::report::Presentation`]): per family
//! of commands, the text summary, the tables, datasets and figures that every front end
//! writes as they are. Each [`super::Analysis::present`] calls its function here; the studies
//! a front end runs into a store of its own (`chart`, `image`) and the commands without a
//! computation of their own (`modes --sweep fig3`, `units`, `cantilevers`) call theirs
//! directly.

#[cfg(feature = "files")]
pub(crate) mod continuation;
pub mod image;
pub mod maps;
pub mod modes;
pub(crate) mod orbits;
