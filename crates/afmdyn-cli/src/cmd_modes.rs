//! `afmdyn modes` and `afmdyn units`.

use crate::args::{read_toml, ModelArgs};
use crate::door::{self, Exit};
use crate::error::CliError;
use crate::output::OutDir;
use afmdyn::eigen::fig3_sweep;
use afmdyn::request::present::modes;
use afmdyn::request::{ModesRequest, Resolved};
use afmdyn::units::PhysicalFile;
use afmdyn::Params;
use clap::Args;
use serde_json::json;
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
        files: Default::default(),
        json: a.json,
        out: None,
        unit: "modes",
    };
    door::run(&ModesRequest {}, &Resolved { params, probe }, exit).map(drop)
}

fn fig3(a: &ModesArgs, p: &Params) -> Result<(), CliError> {
    let out = OutDir::lock(&a.out)?;
    let pts = fig3_sweep(p.modes, &modes::fig3_alpha1(), &modes::fig3_alpha4())?;
    door::write_files(&out, &modes::fig3(p.modes, &pts))?;
    if a.json {
        outln!("{}", json!({ "params": p, "points": pts, "out": a.out }));
    } else {
        outln!("wrote {} points to {}", pts.len(), out.path().display());
    }
    Ok(())
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
    /// examples/probe-beam-dmt.toml and docs/afm-workflow.md): print its dimensionless set and
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

/// Run `afmdyn units`.
pub fn units(a: &UnitsArgs) -> Result<(), CliError> {
    if let Some(path) = &a.probe {
        let (_, pr) = afmdyn::probe::Probe::source_text(
            afmdyn::probe::ProbeSource::Path(path),
            a.cantilever.as_deref(),
            a.medium.as_deref(),
        )?;
        let p = pr.params;
        let doc = json!({ "params": p, "si": afmdyn::report::si(&pr, &p, &json!({})) });
        if a.json {
            outln!("{doc}");
        } else {
            outln!("{}", serde_json::to_string_pretty(&doc).expect("json"));
        }
        return Ok(());
    }
    let Some(config) = &a.config else {
        return Err(CliError::Input("give --config or --probe".into()));
    };
    let pf: PhysicalFile = read_toml(config)?;
    let model = pf.resolve()?;
    let p = model.to_params()?;
    let s = model.scales();
    if a.json {
        outln!("{}", json!({ "params": p, "scales": s, "physical": model }));
        return Ok(());
    }
    door::emit(None, &modes::units(&model, &p, &s), &json!({}), false)
}

/// `afmdyn cantilevers` flags.
#[derive(Debug, Args)]
pub struct CantileversArgs {
    /// Print one JSON document (every entry with its source)
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn cantilevers`: the cantilever library, one line per cantilever.
pub fn cantilevers(a: &CantileversArgs) -> Result<(), CliError> {
    if a.json {
        let doc = afmdyn::cantilevers::document();
        outln!("{doc}");
        return Ok(());
    }
    door::emit(None, &modes::cantilevers(), &json!({}), false)
}
