//! `afmdyn fm`: the frequency-modulation curve at constant amplitude over the rest distance
//! z_c — the drive frequency an ideal PLL locks at and the excitation an ideal amplitude
//! controller sets, as exact periodic orbits. The request, the analysis and the document are
//! the library's ([`afmdyn::request::FmRequest`], [`afmdyn::analysis::fm`]), and so are its
//! summary, `fm.csv`, `fm.json` and the frequency-shift figure
//! ([`afmdyn::request::present::fm`]); this front end maps the flags.

use crate::args::{quantity, Dim, ModelArgs, Quantity};
use crate::cmd_approach::files;
use crate::cmd_simulate::Files;
use crate::door;
use crate::error::CliError;
use crate::output::{units_of, OutDir};
use afmdyn::request::present;
use afmdyn::request::{self, FmRequest, Resolved};
use afmdyn::Params;
use clap::Args;
use std::path::PathBuf;

/// `afmdyn fm` flags.
#[derive(Debug, Args)]
pub struct FmArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Oscillation amplitude A the amplitude controller holds (m with --probe, else g0; a unit
    /// may follow: 10nm) [default: the probe's free amplitude A0]
    #[arg(long, allow_hyphen_values = true)]
    amplitude: Option<Quantity>,
    /// Mode K the PLL tracks (1..=N)
    #[arg(long, default_value_t = 1)]
    mode: usize,
    /// Rest distance z_c where the approach starts [default: where the frequency shift has
    /// decayed to 0.5 % of its value at --to (Giessibl's first-order shift of the law's force);
    /// 2A + a0 for a law without a force before contact]
    #[arg(long, allow_hyphen_values = true)]
    from: Option<Quantity>,
    /// Rest distance z_c where it ends [default: A + a0, the lower turning point at the contact
    /// distance a0]
    #[arg(long, allow_hyphen_values = true)]
    to: Option<Quantity>,
    /// Step of z_c (in the units of --from/--to); conflicts with --points
    #[arg(long, conflicts_with = "points", allow_hyphen_values = true)]
    step: Option<Quantity>,
    /// Number of z_c values, ends included [default: 120]
    #[arg(long)]
    points: Option<usize>,
    /// Tolerance of the loop conditions: |A1/A − 1| and the phase error (rad)
    #[arg(long, default_value_t = FmRequest::default().tolerance)]
    tolerance: f64,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/fm")]
    out: PathBuf,
    /// Files written: all (data and plots), data (no plots) or none (only the summary)
    #[arg(long, value_enum, default_value = "all")]
    files: Files,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn fm`.
pub fn fm(a: &FmArgs) -> Result<(), CliError> {
    let si = a.model.probe.is_some();
    let (params, probe) = a.model.resolve(Params::default())?;
    let request = FmRequest {
        amplitude: quantity(a.amplitude, "amplitude", Dim::Length, si)?,
        mode: a.mode,
        from: quantity(a.from, "from", Dim::Length, si)?,
        to: quantity(a.to, "to", Dim::Length, si)?,
        step: quantity(a.step, "step", Dim::Length, si)?,
        points: a.points,
        tolerance: a.tolerance,
    };
    let model = Resolved { params, probe };
    request::Analysis::validate(&request, &model)?;
    let out = (a.files != Files::None)
        .then(|| OutDir::lock(&a.out))
        .transpose()?;
    let mut doc = crate::progress::run(&request, &model, "z_c values")?.json;
    let units = units_of(model.probe.as_ref());
    let dir = out.as_ref().map(OutDir::path);
    let shown = present::fm::fm(&mut doc, units, files(a.files), dir);
    door::emit(out.as_ref(), &shown, &doc, a.json)
}
