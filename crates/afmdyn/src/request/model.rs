//! The model part of every request: the parameter values a user gave, by name, and the one
//! table of those names ([`MODEL_PARAMETERS`]) that the command line's flags and help, the TOML
//! config keys, the Python keywords, their docstrings and type stubs are checked against.
//!
//! Precedence, the same for every front end: the defaults of the analysis (the paper's
//! Figs. 5–14 set, [`Params::default`]) ← a probe file in SI ([`crate::probe::Probe`]) ← the
//! single values of [`ModelSpec`] ← the SI overrides `z_c` (sets α5) and `drive_frequency`
//! (sets Ω), which need the probe's scales.

use crate::contact::{ContactLaw, LawGroups, LawKind, GROUPS, LAWS};
use crate::error::SimError;
use crate::params::{Excitation, Params};
use crate::probe::Probe;
use serde::{Deserialize, Serialize};

/// What kind of value a model parameter takes (for the front ends' type checks and stubs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ValueKind {
    /// A non-negative integer.
    Integer,
    /// A real number.
    Real,
    /// A registered law's name ([`LAWS`]).
    Law,
    /// One of `base`, `tip`.
    Excitation,
}

/// One model parameter: its library name, the paper's alias, symbol, unit, range and help.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ParamInfo {
    /// The library's name (snake_case): the TOML key, the Python keyword; the flag is the same
    /// in kebab-case (`tip_mass_ratio` → `--tip-mass-ratio`).
    pub name: &'static str,
    /// The paper's name (`alpha1` … `alpha6`), accepted everywhere as well; `None` when the
    /// name is the paper's.
    pub alias: Option<&'static str>,
    /// The symbol as the paper writes it.
    pub symbol: &'static str,
    /// The unit: `1` (dimensionless, eq. 5 and 7), `m` or `Hz` (SI, with a probe).
    pub unit: &'static str,
    /// The allowed range in words (the limits of [`crate::params`]).
    pub range: &'static str,
    /// The default in words.
    pub default: &'static str,
    /// One line of help.
    pub help: &'static str,
    /// Integer, real or law name.
    pub kind: ValueKind,
}

/// A table of [`ParamInfo`], an entry a line: `name | alias, symbol, unit, range, default,
/// kind: help` (`| alias` only where the paper names it otherwise).
macro_rules! param_infos {
    ($($name:literal $(| $alias:literal)?, $symbol:literal, $unit:literal, $range:expr,
       $default:literal, $kind:ident: $help:expr;)*) => {
        [$(ParamInfo {
            name: $name,
            alias: param_infos!(@alias $($alias)?),
            symbol: $symbol,
            unit: $unit,
            range: $range,
            default: $default,
            help: $help,
            kind: ValueKind::$kind,
        }),*]
    };
    (@alias) => { None };
    (@alias $alias:literal) => { Some($alias) };
}

/// The model parameters before the law's groups, in the order the front ends list them.
const BEFORE_GROUPS: [ParamInfo; 10] = param_infos! {
    "modes", "N", "1", "1..=20", "3", Integer: "number of Galerkin modes N (eq. 9)";
    "tip_mass_ratio" | "alpha1", "α1", "1", "0..=1e4", "0.1", Real: "tip-mass ratio α1 = M/(mL)";
    "drive_amplitude" | "alpha2", "α2", "1", "0..=1e6", "0.1", Real:
        "base-drive amplitude α2 = f/g0";
    "beam_damping" | "alpha3", "α3", "1", "0..=1e4", "0.1", Real: "beam damping α3";
    "contact_stiffness" | "alpha4", "α4", "1", "0..=1e8", "20", Real:
        "contact stiffness α4 = K1 L³/(EI)";
    "gap" | "alpha5", "α5", "1", "-1e6..=1e6", "0", Real:
        "tip–sample gap α5 = g1/g0 (may be negative)";
    "contact_damping" | "alpha6", "α6", "1", "0..=1e4", "0.2", Real: "contact damping α6";
    "omega", "Ω", "1", "1e-3..=1e5", "2.6", Real: "dimensionless drive frequency Ω";
    // the help: the registry's laws and doc lines ([`law_help`])
    "contact_law", "F_c", "1", crate::contact::LawKind::EXPECTED, "linear", Law: "tip–sample law";
    "excitation", "—", "1", "base or tip", "base", Excitation:
        "where the drive acts on the beam: base (α2 sin Ωτ, the paper; acoustic) or tip (a \
         force α2 cos Ωτ at the tip: magnetic, photothermal)";
};

