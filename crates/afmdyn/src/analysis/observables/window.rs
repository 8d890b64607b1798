//! The quadrature over a window of dense output ([`super::observe`],
//! [`super::observe_tapered`]): the values at the nodes of each smooth piece, the accumulators
//! of every integral, and the extrema located between the nodes (module docs of [`super`]).

use super::*;

/// Values of the dense output at one τ of a smooth piece.
pub(super) struct Node {
    /// τ.
    tau: f64,
    /// State (a, ȧ), shape `[2N]`.
    z: DVector<f64>,
    /// Its vector field (ȧ, ä), shape `[2N]`.
    dz: DVector<f64>,
    /// W(1,τ) and ∂W/∂τ.
    w: f64,
    wd: f64,
    /// [V_T, V̇_T, V̈_T].
    v: [f64; 3],
    /// F_c.
    f: f64,
    /// (sin Ωτ, cos Ωτ).
    sc: (f64, f64),
}

impl Node {
    /// A node of states of length `dim`, for [`Ctx::node_into`] to fill.
    fn zeros(dim: usize) -> Self {
        Node {
            tau: 0.0,
            z: DVector::zeros(dim),
            dz: DVector::zeros(dim),
            w: 0.0,
            wd: 0.0,
            v: [0.0; 3],
            f: 0.0,
            sc: (0.0, 0.0),
        }
    }
}

/// What [`observe`] needs of the model, computed once.
pub(super) struct Ctx {
    model: CantileverModel,
    law: PreparedLaw,
    free: RegionMatrices,
    tip: DVector<f64>,
    /// Row k: (φᵀx_k) x_kᵀM, the tip deflection carried by eigenmode k of the free region
    /// (x_k mass-normalised, [`crate::eigen::natural_modes`]) at modal coordinates a; the rows
    /// sum to φᵀ (Σ_k x_k x_kᵀ M = I).
    participation: DMatrix<f64>,
    omega: f64,
    /// (sin ψ, cos ψ) of the drive phase ψ.
    psi: (f64, f64),
    /// The drive components of a multifrequency drive, the primary first: (ω_c, ψ_c) (empty
    /// for one frequency; [`ComponentObservables`]).
    components: Vec<(f64, f64)>,
    /// Gauss–Legendre nodes and weights on [−1, 1], ascending: [`GL_NODES`] of them, and
    /// [`GL_NODES_SHORT`].
    gl: [Vec<(f64, f64)>; 2],
    /// Longest smooth piece in each region (free, contact).
    h_max: [f64; 2],
    /// |c| per unit half-length of a product of two integrand factors in each region,
    /// ρ + max(ρ, HΩ) with ρ the region's fastest |λ| and H the highest harmonic.
    product_rate: [f64; 2],
    /// The tapered window's start τ₀ and angular rate κ = 2π/L over the window's length L
    /// ([`observe_tapered`]); `None`: every weight 1.
    taper: Option<(f64, f64)>,
    /// Weights constant over each drive period of the window ([`observe_weighted`]): the
    /// window's start τ₀, the period T and the weight of each period; `None`: every weight 1.
    steps: Option<(f64, f64, Vec<f64>)>,
}

impl Ctx {
    pub(super) fn new(model: &CantileverModel, harmonics: usize) -> Self {
        let p = model.params();
        // pieces short against the highest harmonic (one period of it) and the region's fastest
        // eigenvalue (|λ| h ≤ π on the half-length h), so each GL rule integrates to round-off
        // (module docs)
        let rho = [Region::Free, Region::Contact].map(|r| {
            model
                .dynamics(r)
                .a
                .complex_eigenvalues()
                .iter()
                .fold(0.0f64, |m, l| m.max(l.norm()))
        });
        let components: Vec<(f64, f64)> = if p.is_multifrequency() {
            p.demodulated()
        } else {
            Vec::new()
        };
        // the highest frequency: the highest harmonic of Ω, or a faster drive component
        let top = components
            .iter()
            .fold(harmonics as f64 * p.omega, |m, c| m.max(c.0));
        let h_max = rho.map(|rho| (TAU / top).min(TAU / rho.max(1e-300)));
        let product_rate = rho.map(|rho| rho + rho.max(top));
        let gl = [GL_NODES, GL_NODES_SHORT].map(|n| {
            let mut gl: Vec<(f64, f64)> = GaussLegendre::new(NonZeroUsize::new(n).expect("> 0"))
                .iter()
                .map(|(x, w)| (*x, *w))
                .collect();
            gl.sort_by(|a, b| a.0.total_cmp(&b.0));
            gl
        });
        Ctx {
            model: model.clone(),
            law: PreparedLaw::new(TipSample {
                law: p.contact_law,
                stiffness: p.alpha4,
                damping: p.alpha6,
            }),
            free: model.galerkin().region(Region::Free).clone(),
            tip: model.tip().clone(),
            participation: {
                let free = model.galerkin().region(Region::Free);
                let x = crate::eigen::natural_modes(free).vectors;
                let scale = model.tip().transpose() * &x;
                DMatrix::from_diagonal(&scale.transpose()) * x.transpose() * &free.mass
            },
            omega: p.omega,
            psi: p.drive_phase().sin_cos(),
            components,
            gl,
            h_max,
            product_rate,
            taper: None,
            steps: None,
        }
    }

