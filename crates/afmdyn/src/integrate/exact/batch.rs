//! Batched exact propagation: many initial states at one parameter set, advanced together.
//!
//! All lanes share one build of the [`ExactPropagator`] (spectral data, Φ_s, particular
//! solutions z_p, grid). Between switchings a lane takes whole grid steps only, and every lane
//! on grid point τ_j takes the step to τ_{j+1} together with the others: the states are kept in
//! structure-of-arrays blocks, one per region (rows: the 2N components of z in a dense region,
//! the real and imaginary parts of the modal coordinates q in a modal one; columns: lanes), and
//! one pass over a block applies
//!
//! z_{j+1} = z_p(τ_{j+1}) + Φ_s (z_j − z_p(τ_j))  or  q_{j+1} = e^{Λh} ⊙ q_j
//!
//! to every lane, evaluates the gap g = σ V_T (eq. 8) and its rate at τ_{j+1}, and applies the
//! certified switching test of the module docs of [`super`] lane by lane. A lane whose test
//! fails (a switching, or a graze, may lie in the step) leaves its block and takes the step
//! with the scalar propagator's code — tip series, leftmost-root search, Newton location,
//! partial steps — up to τ_{j+1}, then rejoins the block of its (new) region. Lanes that start
//! off the grid, or end the step off it, are stepped alone until they reach a grid point.
//!
//! Every lane's arithmetic is the scalar propagator's, operation for operation (the same
//! products and sums in the same order; only the loop over lanes is innermost), so a batch
//! gives bit-identical states, events and errors to [`Integrator::advance_to`] on each lane
//! alone. What it saves is the per-step bookkeeping of the scalar step, and the loops over
//! lanes vectorize.

use super::forcing::grid_v_t;
use super::search::StepEnds;
use super::step::Form;
use super::ExactPropagator;
use crate::error::SimError;
use crate::integrate::Integrator;
use crate::system::Region;
use nalgebra::DVector;

/// Lanes per pass of the modal step (the slot capacity of a block is a multiple of it).
const W: usize = 4;

/// One mode of the modal step for W lanes: (oa, ob) = e^{λh} ⊙ (a, b) (Modes::mul_assign) and
/// w += Re(tip · q), d += Re(tip_dot · q) (the terms of ModalExp::advance_into), with
/// `t` = (Re tip, Im tip, Re tip_dot, Im tip_dot).
#[inline(always)]
fn modal_mode(
    (a, b): (&[f64; W], &[f64; W]),
    (oa, ob): (&mut [f64; W], &mut [f64; W]),
    (fc, fd): (f64, f64),
    t: [f64; 4],
    (w, d): (&mut [f64; W], &mut [f64; W]),
) {
    for l in 0..W {
        let (yre, yim) = (a[l] * fc - b[l] * fd, a[l] * fd + b[l] * fc);
        oa[l] = yre;
        ob[l] = yim;
        w[l] += t[0] * yre - t[1] * yim;
        d[l] += t[2] * yre - t[3] * yim;
    }
}

/// Where a lane is during [`ExactBatch::advance_to`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Lane {
    /// Not advanced by this call.
    Idle,
    /// Stepped alone until it reaches a grid point (or the end).
    Loose,
    /// On grid point j, waiting for the blocks to reach j.
    Parked(i64),
    /// In the block of its region.
    Blocked,
    /// At the end time, or stopped by an error.
    Done,
}

/// The lanes of one region in structure-of-arrays form, W slots at a time: value `row` of slot
/// `s` at `x[at(row, s)]`, chunk by chunk (rows × W values per chunk of W slots).
#[derive(Debug, Clone)]
struct Block {
    region: Region,
    modal: bool,
    /// 2N (dense) or 2r (modal: r real parts, then r imaginary parts).
    rows: usize,
    cap: usize,
    /// Lane index of each slot.
    ids: Vec<usize>,
    /// States at the current grid point, and after the step.
    x: Vec<f64>,
    y: Vec<f64>,
    /// Dense: z − z_p(τ_j).
    dz: Vec<f64>,
    /// V_T and dV_T/dτ at the current grid point, and after the step.
    v: Vec<f64>,
    vd: Vec<f64>,
    vb: Vec<f64>,
    vdb: Vec<f64>,
    /// Curvature bound of the lane's stint.
    curv: Vec<f64>,
    /// Whether the lane switched at its last step.
    switched: Vec<bool>,
    /// Result of the certified test of the step.
    ok: Vec<bool>,
}