/// The SI model parameters after the law's groups (they need a probe file).
const AFTER_GROUPS: [ParamInfo; 2] = param_infos! {
    "z_c", "z_c", "m", "finite", "the probe's", Real:
        "with a probe: the rest tip–sample distance z_c in metres (sets α5)";
    "drive_frequency", "f", "Hz", "> 0", "the probe's", Real:
        "with a probe: the drive frequency in Hz (sets Ω; the drive force or base amplitude is \
         kept)";
};

/// Every model parameter a request takes, in the order the front ends list them: the model's
/// own, the law groups of the registry ([`crate::contact::GROUPS`], each described by its
/// law's `crate::contact::Param`), then `z_c` and `drive_frequency`, SI values that need a
/// probe file. The ranges are those [`Params::validate`] and [`ContactLaw::validate`] enforce.
pub static MODEL_PARAMETERS: std::sync::LazyLock<Vec<ParamInfo>> = std::sync::LazyLock::new(|| {
    let groups = GROUPS.iter().map(|g| ParamInfo {
        name: g.name,
        alias: None,
        symbol: g.symbol,
        unit: g.unit,
        range: g.range,
        default: leak(crate::error::number(g.default)),
        help: leak(format!("{} law: {}", crate::contact::owners(g.name), g.doc)),
        kind: ValueKind::Real,
    });
    let laws = BEFORE_GROUPS.into_iter().map(|p| match p.kind {
        ValueKind::Law => ParamInfo {
            help: law_help(),
            ..p
        },
        _ => p,
    });
    laws.chain(groups).chain(AFTER_GROUPS).collect()
});

/// The help of `contact_law`: each registered law's name and doc line ([`LAWS`]).
fn law_help() -> &'static str {
    let laws: Vec<String> = LAWS
        .iter()
        .map(|l| format!("{} ({})", l.name, l.doc))
        .collect();
    leak(format!("tip–sample law: {}", laws.join(", ")))
}

/// A text built once for the table of [`MODEL_PARAMETERS`], kept for the program's life.
fn leak(text: String) -> &'static str {
    Box::leak(text.into_boxed_str())
}

/// The entry of [`MODEL_PARAMETERS`] named `key` (its name or its alias).
pub fn parameter(key: &str) -> Option<&'static ParamInfo> {
    MODEL_PARAMETERS
        .iter()
        .find(|p| p.name == key || p.alias == Some(key))
}

/// The model parameter name (or alias) closest to a misspelt `key` — Jaro–Winkler similarity
/// ≥ 0.85 (`omgea` → `omega`, `beam_dampnig` → `beam_damping`) — for a "did you mean" hint.
pub(crate) fn closest_parameter(key: &str) -> Option<&'static str> {
    MODEL_PARAMETERS
        .iter()
        .flat_map(|p| std::iter::once(p.name).chain(p.alias))
        .map(|name| (strsim::jaro_winkler(key, name), name))
        .filter(|(score, _)| *score >= 0.85)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, name)| name)
}

