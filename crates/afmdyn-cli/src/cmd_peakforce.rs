//! `afmdyn peakforce`: off-resonance (PeakForce) tapping — one steady tap of a modulated
//! sample at a mean rest separation z_c, or at the z_c an ideal peak-force feedback finds for
//! a setpoint, with the instrument's channels, one cycle and the force–distance curve. The
//! request, the analysis and the document are the library's
//! ([`afmdyn::request::PeakForceRequest`], [`afmdyn::analysis::peakforce`]), and so are its
//! summary, tables, figures and `peakforce.json` ([`afmdyn::report::present::peakforce`]);
//! this front end maps the flags.

use crate::args::{Dim, ModelArgs, Quantity};
use crate::cmd_approach::files;
use crate::cmd_simulate::Files;
use crate::door::{self, Exit};
use crate::error::CliError;
use crate::flags::PeakForceFlags;
use afmdyn::request::Params;
use afmdyn::request::{PeakForceSweep, PeakForceSweepParam, Resolved};
use clap::Args;
use std::path::PathBuf;

/// `afmdyn peakforce` flags.
#[derive(Debug, Args)]
pub struct PeakForceArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: PeakForceFlags,
    /// Sweep the steady tap over this quantity from --from to --to in steps of --step: z_c
    /// (m with --probe, else g0; a unit may follow: 5nm) or modulation_frequency (Hz with
    /// --probe, else Ω; 2kHz); the channels become curves (peakforce-sweep.csv, "sweep" in
    /// --json), each tap continued from the previous tap's orbit
    #[arg(long, requires_all = ["from", "to", "step"])]
    sweep: Option<PeakForceSweepParam>,
    /// First value of the sweep (z_c without --sweep)
    #[arg(long, allow_hyphen_values = true, requires_all = ["to", "step"])]
    from: Option<Quantity>,
    /// Last value of the sweep
    #[arg(long, allow_hyphen_values = true, requires = "from")]
    to: Option<Quantity>,
    /// Step of the sweep (in the units of --from/--to)
    #[arg(long, requires = "from")]
    step: Option<Quantity>,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/peakforce")]
    out: PathBuf,
    /// Files written: all (data and plots), data (no plots) or none (only the summary)
    #[arg(long, value_enum, default_value = "all")]
    files: Files,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn peakforce`.
pub fn peakforce(a: &PeakForceArgs) -> Result<(), CliError> {
    let si = a.model.probe.is_some();
    if a.request.setpoint.is_some() && a.model.z_c.is_some() {
        return Err(CliError::Input(
            "give either --z-c (the mean rest separation) or --setpoint (the peak force the \
             feedback holds), not both"
                .into(),
        ));
    }
    let (params, probe) = a.model.resolve(Params::default())?;
    let sweep = match (a.from, a.to, a.step) {
        (Some(from), Some(to), Some(step)) => {
            let param = a.sweep.unwrap_or(PeakForceSweepParam::ZC);
            if param == PeakForceSweepParam::ZC && a.model.z_c.is_some() {
                return Err(CliError::Input(
                    "a sweep in z_c (--from/--to/--step) excludes --z-c".into(),
                ));
            }
            let dim = match param {
                PeakForceSweepParam::ZC => Dim::Length,
                PeakForceSweepParam::ModulationFrequency => Dim::Frequency,
            };
            let v = |q: Quantity, flag: &str| crate::args::flag_value(q, flag, dim, si);
            let values = PeakForceSweep::grid(v(from, "from")?, v(to, "to")?, v(step, "step")?)?;
            Some(PeakForceSweep {
                quantity: param,
                values,
            })
        }
        _ => None,
    };
    let request = a.request.request(si, sweep)?;
    let exit = Exit {
        json: a.json,
        out: (a.files != Files::None).then_some(a.out.as_path()),
        files: files(a.files),
        unit: "steady taps",
        ..Exit::default()
    };
    door::run(&request, &Resolved { params, probe }, exit).map(drop)
}
