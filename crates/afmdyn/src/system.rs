//! Periodically forced hybrid (switched) systems: the interface every integrator and every
//! analysis is written against.
//!
//! A system has a state z ∈ R^d, a forcing period T, and discrete modes ([`Region`]: free flight
//! and contact). In mode s the flow is ż = f_s(τ, z); the mode is left where its guard
//! g_s(τ, z) > 0 reaches zero from above, and a jump map z⁺ = r_s(τ, z⁻) (identity for a plain
//! switching, an impulse for an impact) gives the new mode and state.
//!
//! The linearisation of the flow across an event is the **saltation matrix** (Leine & Nijmeijer,
//! *Dynamics and Bifurcations of Non-Smooth Mechanical Systems*, Springer 2004, §7.1;
//! Müller, *Chaos Solitons Fractals* 5 (1995) 1671), derived once here for every system:
//!
//! S = R + (f⁺ − R f⁻ − ∂r/∂τ) ∇_z gᵀ / ġ,  ġ = ∇_z g · f⁻ + ∂g/∂τ,
//!
//! with R = ∂r/∂z, f∓ the vector fields before and after the event, all at the event point.
//! (Perturbing z⁻ by δz moves the event by δτ = −∇gᵀδz/ġ; the post-event state at the nominal
//! event time is then r + R(δz + f⁻δτ) + ∂r/∂τ δτ − f⁺δτ.) At a grazing event ġ → 0 and S grows
//! like 1/ġ — the square-root singularity of the impact map (Nordmark 1991).

use crate::error::SimError;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// The two regions of the switched model (eq. 10).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
pub enum Region {
    /// Region I: tip free, V_T > 0.
    #[default]
    Free,
    /// Region II: tip in contact with the sample spring α4 and damper α6, V_T ≤ 0.
    Contact,
}

impl Region {
    /// Index 0 (free) or 1 (contact).
    pub fn index(self) -> usize {
        match self {
            Region::Free => 0,
            Region::Contact => 1,
        }
    }

    /// The other region.
    pub(crate) fn other(self) -> Region {
        match self {
            Region::Free => Region::Contact,
            Region::Contact => Region::Free,
        }
    }

    /// Sign σ of the guard g = σ V_T of a region of the smooth laws: +1 in free flight (left
    /// when V_T falls to 0), −1 in contact (left when V_T rises to 0).
    pub(crate) fn guard_sign(self) -> f64 {
        match self {
            Region::Free => 1.0,
            Region::Contact => -1.0,
        }
    }

    /// Region of a tip displacement V_T: contact when V_T ≤ 0 (eq. 10).
    pub(crate) fn of_v_t(v_t: f64) -> Region {
        if v_t <= 0.0 {
            Region::Contact
        } else {
            Region::Free
        }
    }
}

/// Value and first derivatives of a guard function g_s(τ, z) (positive inside mode s).
#[derive(Debug, Clone, PartialEq)]
pub struct Guard {
    /// g.
    pub value: f64,
    /// ∇_z g, shape `[d]`.
    pub grad: DVector<f64>,
    /// ∂g/∂τ.
    pub d_tau: f64,
}

/// What happens at an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EventKind {
    /// A switching between the vector fields of two modes; the state is continuous.
    Switching,
    /// An impact: the velocity jumps (Newton's restitution law); the mode stays free flight.
    Impact,
    /// The end of a chattering sequence: the tip sticks to the sample (a plastic impact
    /// followed by constrained motion).
    Stick,
    /// The tip leaves the sample after sticking (the constraint force changed sign).
    Release,
}

/// The result of a jump map at an event.
#[derive(Debug, Clone, PartialEq)]
pub struct Jump {
    /// Mode after the event.
    pub to: Region,
    /// What kind of event.
    pub kind: EventKind,
    /// z⁺, shape `[d]`.
    pub state: DVector<f64>,
    /// R = ∂z⁺/∂z⁻, d×d.
    pub jacobian: DMatrix<f64>,
    /// ∂z⁺/∂τ, shape `[d]`.
    pub d_tau: DVector<f64>,
}

impl Jump {
    /// A plain switching to `to`: z⁺ = z⁻.
    pub(crate) fn switching(to: Region, z: &[f64]) -> Jump {
        let d = z.len();
        Jump {
            to,
            kind: EventKind::Switching,
            state: DVector::from_column_slice(z),
            jacobian: DMatrix::identity(d, d),
            d_tau: DVector::zeros(d),
        }
    }
}

