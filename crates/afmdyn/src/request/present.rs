//! The presentations of the requests' results ([`crate::report::Presentation`]): per family
//! of commands, the text summary, the tables, datasets and figures that every front end
//! writes as they are. Each [`super::Analysis::present`] calls its function here.

pub(crate) mod orbits;
