//! The layout of a recorded trajectory (`afmdyn simulate`'s series in one result): time
//! series, switchings, the stroboscopic section, the energy balance per period and the
//! amplitude spectrum of W(1,τ), in the units of a [`SeriesUnits`] (the model's, or SI with a
//! probe), declared once for the Python `xarray.Dataset`.

use super::SeriesUnits;
use crate::analysis::spectrum::{amplitude_spectrum, SPECTRUM_SAMPLES};
use crate::layout::{Attr, Layout, Values, Variable};
use crate::model::CantileverModel;
use crate::system::Region;
use crate::trajectory::{EnergyBalance, Sample, Trajectory};
use nalgebra::DVector;

/// `tr` (recorded from `model` at `samples_per_period`) as a layout in `su`'s units.
///
/// Dimensions: the time (named `t` in SI, else `tau`; S samples), `mode` (N), `event` (E
/// switchings), `section` (P section points τ = 2πk/Ω), `component` (2N), `cycle` (C complete
/// drive periods) and `frequency` (F). Variables: the time coordinate; `v_t`, `v_t_dot`,
/// `w_tip`, `w_tip_dot`, `in_contact`, `contact_force` `[S]`; `a`, `a_dot` `[S, N]`;
/// `event_tau`, `event_to_contact`, `event_v_t_dot` `[E]`; `section_tau`, `section_v_t`,
/// `section_w_tip`, `section_w_tip_dot` `[P]`, `section_state` `[P, 2N]` (a in lengths, ȧ in
/// velocities); the energy balance per period `[C]` (`energy_tau0`, `energy_start`,
/// `energy_end`, `base_work`, `beam_dissipation`, `contact_dissipation`, `energy_residual`);
/// `spectrum` `[F]` over the coordinate `frequency` (the amplitude spectrum of W(1,τ) over the
/// last `SPECTRUM_SAMPLES` samples, the command line's `spectrum.csv`); the coordinates
/// `mode` (1…N) and `component` (`a_1` … `a_dot_N`).
pub fn simulate_layout(
    model: &CantileverModel,
    tr: &Trajectory,
    su: &SeriesUnits,
    samples_per_period: usize,
) -> Layout {
    let n = model.modes();
    let names = su.names();
    let (freq, amp) = spectrum(model, tr, su, samples_per_period);
    let mut variables = sample_variables(model, tr, su);
    variables.extend(event_variables(tr, su));
    variables.extend(section_variables(model, tr, su));
    variables.extend(energy_variables(tr, su));
    let component: Vec<String> = (1..=n)
        .map(|j| format!("a_{j}"))
        .chain((1..=n).map(|j| format!("a_dot_{j}")))
        .collect();
    let frequency_unit = if su.u.si { "Hz" } else { "Ω units (1/t0)" };
    let spectrum_name = "amplitude spectrum of W(1,τ) (spectrum.csv)";
    variables.extend([
        Variable::f64(
            "spectrum",
            &["frequency"],
            names.length,
            spectrum_name,
            &amp,
        ),
        Variable::f64(
            "frequency",
            &["frequency"],
            frequency_unit,
            "frequency",
            &freq,
        ),
        Variable::new(
            "mode",
            &["mode"],
            "1",
            "Galerkin mode i",
            Values::I32((1..=n as i32).collect()),
        ),
        Variable::new(
            "component",
            &["component"],
            "",
            "state component (a_i, then da_i/dτ)",
            Values::Text(component),
        ),
    ]);
    Layout::new(
        "afmdyn simulate: one trajectory",
        &[
            (names.time, tr.samples.len()),
            ("mode", n),
            ("event", tr.events.len()),
            ("section", tr.poincare.len()),
            ("component", 2 * n),
            ("cycle", tr.energy.len()),
            ("frequency", freq.len()),
        ],
        variables,
    )
}