    /// The window's weight w(τ): 1, or the Hann² window (2/3)(1 − cos x)², x = κ(τ − τ₀)
    /// (mean 1 over the window; it and its first three derivatives vanish at the ends).
    pub(super) fn weight(&self, tau: f64) -> f64 {
        if let Some((t0, t, w)) = &self.steps {
            let k = ((tau - t0) / t).floor().clamp(0.0, (w.len() - 1) as f64) as usize;
            return w[k];
        }
        match self.taper {
            Some((t0, k)) => {
                let c = 1.0 - (k * (tau - t0)).cos();
                TAPER_NORM * c * c
            }
            None => 1.0,
        }
    }

    /// dw/dτ (0 without a window): (4/3)κ(1 − cos x) sin x.
    pub(super) fn weight_rate(&self, tau: f64) -> f64 {
        match self.taper {
            Some((t0, k)) => {
                let (s, c) = (k * (tau - t0)).sin_cos();
                2.0 * TAPER_NORM * k * (1.0 - c) * s
            }
            None => 0.0,
        }
    }

    /// ∫ₐᵇ w dτ, in closed form: (2/3)∫(1 − cos x)² dx = x − (4/3) sin x + (1/6) sin 2x over κ.
    pub(super) fn weighted_length(&self, a: f64, b: f64) -> f64 {
        if self.steps.is_some() {
            // [a, b] lies in one period: the window's steps end at the periods' ends
            return self.weight(0.5 * (a + b)) * (b - a);
        }
        match self.taper {
            Some((t0, k)) => {
                let f = |t: f64| {
                    let x = k * (t - t0);
                    x - 4.0 / 3.0 * x.sin() + (2.0 * x).sin() / 6.0
                };
                (f(b) - f(a)) / k
            }
            None => b - a,
        }
    }

    /// The dense output of the last step (region `r`) at τ: V_T, W and F_c from one sine and
    /// cosine of Ωτ, which the harmonics and the drive's work reuse.
    pub(super) fn node(&self, integ: &mut dyn Integrator, r: Region, tau: f64) -> Node {
        let mut nd = Node::zeros(integ.state().len());
        self.node_into(integ, r, tau, &mut nd);
        nd
    }

    /// [`Ctx::node`] written into `nd` (its states' length the state's): no allocation, and
    /// the sine and cosine of Ωτ computed once for the drive, the state's rate and V_T.
    pub(super) fn node_into(&self, integ: &mut dyn Integrator, r: Region, tau: f64, nd: &mut Node) {
        let n = self.model.modes();
        let sc = (self.omega * tau).sin_cos();
        integ.dense_state_at(tau, sc, nd.z.as_mut_slice());
        nd.dz.fill(0.0);
        self.model
            .rhs_slice_at(r, tau, sc, nd.z.as_slice(), nd.dz.as_mut_slice());
        let [_, w, wd, f] = self.model.sample_values(r, tau, sc, nd.z.as_slice());
        let wdd = self.tip.dot(&nd.dz.rows(n, n));
        nd.v = self.model.v_t_at(sc, [w, wd, wdd]);
        (nd.tau, nd.w, nd.wd, nd.f, nd.sc) = (tau, w, wd, f, sc);
    }

