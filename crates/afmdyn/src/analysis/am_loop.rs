//! AM-AFM's amplitude feedback in the time domain: the cantilever integrated drive period after
//! drive period while the sample under the tip changes (a scan line), a lock-in amplifier
//! measuring the tip's first harmonic and a PI controller moving the z piezo to hold it at the
//! setpoint, as an instrument's digital loops do once per drive period — the scanning AM-AFM of
//! VEDA (Kiracofe, Melcher & Raman, *Rev. Sci. Instrum.* 83 (2012) 013702, with continuous-time
//! loops) and of the control model of Stirling (*Beilstein J. Nanotechnol.* 5 (2014) 337).
//! [`crate::request::image_scan`] builds an image from its lines.
//!
//! Units are the model's: τ (eq. 5) and lengths in g₀.
//!
//! **Lock-in** (`LockIn`). Over drive period k the deflection W(1,τ) is sampled at the ends of
//! M equal parts (θ_j = Ωτ_j + ψ, ψ the drive's phase) and demodulated by the rectangle rule,
//! X_k = (2/M) Σ_j W_j sin θ_j = A cos φ, Y_k = −(2/M) Σ_j W_j cos θ_j = A sin φ for
//! W = ⟨W⟩ + A sin(θ − φ): exact for a periodic motion but for the harmonics M ± 1, 2M ± 1, …
//! that alias onto the first (a digital lock-in sampling at M times the drive frequency). The
//! sines and cosines come from one of each per period: θ₀ = Ωτ₀ + ψ rotated by ΩT/M at each
//! sample (M rotations of a few ulp each: within 1e-14 of sin θ_j, while Ωτ itself carries
//! the rounding of τ, about 1e-10 after 10⁵ periods). The
//! output low-pass is first order with time constant τ_L, sampled exactly for an input held
//! over the period T: X̄_k = X̄_{k−1} + β (X_k − X̄_{k−1}), β = 1 − e^{−T/τ_L} (β = 1 for
//! τ_L = 0: the period's own boxcar average); A = |(X̄, Ȳ)|, φ = arg(X̄ + iȲ).
//!
//! **PI controller** (`PiController`). With the error e_k = A_sp − A_k (positive when the tip
//! presses too hard and the amplitude drops) the piezo's rest distance for the next period is
//! z_{k+1} = z_origin + K_P e_k + K_I T Σ_{j≤k} e_j (position form; K_P dimensionless, K_I per
//! unit time), held within the output range given; a period at a limit counts as saturated and
//! does not integrate an error that drives the output further out (conditional integration
//! against wind-up).
//!
//! **Default gains** (`FeedbackGains::for_lever`). The amplitude answers a step of z within
//! τ_c = 2Q/ω₀ (the lever's amplitude decay time) and, in both regimes, by about the step
//! (dA/dz_c ≈ 1 on an approach curve), so with the lock-in's delay the loop is an integrator
//! over a first-order lag τ_c + τ_L: K_I = 1/(4(τ_c + τ_L)) damps it critically
//! (s²(τ_c + τ_L) + s + K_I = 0 has a double root). The lock-in's default time constant is
//! τ_c/4, K_P = 0.

use super::observables::{observe, wrap_phase, ObservableOptions, Observables};
use crate::error::SimError;
use crate::integrate::dense::{sample_dense, SpanSampling, StartSample};
use crate::integrate::exact::noise::{holding_samples, ThermalExact, ThermalForce};
use crate::integrate::{advance, build, check_start, Integrator, IntegratorOptions};
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use nalgebra::DVector;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};

/// Samples per drive period of the lock-in's demodulation.
pub(crate) const LOCK_IN_SAMPLES: usize = 32;

/// The feedback's gains and the lock-in's time constant (model units: τ, g₀).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(crate) struct FeedbackGains {
    /// K_P: rest-distance change per unit amplitude error (dimensionless), ≥ 0.
    pub proportional: f64,
    /// K_I: rest-distance rate per unit amplitude error (per unit τ), > 0.
    pub integral: f64,
    /// τ_L: the lock-in's low-pass time constant (units of τ), ≥ 0.
    pub time_constant: f64,
}

