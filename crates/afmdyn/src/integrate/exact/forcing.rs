//! The forcing data of a build: each region's particular solution z_p (eq. 10 with harmonic
//! forcing), its values on the grid, the V_T of the particular part there (and V_T in a modal
//! region from it and the homogeneous tip), shared between the builds of one
//! [`super::PropagatorCache`].

use super::modal::Modes;
use super::spectral::Spectral;
use super::tip::base_amp;
use super::{INV_FACT, K};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::system::Region;
use nalgebra::{DMatrix, DVector, Dyn, LU};
use std::sync::Arc;

/// Data of one region that depends on the forcing (Ω, α2, α5) and the grid step.
#[derive(Debug, Clone)]
pub(super) struct Forced {
    /// Particular solution z_p(τ) = p0 + ps sin Ωτ + pc cos Ωτ.
    pub(super) p0: DVector<f64>,
    pub(super) ps: DVector<f64>,
    pub(super) pc: DVector<f64>,
    /// z_p at the m + 1 grid points of one period (columns).
    pub(super) zp_grid: DMatrix<f64>,
    /// Tip part of z_p: W_p = w0 + ws sin + wc cos.
    pub(super) wp: [f64; 3],
    /// Ω² · amplitude of V_p (bound on |V_p''|).
    pub(super) vp_curv: f64,
    /// [V_T, dV_T/dτ] of the particular solution at the grid points (k = 0..=m).
    pub(super) vp_grid: Vec<(f64, f64)>,
    /// Ωⁿ/n! and Ωⁿ⁺¹/n!, n = 0..=K: the Taylor factors of the harmonic part of V_T and of
    /// its rate (`build_poly`).
    pub(super) harm_fact: [[f64; K + 1]; 2],
    /// e^{λ_k h} of the modal representatives (empty without an eigendecomposition).
    pub(super) grid_fac: Modes,
    /// e^{λ_k h/2}: the modal coordinates at the middle of a grid step, where its tip series
    /// is centred (`step_impl`).
    pub(super) half_fac: Modes,
    /// LU of [[A, ΩI], [−ΩI, A]] (4N×4N), kept for the parameter derivatives of (ps, pc).
    pub(super) harmonic_lu: LU<f64, Dyn, Dyn>,
}

/// [V_T, dV_T/dτ] in a modal region at a time with (sin Ωτ, cos Ωτ) = `sc`, from the tip
/// deflection and rate (w, ẇ) of the homogeneous part: W = w + W_p with the particular part
/// W_p = w0 + ws sin Ωτ + wc cos Ωτ of [`Forced`], then eq. 8
/// ([`CantileverModel::v_t_at`]).
pub(super) fn modal_v_t(
    model: &CantileverModel,
    fr: &Forced,
    (w, wd): (f64, f64),
    sc: (f64, f64),
) -> (f64, f64) {
    let tip = modal_tip(model.omega(), fr, (w, wd), sc);
    let [v, vd, _] = model.v_t_at(sc, [tip.0, tip.1, 0.0]);
    (v, vd)
}

/// (W(1,τ), ∂W(1,τ)/∂τ) in a modal region at a time with (sin Ωτ, cos Ωτ) = `sc`, from the tip
/// deflection and rate (w, ẇ) of the homogeneous part: W = w + W_p (see [`modal_v_t`]).
#[inline(always)]
pub(super) fn modal_tip(
    omega: f64,
    fr: &Forced,
    (w, wd): (f64, f64),
    (s, c): (f64, f64),
) -> (f64, f64) {
    let [w0, ws, wc] = fr.wp;
    (w + w0 + ws * s + wc * c, wd + omega * (ws * c - wc * s))
}

/// [`modal_v_t`] at grid point k of a period from the particular part's V_T there
/// ([`Forced`]'s `vp_grid`, formed by `modal_v_t` with w = ẇ = 0): V_T is affine in (w, ẇ), so
/// the whole grid steps of a modal region add two numbers instead of forming eq. 8 again.
#[inline(always)]
pub(super) fn grid_v_t(fr: &Forced, k: usize, (w, wd): (f64, f64)) -> (f64, f64) {
    let (v, vd) = fr.vp_grid[k];
    (w + v, wd + vd)
}

/// The forcing data of a build, shared by every build with the same key ([`forcing_key`]):
/// both regions' [`Forced`], sin/cos of Ωτ_k on the grid (k = 0..=m) and at the middles of its
/// steps (k + 1/2, k < m).
pub(super) type Forcing = (Arc<[Forced; 2]>, Arc<[(f64, f64)]>, Arc<[(f64, f64)]>);

/// Largest forcing data kept in a [`super::PropagatorCache`], counted as (4N + 2)(m + 1)
/// numbers (both regions' grid values of z_p and the grid's sin/cos): 2 MiB (N = 20 at the
/// default parameters: 1.4 MiB). The bytes an entry really holds: [`super::cache`].
pub(super) const FORCING_KEEP_BYTES: f64 = 2.0 * 1024.0 * 1024.0;

