//! A front end's keywords on their way into a request ([`Keyword`]: numbers, strings, lists
//! and maps, NaN and ±∞ kept so that the request's own checks name them) and the errors that
//! tell an unknown keyword, a value of the wrong type and a value out of range apart
//! ([`KeywordError`]), worded for the user ([`KeywordError::message`],
//! [`KeywordError::model_message`]): what a dynamically typed front end (Python) needs to
//! deserialise a request or the model's keywords ([`super::ModelSpec`]) with serde.

use super::model::{closest_parameter, ValueKind};
use super::{parameter, MODEL_PARAMETERS};
use serde::de::{self, IntoDeserializer, Unexpected, Visitor};

/// A value given for a keyword.
#[derive(Debug, Clone, PartialEq)]
pub enum Keyword {
    /// Nothing (the request's default).
    Null,
    /// `None` given where nothing stands for no default (a model keyword): a value of the
    /// wrong type.
    NoneGiven,
    /// A boolean.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A real number (NaN and ±∞ kept).
    Float(f64),
    /// A string.
    Str(String),
    /// A list.
    Seq(Vec<Keyword>),
    /// A map of keywords, in their order.
    Map(Vec<(String, Keyword)>),
}

/// What a [`KeywordError`] is about.
#[derive(Debug, Clone, PartialEq)]
pub enum KeywordErrorKind {
    /// A keyword the request does not have.
    Unknown(String),
    /// A value of another type: the type given, in Python's words (`str`, `float`, …).
    Type(&'static str),
    /// A value the request refuses: the value, where serde shows it.
    Value(Option<String>),
}

/// A serde error of a request's keywords.
#[derive(Debug, Clone, PartialEq)]
pub struct KeywordError {
    /// serde's message.
    pub msg: String,
    /// What it is about.
    pub kind: KeywordErrorKind,
}

impl std::fmt::Display for KeywordError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.msg)
    }
}

impl std::error::Error for KeywordError {}

impl de::Error for KeywordError {
    fn custom<T: std::fmt::Display>(msg: T) -> Self {
        KeywordError {
            msg: msg.to_string(),
            kind: KeywordErrorKind::Value(None),
        }
    }
    fn unknown_field(field: &str, expected: &'static [&'static str]) -> Self {
        KeywordError {
            msg: format!(
                "unknown keyword '{field}': expected {}",
                expected.join(", ")
            ),
            kind: KeywordErrorKind::Unknown(field.to_string()),
        }
    }
    fn invalid_type(unexp: Unexpected, exp: &dyn de::Expected) -> Self {
        let got = match unexp {
            Unexpected::Bool(_) => "bool",
            Unexpected::Signed(_) | Unexpected::Unsigned(_) => "int",
            Unexpected::Float(_) => "float",
            Unexpected::Str(_) | Unexpected::Char(_) => "str",
            Unexpected::Unit | Unexpected::Option => "NoneType",
            Unexpected::Seq => "list",
            Unexpected::Map => "dict",
            _ => "value",
        };
        KeywordError {
            msg: format!("invalid type: {unexp}, expected {exp}"),
            kind: KeywordErrorKind::Type(got),
        }
    }
    fn invalid_value(unexp: Unexpected, exp: &dyn de::Expected) -> Self {
        let shown = match unexp {
            Unexpected::Signed(i) => Some(i.to_string()),
            Unexpected::Unsigned(u) => Some(u.to_string()),
            Unexpected::Float(x) => Some(x.to_string()),
            _ => None,
        };
        KeywordError {
            msg: format!("invalid value: {unexp}, expected {exp}"),
            kind: KeywordErrorKind::Value(shown),
        }
    }
    fn duplicate_field(field: &'static str) -> Self {
        let msg = match parameter(field).and_then(|p| p.alias) {
            Some(alias) => format!("{field} and {alias} both given: they are the same parameter"),
            None => format!("{field} given twice"),
        };
        KeywordError {
            msg,
            kind: KeywordErrorKind::Value(None),
        }
    }
}

impl KeywordError {
    /// Whether a front end raises it as a type error (an unknown keyword).
    pub fn is_unknown(&self) -> bool {
        matches!(self.kind, KeywordErrorKind::Unknown(_))
    }

