//! A point of a stepped sweep measured on the invariant circle of a two-frequency drive
//! ([`crate::analysis::torus`]; Schilder, Osinga & Vogt, *SIAM J. Appl. Dyn. Syst.* 4 (2005)
//! 459): the point mode of a drive whose common period is long (f₂/f₁ = 6.27 = 627/100 repeats
//! only every 100 drive periods, which every exact orbit spans).
//!
//! At each value the circle is continued from the previous point's: its node state x_0
//! (the state at τ = 0, [`CurvePoint::state`]) predicted from the previous points of the
//! branch (the quadratic or secant extrapolation of the orbits' curve), Broyden's updates
//! from the previous circle's map Jacobian ([`CirclePoint::jacobian`];
//! [`continue_circle`]), else Newton ([`invariant_circle`]). Each drive component's
//! amplitude, phase, virial and dissipated energy come from the circle ([`observe_circle`]),
//! its stability from the contraction of its linearisation
//! ([`crate::analysis::torus::InvariantCircle::contraction`]).
//!
//! On a circle of rational rotation p/q the motion repeats after q periods: the point is the
//! periodic orbit of the common period, to the circle's interpolation error (period 1 in
//! common periods, its state the orbit's at τ = 0). Where the circle is not found, lands
//! away from the previous point (a jump), is unstable, or is not smooth (a node within
//! `crate::analysis::torus::NEAR_GRAZING` of grazing: a touch appears at some phases of the
//! second drive and not at others, and the interpolation converges only algebraically), the
//! point is the exact orbit (as without circles: continued, halved, or settled by
//! the transient), flagged with [`Fallback`]; the curve's warnings count them. Inside a stretch
//! of such points (not smooth or not found) the circle is tried only at every
//! `STRETCH_RETRY`-th point ([`Fallback::Skipped`]).

use super::point::{orbit_point, prediction_slope};
use super::{relative_gap, CurvePoint, Reached, SteppedSpec};
use crate::analysis::torus::{
    continue_circle, invariant_circle, observe_circle, CircleOptions, InvariantCircle,
};
use crate::error::{within, SimError};
use crate::maps::circle::MAX_NODES;
use crate::model::CantileverModel;
use crate::params::Params;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Common periods (in primary drive periods) beyond which a two-frequency approach curve is
/// measured on invariant circles by default (`uses_torus`): an exact orbit then spans more
/// than this many periods, a circle `CURVE_NODES` or a few more (at 6.25 = 25/4 the orbit
/// spans 4 and is kept; at 94/15, 15; at 6.27 = 627/100, 100 against a circle's 37).
pub const TORUS_PERIODS: u64 = 32;

/// Nodes asked for by a curve measured on invariant circles ([`TorusOptions::default`]): 37 at
/// 627/100 (the convergent 10/37 of 0.27), whose points agree with the exact orbits' to 1e-7
/// of each free amplitude on the eigenmode lever in the repulsive regime, where 26 nodes leave
/// 2.5e-6 (`tests/torus.rs`; the N = 3 beam needs 63, asked by 38).
pub(crate) const CURVE_NODES: usize = 30;

/// The options of a curve measured on invariant circles ([`SteppedSpec::torus`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TorusOptions {
    /// Nodes asked for, in 1..=`MAX_NODES`
    /// (`crate::maps::circle::node_count` rounds up to a convergent's or semiconvergent's
    /// denominator of the rotation: 30 gives 37 at 627/100).
    pub nodes: usize,
}

impl Default for TorusOptions {
    fn default() -> Self {
        TorusOptions { nodes: CURVE_NODES }
    }
}

impl TorusOptions {
    /// Check the range of the nodes.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `torus.nodes`.
    pub fn check(&self) -> Result<(), SimError> {
        within(
            "torus.nodes",
            self.nodes,
            1..=MAX_NODES,
            "must be in 1..=1000 (nodes of the invariant circle)",
        )?;
        Ok(())
    }
}

/// Whether an approach curve of `base` is measured on invariant circles by default: a drive of
/// two frequencies (one further component) whose common period spans more than
/// [`TORUS_PERIODS`] drive periods and has a periodic orbit to fall back on (not
/// quasi-periodic, [`Params::is_quasiperiodic`]).
pub(crate) fn uses_torus(base: &Params) -> bool {
    base.components().count() == 1
        && base.common_periods() > TORUS_PERIODS
        && !base.is_quasiperiodic()
}

