//! `reconstruct` from a document rather than a curve: an `fm` document in SI
//! ([`ReconstructRequest::from_fm_document`], its k, f0 and A replaced by those given) or an AM
//! approach document of the point mass ([`super::reconstruct::am_curve_from_approach`]), as a
//! front end that knows the analysis by name gives them (Python's `afmdyn.reconstruct(fm=…)`
//! and `(am=…)`): the named request `reconstruct_document` ([`super::named::parse`]), whose
//! outcome is the JSON document and the reconstruction's layout. Here: its keywords, their
//! check and the documents' text parsed.
//!
//! [`ReconstructRequest::from_fm_document`]: super::reconstruct::ReconstructRequest::from_fm_document

use super::reconstruct::FmInversion;
use crate::error::SimError;
use serde::Deserialize;
use serde_json::Value;

/// The keywords of a reconstruction from a document ([module docs](self)).
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct FromDocument {
    /// An `fm` document's JSON text.
    pub fm: Option<String>,
    /// An AM approach document's JSON text (its constants are the probe's).
    pub am: Option<String>,
    /// k (N/m), replacing the `fm` document's.
    pub spring_constant: Option<f64>,
    /// f0 (Hz), replacing the `fm` document's.
    pub resonance_frequency: Option<f64>,
    /// A (m), replacing the `fm` document's.
    pub amplitude: Option<f64>,
    /// The inversion of an `fm` curve (default Sader–Jarvis).
    #[serde(default)]
    pub inversion: FmInversion,
}

/// A document given as JSON text (`name` the keyword, for the error).
pub(crate) fn document(name: &'static str, text: &str) -> Result<Value, SimError> {
    serde_json::from_str(text).map_err(|e| {
        SimError::out_of_range(name, "the text given", format!("not a JSON document: {e}"))
    })
}

impl FromDocument {
    /// Check that one document is given, not both or neither.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `fm`.
    pub(crate) fn validate(&self) -> Result<(), SimError> {
        match (&self.fm, &self.am) {
            (Some(_), None) | (None, Some(_)) => Ok(()),
            _ => Err(SimError::out_of_range(
                "fm",
                "both or neither of fm and am",
                "give one document: fm or am",
            )),
        }
    }
}
