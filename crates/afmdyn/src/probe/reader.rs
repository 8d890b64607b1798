//! The probe file's TOML walker ([`Reader`]): every value read with its unit and allowed range,
//! every problem collected (unknown keys, missing keys, values out of range, values off any
//! probe's scale by 1e3–1e12, read as a unit slip) instead of stopping at the first.

use super::*;

/// A TOML table walker that collects every problem instead of stopping at the first.
pub(super) struct Reader<'a> {
    pub(super) problems: &'a mut Vec<String>,
    /// Values inside their physical range but outside the range any AFM probe or sample
    /// typically takes ([`typical_hint`]): warnings, with the likely unit slip named.
    pub(super) warnings: Vec<String>,
}

impl Reader<'_> {
    pub(super) fn table<'t>(
        &mut self,
        root: &'t toml::Table,
        name: &str,
        required: bool,
    ) -> Option<&'t toml::Table> {
        match root.get(name) {
            Some(toml::Value::Table(t)) => Some(t),
            Some(_) => {
                self.problems.push(format!("[{name}] must be a table"));
                None
            }
            None => {
                if required && name == "cantilever" {
                    self.problems.push(
                        "missing table [cantilever] (k, f0, Q or the geometry; or a cantilever of \
                         the library: [cantilever] name = \"…\" or --cantilever NAME, listed by \
                         `afmdyn cantilevers`)"
                            .into(),
                    );
                } else if required {
                    self.problems.push(format!("missing table [{name}]"));
                }
                None
            }
        }
    }

    pub(super) fn unknown(&mut self, table: &toml::Table, section: &str, known: &[&str]) {
        for k in table.keys() {
            if !known.contains(&k.as_str()) {
                self.problems.push(format!(
                    "unknown key {}{k} (expected one of: {})",
                    prefix(section),
                    known.join(", ")
                ));
            }
        }
    }

    /// A number (integers accepted), optional.
    pub(super) fn number(&mut self, table: &toml::Table, section: &str, key: &str) -> Option<f64> {
        match table.get(key) {
            None => None,
            Some(toml::Value::Float(x)) => Some(*x),
            Some(toml::Value::Integer(i)) => Some(*i as f64),
            Some(_) => {
                self.problems
                    .push(format!("{}{key} must be a number", prefix(section)));
                None
            }
        }
    }

    /// A number that must be present, finite and in `check` (described by `range`).
    pub(super) fn required(
        &mut self,
        table: &toml::Table,
        section: &str,
        key: &str,
        unit: &str,
        range: (&str, fn(f64) -> bool),
    ) -> Option<f64> {
        if !table.contains_key(key) {
            self.problems
                .push(format!("missing key {}{key} ({unit})", prefix(section)));
            return None;
        }
        self.optional(table, section, key, unit, range)
    }

    /// A number that may be absent; when present, finite and in `check`.
    pub(super) fn optional(
        &mut self,
        table: &toml::Table,
        section: &str,
        key: &str,
        unit: &str,
        range: (&str, fn(f64) -> bool),
    ) -> Option<f64> {
        let x = self.number(table, section, key)?;
        self.check(section, key, unit, x, range)
    }

    pub(super) fn check(
        &mut self,
        section: &str,
        key: &str,
        unit: &str,
        x: f64,
        (range, ok): (&str, fn(f64) -> bool),
    ) -> Option<f64> {
        if x.is_finite() && ok(x) {
            if let Some(hint) = scale_hint(section, key, x) {
                self.problems.push(format!(
                    "{}{key} = {} ({unit}): {hint}",
                    prefix(section),
                    crate::error::number(x)
                ));
                return None;
            }
            if let Some(hint) = typical_hint(section, key, x) {
                self.warnings.push(format!(
                    "{}{key} = {} ({unit}) is {hint}",
                    prefix(section),
                    crate::error::number(x)
                ));
            }
            Some(x)
        } else {
            self.problems.push(format!(
                "{}{key} = {} ({unit}): must be {range}",
                prefix(section),
                crate::error::number(x)
            ));
            None
        }
    }

    pub(super) fn string<'t>(
        &mut self,
        table: &'t toml::Table,
        section: &str,
        key: &str,
    ) -> Option<&'t str> {
        match table.get(key) {
            None => None,
            Some(toml::Value::String(s)) => Some(s),
            Some(_) => {
                self.problems
                    .push(format!("{}{key} must be a string", prefix(section)));
                None
            }
        }
    }
}

