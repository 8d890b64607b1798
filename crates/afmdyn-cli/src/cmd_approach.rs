//! `afmdyn approach`, `bimodal` (the approach–retract curve over the rest distance z_c) and
//! `afmdyn resonance` (amplitude and phase against the drive frequency): stepped sweeps both
//! ways plus branch continuation ([`afmdyn::analysis::stepped`]), run as resumable studies
//! into the `--out` directory's store ([`CurveStudy`]); their summary, tables, traces and
//! figures are the library's ([`afmdyn::request::present::curves`]).

use crate::args::{quantity, Dim, ModelArgs, Quantity};
use crate::cmd_simulate::Files;
use crate::door;
use crate::error::CliError;
use crate::output::{units_of, OutDir};
use afmdyn::analysis::stepped::SteppedCurve;
use afmdyn::request::present;
use afmdyn::request::present::curves::{stepped, CurveKind, CurveOptions};
use afmdyn::request::{Analysis, ApproachRequest, CurveRequest, Resolved, ResonanceRequest};
use afmdyn::study::stepped::{curve_store, CurveStudy};
use afmdyn::{Params, SimError};
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
    /// Measure every point on the exact periodic orbit of the common period, with branches
    /// and folds, even where a two-frequency drive repeats only after more than 32 drive
    /// periods (e.g. f2/f1 = 6.27 = 627/100), whose points are otherwise measured on the
    /// invariant circle of the stroboscopic map (the exact orbit where the circle is not
    /// smooth, as the warnings say)
    #[arg(long, conflicts_with = "average")]
    exact: bool,
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

/// The library's choice of files for `--files`.
pub(crate) fn files(f: Files) -> present::Files {
    match f {
        Files::All => present::Files::All,
        Files::Data => present::Files::Data,
        Files::None => present::Files::None,
    }
}

/// Lock the output directory, run the curve (resumable into its store, without files in
/// memory), then write the library's presentation through the door.
fn go<A: Analysis<Output = SteppedCurve>>(
    args: &CurveArgs,
    (out, stem): (&Path, &'static str),
    request: &A,
    model: &Resolved,
    study: impl FnOnce() -> Result<CurveStudy, SimError>,
    kind: CurveKind,
) -> Result<(), CliError> {
    request.validate(model)?;
    let out = (args.files != Files::None)
        .then(|| OutDir::lock(out))
        .transpose()?;
    let (c, json) = match &out {
        // no files: nothing to resume from
        None if args.resume => {
            return Err(CliError::Input(
                "--resume: --files none keeps no store to resume; use --files data or all".into(),
            ))
        }
        None => {
            let d = crate::progress::run(request, model, "points")?;
            (d.output, d.json)
        }
        Some(o) => {
            // the points in the directory's store, resumable; the branches after them
            let study = study()?;
            let mut store = curve_store(o.dir_lock());
            crate::progress::study(
                &study,
                &mut store,
                args.resume,
                None,
                "points",
                args.abort_after,
            )
            .map_err(|e| crate::error::study_error(e, stem))?;
            let records = store
                .records()
                .map_err(|e| crate::error::store_error(e, stem))?;
            let c = crate::progress::with_bar("branch points", |p| study.curve(records, p))?;
            let json = afmdyn::request::run::document(request, model, &c)?;
            (c, json)
        }
    };
    let options = CurveOptions {
        stem,
        files: files(args.files),
        dforce_columns: args.dforce_columns,
    };
    let units = units_of(model.probe.as_ref());
    let shown = stepped(kind, model, &c, &json, units, &options);
    door::emit(out.as_ref(), &shown, &json, args.json)
}

/// The model of the flags, with `--from`/`--to` checked finite.
fn setup(model: &ModelArgs, from: Option<f64>, to: Option<f64>) -> Result<Resolved, CliError> {
    let (params, probe) = model.resolve(Params::default())?;
    check_finite("--from", from)?;
    check_finite("--to", to)?;
    Ok(Resolved { params, probe })
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
    let model = setup(&a.model, from, to)?;
    let request = ApproachRequest {
        curve: a.curve.request(from, to, Dim::Length, si)?,
        setpoint: a.setpoint,
        average: false,
        exact: false,
    };
    let study = || CurveStudy::approach(&request, &model);
    let out = (a.out.as_path(), "approach");
    go(&a.curve, out, &request, &model, study, CurveKind::Approach)
}

/// Run `afmdyn bimodal`: the approach curve of a multifrequency drive
/// ([`afmdyn::request::curves::check_bimodal`]), its files `bimodal.*`.
pub fn bimodal(a: &BimodalArgs) -> Result<(), CliError> {
    let si = a.model.probe.is_some();
    let (from, to) = a.range.ends(si)?;
    let model = setup(&a.model, from, to)?;
    afmdyn::request::curves::check_bimodal(&model.params)?;
    let request = ApproachRequest {
        curve: a.curve.request(from, to, Dim::Length, si)?,
        setpoint: a.setpoint,
        average: a.average,
        exact: a.exact,
    };
    let study = || CurveStudy::approach(&request, &model);
    let out = (a.out.as_path(), "bimodal");
    go(&a.curve, out, &request, &model, study, CurveKind::Approach)
}

/// Run `afmdyn resonance`.
pub fn resonance(a: &ResonanceArgs) -> Result<(), CliError> {
    let si = a.model.probe.is_some();
    let from = quantity(a.from, "from", Dim::Frequency, si)?;
    let to = quantity(a.to, "to", Dim::Frequency, si)?;
    let model = setup(&a.model, from, to)?;
    let request = ResonanceRequest {
        mode: a.mode,
        curve: a.curve.request(from, to, Dim::Frequency, si)?,
    };
    let study = || CurveStudy::resonance(&request, &model);
    let out = (a.out.as_path(), "resonance");
    go(&a.curve, out, &request, &model, study, CurveKind::Resonance)
}
