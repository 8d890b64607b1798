//! `afmdyn simulate` and `afmdyn converge`.

use crate::args::{IntegratorArgs, ModelArgs};
use crate::error::CliError;
use crate::output::{f, write_csv, write_csv_numbers, OutDir};
use crate::plot::{save, Figure, PixelColumns, Series, Style};
use afmdyn::analysis::spectrum::{amplitude_spectrum, SPECTRUM_SAMPLES};
use afmdyn::integrate::build;
use afmdyn::report::SeriesUnits;
use afmdyn::request::simulate_files::{SeriesFiles, SERIES_FILES};
use afmdyn::request::{ConvergeRequest, SeriesStore, SimulateRequest};
use afmdyn::request::{Document, Resolved};
use afmdyn::trajectory::chunked::{record_chunked, Chunk, ChunkedSpec};
use afmdyn::{CantileverModel, Params, Region};
use clap::{Args, ValueEnum};
use serde_json::json;
use std::collections::VecDeque;
use std::path::PathBuf;

/// Which files a run writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Files {
    /// Data files and plots.
    All,
    /// Data files only (no plots).
    Data,
    /// Nothing: only the summary on stdout.
    None,
}

/// Every file `simulate` writes in its `--out` directory: a run removes their stale temporary
/// siblings (`.NAME.partial.EXT`), which a run killed outright (a second Ctrl-C) leaves.
const SIMULATE_OUTPUTS: &[&str] = &[
    "spectrum.csv",
    "tip.png",
    "tip.svg",
    "tip-all.png",
    "tip-all.svg",
    "phase.png",
    "phase.svg",
    "spectrum.png",
    "spectrum.svg",
];

/// Samples kept for the phase portrait (the last ones).
const PHASE_SAMPLES: usize = 50_000;
/// Drive periods `tip.png` shows (the last ones) when more were recorded; `tip-all.png` then
/// shows every recorded period (a 50-period chaotic record drawn whole is unreadable).
const TIP_WINDOW_PERIODS: usize = 10;

/// `afmdyn simulate` flags.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    integrator: IntegratorArgs,
    /// Drive periods to record after the transient; transient + periods ≤ 1e8 [default: 50]
    #[arg(long, conflicts_with = "tau_end", allow_negative_numbers = true)]
    periods: Option<f64>,
    /// End time τ of the run (instead of --periods)
    #[arg(long, allow_negative_numbers = true)]
    tau_end: Option<f64>,
    /// Drive periods discarded before recording
    #[arg(long, default_value_t = SimulateRequest::default().transient, allow_negative_numbers = true)]
    transient: f64,
    /// Initial modal state "a1,..,aN;adot1,..,adotN" (default: rest); |z| < 1e12
    #[arg(long, allow_hyphen_values = true)]
    initial_modal: Option<String>,
    /// Samples per drive period in the time series (1..=100000)
    #[arg(long, default_value_t = SimulateRequest::default().samples_per_period)]
    samples_per_period: usize,
    /// Files written: all (data and plots), data (no plots) or none (only the summary)
    #[arg(long, value_enum, default_value = "all")]
    files: Files,
    /// Also write the time series as CSV (timeseries.csv); by default only timeseries.npy
    #[arg(long)]
    csv: bool,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/simulate")]
    out: PathBuf,
    /// Print one JSON summary instead of text
    #[arg(long)]
    json: bool,
    /// Drive periods held in memory at once (testing the streaming; default from the samples)
    #[arg(long, hide = true)]
    chunk_periods: Option<usize>,
}

fn parse_list(s: &str, flag: &str, what: &'static str) -> Result<Vec<f64>, CliError> {
    if s.trim().is_empty() {
        return Ok(vec![]);
    }
    s.split(',')
        .map(|t| {
            t.trim()
                .parse::<f64>()
                .map_err(|_| CliError::Input(format!("--{flag}: cannot read '{t}' in the {what}")))
        })
        .collect()
}