/// A value that is a unit slip rather than a measurement — a tip radius of 10 m written for
/// 10 nm, a modulus of 4 Pa for 4 GPa, a resonance at 300 Hz for 300 kHz (below 1 kHz), a Hamaker constant
/// of 6.6 J for 6.6e-20 J: values 1e3–1e12 off the range any AFM probe or sample takes, refused
/// with the reading that was probably meant. `None` for a plausible value.
pub(super) fn scale_hint(section: &str, key: &str, x: f64) -> Option<String> {
    let nano = |what: &str| {
        format!("longer than 100 µm for {what}; probe files are in metres: {x} nm is {x}e-9")
    };
    match (section, key) {
        ("tip", "radius") if x > 1e-4 => Some(nano("a tip radius")),
        ("drive", "free_amplitude") if x < 1e-12 => Some(
            "below 1 pm, under the lever's thermal motion (probe files are in metres: 10 nm is \
             10e-9)"
                .into(),
        ),
        ("sample", "intermolecular_distance") if x > 1e-6 => Some(nano("a₀ (0.165e-9 m typical)")),
        ("sample", "z_c") if x.abs() > 1e-4 => Some(nano("a rest distance")),
        ("cantilever", "length" | "width" | "thickness") if x > 1e-2 => Some(format!(
            "longer than 1 cm for a cantilever; probe files are in metres: {x} µm is {x}e-6"
        )),
        ("tip", "youngs_modulus") if x < 1e6 => Some(format!(
            "below 1 MPa for a tip; moduli are in Pa: {x} GPa is {x}e9"
        )),
        ("sample", "youngs_modulus") if x < 100.0 => Some(format!(
            "below 100 Pa (softer than any cell); moduli are in Pa: {x} MPa is {x}e6, {x} GPa \
             is {x}e9"
        )),
        ("cantilever", "resonance_frequency") | ("drive", "frequency") if x < 1e3 => Some(format!(
            "below 1 kHz for a cantilever; frequencies are in Hz: {x} kHz is {x}e3"
        )),
        ("sample", "hamaker") if x > 1e-17 => Some(format!(
            "above 1e-17 J (Hamaker constants are ~1e-20 J); in J: {x}e-20"
        )),
        // the highest surface tension of a liquid at room temperature is mercury's, 0.485 N/m
        // (CRC Handbook, 97th ed., "Surface tension of common liquids")
        ("sample", "surface_tension") if x > 1.0 => Some(format!(
            "above 1 N/m, beyond any liquid (water 0.072 N/m, mercury 0.485 N/m); surface \
             tensions are in N/m: {x} mN/m is {x}e-3"
        )),
        // works of adhesion: polymers 0.03–0.1 J/m², water on silica 0.14 J/m², clean metals
        // up to ~3 J/m² (Israelachvili 2011, ch. 13 and 17)
        ("sample", "adhesion_energy") if x > 10.0 => Some(format!(
            "above 10 J/m², beyond any solid's work of adhesion (polymers 0.03–0.1 J/m², \
             metals up to ~3 J/m²); in J/m²: {x} mJ/m² is {x}e-3"
        )),
        _ => None,
    }
}

