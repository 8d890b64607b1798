//! Flags shared by every subcommand: the model parameters (with the paper's α aliases), the
//! TOML config file, the probe; numbers with SI units ([`Quantity`]). The request flags are
//! generated ([`crate::flags`]).

use crate::error::CliError;
use afmdyn::io::InputKind;
use afmdyn::probe::ProbeNeeds;
use afmdyn::request::ModelSpec;
use afmdyn::request::{LawGroups, LawKind, Params, GROUPS};
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
    /// see docs/getting-started.md): sets every parameter, the flags below override single ones,
    /// and JSON output gains an "si" block with the scales and headline values in SI
    #[arg(long, value_name = "PROBE.toml", conflicts_with = "config")]
    pub probe: Option<PathBuf>,
    /// A cantilever of the library (`afmdyn cantilevers` lists them) for the probe file, which
    /// then needs only [sample] and [drive]: its k, f0, Q and tip radius fill the keys the file
    /// leaves out
    // the text is the flag's help: [sample] and [drive] are TOML sections, not links
    #[allow(rustdoc::broken_intra_doc_links)]
    #[arg(long, value_name = "NAME", requires = "probe")]
    pub cantilever: Option<String>,
    /// The fluid around the lever, over the probe file's [medium]: water or air (Sader's
    /// hydrodynamic loading of every mode; docs/tutorials/liquids.md), or none (no fluid)
    #[allow(rustdoc::broken_intra_doc_links)]
    #[arg(long, value_name = "NAME", requires = "probe")]
    pub medium: Option<String>,
    // The help of the model flags comes from the library's table (afmdyn::request::
    // MODEL_PARAMETERS), set in main.rs.
    #[arg(
        long = "z-c",
        value_name = "METRES",
        requires = "probe",
        conflicts_with = "alpha5",
        allow_hyphen_values = true
    )]
    pub z_c: Option<Quantity>,
    #[arg(
        long = "drive-frequency",
        value_name = "HZ",
        requires = "probe",
        conflicts_with = "omega",
        allow_hyphen_values = true
    )]
    pub drive_frequency: Option<Quantity>,
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
    #[arg(long, value_name = "WHERE", value_parser = parse_excitation)]
    pub excitation: Option<afmdyn::request::Excitation>,
    /// The law groups' flags ([`GroupArgs`]).
    #[command(flatten)]
    pub groups: GroupArgs,
}

/// The flags of the law groups, one per group of the library's registry
/// ([`afmdyn::request::GROUPS`]: `--hamaker`, `--maxwell-stiffness`, …), built with clap's
/// builder API: each takes a number (negative ones too, refused by the law's range), its value
/// named by the group's symbol; the help comes from the library's table, as every model flag's
/// (main.rs).
#[derive(Debug, Clone, Copy, Default)]
pub struct GroupArgs(pub LawGroups);

/// The groups' flag names (`_` as `-`), in the order of [`GROUPS`].
fn group_flags() -> &'static [String] {
    static FLAGS: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    FLAGS.get_or_init(|| GROUPS.iter().map(|g| g.name.replace('_', "-")).collect())
}

impl clap::FromArgMatches for GroupArgs {
    fn from_arg_matches(m: &clap::ArgMatches) -> Result<Self, clap::Error> {
        let mut out = GroupArgs::default();
        out.update_from_arg_matches(m)?;
        Ok(out)
    }

    fn update_from_arg_matches(&mut self, m: &clap::ArgMatches) -> Result<(), clap::Error> {
        for g in GROUPS.iter() {
            if let Some(v) = m.get_one::<f64>(g.name) {
                self.0.set(g.name, Some(*v));
            }
        }
        Ok(())
    }
}

