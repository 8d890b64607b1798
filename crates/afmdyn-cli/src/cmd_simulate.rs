//! `afmdyn simulate` and `afmdyn converge`.

use crate::args::{IntegratorArgs, ModelArgs};
use crate::error::CliError;
use crate::output::{ensure_dir, f, write_csv, write_npy};
use crate::plot::{save, Figure, Series, Style};
use afmdyn::analysis::converge::mode_convergence;
use afmdyn::analysis::steady::SteadyOptions;
use afmdyn::integrate::build;
use afmdyn::trajectory::{record, RecordSpec, Trajectory};
use afmdyn::{CantileverModel, Params, Region, SimError};
use clap::Args;
use serde_json::json;
use std::path::PathBuf;

/// `afmdyn simulate` flags.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    integrator: IntegratorArgs,
    /// Drive periods to record after the transient
    #[arg(long, conflicts_with = "tau_end", allow_negative_numbers = true)]
    periods: Option<f64>,
    /// End time τ of the run (instead of --periods)
    #[arg(long, allow_negative_numbers = true)]
    tau_end: Option<f64>,
    /// Drive periods discarded before recording
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    transient: f64,
    /// Initial modal state "a1,..,aN;adot1,..,adotN" (default: rest)
    #[arg(long, allow_hyphen_values = true)]
    initial_modal: Option<String>,
    /// Samples per drive period in the time series
    #[arg(long, default_value_t = 200)]
    samples_per_period: usize,
    /// Output directory
    #[arg(long, default_value = "afmdyn-out/simulate")]
    out: PathBuf,
    /// Print one JSON summary instead of text
    #[arg(long)]
    json: bool,
}

fn parse_list(s: &str, what: &'static str) -> Result<Vec<f64>, CliError> {
    if s.trim().is_empty() {
        return Ok(vec![]);
    }
    s.split(',')
        .map(|t| {
            t.trim().parse::<f64>().map_err(|_| {
                CliError::Input(format!("--initial-modal: cannot read '{t}' in the {what}"))
            })
        })
        .collect()
}

pub(crate) fn initial_state(
    model: &CantileverModel,
    spec: &Option<String>,
) -> Result<nalgebra::DVector<f64>, CliError> {
    let Some(s) = spec else {
        return Ok(model.rest());
    };
    let (a, ad) = s.split_once(';').ok_or_else(|| {
        CliError::Input("--initial-modal: expected \"a1,..,aN;adot1,..,adotN\"".into())
    })?;
    let a = parse_list(a, "displacements")?;
    let ad = parse_list(ad, "velocities")?;
    Ok(model.state_from(&a, &ad)?)
}

/// Run `afmdyn simulate`.
pub fn simulate(a: &SimulateArgs) -> Result<(), CliError> {
    let p = a.model.params(Params::default())?;
    let model = CantileverModel::new(&p)?;
    let z0 = initial_state(&model, &a.initial_modal)?;
    if a.samples_per_period == 0 || a.samples_per_period > 100_000 {
        return Err(CliError::Input(format!(
            "samples-per-period = {}: must be in 1..=100000",
            a.samples_per_period
        )));
    }
    if !(a.transient.is_finite() && a.transient >= 0.0) {
        return Err(CliError::Input(format!(
            "transient = {}: must be finite and >= 0",
            a.transient
        )));
    }
    let t_transient = a.transient * p.period();
    let record_tau = match (a.periods, a.tau_end) {
        (Some(n), None) if n.is_finite() && n > 0.0 => n * p.period(),
        (Some(n), None) => {
            return Err(CliError::Input(format!(
                "periods = {n}: must be finite and > 0"
            )))
        }
        (None, Some(t)) if t.is_finite() && t > t_transient => t - t_transient,
        (None, Some(t)) => {
            return Err(CliError::Input(format!(
                "tau-end = {t}: must be finite and > the transient ({t_transient})"
            )))
        }
        _ => 50.0 * p.period(),
    };
    let opts = a.integrator.options(a.samples_per_period);
    let mut integ = build(&model, opts, 0.0, &z0)?;
    let tr = record(
        integ.as_mut(),
        &RecordSpec {
            transient_periods: a.transient,
            record_tau,
            samples_per_period: a.samples_per_period,
            energy: true,
            body_contact: true,
        },
    )?;
    write_outputs(a, &model, &tr)?;
    let zf = &tr.final_state;
    let summary = afmdyn::report::simulate(&model, &tr);
    if a.json {
        println!("{summary}");
    } else {
        let worst = tr
            .energy
            .iter()
            .map(|e| e.residual().abs())
            .fold(0.0, f64::max);
        println!(
            "integrator {}, τ from {:.6} to {:.6}",
            integ.name(),
            t_transient,
            tr.tau_end
        );
        println!(
            "switchings: {}, Poincaré points: {}",
            tr.events.len(),
            tr.poincare.len()
        );
        println!(
            "final W(1,τ) = {:.9}, V_T = {:.9}",
            model.w_tip(zf),
            model.v_t(tr.tau_end, zf)
        );
        println!("energy balance: largest per-period residual {worst:.3e}");
        if tr.body_contact {
            println!("warning: a point of the beam other than the tip reached the substrate (paper Fig. 2f)");
        }
        println!("outputs in {}", a.out.display());
    }
    Ok(())
}

