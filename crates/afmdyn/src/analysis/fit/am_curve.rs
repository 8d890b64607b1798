//! The dynamic fit's model (issue 62 §1): a measured amplitude-modulation curve — the first
//! harmonic's amplitude A (m) and phase φ (deg) against the piezo position z (m) — as the
//! stepped approach the instrument did ([`crate::analysis::stepped`]: each point's periodic
//! orbit continued from the previous one, following its branch through a bistable range and
//! jumping where it ends), with the exact sensitivities of each point's orbit
//! ([`super::sensitivity`]) as the Jacobian.
//!
//! # Parameters (SI, probe names)
//! * `sample.youngs_modulus` E_s (Pa): the Hertz group α4 ∝ E*, 1/E* = (1 − ν_t²)/E_t +
//!   (1 − ν_s²)/E_s (Johnson, *Contact Mechanics*, 1985, eq. 4.22), so
//!   ∂α4/∂E_s = α4 E* (1 − ν_s²)/E_s²;
//! * `sample.hamaker` H (J), DMT's: H̃ ∝ H, ∂H̃/∂H = H̃/H;
//! * `tip.radius` R (m): α4 ∝ √R (Hertz's paraboloid) and H̃ ∝ R (the sphere's van der Waals
//!   force, −HR/(6d²)), so ∂α4/∂R = α4/(2R), ∂H̃/∂R = H̃/R;
//! * `sample.damping` c (N s/m), the Hertz law's damper (F_c = α4 δ^{3/2} + α6 δ̇,
//!   [`crate::contact::HertzLaw`]): α6 = c g₀/(t_s F_s)
//!   (`crate::contact::SampleSi::damper_alpha6`), ∂α6/∂c = g₀/(t_s F_s) ([`AmProbe::damping_unit`]), independent of R (a dashpot, not
//!   a contact-area law);
//! * `sample.viscosity` η (Pa s), DMT's Kelvin–Voigt term α6 √δ δ̇ (JKR's α6 q² δ̇):
//!   α6 = η √(R g₀) g₀/(t_s F_s)
//!   (`AmProbe::viscosity_unit`), so ∂α6/∂η = α6/η and R's chain gains ∂α6/∂R = α6/(2R);
//! * `cantilever.quality_factor` Q₁ and `drive.free_amplitude` A₀ (m): through the lever's
//!   damping α3 ∝ 1/Q₁ and the drive α2, which holds the free amplitude A₀ the instrument set
//!   (`lever_and_drive`; the orbit's columns [`OrbitParam::LeverDamping`] and
//!   [`OrbitParam::DriveAmplitude`]); g₀ stays the probe's A₀;
//! * `z_offset` (m): the rest distance of row i is z_c = z_i + z_offset (the piezo's zero is not
//!   the sample's), α5 = z_c/g₀ − ã_offset ([`crate::params::Params::alpha5_for_rest_distance`]),
//!   ∂α5/∂z_offset = 1/g₀.
//! * `sample.adhesion_energy` W (J/m²), JKR's work of adhesion: the adhesion group
//!   P̃ = πWR/F_s (Johnson, Kendall & Roberts 1971; [`crate::contact::Jkr`]) is linear in W and
//!   in R, so ∂P̃/∂W = P̃/W, and R's chain gains ∂P̃/∂R = P̃/R beside α4's (E moves α4 alone).
//!   The probe's W is [`AmProbe::adhesion_energy`].
//!
//! The model's values are the amplitudes A g₀ (m) of the rows, then their phases φ (deg), for
//! the channels fitted; a row whose point is not a stable period-1 orbit keeps the stepped
//! sweep's observables with a zero Jacobian row, and says so in [`AmCurveModel::warnings`], as
//! a fold or a grazing orbit does (where the sensitivities are not to be trusted).
//!
//! An evaluation is a stepped approach of every row (and, with the Jacobian, an orbit's
//! sensitivities per row): [`CurveModel::evaluate_cancellable`] checks the run's cancel flag
//! between the rows and stops there, its values NaN.

