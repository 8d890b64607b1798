//! `thermal`'s running ([`crate::request::thermal`] is the request): the probe's model and
//! scales handed to [`crate::analysis::thermal::thermal_spectrum`], its document, layout and
//! presentation.

use crate::analysis::progress::Progress;
use crate::analysis::thermal::{thermal_spectrum, ThermalSpectrum};
use crate::error::SimError;
use crate::report::{self, Convergence};
use crate::request::run::{Analysis, Resolved};
use crate::request::thermal::ThermalRequest;
use serde_json::{json, Value};

impl ThermalRequest {
    /// The frequencies (Hz): `points` evenly spaced up to `to`, by default 1.25 times the
    /// highest mode's frequency and at least 3 f₀ (the modes' frequencies `modes`, Hz).
    fn frequencies(&self, modes: &[f64]) -> Vec<f64> {
        let top = modes.iter().copied().fold(0.0, f64::max);
        let first = modes.first().copied().unwrap_or(top);
        let to = self.to.unwrap_or((1.25 * top).max(3.0 * first));
        let n = self.points;
        (1..=n).map(|i| to * i as f64 / n as f64).collect()
    }
}

impl Analysis for ThermalRequest {
    type Output = ThermalSpectrum;
    fn convergence(&self, _: &ThermalSpectrum) -> Convergence {
        Convergence::exact("linear response")
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<ThermalSpectrum, SimError> {
        let probe = model.probe.as_ref().expect("validated: a probe");
        let units = super::model_units(&probe.scales);
        let (t, spot) = (self.temperature, self.spot);
        // the modes first (no frequency), then the spectrum at the frequencies they set
        let modes = thermal_spectrum(&model.params, units, t, spot, &[], progress)?;
        let f: Vec<f64> = modes.modes.iter().map(|m| m.frequency).collect();
        let frequencies = self.frequencies(&f);
        progress.add_total(frequencies.len());
        thermal_spectrum(&model.params, units, t, spot, &frequencies, progress)
    }
    fn report(&self, _: &Resolved, s: &ThermalSpectrum) -> Result<Value, SimError> {
        Ok(document(self, s))
    }
    fn present(
        &self,
        s: &ThermalSpectrum,
        at: crate::request::Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        Ok(crate::report::present::thermal::thermal(s, at.document))
    }
}

impl super::named::Datasets for ThermalRequest {
    /// `thermal` over `frequency` (the PSDs); `modes` over `mode` (each mode's share).
    fn datasets(
        &self,
        _: &Resolved,
        s: &ThermalSpectrum,
    ) -> Result<super::named::Arrays, SimError> {
        let layouts = crate::report::present::thermal::layouts(s);
        let mut facts = serde_json::Map::new();
        facts.insert("temperature".into(), json!(s.temperature));
        facts.insert("spring_constant".into(), json!(s.spring_constant));
        facts.insert("spot".into(), json!(s.spot));
        Ok((layouts, facts))
    }
}

/// The document (`afmdyn thermal --json`, Python's `summary`): `temperature` (K),
/// `spring_constant` (the static stiffness at the tip, N/m), `spot`, `modes` (each mode's
/// `mode`, `frequency` (Hz), `quality_factor`, `effective_spring_constant` (N/m),
/// `mean_square_deflection` and `mean_square_apparent_deflection` (m²), `deflection_factor`
/// and `optical_lever_factor`), `mean_square_deflection` (m², over the model's modes), `psd`
/// (`frequency` Hz, `deflection` and `apparent_deflection` m²/Hz), `units`, `method` and
/// `warnings`.
pub(crate) fn document(r: &ThermalRequest, s: &ThermalSpectrum) -> Value {
    let mut warnings = crate::request::limits::temperature_warnings(r.temperature);
    if !s.reads_slope {
        warnings.push(warning!(
            "thermal.no-beam",
            "Nothing, for a point mass or eigenmodes; a beam model gives the optical \
                 lever's own correction factors.",
            "the model has no beam (point mass or eigenmodes): the optical lever's apparent \
             deflection is the deflection, its correction factors those of the deflection"
        ));
    }
    json!({
        "temperature": s.temperature,
        "spring_constant": s.spring_constant,
        "spot": s.spot,
        "modes": s.modes,
        "mean_square_deflection": s.mean_square_deflection,
        "psd": {"frequency": s.frequency, "deflection": s.deflection, "apparent_deflection": s.apparent_deflection},
        "units": {"temperature": "K", "spring_constant": "N/m", "frequency": "Hz",
                  "effective_spring_constant": "N/m", "mean_square_deflection": "m^2",
                  "mean_square_apparent_deflection": "m^2", "deflection": "m^2/Hz",
                  "apparent_deflection": "m^2/Hz", "spot": "1"},
        "method": "the fluctuation–dissipation theorem on the free lever's dynamic compliance: \
                   S(f) = (4 k_B T/ω) |Im h(ω)|, h = cᵀ(K − ω²M + iωC)⁻¹c over every Galerkin mode \
                   (the tip mass, the medium's added mass and damping per mode); each mode's share \
                   k_B T (cᵀx_k)²/ω_k² by equipartition; the optical lever reads the slope at the \
                   spot times the static end-load factor 2/(3ξ(2 − ξ)) (Butt & Jaschke 1995; \
                   crate::analysis::thermal)",
        "warnings": warnings,
    })
}