/// The `--initial-modal "a1,..,aN;adot1,..,adotN"` flag as the library's 2N values for N =
/// `modes` (its syntax only: the magnitudes are checked by
/// [`afmdyn::request::analyses::initial_state`]).
pub(crate) fn parse_initial(
    spec: &Option<String>,
    modes: usize,
) -> Result<Option<Vec<f64>>, CliError> {
    parse_modal_state("initial-modal", spec, modes)
}

/// A modal state flag `--<flag> "a1,..,aN;adot1,..,adotN"` as 2N values (syntax only).
pub(crate) fn parse_modal_state(
    flag: &str,
    spec: &Option<String>,
    modes: usize,
) -> Result<Option<Vec<f64>>, CliError> {
    let Some(s) = spec else {
        return Ok(None);
    };
    let (a, ad) = s.split_once(';').ok_or_else(|| {
        CliError::Input(format!("--{flag}: expected \"a1,..,aN;adot1,..,adotN\""))
    })?;
    let mut z = parse_list(a, flag, "displacements")?;
    let ad = parse_list(ad, flag, "velocities")?;
    if z.len() != modes || ad.len() != modes {
        return Err(CliError::Input(format!(
            "--{flag}: expected {modes} displacements and {modes} velocities (N = \
             {modes}), got {} and {}",
            z.len(),
            ad.len()
        )));
    }
    z.extend(ad);
    Ok(Some(z))
}

/// Contact intervals for shading, merged when closer than `min_gap` (bounded memory).
struct Shade {
    intervals: Vec<(f64, f64)>,
    open: Option<f64>,
    min_gap: f64,
}

impl Shade {
    fn push(&mut self, a: f64, b: f64) {
        match self.intervals.last_mut() {
            Some(last) if a - last.1 <= self.min_gap => last.1 = last.1.max(b),
            _ => self.intervals.push((a, b)),
        }
    }
}

/// What the plots need, gathered chunk by chunk in bounded memory.
struct PlotData {
    tip: Vec<(f64, f64)>,
    vt: Vec<(f64, f64)>,
    /// The open pixel columns of `tip` and `vt` once they are decimated as they come
    /// (`streaming`: from the first chunk after which they hold more than 8 points a column).
    tip_cols: PixelColumns,
    vt_cols: PixelColumns,
    streaming: bool,
    columns: f64,
    t0: f64,
    t1: f64,
    shade: Shade,
    /// The last [`PHASE_SAMPLES`]: τ, V_T, ∂W(1,τ)/∂τ (dV_T/dτ formed at the end).
    phase: VecDeque<(f64, f64, f64)>,
    /// The last [`TIP_WINDOW_PERIODS`] periods: τ, W(1,τ), V_T, in contact.
    recent: VecDeque<(f64, f64, f64, bool)>,
    /// Its capacity (samples).
    recent_cap: usize,
}

impl PlotData {
    /// The pixel column of τ on the tip plots' grid.
    fn column(&self, x: f64) -> i32 {
        (((x - self.t0) / (self.t1 - self.t0).max(1e-300)) * self.columns) as i32
    }

    /// Add a sample (τ, W, V_T) to the tip plots' lines: as it is, or into its pixel column
    /// once the lines are decimated as they come (the first, lowest, highest and last point
    /// of every column, [`PixelColumns`]: what decimating the whole line keeps; a non-finite
    /// value closes the column and is dropped, as there).
    fn add(&mut self, t: f64, w: f64, v: f64) {
        if !self.streaming {
            self.tip.push((t, w));
            self.vt.push((t, v));
            return;
        }
        let cx = self.column(t);
        for (q, cols, out) in [
            ((t, w), &mut self.tip_cols, &mut self.tip),
            ((t, v), &mut self.vt_cols, &mut self.vt),
        ] {
            if q.0.is_finite() && q.1.is_finite() {
                cols.push(cx, q, out);
            } else {
                cols.flush(out);
            }
        }
    }

