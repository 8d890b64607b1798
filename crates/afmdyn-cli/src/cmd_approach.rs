//! `afmdyn approach` (the approach–retract curve over the rest distance z_c) and `afmdyn
//! resonance` (amplitude and phase against the drive frequency): stepped sweeps both ways plus
//! branch continuation ([`afmdyn::analysis::stepped`]), written as CSV, NPY and plots.

use crate::args::{quantity, Dim, ModelArgs, Quantity};
use crate::cmd_simulate::Files;
use crate::error::CliError;
use crate::output::si_value;
use crate::output::{f, write_csv, NpyStream, OutDir};
use crate::plot::{save, Figure, Series, Style};
use afmdyn::analysis::approach::rest_distance;
use afmdyn::analysis::continuation::BranchEvent;
use afmdyn::analysis::observables::Observables;
use afmdyn::analysis::stepped::{SteppedCurve, Sweep};
use afmdyn::layout::{Layout, Variable};
use afmdyn::probe::Probe;
use afmdyn::report::{
    component_columns, component_row, curve_column_index, curve_row, curve_table, CurveAxis,
    CurveUnits,
};
use afmdyn::request::{Analysis, ApproachRequest, CurveRequest, Resolved, ResonanceRequest};
use afmdyn::study::stepped::{curve_store, CurveStudy};
use afmdyn::Params;
use clap::Args;
use std::path::{Path, PathBuf};

/// Grid, solver and output flags shared by `approach` and `resonance`.
#[derive(Debug, Args)]
pub struct CurveArgs {
    /// Grid step of the swept quantity (in the units of --from/--to); conflicts with --points
    #[arg(long, conflicts_with = "points", allow_hyphen_values = true)]
    step: Option<Quantity>,
    /// Number of grid values, ends included (2..=100000) [default: 120]
    #[arg(long)]
    points: Option<usize>,
    /// Skip the continuation of the periodic-orbit branches (stepped sweeps only)
    #[arg(long)]
    no_branches: bool,
    /// Tolerance of the adaptive integrator (the exact propagator ignores it)
    #[arg(long, default_value_t = CurveRequest::default().tolerance)]
    tolerance: f64,
    /// Record one steady-state cycle per point of the first sweep (tip deflection, distance
    /// V_T, tip–sample force), N samples per drive period (default 200): STEM-traces.nc, the
    /// force–distance loops plot and "traces" in --json
    #[arg(long, value_name = "N", num_args = 0..=1, default_missing_value = "200")]
    traces: Option<usize>,
    /// Files written: all (data and plots), data (no plots) or none (only the summary)
    #[arg(long, value_enum, default_value = "all")]
    files: Files,
    /// Name and order the CSV/NPY columns as dForce 2.0's zcdom table (zc, Amplitude, Phase,
    /// Distance_min, Force_max, Energy_diss, Virial1, …) for scripts written for it; the
    /// default names them as the JSON document (z_c, amplitude, phase_deg, …)
    #[arg(long)]
    dforce_columns: bool,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
    /// Continue an interrupted curve from its last stored point; refused unless the other
    /// arguments are those of the interrupted run (recorded in OUT/.curve.run.json)
    #[arg(long)]
    resume: bool,
    /// Testing: abort the process, as if killed, after this many points are stored
    #[arg(long, hide = true)]
    abort_after: Option<usize>,
}

impl CurveArgs {
    /// The request of these flags with the ends `from`, `to` (the library checks and applies
    /// it: [`CurveRequest`]); the step in `dim` when `si` (a probe).
    fn request(
        &self,
        from: Option<f64>,
        to: Option<f64>,
        dim: Dim,
        si: bool,
    ) -> Result<CurveRequest, CliError> {
        Ok(CurveRequest {
            from,
            to,
            step: quantity(self.step, "step", dim, si)?,
            points: self.points,
            branches: !self.no_branches,
            traces: self.traces,
            tolerance: self.tolerance,
        })
    }
}

