//! Flags shared by every subcommand: the model parameters (with the paper's α aliases), the
//! TOML config file, the integrator.

use crate::error::CliError;
use afmdyn::integrate::{IntegratorKind, IntegratorOptions};
use afmdyn::{LawKind, Params};
use clap::Args;
use serde::Deserialize;
use std::path::PathBuf;

/// Model flags; each overrides the config file, which overrides the defaults (paper Figs. 5–14).
#[derive(Debug, Clone, Args, Default)]
pub struct ModelArgs {
    /// TOML file with model parameters (snake_case names of these flags, or alpha1..alpha6)
    #[arg(long, value_name = "FILE.toml")]
    pub config: Option<PathBuf>,
    /// Probe file in SI units (cantilever k, f0, Q or geometry; tip; sample law; drive A0, f;
    /// see docs/afm-workflow.md): sets every parameter, the flags below override single ones,
    /// and JSON output gains an "si" block with the scales and headline values in SI
    #[arg(long, value_name = "PROBE.toml", conflicts_with = "config")]
    pub probe: Option<PathBuf>,
    /// With --probe: the rest tip–sample distance z_c in metres (sets α5; overrides the probe's
    /// z_c)
    #[arg(
        long = "z-c",
        value_name = "METRES",
        requires = "probe",
        conflicts_with = "alpha5",
        allow_negative_numbers = true
    )]
    pub z_c: Option<f64>,
    /// With --probe: the drive frequency in Hz (sets Ω; the drive force or base amplitude is
    /// kept, as in a frequency sweep of an instrument)
    #[arg(
        long = "drive-frequency",
        value_name = "HZ",
        requires = "probe",
        conflicts_with = "omega"
    )]
    pub drive_frequency: Option<f64>,
    /// Number of Galerkin modes N (1..=20) [default: 3]
    #[arg(long, value_name = "N")]
    pub modes: Option<usize>,
    /// Tip-mass ratio α1 = M/(mL), 0..=1e4 [default: 0.1]
    #[arg(
        long = "tip-mass-ratio",
        alias = "alpha1",
        value_name = "α1",
        allow_negative_numbers = true
    )]
    pub alpha1: Option<f64>,
    /// Base-drive amplitude α2 = f/g0, 0..=1e6 [default: 0.1]
    #[arg(
        long = "drive-amplitude",
        alias = "alpha2",
        value_name = "α2",
        allow_negative_numbers = true
    )]
    pub alpha2: Option<f64>,
    /// Beam damping α3, 0..=1e4 [default: 0.1]
    #[arg(
        long = "beam-damping",
        alias = "alpha3",
        value_name = "α3",
        allow_negative_numbers = true
    )]
    pub alpha3: Option<f64>,
    /// Contact stiffness α4 = K1 L³/(EI), 0..=1e8 [default: 20]
    #[arg(
        long = "contact-stiffness",
        alias = "alpha4",
        value_name = "α4",
        allow_negative_numbers = true
    )]
    pub alpha4: Option<f64>,
    /// Tip–sample gap α5 = g1/g0 (may be negative), −1e6..=1e6 [default: 0]
    #[arg(
        long = "gap",
        alias = "alpha5",
        value_name = "α5",
        allow_negative_numbers = true
    )]
    pub alpha5: Option<f64>,
    /// Contact damping α6, 0..=1e4 [default: 0.2]
    #[arg(
        long = "contact-damping",
        alias = "alpha6",
        value_name = "α6",
        allow_negative_numbers = true
    )]
    pub alpha6: Option<f64>,
    /// Dimensionless drive frequency Ω, 1e-3..=1e5 [default: 2.6; converge: 4.1]
    #[arg(long, value_name = "Ω", allow_negative_numbers = true)]
    pub omega: Option<f64>,
    /// Tip–sample law: linear (the paper, α4 δ + α6 δ̇), hertz (α4 δ^1.5 + α6 δ̇), dmt (van der
    /// Waals + adhesion + Hertz + α6 √δ δ̇) or impact (rigid sample, restitution r)
    #[arg(long, value_name = "LAW", value_parser = parse_law)]
    pub contact_law: Option<LawKind>,
    /// Coefficient of restitution r of the impact law, 0..=1 (default 0.8)
    #[arg(long, value_name = "r", allow_negative_numbers = true)]
    pub restitution: Option<f64>,
    /// DMT van der Waals group H̃ = H R L³/(6 EI g0³) ≥ 0 (default 1e-5)
    #[arg(long, value_name = "H̃", allow_negative_numbers = true)]
    pub hamaker: Option<f64>,
    /// DMT intermolecular distance ã0 = a0/g0 > 0, the contact threshold (default 0.01)
    #[arg(long, value_name = "ã0", allow_negative_numbers = true)]
    pub intermolecular_distance: Option<f64>,
}