fn write_outputs(
    a: &SimulateArgs,
    model: &CantileverModel,
    tr: &Trajectory,
) -> Result<(), CliError> {
    let n = model.modes();
    ensure_dir(&a.out)?;
    let mut header: Vec<String> = [
        "tau",
        "v_t",
        "w_tip",
        "w_tip_dot",
        "in_contact",
        "contact_force",
    ]
    .map(String::from)
    .to_vec();
    header.extend((1..=n).map(|j| format!("a_{j}")));
    header.extend((1..=n).map(|j| format!("a_dot_{j}")));
    let row = |s: &afmdyn::trajectory::Sample| -> Vec<f64> {
        let mut r = vec![
            s.tau,
            s.v_t,
            s.w_tip,
            s.w_tip_dot,
            f64::from(u8::from(s.region == Region::Contact)),
            s.contact_force,
        ];
        r.extend(s.state.iter());
        r
    };
    let hdr: Vec<&str> = header.iter().map(String::as_str).collect();
    write_csv(
        &a.out.join("timeseries.csv"),
        &hdr,
        tr.samples
            .iter()
            .map(|s| row(s).into_iter().map(f).collect()),
    )?;
    write_npy(
        &a.out.join("timeseries.npy"),
        header.len(),
        tr.samples.iter().map(row),
        tr.samples.len(),
    )?;
    write_csv(
        &a.out.join("events.csv"),
        &["tau", "from", "to", "v_t_dot"],
        tr.events.iter().map(|e| {
            vec![
                f(e.tau),
                format!("{:?}", e.from).to_lowercase(),
                format!("{:?}", e.to).to_lowercase(),
                f(e.v_t_dot),
            ]
        }),
    )?;
    write_csv(
        &a.out.join("poincare.csv"),
        &["tau", "v_t", "w_tip", "w_tip_dot"],
        tr.poincare.iter().map(|(t, z)| {
            vec![
                f(*t),
                f(model.v_t(*t, z)),
                f(model.w_tip(z)),
                f(model.w_tip_dot(z)),
            ]
        }),
    )?;
    write_csv(
        &a.out.join("energy.csv"),
        &[
            "tau0",
            "e_start",
            "e_end",
            "base_work",
            "beam_dissipation",
            "contact_dissipation",
            "residual",
        ],
        tr.energy.iter().map(|e| {
            vec![
                f(e.tau0),
                f(e.e_start),
                f(e.e_end),
                f(e.base_work),
                f(e.beam_dissipation),
                f(e.contact_dissipation),
                f(e.residual()),
            ]
        }),
    )?;
    // plots
    let mut shade = Vec::new();
    let mut open: Option<f64> = tr
        .samples
        .first()
        .filter(|s| s.region == Region::Contact)
        .map(|s| s.tau);
    for e in &tr.events {
        match e.to {
            Region::Contact => open = Some(e.tau),
            Region::Free => {
                if let Some(t0) = open.take() {
                    shade.push((t0, e.tau));
                }
            }
        }
    }
    if let (Some(t0), Some(last)) = (open, tr.samples.last()) {
        shade.push((t0, last.tau));
    }
    save(
        &a.out,
        "tip",
        &Figure {
            title: "Tip motion (contact intervals shaded)".into(),
            x_label: "τ".into(),
            y_label: "W(1,τ), V_T".into(),
            series: vec![
                Series {
                    label: "W(1,τ)".into(),
                    points: tr.samples.iter().map(|s| (s.tau, s.w_tip)).collect(),
                    style: Style::Line,
                    color: 0,
                },
                Series {
                    label: "V_T".into(),
                    points: tr.samples.iter().map(|s| (s.tau, s.v_t)).collect(),
                    style: Style::Line,
                    color: 1,
                },
            ],
            shade,
        },
    )?;
    let p = model.params();
    save(
        &a.out,
        "phase",
        &Figure {
            title: "Phase portrait".into(),
            x_label: "V_T".into(),
            y_label: "dV_T/dτ".into(),
            series: vec![Series {
                label: String::new(),
                points: tr
                    .samples
                    .iter()
                    .map(|s| {
                        (
                            s.v_t,
                            s.w_tip_dot + p.alpha2 * p.omega * (p.omega * s.tau).cos(),
                        )
                    })
                    .collect(),
                style: Style::Line,
                color: 0,
            }],
            shade: vec![],
        },
    )?;
    let spec = amplitude_spectrum(
        &tr.samples.iter().map(|s| s.w_tip).collect::<Vec<_>>(),
        a.samples_per_period,
        p.omega,
    );
    write_csv(
        &a.out.join("spectrum.csv"),
        &["frequency", "amplitude"],
        spec.iter().map(|(x, y)| vec![f(*x), f(*y)]),
    )?;
    save(
        &a.out,
        "spectrum",
        &Figure {
            title: "Amplitude spectrum of W(1,τ) (recorded part)".into(),
            x_label: "frequency (dimensionless, Ω = drive)".into(),
            y_label: "amplitude".into(),
            series: vec![Series {
                label: String::new(),
                points: spec,
                style: Style::Line,
                color: 0,
            }],
            shade: vec![],
        },
    )?;
    Ok(())
}

