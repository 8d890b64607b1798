//! The running of `simulate` streamed to files (`request::simulate_stream`): the run is
//! recorded in chunks of whole periods (`crate::trajectory::chunked::record_chunked`) and
//! every chunk is written to the data files (`crate::report::simulate_files::SeriesFiles`) as
//! it comes, while what the plots and the spectrum need is gathered in bounded memory
//! ([`PlotData`]); memory does not grow with the length of the run. Its [`Analysis`]:
//! `execute` is the run itself (it writes the data files into `dir`), `present` the spectrum,
//! the figures and the summary (its presentation, `simulate`, is here too).

use crate::analysis::progress::Progress;
use crate::analysis::spectrum::amplitude_spectrum;
use crate::analysis::spectrum::SPECTRUM_SAMPLES;
use crate::error::SimError;
use crate::layout::figure::PixelColumns;
use crate::layout::figure::{Figure, Plot, Series, Style};
use crate::layout::files::f;
use crate::model::CantileverModel;
use crate::params::Params;
use crate::report::simulate_files::{SeriesFiles, SERIES_FILES};
use crate::report::{self, SeriesUnits, SimulateSummary};
use crate::report::{Convergence, Presentation};
use crate::request::analyses::initial_state;
use crate::request::run::{Analysis, Resolved};
use crate::request::simulate_stream::{
    SimulateStream, PHASE_SAMPLES, TIP_COLUMNS, TIP_WINDOW_PERIODS,
};
use crate::system::Region;
use crate::trajectory::chunked::{record_chunked, Chunk, ChunkedSpec};
use serde_json::{json, Value};
use std::collections::VecDeque;

/// What a streamed run leaves besides its files: the run's summary, the spectrum's window and
/// the plots' data.
#[derive(Debug, Clone)]
pub struct SimulateRecording {
    /// The integrator's name.
    pub integrator: &'static str,
    /// τ at which recording started.
    pub transient_tau: f64,
    /// The run: its end, final state, switchings, sections and energy balance.
    pub summary: SimulateSummary,
    /// The last `SPECTRUM_SAMPLES` values of W(1,τ) (with files).
    pub spectrum: Vec<f64>,
    /// The plots' data (with figures).
    pub plots: Option<PlotData>,
}

impl Analysis for SimulateStream {
    type Output = SimulateRecording;
    fn convergence(&self, _: &SimulateRecording) -> Convergence {
        // a trajectory from its start, nothing iterated (its energy audit, when asked, warns on
        // its own)
        Convergence::exact("trajectory")
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<Self::Output, SimError> {
        let p = &model.params;
        let span = self.span(p)?;
        let m = CantileverModel::new(p)?;
        let z0 = initial_state(&m, self.request.initial.as_deref())?;
        let mut integ = self.request.integrator(&m, model.probe.as_ref(), &z0)?;
        let su = SeriesUnits::new(p, model.probe.as_ref());
        let mut files = match &self.dir {
            Some(dir) => {
                // what a run killed outright left of these files
                crate::io::dir_lock::remove_partials_in(dir, &SERIES_FILES)?;
                Some(SeriesFiles::create(
                    dir,
                    p.modes,
                    su,
                    self.csv,
                    self.request.energy_balance,
                )?)
            }
            None => None,
        };
        let spp = self.request.samples_per_period;
        let (start, end) = (span.transient_tau, span.transient_tau + span.record_tau);
        let mut plots = (self.figures && files.is_some()).then(|| PlotData::new(start, end, spp));
        let mut spectrum: VecDeque<f64> = VecDeque::new();
        let spec = ChunkedSpec {
            transient_periods: self.request.transient,
            record_tau: span.record_tau,
            samples_per_period: if files.is_some() { spp } else { 0 },
            energy: self.request.energy_balance,
            chunk_periods: self.chunk_periods,
        };
        progress.add_total(span.total_periods.ceil() as usize);
        let each = |c: &Chunk<'_>| -> Result<(), SimError> {
            // a cancel ends here; the streams' partial files are removed as they are dropped
            progress.check()?;
            if let Some(fl) = files.as_mut() {
                fl.push(&m, c)?;
                // the spectrum's window: the last SPECTRUM_SAMPLES values of W(1,τ)
                keep_last(&mut spectrum, SPECTRUM_SAMPLES, c, |s| s[2]);
            }
            if let Some(pd) = plots.as_mut() {
                pd.push(c);
            }
            Ok(())
        };
        let mut counted = 0;
        let summary = record_chunked(integ.as_mut(), &spec, each, |done| {
            let done = done as usize;
            progress.advance(done.saturating_sub(counted));
            counted = counted.max(done);
        })?;
        if let Some(fl) = files {
            fl.finish()?;
        }
        if let Some(pd) = plots.as_mut() {
            pd.finish(summary.tau_end);
        }
        Ok(SimulateRecording {
            integrator: integ.name(),
            transient_tau: span.transient_tau,
            summary: SimulateSummary {
                tau_end: summary.tau_end,
                final_state: summary.final_state.clone().unwrap_or(z0),
                switchings: summary.switchings,
                body_contact: summary.body_contact,
                poincare_points: summary.sections,
                energy_residual: spec.energy.then_some((summary.residual, summary.relative)),
            },
            spectrum: spectrum.into(),
            plots,
        })
    }
    fn report(&self, model: &Resolved, r: &Self::Output) -> Result<Value, SimError> {
        let mut doc = report::simulate_summary(&CantileverModel::new(&model.params)?, &r.summary);
        doc["files"] = json!(self.files());
        self.request
            .thermal_into(&mut doc, &model.params.contact_law);
        Ok(doc)
    }
    fn present(
        &self,
        r: &Self::Output,
        at: crate::request::Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        simulate(self, at.model, r)
    }
}

