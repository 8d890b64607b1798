//! Quasi-periodic steady states of a two-frequency drive (bimodal AFM at a lever's true mode
//! ratio) as invariant circles of the stroboscopic map: [`invariant_circle`] finds the
//! circle by Newton on the map of `crate::maps::circle` (collocation on one orbit segment of
//! M drive periods, closed through the trigonometric interpolant; the module docs there give
//! the equations and their source), and [`observe_circle`] averages the AFM observables over
//! it — each component's amplitude, phase, virial and dissipated energy from the torus.
//!
//! A drive at r = 627/100 repeats only after 100 periods, so its periodic orbit costs 100
//! periods per Newton iteration; its circle on the 26 or 37 nodes of a convergent of 0.27
//! costs that many, with the interpolation's error instead of none. At a ratio whose period
//! is at most the nodes asked for, the circle is the periodic orbit itself (same equations).
//!
//! Stability: the circle attracts when the linear cocycle along it contracts. Its rate per
//! drive period, ρ(Φ_M)^{1/M} with Φ_M the monodromy matrix of the M-period segment (the
//! product of the one-period monodromy matrices and the saltation matrices of its events), is
//! [`InvariantCircle::contraction`]; for a closed period it is the largest Floquet multiplier's
//! modulus to the power 1/M.

use crate::analysis::observables::{observe_weighted, ObservableOptions, Observables};
use crate::analysis::shooting::{shoot, Guess, ShootingOptions, ShootingStrategy, GRAZING_TOL};
use crate::error::SimError;
use crate::integrate::{build, IntegratorOptions};
use crate::maps::circle::{node_count, CircleMap, CircleNodes};
use crate::maps::DiscreteMap;
use crate::model::CantileverModel;
use nalgebra::{DMatrix, DVector};

/// A node's distance to grazing below which the circle may cross a grazing bifurcation
/// between two nodes ([`InvariantCircle::smooth`]): on the test levers a node next to such a
/// crossing comes within 2e-3 (gap units) of grazing, a smooth circle's nodes stay beyond
/// 5e-2 (`tests/torus.rs`).
pub(crate) const NEAR_GRAZING: f64 = 1e-2;

/// Default number of nodes asked for: the circle takes the smallest convergent denominator of
/// the rotation at or above it ([`node_count`]).
pub(crate) const DEFAULT_NODES: usize = 24;

/// Options of [`invariant_circle`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CircleOptions {
    /// Nodes asked for (≥ 1; `node_count` rounds up to a convergent's or semiconvergent's
    /// denominator).
    pub nodes: usize,
    /// Newton's tolerance and iteration cap.
    pub shooting: ShootingOptions,
}

impl Default for CircleOptions {
    fn default() -> Self {
        CircleOptions {
            nodes: DEFAULT_NODES,
            shooting: ShootingOptions::default(),
        }
    }
}

/// An invariant circle of the stroboscopic map: its nodes, their states and its stability.
#[derive(Debug, Clone, PartialEq)]
pub struct InvariantCircle {
    /// The nodes (phases, closure and quadrature weights).
    pub nodes: CircleNodes,
    /// x_k = u(θ_k) at τ = kT, k = 0..M−1 (M states `[2N]`).
    pub states: Vec<DVector<f64>>,
    /// ∂G at the solution (2N×2N), G the circle's map (`CircleMap`), from its linearisation
    /// there: Broyden's first estimate when the circle is continued ([`continue_circle`]).
    pub jacobian: DMatrix<f64>,
    /// ‖F‖ after each Newton iteration.
    pub residuals: Vec<f64>,
    /// ρ(Φ_M)^{1/M}: the cocycle's contraction per drive period (module docs).
    pub contraction: f64,
    /// `contraction` < 1.
    pub stable: bool,
    /// Distance to grazing over the segment ([`crate::maps::flow::FlowMap::grazing_distance`]).
    pub grazing_distance: f64,
    /// `grazing_distance` < `GRAZING_TOL`: the circle may not be smooth there, and the
    /// interpolation's error not small.
    pub grazing: bool,
    /// Switchings (contacts formed and broken, impacts) in each node's drive period, `[M]`.
    pub switchings: Vec<usize>,
    /// Whether the circle is smooth as far as its nodes show: no node within `NEAR_GRAZING`
    /// of grazing. A circle that crosses a grazing bifurcation between two nodes (a touch of
    /// the sample appears at some phases of the second drive and not at others, as mode 2's
    /// ripple reaches the sample near the bottom of the first mode's swing; the number of
    /// switchings per period then changes along the circle) is only piecewise smooth, and its
    /// interpolation and quadrature converge algebraically with M (about 1e-5 of A₀ at 37
    /// nodes on the test lever, `tests/torus.rs`) instead of geometrically (below 1e-8).
    /// (The number of switchings in a node's period alone does not tell: it also changes when
    /// a contact straddles the section τ = kT.)
    pub smooth: bool,
}

/// The second drive component's frequency ratio p/q (the model's one further component).
///
/// # Errors
/// [`SimError::OutOfRange`] unless the drive has exactly one further component.
pub(crate) fn rotation(model: &CantileverModel) -> Result<(u64, u64), SimError> {
    let comps: Vec<_> = model.params().components().collect();
    match comps.as_slice() {
        [c] => Ok((u64::from(c.ratio[0]), u64::from(c.ratio[1]))),
        _ => Err(SimError::out_of_range(
            "drive_components",
            comps.len(),
            "must be one further drive component for an invariant circle (two frequencies)",
        )),
    }
}

