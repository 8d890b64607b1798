//! The DOP853 stepper: the explicit Runge–Kutta pair of order 8 with embedded error estimators
//! of orders 5 and 3 and a dense output of order 7 (Dormand & Prince; Hairer, Nørsett & Wanner,
//! *Solving Ordinary Differential Equations I*, 2nd ed., Springer 1993, §II.5 (the method,
//! Table 5.4 and the code `DOP853`), §II.6 (the dense output `CONTD8`), §II.4 (step-size
//! control and the starting step `HINIT`)).
//!
//! Written for [`super::adaptive::Adaptive`], which takes one step at a time and often only one
//! step per stepper (with the variational equations Φ restarts at I every step):
//! - **no heap traffic per step or stage**: every buffer (the 12 stages, the 3 dense-output
//!   stages, the stage state, the dense coefficients) is allocated once per stepper;
//! - **dense output on demand**: the 3 extra stages and the 8 coefficients of the order-7
//!   interpolant are formed on the first interpolation inside the last accepted step (most
//!   steps are never interpolated: only those where a guard may change sign or samples are
//!   taken), saving 3 of 15 function evaluations per step;
//! - **step-size control as `DOP853`**: err = |h| · e₅ / √(n (e₅ + 0.01 e₃)) with
//!   e₅ = Σ(err₅ᵢ/skᵢ)², e₃ = Σ(err₃ᵢ/skᵢ)², skᵢ = atol + rtol·max(|y₀ᵢ|, |y₁ᵢ|); the new step
//!   h·clamp(0.9·err^(−1/8), 0.2, 10), not growing after a rejection, at most `h_max`.
//!
//! The coefficients are those of `DOP853` (Hairer's Fortran, `dop853.f`, 1993), as also
//! tabulated by the `differential-equations` crate (0.7, `tableau/dorman_prince.rs`).

/// A vector field y′ = f(t, y) on slices of one fixed length.
pub(crate) trait Field {
    /// f(t, y) into `dy` (same length as `y`).
    fn eval(&self, t: f64, y: &[f64], dy: &mut [f64]);
}

/// Nodes c of the 12 stages and of the 3 dense-output stages (indices 13–15; 12 is the
/// derivative at the step's end).
pub(crate) const C: [f64; 16] = [
    0.0,
    5.260_015_195_876_773E-2,
    7.890_022_793_815_16E-2,
    1.183_503_419_072_274E-1,
    2.816_496_580_927_726E-1,
    3.333_333_333_333_333E-1,
    0.25,
    3.076_923_076_923_077E-1,
    6.512_820_512_820_513E-1,
    0.6,
    8.571_428_571_428_571E-1,
    1.0,
    1.0,
    0.1,
    0.2,
    7.777_777_777_777_778E-1,
];

