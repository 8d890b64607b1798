//! `afmdyn bifurcation` and `afmdyn attractors`.

use crate::args::{IntegratorArgs, ModelArgs};
use crate::error::CliError;
use crate::output::{f, io_error, temp_path, write_bytes, write_csv, Column, NpyStream, OutDir};
use crate::plot::{save, save_scatter_stream, ChunkSink, Figure, LegendEntry, Series, Style};
use afmdyn::analysis::attractors::find_attractors;
use afmdyn::analysis::bifurcation::{run_sweep, Branch, Resume, SweepPoint, SweepSpec};
use afmdyn::integrate::build;
use afmdyn::request::limits::ATTRACTOR_SAMPLES_PER_PERIOD;
use afmdyn::request::{AttractorsRequest, BifurcationRequest, SteadyRequest};
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

/// Key of a row group (one sweep task): (index, branch).
fn row_key(line: &str) -> Option<(usize, Branch)> {
    let mut cells = line.split(',').skip(COL_INDEX);
    let index = cells.next()?.parse().ok()?;
    let branch = cells.next()?.parse().ok()?;
    Some((index, branch))
}

/// A task's rows in the partial file: key, byte range, lines.
type Group = ((usize, Branch), std::ops::Range<u64>, Vec<String>);

/// Complete groups of rows of the partial file, in file order.
/// A group is complete when all its `points` rows are present in order and newline-terminated
/// (a killed run may leave a cut row or an unfinished group at the end).
fn partial_groups(path: &Path) -> Result<(String, Vec<Group>), CliError> {
    let rd = |e| io_error("read", path, e);
    let mut reader = BufReader::new(File::open(path).map_err(rd)?);
    let mut header = String::new();
    let mut groups = Vec::new();
    let mut group: Vec<String> = Vec::new();
    let mut start = 0u64;
    let mut pos = 0u64;
    let complete = |g: &[String]| {
        let cells: Vec<Vec<&str>> = g.iter().map(|l| l.split(',').collect()).collect();
        cells.iter().all(|c| c.len() == HEADER.len())
            && cells[0][COL_POINTS].parse::<usize>().ok() == Some(cells.len())
            && cells
                .iter()
                .enumerate()
                .all(|(i, c)| c[COL_POINT].parse::<usize>().ok() == Some(i))
    };
    let mut buf = Vec::new();
    loop {
        buf.clear();
        let n = reader.read_until(b'\n', &mut buf).map_err(rd)? as u64;
        if n == 0 || buf.last() != Some(&b'\n') {
            break; // end, or a cut row without its newline
        }
        let line = String::from_utf8_lossy(&buf[..buf.len() - 1]).to_string();
        if header.is_empty() {
            header = line;
            pos += n;
            start = pos;
            continue;
        }
        if group.first().and_then(|g| row_key(g)) != row_key(&line) && !group.is_empty() {
            if complete(&group) {
                let key = row_key(&group[0]).expect("checked");
                groups.push((key, start..pos, std::mem::take(&mut group)));
            }
            group.clear();
            start = pos;
        }
        group.push(line);
        pos += n;
    }
    if !group.is_empty() && complete(&group) {
        let key = row_key(&group[0]).expect("checked");
        groups.push((key, start..pos, group));
    }
    Ok((header, groups))
}

/// Rewrite the partial file keeping only complete tasks; collect what is done and the
/// continuation states.
fn scan_partial(path: &Path) -> Result<Resume, CliError> {
    let mut resume = Resume::default();
    let (header, groups) = partial_groups(path)?;
    let mut text = header + "\n";
    for ((index, branch), _, lines) in groups {
        resume.done.insert((index, branch));
        if matches!(branch, Branch::Forward | Branch::Backward) {
            let last: Vec<&str> = lines.last().expect("rows").split(',').collect();
            if last[COL_STATUS] != "error" {
                let state: Vec<f64> = last[COL_STATE]
                    .split(' ')
                    .filter_map(|v| v.parse().ok())
                    .collect();
                if !state.is_empty() {
                    resume
                        .chain
                        .insert(branch, (index, DVector::from_vec(state)));
                }
            }
        }
        for l in lines {
            text.push_str(&l);
            text.push('\n');
        }
    }
    write_bytes(path, text.as_bytes())?;
    Ok(resume)
}