impl Block {
    fn new(region: Region, modal: bool, rows: usize, cap: usize) -> Block {
        let vals = |n: usize| vec![0.0; n];
        Block {
            region,
            modal,
            rows,
            cap,
            ids: Vec::with_capacity(cap),
            x: vals(rows * cap),
            y: vals(rows * cap),
            dz: if modal { Vec::new() } else { vals(rows * cap) },
            v: vals(cap),
            vd: vals(cap),
            vb: vals(cap),
            vdb: vals(cap),
            curv: vals(cap),
            switched: vec![false; cap],
            ok: vec![false; cap],
        }
    }

    fn len(&self) -> usize {
        self.ids.len()
    }

    /// Index of value `row` of slot `s`.
    fn at(&self, row: usize, s: usize) -> usize {
        (s / W) * self.rows * W + row * W + s % W
    }

    /// Append lane `id` (on a grid point, in this block's region) with its state.
    fn insert(&mut self, id: usize, lane: &ExactPropagator) {
        let (s, cap) = (self.ids.len(), self.cap);
        debug_assert!(s < cap && lane.region == self.region);
        self.ids.push(id);
        if self.modal {
            let r = self.rows / 2;
            for k in 0..r {
                let (a, b) = (self.at(k, s), self.at(r + k, s));
                self.x[a] = lane.q.re[k];
                self.x[b] = lane.q.im[k];
            }
        } else {
            debug_assert!(!lane.stale);
            for (i, z) in lane.z.iter().enumerate() {
                let a = self.at(i, s);
                self.x[a] = *z;
            }
        }
        self.v[s] = lane.vt.0;
        self.vd[s] = lane.vt.1;
        self.curv[s] = lane.stint_curvature;
        self.switched[s] = lane.just_switched;
    }

    /// Write slot `s` (state `x`) into its lane, which is at τ = `tau` on grid point `at`.
    fn scatter(&self, s: usize, lane: &mut ExactPropagator, tau: f64, at: (i64, usize)) {
        if self.modal {
            let r = self.rows / 2;
            for k in 0..r {
                lane.q.re[k] = self.x[self.at(k, s)];
                lane.q.im[k] = self.x[self.at(r + k, s)];
            }
            lane.stale = true;
            lane.tip_hom = None;
        } else {
            for (i, z) in lane.z.iter_mut().enumerate() {
                *z = self.x[self.at(i, s)];
            }
            lane.stale = false;
        }
        lane.region = self.region;
        lane.tau = tau;
        lane.on_grid = Some(at);
        lane.vt = (self.v[s], self.vd[s]);
        lane.just_switched = self.switched[s];
    }

    /// Remove slot `s` (the last slot, with its state before and after the step, moves into
    /// it).
    fn remove(&mut self, s: usize) {
        let last = self.ids.len() - 1;
        if s != last {
            for row in 0..self.rows {
                let (to, from) = (self.at(row, s), self.at(row, last));
                self.x[to] = self.x[from];
                self.y[to] = self.y[from];
            }
            self.ids[s] = self.ids[last];
            self.v[s] = self.v[last];
            self.vd[s] = self.vd[last];
            self.vb[s] = self.vb[last];
            self.vdb[s] = self.vdb[last];
            self.ok[s] = self.ok[last];
            self.curv[s] = self.curv[last];
            self.switched[s] = self.switched[last];
        }
        self.ids.pop();
    }