/// The z_c range of `approach` and `bimodal`.
#[derive(Debug, Args)]
struct ZcRange {
    /// Rest distance z_c where the approach starts (m with --probe, else units of g0)
    /// [default: 1.2 × the free amplitude A0 from the sample, the sum of the components' under
    /// a multifrequency drive]; with --probe a unit may follow (20nm)
    #[arg(long, allow_hyphen_values = true)]
    from: Option<Quantity>,
    /// Rest distance z_c where the approach ends and the retract starts [default: 0.1 × A0]
    #[arg(long, allow_hyphen_values = true)]
    to: Option<Quantity>,
}

impl ZcRange {
    /// The ends in the model's or SI lengths (a probe: `si`).
    fn ends(&self, si: bool) -> Result<(Option<f64>, Option<f64>), CliError> {
        Ok((
            quantity(self.from, "from", Dim::Length, si)?,
            quantity(self.to, "to", Dim::Length, si)?,
        ))
    }
}

/// `afmdyn approach` flags.
#[derive(Debug, Args)]
pub struct ApproachArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    range: ZcRange,
    #[command(flatten)]
    curve: CurveArgs,
    /// Amplitude setpoint A_sp/A0 in (0, 1]: the operating points where the curve's amplitude
    /// equals it on each stable branch (attractive and repulsive in the bistable range), with
    /// phase, peak force, indentation and dissipated energy there ("setpoint" in --json)
    #[arg(long, value_name = "RATIO")]
    setpoint: Option<f64>,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/approach")]
    out: PathBuf,
}

/// `afmdyn bimodal` flags: those of `approach`; the probe's `[drive]` gives two or more
/// components (`free_amplitude = [A01, A02]`, `frequency = [f1, f2]`).
#[derive(Debug, Args)]
pub struct BimodalArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    range: ZcRange,
    #[command(flatten)]
    curve: CurveArgs,
    /// Measure every point by the time average (Hann-windowed demodulation until successive
    /// windows agree, with an error estimate per component) instead of the exact periodic
    /// orbit of the common period; always so for an incommensurate ratio (common period beyond
    /// 1000 drive periods). No branches
    #[arg(long)]
    average: bool,
    /// Setpoint A1/A01 in (0, 1] of the first component's amplitude (the one the feedback
    /// holds): the operating points where the curve reaches it, with every component's
    /// amplitude, phase, virial and dissipated energy there ("setpoint" in --json)
    #[arg(long, value_name = "RATIO")]
    setpoint: Option<f64>,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/bimodal")]
    out: PathBuf,
}

/// `afmdyn resonance` flags.
#[derive(Debug, Args)]
pub struct ResonanceArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Mode k whose natural frequency the default band surrounds (1..=N)
    #[arg(long, default_value_t = ResonanceRequest::default().mode)]
    mode: usize,
    /// Start of the band (Hz with --probe, else Ω) [default: ω_k (1 − w), w = max(6/Q_k, 0.02)];
    /// with --probe a unit may follow (295kHz)
    #[arg(long, allow_hyphen_values = true)]
    from: Option<Quantity>,
    /// End of the band [default: ω_k (1 + w)]
    #[arg(long, allow_hyphen_values = true)]
    to: Option<Quantity>,
    #[command(flatten)]
    curve: CurveArgs,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/resonance")]
    out: PathBuf,
}

/// How one curve is labelled and converted.
struct Labels {
    /// File stem.
    stem: &'static str,
    /// Names of the two sweeps.
    sweeps: (&'static str, &'static str),
    /// Abscissa column name and axis label.
    x_name: &'static str,
    x_label: String,
    /// The abscissa's symbol in the printed summary and its SI unit (`None`: dimensionless).
    x_text: &'static str,
    x_unit: Option<&'static str>,
}

impl Labels {
    /// An abscissa value as the summary prints it: with an SI prefix and the unit (13.4747 nm,
    /// 300.000 kHz), or to 7 significant digits when dimensionless.
    fn show(&self, v: f64) -> String {
        match self.x_unit {
            Some(unit) => si_value(v, unit),
            None => format!("{v:.6e}"),
        }
    }
}

