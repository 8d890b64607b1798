//! The invariant circle of the stroboscopic map of a two-frequency drive, as a map whose fixed
//! points are the circle: [`CircleMap`] over any [`Integrator`], on the nodes of
//! [`CircleNodes`].
//!
//! A drive at Ω and at a second frequency r Ω (r = p/q, [`crate::params::DriveComponent`]) has a
//! steady state that repeats only after q periods T = 2π/Ω, or never when r is irrational. Seen
//! once per period T, the state lies on an invariant circle x = u(θ) of the stroboscopic map,
//! θ the second drive's phase; one period advances θ by the rotation 2πρ, ρ = r mod 1, and the
//! circle obeys the invariance equation u(θ + 2πρ) = P_θ(u(θ)), P_θ the flow over one period T
//! with the second drive at phase θ (Schilder, Osinga & Vogt, *SIAM J. Appl. Dyn. Syst.* 4
//! (2005) 459; for a forced system ρ is known and no phase condition is needed).
//!
//! **Collocation on one orbit segment.** The nodes are the phases θ_k = 2π (k ρ mod 1) of M
//! consecutive periods, k = 0..M−1, and u is the trigonometric polynomial through the M
//! node states x_k (degree ⌊M/2⌋). The invariance equation at θ_k, x_{k+1} = P(x_k), holds
//! exactly for k < M−1 by integrating one segment x_k = Pᵏ(x_0) from τ = 0; at the last node
//! it closes the circle through the interpolant: P(x_{M−1}) = u(θ_M) = Σ_j w_j x_j, w_j the
//! trigonometric Lagrange weights at θ_M ([`CircleNodes::closure`]). One unknown, x_0 (2N),
//! against 2N equations F(x_0) = x_M − Σ_j w_j x_j, with ∂F/∂x_0 = Φ_M − Σ_j w_j Φ_j
//! (Φ_j = ∂x_j/∂x_0, the products of the one-period monodromy matrices with their saltation
//! matrices, [`crate::maps::flow`]). When the M nodes close the drive's period (M ρ an
//! integer, M a multiple of q) the weights are w = e_0 and F is the periodic orbit's
//! Pᴹ(x_0) − x_0 itself. Otherwise the error is the interpolation error of the circle at θ_M,
//! which falls geometrically with M for a circle that is smooth (no grazing on it); M at a
//! denominator of a convergent of ρ puts the nodes nearly evenly around the circle (the three
//! gap theorem), where the interpolation is well conditioned ([`node_count`]).
//!
//! [`CircleMap`] is a [`DiscreteMap`] whose fixed points are the circle's x_0: G(x_0) = x_0 +
//! F(x_0), ∂G = I + ∂F, so the one Newton of [`crate::analysis::shooting::shoot`] solves it.

use crate::error::{within, SimError};
use crate::integrate::Integrator;
use crate::maps::discrete::DiscreteMap;
use crate::maps::flow::{flow, flow_state, grazing_distance, FlowMap};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::TAU;

/// The most nodes a circle takes (its cost is that many drive periods per Newton iteration).
pub(crate) const MAX_NODES: usize = 1000;

/// The nodes of an invariant circle: their phases and the interpolation's weights.
#[derive(Debug, Clone, PartialEq)]
pub struct CircleNodes {
    /// ρ = p/q mod 1 as (p mod q, q): the rotation per drive period, in turns.
    pub rotation: (u64, u64),
    /// θ_k = 2π (k p mod q)/q, k = 0..M−1, rad: the second drive's phase at τ = kT, relative
    /// to its phase at τ = 0.
    pub angles: Vec<f64>,
    /// w_j: u(θ_M) = Σ_j w_j u(θ_j) for the trigonometric interpolant through the nodes, `[M]`.
    pub closure: Vec<f64>,
    /// q_j: (1/2π) ∫ u dθ = Σ_j q_j u(θ_j) for the same interpolant (they sum to 1), `[M]`.
    pub quadrature: Vec<f64>,
    /// Whether the nodes close the drive's period (M p ≡ 0 mod q): then w = e_0, q_j = 1/M and
    /// the circle is the periodic orbit of M periods.
    pub exact: bool,
}

