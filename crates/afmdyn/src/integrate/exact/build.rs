//! Building an [`ExactPropagator`]: the options, the grid refined until ‖Ã_s‖₂ h ≤ θ, and the
//! spectral, grid-exponential and forcing data (each from its cache when the inputs match).

use super::bound::BoundCols;
use super::cache::{cached, PropagatorCache};
use super::forcing::{forced, forcing_key, Forcing, FORCING_KEEP_BYTES};
use super::modal::Modes;
use super::search::TipPoly;
use super::series::LastStep;
use super::spectral::Spectral;
use super::tip::base_amp;
use super::{spectral, ExactPropagator, CHATTER_COUNT, CHATTER_WINDOW, THETA};
use crate::error::SimError;
use crate::integrate::grid::PeriodGrid;
use crate::integrate::ChatterWindow;
use crate::linalg::kernel;
use crate::model::CantileverModel;
use crate::system::Region;
use nalgebra::DVector;
use std::sync::Arc;

/// How the grid steps of a region are propagated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Propagation {
    /// Modal wherever the eigenvector basis is well conditioned (condition number ≤
    /// `MAX_MODAL_CONDITION` and residual at round-off), dense
    /// elsewhere (default): the faster path at every N measured, N = 1 included
    /// (`docs/performance.md`).
    #[default]
    Auto,
    /// Always the dense Φ_s (fixed-size kernel for N ≤ 6).
    Dense,
}

/// Build options of [`ExactPropagator::try_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct ExactOptions {
    /// The grid has a multiple of this many sub-steps per period (≥ 1).
    pub min_steps_per_period: usize,
    /// Propagation of the grid steps.
    pub propagation: Propagation,
    /// The cache whose spectral data, grid exponentials and forcing data of earlier builds
    /// with bit-identical inputs this build reuses and adds to — the same values a rebuild
    /// computes ([`PropagatorCache`]); `None`: everything computed afresh, nothing kept.
    pub cache: Option<PropagatorCache>,
}

impl Default for ExactOptions {
    fn default() -> Self {
        ExactOptions {
            min_steps_per_period: 1,
            propagation: Propagation::Auto,
            cache: None,
        }
    }
}

impl ExactPropagator {
    /// The cantilever model propagated (the exact propagator is the cantilever's own: it needs
    /// the affine regions of the linear law, eqs. 10–18).
    pub fn model(&self) -> &CantileverModel {
        &self.model
    }

    /// Build the propagator; the grid has a multiple of `min_steps_per_period` sub-steps per
    /// period, refined until ‖Ã_s‖₂ h ≤ θ in both regions.
    ///
    /// # Panics
    /// When the forced response is singular: Ω exactly at an undamped natural frequency
    /// (α3 = 0 and no contact damping), where no periodic particular solution exists.
    pub fn new(model: &CantileverModel, min_steps_per_period: usize) -> Self {
        Self::try_new(model, min_steps_per_period).expect("forced response exists")
    }

    /// As [`ExactPropagator::new`], with an error instead of a panic.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] for Ω at an undamped resonance (see [`ExactPropagator::new`]);
    /// [`SimError::Unsupported`] for a law that is not affine (only the linear law is).
    pub(crate) fn try_new(
        model: &CantileverModel,
        min_steps_per_period: usize,
    ) -> Result<Self, SimError> {
        Self::try_with(
            model,
            ExactOptions {
                min_steps_per_period,
                ..ExactOptions::default()
            },
        )
    }