/// [`ModelSpec`], its serde form and its schema from one list of its own fields: those before
/// the law's groups, and the SI values after them (`name | alias: type`, each documented).
macro_rules! model_spec {
    (
        [$( $(#[doc = $bdoc:expr])* $b:ident $(| $balias:ident)? : $bty:ty, )*]
        [$( $(#[doc = $adoc:expr])* $a:ident : $aty:ty, )*]
    ) => {
        /// The model values of a request, each optional (a missing one keeps the value below it in the
        /// precedence of this module). Serialised with the names of [`MODEL_PARAMETERS`]; the paper's
        /// `alpha1` … `alpha6` are accepted as aliases; unknown keys are refused (this is also the
        /// schema of a `--config FILE.toml`).
        #[derive(Debug, Clone, Copy, Default, PartialEq)]
        pub struct ModelSpec {
            $( $(#[doc = $bdoc])* pub $b: Option<$bty>, )*
            /// The law's groups, each under its own name ([`crate::contact::GROUPS`]:
            /// `hamaker`, `restitution`, …), as the registry's laws declare them.
            pub groups: LawGroups,
            $( $(#[doc = $adoc])* pub $a: Option<$aty>, )*
        }

        impl ModelSpec {
            /// `self`'s values, and `lower`'s where `self` has none (flags over a config file).
            pub fn over(self, lower: ModelSpec) -> ModelSpec {
                ModelSpec {
                    $( $b: self.$b.or(lower.$b), )*
                    groups: self.groups.or(lower.groups),
                    $( $a: self.$a.or(lower.$a), )*
                }
            }
        }

        /// The keys a model spec takes, aliases before names (as serde's derive lists them).
        fn fields() -> &'static [&'static str] {
            static FIELDS: std::sync::OnceLock<Vec<&'static str>> = std::sync::OnceLock::new();
            FIELDS.get_or_init(|| {
                let before = [$( $(stringify!($balias),)? stringify!($b), )*];
                let after = [$( stringify!($a), )*];
                before
                    .into_iter()
                    .chain(GROUPS.iter().map(|g| g.name))
                    .chain(after)
                    .collect()
            })
        }

        /// The name of key `key` (a name or an alias).
        fn canonical(key: &str) -> Option<&'static str> {
            match key {
                $( $(stringify!($balias) | )? stringify!($b) => Some(stringify!($b)), )*
                $( stringify!($a) => Some(stringify!($a)), )*
                _ => GROUPS.iter().find(|g| g.name == key).map(|g| g.name),
            }
        }

        impl Serialize for ModelSpec {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                use serde::ser::SerializeStruct;
                let given = [$( self.$b.is_some(), )* $( self.$a.is_some(), )*];
                let n = given.iter().filter(|g| **g).count() + self.groups.given().count();
                let mut st = s.serialize_struct("ModelSpec", n)?;
                $( if let Some(v) = &self.$b { st.serialize_field(stringify!($b), v)?; } )*
                for (name, v) in self.groups.given() {
                    st.serialize_field(name, &v)?;
                }
                $( if let Some(v) = &self.$a { st.serialize_field(stringify!($a), v)?; } )*
                st.end()
            }
        }

        impl<'de> serde::de::Visitor<'de> for SpecVisitor {
            type Value = ModelSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("struct ModelSpec")
            }
            fn visit_map<M: serde::de::MapAccess<'de>>(self, mut map: M) -> Result<ModelSpec, M::Error> {
                let mut spec = ModelSpec::default();
                let mut seen: Vec<&'static str> = Vec::new();
                while let Some(Key(key)) = map.next_key()? {
                    if seen.contains(&key) {
                        return Err(serde::de::Error::duplicate_field(key));
                    }
                    seen.push(key);
                    match key {
                        $( stringify!($b) => spec.$b = map.next_value()?, )*
                        $( stringify!($a) => spec.$a = map.next_value()?, )*
                        group => {
                            spec.groups.set(group, map.next_value()?);
                        }
                    }
                }
                Ok(spec)
            }
        }

        #[cfg(feature = "schema")]
        impl schemars::JsonSchema for ModelSpec {
            fn schema_name() -> std::borrow::Cow<'static, str> {
                "ModelSpec".into()
            }
            fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
                let mut props = serde_json::Map::new();
                $( props.insert(
                    stringify!($b).into(),
                    described(generator.subschema_for::<Option<$bty>>(), concat!($($bdoc, "\n"),*)),
                ); )*
                for g in GROUPS.iter() {
                    let doc = format!("{} law: {}.", crate::contact::owners(g.name), g.symbol);
                    props.insert(g.name.into(), described(generator.subschema_for::<Option<f64>>(), &doc));
                }
                $( props.insert(
                    stringify!($a).into(),
                    described(generator.subschema_for::<Option<$aty>>(), concat!($($adoc, "\n"),*)),
                ); )*
                let doc = doc_text(concat!(
                    " The model values of a request, each optional (a missing one keeps the value below it in the\n",
                    " precedence of this module). Serialised with the names of [`MODEL_PARAMETERS`]; the paper's\n",
                    " `alpha1` … `alpha6` are accepted as aliases; unknown keys are refused (this is also the\n",
                    " schema of a `--config FILE.toml`).",
                ));
                schemars::json_schema!({
                    "title": "ModelSpec",
                    "description": doc,
                    "type": "object",
                    "properties": props,
                    "additionalProperties": false,
                })
            }
        }
    };
}

model_spec! {
    [
        /// N.
        modes: usize,
        /// α1.
        tip_mass_ratio | alpha1: f64,
        /// α2.
        drive_amplitude | alpha2: f64,
        /// α3.
        beam_damping | alpha3: f64,
        /// α4.
        contact_stiffness | alpha4: f64,
        /// α5.
        gap | alpha5: f64,
        /// α6.
        contact_damping | alpha6: f64,
        /// Ω.
        omega: f64,
        /// The tip–sample law.
        contact_law: LawKind,
        /// Where the drive acts (beam).
        excitation: Excitation,
    ]
    [
        /// With a probe: z_c in m.
        z_c: f64,
        /// With a probe: the drive frequency in Hz.
        drive_frequency: f64,
    ]
}

/// A key of a model spec, by its name ([`canonical`]); an unknown key is refused as serde's
/// derive refuses it, listing [`fields`].
struct Key(&'static str);

impl<'de> Deserialize<'de> for Key {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Key, D::Error> {
        struct KeyVisitor;
        impl serde::de::Visitor<'_> for KeyVisitor {
            type Value = Key;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("field identifier")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Key, E> {
                canonical(v)
                    .map(Key)
                    .ok_or_else(|| E::unknown_field(v, fields()))
            }
        }
        d.deserialize_identifier(KeyVisitor)
    }
}

/// [`ModelSpec`]'s map visitor.
struct SpecVisitor;

impl<'de> Deserialize<'de> for ModelSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<ModelSpec, D::Error> {
        d.deserialize_struct("ModelSpec", fields(), SpecVisitor)
    }
}

/// A doc comment's text as a schema's description (each line's leading space dropped).
#[cfg(feature = "schema")]
fn doc_text(doc: &str) -> String {
    let lines: Vec<&str> = doc
        .lines()
        .map(|l| l.strip_prefix(' ').unwrap_or(l))
        .collect();
    lines.join("\n").trim().to_string()
}

/// `schema` with the description `doc`, as JSON.
#[cfg(feature = "schema")]
fn described(mut schema: schemars::Schema, doc: &str) -> serde_json::Value {
    schema.insert("description".into(), doc_text(doc).into());
    schema.to_value()
}

impl ModelSpec {
    /// Every given value is a finite number. A chart carries its model values through JSON to
    /// set one per cell, where a NaN or an infinity would become `null` and silently the
    /// default; the other analyses refuse them through [`ModelSpec::resolve`] alike.
    ///
    /// # Errors
    /// [`SimError::NotFinite`] naming the first value that is not finite by its request name
    /// (`contact_stiffness`, `z_c`, …).
    pub(crate) fn check_finite(&self) -> Result<(), SimError> {
        for (name, v) in self.reals() {
            if let Some(x) = v {
                crate::error::finite(name, x)?;
            }
        }
        Ok(())
    }

    /// The real values by their names, in the order of [`MODEL_PARAMETERS`].
    fn reals(&self) -> impl Iterator<Item = (&'static str, Option<f64>)> + '_ {
        [
            ("tip_mass_ratio", self.tip_mass_ratio),
            ("drive_amplitude", self.drive_amplitude),
            ("beam_damping", self.beam_damping),
            ("contact_stiffness", self.contact_stiffness),
            ("gap", self.gap),
            ("contact_damping", self.contact_damping),
            ("omega", self.omega),
        ]
        .into_iter()
        .chain(self.groups.entries())
        .chain([("z_c", self.z_c), ("drive_frequency", self.drive_frequency)])
    }

    /// The parameter set: `defaults`, or the probe's set when a probe is given, with this
    /// spec's values applied, then `z_c` (α5 = [`Params::alpha5_for_rest_distance`] of z_c in
    /// units of the probe's length scale) and `drive_frequency` (Ω from the probe's time
    /// scale), validated.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `z_c` or `drive_frequency` when given without a probe or
    /// not finite (not positive); [`SimError::Params`] for a law group of another law or a
    /// value out of range ([`Params::validate`]).
    pub fn resolve(&self, defaults: Params, probe: Option<&Probe>) -> Result<Params, SimError> {
        if let Some(pr) = probe {
            self.refuse_dimensionless_under_probe()?;
            self.check_probe_modes(pr)?;
        }
        let base = probe.map_or(defaults, |p| p.params);
        let contact_law = ContactLaw::from_parts(self.contact_law, self.groups, base.contact_law)?;
        let mut p = Params {
            contact_law,
            modes: self.modes.unwrap_or(base.modes),
            alpha1: self.tip_mass_ratio.unwrap_or(base.alpha1),
            alpha2: self.drive_amplitude.unwrap_or(base.alpha2),
            alpha3: self.beam_damping.unwrap_or(base.alpha3),
            alpha4: self.contact_stiffness.unwrap_or(base.alpha4),
            alpha5: self.gap.unwrap_or(base.alpha5),
            alpha6: self.contact_damping.unwrap_or(base.alpha6),
            omega: self.omega.unwrap_or(base.omega),
            excitation: self.excitation.unwrap_or(base.excitation),
            ..base
        };
        // a lever in a fluid with another N: every mode loaded as the probe's were
        if let Some(pr) = probe {
            if let (Some(m), true) = (&pr.medium, p.modes != pr.params.modes) {
                m.reload(&mut p, pr.scales.time_s)
                    .map_err(SimError::Probe)?;
            }
        }
        if let Some(z) = self.z_c {
            p.alpha5 = alpha5_of_rest_distance(z, &p, probe)?;
        }
        if let Some(f) = self.drive_frequency {
            p.omega = omega_of_drive_frequency(f, probe)?;
        }
        p.validate_fields().map_err(SimError::from)?;
        Ok(p)
    }

    /// One meaning of N everywhere: a lumped model's modes are the probe's (the point mass has
    /// one, the eigenmode model one per entry of [cantilever].spring_constant), as the probe
    /// file's own `modes` key is checked; a larger N would repeat mode 1.
    fn check_probe_modes(&self, pr: &Probe) -> Result<(), SimError> {
        if let (Some(n), true) = (self.modes, pr.params.structure.is_lumped()) {
            if n != pr.params.modes {
                return Err(SimError::out_of_range(
                    "modes",
                    format!(
                        "{n} (this probe's {} model has {} mode(s))",
                        pr.params.structure.name(),
                        pr.params.modes
                    ),
                    "must equal the probe's number of modes: the point-mass model has \
                     one mode and the eigenmode model one per entry of [cantilever] \
                     spring_constant (omit modes, or edit the probe's arrays)",
                ));
            }
        }
        Ok(())
    }

    /// Refuse the values a probe sets in SI ([`probe_sets`]): the first one given, named.
    fn refuse_dimensionless_under_probe(&self) -> Result<(), SimError> {
        let reals = self
            .reals()
            .filter_map(|(name, v)| Some((name, crate::error::number(v?))));
        let law = self
            .contact_law
            .map(|l| ("contact_law", l.name().to_string()));
        let excitation = self
            .excitation
            .map(|e| ("excitation", e.name().to_string()));
        for (name, value) in reals.chain(law).chain(excitation) {
            if let Some(allowed) = probe_sets(name) {
                return Err(SimError::out_of_range(name, value, allowed));
            }
        }
        Ok(())
    }

    /// Read a config file's text (TOML, the keys of [`MODEL_PARAMETERS`]); the error is one
    /// line: `line L, column C: message`.
    ///
    /// # Errors
    /// [`ModelSpecError`] for a syntax error, an unknown key or a value of the wrong type.
    pub fn from_toml(text: &str) -> Result<ModelSpec, ModelSpecError> {
        parse_toml(text).map_err(ModelSpecError)
    }
}

/// α5 of `p` for the rest distance `z` (m, the request's `z_c`): z in units of the probe's
/// length scale ([`Params::alpha5_for_rest_distance`]), within the model's range.
fn alpha5_of_rest_distance(z: f64, p: &Params, probe: Option<&Probe>) -> Result<f64, SimError> {
    let probe = probe
        .ok_or_else(|| SimError::out_of_range("z_c", z, "needs a probe file (z_c is in m, SI)"))?;
    crate::error::within(
        "z_c",
        z,
        f64::MIN..=f64::MAX,
        "must be a finite distance in m",
    )?;
    super::limits::si_distance("z_c", z)?;
    let alpha5 = p.alpha5_for_rest_distance(z / probe.scales.length_m);
    if alpha5.is_nan() || alpha5.abs() > crate::params::DISPLACEMENT_MAX {
        // the model's range of α5 in the user's unit: z_c in m for this probe's A0
        let edge = |a5: f64| Params { alpha5: a5, ..*p }.rest_distance() * probe.scales.length_m;
        return Err(SimError::out_of_range(
            "z_c",
            format!(
                "{} m (this probe allows [{}, {}] m: ±1e6 × its length unit A0 = {} m)",
                crate::error::number(z),
                crate::error::number(edge(-crate::params::DISPLACEMENT_MAX)),
                crate::error::number(edge(crate::params::DISPLACEMENT_MAX)),
                crate::error::number(probe.scales.length_m)
            ),
            "must lie within the probe's range: the model takes rest distances up to \
             1e6 free amplitudes A0 from the sample",
        ));
    }
    Ok(alpha5)
}

/// Ω of the drive frequency `f` (Hz, the request's `drive_frequency`) under the probe's time
/// scale, within [`super::limits::SI_FREQUENCY_RATIO`] of the probe's drive frequency.
fn omega_of_drive_frequency(f: f64, probe: Option<&Probe>) -> Result<f64, SimError> {
    let probe = probe.ok_or_else(|| {
        SimError::out_of_range(
            "drive_frequency",
            f,
            "needs a probe file (drive_frequency is in Hz, SI)",
        )
    })?;
    super::limits::positive("drive_frequency", f, "must be finite and > 0 (Hz)")?;
    let (lo, hi) = super::limits::SI_FREQUENCY_RATIO;
    let ratio = f / probe.drive_frequency;
    if !(lo..=hi).contains(&ratio) {
        return Err(SimError::out_of_range(
            "drive_frequency",
            format!(
                "{} Hz ({} × the probe's {} Hz)",
                crate::error::number(f),
                crate::error::number(ratio),
                crate::error::number(probe.drive_frequency)
            ),
            "must be within [0.01, 1e4] × the probe's drive frequency: frequencies are \
             in Hz (300 kHz is 300e3, or 300kHz on the command line)",
        ));
    }
    Ok(probe.scales.omega(f))
}

/// The model values a probe file sets in SI, refused as dimensionless values when a probe is
/// given (its scales would not apply to them: `hamaker = 6.6e-20` taken as H̃ is not the
/// Hamaker constant in J): the value's name and what to give instead. The law's groups say
/// it themselves (`crate::contact::Param::under_probe`, `probe_sets`). `modes`,
/// `restitution` (pure numbers, the same in SI) and the SI values `z_c` and `drive_frequency`
/// are taken with a probe.
pub const PROBE_SETS: [(&str, &str); 9] = [
    (
        "tip_mass_ratio",
        "is the dimensionless α1 and a probe sets it: give it in the probe file's [cantilever] \
         tip_mass_ratio (beam)",
    ),
    (
        "drive_amplitude",
        "is the dimensionless α2 and a probe sets it: give the free amplitude in the probe \
         file's [drive] free_amplitude (m)",
    ),
    (
        "beam_damping",
        "is the dimensionless α3 and a probe sets it: give the quality factor in the probe \
         file's [cantilever] quality_factor",
    ),
    (
        "contact_stiffness",
        "is the dimensionless α4 and a probe sets it: give the sample in the probe file's \
         [sample] youngs_modulus (Pa; linear law: stiffness in N/m)",
    ),
    (
        "gap",
        "is the dimensionless α5 and a probe sets it: give the rest distance z_c in m instead \
         (--z-c 8nm on the command line, z_c=8e-9 in Python)",
    ),
    (
        "contact_damping",
        "is the dimensionless α6 and a probe sets it: give it in the probe file's [sample] \
         viscosity (Pa s, DMT) or damping (N s/m, linear and Hertz)",
    ),
    (
        "omega",
        "is the dimensionless Ω and a probe sets it: give the drive frequency in Hz instead \
         (--drive-frequency 300kHz on the command line, drive_frequency=300e3 in Python)",
    ),
    (
        "contact_law",
        "is set by the probe file's [sample] law (its constants are SI keys of that section): \
         change the law there",
    ),
    (
        "excitation",
        "is set by the probe file's [drive] excitation (its drive amplitude is calibrated for \
         it): change it there",
    ),
];

/// What to give instead of `name` under a probe ([`PROBE_SETS`], or the law group's
/// [`crate::contact::Param::under_probe`]), if a probe sets it.
pub(crate) fn probe_sets(name: &str) -> Option<std::borrow::Cow<'static, str>> {
    if let Some((_, allowed)) = PROBE_SETS.iter().find(|(key, _)| *key == name) {
        return Some((*allowed).into());
    }
    let g = GROUPS.iter().find(|g| g.name == name)?;
    let hint = g.under_probe?;
    Some(
        format!(
            "is the dimensionless {} and a probe sets it: {hint}",
            g.symbol
        )
        .into(),
    )
}

/// A model spec that could not be read (a config file's text): the parser's message.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct ModelSpecError(pub String);

/// Parse TOML text into `T`; the error is one line: "line L, column C: message" (for a
/// duplicate key, the key).
pub fn parse_toml<T: for<'de> Deserialize<'de>>(text: &str) -> Result<T, String> {
    toml::from_str(text).map_err(|e| {
        let mut msg = e.message().trim().replace('\n', " ");
        let Some(span) = e.span() else { return msg };
        let start = span.start.min(text.len());
        let before = &text[..start];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        if msg.starts_with("duplicate key") {
            let key = text.get(span.clone()).unwrap_or("").trim();
            if !key.is_empty() && !msg.contains(key) {
                msg = format!("duplicate key `{key}`");
            }
        }
        format!("line {line}, column {column}: {msg}")
    })
}

#[cfg(test)]
mod tests;
