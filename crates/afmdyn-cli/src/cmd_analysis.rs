//! `afmdyn bifurcation` and `afmdyn attractors`.

use crate::args::{IntegratorArgs, ModelArgs};
use crate::error::CliError;
use crate::output::{ensure_dir, f, temp_path, write_bytes, write_csv, write_npy};
use crate::plot::{save, save_scatter_stream, ChunkSink, Figure, Series, Style};
use afmdyn::analysis::attractors::{find_attractors, AttractorSpec};
use afmdyn::analysis::bifurcation::{run_sweep, Branch, Resume, SweepPoint, SweepSpec};
use afmdyn::analysis::steady::SteadyOptions;
use afmdyn::integrate::build;
use afmdyn::trajectory::{record, RecordSpec};
use afmdyn::{CantileverModel, Params, SweepParam};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use nalgebra::DVector;
use serde_json::json;
use std::fs::{self, File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Steady-state flags.
#[derive(Debug, Clone, Args)]
pub struct SteadyArgs {
    /// Relative tolerance for returns of the stroboscopic map to coincide
    #[arg(long, default_value_t = 1e-8)]
    tol: f64,
    /// Cap on the transient, in drive periods
    #[arg(long, default_value_t = 1500)]
    max_periods: usize,
    /// Largest period searched (≤ 64)
    #[arg(long, default_value_t = 64)]
    max_period: usize,
}

impl SteadyArgs {
    /// Steady-state options, validated.
    pub fn options(&self) -> Result<SteadyOptions, CliError> {
        if !(self.tol.is_finite() && self.tol > 0.0) {
            return Err(CliError::Input(format!(
                "tol = {}: must be finite and > 0",
                self.tol
            )));
        }
        if !(1..=64).contains(&self.max_period) {
            return Err(CliError::Input(format!(
                "max-period = {}: must be in 1..=64",
                self.max_period
            )));
        }
        if self.max_periods == 0 {
            return Err(CliError::Input("max-periods = 0: must be >= 1".into()));
        }
        Ok(SteadyOptions {
            tol: self.tol,
            max_periods: self.max_periods,
            max_period: self.max_period,
            ..SteadyOptions::default()
        })
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
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    from: f64,
    /// Last value
    #[arg(long, default_value_t = 5.0, allow_negative_numbers = true)]
    to: f64,
    /// Number of values
    #[arg(long, default_value_t = 400)]
    steps: usize,
    /// Random initial states per value (in addition to continuation)
    #[arg(long, default_value_t = 0)]
    starts: u32,
    /// Seed of the random initial states
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Only random starts, no forward/backward continuation
    #[arg(long)]
    no_continuation: bool,
    /// Worker threads (default: all cores)
    #[arg(long)]
    threads: Option<usize>,
    /// Continue an interrupted sweep with the same arguments
    #[arg(long)]
    resume: bool,
    /// Output directory
    #[arg(long, default_value = "afmdyn-out")]
    out: PathBuf,
    /// Print one JSON summary
    #[arg(long)]
    json: bool,
}

const HEADER: [&str; 18] = [
    "param",
    "value",
    "index",
    "branch",
    "status",
    "period",
    "point",
    "points",
    "tau",
    "v_t",
    "w_tip",
    "x_max",
    "v_t_min",
    "contact_fraction",
    "contacts_per_period",
    "transient_periods",
    "message",
    "state",
];

/// Column positions in [`HEADER`] (also read by `afmdyn continue --overlay`).
pub(crate) const COL_VALUE: usize = 1;
pub(crate) const COL_INDEX: usize = 2;
pub(crate) const COL_BRANCH: usize = 3;
pub(crate) const COL_STATUS: usize = 4;
pub(crate) const COL_PERIOD: usize = 5;
pub(crate) const COL_POINT: usize = 6;
pub(crate) const COL_POINTS: usize = 7;
pub(crate) const COL_W_TIP: usize = 10;
pub(crate) const COL_X_MAX: usize = 11;
pub(crate) const COL_STATE: usize = 17;

fn branch_code(b: Branch) -> f64 {
    match b {
        Branch::Forward => 0.0,
        Branch::Backward => 1.0,
        Branch::Start(k) => 2.0 + f64::from(k),
    }
}

fn point_rows(param: SweepParam, p: &SweepPoint) -> Vec<Vec<String>> {
    let base = |status: &str, period: String, i: usize, n: usize| {
        vec![
            param.name().to_string(),
            f(p.value),
            p.index.to_string(),
            p.branch.to_string(),
            status.to_string(),
            period,
            i.to_string(),
            n.to_string(),
        ]
    };
    match &p.result {
        Err(msg) => {
            let mut r = base("error", String::new(), 0, 1);
            r.extend(std::iter::repeat_n(String::new(), 8));
            r.push(msg.replace(['\n', ','], " "));
            r.push(String::new());
            vec![r]
        }
        Ok(s) => {
            let (status, period) = match s.period() {
                Some(n) => ("periodic", n.to_string()),
                None => ("nonperiodic", String::new()),
            };
            let n = s.poincare.len();
            s.poincare
                .iter()
                .enumerate()
                .map(|(i, q)| {
                    let mut r = base(status, period.clone(), i, n);
                    r.extend([
                        f(q.tau),
                        f(q.v_t),
                        f(q.w_tip),
                        f(s.stats.x_max),
                        f(s.stats.v_t_min),
                        f(s.stats.contact_fraction),
                        f(s.stats.contacts_per_period),
                        s.transient_periods.to_string(),
                        String::new(),
                        q.state
                            .iter()
                            .map(|v| format!("{v}"))
                            .collect::<Vec<_>>()
                            .join(" "),
                    ]);
                    r
                })
                .collect()
        }
    }
}

/// Rewrite the partial file keeping only complete tasks (all their `points` rows present, the
/// last line newline-terminated); collect what is done and the continuation states.
fn scan_partial(path: &Path) -> Result<Resume, CliError> {
    let mut resume = Resume::default();
    let text_ok = path.exists();
    if !text_ok {
        return Ok(resume);
    }
    let clean = temp_path(&path.with_file_name("resume-scan.csv"));
    {
        let reader = BufReader::new(File::open(path)?);
        let mut out = std::io::BufWriter::new(File::create(&clean)?);
        let mut group: Vec<String> = Vec::new();
        let mut lines = reader.split(b'\n').peekable();
        let mut first = true;
        let flush_group = |group: &mut Vec<String>,
                           out: &mut dyn Write,
                           resume: &mut Resume|
         -> Result<(), CliError> {
            if group.is_empty() {
                return Ok(());
            }
            let cells: Vec<Vec<&str>> = group.iter().map(|l| l.split(',').collect()).collect();
            let complete = cells.iter().all(|c| c.len() == HEADER.len())
                && cells[0][COL_POINTS].parse::<usize>().ok() == Some(cells.len())
                && cells
                    .iter()
                    .enumerate()
                    .all(|(i, c)| c[COL_POINT].parse::<usize>().ok() == Some(i));
            if complete {
                let index: usize = cells[0][COL_INDEX]
                    .parse()
                    .map_err(|_| CliError::Io("resume: bad index".into()))?;
                let branch: Branch = cells[0][COL_BRANCH].parse().map_err(CliError::Io)?;
                resume.done.insert((index, branch));
                if matches!(branch, Branch::Forward | Branch::Backward)
                    && cells[0][COL_STATUS] != "error"
                {
                    let state: Vec<f64> = cells.last().expect("rows")[COL_STATE]
                        .split(' ')
                        .filter_map(|v| v.parse().ok())
                        .collect();
                    if !state.is_empty() {
                        resume
                            .chain
                            .insert(branch, (index, DVector::from_vec(state)));
                    }
                }
                for l in group.iter() {
                    writeln!(out, "{l}")?;
                }
            }
            group.clear();
            Ok(())
        };
        while let Some(line) = lines.next() {
            let line = line?;
            let complete_line = lines.peek().is_some();
            if !complete_line {
                break; // the last piece has no newline: a partial row
            }
            let line = String::from_utf8_lossy(&line).to_string();
            if first {
                first = false;
                writeln!(out, "{line}")?;
                continue;
            }
            let key = |l: &str| l.split(',').skip(2).take(2).collect::<Vec<_>>().join(",");
            if let Some(g) = group.first() {
                if key(g) != key(&line) {
                    flush_group(&mut group, &mut out, &mut resume)?;
                }
            }
            group.push(line);
        }
        flush_group(&mut group, &mut out, &mut resume)?;
        out.flush()?;
    }
    fs::rename(&clean, path)?;
    Ok(resume)
}

fn status_code(status: &str, period: &str) -> f64 {
    match status {
        "periodic" => period.parse().unwrap_or(f64::NAN),
        "nonperiodic" => -1.0,
        _ => -2.0,
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
    let mut rd = csv::Reader::from_path(path)?;
    for r in rd.records() {
        let r = r?;
        each(&r).map_err(CliError::Io)?;
    }
    Ok(())
}

/// Run `afmdyn bifurcation`.
pub fn bifurcation(a: &BifurcationArgs) -> Result<(), CliError> {
    let base = a.model.params(Params::default())?;
    let values =
        SweepSpec::linspace(a.from, a.to, a.steps).map_err(|e| CliError::Input(e.to_string()))?;
    let spec = SweepSpec {
        base,
        param: a.param,
        values,
        continuation: !a.no_continuation,
        starts: a.starts,
        seed: a.seed,
        steady: a.steady.options()?,
        integrator: a.integrator.options(1),
    };
    spec.validate()
        .map_err(|e| CliError::Input(e.to_string()))?;
    if let Some(t) = a.threads {
        if t == 0 {
            return Err(CliError::Input("threads = 0: must be >= 1".into()));
        }
    }
    ensure_dir(&a.out)?;
    let final_csv = a.out.join("bifurcation.csv");
    let partial = temp_path(&final_csv);
    let resume = if a.resume {
        if !partial.exists() && final_csv.exists() {
            // already finished: redo only the derived files
            Resume {
                done: (0..spec.values.len())
                    .flat_map(|i| [(i, Branch::Forward), (i, Branch::Backward)])
                    .collect(),
                ..Resume::default()
            }
        } else {
            scan_partial(&partial)?
        }
    } else {
        Resume::default()
    };
    let finished_already = a.resume && !partial.exists() && final_csv.exists();
    if !finished_already {
        let fresh = !a.resume || !partial.exists();
        let mut file = OpenOptions::new()
            .create(true)
            .append(true)
            .truncate(false)
            .open(&partial)?;
        if fresh {
            file.set_len(0)?;
            writeln!(file, "{}", HEADER.join(","))?;
        }
        let writer = Mutex::new(std::io::BufWriter::new(file));
        let tasks = spec.values.len() * (usize::from(spec.continuation) * 2 + spec.starts as usize);
        let bar = ProgressBar::new(tasks as u64);
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} points  {elapsed} / ~{duration}")
                .expect("template"),
        );
        bar.inc(resume.done.len() as u64);
        let failed = Mutex::new(None::<String>);
        let sink = |p: SweepPoint| {
            let rows = point_rows(spec.param, &p);
            let mut w = writer.lock().expect("writer");
            let mut text = String::new();
            for r in rows {
                text.push_str(&r.join(","));
                text.push('\n');
            }
            if let Err(e) = w.write_all(text.as_bytes()).and_then(|_| w.flush()) {
                *failed.lock().expect("flag") = Some(e.to_string());
            }
            bar.inc(1);
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(a.threads.unwrap_or(0))
            .build()
            .map_err(|e| CliError::Io(e.to_string()))?;
        pool.install(|| run_sweep(&spec, &resume, &sink));
        bar.finish_and_clear();
        if let Some(e) = failed.into_inner().expect("flag") {
            return Err(CliError::Io(format!("writing {}: {e}", partial.display())));
        }
        writer.into_inner().expect("writer").flush()?;
        fs::rename(&partial, &final_csv)?;
    }
    // derived files, streamed from the finished CSV
    let mut rows = 0usize;
    let mut b = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    let (mut periodic, mut nonperiodic, mut errors) = (0usize, 0usize, 0usize);
    read_rows(&final_csv, &mut |r| {
        rows += 1;
        let v: f64 = r[COL_VALUE].parse().unwrap_or(f64::NAN);
        let w: f64 = r[COL_W_TIP].parse().unwrap_or(f64::NAN);
        let x: f64 = r[COL_X_MAX].parse().unwrap_or(f64::NAN);
        if r[COL_POINT] == *"0" {
            match &r[COL_STATUS] {
                "periodic" => periodic += 1,
                "nonperiodic" => nonperiodic += 1,
                _ => errors += 1,
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
    write_bifurcation_npy(&final_csv, &a.out.join("bifurcation.npy"), rows)?;
    let sym = a.param.symbol();
    let legend: Vec<(String, usize)> = [
        ("period 1", 1.0),
        ("period 2", 2.0),
        ("period 3", 3.0),
        ("period 4", 4.0),
        ("period 5–8", 5.0),
        ("period 9–64", 9.0),
        ("nonperiodic", -1.0),
    ]
    .iter()
    .map(|(l, p)| (l.to_string(), period_color(*p)))
    .collect();
    for (stem, col, title, ylab, by_branch) in [
        (
            "bifurcation",
            10usize,
            "Bifurcation diagram: Poincaré points (drive phase 0)",
            "W(1,τ) at τ = 2πk/Ω",
            false,
        ),
        (
            "bifurcation-branches",
            10usize,
            "Poincaré points: forward (blue), backward (red), random starts (grey)",
            "W(1,τ) at τ = 2πk/Ω",
            true,
        ),
        (
            "bifurcation-xmax",
            11usize,
            "Bifurcation diagram: X_max",
            "X_max",
            false,
        ),
    ] {
        let bounds = if col == 10 {
            (b.0, b.1, b.2, b.3)
        } else {
            (b.0, b.1, b.4, b.5)
        };
        let bounds = if bounds.0.is_finite() {
            bounds
        } else {
            (0.0, 1.0, 0.0, 1.0)
        };
        let leg = if by_branch { vec![] } else { legend.clone() };
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
            &a.out,
            stem,
            title,
            (&format!("{} ({})", sym, a.param.name()), ylab),
            bounds,
            &leg,
            &feed,
        )?;
    }
    let summary = json!({
        "params": base,
        "param": a.param.name(),
        "values": spec.values.len(),
        "periodic": periodic,
        "nonperiodic": nonperiodic,
        "errors": errors,
        "csv": final_csv,
        "npy": a.out.join("bifurcation.npy"),
    });
    if a.json {
        println!("{summary}");
    } else {
        println!(
            "{} values of {}: {} periodic, {} nonperiodic, {} failed points; outputs in {}",
            spec.values.len(),
            a.param.name(),
            periodic,
            nonperiodic,
            errors,
            a.out.display()
        );
    }
    Ok(())
}

fn write_bifurcation_npy(csv_path: &Path, npy: &Path, rows: usize) -> Result<(), CliError> {
    // columns: value, index, branch (0 fwd, 1 bwd, 2+k start k), period (−1 nonperiodic,
    // −2 error), point, tau, v_t, w_tip, x_max, v_t_min, contact_fraction, contacts_per_period
    let mut rd = csv::Reader::from_path(csv_path)?;
    let it = rd.records().filter_map(Result::ok).map(|r| {
        let num = |i: usize| r[i].parse::<f64>().unwrap_or(f64::NAN);
        let branch: Branch = r[COL_BRANCH].parse().unwrap_or(Branch::Start(u32::MAX));
        vec![
            num(1),
            num(2),
            branch_code(branch),
            status_code(&r[COL_STATUS], &r[COL_PERIOD]),
            num(6),
            num(8),
            num(9),
            num(10),
            num(11),
            num(12),
            num(13),
            num(14),
        ]
    });
    write_npy(npy, 12, it, rows)
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
    #[arg(long, default_value_t = 64)]
    samples: usize,
    /// Seed of the initial states
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Relative tolerance for two Poincaré point sets to be the same attractor
    #[arg(long, default_value_t = 1e-5)]
    cluster_tol: f64,
    /// Output directory
    #[arg(long, default_value = "afmdyn-out/attractors")]
    out: PathBuf,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn attractors`.
pub fn attractors(a: &AttractorsArgs) -> Result<(), CliError> {
    let p = a.model.params(Params::default())?;
    let spp = 200;
    let spec = AttractorSpec {
        params: p,
        samples: a.samples,
        seed: a.seed,
        cluster_tol: a.cluster_tol,
        steady: a.steady.options()?,
        integrator: a.integrator.options(spp),
    };
    let report = find_attractors(&spec)?;
    ensure_dir(&a.out)?;
    let model = CantileverModel::new(&p)?;
    for (k, att) in report.attractors.iter().enumerate() {
        let periods = att.steady.period().unwrap_or(8).max(2);
        let z0 = att.steady.end_state().clone();
        let tau0 = att.steady.poincare.last().map_or(0.0, |q| q.tau);
        let mut integ = build(&model, spec.integrator, tau0, &z0)?;
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
            &a.out.join(format!("{stem}.csv")),
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
            &a.out,
            &format!("{stem}-time"),
            &Figure {
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
            &a.out,
            &format!("{stem}-phase"),
            &Figure {
                title: format!("Attractor {} ({label}): phase plane", k + 1),
                x_label: "W(1,τ)".into(),
                y_label: "∂W(1,τ)/∂τ".into(),
                series,
                shade: vec![],
            },
        )?;
    }
    let doc = afmdyn::report::attractors(&p, a.samples, &report);
    write_bytes(
        &a.out.join("attractors.json"),
        serde_json::to_string_pretty(&doc).expect("json").as_bytes(),
    )?;
    if a.json {
        println!("{doc}");
    } else {
        println!(
            "{} attractors from {} starts ({} failed) at Ω = {}:",
            report.attractors.len(),
            a.samples,
            report.failures.len(),
            p.omega
        );
        for (k, x) in report.attractors.iter().enumerate() {
            println!(
                "  {}: {:<12} basin {:>5.1} %  X_max = {:.4}  min V_T = {:.4}  contact fraction {:.3}{}",
                k + 1,
                x.steady.period().map_or("nonperiodic".into(), |n| format!("period-{n}")),
                100.0 * x.basin_fraction,
                x.steady.stats.x_max,
                x.steady.stats.v_t_min,
                x.steady.stats.contact_fraction,
                if x.steady.stats.body_contact { "  (beam body touches the substrate: Fig. 2f)" } else { "" }
            );
        }
        println!("outputs in {}", a.out.display());
    }
    Ok(())
}