/// The trigonometric basis of M nodes at θ: 1, cos θ, sin θ, …, cos Kθ, sin Kθ with K =
/// (M−1)/2 for odd M; for even M the last pair is cos(Mθ/2) alone (M functions in all).
fn basis(m: usize, theta: f64) -> DVector<f64> {
    DVector::from_fn(m, |j, _| {
        if j == 0 {
            1.0
        } else {
            let k = j.div_ceil(2) as f64;
            if j % 2 == 1 {
                (k * theta).cos()
            } else {
                (k * theta).sin()
            }
        }
    })
}

impl CircleNodes {
    /// The M nodes of the rotation ρ = p/q mod 1 (r = p/q the second drive's frequency ratio).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] for M outside 1..=[`MAX_NODES`] or q = 0;
    /// [`SimError::NoConvergence`] when the nodes are too close together for the interpolation
    /// (two nodes at one phase before the period closes).
    pub(crate) fn new(p: u64, q: u64, m: usize) -> Result<Self, SimError> {
        if q == 0 {
            return Err(SimError::out_of_range("q", 0, "must be ≥ 1"));
        }
        within(
            "nodes",
            m,
            1..=MAX_NODES,
            "must be in 1..=1000 (drive periods per Newton iteration)",
        )?;
        let p = p % q;
        let angle =
            |k: u64| TAU * ((u128::from(k) * u128::from(p)) % u128::from(q)) as f64 / q as f64;
        let angles: Vec<f64> = (0..m as u64).map(angle).collect();
        let exact = (u128::from(m as u64) * u128::from(p)).is_multiple_of(u128::from(q));
        if exact {
            let mut closure = vec![0.0; m];
            closure[0] = 1.0;
            return Ok(CircleNodes {
                rotation: (p, q),
                angles,
                closure,
                quadrature: vec![1.0 / m as f64; m],
                exact,
            });
        }
        // two nodes at one phase: the orbit closed before M (M beyond the period q)
        if (m as u64) > q {
            return Err(SimError::out_of_range(
                "nodes",
                m,
                "must be a multiple of the drive's period q, or below it",
            ));
        }
        // V[i, j] = basis_j(θ_i); the weights solve Vᵀ w = basis(θ_M), Vᵀ q = e_0
        let v = DMatrix::from_fn(m, m, |i, j| basis(m, angles[i])[j]);
        let lu = v.transpose().lu();
        let mut e0 = DVector::zeros(m);
        e0[0] = 1.0;
        let singular = || SimError::NoConvergence {
            what: "the invariant circle's interpolation (nodes too close together)",
            iterations: 0,
            residual: f64::NAN,
        };
        let closure = lu.solve(&basis(m, angle(m as u64))).ok_or_else(singular)?;
        let quadrature = lu.solve(&e0).ok_or_else(singular)?;
        Ok(CircleNodes {
            rotation: (p, q),
            angles,
            closure: closure.as_slice().to_vec(),
            quadrature: quadrature.as_slice().to_vec(),
            exact,
        })
    }

    /// M, the number of nodes.
    pub fn len(&self) -> usize {
        self.angles.len()
    }

    /// Never: a circle has at least one node.
    pub fn is_empty(&self) -> bool {
        self.angles.is_empty()
    }
}

