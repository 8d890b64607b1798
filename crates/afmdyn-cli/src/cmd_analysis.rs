//! `afmdyn bifurcation` and `afmdyn attractors`.

use crate::args::{IntegratorArgs, ModelArgs};
use crate::error::CliError;
use crate::output::{f, io_error, write_bytes, write_csv, OutDir};
use crate::plot::{
    save, save_scatter_stream, save_stacked, ChunkSink, Figure, IdSeries, LegendEntry, Series,
    StackedFractions, Style,
};
use afmdyn::integrate::build;
use afmdyn::request::checkpoint::CheckpointError;
use afmdyn::request::limits::ATTRACTOR_SAMPLES_PER_PERIOD;
use afmdyn::request::sweep::{
    status_code, sweep_failure, COL_BRANCH, COL_MESSAGE, COL_PERIOD, COL_POINT, COL_STATUS,
    COL_X_MAX,
};
use afmdyn::request::{
    AttractorsRequest, BifurcationRequest, FileCheckpoint, GlobalContinuationRequest, SteadyRequest,
};
use afmdyn::request::{Document, Resolved};
use afmdyn::study::global_continuation::{continuation_store, ContinuationStudy};
use afmdyn::study::sweep::SweepStudy;
use afmdyn::trajectory::{record, RecordSpec};
use afmdyn::{CantileverModel, Params, SweepParam};
use clap::Args;
use serde_json::json;
use std::path::{Path, PathBuf};

/// Steady-state flags.
#[derive(Debug, Clone, Args)]
pub struct SteadyArgs {
    /// Relative tolerance for returns of the stroboscopic map to coincide
    #[arg(long, default_value_t = SteadyRequest::default().tol)]
    tol: f64,
    /// Cap on the transient, in drive periods [default: derived from the model's slowest free
    /// decay: six times the periods it takes to decay by --tol, at least 1500; ≈ 1.9 Q
    /// ln(1/tol) for a lever of quality factor Q]
    #[arg(long)]
    max_periods: Option<usize>,
    /// Largest period searched (≤ 64)
    #[arg(long, default_value_t = SteadyRequest::default().max_period)]
    max_period: usize,
}

impl SteadyArgs {
    /// The library's request ([`SteadyRequest::options`] validates it).
    pub fn request(&self) -> SteadyRequest {
        SteadyRequest {
            tol: self.tol,
            max_periods: self.max_periods,
            max_period: self.max_period,
        }
    }
}

/// `afmdyn bifurcation` flags.
#[derive(Debug, Args)]
pub struct BifurcationArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    integrator: IntegratorArgs,
    #[command(flatten)]
    steady: SteadyArgs,
    /// Swept parameter: omega, alpha1..alpha6 (or tip-mass-ratio, drive-amplitude, …)
    #[arg(long, default_value = "omega")]
    param: SweepParam,
    /// First value
    #[arg(long, default_value_t = BifurcationRequest::default().from, allow_negative_numbers = true)]
    from: f64,
    /// Last value
    #[arg(long, default_value_t = BifurcationRequest::default().to, allow_negative_numbers = true)]
    to: f64,
    /// Number of values
    #[arg(long, default_value_t = BifurcationRequest::default().steps)]
    steps: usize,
    /// Random initial states per value (in addition to continuation)
    #[arg(long, default_value_t = BifurcationRequest::default().starts)]
    starts: u32,
    /// Seed of the random initial states
    #[arg(long, default_value_t = BifurcationRequest::default().seed)]
    seed: u64,
    /// Only random starts, no forward/backward continuation
    #[arg(long)]
    no_continuation: bool,
    /// Worker threads (default: all cores)
    #[arg(long)]
    threads: Option<usize>,
    /// Continue an interrupted sweep; refused unless the other arguments are those of the
    /// interrupted run (recorded in OUT/.bifurcation.run.json)
    #[arg(long)]
    resume: bool,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out")]
    out: PathBuf,
    /// Testing: abort the process, as if killed, after this many points are written
    #[arg(long, hide = true)]
    abort_after: Option<usize>,
    /// Print one JSON summary
    #[arg(long)]
    json: bool,
}

/// Column positions in the library's sweep records (also read by `afmdyn continue --overlay`).
pub(crate) use afmdyn::request::sweep::{COL_VALUE, COL_W_TIP};

