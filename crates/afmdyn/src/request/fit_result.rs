//! What the force-curve fit ([`super::fit`]) and the dynamic fit ([`super::fit_dynamic`])
//! share as requests: the data of an AM or FM curve, the fewest rows and the probe's values
//! the fit needs.

use crate::error::SimError;

/// The fewest rows fitted (more than the parameters, for the χ²'s degrees of freedom).
pub(crate) const MIN_FIT_ROWS: usize = 8;

/// The probe's value `v` of `key`, which the fit needs.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `probe` and `key` when the probe lacks it.
pub(crate) fn probe_value(v: Option<f64>, key: &str) -> Result<f64, SimError> {
    v.ok_or_else(|| {
        SimError::out_of_range("probe", key, format!("the fit needs the probe's {key}"))
    })
}

impl AmData {
    /// Its optional columns, by their names in a data file.
    fn optional(&mut self) -> [(&'static str, &mut Option<Vec<f64>>); 10] {
        [
            ("amplitude", &mut self.amplitude),
            ("phase", &mut self.phase),
            ("sigma_amplitude", &mut self.sigma_amplitude),
            ("sigma_phase", &mut self.sigma_phase),
            ("frequency_shift", &mut self.frequency_shift),
            ("sigma_frequency_shift", &mut self.sigma_frequency_shift),
            ("amplitude_2", &mut self.amplitude_2),
            ("phase_2", &mut self.phase_2),
            ("sigma_amplitude_2", &mut self.sigma_amplitude_2),
            ("sigma_phase_2", &mut self.sigma_phase_2),
        ]
    }
    /// Its columns present (z first), by their names in a data file.
    pub(crate) fn named(&self) -> Vec<(&'static str, Vec<f64>)> {
        let mut d = self.clone();
        let optional = d.optional().map(|(n, c)| c.take().map(|c| (n, c)));
        std::iter::once(("z", self.z.clone()))
            .chain(optional.into_iter().flatten())
            .collect()
    }
    /// The rows whose piezo position z lies in `range` [lo, hi] (m), every column kept alike
    /// (`FitRequest::range` on a dynamic curve).
    pub(crate) fn within(mut self, [lo, hi]: [f64; 2]) -> AmData {
        let keep: Vec<bool> = self.z.iter().map(|z| (lo..=hi).contains(z)).collect();
        let rows = |c: &mut Vec<f64>| {
            let mut k = keep.iter();
            c.retain(|_| k.next() == Some(&true));
        };
        rows(&mut self.z);
        self.optional()
            .into_iter()
            .for_each(|(_, c)| c.iter_mut().for_each(rows));
        self
    }
    /// Its columns held against the probe (issue 77 item 4): the piezo positions' span
    /// against an approach's (10 pm to 100 µm), the largest amplitude against the free
    /// amplitude `a0` (10⁻³ to 3 times it), the largest |Δf| against the resonance `f0`
    /// (10⁻⁶ f₀ to half of it).
    pub(crate) fn unit_slips(&self, a0: f64, f0: f64) -> Vec<String> {
        use super::quantity::{largest_magnitude, shift_slip, span, unit_slip, Dim};
        let amplitude = |name, v: &Option<Vec<f64>>| {
            let a = v.as_deref().map_or(0.0, largest_magnitude);
            unit_slip(name, "the largest", a, Dim::Length, (1e-3 * a0, 3.0 * a0))
        };
        [
            unit_slip("z", "the span", span(&self.z), Dim::Length, (1e-11, 1e-4)),
            amplitude("amplitude", &self.amplitude),
            shift_slip(self.frequency_shift.as_deref().unwrap_or(&[]), f0),
        ]
        .into_iter()
        .flatten()
        .collect()
    }
}

/// A measured dynamic curve's columns: an AM curve (amplitude and/or phase) or an FM curve
/// (frequency shift).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AmData {
    /// The piezo positions z (m).
    pub z: Vec<f64>,
    /// The amplitudes (m).
    pub amplitude: Option<Vec<f64>>,
    /// The phases (deg).
    pub phase: Option<Vec<f64>>,
    /// The amplitudes' standard deviations (m).
    pub sigma_amplitude: Option<Vec<f64>>,
    /// The phases' standard deviations (deg).
    pub sigma_phase: Option<Vec<f64>>,
    /// The frequency shifts Δf (Hz) of an FM curve (then the curve is fitted as one, by
    /// [`crate::analysis::fit::fm_curve`]).
    pub frequency_shift: Option<Vec<f64>>,
    /// The frequency shifts' standard deviations (Hz).
    pub sigma_frequency_shift: Option<Vec<f64>>,
    /// The second drive component's amplitudes A₂ (m) of a bimodal curve (then it is fitted
    /// by [`crate::analysis::fit::bimodal_curve`]).
    pub amplitude_2: Option<Vec<f64>>,
    /// The second component's phases φ₂ (deg).
    pub phase_2: Option<Vec<f64>>,
    /// A₂'s standard deviations (m).
    pub sigma_amplitude_2: Option<Vec<f64>>,
    /// φ₂'s standard deviations (deg).
    pub sigma_phase_2: Option<Vec<f64>>,
}
