//! `orbit` and `lyapunov`: their text summaries.

use crate::analysis::lyapunov::LyapunovSpectrum;
use crate::analysis::shooting::PeriodicOrbit;
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::Params;
use crate::report::{Presentation, TextUnits};

/// A periodic orbit: period, drive, stability, Newton residuals, Floquet multipliers, the
/// critical multiplier and grazing, the tip deflection at each section.
///
/// # Errors
/// [`SimError`] when `p` does not build a model.
pub(crate) fn orbit(p: &Params, o: &PeriodicOrbit, u: TextUnits) -> Result<Presentation, SimError> {
    let mut s = Presentation::default();
    s.line(format!(
        "period-{} orbit at {}{}{} ({}), {} switchings per cycle",
        o.period,
        u.drive(p.omega),
        if p.is_multifrequency() {
            format!(
                " (a multifrequency drive: periods of its common period, {} of the first \
                 component's)",
                p.common_periods()
            )
        } else {
            String::new()
        },
        if u.si() {
            format!(", z_c = {}", u.length(p.rest_distance()))
        } else {
            String::new()
        },
        if o.stable { "stable" } else { "unstable" },
        o.switchings
    ));
    s.line(format!(
        "Newton residuals: {}",
        o.residuals
            .iter()
            .map(|r| format!("{r:.2e}"))
            .collect::<Vec<_>>()
            .join(" → ")
    ));
    s.line("Floquet multipliers (|μ|):");
    for m in &o.multipliers {
        s.line(format!("  {:+.8} {:+.8}i   {:.8}", m.re, m.im, m.norm()));
    }
    s.line(format!(
        "critical multiplier type: {:?}; distance to grazing {}{}",
        o.critical,
        if u.si() {
            u.length(o.grazing_distance)
        } else {
            format!("{:.3e}", o.grazing_distance)
        },
        if o.grazing { " (grazing)" } else { "" }
    ));
    let model = CantileverModel::new(p)?;
    for (k, z) in o.section.iter().enumerate() {
        if u.si() {
            s.line(format!(
                "  section {k}: tip deflection = {}",
                u.length(model.w_tip(z))
            ));
        } else {
            s.line(format!("  section {k}: W(1,τ) = {:.9}", model.w_tip(z)));
        }
    }
    Ok(s)
}

/// A Lyapunov spectrum: each exponent with its statistical and convergence uncertainty, the
/// sum, the phase-volume contraction and the 0–1 test.
pub(crate) fn lyapunov(p: &Params, l: &LyapunovSpectrum, u: TextUnits) -> Presentation {
    let mut s = Presentation::default();
    s.line(format!(
        "Lyapunov exponents ({}) over {} periods at {}:",
        if u.si() { "1/s" } else { "per unit τ" },
        l.periods,
        u.drive(p.omega)
    ));
    for ((e, sd), c) in l.exponents.iter().zip(&l.uncertainty).zip(&l.convergence) {
        s.line(format!(
            "  {} ± {} (statistical) ± {} (convergence, |λ(T) − λ(T/2)|)",
            u.rate(*e),
            u.rate(*sd).trim_start_matches('+'),
            u.rate(*c).trim_start_matches('+')
        ));
    }
    s.line(format!(
        "sum {}; mean phase-volume contraction {}",
        u.rate(l.exponents.iter().sum::<f64>()),
        u.rate(l.volume_rate)
    ));
    s.line(format!(
        "0–1 test K = {:.3}; verdict: {:?}",
        l.zero_one, l.verdict
    ));
    s
}