fn parse_law(s: &str) -> Result<LawKind, String> {
    s.parse()
}

/// The model section of a config file. Unknown keys are rejected.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// N.
    pub modes: Option<usize>,
    /// α1.
    #[serde(alias = "alpha1")]
    pub tip_mass_ratio: Option<f64>,
    /// α2.
    #[serde(alias = "alpha2")]
    pub drive_amplitude: Option<f64>,
    /// α3.
    #[serde(alias = "alpha3")]
    pub beam_damping: Option<f64>,
    /// α4.
    #[serde(alias = "alpha4")]
    pub contact_stiffness: Option<f64>,
    /// α5.
    #[serde(alias = "alpha5")]
    pub gap: Option<f64>,
    /// α6.
    #[serde(alias = "alpha6")]
    pub contact_damping: Option<f64>,
    /// Ω.
    pub omega: Option<f64>,
    /// linear | hertz | dmt | impact.
    pub contact_law: Option<LawKind>,
    /// Impact law: r.
    pub restitution: Option<f64>,
    /// DMT: H̃.
    pub hamaker: Option<f64>,
    /// DMT: ã0.
    pub intermolecular_distance: Option<f64>,
}

/// Read and parse a TOML config file. Errors name the file, the line and column, and for a
/// duplicate key the key.
pub fn read_toml<T: for<'de> Deserialize<'de>>(path: &PathBuf) -> Result<T, CliError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::Input(format!("config {}: {e}", path.display())))?;
    parse_toml(&text).map_err(|msg| CliError::Input(format!("config {}: {msg}", path.display())))
}

/// Parse TOML text; the error is one line: "line L, column C: message".
pub fn parse_toml<T: for<'de> Deserialize<'de>>(text: &str) -> Result<T, String> {
    toml::from_str(text).map_err(|e| {
        let mut msg = e.message().trim().replace('\n', " ");
        let Some(span) = e.span() else { return msg };
        let start = span.start.min(text.len());
        let before = &text[..start];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        if msg.starts_with("duplicate key") {
            let key = text.get(span.clone()).unwrap_or("").trim();
            if !key.is_empty() && !msg.contains(key) {
                msg = format!("duplicate key `{key}`");
            }
        }
        format!("line {line}, column {column}: {msg}")
    })
}

impl ModelArgs {
    /// The probe file, when given (read once per call).
    pub fn probe(&self) -> Result<Option<afmdyn::probe::Probe>, CliError> {
        self.probe
            .as_ref()
            .map(|p| afmdyn::probe::Probe::load(p).map_err(CliError::from))
            .transpose()
    }

