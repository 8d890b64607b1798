//! The one door of the command line, for every subcommand: a request is validated and held
//! to the budgets (admitted once), its `--out` directory locked, it runs with a progress bar
//! ([`run`]; a study resumably into the directory's store, [`run_stored`]: the library's
//! [`afmdyn::study::stored::Resumable`], `--resume` and `--abort-after` included), and its
//! presentation ([`afmdyn::report::Presentation`], built by the library for the destination)
//! is written: its warnings and the document's on stderr, every file into the directory (CSV,
//! NetCDF, JSON, figures through the one plotting module), then the JSON document (`--json`)
//! or the text summary on stdout.

use crate::error::study_error;
use crate::error::CliError;
use crate::output::{print_warnings, units_of, write_layout, OutDir};
use crate::progress;
use afmdyn::layout::files::{write_bytes, write_csv, NpyStream};
use afmdyn::report::present::Files;
use afmdyn::report::{OutputFile, Presentation};
use afmdyn::request::{Analysis, Destination, Document, Presenting, Resolved};
use afmdyn::study::stored::{Resumable, Storage};
use serde_json::Value;
use std::path::Path;

/// How a command's results leave: the JSON document on stdout instead of the summary, and the
/// output directory of its files (none: a command that writes none).
#[derive(Debug, Clone, Copy, Default)]
pub struct Exit<'a> {
    /// Print the JSON document.
    pub json: bool,
    /// The output directory.
    pub out: Option<&'a Path>,
    /// The files written there (`--files`): all, the data without the figures, or none.
    pub files: Files,
    /// What the progress bar counts ("points", "starts").
    pub unit: &'static str,
    /// A stepped curve's columns named as dForce 2.0's (`--dforce-columns`).
    pub dforce_columns: bool,
}

/// How a study runs into the store of `--out`: continued (`--resume`), the testing hook
/// `--abort-after`, and what the store holds in the refusals of a resume (`sweep`, `chart`).
#[derive(Debug, Clone, Copy)]
pub struct Resume {
    /// Continue the interrupted run.
    pub resume: bool,
    /// Testing: abort the process once this many tasks are stored.
    pub abort_after: Option<usize>,
    /// The store's results, in its refusals.
    pub what: &'static str,
}

/// Run `request` on `model` through the door and write its presentation; the typed result
/// and its document are returned for a command that adds to them.
///
/// # Errors
/// The request's validation and run errors; [`CliError::Input`] when `--out` is held by
/// another run; [`CliError::Io`] naming a file that cannot be written.
pub fn run<A: Analysis>(
    request: &A,
    model: &Resolved,
    exit: Exit<'_>,
) -> Result<Document<A::Output>, CliError> {
    run_with(request, model, exit, |_| {})
}

/// [`run`], with `decorate` adding to the presentation before it is written (a front end's
/// own underlay in a figure).
///
/// # Errors
/// As [`run`].
pub fn run_with<A: Analysis>(
    request: &A,
    model: &Resolved,
    exit: Exit<'_>,
    decorate: impl FnOnce(&mut Presentation),
) -> Result<Document<A::Output>, CliError> {
    // validated and held to the budgets before the output directory is created or locked
    afmdyn::request::run::admit(request, model)?;
    let out = exit.out.map(OutDir::lock).transpose()?;
    let doc = progress::run_admitted(request, model, exit.unit)?;
    let mut shown = present(request, model, &doc.output, &doc.json, out.as_ref(), exit)?;
    decorate(&mut shown);
    emit(out.as_ref(), &shown, &doc.json, exit.json)?;
    Ok(doc)
}

