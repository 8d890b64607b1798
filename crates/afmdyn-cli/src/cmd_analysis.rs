//! `afmdyn bifurcation` and `afmdyn attractors`.

use crate::args::ModelArgs;
use crate::error::{store_error, study_error, CliError};
use crate::flags::{AttractorsFlags, AttractorsSweepFlags, BifurcationFlags};
use crate::output::{io_error, units_of, OutDir};
use crate::plot::{save_scatter_stream, ChunkSink};
use afmdyn::request::present::census::failed_starts;
use afmdyn::request::present::sweeps::{
    branch_legend, diagram_point, SweepRow, SweepTally, BIFURCATION_FIGURES,
};
use afmdyn::request::Analysis;
use afmdyn::request::{Document, Resolved};
use afmdyn::request::{FileCheckpoint, GlobalContinuationRequest};
use afmdyn::request::{Params, SweepParam};
use afmdyn::study::global_continuation::{continuation_store, ContinuationStudy};
use afmdyn::study::sweep::SweepStudy;
use clap::Args;
use serde_json::json;
use std::path::{Path, PathBuf};

/// `afmdyn bifurcation` flags.
#[derive(Debug, Args)]
pub struct BifurcationArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: BifurcationFlags,
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

/// Each row of the store's CSV `path`, read back through the bounded reader as a store file.
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
    let file = afmdyn::io::open(path, afmdyn::io::InputKind::Store).map_err(refused)?;
    let mut rd_csv = csv::Reader::from_reader(file);
    for r in rd_csv.records() {
        let r = r.map_err(rd)?;
        each(&r).map_err(CliError::Io)?;
    }
    Ok(())
}

/// Run `afmdyn bifurcation`: its cost checked by the library, the sweep run resumably into
/// the store in `--out`, the diagrams streamed from the store's CSV.
pub fn bifurcation(a: &BifurcationArgs) -> Result<(), CliError> {
    let (base, probe) = a.model.resolve(Params::default())?;
    let request = a.request.request();
    let spec = request
        .spec(&base)
        .map_err(|e| CliError::Input(crate::error::spell(&e)))?;
    afmdyn::request::admit(&request, &Resolved::plain(base))?;
    let out = OutDir::lock(&a.out)?;
    let mut store = FileCheckpoint::new(out.dir_lock());
    let final_csv = store.final_csv();
    let study = SweepStudy::new(&request, spec.clone());
    crate::progress::study(
        &study,
        &mut store,
        a.resume,
        request.threads,
        "points",
        a.abort_after,
    )
    .map_err(|e| study_error(e, "sweep"))?;
    // derived files, streamed from the finished CSV
    let mut tally = SweepTally::default();
    read_rows(&final_csv, &mut |r| {
        tally.add_row(SweepRow::from_csv(r));
        Ok(())
    })?;
    let npy = store.write_npy(request.param)?;
    let branches = branch_legend(spec.continuation, spec.starts);
    for (stem, col, title, ylab, by_branch) in BIFURCATION_FIGURES {
        let feed = |draw: &mut ChunkSink<'_>| -> Result<(), CliError> {
            let mut chunk = Vec::with_capacity(4096);
            read_rows(&final_csv, &mut |r| {
                chunk.extend(diagram_point(SweepRow::from_csv(r), col, by_branch));
                if chunk.len() == chunk.capacity() {
                    draw(&chunk)?;
                    chunk.clear();
                }
                Ok(())
            })?;
            draw(&chunk).map_err(CliError::Io)
        };
        let legend = if by_branch {
            branches.clone()
        } else {
            tally.legend()
        };
        let x_label = format!("{} ({})", request.param.symbol(), request.param.name());
        let (bounds, labels) = (tally.bounds(col), (x_label.as_str(), ylab));
        save_scatter_stream(out.path(), stem, title, labels, bounds, &legend, &feed)?;
    }
    let mut summary = tally.document(&base, request.param, spec.values.len());
    summary["csv"] = json!(final_csv);
    summary["npy"] = json!(npy);
    summary = afmdyn::report::with_si(summary, probe.as_ref(), &base);
    // the exit-code rule (docs/outputs.md): failed points are reported on stderr too, and a
    // sweep with no point computed has no answer (exit 1)
    if let Some(e) = tally.failure() {
        if a.json {
            outln!("{summary}");
        }
        return Err(CliError::Sim(e));
    }
    if let Some(w) = tally.warning() {
        errln!("afmdyn: warning: {w}");
    }
    if a.json {
        outln!("{summary}");
    } else {
        let line = tally.summary(spec.values.len(), request.param);
        outln!("{line}; outputs in {}", out.path().display());
    }
    Ok(())
}

/// `afmdyn attractors` flags.
#[derive(Debug, Args)]
pub struct AttractorsArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: AttractorsFlags,
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
    #[command(flatten)]
    sweep_flags: AttractorsSweepFlags,
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

/// Run `afmdyn attractors`: the census through the door (or its global continuation over
/// `--sweep`, run resumably into the store in `--out`), presented by the library.
pub fn attractors(a: &AttractorsArgs) -> Result<(), CliError> {
    let (params, probe) = a.model.resolve(Params::default())?;
    let model = Resolved { params, probe };
    let request = a.request.request();
    if let Some(param) = a.sweep {
        let sweep = GlobalContinuationRequest {
            param,
            values: None,
            from: a.from.unwrap_or(f64::NAN),
            to: a.to.unwrap_or(f64::NAN),
            steps: a.sweep_flags.steps,
            match_tol: a.sweep_flags.match_tol,
            samples: request.samples,
            seed: request.seed,
            cluster_tol: request.cluster_tol,
            steady: request.steady,
            integrator: request.integrator,
        };
        return attractors_sweep(a, &sweep, &model);
    }
    request.validate(&model)?;
    let out = OutDir::lock(&a.out)?;
    let Document { output, json } = crate::progress::run(&request, &model, "starts")?;
    let shown = request.present(&model, &output, &json, units_of(model.probe.as_ref()))?;
    if let Some(w) = failed_starts(&output, request.samples) {
        errln!("afmdyn: warning: {w}");
    }
    crate::door::emit(Some(&out), &shown, &json, a.json)
}

/// `afmdyn attractors --sweep`: the global continuation run resumably into the store in
/// `--out`, presented by the library.
fn attractors_sweep(
    a: &AttractorsArgs,
    request: &GlobalContinuationRequest,
    model: &Resolved,
) -> Result<(), CliError> {
    let study = ContinuationStudy::new(request, &model.params)?;
    afmdyn::request::admit(request, model)?;
    let out = OutDir::lock(&a.out)?;
    let mut store = continuation_store(out.dir_lock());
    crate::progress::study(&study, &mut store, a.resume, None, "starts", a.abort_after)
        .map_err(|e| study_error(e, "attractors --sweep"))?;
    let records = store
        .records()
        .map_err(|e| store_error(e, "attractors --sweep"))?;
    let steps = study.steps(records)?;
    let doc = afmdyn::request::run::document(request, model, &steps)?;
    let shown = request.present(model, &steps, &doc, units_of(model.probe.as_ref()))?;
    crate::door::emit(Some(&out), &shown, &doc, a.json)
}