/// The invariant circle of `model`'s two-frequency drive near `guess` (the state at τ = 0,
/// `[2N]`): Newton ([`shoot`]) on the circle's map of `opts.nodes` nodes
/// (`node_count`), its stability and its distance to grazing from the last Newton
/// linearisation (at the solution).
///
/// # Errors
/// [`SimError::OutOfRange`] for a drive without exactly one further component or nodes
/// outside 1..=1000; [`SimError::NoConvergence`] when Newton fails; [`SimError`] from the
/// integrator.
pub fn invariant_circle(
    model: &CantileverModel,
    integ: IntegratorOptions,
    guess: &DVector<f64>,
    opts: &CircleOptions,
) -> Result<InvariantCircle, SimError> {
    solve(model, integ, guess, opts, None)
}

/// The circle of `model` continued from a predicted node state `guess` (`[2N]`, at τ = 0; the
/// previous circle's first state, or a stepped curve's extrapolation from its previous points)
/// and an estimate `jacobian` (2N×2N) of its map's Jacobian ∂G (the previous circle's
/// [`InvariantCircle::jacobian`], at a nearby parameter value, on as many nodes): Broyden's
/// updates ([`ShootingStrategy::Broyden`]) by flows without the variational equations, and one
/// linearisation at the solution (its Jacobian, stability and distance to grazing) — a step of
/// an approach curve at the cost of about one Newton iteration.
///
/// # Errors
/// As [`invariant_circle`]; [`SimError::OutOfRange`] naming the monodromy estimate when
/// `jacobian` is not 2N×2N.
pub fn continue_circle(
    model: &CantileverModel,
    integ: IntegratorOptions,
    guess: &DVector<f64>,
    jacobian: &DMatrix<f64>,
    opts: &CircleOptions,
) -> Result<InvariantCircle, SimError> {
    solve(model, integ, guess, opts, Some(jacobian))
}

fn solve(
    model: &CantileverModel,
    integ: IntegratorOptions,
    guess: &DVector<f64>,
    opts: &CircleOptions,
    jacobian: Option<&DMatrix<f64>>,
) -> Result<InvariantCircle, SimError> {
    let (p, q) = rotation(model)?;
    if opts.nodes == 0 {
        return Err(SimError::out_of_range("nodes", 0, "must be ≥ 1"));
    }
    let nodes = CircleNodes::new(p, q, node_count(p, q, opts.nodes))?;
    let mut it = build(model, integ, 0.0, guess)?;
    let mut map = CircleMap::new(it.as_mut(), nodes.clone());
    // Newton's solution (whose last linearisation, at the solution, watched the distance to
    // grazing), or Broyden's, linearised once at the solution: its exact Jacobian (the next
    // point's first Broyden Jacobian), its distance to grazing and its monodromy matrices
    // from one segment
    let newton = opts.shooting.with_period(1);
    let (state, jacobian, residuals, graze) = match jacobian {
        None => {
            let o = shoot(&mut map, guess, &newton)?;
            (o.state, o.monodromy, o.residuals, o.grazing_distance)
        }
        Some(m0) => {
            let broyden = ShootingOptions {
                strategy: ShootingStrategy::Broyden,
                ..newton
            };
            let estimated = Guess::Estimated {
                state: guess,
                monodromy: m0,
            };
            let o = shoot(&mut map, estimated, &broyden)?;
            let lin = map.linearise(&o.state, 1, true)?;
            (o.state, lin.jacobian, o.residuals, lin.grazing_distance)
        }
    };
    let mut seg = map.segment_at(&state)?;
    let m = nodes.len();
    let radius = seg.monodromy[m]
        .complex_eigenvalues()
        .iter()
        .fold(0.0f64, |r, l| r.max(l.norm()));
    let contraction = radius.powf(1.0 / m as f64);
    seg.states.truncate(m);
    Ok(InvariantCircle {
        nodes,
        states: seg.states,
        jacobian,
        residuals,
        contraction,
        stable: contraction < 1.0,
        grazing_distance: graze,
        grazing: graze < GRAZING_TOL,
        smooth: graze >= NEAR_GRAZING,
        switchings: seg.switchings,
    })
}

/// The AFM observables averaged over the circle (`observe_weighted` over its M-period
/// segment with its quadrature weights): the primary's harmonics, each drive component's
/// amplitude, phase, virial and dissipated energy ([`Observables::components`]), the mean
/// force, the energy balance per mode; extremes over the segment. Per drive period 2π/Ω.
///
/// # Errors
/// As `observe_weighted`.
pub fn observe_circle(
    model: &CantileverModel,
    integ: IntegratorOptions,
    circle: &InvariantCircle,
    harmonics: usize,
) -> Result<Observables, SimError> {
    let mut it = build(model, integ, 0.0, &circle.states[0])?;
    let opts = ObservableOptions {
        periods: circle.nodes.len(),
        harmonics,
    };
    observe_weighted(it.as_mut(), &opts, &circle.nodes.quadrature)
}