/// Run `request`'s study on `model` resumably into the store of `--out` (the library's
/// [`Resumable`]: in memory without a directory), then write its presentation as [`run`]
/// does; a result that is no answer ([`Resumable::failure`]) has its files written (and its
/// document printed where it says so), then fails.
///
/// # Errors
/// As [`run`]; the store's refusals of a resume naming `how.what`.
pub fn run_stored<A: Resumable>(
    request: &A,
    model: &Resolved,
    exit: Exit<'_>,
    how: Resume,
) -> Result<(), CliError> {
    afmdyn::request::run::admit(request, model)?;
    let out = exit.out.map(OutDir::lock).transpose()?;
    let study = request.study(model)?;
    let storage = Storage {
        lock: out.as_ref().map(OutDir::dir_lock),
        resume: how.resume,
        abort_after: how.abort_after,
    };
    let output = progress::with_bar(exit.unit, |p| request.resume(&study, model, storage, p))
        .map_err(|e| study_error(e, how.what))?;
    let json = afmdyn::request::run::document(request, model, &output)?;
    let shown = present(request, model, &output, &json, out.as_ref(), exit)?;
    if let Some(failed) = request.failure(&output) {
        // the files are written, then the run fails (exit 1): the document first, if asked for
        if let Some(out) = &out {
            write_files(out, &shown)?;
        }
        if failed.with_document && exit.json {
            outln!("{json}");
        }
        return Err(failed.error.into());
    }
    emit(out.as_ref(), &shown, &json, exit.json)
}

/// The library's presentation of `output` at the command's destination.
fn present<A: Analysis>(
    request: &A,
    model: &Resolved,
    output: &A::Output,
    document: &Value,
    out: Option<&OutDir>,
    exit: Exit<'_>,
) -> Result<Presentation, CliError> {
    let to = Destination {
        files: exit.files,
        dir: out.map(OutDir::path),
        dforce_columns: exit.dforce_columns,
    };
    let units = units_of(model.probe.as_ref());
    let at = Presenting {
        model,
        document,
        units,
        to,
    };
    let mut shown = request.present(output, at)?;
    to.keep(&mut shown);
    Ok(shown)
}

/// Write a presentation: its warnings and `document`'s on stderr, the files into `out`, then
/// the document (`json`; the presentation's own where it has one) or the summary and where
/// the outputs are on stdout.
///
/// # Errors
/// [`CliError::Io`] naming a file or stream that cannot be written.
pub fn emit(
    out: Option<&OutDir>,
    shown: &Presentation,
    document: &Value,
    json: bool,
) -> Result<(), CliError> {
    let document = shown.document.as_ref().unwrap_or(document);
    for w in &shown.warnings {
        errln!("afmdyn: warning: {w}");
    }
    print_warnings(document)?;
    if let Some(out) = out {
        write_files(out, shown)?;
    }
    if json {
        outln!("{document}");
        return Ok(());
    }
    let dir = out.filter(|_| !shown.files.is_empty()).map(OutDir::path);
    for line in shown.summary_with(dir) {
        outln!("{line}");
    }
    Ok(())
}

/// Every file of a presentation written atomically into `out` (their stale temporary files
/// removed first).
///
/// # Errors
/// [`CliError::Io`] naming a file.
pub fn write_files(out: &OutDir, shown: &Presentation) -> Result<(), CliError> {
    let names = shown.file_names();
    out.remove_partials(&names.iter().map(String::as_str).collect::<Vec<_>>())?;
    for file in &shown.files {
        write_file(out, file)?;
    }
    Ok(())
}

/// One output file written atomically into `out`.
///
/// # Errors
/// [`CliError::Io`] naming the file.
pub fn write_file(out: &OutDir, file: &OutputFile) -> Result<(), CliError> {
    match file {
        OutputFile::Csv { name, header, rows } => {
            let header: Vec<&str> = header.iter().map(String::as_str).collect();
            write_csv(&out.join(name), &header, rows.iter().cloned())?;
        }
        OutputFile::Dataset { name, layout } => write_layout(&out.join(name), layout)?,
        OutputFile::Text { name, text } => write_bytes(&out.join(name), text.as_bytes())?,
        OutputFile::Figure { stem, plot } => crate::plot::save_plot(out.path(), stem, plot)?,
        OutputFile::Npy {
            name,
            columns,
            rows,
        } => {
            let mut npy = NpyStream::create(&out.join(name), columns.clone())?;
            for r in rows {
                npy.push(r)?;
            }
            npy.finish()?;
        }
        OutputFile::Json { name, value } => write_bytes(
            &out.join(name),
            serde_json::to_string_pretty(value)
                .expect("a JSON value serialises")
                .as_bytes(),
        )?,
    }
    Ok(())
}
