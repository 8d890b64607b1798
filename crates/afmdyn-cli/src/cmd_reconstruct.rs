//! `afmdyn reconstruct`: the tip–sample force and potential behind a frequency-modulation
//! curve by the Sader–Jarvis inversion or its exact correction (`--inversion exact`). The request, the inversion and the document are the
//! library's ([`afmdyn::request::ReconstructRequest`], [`afmdyn::analysis::reconstruct`]),
//! and so are the reading of the curve file ([`afmdyn::io::curve_file`]), the summary,
//! `reconstruct.csv`, the force figure and the JSON document
//! ([`afmdyn::report::present::reconstruct`]); this front end maps the flags.

use crate::args::{named, quantity, Dim};
use crate::cmd_approach::files;
use crate::cmd_simulate::Files;
use crate::door::{self, Exit};
use crate::error::CliError;
use crate::flags_afm::ReconstructFlags;
use afmdyn::io::curve_file::{read_curve_file, read_document, CurveFile};
use afmdyn::io::InputFileError;
use afmdyn::request::reconstruct::{AmReconstruction, FmInversion};
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
    /// The request's flags: --spring-constant, --resonance-frequency, --amplitude, --inversion
    #[command(flatten)]
    request: ReconstructFlags,
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
fn input(option: &'static str) -> impl Fn(InputFileError) -> CliError {
    move |e| CliError::Input(format!("{option} {e}"))
}

/// The request of the flags: from an `fm` JSON document, or from a CSV with k, f0 and A.
fn request_of(a: &ReconstructArgs, fm: &Path) -> Result<ReconstructRequest, CliError> {
    let flags = &a.request;
    let k = flags.spring_constant;
    let f0 = quantity(
        flags.resonance_frequency,
        "resonance-frequency",
        Dim::Frequency,
        true,
    )?;
    let amp = quantity(flags.amplitude, "amplitude", Dim::Length, true)?;
    let inversion = named::<FmInversion>(&flags.inversion, "inversion")?;
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
    let (names, mut columns) = match read_curve_file(fm).map_err(input("--fm"))? {
        CurveFile::Document(doc) => {
            return Ok(ReconstructRequest {
                inversion,
                ..ReconstructRequest::from_fm_document(&doc, k, f0, amp)?
            })
        }
        CurveFile::Columns(names, columns) => (names, columns),
    };
    let missing = |flag: &str| {
        CliError::Input(format!(
            "--{flag} is required with a CSV curve (an afmdyn fm document carries it)"
        ))
    };
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
        inversion,
        law_force: None,
        distance: take("distance"),
        z_c: take("z_c"),
        frequency_shift,
        spring_constant: k.ok_or_else(|| missing("spring-constant"))?,
        resonance_frequency: f0.ok_or_else(|| missing("resonance-frequency"))?,
        amplitude: amp.ok_or_else(|| missing("amplitude"))?,
    })
}

/// A library error with the cantilever's constants spelled as their flags
/// (`--amplitude = 10: must be …`).
fn flagged(e: afmdyn::error::SimError) -> CliError {
    match &e {
        afmdyn::error::SimError::OutOfRange { name, .. }
            if ["amplitude", "resonance_frequency", "spring_constant"].contains(name) =>
        {
            CliError::Input(format!("--{}", crate::error::spell(&e)))
        }
        _ => e.into(),
    }
}

/// Run `afmdyn reconstruct` through the door: the FM curve's request, or the AM document's.
pub fn reconstruct(a: &ReconstructArgs) -> Result<(), CliError> {
    // no model: the curve carries the cantilever's constants
    let model = Resolved::plain(afmdyn::request::Params::default());
    let exit = Exit {
        json: a.json,
        out: (a.files != Files::None).then_some(a.out.as_path()),
        files: files(a.files),
        unit: "distances",
        ..Exit::default()
    };
    match (&a.am, &a.fm) {
        (Some(path), _) => {
            let doc = read_document(path).map_err(input("--am"))?;
            door::run(&AmReconstruction(doc), &model, exit).map(drop)
        }
        (None, Some(fm)) => {
            let request = request_of(a, fm)?;
            // the cantilever's constants refused naming their flags
            request::Request::validate(&request, &model).map_err(flagged)?;
            door::run(&request, &model, exit).map(drop)
        }
        (None, None) => Err(CliError::Input(
            "give --fm FILE or --am FILE (the curve to invert)".into(),
        )),
    }
}