/// The command line's message for a checkpoint error (`--resume` names the flag) of a store of
/// `what` (`sweep`, `chart`) results.
pub(crate) fn store_error(e: CheckpointError, what: &str) -> CliError {
    match e {
        CheckpointError::Io { .. } => CliError::Io(e.to_string()),
        CheckpointError::Mismatch { field, then, now } => CliError::Input(format!(
            "--resume: {} = {then} in the interrupted run, {now} now; rerun with the same \
             arguments, or without --resume to start over",
            field.replace('_', "-")
        )),
        CheckpointError::Unrecorded { store, ledger } => CliError::Input(format!(
            "--resume: {store} has {what} results but no record of the arguments that made them \
             ({ledger} is missing); rerun without --resume to start over"
        )),
        CheckpointError::Corrupt { .. } => CliError::Input(e.to_string()),
    }
}

/// The command line's message for a study that stopped ([`store_error`] for its store).
pub(crate) fn study_error(e: afmdyn::study::StudyError, what: &str) -> CliError {
    match e {
        afmdyn::study::StudyError::Store(e) => store_error(e, what),
        afmdyn::study::StudyError::Sim(e) => CliError::Sim(e),
    }
}

fn period_color(period: f64) -> usize {
    match period as i64 {
        1 => 0,
        2 => 1,
        3 => 2,
        4 => 3,
        5..=8 => 4,
        9..=64 => 5,
        _ => 7,
    }
}

fn read_rows(
    path: &Path,
    each: &mut dyn FnMut(&csv::StringRecord) -> Result<(), String>,
) -> Result<(), CliError> {
    // a refusal of the bounded reader (past the cap, not a store's CSV) is the input's fault:
    // exit code 2, the store left as it is
    let refused = |e: afmdyn::io::InputFileError| match e {
        afmdyn::io::InputFileError::Io { message, .. } => io_error("read", path, message),
        e => CliError::Input(format!("{e}; rerun without --resume to start over")),
    };
    let rd = |e: csv::Error| {
        if let csv::ErrorKind::Io(io) = e.kind() {
            if let Some(r) = afmdyn::io::refusal(io) {
                return refused(r.clone());
            }
        }
        io_error("read", path, e)
    };
    // the sweep's own output, read back through the bounded reader as a store file
    let file = afmdyn::io::open(path, afmdyn::io::InputKind::Store).map_err(refused)?;
    let mut rd_csv = csv::Reader::from_reader(file);
    for r in rd_csv.records() {
        let r = r.map_err(rd)?;
        each(&r).map_err(CliError::Io)?;
    }
    Ok(())
}