/// A periodically forced hybrid system with one guard per mode.
///
/// Slices are states z of length [`HybridSystem::dim`]. Every method is pure (no interior
/// state), so one system is shared by any number of integrators.
pub trait HybridSystem: Send + Sync {
    /// State dimension d.
    fn dim(&self) -> usize;
    /// Forcing period T.
    fn period(&self) -> f64;
    /// The mode a trajectory starting at (τ, z) is in.
    fn mode_at(&self, tau: f64, z: &[f64]) -> Region;
    /// ż = f_s(τ, z) written into `dz`. No allocation.
    fn rhs(&self, mode: Region, tau: f64, z: &[f64], dz: &mut [f64]);
    /// ∂f_s/∂z at (τ, z) written into `jac` (d×d).
    fn jacobian(&self, mode: Region, tau: f64, z: &[f64], jac: &mut DMatrix<f64>);
    /// The guard of mode s: its value and derivatives.
    fn guard(&self, mode: Region, tau: f64, z: &[f64]) -> Guard;
    /// The guard's value only (cheap; the event search calls it often).
    fn guard_value(&self, mode: Region, tau: f64, z: &[f64]) -> f64 {
        self.guard(mode, tau, z).value
    }
    /// dg/dτ along the flow, ∇g · f + ∂g/∂τ, given the vector field `f` at (τ, z) (the event
    /// search calls it often; override to avoid the gradient's allocation).
    fn guard_rate(&self, mode: Region, tau: f64, z: &[f64], f: &[f64]) -> f64 {
        let g = self.guard(mode, tau, z);
        g.grad.iter().zip(f).map(|(a, b)| a * b).sum::<f64>() + g.d_tau
    }
    /// Round-off dead band of the guard of `mode` at (τ, z): a zero counts only where g falls
    /// below −tolerance, so a trajectory leaving the guard surface tangentially does not
    /// re-trigger (default 1e-12).
    fn guard_tolerance(&self, mode: Region, tau: f64, z: &[f64]) -> f64 {
        let _ = (mode, tau, z);
        1e-12
    }
    /// The jump map applied where the guard of mode `from` vanishes.
    fn jump(&self, from: Region, tau: f64, z: &[f64]) -> Jump;
    /// Right-hand side of the variational equations in tangent coordinates: dΨ = (∂f/∂z) Ψ
    /// for the default identity coordinates ([`HybridSystem::to_tangent_coords`]). `psi` and
    /// `dpsi` are d×d column-major. Systems whose Jacobian has an integrable singularity override
    /// this together with the coordinate change.
    fn variational_rhs(
        &self,
        mode: Region,
        tau: f64,
        z: &[f64],
        psi: &[f64],
        dpsi: &mut [f64],
        jac: &mut DMatrix<f64>,
    ) {
        self.jacobian(mode, tau, z, jac);
        jacobian_product(jac, psi, dpsi);
    }
    /// Tangent coordinates Ψ = P(τ, z) Φ of mode `mode` (in place; `forward = false` applies
    /// P⁻¹). Default: the identity.
    fn to_tangent_coords(&self, mode: Region, tau: f64, z: &[f64], m: &mut [f64], forward: bool) {
        let _ = (mode, tau, z, m, forward);
    }
    /// Whether every mode is affine in z with a harmonic forcing and linear guards (the exact
    /// propagator applies).
    fn is_affine(&self) -> bool;
}

/// Check a state of a system of dimension `dim`: length `dim`, finite entries, ‖z‖ below the
/// integrators' divergence threshold [`crate::params::STATE_NORM_MAX`] (1e12).
///
/// # Errors
/// [`SimError::StateLength`], [`SimError::NotFinite`] or [`SimError::OutOfRange`], naming
/// `name`.
pub(crate) fn check_state(
    name: &'static str,
    dim: usize,
    z: &DVector<f64>,
) -> Result<(), SimError> {
    if z.len() != dim {
        return Err(SimError::StateLength {
            name,
            expected: dim,
            got: z.len(),
        });
    }
    if let Some(v) = z.iter().find(|v| !v.is_finite()) {
        return Err(SimError::NotFinite { name, value: *v });
    }
    let norm = z.norm();
    if norm.is_nan() || norm >= crate::params::STATE_NORM_MAX {
        return Err(SimError::out_of_range(
            name,
            format!("|z| = {norm:e}"),
            "must be < 1e12 (the divergence threshold of the integrators)",
        ));
    }
    Ok(())
}

/// dΨ = J Ψ for d×d column-major `psi` and `dpsi` (the variational equations' product).
pub(crate) fn jacobian_product(jac: &DMatrix<f64>, psi: &[f64], dpsi: &mut [f64]) {
    jacobian_rows_product(jac, 0, psi, dpsi);
}

/// Rows `row0..d` of dΨ = J Ψ (d×d column-major `psi` and `dpsi`; the other rows of `dpsi` are
/// left as they are). Column by column as axpys over J's columns: for the small d of this model
/// (2N ≤ 40) a plain loop beats a packed GEMM several times, and it allocates nothing. A
/// second-order system in z = (a, ȧ) has `J = [[0, I], [L]]`: its top rows are a copy of Ψ's
/// lower rows, and only the lower rows (`row0` = d/2) need this product.
#[inline]
pub(crate) fn jacobian_rows_product(
    jac: &DMatrix<f64>,
    row0: usize,
    psi: &[f64],
    dpsi: &mut [f64],
) {
    let d = jac.nrows();
    let j = jac.as_slice();
    for (out, col) in dpsi.chunks_exact_mut(d).zip(psi.chunks_exact(d)) {
        let out = &mut out[row0..];
        out.fill(0.0);
        for (k, &p) in col.iter().enumerate() {
            if p != 0.0 {
                for (o, a) in out.iter_mut().zip(&j[k * d + row0..(k + 1) * d]) {
                    *o += a * p;
                }
            }
        }
    }
}