/// Keep in `window` the last `cap` values `of` the samples of chunk `c`.
fn keep_last<T>(window: &mut VecDeque<T>, cap: usize, c: &Chunk<'_>, of: impl Fn(&[f64]) -> T) {
    let new = c.samples().len();
    let keep = new.min(cap);
    let drop = (window.len() + keep).saturating_sub(cap);
    window.drain(..drop);
    window.extend(c.samples().skip(new - keep).map(of));
}

/// Contact intervals for shading, merged when closer than `min_gap` (bounded memory).
#[derive(Debug, Clone)]
pub struct Shade {
    /// The intervals (τ).
    pub intervals: Vec<(f64, f64)>,
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
#[derive(Debug, Clone)]
pub struct PlotData {
    /// The tip line (τ, W(1,τ)), decimated to the pixel columns once long.
    pub tip: Vec<(f64, f64)>,
    /// The line (τ, V_T), likewise.
    pub vt: Vec<(f64, f64)>,
    /// The open pixel columns of `tip` and `vt` once they are decimated as they come
    /// (`streaming`: from the first chunk after which they hold more than 8 points a column).
    tip_cols: PixelColumns,
    vt_cols: PixelColumns,
    streaming: bool,
    /// The recorded span (τ).
    pub t0: f64,
    /// See `t0`.
    pub t1: f64,
    /// The contact intervals.
    pub shade: Shade,
    /// The last `PHASE_SAMPLES`: τ, V_T, ∂W(1,τ)/∂τ (dV_T/dτ formed at the end).
    pub phase: VecDeque<(f64, f64, f64)>,
    /// The last `TIP_WINDOW_PERIODS` periods: τ, W(1,τ), V_T, in contact.
    pub recent: VecDeque<(f64, f64, f64, bool)>,
    /// Its capacity (samples).
    recent_cap: usize,
}

impl PlotData {
    fn new(t0: f64, t1: f64, spp: usize) -> Self {
        PlotData {
            tip: vec![],
            vt: vec![],
            tip_cols: PixelColumns::default(),
            vt_cols: PixelColumns::default(),
            streaming: false,
            t0,
            t1,
            shade: Shade {
                intervals: vec![],
                open: None,
                min_gap: (t1 - t0) / 4000.0,
            },
            phase: VecDeque::new(),
            recent: VecDeque::new(),
            recent_cap: TIP_WINDOW_PERIODS * spp + 1,
        }
    }

