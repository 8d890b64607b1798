//! The cantilever library (issue 28): nominal datasheet values of widely used tapping-mode,
//! soft-tapping and biological-imaging cantilevers, embedded from `assets/cantilevers.toml`
//! (each entry with its source). A probe file names one with `[cantilever] name = "…"`; the
//! entry fills the keys the file leaves out (`fill`): `spring_constant`,
//! `resonance_frequency`, `quality_factor`, `[tip].radius`, the tip's elastic constants
//! (silicon, `SILICON_YOUNGS_MODULUS`, `SILICON_POISSON_RATIO`) and `model =
//! "point-mass"`. The file's own keys always win; a spring constant or resonance frequency
//! beyond the maker's spread of the named lever's warns (`calibration_warnings`).

use std::sync::OnceLock;

/// Young's modulus of a silicon tip (Pa), from the one materials table
/// ([`crate::units::SILICON_TIP`]: 130 GPa along ⟨100⟩, the lower end of 130–188 GPa over
/// orientations; Hopcroft, Nix & Kenny, "What is the Young's modulus of silicon?", J.
/// Microelectromech. Syst. 19, 229 (2010)).
pub(crate) const SILICON_YOUNGS_MODULUS: f64 = crate::units::SILICON_TIP.youngs_modulus;
/// Poisson's ratio of a silicon tip, from the one materials table
/// ([`crate::units::SILICON_TIP`]: 0.27, the paper's).
pub(crate) const SILICON_POISSON_RATIO: f64 = crate::units::SILICON_TIP.poisson_ratio;

/// One cantilever of the library (SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct Cantilever {
    /// Its name as the maker spells it (upper case; looked up case-insensitively).
    pub name: String,
    /// The maker.
    pub maker: String,
    /// k (N/m), nominal.
    pub spring_constant: f64,
    /// f0 (Hz), nominal, in air.
    pub resonance_frequency: f64,
    /// Q in air.
    pub quality_factor: f64,
    /// Whether Q is a typical value of the lever class (not on the datasheet).
    pub q_typical: bool,
    /// Tip radius R (m), nominal or the datasheet's upper bound.
    pub radius: f64,
    /// Where the values come from.
    pub source: String,
}

const LIBRARY: &str = include_str!("../assets/cantilevers.toml");

/// Every cantilever of the library, in the file's order.
///
/// # Panics
/// Never for the embedded file (its reading is tested); a malformed entry would panic at the
/// first call.
pub(crate) fn cantilevers() -> &'static [Cantilever] {
    static ALL: OnceLock<Vec<Cantilever>> = OnceLock::new();
    ALL.get_or_init(|| {
        let root: toml::Table = LIBRARY.parse().expect("the embedded cantilever library");
        root.iter()
            .map(|(name, v)| {
                let t = v.as_table().expect("an entry is a table");
                let num = |k: &str| {
                    t.get(k)
                        .and_then(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
                        .unwrap_or_else(|| panic!("{name}.{k}"))
                };
                let text = |k: &str| {
                    t.get(k)
                        .and_then(|x| x.as_str())
                        .unwrap_or_else(|| panic!("{name}.{k}"))
                        .to_string()
                };
                Cantilever {
                    name: name.clone(),
                    maker: text("maker"),
                    spring_constant: num("spring_constant"),
                    resonance_frequency: num("resonance_frequency"),
                    quality_factor: num("quality_factor"),
                    q_typical: t
                        .get("q_typical")
                        .and_then(|x| x.as_bool())
                        .unwrap_or(false),
                    radius: num("radius"),
                    source: text("source"),
                }
            })
            .collect()
    })
}

/// The cantilever called `name` (case-insensitive; `_` and spaces read as `-`).
///
/// # Errors
/// A message naming the unknown cantilever and the library's names that contain it (or all).
pub(crate) fn find(name: &str) -> Result<&'static Cantilever, String> {
    let key = |s: &str| s.trim().to_ascii_uppercase().replace(['_', ' '], "-");
    let want = key(name);
    let all = cantilevers();
    if let Some(c) = all.iter().find(|c| key(&c.name) == want) {
        return Ok(c);
    }
    let near: Vec<&str> = all
        .iter()
        .filter(|c| {
            let k = key(&c.name);
            !want.is_empty() && (k.contains(&want) || want.contains(&k))
        })
        .map(|c| c.name.as_str())
        .collect();
    let names: Vec<&str> = if near.is_empty() {
        all.iter().map(|c| c.name.as_str()).collect()
    } else {
        near
    };
    Err(format!(
        "[cantilever].name = \"{name}\": not in the cantilever library (did you mean {}? \
         `afmdyn cantilevers` lists them)",
        names.join(", ")
    ))
}

