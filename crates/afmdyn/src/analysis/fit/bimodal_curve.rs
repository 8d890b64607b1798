//! The dynamic fit's model of a measured bimodal AM curve (issue 62 §1, "the bimodal
//! channels"): under a probe whose drive has a second component at a commensurate ratio
//! ([`crate::params::Params::drive_components`]), the first harmonic's A₁, φ₁ and the second
//! component's A₂ (m), φ₂ (deg) against the piezo position z (m), as the stepped approach the
//! instrument did (as [`super::am_curve`]: each row's orbit continued from the previous one).
//! A₂ and φ₂ are the harmonic of the tip deflection at the component's frequency over the
//! drive's common period, with their exact sensitivities from a second pair of Fourier
//! integrals of the extended flow ([`super::sensitivity::orbit_sensitivity`]); the
//! parameters map onto the model's as in [`super::am_curve`].
//!
//! The model's values are, for the channels fitted, the rows' A₁ g₀, then φ₁, A₂ g₀, φ₂ (m and
//! deg); rows off a stable period-1 orbit (of the common period) keep the stepped sweep's
//! observables without a Jacobian row, and the warnings say so, as at folds and grazing.

use super::am_curve::CheckedModel;
use super::am_curve::{
    first_sweep_cancellable, gaps, scaled, AmParam, AmProbe, SENSITIVITY_TOLERANCE,
};
use super::sensitivity::orbit_sensitivity;
use crate::analysis::stepped::SteppedSpec;
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::SweepParam;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// The model of a measured bimodal curve (module docs).
#[derive(Debug)]
pub struct BimodalCurveModel {
    /// The probe (its drive with a second component).
    pub probe: AmProbe,
    /// The piezo positions z (m) of the rows, in the order the instrument stepped.
    pub z: Vec<f64>,
    /// Which of (A₁, φ₁, A₂, φ₂) are fitted, in that order of the values.
    pub channels: [bool; 4],
    /// The model's parameters, in the fit's order.
    pub params: Vec<AmParam>,
    /// The stepped sweep's settings (its values are overwritten by the rows').
    pub spec: SteppedSpec,
    /// The adaptive integrator's tolerance of the sensitivities.
    pub tolerance: f64,
    warnings: Mutex<Vec<String>>,
}

impl BimodalCurveModel {
    /// A model of the rows `z` (m) under `probe`, with parameters `params` and the channels
    /// (A₁, φ₁, A₂, φ₂).
    pub fn new(probe: AmProbe, z: Vec<f64>, channels: [bool; 4], params: Vec<AmParam>) -> Self {
        let mut spec = SteppedSpec::new(probe.params, SweepParam::Alpha5, Vec::new());
        spec.branches = false;
        BimodalCurveModel {
            probe,
            z,
            channels,
            params,
            spec,
            tolerance: SENSITIVITY_TOLERANCE,
            warnings: Mutex::new(Vec::new()),
        }
    }

    /// The last evaluation's warnings (folds, grazing, rows off a period-1 orbit).
    pub fn warnings(&self) -> Vec<String> {
        self.warnings.lock().map(|w| w.clone()).unwrap_or_default()
    }
}

impl CheckedModel for BimodalCurveModel {
    fn rows(&self) -> usize {
        self.z.len() * self.channels.iter().filter(|c| **c).count()
    }
    fn kept(&self) -> &Mutex<Vec<String>> {
        &self.warnings
    }
    /// Stops at the next row of the curve, or of its sensitivities, once `cancel` is set.
    fn evaluate_checked(
        &self,
        p: &[f64],
        values: &mut [f64],
        mut jacobian: Option<&mut [f64]>,
        cancel: &AtomicBool,
    ) -> Result<Vec<String>, SimError> {
        if !self.probe.params.is_multifrequency() {
            return Err(SimError::out_of_range(
                "drive",
                "one frequency",
                "the bimodal channels need a probe whose drive has a second component",
            ));
        }
        if self.params.contains(&AmParam::QualityFactor)
            && self.probe.params.components().count() > 1
        {
            // the chain follows one further component's force (F̃₁ = A₀₁/(g₀|H₁|))
            return Err(SimError::out_of_range(
                "fit",
                AmParam::QualityFactor.name(),
                "Q is fitted under a drive of at most two components",
            ));
        }
        let (q, z_offset, chain) = scaled(&self.probe, &self.params, p);
        let g0 = self.probe.length_m;
        let alpha5 = gaps(&self.probe, &q, &self.z, z_offset);
        let mut spec = self.spec.clone();
        spec.base = q;
        spec.values = alpha5.clone();
        let first = first_sweep_cancellable(&spec, cancel)?;
        let orbit_params = chain.orbit_params();
        let m = self.z.len();
        let n = self.params.len();
        // each fitted channel's first value
        let mut offset = [0usize; 4];
        let mut next = 0;
        for (c, on) in self.channels.iter().enumerate() {
            offset[c] = next;
            if *on {
                next += m;
            }
        }
        let deg = 180.0 / std::f64::consts::PI;
        let scale = [g0, deg, g0, deg];
        let mut warnings = Vec::new();
        let mut off = 0;
        if let Some(j) = jacobian.as_deref_mut() {
            j.fill(0.0);
        }
        for (i, point) in first.iter().enumerate() {
            let o = &point.observables;
            let second = o.components.get(1);
            let mut v = [
                o.amplitude,
                o.phase,
                second.map_or(f64::NAN, |c| c.amplitude),
                second.map_or(f64::NAN, |c| c.phase),
            ];
            let mut d = vec![vec![0.0; n]; 4];
            let on_orbit = point.period == Some(1) && point.stable;
            if jacobian.is_some() && on_orbit {
                if cancel.load(Ordering::Relaxed) {
                    return Err(SimError::Cancelled);
                }
                let model = CantileverModel::new(&q.with(SweepParam::Alpha5, alpha5[i]))?;
                let s = orbit_sensitivity(
                    &model,
                    self.tolerance,
                    &point.state,
                    &orbit_params,
                    None,
                    Some(1),
                )?;
                for w in &s.warnings {
                    warnings.push(format!("row {} (z = {:.4e} m): {w}", i + 1, self.z[i]));
                }
                let two = s.component.as_ref().ok_or(SimError::NoConvergence {
                    what: "the second component's harmonic",
                    iterations: 0,
                    residual: f64::NAN,
                })?;
                v = [s.amplitude, s.phase, two.amplitude, two.phase];
                // (gap, α4, H̃, α6) → (E_s, H, z_offset, R, c), as the AM model maps them
                let map = |dd: &[f64]| -> Vec<f64> {
                    let si = |a: &AmParam| chain.to_si(&orbit_params, dd, *a);
                    self.params.iter().map(si).collect()
                };
                d = vec![
                    map(&s.d_amplitude),
                    map(&s.d_phase),
                    map(&two.d_amplitude),
                    map(&two.d_phase),
                ];
            } else if !on_orbit {
                off += 1;
            }
            for c in 0..4 {
                if !self.channels[c] {
                    continue;
                }
                let row = offset[c] + i;
                values[row] = v[c] * scale[c];
                if let Some(j) = jacobian.as_deref_mut() {
                    for k in 0..n {
                        j[row * n + k] = d[c][k] * scale[c];
                    }
                }
            }
        }
        if off > 0 {
            warnings.push(format!(
                "{off} row(s) not on a stable period-1 orbit: their model values are the stepped \
                 sweep's, without sensitivities"
            ));
        }
        Ok(warnings)
    }
}
