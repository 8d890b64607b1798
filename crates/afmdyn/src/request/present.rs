//! The presentation that still reads request types: the images (their result types are the
//! requests'); the others are [`crate::report::present`]'s.

pub mod image;
