//! Indenter shapes of the quasi-static force-curve fit: the elastic force of a rigid tip of a
//! given geometry pressed into an elastic half space, per unit reduced modulus E*
//! (1/E* = (1 − ν_t²)/E_t + (1 − ν_s²)/E_s, Johnson, *Contact Mechanics*, 1985, eq. 4.22), with
//! its derivatives for the fit's Jacobian, and the finite-thickness (bottom-effect) corrections
//! of [`bottom_effect`].
//!
//! Each shape's force lives in one file: [`paraboloid`] (Hertz), [`sphere`] (Sneddon's exact
//! sphere), [`cone`] (Sneddon), [`pyramid3`] and [`pyramid4`] (Bilodeau), [`flat_punch`]
//! (Sneddon's cylinder).
//!
//! # A geometry the elastic law shares, not a law of its own
//! The shape is a geometry of the `[tip]` that the elastic (Hertz) law takes in the force-curve
//! fit: F = E* g(δ), where only g, the shape's force per unit E*, changes. A law of the
//! registry ([`crate::contact::LAWS`]) is a *material* response (elastic, adhesive,
//! viscoelastic) with its dimensionless groups, integrated by the dynamic models through its
//! jet and potential; the shape does not add a material group, and an adhesive law's
//! adhesion (DMT's constant pull HR/(6a₀²), JKR's neck) is derived for the sphere's
//! paraboloid, so a law × shape registry would hold mostly undefined pairs. Hence:
//! * `hertz` in `fit` takes every shape (F = E* g(δ) and, with a thickness, times the
//!   bottom-effect factor);
//! * `dmt`, `jkr` and `sls` keep the paraboloid and refuse another shape naming `tip.shape`
//!   ([`TipShape::check_law`]);
//! * the dynamic analyses (simulate, approach, images, …) keep the paraboloid of the
//!   registry's laws: the probe reader refuses another shape for them naming `[tip].shape`
//!   (`crate::probe::Probe::from_table_for`).

pub(crate) mod bottom_effect;
pub(crate) mod cone;
pub(crate) mod flat_punch;
pub(crate) mod paraboloid;
pub(crate) mod pyramid3;
pub(crate) mod pyramid4;
pub(crate) mod sphere;

use crate::contact::LawKind;
use crate::error::SimError;

/// The elastic force of a shape per unit E* at an indentation δ, with its derivatives.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Elastic {
    /// g = F/E* (m²).
    pub force: f64,
    /// ∂g/∂δ (m).
    pub d_delta: f64,
    /// ∂g/∂R (m) at fixed δ; 0 for a shape without a radius.
    pub d_radius: f64,
}

/// The shape of the tip (`[tip] shape`), with its angle (degrees) where it has one; the radius,
/// where the shape has one, is `[tip] radius` (the fit's `tip.radius`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) enum TipShape {
    /// Hertz's paraboloid of apex radius R (the default).
    #[default]
    Paraboloid,
    /// Sneddon's exact sphere of radius R.
    Sphere,
    /// A cone of half-opening angle `half_angle` (degrees).
    Cone {
        /// The half-opening angle θ (degrees).
        half_angle: f64,
    },
    /// A three-sided pyramid of face angle `face_angle` (degrees, nanite's `hertz_pyr3s` α).
    Pyramid3 {
        /// The inclination angle of a face α (degrees).
        face_angle: f64,
    },
    /// A four-sided pyramid of half angle `half_angle` (degrees, to the face).
    Pyramid4 {
        /// The half angle α (degrees), between the axis and a face.
        half_angle: f64,
    },
    /// A flat cylindrical punch of radius R.
    FlatPunch,
}

/// The names `[tip] shape` takes, in [`TipShape`]'s order.
pub(crate) const SHAPES: &str = "paraboloid, sphere, cone, pyramid-3, pyramid-4 or flat-punch";