impl FeedbackGains {
    /// The defaults of a lever of quality factor `q` and first free resonance `omega0` (rad
    /// per unit τ) (module docs): τ_L = τ_c/4, K_P = 0, K_I = 1/(4(τ_c + τ_L)), τ_c = 2Q/ω₀.
    pub(crate) fn for_lever(q: f64, omega0: f64) -> Self {
        let tau_c = 2.0 * q / omega0;
        let time_constant = tau_c / 4.0;
        FeedbackGains {
            proportional: 0.0,
            integral: 1.0 / (4.0 * (tau_c + time_constant)),
            time_constant,
        }
    }
}

/// The low-pass's weight per period β = 1 − e^{−T/τ_L} of a lock-in of time constant
/// `time_constant` (τ_L ≥ 0) updated once per `period` (T): 1 for τ_L = 0 (module docs).
pub(crate) fn lock_in_beta(time_constant: f64, period: f64) -> f64 {
    if time_constant > 0.0 {
        -(-period / time_constant).exp_m1()
    } else {
        1.0
    }
}

/// The lock-in amplifier (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LockIn {
    /// β = 1 − e^{−T/τ_L}.
    beta: f64,
    /// X̄, Ȳ.
    x: f64,
    y: f64,
}

impl LockIn {
    /// A lock-in of time constant `time_constant` (τ_L ≥ 0) updated once per `period`, its
    /// output preloaded with (`amplitude`, `phase`).
    pub(crate) fn new(time_constant: f64, period: f64, amplitude: f64, phase: f64) -> Self {
        LockIn {
            beta: lock_in_beta(time_constant, period),
            x: amplitude * phase.cos(),
            y: amplitude * phase.sin(),
        }
    }

    /// Feed one period's demodulated first harmonic (A_k, φ_k).
    pub(crate) fn update(&mut self, amplitude: f64, phase: f64) {
        self.x += self.beta * (amplitude * phase.cos() - self.x);
        self.y += self.beta * (amplitude * phase.sin() - self.y);
    }

    /// The output amplitude A = |(X̄, Ȳ)|.
    pub(crate) fn amplitude(&self) -> f64 {
        self.x.hypot(self.y)
    }

    /// The output phase lag φ = arg(X̄ + iȲ), in (−π/2, 3π/2].
    pub(crate) fn phase(&self) -> f64 {
        wrap_phase(self.y.atan2(self.x))
    }
}

/// The first harmonic (A, φ) of W(1,τ) over the drive period from the integrator's current τ,
/// sampled `samples` times (module docs), the integrator advanced to the period's end.
///
/// The samples are read from the integrator's dense output inside the steps it takes over the
/// period (`sample_dense`), so that they do not cut its steps: (A, φ) differ from
/// [`demodulate_period_stepped`]'s by about the tolerance times the amplitude (the test
/// `dense_and_stepped_demodulation_agree`). An integrator with spans ([`Integrator::spans`]:
/// the exact propagator, the split integrator) is stepped to each sample as
/// [`demodulate_period_stepped`] does.
///
/// # Errors
/// As the integrator.
pub(crate) fn demodulate_period(
    integ: &mut dyn Integrator,
    model: &CantileverModel,
    samples: usize,
) -> Result<(f64, f64), SimError> {
    let p = model.params();
    let (t0, period) = (integ.tau(), model.period());
    let psi = p.drive_phase();
    let tau_of = |j: usize| t0 + period * j as f64 / samples as f64;
    // sin θ_j, cos θ_j by rotating θ₀ = Ωτ₀ + ψ by ΩT/M per sample (module docs)
    let (mut s, mut c) = (p.omega * t0 + psi).sin_cos();
    let (sd, cd) = (p.omega * (period / samples as f64)).sin_cos();
    let (mut x, mut y) = (0.0, 0.0);
    sample_dense(
        integ,
        samples,
        &tau_of,
        SpanSampling::Cut,
        StartSample::Excluded,
        &mut |_, _, z| {
            (s, c) = (s * cd + c * sd, c * cd - s * sd);
            let w = model.w_tip_slice(z, 0);
            x += w * s;
            y -= w * c;
            Ok(())
        },
    )?;
    let k = 2.0 / samples as f64;
    Ok(((k * x).hypot(k * y), wrap_phase((k * y).atan2(k * x))))
}

