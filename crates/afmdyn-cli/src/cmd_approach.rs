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

mod figures;
use figures::{plots, write_traces};

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
                .map_err(|e| crate::error::study_error(e, what))?;
                let records = store
                    .records()
                    .map_err(|e| crate::error::store_error(e, what))?;
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