impl Args for GroupArgs {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        GROUPS
            .iter()
            .zip(group_flags())
            .fold(cmd, |cmd, (g, flag)| {
                cmd.arg(
                    clap::Arg::new(g.name)
                        .long(flag.as_str())
                        .value_name(g.symbol)
                        .allow_negative_numbers(true)
                        .value_parser(clap::value_parser!(f64))
                        .action(clap::ArgAction::Set),
                )
            })
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

fn parse_law(s: &str) -> Result<LawKind, String> {
    s.parse()
}

fn parse_excitation(s: &str) -> Result<afmdyn::request::Excitation, String> {
    s.parse()
}

/// Read and parse a TOML file. Errors name the file, the line and column, and for a duplicate
/// key the key ([`afmdyn::request::model::parse_toml`]).
pub fn read_toml<T: for<'de> Deserialize<'de>>(path: &std::path::Path) -> Result<T, CliError> {
    let text =
        read_text(path, InputKind::Config).map_err(|e| CliError::Input(format!("--config {e}")))?;
    afmdyn::request::model::parse_toml(&text)
        .map_err(|msg| CliError::Input(format!("config {}: {msg}", path.display())))
}

/// The text of an input file (a probe or `--config` file) of kind `kind`, at most its cap
/// ([`afmdyn::io::read_text`]).
///
/// # Errors
/// The library's [`afmdyn::io::InputFileError`] naming the file, the cap and the kind.
pub fn read_text(
    path: &std::path::Path,
    kind: InputKind,
) -> Result<String, afmdyn::io::InputFileError> {
    afmdyn::io::read_text(path, kind)
}

impl ModelArgs {
    /// The flags as the library's model values (names only; no numerics).
    ///
    /// # Errors
    /// [`CliError::Input`] for a `--z-c` or `--drive-frequency` with a unit of the other kind.
    pub fn spec(&self) -> Result<ModelSpec, CliError> {
        Ok(ModelSpec {
            modes: self.modes,
            tip_mass_ratio: self.alpha1,
            drive_amplitude: self.alpha2,
            beam_damping: self.alpha3,
            contact_stiffness: self.alpha4,
            gap: self.alpha5,
            contact_damping: self.alpha6,
            omega: self.omega,
            contact_law: self.contact_law,
            excitation: self.excitation,
            groups: self.groups.0,
            z_c: quantity(self.z_c, "z-c", Dim::Length, true)?,
            drive_frequency: quantity(
                self.drive_frequency,
                "drive-frequency",
                Dim::Frequency,
                true,
            )?,
        })
    }

    /// The probe file, when given (read once per call), with `--cantilever`'s name in it,
    /// read for a request that uses what `needs` says.
    pub fn probe(&self, needs: ProbeNeeds) -> Result<Option<afmdyn::probe::Probe>, CliError> {
        let (Some(path), Some(text)) = (&self.probe, self.probe_text()?) else {
            return Ok(None);
        };
        afmdyn::probe::Probe::parse_for(&text, &path.display().to_string(), needs)
            .map(Some)
            .map_err(CliError::from)
    }

    /// The probe file's text, with `[cantilever].name` set from `--cantilever` and the fluid
    /// from `--medium`.
    pub fn probe_text(&self) -> Result<Option<String>, CliError> {
        self.probe
            .as_deref()
            .map(|path| probe_text(path, self.cantilever.as_deref(), self.medium.as_deref()))
            .transpose()
    }

    /// The model values of the flags over the config file, and the probe (unresolved: a
    /// chart resolves them once per cell).
    pub fn spec_and_probe(&self) -> Result<(ModelSpec, Option<afmdyn::probe::Probe>), CliError> {
        self.spec_and_probe_for(ProbeNeeds::Oscillation)
    }

    /// As [`ModelArgs::spec_and_probe`], the probe read for what `needs` says.
    fn spec_and_probe_for(
        &self,
        needs: ProbeNeeds,
    ) -> Result<(ModelSpec, Option<afmdyn::probe::Probe>), CliError> {
        let probe = self.probe(needs)?;
        let file: ModelSpec = match &self.config {
            Some(p) => read_toml(p)?,
            None => ModelSpec::default(),
        };
        Ok((self.spec()?.over(file), probe))
    }

    /// The parameter set: [`ModelSpec::resolve`] of the flags over the config file, on
    /// `defaults` or the probe's set; the probe is returned for the SI outputs.
    pub fn resolve(
        &self,
        defaults: Params,
    ) -> Result<(Params, Option<afmdyn::probe::Probe>), CliError> {
        self.resolve_for(defaults, ProbeNeeds::Oscillation)
    }

