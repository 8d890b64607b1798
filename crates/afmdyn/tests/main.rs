//! The library's integration tests, compiled inside the crate as the module `integration` of
//! its test build (src/lib.rs; they reach `pub(crate)` items): each tests/*.rs file is a module
//! here, so `cargo test -p afmdyn --lib integration::fm::` runs
//! tests/fm.rs. The modules that read probe files need the `files` feature and those that set
//! rayon's thread count `parallel`. Two files are binaries of their own: tests/door.rs (a
//! counting global allocator, the peak heap over all threads, and cancels timed) and
//! tests/toy_law.rs (feature `toy-law`).

// the helpers the files share (tests/common/)
mod common;

mod analysis;
#[cfg(feature = "files")]
mod approach;
#[cfg(feature = "parallel")]
mod basins;
mod bimodal;
mod bounded;
mod capillary;
mod conformance;
mod dense_samples;
mod eigenmodes;
mod electrostatic;
mod exact_paths;
mod fit;
#[cfg(feature = "files")]
mod fit_bimodal;
#[cfg(feature = "files")]
mod fit_dynamic;
#[cfg(feature = "files")]
mod fit_fm;
#[cfg(feature = "files")]
mod fit_jkr;
#[cfg(feature = "files")]
mod fit_lever;
#[cfg(all(feature = "files", feature = "parallel"))]
mod fit_map;
#[cfg(feature = "files")]
mod fit_profiles;
mod fit_sls;
#[cfg(feature = "files")]
mod fit_viscosity;
mod fm;
mod fm_range;
#[cfg(feature = "parallel")]
mod global_continuation;
mod high_q;
mod hydro;
mod image;
mod image_peakforce;
mod image_scan;
mod impact;
#[cfg(feature = "files")]
mod input_limits;
mod integrators;
mod jkr;
mod jkr_settle;
mod laws;
mod laws_table;
mod layouts;
mod layouts_documents;
mod limits;
mod limits_table;
mod liquid;
mod maps;
mod modal;
mod observables;
mod params_units;
mod peakforce;
mod peakforce_sweep;
#[cfg(feature = "files")]
mod probe;
mod reconstruct;
mod report;
mod schema;
mod sls;
mod stability;
#[cfg(feature = "parallel")]
mod study;
mod taylor;
mod time_average;
mod tip_sample;
mod torus;

/// Every tests/*.rs file is a module above or a binary of its own in Cargo.toml: with
/// `autotests = false` cargo no longer builds a new file by itself, which would then run nothing.
#[test]
fn every_test_file_is_built() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let main = include_str!("main.rs");
    let manifest = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
    for entry in std::fs::read_dir(root.join("tests")).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if let Some(stem) = name.strip_suffix(".rs").filter(|s| *s != "main") {
            assert!(
                main.contains(&format!("\nmod {stem};\n"))
                    || manifest.contains(&format!("path = \"tests/{name}\"")),
                "tests/{name} is in no test binary: add `mod {stem};` to tests/main.rs"
            );
        }
    }
}
