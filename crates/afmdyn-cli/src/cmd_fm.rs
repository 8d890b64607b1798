//! `afmdyn fm`: the frequency-modulation curve at constant amplitude over the rest distance
//! z_c — the drive frequency an ideal PLL locks at and the excitation an ideal amplitude
//! controller sets, as exact periodic orbits. The request, the analysis and the document are
//! the library's ([`afmdyn::request::FmRequest`], [`afmdyn::analysis::fm`]); this front end
//! maps the flags and writes `fm.csv`, `fm.json` and the frequency-shift plot.

use crate::args::{quantity, Dim, ModelArgs, Quantity};
use crate::cmd_simulate::Files;
use crate::error::CliError;
use crate::output::{f, si_value, write_csv, write_document, OutDir};
use crate::plot::{save, Figure, Series, Style};
use afmdyn::request::fm::{rows, COLUMNS};
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
    /// decayed to 1 % of its value at --to (Giessibl's first-order shift of the law's force);
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
    let out = match a.files {
        Files::None => None,
        _ => Some(OutDir::lock(&a.out)?),
    };
    let doc = crate::progress::run(&request, &model, "z_c values")?;
    let mut json = doc.json;
    let table = rows(&json);
    let column = |name: &str| COLUMNS.iter().position(|c| *c == name).unwrap_or(0);
    if let Some(out) = &out {
        write_csv(
            &out.join("fm.csv"),
            &COLUMNS,
            table.iter().map(|r| r.iter().map(|v| f(*v)).collect()),
        )?;
    }
    let (x_unit, y_unit) = if si {
        (" (m)", " (Hz)")
    } else {
        (" (g0)", " (Ω)")
    };
    let (x, y) = (column("z_c"), column("frequency_shift"));
    let points: Vec<(f64, f64)> = table.iter().map(|r| (r[x], r[y])).collect();
    if let (Some(out), Files::All) = (&out, a.files) {
        save(
            out.path(),
            "fm-frequency-shift",
            &Figure {
                title: "FM-AFM: frequency shift at constant amplitude".into(),
                x_label: format!("rest distance z_c{x_unit}"),
                y_label: format!("frequency shift Δf{y_unit}"),
                series: vec![Series {
                    label: String::new(),
                    points,
                    style: Style::Line,
                    color: 0,
                }],
                shade: Vec::new(),
                y_min_span: 0.0,
            },
        )?;
    }
    if let Some(out) = &out {
        json["csv"] = serde_json::json!(out.join("fm.csv"));
        write_document(out, "fm.json", &json)?;
    }
    if a.json {
        outln!("{json}");
    } else {
        let value = |v: f64, si_unit: &str, model_unit: &str| {
            if si {
                si_value(v, si_unit)
            } else {
                format!("{v:e} {model_unit}")
            }
        };
        let (first, last) = (table.first(), table.last());
        let k = |name: &str| COLUMNS.iter().position(|c| *c == name).unwrap_or(0);
        let at = |r: Option<&Vec<f64>>, k: usize| r.map_or(f64::NAN, |r| r[k]);
        outln!(
            "{} z_c values from {} to {}: Δf from {} to {}, excitation up to {:.4} × the free \
             one; {} unstable, {} folds; {}",
            table.len(),
            value(at(first, k("z_c")), "m", "g0"),
            value(at(last, k("z_c")), "m", "g0"),
            value(at(first, k("frequency_shift")), "Hz", "Ω"),
            value(at(last, k("frequency_shift")), "Hz", "Ω"),
            table
                .iter()
                .map(|r| r[k("excitation")])
                .fold(f64::NAN, f64::max),
            table.iter().filter(|r| r[k("stable")] == 0.0).count(),
            json["folds"].as_array().map_or(0, |v| v.len()),
            out.as_ref().map_or("no files written".into(), |o| format!(
                "outputs in {}",
                o.path().display()
            ))
        );
    }
    Ok(())
}