/// `demodulate_period` with the integrator advanced to each sample (its steps cut there):
/// the reference of the dense sampling.
///
/// # Errors
/// As the integrator.
pub fn demodulate_period_stepped(
    integ: &mut dyn Integrator,
    model: &CantileverModel,
    samples: usize,
) -> Result<(f64, f64), SimError> {
    let p = model.params();
    let (t0, period) = (integ.tau(), model.period());
    let psi = p.drive_phase();
    let (mut x, mut y) = (0.0, 0.0);
    for j in 1..=samples {
        let tau = t0 + period * j as f64 / samples as f64;
        advance(integ, tau)?;
        let w = model.tip_values(tau, integ.state())[0];
        let (s, c) = (p.omega * tau + psi).sin_cos();
        x += w * s;
        y -= w * c;
    }
    let k = 2.0 / samples as f64;
    Ok(((k * x).hypot(k * y), wrap_phase((k * y).atan2(k * x))))
}

/// The PI controller (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PiController {
    proportional: f64,
    /// K_I T.
    integral_step: f64,
    origin: f64,
    /// Σ e_j.
    sum: f64,
}

impl PiController {
    /// A controller of `gains` updated once per `period`, its output `origin` at zero error.
    pub(crate) fn new(gains: &FeedbackGains, period: f64, origin: f64) -> Self {
        PiController {
            proportional: gains.proportional,
            integral_step: gains.integral * period,
            origin,
            sum: 0.0,
        }
    }

    /// The output after the error `e`, held within `range` = (lowest, highest): the output and
    /// whether it saturated. An error that drives a saturated output further out is not
    /// integrated (conditional integration); one that drives it back is.
    pub(crate) fn output(&mut self, e: f64, range: (f64, f64)) -> (f64, bool) {
        let z = self.origin + self.proportional * e + self.integral_step * (self.sum + e);
        let (low, high) = (z < range.0, z > range.1);
        if !((low && e < 0.0) || (high && e > 0.0)) {
            self.sum += e;
        }
        (z.clamp(range.0, range.1), low || high)
    }
}

/// One scanned pixel (model units): means over its drive periods and the observables of its
/// last period.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ScanPixel {
    /// Mean piezo position (rest distance over the sample's zero height), g₀.
    pub z: f64,
    /// Mean lock-in amplitude, g₀.
    pub amplitude: f64,
    /// Mean lock-in phase lag, rad.
    pub phase: f64,
    /// Mean error A_sp − A, g₀ (the error image).
    pub tracking_error: f64,
    /// The material under the tip at the pixel's last period.
    pub material: usize,
    /// Energy dissipated over the last period (F̃·g₀; `observe`).
    pub energy_dissipated: f64,
    /// Virial over the last period (F̃·g₀).
    pub virial: f64,
    /// Peak force over the last period (F̃).
    pub peak_force: f64,
    /// Indentation over the last period (g₀).
    pub indentation: f64,
    /// Mean deflection ⟨W⟩ over the last period (g₀; its sign is the regime's, as the
    /// setpoint report's).
    pub mean_deflection: f64,
    /// Whether the controller lost contact ("parachuting"): in the last period the tip did not
    /// reach the sample and the lock-in amplitude was nearer to the free amplitude than to
    /// the setpoint.
    pub lost_contact: bool,
    /// Periods at the controller's output limit.
    pub saturated: usize,
    /// The per-mode energy balance of the last period (`observe`'s
    /// [`crate::analysis::observables::ModeBalance`]): the largest |residual| relative to the
    /// drive's work on its mode — the balance ΔE_j = drive − damping − sample − coupling holds
    /// over any window, settled or not. NaN under a thermal force, whose work the balance
    /// leaves out.
    pub energy_residual: f64,
}