impl TipShape {
    /// The shape's name as `[tip] shape` spells it.
    pub(crate) fn name(&self) -> &'static str {
        match self {
            TipShape::Paraboloid => "paraboloid",
            TipShape::Sphere => "sphere",
            TipShape::Cone { .. } => "cone",
            TipShape::Pyramid3 { .. } => "pyramid-3",
            TipShape::Pyramid4 { .. } => "pyramid-4",
            TipShape::FlatPunch => "flat-punch",
        }
    }

    /// The `[tip]` key of the shape's angle (`half_angle`, `face_angle`); `None` for a shape of
    /// radius `[tip] radius`.
    pub(crate) fn angle_key(name: &str) -> Option<&'static str> {
        match name {
            "cone" | "pyramid-4" => Some("half_angle"),
            "pyramid-3" => Some("face_angle"),
            _ => None,
        }
    }

    /// The shape named `name` with its angle `angle` (degrees; read where
    /// [`TipShape::angle_key`] names one); `None` for a name that is no shape.
    pub(crate) fn of(name: &str, angle: f64) -> Option<TipShape> {
        Some(match name {
            "paraboloid" => TipShape::Paraboloid,
            "sphere" => TipShape::Sphere,
            "cone" => TipShape::Cone { half_angle: angle },
            "pyramid-3" => TipShape::Pyramid3 { face_angle: angle },
            "pyramid-4" => TipShape::Pyramid4 { half_angle: angle },
            "flat-punch" => TipShape::FlatPunch,
            _ => return None,
        })
    }

    /// Whether the shape has the radius `[tip] radius` (fittable as `tip.radius`).
    pub(crate) fn has_radius(&self) -> bool {
        matches!(
            self,
            TipShape::Paraboloid | TipShape::Sphere | TipShape::FlatPunch
        )
    }

    /// g = F/E* and its derivatives at indentation `delta` (m; zero out of contact, δ ≤ 0)
    /// for the radius `radius` (m; unused by a shape without one).
    pub(crate) fn elastic(&self, radius: f64, delta: f64) -> Elastic {
        if delta.is_nan() || delta <= 0.0 {
            return Elastic::default();
        }
        match *self {
            TipShape::Paraboloid => paraboloid::elastic(radius, delta),
            TipShape::Sphere => sphere::elastic(radius, delta),
            TipShape::Cone { half_angle } => cone::elastic(half_angle, delta),
            TipShape::Pyramid3 { face_angle } => pyramid3::elastic(face_angle, delta),
            TipShape::Pyramid4 { half_angle } => pyramid4::elastic(half_angle, delta),
            TipShape::FlatPunch => flat_punch::elastic(radius, delta),
        }
    }

    /// The shape under the registry's law `law` in the force-curve fit: every shape under
    /// `hertz`, the paraboloid only under the others (module docs).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `tip.shape`.
    pub(crate) fn check_law(&self, law: LawKind) -> Result<(), SimError> {
        if law == LawKind::Hertz || *self == TipShape::Paraboloid {
            return Ok(());
        }
        Err(SimError::out_of_range(
            "tip.shape",
            self.name(),
            format!(
                "the {} law's force is derived for the paraboloid (shape = \"paraboloid\", \
                 the default); the other shapes are the hertz law's",
                law.name()
            ),
        ))
    }
}

/// The elastic force of a shape with the optional bottom-effect correction: what the
/// force-curve fit evaluates, F = E* g(δ) c(δ).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Indenter {
    /// The tip's shape.
    pub shape: TipShape,
    /// The finite-thickness correction, when the sample's thickness is given.
    pub bottom: Option<bottom_effect::BottomEffect>,
}

impl Indenter {
    /// g·c, the force per unit E* with the bottom-effect factor c, and its derivatives, at
    /// indentation `delta` (m) for the radius `radius` (m).
    pub(crate) fn elastic(&self, radius: f64, delta: f64) -> Elastic {
        let g = self.shape.elastic(radius, delta);
        match (&self.bottom, g.force > 0.0) {
            (Some(b), true) => {
                let c = b.factor(radius, delta);
                Elastic {
                    force: g.force * c.value,
                    d_delta: g.d_delta * c.value + g.force * c.d_delta,
                    d_radius: g.d_radius * c.value + g.force * c.d_radius,
                }
            }
            _ => g,
        }
    }
}

#[cfg(test)]
mod tests;