/// Check that `base` has a drive the invariant circle takes: two frequencies (one further
/// component) whose common period has a periodic orbit to fall back on.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `torus`.
pub(super) fn rotation_of(base: &Params) -> Result<(), SimError> {
    if base.components().count() != 1 {
        return Err(SimError::out_of_range(
            "torus",
            base.components().count() + 1,
            "drive components: the invariant circle is for a drive of two frequencies",
        ));
    }
    if base.is_quasiperiodic() {
        return Err(SimError::out_of_range(
            "torus",
            "quasi-periodic drive",
            "needs a common period of at most 1000 drive periods (the exact orbit it falls \
             back on): measure a quasi-periodic drive by the time average",
        ));
    }
    Ok(())
}

/// The invariant circle found at a point: what its continuation at the next value needs, and
/// its stability (also at a point that fell back on the exact orbit, [`CurvePoint::fallback`],
/// when the circle converged there).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CirclePoint {
    /// M, the circle's nodes (its first node's state is the point's state).
    pub nodes: usize,
    /// ρ(Φ_M)^{1/M}: the contraction per drive period of its linearisation (< 1: stable).
    pub contraction: f64,
    /// The smallest distance to grazing of its nodes' periods (model length units).
    pub grazing_distance: f64,
    /// ∂G at the solution (2N×2N), G the circle's map: Broyden's first Jacobian at the next
    /// value.
    pub jacobian: DMatrix<f64>,
}

/// Why a point of a curve measured on invariant circles is the exact orbit instead.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Fallback {
    /// Neither Broyden's updates nor Newton found the circle.
    NotFound,
    /// The circle is not smooth: a node near grazing.
    NotSmooth,
    /// The circle found is unstable.
    Unstable,
    /// The circle found is farther than the jump tolerance from the previous point.
    Jump,
    /// The circle was not tried: the point lies in a grazing stretch (`STRETCH_RETRY`).
    Skipped,
}

impl Fallback {
    /// Its name in documents and warnings.
    pub fn name(self) -> &'static str {
        match self {
            Fallback::NotFound => "not-found",
            Fallback::NotSmooth => "not-smooth",
            Fallback::Unstable => "unstable",
            Fallback::Jump => "jump",
            Fallback::Skipped => "skipped",
        }
    }
}

/// Inside a grazing stretch — the point just before fell back on the exact orbit because its
/// circle was not smooth or not found, or was skipped — the circle is tried again only at
/// every `STRETCH_RETRY`-th point: after `STRETCH_RETRY − 1` skipped points in a row; the
/// others go straight to the exact orbit ([`Fallback::Skipped`]). A circle that crosses
/// grazing stays non-smooth over a range of z_c (while mode 2's ripple touches the sample at
/// some phases and not at others), and each try costs a circle's Newton on top of the orbit;
/// past the stretch's end at most `STRETCH_RETRY − 1` points are exact orbits that a circle
/// would have measured. At most 4: a point sees the last 3 points of its sweep.
pub(crate) const STRETCH_RETRY: usize = 4;

/// Whether the point after `history` skips its circle ([`STRETCH_RETRY`]).
fn skips_circle(history: &[CurvePoint]) -> bool {
    let in_stretch = history.last().is_some_and(|p| {
        matches!(
            p.fallback,
            Some(Fallback::NotSmooth | Fallback::NotFound | Fallback::Skipped)
        )
    });
    let skipped = history
        .iter()
        .rev()
        .take_while(|p| p.fallback == Some(Fallback::Skipped))
        .count();
    in_stretch && skipped < STRETCH_RETRY - 1
}

/// The circle at `value`: continued from the previous point's circle by Broyden's updates
/// from the predicted node state, else Newton from it.
fn find_circle(
    spec: &SteppedSpec,
    model: &CantileverModel,
    opts: &CircleOptions,
    value: f64,
    history: &[CurvePoint],
) -> Result<InvariantCircle, SimError> {
    let guess: DVector<f64> = match history.last() {
        Some(p) => match prediction_slope(history, value) {
            Some(s) => &p.state + s * (value - p.value),
            None => p.state.clone(),
        },
        None => model.rest(),
    };
    let integ = spec.integrator.clone();
    let previous = history
        .last()
        .and_then(|p| p.circle.as_ref())
        .filter(|c| c.jacobian.nrows() == guess.len());
    match previous {
        Some(c) => continue_circle(model, integ.clone(), &guess, &c.jacobian, opts)
            .or_else(|_| invariant_circle(model, integ, &guess, opts)),
        None => invariant_circle(model, integ, &guess, opts),
    }
}

