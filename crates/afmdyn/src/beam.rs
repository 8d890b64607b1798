//! Clamped–free Euler–Bernoulli beam modes φ_i(ξ) (paper eq. 9, Chang & Craig, the paper's ref. 36).
//!
//! The mode shape is φ(ξ) = cosh βξ − cos βξ − σ (sinh βξ − sin βξ) with
//! σ = (cosh β + cos β)/(sinh β + sin β) and β a root of 1 + cos β cosh β = 0.
//! Written this way it cancels catastrophically (cosh βξ ≈ σ sinh βξ ≈ e^{β}/2 ≈ 1e13 at β ≈ 30),
//! so it is evaluated in the equivalent form built on decaying exponentials
//!
//! φ(ξ) = D e^{−β(1−ξ)} + ½(1+σ) e^{−βξ} − cos βξ + σ sin βξ,
//! D = (sin β − cos β − e^{−β}) / (1 − e^{−2β} + 2 e^{−β} sin β),
//!
//! in which every term is O(1) for ξ ∈ [0, 1]. With this normalisation ∫₀¹ φ_i² dξ = 1 and
//! φ_i(1) = 2(−1)^{i+1}; ∫₀¹ φ_i dξ = 2σ_i/β_i in closed form.

use crate::params::MAX_MODES;

/// The i-th root (i = 1, 2, …) of the clamped–free frequency equation 1 + cos β cosh β = 0,
/// to full double precision.
///
/// Solved as cos β + 1/cosh β = 0 (well scaled for every i) by Newton's method from
/// (2i − 1)π/2. β_i² is the dimensionless natural frequency ω_{0i} of eq. 22–23.
///
/// # Panics
/// If `i == 0`.
pub(crate) fn beta_root(i: usize) -> f64 {
    assert!(i >= 1, "mode index starts at 1");
    let mut b = (2.0 * i as f64 - 1.0) * std::f64::consts::FRAC_PI_2;
    for _ in 0..60 {
        let f = b.cos() + 1.0 / b.cosh();
        let df = -b.sin() - b.sinh() / (b.cosh() * b.cosh());
        let step = f / df;
        b -= step;
        if step.abs() <= 1e-16 * b {
            break;
        }
    }
    b
}

/// One clamped–free mode: its wavenumber β and the coefficients of the stable form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BeamMode {
    /// β_i, root of 1 + cos β cosh β = 0.
    pub beta: f64,
    /// σ_i = (cosh β + cos β)/(sinh β + sin β).
    pub sigma: f64,
    d: f64,
}

impl BeamMode {
    /// The i-th mode (i ≥ 1).
    pub(crate) fn new(i: usize) -> Self {
        let beta = beta_root(i);
        let e = (-beta).exp();
        let (s, c) = beta.sin_cos();
        let den = 1.0 - e * e + 2.0 * e * s;
        let sigma = (1.0 + e * e + 2.0 * e * c) / den;
        let d = (s - c - e) / den;
        BeamMode { beta, sigma, d }
    }

    /// The k-th derivative d^kφ/dξ^k at ξ ∈ [0, 1] (k = 0..=4; k = 4 gives β⁴φ).
    pub(crate) fn derivative(&self, k: u32, xi: f64) -> f64 {
        let b = self.beta;
        let x = b * xi;
        let grow = self.d * (-b * (1.0 - xi)).exp();
        let decay = 0.5 * (1.0 + self.sigma) * (-x).exp();
        let (s, c) = x.sin_cos();
        let sign = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
        // derivatives of −cos x + σ sin x cycle with period 4
        let trig = match k % 4 {
            0 => -c + self.sigma * s,
            1 => s + self.sigma * c,
            2 => c - self.sigma * s,
            _ => -s - self.sigma * c,
        };
        b.powi(k as i32) * (grow + sign * decay + trig)
    }

    /// φ(ξ).
    pub(crate) fn value(&self, xi: f64) -> f64 {
        self.derivative(0, xi)
    }

    /// ∫₀¹ φ dξ = 2σ/β (closed form: the bracket of the antiderivative reduces to 2σ because
    /// 1 + cos β cosh β = 0).
    pub(crate) fn integral(&self) -> f64 {
        2.0 * self.sigma / self.beta
    }
}

/// The first N clamped–free modes with their tip values φ_i(1) and integrals ∫φ_i.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ModeShapes {
    modes: Vec<BeamMode>,
}

impl ModeShapes {
    /// The first `n` modes, `n` in 1..=20 (checked by [`crate::Params::validate`] upstream).
    ///
    /// # Panics
    /// If `n` is 0 or larger than `MAX_MODES`.
    pub(crate) fn new(n: usize) -> Self {
        assert!((1..=MAX_MODES).contains(&n), "modes must be in 1..=20");
        ModeShapes {
            modes: (1..=n).map(BeamMode::new).collect(),
        }
    }

    /// The modes, index 0 = mode 1.
    pub(crate) fn modes(&self) -> &[BeamMode] {
        &self.modes
    }

    /// φ_i(ξ) for all i: shape `[N]`.
    pub(crate) fn values(&self, xi: f64) -> Vec<f64> {
        self.modes.iter().map(|m| m.value(xi)).collect()
    }

    /// Tip values φ_i(1): shape `[N]`.
    pub(crate) fn tip(&self) -> Vec<f64> {
        self.values(1.0)
    }

    /// ∫₀¹ φ_i dξ: shape `[N]`.
    pub(crate) fn integrals(&self) -> Vec<f64> {
        self.modes.iter().map(BeamMode::integral).collect()
    }

    /// β_i⁴ = ∫₀¹ φ_i φ_i'''' dξ (with ∫φ_i² = 1): shape `[N]`.
    pub(crate) fn beta4(&self) -> Vec<f64> {
        self.modes.iter().map(|m| m.beta.powi(4)).collect()
    }
}
