//! Dense output at equally spaced sample times τ_i = t0 + i·dt ([`Integrator::dense_states_into`])
//! without ending a step at each: a recorded run takes the natural grid steps and forms its
//! samples here.
//!
//! In a region with an eigendecomposition the homogeneous part is z − z_p = T⁻¹V q with
//! q(τ + t) = e^{Λt} q(τ) along a stint (eq. 10 in modal coordinates, `modal.rs`), so the
//! samples of one stint are one geometric sequence: q_{i+1} = e^{Λ dt} ⊙ q_i, and the drive
//! phase (sin Ωτ_i, cos Ωτ_i) turns by the fixed rotation (sin Ω dt, cos Ω dt). A sample is then
//! r complex products, one rotation and the expansion T⁻¹V q (2N × r), with no exponential or
//! sine. The sequence is anchored (q_i = e^{Λ(τ_i − τ0)} q0 from the last step's start, sin/cos
//! of Ωτ_i) at its first sample, after a stint entry, when an index is skipped, and every
//! [`REANCHOR`] samples, so that the rounding of the products (about one ulp each, |e^{λdt}| ≤ 1
//! as Re λ ≤ 0) grows over at most that many: ≤ 256 ε ≈ 6e-14 relative, against the ulp of τ the
//! sample time has anyway (`tests/dense_samples.rs`, `dense_samples_equal_the_states_of_steps_ended_there`).
//! Where the region has no eigendecomposition each sample is the last step's dense state.
//!
//! [`Integrator::dense_states_into`]: crate::integrate::Integrator::dense_states_into

use super::forcing::Forced;
use super::modal::{ModalExp, Modes, Split};
use super::ExactPropagator;

/// Samples advanced by products before the sequence is anchored again.
const REANCHOR: u64 = 256;

/// Where the sample sequence is: the modal coordinates and drive phase of sample `i` of the
/// times t0 + i·dt in a stint, and the per-sample factors e^{Λ dt}, (sin Ω dt, cos Ω dt) of a
/// region and dt.
#[derive(Debug, Clone)]
pub(super) struct SampleCursor {
    /// (stint, region, t0 bits, dt bits) of the sequence; `None`: no sequence to continue.
    key: Option<(u64, usize, u64, u64)>,
    /// The index of the sample the cursor is at, and of the last anchored one.
    i: u64,
    anchor: u64,
    q: Box<Modes>,
    trig: (f64, f64),
    /// (region, dt bits) of the factors.
    fac_key: Option<(usize, u64)>,
    fac: Box<Modes>,
    rot: (f64, f64),
}

impl Default for SampleCursor {
    fn default() -> Self {
        SampleCursor {
            key: None,
            i: 0,
            anchor: 0,
            q: Box::new(Modes::ZERO),
            trig: (0.0, 1.0),
            fac_key: None,
            fac: Box::new(Modes::ZERO),
            rot: (0.0, 1.0),
        }
    }
}

impl SampleCursor {
    /// Forget the sequence (a restart: the next sample is anchored).
    pub(super) fn clear(&mut self) {
        self.key = None;
    }
}

impl ExactPropagator {
    /// [`crate::integrate::Integrator::dense_states_into`] (module docs).
    pub(super) fn dense_states_impl(&mut self, t0: f64, dt: f64, first: u64, out: &mut [f64]) {
        let dim = self.z.len();
        let ri = self.last.region.index();
        let Some(me) = &self.spec[ri].modal else {
            for (j, row) in out.chunks_exact_mut(dim).enumerate() {
                let tau = t0 + (first + j as u64) as f64 * dt;
                self.state_in_last(tau - self.last.tau0, row);
            }
            return;
        };
        let r = me.len();
        let omega = self.model.omega();
        // the stint of the last step: the one before the current when that step ended at a
        // switching (the propagator has entered the next stint since)
        let stint = if self.just_switched {
            self.stints.wrapping_sub(1)
        } else {
            self.stints
        };
        let key = Some((stint, ri, t0.to_bits(), dt.to_bits()));
        let cur = &mut self.sampler;
        if cur.fac_key != Some((ri, dt.to_bits())) {
            me.factors(dt, &mut cur.fac);
            cur.rot = (omega * dt).sin_cos();
            cur.fac_key = Some((ri, dt.to_bits()));
        }
        let fr = &self.forced[ri];
        for (j, row) in out.chunks_exact_mut(dim).enumerate() {
            let i = first + j as u64;
            if cur.key == key && i == cur.i + 1 && i - cur.anchor < REANCHOR {
                cur.q.mul_assign(&cur.fac, r);
                let (s, c) = cur.trig;
                let (sd, cd) = cur.rot;
                cur.trig = (s * cd + c * sd, c * cd - s * sd);
            } else {
                // anchored: from the last step's start
                let tau = t0 + i as f64 * dt;
                let t = tau - self.last.tau0;
                if self.last.modal {
                    cur.q.copy_prefix(&self.last.q0, r);
                } else {
                    me.project_plain(self.last.dz0.as_slice(), &mut cur.q);
                }
                let mut f = Modes::ZERO;
                me.factors(t, &mut f);
                cur.q.mul_assign(&f, r);
                cur.trig = (omega * tau).sin_cos();
                cur.anchor = i;
                cur.key = key;
            }
            cur.i = i;
            sample_row(fr, &me.tv, &cur.q, cur.trig, row);
        }
    }
}

/// z = z_p + Σ_k Re(b_k q_k) into `row` at (sin Ωτ, cos Ωτ) = `trig`: `zp_at` and
/// `ModalExp::expand` (the same operations in the same order, so the same values), with the
/// row's length fixed at compile time for N ≤ 6 (the loops unrolled: a sample is a few dozen
/// instructions).
#[inline(always)]
fn sample_row(fr: &Forced, tv: &Split, q: &Modes, trig: (f64, f64), row: &mut [f64]) {
    match row.len() {
        2 => sample_row_fixed::<2>(fr, tv, q, trig, row),
        4 => sample_row_fixed::<4>(fr, tv, q, trig, row),
        6 => sample_row_fixed::<6>(fr, tv, q, trig, row),
        8 => sample_row_fixed::<8>(fr, tv, q, trig, row),
        10 => sample_row_fixed::<10>(fr, tv, q, trig, row),
        12 => sample_row_fixed::<12>(fr, tv, q, trig, row),
        _ => {
            ExactPropagator::zp_at(fr, trig, row);
            ModalExp::expand(tv, q, row, true);
        }
    }
}

/// [`sample_row`] for a row of `D` values.
#[inline(always)]
fn sample_row_fixed<const D: usize>(
    fr: &Forced,
    tv: &Split,
    q: &Modes,
    (s, c): (f64, f64),
    row: &mut [f64],
) {
    let fixed = |v: &[f64]| -> [f64; D] { v[..D].try_into().expect("D values") };
    let (p0, ps, pc) = (
        fixed(fr.p0.as_slice()),
        fixed(fr.ps.as_slice()),
        fixed(fr.pc.as_slice()),
    );
    let mut o = [0.0; D];
    for i in 0..D {
        o[i] = p0[i] + s * ps[i] + c * pc[i];
    }
    let (re, im) = (tv.re.as_slice(), tv.im.as_slice());
    for k in 0..tv.re.ncols() {
        let (br, bi) = (fixed(&re[k * D..]), fixed(&im[k * D..]));
        let (qr, qi) = (q.re[k], q.im[k]);
        for i in 0..D {
            o[i] += br[i] * qr - bi[i] * qi;
        }
    }
    row.copy_from_slice(&o);
}