    /// dF_c/dτ at `nd` (τ = `t` in the piece [lo, hi]): analytic for the smooth laws
    /// ([`force_rate`]) and the SLS sample ((α4 + κ)δ̇ − κu̇ in contact), a central difference
    /// inside the piece for the sticking force of the impact law (only the extremum's location
    /// depends on it, its value to second order).
    pub(super) fn rate(
        &self,
        integ: &mut dyn Integrator,
        r: Region,
        t: f64,
        nd: &Node,
        lo: f64,
        hi: f64,
    ) -> f64 {
        if let Some(zn) = self.model.zener() {
            // F = (α4 + κ)δ − κu: its rate from δ̇ = −V̇_T and u̇ (the state's last rate)
            return if r == Region::Contact {
                let u_dot = nd.dz[nd.dz.len() - 1];
                -(zn.relaxed + zn.maxwell) * nd.v[1] - zn.maxwell * u_dot
            } else {
                0.0
            };
        }
        if r != Region::Contact || self.law.law().restitution().is_none() {
            return force_rate(&self.law, r, nd);
        }
        let h = 1e-5 * (hi - lo);
        let (tm, tp) = ((t - h).max(lo), (t + h).min(hi));
        (self.node(integ, r, tp).f - self.node(integ, r, tm).f) / (tp - tm)
    }
}

/// Σ_{k≠j} m_jk x_k.
pub(super) fn off_diagonal(m: &DMatrix<f64>, j: usize, x: &[f64]) -> f64 {
    m.row(j).iter().zip(x).map(|(a, b)| a * b).sum::<f64>() - m[(j, j)] * x[j]
}

/// Buffers of [`Acc::piece`]: the drive F^I at a node, the scan of a piece's nodes, and the
/// last piece's end node (τ, dF_c/dτ, dV_T/dτ), which starts the next piece of the same step.
pub(super) struct Scratch {
    fi: DVector<f64>,
    /// The node under evaluation ([`Ctx::node_into`]).
    node: Node,
    scan: Vec<(f64, f64, f64)>,
    start: Option<(f64, f64, f64)>,
}

/// Running integrals of [`observe`] (over the whole window; divided at the end).
pub(super) struct Acc {
    mean: f64,
    w2: f64,
    wd2: f64,
    cos: Vec<f64>,
    sin: Vec<f64>,
    e_dis: f64,
    impact_loss: f64,
    virial: f64,
    force: f64,
    contact_time: f64,
    impacts: usize,
    drive: Vec<f64>,
    damp: Vec<f64>,
    sample: Vec<f64>,
    coupling: Vec<f64>,
    f_max: f64,
    f_min: f64,
    v_min: f64,
    /// Per drive component: ∫W sin θ_c, ∫W cos θ_c, ∫F_c sin θ_c, ∫F_c cos θ_c with
    /// θ_c = ω_c τ + ψ_c (impulses P sin θ_c, P cos θ_c in the force's).
    comp: Vec<[f64; 4]>,
    /// Per mode, ∫w′E_j dτ under a window (E_j of [`ModeBalance::energy_change`]).
    energy_rate: Vec<f64>,
    /// Per eigenmode k, ∫w_k and ∫w_k² (w_k its tip deflection, `Ctx::participation`).
    eigen_mean: Vec<f64>,
    eigen_sq: Vec<f64>,
}

impl Acc {
    pub(super) fn new(modes: usize, harmonics: usize) -> Self {
        Acc {
            mean: 0.0,
            w2: 0.0,
            wd2: 0.0,
            cos: vec![0.0; harmonics],
            sin: vec![0.0; harmonics],
            e_dis: 0.0,
            impact_loss: 0.0,
            virial: 0.0,
            force: 0.0,
            contact_time: 0.0,
            impacts: 0,
            drive: vec![0.0; modes],
            damp: vec![0.0; modes],
            sample: vec![0.0; modes],
            coupling: vec![0.0; modes],
            f_max: f64::NEG_INFINITY,
            f_min: f64::INFINITY,
            v_min: f64::INFINITY,
            comp: Vec::new(),
            energy_rate: vec![0.0; modes],
            eigen_mean: vec![0.0; modes],
            eigen_sq: vec![0.0; modes],
        }
    }

