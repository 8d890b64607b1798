//! What a resumed sweep holds against its store: the plan in a bifurcation request's
//! fingerprint (`super::analyses::fingerprint`), the first field in which two fingerprints
//! differ and the number of a sweep's points; the sweep's records are `crate::report::sweep`'s
//! (re-exported here).

pub use crate::report::sweep::*;

use crate::analysis::bifurcation::SweepSpec;
use serde_json::Value;

/// The plan of a sweep's tasks in its fingerprint: chains cut into ⌈√n⌉ chunks seeded by a
/// coarse pass, random starts keyed by (seed, value, start).
pub(crate) const PLAN: &str = "chunks-sqrt, starts keyed by value";

/// The order in which [`first_difference`] compares a fingerprint's fields.
const FIELD_ORDER: [&str; 17] = [
    "afmdyn",
    "plan",
    "params",
    "param",
    "from",
    "to",
    "steps",
    "values",
    "continuation",
    "starts",
    "seed",
    "tol",
    "max_periods",
    "max_period",
    "integrator",
    "steps_per_period",
    "tolerance",
];

/// The first field in which two fingerprints differ, with its value in each (`absent` where a
/// field is missing): `("steps", "60", "30")`. A model parameter is named without its
/// `params.` prefix (`alpha4`, `contact_law.kind`). `None` when they are equal.
pub fn first_difference(then: &Value, now: &Value) -> Option<(String, String, String)> {
    fn show(v: Option<&Value>) -> String {
        match v {
            None => "absent".into(),
            Some(Value::Null) => "not given (its default)".into(),
            Some(Value::String(s)) => s.clone(),
            Some(v) => v.to_string(),
        }
    }
    fn walk(path: &str, a: Option<&Value>, b: Option<&Value>) -> Option<(String, String, String)> {
        if a == b {
            return None;
        }
        if let (Some(Value::Object(x)), Some(Value::Object(y))) = (a, b) {
            let mut keys: Vec<&String> = x.keys().chain(y.keys()).collect();
            keys.sort_by_key(|k| {
                let pos = FIELD_ORDER.iter().position(|f| f == k);
                (pos.unwrap_or(usize::MAX), k.to_string())
            });
            keys.dedup();
            return keys.into_iter().find_map(|k| {
                let sub = match path {
                    "" | "params" => k.clone(),
                    p => format!("{p}.{k}"),
                };
                walk(&sub, x.get(k), y.get(k))
            });
        }
        Some((path.to_string(), show(a), show(b)))
    }
    walk("", Some(then), Some(now))
}
/// The number of points of a sweep: values × (2 with continuation + random starts).
pub fn point_count(spec: &SweepSpec) -> usize {
    spec.values.len() * (usize::from(spec.continuation) * 2 + spec.starts as usize)
}