/// What a scan line needs (model units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct LineSpec {
    /// The materials under the tip: the same lever and drive, only the sample differs (their
    /// α5 is set per period).
    pub materials: Vec<Params>,
    /// The amplitude setpoint A_sp (g₀).
    pub setpoint: f64,
    /// The free amplitude A₀ (g₀): a pixel whose amplitude is nearer to it than to the
    /// setpoint, with the tip off the sample, lost contact.
    pub free_amplitude: f64,
    /// Gains and the lock-in's time constant.
    pub gains: FeedbackGains,
    /// Samples per period of the lock-in ([`LOCK_IN_SAMPLES`]).
    pub samples: usize,
    /// Pixels per line.
    pub pixels: usize,
    /// Drive periods per pixel.
    pub periods_per_pixel: usize,
    /// Drive periods of the engage at the line's start, before the trace.
    pub engage_periods: usize,
    /// The rest-distance range of the controller above the local surface (lowest, highest).
    pub range: (f64, f64),
    /// The integrator (not serialised: a scan's is the default, [`IntegratorOptions::default`]).
    #[serde(skip)]
    pub integrator: IntegratorOptions,
    /// The thermal force (k_B T in the model's energy unit and the seed; `None`: no noise).
    /// Line t draws material m's force from stream t × materials + m of the seed
    /// ([`ThermalForce::stream`]), one stream over the whole line: the exact stochastic step
    /// moved to each period's gap in place ([`Integrator::set_gap`]), its stream going on.
    pub thermal: Option<ThermalForce>,
}

/// Where a line engages: far above its first pixel's material, on the steady state there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct Engage {
    /// The steady state at the start (τ = 0 of a period), shape `[dim]` of its material.
    pub state: DVector<f64>,
    /// Its rest distance z_c (g₀).
    pub z_c: f64,
    /// Its first harmonic (A, φ): the lock-in's preload.
    pub amplitude: f64,
    /// Phase lag, rad.
    pub phase: f64,
}

/// The trace and the retrace of one line, each in x order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScanLine {
    /// Trace (x increasing).
    pub trace: Vec<ScanPixel>,
    /// Retrace (scanned x decreasing, stored in x order).
    pub retrace: Vec<ScanPixel>,
}

/// `z` for a state of dimension `dim`: the modal part kept, a law's internal states at rest
/// where the material under the tip has them (a fresh, relaxed SLS surface), dropped where it
/// has none.
fn fit_state(z: &DVector<f64>, dim: usize) -> DVector<f64> {
    if z.len() == dim {
        return z.clone();
    }
    DVector::from_fn(dim, |i, _| if i < z.len() { z[i] } else { 0.0 })
}

/// A material's model and integrator, kept across a scan line.
type Kept = (CantileverModel, Box<dyn Integrator>);

