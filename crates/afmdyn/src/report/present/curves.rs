//! The stepped curves (`approach`, `bimodal`, `resonance`): the text summary (folds,
//! bistable ranges, jumps, the setpoint's operating points), the table (`STEM.csv` and
//! `STEM.npy`, columns named as the document or as dForce's), the figures against the swept
//! quantity (`curve_figures.rs`) and the force–distance traces (`STEM-traces.nc` and
//! their figure).

use super::curve_figures::{panels, traces_figure, Labels, Shown};
use super::Files;
use crate::analysis::approach::rest_distance;
use crate::analysis::lock_in_noise::LockInNoise;
use crate::analysis::stepped::{SteppedCurve, Sweep};
use crate::analysis::traces::Traces;
use crate::layout::{Layout, Variable};
use crate::params::Params;
use crate::probe::Probe;
use crate::report::{CurveUnits, OutputsNote, Presentation, TextUnits};
use serde_json::Value;

/// How a stepped curve's presentation is made (`--files`, `--dforce-columns`).
#[derive(Debug, Clone, Copy)]
pub struct CurveOptions {
    /// The files' stem (`approach`, `bimodal`, `resonance`).
    pub stem: &'static str,
    /// Which files: all (data and figures), the data, none.
    pub files: Files,
    /// Name and order the table's columns as dForce 2.0's `zcdom` table.
    pub dforce_columns: bool,
}

/// Which stepped curve is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum CurveKind {
    /// An approach curve over z_c (`approach`, `bimodal`).
    Approach,
    /// A resonance curve over the drive frequency.
    Resonance,
}

/// A stepped curve's presentation at `model` (its parameters, and its probe for SI units): the
/// summary (with the setpoint's operating points of an approach curve's document), and per
/// `options` the table, figures and traces.
pub(crate) fn stepped(
    kind: CurveKind,
    model: (&Params, Option<&Probe>),
    c: &SteppedCurve,
    document: &Value,
    text: TextUnits,
    options: &CurveOptions,
) -> Presentation {
    let base = *model.0;
    let (u, x, l): (CurveUnits, Box<dyn Fn(f64) -> f64>, Labels) = match kind {
        CurveKind::Approach => {
            let u = CurveUnits::of(model.1, false);
            let l = Labels {
                stem: options.stem,
                sweeps: ("approach", "retract"),
                x_name: "z_c",
                x_label: format!("rest distance z_c{}", if u.si { " (m)" } else { " (g0)" }),
                x_text: "z_c",
                x_unit: u.si.then_some("m"),
                text,
            };
            (u, Box::new(move |v| rest_distance(&base, v) * u.length), l)
        }
        CurveKind::Resonance => {
            let u = CurveUnits::of(model.1, true);
            let si = u.hz_per_omega.is_some();
            let l = Labels {
                stem: options.stem,
                sweeps: ("up", "down"),
                x_name: if si { "frequency_hz" } else { "omega" },
                x_label: if si {
                    "drive frequency (Hz)".into()
                } else {
                    "drive frequency Ω".into()
                },
                x_text: if si { "f" } else { "Ω" },
                x_unit: si.then_some("Hz"),
                text,
            };
            let hz = u.hz_per_omega.unwrap_or(1.0);
            (u, Box::new(move |v| v * hz), l)
        }
    };
    let s = &Shown {
        c,
        x: &*x,
        u: &u,
        l: &l,
    };
    present(s, model.0, document, options)
}

/// The presentation of a curve: the summary (then, after the directory is named, the
/// setpoint's lines), the table, the figures, the traces.
fn present(s: &Shown<'_>, params: &Params, document: &Value, o: &CurveOptions) -> Presentation {
    let mut p = Presentation::default();
    summary(&mut p, s);
    p.outputs_note = OutputsNote::After(p.summary.len());
    if let Some(sp) = document.get("setpoint") {
        setpoint(&mut p, sp, s.l, s.u);
    }
    if let Some(t) = document.get("thermal") {
        thermal(&mut p, t, s);
    }
    if o.files == Files::None {
        return p;
    }
    #[cfg(feature = "files")]
    table(&mut p, s, params, o.dforce_columns);
    #[cfg(not(feature = "files"))]
    let _ = params;
    if o.files == Files::All {
        for (stem, plot) in panels(s) {
            p.figure(&stem, plot);
        }
    }
    if let Some(t) = &s.c.traces {
        let (layout, figure) = traces(s, t);
        p.dataset(&format!("{}-traces.nc", s.l.stem), layout);
        if o.files == Files::All {
            if let Some(figure) = figure {
                p.figure(&format!("{}-traces", s.l.stem), figure);
            }
        }
    }
    p
}