use super::sensitivity::{orbit_sensitivity, OrbitParam};
use super::CurveModel;
use crate::analysis::stepped::{check_values, sweep_points, CurvePoint, SteppedSpec};
use crate::contact::{reduced_modulus, ContactLaw};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// `z_offset` (m).
pub(crate) const Z_OFFSET: &str = "z_offset";
/// `sample.youngs_modulus` (Pa).
pub(crate) const YOUNGS_MODULUS: &str = "sample.youngs_modulus";
/// `sample.hamaker` (J).
pub(crate) const HAMAKER: &str = "sample.hamaker";
/// `tip.radius` (m).
pub(crate) const RADIUS: &str = "tip.radius";
/// `sample.damping` (N s/m), the Hertz law's damper.
pub(crate) const DAMPING: &str = "sample.damping";
/// `sample.viscosity` (Pa s), the Kelvin–Voigt η of DMT and JKR.
pub(crate) const VISCOSITY: &str = "sample.viscosity";
/// `cantilever.quality_factor` (1), the lever's Q₁.
pub(crate) const QUALITY_FACTOR: &str = "cantilever.quality_factor";
/// `drive.free_amplitude` (m), the free amplitude A₀ the instrument set.
pub(crate) const FREE_AMPLITUDE: &str = "drive.free_amplitude";
/// `sample.adhesion_energy` (J/m²), JKR's work of adhesion.
pub(crate) const ADHESION_ENERGY: &str = "sample.adhesion_energy";

/// The adaptive integrator's tolerance of the fit's Jacobian: the sensitivities to ~1e-7
/// relative, far inside what Levenberg–Marquardt and the covariance need (the values are the
/// stepped sweep's, at its own tolerance).
pub(crate) const SENSITIVITY_TOLERANCE: f64 = 1e-9;

/// A parameter of the dynamic fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum AmParam {
    /// `sample.youngs_modulus`.
    YoungsModulus,
    /// `sample.hamaker` (DMT).
    Hamaker,
    /// `z_offset`.
    ZOffset,
    /// `tip.radius`.
    TipRadius,
    /// `sample.damping` (Hertz).
    Damping,
    /// `cantilever.quality_factor` (AM and bimodal curves; not FM).
    QualityFactor,
    /// `drive.free_amplitude`.
    FreeAmplitude,
    /// `sample.adhesion_energy` (JKR).
    AdhesionEnergy,
    /// `sample.viscosity` (DMT's and JKR's Kelvin–Voigt η).
    Viscosity,
}

impl AmParam {
    /// The parameter of a probe name; `None` for another.
    pub(crate) fn from_name(name: &str) -> Option<AmParam> {
        match name {
            YOUNGS_MODULUS => Some(AmParam::YoungsModulus),
            HAMAKER => Some(AmParam::Hamaker),
            Z_OFFSET => Some(AmParam::ZOffset),
            RADIUS => Some(AmParam::TipRadius),
            DAMPING => Some(AmParam::Damping),
            QUALITY_FACTOR => Some(AmParam::QualityFactor),
            FREE_AMPLITUDE => Some(AmParam::FreeAmplitude),
            ADHESION_ENERGY => Some(AmParam::AdhesionEnergy),
            VISCOSITY => Some(AmParam::Viscosity),
            _ => None,
        }
    }
    /// Its probe name.
    pub(crate) fn name(self) -> &'static str {
        match self {
            AmParam::YoungsModulus => YOUNGS_MODULUS,
            AmParam::Hamaker => HAMAKER,
            AmParam::ZOffset => Z_OFFSET,
            AmParam::TipRadius => RADIUS,
            AmParam::Damping => DAMPING,
            AmParam::QualityFactor => QUALITY_FACTOR,
            AmParam::FreeAmplitude => FREE_AMPLITUDE,
            AmParam::AdhesionEnergy => ADHESION_ENERGY,
            AmParam::Viscosity => VISCOSITY,
        }
    }
}

/// The chain rule from the model's groups to the SI parameters (module docs): the terms
/// ∂o/∂p of each fitted SI parameter p through each orbit parameter o it moves, so that
/// ∂y/∂p = Σ_o ∂y/∂o · ∂o/∂p. A parameter adds its terms in [`scaled`]; the orbit parameters
/// a model differentiates are those the terms name ([`Chain::orbit_params`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Chain {
    /// (p, o, ∂o/∂p), in the order added.
    pub terms: Vec<(AmParam, OrbitParam, f64)>,
}

