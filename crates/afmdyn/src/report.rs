//! Result documents shared by the front ends: the JSON that `afmdyn … --json` prints and that
//! the Python package's `to_dict()` returns. One place builds each document, so the command
//! line and Python cannot drift apart; a front end adds only its own keys (output paths).
//!
//! Every function returns a [`serde_json::Value`] object; serialised with
//! `serde_json::to_string` it is byte for byte what the command line prints.

use crate::analysis::attractors::{Attractor, AttractorReport};
use crate::analysis::continuation::Branch;
use crate::analysis::converge::ConvergenceRun;
use crate::analysis::global_continuation::ContinuationStep;
use crate::analysis::lyapunov::LyapunovSpectrum;
use crate::analysis::observables::{ModeBalance, Observables};
use crate::analysis::shooting::PeriodicOrbit;
use crate::analysis::steady::SteadyState;
use crate::analysis::stepped::{CurvePoint, SteppedCurve, Sweep};
use crate::eigen::RegionSpectrum;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use crate::trajectory::Trajectory;
use nalgebra::DVector;
use serde_json::{json, Value};

/// One region of `afmdyn modes --json`: `{"omega": [ω_i], "eigenvalues": [[re, im], …]}`.
pub fn region_spectrum(r: &RegionSpectrum) -> Value {
    json!({
        "omega": r.omega,
        "eigenvalues": r.eigenvalues.iter().map(|e| [e.re, e.im]).collect::<Vec<_>>(),
    })
}

/// `afmdyn modes --json`: the parameters and the free and contact spectra (eqs. 19–23).
pub fn modes(params: &Params, free: &RegionSpectrum, contact: &RegionSpectrum) -> Value {
    json!({ "params": params, "free": region_spectrum(free), "contact": region_spectrum(contact) })
}

pub use crate::trajectory::energy_residual;

/// What `afmdyn simulate --json` reports of a run (the front ends add their own keys, e.g. the
/// files written and warnings).
#[derive(Debug, Clone, PartialEq)]
pub struct SimulateSummary {
    /// Final τ.
    pub tau_end: f64,
    /// Final state, shape `[2N]`.
    pub final_state: DVector<f64>,
    /// Number of events.
    pub switchings: usize,
    /// Whether the beam body touched the substrate.
    pub body_contact: bool,
    /// Stroboscopic section points recorded.
    pub poincare_points: usize,
    /// [`energy_residual`] of the run.
    pub energy_residual: (f64, f64),
}

/// Relative per-period energy residual above which a run is reported as inaccurate (normal runs
/// close to ~1e-10 with the exact propagator and with the adaptive integrator's dense output).
pub const ENERGY_TOLERANCE: f64 = 1e-6;

/// The run's own accuracy checks that failed: the energy balance beyond [`ENERGY_TOLERANCE`],
/// and the beam body reaching the substrate (outside the paper's model, Fig. 2f).
pub fn simulate_warnings(s: &SimulateSummary) -> Vec<String> {
    let mut w = vec![];
    let relative = s.energy_residual.1;
    if relative.is_nan() || relative > ENERGY_TOLERANCE {
        w.push(format!(
            "energy balance violated: a per-period residual of {relative:.1e} relative \
             (tolerance 1e-6); the trajectory is not accurate (integrator too coarse, or \
             parameters at the edge of the valid range)"
        ));
    }
    if s.body_contact {
        w.push(
            "a point of the beam other than the tip reached the substrate (paper Fig. 2f): \
             outside the model's assumption"
                .into(),
        );
    }
    w
}

/// `afmdyn simulate --json`: final time and state, events, body contact, section points, the
/// energy-balance residual and [`simulate_warnings`].
pub fn simulate_summary(model: &CantileverModel, s: &SimulateSummary) -> Value {
    let zf = &s.final_state;
    let n = model.modes();
    json!({
        "params": model.params(),
        "tau_end": s.tau_end,
        "final": {
            "w_tip": model.w_tip(zf),
            "w_tip_dot": model.w_tip_dot(zf),
            "v_t": model.v_t(s.tau_end, zf),
            "a": zf.rows(0, n).iter().collect::<Vec<_>>(),
            "a_dot": zf.rows(n, n).iter().collect::<Vec<_>>(),
        },
        "switchings": s.switchings,
        "body_contact": s.body_contact,
        "poincare_points": s.poincare_points,
        "energy_residual": { "max_abs": s.energy_residual.0, "max_relative": s.energy_residual.1 },
        "warnings": simulate_warnings(s),
    })
}

/// [`simulate_summary`] of a whole [`Trajectory`].
pub fn simulate(model: &CantileverModel, tr: &Trajectory) -> Value {
    simulate_summary(
        model,
        &SimulateSummary {
            tau_end: tr.tau_end,
            final_state: tr.final_state.clone(),
            switchings: tr.events.len(),
            body_contact: tr.body_contact,
            poincare_points: tr.poincare.len(),
            energy_residual: energy_residual(&tr.energy),
        },
    )
}