/// The amplitude spectrum of W(1,τ) over the last [`SPECTRUM_SAMPLES`] samples (spectrum.csv):
/// (frequencies, amplitudes) in `su`'s units.
fn spectrum(
    model: &CantileverModel,
    tr: &Trajectory,
    su: &SeriesUnits,
    samples_per_period: usize,
) -> (Vec<f64>, Vec<f64>) {
    let w: Vec<f64> = tr.samples.iter().map(|s| s.w_tip).collect();
    let tail = &w[w.len().saturating_sub(SPECTRUM_SAMPLES)..];
    let hz = su.u.hz_per_omega.unwrap_or(1.0);
    amplitude_spectrum(tail, samples_per_period, model.omega())
        .into_iter()
        .map(|(w, a)| (w * hz, su.x(a)))
        .unzip()
}

/// The time series over the time dimension: the time, V_T, its rate, W(1,τ), ∂W/∂τ, the contact
/// flag and force, then the modal state `a`, `a_dot` `[time, mode]`.
fn sample_variables(model: &CantileverModel, tr: &Trajectory, su: &SeriesUnits) -> Vec<Variable> {
    let n = model.modes();
    let names = su.names();
    let columns = su.columns(n);
    let long = |name: &str| {
        columns
            .iter()
            .find(|c| c.name == name)
            .map_or(String::new(), |c| c.long_name.clone())
    };
    let (time, length, velocity) = (names.time, names.length, names.velocity);
    let samples = &tr.samples;
    let series = |f: &dyn Fn(&Sample) -> f64| -> Vec<f64> { samples.iter().map(f).collect() };
    let t_dim: &[&str] = &[time];
    let mut a = Vec::with_capacity(samples.len() * n);
    let mut a_dot = Vec::with_capacity(samples.len() * n);
    for s in samples {
        a.extend(s.state.rows(0, n).iter().map(|&v| su.x(v)));
        a_dot.extend(s.state.rows(n, n).iter().map(|&v| su.v(v)));
    }
    let in_contact = samples.iter().map(|s| s.region == Region::Contact);
    let v_t_dot = series(&|s| su.v(model.v_t_dot(s.tau, &s.state)));
    vec![
        Variable::f64(
            time,
            t_dim,
            names.time_unit,
            long(time),
            &series(&|s| su.t(s.tau)),
        ),
        Variable::f64("v_t", t_dim, length, long("v_t"), &series(&|s| su.x(s.v_t))),
        Variable::f64("v_t_dot", t_dim, velocity, "dV_T/dτ", &v_t_dot),
        Variable::f64(
            "w_tip",
            t_dim,
            length,
            long("w_tip"),
            &series(&|s| su.x(s.w_tip)),
        ),
        Variable::f64(
            "w_tip_dot",
            t_dim,
            velocity,
            long("w_tip_dot"),
            &series(&|s| su.v(s.w_tip_dot)),
        ),
        Variable::new(
            "in_contact",
            t_dim,
            "",
            long("in_contact"),
            Values::Bool(in_contact.collect()),
        ),
        Variable::f64(
            "contact_force",
            t_dim,
            names.force,
            long("contact_force"),
            &series(&|s| su.force(s.contact_force)),
        )
        .with(
            "sign_convention",
            Attr::Text(crate::contact::FORCE_SIGN.into()),
        ),
        Variable::f64("a", &[time, "mode"], length, "modal displacement a_i", &a),
        Variable::f64(
            "a_dot",
            &[time, "mode"],
            velocity,
            "modal velocity da_i/dτ",
            &a_dot,
        ),
    ]
}

