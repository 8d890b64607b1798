//! `reconstruct` from a document rather than a curve: an `fm` document in SI
//! ([`ReconstructRequest::from_fm_document`], its k, f0 and A replaced by those given) or an AM
//! approach document of the point mass ([`am_reconstruction`]), as a front end that knows the
//! analysis by name gives them (Python's `afmdyn.reconstruct(fm=…)` and `(am=…)`): the named
//! request `reconstruct_document` ([`super::named::parse`]), whose outcome is the JSON document
//! and the reconstruction's layout ([`FromDocument::run`]).

use super::reconstruct::{am_reconstruction, layout, FmInversion, ReconstructRequest};
use super::run::{run, Resolved};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::layout::Layout;
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
fn document(name: &'static str, text: &str) -> Result<Value, SimError> {
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

    /// The reconstruction's JSON document and its layout ([`super::reconstruct::layout`]:
    /// with the `fm` document's `law_force`), counting in `progress` (cancellable).
    ///
    /// # Errors
    /// As [`FromDocument::validate`]; a text that is not JSON, a document that is not an SI
    /// `fm` document or an AM approach of the point mass; the inversion's errors.
    pub(crate) fn run(
        &self,
        model: &Resolved,
        progress: &Progress,
    ) -> Result<(Value, Layout), SimError> {
        self.validate()?;
        match (&self.fm, &self.am) {
            (Some(fm), _) => {
                let request = ReconstructRequest {
                    inversion: self.inversion,
                    ..ReconstructRequest::from_fm_document(
                        &document("fm", fm)?,
                        self.spring_constant,
                        self.resonance_frequency,
                        self.amplitude,
                    )?
                };
                let done = run(&request, model, progress)?;
                Ok((done.json, layout(&done.output, request.law_in_order())))
            }
            (None, Some(am)) => {
                let done = am_reconstruction(&document("am", am)?, progress)?;
                Ok((done.json, layout(&done.output, None)))
            }
            (None, None) => unreachable!("validated"),
        }
    }
}