/// `afmdyn converge --json` without the output directory: the parameters and, per N, the
/// period and the RMS change of the tip motion against N − 1.
pub fn converge(params: &Params, runs: &[ConvergenceRun]) -> Value {
    let rows: Vec<_> = runs
        .iter()
        .map(|r| json!({ "modes": r.modes, "period": r.period, "rms_change": r.rms_change }))
        .collect();
    json!({ "params": params, "runs": rows })
}

/// A section state as the `--initial-modal` string "a1,..,aN;adot1,..,adotN" (at drive phase 0),
/// so that `afmdyn orbit --initial-modal` can start from an attractor; empty for `None`.
pub fn initial_modal(z: Option<&DVector<f64>>) -> String {
    let Some(z) = z else { return String::new() };
    let n = z.len() / 2;
    let join = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x}"))
            .collect::<Vec<_>>()
            .join(",")
    };
    format!("{};{}", join(&z.as_slice()[..n]), join(&z.as_slice()[n..]))
}

/// One attractor of `afmdyn attractors --json`; `multipliers` ([re, im] pairs) and `stable` of
/// the shooting-polished orbit, null for a nonperiodic motion.
pub fn attractor(s: &SteadyState, basin: f64, orbit: Option<&PeriodicOrbit>) -> Value {
    json!({
        "multipliers": orbit.map(|o| o.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>()),
        "stable": orbit.map(|o| o.stable),
        "period": s.period(),
        "poincare": {
            "v_t": s.poincare.iter().map(|p| p.v_t).collect::<Vec<_>>(),
            "w_tip": s.poincare.iter().map(|p| p.w_tip).collect::<Vec<_>>(),
        },
        "x_max": s.stats.x_max,
        "v_t_min": s.stats.v_t_min,
        "contact_fraction": s.stats.contact_fraction,
        "contacts_per_period": s.stats.contacts_per_period,
        "body_contact": s.stats.body_contact,
        "basin_fraction": basin,
        "initial_modal": initial_modal(s.poincare.first().map(|q| &q.state)),
    })
}

/// `afmdyn attractors --json` (also written to `attractors.json`): `samples` starts at `params`.
pub fn attractors(params: &Params, samples: usize, report: &AttractorReport) -> Value {
    json!({
        "params": params,
        "samples": samples,
        "failures": report.failures.len(),
        "transient_cap": report.transient_cap,
        "attractors": report
            .attractors
            .iter()
            .map(|x| census_entry(x, x.basin_fraction))
            .collect::<Vec<_>>(),
        "unsettled": report
            .unsettled
            .iter()
            .map(|x| {
                let mut d = census_entry(x, 0.0);
                d["count"] = json!(x.count);
                d
            })
            .collect::<Vec<_>>(),
        "warnings": report.warnings(),
    })
}

/// One attractor of a census: [`attractor`] with λ₁ and its error for a nonperiodic one.
fn census_entry(x: &Attractor, basin: f64) -> Value {
    let mut d = attractor(&x.steady, basin, x.orbit.as_ref());
    if let Some((l, e)) = x.lyapunov {
        d["lyapunov"] = json!(l);
        d["lyapunov_error"] = json!(e);
    }
    d
}