impl Chain {
    /// Add the term ∂o/∂p = `factor`.
    pub(crate) fn push(&mut self, param: AmParam, orbit: OrbitParam, factor: f64) {
        self.terms.push((param, orbit, factor));
    }
    /// The orbit parameters the terms name, each once, in the order first named.
    pub(crate) fn orbit_params(&self) -> Vec<OrbitParam> {
        let mut v: Vec<OrbitParam> = Vec::new();
        for (_, o, _) in &self.terms {
            if !v.contains(o) {
                v.push(*o);
            }
        }
        v
    }
    /// ∂y/∂`param` from the orbit's sensitivities `d` (one per `orbit`, in its order): the sum
    /// of the terms of `param`; an orbit parameter not in `orbit` counts 0.
    pub(crate) fn to_si(&self, orbit: &[OrbitParam], d: &[f64], param: AmParam) -> f64 {
        let at = |o: OrbitParam| orbit.iter().position(|x| *x == o).map_or(0.0, |i| d[i]);
        self.terms
            .iter()
            .filter(|(p, _, _)| *p == param)
            .map(|(_, o, f)| at(*o) * f)
            .sum()
    }
}

/// The probe's SI values the model scales from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AmProbe {
    /// The probe's dimensionless parameters (α4 at `youngs_modulus`, H̃ at `hamaker`).
    pub params: Params,
    /// g₀ (m per unit length).
    pub length_m: f64,
    /// The probe's E_s (Pa).
    pub youngs_modulus: f64,
    /// ν_s.
    pub poisson_ratio: f64,
    /// E_t (Pa), ν_t.
    pub tip: (f64, f64),
    /// The probe's H (J; 0 for Hertz).
    pub hamaker: f64,
    /// The probe's R (m).
    pub radius: f64,
    /// α6 per N s/m of the Hertz damper, g₀/(t_s F_s) (the probe's scales; the probe's
    /// `[sample] damping` is `params.alpha6 / damping_unit`).
    pub damping_unit: f64,
    /// The lever's Q₁ that gave `params.alpha3` (the probe's `[cantilever] quality_factor`).
    pub quality_factor: f64,
}

impl AmProbe {
    /// α6 per Pa s of DMT's (and JKR's) Kelvin–Voigt term at the tip radius `radius` (m):
    /// √(R g₀) g₀/(t_s F_s) ([`crate::contact::SampleSi::kelvin_voigt_alpha6`]: the damper
    /// η a δ̇ with the contact radius a = √(Rδ)).
    pub(crate) fn viscosity_unit(&self, radius: f64) -> f64 {
        self.damping_unit * (radius * self.length_m).sqrt()
    }

    /// The probe's viscosity η (Pa s) of DMT's or JKR's Kelvin–Voigt term, α6 over
    /// `AmProbe::viscosity_unit`; 0 under another law.
    pub(crate) fn viscosity(&self) -> f64 {
        match self.params.contact_law {
            ContactLaw::Dmt { .. } | ContactLaw::Jkr { .. } if self.radius > 0.0 => {
                self.params.alpha6 / self.viscosity_unit(self.radius)
            }
            _ => 0.0,
        }
    }

    /// The probe's work of adhesion W (J/m²) under JKR, from its groups: P̃ = πWR/F_s with
    /// the force scale of its Hertz group, F_s = (4/3)E*√R g₀^{3/2}/α4
    /// (`crate::contact::SampleSi::hertz_alpha4`), so W = P̃ (4/3) E* g₀^{3/2}/(π α4 √R)
    /// (the probe's E*, R, g₀). 0 under another law (or α4 = 0).
    pub(crate) fn adhesion_energy(&self) -> f64 {
        let ContactLaw::Jkr { adhesion } = self.params.contact_law else {
            return 0.0;
        };
        let alpha4 = self.params.alpha4;
        if !(alpha4 > 0.0 && self.radius > 0.0) {
            return 0.0;
        }
        let e_star = reduced_modulus(
            self.tip.0,
            self.tip.1,
            self.youngs_modulus,
            self.poisson_ratio,
        );
        adhesion * 4.0 / 3.0 * e_star * self.length_m.powf(1.5)
            / (std::f64::consts::PI * alpha4 * self.radius.sqrt())
    }
}