/// The CSV (the same numeric columns as the NPY: named as the JSON document, or dForce's
/// `zcdom` columns first with `dforce`), NPY and plots of one curve in `out`.
#[allow(clippy::too_many_arguments)]
fn write_files(
    out: &OutDir,
    files: Files,
    dforce: bool,
    c: &SteppedCurve,
    x: &dyn Fn(f64) -> f64,
    u: &CurveUnits,
    l: &Labels,
    base: &Params,
) -> Result<(), CliError> {
    let axis = CurveAxis {
        name: l.x_name,
        label: l.x_label.clone(),
        sweeps: l.sweeps,
    };
    let (table, cols) = curve_table(c, x, u, base, &axis, dforce);
    let header: Vec<&str> = cols.iter().map(|c| c.name.as_str()).collect();
    write_csv(
        &out.join(format!("{}.csv", l.stem)),
        &header,
        table.iter().map(|r| r.iter().map(|v| f(*v)).collect()),
    )?;
    let mut npy = NpyStream::create(&out.join(format!("{}.npy", l.stem)), cols)?;
    for r in &table {
        npy.push(r)?;
    }
    npy.finish()?;
    if files == Files::All {
        plots(out, c, x, u, l)?;
    }
    Ok(())
}

/// Where a plotted value comes from: a CURVE_COLUMNS index, or an index into the drive
/// components' columns (`component_row`).
#[derive(Clone, Copy)]
enum Key {
    Curve(usize),
    Component(usize),
}

/// One value of the observables.
fn col(o: &Observables, u: &CurveUnits, k: Key) -> f64 {
    match k {
        Key::Curve(k) => curve_row(o, u)[k],
        Key::Component(k) => component_row(o, u).get(k).copied().unwrap_or(f64::NAN),
    }
}