/// `afmdyn attractors --sweep --json`: the attractors at every value with their ids, and the
/// basin fractions as a values × ids table (0 where an id has no attractor).
pub fn global_continuation(
    base: &Params,
    param: SweepParam,
    samples: usize,
    steps: &[ContinuationStep],
) -> Value {
    let ids = steps
        .iter()
        .flat_map(|s| s.attractors.iter().map(|(id, _)| id + 1))
        .max()
        .unwrap_or(0);
    let fractions: Vec<Vec<f64>> = steps
        .iter()
        .map(|s| {
            let mut row = vec![0.0; ids];
            for (id, a) in &s.attractors {
                row[*id] = a.basin_fraction;
            }
            row
        })
        .collect();
    let mut warnings: Vec<String> = steps
        .iter()
        .filter(|s| s.attractors.is_empty())
        .map(|s| {
            format!(
                "{} = {}: every run failed ({})",
                param.name(),
                s.value,
                s.failures.first().map_or("", String::as_str)
            )
        })
        .collect();
    for s in steps {
        for w in &s.warnings {
            warnings.push(format!("{} = {}: {w}", param.name(), s.value));
        }
    }
    json!({
        "params": base,
        "param": param.name(),
        "samples": samples,
        "values": steps.iter().map(|s| s.value).collect::<Vec<_>>(),
        "ids": ids,
        "fractions": fractions,
        "steps": steps.iter().map(|s| json!({
            "value": s.value,
            "failures": s.failures.len(),
            "attractors": s.attractors.iter().map(|(id, a)| {
                let mut d = attractor(&a.steady, a.basin_fraction, a.orbit.as_ref());
                d["id"] = json!(id);
                d
            }).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "warnings": warnings,
    })
}

/// `afmdyn orbit --json`: a period-n orbit of `model` with its Floquet multipliers.
pub fn orbit(model: &CantileverModel, o: &PeriodicOrbit) -> Value {
    let mut doc = json!({
        "period": o.period,
        "poincare": {
            "v_t": o.section.iter().map(|z| model.v_t(0.0, z)).collect::<Vec<_>>(),
            "w_tip": o.section.iter().map(|z| model.w_tip(z)).collect::<Vec<_>>(),
        },
        "multipliers": o.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>(),
        "stable": o.stable,
        "critical": o.critical,
        "grazing": o.grazing,
        "grazing_distance": o.grazing_distance,
        "switchings": o.switchings,
        "newton_residuals": o.residuals,
        "state": o.state.iter().collect::<Vec<_>>(),
    });
    doc["params"] = json!(model.params());
    doc
}

/// `afmdyn continue --json` without the output directory: the branches' sizes and their
/// located bifurcations.
pub fn continuation(base: &Params, param: SweepParam, branches: &[Branch]) -> Value {
    let events: Vec<_> = branches
        .iter()
        .flatten()
        .filter(|b| b.event.is_some())
        .map(|b| json!({ "event": b.event, "value": b.value, "period": b.period, "stable": b.stable }))
        .collect();
    json!({
        "params": base,
        "param": param.name(),
        "branches": branches.len(),
        "points": branches.iter().map(|b| b.len()).sum::<usize>(),
        "events": events,
        "ends": branches.iter().map(|b| b.end).collect::<Vec<_>>(),
        "warnings": continuation_warnings(param, branches),
    })
}

/// One line for every branch that ended before covering what was asked
/// ([`crate::analysis::continuation::BranchEnd::warning`]).
pub fn continuation_warnings(param: SweepParam, branches: &[Branch]) -> Vec<String> {
    branches
        .iter()
        .filter_map(|b| b.end.warning(param, b.first().map_or(1, |p| p.period)))
        .collect()
}

/// Scales of a stepped-curve document ([`approach`], [`resonance`]): the factors that turn the
/// model's lengths (g₀), forces (F̃) and energies (F̃·g₀) into the reported units, and Ω into Hz.
/// The one place the curves are converted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveUnits {
    /// Reported length per g₀ (1, or metres per g₀).
    pub length: f64,
    /// Reported force per F̃ (1, or newtons).
    pub force: f64,
    /// Reported energy per F̃·g₀ (1, or joules).
    pub energy: f64,
    /// Reported time per unit τ (1, or seconds).
    pub time: f64,
    /// Hz per unit Ω, when frequencies are reported in Hz.
    pub hz_per_omega: Option<f64>,
    /// Whether the factors convert to SI (the unit names of the document).
    pub si: bool,
}

impl CurveUnits {
    /// The model's own units (every factor 1).
    pub fn dimensionless() -> Self {
        CurveUnits {
            length: 1.0,
            force: 1.0,
            energy: 1.0,
            time: 1.0,
            hz_per_omega: None,
            si: false,
        }
    }

    /// SI units from a probe's scales ([`crate::probe::Scales`]): metres, newtons, joules;
    /// frequencies in Hz when `hz` is set.
    pub fn from_scales(s: &crate::probe::Scales, hz: bool) -> Self {
        CurveUnits {
            length: s.length_m,
            force: s.force_n,
            energy: s.energy_j(),
            time: s.time_s,
            hz_per_omega: hz.then(|| s.frequency_hz(1.0)),
            si: true,
        }
    }

    /// The name of the unit of `kind` (the document's `units` block).
    pub fn unit(&self, kind: UnitKind) -> &'static str {
        match (kind, self.si) {
            (UnitKind::Length, true) => "m",
            (UnitKind::Length, false) => "g0",
            (UnitKind::Force, true) => "N",
            (UnitKind::Force, false) => "F~ (k g0 for the point mass)",
            (UnitKind::Energy, true) => "J",
            (UnitKind::Energy, false) => "F~ g0",
            (UnitKind::Phase, _) => "degree",
            (UnitKind::One, _) => "1",
        }
    }

    fn names(&self) -> Value {
        let k = |kind| self.unit(kind);
        let frequency = if self.si && self.hz_per_omega.is_some() {
            "Hz"
        } else {
            "Ω"
        };
        json!({"length": k(UnitKind::Length), "force": k(UnitKind::Force),
               "energy": k(UnitKind::Energy), "phase": k(UnitKind::Phase),
               "frequency": frequency})
    }
}

/// The units of a recorded trajectory's files and plots (`simulate`): the model's (τ, g₀, its
/// force and energy units) or, with a probe, SI (s, m, m/s, N, J, Hz) from its scales
/// ([`CurveUnits::from_scales`]). The one place a time series is converted; every factor
/// multiplies a dimensionless value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeriesUnits {
    /// The factors (time, length, force, energy, Hz per unit Ω for a spectrum; `si`).
    pub u: CurveUnits,
    /// The point-mass model (force unit k g₀ rather than EI g₀/L³).
    pub point_mass: bool,
}