/// The channels of a [`SteppedCurveModel`]: the AM curve's (amplitude, phase), the bimodal
/// curve's (A₁, φ₁, A₂, φ₂) ([`super::bimodal_curve`]).
pub(crate) trait Channels: Copy + std::fmt::Debug {
    /// The further drive component whose harmonic is A₂, φ₂ (`None`: the first harmonic alone).
    const COMPONENT: Option<usize>;
    /// Which of (A₁, φ₁, A₂, φ₂) are the values, in that order.
    fn fitted(&self) -> [bool; 4];
    /// Refuse a probe or parameters the channels cannot be evaluated under (none for the AM
    /// curve's).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming what is refused.
    fn check(probe: &AmProbe, params: &[AmParam]) -> Result<(), SimError> {
        let _ = (probe, params);
        Ok(())
    }
}

/// The amplitude and the phase: the values are the amplitudes, then the phases.
impl Channels for (bool, bool) {
    const COMPONENT: Option<usize> = None;
    fn fitted(&self) -> [bool; 4] {
        [self.0, self.1, false, false]
    }
}

/// The model of a measured curve as the stepped approach of its rows (module docs): the AM
/// curve's ([`AmCurveModel`]) or the bimodal channels'
/// ([`super::bimodal_curve::BimodalCurveModel`]).
#[derive(Debug)]
pub(crate) struct SteppedCurveModel<C> {
    /// The probe (for the bimodal channels, its drive with a second component).
    pub probe: AmProbe,
    /// The piezo positions z (m) of the rows, in the order the instrument stepped.
    pub z: Vec<f64>,
    /// Which channels are fitted ([`Channels::fitted`]), in that order of the values.
    pub channels: C,
    /// The model's parameters, in the fit's order.
    pub params: Vec<AmParam>,
    /// The stepped sweep's settings (its values are overwritten by the rows').
    pub spec: SteppedSpec,
    /// The adaptive integrator's tolerance of the sensitivities (default
    /// `SENSITIVITY_TOLERANCE`).
    pub tolerance: f64,
    /// The last evaluation's warnings.
    warnings: Mutex<Vec<String>>,
}

/// The model of a measured AM curve (module docs).
pub(crate) type AmCurveModel = SteppedCurveModel<(bool, bool)>;

impl<C: Channels> SteppedCurveModel<C> {
    /// A model of the rows `z` (m) under `probe`, with parameters `params` and the channels
    /// (amplitude, phase; or A₁, φ₁, A₂, φ₂).
    pub(crate) fn new(probe: AmProbe, z: Vec<f64>, channels: C, params: Vec<AmParam>) -> Self {
        let mut spec = SteppedSpec::new(probe.params, SweepParam::Alpha5, Vec::new());
        spec.branches = false;
        let tolerance = SENSITIVITY_TOLERANCE;
        SteppedCurveModel {
            probe,
            z,
            channels,
            params,
            spec,
            tolerance,
            warnings: Mutex::new(Vec::new()),
        }
    }

    /// The last evaluation's warnings (folds, grazing, rows off a period-1 orbit).
    pub(crate) fn warnings(&self) -> Vec<String> {
        self.warnings.lock().map(|w| w.clone()).unwrap_or_default()
    }
}

/// The gaps α5 of the rows at the piezo positions `z` (m), shifted by `z_offset` (m), under the
/// parameters `q` of `probe` (module docs: α5 from the rest distance (z + z_offset)/g₀).
pub(crate) fn gaps(probe: &AmProbe, q: &Params, z: &[f64], z_offset: f64) -> Vec<f64> {
    let g0 = probe.length_m;
    z.iter()
        .map(|z| q.alpha5_for_rest_distance((z + z_offset) / g0))
        .collect()
}