/// The number of nodes for the rotation ρ = p/q mod 1: q itself when q ≤ `target` (the
/// periodic orbit, exact), else the smallest denominator ≥ `target` of a convergent or
/// semiconvergent of ρ (q_{k−2} + j q_{k−1}, j = 1..a_k, from its continued fraction
/// [0; a_1, a_2, …]: the first M multiples of ρ then leave at most three gap lengths around
/// the circle and lie nearly evenly, Khinchin, *Continued Fractions*, 1964, §6), at most
/// [`MAX_NODES`] and at most q.
pub(crate) fn node_count(p: u64, q: u64, target: usize) -> usize {
    let (p, q) = (p % q.max(1), q.max(1));
    let target = target as u64;
    if q <= target {
        return q as usize;
    }
    // denominators q_k = a_k q_{k−1} + q_{k−2} and the semiconvergents' between them
    let (mut num, mut den) = (p, q);
    let (mut q_prev, mut q_cur) = (0u64, 1u64);
    while num != 0 {
        let a = den / num;
        (den, num) = (num, den % num);
        for j in 1..=a {
            let d = q_prev.saturating_add(j.saturating_mul(q_cur));
            if d >= target {
                return d.min(q).min(MAX_NODES as u64) as usize;
            }
        }
        (q_prev, q_cur) = (q_cur, a.saturating_mul(q_cur).saturating_add(q_prev));
    }
    q.min(MAX_NODES as u64) as usize
}

/// One orbit segment of M drive periods from x_0 with its linearisation
/// ([`CircleMap::linearised_segment`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// x_0 … x_M (M + 1 states `[2N]`), x_{k+1} = P(x_k).
    pub states: Vec<DVector<f64>>,
    /// Φ_0 = I … Φ_M, Φ_k = ∂x_k/∂x_0 (M + 1 matrices 2N×2N, saltation matrices included).
    pub monodromy: Vec<DMatrix<f64>>,
    /// Switchings in each period, `[M]`.
    pub switchings: Vec<usize>,
    /// Contacts (entries into region II and impacts) over the segment.
    pub contacts: usize,
    /// Time in region II over the segment (τ).
    pub contact_time: f64,
    /// Smallest distance to grazing over the segment (NaN when not watched).
    pub grazing_distance: f64,
}

/// The circle's map over an integrator (module docs): G(x_0) = x_0 + x_M − Σ_j w_j x_j, whose
/// fixed point is the circle's node at θ = 0. One iterate integrates M drive periods from
/// τ = 0; only n = 1 iterate is defined.
pub(crate) struct CircleMap<'a> {
    integ: &'a mut dyn Integrator,
    nodes: CircleNodes,
    /// The last linearised segment ([`DiscreteMap::linearise`] keeps it: a Newton solve ends
    /// with a linearisation at its solution, whose monodromy matrices the circle's stability
    /// reads).
    last: Option<Segment>,
}

impl<'a> CircleMap<'a> {
    /// The circle's map on `nodes` over `integ` (at its system's parameters; the drive period
    /// T = 2π/Ω of the primary drive).
    pub(crate) fn new(integ: &'a mut dyn Integrator, nodes: CircleNodes) -> Self {
        CircleMap {
            integ,
            nodes,
            last: None,
        }
    }

    /// The primary drive's period T = 2π/Ω (dimensionless τ).
    fn period(&self) -> f64 {
        TAU / self.integ.system().omega()
    }

    /// The node states x_0 … x_{M−1} and x_M = P(x_{M−1}), `M + 1` states `[2N]`, from x_0.
    ///
    /// # Errors
    /// [`SimError`] from the integrator.
    pub(crate) fn segment(&mut self, x0: &DVector<f64>) -> Result<Vec<DVector<f64>>, SimError> {
        let t = self.period();
        let mut xs = vec![x0.clone()];
        for k in 0..self.nodes.len() {
            let next = flow_state(&mut *self.integ, k as f64 * t, &xs[k], (k + 1) as f64 * t)?;
            xs.push(next);
        }
        Ok(xs)
    }

