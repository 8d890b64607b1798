//! `reconstruct`'s running ([`crate::request::reconstruct`] is the request): the force and
//! potential behind a frequency-modulation curve (the Sader–Jarvis inversion or its exact
//! correction) or an AM approach of the point mass, their JSON documents and layout, and the
//! named request `reconstruct_document`'s run ([`FromDocument::run`]). SI throughout.

use crate::analysis::progress::Progress;
use crate::analysis::reconstruct::{sader_jarvis, Reconstruction};
use crate::analysis::reconstruct_am::AmCurve;
use crate::analysis::reconstruct_exact::exact_inversion;
use crate::error::SimError;
use crate::layout::Layout;
use crate::report::present::reconstruct::{reconstruction, Inversion};
use crate::report::Convergence;
use crate::request::reconstruct::{
    am_curve_from_approach, AmReconstruction, FmInversion, ReconstructRequest,
};
use crate::request::reconstruct_document::{self, FromDocument};
use crate::request::run::{run, Analysis, Resolved};
use crate::study::named::{Arrays, Datasets};
use serde_json::{json, Value};

impl Analysis for ReconstructRequest {
    type Output = Reconstruction;
    fn convergence(&self, r: &Reconstruction) -> Convergence {
        inversion_convergence(r)
    }
    fn execute(&self, _: &Resolved, progress: &Progress) -> Result<Reconstruction, SimError> {
        match self.inversion {
            FmInversion::SaderJarvis => sader_jarvis(&self.curve()?, progress),
            FmInversion::Exact => exact_inversion(&self.curve()?, progress),
        }
    }
    fn report(&self, _: &Resolved, r: &Reconstruction) -> Result<Value, SimError> {
        Ok(document(self, r))
    }
    fn present(
        &self,
        r: &Reconstruction,
        at: crate::request::Presenting<'_>,
    ) -> Result<crate::report::Presentation, SimError> {
        let how = match self.inversion {
            FmInversion::SaderJarvis => Inversion::SaderJarvis,
            FmInversion::Exact => Inversion::Exact,
        };
        present_reconstruction(r, how, self.law_in_order(), at.document, at.units, at.to)
    }
}

/// A reconstruction's presentation at `to` ([`crate::report::present::reconstruct::reconstruction`]),
/// the printed document naming its table.
fn present_reconstruction(
    r: &Reconstruction,
    how: Inversion,
    law: Option<Vec<f64>>,
    document: &Value,
    units: crate::report::TextUnits,
    to: crate::request::run::Destination<'_>,
) -> Result<crate::report::Presentation, SimError> {
    let mut document = document.clone();
    let mut shown = reconstruction(r, how, law, &mut document, units, to);
    shown.document = Some(document);
    Ok(shown)
}

impl Analysis for AmReconstruction {
    type Output = Reconstruction;
    fn convergence(&self, r: &Reconstruction) -> Convergence {
        inversion_convergence(r)
    }
    fn execute(&self, _: &Resolved, progress: &Progress) -> Result<Reconstruction, SimError> {
        let curve = am_curve_from_approach(&self.0)?;
        crate::analysis::reconstruct_am::matrix_inversion(&curve, progress)
    }
    fn report(&self, _: &Resolved, r: &Reconstruction) -> Result<Value, SimError> {
        Ok(am_document(&am_curve_from_approach(&self.0)?, r))
    }
    fn present(
        &self,
        r: &Reconstruction,
        at: crate::request::Presenting<'_>,
    ) -> Result<crate::report::Presentation, SimError> {
        present_reconstruction(r, Inversion::AmMatrix, None, at.document, at.units, at.to)
    }
}