/// `STEM.csv` and `STEM.npy` (the same numeric columns: named as the JSON document, or
/// dForce's `zcdom` columns first with `dforce`).
#[cfg(feature = "files")]
fn table(p: &mut Presentation, s: &Shown<'_>, params: &Params, dforce: bool) {
    use crate::report::{curve_table, CurveAxis};
    let axis = CurveAxis {
        name: s.l.x_name,
        label: s.l.x_label.clone(),
        sweeps: s.l.sweeps,
    };
    let (rows, columns) = curve_table(s.c, s.x, s.u, params, &axis, dforce);
    let header: Vec<&str> = columns.iter().map(|c| c.name.as_str()).collect();
    super::numeric_csv(p, &format!("{}.csv", s.l.stem), &header, &rows);
    p.files.push(crate::report::OutputFile::Npy {
        name: format!("{}.npy", s.l.stem),
        columns,
        rows,
    });
}

/// The curve's lines: its points and branches, folds, bistable ranges and jumps.
fn summary(p: &mut Presentation, s: &Shown<'_>) {
    let (c, x, l) = (s.c, s.x, s.l);
    p.line(format!(
        "{}: {} values each way, {} branch(es) with {} points",
        l.stem,
        c.first.len(),
        c.branches.len(),
        c.branches.iter().map(Vec::len).sum::<usize>()
    ));
    for fv in &c.folds {
        p.line(format!("  fold at {} = {}", l.x_text, l.show(x(*fv))));
    }
    for &(a, b) in &c.bistable {
        let (lo, hi) = (x(a), x(b));
        p.line(format!(
            "  bistable for {} in [{}, {}]",
            l.x_text,
            l.show(lo.min(hi)),
            l.show(lo.max(hi))
        ));
    }
    for j in &c.jumps {
        p.line(format!(
            "  {} jumps between {} = {} and {}{}",
            match j.sweep {
                Sweep::First => l.sweeps.0,
                Sweep::Second => l.sweeps.1,
            },
            l.x_text,
            l.show(x(j.from)),
            l.show(x(j.to)),
            j.fold
                .map_or(String::new(), |fv| format!(" (fold at {})", l.show(x(fv))))
        ));
    }
}

/// The line of the `"thermal"` block (an approach with a temperature): the lock-in's time
/// constant and bandwidth, and the range of σ_A and σ_φ over the stable period-1 points (under
/// a multifrequency drive, of the first component; each further one's on a line of its own).
fn thermal(p: &mut Presentation, t: &Value, s: &Shown<'_>) {
    let Some(noise) = &s.c.noise else {
        return;
    };
    let range = |f: &dyn Fn(&LockInNoise) -> f64| {
        let v = noise.iter().flatten().map(f).filter(|v| v.is_finite());
        v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        })
    };
    let (a, b) = range(&|n| n.amplitude * s.u.length);
    let (c, d) = range(&|n| n.phase.to_degrees());
    if a > b {
        return;
    }
    // a temperature needs the probe: the block is in SI
    let num = |k: &str| t[k].as_f64().unwrap_or(f64::NAN);
    let text = s.l.text;
    let (tc, bw) = (
        text.value(num("time_constant"), "s"),
        text.value(num("bandwidth"), "Hz"),
    );
    p.line(format!(
        "  thermal noise at {} K (lock-in τ_L = {tc}, bandwidth {bw}): σ_A {} to {}, σ_φ \
         {c:.4}° to {d:.4}°",
        num("temperature"),
        s.l.show(a),
        s.l.show(b)
    ));
    for i in 1..s.c.components() {
        let (a, b) = range(&|n| n.further[i - 1][0] * s.u.length);
        let (c, d) = range(&|n| n.further[i - 1][1].to_degrees());
        if a <= b {
            let (a, b) = (s.l.show(a), s.l.show(b));
            p.line(format!(
                "    component {}: σ_A {a} to {b}, σ_φ {c:.4}° to {d:.4}°",
                i + 1
            ));
        }
    }
}

/// Below this fraction of the model's force and energy units (F̃ and F̃·g₀: kA₀ and kA₀² for
/// the point mass) a printed force or energy is the round-off of its computation and is printed
/// as 0: the steady state is solved to 1e-10 of the state and the observables' quadratures are
/// exact to ~1e-12 relative, so a conservative law's E_dis comes out as 1e-13 of the energy unit
/// (5.5e-28 J against kA₀² = 4e-15 J for examples/probe-point-mass-dmt.toml), while the
/// smallest dissipation of interest (air damping at Q = 1e4 over a period, 2π/Q · ½ of the unit)
/// is 3e-4 of it. The same extent as the figures' smallest axis span (`y_min_span`).
pub(crate) const PRINT_RESOLUTION: f64 = 1e-6;

