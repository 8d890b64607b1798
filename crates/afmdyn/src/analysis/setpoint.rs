//! Operating points at an amplitude setpoint (issue 28): where an approach curve's amplitude
//! ratio A/A₀ equals the setpoint A_sp/A₀ that an instrument's feedback holds while it images.
//! On every stable stretch of every continued branch (or, without branches, of the approach and
//! retract sweeps) each crossing of the setpoint is located by linear interpolation between
//! the two curve points around it (error of the order of the grid step squared times the
//! curvature of A(z_c)); the observables there — phase, peak force, indentation, dissipated
//! energy: the quantities of a phase image — are interpolated the same way ([`Crossing`] gives
//! the two points and the weight). In the bistable range there is one crossing on the
//! attractive and one on the repulsive branch: which one the instrument holds depends on
//! its history (García & San Paulo, Phys. Rev. B 61, R13381 (2000)).

use super::stepped::{SteppedCurve, Sweep};

/// Which curve a crossing lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// Continued branch k.
    Branch(usize),
    /// A stepped sweep (the approach or the retract).
    Sweep(Sweep),
}

/// A crossing of the setpoint between points `index` and `index + 1` of its curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// The curve.
    pub source: Source,
    /// The first of the two points around the crossing.
    pub index: usize,
    /// The weight of the second point: a quantity q at the setpoint is
    /// `(1 − t)·q[index] + t·q[index + 1]`.
    pub t: f64,
    /// The swept parameter (α5 for an approach) at the setpoint.
    pub value: f64,
}

/// A point of a curve: (swept value, A/A₀, stable).
type Point = (f64, f64, bool);

fn crossings_of(points: &[Point], source: Source, ratio: f64, out: &mut Vec<Crossing>) {
    for (i, w) in points.windows(2).enumerate() {
        let ((v0, r0, s0), (v1, r1, s1)) = (w[0], w[1]);
        if !(s0 && s1 && r0.is_finite() && r1.is_finite()) || r0 == r1 {
            continue;
        }
        // a crossing in [r0, r1) (half-open, so a point exactly at the setpoint counts once)
        let (lo, hi) = (r0.min(r1), r0.max(r1));
        if ratio >= lo && ratio < hi || (ratio == hi && i + 2 == points.len()) {
            let t = (ratio - r0) / (r1 - r0);
            out.push(Crossing {
                source,
                index: i,
                t,
                value: v0 + t * (v1 - v0),
            });
        }
    }
}

/// Every crossing of A/A₀ = `ratio` on the stable stretches of `curve`'s branches, or of its
/// two sweeps when it has no branches.
pub fn setpoint_crossings(curve: &SteppedCurve, ratio: f64) -> Vec<Crossing> {
    let ratio_of = |o: &super::observables::Observables| o.amplitude / o.closed_form.free_amplitude;
    let mut out = Vec::new();
    if curve.branches.is_empty() {
        for (sweep, pts) in [(Sweep::First, &curve.first), (Sweep::Second, &curve.second)] {
            let points: Vec<Point> = pts
                .iter()
                .map(|p| (p.value, ratio_of(&p.observables), p.stable))
                .collect();
            crossings_of(&points, Source::Sweep(sweep), ratio, &mut out);
        }
    } else {
        for (k, b) in curve.branches.iter().enumerate() {
            let points: Vec<Point> = b
                .iter()
                .map(|s| (s.point.value, ratio_of(&s.observables), s.point.stable))
                .collect();
            crossings_of(&points, Source::Branch(k), ratio, &mut out);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossings_are_interpolated_on_stable_segments_only() {
        let pts = [
            (1.0, 1.0, true),
            (0.8, 0.8, true),
            (0.6, 0.6, false),
            (0.4, 0.4, true),
            (0.2, 0.2, true),
        ];
        let mut out = Vec::new();
        crossings_of(&pts, Source::Branch(0), 0.9, &mut out);
        assert_eq!(out.len(), 1);
        assert!((out[0].t - 0.5).abs() < 1e-15 && (out[0].value - 0.9).abs() < 1e-15);
        // 0.7 lies on an unstable segment: none
        out.clear();
        crossings_of(&pts, Source::Branch(0), 0.7, &mut out);
        assert!(out.is_empty());
        // a non-monotone curve crosses twice
        let pts = [(0.0, 0.2, true), (1.0, 0.9, true), (2.0, 0.3, true)];
        out.clear();
        crossings_of(&pts, Source::Branch(1), 0.5, &mut out);
        assert_eq!(out.len(), 2);
        assert_eq!(out[1].index, 1);
    }
}
