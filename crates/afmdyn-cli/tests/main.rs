//! The command line's integration tests, one binary (crates/afmdyn-cli/Cargo.toml:
//! `autotests = false`): each tests/*.rs file is a module here, so `cargo test -p afmdyn-cli
//! --test main fm::` runs tests/fm.rs.

// the helpers the files share (tests/common/)
mod common;

mod approach;
mod battery;
mod bimodal;
mod bounded_inputs;
mod chart;
mod cli;
mod fm;
mod image;
mod laws;
mod limits_and_files;
mod long_runs;
mod messages;
mod peakforce;
mod probe;
mod probe_text;
mod reconstruct;
mod request_flags;
mod silent_answers;
mod wasm_api;