/// Write the finished sweep to `final_csv` in a stable order — by value index, then forward,
/// backward, start 0, 1, … — whatever order the workers finished in, so that two runs with the
/// same arguments give identical files. Groups are copied by byte range (never all in memory).
fn finish_sorted(partial: &Path, final_csv: &Path) -> Result<(), CliError> {
    use std::io::{Read, Seek, SeekFrom};
    let (header, mut groups) = partial_groups(partial)?;
    groups.sort_by_key(|g| g.0);
    let rd = |e| io_error("read", partial, e);
    let mut src = File::open(partial).map_err(rd)?;
    let sorted = final_csv.with_file_name(".bifurcation.sorted.csv");
    let wr = |e| io_error("write", final_csv, e);
    {
        let mut out = std::io::BufWriter::new(File::create(&sorted).map_err(wr)?);
        writeln!(out, "{header}").map_err(wr)?;
        let mut buf = Vec::new();
        for (_, range, _) in &groups {
            buf.resize((range.end - range.start) as usize, 0);
            src.seek(SeekFrom::Start(range.start)).map_err(rd)?;
            src.read_exact(&mut buf).map_err(rd)?;
            out.write_all(&buf).map_err(wr)?;
        }
        out.into_inner()
            .map_err(|e| wr(e.into_error()))?
            .sync_all()
            .map_err(wr)?;
    }
    fs::rename(&sorted, final_csv).map_err(|e| io_error("finish", final_csv, e))?;
    fs::remove_file(partial).map_err(|e| io_error("remove", partial, e))
}

/// The arguments that determine a sweep's rows; a partial run is resumed only with the same.
fn fingerprint(a: &BifurcationArgs, spec: &SweepSpec) -> serde_json::Value {
    json!({
        "afmdyn": env!("CARGO_PKG_VERSION"),
        "params": spec.base,
        "param": spec.param.name(),
        "from": a.from,
        "to": a.to,
        "steps": a.steps,
        "continuation": spec.continuation,
        "starts": spec.starts,
        "seed": spec.seed,
        "tol": spec.steady.tol,
        "max_periods": spec.steady.max_periods,
        "max_period": spec.steady.max_period,
        "integrator": spec.integrator.kind,
        "steps_per_period": spec.integrator.steps_per_period,
        "tolerance": spec.integrator.tolerance,
    })
}

/// Where a sweep stands in its output directory.
enum SweepState {
    Fresh,
    Partial(Resume),
    Finished,
}

/// The ledger `.bifurcation.run.json`: the fingerprint of the run that owns the directory's
/// partial and final CSV, and whether it finished.
fn read_ledger(path: &Path) -> Result<Option<serde_json::Value>, CliError> {
    match fs::read_to_string(path) {
        Ok(t) => serde_json::from_str(&t)
            .map(Some)
            .map_err(|e| CliError::Input(format!("{}: {e}", path.display()))),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(io_error("read", path, e)),
    }
}

fn write_ledger(path: &Path, args: &serde_json::Value, finished: bool) -> Result<(), CliError> {
    let doc = json!({ "args": args, "finished": finished });
    write_bytes(
        path,
        (serde_json::to_string_pretty(&doc).expect("json") + "\n").as_bytes(),
    )
}

