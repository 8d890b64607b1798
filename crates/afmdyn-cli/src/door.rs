//! The one door of the command line: a request is validated and held to the budgets, its
//! `--out` directory locked, it runs with a progress bar ([`progress::run`]), and its presentation
//! ([`afmdyn::report::Presentation`], built by the library) is written: the document's
//! warnings on stderr, every file into the directory (CSV, NetCDF, JSON, figures through the
//! one plotting module), then the JSON document (`--json`) or the text summary on stdout.

use crate::error::CliError;
use crate::output::{print_warnings, units_of, write_layout, OutDir};
use crate::progress;
use afmdyn::layout::files::{write_bytes, write_csv, NpyStream};
use afmdyn::report::{OutputFile, OutputsNote, Presentation};
use afmdyn::request::present::Files;
use afmdyn::request::{Analysis, Document, Resolved};
use serde_json::Value;
use std::path::Path;

/// How a command's results leave: the JSON document on stdout instead of the summary, and the
/// output directory of its files (none: a command that writes none).
#[derive(Debug, Clone, Copy)]
pub struct Exit<'a> {
    /// Print the JSON document.
    pub json: bool,
    /// The output directory.
    pub out: Option<&'a Path>,
    /// The files written there (`--files`): all, the data without the figures, or none.
    pub files: Files,
    /// What the progress bar counts ("points", "starts").
    pub unit: &'static str,
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
    let mut shown = request.present(
        model,
        &doc.output,
        &doc.json,
        units_of(model.probe.as_ref()),
    )?;
    decorate(&mut shown);
    // --files: the figures (data) or every file (none) left out
    match exit.files {
        Files::All => {}
        Files::Data => shown
            .files
            .retain(|f| !matches!(f, OutputFile::Figure { .. })),
        Files::None => shown.files.clear(),
    }
    emit(out.as_ref(), &shown, &doc.json, exit.json)?;
    Ok(doc)
}

/// Write a presentation: `document`'s warnings on stderr, the files into `out`, then the
/// document (`json`) or the summary and where the outputs are on stdout.
///
/// # Errors
/// [`CliError::Io`] naming a file or stream that cannot be written.
pub fn emit(
    out: Option<&OutDir>,
    shown: &Presentation,
    document: &Value,
    json: bool,
) -> Result<(), CliError> {
    emit_as(out, shown, document, json, false)
}

/// [`emit`]; `inline`: the summary's last line ends with `; outputs in DIR` instead of a line
/// of its own (the one-line summaries of `chart` and `basins`).
///
/// # Errors
/// As [`emit`].
pub fn emit_as(
    out: Option<&OutDir>,
    shown: &Presentation,
    document: &Value,
    json: bool,
    inline: bool,
) -> Result<(), CliError> {
    print_warnings(document)?;
    if let Some(out) = out {
        write_files(out, shown)?;
    }
    if json {
        outln!("{document}");
        return Ok(());
    }
    let dir = out.filter(|_| !shown.files.is_empty()).map(OutDir::path);
    let lines = if inline && dir.is_some() {
        // the one-line summaries: `…; outputs in DIR`
        let tail = Presentation {
            summary: shown.summary.clone(),
            outputs_note: OutputsNote::Tail,
            ..Presentation::default()
        };
        tail.summary_with(dir)
    } else {
        shown.summary_with(dir)
    };
    for line in lines {
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