/// The names of [`SeriesUnits`]: the time column and the units of each kind of quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SeriesNames {
    /// The time column: `t` (SI) or `tau`.
    pub time: &'static str,
    /// Its unit.
    pub time_unit: &'static str,
    /// Lengths (V_T, W, modal coordinates).
    pub length: &'static str,
    /// Velocities.
    pub velocity: &'static str,
    /// Forces.
    pub force: &'static str,
    /// Energies.
    pub energy: &'static str,
}

impl SeriesUnits {
    /// The units of `params`' trajectories, SI when `probe` is given.
    pub fn new(params: &Params, probe: Option<&crate::probe::Probe>) -> Self {
        SeriesUnits {
            u: probe.map_or_else(CurveUnits::dimensionless, |pr| {
                CurveUnits::from_scales(&pr.scales, true)
            }),
            point_mass: params.structure == crate::Structure::PointMass,
        }
    }
    /// A time τ in the reported unit.
    pub fn t(&self, tau: f64) -> f64 {
        tau * self.u.time
    }
    /// A length (g₀) in the reported unit.
    pub fn x(&self, v: f64) -> f64 {
        v * self.u.length
    }
    /// A velocity (g₀ per unit τ) in the reported unit.
    pub fn v(&self, v: f64) -> f64 {
        v * self.u.length / self.u.time
    }
    /// A force in the reported unit.
    pub fn force(&self, v: f64) -> f64 {
        v * self.u.force
    }
    /// An energy in the reported unit.
    pub fn energy(&self, v: f64) -> f64 {
        v * self.u.energy
    }
    /// The names of the reported units.
    pub fn names(&self) -> SeriesNames {
        let (force, energy) = match (self.u.si, self.point_mass) {
            (true, _) => ("N", "J"),
            (false, true) => ("k g0", "k g0²"),
            (false, false) => ("EI g0/L³", "EI g0²/L³"),
        };
        if self.u.si {
            SeriesNames {
                time: "t",
                time_unit: "s",
                length: "m",
                velocity: "m/s",
                force,
                energy,
            }
        } else {
            SeriesNames {
                time: "tau",
                time_unit: "τ (eq. 5)",
                length: "g0",
                velocity: "g0 per unit τ",
                force,
                energy,
            }
        }
    }
}

/// One column of a time series: its name, unit and meaning.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesColumn {
    /// The name (`tau` or `t`, `v_t`, `w_tip`, …, `a_1`, `a_dot_1`, …).
    pub name: String,
    /// Its unit ([`SeriesNames`]).
    pub unit: &'static str,
    /// What it is.
    pub long_name: String,
}

impl SeriesUnits {
    /// The columns of a trajectory of `n` modes, in their order (`timeseries.csv`, the `.npy`
    /// and its `.npy.json`, Python's `simulate` dataset): time, V_T (eq. 8), W(1,τ), ∂W/∂τ,
    /// the contact flag, F_c (sign [`crate::contact::FORCE_SIGN`]), a_1…a_n, ȧ_1…ȧ_n (eq. 9).
    pub fn columns(&self, n: usize) -> Vec<SeriesColumn> {
        let u = self.names();
        let col = |name: String, unit, long_name: String| SeriesColumn {
            name,
            unit,
            long_name,
        };
        let time = if self.u.si {
            "time t = τ t_s (t_s: seconds per unit τ, the probe's scales)"
        } else {
            "dimensionless time τ = t √(EI/(mL⁴))"
        };
        let mut c = vec![
            col(u.time.into(), u.time_unit, time.into()),
            col(
                "v_t".into(),
                u.length,
                "tip–sample distance V_T = W(1,τ) + α2 sin Ωτ + α5 (eq. 8); contact while V_T ≤ 0"
                    .into(),
            ),
            col(
                "w_tip".into(),
                u.length,
                "tip deflection W(1,τ) relative to the clamped base".into(),
            ),
            col("w_tip_dot".into(), u.velocity, "tip velocity ∂W(1,τ)/∂τ".into()),
            col(
                "in_contact".into(),
                "0/1",
                "1 while the tip is in contact (region II)".into(),
            ),
            col(
                "contact_force".into(),
                u.force,
                format!(
                    "tip–sample force F_c(δ, δ̇) on the tip, δ = −V_T the indentation (linear law: \
                     α4 δ + α6 δ̇ in contact; 0 in free flight except DMT's van der Waals force): {}",
                    crate::contact::FORCE_SIGN
                ),
            ),
        ];
        c.extend((1..=n).map(|j| {
            col(
                format!("a_{j}"),
                u.length,
                format!("modal coordinate a_{j} (eq. 9)"),
            )
        }));
        c.extend((1..=n).map(|j| {
            col(
                format!("a_dot_{j}"),
                u.velocity,
                format!("modal velocity da_{j}/dτ"),
            )
        }));
        c
    }
}