    /// The pixel column of τ on the tip plots' grid.
    fn column(&self, x: f64) -> i32 {
        (((x - self.t0) / (self.t1 - self.t0).max(1e-300)) * TIP_COLUMNS) as i32
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

    /// Gather a chunk: its samples on the lines, the last ones of the phase portrait and the
    /// tip window, its contact intervals.
    fn push(&mut self, c: &Chunk<'_>) {
        for s in c.samples() {
            self.add(s[0], s[2], s[1]);
        }
        // the phase portrait's and the tip window's last samples (only those kept)
        keep_last(&mut self.phase, PHASE_SAMPLES, c, |s| (s[0], s[1], s[3]));
        let cap = self.recent_cap;
        keep_last(&mut self.recent, cap, c, |s| {
            (s[0], s[2], s[1], s[4] != 0.0)
        });
        if let Some(s) = c.samples().next().filter(|s| c.first && s[4] != 0.0) {
            self.shade.open = Some(s[0]);
        }
        for e in c.events() {
            match e.to {
                Region::Contact => self.shade.open = Some(e.tau),
                Region::Free => {
                    if let Some(t0) = self.shade.open.take() {
                        self.shade.push(t0, e.tau);
                    }
                }
            }
        }
        self.redecimate();
    }

    /// After a chunk: once the lines hold more than 8 points a pixel column, decimate them
    /// from then on as the samples come ([`PlotData::add`]).
    fn redecimate(&mut self) {
        if self.streaming || self.tip.len() <= 8 * TIP_COLUMNS as usize {
            return;
        }
        self.streaming = true;
        let (tip, vt) = (std::mem::take(&mut self.tip), std::mem::take(&mut self.vt));
        for (&(t, w), &(_, v)) in tip.iter().zip(&vt) {
            self.add(t, w, v);
        }
    }

    /// Close the open pixel columns, and a contact interval open at the end `tau_end`.
    fn finish(&mut self, tau_end: f64) {
        self.tip_cols.flush(&mut self.tip);
        self.vt_cols.flush(&mut self.vt);
        if let Some(t0) = self.shade.open.take() {
            self.shade.push(t0, tau_end);
        }
    }
}

/// `simulate` streamed to files: the summary (the integrator, the recorded span, switchings,
/// sections, the final tip state, SI values with a probe, the energy balance), and with files
/// `spectrum.csv` and the figures, in the series' units (SI with a probe: time in s, lengths
/// in m, frequencies in Hz; the plots' axes take the prefix of their range).
///
/// # Errors
/// [`SimError`] when the model cannot be built.
pub(crate) fn simulate(
    run: &SimulateStream,
    model: &Resolved,
    r: &SimulateRecording,
) -> Result<Presentation, SimError> {
    let p = &model.params;
    let m = CantileverModel::new(p)?;
    let su = SeriesUnits::new(p, model.probe.as_ref());
    let mut s = Presentation::default();
    let (zf, tau_end) = (&r.summary.final_state, r.summary.tau_end);
    s.line(format!(
        "integrator {}, τ from {:.6} to {:.6}",
        r.integrator, r.transient_tau, tau_end
    ));
    s.line(format!(
        "switchings: {}, Poincaré points: {}",
        r.summary.switchings, r.summary.poincare_points
    ));
    s.line(format!(
        "final W(1,τ) = {:.9}, V_T = {:.9}",
        m.w_tip(zf),
        m.v_t(tau_end, zf)
    ));
    if su.u.si {
        let nm = |v: f64| su.x(v) * 1e9;
        s.line(format!(
            "  in SI: t from {:.6} µs to {:.6} µs, final W = {:.6} nm, V_T = {:.6} nm",
            su.t(r.transient_tau) * 1e6,
            su.t(tau_end) * 1e6,
            nm(m.w_tip(zf)),
            nm(m.v_t(tau_end, zf))
        ));
    }
    s.line(match r.summary.energy_residual {
        Some((residual, relative)) => format!(
            "energy balance: largest per-period residual {residual:.3e} ({relative:.1e} relative)"
        ),
        None => "energy balance: not audited (--energy-balance)".into(),
    });
    if run.dir.is_none() {
        s.line("no files written (--files none)");
        return Ok(s);
    }
    let spp = run.request.samples_per_period;
    let hz = su.u.hz_per_omega.unwrap_or(1.0);
    let spec: Vec<(f64, f64)> = amplitude_spectrum(&r.spectrum, spp, p.omega)
        .into_iter()
        .map(|(w, a)| (w * hz, su.x(a)))
        .collect();
    s.csv(
        "spectrum.csv",
        &[
            if su.u.si { "frequency_hz" } else { "frequency" },
            "amplitude",
        ],
        spec.iter().map(|&(x, y)| vec![f(x), f(y)]).collect(),
    );
    if let Some(pd) = &r.plots {
        figures(&mut s, p, &su, spp, pd, r.spectrum.len(), &spec);
    }
    Ok(s)
}

/// The figures of a streamed run: the tip motion (its last periods and all of it when long),
/// the phase portrait and the spectrum on a log axis.
fn figures(
    s: &mut Presentation,
    p: &Params,
    su: &SeriesUnits,
    spp: usize,
    pd: &PlotData,
    window: usize,
    spec: &[(f64, f64)],
) {
    let period = p.period();
    let hz = su.u.hz_per_omega.unwrap_or(1.0);
    // the plots' data in the files' units
    let xy = |v: &[(f64, f64)]| -> Vec<(f64, f64)> {
        v.iter().map(|pt| (su.t(pt.0), su.x(pt.1))).collect()
    };
    // dV_T/dτ = ∂W(1,τ)/∂τ + α2 Ω cos Ωτ (eq. 8)
    let (a2, om) = (p.alpha2, p.omega);
    let phase: Vec<(f64, f64)> = pd
        .phase
        .iter()
        .map(|&(tau, v_t, w_dot)| (su.x(v_t), su.v(w_dot + a2 * om * (om * tau).cos())))
        .collect();
    let recent: Vec<(f64, f64, f64, bool)> = (pd.recent.iter())
        .map(|r| (su.t(r.0), su.x(r.1), su.x(r.2), r.3))
        .collect();
    let shade_all: Vec<(f64, f64)> = (pd.shade.intervals.iter())
        .map(|iv| (su.t(iv.0), su.t(iv.1)))
        .collect();
    let [t_label, y_label, phase_x, phase_y, spec_x, spec_y] = axis_labels(su.u.si);
    let recorded = (pd.t1 - pd.t0) / period;
    let last = |n: usize, what: &str| {
        let periods = n as f64 / spp as f64;
        if periods + 1e-9 < recorded {
            format!("{what} (last {periods:.0} periods)")
        } else {
            format!("{what} (recorded part)")
        }
    };
    let line = |label: &str, points, color| Series {
        label: label.into(),
        points,
        style: Style::Line,
        color,
    };
    let tip_figure = |title: String, tip, vt, shade| {
        Plot::Lines(Figure {
            y_min_span: 0.0,
            title,
            x_label: t_label.into(),
            y_label: y_label.into(),
            series: vec![
                line(if su.u.si { "W(1,t)" } else { "W(1,τ)" }, tip, 0),
                line("V_T", vt, 1),
            ],
            shade,
        })
    };
    if recorded > TIP_WINDOW_PERIODS as f64 + 1e-9 {
        // the last periods, readable; every recorded period in tip-all
        s.figure(
            "tip",
            tip_figure(
                format!(
                    "Tip motion, last {TIP_WINDOW_PERIODS} of {recorded:.0} periods (contact \
                     shaded; all: tip-all)"
                ),
                recent.iter().map(|&(t, w, ..)| (t, w)).collect(),
                recent.iter().map(|&(t, _, v, _)| (t, v)).collect(),
                contact_shade(&recent),
            ),
        );
        s.figure(
            "tip-all",
            tip_figure(
                format!("Tip motion, all {recorded:.0} recorded periods (contact shaded)"),
                xy(&pd.tip),
                xy(&pd.vt),
                shade_all,
            ),
        );
    } else {
        s.figure(
            "tip",
            tip_figure(
                "Tip motion (contact intervals shaded)".into(),
                xy(&pd.tip),
                xy(&pd.vt),
                shade_all,
            ),
        );
    }
    let one = |title: String, x: &str, y: &str, points| {
        Plot::Lines(Figure {
            y_min_span: 0.0,
            title,
            x_label: x.into(),
            y_label: y.into(),
            series: vec![line("", points, 0)],
            shade: vec![],
        })
    };
    let phase_title = last(phase.len(), "Phase portrait");
    s.figure("phase", one(phase_title, phase_x, phase_y, phase));
    let f_max = spectrum_axis_end(spec, p.omega * hz);
    let title = last(window, "Amplitude spectrum of W(1,τ)");
    let points = log_spectrum(spec, f_max);
    s.figure("spectrum", one(title, spec_x, spec_y, points));
}

/// The axis labels of a run's figures, in SI (`si`) or the model's units: time, tip motion,
/// the phase portrait's V_T and its rate, the spectrum's frequency and log amplitude.
fn axis_labels(si: bool) -> [&'static str; 6] {
    if si {
        [
            "time t (s)",
            "W(1,t), V_T (m)",
            "V_T (m)",
            "dV_T/dt (m/s)",
            "frequency (Hz)",
            "log₁₀(amplitude / m)",
        ]
    } else {
        [
            "τ",
            "W(1,τ), V_T",
            "V_T",
            "dV_T/dτ",
            "frequency (dimensionless, Ω = drive)",
            "log₁₀(amplitude / g0)",
        ]
    }
}

/// The contact intervals of the `recent` samples (t, W, V_T, in contact), the last one closed
/// at the last sample.
fn contact_shade(recent: &[(f64, f64, f64, bool)]) -> Vec<(f64, f64)> {
    let mut shade: Vec<(f64, f64)> = Vec::new();
    let mut open: Option<f64> = None;
    for &(t, _, _, contact) in recent {
        match (contact, open) {
            (true, None) => open = Some(t),
            (false, Some(t0)) => {
                shade.push((t0, t));
                open = None;
            }
            _ => {}
        }
    }
    if let (Some(t0), Some(&(t1, ..))) = (open, recent.last()) {
        shade.push((t0, t1));
    }
    shade
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
