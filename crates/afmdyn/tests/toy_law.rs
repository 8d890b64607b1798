//! The toy contact law `spring_adhesion` (feature `toy-law`: a linear spring with a constant
//! adhesion force, F_c = α4 δ + α6 δ̇ − F̃_ad in contact) shows that a law is one file plus one
//! registry line: `crates/afmdyn/src/contact/spring_adhesion.rs` and the line
//! `spring_adhesion => SpringAdhesion { adhesion } : SpringAdhesionLaw` of `contact.rs`'s
//! `laws!` (with its `#[cfg(feature = "toy-law")]`, because the toy law does not ship; the
//! feature and this test's `required-features` are the only other lines, in Cargo.toml).
//!
//! From those alone it runs through the registry (parser, serde form, descriptors, the groups'
//! owners), the request schema and a request, the force law's identities, an orbit (shooting)
//! and an approach (stepped curve); the conformance suite takes every registered law, so
//! `cargo test -p afmdyn --features toy-law --test main conformance::` runs its cases on it too.
#![cfg(feature = "toy-law")]

use afmdyn::analysis::approach::{approach_retract, approach_spec};
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::analysis::stepped::Spacing;
use afmdyn::contact::{LawGroups, TipSample, TipSampleLaw, LAWS};
use afmdyn::integrate::{advance, build, IntegratorKind, IntegratorOptions};
use afmdyn::maps::StroboscopicMap;
use afmdyn::request::ModelSpec;
use afmdyn::{CantileverModel, ContactLaw, LawKind, Params};
use std::path::{Path, PathBuf};

const TOY: ContactLaw = ContactLaw::SpringAdhesion { adhesion: 0.1 };

fn params() -> Params {
    Params {
        contact_law: TOY,
        omega: 2.8,
        ..Params::default()
    }
}

/// The text files under `dir` (sources, Python, the explorer), without build outputs.
fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        let name = e.file_name().to_string_lossy().into_owned();
        if p.is_dir() {
            if !matches!(name.as_str(), "target" | "node_modules" | "pkg") && !name.starts_with('.')
            {
                files(&p, out);
            }
        } else if ["rs", "py", "pyi", "js", "mjs", "ts", "html", "toml", "md"]
            .iter()
            .any(|x| name.ends_with(&format!(".{x}")))
        {
            out.push(p);
        }
    }
}

/// The toy law is spelled in its own file and in one line of the registry, nowhere else in the
/// crates or the explorer (this test aside).
#[test]
fn the_toy_law_is_one_file_and_one_registry_line() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut all = Vec::new();
    files(&root.join("crates"), &mut all);
    files(&root.join("explorer"), &mut all);
    let mut spelled: Vec<(String, usize)> = Vec::new();
    for f in all {
        let rel = f
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        if rel.ends_with("tests/toy_law.rs") {
            continue;
        }
        let Ok(text) = std::fs::read_to_string(&f) else {
            continue;
        };
        let lines = text
            .lines()
            .filter(|l| l.contains("spring_adhesion") || l.contains("SpringAdhesion"))
            .count();
        if lines > 0 {
            spelled.push((rel, lines));
        }
    }
    spelled.sort();
    eprintln!("files spelling the toy law: {spelled:?}");
    let names: Vec<&str> = spelled.iter().map(|(f, _)| f.as_str()).collect();
    assert_eq!(
        names,
        [
            "crates/afmdyn/src/contact.rs",
            "crates/afmdyn/src/contact/spring_adhesion.rs"
        ]
    );
    assert_eq!(spelled[0].1, 1, "one registry line");
}

