//! The dynamic fit's model of a measured frequency-modulation curve (issue 62 §1, §3: where
//! the first-order relation breaks, Δf against the full dynamic model): the frequency shift Δf
//! (Hz) against the piezo position z (m), as the FM loop's steady state at each row
//! ([`crate::analysis::fm`]: an ideal PLL and amplitude controller; the orbit's drive Ω and
//! excitation α2 fixed by the loop conditions g(Ω, α2) = (A₁/A − 1, φ₁ − φ_set) = 0), followed
//! along the rows as `afmdyn fm` follows its curve, at the amplitude setpoint A = the probe's
//! free amplitude A₀ (1 g₀, `afmdyn fm`'s default), tracking mode 1. Δf = (Ω − ω₁)·f_scale,
//! ω₁ the free lever's resonance, as `afmdyn fm` reports it.
//!
//! # Sensitivities
//! By the implicit function theorem on the loop conditions at fixed model parameters p,
//! d(Ω, α2)/dp = −[∂g/∂(Ω, α2)]⁻¹ ∂g/∂p, with ∂g/∂p = (∂A₁/∂p / A, ∂φ₁/∂p) the orbit's
//! sensitivities at a fixed drive ([`super::sensitivity`]: the gap α5, α4, H̃) and
//! ∂g/∂(Ω, α2) from the same extended flow ([`OrbitParam::DriveFrequency`]: time rescaled to
//! a fixed phase; [`OrbitParam::DriveAmplitude`]: a column of the forcing), so that
//! dΔf/dp = f_scale dΩ/dp. The reference ω₁, the setpoint A and the lag φ_set are those of the
//! free lever, which E, H, R, c and z_offset do not move. The SI parameters map onto
//! (α5, α4, H̃, α6) as in [`super::am_curve`]. The free amplitude A₀ (`drive.free_amplitude`)
//! is the loop's amplitude setpoint A = A₀/g₀, so ∂g/∂A₀ = (−A₁/A² · 1/g₀, 0) at fixed
//! (Ω, α2); the lever's Q₁ is refused (the loop holds the phase at resonance: Δf alone does
//! not constrain Q₁, which shows in the drive the loop needs).
//!
//! # Where it breaks
//! A fold of the FM curve (det ∂g/∂(Ω, α2) = 0, [`crate::analysis::fm::FmCurve::folds`]), a
//! fold or grazing of the orbit ([`super::sensitivity::SensitivityWarning`]) and rows the loop
//! does not reach (the curve ends; those rows keep the last Δf reached, without a Jacobian row)
//! are reported in [`FmCurveModel::warnings`].

use super::am_curve::CheckedModel;
use super::am_curve::{gaps, scaled, AmParam, AmProbe, SENSITIVITY_TOLERANCE};
use super::sensitivity::{orbit_sensitivity, OrbitParam, SensitivityWarning};
use crate::analysis::fm::{fm_curve_cancellable, FmCurve, FmSpec, DEFAULT_LOOP_TOLERANCE};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::SweepParam;
use nalgebra::{Matrix2, Vector2};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// The model of a measured Δf curve (module docs).
#[derive(Debug)]
pub(crate) struct FmCurveModel {
    /// The probe (its free amplitude A₀ = 1 g₀ the amplitude setpoint).
    pub probe: AmProbe,
    /// The piezo positions z (m) of the rows, in the order the instrument stepped.
    pub z: Vec<f64>,
    /// The model's parameters, in the fit's order.
    pub params: Vec<AmParam>,
    /// Hz per unit Ω of the probe's scales.
    pub hz_per_omega: f64,
    /// The amplitude setpoint A (units of g₀; 1, the probe's A₀).
    pub amplitude: f64,
    /// The loop conditions' tolerance ([`FmSpec::tolerance`]).
    pub loop_tolerance: f64,
    /// The adaptive integrator's tolerance of the sensitivities.
    pub tolerance: f64,
    /// The last evaluation's warnings.
    warnings: Mutex<Vec<String>>,
}

impl FmCurveModel {
    /// A model of the rows `z` (m) under `probe` (whose scales give `hz_per_omega`), with
    /// parameters `params`; setpoint A₀, the loop to `DEFAULT_LOOP_TOLERANCE`, the
    /// sensitivities to `SENSITIVITY_TOLERANCE`.
    pub(crate) fn new(
        probe: AmProbe,
        z: Vec<f64>,
        params: Vec<AmParam>,
        hz_per_omega: f64,
    ) -> Self {
        FmCurveModel {
            probe,
            z,
            params,
            hz_per_omega,
            amplitude: 1.0,
            loop_tolerance: DEFAULT_LOOP_TOLERANCE,
            tolerance: SENSITIVITY_TOLERANCE,
            warnings: Mutex::new(Vec::new()),
        }
    }

    /// The last evaluation's warnings (folds, grazing, rows not reached).
    pub(crate) fn warnings(&self) -> Vec<String> {
        self.warnings.lock().map(|w| w.clone()).unwrap_or_default()
    }

    /// Row i (0-based) as the warnings name it, with its piezo position.
    fn row(&self, i: usize) -> String {
        format!("row {} (z = {:.4e} m)", i + 1, self.z[i])
    }