/// The document of a reconstruction (`afmdyn reconstruct --json`): `force` (`distance` (m),
/// `force` (N), `potential` (J), increasing distance; `law` (N), the model's force there, for a
/// curve from an `fm` document), the cantilever's constants, `method`,
/// `units`, `warnings` ([`ReconstructRequest::warnings`]: constants outside their typical
/// ranges, data that end before the shift has decayed); `inversion` (`"sader-jarvis"` or
/// `"exact"`) and for the exact inversion `exact` ([`ExactRecord`]: `iterations`,
/// `sader_jarvis_residual`, `forward_residual`, `converged`).
///
/// [`ExactRecord`]: crate::analysis::reconstruct::ExactRecord
pub(crate) fn document(request: &ReconstructRequest, r: &Reconstruction) -> Value {
    let mut force = json!({"distance": r.distance, "force": r.force, "potential": r.potential});
    if let Some(law) = request.law_in_order() {
        force["law"] = json!(law);
    }
    let method = match request.inversion {
        FmInversion::SaderJarvis => {
            "Sader-Jarvis inversion (Appl. Phys. Lett. 84, 1801 (2004)); potential by \
             integrating the force from the last distance"
        }
        FmInversion::Exact => {
            "exact inversion of Giessibl's first-order relation: the Sader-Jarvis estimate \
             corrected by defect correction through the piecewise-linear forward relation \
             (Giessibl's matrix method, Appl. Phys. Lett. 78, 123 (2001)); potential by \
             integrating the force from the last distance"
        }
    };
    let mut doc = json!({
        "force": force,
        "spring_constant": request.spring_constant,
        "resonance_frequency": request.resonance_frequency,
        "amplitude": request.amplitude,
        "inversion": request.inversion.word(),
        "method": method,
        "units": {"distance": "m", "force": "N", "potential": "J"},
        "warnings": request.warnings(),
    });
    if let Some(e) = &r.exact {
        doc["exact"] = json!(e);
        if let (Some(w), Some(ws)) = (exact_warning(e), doc["warnings"].as_array_mut()) {
            ws.push(w.into());
        }
    }
    doc
}

/// An inversion's convergence: Sader–Jarvis's closed form is direct, the exact inversion's
/// iteration converged or stopped above round-off.
fn inversion_convergence(r: &Reconstruction) -> Convergence {
    r.exact
        .as_ref()
        .map_or(Convergence::exact("inversion"), |e| {
            Convergence::of("exact inversion", usize::from(e.converged), 1)
        })
}

/// The warning of an exact inversion that did not converge to round-off
/// (`crate::analysis::reconstruct_exact`: it stops where a correction step no longer shrinks
/// the forward residual, typically in the rows within 2A of the data's end), or `None`.
fn exact_warning(e: &crate::analysis::reconstruct::ExactRecord) -> Option<String> {
    (!e.converged).then(|| {
        warning!(
            "reconstruct.exact-unconverged",
            "Read the force within 2A of the data's end as the last iterate; take data \
             further out.",
            "the exact inversion did not converge (exact.converged = false): it stopped after \
             {} correction step(s) at a forward residual of {} of the largest |Δf| (Sader–Jarvis's: \
             {}), above round-off ({}), where a step no longer shrank it — usually in the rows \
             within 2A of the data's end, whose cycles reach beyond the data; the force is the \
             last iterate",
            e.iterations,
            crate::error::number(e.forward_residual),
            crate::error::number(e.sader_jarvis_residual),
            crate::error::number(crate::analysis::reconstruct_exact::EXACT_TOLERANCE),
        )
    })
}

/// The document of an AM reconstruction (`afmdyn reconstruct --am`): as [`document`]'s, with
/// `amplitude` the free amplitude A₀, `quality_factor`, `drive_frequency` and the points used.
pub(crate) fn am_document(curve: &AmCurve, r: &Reconstruction) -> Value {
    json!({
        "force": {"distance": r.distance, "force": r.force, "potential": r.potential},
        "spring_constant": curve.spring_constant,
        "resonance_frequency": curve.resonance_frequency,
        "amplitude": curve.free_amplitude,
        "quality_factor": curve.quality_factor,
        "drive_frequency": curve.drive_frequency,
        "points": curve.z_c.len(),
        "method": "AM inversion: the first-harmonic balance kA(1 - w^2/w0^2) - F0 cos(phi) = \
                   (1/pi) integral of F cos(theta), inverted by Giessibl's matrix method (Appl. \
                   Phys. Lett. 78, 123 (2001)) with hat functions at each point's lower turning \
                   point and amplitude (analysis::reconstruct_am); the approach's attractive run \
                   (phase lag above 90 degrees)",
        "units": {"distance": "m", "force": "N", "potential": "J"},
        "warnings": [
            "the force near the largest distance is not reconstructed: the inversion integrates \
             the curve beyond each distance, and the data end there (start the approach where \
             the amplitude and phase are the free ones)"
        ],
    })
}