    /// Resolve defaults ← probe or config ← flags and validate; the probe is returned for the
    /// SI outputs.
    pub fn resolve(
        &self,
        defaults: Params,
    ) -> Result<(Params, Option<afmdyn::probe::Probe>), CliError> {
        let probe = self.probe()?;
        let defaults = probe.as_ref().map_or(defaults, |p| p.params);
        let file: ModelFile = match &self.config {
            Some(p) => read_toml(p)?,
            None => ModelFile::default(),
        };
        let pick = |flag: Option<f64>, file: Option<f64>, def: f64| flag.or(file).unwrap_or(def);
        let kind = self.contact_law.or(file.contact_law);
        let restitution = self.restitution.or(file.restitution);
        let hamaker = self.hamaker.or(file.hamaker);
        let a0 = self
            .intermolecular_distance
            .or(file.intermolecular_distance);
        let contact_law =
            afmdyn::ContactLaw::from_parts(kind, hamaker, a0, restitution, defaults.contact_law)
                .map_err(|e| CliError::Input(e.to_string()))?;
        // `..defaults` carries any field without a flag (e.g. a contact law added to Params)
        #[allow(clippy::needless_update)]
        let p = Params {
            contact_law,
            modes: self.modes.or(file.modes).unwrap_or(defaults.modes),
            alpha1: pick(self.alpha1, file.tip_mass_ratio, defaults.alpha1),
            alpha2: pick(self.alpha2, file.drive_amplitude, defaults.alpha2),
            alpha3: pick(self.alpha3, file.beam_damping, defaults.alpha3),
            alpha4: pick(self.alpha4, file.contact_stiffness, defaults.alpha4),
            alpha5: pick(self.alpha5, file.gap, defaults.alpha5),
            alpha6: pick(self.alpha6, file.contact_damping, defaults.alpha6),
            omega: pick(self.omega, file.omega, defaults.omega),
            ..defaults
        };
        let mut p = p;
        if let Some(pr) = &probe {
            if let Some(z) = self.z_c {
                if !z.is_finite() {
                    return Err(CliError::Input(format!(
                        "z-c = {z}: must be a finite distance in m"
                    )));
                }
                p.alpha5 = p.alpha5_for_rest_distance(z / pr.scales.length_m);
            }
            if let Some(f) = self.drive_frequency {
                if !(f.is_finite() && f > 0.0) {
                    return Err(CliError::Input(format!(
                        "drive-frequency = {f}: must be finite and > 0 (Hz)"
                    )));
                }
                p.omega = pr.scales.omega(f);
            }
        }
        p.validate().map_err(|e| CliError::Input(e.to_string()))?;
        Ok((p, probe))
    }
}

/// Integrator flags.
#[derive(Debug, Clone, Args)]
pub struct IntegratorArgs {
    /// Time integrator: auto (exact for the linear law, adaptive otherwise; default), exact
    /// (piecewise-exact), rk4 (located switchings), rk4-naive (region per stage, as in the
    /// paper) or adaptive (DOP853 with events and variational equations)
    #[arg(long, default_value = "auto", value_parser = parse_integrator)]
    pub integrator: IntegratorKind,
    /// Fixed steps per drive period of rk4 / rk4-naive (default 2000)
    #[arg(long, value_name = "M")]
    pub steps_per_period: Option<usize>,
    /// Relative/absolute tolerance of the adaptive integrator
    #[arg(long, default_value_t = 1e-12)]
    pub tolerance: f64,
}

fn parse_integrator(s: &str) -> Result<IntegratorKind, String> {
    s.parse()
}

impl IntegratorArgs {
    /// Options. `exact` chooses its own grid, refined from `samples_per_period` so that samples
    /// land on grid points; `--steps-per-period` is the fixed step count of rk4 (default 2000).
    pub fn options(&self, samples_per_period: usize) -> IntegratorOptions {
        let steps = match self.integrator {
            IntegratorKind::Auto | IntegratorKind::Exact => samples_per_period.max(1),
            IntegratorKind::Rk4 | IntegratorKind::Rk4Naive => self.steps_per_period.unwrap_or(2000),
            IntegratorKind::Adaptive => 1,
        };
        IntegratorOptions {
            kind: self.integrator,
            steps_per_period: steps,
            tolerance: self.tolerance,
        }
    }
}