/// The switchings `[event]`: their times, directions and impact velocities.
fn event_variables(tr: &Trajectory, su: &SeriesUnits) -> Vec<Variable> {
    let names = su.names();
    let (ev, events): (&[&str], _) = (&["event"], &tr.events);
    let to_contact = events.iter().map(|e| e.to == Region::Contact).collect();
    vec![
        Variable::f64(
            "event_tau",
            ev,
            names.time_unit,
            "switching time",
            &events.iter().map(|e| su.t(e.tau)).collect::<Vec<_>>(),
        ),
        Variable::new(
            "event_to_contact",
            ev,
            "",
            "switching into contact (else out of it)",
            Values::Bool(to_contact),
        ),
        Variable::f64(
            "event_v_t_dot",
            ev,
            names.velocity,
            "dV_T/dτ at the switching (impact velocity)",
            &events.iter().map(|e| su.v(e.v_t_dot)).collect::<Vec<_>>(),
        ),
    ]
}

/// The stroboscopic section `[section]` (τ = 2πk/Ω): its times, V_T, W(1,τ) and ∂W/∂τ, and the
/// modal state `[section, component]` (a in lengths, ȧ in velocities; a law's internal states
/// are not listed).
fn section_variables(model: &CantileverModel, tr: &Trajectory, su: &SeriesUnits) -> Vec<Variable> {
    let n = model.modes();
    let names = su.names();
    let sec: &[&str] = &["section"];
    let section = |f: &dyn Fn(f64, &DVector<f64>) -> f64| -> Vec<f64> {
        tr.poincare.iter().map(|(t, z)| f(*t, z)).collect()
    };
    let state: Vec<f64> = tr
        .poincare
        .iter()
        .flat_map(|(_, z)| {
            z.iter()
                .take(2 * n)
                .enumerate()
                .map(|(i, &v)| if i < n { su.x(v) } else { su.v(v) })
        })
        .collect();
    vec![
        Variable::f64(
            "section_tau",
            sec,
            names.time_unit,
            "section time 2πk/Ω",
            &section(&|t, _| su.t(t)),
        ),
        Variable::f64(
            "section_v_t",
            sec,
            names.length,
            "V_T at the section",
            &section(&|t, z| su.x(model.v_t(t, z))),
        ),
        Variable::f64(
            "section_w_tip",
            sec,
            names.length,
            "W(1,τ) at the section",
            &section(&|_, z| su.x(model.w_tip(z))),
        ),
        Variable::f64(
            "section_w_tip_dot",
            sec,
            names.velocity,
            "∂W(1,τ)/∂τ at the section",
            &section(&|_, z| su.v(model.w_tip_dot(z))),
        ),
        Variable::f64(
            "section_state",
            &["section", "component"],
            "",
            "state (a, da/dτ) at the section",
            &state,
        ),
    ]
}

/// A term of the energy balance: its name, long name and value.
type EnergyTerm = (&'static str, &'static str, fn(&EnergyBalance) -> f64);

/// The energy balance per period `[cycle]`: the period's start, then each term.
fn energy_variables(tr: &Trajectory, su: &SeriesUnits) -> Vec<Variable> {
    let names = su.names();
    let terms: [EnergyTerm; 6] = [
        ("energy_start", "stored energy at the start", |e| e.e_start),
        ("energy_end", "stored energy at the end", |e| e.e_end),
        ("base_work", "work of the base drive", |e| e.base_work),
        ("beam_dissipation", "beam damping loss", |e| {
            e.beam_dissipation
        }),
        (
            "contact_dissipation",
            "dissipation in the sample (contact damping, impacts)",
            |e| e.contact_dissipation,
        ),
        ("energy_residual", "ΔE − (work − losses)", |e| {
            e.residual()
        }),
    ];
    let tau0: Vec<f64> = tr.energy.iter().map(|e| su.t(e.tau0)).collect();
    let start = "start of the period";
    let mut v = vec![Variable::f64(
        "energy_tau0",
        &["cycle"],
        names.time_unit,
        start,
        &tau0,
    )];
    v.extend(terms.iter().map(|&(name, long, f)| {
        let values: Vec<f64> = tr.energy.iter().map(|e| su.energy(f(e))).collect();
        Variable::f64(name, &["cycle"], names.energy, long, &values)
    }));
    v
}
