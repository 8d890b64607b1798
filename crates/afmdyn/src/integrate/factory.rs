//! Choosing and building an integrator: [`IntegratorKind`] (the name a request or the CLI gives,
//! [`IntegratorKind::resolve`] for `auto`), [`IntegratorOptions`], the checks of the options and
//! of the start ([`check_tolerance`], [`check_start`], [`check_buildable`]) and the factory
//! [`build`], the one place that imports every integrator.

use super::{adaptive, exact, rk4, split, taylor, Integrator};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::SweepParam;
use crate::system::Region;
use exact::PropagatorCache;
use nalgebra::DVector;
use serde::{Deserialize, Serialize};
use std::str::FromStr;

/// Which integrator to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "kebab-case")]
pub enum IntegratorKind {
    /// The exact propagator for the linear law, the split integrator for Hertz and impact, the
    /// Taylor integrator for DMT (default; [`IntegratorKind::resolve`]).
    #[default]
    Auto,
    /// Exact piecewise-linear propagation (linear law only).
    Exact,
    /// Fixed-step RK4 with located switchings.
    Rk4,
    /// Fixed-step RK4 choosing the region per stage from sign(V_T), as in the paper.
    Rk4Naive,
    /// Adaptive DOP853 oracle with terminal events.
    Adaptive,
    /// Exact free flight; in contact the Taylor integrator (Hertz) or adaptive DOP853 (the
    /// linear law, the impact law's sticking) ([`split::Split`]; every law but DMT).
    Split,
    /// A Taylor series method of high order ([`taylor::Taylor`]): DMT's free flight in τ, the
    /// Hertz and DMT contact in a regularising time σ (dτ = 2√δ dσ) in which the δ^{3/2} force
    /// is a polynomial; Hertz and DMT only.
    Taylor,
}

impl FromStr for IntegratorKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(IntegratorKind::Auto),
            "exact" => Ok(IntegratorKind::Exact),
            "rk4" => Ok(IntegratorKind::Rk4),
            "rk4-naive" | "rk4_naive" => Ok(IntegratorKind::Rk4Naive),
            "adaptive" | "dop853" => Ok(IntegratorKind::Adaptive),
            "split" => Ok(IntegratorKind::Split),
            "taylor" => Ok(IntegratorKind::Taylor),
            _ => Err(format!(
                "integrator '{s}': expected auto, exact, rk4, rk4-naive, adaptive, split or \
                 taylor"
            )),
        }
    }
}

/// The range of an integrator tolerance ([`IntegratorOptions::tolerance`]), checked by
/// [`build`] for every integrator, those that ignore it (the exact propagator, RK4) included:
/// below 1e-16 a relative tolerance is beneath a double's resolution (the steps would shrink
/// without end), above 1e-3 it is no longer an accuracy.
pub const TOLERANCE_RANGE: (f64, f64) = (1e-16, 1e-3);

/// Check `tol` against [`TOLERANCE_RANGE`].
///
/// # Errors
/// [`SimError::OutOfRange`] naming `tolerance`.
pub fn check_tolerance(tol: f64) -> Result<(), SimError> {
    if tol.is_finite() && (TOLERANCE_RANGE.0..=TOLERANCE_RANGE.1).contains(&tol) {
        Ok(())
    } else {
        Err(SimError::out_of_range(
            "tolerance",
            crate::error::number(tol),
            "must be in [1e-16, 1e-3] (the integrator's relative and absolute tolerance)",
        ))
    }
}

/// Options shared by the integrators.
#[derive(Debug, Clone, PartialEq)]
pub struct IntegratorOptions {
    /// Which integrator.
    pub kind: IntegratorKind,
    /// Steps per drive period: a lower bound for `exact` (its grid is refined to resolve the
    /// fastest mode, and made a multiple of this value), the fixed step for `rk4`.
    pub steps_per_period: usize,
    /// Relative and absolute tolerance of the adaptive oracle.
    pub tolerance: f64,
    /// The exact propagator's cache every build with these options shares (the exact and the
    /// split integrator's free flight; [`PropagatorCache`]): options cloned for the tasks of one
    /// request share it; [`IntegratorOptions::default`] starts a new one. Results do not depend
    /// on it.
    pub cache: PropagatorCache,
}