    /// After a chunk: once the lines hold more than 8 points a pixel column, decimate them
    /// from then on as the samples come ([`PlotData::add`]).
    fn redecimate(&mut self) {
        if self.streaming || self.tip.len() <= 8 * self.columns as usize {
            return;
        }
        self.streaming = true;
        let (tip, vt) = (std::mem::take(&mut self.tip), std::mem::take(&mut self.vt));
        for (&(t, w), &(_, v)) in tip.iter().zip(&vt) {
            self.add(t, w, v);
        }
    }

    /// Close the open pixel columns.
    fn finish(&mut self) {
        self.tip_cols.flush(&mut self.tip);
        self.vt_cols.flush(&mut self.vt);
    }
}

/// Run `afmdyn simulate`: the run is recorded in chunks of whole periods and every chunk is
/// streamed to the files, so memory does not grow with the length of the run.
pub fn simulate(a: &SimulateArgs) -> Result<(), CliError> {
    let (p, probe) = a.model.resolve(Params::default())?;
    let model = CantileverModel::new(&p)?;
    let request = SimulateRequest {
        periods: a.periods,
        tau_end: a.tau_end,
        transient: a.transient,
        initial: parse_initial(&a.initial_modal, p.modes)?,
        samples_per_period: a.samples_per_period,
        integrator: a.integrator.request(),
    };
    let z0 = afmdyn::request::analyses::initial_state(&model, request.initial.as_deref())?;
    let n = p.modes;
    let su = SeriesUnits::new(&p, probe.as_ref());
    let (store, bytes_per_value) = match a.files {
        Files::None => (SeriesStore::Nothing, 0.0),
        // NPY 8 bytes a value, CSV up to 24 more
        _ => (SeriesStore::Files, if a.csv { 8.0 + 24.0 } else { 8.0 }),
    };
    // τ, V_T, W, Ẇ, contact, force and the 2N modal coordinates per sample
    let span = request.validate(&p, store, 6 + 2 * n, bytes_per_value)?;
    let (t_transient, record_tau, total_periods) =
        (span.transient_tau, span.record_tau, span.total_periods);
    let spp = a.samples_per_period;
    let opts = request.integrator_options()?;
    let mut integ = build(&model, opts, 0.0, &z0)?;
    // inputs are valid: lock the output directory (removing what a run killed outright left
    // of these files) and open the files
    let out = match a.files {
        Files::None => None,
        _ => {
            let o = OutDir::lock(&a.out)?;
            o.remove_partials(&SERIES_FILES)?;
            o.remove_partials(SIMULATE_OUTPUTS)?;
            Some(o)
        }
    };
    let mut files = match &out {
        None => None,
        Some(o) => Some(SeriesFiles::create(o.path(), n, su, a.csv)?),
    };
    let start = t_transient;
    let end = start + record_tau;
    let mut plots = (a.files == Files::All).then(|| PlotData {
        tip: vec![],
        vt: vec![],
        tip_cols: PixelColumns::default(),
        vt_cols: PixelColumns::default(),
        streaming: false,
        columns: 2000.0,
        t0: start,
        t1: end,
        shade: Shade {
            intervals: vec![],
            open: None,
            min_gap: (end - start) / 4000.0,
        },
        phase: VecDeque::new(),
        recent: VecDeque::new(),
        recent_cap: TIP_WINDOW_PERIODS * spp + 1,
    });
    let mut spectrum: VecDeque<f64> = VecDeque::new();
    let record_samples = if files.is_some() { spp } else { 0 };
    let bar = indicatif::ProgressBar::new(total_periods.ceil() as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} periods  {elapsed} / ~{duration}",
        )
        .expect("template"),
    );
    let spec = ChunkedSpec {
        transient_periods: a.transient,
        record_tau,
        samples_per_period: record_samples,
        chunk_periods: a.chunk_periods,
    };
    crate::error::stop_on_signal();
    let each = |c: &Chunk<'_>| -> Result<(), CliError> {
        // SIGINT/SIGTERM: end here; the streams' partial files are removed as they are dropped
        crate::error::interrupted()?;
        if let Some(fl) = files.as_mut() {
            fl.push(&model, c)?;
            // the spectrum's window: the last SPECTRUM_SAMPLES values of W(1,τ)
            let new = c.samples().len();
            let keep = new.min(SPECTRUM_SAMPLES);
            let drop = (spectrum.len() + keep).saturating_sub(SPECTRUM_SAMPLES);
            spectrum.drain(..drop);
            spectrum.extend(c.samples().skip(new - keep).map(|s| s[2]));
        }
        if let Some(pd) = plots.as_mut() {
            let new = c.samples().len();
            for s in c.samples() {
                pd.add(s[0], s[2], s[1]);
            }
            // the phase portrait's and the tip window's last samples (only those kept)
            let keep = new.min(PHASE_SAMPLES);
            let drop = (pd.phase.len() + keep).saturating_sub(PHASE_SAMPLES);
            pd.phase.drain(..drop);
            pd.phase
                .extend(c.samples().skip(new - keep).map(|s| (s[0], s[1], s[3])));
            let keep = new.min(pd.recent_cap);
            let drop = (pd.recent.len() + keep).saturating_sub(pd.recent_cap);
            pd.recent.drain(..drop);
            pd.recent.extend(
                c.samples()
                    .skip(new - keep)
                    .map(|s| (s[0], s[2], s[1], s[4] != 0.0)),
            );
            if let Some(s) = c.samples().next().filter(|s| c.first && s[4] != 0.0) {
                pd.shade.open = Some(s[0]);
            }
            for e in c.events() {
                match e.to {
                    Region::Contact => pd.shade.open = Some(e.tau),
                    Region::Free => {
                        if let Some(t0) = pd.shade.open.take() {
                            pd.shade.push(t0, e.tau);
                        }
                    }
                }
            }
            pd.redecimate();
        }
        Ok(())
    };
    let summary = record_chunked(integ.as_mut(), &spec, each, |done| {
        bar.set_position(done as u64)
    })?;
    bar.finish_and_clear();
    if let Some(fl) = files {
        fl.finish()?;
    }
    if let Some(o) = &out {
        write_spectrum_and_plots(o, &p, &su, spp, spectrum, plots, summary.tau_end)?;
    }
    let zf = summary.final_state.clone().unwrap_or_else(|| z0.clone());
    let run = afmdyn::report::SimulateSummary {
        tau_end: summary.tau_end,
        final_state: zf.clone(),
        switchings: summary.switchings,
        body_contact: summary.body_contact,
        poincare_points: summary.sections,
        energy_residual: (summary.residual, summary.relative),
    };
    let warnings = afmdyn::report::simulate_warnings(&run);
    let mut doc = afmdyn::report::simulate_summary(&model, &run);
    doc = afmdyn::report::with_si(doc, probe.as_ref(), &p);
    doc["files"] = json!(a
        .files
        .to_possible_value()
        .map(|v| v.get_name().to_string()));
    for w in &warnings {
        errln!("afmdyn: warning: {w}");
    }
    if a.json {
        outln!("{doc}");
    } else {
        outln!(
            "integrator {}, τ from {:.6} to {:.6}",
            integ.name(),
            t_transient,
            summary.tau_end
        );
        outln!(
            "switchings: {}, Poincaré points: {}",
            summary.switchings,
            summary.sections
        );
        outln!(
            "final W(1,τ) = {:.9}, V_T = {:.9}",
            model.w_tip(&zf),
            model.v_t(summary.tau_end, &zf)
        );
        if su.u.si {
            let nm = |v: f64| su.x(v) * 1e9;
            outln!(
                "  in SI: t from {:.6} µs to {:.6} µs, final W = {:.6} nm, V_T = {:.6} nm",
                su.t(t_transient) * 1e6,
                su.t(summary.tau_end) * 1e6,
                nm(model.w_tip(&zf)),
                nm(model.v_t(summary.tau_end, &zf))
            );
        }
        outln!(
            "energy balance: largest per-period residual {:.3e} ({:.1e} relative)",
            summary.residual,
            summary.relative
        );
        match &out {
            Some(o) => outln!("outputs in {}", o.path().display()),
            None => outln!("no files written (--files none)"),
        }
    }
    Ok(())
}