    /// As [`ModelArgs::resolve`], the probe read for a request that uses what `needs` says
    /// (a force-curve fit: the spring constant, tip and sample).
    pub fn resolve_for(
        &self,
        defaults: Params,
        needs: ProbeNeeds,
    ) -> Result<(Params, Option<afmdyn::probe::Probe>), CliError> {
        let (spec, probe) = self.spec_and_probe_for(needs)?;
        let p = spec
            .resolve(defaults, probe.as_ref())
            .map_err(|e| CliError::Input(crate::error::spell(&e)))?;
        Ok((p, probe))
    }
}

pub use afmdyn::request::quantity::{Dim, Quantity};

/// The value of flag `--flag` ([`Quantity::si`]), which takes `want` in SI when `si` (with a
/// probe), else a dimensionless number.
///
/// # Errors
/// [`CliError::Input`] for a unit of another dimension, or a unit without a probe.
pub fn flag_value(q: Quantity, flag: &str, want: Dim, si: bool) -> Result<f64, CliError> {
    q.si(&format!("--{flag}"), "--probe", want, si)
        .map_err(CliError::Input)
}

/// `Option<Quantity>` → its value ([`flag_value`]).
pub fn quantity(
    q: Option<Quantity>,
    flag: &str,
    want: Dim,
    si: bool,
) -> Result<Option<f64>, CliError> {
    q.map(|q| flag_value(q, flag, want, si)).transpose()
}

/// The value of flag `--flag` whose dimension the command's mode gives: `want` as in
/// [`flag_value`], or `None` for a plain number (a ratio), which takes no unit.
///
/// # Errors
/// [`CliError::Input`] as [`flag_value`], or for a unit where the mode takes a plain number.
pub fn value_in(q: Quantity, flag: &str, want: Option<Dim>, si: bool) -> Result<f64, CliError> {
    match (want, q.dim) {
        (Some(want), _) => flag_value(q, flag, want, si),
        (None, Some(d)) => Err(CliError::Input(format!(
            "--{flag}: the unit makes it {}, but here --{flag} is a plain number \
                 (a ratio, without a unit)",
            d.name()
        ))),
        (None, None) => Ok(q.value),
    }
}

/// The values of a comma-separated flag `--flag` of exactly `N` quantities of dimension
/// `want` ([`flag_value`]), e.g. `--range LO,HI` (`names`: its value name, `LO,HI`).
///
/// # Errors
/// [`CliError::Input`] naming the flag for another number of values, or as
/// [`flag_value`].
pub fn values<const N: usize>(
    q: Option<&[Quantity]>,
    flag: &str,
    names: &str,
    want: Dim,
    si: bool,
) -> Result<Option<[f64; N]>, CliError> {
    let Some(q) = q else { return Ok(None) };
    if q.len() != N {
        let names = format!("{names} ({})", want.unit());
        return Err(count_error(flag, q.len(), N, &names));
    }
    let mut out = [0.0; N];
    for (o, v) in out.iter_mut().zip(q) {
        *o = flag_value(*v, flag, want, si)?;
    }
    Ok(Some(out))
}

/// The numbers of a comma-separated flag `--flag` of exactly `N` plain numbers (`names`: its
/// value name, e.g. `P,I`).
///
/// # Errors
/// [`CliError::Input`] naming the flag for another number of values.
pub fn numbers<const N: usize>(
    q: Option<&[f64]>,
    flag: &str,
    names: &str,
) -> Result<Option<[f64; N]>, CliError> {
    let Some(q) = q else { return Ok(None) };
    <[f64; N]>::try_from(q)
        .map(Some)
        .map_err(|_| count_error(flag, q.len(), N, names))
}

/// `--flag: 1 value(s) given; must be two, LO,HI`.
fn count_error(flag: &str, given: usize, n: usize, names: &str) -> CliError {
    let words = ["none", "one", "two", "three", "four"];
    CliError::Input(format!(
        "--{flag}: {given} value(s) given; must be {}, {names}",
        words.get(n).map_or(n.to_string(), |w| w.to_string())
    ))
}

/// A name of the library's enum (a request field's `oneOf` of names in its schema) as serde
/// reads it; clap admits only the schema's names, so this fails only if they drift apart.
///
/// # Errors
/// [`CliError::Input`] naming the flag for a name the type does not take.
pub fn named<T: serde::de::DeserializeOwned>(name: &str, flag: &str) -> Result<T, CliError> {
    serde_json::from_value(serde_json::Value::String(name.to_string()))
        .map_err(|e| CliError::Input(format!("--{flag} {name}: {e}")))
}

/// An optional boolean of two flags, `--x` (`on`) and `--no-x` (`off`; clap refuses both):
/// `Some(true)`, `Some(false)`, or `None` (the request's default) when neither is given.
pub fn either(on: bool, off: bool) -> Option<bool> {
    match (on, off) {
        (true, _) => Some(true),
        (_, true) => Some(false),
        _ => None,
    }
}

/// The text of the probe file `path` (read through the bounded reader, its refusals naming
/// `--probe`) with `[cantilever].name` set to `cantilever` and the fluid to `medium` when given
/// (`--cantilever`, `--medium`): every command's probe, `image`'s included.
pub fn probe_text(
    path: &std::path::Path,
    cantilever: Option<&str>,
    medium: Option<&str>,
) -> Result<String, CliError> {
    let text =
        read_text(path, InputKind::Probe).map_err(|e| CliError::Input(format!("--probe {e}")))?;
    let bad = |e: String| CliError::Input(format!("{}: {e}", path.display()));
    let text = match cantilever {
        None => text,
        Some(name) => afmdyn::cantilevers::with_name(&text, name).map_err(bad)?,
    };
    match medium {
        None => Ok(text),
        Some(name) => afmdyn::hydro::with_medium(&text, name).map_err(bad),
    }
}