/// The model of `mat` at the gap `alpha5` and its integrator started at τ = 0 from `z`
/// ([`fit_state`] to the material's dimension): what [`CantileverModel::new`] and [`build`]
/// of `mat` with α5 replaced give, bit for bit (their errors included), but the model and the
/// integrator of `kept` moved to the gap in place ([`CantileverModel::set_gap`],
/// [`Integrator::set_gap`]) where there are some, instead of assembled every drive period.
/// With a `thermal` force the integrator is the exact stochastic step, built once and moved
/// from gap to gap, so that its random stream goes on.
///
/// # Errors
/// As [`CantileverModel::new`], [`build`] and [`ThermalExact::new`].
fn at_gap<'a>(
    kept: &'a mut Option<Kept>,
    mat: &Params,
    alpha5: f64,
    z: &DVector<f64>,
    opts: &IntegratorOptions,
    thermal: Option<ThermalForce>,
) -> Result<(&'a CantileverModel, &'a mut Box<dyn Integrator>), SimError> {
    let reused = match kept {
        Some((model, integ)) => {
            model.set_gap(alpha5)?;
            let moved = integ.set_gap(alpha5);
            if !moved && thermal.is_some() {
                // a rebuilt stochastic step would start its stream again
                return Err(SimError::out_of_range(
                    "alpha5",
                    crate::error::number(alpha5),
                    "the thermal scan could not move its propagator to this gap",
                ));
            }
            moved
        }
        None => false,
    };
    if reused {
        let (model, integ) = kept.as_mut().expect("kept above");
        let start = fit_state(z, model.dim());
        // `build`'s checks that depend on the state (the others do not depend on α5)
        check_start(&start)?;
        integ.reset(0.0, &start)?;
    } else {
        let model = match kept.take() {
            Some((model, _)) => model,
            None => CantileverModel::new(&mat.with(SweepParam::Alpha5, alpha5))?,
        };
        let start = fit_state(z, model.dim());
        let integ: Box<dyn Integrator> = match thermal {
            None => build(&model, opts.clone(), 0.0, &start)?,
            Some(force) => {
                let mut it = ThermalExact::new(&model, opts, force)?;
                it.reset(0.0, &start)?;
                Box::new(it)
            }
        };
        *kept = Some((model, integ));
    }
    let (model, integ) = kept.as_mut().expect("kept above");
    Ok((model, integ))
}

/// Accumulates a pixel's means.
#[derive(Default)]
struct Sums {
    z: f64,
    amplitude: f64,
    phase: f64,
    error: f64,
    saturated: usize,
    n: usize,
    /// The lock-in amplitude after the last period.
    last: f64,
}

impl Sums {
    /// The pixel of these means, on `material` with the observables `o` of its last period.
    fn pixel(&self, spec: &LineSpec, material: usize, o: &Observables) -> ScanPixel {
        let n = self.n as f64;
        ScanPixel {
            z: self.z / n,
            amplitude: self.amplitude / n,
            phase: self.phase / n,
            tracking_error: self.error / n,
            material,
            energy_dissipated: o.energy_dissipated,
            virial: o.virial,
            peak_force: o.peak_force,
            indentation: o.indentation,
            mean_deflection: o.mean_deflection,
            lost_contact: o.contact_fraction == 0.0
                && o.impacts_per_period == 0.0
                && 2.0 * self.last > spec.setpoint + spec.free_amplitude,
            saturated: self.saturated,
            energy_residual: match spec.thermal {
                Some(_) => f64::NAN,
                None => (o.mode_balance.iter())
                    .map(|b| b.residual.abs() / b.drive.abs().max(f64::MIN_POSITIVE))
                    .fold(0.0, f64::max),
            },
        }
    }
}

/// The integrator options of a line: the spec's; with a thermal force on a grid that holds
/// the lock-in's samples (the stochastic step's drawn points).
fn line_options(spec: &LineSpec) -> IntegratorOptions {
    let mut opts = spec.integrator.clone();
    if spec.thermal.is_some() {
        opts.steps_per_period = holding_samples(opts.steps_per_period, spec.samples);
    }
    opts
}

/// Where a line engages, in pixels along it: the trace's first drive period,
/// 0.5/`periods_per_pixel` (its material is the one [`Engage`] must be of).
pub(crate) fn engage_position(spec: &LineSpec) -> f64 {
    0.5 / spec.periods_per_pixel as f64
}