    /// Extremes over a point of the dense output.
    pub(super) fn extremes(&mut self, f: f64, v_t: f64) {
        self.f_max = self.f_max.max(f);
        self.f_min = self.f_min.min(f);
        self.v_min = self.v_min.min(v_t);
    }

    /// One quadrature node at τ with weight `wq` (every integrand of the module docs).
    pub(super) fn quadrature(&mut self, ctx: &Ctx, wq: f64, nd: &Node, fi: &mut DVector<f64>) {
        let n = ctx.tip.len();
        if ctx.taper.is_some() {
            // ∫w dE_j = −∫w′E_j for w vanishing at the window's ends (module docs)
            let wr = wq * ctx.weight_rate(nd.tau);
            let z = nd.z.as_slice();
            for (j, acc) in self.energy_rate.iter_mut().enumerate() {
                let e = 0.5 * ctx.free.mass[(j, j)] * z[n + j] * z[n + j]
                    + 0.5 * ctx.free.stiffness[(j, j)] * z[j] * z[j];
                *acc += wr * e;
            }
        }
        let wq = wq * ctx.weight(nd.tau);
        self.mean += wq * nd.w;
        self.w2 += wq * nd.w * nd.w;
        self.wd2 += wq * nd.wd * nd.wd;
        // sin and cos of h(Ωτ + ψ), h = 1, 2, …: the angle sum from those of Ωτ and ψ, then
        // the rotation by Ωτ + ψ (its error grows like h ulps, as the argument h(Ωτ + ψ)'s own)
        let ((s, c), (sp, cp)) = (nd.sc, ctx.psi);
        let (s1, c1) = (s * cp + c * sp, c * cp - s * sp);
        let (mut sh, mut ch) = (s1, c1);
        for (sin, cos) in self.sin.iter_mut().zip(self.cos.iter_mut()) {
            *sin += wq * nd.w * sh;
            *cos += wq * nd.w * ch;
            (sh, ch) = (sh * c1 + ch * s1, ch * c1 - sh * s1);
        }
        let a_now = nd.z.rows(0, n);
        for k in 0..n {
            let wk = ctx.participation.row(k).dot(&a_now.transpose());
            self.eigen_mean[k] += wq * wk;
            self.eigen_sq[k] += wq * wk * wk;
        }
        self.e_dis -= wq * nd.f * nd.v[1];
        self.virial += wq * nd.f * nd.w;
        self.force += wq * nd.f;
        for (acc, &(om, psi)) in self.comp.iter_mut().zip(&ctx.components) {
            let (st, ct) = (om * nd.tau + psi).sin_cos();
            acc[0] += wq * nd.w * st;
            acc[1] += wq * nd.w * ct;
            acc[2] += wq * nd.f * st;
            acc[3] += wq * nd.f * ct;
        }
        // the drive F^I(τ) (eq. 14) from the node's sin and cos of Ωτ, and the further drive
        // components' force at the tip
        let forcing = &ctx.free.forcing;
        let tip_force = ctx.model.params().component_force(nd.tau);
        for (j, o) in fi.iter_mut().enumerate() {
            *o = forcing.constant[j]
                + s * forcing.sin[j]
                + c * forcing.cos[j]
                + tip_force * ctx.tip[j];
        }
        let (a, ad, add) = (
            &nd.z.as_slice()[..n],
            &nd.z.as_slice()[n..2 * n],
            &nd.dz.as_slice()[n..2 * n],
        );
        for j in 0..n {
            let aj = ad[j];
            self.drive[j] += wq * fi[j] * aj;
            self.damp[j] += wq
                * ctx
                    .free
                    .damping
                    .row(j)
                    .iter()
                    .zip(ad)
                    .map(|(c, v)| c * v)
                    .sum::<f64>()
                * aj;
            self.sample[j] -= wq * ctx.tip[j] * nd.f * aj;
            let c = off_diagonal(&ctx.free.mass, j, add) + off_diagonal(&ctx.free.stiffness, j, a);
            self.coupling[j] += wq * aj * c;
        }
    }