/// Run `afmdyn bifurcation`.
pub fn bifurcation(a: &BifurcationArgs) -> Result<(), CliError> {
    let (base, probe) = a.model.resolve(Params::default())?;
    let request = BifurcationRequest {
        param: a.param,
        values: None,
        from: a.from,
        to: a.to,
        steps: a.steps,
        starts: a.starts,
        seed: a.seed,
        continuation: !a.no_continuation,
        threads: a.threads,
        steady: a.steady.request(),
        integrator: a.integrator.request(),
    };
    let spec = request
        .spec(&base)
        .map_err(|e| CliError::Input(crate::error::spell(&e)))?;
    let out = OutDir::lock(&a.out)?;
    let mut store = FileCheckpoint::new(out.dir_lock());
    let final_csv = store.final_csv();
    let study = SweepStudy::new(&request, spec.clone());
    crate::progress::study(
        &study,
        &mut store,
        a.resume,
        a.threads,
        "points",
        a.abort_after,
    )
    .map_err(|e| study_error(e, "sweep"))?;
    // derived files, streamed from the finished CSV
    let mut b = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    let (mut periodic, mut nonperiodic, mut errors) = (0usize, 0usize, 0usize);
    let mut first_error: Option<String> = None;
    // the colours of the period classes drawn: the legend lists only those (issue 28)
    let mut drawn = std::collections::HashSet::new();
    read_rows(&final_csv, &mut |r| {
        let v: f64 = r[COL_VALUE].parse().unwrap_or(f64::NAN);
        let w: f64 = r[COL_W_TIP].parse().unwrap_or(f64::NAN);
        let x: f64 = r[COL_X_MAX].parse().unwrap_or(f64::NAN);
        if w.is_finite() || x.is_finite() {
            drawn.insert(period_color(status_code(&r[COL_STATUS], &r[COL_PERIOD])));
        }
        if r[COL_POINT] == *"0" {
            match &r[COL_STATUS] {
                "periodic" => periodic += 1,
                "nonperiodic" => nonperiodic += 1,
                _ => {
                    errors += 1;
                    first_error.get_or_insert_with(|| r[COL_MESSAGE].to_string());
                }
            }
        }
        if w.is_finite() {
            b = (
                b.0.min(v),
                b.1.max(v),
                b.2.min(w),
                b.3.max(w),
                b.4.min(x),
                b.5.max(x),
            );
        }
        Ok(())
    })?;
    let npy = store.write_npy(a.param)?;
    let sym = a.param.symbol();
    let legend: Vec<LegendEntry> = [
        ("period 1", 1.0),
        ("period 2", 2.0),
        ("period 3", 3.0),
        ("period 4", 4.0),
        ("period 5–8", 5.0),
        ("period 9–64", 9.0),
        ("nonperiodic", -1.0),
    ]
    .iter()
    .map(|(l, p)| (l.to_string(), period_color(*p), true))
    .filter(|(_, c, _)| drawn.contains(c))
    .collect();
    let mut branch_legend: Vec<LegendEntry> = Vec::new();
    if spec.continuation {
        branch_legend.push(("forward continuation".into(), 0, true));
        branch_legend.push(("backward continuation".into(), 1, true));
    }
    if spec.starts > 0 {
        branch_legend.push((
            format!("random starts ({} per value)", spec.starts),
            7,
            true,
        ));
    }
    for (stem, col, title, ylab, by_branch) in [
        (
            "bifurcation",
            COL_W_TIP,
            "Bifurcation diagram: Poincaré points (drive phase 0)",
            "W(1,τ) at τ = 2πk/Ω",
            false,
        ),
        (
            "bifurcation-branches",
            COL_W_TIP,
            "Poincaré points by how they were reached",
            "W(1,τ) at τ = 2πk/Ω",
            true,
        ),
        (
            "bifurcation-xmax",
            COL_X_MAX,
            "Bifurcation diagram: X_max",
            "X_max",
            false,
        ),
    ] {
        let bounds = if col == COL_W_TIP {
            (b.0, b.1, b.2, b.3)
        } else {
            (b.0, b.1, b.4, b.5)
        };
        let bounds = if bounds.0.is_finite() {
            bounds
        } else {
            (0.0, 1.0, 0.0, 1.0)
        };
        let leg = if by_branch { &branch_legend } else { &legend };
        let feed = |draw: &mut ChunkSink<'_>| -> Result<(), CliError> {
            let mut chunk = Vec::with_capacity(4096);
            read_rows(&final_csv, &mut |r| {
                let v: f64 = r[COL_VALUE].parse().unwrap_or(f64::NAN);
                let y: f64 = r[col].parse().unwrap_or(f64::NAN);
                if !y.is_finite() {
                    return Ok(());
                }
                let c = if by_branch {
                    match &r[COL_BRANCH] {
                        "forward" => 0,
                        "backward" => 1,
                        _ => 7,
                    }
                } else {
                    period_color(status_code(&r[COL_STATUS], &r[COL_PERIOD]))
                };
                chunk.push((v, y, c));
                if chunk.len() == chunk.capacity() {
                    draw(&chunk)?;
                    chunk.clear();
                }
                Ok(())
            })?;
            draw(&chunk).map_err(CliError::Io)
        };
        save_scatter_stream(
            out.path(),
            stem,
            title,
            (&format!("{} ({})", sym, a.param.name()), ylab),
            bounds,
            leg,
            &feed,
        )?;
    }
    let mut summary = json!({
        "params": base,
        "param": a.param.name(),
        "values": spec.values.len(),
        "periodic": periodic,
        "nonperiodic": nonperiodic,
        "errors": errors,
        "csv": final_csv,
        "npy": npy,
    });
    summary = afmdyn::report::with_si(summary, probe.as_ref(), &base);
    // the exit-code rule (docs/outputs.md): failed points are reported on stderr too, and a
    // sweep with no point computed has no answer (exit 1)
    let failed = sweep_failure(periodic + nonperiodic, errors, first_error.as_deref());
    if let Some(e) = failed {
        if a.json {
            outln!("{summary}");
        }
        return Err(CliError::Sim(e));
    }
    if let Some(first) = &first_error {
        errln!(
            "afmdyn: warning: {errors} of {} sweep points failed; the first: {first}",
            periodic + nonperiodic + errors
        );
    }
    if a.json {
        outln!("{summary}");
    } else {
        outln!(
            "{} values of {}: {} periodic, {} nonperiodic, {} failed points; outputs in {}",
            spec.values.len(),
            a.param.name(),
            periodic,
            nonperiodic,
            errors,
            out.path().display()
        );
    }
    Ok(())
}