    /// The message of this error of keyword `path` (serde_path_to_error's; `.` for the
    /// request itself) of request `what`, the unsigned integers named in words (a negative
    /// count as `steps = -1: must be >= 0`).
    pub fn message(&self, what: &str, path: &str) -> String {
        let text = ["usize", "u64", "u32", "u16", "u8"]
            .iter()
            .fold(self.msg.clone(), |t, ty| {
                t.replace(&format!("expected {ty}"), "expected a non-negative integer")
            });
        if let KeywordErrorKind::Value(Some(v)) = &self.kind {
            if v.starts_with('-') && text.ends_with("expected a non-negative integer") {
                return format!("{what}: {path} = {v}: must be >= 0");
            }
        }
        if self.is_unknown() || path == "." {
            format!("{what}: {text}")
        } else {
            format!("{what}: {path}: {text}")
        }
    }

    /// The message of this error of model keyword `key` ([`super::ModelSpec`]'s path) and
    /// whether it is a type error: an unknown keyword (with the closest name and every name;
    /// `from`, a Python keyword, as `from_`) or a value of the wrong type (what the keyword
    /// takes, from [`MODEL_PARAMETERS`]); else a value out of range (with the range).
    pub fn model_message(&self, key: &str) -> (bool, String) {
        let p = parameter(key);
        match &self.kind {
            KeywordErrorKind::Unknown(key) => {
                let hint = if key == "from" {
                    "'from' is a Python keyword: the start of a range is from_=...; ".to_string()
                } else {
                    closest_parameter(key).map_or(String::new(), |n| format!("did you mean {n}? "))
                };
                let names: Vec<String> = MODEL_PARAMETERS
                    .iter()
                    .map(|p| match p.alias {
                        None => p.name.to_string(),
                        Some(alias) => format!("{} ({alias})", p.name),
                    })
                    .collect();
                let msg = format!(
                    "unknown model parameter '{key}': {hint}expected {}",
                    names.join(", ")
                );
                (true, msg)
            }
            KeywordErrorKind::Type(got) => {
                let takes = match p.map(|p| p.kind) {
                    Some(ValueKind::Integer) => "an integer",
                    Some(ValueKind::Real) => "a number",
                    Some(ValueKind::Law) => "a string (a contact law)",
                    Some(ValueKind::Excitation) => "a string (base or tip)",
                    None => "another type",
                };
                (true, format!("{key}: expected {takes}, got {got}"))
            }
            KeywordErrorKind::Value(Some(v)) if p.is_some() => {
                let range = p.map_or("", |p| p.range);
                (false, format!("{key} = {v}: must be in {range}"))
            }
            KeywordErrorKind::Value(_) if key == "." => (false, self.msg.clone()),
            KeywordErrorKind::Value(_) => (false, format!("{key}: {}", self.msg)),
        }
    }
}

/// The name `s` given for keyword `key` in the request's spelling, for the keywords whose
/// names are parsed as the command line parses them (`integrator`, `param`, `contact_law`,
/// `excitation`: aliases and "did you mean" from their `FromStr`); `s` itself for the others.
///
/// # Errors
/// The `FromStr` message of a name it refuses.
pub fn canonical_name(key: &str, s: String) -> Result<String, String> {
    fn spelled<T>(s: String) -> Result<String, String>
    where
        T: std::str::FromStr + serde::Serialize,
        T::Err: std::fmt::Display,
    {
        let t: T = s.parse().map_err(|e: T::Err| e.to_string())?;
        match serde_json::to_value(t) {
            Ok(serde_json::Value::String(name)) => Ok(name),
            _ => Ok(s),
        }
    }
    match key {
        "integrator" => spelled::<crate::integrate::IntegratorKind>(s),
        "param" => spelled::<crate::SweepParam>(s),
        "contact_law" => spelled::<crate::LawKind>(s),
        "excitation" => spelled::<crate::Excitation>(s),
        _ => Ok(s),
    }
}

