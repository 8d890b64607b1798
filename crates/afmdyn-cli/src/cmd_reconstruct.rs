//! `afmdyn reconstruct`: the tip–sample force and potential behind a frequency-modulation
//! curve by the Sader–Jarvis inversion. The request, the inversion and the document are the
//! library's ([`afmdyn::request::ReconstructRequest`], [`afmdyn::analysis::reconstruct`]);
//! this front end reads the curve's CSV, maps the flags, and writes `reconstruct.csv`, the
//! force plot and the JSON document.

use crate::args::{quantity, Dim, Quantity};
use crate::cmd_simulate::Files;
use crate::error::CliError;
use crate::output::{si_value, write_csv_numbers, write_document, OutDir};
use crate::plot::{save, Figure, Series, Style};
use afmdyn::analysis::reconstruct::Reconstruction;
use afmdyn::io::{InputFileError, InputKind};
use afmdyn::request::{self, ReconstructRequest, Resolved};
use clap::Args;
use std::path::{Path, PathBuf};

/// `afmdyn reconstruct` flags.
#[derive(Debug, Args)]
pub struct ReconstructArgs {
    /// The frequency-shift curve: the JSON document of `afmdyn fm --probe` (fm.json: its
    /// distances of closest approach, shifts, k, f0 and A), or a CSV with a header naming
    /// `frequency_shift` (Hz) and `distance` (m, closest approach) or `z_c` (m, rest distance:
    /// d = z_c − A)
    #[arg(
        long,
        value_name = "FILE",
        required_unless_present = "am",
        conflicts_with = "am"
    )]
    fm: Option<PathBuf>,
    /// Instead of an FM curve, an AM curve: the JSON document of `afmdyn approach --probe` on
    /// the point-mass model (approach.json); its attractive run (phase lag above 90°) is
    /// inverted at each point's amplitude (the matrix method)
    #[arg(long, value_name = "FILE")]
    am: Option<PathBuf>,
    /// Spring constant k (N/m; typical 0.01–1e6, refused outside 1e-6–1e9); required with a
    /// CSV, replaces the document's
    #[arg(long, conflicts_with = "am", allow_hyphen_values = true)]
    spring_constant: Option<f64>,
    /// Free resonance frequency f0 (Hz; a unit may follow: 300kHz; typical 1 kHz–10 MHz,
    /// refused outside 1 Hz–10 GHz); required with a CSV, replaces the document's
    #[arg(long, conflicts_with = "am", allow_hyphen_values = true)]
    resonance_frequency: Option<Quantity>,
    /// Oscillation amplitude A (m; a unit may follow: 10nm; typical 10 pm–1 µm, refused
    /// outside 1 fm–1 mm); required with a CSV, replaces the document's
    #[arg(long, conflicts_with = "am", allow_hyphen_values = true)]
    amplitude: Option<Quantity>,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/reconstruct")]
    out: PathBuf,
    /// Files written: all (data and plots), data (no plots) or none (only the summary)
    #[arg(long, value_enum, default_value = "all")]
    files: Files,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// An input file's refusal as bad input naming the option (`--fm FILE: …`).
fn input(option: &str, e: InputFileError) -> CliError {
    CliError::Input(format!("{option} {e}"))
}

/// The curve's columns by name from the CSV `path`, read through the bounded reader
/// ([`InputKind::CurveCsv`]).
fn read_curve(path: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), CliError> {
    let bad = |what: String| CliError::Input(format!("--fm {}: {what}", path.display()));
    let csv_error = |e: csv::Error| match e.kind() {
        csv::ErrorKind::Io(io) => match afmdyn::io::refusal(io) {
            Some(r) => input("--fm", r.clone()),
            None => bad(e.to_string()),
        },
        _ => bad(e.to_string()),
    };
    let file = afmdyn::io::open(path, InputKind::CurveCsv).map_err(|e| input("--fm", e))?;
    let mut reader = csv::Reader::from_reader(file);
    let names: Vec<String> = reader
        .headers()
        .map_err(csv_error)?
        .iter()
        .map(|h| h.trim().to_string())
        .collect();
    let mut columns = vec![Vec::new(); names.len()];
    for (line, record) in reader.records().enumerate() {
        let record = record.map_err(csv_error)?;
        for (k, field) in record.iter().enumerate().take(names.len()) {
            let v: f64 = field.trim().parse().map_err(|_| {
                bad(format!(
                    "line {}: {} = {field:?} is not a number",
                    line + 2,
                    names[k]
                ))
            })?;
            columns[k].push(v);
        }
    }
    Ok((names, columns))
}

