//! What a result shows besides its JSON document: a text summary, tables (CSV), datasets
//! (a [`Layout`]: the NetCDF file and the Python `xarray.Dataset`) and figures as data
//! ([`Plot`]), built once here for every front end ([`Presentation`]). A front end only
//! writes them: the command line prints the summary (unless `--json`) and writes each file
//! into its `--out` directory, rendering figures with its one plotting module.
//!
//! The text speaks SI with a probe ([`TextUnits`]: prefixed values such as 13.4747 nm, or
//! plain SI with `--units si`), else the model's dimensionless units (g₀, Ω, τ).

use crate::layout::figure::Plot;
use crate::layout::Layout;
use serde_json::Value;

/// A result's presentation: summary lines and output files, in the order they are written.
#[derive(Debug, Clone, Default)]
pub struct Presentation {
    /// The text summary, one entry a line (without a trailing newline).
    pub summary: Vec<String>,
    /// The files, written in this order.
    pub files: Vec<OutputFile>,
    /// Where a front end that writes the files into a directory says so in the summary.
    pub outputs_note: OutputsNote,
    /// Warnings a front end shows beside the document's (on stderr, before them).
    pub warnings: Vec<String>,
    /// The document as a front end prints it, when presenting it to a directory added to it
    /// (the paths of its files); `None`: the result's document as it is.
    pub document: Option<Value>,
}

/// Where the summary of a front end that writes files into a directory names it
/// ([`Presentation::summary_with`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum OutputsNote {
    /// `outputs in DIR` on a line of its own after the summary (the default).
    #[default]
    End,
    /// `outputs in DIR` on a line of its own after the first `n` summary lines.
    After(usize),
    /// At the end of the last summary line: `; outputs in DIR`, or `; no files written`.
    Tail,
    /// The directory itself ends the last summary line (`wrote 1111 points to DIR`).
    Named,
}

/// One output file of a result (its name relative to the output directory).
#[derive(Debug, Clone)]
pub enum OutputFile {
    /// A CSV table: header and rows of already formatted fields.
    Csv {
        /// File name (`orbit.csv`).
        name: String,
        /// Column names.
        header: Vec<String>,
        /// Rows, each as many fields as the header.
        rows: Vec<Vec<String>>,
    },
    /// A dataset: a NetCDF file from the command line, an `xarray.Dataset` in Python.
    Dataset {
        /// File name (`chart.nc`).
        name: String,
        /// Dimensions and variables.
        layout: Layout,
    },
    /// A figure: `stem.png` and `stem.svg`.
    Figure {
        /// File stem (`amplitude`).
        stem: String,
        /// The figure as data.
        plot: Plot,
    },
    /// A 2-D float64 NPY array (`approach.npy`) and its header file (`approach.npy.json`:
    /// shape, dtype, each column's name, unit and meaning).
    #[cfg(feature = "files")]
    Npy {
        /// File name.
        name: String,
        /// The columns.
        columns: Vec<crate::layout::files::Column>,
        /// Rows, each as many values as the columns.
        rows: Vec<Vec<f64>>,
    },
    /// A text file written as it is (a table formatted by its request: `chart.csv`).
    Text {
        /// File name.
        name: String,
        /// The file's text.
        text: String,
    },
    /// A JSON document written pretty (`image.json`).
    Json {
        /// File name.
        name: String,
        /// The document.
        value: Value,
    },
}