/// The kind of unit of a reported quantity ([`CurveUnits::unit`] names it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnitKind {
    /// A length (g₀, or m).
    Length,
    /// A force (F̃, or N).
    Force,
    /// An energy (F̃·g₀, or J).
    Energy,
    /// A phase in degrees.
    Phase,
    /// A pure number.
    One,
}

/// A per-point column of a stepped curve: its name, its kind of unit and its meaning — the
/// one declaration of the JSON document's keys, the command line's `.npy.json` meanings and
/// Python's dataset attributes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CurveColumn {
    /// The key (`amplitude`, `phase_deg`, …).
    pub name: &'static str,
    /// Its kind of unit.
    pub kind: UnitKind,
    /// What it is.
    pub long_name: &'static str,
}

const fn curve_column(name: &'static str, kind: UnitKind, long_name: &'static str) -> CurveColumn {
    CurveColumn {
        name,
        kind,
        long_name,
    }
}

/// The per-point columns of a stepped-curve document, in this order after the abscissa.
pub const CURVE_COLUMNS: [CurveColumn; 12] = [
    curve_column(
        "amplitude",
        UnitKind::Length,
        "first-harmonic amplitude A of the tip deflection",
    ),
    curve_column(
        "amplitude_ratio",
        UnitKind::One,
        "A/A0 (A0 the free amplitude at the same drive)",
    ),
    curve_column(
        "phase_deg",
        UnitKind::Phase,
        "phase lag of the deflection behind the drive (90 free, > 90 attractive, < 90 repulsive)",
    ),
    curve_column(
        "mean_deflection",
        UnitKind::Length,
        "mean tip deflection <W>",
    ),
    curve_column(
        "peak_force",
        UnitKind::Force,
        "largest tip-sample force F_c: the repulsive maximum (F_c > 0 pushes the tip away)",
    ),
    curve_column(
        "min_force",
        UnitKind::Force,
        "smallest tip-sample force F_c: the adhesion minimum (F_c < 0 pulls the tip)",
    ),
    curve_column(
        "indentation",
        UnitKind::Length,
        "largest indentation max(-V_T, 0)",
    ),
    curve_column(
        "contact_fraction",
        UnitKind::One,
        "fraction of the time in contact (V_T <= 0)",
    ),
    curve_column(
        "min_distance",
        UnitKind::Length,
        "minimum tip-sample distance",
    ),
    curve_column(
        "energy_dissipated",
        UnitKind::Energy,
        "energy dissipated in the sample per drive period E_dis",
    ),
    curve_column(
        "virial",
        UnitKind::Energy,
        "virial (1/T) integral of F_c W over a period",
    ),
    curve_column(
        "harmonic_distortion",
        UnitKind::One,
        "total harmonic distortion of the deflection",
    ),
];

/// The column of [`CURVE_COLUMNS`] named `name`.
pub fn curve_column_index(name: &str) -> Option<usize> {
    CURVE_COLUMNS.iter().position(|c| c.name == name)
}

/// The [`CURVE_COLUMNS`] of one orbit's observables in `u`'s units: A, A/A₀ (A₀ the free
/// amplitude at the same drive), φ in degrees, ⟨W⟩, max F_c, min F_c, indentation, contact
/// fraction, min distance, E_dis, virial, THD.
pub fn curve_row(o: &Observables, u: &CurveUnits) -> [f64; 12] {
    [
        o.amplitude * u.length,
        o.amplitude / o.closed_form.free_amplitude,
        o.phase.to_degrees(),
        o.mean_deflection * u.length,
        o.peak_force * u.force,
        o.min_force * u.force,
        o.indentation * u.length,
        o.contact_fraction,
        o.min_distance * u.length,
        o.energy_dissipated * u.energy,
        o.virial * u.energy,
        o.thd,
    ]
}