fn plots(
    out: &OutDir,
    c: &SteppedCurve,
    x: &dyn Fn(f64) -> f64,
    u: &CurveUnits,
    l: &Labels,
) -> Result<(), CliError> {
    let unit = |base: &str| {
        if u.si {
            base.to_string()
        } else {
            String::new()
        }
    };
    let idx = |name: &str| Key::Curve(curve_column_index(name).expect("column"));
    let mut panels = vec![
        if l.x_name == "z_c" {
            ("amplitude_ratio", "A/A0".to_string(), "amplitude")
        } else {
            (
                "amplitude",
                format!("amplitude A {}", unit("(m)")),
                "amplitude",
            )
        },
        ("phase_deg", "phase lag φ (deg)".to_string(), "phase"),
        (
            "energy_dissipated",
            format!("E_dis per period {}", unit("(J)")),
            "dissipation",
        ),
        ("virial", format!("virial {}", unit("(J)")), "virial"),
        (
            "peak_force",
            format!("peak force {}", unit("(N)")),
            "peak-force",
        ),
    ]
    .into_iter()
    .map(|(name, y, suffix)| (idx(name), name.to_string(), y, suffix.to_string()))
    .collect::<Vec<_>>();
    // a multifrequency drive: A_i and φ_i of each component
    let count = c
        .first
        .first()
        .map_or(0, |p| p.observables.components.len());
    for (k, (name, _, _)) in component_columns(count).into_iter().enumerate() {
        let i = k / 4 + 1;
        match k % 4 {
            0 => panels.push((
                Key::Component(k),
                name,
                format!("amplitude A{i} {}", unit("(m)")),
                format!("amplitude-{i}"),
            )),
            1 => panels.push((
                Key::Component(k),
                name,
                format!("phase lag φ{i} (deg)"),
                format!("phase-{i}"),
            )),
            _ => {}
        }
    }
    // more than one mode: the higher modes' share of the motion (in liquid, every tap rings them)
    let modes = c
        .first
        .first()
        .map_or(0, |p| p.observables.mode_amplitudes.len());
    if modes > 1 {
        panels.push((
            idx("higher_mode_fraction"),
            "higher_mode_fraction".to_string(),
            "higher modes' RMS tip amplitude / mode 1's".to_string(),
            "higher-modes".to_string(),
        ));
    }
    for (k, name, y_label, suffix) in panels {
        let name = name.as_str();
        let mut series = Vec::new();
        // branches first (underneath): each unstable stretch a dotted line, stable points as
        // small dots
        for b in &c.branches {
            let stable: Vec<(f64, f64)> = b
                .iter()
                .filter(|s| s.point.stable)
                .map(|s| (x(s.point.value), col(&s.observables, u, k)))
                .collect();
            for run in b.chunk_by(|p, q| p.point.stable == q.point.stable) {
                if !run[0].point.stable {
                    series.push(Series {
                        label: String::new(),
                        points: run
                            .iter()
                            .map(|s| (x(s.point.value), col(&s.observables, u, k)))
                            .collect(),
                        style: Style::Dotted,
                        color: 3,
                    });
                }
            }
            if !stable.is_empty() {
                series.push(Series {
                    label: String::new(),
                    points: stable,
                    style: Style::Dots,
                    color: 7,
                });
            }
        }
        if let Some(s) = series.iter_mut().find(|s| s.color == 3) {
            s.label = "unstable branch (dotted)".into();
        }
        if let Some(s) = series.iter_mut().find(|s| s.color == 7) {
            s.label = "stable branch (continuation)".into();
        }
        for (sweep, style, color, label) in [
            (&c.first, Style::Line, 0, format!("{} (solid)", l.sweeps.0)),
            (
                &c.second,
                Style::Dashed,
                1,
                format!("{} (dashed)", l.sweeps.1),
            ),
        ] {
            series.push(Series {
                label,
                points: sweep
                    .iter()
                    .map(|p| (x(p.value), col(&p.observables, u, k)))
                    .collect(),
                style,
                color,
            });
        }
        let mut marks = Vec::new();
        for j in &c.jumps {
            let sw = match j.sweep {
                Sweep::First => &c.first,
                Sweep::Second => &c.second,
            };
            for p in &sw[j.index - 1..=j.index] {
                marks.push((x(p.value), col(&p.observables, u, k)));
            }
        }
        if !marks.is_empty() {
            series.push(Series {
                label: "jumps".into(),
                points: marks,
                style: Style::Points,
                color: 2,
            });
        }
        let folds: Vec<(f64, f64)> = c
            .branches
            .iter()
            .flatten()
            .filter(|s| s.point.event == Some(BranchEvent::Fold))
            .map(|s| (x(s.point.value), col(&s.observables, u, k)))
            .collect();
        if !folds.is_empty() {
            series.push(Series {
                label: "folds (saddle-node)".into(),
                points: folds,
                style: Style::Points,
                color: 4,
            });
        }
        save(
            out.path(),
            &format!("{}-{suffix}", l.stem),
            &Figure {
                // energies and forces below 1e-6 of the model's units are round-off (a
                // conservative law's E_dis): drawn as zero on an axis of that extent
                y_min_span: match name {
                    "energy_dissipated" | "virial" => 1e-6 * u.energy,
                    "peak_force" => 1e-6 * u.force,
                    _ => 0.0,
                },
                title: format!("{} curve: {}", l.stem, name.replace('_', " ")),
                x_label: l.x_label.clone(),
                y_label,
                series,
                shade: c
                    .bistable
                    .iter()
                    .map(|&(a, b)| {
                        let (p, q) = (x(a), x(b));
                        (p.min(q), p.max(q))
                    })
                    .collect(),
            },
        )?;
    }
    Ok(())
}

fn summary(
    c: &SteppedCurve,
    x: &dyn Fn(f64) -> f64,
    l: &Labels,
    out: Option<&OutDir>,
) -> Result<(), CliError> {
    outln!(
        "{}: {} values each way, {} branch(es) with {} points",
        l.stem,
        c.first.len(),
        c.branches.len(),
        c.branches.iter().map(Vec::len).sum::<usize>()
    );
    for fv in &c.folds {
        outln!("  fold at {} = {}", l.x_text, l.show(x(*fv)));
    }
    for &(a, b) in &c.bistable {
        let (p, q) = (x(a), x(b));
        outln!(
            "  bistable for {} in [{}, {}]",
            l.x_text,
            l.show(p.min(q)),
            l.show(p.max(q))
        );
    }
    for j in &c.jumps {
        outln!(
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
        );
    }
    if let Some(o) = out {
        outln!("outputs in {}", o.path().display());
    }
    Ok(())
}

/// The parameters, the output units (SI with a probe; frequencies in Hz when `hz`) and the
/// probe, with `--from`/`--to` checked finite.
fn setup(
    model: &ModelArgs,
    from: Option<f64>,
    to: Option<f64>,
    hz: bool,
) -> Result<(Params, CurveUnits, Option<Probe>), CliError> {
    let (base, probe) = model.resolve(Params::default())?;
    check_finite("--from", from)?;
    check_finite("--to", to)?;
    let units = probe.as_ref().map_or_else(CurveUnits::dimensionless, |p| {
        CurveUnits::from_scales(&p.scales, hz)
    });
    Ok((base, units, probe))
}