/// A JSON document (`--fm fm.json`, `--am approach.json`) parsed as it is read through the
/// bounded reader ([`InputKind::CurveDocument`]), from `reader` that has read none of it yet
/// beyond the whitespace [`first_byte`] skipped.
fn read_document(
    option: &str,
    path: &Path,
    reader: impl std::io::Read,
) -> Result<serde_json::Value, CliError> {
    serde_json::from_reader(reader).map_err(|e| {
        if e.is_io() {
            let io = std::io::Error::from(e);
            return match afmdyn::io::refusal(&io) {
                Some(r) => input(option, r.clone()),
                None => CliError::Input(format!("{option} {}: {io}", path.display())),
            };
        }
        CliError::Input(format!(
            "{option} {}: not a JSON document: {e}",
            path.display()
        ))
    })
}

/// The first byte of `reader` that is not ASCII whitespace, the whitespace before it consumed
/// (`None` at the end).
fn first_byte(reader: &mut impl std::io::BufRead) -> std::io::Result<Option<u8>> {
    loop {
        let buf = reader.fill_buf()?;
        if buf.is_empty() {
            return Ok(None);
        }
        match buf.iter().position(|b| !b.is_ascii_whitespace()) {
            Some(i) => {
                let b = buf[i];
                reader.consume(i);
                return Ok(Some(b));
            }
            None => {
                let n = buf.len();
                reader.consume(n);
            }
        }
    }
}

/// The bounded reader of `path` as `kind` and its first byte that is not whitespace.
fn open_document(
    option: &str,
    path: &Path,
) -> Result<(std::io::BufReader<afmdyn::io::Bounded>, Option<u8>), CliError> {
    let file = afmdyn::io::open(path, InputKind::CurveDocument).map_err(|e| input(option, e))?;
    let mut reader = std::io::BufReader::new(file);
    let first = first_byte(&mut reader).map_err(|e| match afmdyn::io::refusal(&e) {
        Some(r) => input(option, r.clone()),
        None => CliError::Input(format!("{option} {}: {e}", path.display())),
    })?;
    Ok((reader, first))
}

/// The request of the flags: from an `fm` JSON document, or from a CSV with k, f0 and A.
fn request_of(a: &ReconstructArgs, fm: &Path) -> Result<ReconstructRequest, CliError> {
    let k = a.spring_constant;
    let f0 = quantity(
        a.resonance_frequency,
        "resonance-frequency",
        Dim::Frequency,
        true,
    )?;
    let amp = quantity(a.amplitude, "amplitude", Dim::Length, true)?;
    // a constant ≤ 0 is refused here naming its flag (the library's ranges name the field)
    for (flag, v) in [
        ("spring-constant", k),
        ("resonance-frequency", f0),
        ("amplitude", amp),
    ] {
        if let Some(v) = v.filter(|v| *v <= 0.0) {
            return Err(CliError::Input(format!(
                "--{flag} = {}: must be > 0",
                afmdyn::error::number(v)
            )));
        }
    }
    let (reader, first) = open_document("--fm", fm)?;
    if first == Some(b'{') {
        let doc = read_document("--fm", fm, reader)?;
        return Ok(ReconstructRequest::from_fm_document(&doc, k, f0, amp)?);
    }
    drop(reader);
    let missing = |flag: &str| {
        CliError::Input(format!(
            "--{flag} is required with a CSV curve (an afmdyn fm document carries it)"
        ))
    };
    let (names, mut columns) = read_curve(fm)?;
    let mut take = |name: &str| {
        names
            .iter()
            .position(|n| n == name)
            .map(|k| std::mem::take(&mut columns[k]))
    };
    let frequency_shift = take("frequency_shift").ok_or_else(|| {
        CliError::Input(format!(
            "--fm {}: no frequency_shift column (the header has {})",
            fm.display(),
            names.join(", ")
        ))
    })?;
    Ok(ReconstructRequest {
        law_force: None,
        distance: take("distance"),
        z_c: take("z_c"),
        frequency_shift,
        spring_constant: k.ok_or_else(|| missing("spring-constant"))?,
        resonance_frequency: f0.ok_or_else(|| missing("resonance-frequency"))?,
        amplitude: amp.ok_or_else(|| missing("amplitude"))?,
    })
}