    /// The smooth piece [a, b] of the last step (region `r`): quadrature, and the extremes of
    /// F_c and V_T at its ends, its nodes and the interior extrema located between them. The
    /// node at a is the end node of the piece before when it ended there (`scratch.start`).
    pub(super) fn piece(
        &mut self,
        ctx: &Ctx,
        integ: &mut dyn Integrator,
        r: Region,
        (a, b): (f64, f64),
        scratch: &mut Scratch,
    ) {
        let half = 0.5 * (b - a);
        // (τ, dF_c/dτ, dV_T/dτ) at the ends and the GL nodes, in order; the nodes in the
        // step's own smooth time ([`crate::integrate::Integrator::smooth_time`]; τ itself but for the Taylor
        // integrator's contact steps)
        let scan = &mut scratch.scan;
        scan.clear();
        match scratch.start.take() {
            Some(start) if start.0 == a => scan.push(start),
            _ => {
                let nd = &mut scratch.node;
                ctx.node_into(integ, r, a, nd);
                self.extremes(nd.f, nd.v[0]);
                scan.push((a, ctx.rate(integ, r, a, nd, a, b), nd.v[1]));
            }
        }
        // the short rule where a product of two factors has |c| ≤ 1 on the piece (module docs),
        // τ being the smooth time: a regularising time stretches the piece's rates unevenly
        let short = integ.smooth_time().is_none() && half * ctx.product_rate[r.index()] <= 1.0;
        for &(x, wx) in &ctx.gl[usize::from(short)] {
            let (tau, dtau) = crate::integrate::smooth_time(integ, a, b, 0.5 * (x + 1.0));
            let nd = &mut scratch.node;
            ctx.node_into(integ, r, tau, nd);
            self.quadrature(ctx, 0.5 * wx * dtau, nd, &mut scratch.fi);
            self.extremes(nd.f, nd.v[0]);
            scan.push((tau, ctx.rate(integ, r, tau, nd, a, b), nd.v[1]));
        }
        let nd = &mut scratch.node;
        ctx.node_into(integ, r, b, nd);
        self.extremes(nd.f, nd.v[0]);
        scan.push((b, ctx.rate(integ, r, b, nd, a, b), nd.v[1]));
        scratch.start = scan.last().copied();
        for pair in scan.windows(2) {
            let ((ta, fda, vda), (tb, fdb, vdb)) = (pair[0], pair[1]);
            if (fda > 0.0) != (fdb > 0.0) {
                let nd = &mut scratch.node;
                let mut g = |t: f64| {
                    ctx.node_into(integ, r, t, nd);
                    ctx.rate(integ, r, t, nd, a, b)
                };
                let t = root_of(ta, fda, tb, fdb, &mut g);
                ctx.node_into(integ, r, t, nd);
                self.extremes(nd.f, nd.v[0]);
            }
            if vda < 0.0 && vdb > 0.0 {
                let mut vt = |t: f64| integ.dense_v_t(t);
                let t = extremum(ta, tb, vda, &mut vt);
                self.v_min = self.v_min.min(vt(t)[0]);
            }
        }
    }

    /// An event, with `after` the state after it: entries into contact and impacts counted;
    /// an impact's impulse P φ at the tip, P = −(1 + r) m_eff V̇_T⁻ (model docs), enters E_dis
    /// (its loss), the virial (P W), ⟨F_c⟩ and each mode's balance.
    pub(super) fn event(&mut self, ctx: &Ctx, e: &SwitchEvent, after: &DVector<f64>) {
        let model = &ctx.model;
        let n = model.modes();
        if match e.kind {
            EventKind::Switching => e.to == Region::Contact,
            EventKind::Impact | EventKind::Stick => true,
            EventKind::Release => false,
        } {
            self.impacts += 1;
        }
        let restitution = match e.kind {
            EventKind::Impact => model.law().restitution(),
            EventKind::Stick => Some(0.0),
            _ => None,
        };
        let Some(rc) = restitution else {
            return;
        };
        // the window's weight at the event multiplies each of its contributions
        let wt = ctx.weight(e.tau);
        let (loss, _) = model.impact_energy(e.tau, e.v_t_dot, rc);
        self.e_dis += wt * loss;
        self.impact_loss += wt * loss;
        let imp = -(1.0 + rc) * model.effective_mass() * e.v_t_dot * wt;
        self.virial += imp * model.w_tip(&e.state);
        self.force += imp;
        for (acc, &(om, psi)) in self.comp.iter_mut().zip(&ctx.components) {
            let (st, ct) = (om * e.tau + psi).sin_cos();
            acc[2] += imp * st;
            acc[3] += imp * ct;
        }
        let jump: Vec<f64> = (0..n).map(|k| after[n + k] - e.state[n + k]).collect();
        for j in 0..n {
            // the impulse's work on mode j and on the others, at the mean velocity
            let avg = 0.5 * (e.state[n + j] + after[n + j]);
            self.sample[j] -= imp * ctx.tip[j] * avg;
            self.coupling[j] += wt * off_diagonal(&ctx.free.mass, j, &jump) * avg;
        }
    }
}