/// The part of a run shared by both commands.
struct Run<'a> {
    args: &'a CurveArgs,
    base: &'a Params,
    out: &'a Path,
    units: &'a CurveUnits,
    labels: &'a Labels,
    x: &'a dyn Fn(f64) -> f64,
}

impl Run<'_> {
    /// Lock the output directory, compute, write the files and print the JSON document or the
    /// summary.
    fn go<A: Analysis<Output = SteppedCurve>>(
        &self,
        request: &A,
        model: &Resolved,
        study: impl FnOnce() -> Result<CurveStudy, afmdyn::SimError>,
    ) -> Result<(), CliError> {
        request.validate(model)?;
        let out = (self.args.files != Files::None)
            .then(|| OutDir::lock(self.out))
            .transpose()?;
        let (c, json) = match &out {
            // no files: nothing to resume from
            None if self.args.resume => {
                return Err(CliError::Input(
                    "--resume: --files none keeps no store to resume; use --files data or all"
                        .into(),
                ))
            }
            None => {
                let d = crate::progress::run(request, model, "points")?;
                (d.output, d.json)
            }
            Some(o) => {
                // the points in the directory's store, resumable; the branches after them
                let study = study()?;
                let what = self.labels.stem;
                let mut store = curve_store(o.dir_lock());
                crate::progress::study(
                    &study,
                    &mut store,
                    self.args.resume,
                    None,
                    "points",
                    self.args.abort_after,
                )
                .map_err(|e| crate::cmd_analysis::study_error(e, what))?;
                let records = store
                    .records()
                    .map_err(|e| crate::cmd_analysis::store_error(e, what))?;
                let c = crate::progress::with_bar("branch points", |p| study.curve(records, p))?;
                let json = afmdyn::request::run::document(request, model, &c)?;
                (c, json)
            }
        };
        if let Some(o) = &out {
            write_files(
                o,
                self.args.files,
                self.args.dforce_columns,
                &c,
                self.x,
                self.units,
                self.labels,
                self.base,
            )?;
            if let Some(t) = &c.traces {
                write_traces(o, self.args.files, t, self.x, self.units, self.labels)?;
            }
        }
        crate::output::print_warnings(&json)?;
        if self.args.json {
            outln!("{json}");
        } else {
            summary(&c, self.x, self.labels, out.as_ref())?;
            if let Some(sp) = json.get("setpoint") {
                print_setpoint(sp, self.labels, self.units)?;
            }
        }
        Ok(())
    }
}