/// Everything [`forced`] and the grid's sin/cos read: the spectral key (A_s, M, K_s), h, Ω,
/// the base-drive amplitude, the gap α5 (V_T on the grid), the tip row and b_const, b_sin, b_cos
/// of both regions, as bits.
pub(super) fn forcing_key(model: &CantileverModel, spectral_key: &[u64], h: f64) -> Vec<u64> {
    let mut key = spectral_key.to_vec();
    let p = model.params();
    key.extend([h, model.omega(), base_amp(p), p.alpha5].map(f64::to_bits));
    key.extend(model.tip().iter().map(|x| x.to_bits()));
    for r in [Region::Free, Region::Contact] {
        let d = model.dynamics(r);
        for b in [&d.b_const, &d.b_sin, &d.b_cos] {
            key.extend(b.iter().map(|x| x.to_bits()));
        }
    }
    key
}

/// (ps, pc) and the LU of [[A, ωI], [−ωI, A]]: [`harmonic_response`]'s.
pub(super) type Harmonic = (DVector<f64>, DVector<f64>, LU<f64, Dyn, Dyn>);

/// The periodic response z = ps sin ωτ + pc cos ωτ of ż = A z + b_s sin ωτ + b_c cos ωτ
/// (`b` = (b_s, b_c), each `[dim]`): [[A, ωI], [−ωI, A]] (ps, pc) = −(b_s, b_c), with the LU of
/// that matrix (4N × 4N). `None` at an undamped natural frequency ω, or within round-off of
/// one (an amplification beyond 10¹³).
pub(super) fn harmonic_response(
    a: &DMatrix<f64>,
    omega: f64,
    (b_sin, b_cos): (&DVector<f64>, &DVector<f64>),
) -> Option<Harmonic> {
    let dim = a.nrows();
    let mut big = DMatrix::zeros(2 * dim, 2 * dim);
    big.view_mut((0, 0), (dim, dim)).copy_from(a);
    big.view_mut((dim, dim), (dim, dim)).copy_from(a);
    for i in 0..dim {
        big[(i, dim + i)] = omega;
        big[(dim + i, i)] = -omega;
    }
    let mut rhs = DVector::zeros(2 * dim);
    rhs.rows_mut(0, dim).copy_from(&(-b_sin));
    rhs.rows_mut(dim, dim).copy_from(&(-b_cos));
    let big_norm = big.norm();
    let lu = big.lu();
    let sol = lu.solve(&rhs)?;
    // numerically singular (ω within round-off of an undamped resonance)
    let amplification = sol.norm() * big_norm;
    if rhs.norm() > 0.0 && (amplification.is_nan() || amplification > 1e13 * rhs.norm()) {
        return None;
    }
    let (ps, pc) = (
        sol.rows(0, dim).into_owned(),
        sol.rows(dim, dim).into_owned(),
    );
    Some((ps, pc, lu))
}

/// Particular solution of one region and its grid values: A p0 = −b_const and
/// [[A, ΩI], [−ΩI, A]] (ps, pc) = −(b_sin, b_cos) (eq. 10 with harmonic forcing).
pub(super) fn forced(
    model: &CantileverModel,
    r: Region,
    spec: &Spectral,
    trig: &[(f64, f64)],
    h: f64,
) -> Result<Forced, SimError> {
    let n = model.modes();
    let dim = 2 * n;
    let omega = model.omega();
    let d = model.dynamics(r);
    let p0 = spec
        .a_lu
        .solve(&(-&d.b_const))
        .ok_or_else(|| SimError::out_of_range("state matrix", "singular", "K must be SPD"))?;
    let resonance = || {
        SimError::out_of_range(
            "omega",
            omega,
            "is an undamped natural frequency: no periodic forced response (add damping)",
        )
    };
    let (ps, pc, harmonic_lu) =
        harmonic_response(&d.a, omega, (&d.b_sin, &d.b_cos)).ok_or_else(resonance)?;
    let mut zp_grid = DMatrix::zeros(dim, trig.len());
    let (a, b, d) = (p0.as_slice(), ps.as_slice(), pc.as_slice());
    for (col, &(s, c)) in zp_grid.as_mut_slice().chunks_exact_mut(dim).zip(trig) {
        for (((o, a), b), d) in col.iter_mut().zip(a).zip(b).zip(d) {
            *o = a + s * b + c * d;
        }
    }
    let tip = model.tip();
    let wp = [
        tip.dot(&p0.rows(0, n)),
        tip.dot(&ps.rows(0, n)),
        tip.dot(&pc.rows(0, n)),
    ];
    let vp_curv = omega * omega * (wp[1] + base_amp(model.params())).hypot(wp[2]);
    let (mut grid_fac, mut half_fac) = (Modes::ZERO, Modes::ZERO);
    if let Some(me) = &spec.modal {
        me.factors(h, &mut grid_fac);
        me.factors(0.5 * h, &mut half_fac);
    }
    let mut harm_fact = [[0.0; K + 1]; 2];
    let mut om_n = 1.0;
    for n in 0..=K {
        harm_fact[0][n] = om_n * INV_FACT[n];
        harm_fact[1][n] = om_n * omega * INV_FACT[n];
        om_n *= omega;
    }
    let mut fr = Forced {
        p0,
        ps,
        pc,
        zp_grid,
        wp,
        vp_curv,
        harm_fact,
        grid_fac,
        half_fac,
        harmonic_lu,
        vp_grid: Vec::new(),
    };
    fr.vp_grid = trig
        .iter()
        .map(|&sc| modal_v_t(model, &fr, (0.0, 0.0), sc))
        .collect();
    Ok(fr)
}
