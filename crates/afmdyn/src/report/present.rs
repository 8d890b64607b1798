//! The presentations of the requests' results ([`crate::report::Presentation`]): per family
//! of commands, the text summary, the tables, datasets and figures that every front end
//! writes as they are. Each request's `Analysis::present` calls its function here; a front end
//! that chooses which files it writes (`--files`, `--dforce-columns`), runs a study into its own
//! store (`chart`, `image`, the stepped curves, `bifurcation`) or streams a run to files, and
//! the commands without a computation of their own (`modes --sweep fig3`, `units`,
//! `cantilevers`) call theirs directly.

pub(crate) mod calibrate;
#[cfg(feature = "files")]
pub(crate) mod census;
#[cfg(feature = "files")]
pub(crate) mod continuation;
#[cfg(feature = "files")]
pub(crate) mod converge;
pub(crate) mod curve_figures;
pub mod curves;
pub mod fit;
pub(crate) mod fit_map;
pub mod fm;
pub mod image;
pub(crate) mod maps;
pub(crate) mod modes;
pub(crate) mod orbits;
pub mod peakforce;
pub mod reconstruct;
pub(crate) mod sweeps;
pub(crate) mod thermal;

/// Which files a presentation holds (`--files`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Files {
    /// Data files and figures.
    #[default]
    All,
    /// Data files only (no figures).
    Data,
    /// None: only the summary.
    None,
}

/// Where a front end writes a result (a request's `Analysis::present`): which files, the directory
/// (none: no files written) and the naming of a stepped curve's columns.
#[derive(Debug, Clone, Copy, Default)]
pub struct Destination<'a> {
    /// The files written: all, the data without the figures, or none.
    pub files: Files,
    /// The output directory.
    pub dir: Option<&'a std::path::Path>,
    /// A stepped curve's CSV/NPY columns named and ordered as dForce 2.0's zcdom table.
    pub dforce_columns: bool,
}

impl Destination<'_> {
    /// A stepped curve's options at this destination, its files named `stem`.
    pub fn curve(&self, stem: &'static str) -> curves::CurveOptions {
        curves::CurveOptions {
            stem,
            files: self.files,
            dforce_columns: self.dforce_columns,
        }
    }
    /// `shown` without the files [`Destination::files`] leaves out (the figures, or all).
    pub fn keep(&self, shown: &mut crate::report::Presentation) {
        match self.files {
            Files::All => {}
            Files::Data => shown
                .files
                .retain(|f| !matches!(f, crate::report::OutputFile::Figure { .. })),
            Files::None => shown.files.clear(),
        }
    }
}

/// A presentation whose output files are named after its whole summary
/// ([`crate::report::OutputsNote::Tail`]).
pub(crate) fn tail() -> crate::report::Presentation {
    crate::report::Presentation {
        outputs_note: crate::report::OutputsNote::Tail,
        ..crate::report::Presentation::default()
    }
}

/// The table `rows` under `columns` as the CSV file `name` of `p`, each number as the files
/// write it ([`crate::layout::files::f`]); none without the feature `files`.
pub(crate) fn numeric_csv(
    p: &mut crate::report::Presentation,
    name: &str,
    columns: &[&str],
    rows: &[Vec<f64>],
) {
    #[cfg(feature = "files")]
    {
        use crate::layout::files::f;
        let text = rows.iter().map(|r| r.iter().map(|v| f(*v)).collect());
        p.csv(name, columns, text.collect());
    }
    #[cfg(not(feature = "files"))]
    let _ = (p, name, columns, rows);
}

/// A figure of `series` against one axis, with the data's own extent and nothing shaded.
pub(crate) fn lines(
    title: &str,
    (x_label, y_label): (String, String),
    series: Vec<crate::layout::figure::Series>,
) -> crate::layout::figure::Plot {
    crate::layout::figure::Plot::Lines(crate::layout::figure::Figure {
        title: title.into(),
        x_label,
        y_label,
        series,
        shade: Vec::new(),
        y_min_span: 0.0,
    })
}

/// The document as a file `name` of `p`; when the files go to `dir`, the document records
/// the path of its table `csv` there (`"csv"`, in the document printed too).
pub(crate) fn with_document(
    p: &mut crate::report::Presentation,
    document: &mut serde_json::Value,
    (name, csv): (&str, &str),
    dir: Option<&std::path::Path>,
) {
    if let Some(dir) = dir {
        document["csv"] = serde_json::json!(dir.join(csv));
    }
    p.files.push(crate::report::OutputFile::Json {
        name: name.into(),
        value: document.clone(),
    });
}