/// `STEM-traces.nc` (NetCDF 3: deflection, distance, force over (point, time), the swept
/// quantity and the time axis in drive periods) and, with plots, `STEM-traces`: the
/// force–distance loops of up to 8 points spread over the sweep.
fn write_traces(
    out: &OutDir,
    files: Files,
    t: &afmdyn::analysis::traces::Traces,
    x: &dyn Fn(f64) -> f64,
    units: &CurveUnits,
    labels: &Labels,
) -> Result<(), CliError> {
    let path = out.join(format!("{}-traces.nc", labels.stem));
    let (np, ns) = (t.values.len(), t.time.len());
    let xs: Vec<f64> = t.values.iter().map(|&v| x(v)).collect();
    let scale = |v: &[f64], s: f64| v.iter().map(|a| a * s).collect::<Vec<f64>>();
    let (length, force) = if units.si { ("m", "N") } else { ("g0", "F~") };
    let (deflection, distance, force_values) = (
        scale(&t.deflection, units.length),
        scale(&t.distance, units.length),
        scale(&t.force, units.force),
    );
    let grid: &[&str] = &["point", "time"];
    let vars = vec![
        Variable::f64(
            labels.x_name,
            &["point"],
            labels.x_unit.unwrap_or("1"),
            labels.x_text,
            &xs,
        ),
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
    crate::output::write_layout(
        &path,
        &Layout::new(
            format!(
                "afmdyn {} traces: one steady-state cycle per point of the {}",
                labels.stem, labels.sweeps.0
            ),
            &[("point", np), ("time", ns)],
            vars,
        ),
    )?;
    if files != Files::All || np == 0 {
        return Ok(());
    }
    let picks: Vec<usize> = if np <= 8 {
        (0..np).collect()
    } else {
        (0..8).map(|k| k * (np - 1) / 7).collect()
    };
    let series = picks
        .iter()
        .enumerate()
        .map(|(c, &i)| Series {
            label: format!(
                "{} = {}",
                labels.x_text,
                match labels.x_unit {
                    Some(u) => si_value(xs[i], u),
                    None => format!("{:.4}", xs[i]),
                }
            ),
            points: (0..ns)
                .map(|k| (distance[i * ns + k], force_values[i * ns + k]))
                .collect(),
            style: Style::Line,
            color: c,
        })
        .collect();
    save(
        out.path(),
        &format!("{}-traces", labels.stem),
        &Figure {
            y_min_span: 0.0,
            title: format!(
                "Force–distance loops over one cycle ({}; the loop's area is E_dis)",
                labels.sweeps.0
            ),
            x_label: format!("tip–sample distance V_T ({length})"),
            y_label: format!("tip–sample force ({force})"),
            series,
            shade: vec![],
        },
    )?;
    Ok(())
}

/// Below this fraction of the model's force and energy units (F̃ and F̃·g₀: kA₀ and kA₀² for
/// the point mass) a printed force or energy is the round-off of its computation and is printed
/// as 0: the steady state is solved to 1e-10 of the state and the observables' quadratures are
/// exact to ~1e-12 relative, so a conservative law's E_dis comes out as 1e-13 of the energy unit
/// (5.5e-28 J against kA₀² = 4e-15 J for examples/probe-point-mass-dmt.toml), while the
/// smallest dissipation of interest (air damping at Q = 1e4 over a period, 2π/Q · ½ of the unit)
/// is 3e-4 of it. The same extent as the plots' smallest axis span (`y_min_span`).
const PRINT_RESOLUTION: f64 = 1e-6;

/// `v` as the summary prints it: 0 below [`PRINT_RESOLUTION`] of `unit_scale` (the model's unit
/// in the reported one), else with its SI prefix (`si`) or six decimals.
fn resolved(v: f64, unit_scale: f64, si: Option<&str>) -> String {
    let v = if v.abs() < PRINT_RESOLUTION * unit_scale.abs() {
        0.0
    } else {
        v
    };
    match si {
        Some(unit) => si_value(v, unit),
        None => format!("{v:.6}"),
    }
}

/// The operating points of the `"setpoint"` block, one line each: the repulsive maximum of the
/// tip–sample force (max F_c when positive, "none" else) and the adhesion minimum (min F_c when
/// negative), energies and forces printed as 0 below [`PRINT_RESOLUTION`].
fn print_setpoint(sp: &serde_json::Value, labels: &Labels, u: &CurveUnits) -> Result<(), CliError> {
    let num = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap_or(f64::NAN);
    let length = |x: f64| match labels.x_unit {
        Some(u) => si_value(x, u),
        None => format!("{x:.6}"),
    };
    let si = |unit| labels.x_unit.map(|_| unit);
    let points = sp["points"].as_array().map_or(&[][..], |v| v.as_slice());
    outln!(
        "setpoint A/A0 = {}: {} operating point(s){}",
        num(sp, "ratio"),
        points.len(),
        if points.is_empty() {
            " (the curve's stable stretches do not reach it)"
        } else {
            ":"
        }
    );
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
        outln!(
            "  {} ({}): z_c = {}, phase {:.2}°, repulsive peak force {repulsive}, adhesion \
             (min force) {adhesion}, indentation {}, E_dis {energy}",
            p["source"].as_str().unwrap_or(""),
            p["regime"].as_str().unwrap_or(""),
            length(num(p, "z_c")),
            num(p, "phase_deg"),
            length(num(p, "indentation")),
        );
        // a multifrequency drive: each component's amplitude and phase there
        for i in 1.. {
            let Some(amp) = p.get(format!("amplitude_{i}")).and_then(|v| v.as_f64()) else {
                break;
            };
            outln!(
                "    component {i}: A{i} = {}, phase {:.2}°, virial {}, E_dis {}",
                length(amp),
                num(p, &format!("phase_{i}_deg")),
                resolved(num(p, &format!("virial_{i}")), u.energy, si("J")),
                resolved(num(p, &format!("energy_dissipated_{i}")), u.energy, si("J")),
            );
        }
    }
    Ok(())
}