/// Decide how a `--resume` proceeds, refusing to mix in a run made with other arguments.
fn resume_state(
    dir: &Path,
    ledger: &Path,
    partial: &Path,
    final_csv: &Path,
    args: &serde_json::Value,
) -> Result<SweepState, CliError> {
    let have_data = partial.exists() || final_csv.exists();
    let Some(doc) = read_ledger(ledger)? else {
        if have_data {
            return Err(CliError::Input(format!(
                "--resume: {} has sweep results but no record of the arguments that made them \
                 ({} is missing); rerun without --resume to start over",
                dir.display(),
                ledger.display()
            )));
        }
        return Ok(SweepState::Fresh);
    };
    let old = &doc["args"];
    if old != args {
        let differ: Vec<String> = args
            .as_object()
            .into_iter()
            .flatten()
            .filter(|(k, v)| old.get(k.as_str()) != Some(*v))
            .map(|(k, v)| {
                format!(
                    "{k} = {} there, {v} here",
                    old.get(k.as_str()).unwrap_or(&json!(null))
                )
            })
            .collect();
        return Err(CliError::Input(format!(
            "--resume: the sweep in {} was made with other arguments ({}); rerun with the same \
             arguments, or without --resume to start over",
            dir.display(),
            differ.join("; ")
        )));
    }
    if partial.exists() {
        return Ok(SweepState::Partial(scan_partial(partial)?));
    }
    if doc["finished"] == json!(true) && final_csv.exists() {
        return Ok(SweepState::Finished);
    }
    Ok(SweepState::Fresh)
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
    let rd = |e| io_error("read", path, e);
    let mut rd_csv = csv::Reader::from_path(path).map_err(rd)?;
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
    let final_csv = out.join("bifurcation.csv");
    let partial = temp_path(&final_csv);
    let ledger = out.join(".bifurcation.run.json");
    let args = fingerprint(a, &spec);
    let state = if a.resume {
        resume_state(out.path(), &ledger, &partial, &final_csv, &args)?
    } else {
        SweepState::Fresh
    };
    let resume = match state {
        SweepState::Finished => None,
        SweepState::Partial(r) => Some(r),
        SweepState::Fresh => {
            // the old partial goes first, then the ledger names the new run
            if partial.exists() {
                fs::remove_file(&partial).map_err(|e| io_error("remove", &partial, e))?;
            }
            write_ledger(&ledger, &args, false)?;
            let mut f = File::create(&partial).map_err(|e| io_error("create", &partial, e))?;
            writeln!(f, "{}", HEADER.join(",")).map_err(|e| io_error("write", &partial, e))?;
            Some(Resume::default())
        }
    };
    if let Some(resume) = resume {
        let file = OpenOptions::new()
            .append(true)
            .open(&partial)
            .map_err(|e| io_error("open", &partial, e))?;
        let writer = Mutex::new(std::io::BufWriter::new(file));
        let tasks = spec.values.len() * (usize::from(spec.continuation) * 2 + spec.starts as usize);
        let bar = ProgressBar::new(tasks as u64);
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} points  {elapsed} / ~{duration}")
                .expect("template"),
        );
        bar.inc(resume.done.len() as u64);
        let failed = Mutex::new(None::<String>);
        let written = std::sync::atomic::AtomicUsize::new(0);
        let sink = |p: SweepPoint| {
            let rows = point_rows(spec.param, &p);
            let mut w = writer.lock().expect("writer");
            let mut text = String::new();
            for r in rows {
                text.push_str(&r.join(","));
                text.push('\n');
            }
            if let Err(e) = w.write_all(text.as_bytes()).and_then(|_| w.flush()) {
                failed.lock().expect("flag").get_or_insert(e.to_string());
            }
            bar.inc(1);
            let n = written.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1;
            if a.abort_after == Some(n) {
                std::process::abort();
            }
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(a.threads.unwrap_or(0))
            .build()
            .map_err(|e| CliError::Io(format!("cannot start worker threads: {e}")))?;
        pool.install(|| run_sweep(&spec, &resume, &sink));
        bar.finish_and_clear();
        if let Some(e) = failed.into_inner().expect("flag") {
            return Err(io_error("write", &partial, e));
        }
        writer
            .into_inner()
            .expect("writer")
            .flush()
            .map_err(|e| io_error("write", &partial, e))?;
        finish_sorted(&partial, &final_csv)?;
        write_ledger(&ledger, &args, true)?;
    }
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
    read_rows(&final_csv, &mut |r| {
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
    write_bifurcation_npy(&final_csv, &out.join("bifurcation.npy"), a.param.name())?;
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
        "npy": out.join("bifurcation.npy"),
    });
    summary = afmdyn::report::with_si(summary, probe.as_ref(), &base);
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
            out.path().display()
        );
    }
    Ok(())
}