/// The model's parameters of `probe` with `params` at `p` (SI, in the order of `params`; the
/// others at the probe's values), z_offset (m), and the chain rule from the model's groups to
/// the fitted parameters (module docs).
pub(crate) fn scaled(probe: &AmProbe, params: &[AmParam], p: &[f64]) -> (Params, f64, Chain) {
    let pr = probe;
    let get = |a: AmParam, default: f64| {
        params
            .iter()
            .position(|q| *q == a)
            .map_or(default, |j| p[j])
    };
    let fitted = |a: AmParam| params.contains(&a);
    let e = get(AmParam::YoungsModulus, pr.youngs_modulus);
    let h = get(AmParam::Hamaker, pr.hamaker);
    let z_offset = get(AmParam::ZOffset, 0.0);
    let r = get(AmParam::TipRadius, pr.radius);
    let e_star = |e| reduced_modulus(pr.tip.0, pr.tip.1, e, pr.poisson_ratio);
    let mut q = pr.params;
    let mut chain = Chain::default();
    let ratio = e_star(e) / e_star(pr.youngs_modulus) * (r / pr.radius).sqrt();
    q.alpha4 = pr.params.alpha4 * ratio;
    if fitted(AmParam::YoungsModulus) {
        let de = q.alpha4 * e_star(e) * (1.0 - pr.poisson_ratio * pr.poisson_ratio) / (e * e);
        chain.push(AmParam::YoungsModulus, OrbitParam::ContactStiffness, de);
    }
    if fitted(AmParam::TipRadius) {
        chain.push(
            AmParam::TipRadius,
            OrbitParam::ContactStiffness,
            q.alpha4 / (2.0 * r),
        );
    }
    if let ContactLaw::Dmt { hamaker, .. } = &mut q.contact_law {
        if pr.hamaker > 0.0 {
            // H̃ ∝ H R
            let dh = *hamaker * (r / pr.radius) / pr.hamaker;
            *hamaker *= h / pr.hamaker * (r / pr.radius);
            if fitted(AmParam::Hamaker) {
                chain.push(AmParam::Hamaker, OrbitParam::Hamaker, dh);
            }
            if fitted(AmParam::TipRadius) {
                chain.push(AmParam::TipRadius, OrbitParam::Hamaker, *hamaker / r);
            }
        }
    }
    if fitted(AmParam::ZOffset) {
        chain.push(AmParam::ZOffset, OrbitParam::Gap, 1.0 / pr.length_m);
    }
    // α6 = c g₀/(t_s F_s), linear in c (a dashpot: R does not enter it)
    if fitted(AmParam::Damping) {
        q.alpha6 = get(AmParam::Damping, 0.0) * pr.damping_unit;
        chain.push(AmParam::Damping, OrbitParam::Damping, pr.damping_unit);
    }
    // DMT's and JKR's Kelvin–Voigt α6 = η √(R g₀) g₀/(t_s F_s) ∝ η √R
    let kelvin_voigt = matches!(
        q.contact_law,
        ContactLaw::Dmt { .. } | ContactLaw::Jkr { .. }
    );
    if kelvin_voigt && (fitted(AmParam::Viscosity) || fitted(AmParam::TipRadius)) {
        let unit = pr.viscosity_unit(r);
        q.alpha6 = get(AmParam::Viscosity, pr.viscosity()) * unit;
        if fitted(AmParam::Viscosity) {
            chain.push(AmParam::Viscosity, OrbitParam::Damping, unit);
        }
        if fitted(AmParam::TipRadius) && q.alpha6 != 0.0 {
            chain.push(
                AmParam::TipRadius,
                OrbitParam::Damping,
                q.alpha6 / (2.0 * r),
            );
        }
    }
    lever_and_drive(pr, params, p, &mut q, &mut chain);
    // JKR's P̃ = πWR/F_s ∝ W R (module docs)
    if let ContactLaw::Jkr { adhesion } = &mut q.contact_law {
        let w0 = pr.adhesion_energy();
        if w0 > 0.0 {
            let w = get(AmParam::AdhesionEnergy, w0);
            *adhesion *= w / w0 * (r / pr.radius);
            if fitted(AmParam::AdhesionEnergy) {
                chain.push(AmParam::AdhesionEnergy, OrbitParam::Adhesion, *adhesion / w);
            }
            if fitted(AmParam::TipRadius) {
                chain.push(AmParam::TipRadius, OrbitParam::Adhesion, *adhesion / r);
            }
        }
    }
    (q, z_offset, chain)
}