/// `spectrum.csv` and the plots, in `su`'s units (SI with a probe: time in s, lengths in m,
/// frequencies in Hz; the plots' axes take the prefix of their range).
fn write_spectrum_and_plots(
    out: &OutDir,
    p: &Params,
    su: &SeriesUnits,
    spp: usize,
    spectrum: VecDeque<f64>,
    plots: Option<PlotData>,
    tau_end: f64,
) -> Result<(), CliError> {
    let period = p.period();
    let window = spectrum.len();
    let data: Vec<f64> = spectrum.into();
    let hz = su.u.hz_per_omega.unwrap_or(1.0);
    let spec: Vec<(f64, f64)> = amplitude_spectrum(&data, spp, p.omega)
        .into_iter()
        .map(|(w, a)| (w * hz, su.x(a)))
        .collect();
    write_csv_numbers(
        &out.join("spectrum.csv"),
        &[
            if su.u.si { "frequency_hz" } else { "frequency" },
            "amplitude",
        ],
        spec.iter().map(|&(x, y)| [x, y]),
    )?;
    let Some(mut pd) = plots else { return Ok(()) };
    pd.finish();
    if let Some(t0) = pd.shade.open.take() {
        pd.shade.push(t0, tau_end);
    }
    // the plots' data in the files' units
    let xy = |v: &mut Vec<(f64, f64)>| {
        for pt in v.iter_mut() {
            *pt = (su.t(pt.0), su.x(pt.1));
        }
    };
    xy(&mut pd.tip);
    xy(&mut pd.vt);
    // dV_T/dτ = ∂W(1,τ)/∂τ + α2 Ω cos Ωτ (eq. 8)
    let (a2, om) = (p.alpha2, p.omega);
    let phase: Vec<(f64, f64)> = pd
        .phase
        .iter()
        .map(|&(tau, v_t, w_dot)| (su.x(v_t), su.v(w_dot + a2 * om * (om * tau).cos())))
        .collect();
    for r in pd.recent.iter_mut() {
        *r = (su.t(r.0), su.x(r.1), su.x(r.2), r.3);
    }
    for iv in pd.shade.intervals.iter_mut() {
        *iv = (su.t(iv.0), su.t(iv.1));
    }
    let (t_label, y_label, phase_x, phase_y, spec_x, spec_y) = if su.u.si {
        (
            "time t (s)",
            "W(1,t), V_T (m)",
            "V_T (m)",
            "dV_T/dt (m/s)",
            "frequency (Hz)".to_string(),
            "log₁₀(amplitude / m)",
        )
    } else {
        (
            "τ",
            "W(1,τ), V_T",
            "V_T",
            "dV_T/dτ",
            "frequency (dimensionless, Ω = drive)".to_string(),
            "log₁₀(amplitude / g0)",
        )
    };
    let recorded = (pd.t1 - pd.t0) / period;
    let last = |n: usize, what: &str| {
        let periods = n as f64 / spp as f64;
        if periods + 1e-9 < recorded {
            format!("{what} (last {periods:.0} periods)")
        } else {
            format!("{what} (recorded part)")
        }
    };
    let tip_figure = |title: String, tip: Vec<(f64, f64)>, vt: Vec<(f64, f64)>, shade| Figure {
        y_min_span: 0.0,
        title,
        x_label: t_label.into(),
        y_label: y_label.into(),
        series: vec![
            Series {
                label: if su.u.si { "W(1,t)" } else { "W(1,τ)" }.into(),
                points: tip,
                style: Style::Line,
                color: 0,
            },
            Series {
                label: "V_T".into(),
                points: vt,
                style: Style::Line,
                color: 1,
            },
        ],
        shade,
    };
    if recorded > TIP_WINDOW_PERIODS as f64 + 1e-9 {
        // the last periods, readable; every recorded period in tip-all
        let mut shade: Vec<(f64, f64)> = Vec::new();
        let mut open: Option<f64> = None;
        for &(t, _, _, contact) in &pd.recent {
            match (contact, open) {
                (true, None) => open = Some(t),
                (false, Some(t0)) => {
                    shade.push((t0, t));
                    open = None;
                }
                _ => {}
            }
        }
        if let (Some(t0), Some(&(t1, ..))) = (open, pd.recent.back()) {
            shade.push((t0, t1));
        }
        save(
            out.path(),
            "tip",
            &tip_figure(
                format!(
                    "Tip motion, last {TIP_WINDOW_PERIODS} of {recorded:.0} periods (contact \
                     shaded; all: tip-all)"
                ),
                pd.recent.iter().map(|&(t, w, ..)| (t, w)).collect(),
                pd.recent.iter().map(|&(t, _, v, _)| (t, v)).collect(),
                shade,
            ),
        )?;
        save(
            out.path(),
            "tip-all",
            &tip_figure(
                format!("Tip motion, all {recorded:.0} recorded periods (contact shaded)"),
                pd.tip,
                pd.vt,
                pd.shade.intervals,
            ),
        )?;
    } else {
        save(
            out.path(),
            "tip",
            &tip_figure(
                "Tip motion (contact intervals shaded)".into(),
                pd.tip,
                pd.vt,
                pd.shade.intervals,
            ),
        )?;
    }
    save(
        out.path(),
        "phase",
        &Figure {
            y_min_span: 0.0,
            title: last(phase.len(), "Phase portrait"),
            x_label: phase_x.into(),
            y_label: phase_y.into(),
            series: vec![Series {
                label: String::new(),
                points: phase,
                style: Style::Line,
                color: 0,
            }],
            shade: vec![],
        },
    )?;
    let f_max = spectrum_axis_end(&spec, p.omega * hz);
    save(
        out.path(),
        "spectrum",
        &Figure {
            y_min_span: 0.0,
            title: last(window, "Amplitude spectrum of W(1,τ)"),
            x_label: spec_x,
            y_label: spec_y.into(),
            series: vec![Series {
                label: String::new(),
                points: log_spectrum(&spec, f_max),
                style: Style::Line,
                color: 0,
            }],
            shade: vec![],
        },
    )?;
    Ok(())
}

