//! Profile-likelihood intervals: the parameter held on a grid outward from its estimate, the
//! others refitted at each point, and the interval where Δχ² = χ²_profile − χ²_min stays at or
//! below [`DELTA_CHI2_95`] (Venzon & Moolgavkar, *J. R. Stat. Soc. C* 37 (1988) 87; Raue et
//! al., *Bioinformatics* 25 (2009) 1923, which also names a profile that never rises a
//! *practically non-identifiable* parameter). Without σ the χ² are scaled by the noise
//! variance estimated at the minimum, s² = χ²_min/(m − n).

use super::least_squares::{minimize, CurveModel, Minimum, Observations, Parameter};

/// The 95 % quantile of χ² with one degree of freedom, 3.841 (the profile's threshold).
pub const DELTA_CHI2_95: f64 = 3.841_458_820_694_124;

/// The most grid points walked on each side before the profile is called flat.
pub const MAX_PROFILE_STEPS: usize = 30;

/// Bisections refining a crossing of [`DELTA_CHI2_95`] between two grid points.
const BISECTIONS: usize = 5;

/// One side's end of a profile interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ProfileEnd {
    /// Δχ² crosses the threshold here.
    Crossing(f64),
    /// The parameter's bound is reached with Δχ² below the threshold.
    Bound(f64),
    /// Δχ² stays below the threshold as far as the grid goes (the last point walked).
    Flat(f64),
}

impl ProfileEnd {
    /// The end's value.
    pub fn value(self) -> f64 {
        match self {
            ProfileEnd::Crossing(x) | ProfileEnd::Bound(x) | ProfileEnd::Flat(x) => x,
        }
    }
}

/// A parameter's profile: its interval's ends and the points walked, (value, Δχ²), in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// The lower end.
    pub lower: ProfileEnd,
    /// The upper end.
    pub upper: ProfileEnd,
    /// The points walked, (value, Δχ²), sorted by value.
    pub points: Vec<(f64, f64)>,
    /// The lowest Δχ² met (negative: the profile found a lower χ² than the fit's).
    pub lowest: f64,
    /// Refits made.
    pub refits: usize,
}

/// The profile of parameter `j` about `best`, the parameters `fixed` in the fit held there
/// too: steps of `step` (its standard error, or a
/// fraction of its scale where that is not finite), half a step at first and growing by half
/// after 4 steps' distance, each refit starting from the previous one; `s2` scales χ² (the
/// noise variance, 1 with σ given).
#[allow(clippy::too_many_arguments)]
pub fn profile(
    model: &dyn CurveModel,
    obs: &Observations,
    params: &[Parameter],
    best: &Minimum,
    fixed: &[Option<f64>],
    j: usize,
    step: f64,
    s2: f64,
) -> Profile {
    let p = &params[j];
    let centre = best.values[j];
    let mut points = vec![(centre, 0.0)];
    let mut refits = 0;
    let mut lowest: f64 = 0.0;
    let delta_at = |x: f64, from: &[f64], refits: &mut usize| -> (f64, Vec<f64>) {
        let mut held = fixed.to_vec();
        held[j] = Some(x);
        let m = minimize(model, obs, params, from, &held);
        *refits += 1;
        ((m.chi2 - best.chi2) / s2, m.values)
    };
    let mut ends = [ProfileEnd::Flat(centre); 2];
    for (side, sign) in [-1.0_f64, 1.0].into_iter().enumerate() {
        let bound = if sign < 0.0 { p.lower } else { p.upper };
        let (mut prev_x, mut prev_d, mut prev_v) = (centre, 0.0, best.values.clone());
        let mut distance = 0.0;
        let mut end = None;
        for i in 1..=MAX_PROFILE_STEPS {
            distance = if i <= 8 {
                0.5 * step * i as f64
            } else {
                distance * 1.5
            };
            let mut x = centre + sign * distance;
            let at_bound = (x - bound) * sign >= 0.0;
            if at_bound {
                x = bound;
            }
            let (d, v) = delta_at(x, &prev_v, &mut refits);
            lowest = lowest.min(d);
            points.push((x, d));
            if d >= DELTA_CHI2_95 {
                // bisect [prev_x, x], then interpolate linearly inside the last bracket
                let (mut a, mut da, mut b, mut db) = (prev_x, prev_d, x, d);
                for _ in 0..BISECTIONS {
                    let c = 0.5 * (a + b);
                    let (dc, vc) = delta_at(c, &prev_v, &mut refits);
                    points.push((c, dc));
                    if dc >= DELTA_CHI2_95 {
                        (b, db) = (c, dc);
                    } else {
                        (a, da, prev_v) = (c, dc, vc);
                    }
                }
                let t = ((DELTA_CHI2_95 - da) / (db - da)).clamp(0.0, 1.0);
                end = Some(ProfileEnd::Crossing(a + t * (b - a)));
                break;
            }
            if at_bound {
                end = Some(ProfileEnd::Bound(x));
                break;
            }
            (prev_x, prev_d, prev_v) = (x, d, v);
        }
        ends[side] = end.unwrap_or(ProfileEnd::Flat(prev_x));
    }
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    Profile {
        lower: ends[0],
        upper: ends[1],
        points,
        lowest,
        refits,
    }
}
