//! The quasi-static force-curve fit: a contact law of the registry (Hertz, DMT, JKR) with its
//! contact point and force baseline, fitted to a measured force against piezo height.
//!
//! # Preprocessing (nanite's steps and names, Müller et al., *BMC Bioinformatics* 20 (2019) 465;
//! nanite 4.2 `preproc.py`, `poc.py`)
//! 1. `compute_tip_position`: the tip position x = h + F/k from the piezo height h (m,
//!    decreasing into the sample), the force F (N, repulsion positive: the lever bends away
//!    from the sample) and the lever's spring constant k (N/m, the probe's) — as JPK's
//!    "Vertical Tip Position".
//! 2. `correct_force_offset`: the contact point's index i_c by `deviation_from_baseline` on
//!    the approach up to its largest force (the baseline is the first 10 % of that part; i_c is
//!    the first point whose force exceeds the baseline's mean by twice its largest deviation;
//!    the middle of that part when none does), and the mean force before i_c subtracted (the
//!    first force when i_c = 0).
//! 3. `correct_tip_offset`: the tip position at i_c subtracted, so the contact point starts
//!    near 0.
//! 4. The segments: the approach up to the lowest piezo height (inclusive), the retract after
//!    it.
//!
//! # Model
//! F(x) = baseline + F_c(δ), δ = contact_point − x (the indentation), F_c the law's force of
//! the registry (`crate::contact::Law::force`) evaluated in SI: its Hertz group
//! k_H = (4/3)E*√R (Hertz 1882; Sneddon, *Int. J. Eng. Sci.* 3 (1965) 47, eq. 6.9: the
//! paraboloid F = (4/3) E/(1 − ν²) √R δ^{3/2} of a rigid tip), 1/E* = (1 − ν_t²)/E_t +
//! (1 − ν_s²)/E_s (Johnson, *Contact Mechanics*, 1985, eq. 4.22); DMT's van der Waals group
//! H R/6 and a₀, in contact the Hertz force minus the adhesion HR/(6a₀²) ([`crate::contact::dmt`]);
//! JKR's adhesion πWR ([`crate::contact::jkr`]; the contact forms at δ = 0 on the approach and
//! holds down to the break on the retract). Each law's groups are homogeneous in their units,
//! so the law's dimensionless force is the SI force with g₀ = 1 m and F̃ = 1 N.
//!
//! # Indenter shapes and finite thickness
//! Under the Hertz law the tip's shape (`[tip] shape`, `contact::indenter`) gives
//! F_c = E* g(δ) c(δ): g the shape's force per unit E* (the paraboloid's (4/3)√R δ^{3/2},
//! Sneddon's exact sphere, cone, the pyramids, the flat punch) and c the bottom-effect factor
//! of a sample of the request's `thickness` (1 without; Dimitriadis et al. 2002, Garcia &
//! Garcia 2018: `contact::indenter::bottom_effect`). A shape without a radius has no
//! `tip.radius` parameter; its angle is held. ∂F/∂E_s = g c ∂E*/∂E_s, ∂F/∂R and ∂F/∂δ are the
//! shape's and the factor's exact derivatives.
//!
//! # Sensitivities
//! ∂F/∂contact_point is the law's exact ∂F_c/∂δ; ∂F/∂baseline = 1; through the groups,
//! ∂F/∂k_H = F_c/k_H exactly for Hertz, and by central differences of relative step 1e-6 on
//! DMT's and JKR's groups (error ~1e-12 relative), chained to E_s, R, H and W analytically.

use crate::contact::indenter::{Indenter, TipShape};
use crate::contact::{reduced_modulus, DmtLaw, HertzLaw, Jkr, JkrLaw, Law, LawKind};