/// How far below the spectrum's peak its log-scale plot reaches: 1e-10 of the peak, where the
/// FFT of samples whose relative round-off is ~1e-15 (summed over up to 1e5 samples) is no
/// longer signal, well under the higher harmonics of tapping (1e-2 to 1e-6 of the first).
const SPECTRUM_DECADES: f64 = 10.0;

/// The spectrum plot's points up to `f_max` on a logarithmic amplitude axis: (f, log₁₀ A),
/// amplitudes below 10^−[`SPECTRUM_DECADES`] of the peak (zeros included) at that floor. On a
/// linear axis every harmonic above the first is a flat line at zero.
fn log_spectrum(spec: &[(f64, f64)], f_max: f64) -> Vec<(f64, f64)> {
    let peak = spec.iter().map(|s| s.1).fold(0.0, f64::max);
    if !(peak > 0.0 && peak.is_finite()) {
        return Vec::new();
    }
    let floor = peak.log10() - SPECTRUM_DECADES;
    spec.iter()
        .filter(|s| s.0 <= f_max)
        .map(|&(f, a)| (f, if a > 0.0 { a.log10().max(floor) } else { floor }))
        .collect()
}

/// End of the spectrum plot's frequency axis: where the spectrum has died out (the last
/// amplitude above 1e-3 of the peak, plus 10 %), at least 4Ω.
fn spectrum_axis_end(spec: &[(f64, f64)], omega: f64) -> f64 {
    let peak = spec.iter().map(|s| s.1).fold(0.0, f64::max);
    let top = spec
        .iter()
        .rev()
        .find(|s| s.1 >= 1e-3 * peak)
        .map_or(0.0, |s| s.0);
    (1.1 * top).max(4.0 * omega)
}

