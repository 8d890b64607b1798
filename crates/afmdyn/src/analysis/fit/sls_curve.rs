//! The standard linear solid's force curve: the registry's `sls` law
//! ([`crate::contact::sls`]) under a recorded approach, dwell and retract, in time, for the
//! quasi-static force-curve fit ([`super::force_curve`]'s preprocessing gives the tip position
//! x and the force of every row, hence the piezo height; the rows' times come from the data).
//!
//! # Model
//! The sample is the law's Zener solid in SI (López-Guerra & Solares, *Beilstein J.
//! Nanotechnol.* 5 (2014) 2149, §2; Zener 1948): the relaxed spring k₁ (N/m) in parallel with a
//! Maxwell arm, the spring k₂ (N/m) in series with a dashpot η = k₂τ (τ the relaxation time,
//! s). Its state is the dashpot's extension u (m). The indentation is δ = contact_point − x.
//! - In contact the surface follows the tip: F_c = k₁δ + k₂(δ − u), u̇ = (δ − u)/τ.
//! - Free, the surface sits where its springs balance, at the depression s(u) = k₂u/(k₁ + k₂),
//!   and recovers as u̇ = −k₁u/(τ(k₁ + k₂)); F_c = 0.
//! - The tip touches the surface where δ ≥ s(u), which is where F_c ≥ 0: the force never
//!   pulls, and the tip leaves the surface where F_c falls to 0 (the law's guard
//!   σ(V_T + s(u))).
//!
//! The sample is driven as the instrument drove it: through the lever (spring constant k) in
//! series, from the piezo's height h (m) of every row, which carries no force noise. (Taking
//! the tip position x = h + F/k from the measured force instead, as the elastic laws' fit does,
//! puts the force noise into the regressor: on a dwell's curve at 200 pN noise that biased k₂ by
//! 11 %.) In the preprocessed frame h = x − F/k (x and F the preprocessed tip position and
//! force), and F = baseline + F_c with the lever bent by F_c: x = h + F_c/k. In contact this
//! gives δ = (k(cp − h) + k₂u)/K, K = k + k₁ + k₂, and
//! - F_c = k[(k₁ + k₂)(cp − h) − k₂u]/K;
//! - u̇ = (g − u)/τ_e, with the equilibrium g = k(cp − h)/(k + k₁) and τ_e = τK/(k + k₁);
//! - the contact condition δ ≥ s(u) reads cp − h ≥ s(u).
//!
//! The sample is at rest (u = 0) at the first row, which must lie before the contact. Between
//! rows h is taken as linear in time (a first-order hold on the recorded piezo height, exact for
//! the ramps and holds of a force curve), under which the contact's u has the closed form
//! u(t + Δt) = g₁ − ġτ_e + (u − g₀ + ġτ_e)e^{−Δt/τ_e} (the linear ODE's solution) and the free
//! recovery u(t + Δt) = u e^{−Δt k₁/(τ(k₁+k₂))}. The region of each interval is that of its first
//! row, so a contact's start or end is located to the rows' spacing.
//!
//! For a stiff lever (k → ∞, x = h) under a ramp δ = vt held at δ₀ after t_r this is the SLS's
//! relaxation F = k₁δ₀ + k₂vτ(1 − e^{−t_r/τ})e^{−(t−t_r)/τ}, and under a constant force F₀ (the
//! piezo following h = x − F₀/k) the creep δ = F₀/k₁ − (F₀/k₁ − F₀/(k₁+k₂))e^{−t/τ_c},
//! τ_c = τ(k₁+k₂)/k₁ (Lakes, *Viscoelastic Materials*, CUP 2009, §2.3–2.4): the fit takes a
//! height-clamped dwell (relaxation and the lever's creep) and a force-clamped one alike.
//!
//! # Sensitivities
//! Exact for this discrete model: the recurrence is evaluated in forward-mode dual numbers
//! carrying ∂/∂(k₁, k₂, τ, contact_point); ∂F/∂baseline = 1. The region of each row is held
//! (F_c = 0 where it switches, so F is continuous there).

use super::CurveModel;

pub(crate) use super::force_curve::{MAXWELL_STIFFNESS, RELAXATION_TIME, STIFFNESS};

/// The parameters the SLS fit frees by default: its three, the contact point and the baseline.
/// The baseline is freed because the preprocessing's force offset (the mean force before the
/// contact found by `deviation_from_baseline`) takes in the rows of the contact's first rise
/// below its threshold; held, that offset biased k₁ (the 95 % intervals covered k₁ in 86 of
/// 100 draws at 200 pN noise, against 95 expected).
pub(crate) const DEFAULT_FIT: [&str; 5] = [
    STIFFNESS,
    MAXWELL_STIFFNESS,
    RELAXATION_TIME,
    super::force_curve::CONTACT_POINT,
    super::force_curve::BASELINE,
];

/// The SLS force-curve model (module docs) over every row of a curve in time order, valued
/// at the fitted rows. Parameters: k₁ (N/m), k₂ (N/m), τ (s), contact_point (m), baseline (N).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SlsCurveModel {
    /// The piezo height h (m) of every row in the preprocessed frame (x − F/k).
    pub height: Vec<f64>,
    /// The time (s) of every row, strictly increasing.
    pub t: Vec<f64>,
    /// The lever's spring constant k (N/m; `f64::INFINITY` for the tip at h).
    pub spring_constant: f64,
    /// The rows fitted (indices into `height`, increasing).
    pub rows: Vec<usize>,
}