/// The reconstruction of an `afmdyn approach --probe` document of the point mass and its JSON
/// document ([`am_curve_from_approach`], [`crate::analysis::reconstruct_am::matrix_inversion`],
/// [`am_document`]): `reconstruct --am` of every front end.
///
/// Counts the rows in `progress` and stops at its cancel flag.
///
/// # Errors
/// As [`am_curve_from_approach`] and the inversion
/// ([`crate::analysis::reconstruct_am::matrix_inversion`]).
pub(crate) fn am_reconstruction(
    approach: &Value,
    progress: &Progress,
) -> Result<crate::request::run::Document<Reconstruction>, SimError> {
    let curve = am_curve_from_approach(approach)?;
    let r = crate::analysis::reconstruct_am::matrix_inversion(&curve, progress)?;
    Ok(crate::request::run::Document {
        json: am_document(&curve, &r),
        output: r,
    })
}

/// The variables of a reconstruction's layout ([`layout`]) after `distance`: name, unit (SI,
/// as the documents' `units` name them: [`document`], [`am_document`]) and long name; `law`
/// only for a curve that carries the model's force (an `fm` document's).
const RECONSTRUCT_VARIABLES: [(&str, &str, &str); 3] = [
    (
        "law",
        "N",
        "the model's force at d (a curve from afmdyn.fm)",
    ),
    ("force", "N", "tip–sample force F(d)"),
    (
        "potential",
        "J",
        "potential U(d), integral of F from d to the last distance",
    ),
];

/// The layout of a reconstruction `r` (what Python's `afmdyn.reconstruct` returns): over
/// `distance` (the distance of closest approach d in m, increasing; its coordinate) `law`
/// (N; with `law`, the model's force at each distance in that order:
/// `ReconstructRequest::law_in_order`), `force` (N) and `potential` (J), SI as the
/// documents.
pub(crate) fn layout(r: &Reconstruction, law: Option<Vec<f64>>) -> crate::layout::Layout {
    use crate::layout::{Layout, Variable};
    let d = ["distance"];
    let mut variables = vec![Variable::f64(
        "distance",
        &d,
        "m",
        "distance of closest approach d",
        &r.distance,
    )];
    for (name, unit, long_name) in RECONSTRUCT_VARIABLES {
        let values = match name {
            "law" => match &law {
                Some(l) => l.as_slice(),
                None => continue,
            },
            "force" => r.force.as_slice(),
            _ => r.potential.as_slice(),
        };
        variables.push(Variable::f64(name, &d, unit, long_name, values));
    }
    Layout::new("reconstruct", &[("distance", r.distance.len())], variables)
}

impl FromDocument {
    /// The reconstruction's JSON document and its layout ([`layout`]:
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
                        &reconstruct_document::document("fm", fm)?,
                        self.spring_constant,
                        self.resonance_frequency,
                        self.amplitude,
                    )?
                };
                let done = run(&request, model, progress)?;
                Ok((done.json, layout(&done.output, request.law_in_order())))
            }
            (None, Some(am)) => {
                let done = am_reconstruction(&reconstruct_document::document("am", am)?, progress)?;
                Ok((done.json, layout(&done.output, None)))
            }
            (None, None) => unreachable!("validated"),
        }
    }
}

impl Datasets for ReconstructRequest {
    /// The reconstruction's layout `reconstruct` (`layout`, with the request's
    /// `law_force`).
    fn datasets(&self, _: &Resolved, r: &Self::Output) -> Result<Arrays, SimError> {
        let layout = layout(r, self.law_in_order());
        Ok((vec![("reconstruct".into(), layout)], serde_json::Map::new()))
    }
}