/// `afmdyn converge` flags.
#[derive(Debug, Args)]
pub struct ConvergeArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    integrator: IntegratorArgs,
    /// Largest number of modes N_max
    #[arg(long, default_value_t = ConvergeRequest::default().max_modes)]
    max_modes: usize,
    /// Drive periods of steady state compared
    #[arg(long, default_value_t = ConvergeRequest::default().periods)]
    periods: usize,
    /// Samples per drive period
    #[arg(long, default_value_t = ConvergeRequest::default().samples_per_period)]
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
    let (p, probe) = a
        .model
        .resolve(afmdyn::request::analyses::converge_defaults())?;
    let request = ConvergeRequest {
        max_modes: a.max_modes,
        periods: a.periods,
        samples_per_period: a.samples_per_period,
        integrator: a.integrator.request(),
    };
    request.validate()?;
    let out = OutDir::lock(&a.out)?;
    let Document { output: runs, json } =
        crate::progress::run(&request, &Resolved { params: p, probe }, "mode counts")?;
    let k = runs.iter().map(|r| r.w_tip.len()).min().unwrap_or(0);
    let mut header = vec!["tau_from_section".to_string()];
    header.extend(runs.iter().map(|r| format!("w_tip_n{}", r.modes)));
    let hdr: Vec<&str> = header.iter().map(String::as_str).collect();
    let t0 = runs[0].tau[0];
    write_csv(
        &out.join("converge.csv"),
        &hdr,
        (0..k).map(|i| {
            let mut row = vec![f(runs[0].tau[i] - t0)];
            row.extend(runs.iter().map(|r| f(r.w_tip[i])));
            row
        }),
    )?;
    save(
        out.path(),
        "converge",
        &Figure {
            y_min_span: 0.0,
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
        let mut doc = json;
        doc["out"] = json!(a.out);
        outln!("{doc}");
    } else {
        if p.alpha3 > 0.0 || p.alpha6 > 0.0 {
            outln!("note: paper eq. 24 is undamped; using α3 = {}, α6 = {} (eq. 26) so a steady state exists", p.alpha3, p.alpha6);
        }
        outln!("{:>3} {:>8} {:>22}", "N", "period", "RMS ΔW_tip vs N−1");
        for r in &runs {
            outln!(
                "{:>3} {:>8} {:>22}",
                r.modes,
                r.period.map_or("nonper.".to_string(), |n| n.to_string()),
                r.rms_change.map_or("-".to_string(), |v| format!("{v:.4e}"))
            );
        }
        outln!("outputs in {}", a.out.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 42 §4: on the spectrum's linear axis a harmonic at 1e-4 of the first was a flat
    /// line; on the log axis it stands 6 of the 10 decades above the floor, and the exact
    /// decades are the amplitudes' log₁₀.
    #[test]
    fn the_spectrum_is_plotted_on_a_log_axis() {
        let spec = [(1.0, 2.0), (2.0, 2e-4), (3.0, 2e-7), (4.0, 0.0), (5.0, 1.0)];
        let pts = log_spectrum(&spec, 4.0);
        assert_eq!(pts.len(), 4);
        let want = [
            2f64.log10(),
            2e-4f64.log10(),
            2e-7f64.log10(),
            2f64.log10() - 10.0,
        ];
        for ((f, y), (g, w)) in pts.iter().zip(spec.iter().map(|s| s.0).zip(want)) {
            assert_eq!(*f, g);
            assert!((y - w).abs() < 1e-12, "{y} {w}");
        }
        let (lo, hi) = (want[3], want[0]);
        assert!((pts[1].1 - lo) / (hi - lo) > 0.5);
        assert!(log_spectrum(&[(1.0, 0.0)], 2.0).is_empty());
    }

    #[test]
    fn spectrum_axis_ends_where_the_content_does() {
        // content below 30, a round-off floor up to 260 (the spectrum.png)
        let spec: Vec<(f64, f64)> = (0..2600)
            .map(|k| {
                let f = k as f64 * 0.1;
                let a = if f < 30.0 {
                    0.05 * (-f / 10.0).exp()
                } else {
                    1e-9
                };
                (f, a)
            })
            .collect();
        let end = spectrum_axis_end(&spec, 2.6);
        assert!((25.0..40.0).contains(&end), "{end}");
        assert_eq!(spectrum_axis_end(&[], 2.6), 4.0 * 2.6);
    }
}