impl Presentation {
    /// Add a summary line.
    pub fn line(&mut self, line: impl Into<String>) {
        self.summary.push(line.into());
    }
    /// Add a CSV table.
    pub fn csv(&mut self, name: &str, header: &[&str], rows: Vec<Vec<String>>) {
        self.files.push(OutputFile::Csv {
            name: name.to_string(),
            header: header.iter().map(|h| h.to_string()).collect(),
            rows,
        });
    }
    /// Add a dataset.
    pub(crate) fn dataset(&mut self, name: &str, layout: Layout) {
        self.files.push(OutputFile::Dataset {
            name: name.to_string(),
            layout,
        });
    }
    /// Add a figure.
    pub fn figure(&mut self, stem: &str, plot: Plot) {
        self.files.push(OutputFile::Figure {
            stem: stem.to_string(),
            plot,
        });
    }
    /// Add a text file written as it is.
    pub fn text(&mut self, name: &str, text: String) {
        self.files.push(OutputFile::Text {
            name: name.to_string(),
            text,
        });
    }
    /// Add a JSON document, written pretty.
    pub fn json(&mut self, name: &str, value: Value) {
        self.files.push(OutputFile::Json {
            name: name.to_string(),
            value,
        });
    }
    /// The figure `stem`'s series, to decorate it (a front end's underlay); `None` when the
    /// presentation has no such figure of lines.
    pub fn series_mut(&mut self, stem: &str) -> Option<&mut Vec<crate::layout::figure::Series>> {
        self.files.iter_mut().find_map(|f| match f {
            OutputFile::Figure {
                stem: s,
                plot: Plot::Lines(fig),
            } if s == stem => Some(&mut fig.series),
            _ => None,
        })
    }
    /// The names of the files, figures as `stem.png` and `stem.svg` (to clear their stale
    /// temporary files before writing).
    pub fn file_names(&self) -> Vec<String> {
        self.files
            .iter()
            .flat_map(|f| match f {
                OutputFile::Csv { name, .. }
                | OutputFile::Dataset { name, .. }
                | OutputFile::Text { name, .. }
                | OutputFile::Json { name, .. } => vec![name.clone()],
                OutputFile::Figure { stem, .. } => {
                    vec![format!("{stem}.png"), format!("{stem}.svg")]
                }
                #[cfg(feature = "files")]
                OutputFile::Npy { name, .. } => vec![name.clone(), format!("{name}.json")],
            })
            .collect()
    }
    /// The summary as a front end prints it that wrote the files into `dir` (none: no files
    /// written), naming the directory where [`Presentation::outputs_note`] says.
    pub fn summary_with(&self, dir: Option<&std::path::Path>) -> Vec<String> {
        let mut lines = self.summary.clone();
        let named = dir.map(|d| format!("outputs in {}", d.display()));
        match (self.outputs_note, named) {
            (OutputsNote::Tail, named) => {
                let tail = named.unwrap_or_else(|| "no files written".into());
                match lines.last_mut() {
                    Some(last) => *last = format!("{last}; {tail}"),
                    None => lines.push(tail),
                }
            }
            (OutputsNote::Named, _) => {
                if let (Some(last), Some(d)) = (lines.last_mut(), dir) {
                    *last = format!("{last} {}", d.display());
                }
            }
            (OutputsNote::End, Some(named)) => lines.push(named),
            (OutputsNote::After(n), Some(named)) => lines.insert(n.min(lines.len()), named),
            (_, None) => {}
        }
        lines
    }
}

/// The SI prefix (a … G) for a magnitude: (its power of ten, the prefix), the one that puts
/// the magnitude's mantissa in [1, 1000) within the range of prefixes; none when `plain`
/// (plain SI units) or for zero and non-finite magnitudes.
pub fn si_prefix(mag: f64, plain: bool) -> (i32, &'static str) {
    const PREFIXES: [(i32, &str); 10] = [
        (-18, "a"),
        (-15, "f"),
        (-12, "p"),
        (-9, "n"),
        (-6, "µ"),
        (-3, "m"),
        (0, ""),
        (3, "k"),
        (6, "M"),
        (9, "G"),
    ];
    if plain || !(mag > 0.0 && mag.is_finite()) {
        return (0, "");
    }
    let e = (mag.log10().floor() as i32).div_euclid(3) * 3;
    PREFIXES
        .iter()
        .copied()
        .min_by_key(|(x, _)| (x - e).abs())
        .unwrap_or((0, ""))
}

/// `v` in `unit` with the SI prefix that puts its mantissa in [1, 1000), 6 significant digits
/// (13.4747 nm, 300.000 kHz), or plain SI when `plain` (8.033740e-9 m): the one format of SI
/// values in every text summary.
pub(crate) fn si_value(v: f64, unit: &str, plain: bool) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v} {unit}");
    }
    let (e, p) = si_prefix(v.abs(), plain);
    let m = v / 10f64.powi(e);
    if !(1e-3..1e4).contains(&m.abs()) {
        // plain SI: 8.033740e-9 m
        return format!("{m:.6e} {p}{unit}");
    }
    let digits = (5 - m.abs().log10().floor() as i32).clamp(0, 5) as usize;
    format!("{m:.digits$} {p}{unit}")
}

/// The format of an estimate `v` with its standard error `se` in `unit` (issue 77: an error
/// printed with more digits than its value): every number of the estimate (the value, the
/// error, the interval's ends) with the SI prefix of the larger of |v| and `se` and the error's
/// two significant digits, `0.07988 aJ ± 0.00043 aJ` (the rounding convention of the GUM, JCGM
/// 100:2008 §7.2.6). `None` where the error is not finite and positive, or the values need a
/// power of ten besides the prefix (plain SI): they print one by one ([`si_value`]) then.
pub(crate) fn si_with_error(
    v: f64,
    se: f64,
    unit: &str,
    plain: bool,
) -> Option<impl Fn(f64) -> String + '_> {
    if !(v.is_finite() && se.is_finite() && se > 0.0) {
        return None;
    }
    let big = v.abs().max(se);
    let (e, p) = si_prefix(big, plain);
    let scale = 10f64.powi(e);
    if !(1e-3..1e4).contains(&(big / scale)) {
        return None;
    }
    let digits = (1 - (se / scale).log10().floor() as i32).clamp(0, 15) as usize;
    Some(move |x: f64| format!("{:.digits$} {p}{unit}", x / scale))
}