fn check_finite(name: &str, v: Option<f64>) -> Result<(), CliError> {
    match v {
        Some(x) if !x.is_finite() => Err(CliError::Input(format!(
            "{name} = {x}: must be a finite number"
        ))),
        _ => Ok(()),
    }
}

/// Run `afmdyn approach`.
pub fn approach(a: &ApproachArgs) -> Result<(), CliError> {
    let si = a.model.probe.is_some();
    let (from, to) = a.range.ends(si)?;
    let (base, units, probe) = setup(&a.model, from, to, false)?;
    let request = ApproachRequest {
        curve: a.curve.request(from, to, Dim::Length, si)?,
        setpoint: a.setpoint,
        average: false,
    };
    approach_run(&a.curve, &a.out, "approach", &request, base, units, probe)
}

/// Run `afmdyn bimodal`: the approach curve of a multifrequency drive
/// ([`afmdyn::request::curves::check_bimodal`]), its files `bimodal.*`.
pub fn bimodal(a: &BimodalArgs) -> Result<(), CliError> {
    let si = a.model.probe.is_some();
    let (from, to) = a.range.ends(si)?;
    let (base, units, probe) = setup(&a.model, from, to, false)?;
    afmdyn::request::curves::check_bimodal(&base)?;
    let request = ApproachRequest {
        curve: a.curve.request(from, to, Dim::Length, si)?,
        setpoint: a.setpoint,
        average: a.average,
    };
    approach_run(&a.curve, &a.out, "bimodal", &request, base, units, probe)
}

/// An approach curve's run with the files named `stem`.
fn approach_run(
    args: &CurveArgs,
    out: &Path,
    stem: &'static str,
    request: &ApproachRequest,
    base: Params,
    units: CurveUnits,
    probe: Option<Probe>,
) -> Result<(), CliError> {
    let x = |v: f64| rest_distance(&base, v) * units.length;
    let labels = Labels {
        stem,
        sweeps: ("approach", "retract"),
        x_name: "z_c",
        x_label: format!(
            "rest distance z_c{}",
            if units.si { " (m)" } else { " (g0)" }
        ),
        x_text: "z_c",
        x_unit: units.si.then_some("m"),
    };
    let run = Run {
        args,
        base: &base,
        out,
        units: &units,
        labels: &labels,
        x: &x,
    };
    let model = Resolved {
        params: base,
        probe,
    };
    run.go(request, &model, || CurveStudy::approach(request, &model))
}

/// Run `afmdyn resonance`.
pub fn resonance(a: &ResonanceArgs) -> Result<(), CliError> {
    let si = a.model.probe.is_some();
    let from = quantity(a.from, "from", Dim::Frequency, si)?;
    let to = quantity(a.to, "to", Dim::Frequency, si)?;
    let (base, units, probe) = setup(&a.model, from, to, true)?;
    let hz = units.hz_per_omega.unwrap_or(1.0);
    let request = ResonanceRequest {
        mode: a.mode,
        curve: a.curve.request(from, to, Dim::Frequency, si)?,
    };
    let x = |v: f64| v * hz;
    let labels = Labels {
        stem: "resonance",
        sweeps: ("up", "down"),
        x_name: if units.hz_per_omega.is_some() {
            "frequency_hz"
        } else {
            "omega"
        },
        x_label: if units.hz_per_omega.is_some() {
            "drive frequency (Hz)".into()
        } else {
            "drive frequency Ω".into()
        },
        x_text: if units.hz_per_omega.is_some() {
            "f"
        } else {
            "Ω"
        },
        x_unit: units.hz_per_omega.map(|_| "Hz"),
    };
    let run = Run {
        args: &a.curve,
        base: &base,
        out: &a.out,
        units: &units,
        labels: &labels,
        x: &x,
    };
    let model = Resolved {
        params: base,
        probe,
    };
    run.go(&request, &model, || CurveStudy::resonance(&request, &model))
}