/// The weighting of [`observe_window`]'s window.
pub(super) enum Weighting {
    /// Every weight 1, over `periods` periods of the system ([`observe`]).
    Flat,
    /// The Hann² window over `periods` primary drive periods ([`observe_tapered`]).
    Hann,
    /// One weight per primary drive period, `periods` of them ([`observe_weighted`]).
    Steps(Vec<f64>),
}

/// [`observe`], [`observe_tapered`] or [`observe_weighted`], as `weighting` says.
pub(super) fn observe_window(
    integ: &mut dyn Integrator,
    opts: &ObservableOptions,
    weighting: Weighting,
) -> Result<Observables, SimError> {
    let taper = matches!(weighting, Weighting::Hann);
    crate::error::within(
        "periods",
        opts.periods,
        1..=MAX_PERIODS,
        "must be in 1..=1000000 (an integer number of drive periods)",
    )?;
    crate::error::within(
        "harmonics",
        opts.harmonics,
        1..=MAX_HARMONICS,
        "must be in 1..=10000 (the highest harmonic reported)",
    )?;
    let model = crate::tip_sample::require_cantilever(integ.system(), "the AFM observables")?;
    let mut ctx = Ctx::new(model, opts.harmonics);
    let p: Params = *ctx.model.params();
    let (n, nh, om) = (ctx.model.modes(), opts.harmonics, p.omega);
    let tau_start = integ.tau();
    // the window: periods of the system, or (tapered) primary drive periods
    let (window, per) = if !matches!(weighting, Weighting::Flat) {
        (opts.periods as f64 * TAU / om, opts.periods as f64)
    } else {
        (
            opts.periods as f64 * ctx.model.period(),
            // per drive period 2π/Ω (a multifrequency drive's common period spans several)
            opts.periods as f64 * p.common_periods() as f64,
        )
    };
    if taper {
        ctx.taper = Some((tau_start, TAU / window));
    }
    if let Weighting::Steps(w) = weighting {
        if w.len() != opts.periods || w.iter().any(|x| !x.is_finite()) {
            return Err(SimError::out_of_range(
                "weights",
                w.len(),
                "must be one finite weight per drive period of the window",
            ));
        }
        ctx.steps = Some((tau_start, TAU / om, w));
    }
    let z_start = integ.state().clone();
    let mut acc = Acc::new(n, nh);
    acc.comp = vec![[0.0; 4]; ctx.components.len()];
    let step_energy = ctx.integrate(integ, &mut acc, tau_start + window)?;
    let model = &ctx.model;
    let z_end = integ.state().clone();
    let t_tot = integ.tau() - tau_start;
    let harmonics = acc.harmonics(t_tot);
    let mean = acc.mean / t_tot;
    let a1 = harmonics[0].amplitude;
    let higher_sq = 2.0 * (acc.w2 / t_tot - mean * mean) - a1 * a1;
    let higher_n2_sq = 2.0 * acc.wd2 / t_tot / (om * om) - a1 * a1;
    let mode_balance = (0..n)
        .map(|j| {
            let de = if ctx.steps.is_some() {
                step_energy[j]
            } else if taper {
                -acc.energy_rate[j]
            } else {
                ctx.mode_energy(&z_end, j) - ctx.mode_energy(&z_start, j)
            };
            acc.mode_balance(j, de, per)
        })
        .collect();
    let mode_amplitudes = (0..n)
        .map(|k| {
            let m = acc.eigen_mean[k] / t_tot;
            (2.0 * (acc.eigen_sq[k] / t_tot - m * m)).max(0.0).sqrt()
        })
        .collect();
    let phase = harmonics[0].phase;
    let closed_form = closed_forms(model, a1, phase)?;
    let components = ctx
        .components
        .iter()
        .zip(&acc.comp)
        .enumerate()
        .map(|(i, (&(om, _), sums))| component(model, i, om, sums, t_tot))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Observables {
        periods: opts.periods,
        amplitude: a1,
        phase,
        thd: higher_sq.max(0.0).sqrt() / a1,
        harmonics,
        mean_deflection: mean,
        higher_sq,
        higher_n2_sq,
        mean_force: acc.force / t_tot,
        peak_force: acc.f_max,
        min_force: acc.f_min,
        indentation: (-acc.v_min).max(0.0),
        contact_fraction: acc.contact_time / t_tot,
        contact_time: acc.contact_time / per,
        min_distance: acc.v_min + p.contact_law.distance_offset(),
        impacts_per_period: acc.impacts as f64 / per,
        energy_dissipated: acc.e_dis / per,
        impact_loss: acc.impact_loss / per,
        virial: acc.virial / t_tot,
        mode_balance,
        mode_amplitudes,
        closed_form,
        components,
    })
}

