//! Finite-thickness (bottom-effect) corrections: the force on a layer of thickness h on a rigid
//! substrate, F = F_∞ c, with c a series in the contact's size over h.
//!
//! # Paraboloid and sphere: Dimitriadis et al. 2002
//! Dimitriadis, Horkay, Maresca, Kachar & Chadwick, *Biophys. J.* 82 (2002) 2798, for a sample
//! bonded to the substrate (glued) or not (free to slide):
//!
//! c = 1 − (2α₀/π) χ + (4α₀²/π²) χ² − (8/π³)(α₀³ + (4π²/15) β₀) χ³
//!     + (16α₀/π⁴)(α₀³ + (3π²/5) β₀) χ⁴,  χ = √(Rδ)/h,
//!
//! bonded: α₀ = −(1.2876 − 1.4678ν + 1.3442ν²)/(1 − ν), β₀ = (0.6387 − 1.0277ν +
//! 1.5164ν²)/(1 − ν); non-bonded: α₀ = −0.347(3 − 2ν)/(1 − ν), β₀ = 0.056(5 − 2ν)/(1 − ν),
//! ν the sample's Poisson ratio (the paper's eq. 11 with its α₀ and β₀). At ν = 0.5 the paper
//! prints the series as numbers: non-bonded 1 + 0.884χ + 0.781χ² + 0.386χ³ + 0.0048χ⁴ (eq. 13),
//! which eq. 11 gives in all four; bonded 1 + 1.133χ + 1.283χ² + 0.769χ³ + 0.0975χ⁴ (eq. 12),
//! where eq. 11 gives the same first three and −0.0975 for the fourth. This module follows eq.
//! 11, which holds at every ν and gives both printed series but for that one sign; the two
//! differ by 0.195χ⁴, 0.6 % of the factor at χ = 0.5. The coefficients are those of the paper as transcribed in
//! ViscoIndent (Efremov et al., `yu-efremov/ViscoIndent`, `bottom_effect_correction.py`, whose
//! bonded pair is used there and the non-bonded pair given as the alternative). The series is
//! derived for Hertz's paraboloid; on the exact sphere it multiplies Sneddon's force with the
//! same χ = √(Rδ)/h (the paper's variable), a correction of the same order as the paraboloid's
//! own error where δ is not small against R.
//!
//! # Cone, pyramids and flat punch: Garcia & Garcia 2018
//! Garcia & Garcia, *Biophys. J.* 114 (2018) 2923 ("Determination of the elastic moduli of a
//! single cell cultured on a rigid support by force microscopy"), for a bonded, incompressible
//! layer (ν = 0.5):
//! * cone of half angle θ: c = 1 + 0.721 b + 0.650 b² + 0.491 b³ + 0.225 b⁴, b = δ tan θ/h;
//! * flat cylindrical punch of radius a: c = 1 + 1.133 b + 1.283 b² + 0.598 b³ − 0.291 b⁴,
//!   b = a/h (independent of δ).
//!
//! The coefficients as transcribed in ViscoIndent (as above), which applies them for
//! 0.45 ≤ ν ≤ 0.5; so does this module, refusing another ν naming `sample.poisson_ratio`.
//! Cross-check: the first coefficients are Dimitriadis's −2α₀/π = 1.1329 at ν = 0.5 (the
//! punch's, whose contact radius is a) and (2/π) × 1.1329 = 0.7212 (the cone's, whose contact
//! radius is (2/π) δ tan θ). A pyramid takes the cone's series with the angle of the cone of
//! the same half-space force (tan θ = (π/2) k, k the pyramid's g/δ²: 0.8887 tan α for
//! [`super::pyramid3`], tan α/√2 for [`super::pyramid4`]), as cell studies approximate
//! pyramids by their equivalent cone. The paper gives no non-bonded series for these shapes:
//! `bonded = false` is refused for them, naming `bonded`.

use super::TipShape;
use crate::error::SimError;
use std::f64::consts::PI;

/// The Poisson ratios Garcia & Garcia's incompressible series are applied at (module docs).
pub(crate) const GARCIA_POISSON: [f64; 2] = [0.45, 0.5];

/// Garcia & Garcia's cone series (module docs).
pub(crate) const GARCIA_CONE: [f64; 4] = [0.721, 0.650, 0.491, 0.225];

/// Garcia & Garcia's flat-punch (cylinder) series (module docs).
pub(crate) const GARCIA_PUNCH: [f64; 4] = [1.133, 1.283, 0.598, -0.291];

/// Dimitriadis et al.'s α₀ and β₀ at the Poisson ratio `nu`, bonded or not (module docs).
pub(crate) fn dimitriadis_alpha_beta(nu: f64, bonded: bool) -> (f64, f64) {
    if bonded {
        (
            -(1.2876 - 1.4678 * nu + 1.3442 * nu * nu) / (1.0 - nu),
            (0.6387 - 1.0277 * nu + 1.5164 * nu * nu) / (1.0 - nu),
        )
    } else {
        (
            -0.347 * (3.0 - 2.0 * nu) / (1.0 - nu),
            0.056 * (5.0 - 2.0 * nu) / (1.0 - nu),
        )
    }
}