    /// The segment from x_0 with its linearisation: each period's flow with its monodromy
    /// matrix ([`crate::maps::flow`]), the distance to grazing when `grazing` (else NaN).
    ///
    /// # Errors
    /// [`SimError`] from the integrator.
    pub(crate) fn linearised_segment(
        &mut self,
        x0: &DVector<f64>,
        grazing: bool,
    ) -> Result<Segment, SimError> {
        let (t, m, d) = (self.period(), self.nodes.len(), x0.len());
        let mut seg = Segment {
            states: vec![x0.clone()],
            monodromy: vec![DMatrix::identity(d, d)],
            switchings: Vec::with_capacity(m),
            contacts: 0,
            contact_time: 0.0,
            grazing_distance: if grazing { f64::INFINITY } else { f64::NAN },
        };
        for k in 0..m {
            let (t0, t1) = (k as f64 * t, (k + 1) as f64 * t);
            let step = flow(&mut *self.integ, t0, &seg.states[k], t1, None, grazing)?;
            seg.monodromy.push(&step.jacobian * &seg.monodromy[k]);
            seg.states.push(step.state);
            seg.switchings.push(step.switchings);
            seg.contacts += step.contacts;
            seg.contact_time += step.contact_time;
            seg.grazing_distance = seg.grazing_distance.min(step.grazing_distance);
        }
        Ok(seg)
    }

    /// The linearised segment from `x0`: the one the last [`DiscreteMap::linearise`] computed
    /// when it started at `x0`, else a new one ([`Self::linearised_segment`], grazing not
    /// watched).
    ///
    /// # Errors
    /// [`SimError`] from the integrator.
    pub(crate) fn segment_at(&mut self, x0: &DVector<f64>) -> Result<Segment, SimError> {
        match self.last.take() {
            Some(seg) if &seg.states[0] == x0 => Ok(seg),
            _ => self.linearised_segment(x0, false),
        }
    }

    /// Σ_j w_j x_j of node states `xs` (the interpolant at θ_M).
    fn closure(&self, xs: &[DVector<f64>]) -> DVector<f64> {
        let mut u = DVector::zeros(xs[0].len());
        for (w, x) in self.nodes.closure.iter().zip(xs) {
            u.axpy(*w, x, 1.0);
        }
        u
    }

    fn one_iterate(n: usize) -> Result<(), SimError> {
        if n == 1 {
            Ok(())
        } else {
            Err(SimError::out_of_range(
                "n",
                n,
                "must be 1 (the invariant circle's map has one iterate)",
            ))
        }
    }
}