/// A value inside its physical range but outside the range AFM probes and samples typically
/// take, with the unit slip it may be: a warning, not an error (a colloidal probe's radius of
/// 20 µm is real). `None` inside the typical range. The ranges: tip radii 1 nm–50 µm (sharp
/// tips to colloidal probes), free amplitudes 10 pm–1 µm (FM at small amplitude to large
/// tapping), spring constants 0.005–1e4 N/m (soft contact levers to qPlus sensors at
/// 1.8 kN/m), resonances up to 10 MHz, Hamaker constants 1e-21–5e-19 J (Israelachvili 2011,
/// table 13.2: 0.4e-20 for hydrocarbons in water to 40e-20 for metals), surface tensions
/// 0.01–0.6 N/m, works of adhesion 1e-3–1 J/m², lever lengths 5 µm–1 mm.
pub(super) fn typical_hint(section: &str, key: &str, x: f64) -> Option<String> {
    let hint = |range: &str, slip: &str| Some(format!("outside the typical {range}: {slip}"));
    match (section, key) {
        ("tip", "radius") if !(1e-9..=5e-5).contains(&x) => hint(
            "1 nm–50 µm of tips and colloidal probes",
            "radii are in m (10 nm is 10e-9)",
        ),
        ("drive", "free_amplitude") if !(1e-11..=1e-6).contains(&x) => hint(
            "10 pm–1 µm of dynamic AFM",
            "amplitudes are in m (10 nm is 10e-9)",
        ),
        ("cantilever", "spring_constant") if !(5e-3..=1e4).contains(&x) => hint(
            "0.005–1e4 N/m of AFM levers and qPlus sensors",
            "stiffnesses are in N/m (40 N/m is 40.0)",
        ),
        ("cantilever", "resonance_frequency") | ("drive", "frequency") if x > 1e7 => hint(
            "1 kHz–10 MHz of AFM levers",
            "frequencies are in Hz (300 kHz is 300e3)",
        ),
        ("sample", "hamaker") if x != 0.0 && !(1e-21..=5e-19).contains(&x) => hint(
            "1e-21–5e-19 J of Hamaker constants",
            "they are in J (6.6e-20 J for polystyrene)",
        ),
        ("sample", "surface_tension") if !(0.01..=0.6).contains(&x) => hint(
            "0.01–0.6 N/m of liquids",
            "surface tensions are in N/m (water 0.072 N/m is 72e-3)",
        ),
        ("sample", "adhesion_energy") if !(1e-3..=1.0).contains(&x) => hint(
            "1e-3–1 J/m² of works of adhesion",
            "they are in J/m² (50 mJ/m² is 50e-3)",
        ),
        ("cantilever", "length") if !(5e-6..=1e-3).contains(&x) => hint(
            "5 µm–1 mm of AFM levers",
            "lengths are in m (125 µm is 125e-6)",
        ),
        _ => None,
    }
}

pub(super) fn prefix(section: &str) -> String {
    if section.is_empty() {
        String::new()
    } else {
        format!("[{section}].")
    }
}

pub(super) const POSITIVE: (&str, fn(f64) -> bool) = ("finite and > 0", |x| x > 0.0);
pub(super) const NON_NEGATIVE: (&str, fn(f64) -> bool) = ("finite and >= 0", |x| x >= 0.0);
pub(super) const POISSON: (&str, fn(f64) -> bool) = ("in (-1, 0.5]", |x| x > -1.0 && x <= 0.5);
/// A quality factor: up to [`MAX_QUALITY_FACTOR`].
pub(super) const QUALITY: (&str, fn(f64) -> bool) =
    ("in (0, 1e7]", |x| x > 0.0 && x <= MAX_QUALITY_FACTOR);
pub(super) const UNIT_INTERVAL: (&str, fn(f64) -> bool) =
    ("in [0, 1]", |x| (0.0..=1.0).contains(&x));
pub(super) const ANY: (&str, fn(f64) -> bool) = ("finite", |_| true);
/// A contact angle of a wetting liquid (degrees): cos θ > 0.
pub(super) const WETTING_ANGLE: (&str, fn(f64) -> bool) =
    ("in [0, 90) degrees (a wetting meniscus)", |x| {
        (0.0..90.0).contains(&x)
    });