/// Fill a probe file's table from the library entry its `[cantilever].name` gives: the keys
/// the file leaves out are the entry's (see the module docs); `name` itself is removed, so the
/// probe reader sees plain values. A table without a name is returned as it is.
///
/// # Errors
/// The message of [`find`] for an unknown name, or one for a name that is not a string.
pub(crate) fn fill(root: &toml::Table) -> Result<toml::Table, String> {
    let Some(cant) = root.get("cantilever").and_then(|c| c.as_table()) else {
        return Ok(root.clone());
    };
    let Some(name) = cant.get("name") else {
        return Ok(root.clone());
    };
    let name = name
        .as_str()
        .ok_or_else(|| format!("[cantilever].name = {name}: must be a string"))?;
    let c = find(name)?;
    let mut out = root.clone();
    out.entry("model")
        .or_insert_with(|| toml::Value::String("point-mass".into()));
    let section = |out: &mut toml::Table, s: &str| -> toml::Table {
        out.get(s)
            .and_then(|v| v.as_table())
            .cloned()
            .unwrap_or_default()
    };
    let mut cantilever = section(&mut out, "cantilever");
    cantilever.remove("name");
    // a geometry in the file replaces the calibrated values; length and width alone are the
    // plan of a calibrated lever, which [medium] needs
    let geometry = ["thickness", "density", "youngs_modulus"]
        .iter()
        .any(|k| cantilever.contains_key(*k));
    if !geometry {
        for (k, v) in [
            ("spring_constant", c.spring_constant),
            ("resonance_frequency", c.resonance_frequency),
        ] {
            cantilever.entry(k).or_insert(toml::Value::Float(v));
        }
    }
    if !cantilever.contains_key("quality_factors") {
        cantilever
            .entry("quality_factor")
            .or_insert(toml::Value::Float(c.quality_factor));
    }
    out.insert("cantilever".into(), toml::Value::Table(cantilever));
    let mut tip = section(&mut out, "tip");
    // a sharp indenter (a cone, a pyramid) has no radius (contact::indenter)
    let sharp = tip
        .get("shape")
        .and_then(|s| s.as_str())
        .is_some_and(|s| crate::contact::indenter::TipShape::angle_key(s.trim()).is_some());
    for (k, v) in [
        ("radius", c.radius),
        ("youngs_modulus", SILICON_YOUNGS_MODULUS),
        ("poisson_ratio", SILICON_POISSON_RATIO),
    ] {
        if !(sharp && k == "radius") {
            tip.entry(k).or_insert(toml::Value::Float(v));
        }
    }
    out.insert("tip".into(), toml::Value::Table(tip));
    Ok(out)
}

/// How far a probe file's own spring constant may lie from its named lever's nominal one
/// before it warns: a factor of 3 either way. Makers state k within about a factor of 2–3 of
/// nominal (Olympus AC160TS-R3: 26 N/m nominal, 8.4–57 N/m), so a calibration outside it more
/// likely belongs to another lever.
pub(crate) const SPRING_CONSTANT_SPREAD: f64 = 3.0;
/// The same for the resonance frequency: a factor of 1.5 either way (AC160TS-R3: 300 kHz
/// nominal, 200–400 kHz).
pub(crate) const RESONANCE_FREQUENCY_SPREAD: f64 = 1.5;

/// Warnings for a probe file that names a library lever (`[cantilever].name`, or the command
/// line's `--cantilever`) and gives its own `spring_constant` or `resonance_frequency` beyond
/// the maker's spread of the nominal value ([`SPRING_CONSTANT_SPREAD`],
/// [`RESONANCE_FREQUENCY_SPREAD`]): the file's value is used (a calibration wins over the
/// datasheet, [`fill`]), which is right for a calibrated lever and a silent wrong lever when
/// the file was written for another one. No warning without a name, for a name not in the
/// library ([`fill`] refuses it) or for values that are not numbers (the probe reader refuses
/// them).
pub(crate) fn calibration_warnings(root: &toml::Table) -> Vec<String> {
    let Some(cant) = root.get("cantilever").and_then(|c| c.as_table()) else {
        return Vec::new();
    };
    let Some(Ok(c)) = cant.get("name").and_then(|n| n.as_str()).map(find) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (key, nominal, spread, unit) in [
        (
            "spring_constant",
            c.spring_constant,
            SPRING_CONSTANT_SPREAD,
            "N/m",
        ),
        (
            "resonance_frequency",
            c.resonance_frequency,
            RESONANCE_FREQUENCY_SPREAD,
            "Hz",
        ),
    ] {
        let Some(v) = cant
            .get(key)
            .and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
        else {
            continue;
        };
        if !(v > 0.0 && v.is_finite()) {
            continue;
        }
        let ratio = v / nominal;
        if ratio > spread || ratio < 1.0 / spread {
            let (factor, side) = if ratio > 1.0 {
                (ratio, "above")
            } else {
                (1.0 / ratio, "below")
            };
            out.push(warning!(
                "probe.off-nominal",
                "Check that the probe file is for this lever; keep the value if it is \
                 your calibration.",
                "[cantilever].{key} = {v} {unit} is {factor:.1}× {side} {}'s nominal \
                 {nominal} {unit} (the maker's spread is a factor of {spread}): the probe's \
                 value is used, as a calibration is; check that the probe file is for this lever",
                c.name
            ));
        }
    }
    out
}

