//! Issue 42's battery defects on the library side, where the command line, Python and Dask
//! share them: a chart's non-finite model values, integrator tolerances, bounded input files,
//! the traces budget, the contact law's name in any case, short numbers in messages.

use afmdyn::error::{io_kind_message, number};
use afmdyn::integrate::{check_buildable, IntegratorKind, IntegratorOptions};
use afmdyn::request::limits::{read_input, InputFileError, MAX_INPUT_TEXT_BYTES};
use afmdyn::request::{approach_request, ChartRequest, CurveRequest, ModelSpec};
use afmdyn::{Params, SimError};

/// A chart refuses a NaN or an infinite model value, naming it (it travelled to the cells as
/// JSON `null` and the cells ran the default).
#[test]
fn chart_refuses_non_finite_model_values() {
    for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let base = ModelSpec {
            contact_stiffness: Some(v),
            ..ModelSpec::default()
        };
        let e = ChartRequest::default()
            .chart(base, Params::default(), None)
            .unwrap_err();
        assert!(
            matches!(
                e,
                SimError::NotFinite {
                    name: "contact_stiffness",
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.is_input_error());
    }
    let base = ModelSpec {
        contact_stiffness: Some(30.0),
        ..ModelSpec::default()
    };
    let chart = ChartRequest::default()
        .chart(base, Params::default(), None)
        .expect("a finite value is taken");
    use afmdyn::analysis::chart::CellParams;
    assert_eq!(chart.model.params(2.6, 0.1).unwrap().alpha4, 30.0);
}

/// Every integrator tolerance has the range [1e-16, 1e-3], the exact propagator's (which
/// ignores it) included.
#[test]
fn every_integrator_checks_its_tolerance() {
    let p = Params::default();
    for kind in [
        IntegratorKind::Auto,
        IntegratorKind::Exact,
        IntegratorKind::Rk4,
        IntegratorKind::Adaptive,
    ] {
        for tol in [f64::NAN, 0.0, -1.0, 1e-2, 1.0, 1e300, 1e-300, f64::INFINITY] {
            let opts = IntegratorOptions {
                kind,
                steps_per_period: 200,
                tolerance: tol,
                ..Default::default()
            };
            let e = check_buildable(&p, opts).unwrap_err();
            assert!(
                matches!(
                    e,
                    SimError::OutOfRange {
                        name: "tolerance",
                        ..
                    }
                ),
                "{kind:?} {tol}: {e}"
            );
        }
        for tol in [1e-16, 1e-12, 1e-3] {
            let opts = IntegratorOptions {
                kind,
                steps_per_period: 200,
                tolerance: tol,
                ..Default::default()
            };
            check_buildable(&p, opts).unwrap_or_else(|e| panic!("{kind:?} {tol}: {e}"));
        }
    }
}

/// An input file is read with at most the limit in memory: `/dev/zero` is refused as too large
/// at once, a binary file as not text, each naming the file; the probe loader (Python's
/// `probe=`) reads through it.
#[test]
fn input_files_are_bounded() {
    let zero = std::path::Path::new("/dev/zero");
    if zero.exists() {
        let start = std::time::Instant::now();
        let e = read_input(zero, MAX_INPUT_TEXT_BYTES).unwrap_err();
        assert!(matches!(e, InputFileError::TooLarge { .. }), "{e}");
        assert!(
            e.to_string()
                .starts_with("/dev/zero: larger than 1048576 bytes"),
            "{e}"
        );
        let e = afmdyn::probe::Probe::load(zero).unwrap_err();
        assert!(e.to_string().contains("/dev/zero: larger than"), "{e}");
        // the reader of Python's probe= in every form (read the whole of /dev/zero before)
        let e = afmdyn::probe::Probe::source_text(
            afmdyn::probe::ProbeSource::Path(zero),
            (None, None),
            afmdyn::probe::ProbeNeeds::Oscillation,
        )
        .unwrap_err();
        assert!(e.to_string().contains("/dev/zero: larger than"), "{e}");
        assert!(start.elapsed().as_secs_f64() < 5.0);
    }
    let dir = std::env::temp_dir().join(format!("afmdyn-input-limits-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bin = dir.join("bin.toml");
    std::fs::write(&bin, [b'a', b'=', 0xff]).unwrap();
    let e = read_input(&bin, MAX_INPUT_TEXT_BYTES).unwrap_err();
    assert_eq!(
        e,
        InputFileError::NotText {
            path: bin.display().to_string(),
            offset: 2
        }
    );
    // exactly the limit is taken, one byte more is not
    let text = dir.join("text.toml");
    std::fs::write(&text, "a = 1\n").unwrap();
    assert_eq!(read_input(&text, 6).unwrap(), "a = 1\n");
    assert!(matches!(
        read_input(&text, 5),
        Err(InputFileError::TooLarge { limit: 5, .. })
    ));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The traces of a stepped curve are refused up front beyond 1 GiB for the worst case
/// (points × samples × 16 periods × 24 bytes): 1000 × 10000 is 3.6 GiB, 200 × 200 is 15 MiB.
#[test]
fn traces_have_a_memory_budget() {
    let req = |points, traces| CurveRequest {
        points: Some(points),
        traces: Some(traces),
        ..CurveRequest::default()
    };
    let e = approach_request(Params::default(), &req(1000, 10000), 1.0, false).unwrap_err();
    assert!(matches!(e, SimError::Budget { what: "traces", .. }), "{e}");
    assert!(e.to_string().contains("up to 3.6 GiB"), "{e}");
    assert!(e.is_input_error());
    approach_request(Params::default(), &req(200, 200), 1.0, false).expect("within the budget");
}

/// The contact law's name in any case, in a config file as on the command line.
#[test]
fn contact_law_in_any_case() {
    let spec: ModelSpec = afmdyn::request::model::parse_toml("contact_law = \"HERTZ\"").unwrap();
    assert_eq!(spec.contact_law, Some(afmdyn::contact::LawKind::Hertz));
    let e = afmdyn::request::model::parse_toml::<ModelSpec>("contact_law = \"hooke\"").unwrap_err();
    assert!(
        e.contains("expected linear, hertz, dmt, electrostatic, jkr, capillary, sls or impact"),
        "{e}"
    );
}

/// Numbers in messages: at most 6 significant digits, 1e300 not as 301 digits.
#[test]
fn numbers_in_messages_are_short() {
    assert_eq!(number(4.999983500000001e6), "4999980");
    assert_eq!(number(1e300), "1e300");
    assert_eq!(number(1.234567890123e-7), "1.23457e-7");
    assert_eq!(number(0.1 + 0.2), "0.3");
    assert_eq!(number(2.5), "2.5");
    assert_eq!(number(f64::NAN), "NaN");
    let e = SimError::out_of_range("periods", 1e300, "must be <= 1e8");
    assert_eq!(e.to_string(), "periods = 1e300: must be <= 1e8");
    assert_eq!(
        e.spelled(|n| format!("--{n}")),
        "--periods = 1e300: must be <= 1e8"
    );
    let e = afmdyn::ParamError::NonNegative {
        name: "alpha4",
        value: -1.0000000000000002,
    };
    assert_eq!(e.to_string(), "alpha4 = -1: must be finite and >= 0");
    assert_eq!(
        io_kind_message(std::io::ErrorKind::StorageFull),
        "no space left on device"
    );
}

/// Q = 1e308 is refused naming the quality factor and its range, not as α2 = NaN.
#[test]
fn quality_factor_has_a_range() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/probe-point-mass-dmt.toml"
    ))
    .unwrap();
    for q in ["1e308", "1e8", "0"] {
        let t = text.replace("quality_factor = 400 ", &format!("quality_factor = {q} "));
        let e = afmdyn::probe::Probe::parse(&t, "p.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("[cantilever].quality_factor") && e.contains("(0, 1e7]"),
            "{q}: {e}"
        );
        assert!(!e.contains("NaN") && !e.contains("[drive]"), "{q}: {e}");
    }
    let t = text.replace("quality_factor = 400 ", "quality_factor = 1e7 ");
    afmdyn::probe::Probe::parse(&t, "p.toml").expect("Q = 1e7 is taken");
}
