//! The toy contact law `spring_adhesion` (feature `toy-law`: a linear spring with a constant
//! adhesion force, F_c = α4 δ + α6 δ̇ − F̃_ad in contact) shows what a new law with a new group
//! costs: its file `crates/afmdyn/src/contact/spring_adhesion.rs` and one line of
//! `contact.rs`'s `laws!` registry (with its `#[cfg(feature = "toy-law")]`, because the toy law
//! does not ship; the feature and this test's `required-features` are the only other lines, in
//! Cargo.toml). Its group `toy_adhesion` is its own: no other law has it, and it is spelled in
//! no other file either.
//!
//! From those alone it runs through the registry (parser, serde form, descriptors, the groups'
//! owners), the model's parameter table, the request schema and a request that sets the group by
//! name (JSON and a `--config` TOML file), the force law's identities, an orbit (shooting) and
//! an approach (stepped curve); the conformance suite takes every registered law, so
//! `cargo test -p afmdyn --features toy-law --lib integration::conformance::` runs its cases on it too.
//! Python's keywords are the registry's: no hand-written Python file spells a law group (the
//! generated stubs and type dictionaries aside, which `scripts/gen_stubs.py` writes from the
//! schema), and `crates/afmdyn-py/tests/test_toy_law.py` calls the law and its group from
//! Python (against a wheel built with the feature, `scripts/test.sh`).
#![cfg(feature = "toy-law")]

use afmdyn::analysis::approach::{approach_retract, approach_spec};
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::analysis::stepped::Spacing;
use afmdyn::contact::{LawGroups, TipSample, TipSampleLaw, GROUPS, LAWS};
use afmdyn::integrate::{advance, build, IntegratorKind, IntegratorOptions};
use afmdyn::maps::StroboscopicMap;
use afmdyn::request::{ModelSpec, MODEL_PARAMETERS};
use afmdyn::{CantileverModel, ContactLaw, LawKind, Params};
use std::path::{Path, PathBuf};

const TOY: ContactLaw = ContactLaw::SpringAdhesion { toy_adhesion: 0.1 };

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

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The files under crates/ and explorer/ (this test aside) with a line containing one of
/// `words`, and how many such lines each has.
fn spelling(words: &[&str]) -> Vec<(String, usize)> {
    let root = root();
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
        if rel.ends_with("tests/toy_law.rs") || rel.ends_with("tests/test_toy_law.py") {
            continue;
        }
        let Ok(text) = std::fs::read_to_string(&f) else {
            continue;
        };
        let lines = text
            .lines()
            .filter(|l| words.iter().any(|w| l.contains(w)))
            .count();
        if lines > 0 {
            spelled.push((rel, lines));
        }
    }
    spelled.sort();
    spelled
}

