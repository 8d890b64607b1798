//! The presentations that still read request types: the images (their result types are
//! the requests'), the maps (`chart`, `basins`: the chart's axes and model) and the
//! bifurcation sweep (its records and store); the others are [`crate::report::present`]'s.

pub mod image;
pub(crate) mod maps;