impl IntegratorKind {
    /// The concrete integrator for `model`: [`IntegratorKind::Auto`] resolves to `Exact` for an
    /// affine (linear-law) model (under a multifrequency drive,
    /// [`crate::params::Params::drive_components`], to `Taylor` for Hertz and DMT and to
    /// `Adaptive` for the others), to `Split` for a law without force in free flight (Hertz,
    /// JKR, capillary, impact with r > 0), to `Adaptive` for the plastic impact law r = 0 (whose free flights
    /// all start tangentially), for the electrostatic law and for a law with internal states
    /// (SLS), and to `Taylor` for DMT; other kinds are returned as given.
    /// ([`build`] falls back from `Split` to `Adaptive` for `Auto` where the exact free flight
    /// cannot be built: Ω at an undamped resonance of the free beam, or a grid beyond its
    /// budget.)
    pub fn resolve(self, model: &CantileverModel) -> IntegratorKind {
        match self {
            // a law with internal states (the SLS sample): only the adaptive integrator carries
            // them
            IntegratorKind::Auto if model.law().internal_states() > 0 => IntegratorKind::Adaptive,
            // a multifrequency drive: the Taylor integrator for Hertz and DMT (its series carry
            // every component), else adaptive (the exact and split integrators propagate one
            // harmonic drive)
            IntegratorKind::Auto if model.params().is_multifrequency() => {
                let p = model.params();
                if model.law().jet(p.alpha4, p.alpha6).is_some() {
                    IntegratorKind::Taylor
                } else {
                    IntegratorKind::Adaptive
                }
            }
            IntegratorKind::Auto if model.law().is_affine() => IntegratorKind::Exact,
            // a plastic impact law (r = 0): every free flight starts tangentially (V̇_T⁺ = 0),
            // which the split integrator hands to the adaptive half anyway
            IntegratorKind::Auto if model.law().restitution() == Some(0.0) => {
                IntegratorKind::Adaptive
            }
            IntegratorKind::Auto if split::Split::applies(model) => IntegratorKind::Split,
            // the electrostatic law: its 1/(d(d + R)) force is not in the Taylor integrator's
            // recurrences; the adaptive DOP853 integrates it with events
            IntegratorKind::Auto
                if model
                    .law()
                    .jet(model.params().alpha4, model.params().alpha6)
                    .is_none() =>
            {
                IntegratorKind::Adaptive
            }
            // DMT: its van der Waals force acts in free flight
            IntegratorKind::Auto => IntegratorKind::Taylor,
            k => k,
        }
    }
}

impl Default for IntegratorOptions {
    fn default() -> Self {
        IntegratorOptions {
            kind: IntegratorKind::Auto,
            steps_per_period: 1,
            tolerance: 1e-12,
            cache: PropagatorCache::new(),
        }
    }
}

/// Check that an integrator of `opts` can be built for `params` at the rest state — [`build`]'s
/// up-front budgets and support checks (the adaptive stepper's steps per drive period, RK4
/// with impacts, the exact propagator's limits) — without integrating. Studies of many runs
/// (attractor censuses, basin maps, sweeps) call it in their validation, so that a refusal is
/// one input error rather than every run failing alike.
///
/// # Errors
/// As [`CantileverModel::new`] and [`build`].
pub fn check_buildable(
    params: &crate::params::Params,
    opts: IntegratorOptions,
) -> Result<(), SimError> {
    let model = CantileverModel::new(params)?;
    build(&model, opts, 0.0, &model.rest()).map(|_| ())
}