/// The observables of one steady state in `u`'s units — SI for a probe's model (m, N, J, s),
/// the model's own otherwise (g₀, F̃, F̃·g₀, τ) — with phases in degrees: the [`CURVE_COLUMNS`]
/// (as [`curve_row`]), then `contact_time`, `mean_force`, `impacts_per_period`, `impact_loss`,
/// `harmonics` (arrays `n`, `amplitude`, `phase_deg`), `mode_balance` (arrays `mode`, `drive`,
/// `beam_damping`, `sample`, `coupling`, `energy_change`, `residual`; energies per drive period)
/// and `units` (the names). The `"reported"` block of `observe`'s document, which Python's
/// dataset is built from.
pub fn observed(o: &Observables, u: &CurveUnits) -> Value {
    let mut m = serde_json::Map::new();
    for (c, v) in CURVE_COLUMNS.iter().zip(curve_row(o, u)) {
        m.insert(c.name.into(), json!(v));
    }
    m.insert("contact_time".into(), json!(o.contact_time * u.time));
    m.insert("mean_force".into(), json!(o.mean_force * u.force));
    m.insert("impacts_per_period".into(), json!(o.impacts_per_period));
    m.insert("impact_loss".into(), json!(o.impact_loss * u.energy));
    let h = &o.harmonics;
    m.insert(
        "harmonics".into(),
        json!({
            "n": h.iter().map(|h| h.n).collect::<Vec<_>>(),
            "amplitude": h.iter().map(|h| h.amplitude * u.length).collect::<Vec<_>>(),
            "phase_deg": h.iter().map(|h| h.phase.to_degrees()).collect::<Vec<_>>(),
        }),
    );
    let b = &o.mode_balance;
    let energies =
        |f: fn(&ModeBalance) -> f64| -> Vec<f64> { b.iter().map(|x| f(x) * u.energy).collect() };
    m.insert(
        "mode_balance".into(),
        json!({
            "mode": b.iter().map(|x| x.mode).collect::<Vec<_>>(),
            "drive": energies(|x| x.drive),
            "beam_damping": energies(|x| x.beam_damping),
            "sample": energies(|x| x.sample),
            "coupling": energies(|x| x.coupling),
            "energy_change": energies(|x| x.energy_change),
            "residual": energies(|x| x.residual),
        }),
    );
    let mut units = u.names();
    units["time"] = json!(if u.si { "s" } else { "τ" });
    m.insert("units".into(), units);
    Value::Object(m)
}

/// The abscissa of a stepped curve: (key, value of the swept parameter → reported value).
type Abscissa<'a> = (&'static str, &'a dyn Fn(f64) -> f64);

fn columns<'a>(
    x: &Abscissa<'_>,
    rows: impl Iterator<Item = (f64, &'a Observables, bool)>,
    u: &CurveUnits,
) -> serde_json::Map<String, Value> {
    let mut xs = Vec::new();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); CURVE_COLUMNS.len()];
    let mut stable = Vec::new();
    for (v, o, s) in rows {
        xs.push((x.1)(v));
        for (c, val) in cols.iter_mut().zip(curve_row(o, u)) {
            c.push(val);
        }
        stable.push(s);
    }
    let mut m = serde_json::Map::new();
    m.insert(x.0.into(), json!(xs));
    for (col, c) in CURVE_COLUMNS.iter().zip(cols) {
        m.insert(col.name.into(), json!(c));
    }
    m.insert("stable".into(), json!(stable));
    m
}

fn sweep_doc(x: &Abscissa<'_>, points: &[CurvePoint], u: &CurveUnits) -> Value {
    let mut m = columns(
        x,
        points.iter().map(|p| (p.value, &p.observables, p.stable)),
        u,
    );
    m.insert(
        "period".into(),
        json!(points.iter().map(|p| p.period).collect::<Vec<_>>()),
    );
    m.insert(
        "reached".into(),
        json!(points.iter().map(|p| p.reached).collect::<Vec<_>>()),
    );
    Value::Object(m)
}

fn curve_doc(
    params: &Params,
    c: &SteppedCurve,
    x: Abscissa<'_>,
    names: (&str, &str),
    u: &CurveUnits,
) -> Value {
    let branches: Vec<Value> = c
        .branches
        .iter()
        .map(|b| {
            let mut m = columns(
                &x,
                b.iter()
                    .map(|s| (s.point.value, &s.observables, s.point.stable)),
                u,
            );
            m.insert(
                "period".into(),
                json!(b.iter().map(|s| s.point.period).collect::<Vec<_>>()),
            );
            m.insert(
                "event".into(),
                json!(b.iter().map(|s| s.point.event).collect::<Vec<_>>()),
            );
            Value::Object(m)
        })
        .collect();
    let sweep_name = |s: Sweep| match s {
        Sweep::First => names.0,
        Sweep::Second => names.1,
    };
    let jumps: Vec<Value> = c
        .jumps
        .iter()
        .map(|j| {
            json!({
                "sweep": sweep_name(j.sweep),
                "from": (x.1)(j.from),
                "to": (x.1)(j.to),
                "fold": j.fold.map(|f| (x.1)(f)),
            })
        })
        .collect();
    let free = c
        .first
        .first()
        .map(|p| p.observables.closed_form.free_amplitude * u.length);
    let traces = c.traces.as_ref().map(|t| {
        let n = t.time.len().max(1);
        let rows = |v: &[f64], scale: f64| -> Vec<Vec<f64>> {
            v.chunks(n)
                .map(|r| r.iter().map(|x| x * scale).collect())
                .collect()
        };
        json!({
            "sweep": names.0,
            "periods": t.periods,
            "samples_per_period": t.samples_per_period,
            x.0: t.values.iter().map(|&v| (x.1)(v)).collect::<Vec<_>>(),
            "time_periods": t.time,
            "deflection": rows(&t.deflection, u.length),
            "distance": rows(&t.distance, u.length),
            "force": rows(&t.force, u.force),
        })
    });
    json!({
        "params": params,
        "units": u.names(),
        "scales": {"length": u.length, "force": u.force, "energy": u.energy, "time": u.time,
                   "hz_per_omega": u.hz_per_omega},
        names.0: sweep_doc(&x, &c.first, u),
        names.1: sweep_doc(&x, &c.second, u),
        "branches": branches,
        "folds": c.folds.iter().map(|&f| (x.1)(f)).collect::<Vec<_>>(),
        "bistable": c.bistable.iter().map(|&(a, b)| {
            let (p, q) = ((x.1)(a), (x.1)(b));
            [p.min(q), p.max(q)]
        }).collect::<Vec<_>>(),
        "jumps": jumps,
        "free_amplitude": free,
        "warnings": c.warnings,
        "traces": traces,
    })
}