impl DiscreteMap for CircleMap<'_> {
    fn dim(&self) -> usize {
        self.integ.system().dim()
    }

    fn periods(&self) -> usize {
        self.nodes.len()
    }

    fn duration(&self) -> f64 {
        self.nodes.len() as f64 * self.period()
    }

    fn iterate(&mut self, z: &DVector<f64>, n: usize) -> Result<DVector<f64>, SimError> {
        Self::one_iterate(n)?;
        let xs = self.segment(z)?;
        let m = self.nodes.len();
        Ok(z + &xs[m] - self.closure(&xs[..m]))
    }

    fn linearise(
        &mut self,
        z: &DVector<f64>,
        n: usize,
        _grazing: bool,
    ) -> Result<FlowMap, SimError> {
        Self::one_iterate(n)?;
        // grazing is watched whether asked or not: a few evaluations of V_T per step against
        // a pass of its own at the solution ([`DiscreteMap::grazing_distance`] reads it)
        let seg = self.linearised_segment(z, true)?;
        let (m, d) = (self.nodes.len(), z.len());
        // F = x_M − Σ w_j x_j and ∂F = Φ_M − Σ w_j Φ_j
        let mut f = seg.states[m].clone();
        let mut df = seg.monodromy[m].clone();
        for (k, w) in self.nodes.closure.iter().enumerate() {
            f.axpy(-w, &seg.states[k], 1.0);
            df -= &seg.monodromy[k] * *w;
        }
        let jacobian = DMatrix::identity(d, d) + df;
        let log_volume = jacobian.determinant().abs().ln();
        let map = FlowMap {
            state: z + f,
            jacobian,
            switchings: seg.switchings.iter().sum(),
            contacts: seg.contacts,
            grazing_distance: seg.grazing_distance,
            contact_time: seg.contact_time,
            log_volume,
            param_derivative: None,
        };
        self.last = Some(seg);
        Ok(map)
    }

    /// The smallest distance to grazing over the segment's periods: the one the last
    /// linearisation watched when it started at `z` (the same steps and searches, so the same
    /// value), else [`crate::maps::flow::grazing_distance`] of each period, without the
    /// Jacobian.
    fn grazing_distance(&mut self, z: &DVector<f64>, n: usize) -> Result<f64, SimError> {
        Self::one_iterate(n)?;
        if let Some(seg) = &self.last {
            if &seg.states[0] == z && !seg.grazing_distance.is_nan() {
                return Ok(seg.grazing_distance);
            }
        }
        let t = self.period();
        // the node states: the last linearisation's when it started at z (a Newton solve
        // measures grazing at its solution, where it has just linearised), else a new segment
        let xs = match &self.last {
            Some(seg) if &seg.states[0] == z => seg.states.clone(),
            _ => self.segment(z)?,
        };
        let mut graze = f64::INFINITY;
        for (k, x) in xs.iter().take(self.nodes.len()).enumerate() {
            let (t0, t1) = (k as f64 * t, (k + 1) as f64 * t);
            graze = graze.min(grazing_distance(&mut *self.integ, t0, x, t1)?);
        }
        Ok(graze)
    }

    fn check_state(&self, name: &'static str, z: &DVector<f64>) -> Result<(), SimError> {
        self.integ.system().check_state(name, z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The weights against closed forms: the interpolant through M = 7 nodes of ρ = 27/100
    /// reproduces every trigonometric polynomial of degree ≤ 3, so the closure weights give
    /// its value at θ_M and the quadrature weights its mean exactly; nodes that close the
    /// period (25/4 on 4 nodes) have w = e_0 and q_j = 1/M.
    #[test]
    fn weights_reproduce_trigonometric_polynomials() {
        let nodes = CircleNodes::new(27, 100, 7).unwrap();
        assert!(!nodes.exact);
        let theta_m = TAU * ((7 * 27) % 100) as f64 / 100.0;
        for (f, exact_mean) in [
            (
                Box::new(|t: f64| (2.0 * t).cos()) as Box<dyn Fn(f64) -> f64>,
                0.0,
            ),
            (Box::new(|t: f64| (3.0 * t).sin() + 0.5), 0.5),
            (Box::new(|t: f64| 1.0 + t.cos() * t.sin()), 1.0),
        ] {
            let at: f64 = nodes
                .closure
                .iter()
                .zip(&nodes.angles)
                .map(|(w, &a)| w * f(a))
                .sum();
            assert!((at - f(theta_m)).abs() < 1e-12, "{at} {}", f(theta_m));
            let mean: f64 = nodes
                .quadrature
                .iter()
                .zip(&nodes.angles)
                .map(|(w, &a)| w * f(a))
                .sum();
            assert!((mean - exact_mean).abs() < 1e-12, "{mean}");
        }
        // a closed period: w = e_0 and q_j = 1/M
        let exact = CircleNodes::new(25, 4, 4).unwrap();
        assert!(exact.exact);
        assert_eq!(exact.closure, vec![1.0, 0.0, 0.0, 0.0]);
        assert_eq!(exact.quadrature, vec![0.25; 4]);
    }

    /// 27/100 = [0; 3, 1, 2, 2, 1, 2]: convergent denominators 3, 4, 11, 26, 37, 100 and the
    /// semiconvergents' 1, 2, 7, 15, 63 between them.
    #[test]
    fn node_counts_are_convergent_denominators() {
        assert_eq!(node_count(627, 100, 20), 26);
        assert_eq!(node_count(627, 100, 12), 15);
        assert_eq!(node_count(627, 100, 30), 37);
        assert_eq!(node_count(627, 100, 38), 63);
        assert_eq!(node_count(627, 100, 64), 100);
        assert_eq!(node_count(25, 4, 20), 4);
        assert_eq!(node_count(627, 100, 200), 100);
    }
}