/// One-sided amplitude spectrum of uniformly sampled data (rustfft), frequencies in the units
/// of Ω; the mean is removed.
fn amplitude_spectrum(x: &[f64], samples_per_period: usize, omega: f64) -> Vec<(f64, f64)> {
    use rustfft::{num_complex::Complex, FftPlanner};
    let len = x.len().saturating_sub(1);
    if len < 4 {
        return vec![];
    }
    let mean = x[..len].iter().sum::<f64>() / len as f64;
    let mut buf: Vec<Complex<f64>> = x[..len]
        .iter()
        .map(|v| Complex::new(v - mean, 0.0))
        .collect();
    FftPlanner::new().plan_fft_forward(len).process(&mut buf);
    let dt = std::f64::consts::TAU / omega / samples_per_period as f64;
    let df = std::f64::consts::TAU / (len as f64 * dt);
    (0..=len / 2)
        .map(|k| (k as f64 * df, 2.0 * buf[k].norm() / len as f64))
        .collect()
}

/// `afmdyn converge` flags.
#[derive(Debug, Args)]
pub struct ConvergeArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    integrator: IntegratorArgs,
    /// Largest number of modes N_max
    #[arg(long, default_value_t = 4)]
    max_modes: usize,
    /// Drive periods of steady state compared
    #[arg(long, default_value_t = 1)]
    periods: usize,
    /// Samples per drive period
    #[arg(long, default_value_t = 200)]
    samples_per_period: usize,
    /// Output directory
    #[arg(long, default_value = "afmdyn-out/converge")]
    out: PathBuf,
    /// Print one JSON summary
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn converge`.
pub fn converge(a: &ConvergeArgs) -> Result<(), CliError> {
    // paper Fig. 4: eq. 24 at Ω = 4.1, with the damping of eq. 26 (α3 = 0.1, α6 = 0.2) so that a
    // steady state exists; --beam-damping 0 --contact-damping 0 restores eq. 24 exactly.
    let defaults = Params {
        omega: 4.1,
        ..Params::default()
    };
    let p = a.model.params(defaults)?;
    if !(1..=afmdyn::params::MAX_MODES).contains(&a.max_modes) {
        return Err(CliError::Input(format!(
            "max-modes = {}: must be in 1..=20",
            a.max_modes
        )));
    }
    let runs = mode_convergence(
        &p,
        a.max_modes,
        a.periods,
        a.samples_per_period,
        &SteadyOptions::default(),
        a.integrator.options(a.samples_per_period),
    )
    .map_err(|e: SimError| CliError::from(e))?;
    ensure_dir(&a.out)?;
    let k = runs.iter().map(|r| r.w_tip.len()).min().unwrap_or(0);
    let mut header = vec!["tau_from_section".to_string()];
    header.extend(runs.iter().map(|r| format!("w_tip_n{}", r.modes)));
    let hdr: Vec<&str> = header.iter().map(String::as_str).collect();
    let t0 = runs[0].tau[0];
    write_csv(
        &a.out.join("converge.csv"),
        &hdr,
        (0..k).map(|i| {
            let mut row = vec![f(runs[0].tau[i] - t0)];
            row.extend(runs.iter().map(|r| f(r.w_tip[i])));
            row
        }),
    )?;
    save(
        &a.out,
        "converge",
        &Figure {
            title: format!("Mode convergence, Ω = {} (paper Fig. 4)", p.omega),
            x_label: "τ − τ₀ (from a section point)".into(),
            y_label: "W(1,τ)".into(),
            series: runs
                .iter()
                .map(|r| Series {
                    label: format!("N = {}", r.modes),
                    points: r
                        .tau
                        .iter()
                        .zip(&r.w_tip)
                        .map(|(t, w)| (t - r.tau[0], *w))
                        .collect(),
                    style: Style::Line,
                    color: r.modes - 1,
                })
                .collect(),
            shade: vec![],
        },
    )?;
    if a.json {
        let mut doc = afmdyn::report::converge(&p, &runs);
        doc["out"] = json!(a.out);
        println!("{doc}");
    } else {
        if p.alpha3 > 0.0 || p.alpha6 > 0.0 {
            println!("note: paper eq. 24 is undamped; using α3 = {}, α6 = {} (eq. 26) so a steady state exists", p.alpha3, p.alpha6);
        }
        println!("{:>3} {:>8} {:>22}", "N", "period", "RMS ΔW_tip vs N−1");
        for r in &runs {
            println!(
                "{:>3} {:>8} {:>22}",
                r.modes,
                r.period.map_or("nonper.".to_string(), |n| n.to_string()),
                r.rms_change.map_or("-".to_string(), |v| format!("{v:.4e}"))
            );
        }
        println!("outputs in {}", a.out.display());
    }
    Ok(())
}