/// `doc` with the [`si`] block of `probe` added (built from `doc` itself, so its headline values
/// appear in SI), when the model came from a probe file; `doc` unchanged otherwise. Every front
/// end adds the block through this one function.
pub fn with_si(mut doc: Value, probe: Option<&crate::probe::Probe>, params: &Params) -> Value {
    if let Some(p) = probe {
        doc["si"] = si(p, params, &doc);
    }
    doc
}

/// `afmdyn approach --json`: `{"approach": {...}, "retract": {...}, "branches": [...], …}`.
/// `approach` and `retract` hold equal-length arrays `z_c` (rest distance,
/// [`Params::rest_distance`]) and the [`CURVE_COLUMNS`], plus `stable`, `period` (null when not
/// period-n) and `reached` ([`crate::analysis::stepped::Reached`]); each branch the same
/// columns with `stable`, `period` and `event` (null, "fold", "grazing", …). Also `folds` and
/// `bistable` ([lo, hi] ranges of z_c between two folds), `jumps` ({sweep, from, to, fold}),
/// `free_amplitude`, `units` (names), `scales` (the [`CurveUnits`] factors), `params` and
/// `warnings`.
pub fn approach(params: &Params, c: &SteppedCurve, u: &CurveUnits) -> Value {
    let x = z_c_of(params, u);
    curve_doc(params, c, ("z_c", &x), ("approach", "retract"), u)
}

/// The abscissa of an approach document: z_c ([`crate::analysis::approach::rest_distance`]) of
/// the gap α5, in `u`'s length.
fn z_c_of<'a>(params: &'a Params, u: &'a CurveUnits) -> impl Fn(f64) -> f64 + 'a {
    move |a5| crate::analysis::approach::rest_distance(params, a5) * u.length
}

/// The `"setpoint"` block of `afmdyn approach --setpoint S --json`: the ratio A_sp/A₀, the
/// amplitude it means (in `u`'s length), and per crossing of the curve
/// ([`crate::analysis::setpoint::setpoint_crossings`]) its `source` (`"branch k"`,
/// `"approach"`, `"retract"`), `z_c`, `regime` (`"attractive"` where the mean tip–sample force,
/// k⟨W⟩ for the point mass, is negative, else `"repulsive"`; García & San Paulo 2000) and the
/// [`CURVE_COLUMNS`] interpolated there.
pub fn setpoint(params: &Params, c: &SteppedCurve, ratio: f64, u: &CurveUnits) -> Value {
    use crate::analysis::setpoint::{setpoint_crossings, Source};
    let x = z_c_of(params, u);
    let points: Vec<Value> = setpoint_crossings(c, ratio)
        .into_iter()
        .map(|k| {
            let (name, a, b) = match k.source {
                Source::Branch(j) => (
                    format!("branch {j}"),
                    &c.branches[j][k.index].observables,
                    &c.branches[j][k.index + 1].observables,
                ),
                Source::Sweep(s) => {
                    let pts = match s {
                        Sweep::First => &c.first,
                        Sweep::Second => &c.second,
                    };
                    let name = if s == Sweep::First {
                        "approach"
                    } else {
                        "retract"
                    };
                    (
                        name.to_string(),
                        &pts[k.index].observables,
                        &pts[k.index + 1].observables,
                    )
                }
            };
            let (ra, rb) = (curve_row(a, u), curve_row(b, u));
            let mut m = serde_json::Map::new();
            m.insert("source".into(), json!(name));
            m.insert("z_c".into(), json!(x(k.value)));
            let row: Vec<f64> = ra
                .iter()
                .zip(rb)
                .map(|(p, q)| (1.0 - k.t) * p + k.t * q)
                .collect();
            let mean = row[3];
            m.insert(
                "regime".into(),
                json!(if mean < 0.0 {
                    "attractive"
                } else {
                    "repulsive"
                }),
            );
            for (c, v) in CURVE_COLUMNS.iter().zip(row) {
                m.insert(c.name.into(), json!(v));
            }
            Value::Object(m)
        })
        .collect();
    let a0 = c
        .first
        .first()
        .map(|p| p.observables.closed_form.free_amplitude * u.length);
    json!({
        "ratio": ratio,
        "amplitude": a0.map(|a| a * ratio),
        "points": points,
    })
}