/// The lever's Q₁ and the free amplitude A₀ (module docs): α3 = α3₀ Q₀/Q₁ (α3 ∝ 1/Q₁ at a
/// fixed damping profile, [`crate::eigen::beam_damping_for_q`]), and α2 = (A₀/g₀)/|H₁(α3)|
/// with H₁ the free tip response per unit α2 ([`CantileverModel::free_tip_response`]): the
/// instrument sets A₀ far from the sample, so the drive follows Q₁. Hence ∂α3/∂Q₁ = −α3/Q₁,
/// ∂α2/∂Q₁ = −α2 (d|H₁|/dα3)/|H₁| · ∂α3/∂Q₁
/// ([`CantileverModel::free_tip_response_damping_derivative`]), ∂α2/∂A₀ = α2/A₀. g₀ stays
/// the probe's (its A₀), so the other groups do not move. With neither fitted, q is left as
/// the probe made it; a model that cannot be built leaves α2 NaN (its evaluation then fails).
fn lever_and_drive(pr: &AmProbe, params: &[AmParam], p: &[f64], q: &mut Params, chain: &mut Chain) {
    let at = |a: AmParam| params.iter().position(|x| *x == a).map(|j| p[j]);
    let (q1, a0) = (at(AmParam::QualityFactor), at(AmParam::FreeAmplitude));
    if q1.is_none() && a0.is_none() {
        return;
    }
    let g0 = pr.length_m;
    let a0 = a0.unwrap_or(g0);
    let (mut d_alpha3, mut d_alpha2_d_alpha3, mut d_force_d_alpha3) = (0.0, 0.0, 0.0);
    if let Some(q1) = q1 {
        q.alpha3 = pr.params.alpha3 * pr.quality_factor / q1;
        d_alpha3 = -q.alpha3 / q1;
        let response = CantileverModel::new(&q.with(SweepParam::Alpha2, 1.0))
            .map_err(SimError::from)
            .and_then(|m| m.free_tip_response_damping_derivative());
        match response {
            Ok((h, dh)) => {
                let mag = h.norm();
                q.alpha2 = a0 / g0 / mag;
                d_alpha2_d_alpha3 = -q.alpha2 * (h.conj() * dh).re / (mag * mag);
            }
            Err(_) => q.alpha2 = f64::NAN,
        }
        // a bimodal drive's further component holds its free amplitude A₀₁ = F̃₁|H₁| g₀ too:
        // F̃₁ = F̃₁⁰ |H₁(α3⁰)|/|H₁(α3)|, ∂F̃₁/∂α3 = −F̃₁ (d|H₁|/dα3)/|H₁| (one component)
        if let Some(d) = component_following(pr, q) {
            d_force_d_alpha3 = d;
        }
    } else {
        q.alpha2 = pr.params.alpha2 * a0 / g0;
    }
    if at(AmParam::QualityFactor).is_some() {
        chain.push(AmParam::QualityFactor, OrbitParam::LeverDamping, d_alpha3);
        chain.push(
            AmParam::QualityFactor,
            OrbitParam::DriveAmplitude,
            d_alpha2_d_alpha3 * d_alpha3,
        );
        if q.is_multifrequency() {
            chain.push(
                AmParam::QualityFactor,
                OrbitParam::ComponentForce,
                d_force_d_alpha3 * d_alpha3,
            );
        }
    }
    if at(AmParam::FreeAmplitude).is_some() {
        chain.push(
            AmParam::FreeAmplitude,
            OrbitParam::DriveAmplitude,
            q.alpha2 / a0,
        );
    }
}