/// The units of a text summary: SI with a probe (lengths, frequencies and rates through its
/// scales, printed by `si_value`), else the model's (g₀, Ω, per unit τ).
#[derive(Debug, Clone, Copy)]
pub struct TextUnits {
    /// The probe's scales (SI), or none (dimensionless).
    pub scales: Option<crate::probe::Scales>,
    /// Plain SI units (no prefixes).
    pub plain: bool,
}

impl TextUnits {
    /// The units of a run on `probe` (SI) or without one; `plain` for unprefixed SI.
    pub fn of(probe: Option<&crate::probe::Probe>, plain: bool) -> Self {
        TextUnits {
            scales: probe.map(|p| p.scales),
            plain,
        }
    }
    /// `v` in `unit` (`si_value` with these units' prefix choice).
    pub fn value(self, v: f64, unit: &str) -> String {
        si_value(v, unit, self.plain)
    }
    /// The drive: `f = 300.000 kHz` or `Ω = 2.6`.
    pub(crate) fn drive(self, omega: f64) -> String {
        match self.scales {
            Some(s) => format!("f = {}", self.value(s.frequency_hz(omega), "Hz")),
            None => format!("Ω = {omega}"),
        }
    }
    /// An angular frequency ω (per unit τ) as a frequency: Hz, or ω itself.
    pub fn frequency(self, omega: f64) -> String {
        match self.scales {
            Some(s) => self.value(s.frequency_hz(omega), "Hz"),
            None => format!("{omega:.6}"),
        }
    }
    /// A length in g₀: m, or g₀.
    pub(crate) fn length(self, v: f64) -> String {
        match self.scales {
            Some(s) => self.value(v * s.length_m, "m"),
            None => format!("{v:.9}"),
        }
    }
    /// A rate per unit τ (a Lyapunov exponent, Re λ): 1/s, or per unit τ.
    pub(crate) fn rate(self, v: f64) -> String {
        match self.scales {
            Some(s) => format!("{:+.6e} 1/s", v / s.time_s),
            None => format!("{v:+.6}"),
        }
    }
    /// Whether the summary speaks SI.
    pub fn si(self) -> bool {
        self.scales.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::{si_value, si_with_error, OutputsNote, Presentation};

    /// An estimate prints its error to two significant digits and every number to the same
    /// decimal place, with one prefix (issue 77: "0.07988 aJ ± 4.346295e-4 aJ").
    #[test]
    fn an_error_sets_the_digits_of_its_estimate() {
        let f = si_with_error(7.988e-20, 4.346295e-22, "J", false).unwrap();
        assert_eq!(
            (f(7.988e-20), f(4.346295e-22)),
            ("0.07988 aJ".into(), "0.00043 aJ".into())
        );
        let f = si_with_error(4998.63, 1.28348, "Pa", false).unwrap();
        assert_eq!(
            (f(4998.63), f(1.28348)),
            ("4.9986 kPa".into(), "0.0013 kPa".into())
        );
        let f = si_with_error(31.6318e-9, 208.954e-12, "m", false).unwrap();
        assert_eq!(f(31.6318e-9), "31.63 nm");
        // an error larger than its value sets the prefix; no error, no rounding
        let f = si_with_error(-1.67529e-12, 1.77567e-12, "N", false).unwrap();
        assert_eq!(
            (f(-1.67529e-12), f(1.77567e-12)),
            ("-1.7 pN".into(), "1.8 pN".into())
        );
        assert!(si_with_error(1.0, 0.0, "m", false).is_none());
        assert!(si_with_error(1.0, f64::NAN, "m", false).is_none());
    }

    /// The output directory is named where the presentation says: on its own line at the end
    /// or after a number of lines, or at the end of the last line ("no files written" without
    /// a directory).
    #[test]
    fn the_summary_names_the_directory_where_asked() {
        let dir = std::path::Path::new("out");
        let mut p = Presentation::default();
        p.line("a");
        p.line("b");
        assert_eq!(p.summary_with(Some(dir)), ["a", "b", "outputs in out"]);
        assert_eq!(p.summary_with(None), ["a", "b"]);
        p.outputs_note = OutputsNote::After(1);
        assert_eq!(p.summary_with(Some(dir)), ["a", "outputs in out", "b"]);
        p.outputs_note = OutputsNote::Tail;
        assert_eq!(p.summary_with(Some(dir)), ["a", "b; outputs in out"]);
        assert_eq!(p.summary_with(None), ["a", "b; no files written"]);
    }

    /// SI prefixes with 6 significant digits; plain SI without.
    #[test]
    fn values_print_with_si_prefixes() {
        assert_eq!(si_value(1.347465e-8, "m", false), "13.4747 nm");
        assert_eq!(si_value(3.0e5, "Hz", false), "300.000 kHz");
        assert_eq!(si_value(-2.5e-10, "m", false), "-250.000 pm");
        assert_eq!(si_value(1.0, "m", false), "1.00000 m");
        assert_eq!(si_value(0.0, "m", false), "0 m");
        assert_eq!(si_value(8.03374e-9, "m", true), "8.033740e-9 m");
    }
}