impl Ctx {
    /// The energy of mode j in the state `z`: ½ M_jj ȧ_j² + ½ K_jj a_j².
    fn mode_energy(&self, z: &DVector<f64>, j: usize) -> f64 {
        let (n, free) = (self.model.modes(), &self.free);
        0.5 * free.mass[(j, j)] * z[n + j] * z[n + j] + 0.5 * free.stiffness[(j, j)] * z[j] * z[j]
    }

    /// The window's integrals into `acc`, `integ` stepped to `end`: each step's smooth pieces
    /// and events. Returns, for a step-weighted window (steps ending at each period's end),
    /// each mode's weighted energy change Σ_k W_k (E_j(end of k) − E_j(start of k)).
    fn integrate(
        &self,
        integ: &mut dyn Integrator,
        acc: &mut Acc,
        end: f64,
    ) -> Result<Vec<f64>, SimError> {
        let tau_start = integ.tau();
        let mut scratch = Scratch {
            fi: DVector::zeros(self.model.modes()),
            node: Node::zeros(integ.state().len()),
            scan: Vec::with_capacity(GL_NODES + 2),
            start: None,
        };
        let mut boundary = 1;
        let mut step_energy = vec![0.0; self.model.modes()];
        if let Some((_, _, w)) = &self.steps {
            for (j, e) in step_energy.iter_mut().enumerate() {
                *e -= w[0] * self.mode_energy(integ.state(), j);
            }
        }
        while integ.tau() < end {
            let target = match &self.steps {
                Some((_, t, w)) if boundary < w.len() => tau_start + boundary as f64 * t,
                _ => end,
            };
            let step = integ.step(target)?;
            if let Some((_, _, w)) = &self.steps {
                if integ.tau() >= target && boundary <= w.len() {
                    let z = integ.state();
                    for (j, e) in step_energy.iter_mut().enumerate() {
                        let ej = self.mode_energy(z, j);
                        *e += w[boundary - 1] * ej - w.get(boundary).map_or(0.0, |wb| wb * ej);
                    }
                    boundary += 1;
                }
            }
            let (r, t0, t1) = (step.region, step.tau0, step.tau1);
            if t1 > t0 {
                if r == Region::Contact {
                    acc.contact_time += self.weighted_length(t0, t1);
                }
                let pieces = ((t1 - t0) / self.h_max[r.index()]).ceil().max(1.0) as usize;
                let hp = (t1 - t0) / pieces as f64;
                // pieces of one step share their end nodes; a step starts afresh
                scratch.start = None;
                for k in 0..pieces {
                    let a = t0 + k as f64 * hp;
                    let b = if k + 1 == pieces {
                        t1
                    } else {
                        t0 + (k + 1) as f64 * hp
                    };
                    acc.piece(self, integ, r, (a, b), &mut scratch);
                }
            }
            if let Some(e) = &step.event {
                acc.event(self, e, integ.state());
            }
        }
        Ok(step_energy)
    }
}

impl Acc {
    /// The harmonics of W(1,τ) over the window's length `t_tot`.
    fn harmonics(&self, t_tot: f64) -> Vec<Harmonic> {
        (0..self.sin.len())
            .map(|h| {
                let s = 2.0 * self.sin[h] / t_tot;
                let c = 2.0 * self.cos[h] / t_tot;
                Harmonic {
                    n: h + 1,
                    amplitude: s.hypot(c),
                    phase: wrap_phase((-c).atan2(s)),
                }
            })
            .collect()
    }

