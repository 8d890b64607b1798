//! Flags shared by every subcommand: the model parameters (with the paper's α aliases), the
//! TOML config file, the integrator.

use crate::error::CliError;
use afmdyn::integrate::IntegratorKind;
use afmdyn::request::{IntegratorRequest, ModelSpec};
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
    /// A cantilever of the library (`afmdyn cantilevers` lists them) for the probe file, which
    /// then needs only [sample] and [drive]: its k, f0, Q and tip radius fill the keys the file
    /// leaves out
    #[arg(long, value_name = "NAME", requires = "probe")]
    pub cantilever: Option<String>,
    // The help of the model flags comes from the library's table (afmdyn::request::
    // MODEL_PARAMETERS), set in main.rs.
    #[arg(
        long = "z-c",
        value_name = "METRES",
        requires = "probe",
        conflicts_with = "alpha5",
        allow_negative_numbers = true
    )]
    pub z_c: Option<f64>,
    #[arg(
        long = "drive-frequency",
        value_name = "HZ",
        requires = "probe",
        conflicts_with = "omega",
        allow_negative_numbers = true
    )]
    pub drive_frequency: Option<f64>,
    #[arg(long, value_name = "N")]
    pub modes: Option<usize>,
    #[arg(
        long = "tip-mass-ratio",
        alias = "alpha1",
        value_name = "α1",
        allow_negative_numbers = true
    )]
    pub alpha1: Option<f64>,
    #[arg(
        long = "drive-amplitude",
        alias = "alpha2",
        value_name = "α2",
        allow_negative_numbers = true
    )]
    pub alpha2: Option<f64>,
    #[arg(
        long = "beam-damping",
        alias = "alpha3",
        value_name = "α3",
        allow_negative_numbers = true
    )]
    pub alpha3: Option<f64>,
    #[arg(
        long = "contact-stiffness",
        alias = "alpha4",
        value_name = "α4",
        allow_negative_numbers = true
    )]
    pub alpha4: Option<f64>,
    #[arg(
        long = "gap",
        alias = "alpha5",
        value_name = "α5",
        allow_negative_numbers = true
    )]
    pub alpha5: Option<f64>,
    #[arg(
        long = "contact-damping",
        alias = "alpha6",
        value_name = "α6",
        allow_negative_numbers = true
    )]
    pub alpha6: Option<f64>,
    #[arg(long, value_name = "Ω", allow_negative_numbers = true)]
    pub omega: Option<f64>,
    #[arg(long, value_name = "LAW", value_parser = parse_law)]
    pub contact_law: Option<LawKind>,
    #[arg(long, value_name = "r", allow_negative_numbers = true)]
    pub restitution: Option<f64>,
    #[arg(long, value_name = "H̃", allow_negative_numbers = true)]
    pub hamaker: Option<f64>,
    #[arg(long, value_name = "ã0", allow_negative_numbers = true)]
    pub intermolecular_distance: Option<f64>,
}

fn parse_law(s: &str) -> Result<LawKind, String> {
    s.parse()
}

/// Read and parse a TOML file. Errors name the file, the line and column, and for a duplicate
/// key the key ([`afmdyn::request::model::parse_toml`]).
pub fn read_toml<T: for<'de> Deserialize<'de>>(path: &PathBuf) -> Result<T, CliError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::Input(format!("config {}: {e}", path.display())))?;
    afmdyn::request::model::parse_toml(&text)
        .map_err(|msg| CliError::Input(format!("config {}: {msg}", path.display())))
}

impl ModelArgs {
    /// The flags as the library's model values (names only; no numerics).
    pub fn spec(&self) -> ModelSpec {
        ModelSpec {
            modes: self.modes,
            tip_mass_ratio: self.alpha1,
            drive_amplitude: self.alpha2,
            beam_damping: self.alpha3,
            contact_stiffness: self.alpha4,
            gap: self.alpha5,
            contact_damping: self.alpha6,
            omega: self.omega,
            contact_law: self.contact_law,
            restitution: self.restitution,
            hamaker: self.hamaker,
            intermolecular_distance: self.intermolecular_distance,
            z_c: self.z_c,
            drive_frequency: self.drive_frequency,
        }
    }

    /// The probe file, when given (read once per call), with `--cantilever`'s name in it.
    pub fn probe(&self) -> Result<Option<afmdyn::probe::Probe>, CliError> {
        let (Some(path), Some(text)) = (&self.probe, self.probe_text()?) else {
            return Ok(None);
        };
        afmdyn::probe::Probe::parse(&text, &path.display().to_string())
            .map(Some)
            .map_err(CliError::from)
    }

    /// The probe file's text, with `[cantilever].name` set from `--cantilever`.
    pub fn probe_text(&self) -> Result<Option<String>, CliError> {
        let Some(path) = &self.probe else {
            return Ok(None);
        };
        let text = std::fs::read_to_string(path)
            .map_err(|e| CliError::Input(format!("{}: {e}", path.display())))?;
        match &self.cantilever {
            None => Ok(Some(text)),
            Some(name) => afmdyn::cantilevers::with_name(&text, name)
                .map(Some)
                .map_err(|e| CliError::Input(format!("{}: {e}", path.display()))),
        }
    }

    /// The model values of the flags over the config file, and the probe (unresolved: a
    /// chart resolves them once per cell).
    pub fn spec_and_probe(&self) -> Result<(ModelSpec, Option<afmdyn::probe::Probe>), CliError> {
        let probe = self.probe()?;
        let file: ModelSpec = match &self.config {
            Some(p) => read_toml(p)?,
            None => ModelSpec::default(),
        };
        Ok((self.spec().over(file), probe))
    }

    /// The parameter set: [`ModelSpec::resolve`] of the flags over the config file, on
    /// `defaults` or the probe's set; the probe is returned for the SI outputs.
    pub fn resolve(
        &self,
        defaults: Params,
    ) -> Result<(Params, Option<afmdyn::probe::Probe>), CliError> {
        let (spec, probe) = self.spec_and_probe()?;
        let p = spec
            .resolve(defaults, probe.as_ref())
            .map_err(|e| CliError::Input(crate::error::spell(&e)))?;
        Ok((p, probe))
    }
}

/// Integrator flags.
#[derive(Debug, Clone, Args)]
pub struct IntegratorArgs {
    /// Time integrator: auto (exact for the linear law, split for Hertz and impact, adaptive
    /// for DMT; default), exact (piecewise-exact), split (exact free flight, adaptive in
    /// contact), rk4 (located switchings), rk4-naive (region per stage, as in the paper) or
    /// adaptive (DOP853 with events and variational equations)
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
    /// The library's request ([`IntegratorRequest::options`] refines `exact`'s grid from the
    /// sampling rate; rk4 takes `--steps-per-period`, default 2000).
    pub fn request(&self) -> IntegratorRequest {
        IntegratorRequest {
            integrator: self.integrator,
            steps_per_period: self.steps_per_period,
            tolerance: self.tolerance,
        }
    }
}