/// [`check_buildable`] at the smallest and the largest of `values` of `param` over `base` (the
/// adaptive step budget grows as Ω falls and as the stiffness grows, so the ends of a sweep
/// bound it).
///
/// # Errors
/// As [`check_buildable`].
pub fn check_buildable_over(
    base: &crate::params::Params,
    param: SweepParam,
    values: &[f64],
    opts: IntegratorOptions,
) -> Result<(), SimError> {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    for v in [lo, hi] {
        if v.is_finite() {
            check_buildable(&base.with(param, v), opts.clone())?;
        }
    }
    Ok(())
}

/// Build an integrator of `model` starting at (τ, z) ([`IntegratorKind::Auto`] resolved by
/// [`IntegratorKind::resolve`]).
///
/// # Errors
/// [`SimError`] for invalid options (a tolerance outside [`TOLERANCE_RANGE`] whatever the
/// integrator) or initial state; [`SimError::Unsupported`] for the exact
/// propagator with a nonlinear law, or RK4 with the impact law.
pub fn build(
    model: &CantileverModel,
    opts: IntegratorOptions,
    tau: f64,
    z: &DVector<f64>,
) -> Result<Box<dyn Integrator>, SimError> {
    check_steps_per_period(opts.steps_per_period)?;
    check_tolerance(opts.tolerance)?;
    // up-front budgets: a start at or beyond the divergence threshold, and (adaptive) a period
    // that would need more steps than the budget, are refused before any work is done
    check_start(z)?;
    let kind = opts.kind.resolve(model);
    check_supported(model, kind)?;
    let mut integ: Box<dyn Integrator> = match kind {
        IntegratorKind::Auto | IntegratorKind::Exact => Box::new(exact::ExactPropagator::try_with(
            model,
            exact::ExactOptions {
                min_steps_per_period: opts.steps_per_period,
                cache: Some(opts.cache.clone()),
                ..exact::ExactOptions::default()
            },
        )?),
        IntegratorKind::Rk4 => Box::new(rk4::Rk4::new(model, opts.steps_per_period, true)),
        IntegratorKind::Rk4Naive => Box::new(rk4::Rk4::new(model, opts.steps_per_period, false)),
        IntegratorKind::Taylor => Box::new(taylor::Taylor::new(model, opts.tolerance)?),
        IntegratorKind::Adaptive | IntegratorKind::Split => {
            if !(opts.tolerance.is_finite() && opts.tolerance > 0.0 && opts.tolerance < 1.0) {
                return Err(SimError::out_of_range(
                    "tolerance",
                    opts.tolerance,
                    "must be in (0, 1)",
                ));
            }
            let adaptive = || Box::new(adaptive::Adaptive::new(model, opts.tolerance));
            if kind == IntegratorKind::Adaptive {
                adaptive()
            } else {
                let cache = Some(opts.cache.clone());
                match split::Split::try_new(model, opts.steps_per_period, opts.tolerance, cache) {
                    Ok(s) => Box::new(s),
                    Err(SimError::OutOfRange { .. } | SimError::Budget { .. })
                        if opts.kind == IntegratorKind::Auto =>
                    {
                        adaptive()
                    }
                    Err(e) => return Err(e),
                }
            }
        }
    };
    integ.reset(tau, z)?;
    Ok(integ)
}

/// The steps per drive period a stepping integrator of `kind` (adaptive, split, Taylor) needs
/// on `model` at most: the fastest rate of its regions (and of an SLS Maxwell arm) times the
/// drive period; `None` for the exact and RK4 integrators, whose steps the drive sets.
pub(crate) fn steps_per_period(model: &CantileverModel, kind: IntegratorKind) -> Option<f64> {
    if !matches!(
        kind,
        IntegratorKind::Adaptive | IntegratorKind::Split | IntegratorKind::Taylor
    ) {
        return None;
    }
    let rate = [Region::Free, Region::Contact]
        .iter()
        .map(|&r| model.dynamics(r).a.norm())
        .fold(0.0, f64::max)
        // the SLS Maxwell arm: its relaxation rate and its spring at the tip
        .max(model.zener().map_or(0.0, |zn| {
            zn.relaxation_rate() + zn.maxwell * model.tip_mobility().norm()
        }));
    Some(rate * model.period())
}