    /// Mode j's energy balance per drive period (`per` periods in the window) with its
    /// energy change `de` over the window.
    fn mode_balance(&self, j: usize, de: f64, per: f64) -> ModeBalance {
        let (d, b, s, c) = (
            self.drive[j],
            self.damp[j],
            self.sample[j],
            self.coupling[j],
        );
        ModeBalance {
            mode: j,
            drive: d / per,
            beam_damping: b / per,
            sample: s / per,
            coupling: c / per,
            energy_change: de / per,
            residual: (de - (d - b - s - c)) / per,
        }
    }
}

/// [`ComponentObservables`] of component `i` (0: the primary) at ω_c = `om` from its window
/// sums (`sums`: ∫W sin θ, ∫W cos θ, ∫F_c sin θ, ∫F_c cos θ over `t_tot`, θ = ω_c τ + ψ_c).
/// With z_c = A sin(θ − φ): V_c = (A/T)(Fs cos φ − Fc sin φ) and
/// ∮F_c ż_c = Aω_c(Fc cos φ + Fs sin φ).
pub(super) fn component(
    model: &CantileverModel,
    i: usize,
    om: f64,
    sums: &[f64; 4],
    t_tot: f64,
) -> Result<ComponentObservables, SimError> {
    let [ws, wc, fs, fc] = *sums;
    let (s, c) = (2.0 * ws / t_tot, 2.0 * wc / t_tot);
    let a = s.hypot(c);
    let phase = wrap_phase((-c).atan2(s));
    let (sp, cp) = phase.sin_cos();
    let virial = a * (fs * cp - fc * sp) / t_tot;
    let cycles = om * t_tot / TAU;
    let e_dis = -a * om * (fc * cp + fs * sp) / cycles;
    let p = model.params();
    let (free_amplitude, free_phase) = if i == 0 {
        let f = free_response(model)?;
        (f.amplitude, f.phase)
    } else {
        let d = p.components().nth(i - 1).expect("component i exists");
        let h = model.free_force_response(om)?;
        (d.force * h.norm(), wrap_phase(-h.arg()))
    };
    // the equivalent point mass of the mode nearest ω_c
    let natural = crate::eigen::natural_modes(model.galerkin().region(Region::Free));
    let mode = (0..model.modes())
        .min_by(|&x, &y| {
            (natural.omega[x] - om)
                .abs()
                .total_cmp(&(natural.omega[y] - om).abs())
        })
        .unwrap_or(0);
    let m = EquivalentMode::of(model, mode);
    Ok(ComponentObservables {
        ratio: om / p.omega,
        amplitude: a,
        phase,
        free_amplitude,
        free_phase,
        virial,
        energy_dissipated: e_dis,
        mode,
        closed_virial: m.virial(a, free_amplitude, phase),
        closed_energy_dissipated: m.energy_dissipated(a, free_amplitude, phase, om),
    })
}

/// dF_c/dτ at a node: ∂F/∂δ δ̇ + ∂F/∂δ̇ δ̈ for the smooth laws (δ = −V_T, partials of
/// [`TipSampleLaw::force`]); 0 where no force acts.
pub(super) fn force_rate(law: &PreparedLaw, r: Region, nd: &Node) -> f64 {
    let contact = r == Region::Contact;
    if !contact && !law.acts_outside() {
        return 0.0;
    }
    let e = law.force(contact, -nd.v[0], -nd.v[1]);
    -e.d_delta * nd.v[1] - e.d_rate * nd.v[2]
}

/// Zero of g on [a, b] between values of opposite signs, by the safeguarded Newton iteration
/// with a central-difference slope (the extremum's value is second-order in the location).
pub(super) fn root_of(a: f64, ga: f64, b: f64, gb: f64, g: &mut dyn FnMut(f64) -> f64) -> f64 {
    let s = if ga > 0.0 { 1.0 } else { -1.0 };
    let h = 1e-6 * (b - a);
    safeguarded_newton(a, s * ga, b, s * gb, 0.0, &mut |t| {
        let v = s * g(t);
        let d = s * (g((t + h).min(b)) - g((t - h).max(a))) / ((t + h).min(b) - (t - h).max(a));
        (v, d)
    })
}