    /// The whole grid step k → k + 1 of length `len` for every slot: the end states in `y`,
    /// V_T and its rate in `vb`, `vdb`, and the certified test in `ok`. The operations per lane
    /// are those of `ExactPropagator::step_impl` (whole grid step, no search). Slots are taken
    /// W at a time (padding slots of the last chunk compute harmless garbage).
    fn step(&mut self, p: &ExactPropagator, k: usize, len: f64) {
        let (n_s, rows) = (self.ids.len(), self.rows);
        if n_s == 0 {
            return;
        }
        let chunk = rows * W;
        let used = n_s.div_ceil(W);
        let ri = self.region.index();
        let fr = &p.forced[ri];
        let (sn, cn) = p.trig[k + 1];
        let xs = self.x[..used * chunk].chunks_exact(chunk);
        let ys = self.y[..used * chunk].chunks_exact_mut(chunk);
        let vbs = self.vb[..used * W].as_chunks_mut::<W>().0.iter_mut();
        let vdbs = self.vdb[..used * W].as_chunks_mut::<W>().0.iter_mut();
        if self.modal {
            let Some(me) = &p.spec[ri].modal else {
                unreachable!("a modal block has an eigendecomposition")
            };
            let r = rows / 2;
            let f = &fr.grid_fac;
            let (tip, tip_dot) = (&me.tip, &me.tip_dot);
            // per chunk, the modes innermost so that the sums stay in registers:
            // q ← e^{λh} ⊙ q (ModalExp::advance_into) and Σ Re(tip_k q_k) for the
            // tip deflection and rate, each in the two interleaved partial sums of
            // ModalExp::advance_into (even k, odd k)
            for (((xc, yc), vb), vdb) in xs.zip(ys).zip(vbs).zip(vdbs) {
                let (xr, xi) = xc.split_at(r * W);
                let (yr, yi) = yc.split_at_mut(r * W);
                let (xr, xi) = (xr.as_chunks::<W>().0, xi.as_chunks::<W>().0);
                let (yr, yi) = (yr.as_chunks_mut::<W>().0, yi.as_chunks_mut::<W>().0);
                // even modes into (w0, d0), odd ones into (w1, d1), unrolled by two so that
                // the accumulators stay in registers
                let (mut w0, mut w1, mut d0, mut d1) = ([0.0; W], [0.0; W], [0.0; W], [0.0; W]);
                type Lanes<'a> = &'a mut [f64; W];
                let mode = |kk: usize, oa: Lanes, ob: Lanes, w: Lanes, d: Lanes| {
                    modal_mode(
                        (&xr[kk], &xi[kk]),
                        (oa, ob),
                        (f.re[kk], f.im[kk]),
                        [tip.re[kk], tip.im[kk], tip_dot.re[kk], tip_dot.im[kk]],
                        (w, d),
                    )
                };
                let mut kk = 0;
                while kk + 1 < r {
                    mode(kk, &mut yr[kk], &mut yi[kk], &mut w0, &mut d0);
                    mode(kk + 1, &mut yr[kk + 1], &mut yi[kk + 1], &mut w1, &mut d1);
                    kk += 2;
                }
                if kk < r {
                    mode(kk, &mut yr[kk], &mut yi[kk], &mut w0, &mut d0);
                }
                for l in 0..W {
                    let tip = (w0[l] + w1[l], d0[l] + d1[l]);
                    (vb[l], vdb[l]) = grid_v_t(fr, k + 1, tip);
                }
            }
        } else {
            let dim = rows;
            let zp = fr.zp_grid.as_slice();
            let (zk, zk1) = (
                &zp[k * dim..(k + 1) * dim],
                &zp[(k + 1) * dim..(k + 2) * dim],
            );
            let phi = p.phi[ri].as_slice();
            let n = dim / 2;
            let tip = p.model.tip().as_slice();
            let dzs = self.dz[..used * chunk].chunks_exact_mut(chunk);
            for ((((xc, yc), dzc), vb), vdb) in xs.zip(ys).zip(dzs).zip(vbs).zip(vdbs) {
                let (xc, yc) = (xc.as_chunks::<W>().0, yc.as_chunks_mut::<W>().0);
                let dzc = dzc.as_chunks_mut::<W>().0;
                // z_{k+1} = z_p(τ_{k+1}) + Φ (z − z_p(τ_k)), column by column (kernel::fixed)
                for (((x, d), o), (a, b)) in xc
                    .iter()
                    .zip(dzc.iter_mut())
                    .zip(yc.iter_mut())
                    .zip(zk.iter().zip(zk1))
                {
                    for l in 0..W {
                        d[l] = x[l] - a;
                        o[l] = *b;
                    }
                }
                for (col, d) in phi.chunks_exact(dim).zip(dzc.iter()) {
                    for (o, a) in yc.iter_mut().zip(col) {
                        for l in 0..W {
                            o[l] += a * d[l];
                        }
                    }
                }
                // V_T = c̃ᵀa + α2 sin Ωτ + α5 and its rate (eq. 8), the sums as the scalar step's
                let mut v = [-0.0; W];
                let mut vd = [-0.0; W];
                for ((t, ya), yd) in tip.iter().zip(&yc[..n]).zip(&yc[n..]) {
                    for l in 0..W {
                        v[l] += t * ya[l];
                        vd[l] += t * yd[l];
                    }
                }
                for l in 0..W {
                    [vb[l], vdb[l], _] = p.model.v_t_at((sn, cn), [v[l], vd[l], 0.0]);
                }
            }
        }
        // the certified test of step_impl
        let sigma = self.region.guard_sign();
        let (dead, vp) = (p.dead, fr.vp_curv);
        for s in 0..n_s {
            let ends = StepEnds::new(
                sigma,
                dead,
                (self.v[s], self.vd[s]),
                (self.vb[s], self.vdb[s]),
                self.switched[s],
            );
            self.ok[s] = ends.certified(self.curv[s] + vp, len);
        }
    }