/// The names of the force-curve model's parameters of the registry's law `law`, in the
/// model's order (every one fittable): Hertz's paraboloid, DMT (Hertz with the van der Waals
/// attraction, a constant adhesion in contact), JKR (the adhesive neck) and the standard linear
/// solid (Zener, with surface memory, in time: its model is
/// [`super::sls_curve::SlsCurveModel`], not [`ForceCurveModel`]); `None` for a law the fit does
/// not take.
pub(crate) fn parameter_names(law: LawKind) -> Option<&'static [&'static str]> {
    match law {
        LawKind::Hertz => Some(&[YOUNGS_MODULUS, RADIUS, CONTACT_POINT, BASELINE]),
        LawKind::Dmt => Some(&[YOUNGS_MODULUS, RADIUS, CONTACT_POINT, BASELINE, HAMAKER]),
        LawKind::Jkr => Some(&[YOUNGS_MODULUS, RADIUS, CONTACT_POINT, BASELINE, ADHESION]),
        LawKind::Sls => Some(&[
            STIFFNESS,
            MAXWELL_STIFFNESS,
            RELAXATION_TIME,
            CONTACT_POINT,
            BASELINE,
        ]),
        _ => None,
    }
}

/// The names of the force-curve model's parameters of the law `law` with a tip of `shape`:
/// [`parameter_names`], less `tip.radius` for a shape without a radius (a cone, a pyramid) under
/// the Hertz law; `None` for a law the fit does not take.
pub(crate) fn parameter_names_of(
    law: LawKind,
    shape: &TipShape,
) -> Option<&'static [&'static str]> {
    match law {
        LawKind::Hertz if !shape.has_radius() => Some(&[YOUNGS_MODULUS, CONTACT_POINT, BASELINE]),
        _ => parameter_names(law),
    }
}

/// `sample.youngs_modulus` (Pa).
pub(crate) const YOUNGS_MODULUS: &str = "sample.youngs_modulus";
/// `tip.radius` (m).
pub(crate) const RADIUS: &str = "tip.radius";
/// `contact_point` (m): the tip position where δ = 0, after `correct_tip_offset`.
pub(crate) const CONTACT_POINT: &str = "contact_point";
/// `baseline` (N): the force far from the sample, after `correct_force_offset`.
pub(crate) const BASELINE: &str = "baseline";
/// `sample.hamaker` (J), DMT's.
pub(crate) const HAMAKER: &str = "sample.hamaker";
/// `sample.adhesion_energy` (J/m²), JKR's work of adhesion W.
pub(crate) const ADHESION: &str = "sample.adhesion_energy";
/// `sample.stiffness` (N/m): the SLS's relaxed spring k₁ ([`super::sls_curve`]).
pub(crate) const STIFFNESS: &str = "sample.stiffness";
/// `sample.maxwell_stiffness` (N/m): the SLS Maxwell arm's spring k₂.
pub(crate) const MAXWELL_STIFFNESS: &str = "sample.maxwell_stiffness";
/// `sample.relaxation_time` (s): the SLS Maxwell arm's τ = η/k₂.
pub(crate) const RELAXATION_TIME: &str = "sample.relaxation_time";

/// Which part of the curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Segment {
    /// Up to the lowest piezo height.
    Approach,
    /// After it.
    Retract,
    /// Every row: approach, dwell and retract (a time-dependent law's history; JKR's
    /// `ForceCurveModel` takes these rows as an approach's).
    Whole,
}

/// A force curve after the preprocessing of the module docs.
#[derive(Debug, Clone, PartialEq)]
pub struct Preprocessed {
    /// The tip position x (m) of every row, after `correct_tip_offset`.
    pub tip_position: Vec<f64>,
    /// The force (N) of every row, after `correct_force_offset`.
    pub force: Vec<f64>,
    /// The number of approach rows (the rest is the retract).
    pub approach_len: usize,
    /// The contact point's index i_c (`deviation_from_baseline`), `None` where no point
    /// deviates (then the middle of the approach's rising part is used, as nanite does).
    pub contact_index: Option<usize>,
    /// The force subtracted (N).
    pub force_offset: f64,
    /// The tip position subtracted (m).
    pub tip_offset: f64,
    /// The rows' times (s), when the data give them (a time-dependent law needs them).
    pub time: Option<Vec<f64>>,
}

impl Preprocessed {
    /// The rows of `segment` whose tip position lies in `range` (m, inclusive; all without).
    pub fn rows(&self, segment: Segment, range: Option<[f64; 2]>) -> Vec<usize> {
        let span = match segment {
            Segment::Approach => 0..self.approach_len,
            Segment::Retract => self.approach_len..self.force.len(),
            Segment::Whole => 0..self.force.len(),
        };
        span.filter(|&i| range.is_none_or(|[lo, hi]| (lo..=hi).contains(&self.tip_position[i])))
            .collect()
    }
}