/// Whether an integrator of `kind` can integrate `model`: an adaptive stepper's steps per drive
/// period within [`crate::params::ADAPTIVE_STEPS_BUDGET`], one harmonic drive for the exact and
/// split integrators, no internal states of the law but for the adaptive one, and neither a
/// contact's neck nor impacts for RK4.
///
/// # Errors
/// [`SimError::Budget`], [`SimError::OutOfRange`] naming `integrator`, or
/// [`SimError::Unsupported`].
fn check_supported(model: &CantileverModel, kind: IntegratorKind) -> Result<(), SimError> {
    if let Some(steps) = steps_per_period(model, kind) {
        if steps.is_nan() || steps > crate::params::ADAPTIVE_STEPS_BUDGET {
            return Err(SimError::Budget {
                what: match kind {
                    IntegratorKind::Taylor => "taylor integrator",
                    IntegratorKind::Split => "split integrator",
                    _ => "adaptive integrator",
                },
                needed: format!("about {steps:.2e} steps per drive period"),
                budget: "1e7".into(),
                hint: "use the exact integrator, or a larger Ω or softer contact",
            });
        }
    }
    if model.params().is_multifrequency()
        && matches!(kind, IntegratorKind::Exact | IntegratorKind::Split)
    {
        return Err(SimError::out_of_range(
            "integrator",
            format!("{kind:?}").to_lowercase(),
            "must be adaptive, taylor, auto or rk4 under a multifrequency drive: the exact and \
             split integrators propagate one harmonic drive",
        ));
    }
    if kind != IntegratorKind::Adaptive && model.law().internal_states() > 0 {
        return Err(SimError::Unsupported {
            integrator: match kind {
                IntegratorKind::Exact => "exact",
                IntegratorKind::Split => "split",
                IntegratorKind::Taylor => "taylor",
                _ => "rk4",
            },
            law: model.law().name(),
            hint: "the sample's internal state (the SLS dashpot's extension) and its surface's \
                   recovery are carried by the adaptive integrator only: use integrator = \
                   \"auto\" (or \"adaptive\")",
        });
    }
    if matches!(kind, IntegratorKind::Rk4 | IntegratorKind::Rk4Naive)
        && model.release_distance() > 0.0
    {
        return Err(SimError::Unsupported {
            integrator: "rk4",
            law: model.law().name(),
            hint: "the contact's neck makes the region depend on the history, which RK4's \
                   region from the sign of V_T cannot follow: use integrator = \"auto\" (or \
                   \"adaptive\")",
        });
    }
    if matches!(kind, IntegratorKind::Rk4 | IntegratorKind::Rk4Naive)
        && model.law().restitution().is_some()
    {
        return Err(SimError::Unsupported {
            integrator: "rk4",
            law: model.law().name(),
            hint: "impacts need located events with jumps: use integrator = \"adaptive\" (or \"auto\")",
        });
    }
    Ok(())
}

/// Refuse a start at or beyond the divergence threshold of the integrators (|z| ≥ 1e12,
/// `crate::params::STATE_NORM_MAX`), as [`build`] does before any work.
///
/// # Errors
/// [`SimError::OutOfRange`] naming the initial state.
pub fn check_start(z: &DVector<f64>) -> Result<(), SimError> {
    let norm = z.norm(); // +∞ when the squares overflow; NaN entries are rejected by reset
    if z.iter().all(|v| v.is_finite()) && norm >= crate::params::STATE_NORM_MAX {
        return Err(SimError::out_of_range(
            "initial state",
            if norm.is_finite() {
                format!("|z| = {norm:e}")
            } else {
                "|z| > 1e154".to_string()
            },
            "must be < 1e12 (the divergence threshold of the integrators)",
        ));
    }
    Ok(())
}

fn check_steps_per_period(steps: usize) -> Result<(), SimError> {
    if steps == 0 || steps > 10_000_000 {
        return Err(SimError::out_of_range(
            "steps_per_period",
            steps,
            "must be in 1..=10000000",
        ));
    }
    Ok(())
}