    /// Accept the step for the slots that passed the test (the others must have been removed).
    fn commit(&mut self) {
        let n_s = self.ids.len();
        debug_assert!(self.ok[..n_s].iter().all(|&o| o));
        std::mem::swap(&mut self.x, &mut self.y);
        self.v[..n_s].copy_from_slice(&self.vb[..n_s]);
        self.vd[..n_s].copy_from_slice(&self.vdb[..n_s]);
        self.switched[..n_s].fill(false);
    }
}

/// Many trajectories of one [`ExactPropagator`] build, advanced together (see the module
/// docs): each lane is an [`ExactPropagator`] sharing the build, so after
/// [`ExactBatch::advance_to`] a lane can go on alone (steps, dense output, Jacobians).
#[derive(Debug, Clone)]
pub struct ExactBatch {
    proto: ExactPropagator,
    lanes: Vec<ExactPropagator>,
}

impl ExactBatch {
    /// An empty batch of lanes built like `proto` (its state is not used).
    pub fn new(proto: &ExactPropagator) -> Self {
        ExactBatch {
            proto: proto.clone(),
            lanes: Vec::new(),
        }
    }

    /// Add a lane starting at (τ, z), `z: [f64; 2N]` as (a, ȧ); returns its index.
    ///
    /// # Errors
    /// As [`Integrator::reset`] (wrong length, non-finite values); nothing is added then.
    pub fn push(&mut self, tau: f64, z: &DVector<f64>) -> Result<usize, SimError> {
        let mut lane = self.proto.clone();
        lane.reset(tau, z)?;
        self.lanes.push(lane);
        Ok(self.lanes.len() - 1)
    }

    /// Number of lanes.
    pub fn len(&self) -> usize {
        self.lanes.len()
    }

    /// Whether there are no lanes.
    pub fn is_empty(&self) -> bool {
        self.lanes.is_empty()
    }

    /// Lane `i`.
    ///
    /// # Panics
    /// When `i >= len()`.
    pub fn lane(&self, i: usize) -> &ExactPropagator {
        &self.lanes[i]
    }

    /// Lane `i`, to go on alone.
    ///
    /// # Panics
    /// When `i >= len()`.
    pub fn lane_mut(&mut self, i: usize) -> &mut ExactPropagator {
        &mut self.lanes[i]
    }

    /// The lanes.
    pub fn into_lanes(self) -> Vec<ExactPropagator> {
        self.lanes
    }