/// nanite's `deviation_from_baseline` on `force` (module docs, step 2): the first index whose
/// force exceeds the first 10 %'s mean by twice their largest deviation.
pub(crate) fn deviation_from_baseline(force: &[f64]) -> Option<usize> {
    let n = force.len() / 10;
    if n == 0 {
        return None;
    }
    let base = &force[..n];
    let mean = base.iter().sum::<f64>() / n as f64;
    let range = 2.0 * base.iter().map(|f| (f - mean).abs()).fold(0.0, f64::max);
    force.iter().position(|f| f - mean > range)
}

/// The preprocessing of the module docs on a curve of piezo heights `height` (m) and forces
/// `force` (N) with the lever's spring constant `spring_constant` (N/m).
pub(crate) fn preprocess(height: &[f64], force: &[f64], spring_constant: f64) -> Preprocessed {
    let mut tip: Vec<f64> = height
        .iter()
        .zip(force)
        .map(|(h, f)| h + f / spring_constant)
        .collect();
    // the approach's part up to its largest force (nanite's clip_approach)
    let peak = force
        .iter()
        .enumerate()
        .fold(0, |best, (i, f)| if *f > force[best] { i } else { best });
    let clipped = &force[..peak];
    let found = deviation_from_baseline(clipped);
    let cp = found.unwrap_or(clipped.len() / 2);
    let force_offset = if cp > 0 {
        force[..cp].iter().sum::<f64>() / cp as f64
    } else {
        force.first().copied().unwrap_or(0.0)
    };
    let force: Vec<f64> = force.iter().map(|f| f - force_offset).collect();
    let tip_offset = tip.get(cp).copied().unwrap_or(0.0);
    for x in &mut tip {
        *x -= tip_offset;
    }
    let lowest = height
        .iter()
        .enumerate()
        .fold(0, |best, (i, h)| if *h < height[best] { i } else { best });
    Preprocessed {
        tip_position: tip,
        force,
        approach_len: (lowest + 1).min(height.len()),
        contact_index: found,
        force_offset,
        tip_offset,
        time: None,
    }
}

/// The force-curve model at the rows' tip positions (module docs). Parameters in
/// `parameter_names`' order.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ForceCurveModel {
    /// The law (one `parameter_names` takes).
    pub law: LawKind,
    /// The tip positions x (m) of the fitted rows.
    pub x: Vec<f64>,
    /// The segment the rows belong to (JKR's contact differs on approach and retract).
    pub segment: Segment,
    /// The sample's Poisson ratio ν_s (held).
    pub poisson_ratio: f64,
    /// The tip's Young's modulus E_t (Pa) and Poisson ratio ν_t (held).
    pub tip: (f64, f64),
    /// DMT's intermolecular distance a₀ (m; held).
    pub intermolecular_distance: f64,
    /// The tip's shape and the sample's bottom-effect correction (the Hertz law's; the
    /// paraboloid of infinite thickness under the other laws).
    pub indenter: Indenter,
}

impl ForceCurveModel {
    /// k_H = (4/3)E*√R and ∂k_H/∂E_s.
    fn hertz_group(&self, e_s: f64, r: f64) -> (f64, f64) {
        let b = 1.0 - self.poisson_ratio * self.poisson_ratio;
        let e_star = reduced_modulus(self.tip.0, self.tip.1, e_s, self.poisson_ratio);
        // ∂E*/∂E_s = E*² (1 − ν_s²)/E_s²
        let k = 4.0 / 3.0 * e_star * r.sqrt();
        (k, k * e_star * b / (e_s * e_s))
    }

