//! `reconstruct`: the force and potential behind a frequency-modulation curve
//! ([`crate::analysis::reconstruct`], the Sader–Jarvis inversion) — the request that the
//! command line (`afmdyn reconstruct --fm FILE`) and Python (`afmdyn.reconstruct`) share, and
//! its JSON document. SI throughout: distances and the amplitude in m, frequencies in Hz, the
//! spring constant in N/m; the force in N, the potential in J.

use super::run::{Analysis, Resolved};
use crate::analysis::progress::Progress;
use crate::analysis::reconstruct::{sader_jarvis, Reconstruction, ShiftCurve};
use crate::error::SimError;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// `reconstruct`: a frequency-shift curve Δf against the distance of closest approach d (or
/// the rest distance z_c, d = z_c − A), with the cantilever's k, f0 and A.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct ReconstructRequest {
    /// Distances of closest approach d (m), monotonic (either order); or give `z_c`.
    pub distance: Option<Vec<f64>>,
    /// Rest distances z_c (m) instead of `distance`: d = z_c − A (the lower turning point of
    /// an oscillation of amplitude A without static deflection).
    pub z_c: Option<Vec<f64>>,
    /// Frequency shifts Δf = f − f0 (Hz), one per distance.
    pub frequency_shift: Vec<f64>,
    /// Spring constant k (N/m), > 0.
    pub spring_constant: f64,
    /// Free resonance frequency f0 (Hz), > 0.
    pub resonance_frequency: f64,
    /// Oscillation amplitude A (m), > 0.
    pub amplitude: f64,
}

impl ReconstructRequest {
    /// The curve to invert, in increasing distance.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the field: neither or both of `distance` and `z_c`,
    /// and as [`ShiftCurve::validate`] (distances not monotonic among them).
    pub fn curve(&self) -> Result<ShiftCurve, SimError> {
        let distance: Vec<f64> =
            match (&self.distance, &self.z_c) {
                (Some(d), None) => d.clone(),
                (None, Some(z)) => z.iter().map(|z| z - self.amplitude).collect(),
                (given, _) => return Err(SimError::out_of_range(
                    "distance",
                    if given.is_some() {
                        "given with z_c"
                    } else {
                        "missing"
                    },
                    "give the distances of closest approach or the rest distances z_c, one of them",
                )),
            };
        let mut curve = ShiftCurve {
            distance,
            frequency_shift: self.frequency_shift.clone(),
            spring_constant: self.spring_constant,
            resonance_frequency: self.resonance_frequency,
            amplitude: self.amplitude,
        };
        // an approach curve runs towards the sample: invert it in increasing distance
        if curve.distance.len() >= 2 && curve.distance[0] > curve.distance[1] {
            curve.distance.reverse();
            curve.frequency_shift.reverse();
        }
        curve.validate()?;
        Ok(curve)
    }
}

impl Analysis for ReconstructRequest {
    type Output = Reconstruction;
    fn validate(&self, _: &Resolved) -> Result<(), SimError> {
        self.curve().map(|_| ())
    }
    fn execute(&self, _: &Resolved, _: &Progress) -> Result<Reconstruction, SimError> {
        sader_jarvis(&self.curve()?)
    }
    fn report(&self, _: &Resolved, r: &Reconstruction) -> Result<Value, SimError> {
        Ok(document(self, r))
    }
}

/// The document of a reconstruction (`afmdyn reconstruct --json`): `force` (`distance` (m),
/// `force` (N), `potential` (J), increasing distance), the cantilever's constants, `method`,
/// `units`, `warnings` (the far end of the data, where the inversion has no data beyond).
pub fn document(request: &ReconstructRequest, r: &Reconstruction) -> Value {
    json!({
        "force": {"distance": r.distance, "force": r.force, "potential": r.potential},
        "spring_constant": request.spring_constant,
        "resonance_frequency": request.resonance_frequency,
        "amplitude": request.amplitude,
        "method": "Sader-Jarvis inversion (Appl. Phys. Lett. 84, 1801 (2004)); potential by \
                   integrating the force from the last distance",
        "units": {"distance": "m", "force": "N", "potential": "J"},
        "warnings": [
            "the force near the largest distance is not reconstructed: the inversion integrates \
             the frequency shift beyond each distance, and the data end there (take data out to \
             where the shift has decayed)"
        ],
    })
}