/// Columns of `bifurcation.npy` (the numeric columns of `bifurcation.csv`, codes for the text).
fn bifurcation_npy_columns(param: &str) -> Vec<Column> {
    vec![
        Column::new(
            "value",
            "as the parameter",
            format!("value of the swept parameter ({param})"),
        ),
        Column::new(
            "index",
            "count",
            "index of the value in the sweep (0-based)",
        ),
        Column::new(
            "branch",
            "code",
            "0 forward continuation, 1 backward, 2 + k random start k",
        ),
        Column::new(
            "period",
            "drive periods",
            "period n of a periodic motion; −1 nonperiodic; −2 failed point",
        ),
        Column::new(
            "point",
            "count",
            "index of the Poincaré point in the recorded cycle",
        ),
        Column::new(
            "tau",
            "τ",
            "time of the Poincaré point (a multiple of the drive period 2π/Ω)",
        ),
        Column::new("v_t", "g0", "V_T at the Poincaré point (eq. 8)"),
        Column::new("w_tip", "g0", "tip deflection W(1,τ) at the Poincaré point"),
        Column::new(
            "x_max",
            "g0",
            "largest tip deflection W(1,τ) over the recorded steady state",
        ),
        Column::new(
            "v_t_min",
            "g0",
            "smallest V_T over the recorded steady state (≤ 0: contact)",
        ),
        Column::new("contact_fraction", "1", "fraction of the time in contact"),
        Column::new(
            "contacts_per_period",
            "1/period",
            "contact entries per drive period",
        ),
    ]
}

fn write_bifurcation_npy(csv_path: &Path, npy: &Path, param: &str) -> Result<(), CliError> {
    let rd = |e| io_error("read", csv_path, e);
    let mut reader = csv::Reader::from_path(csv_path).map_err(rd)?;
    let mut s = NpyStream::create(npy, bifurcation_npy_columns(param))?;
    for r in reader.records() {
        let r = r.map_err(rd)?;
        let num = |i: usize| r[i].parse::<f64>().unwrap_or(f64::NAN);
        let branch: Branch = r[COL_BRANCH].parse().unwrap_or(Branch::Start(u32::MAX));
        s.push(&[
            num(COL_VALUE),
            num(COL_INDEX),
            branch_code(branch),
            status_code(&r[COL_STATUS], &r[COL_PERIOD]),
            num(COL_POINT),
            num(8),
            num(9),
            num(COL_W_TIP),
            num(COL_X_MAX),
            num(12),
            num(13),
            num(14),
        ])?;
    }
    s.finish()
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
    let (p, probe) = a.model.resolve(Params::default())?;
    let spp = ATTRACTOR_SAMPLES_PER_PERIOD;
    let spec = AttractorsRequest {
        samples: a.samples,
        seed: a.seed,
        cluster_tol: a.cluster_tol,
        steady: a.steady.request(),
        integrator: a.integrator.request(),
    }
    .spec(&p)?;
    let out = OutDir::lock(&a.out)?;
    let report = find_attractors(&spec)?;
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
                title: format!("Attractor {} ({label}): phase plane", k + 1),
                x_label: "W(1,τ)".into(),
                y_label: "∂W(1,τ)/∂τ".into(),
                series,
                shade: vec![],
            },
        )?;
    }
    let mut doc = afmdyn::report::attractors(&p, a.samples, &report);
    doc = afmdyn::report::with_si(doc, probe.as_ref(), &p);
    write_bytes(
        &out.join("attractors.json"),
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
        println!("outputs in {}", out.path().display());
    }
    Ok(())
}