/// The saltation matrix S (module docs) of the event of mode `from` at (τ, z⁻), with the
/// jump it describes. Returns R when ġ = 0 (exact grazing, where S is unbounded).
pub fn saltation<S: HybridSystem + ?Sized>(
    sys: &S,
    from: Region,
    tau: f64,
    z_minus: &[f64],
) -> (DMatrix<f64>, Jump) {
    let (s, jump, _) = saltation_with_shift(sys, from, tau, z_minus);
    (s, jump)
}

/// [`saltation`] with the event shift w = (f⁺ − R f⁻ − ∂r/∂τ) / ġ (zero when ġ = 0), so that
/// S = R + w ∇_z gᵀ. A parameter p that moves the guard by ∂g/∂p at fixed (τ, z) moves the
/// event by δτ = −(∂g/∂p) δp / ġ, and the post-event state at the nominal event time by
/// w (∂g/∂p) δp: the sensitivity s = ∂z/∂p crosses the event as s⁺ = S s⁻ + w ∂g/∂p (the
/// parameter column of the saltation matrix of the system extended by ṗ = 0; Leine &
/// Nijmeijer 2004, §7.1, with p as a state).
pub fn saltation_with_shift<S: HybridSystem + ?Sized>(
    sys: &S,
    from: Region,
    tau: f64,
    z_minus: &[f64],
) -> (DMatrix<f64>, Jump, DVector<f64>) {
    let parts = saltation_parts(sys, from, tau, z_minus);
    let mut s = parts.jump.jacobian.clone();
    s.ger(1.0, &parts.shift, &parts.grad, 1.0);
    (s, parts.jump, parts.shift)
}

/// The saltation matrix S = R + w ∇_z gᵀ of an event as its parts ([`saltation_parts`]), to
/// apply it without forming it: S M = R M + w (∇_z gᵀ M) is a rank-one update of R M, and R = I
/// at a switching.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SaltationParts {
    /// The jump (with R = ∂z⁺/∂z⁻).
    pub jump: Jump,
    /// ∇_z g of the guard left, shape `[d]`.
    pub grad: DVector<f64>,
    /// The event shift w of `saltation_with_shift`, shape `[d]`.
    pub shift: DVector<f64>,
}

impl SaltationParts {
    /// M ← S M for M of d rows (column-major `m`, any number of whole columns: the monodromy
    /// matrix, or one sensitivity vector; a trailing partial column is left alone). Allocates
    /// nothing at a switching (R = I), one column of scratch otherwise.
    pub(crate) fn apply(&self, m: &mut [f64]) {
        let d = self.shift.len();
        let identity = self.jump.kind == EventKind::Switching;
        let mut scratch = if identity { Vec::new() } else { vec![0.0; d] };
        for col in m.chunks_exact_mut(d.max(1)) {
            let gm: f64 = self.grad.iter().zip(col.iter()).map(|(g, x)| g * x).sum();
            if !identity {
                scratch.copy_from_slice(col);
                crate::linalg::matvec(&self.jump.jacobian, &scratch, col, 1.0, false);
            }
            for (c, w) in col.iter_mut().zip(self.shift.iter()) {
                *c += w * gm;
            }
        }
    }
}

/// The parts R, ∇_z g and w of the saltation matrix of the event of mode `from` at (τ, z⁻)
/// (module docs; w as in `saltation_with_shift`, zero when ġ = 0).
pub(crate) fn saltation_parts<S: HybridSystem + ?Sized>(
    sys: &S,
    from: Region,
    tau: f64,
    z_minus: &[f64],
) -> SaltationParts {
    let d = sys.dim();
    let jump = sys.jump(from, tau, z_minus);
    let guard = sys.guard(from, tau, z_minus);
    let mut f_minus = DVector::zeros(d);
    let mut shift = DVector::zeros(d);
    sys.rhs(from, tau, z_minus, f_minus.as_mut_slice());
    let rate = guard.grad.dot(&f_minus) + guard.d_tau;
    if rate != 0.0 {
        // w = (f⁺ − R f⁻ − ∂r/∂τ) / ġ
        sys.rhs(jump.to, tau, jump.state.as_slice(), shift.as_mut_slice());
        shift.gemv(-1.0, &jump.jacobian, &f_minus, 1.0);
        shift -= &jump.d_tau;
        shift /= rate;
    }
    SaltationParts {
        jump,
        grad: guard.grad,
        shift,
    }
}
