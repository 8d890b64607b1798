//! `converge`: its table, figure and summary; `simulate`: its spectrum, figures and summary
//! (the run streamed to files in bounded memory, [`crate::request::simulate_stream`]).

use crate::analysis::converge::ConvergenceRun;
use crate::analysis::spectrum::amplitude_spectrum;
use crate::error::SimError;
use crate::layout::figure::{Figure, Plot, Series, Style};
use crate::layout::files::f;
use crate::model::CantileverModel;
use crate::params::Params;
use crate::report::{Presentation, SeriesUnits};
use crate::request::run::Resolved;
use crate::request::simulate_stream::{
    PlotData, SimulateRecording, SimulateStream, TIP_WINDOW_PERIODS,
};

/// `converge`: `converge.csv` (W(1,τ) of every N over the common samples, τ from the first
/// run's section point), the figure of paper Fig. 4 and the table of periods and RMS changes.
pub fn converge(p: &Params, runs: &[ConvergenceRun]) -> Presentation {
    let mut s = Presentation::default();
    let k = runs.iter().map(|r| r.w_tip.len()).min().unwrap_or(0);
    let mut header = vec!["tau_from_section".to_string()];
    header.extend(runs.iter().map(|r| format!("w_tip_n{}", r.modes)));
    let hdr: Vec<&str> = header.iter().map(String::as_str).collect();
    let t0 = runs.first().map_or(0.0, |r| r.tau[0]);
    let rows = (0..k)
        .map(|i| {
            let mut row = vec![f(runs[0].tau[i] - t0)];
            row.extend(runs.iter().map(|r| f(r.w_tip[i])));
            row
        })
        .collect();
    s.csv("converge.csv", &hdr, rows);
    s.figure(
        "converge",
        Plot::Lines(Figure {
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
        }),
    );
    if p.alpha3 > 0.0 || p.alpha6 > 0.0 {
        s.line(format!(
            "note: paper eq. 24 is undamped; using α3 = {}, α6 = {} (eq. 26) so a steady state \
             exists",
            p.alpha3, p.alpha6
        ));
    }
    s.line(format!(
        "{:>3} {:>8} {:>22}",
        "N", "period", "RMS ΔW_tip vs N−1"
    ));
    for r in runs {
        s.line(format!(
            "{:>3} {:>8} {:>22}",
            r.modes,
            r.period.map_or("nonper.".to_string(), |n| n.to_string()),
            r.rms_change.map_or("-".to_string(), |v| format!("{v:.4e}"))
        ));
    }
    s
}

/// `simulate` streamed to files: the summary (the integrator, the recorded span, switchings,
/// sections, the final tip state, SI values with a probe, the energy balance), and with files
/// `spectrum.csv` and the figures, in the series' units (SI with a probe: time in s, lengths
/// in m, frequencies in Hz; the plots' axes take the prefix of their range).
///
/// # Errors
/// [`SimError`] when the model cannot be built.
pub fn simulate(
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
    let (residual, relative) = r.summary.energy_residual;
    s.line(format!(
        "energy balance: largest per-period residual {residual:.3e} ({relative:.1e} relative)"
    ));
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
    let (t_label, y_label, phase_x, phase_y, spec_x, spec_y) = if su.u.si {
        (
            "time t (s)",
            "W(1,t), V_T (m)",
            "V_T (m)",
            "dV_T/dt (m/s)",
            "frequency (Hz)",
            "log₁₀(amplitude / m)",
        )
    } else {
        (
            "τ",
            "W(1,τ), V_T",
            "V_T",
            "dV_T/dτ",
            "frequency (dimensionless, Ω = drive)",
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
        let mut shade: Vec<(f64, f64)> = Vec::new();
        let mut open: Option<f64> = None;
        for &(t, _, _, contact) in &recent {
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
        s.figure(
            "tip",
            tip_figure(
                format!(
                    "Tip motion, last {TIP_WINDOW_PERIODS} of {recorded:.0} periods (contact \
                     shaded; all: tip-all)"
                ),
                recent.iter().map(|&(t, w, ..)| (t, w)).collect(),
                recent.iter().map(|&(t, _, v, _)| (t, v)).collect(),
                shade,
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