/// A forward-mode dual number: a value and its derivatives by (k₁, k₂, τ, contact_point).
#[derive(Debug, Clone, Copy, Default)]
struct Dual(f64, [f64; 4]);

impl Dual {
    fn var(v: f64, i: usize) -> Dual {
        let mut d = [0.0; 4];
        d[i] = 1.0;
        Dual(v, d)
    }
    fn map(self, v: f64, dv: f64) -> Dual {
        Dual(v, self.1.map(|d| d * dv))
    }
    fn exp(self) -> Dual {
        let e = self.0.exp();
        self.map(e, e)
    }
    fn recip(self) -> Dual {
        self.map(1.0 / self.0, -1.0 / (self.0 * self.0))
    }
}

impl std::ops::Add for Dual {
    type Output = Dual;
    fn add(self, o: Dual) -> Dual {
        Dual(self.0 + o.0, std::array::from_fn(|i| self.1[i] + o.1[i]))
    }
}
impl std::ops::Sub for Dual {
    type Output = Dual;
    fn sub(self, o: Dual) -> Dual {
        Dual(self.0 - o.0, std::array::from_fn(|i| self.1[i] - o.1[i]))
    }
}
impl std::ops::Mul for Dual {
    type Output = Dual;
    // the product rule
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn mul(self, o: Dual) -> Dual {
        Dual(
            self.0 * o.0,
            std::array::from_fn(|i| self.1[i] * o.0 + self.0 * o.1[i]),
        )
    }
}
impl std::ops::Div for Dual {
    type Output = Dual;
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, o: Dual) -> Dual {
        self * o.recip()
    }
}
impl std::ops::Mul<Dual> for f64 {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        Dual(self * o.0, o.1.map(|d| self * d))
    }
}

impl SlsCurveModel {
    /// The contact force F_c (N) of every row, and ∂F_c/∂(k₁, k₂, τ, contact_point) when
    /// `jacobian` is given (row-major, 4 per row).
    pub(crate) fn forces(&self, p: &[f64], forces: &mut [f64], mut jacobian: Option<&mut [f64]>) {
        let (k1, k2, tau, cp) = (
            Dual::var(p[0], 0),
            Dual::var(p[1], 1),
            Dual::var(p[2], 2),
            Dual::var(p[3], 3),
        );
        let k = self.spring_constant;
        let sum = k1 + k2;
        let gain = k2 / sum;
        // the lever in series (module docs): g = g_of·(cp − h), u̇ = rate_e·(g − u) and
        // F_c = a(cp − h) − b·u; a rigid lever (k = ∞) leaves the tip at h
        let (g_of, rate_e, a, b) = if k.is_finite() {
            let lever = Dual(k, [0.0; 4]);
            let big = lever + sum;
            (
                k * (lever + k1).recip(),
                (lever + k1) / (big * tau),
                k * sum / big,
                k * k2 / big,
            )
        } else {
            (Dual(1.0, [0.0; 4]), tau.recip(), sum, k2)
        };
        let free_rate = k1 / (tau * sum);
        let mut u = Dual::default();
        let mut contact = false;
        // e^{−Δt·rate} of the contact and of the free surface, kept while Δt repeats (an
        // evenly sampled curve computes each once)
        let mut decay: Option<(f64, Dual, Dual)> = None;
        for i in 0..self.height.len() {
            // cp − h: the indentation of a rigid lever
            let d = cp - Dual(self.height[i], [0.0; 4]);
            if i > 0 {
                let dt = self.t[i] - self.t[i - 1];
                let (e_contact, e_free) = match decay {
                    Some((h, c, f)) if h == dt => (c, f),
                    _ => {
                        let c = (-dt * rate_e).exp();
                        let f = (-dt * free_rate).exp();
                        decay = Some((dt, c, f));
                        (c, f)
                    }
                };
                if contact {
                    let d0 = cp - Dual(self.height[i - 1], [0.0; 4]);
                    let (g0, g1) = (g_of * d0, g_of * d);
                    // ġ τ_e = (g₁ − g₀)/(Δt · rate_e)
                    let slope = (g1 - g0) / (dt * rate_e);
                    u = g1 - slope + (u - g0 + slope) * e_contact;
                } else {
                    u = u * e_free;
                }
            }
            contact = d.0 >= (gain * u).0;
            let f = if contact {
                a * d - b * u
            } else {
                Dual::default()
            };
            forces[i] = f.0;
            if let Some(j) = jacobian.as_deref_mut() {
                j[4 * i..4 * i + 4].copy_from_slice(&f.1);
            }
        }
    }
}

impl CurveModel for SlsCurveModel {
    fn points(&self) -> usize {
        self.rows.len()
    }
    fn evaluate(&self, p: &[f64], values: &mut [f64], jacobian: Option<&mut [f64]>) {
        let n = self.height.len();
        let mut forces = vec![0.0; n];
        let mut dforce = jacobian.is_some().then(|| vec![0.0; 4 * n]);
        self.forces(p, &mut forces, dforce.as_deref_mut());
        let np = p.len();
        for (k, &i) in self.rows.iter().enumerate() {
            values[k] = p[4] + forces[i];
        }
        if let (Some(j), Some(d)) = (jacobian, dforce) {
            for (k, &i) in self.rows.iter().enumerate() {
                let row = &mut j[k * np..(k + 1) * np];
                row[..4].copy_from_slice(&d[4 * i..4 * i + 4]);
                row[4] = 1.0;
            }
        }
    }
}