/// The point at `value` on the invariant circle continued from the last point of `history`,
/// or the exact orbit with the reason ([`Fallback`]; module docs).
///
/// # Errors
/// [`SimError::Params`] for an invalid value; [`SimError`] from the integrator or the
/// observables.
pub(super) fn torus_point(
    spec: &SteppedSpec,
    opts: &TorusOptions,
    value: f64,
    history: &[CurvePoint],
) -> Result<CurvePoint, SimError> {
    let prev = history.last();
    let model = CantileverModel::new(&spec.base.with(spec.param, value))?;
    let copts = CircleOptions {
        nodes: opts.nodes,
        shooting: spec.newton,
    };
    if skips_circle(history) {
        let mut p = orbit_point(spec, value, history)?;
        p.fallback = Some(Fallback::Skipped);
        return Ok(p);
    }
    let circle = find_circle(spec, &model, &copts, value, history);
    let why = match &circle {
        Err(_) => Some(Fallback::NotFound),
        Ok(c) if !c.smooth => Some(Fallback::NotSmooth),
        Ok(c) if !c.stable => Some(Fallback::Unstable),
        Ok(c) if prev.is_some_and(|p| relative_gap(&c.states[0], &p.state) > spec.jump_tol) => {
            Some(Fallback::Jump)
        }
        Ok(_) => None,
    };
    let circle = match (circle, why) {
        (Ok(c), None) => c,
        (c, why) => {
            let mut p = orbit_point(spec, value, history)?;
            p.fallback = why;
            // a circle that converged (not smooth, unstable, or away) still carries its map's
            // Jacobian for the next point's Broyden updates
            p.circle = c.ok().map(circle_point);
            return Ok(p);
        }
    };
    let observables = observe_circle(
        &model,
        spec.integrator.clone(),
        &circle,
        spec.observables.harmonics,
    )?;
    Ok(CurvePoint {
        value,
        period: Some(1),
        state: circle.states[0].clone(),
        multipliers: Vec::new(),
        monodromy: None,
        stable: circle.stable,
        reached: if prev.is_some() {
            Reached::Continued
        } else {
            Reached::Start
        },
        observables,
        tau: 0.0,
        average: None,
        circle: Some(circle_point(circle)),
        fallback: None,
        free_decay_wait: false,
    })
}

/// What a point keeps of its circle.
fn circle_point(c: InvariantCircle) -> CirclePoint {
    CirclePoint {
        nodes: c.nodes.len(),
        contraction: c.contraction,
        grazing_distance: c.grazing_distance,
        jacobian: c.jacobian,
    }
}

/// The warning of a curve measured on invariant circles: how many points are the exact orbit
/// and why (none: `None`).
pub(super) fn fallback_warning(points: &[&CurvePoint]) -> Option<String> {
    let mut counts: Vec<(Fallback, usize)> = Vec::new();
    for f in points.iter().filter_map(|p| p.fallback) {
        match counts.iter_mut().find(|(g, _)| *g == f) {
            Some((_, n)) => *n += 1,
            None => counts.push((f, 1)),
        }
    }
    if counts.is_empty() {
        return None;
    }
    let total: usize = counts.iter().map(|c| c.1).sum();
    let why = counts
        .iter()
        .map(|(f, n)| format!("{n} {}", f.name()))
        .collect::<Vec<_>>()
        .join(", ");
    Some(warning!(
        "curve.circle-fallback",
        "Nothing: those points are exact orbits; invariant_circle.fallback gives each \
         point's reason.",
        "{total} point(s) of the curve are the exact periodic orbit of the common period instead \
         of the invariant circle ({why}; not-smooth: a node near grazing, where a touch appears \
         at some phases of the second drive and not at others; skipped: not tried inside such \
         a stretch, tried again every {STRETCH_RETRY}th point): the per-point reason is in \
         invariant_circle.fallback"
    ))
}