    /// Advance every lane with `active[i]` to exactly `tau_end` (lanes already there or beyond
    /// are left as they are), as [`Integrator::advance_to`] would lane by lane — bit for bit.
    /// Returns one result per lane (`Ok` for inactive lanes): a lane that diverges or chatters
    /// stops at its error and the others go on. Afterwards each lane's state is formed and its
    /// dense output refers to the current state only (a zero-length last step).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] when `tau_end` is not finite or `active.len() != len()`.
    pub fn advance_to(
        &mut self,
        tau_end: f64,
        active: &[bool],
    ) -> Result<Vec<Result<(), SimError>>, SimError> {
        crate::error::finite("tau_end", tau_end)?;
        if active.len() != self.lanes.len() {
            return Err(SimError::out_of_range(
                "active lanes",
                active.len(),
                "must have one entry per lane",
            ));
        }
        let mut out: Vec<Result<(), SimError>> = self.lanes.iter().map(|_| Ok(())).collect();
        let mut state: Vec<Lane> = active
            .iter()
            .map(|&a| if a { Lane::Loose } else { Lane::Idle })
            .collect();
        let cap = active.iter().filter(|&&a| a).count().div_ceil(W) * W;
        let p = &self.proto;
        let (m, period, h) = (p.grid.m as i64, p.grid.period, p.grid.h);
        // as the t_grid of step_impl
        let grid_tau = |j: i64| j.div_euclid(m) as f64 * period + j.rem_euclid(m) as f64 * h;
        let rows = |r: Region| match &p.spec[r.index()].modal {
            Some(me) if p.modal[r.index()] => (true, 2 * me.len()),
            _ => (false, p.z.len()),
        };
        let mut blocks = [Region::Free, Region::Contact].map(|r| {
            let (modal, n) = rows(r);
            Block::new(r, modal, n, cap)
        });
        // grid point of the blocks (all blocked lanes are on it)
        let mut at: Option<i64> = None;
        loop {
            // lanes alone: step until on a grid point whose step ends by tau_end, or done
            for (l, st) in state.iter_mut().enumerate() {
                if *st != Lane::Loose {
                    continue;
                }
                let lane = &mut self.lanes[l];
                *st = loop {
                    if lane.tau >= tau_end {
                        break Lane::Done;
                    }
                    if let Some((pp, k)) = lane.on_grid {
                        let j = pp * m + k as i64;
                        if grid_tau(j + 1) <= tau_end && lane.tau == grid_tau(j) {
                            break Lane::Parked(j);
                        }
                    }
                    if let Err(e) = lane.step_impl(tau_end, Form::Nothing) {
                        out[l] = Err(e);
                        break Lane::Done;
                    }
                };
            }
            let parked = state.iter().filter_map(|s| match s {
                Lane::Parked(j) => Some(*j),
                _ => None,
            });
            let Some(j) = parked.chain(at).min() else {
                break;
            };
            debug_assert!(at.is_none_or(|a| a == j));
            for (l, st) in state.iter_mut().enumerate() {
                if *st == Lane::Parked(j) {
                    let lane = &self.lanes[l];
                    blocks[lane.region.index()].insert(l, lane);
                    *st = Lane::Blocked;
                }
            }
            let (tau_a, tau_b) = (grid_tau(j), grid_tau(j + 1));
            let (k, next) = (j.rem_euclid(m) as usize, j + 1);
            let next_at = (next.div_euclid(m), next.rem_euclid(m) as usize);
            for b in &mut blocks {
                b.step(p, k, tau_b - tau_a);
                // lanes whose step may hold a switching take it alone, from the state before it
                for s in (0..b.len()).rev() {
                    if b.ok[s] {
                        continue;
                    }
                    let l = b.ids[s];
                    let lane = &mut self.lanes[l];
                    b.scatter(s, lane, tau_a, (j.div_euclid(m), k));
                    b.remove(s);
                    state[l] = Lane::Loose;
                    // (back on the grid at τ_{j+1}, it is parked there by the next pass)
                    while lane.tau < tau_b {
                        if let Err(e) = lane.step_impl(tau_b, Form::Nothing) {
                            out[l] = Err(e);
                            state[l] = Lane::Done;
                            break;
                        }
                    }
                }
                b.commit();
            }
            // at the end of a period: the plain state is formed and checked for divergence (as
            // step_impl does)
            if next_at.1 == 0 {
                for b in &mut blocks {
                    for s in (0..b.len()).rev() {
                        let l = b.ids[s];
                        let lane = &mut self.lanes[l];
                        b.scatter(s, lane, tau_b, next_at);
                        if let Err(e) = lane.check_divergence() {
                            out[l] = Err(e);
                            state[l] = Lane::Done;
                            b.remove(s);
                        }
                    }
                }
            }
            at = blocks.iter().any(|b| b.len() > 0).then_some(next);
            // the next step would end beyond tau_end: the rest alone
            if at.is_some() && grid_tau(next + 1) > tau_end {
                for b in &mut blocks {
                    for s in (0..b.len()).rev() {
                        let l = b.ids[s];
                        b.scatter(s, &mut self.lanes[l], tau_b, next_at);
                        b.remove(s);
                        state[l] = Lane::Loose;
                    }
                }
                at = None;
            }
        }
        for (lane, st) in self.lanes.iter_mut().zip(&state) {
            if *st != Lane::Idle {
                lane.materialize();
                lane.rest_here();
            }
        }
        Ok(out)
    }
}
