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
/// 10 nm, a modulus of 4 Pa for 4 GPa, a resonance at 300 Hz for 300 kHz: outside its physical
/// range ([`super::ranges`]), refused with the reading that was probably meant. `None` for a
/// plausible value.
pub(super) fn scale_hint(section: &str, key: &str, x: f64) -> Option<String> {
    super::ranges::refusal(section, key, x)
}

/// A value inside its physical range but outside the range AFM probes and samples typically
/// take, with the unit slip it may be ([`super::ranges`]): a warning, not an error (a
/// colloidal probe's radius of 20 µm is real). `None` inside the typical range.
pub(super) fn typical_hint(section: &str, key: &str, x: f64) -> Option<String> {
    super::ranges::warning(section, key, x)
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
/// An indenter's angle (degrees): between the axis and the surface, 0 and 90 excluded.
pub(super) const ANGLE: (&str, fn(f64) -> bool) = ("in (0, 90) degrees", |x| x > 0.0 && x < 90.0);
