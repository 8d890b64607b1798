//! `afmdyn peakforce`: off-resonance (PeakForce) tapping — one steady tap of a modulated
//! sample at a mean rest separation z_c, or at the z_c an ideal peak-force feedback finds for
//! a setpoint, with the instrument's channels, one cycle and the force–distance curve. The
//! request, the analysis and the document are the library's
//! ([`afmdyn::request::PeakForceRequest`], [`afmdyn::analysis::peakforce`]), and so are its
//! summary, tables, figures and `peakforce.json` ([`afmdyn::request::present::peakforce`]);
//! this front end maps the flags.

use crate::args::{quantity, Dim, ModelArgs, Quantity};
use crate::door;
use crate::error::CliError;
use afmdyn::request::{PeakForceRequest, Resolved};
use afmdyn::Params;
use clap::Args;
use std::path::PathBuf;

/// `afmdyn peakforce` flags.
#[derive(Debug, Args)]
pub struct PeakForceArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Peak force the ideal feedback holds (N with --probe, else F; a unit may follow: 2nN);
    /// excludes --z-c (the mean rest separation, else the probe's [sample] z_c)
    #[arg(long, allow_hyphen_values = true)]
    setpoint: Option<Quantity>,
    /// Points of the reported cycle (2000..=1000000)
    #[arg(long, default_value_t = PeakForceRequest::default().samples)]
    samples: usize,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/peakforce")]
    out: PathBuf,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn peakforce`.
pub fn peakforce(a: &PeakForceArgs) -> Result<(), CliError> {
    let si = a.model.probe.is_some();
    if a.setpoint.is_some() && a.model.z_c.is_some() {
        return Err(CliError::Input(
            "give either --z-c (the mean rest separation) or --setpoint (the peak force the \
             feedback holds), not both"
                .into(),
        ));
    }
    let (params, probe) = a.model.resolve(Params::default())?;
    let request = PeakForceRequest {
        setpoint: quantity(a.setpoint, "setpoint", Dim::Force, si)?,
        samples: a.samples,
        ..PeakForceRequest::default()
    };
    let model = Resolved { params, probe };
    let exit = door::Exit {
        json: a.json,
        out: Some(&a.out),
        unit: "steady taps",
    };
    door::run(&request, &model, exit).map(|_| ())
}