impl Keyword {
    /// As a TOML value (a probe given as a map of its sections); `None` for nothing.
    pub fn into_toml(self) -> Option<toml::Value> {
        Some(match self {
            Keyword::Null | Keyword::NoneGiven => return None,
            Keyword::Bool(b) => toml::Value::Boolean(b),
            Keyword::Int(i) => toml::Value::Integer(i),
            Keyword::Float(x) => toml::Value::Float(x),
            Keyword::Str(s) => toml::Value::String(s),
            Keyword::Seq(items) => {
                toml::Value::Array(items.into_iter().filter_map(Keyword::into_toml).collect())
            }
            Keyword::Map(entries) => toml::Value::Table(
                entries
                    .into_iter()
                    .filter_map(|(k, v)| v.into_toml().map(|v| (k, v)))
                    .collect(),
            ),
        })
    }
}

impl<'de> IntoDeserializer<'de, KeywordError> for Keyword {
    type Deserializer = Keyword;
    fn into_deserializer(self) -> Keyword {
        self
    }
}

impl<'de> de::Deserializer<'de> for Keyword {
    type Error = KeywordError;
    fn deserialize_any<V: Visitor<'de>>(self, v: V) -> Result<V::Value, KeywordError> {
        use de::value::{MapDeserializer, SeqDeserializer};
        match self {
            Keyword::Null | Keyword::NoneGiven => v.visit_unit(),
            Keyword::Bool(b) => v.visit_bool(b),
            Keyword::Int(i) => v.visit_i64(i),
            Keyword::Float(x) => v.visit_f64(x),
            Keyword::Str(s) => v.visit_string(s),
            Keyword::Seq(items) => v.visit_seq(SeqDeserializer::new(items.into_iter())),
            Keyword::Map(entries) => v.visit_map(MapDeserializer::new(entries.into_iter())),
        }
    }
    fn deserialize_option<V: Visitor<'de>>(self, v: V) -> Result<V::Value, KeywordError> {
        match self {
            Keyword::Null => v.visit_none(),
            other => v.visit_some(other),
        }
    }
    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _variants: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, KeywordError> {
        match self {
            Keyword::Str(s) => v.visit_enum(de::value::StringDeserializer::new(s)),
            other => other.deserialize_any(v),
        }
    }
    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf
        unit unit_struct newtype_struct seq tuple tuple_struct map struct identifier
        ignored_any
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::request::ModelSpec;
    use serde::Deserialize;

    fn model(entries: Vec<(&str, Keyword)>) -> Result<ModelSpec, KeywordError> {
        let map = entries.into_iter().map(|(k, v)| (k.to_string(), v));
        ModelSpec::deserialize(Keyword::Map(map.collect()))
    }

    #[test]
    fn the_model_keywords_deserialise_with_their_aliases_and_typed_errors() {
        let m = model(vec![
            ("alpha1", Keyword::Float(0.2)),
            ("modes", Keyword::Int(4)),
        ]);
        assert_eq!(m.unwrap().tip_mass_ratio, Some(0.2));
        let e = model(vec![("omegaa", Keyword::Float(1.0))]).unwrap_err();
        let (ty, msg) = e.model_message(".");
        assert!(ty && msg.contains("'omegaa': did you mean omega?"), "{msg}");
        let e = model(vec![("modes", Keyword::Bool(true))]).unwrap_err();
        assert_eq!(
            e.model_message("modes"),
            (true, "modes: expected an integer, got bool".into())
        );
        let e = model(vec![("gap", Keyword::NoneGiven)]).unwrap_err();
        assert_eq!(
            e.model_message("gap"),
            (true, "gap: expected a number, got NoneType".into())
        );
        let e = model(vec![("modes", Keyword::Int(-1))]).unwrap_err();
        assert_eq!(
            e.model_message("modes"),
            (false, "modes = -1: must be in 1..=20".into())
        );
        let both = vec![
            ("alpha4", Keyword::Float(1.0)),
            ("contact_stiffness", Keyword::Float(2.0)),
        ];
        let (ty, msg) = model(both).unwrap_err().model_message(".");
        assert!(!ty && msg.contains("both given"), "{msg}");
        assert_eq!(
            canonical_name("excitation", "magnetic".into()),
            Ok("tip".into())
        );
        let e = usize::deserialize(Keyword::Int(-3)).unwrap_err();
        let msg = e.message("simulate", "periods");
        assert_eq!(msg, "simulate: periods = -3: must be >= 0");
    }
}