/// The operating points of the `"setpoint"` block, one line each: the repulsive maximum of the
/// tip–sample force (max F_c when positive, "none" else) and the adhesion minimum (min F_c when
/// negative), energies and forces printed as 0 below [`PRINT_RESOLUTION`].
fn setpoint(out: &mut Presentation, sp: &Value, l: &Labels, u: &CurveUnits) {
    let num = |v: &Value, k: &str| v[k].as_f64().unwrap_or(f64::NAN);
    let length = |x: f64| match l.x_unit {
        Some(u) => l.text.value(x, u),
        None => format!("{x:.6}"),
    };
    let si = |unit| l.x_unit.map(|_| unit);
    // `v` as printed: 0 below PRINT_RESOLUTION of `scale` (the model's unit in the reported
    // one), else with its SI prefix (`si`) or six decimals
    let resolved = |v: f64, scale: f64, si: Option<&str>| {
        let v = if v.abs() < PRINT_RESOLUTION * scale.abs() {
            0.0
        } else {
            v
        };
        match si {
            Some(unit) => l.text.value(v, unit),
            None => format!("{v:.6}"),
        }
    };
    let points = sp["points"].as_array().map_or(&[][..], |v| v.as_slice());
    out.line(format!(
        "setpoint A/A0 = {}: {} operating point(s){}",
        num(sp, "ratio"),
        points.len(),
        if points.is_empty() {
            " (the curve's stable stretches do not reach it)"
        } else {
            ":"
        }
    ));
    for p in points {
        let (peak, least) = (num(p, "peak_force"), num(p, "min_force"));
        let res = PRINT_RESOLUTION * u.force;
        let repulsive = if peak > res {
            resolved(peak, u.force, si("N"))
        } else {
            "none".into()
        };
        let adhesion = if least < -res {
            resolved(least, u.force, si("N"))
        } else {
            "none".into()
        };
        let energy = resolved(num(p, "energy_dissipated"), u.energy, si("J"));
        out.line(format!(
            "  {} ({}): z_c = {}, phase {:.2}°, repulsive peak force {repulsive}, adhesion \
             (min force) {adhesion}, indentation {}, E_dis {energy}",
            p["source"].as_str().unwrap_or(""),
            p["regime"].as_str().unwrap_or(""),
            length(num(p, "z_c")),
            num(p, "phase_deg"),
            length(num(p, "indentation")),
        ));
        // with a temperature: the lock-in's noise there
        if let Some(a) = p.get("amplitude_noise").and_then(Value::as_f64) {
            out.line(format!(
                "    thermal noise: σ_A = {}, σ_φ = {:.4}°",
                length(a),
                num(p, "phase_noise_deg")
            ));
        }
        // a multifrequency drive: each component's amplitude and phase there
        for i in 1.. {
            let Some(amp) = p.get(format!("amplitude_{i}")).and_then(Value::as_f64) else {
                break;
            };
            out.line(format!(
                "    component {i}: A{i} = {}, phase {:.2}°, virial {}, E_dis {}",
                length(amp),
                num(p, &format!("phase_{i}_deg")),
                resolved(num(p, &format!("virial_{i}")), u.energy, si("J")),
                resolved(num(p, &format!("energy_dissipated_{i}")), u.energy, si("J")),
            ));
        }
    }
}

/// `STEM-traces.nc` (deflection, distance, force over (point, time), the swept quantity and
/// the time axis in drive periods) and its figure: the force–distance loops of up to 8
/// points spread over the sweep (none without points).
fn traces(s: &Shown<'_>, t: &Traces) -> (Layout, Option<crate::layout::figure::Plot>) {
    let (u, l) = (s.u, s.l);
    let np = t.values.len();
    let xs: Vec<f64> = t.values.iter().map(|&v| (s.x)(v)).collect();
    let scale = |v: &[f64], k: f64| v.iter().map(|a| a * k).collect::<Vec<f64>>();
    let (length, force) = if u.si { ("m", "N") } else { ("g0", "F~") };
    let (deflection, distance, force_values) = (
        scale(&t.deflection, u.length),
        scale(&t.distance, u.length),
        scale(&t.force, u.force),
    );
    let grid: &[&str] = &["point", "time"];
    let vars = vec![
        Variable::f64(l.x_name, &["point"], l.x_unit.unwrap_or("1"), l.x_text, &xs),
        Variable::f64(
            "time",
            &["time"],
            "drive periods",
            "time within the cycle",
            &t.time,
        ),
        Variable::f64(
            "deflection",
            grid,
            length,
            "tip deflection W(1,tau)",
            &deflection,
        ),
        Variable::f64(
            "distance",
            grid,
            length,
            "tip-sample distance V_T (<= 0 in contact)",
            &distance,
        ),
        Variable::f64(
            "force",
            grid,
            force,
            "tip-sample force F_c (> 0 repulsive, < 0 attractive)",
            &force_values,
        ),
    ];
    let layout = Layout::new(
        format!(
            "afmdyn {} traces: one steady-state cycle per point of the {}",
            l.stem, l.sweeps.0
        ),
        &[("point", np), ("time", t.time.len())],
        vars,
    );
    let figure = (np > 0).then(|| {
        traces_figure(
            l,
            &xs,
            &distance,
            &force_values,
            t.time.len(),
            (length, force),
        )
    });
    (layout, figure)
}