    /// The law's force and ∂F/∂δ at indentation δ with Hertz group k and second group g.
    fn law_force(&self, k: f64, g: f64, delta: f64) -> (f64, f64) {
        let e = match self.law {
            LawKind::Hertz => HertzLaw.force(k, 0.0, delta >= 0.0, delta, 0.0),
            LawKind::Dmt => DmtLaw {
                hamaker: g,
                intermolecular_distance: self.intermolecular_distance,
            }
            .force(k, 0.0, delta >= 0.0, delta, 0.0),
            LawKind::Jkr => {
                let contact = match self.segment {
                    Segment::Approach | Segment::Whole => delta >= 0.0,
                    Segment::Retract => delta > Jkr::new(k, g).release(),
                };
                JkrLaw { adhesion: g }.force(k, 0.0, contact, delta, 0.0)
            }
            // not this model's law (SLS's history needs the rows' times): no value
            _ => crate::contact::ForceEval {
                force: f64::NAN,
                d_delta: f64::NAN,
                d_rate: f64::NAN,
            },
        };
        (e.force, e.d_delta)
    }
}

impl ForceCurveModel {
    /// The Hertz law's F = baseline + E* g(δ) c(δ) of the tip's shape (module docs), with the
    /// parameters of [`parameter_names_of`]: E_s, R (a shape with a radius), contact point and
    /// baseline.
    fn evaluate_shape(&self, p: &[f64], values: &mut [f64], jacobian: Option<&mut [f64]>) {
        let radius = self.indenter.shape.has_radius();
        let (e_s, [r, cp, baseline]) = match radius {
            true => (p[0], [p[1], p[2], p[3]]),
            false => (p[0], [f64::NAN, p[1], p[2]]),
        };
        let b = 1.0 - self.poisson_ratio * self.poisson_ratio;
        let e_star = reduced_modulus(self.tip.0, self.tip.1, e_s, self.poisson_ratio);
        // ∂E*/∂E_s = E*² (1 − ν_s²)/E_s²
        let de_star = e_star * e_star * b / (e_s * e_s);
        let n = p.len();
        let mut jac = jacobian;
        for (i, x) in self.x.iter().enumerate() {
            let g = self.indenter.elastic(r, cp - x);
            values[i] = baseline + e_star * g.force;
            let Some(j) = jac.as_deref_mut() else {
                continue;
            };
            let row = &mut j[i * n..(i + 1) * n];
            row[0] = g.force * de_star;
            let at = if radius {
                row[1] = e_star * g.d_radius;
                2
            } else {
                1
            };
            row[at] = e_star * g.d_delta;
            row[at + 1] = 1.0;
        }
    }
}

impl super::CurveModel for ForceCurveModel {
    fn points(&self) -> usize {
        self.x.len()
    }
    fn evaluate(&self, p: &[f64], values: &mut [f64], jacobian: Option<&mut [f64]>) {
        if self.law == LawKind::Hertz {
            return self.evaluate_shape(p, values, jacobian);
        }
        let (e_s, r, cp, baseline) = (p[0], p[1], p[2], p[3]);
        let (k, dk_de) = self.hertz_group(e_s, r);
        // the law's second group and its derivatives by R and by its own parameter
        let (g, dg_dr, dg_dq) = match self.law {
            LawKind::Dmt => (p[4] * r / 6.0, p[4] / 6.0, r / 6.0),
            LawKind::Jkr => {
                let pi = std::f64::consts::PI;
                (pi * p[4] * r, pi * p[4], pi * r)
            }
            _ => (0.0, 0.0, 0.0),
        };
        let n = p.len();
        let mut jac = jacobian;
        for (i, x) in self.x.iter().enumerate() {
            let delta = cp - x;
            let (f, d_delta) = self.law_force(k, g, delta);
            values[i] = baseline + f;
            let Some(j) = jac.as_deref_mut() else {
                continue;
            };
            let (df_dk, df_dg) = match self.law {
                LawKind::Hertz => (f / k, 0.0),
                _ => {
                    let hk = 1e-6 * k;
                    let hg = 1e-6 * g.abs().max(f64::MIN_POSITIVE);
                    (
                        (self.law_force(k + hk, g, delta).0 - self.law_force(k - hk, g, delta).0)
                            / (2.0 * hk),
                        (self.law_force(k, g + hg, delta).0 - self.law_force(k, g - hg, delta).0)
                            / (2.0 * hg),
                    )
                }
            };
            let row = &mut j[i * n..(i + 1) * n];
            row[0] = df_dk * dk_de;
            row[1] = df_dk * k / (2.0 * r) + df_dg * dg_dr;
            row[2] = d_delta;
            row[3] = 1.0;
            if n > 4 {
                row[4] = df_dg * dg_dq;
            }
        }
    }
}
