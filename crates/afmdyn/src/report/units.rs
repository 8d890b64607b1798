//! The units a result is reported in: the factors and names of a stepped curve's document
//! ([`CurveUnits`], [`UnitKind`]) and of a time series ([`SeriesUnits`], [`SeriesNames`]), and
//! the declarations of their columns ([`CURVE_COLUMNS`], [`SeriesUnits::columns`]).

use super::*;

/// Scales of a stepped-curve document (`approach`, `resonance`): the factors that turn the
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
    pub(crate) fn dimensionless() -> Self {
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
    pub(crate) fn from_scales(s: &crate::probe::Scales, hz: bool) -> Self {
        CurveUnits {
            length: s.length_m,
            force: s.force_n,
            energy: s.energy_j(),
            time: s.time_s,
            hz_per_omega: hz.then(|| s.frequency_hz(1.0)),
            si: true,
        }
    }

    /// [`CurveUnits::from_scales`] of a probe's scales, the model's own units without one.
    pub(crate) fn of(probe: Option<&crate::probe::Probe>, hz: bool) -> Self {
        probe.map_or_else(Self::dimensionless, |p| Self::from_scales(&p.scales, hz))
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

    pub(super) fn names(&self) -> Value {
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
/// (`CurveUnits::from_scales`). The one place a time series is converted; every factor
/// multiplies a dimensionless value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeriesUnits {
    /// The factors (time, length, force, energy, Hz per unit Ω for a spectrum; `si`).
    pub u: CurveUnits,
    /// A lumped model, point mass or eigenmodes (force unit k g₀ rather than EI g₀/L³).
    pub point_mass: bool,
}

/// The names of [`SeriesUnits`]: the time column and the units of each kind of quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SeriesNames {
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
    pub(crate) fn new(params: &Params, probe: Option<&crate::probe::Probe>) -> Self {
        SeriesUnits {
            u: CurveUnits::of(probe, true),
            point_mass: params.structure.is_lumped(),
        }
    }
    /// A time τ in the reported unit.
    pub(crate) fn t(&self, tau: f64) -> f64 {
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
    pub(crate) fn names(&self) -> SeriesNames {
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
    /// Its unit (`SeriesNames`).
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

impl UnitKind {
    /// The kind's key in a document's `units` block (`length`, `force`, `energy`, `phase`;
    /// `None` for a pure number): how Python's datasets and a document's column lists name it.
    pub(crate) fn key(self) -> Option<&'static str> {
        match self {
            UnitKind::Length => Some("length"),
            UnitKind::Force => Some("force"),
            UnitKind::Energy => Some("energy"),
            UnitKind::Phase => Some("phase"),
            UnitKind::One => None,
        }
    }
}

/// A per-point column of a stepped curve: its name, its kind of unit and its meaning — the
/// one declaration of the JSON document's keys, the command line's `.npy.json` meanings and
/// Python's dataset attributes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct CurveColumn {
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

/// The per-point columns of an approach with a temperature
/// ([`crate::analysis::lock_in_noise`]), after [`CURVE_COLUMNS`]: NaN (null) where a point is
/// not a stable period-1 orbit.
pub(crate) const NOISE_COLUMNS: [CurveColumn; 2] = [
    curve_column(
        "amplitude_noise",
        UnitKind::Length,
        "standard deviation of the lock-in amplitude under the thermal force (linear response)",
    ),
    curve_column(
        "phase_noise_deg",
        UnitKind::Phase,
        "standard deviation of the lock-in phase under the thermal force (linear response)",
    ),
];

/// The lock-in noise columns of a multifrequency drive's further components 2..=`count` (after
/// [`NOISE_COLUMNS`], which are the first component's), each with its kind of unit and meaning.
pub(crate) fn component_noise_columns(count: usize) -> Vec<(String, UnitKind, String)> {
    let what = "under the thermal force (linear response)";
    (2..=count)
        .flat_map(|i| {
            [
                (
                    format!("amplitude_noise_{i}"),
                    UnitKind::Length,
                    format!("standard deviation of component {i}'s lock-in amplitude {what}"),
                ),
                (
                    format!("phase_noise_{i}_deg"),
                    UnitKind::Phase,
                    format!("standard deviation of component {i}'s lock-in phase {what}"),
                ),
            ]
        })
        .collect()
}

/// The names of [`NOISE_COLUMNS`] and [`component_noise_columns`] of a drive of `count`
/// components, and their values at `noise` in `u`'s units (NaN without an estimate).
pub(crate) fn noise_row(
    noise: Option<&crate::analysis::lock_in_noise::LockInNoise>,
    count: usize,
    u: &CurveUnits,
) -> Vec<(String, f64)> {
    let n = noise.unwrap_or(&crate::analysis::lock_in_noise::LockInNoise::NONE);
    let further = n.further.into_iter().take(count.saturating_sub(1));
    let values = std::iter::once([n.amplitude, n.phase])
        .chain(further)
        .flat_map(|[a, p]| [a * u.length, p.to_degrees()]);
    let names = (NOISE_COLUMNS.iter().map(|c| c.name.to_string()))
        .chain(component_noise_columns(count).into_iter().map(|c| c.0));
    names.zip(values).collect()
}

/// The per-point columns of a stepped-curve document, in this order after the abscissa.
pub(crate) const CURVE_COLUMNS: [CurveColumn; 13] = [
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
    curve_column(
        "higher_mode_fraction",
        UnitKind::One,
        "participation of the higher eigenmodes: RMS amplitude of the tip deflection of modes \
         2..N relative to mode 1's (0 for one mode)",
    ),
];

/// The column of [`CURVE_COLUMNS`] named `name`.
pub(crate) fn curve_column_index(name: &str) -> Option<usize> {
    CURVE_COLUMNS.iter().position(|c| c.name == name)
}

/// The per-component columns of a curve under a multifrequency drive
/// ([`crate::analysis::observables::ComponentObservables`]), for components 1..=`count` (1 the
/// primary): `amplitude_i`, `phase_i_deg`, `virial_i`, `energy_dissipated_i` (per cycle of
/// component i), each with its kind of unit and meaning. [`component_row`] gives the values in
/// this order.
pub(crate) fn component_columns(count: usize) -> Vec<(String, UnitKind, String)> {
    (1..=count)
        .flat_map(|i| {
            [
                (
                    format!("amplitude_{i}"),
                    UnitKind::Length,
                    format!("amplitude of the tip deflection at drive component {i}'s frequency"),
                ),
                (
                    format!("phase_{i}_deg"),
                    UnitKind::Phase,
                    format!("phase lag of the deflection behind drive component {i}"),
                ),
                (
                    format!("virial_{i}"),
                    UnitKind::Energy,
                    format!(
                        "virial of component {i}: <F_ts z_{i}>, z_{i} the motion at its frequency"
                    ),
                ),
                (
                    format!("energy_dissipated_{i}"),
                    UnitKind::Energy,
                    format!("energy dissipated by component {i}'s motion, per cycle of it"),
                ),
            ]
        })
        .collect()
}

/// The values of [`component_columns`] of one orbit's observables in `u`'s units (empty for a
/// single-frequency drive).
pub(crate) fn component_row(
    o: &crate::analysis::observables::Observables,
    u: &CurveUnits,
) -> Vec<f64> {
    o.components
        .iter()
        .flat_map(|c| {
            [
                c.amplitude * u.length,
                c.phase.to_degrees(),
                c.virial * u.energy,
                c.energy_dissipated * u.energy,
            ]
        })
        .collect()
}