/// The reconstruction of an AM document (`--am FILE`) and its JSON document.
fn am_reconstruction(path: &Path) -> Result<(Reconstruction, serde_json::Value), CliError> {
    let (reader, _) = open_document("--am", path)?;
    let doc = read_document("--am", path, reader)?;
    let d = request::reconstruct::am_reconstruction(
        &doc,
        &afmdyn::analysis::progress::Progress::new(),
    )?;
    Ok((d.output, d.json))
}

/// A library error with the cantilever's constants spelled as their flags
/// (`--amplitude = 10: must be …`).
fn flagged(e: afmdyn::SimError) -> CliError {
    match &e {
        afmdyn::SimError::OutOfRange { name, .. }
            if ["amplitude", "resonance_frequency", "spring_constant"].contains(name) =>
        {
            CliError::Input(format!("--{}", crate::error::spell(&e)))
        }
        _ => e.into(),
    }
}

/// Run `afmdyn reconstruct`.
pub fn reconstruct(a: &ReconstructArgs) -> Result<(), CliError> {
    let (r, json, law) = match (&a.am, &a.fm) {
        (Some(path), _) => {
            let (r, json) = am_reconstruction(path)?;
            (r, json, None)
        }
        (None, Some(fm)) => {
            let request = request_of(a, fm)?;
            let model = Resolved::plain(afmdyn::Params::default());
            request::Analysis::validate(&request, &model).map_err(flagged)?;
            let doc = request::run(
                &request,
                &model,
                &afmdyn::analysis::progress::Progress::new(),
            )?;
            (doc.output, doc.json, request.law_in_order())
        }
        (None, None) => {
            return Err(CliError::Input(
                "give --fm FILE or --am FILE (the curve to invert)".into(),
            ))
        }
    };
    let out = match a.files {
        Files::None => None,
        _ => Some(OutDir::lock(&a.out)?),
    };
    finish(a, out.as_ref(), &r, json, law)
}

/// Write the outputs of reconstruction `r` and print its document or summary.
fn finish(
    a: &ReconstructArgs,
    out: Option<&OutDir>,
    r: &Reconstruction,
    mut json: serde_json::Value,
    law: Option<Vec<f64>>,
) -> Result<(), CliError> {
    if let Some(out) = out {
        let write = || -> Result<(), CliError> {
            write_csv_numbers(
                &out.join("reconstruct.csv"),
                &["distance", "force", "potential"],
                r.distance
                    .iter()
                    .zip(&r.force)
                    .zip(&r.potential)
                    .map(|((d, f), u)| [*d, *f, *u]),
            )?;
            let points = |ys: &[f64]| r.distance.iter().copied().zip(ys.iter().copied()).collect();
            if a.files != Files::All {
                return Ok(());
            }
            save(
                out.path(),
                "reconstruct-force",
                &Figure {
                    title: if a.am.is_some() {
                        "Tip–sample force from the AM curve (matrix method)".into()
                    } else {
                        "Tip–sample force by the Sader–Jarvis inversion".into()
                    },
                    x_label: "distance of closest approach d (m)".into(),
                    y_label: "force F (N)".into(),
                    series: std::iter::once(Series {
                        label: "reconstructed".into(),
                        points: points(&r.force),
                        style: Style::Line,
                        color: 0,
                    })
                    .chain(law.map(|law| Series {
                        label: "the model's force law".into(),
                        points: points(&law),
                        style: Style::Dashed,
                        color: 1,
                    }))
                    .collect(),
                    shade: Vec::new(),
                    y_min_span: 0.0,
                },
            )?;
            Ok(())
        };
        write()?;
        json["csv"] = serde_json::json!(out.join("reconstruct.csv"));
        write_document(out, "reconstruct.json", &json)?;
    }
    if a.json {
        outln!("{json}");
    } else {
        let (k, f) = r
            .force
            .iter()
            .enumerate()
            .min_by(|x, y| x.1.total_cmp(y.1))
            .map_or((0, f64::NAN), |(k, f)| (k, *f));
        outln!(
            "{} distances from {} to {}: most attractive force {} at d = {}; {}",
            r.distance.len(),
            si_value(r.distance[0], "m"),
            si_value(r.distance[r.distance.len() - 1], "m"),
            si_value(f, "N"),
            si_value(r.distance.get(k).copied().unwrap_or(f64::NAN), "m"),
            out.map_or("no files written".into(), |o| format!(
                "outputs in {}",
                o.path().display()
            ))
        );
    }
    Ok(())
}
