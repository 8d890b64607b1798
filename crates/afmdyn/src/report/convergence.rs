//! A result's convergence state (issue 77 item 3: no result without its convergence): how
//! many of the parts a result is made of settled, which every analysis states of its result
//! (`crate::request::Analysis::convergence`) and the door writes into every document
//! (`"converged"`) and, for a partial result, into its warnings, on every front end.

use serde::Serialize;
use serde_json::Value;

/// How many of a result's parts converged: the points of a curve, the pixels of an image, the
/// cells of a map, the random starts of a census, the branches of a continuation, the
/// minimiser of a fit, the inversion of a reconstruction. A part that did not settle (a
/// transient still converging at its cap, a branch ended early, a pixel with no operating
/// point, a failed run) is counted in `of` but not in `settled`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Convergence {
    /// What the parts are (`"points"`, `"pixels"`, `"cells"`, `"starts"`, …).
    pub part: &'static str,
    /// The parts that converged.
    pub settled: usize,
    /// The parts computed or asked for.
    pub of: usize,
}

impl Convergence {
    /// The state of a document that is no computation's result (the lever library, a unit
    /// conversion): none, and the door writes none.
    pub const NOTHING: Convergence = Convergence {
        part: "",
        settled: 0,
        of: 0,
    };

    /// `settled` of `of` parts.
    pub fn of(part: &'static str, settled: usize, of: usize) -> Self {
        Convergence { part, settled, of }
    }

    /// A result with no part that could fail to settle: computed directly (an eigenproblem, a
    /// closed form, a trajectory from its start), or refused as an error where it does not
    /// converge (a Newton solve).
    pub fn exact(part: &'static str) -> Self {
        Self::of(part, 1, 1)
    }

    /// The parts of `parts` for which `settled` holds.
    pub fn count<T>(part: &'static str, parts: &[T], settled: impl Fn(&T) -> bool) -> Self {
        Self::of(
            part,
            parts.iter().filter(|p| settled(p)).count(),
            parts.len(),
        )
    }

    /// Whether every part settled.
    pub fn converged(&self) -> bool {
        self.settled == self.of
    }

    /// The door's part of a document ([`crate::request::document`]): `"converged"`
    /// (`part`, `settled`, `of`, and `all`: whether every part settled) and, where a part did
    /// not settle, a warning naming how many, first among the document's warnings. A document
    /// that states its convergence already (one a front end also builds outside the door: a
    /// chart's cells for Dask) is left as it is.
    pub(crate) fn write_into(&self, doc: &mut Value) {
        if !doc.is_object() || *self == Self::NOTHING || doc.get("converged").is_some() {
            return;
        }
        doc["converged"] = serde_json::json!({
            "part": self.part,
            "settled": self.settled,
            "of": self.of,
            "all": self.converged(),
        });
        if !self.converged() {
            let warning = Value::from(warning!(
                "converged.partial",
                "Read the other warnings for which parts and why; a larger transient cap \
                 (max_periods) or budget usually settles them.",
                "convergence: {} of {} {} did not converge (the document's converged)",
                self.of - self.settled,
                self.of,
                self.part
            ));
            match doc.get_mut("warnings").and_then(Value::as_array_mut) {
                Some(w) => w.insert(0, warning),
                None => doc["warnings"] = Value::from(vec![warning]),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_partial_result_is_written_and_warned_of_and_a_whole_one_only_written() {
        let mut doc = serde_json::json!({"warnings": ["w"]});
        Convergence::count("points", &[1.0, f64::NAN, 2.0], |x| x.is_finite()).write_into(&mut doc);
        assert_eq!(doc["converged"]["settled"], 2);
        assert_eq!(doc["converged"]["of"], 3);
        assert_eq!(doc["converged"]["all"], false);
        assert_eq!(doc["warnings"].as_array().unwrap().len(), 2);
        assert!(doc["warnings"][0]
            .as_str()
            .unwrap()
            .starts_with("convergence: 1 of 3 points did not converge"));
        let mut doc = serde_json::json!({});
        Convergence::exact("inversion").write_into(&mut doc);
        assert_eq!(doc["converged"]["all"], true);
        assert!(doc.get("warnings").is_none());
    }
}