/// Scan one line (module docs): engage at the line's start for `engage_periods` from `engage`,
/// then the trace over `pixels` × `periods_per_pixel` drive periods and the retrace back.
/// `under_tip(s)` is the material and the true height (g₀) at the position s ∈ [0, pixels]
/// along the line (in pixels, x increasing); `line` numbers the line's thermal streams
/// ([`LineSpec::thermal`]).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `periods_per_pixel`, `samples` or `materials` when 0;
/// [`SimError::Cancelled`] once `cancel` is set; `material` when `under_tip` names none of
/// `spec.materials`; the model's and the integrator's errors.
pub(crate) fn scan_line(
    spec: &LineSpec,
    engage: &Engage,
    under_tip: &dyn Fn(f64) -> (usize, f64),
    line: usize,
    cancel: &AtomicBool,
) -> Result<ScanLine, SimError> {
    for (name, n) in [
        ("periods_per_pixel", spec.periods_per_pixel),
        ("samples", spec.samples),
        ("materials", spec.materials.len()),
    ] {
        if n == 0 {
            return Err(SimError::out_of_range(name, n, "must be at least 1"));
        }
    }
    let base = &spec.materials[0];
    let period = base.period();
    // the engage holds the tip where the trace's first period is
    let s0 = engage_position(spec);
    let h0 = under_tip(s0).1;
    let mut z = engage.state.clone();
    let mut lock = LockIn::new(
        spec.gains.time_constant,
        period,
        engage.amplitude,
        engage.phase,
    );
    let mut pi = PiController::new(&spec.gains, period, engage.z_c + h0);
    let mut piezo = engage.z_c + h0;
    let opts = ObservableOptions {
        periods: 1,
        harmonics: 1,
    };
    // each material's model and integrator, kept across the line and moved to each period's
    // gap in place (`at_gap`)
    let mut kept: Vec<Option<Kept>> = spec.materials.iter().map(|_| None).collect();
    let materials = spec.materials.len() as u64;
    let integrator = line_options(spec);
    // one period at position s: returns the observables when `observe_it`
    let mut period_at = |s: f64,
                         observe_it: bool,
                         piezo: &mut f64,
                         sums: &mut Sums|
     -> Result<Option<(usize, Observables)>, SimError> {
        let (m, h) = under_tip(s);
        let mat = spec.materials.get(m).ok_or_else(|| {
            SimError::out_of_range("material", m, "must be one of the spec's materials")
        })?;
        let (model, integ) = at_gap(
            &mut kept[m],
            mat,
            mat.alpha5_for_rest_distance(*piezo - h),
            &z,
            &integrator,
            (spec.thermal).map(|f| f.stream(line as u64 * materials + m as u64)),
        )?;
        let (raw, o) = if observe_it {
            let o = observe(integ.as_mut(), &opts)?;
            ((o.amplitude, o.phase), Some((m, o)))
        } else {
            (
                demodulate_period(integ.as_mut(), model, spec.samples)?,
                None,
            )
        };
        z.clone_from(integ.state());
        lock.update(raw.0, raw.1);
        sums.z += *piezo;
        sums.amplitude += lock.amplitude();
        sums.last = lock.amplitude();
        sums.phase += lock.phase();
        let e = spec.setpoint - lock.amplitude();
        sums.error += e;
        let (next, sat) = pi.output(e, (h + spec.range.0, h + spec.range.1));
        sums.saturated += usize::from(sat);
        sums.n += 1;
        *piezo = next;
        Ok(o)
    };
    let mut scratch = Sums::default();
    for _ in 0..spec.engage_periods {
        if cancel.load(Ordering::Relaxed) {
            return Err(SimError::Cancelled);
        }
        period_at(s0, false, &mut piezo, &mut scratch)?;
    }
    let n_c = spec.periods_per_pixel;
    let mut lines = [Vec::new(), Vec::new()];
    for (dir, out) in lines.iter_mut().enumerate() {
        for i in 0..spec.pixels {
            if cancel.load(Ordering::Relaxed) {
                return Err(SimError::Cancelled);
            }
            let mut sums = Sums::default();
            let mut last = None;
            for c in 0..n_c {
                let along = i as f64 + (c as f64 + 0.5) / n_c as f64;
                let s = if dir == 0 {
                    along
                } else {
                    spec.pixels as f64 - along
                };
                if let Some(o) = period_at(s, c + 1 == n_c, &mut piezo, &mut sums)? {
                    last = Some(o);
                }
            }
            let (material, o) = last.expect("a pixel has at least one period");
            out.push(sums.pixel(spec, material, &o));
        }
    }
    let [trace, mut retrace] = lines;
    retrace.reverse();
    Ok(ScanLine { trace, retrace })
}