/// `afmdyn resonance --json`: as [`approach`] with the abscissa `omega` (dimensionless Ω) or
/// `frequency_hz` (with [`CurveUnits::hz_per_omega`]) and the sweeps `up` and `down`.
pub fn resonance(params: &Params, c: &SteppedCurve, u: &CurveUnits) -> Value {
    let scale = u.hz_per_omega.unwrap_or(1.0);
    let key = if u.hz_per_omega.is_some() {
        "frequency_hz"
    } else {
        "omega"
    };
    let x = move |om: f64| om * scale;
    curve_doc(params, c, (key, &x), ("up", "down"), u)
}

/// `afmdyn lyapunov --json`: the Lyapunov spectrum and the 0–1 test at `params` (every field of
/// [`LyapunovSpectrum`], so a field added there reaches both front ends).
pub fn lyapunov(params: &Params, l: &LyapunovSpectrum) -> Value {
    let mut doc = serde_json::to_value(l).expect("a Lyapunov spectrum serialises");
    doc["params"] = json!(params);
    doc
}

/// The `"si"` block a front end adds to any document when the model came from a probe file
/// ([`crate::probe`]): the scales back to SI (every dimensionless value of the document converts
/// with them: lengths × `length_m`, τ × `time_s`, forces × `force_n`, energies × `energy_j`,
/// Ω → Hz), the probe's drive, free amplitude and rest distance, and the headline quantities of
/// the document in SI: natural frequencies in Hz (`modes`), X_max and V_T in m (`simulate`,
/// `attractors`, `orbit`), the swept parameter (Ω in Hz, α5 as z_c in m; `continue`), Lyapunov
/// exponents in 1/s (`lyapunov`).
pub fn si(probe: &crate::probe::Probe, params: &Params, doc: &Value) -> Value {
    let s = &probe.scales;
    let hz = |om: &Value| om.as_f64().map(|w| s.frequency_hz(w));
    let metres = |v: &Value| v.as_f64().map(|x| x * s.length_m);
    let mut out = json!({
        "scales": {
            "length_m": s.length_m,
            "time_s": s.time_s,
            "force_n": s.force_n,
            "energy_j": s.energy_j(),
            "power_w": s.power_w(),
        },
        "calibration": probe.calibration,
        "drive_frequency_hz": s.frequency_hz(params.omega),
        "period_s": params.period() * s.time_s,
        "free_amplitude_m": probe.free_amplitude,
        "z_c_m": probe.z_c_of(params),
    });
    let map_array = |v: &Value, f: &dyn Fn(&Value) -> Option<f64>| -> Value {
        v.as_array()
            .map(|a| Value::from(a.iter().map(f).collect::<Vec<_>>()))
            .unwrap_or(Value::Null)
    };
    for region in ["free", "contact"] {
        if let Some(om) = doc.get(region).and_then(|r| r.get("omega")) {
            out[format!("{region}_frequencies_hz")] = map_array(om, &hz);
        }
    }
    if let Some(x) = doc.get("x_max") {
        out["x_max_m"] = json!(metres(x));
    }
    if let Some(p) = doc.get("poincare").and_then(|p| p.get("v_t")) {
        out["poincare_v_t_m"] = map_array(p, &metres);
    }
    if let Some(att) = doc.get("attractors").and_then(Value::as_array) {
        out["attractors_x_max_m"] =
            Value::from(att.iter().map(|a| metres(&a["x_max"])).collect::<Vec<_>>());
    }
    if let Some(ex) = doc.get("exponents") {
        out["exponents_per_s"] = map_array(ex, &|v| v.as_f64().map(|l| l / s.time_s));
    }
    if let (Some(param), Some(events)) = (
        doc.get("param").and_then(Value::as_str),
        doc.get("events").and_then(Value::as_array),
    ) {
        let convert = |v: &Value| -> Option<f64> {
            let x = v.as_f64()?;
            match param {
                "omega" => Some(s.frequency_hz(x)),
                "alpha5" => Some(params.with(SweepParam::Alpha5, x).rest_distance() * s.length_m),
                _ => None,
            }
        };
        let unit = match param {
            "omega" => "hz",
            "alpha5" => "z_c_m",
            _ => "",
        };
        if !unit.is_empty() {
            out[format!("event_values_{unit}")] = Value::from(
                events
                    .iter()
                    .map(|e| convert(&e["value"]))
                    .collect::<Vec<_>>(),
            );
        }
    }
    out
}

/// The observables of a steady state ([`Observables`], every field, so a field added there
/// reaches both front ends): dimensionless units of the model (lengths g₀, time τ, forces F̃,
/// energies F̃·g₀); phases in radians. Non-finite values (e.g. Q = ∞ without damping) become
/// `null`.
pub fn observables(o: &Observables) -> Value {
    serde_json::to_value(o).expect("observables serialise")
}