/// The stage coefficients a_ij (row i uses stages j < i), the last three rows those of the
/// dense output.
#[rustfmt::skip]
const A: [[f64; 15]; 16] = [
    [0.0; 15],
    [5.260_015_195_876_773E-2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [1.972_505_698_453_79E-2, 5.917_517_095_361_37E-2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [2.958_758_547_680_685E-2, 0.0, 8.876_275_643_042_054E-2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [2.413_651_341_592_667E-1, 0.0, -8.845_494_793_282_861E-1, 9.248_340_032_617_92E-1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.703_703_703_703_703_5E-2, 0.0, 0.0, 1.708_286_087_294_738_6E-1, 1.254_676_875_668_224_2E-1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.710_937_5E-2, 0.0, 0.0, 1.702_522_110_195_440_5E-1, 6.021_653_898_045_596E-2, -1.757_812_5E-2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.709_200_011_850_479E-2, 0.0, 0.0, 1.703_839_257_122_399_8E-1, 1.072_620_304_463_732_8E-1, -1.531_943_774_862_440_2E-2, 8.273_789_163_814_023E-3, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [6.241_109_587_160_757E-1, 0.0, 0.0, -3.360_892_629_446_941_4, -8.682_193_468_417_26E-1, 2.759_209_969_944_671E1, 2.015_406_755_047_789_4E1, -4.348_988_418_106_996E1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [4.776_625_364_382_643_4E-1, 0.0, 0.0, -2.488_114_619_971_667_7, -5.902_908_268_368_43E-1, 2.123_005_144_818_119_3E1, 1.527_923_363_288_242_3E1, -3.328_821_096_898_486E1, -2.033_120_170_850_862_7E-2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [-9.371_424_300_859_873E-1, 0.0, 0.0, 5.186_372_428_844_064, 1.091_437_348_996_729_5, -8.149_787_010_746_927, -1.852_006_565_999_696E1, 2.273_948_709_935_050_5E1, 2.493_605_552_679_652_3, -3.046_764_471_898_219_6, 0.0, 0.0, 0.0, 0.0, 0.0],
    [2.273_310_147_516_538, 0.0, 0.0, -1.053_449_546_673_725E1, -2.000_872_058_224_862_5, -1.795_893_186_311_88E1, 2.794_888_452_941_996E1, -2.858_998_277_135_023_5, -8.872_856_933_530_63, 1.236_056_717_579_430_3E1, 6.433_927_460_157_636E-1, 0.0, 0.0, 0.0, 0.0],
    [0.0; 15],
    [5.616_750_228_304_795_4E-2, 0.0, 0.0, 0.0, 0.0, 0.0, 2.535_002_102_166_248_3E-1, -2.462_390_374_708_025E-1, -1.241_914_232_638_163_7E-1, 1.532_917_982_787_656_8E-1, 8.201_052_295_634_69E-3, 7.567_897_660_545_699E-3, -8.298E-3, 0.0, 0.0],
    [3.183_464_816_350_214E-2, 0.0, 0.0, 0.0, 0.0, 2.830_090_967_236_677_6E-2, 5.354_198_830_743_856_6E-2, -5.492_374_857_139_099E-2, 0.0, 0.0, -1.083_473_286_972_493_2E-4, 3.825_710_908_356_584E-4, -3.404_650_086_874_045_6E-4, 1.413_124_436_746_325E-1, 0.0],
    [-4.288_963_015_837_919_4E-1, 0.0, 0.0, 0.0, 0.0, -4.697_621_415_361_164, 7.683_421_196_062_599, 4.068_989_818_397_11, 3.567_271_874_552_811E-1, 0.0, 0.0, 0.0, -1.399_024_165_159_014_5E-3, 2.947_514_789_152_772_4, -9.150_958_472_179_87],
];

/// Weights b of the order-8 solution (stages 1–12).
const B: [f64; 12] = [
    5.429_373_411_656_876_5E-2,
    0.0,
    0.0,
    0.0,
    0.0,
    4.450_312_892_752_409,
    1.891_517_899_314_500_3,
    -5.801_203_960_010_585,
    3.111_643_669_578_199E-1,
    -1.521_609_496_625_161E-1,
    2.013_654_008_040_303_4E-1,
    4.471_061_572_777_259E-2,
];

/// Weights of the order-3 estimator: err₃ = Σ b k − (bh₁ k₁ + bh₉ k₉ + bh₁₂ k₁₂).
const BH: [(usize, f64); 3] = [
    (0, 2.440_944_881_889_764E-1),
    (8, 7.338_466_882_816_118E-1),
    (11, 2.205_882_352_941_176_6E-2),
];

/// Weights of the order-5 estimator err₅ = Σ er k.
const ER: [(usize, f64); 8] = [
    (0, 1.312_004_499_419_488E-2),
    (5, -1.225_156_446_376_204_4),
    (6, -4.957_589_496_572_502E-1),
    (7, 1.664_377_182_454_986_4),
    (8, -3.503_288_487_499_736_6E-1),
    (9, 3.341_791_187_130_175E-1),
    (10, 8.192_320_648_511_571E-2),
    (11, -2.235_530_786_388_629_4E-2),
];

/// Coefficients d of the dense output's cont₄…cont₇ = h Σⱼ d_ij kⱼ over the 16 stages.
#[rustfmt::skip]
const D: [[f64; 16]; 4] = [
    [-8.428_938_276_109_013, 0.0, 0.0, 0.0, 0.0, 5.667_149_535_193_777E-1, -3.068_949_945_949_891_7, 2.384_667_656_512_07, 2.117_034_582_445_028, -8.713_915_837_779_73E-1, 2.240_437_430_260_788_3, 6.315_787_787_694_688E-1, -8.899_033_645_133_331E-2, 1.814_850_552_085_472_7E1, -9.194_632_392_478_356, -4.436_036_387_594_894],
    [1.042_750_864_257_913_4E1, 0.0, 0.0, 0.0, 0.0, 2.422_834_917_752_581_7E2, 1.652_004_517_172_702_8E2, -3.745_467_547_226_902E2, -2.211_366_685_312_530_6E1, 7.733_432_668_472_264, -3.067_408_473_108_939_8E1, -9.332_130_526_430_229, 1.569_723_812_177_084_5E1, -3.113_940_321_956_517_8E1, -9.352_924_358_844_48, 3.581_684_148_639_408E1],
    [1.998_505_324_200_243_3E1, 0.0, 0.0, 0.0, 0.0, -3.870_373_087_493_518E2, -1.891_781_381_951_675_8E2, 5.278_081_592_054_236E2, -1.157_390_253_995_963E1, 6.881_232_694_696_3, -1.000_605_096_691_083_8, 7.777_137_798_053_443E-1, -2.778_205_752_353_508, -6.019_669_523_126_412E1, 8.432_040_550_667_716E1, 1.199_229_113_618_279E1],
    [-2.569_393_346_270_375E1, 0.0, 0.0, 0.0, 0.0, -1.541_897_486_902_364_3E2, -2.315_293_791_760_455E2, 3.576_391_179_106_141E2, 9.340_532_418_362_432E1, -3.745_832_313_645_163E1, 1.040_996_495_089_623E2, 2.984_029_342_666_05E1, -4.353_345_659_001_114E1, 9.632_455_395_918_828E1, -3.917_726_167_561_544E1, -1.497_268_362_579_856_4E2],
];

/// out = base + h Σⱼ wⱼ kⱼ (base 0 when `None`), kⱼ the j-th length-n block of `k`.
fn combine(out: &mut [f64], base: Option<&[f64]>, h: f64, w: &[f64], k: &[f64], n: usize) {
    match base {
        Some(b) => out.copy_from_slice(b),
        None => out.fill(0.0),
    }
    for (j, &wj) in w.iter().enumerate() {
        if wj != 0.0 {
            axpy(out, h * wj, &k[j * n..(j + 1) * n]);
        }
    }
}

/// y += a x.
fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

/// Safety factor and the bounds of the step-size ratio.
const SAFETY: f64 = 0.9;
const MIN_SCALE: f64 = 0.2;
const MAX_SCALE: f64 = 10.0;

/// Why a step could not be taken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum StepFailure {
    /// The step size is not positive and finite, or fell below 1e-14 of the last accepted one.
    StepSizeUnderflow {
        /// Time of the step.
        t: f64,
        /// The step size.
        h: f64,
    },
}

impl std::fmt::Display for StepFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StepFailure::StepSizeUnderflow { t, h } => write!(
                f,
                "DOP853 step size {h:e} at t = {t:e} collapsed (below 1e-14 of the last accepted step)"
            ),
        }
    }
}

/// A DOP853 stepper of an n-dimensional system (module docs).
#[derive(Debug, Clone)]
pub(crate) struct Dop853 {
    n: usize,
    rtol: f64,
    atol: f64,
    h_max: f64,
    t: f64,
    t_prev: f64,
    h: f64,
    h_prev: f64,
    y: Vec<f64>,
    y_prev: Vec<f64>,
    /// Stages of the step being attempted, 16 × n: k₁…k₁₂, f(t + h, y₁), the 3 dense stages.
    work: Vec<f64>,
    /// The stages of the last accepted step (swapped with `work` on acceptance).
    accepted: Vec<f64>,
    /// Stage state.
    tmp: Vec<f64>,
    /// The proposed solution of the attempt.
    y_new: Vec<f64>,
    /// The order-5 error estimate of the attempt.
    err: Vec<f64>,
    /// cont₀…cont₇ of the last accepted step, 8 × n.
    cont: Vec<f64>,
    /// Whether `cont` is formed for the last accepted step.
    dense_ready: bool,
    /// The last attempt was rejected (the next step may not grow).
    rejected: bool,
    /// The leading components under error control (n, all of them, unless
    /// [`Dop853::set_controlled`] narrowed it for an attempt).
    controlled: usize,
}

impl Dop853 {
    /// A stepper of dimension `n` with relative and absolute tolerances and the largest step.
    ///
    /// Every component is under error control, the variational equations appended to a state
    /// included: with the Hertz and DMT laws the Jacobian has a √δ singularity at the contact
    /// onset that the state's error does not see (controlling the state alone moved Floquet
    /// multipliers by 5e-7 against an independent integrator). The one exception is the
    /// adaptive integrator's remainder step of a few ulps that it could not otherwise take
    /// ([`Dop853::set_controlled`]).
    pub(crate) fn new(n: usize, rtol: f64, atol: f64, h_max: f64) -> Self {
        Dop853 {
            n,
            rtol,
            atol,
            h_max,
            t: 0.0,
            t_prev: 0.0,
            h: 0.0,
            h_prev: 0.0,
            y: vec![0.0; n],
            y_prev: vec![0.0; n],
            work: vec![0.0; 16 * n],
            accepted: vec![0.0; 16 * n],
            tmp: vec![0.0; n],
            y_new: vec![0.0; n],
            err: vec![0.0; n],
            cont: vec![0.0; 8 * n],
            dense_ready: false,
            rejected: false,
            controlled: n,
        }
    }

    /// Start at (t, y): evaluates f(t, y) (the first stage); with `h0` ≤ 0 the starting step is
    /// chosen as `HINIT` does (one more evaluation). No allocation.
    pub(crate) fn init<F: Field + ?Sized>(&mut self, f: &F, t: f64, y: &[f64], h0: f64) {
        let n = self.n;
        self.t = t;
        self.t_prev = t;
        self.y.copy_from_slice(y);
        self.y_prev.copy_from_slice(y);
        f.eval(t, y, &mut self.work[..n]);
        self.rejected = false;
        self.dense_ready = false;
        self.controlled = n;
        self.h = if h0 > 0.0 { h0 } else { self.initial_step(f) };
        self.h = self.h.min(self.h_max);
        self.h_prev = self.h;
        // the "accepted" step is the empty one at t: its interpolant is constant
        self.accepted.copy_from_slice(&self.work);
    }

    /// Hairer et al. §II.4, p. 169 (`HINIT` of `DOP853`, order 8).
    fn initial_step<F: Field + ?Sized>(&mut self, f: &F) -> f64 {
        let n = self.n;
        let (f0, rest) = self.work.split_at_mut(n);
        let (atol, rtol) = (self.atol, self.rtol);
        let sk = |y: f64| atol + rtol * y.abs();
        let mut dnf = 0.0;
        let mut dny = 0.0;
        for (y, f) in self.y.iter().zip(f0.iter()) {
            dnf += (f / sk(*y)).powi(2);
            dny += (y / sk(*y)).powi(2);
        }
        let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
            1e-6
        } else {
            (dny / dnf).sqrt() * 0.01
        };
        h = h.min(self.h_max);
        for ((t, y), f) in self.tmp.iter_mut().zip(&self.y).zip(f0.iter()) {
            *t = y + h * f;
        }
        let f1 = &mut rest[..n];
        f.eval(self.t + h, &self.tmp, f1);
        let mut der2 = 0.0;
        for ((y, a), b) in self.y.iter().zip(f1.iter()).zip(f0.iter()) {
            der2 += ((a - b) / sk(*y)).powi(2);
        }
        let der2 = der2.sqrt() / h;
        let der12 = der2.abs().max(dnf.sqrt());
        let h1 = if der12 <= 1e-15 {
            (h * 1e-3).max(1e-6)
        } else {
            (0.01 / der12).powf(1.0 / 8.0)
        };
        (100.0 * h).min(h1).min(self.h_max)
    }

    /// Current time (end of the last accepted step).
    pub(crate) fn t(&self) -> f64 {
        self.t
    }
    /// Start of the last accepted step.
    pub(crate) fn t_prev(&self) -> f64 {
        self.t_prev
    }
    /// Current state.
    pub(crate) fn y(&self) -> &[f64] {
        &self.y
    }
    /// State at the start of the last accepted step.
    pub(crate) fn y_prev(&self) -> &[f64] {
        &self.y_prev
    }
    /// Step size of the next attempt.
    pub(crate) fn h(&self) -> f64 {
        self.h
    }
    /// Set the step size of the next attempt (capped at `h_max`).
    pub(crate) fn set_h(&mut self, h: f64) {
        self.h = h.min(self.h_max);
    }

    /// Put only the first `m` (≤ n) components under error control from the next attempt on;
    /// `m` = n (the default) controls every component. The adaptive integrator narrows it to the
    /// state for the one step it cannot otherwise take (`integrate/adaptive.rs`, `advance`), as
    /// CVODES lets sensitivities out of the error test (`CVodeSetSensErrCon`; Hindmarsh et al.,
    /// *ACM TOMS* 31 (2005) 363, §3.2).
    pub(crate) fn set_controlled(&mut self, m: usize) {
        self.controlled = m.min(self.n);
    }

    /// One attempt with the current step size: `Ok(true)` when accepted (t, y advance; the
    /// interpolant covers the step), `Ok(false)` when rejected (h shrinks). 11 evaluations of
    /// `f` (12 with the derivative at an accepted end), nothing allocated.
    ///
    /// # Errors
    /// [`StepFailure::StepSizeUnderflow`] when h is not positive and finite or below 1e-14 of
    /// the last accepted step.
    pub(crate) fn step<F: Field + ?Sized>(&mut self, f: &F) -> Result<bool, StepFailure> {
        let n = self.n;
        let h = self.h;
        if !(h > 0.0 && h.is_finite()) || h < 1e-14 * self.h_prev {
            return Err(StepFailure::StepSizeUnderflow { t: self.t, h });
        }
        // stages 2…12 (the first is f(t, y), kept from the last accepted step); every sum is
        // a run of axpys over whole stage vectors
        for i in 1..12 {
            let (done, rest) = self.work.split_at_mut(i * n);
            combine(&mut self.tmp, Some(&self.y), h, &A[i][..i], done, n);
            f.eval(self.t + C[i] * h, &self.tmp, &mut rest[..n]);
        }
        // the solution and both error estimators
        let k = &self.work;
        combine(&mut self.tmp, None, 1.0, &B, k, n);
        self.err.fill(0.0);
        for &(j, c) in &ER {
            axpy(&mut self.err, c, &k[j * n..(j + 1) * n]);
        }
        let (mut e5, mut e3) = (0.0, 0.0);
        for m in 0..n {
            let bk = self.tmp[m];
            let y1 = self.y[m] + h * bk;
            self.y_new[m] = y1;
            if m >= self.controlled {
                continue;
            }
            let sk = self.atol + self.rtol * self.y[m].abs().max(y1.abs());
            let err3 = bk - BH.iter().map(|&(j, c)| c * k[j * n + m]).sum::<f64>();
            e5 += (self.err[m] / sk).powi(2);
            e3 += (err3 / sk).powi(2);
        }
        let mut deno = e5 + 0.01 * e3;
        if deno <= 0.0 {
            deno = 1.0;
        }
        let err = h.abs() * e5 * (1.0 / (deno * self.controlled as f64)).sqrt();
        let mut scale = if err.is_finite() {
            (SAFETY * err.powf(-1.0 / 8.0)).clamp(MIN_SCALE, MAX_SCALE)
        } else {
            MIN_SCALE
        };
        if err.is_finite() && err <= 1.0 {
            let t_new = self.t + h;
            let (_, end) = self.work.split_at_mut(12 * n);
            f.eval(t_new, &self.y_new, &mut end[..n]);
            if self.rejected {
                scale = scale.min(1.0);
            }
            self.rejected = false;
            std::mem::swap(&mut self.work, &mut self.accepted);
            self.y_prev.copy_from_slice(&self.y);
            self.y.copy_from_slice(&self.y_new);
            self.t_prev = self.t;
            self.t = t_new;
            self.h_prev = h;
            self.dense_ready = false;
            // FSAL: the next step's first stage
            let (first, _) = self.work.split_at_mut(n);
            first.copy_from_slice(&self.accepted[12 * n..13 * n]);
            self.h = (h * scale).min(self.h_max);
            Ok(true)
        } else {
            self.rejected = true;
            self.h = (h * scale).min(self.h_max);
            Ok(false)
        }
    }

    /// The interpolant's coefficients cont₀…cont₇ of the last accepted step (Hairer et al.
    /// §II.6, `DOP853`'s dense output): 3 more evaluations of `f`.
    fn form_dense<F: Field + ?Sized>(&mut self, f: &F) {
        let n = self.n;
        let h = self.h_prev;
        for i in 13..16 {
            let (done, rest) = self.accepted.split_at_mut(i * n);
            combine(&mut self.tmp, Some(&self.y_prev), h, &A[i][..i], done, n);
            f.eval(self.t_prev + C[i] * h, &self.tmp, &mut rest[..n]);
        }
        let k = &self.accepted;
        for m in 0..n {
            let ydiff = self.y[m] - self.y_prev[m];
            let bspl = h * k[m] - ydiff;
            self.cont[m] = self.y_prev[m];
            self.cont[n + m] = ydiff;
            self.cont[2 * n + m] = bspl;
            self.cont[3 * n + m] = ydiff - h * k[12 * n + m] - bspl;
        }
        for (r, d) in D.iter().enumerate() {
            let (_, out) = self.cont.split_at_mut((4 + r) * n);
            combine(&mut out[..n], None, h, d, k, n);
        }
        self.dense_ready = true;
    }

    /// The order-7 interpolant of the last accepted step at `t` (clamped into
    /// [t_prev, t]): its first `out.len()` (≤ n) components into `out`; the dense stages are
    /// formed on the first call.
    pub(crate) fn interpolate<F: Field + ?Sized>(&mut self, f: &F, t: f64, out: &mut [f64]) {
        let n = self.n;
        let len = out.len();
        if self.t == self.t_prev || t >= self.t {
            out.copy_from_slice(&self.y[..len]);
            return;
        }
        if t <= self.t_prev {
            out.copy_from_slice(&self.y_prev[..len]);
            return;
        }
        if !self.dense_ready {
            self.form_dense(f);
        }
        let s = (t - self.t_prev) / self.h_prev;
        let s1 = 1.0 - s;
        let c = &self.cont;
        for m in 0..len {
            let conpar = c[4 * n + m] + s * (c[5 * n + m] + s1 * (c[6 * n + m] + s * c[7 * n + m]));
            out[m] = c[m] + s * (c[n + m] + s1 * (c[2 * n + m] + s * (c[3 * n + m] + s1 * conpar)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y″ = −y as a first-order system: y = (cos t, −sin t) from (1, 0).
    struct Harmonic;
    impl Field for Harmonic {
        fn eval(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[1];
            dy[1] = -y[0];
        }
    }

    /// y′ = y² from y(0) = 1: y = 1/(1 − t), a blow-up at t = 1 that needs the step control.
    struct Riccati;
    impl Field for Riccati {
        fn eval(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[0] * y[0];
        }
    }

    fn run<F: Field>(f: &F, y0: &[f64], t_end: f64, tol: f64) -> (Dop853, usize) {
        let mut s = Dop853::new(y0.len(), tol, tol, f64::INFINITY);
        s.init(f, 0.0, y0, 0.0);
        let mut steps = 0;
        while s.t() < t_end {
            if s.t() + s.h() > t_end {
                s.set_h(t_end - s.t());
            }
            s.step(f).unwrap();
            steps += 1;
            assert!(steps < 100_000);
        }
        (s, steps)
    }

    /// The global error of the harmonic oscillator over 10 periods follows the tolerance
    /// (within a factor 100 of it, the usual DOP853 behaviour) and the method has order 8:
    /// with fixed steps h and h/2 the error ratio is near 2⁸ = 256.
    #[test]
    fn harmonic_oscillator_accuracy_and_order() {
        let t_end = 20.0 * std::f64::consts::PI;
        for tol in [1e-6, 1e-9, 1e-12] {
            let (s, _) = run(&Harmonic, &[1.0, 0.0], t_end, tol);
            let e = (s.y()[0] - t_end.cos()).abs() + (s.y()[1] + t_end.sin()).abs();
            assert!(e < 100.0 * tol, "tol {tol}: error {e}");
        }
        let fixed = |h: f64| {
            let mut s = Dop853::new(2, 1.0, 1.0, h);
            s.init(&Harmonic, 0.0, &[1.0, 0.0], h);
            let steps = (2.0 / h).round() as usize;
            for _ in 0..steps {
                s.set_h(h);
                assert!(s.step(&Harmonic).unwrap(), "tolerance 1 accepts every step");
            }
            (s.y()[0] - s.t().cos()).abs()
        };
        let ratio = fixed(0.25) / fixed(0.125);
        assert!((150.0..450.0).contains(&ratio), "order-8 ratio {ratio}");
    }

    /// The interpolant is of order 7: inside one fixed step h its error at the midpoint falls
    /// by about 2⁸ = 256 when h halves (local error O(h⁸)), and it meets both ends exactly.
    #[test]
    fn dense_output_order_seven() {
        let mid_error = |h: f64| {
            let mut s = Dop853::new(2, 1.0, 1.0, h);
            s.init(&Harmonic, 0.0, &[1.0, 0.0], h);
            assert!(s.step(&Harmonic).unwrap());
            let mut out = [0.0; 2];
            s.interpolate(&Harmonic, 0.3 * h, &mut out);
            let e = (out[0] - (0.3 * h).cos()).abs() + (out[1] + (0.3 * h).sin()).abs();
            s.interpolate(&Harmonic, h, &mut out);
            assert_eq!(out, [s.y()[0], s.y()[1]]);
            e
        };
        let ratio = mid_error(0.4) / mid_error(0.2);
        assert!(
            (150.0..600.0).contains(&ratio),
            "order-7 interpolant ratio {ratio}"
        );
        assert!(mid_error(0.2) < 1e-10);
    }

    /// Near the blow-up of y′ = y² the step control rejects and shrinks steps yet stays within
    /// the tolerance: y(0.9) = 10.
    #[test]
    fn riccati_near_blow_up() {
        let (s, steps) = run(&Riccati, &[1.0], 0.9, 1e-10);
        assert!((s.y()[0] - 10.0).abs() < 1e-7 * 10.0, "{}", s.y()[0]);
        assert!(steps > 10);
    }
}