    /// Build with explicit [`ExactOptions`] (propagation path, reuse of earlier builds).
    ///
    /// # Errors
    /// As `ExactPropagator::try_new`; [`SimError::Budget`] when the grid of one period would
    /// exceed `crate::params::GRID_BUDGET_BYTES`.
    pub fn try_with(model: &CantileverModel, opts: ExactOptions) -> Result<Self, SimError> {
        if !model.law().is_affine() {
            return Err(SimError::Unsupported {
                integrator: "exact",
                law: model.law().name(),
                hint:
                    "only the linear law is piecewise affine: use integrator = \"adaptive\" (or \"auto\")",
            });
        }
        let dim = 2 * model.modes();
        let period = model.period();
        let key = spectral::matrix_key(model);
        let cache = opts.cache.as_ref();
        let tables = cache.map(PropagatorCache::tables);
        let (spec, spec_reused) = cached(tables.map(|t| &t.spectral), &key, || {
            spectral::spectral(model)
        })?;
        let rho = spec[0].rho.max(spec[1].rho);
        let base = opts.min_steps_per_period.max(1);
        let m = grid_steps(period, rho, base, dim)?;
        let h = period / m as f64;
        let mut grid_key = key.clone();
        grid_key.push(h.to_bits());
        let (phi, phi_reused) = cached(tables.map(|t| &t.grid_exp), &grid_key, || {
            Ok(spectral::grid_exp(&spec, h))
        })?;
        // kept only while small: a cache entry outlives the propagators that use it, and the
        // grid of a stiff, large-N build may take up to params::GRID_BUDGET_BYTES
        let keep = (2 * dim + 2) as f64 * (m as f64 + 1.0) * 8.0 <= FORCING_KEEP_BYTES;
        let (forcing, forcing_reused) = cached(
            tables.filter(|_| keep).map(|t| &t.forcing),
            &forcing_key(model, &key, h),
            || forcing(model, &spec, m, h),
        )?;
        let (forced, trig, trig_mid) = (forcing.0.clone(), forcing.1.clone(), forcing.2.clone());
        let modal = std::array::from_fn(|i| {
            spec[i].modal.is_some() && opts.propagation == Propagation::Auto
        });
        let p = model.params();
        let scale = forced
            .iter()
            .map(|r| r.wp[1].hypot(r.wp[2]) + r.wp[0].abs())
            .fold(0.0, f64::max);
        let dead = 1e-15 * (1.0 + p.alpha5.abs() + base_amp(p) + scale);
        let zero = DVector::zeros(dim);
        Ok(ExactPropagator {
            model: model.clone(),
            spec,
            phi,
            forced,
            modal,
            reused: (spec_reused, phi_reused, forcing_reused),
            kernel: kernel::for_dim(dim),
            grid: PeriodGrid::new(period, m),
            tau: 0.0,
            z: zero.clone(),
            q: Box::new(Modes::ZERO),
            tip_hom: None,
            stale: false,
            scratch: Box::new(Modes::ZERO),
            region: Region::Free,
            on_grid: Some((0, 0)),
            between: None,
            stint_curvature: 0.0,
            just_switched: true,
            chatter: ChatterWindow::new(CHATTER_COUNT, CHATTER_WINDOW),
            last: LastStep {
                tau0: 0.0,
                region: Region::Free,
                dz0: zero.clone(),
                q0: Box::new(Modes::ZERO),
                modal: false,
                full: false,
                span: false,
                q1: Box::new(Modes::ZERO),
                trig0: (0.0, 1.0),
                trig1: (0.0, 1.0),
                k: 0,
            },
            poly: Box::new(TipPoly::empty()),
            poly_built: false,
            vt: (0.0, 0.0),
            entry_trig: (f64::NAN, (0.0, 1.0)),
            dead,
            trig,
            trig_mid,
            zb: zero.clone(),
            dz_run: zero,
            param_data: None,
            param_end: None,
            energy: None,
            bound_cols: BoundCols::default(),
            span_guard: None,
            guard_stopped: false,
            span_q0: Box::new(Modes::ZERO),
            q_switch: Box::new(Modes::ZERO),
            stints: 0,
            sampler: Default::default(),
        })
    }

    /// Sub-steps per drive period m.
    pub fn steps_per_period(&self) -> usize {
        self.grid.m
    }

    /// Whether this build reused earlier builds ([`ExactOptions::cache`]): (the spectral data —
    /// energy transforms, Ã_s, eigendecomposition —, the grid exponentials Φ_s, the forcing
    /// data — particular solutions, their grid values, sin/cos on the grid).
    pub fn reused(&self) -> (bool, bool, bool) {
        self.reused
    }

    /// Whether the grid steps of the free and the contact region (in that order) are modal.
    pub fn modal_regions(&self) -> [bool; 2] {
        self.modal
    }
}

/// The grid's sub-steps per drive period m: the fewest (at least 8) with ‖Ã_s‖₂ h ≤ θ in both
/// regions (`rho` the larger norm), rounded up to a multiple of `base`.
///
/// # Errors
/// [`SimError::Budget`] when the grid of one period, (2N + 2)(m + 1) values (`dim` = 2N),
/// would exceed [`crate::params::GRID_BUDGET_BYTES`]: checked in floating point before any
/// allocation.
fn grid_steps(period: f64, rho: f64, base: usize, dim: usize) -> Result<usize, SimError> {
    let need_f = (period * rho / THETA).ceil().max(8.0);
    let m_f = base as f64 * (need_f / base as f64).ceil();
    let bytes = (dim as f64 + 2.0) * (m_f + 1.0) * 8.0;
    if bytes.is_nan() || bytes > crate::params::GRID_BUDGET_BYTES {
        return Err(SimError::Budget {
            what: "exact integrator grid",
            needed: format!(
                "{m_f:.3e} steps per drive period ({:.0} MiB)",
                bytes / (1024.0 * 1024.0)
            ),
            budget: "128 MiB".into(),
            hint: "the system is too stiff for its drive period: raise Ω, lower α3, α4, α6 \
                   or N, or lower the samples per period",
        });
    }
    let need = need_f as usize;
    Ok(base * need.div_ceil(base))
}

/// The forcing data of `model` on the grid of `m` steps of `h`: both regions' particular
/// solutions (their spectral data `spec`), and sin, cos Ωτ on the grid and at its middles.
///
/// # Errors
/// As [`forced`].
fn forcing(
    model: &CantileverModel,
    spec: &[Spectral; 2],
    m: usize,
    h: f64,
) -> Result<Forcing, SimError> {
    let omega = model.omega();
    let trig: Vec<(f64, f64)> = (0..=m)
        .map(|k| (omega * (k as f64 * h)).sin_cos())
        .collect();
    let trig_mid: Vec<(f64, f64)> = (0..m)
        .map(|k| (omega * ((2 * k + 1) as f64 * (0.5 * h))).sin_cos())
        .collect();
    let forced = Arc::new([
        forced(model, Region::Free, &spec[0], &trig, h)?,
        forced(model, Region::Contact, &spec[1], &trig, h)?,
    ]);
    Ok((forced, trig.into(), trig_mid.into()))
}