/// `afmdyn attractors` flags.
#[derive(Debug, Args)]
pub struct AttractorsArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    integrator: IntegratorArgs,
    #[command(flatten)]
    steady: SteadyArgs,
    /// Number of random initial states
    #[arg(long, default_value_t = AttractorsRequest::default().samples)]
    samples: usize,
    /// Seed of the initial states
    #[arg(long, default_value_t = AttractorsRequest::default().seed)]
    seed: u64,
    /// Relative tolerance for two Poincaré point sets to be the same attractor
    #[arg(long, default_value_t = AttractorsRequest::default().cluster_tol)]
    cluster_tol: f64,
    /// Continue the attractors over this parameter (omega, alpha1..alpha6): a census at every
    /// value, seeded from the previous value's attractors and matched to them (global
    /// continuation); needs --from and --to
    #[arg(long, requires_all = ["from", "to"])]
    sweep: Option<SweepParam>,
    /// First value of --sweep
    #[arg(long, allow_negative_numbers = true, requires = "sweep")]
    from: Option<f64>,
    /// Last value of --sweep
    #[arg(long, allow_negative_numbers = true, requires = "sweep")]
    to: Option<f64>,
    /// Number of values of --sweep
    #[arg(long, default_value_t = GlobalContinuationRequest::default().steps, requires = "sweep")]
    steps: usize,
    /// Largest relative distance between the Poincaré point sets of two attractors at
    /// consecutive values of --sweep that are one attractor
    #[arg(long, default_value_t = GlobalContinuationRequest::default().match_tol, requires = "sweep")]
    match_tol: f64,
    /// Continue an interrupted --sweep; refused unless the other arguments are those of the
    /// interrupted run (recorded in OUT/.continuation.run.json)
    #[arg(long, requires = "sweep")]
    resume: bool,
    /// Testing: abort the process, as if killed, after this many values of --sweep are stored
    #[arg(long, hide = true, requires = "sweep")]
    abort_after: Option<usize>,
    /// Output directory
    #[arg(long, default_value = "afmdyn-out/attractors")]
    out: PathBuf,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn attractors`.
pub fn attractors(a: &AttractorsArgs) -> Result<(), CliError> {
    let (p, probe) = a.model.resolve(Params::default())?;
    let spp = ATTRACTOR_SAMPLES_PER_PERIOD;
    let request = AttractorsRequest {
        samples: a.samples,
        seed: a.seed,
        cluster_tol: a.cluster_tol,
        steady: a.steady.request(),
        integrator: a.integrator.request(),
    };
    if let Some(param) = a.sweep {
        let sweep = GlobalContinuationRequest {
            param,
            values: None,
            from: a.from.unwrap_or(f64::NAN),
            to: a.to.unwrap_or(f64::NAN),
            steps: a.steps,
            match_tol: a.match_tol,
            samples: request.samples,
            seed: request.seed,
            cluster_tol: request.cluster_tol,
            steady: request.steady,
            integrator: request.integrator,
        };
        return attractors_sweep(a, &sweep, Resolved { params: p, probe });
    }
    let spec = request.spec(&p)?;
    let out = OutDir::lock(&a.out)?;
    let u = crate::output::units_of(probe.as_ref());
    let Document {
        output: report,
        json: doc,
    } = crate::progress::run(&request, &Resolved { params: p, probe }, "starts")?;
    let model = CantileverModel::new(&p)?;
    for (k, att) in report.attractors.iter().enumerate() {
        let periods = att.steady.period().unwrap_or(8).max(2);
        let z0 = att.steady.end_state().clone();
        let tau0 = att.steady.poincare.last().map_or(0.0, |q| q.tau);
        let mut integ = build(&model, spec.integrator.clone(), tau0, &z0)?;
        let tr = record(
            integ.as_mut(),
            &RecordSpec {
                transient_periods: 0.0,
                record_tau: periods as f64 * p.period(),
                samples_per_period: spp,
                energy: false,
                body_contact: false,
            },
        )?;
        let stem = format!("attractor-{}", k + 1);
        write_csv(
            &out.join(format!("{stem}.csv")),
            &["tau", "v_t", "w_tip", "w_tip_dot", "in_contact"],
            tr.samples.iter().map(|s| {
                vec![
                    f(s.tau),
                    f(s.v_t),
                    f(s.w_tip),
                    f(s.w_tip_dot),
                    u8::from(s.region == afmdyn::Region::Contact).to_string(),
                ]
            }),
        )?;
        let label = match att.steady.period() {
            Some(n) => format!("period-{n}"),
            None => "nonperiodic".into(),
        };
        save(
            out.path(),
            &format!("{stem}-time"),
            &Figure {
                y_min_span: 0.0,
                title: format!(
                    "Attractor {} ({label}, basin {:.1} %), Ω = {}",
                    k + 1,
                    100.0 * att.basin_fraction,
                    p.omega
                ),
                x_label: "τ".into(),
                y_label: "W(1,τ)".into(),
                series: vec![Series {
                    label: String::new(),
                    points: tr.samples.iter().map(|s| (s.tau, s.w_tip)).collect(),
                    style: Style::Line,
                    color: k,
                }],
                shade: vec![],
            },
        )?;
        let mut series = vec![Series {
            label: String::new(),
            points: tr.samples.iter().map(|s| (s.w_tip, s.w_tip_dot)).collect(),
            style: Style::Line,
            color: k,
        }];
        series.push(Series {
            label: "Poincaré points".into(),
            points: att
                .steady
                .poincare
                .iter()
                .map(|q| (q.w_tip, model.w_tip_dot(&q.state)))
                .collect(),
            style: Style::Points,
            color: if k % 10 == 3 { 4 } else { 3 },
        });
        save(
            out.path(),
            &format!("{stem}-phase"),
            &Figure {
                y_min_span: 0.0,
                title: format!("Attractor {} ({label}): phase plane", k + 1),
                x_label: "W(1,τ)".into(),
                y_label: "∂W(1,τ)/∂τ".into(),
                series,
                shade: vec![],
            },
        )?;
    }
    if let Some(first) = report.failures.first() {
        errln!(
            "afmdyn: warning: {} of {} random starts failed; the first: {first}",
            report.failures.len(),
            a.samples
        );
    }
    write_bytes(
        &out.join("attractors.json"),
        serde_json::to_string_pretty(&doc).expect("json").as_bytes(),
    )?;
    for w in report.warnings() {
        errln!("afmdyn: warning: {w}");
    }
    if a.json {
        outln!("{doc}");
    } else {
        outln!(
            "{} attractors from {} starts ({} failed) at {}{}:",
            report.attractors.len(),
            a.samples,
            report.failures.len(),
            u.drive(p.omega),
            if u.si() {
                format!(", z_c = {}", u.length(p.rest_distance()))
            } else {
                String::new()
            }
        );
        for (k, x) in report.attractors.iter().enumerate() {
            // lengths in g0, or in m with a probe (13.4747 nm)
            let length = |v: f64| {
                if u.si() {
                    u.length(v)
                } else {
                    format!("{v:.4}")
                }
            };
            outln!(
                "  {}: {:<12} basin {:>5.1} %  X_max = {}  min V_T = {}  contact fraction {:.3}{}",
                k + 1,
                x.steady
                    .period()
                    .map_or("nonperiodic".into(), |n| format!("period-{n}")),
                100.0 * x.basin_fraction,
                length(x.steady.stats.x_max),
                length(x.steady.stats.v_t_min),
                x.steady.stats.contact_fraction,
                if x.steady.stats.body_contact {
                    "  (beam body touches the substrate: Fig. 2f)"
                } else {
                    ""
                }
            );
        }
        for x in &report.unsettled {
            outln!(
                "  unsettled: {} start(s) still converging after {} periods (λ₁ = {:.3e})",
                x.count,
                report.transient_cap,
                x.lyapunov.map_or(f64::NAN, |l| l.0)
            );
        }
        outln!("outputs in {}", out.path().display());
    }
    Ok(())
}

/// `afmdyn attractors --sweep`: the global continuation, its table, figure and document.
fn attractors_sweep(
    a: &AttractorsArgs,
    request: &GlobalContinuationRequest,
    model: Resolved,
) -> Result<(), CliError> {
    let study = ContinuationStudy::new(request, &model.params)?;
    let out = OutDir::lock(&a.out)?;
    let mut store = continuation_store(out.dir_lock());
    crate::progress::study(&study, &mut store, a.resume, None, "starts", a.abort_after)
        .map_err(|e| study_error(e, "attractors --sweep"))?;
    let records = store
        .records()
        .map_err(|e| store_error(e, "attractors --sweep"))?;
    let steps = study.steps(records)?;
    let doc = afmdyn::request::run::document(request, &model, &steps)?;
    let name = request.param.name();
    let mut rows = Vec::new();
    for s in &steps {
        for (id, x) in &s.attractors {
            rows.push(vec![
                f(s.value),
                id.to_string(),
                x.steady
                    .period()
                    .map_or("nonperiodic".into(), |n| n.to_string()),
                f(x.basin_fraction),
                f(x.steady.stats.x_max),
                f(x.steady.stats.v_t_min),
                f(x.steady.stats.contact_fraction),
                x.orbit
                    .as_ref()
                    .map_or(String::new(), |o| u8::from(o.stable).to_string()),
            ]);
        }
    }
    write_csv(
        &out.join("attractors-sweep.csv"),
        &[
            name,
            "id",
            "period",
            "basin_fraction",
            "x_max",
            "v_t_min",
            "contact_fraction",
            "stable",
        ],
        rows,
    )?;
    crate::output::write_layout(
        &out.join("attractors-sweep.nc"),
        &afmdyn::report::global_continuation_layout(request.param, &steps),
    )?;
    let ids = doc["ids"].as_u64().unwrap_or(0) as usize;
    let per_id: Vec<IdSeries> = (0..ids)
        .map(|id| {
            let points: Vec<Option<(f64, f64)>> = steps
                .iter()
                .map(|s| {
                    s.attractors
                        .iter()
                        .find(|(i, _)| *i == id)
                        .map(|(_, x)| (x.basin_fraction, x.steady.stats.x_max))
                })
                .collect();
            let periods: std::collections::BTreeSet<String> = steps
                .iter()
                .flat_map(|s| s.attractors.iter().filter(|(i, _)| *i == id))
                .map(|(_, x)| {
                    x.steady
                        .period()
                        .map_or("nonperiodic".into(), |n| format!("P{n}"))
                })
                .collect();
            let kinds: Vec<String> = periods.into_iter().collect();
            (format!("attractor {id}: {}", kinds.join(", ")), points)
        })
        .collect();
    save_stacked(
        out.path(),
        "attractors-sweep",
        &StackedFractions {
            title: format!(
                "Attractors over {} ({} random starts per value)",
                request.param.symbol(),
                request.samples
            ),
            x_label: request.param.symbol().into(),
            values: steps.iter().map(|s| s.value).collect(),
            ids: per_id,
        },
    )?;
    write_bytes(
        &out.join("attractors-sweep.json"),
        serde_json::to_string_pretty(&doc).expect("json").as_bytes(),
    )?;
    for w in doc["warnings"].as_array().into_iter().flatten() {
        errln!("afmdyn: warning: {}", w.as_str().unwrap_or_default());
    }
    if a.json {
        outln!("{doc}");
    } else {
        outln!(
            "{ids} attractors over {} values of {name} ({} random starts each):",
            steps.len(),
            request.samples
        );
        for s in &steps {
            let line: Vec<String> = s
                .attractors
                .iter()
                .map(|(id, x)| {
                    format!(
                        "#{id} {} {:.1} %",
                        x.steady
                            .period()
                            .map_or("nonperiodic".into(), |n| format!("P{n}")),
                        100.0 * x.basin_fraction
                    )
                })
                .collect();
            // 10 significant digits: a linspace value such as 1.7999999999999998 reads 1.8
            let value: f64 = format!("{:.9e}", s.value).parse().unwrap_or(s.value);
            outln!("  {name} = {value:<10} {}", line.join("  "));
        }
        outln!("outputs in {}", out.path().display());
    }
    Ok(())
}