/// The toy law and its group are spelled in the law's own file and in one line of the
/// registry, nowhere else in the crates or the explorer (this test aside).
#[test]
fn the_toy_law_and_its_group_are_one_file_and_one_registry_line() {
    let law = spelling(&["spring_adhesion", "SpringAdhesion"]);
    let group = spelling(&["toy_adhesion"]);
    eprintln!("files spelling the toy law: {law:?}, its group: {group:?}");
    for spelled in [&law, &group] {
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
    // the group is the law's own: no other law has it
    let owners: Vec<&str> = LAWS
        .iter()
        .filter(|l| l.params.iter().any(|p| p.name == "toy_adhesion"))
        .map(|l| l.name)
        .collect();
    assert_eq!(owners, ["spring_adhesion"]);
}

/// The text of a hand-written Python file, without the blocks `scripts/gen_stubs.py` writes;
/// `None` for a generated file.
fn hand_written(text: &str) -> Option<String> {
    if text
        .lines()
        .next()
        .is_some_and(|l| l.contains("generated by"))
    {
        return None;
    }
    let mut out = String::new();
    let mut generated = false;
    for line in text.lines() {
        let marker = line.trim_start();
        if marker.starts_with("# --- ") && marker.contains("generated by scripts/gen_stubs.py") {
            generated = true;
        } else if marker.starts_with("# --- end of the generated block") {
            generated = false;
        } else if !generated {
            out.push_str(line);
            out.push('\n');
        }
    }
    Some(out)
}

/// Python's model keywords come from the registry: no hand-written file of the package spells
/// a law group as a keyword (``name``, `name=` or `name:`), so a new group needs no
/// Python line. (A Python call with the toy law needs the extension built with the feature,
/// which the Python suite does not do.)
#[test]
fn no_python_file_spells_a_law_group() {
    let mut all = Vec::new();
    files(&root().join("crates/afmdyn-py/python"), &mut all);
    assert!(!all.is_empty());
    let mut spelled = Vec::new();
    for f in all {
        let Some(text) = hand_written(&std::fs::read_to_string(&f).unwrap()) else {
            continue;
        };
        for g in GROUPS.iter().map(|g| g.name) {
            let shapes = [format!("``{g}``"), format!("{g}="), format!("{g}:")];
            if shapes.iter().any(|s| text.contains(s.as_str())) {
                spelled.push(format!("{}: {g}", f.display()));
            }
        }
    }
    assert!(spelled.is_empty(), "{spelled:?}");
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
    assert_eq!(info.params[0].name, "toy_adhesion");
    // the serde form of every law: {"law": name, groups…}
    let json = serde_json::to_string(&TOY).unwrap();
    assert_eq!(json, r#"{"law":"spring_adhesion","toy_adhesion":0.1}"#);
    assert_eq!(serde_json::from_str::<ContactLaw>(&json).unwrap(), TOY);
    // a front end's groups: its own accepted, another law's refused naming the owners
    let groups = LawGroups::default().with("toy_adhesion", 0.3);
    let law = ContactLaw::from_parts(Some(kind), groups, ContactLaw::Linear).unwrap();
    assert_eq!(law, ContactLaw::SpringAdhesion { toy_adhesion: 0.3 });
    assert_eq!(law.groups(), groups);
    let other = LawGroups::default().with("hamaker", 1e-5);
    let err = ContactLaw::from_parts(Some(kind), other, ContactLaw::Linear).unwrap_err();
    assert!(err.to_string().contains("dmt or electrostatic"), "{err}");
    let err = ContactLaw::from_parts(Some(LawKind::Hertz), groups, ContactLaw::Linear);
    assert!(
        err.unwrap_err()
            .to_string()
            .contains("toy_adhesion is a group of the spring_adhesion law"),
        "the owner of toy_adhesion"
    );
    assert!(ContactLaw::SpringAdhesion { toy_adhesion: -1.0 }
        .validate()
        .is_err());
    assert_eq!(
        kind.with_groups(LawGroups::default()),
        TOY,
        "its default F̃_ad"
    );
}

/// The model's table, the request schema and a request take the toy law and its group by name:
/// as JSON, as a `--config` TOML file, and back from a set's keywords.
#[test]
fn the_table_the_schema_and_a_request_take_the_toy_law_and_its_group() {
    let row = MODEL_PARAMETERS
        .iter()
        .find(|p| p.name == "toy_adhesion")
        .expect("a row of the table");
    assert_eq!((row.symbol, row.default), ("F̃_ad", "0.1"));
    assert!(
        row.help.starts_with("spring_adhesion law: "),
        "{}",
        row.help
    );
    let schema = schemars::schema_for!(ModelSpec).to_value();
    let text = schema.to_string();
    assert!(text.contains(r#""const":"spring_adhesion""#), "{text}");
    assert!(schema["properties"]["toy_adhesion"].is_object(), "{text}");
    let spec: ModelSpec =
        serde_json::from_str(r#"{"contact_law": "spring_adhesion", "toy_adhesion": 0.25}"#)
            .unwrap();
    let law = ContactLaw::SpringAdhesion { toy_adhesion: 0.25 };
    let p = spec.resolve(Params::default(), None).unwrap();
    assert_eq!(p.contact_law, law);
    let toml = ModelSpec::from_toml("contact_law = \"spring_adhesion\"\ntoy_adhesion = 0.25\n");
    assert_eq!(toml.unwrap(), spec);
    // a set's keywords carry the group, and serialise under its name
    let of = ModelSpec::of(&p);
    assert_eq!(of.groups.get("toy_adhesion"), Some(0.25));
    assert_eq!(of.value("toy_adhesion"), Some(0.25.into()));
    assert_eq!(serde_json::to_value(of).unwrap()["toy_adhesion"], 0.25);
    // another law refuses it, naming its owner
    let err = ModelSpec::from_toml("contact_law = \"jkr\"\ntoy_adhesion = 0.25\n")
        .unwrap()
        .resolve(Params::default(), None)
        .unwrap_err();
    assert!(err.to_string().contains("spring_adhesion"), "{err}");
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