    /// The warnings of the FM curve `curve` of the rows: its folds, and the rows from the first
    /// one it did not reach.
    fn curve_warnings(&self, curve: &FmCurve) -> Vec<String> {
        let mut warnings = Vec::new();
        for f in &curve.folds {
            warnings.push(warning!(
                "fit.fm-fold",
                "Leave the rows near the fold out of the fit (range), or take the \
                 intervals from the profile likelihood (profiles).",
                "{}: a fold of the FM curve (det ∂(A₁, φ₁)/∂(Ω, α2) changes sign before the \
                 next row); the sensitivities are unreliable there",
                self.row(f.index)
            ));
        }
        let reached = curve.points.len();
        if let Some(u) = &curve.unreached {
            warnings.push(warning!(
                "fit.fm-unreached",
                "Fit the rows before that distance only (range), or check the probe's \
                 free amplitude and the sample's law there.",
                "{}: the FM steady state was not found ({}); the {} row(s) from there keep the \
                 last frequency shift reached, without sensitivities",
                self.row(reached),
                u.reason,
                self.z.len() - reached
            ));
        }
        warnings
    }
}

impl CheckedModel for FmCurveModel {
    fn rows(&self) -> usize {
        self.z.len()
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
        if self.params.contains(&AmParam::QualityFactor) {
            return Err(SimError::out_of_range(
                "fit",
                AmParam::QualityFactor.name(),
                "not on an FM curve: the frequency shift does not constrain Q (the loop holds \
                 the phase at resonance)",
            ));
        }
        let (q, z_offset, chain) = scaled(&self.probe, &self.params, p);
        let alpha5 = gaps(&self.probe, &q, &self.z, z_offset);
        // the amplitude setpoint: the free amplitude A₀ (the probe's, or the one fitted)
        let g0 = self.probe.length_m;
        let a0_at = self
            .params
            .iter()
            .position(|x| *x == AmParam::FreeAmplitude);
        let setpoint_per_a0 = self.amplitude / g0;
        let a = a0_at.map_or(self.amplitude, |j| setpoint_per_a0 * p[j]);
        let mut spec = FmSpec::new(q, alpha5, a);
        spec.tolerance = self.loop_tolerance;
        let curve = fm_curve_cancellable(&spec, cancel)?;
        let hz = self.hz_per_omega;
        // the loop solves for α2 and Ω: the chain's own drive terms (A₀'s through α2) are the
        // setpoint's here
        let mut orbit_params: Vec<OrbitParam> = chain
            .orbit_params()
            .into_iter()
            .filter(|o| !matches!(o, OrbitParam::DriveAmplitude | OrbitParam::DriveFrequency))
            .collect();
        let k = orbit_params.len();
        orbit_params.extend([OrbitParam::DriveFrequency, OrbitParam::DriveAmplitude]);
        let n = self.params.len();
        let mut warnings = self.curve_warnings(&curve);
        let row = |i: usize| self.row(i);
        let omega_ref = curve.reference.omega;
        if let Some(j) = jacobian.as_deref_mut() {
            j.fill(0.0);
        }
        let mut last = 0.0;
        for i in 0..self.z.len() {
            let Some(point) = curve.points.get(i) else {
                values[i] = last;
                continue;
            };
            last = (point.omega - omega_ref) * hz;
            values[i] = last;
            let Some(j) = jacobian.as_deref_mut() else {
                continue;
            };
            if cancel.load(Ordering::Relaxed) {
                return Err(SimError::Cancelled);
            }
            let at = q
                .with(SweepParam::Alpha5, point.alpha5)
                .with(SweepParam::Omega, point.omega)
                .with(SweepParam::Alpha2, point.alpha2);
            let model = CantileverModel::new(&at)?;
            let s = orbit_sensitivity(
                &model,
                self.tolerance,
                &point.state,
                &orbit_params,
                None,
                None,
            )?;
            // the orbit's own near-fold measure is not the FM curve's: locked at the lever's
            // resonance, I − M has multipliers within ~π/Q of 1 by construction (the
            // oscillation's amplitude and phase), the very directions the loop conditions fix;
            // the curve's folds are those of ∂g/∂(Ω, α2) (above and below)
            for w in &s.warnings {
                if matches!(w, SensitivityWarning::Grazing { .. }) {
                    warnings.push(format!("{}: {w}", row(i)));
                }
            }
            // ∂g/∂(Ω, α2) and ∂g/∂p_m for g = (A₁/A − 1, φ₁ − φ_set)
            let g_x = Matrix2::new(
                s.d_amplitude[k] / a,
                s.d_amplitude[k + 1] / a,
                s.d_phase[k],
                s.d_phase[k + 1],
            );
            let Some(inv) = g_x.try_inverse() else {
                warnings.push(warning!(
                    "fit.fm-singular",
                    "Leave that row out of the fit (range), or take the intervals from \
                     the profile likelihood (profiles).",
                    "{}: ∂(A₁, φ₁)/∂(Ω, α2) is singular (a fold of the FM curve): no \
                     sensitivities",
                    row(i)
                ));
                continue;
            };
            // dΩ/dp_m = first row of −G⁻¹ ∂g/∂p_m, for (gap, α4, H̃, α6)
            let d_omega: Vec<f64> = (0..k)
                .map(|m| -(inv * Vector2::new(s.d_amplitude[m] / a, s.d_phase[m]))[0])
                .collect();
            // (gap, α4, H̃, α6) → (E_s, H, z_offset, R, c), as the AM model maps them
            for (c, param) in self.params.iter().enumerate() {
                j[i * n + c] = chain.to_si(&orbit_params[..k], &d_omega, *param) * hz;
            }
            // A₀ moves the setpoint A = A₀/g₀: ∂g/∂A₀ = (−A₁/A² · ∂A/∂A₀, 0)
            if let Some(c) = a0_at {
                let dg = -s.amplitude / (a * a) * setpoint_per_a0;
                j[i * n + c] = -(inv * Vector2::new(dg, 0.0))[0] * hz;
            }
        }
        Ok(warnings)
    }
}