/// Dimitriadis et al.'s series coefficients c₁ … c₄ of χ (module docs).
pub(crate) fn dimitriadis_series(nu: f64, bonded: bool) -> [f64; 4] {
    let (a, b) = dimitriadis_alpha_beta(nu, bonded);
    let pi2 = PI * PI;
    [
        -2.0 * a / PI,
        4.0 * a * a / pi2,
        -8.0 / (pi2 * PI) * (a * a * a + 4.0 * pi2 / 15.0 * b),
        16.0 * a / (pi2 * pi2) * (a * a * a + 3.0 * pi2 / 5.0 * b),
    ]
}

/// What the series runs in.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Argument {
    /// χ = √(Rδ)/h (paraboloid, sphere).
    ContactRadius,
    /// b = δ tan θ/h with this tan θ (cone, pyramids).
    Slope(f64),
    /// b = a/h (flat punch).
    PunchRadius,
}

/// The factor c and its derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Factor {
    /// c.
    pub value: f64,
    /// ∂c/∂δ (1/m).
    pub d_delta: f64,
    /// ∂c/∂R (1/m).
    pub d_radius: f64,
}

/// The bottom-effect correction of one shape on one layer (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BottomEffect {
    /// The layer's thickness h (m).
    thickness: f64,
    /// c₁ … c₄.
    coefficients: [f64; 4],
    /// The series' variable.
    argument: Argument,
}

impl BottomEffect {
    /// The correction of `shape` on a layer of `thickness` h (m, > 0), `bonded` to the
    /// substrate or not, of Poisson ratio `nu`.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `thickness` (not finite and > 0), `bonded` (a shape
    /// whose source gives no non-bonded series) or `sample.poisson_ratio` (Garcia & Garcia's
    /// shapes outside 0.45–0.5).
    pub(crate) fn new(
        shape: TipShape,
        thickness: f64,
        bonded: bool,
        nu: f64,
    ) -> Result<BottomEffect, SimError> {
        if !(thickness.is_finite() && thickness > 0.0) {
            return Err(SimError::out_of_range(
                "thickness",
                crate::error::number(thickness),
                "the sample's thickness must be finite and > 0 (m)",
            ));
        }
        let slope = |k: f64| Argument::Slope(PI / 2.0 * k);
        let (coefficients, argument) = match shape {
            TipShape::Paraboloid | TipShape::Sphere => {
                (dimitriadis_series(nu, bonded), Argument::ContactRadius)
            }
            TipShape::Cone { half_angle } => {
                (GARCIA_CONE, Argument::Slope(half_angle.to_radians().tan()))
            }
            TipShape::Pyramid3 { face_angle } => (
                GARCIA_CONE,
                slope(super::pyramid3::COEFFICIENT * face_angle.to_radians().tan()),
            ),
            TipShape::Pyramid4 { half_angle } => (
                GARCIA_CONE,
                slope(half_angle.to_radians().tan() * std::f64::consts::FRAC_1_SQRT_2),
            ),
            TipShape::FlatPunch => (GARCIA_PUNCH, Argument::PunchRadius),
        };
        if argument != Argument::ContactRadius {
            if !bonded {
                return Err(SimError::out_of_range(
                    "bonded",
                    "false",
                    format!(
                        "Garcia & Garcia (2018) give the bottom-effect correction of the {} for \
                         a sample bonded to its substrate only: omit bonded (or set it true)",
                        shape.name()
                    ),
                ));
            }
            let [lo, hi] = GARCIA_POISSON;
            if !(lo..=hi).contains(&nu) {
                return Err(SimError::out_of_range(
                    "sample.poisson_ratio",
                    crate::error::number(nu),
                    format!(
                        "the bottom-effect correction of the {} (Garcia & Garcia 2018) is for \
                         an incompressible sample: {lo}..={hi} with a thickness",
                        shape.name()
                    ),
                ));
            }
        }
        Ok(BottomEffect {
            thickness,
            coefficients,
            argument,
        })
    }

    /// c and its derivatives at indentation `delta` > 0 (m) and radius `radius` (m).
    pub(crate) fn factor(&self, radius: f64, delta: f64) -> Factor {
        let h = self.thickness;
        // the variable x and ∂x/∂δ, ∂x/∂R
        let (x, dx_dd, dx_dr) = match self.argument {
            Argument::ContactRadius => {
                let x = (radius * delta).sqrt() / h;
                (x, x / (2.0 * delta), x / (2.0 * radius))
            }
            Argument::Slope(t) => (delta * t / h, t / h, 0.0),
            Argument::PunchRadius => (radius / h, 0.0, 1.0 / h),
        };
        let [c1, c2, c3, c4] = self.coefficients;
        let value = 1.0 + x * (c1 + x * (c2 + x * (c3 + x * c4)));
        let slope = c1 + x * (2.0 * c2 + x * (3.0 * c3 + x * 4.0 * c4));
        Factor {
            value,
            d_delta: slope * dx_dd,
            d_radius: slope * dx_dr,
        }
    }
}
