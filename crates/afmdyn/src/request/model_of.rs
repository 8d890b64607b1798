//! The model keywords of a parameter set ([`ModelSpec::of`]): what a front end shows as a
//! set's attributes (Python's `Params.omega`, `Params.hamaker`, …), from the one table of
//! names ([`super::MODEL_PARAMETERS`]).

use super::{parameter, ModelSpec};
use crate::Params;

impl ModelSpec {
    /// Every model value of `p` under its keyword: the law's groups those it has (the others
    /// `None`), no SI values (`z_c`, `drive_frequency`: a probe's, not the set's). Resolved
    /// over any set it gives `p` back (for the keywords' part of it).
    pub fn of(p: &Params) -> ModelSpec {
        ModelSpec {
            modes: Some(p.modes),
            tip_mass_ratio: Some(p.alpha1),
            drive_amplitude: Some(p.alpha2),
            beam_damping: Some(p.alpha3),
            contact_stiffness: Some(p.alpha4),
            gap: Some(p.alpha5),
            contact_damping: Some(p.alpha6),
            omega: Some(p.omega),
            contact_law: Some(p.contact_law.kind()),
            excitation: Some(p.excitation),
            groups: p.contact_law.groups(),
            z_c: None,
            drive_frequency: None,
        }
    }

    /// The value of keyword `key` (a name or alias of [`super::MODEL_PARAMETERS`]) as JSON:
    /// `Some(Null)` for a keyword without a value here, `None` for a name that is no keyword.
    pub fn value(&self, key: &str) -> Option<serde_json::Value> {
        let name = parameter(key)?.name;
        let map = serde_json::to_value(self).ok()?;
        Some(map.get(name).cloned().unwrap_or(serde_json::Value::Null))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::LawKind;

    #[test]
    fn a_sets_keywords_resolve_to_the_set() {
        let dmt = ModelSpec {
            contact_law: Some(LawKind::Dmt),
            omega: Some(3.1),
            ..ModelSpec::default()
        };
        for p in [
            Params::default(),
            dmt.resolve(Params::default(), None).unwrap(),
        ] {
            let spec = ModelSpec::of(&p);
            assert_eq!(spec.resolve(Params::default(), None).unwrap(), p);
            assert_eq!(spec.value("alpha4"), Some(p.alpha4.into()));
            assert_eq!(spec.value("omega"), Some(p.omega.into()));
        }
        let spec = ModelSpec::of(&Params::default());
        assert_eq!(spec.value("hamaker"), Some(serde_json::Value::Null));
        assert_eq!(spec.value("period"), None);
    }
}
