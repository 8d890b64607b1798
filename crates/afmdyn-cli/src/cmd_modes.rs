//! `afmdyn modes` and `afmdyn units`.

use crate::args::{read_toml, ModelArgs};
use crate::door::{self, Exit};
use crate::error::CliError;
use afmdyn::request::Params;
use afmdyn::request::{CantileversRequest, Fig3Request, ModesRequest, Resolved, UnitsRequest};
use afmdyn::units::PhysicalFile;
use clap::Args;
use std::path::PathBuf;

/// `afmdyn modes` flags.
#[derive(Debug, Args)]
pub struct ModesArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Print one JSON document instead of a table
    #[arg(long)]
    json: bool,
    /// Run a sweep instead: `fig3` (ω₁/ω₀₁ and ω₂/ω₀₂ over α1 × α4, paper Fig. 3)
    #[arg(long, value_parser = ["fig3"])]
    sweep: Option<String>,
    /// Output directory of the sweep
    #[arg(long, default_value = "afmdyn-out/modes")]
    out: PathBuf,
}

/// Run `afmdyn modes`.
pub fn modes(a: &ModesArgs) -> Result<(), CliError> {
    let (params, probe) = a.model.resolve(Params::default())?;
    if a.sweep.is_some() {
        return fig3(a, &params);
    }
    let exit = Exit {
        json: a.json,
        out: None,
        unit: "modes",
        ..Exit::default()
    };
    door::run(&ModesRequest {}, &Resolved { params, probe }, exit).map(drop)
}

/// `--sweep fig3`, on the model's parameters alone (the maps are dimensionless: no SI block).
fn fig3(a: &ModesArgs, p: &Params) -> Result<(), CliError> {
    let request = Fig3Request {
        out: a.out.display().to_string(),
    };
    let exit = Exit {
        json: a.json,
        out: Some(&a.out),
        unit: "points",
        ..Exit::default()
    };
    door::run(&request, &Resolved::plain(*p), exit).map(drop)
}

/// `afmdyn units` flags.
#[derive(Debug, Args)]
pub struct UnitsArgs {
    /// Physical model in the paper's terms (TOML, SI units: geometry, tip mass, C or Q₁,
    /// contact K₁ or Hertz, g₀, g₁, drive); see examples/probe.toml
    #[arg(
        long,
        value_name = "FILE.toml",
        required_unless_present = "probe",
        conflicts_with = "probe"
    )]
    config: Option<PathBuf>,
    /// Probe file (cantilever k, f0, Q or geometry; tip; sample law; drive A0, f; see
    /// examples/probe-beam-dmt.toml and docs/getting-started.md): print its dimensionless set and
    /// scales
    #[arg(long, value_name = "PROBE.toml")]
    probe: Option<PathBuf>,
    /// A cantilever of the library for the probe file (as every command's --cantilever)
    #[arg(long, value_name = "NAME", requires = "probe")]
    cantilever: Option<String>,
    /// The fluid around the lever, over the probe's [medium]: water, air or none (as every
    /// command's --medium)
    #[allow(rustdoc::broken_intra_doc_links)]
    #[arg(long, value_name = "NAME", requires = "probe")]
    medium: Option<String>,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn units`: the probe file's model (its SI block) or the physical model's
/// dimensionless set, through the door.
pub fn units(a: &UnitsArgs) -> Result<(), CliError> {
    let (request, model) = match (&a.probe, &a.config) {
        (Some(path), _) => {
            let (_, probe) = afmdyn::probe::Probe::source_text(
                afmdyn::probe::ProbeSource::Path(path),
                (a.cantilever.as_deref(), a.medium.as_deref()),
                afmdyn::probe::ProbeNeeds::Oscillation,
            )?;
            let model = Resolved::plain(probe.params);
            let request = UnitsRequest {
                probe: Some(probe),
                physical: None,
            };
            (request, model)
        }
        (None, Some(config)) => {
            let pf: PhysicalFile = read_toml(config)?;
            let request = UnitsRequest {
                probe: None,
                physical: Some(pf.resolve()?),
            };
            (request, Resolved::plain(Params::default()))
        }
        (None, None) => return Err(CliError::Input("give --config or --probe".into())),
    };
    door::run(&request, &model, quiet(a.json)).map(drop)
}

/// A command that writes no file and shows no progress: its document (`--json`) or summary.
fn quiet(json: bool) -> Exit<'static> {
    Exit {
        json,
        out: None,
        unit: "",
        ..Exit::default()
    }
}

/// `afmdyn cantilevers` flags.
#[derive(Debug, Args)]
pub struct CantileversArgs {
    /// Print one JSON document (every entry with its source)
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn cantilevers`: the cantilever library, one line per cantilever (every entry
/// with its source in the JSON document).
pub fn cantilevers(a: &CantileversArgs) -> Result<(), CliError> {
    door::run(
        &CantileversRequest {},
        &Resolved::plain(Params::default()),
        quiet(a.json),
    )
    .map(drop)
}