/// The first further drive component's force F̃₁ of `q` (its α3 moved from the probe's) set so
/// that its free amplitude stays the probe's, and ∂F̃₁/∂α3 ([`lever_and_drive`]); `None` without
/// a further component. A response that cannot be formed leaves F̃₁ NaN (the evaluation then
/// fails).
fn component_following(pr: &AmProbe, q: &mut Params) -> Option<f64> {
    let c = q.drive_components.iter().flatten().next().copied()?;
    let omega = c.ratio() * q.omega;
    let at = |p: &Params| {
        CantileverModel::new(p)
            .map_err(SimError::from)
            .and_then(|m| m.free_force_response_damping_derivative(omega))
    };
    let (force, derivative) = match (at(&pr.params), at(q)) {
        (Ok((h0, _)), Ok((h, dh))) => {
            let mag = h.norm();
            let force = c.force * h0.norm() / mag;
            (force, Some(-force * (h.conj() * dh).re / (mag * mag)))
        }
        _ => (f64::NAN, None),
    };
    if let Some(slot) = q.drive_components.iter_mut().flatten().next() {
        slot.force = force;
    }
    derivative
}

/// The values of the fitted channels at `p` (A g₀ in m, φ in deg), each channel's rows in turn,
/// and with the Jacobian their sensitivities (rows off a stable period-1 orbit: the stepped
/// sweep's observables, a zero Jacobian row); stops at the next row once `cancel` is set.
impl<C: Channels> CheckedModel for SteppedCurveModel<C> {
    fn rows(&self) -> usize {
        self.z.len() * self.channels.fitted().iter().filter(|c| **c).count()
    }
    fn kept(&self) -> &Mutex<Vec<String>> {
        &self.warnings
    }
    fn evaluate_checked(
        &self,
        p: &[f64],
        values: &mut [f64],
        mut jacobian: Option<&mut [f64]>,
        cancel: &AtomicBool,
    ) -> Result<Vec<String>, SimError> {
        C::check(&self.probe, &self.params)?;
        let (q, z_offset, chain) = scaled(&self.probe, &self.params, p);
        let g0 = self.probe.length_m;
        let alpha5 = gaps(&self.probe, &q, &self.z, z_offset);
        let channels = self.channels.fitted();
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
        for (c, on) in channels.iter().enumerate() {
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
            if cancel.load(Ordering::Relaxed) {
                return Err(SimError::Cancelled);
            }
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
            // the values alone (the residuals) are the sweep's observables; with the Jacobian,
            // those of the sensitivities' Fourier integrals (the same to the integration error)
            if jacobian.is_some() && on_orbit {
                let model = CantileverModel::new(&q.with(SweepParam::Alpha5, alpha5[i]))?;
                let s = orbit_sensitivity(
                    &model,
                    self.tolerance,
                    &point.state,
                    &orbit_params,
                    None,
                    C::COMPONENT,
                )?;
                for w in &s.warnings {
                    warnings.push(format!("row {} (z = {:.4e} m): {w}", i + 1, self.z[i]));
                }
                // (gap, α4, H̃, α6, P̃) → (E_s, H, z_offset, R, c, W)
                let map = |dd: &[f64]| -> Vec<f64> {
                    let si = |a: &AmParam| chain.to_si(&orbit_params, dd, *a);
                    self.params.iter().map(si).collect()
                };
                (v[0], v[1]) = (s.amplitude, s.phase);
                (d[0], d[1]) = (map(&s.d_amplitude), map(&s.d_phase));
                if C::COMPONENT.is_some() {
                    let two = s.component.as_ref().ok_or(SimError::NoConvergence {
                        what: "the second component's harmonic",
                        iterations: 0,
                        residual: f64::NAN,
                    })?;
                    (v[2], v[3]) = (two.amplitude, two.phase);
                    (d[2], d[3]) = (map(&two.d_amplitude), map(&two.d_phase));
                }
            } else if !on_orbit {
                off += 1;
            }
            for c in 0..4 {
                if !channels[c] {
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
            warnings.push(warning!(
                "fit.off-orbit",
                "Leave those rows out of the fit (range), or start nearer the data so \
                 that the model's orbit there is the measured one.",
                "{off} row(s) not on a stable period-1 orbit: their model values are the stepped \
                 sweep's, without sensitivities"
            ));
        }
        Ok(warnings)
    }
}

/// The first sweep of `spec` alone ([`sweep_points`], stopped once its last point is done: the
/// instrument's path through the rows; the sweep back is not run), stopped after the point
/// under way once `stop` is set.
///
/// # Errors
/// As [`sweep_points`]; [`SimError::Cancelled`] when `stop` was set before the last point.
pub(crate) fn first_sweep_cancellable(
    spec: &SteppedSpec,
    stop: &AtomicBool,
) -> Result<Vec<CurvePoint>, SimError> {
    check_values(spec)?;
    let n = spec.values.len();
    let cancel = AtomicBool::new(stop.load(Ordering::Relaxed));
    let points = Mutex::new(Vec::with_capacity(n));
    let sink = |k: usize, p: &CurvePoint| {
        if k < n {
            if let Ok(mut v) = points.lock() {
                v.push(p.clone());
            }
        }
        if k + 1 >= n || stop.load(Ordering::Relaxed) {
            cancel.store(true, Ordering::Relaxed);
        }
    };
    match sweep_points(spec, &[], &cancel, &sink) {
        Ok(_) | Err(SimError::Cancelled) => {}
        Err(e) => return Err(e),
    }
    let points = points.into_inner().unwrap_or_default();
    if points.len() == n && !stop.load(Ordering::Relaxed) {
        Ok(points)
    } else {
        Err(SimError::Cancelled)
    }
}

/// A dynamic model (the AM curve, the bimodal channels, the FM curve): an evaluation row by row
/// that may fail or be cancelled, and the warnings of the last one it finished. Every such
/// model is a [`CurveModel`] through one implementation, which keeps the outcome: a Jacobian
/// evaluation's warnings replace the last ones, a failed evaluation's values are NaN with a
/// warning naming where it failed, a cancelled one's values NaN.
pub(crate) trait CheckedModel {
    /// The number of data points m (rows × channels).
    fn rows(&self) -> usize;
    /// Where the last evaluation's warnings are kept.
    fn kept(&self) -> &Mutex<Vec<String>>;
    /// The values (and the Jacobian, row-major m × n) at `p`, stopping at the next row once
    /// `cancel` is set; the evaluation's warnings.
    ///
    /// # Errors
    /// The model's failure; [`SimError::Cancelled`] once `cancel` is set.
    fn evaluate_checked(
        &self,
        p: &[f64],
        values: &mut [f64],
        jacobian: Option<&mut [f64]>,
        cancel: &AtomicBool,
    ) -> Result<Vec<String>, SimError>;
}

impl<T: CheckedModel> CurveModel for T {
    fn points(&self) -> usize {
        self.rows()
    }
    fn evaluate(&self, p: &[f64], values: &mut [f64], jacobian: Option<&mut [f64]>) {
        self.evaluate_cancellable(p, values, jacobian, &AtomicBool::new(false));
    }
    fn evaluate_cancellable(
        &self,
        p: &[f64],
        values: &mut [f64],
        jacobian: Option<&mut [f64]>,
        cancel: &AtomicBool,
    ) {
        let has_jacobian = jacobian.is_some();
        let outcome = self.evaluate_checked(p, values, jacobian, cancel);
        record(self.kept(), outcome, has_jacobian, values, p);
    }
}

/// One evaluation's outcome, as every dynamic model keeps it (AM, bimodal, FM): a Jacobian
/// evaluation's warnings replace the last ones (a value-only evaluation, a trial step of the
/// minimiser, leaves them); a failed one fills `values` with NaN (the minimiser's refusal) and
/// says where it failed at `p`; a cancelled one fills them with NaN and leaves the warnings as
/// the last finished evaluation's (the run ends).
fn record(
    warnings: &Mutex<Vec<String>>,
    outcome: Result<Vec<String>, SimError>,
    has_jacobian: bool,
    values: &mut [f64],
    p: &[f64],
) {
    let keep = match outcome {
        Ok(w) if has_jacobian => w,
        Ok(_) => return,
        Err(SimError::Cancelled) => {
            values.fill(f64::NAN);
            return;
        }
        Err(e) => {
            values.fill(f64::NAN);
            vec![format!("the model failed at {p:?}: {e}")]
        }
    };
    if let Ok(mut l) = warnings.lock() {
        *l = keep;
    }
}