/// The library as a JSON document (`afmdyn cantilevers --json`, Python's
/// `afmdyn.cantilevers()`): `{"cantilevers": [{"name", "maker", "spring_constant",
/// "resonance_frequency", "quality_factor", "q_typical", "radius", "source"}, …]}` in SI.
pub fn document() -> serde_json::Value {
    serde_json::json!({
        "cantilevers": cantilevers().iter().map(|c| serde_json::json!({
            "name": c.name,
            "maker": c.maker,
            "spring_constant": c.spring_constant,
            "resonance_frequency": c.resonance_frequency,
            "quality_factor": c.quality_factor,
            "q_typical": c.q_typical,
            "radius": c.radius,
            "source": c.source,
        })).collect::<Vec<_>>(),
    })
}

/// A probe file's text with `[cantilever].name` set to `name` (the command line's
/// `--cantilever NAME`, which wins over a name in the file).
///
/// # Errors
/// The TOML parser's message for a file that is not TOML, or one for a `cantilever` key that
/// is not a table.
pub fn with_name(text: &str, name: &str) -> Result<String, String> {
    let mut root: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| e.to_string().replace('\n', " "))?;
    let cant = root
        .entry("cantilever")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    let cant = cant
        .as_table_mut()
        .ok_or("cantilever must be a table ([cantilever])")?;
    cant.insert("name".into(), toml::Value::String(name.into()));
    Ok(toml::to_string(&root).expect("a TOML table serialises"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_library_reads_and_every_entry_is_plausible() {
        let all = cantilevers();
        assert!(all.len() >= 12);
        for c in all {
            assert!(
                c.spring_constant > 0.01 && c.spring_constant < 100.0,
                "{c:?}"
            );
            assert!(
                c.resonance_frequency > 1e4 && c.resonance_frequency < 5e6,
                "{c:?}"
            );
            assert!(c.radius > 1e-9 && c.radius < 50e-9, "{c:?}");
            assert!(
                c.quality_factor >= 10.0 && c.source.starts_with("https://"),
                "{c:?}"
            );
        }
    }

    #[test]
    fn names_are_found_case_insensitively_and_unknown_ones_suggest() {
        assert_eq!(find("rtespa_300").unwrap().spring_constant, 40.0);
        assert_eq!(find("ac160ts-r3").unwrap().resonance_frequency, 300e3);
        let e = find("RTESPA").unwrap_err();
        assert!(e.contains("RTESPA-300") && e.contains("RTESPA-150"), "{e}");
        assert!(find("nope").unwrap_err().contains("TESPA-V2"));
        // the levers of PeakForce in liquid (issue 77): a 20 nm and a sharpened 2 nm tip
        assert_eq!(find("scanasyst-fluid").unwrap().radius, 20e-9);
        assert_eq!(find("ScanAsyst-Fluid+").unwrap().radius, 2e-9);
    }

    #[test]
    fn a_named_sample_file_is_a_probe() {
        let sample = "[sample]\nlaw = \"hertz\"\nyoungs_modulus = 1e9\npoisson_ratio = 0.3\n\
                      z_c = 8e-9\n[drive]\nfree_amplitude = 10e-9\n";
        let text = with_name(sample, "ac160ts-r3").unwrap();
        let p = crate::probe::Probe::parse(&text, "sample.toml").unwrap();
        let same = crate::probe::Probe::parse(
            "model = \"point-mass\"\n[cantilever]\nspring_constant = 26.0\n\
             resonance_frequency = 300e3\nquality_factor = 500\n[tip]\nradius = 7e-9\n\
             youngs_modulus = 130e9\npoisson_ratio = 0.27\n[sample]\nlaw = \"hertz\"\n\
             youngs_modulus = 1e9\npoisson_ratio = 0.3\nz_c = 8e-9\n[drive]\n\
             free_amplitude = 10e-9\n",
            "written out",
        )
        .unwrap();
        assert_eq!(p.params, same.params);
        let e = crate::probe::Probe::parse(&with_name(sample, "nope").unwrap(), "s").unwrap_err();
        assert!(
            e.to_string().contains("not in the cantilever library"),
            "{e}"
        );
    }

    #[test]
    fn fill_keeps_the_files_keys_and_adds_the_entrys() {
        let root: toml::Table = r#"
            [cantilever]
            name = "RTESPA-300"
            spring_constant = 37.5
            [tip]
            radius = 12e-9
        "#
        .parse()
        .unwrap();
        let t = fill(&root).unwrap();
        let c = t["cantilever"].as_table().unwrap();
        assert_eq!(c["spring_constant"].as_float(), Some(37.5));
        assert_eq!(c["resonance_frequency"].as_float(), Some(300e3));
        assert!(!c.contains_key("name"));
        let tip = t["tip"].as_table().unwrap();
        assert_eq!(tip["radius"].as_float(), Some(12e-9));
        assert_eq!(
            tip["youngs_modulus"].as_float(),
            Some(SILICON_YOUNGS_MODULUS)
        );
        assert_eq!(t["model"].as_str(), Some("point-mass"));
    }
}