/// The registry gives the parser, the serde form, the descriptor and the groups' owners.
#[test]
fn the_registry_carries_the_toy_law() {
    let kind: LawKind = "Spring_Adhesion".parse().unwrap();
    assert_eq!(kind, TOY.kind());
    assert_eq!(TOY.name(), "spring_adhesion");
    assert!(LawKind::ALL.contains(&kind));
    assert!(LawKind::EXPECTED.ends_with("or spring_adhesion"));
    let info = LAWS.iter().find(|l| l.name == "spring_adhesion").unwrap();
    assert_eq!(info.params.len(), 1);
    assert_eq!(info.params[0].name, "adhesion");
    // the serde form of every law: {"law": name, groups…}
    let json = serde_json::to_string(&TOY).unwrap();
    assert_eq!(json, r#"{"law":"spring_adhesion","adhesion":0.1}"#);
    assert_eq!(serde_json::from_str::<ContactLaw>(&json).unwrap(), TOY);
    // a front end's groups: its own accepted, another law's refused naming the owners
    let groups = LawGroups {
        adhesion: Some(0.3),
        ..LawGroups::default()
    };
    let law = ContactLaw::from_parts(Some(kind), groups, ContactLaw::Linear).unwrap();
    assert_eq!(law, ContactLaw::SpringAdhesion { adhesion: 0.3 });
    let other = LawGroups {
        hamaker: Some(1e-5),
        ..LawGroups::default()
    };
    let err = ContactLaw::from_parts(Some(kind), other, ContactLaw::Linear).unwrap_err();
    assert!(err.to_string().contains("dmt or electrostatic"), "{err}");
    let err = ContactLaw::from_parts(Some(LawKind::Hertz), groups, ContactLaw::Linear);
    assert!(
        err.unwrap_err()
            .to_string()
            .contains("jkr or spring_adhesion"),
        "the owners of adhesion"
    );
    assert!(ContactLaw::SpringAdhesion { adhesion: -1.0 }
        .validate()
        .is_err());
    assert_eq!(
        kind.with_groups(LawGroups::default()),
        TOY,
        "its default F̃_ad"
    );
}

/// The request schema lists the toy law, and a request with it resolves to it.
#[test]
fn the_schema_and_a_request_take_the_toy_law() {
    let schema = schemars::schema_for!(ModelSpec).to_value().to_string();
    assert!(schema.contains(r#""const":"spring_adhesion""#), "{schema}");
    let spec: ModelSpec =
        serde_json::from_str(r#"{"contact_law": "spring_adhesion", "adhesion": 0.25}"#).unwrap();
    let p = spec.resolve(Params::default(), None).unwrap();
    assert_eq!(p.contact_law, ContactLaw::SpringAdhesion { adhesion: 0.25 });
}

/// The force's partials are its central differences and its conservative part is the
/// potential's derivative; the adhesion pulls in contact only.
#[test]
fn force_partials_and_potential_are_consistent() {
    let ts = TipSample {
        law: TOY,
        stiffness: 20.0,
        damping: 0.2,
    };
    assert_eq!(ts.force(false, -0.1, 0.3).force, 0.0);
    assert_eq!(ts.force(true, 0.0, 0.0).force, -0.1);
    for (delta, rate) in [(0.07, 0.3), (0.5, -1.2)] {
        let f = ts.force(true, delta, rate);
        let h = 1e-6;
        let fd = (ts.force(true, delta + h, rate).force - ts.force(true, delta - h, rate).force)
            / (2.0 * h);
        assert!((f.d_delta - fd).abs() < 1e-6 * (1.0 + fd.abs()));
        let du = (ts.potential(true, delta + h) - ts.potential(true, delta - h)) / (2.0 * h);
        let cons = f.force - ts.dissipative(true, delta, rate);
        assert!((du - cons).abs() < 1e-6 * (1.0 + du.abs()));
    }
}

/// A period-1 orbit by shooting: it touches the sample and is a fixed point of the period map.
#[test]
fn an_orbit_by_shooting() {
    let m = CantileverModel::new(&params()).unwrap();
    let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
    let map = &mut StroboscopicMap::new(it.as_mut(), 1);
    let o = shoot(map, &m.rest(), &ShootingOptions::default()).unwrap();
    assert!(o.switchings >= 2, "the orbit touches the sample");
    let opts = IntegratorOptions {
        kind: IntegratorKind::Adaptive,
        tolerance: 1e-12,
        ..Default::default()
    };
    let mut it = build(&m, opts, 0.0, &o.state).unwrap();
    advance(it.as_mut(), m.period()).unwrap();
    let err = (it.state() - &o.state).amax();
    assert!(err < 1e-7, "fixed point of the period map: {err:e}");
}

/// An approach–retract curve: the far points fly free, the near ones tap.
#[test]
fn an_approach_curve() {
    let spec = approach_spec(params(), 1.5, 0.2, Spacing::Points(7)).unwrap();
    let c = approach_retract(&spec).unwrap();
    assert_eq!(c.first.len(), 7);
    assert!(c.largest_indentation() > 0.0, "the near points tap");
}
