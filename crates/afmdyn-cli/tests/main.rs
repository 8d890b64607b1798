//! The command line's integration tests, one binary (crates/afmdyn-cli/Cargo.toml:
//! `autotests = false`): each tests/*.rs file is a module here, so `cargo test -p afmdyn-cli
//! --test main fm::` runs tests/fm.rs.

// the helpers the files share (tests/common/)
mod common;

mod approach;
mod battery;
mod bimodal;
mod bounded_inputs;
mod calibrate;
mod chart;
mod cli;
mod fit_map;
mod fm;
mod image;
mod interrupt;
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
mod thermal;
mod wasm_api;

/// Every tests/*.rs file is a module above: with `autotests = false` cargo no longer builds a
/// new file by itself, which would then run nothing.
#[test]
fn every_test_file_is_built() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let main = include_str!("main.rs");
    for entry in std::fs::read_dir(root.join("tests")).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if let Some(stem) = name.strip_suffix(".rs").filter(|s| *s != "main") {
            assert!(
                main.contains(&format!("\nmod {stem};\n")),
                "tests/{name} is in no test binary: add `mod {stem};` to tests/main.rs"
            );
        }
    }
}
