//! `bifurcation`: the tally of its records (counts by status, the diagrams' bounds, the period
//! classes drawn), its document, summary and the diagrams' series, read row by row from the
//! records in memory or from the store's CSV (a diagram is streamed from the store by a front
//! end); `attractors` and `attractors --sweep`: their summaries, tables and figures.

#[cfg(feature = "files")]
use crate::error::SimError;
use crate::params::{Params, SweepParam};
use crate::report::sweep::SweepRecord;
#[cfg(feature = "files")]
use crate::report::sweep::{sweep_failure, COL_W_TIP, COL_X_MAX};
use serde_json::{json, Value};
use std::collections::HashSet;

/// The palette index of a period class: 1, 2, 3, 4, 5–8, 9–64, nonperiodic (and failed).
pub(crate) fn period_color(period: f64) -> usize {
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

/// What the tally and the diagrams read of a sweep's row.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SweepRow<'a> {
    /// The parameter's value.
    pub value: f64,
    /// W(1,τ) at the Poincaré point (NaN: none).
    pub w_tip: f64,
    /// X_max (NaN: none).
    pub x_max: f64,
    /// `periodic`, `nonperiodic` or `error`.
    pub status: &'a str,
    /// The status code ([`crate::report::sweep::status_code`]).
    pub code: f64,
    /// Whether the row is its sweep point's first (`point` = 0).
    pub first: bool,
    /// A failed point's message.
    pub message: &'a str,
    /// The palette index of how the point was reached: forward 0, backward 1, a start 7.
    #[cfg(feature = "files")]
    pub branch: usize,
}

#[cfg(feature = "files")]
fn branch_color(branch: &str) -> usize {
    match branch {
        "forward" => 0,
        "backward" => 1,
        _ => 7,
    }
}

impl<'a> SweepRow<'a> {
    /// The row of a record.
    pub(crate) fn of(r: &'a SweepRecord) -> Self {
        SweepRow {
            value: r.value,
            w_tip: r.w_tip,
            x_max: r.x_max,
            status: r.status.name(),
            code: r.status.code() as f64,
            first: r.point == 0,
            message: &r.message,
            #[cfg(feature = "files")]
            branch: branch_color(&r.branch.to_string()),
        }
    }

    /// The row of a line of the store's CSV (unreadable numbers as NaN).
    #[cfg(feature = "files")]
    pub(crate) fn from_csv(r: &'a csv::StringRecord) -> Self {
        use crate::report::sweep::*;
        let num = |c: usize| r[c].parse().unwrap_or(f64::NAN);
        SweepRow {
            value: num(COL_VALUE),
            w_tip: num(COL_W_TIP),
            x_max: num(COL_X_MAX),
            status: &r[COL_STATUS],
            code: status_code(&r[COL_STATUS], &r[COL_PERIOD]),
            first: r[COL_POINT] == *"0",
            message: &r[COL_MESSAGE],
            branch: branch_color(&r[COL_BRANCH]),
        }
    }
}

/// The tally of a sweep's rows: its points by status, the first failure, the diagrams'
/// bounds and the period classes drawn.
#[derive(Debug, Clone)]
pub struct SweepTally {
    /// Value, W(1,τ) and X_max bounds of the rows with a finite W(1,τ): (min, max) each.
    bounds: [(f64, f64); 3],
    /// Periodic points.
    pub periodic: usize,
    /// Nonperiodic points.
    pub nonperiodic: usize,
    /// Failed points.
    pub errors: usize,
    /// The first failure's message.
    pub first_error: Option<String>,
    /// The colours of the period classes drawn: the legend lists only those (issue 28).
    drawn: HashSet<usize>,
}

impl Default for SweepTally {
    fn default() -> Self {
        SweepTally {
            bounds: [(f64::INFINITY, f64::NEG_INFINITY); 3],
            periodic: 0,
            nonperiodic: 0,
            errors: 0,
            first_error: None,
            drawn: HashSet::new(),
        }
    }
}

/// The diagrams of a sweep: stem, column drawn, title, y label, coloured by branch.
#[cfg(feature = "files")]
pub(crate) const BIFURCATION_FIGURES: [(&str, usize, &str, &str, bool); 3] = [
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
];

/// A legend entry: label, palette index, drawn as a marker.
#[cfg(feature = "files")]
pub(crate) type Legend = (String, usize, bool);

impl SweepTally {
    /// Count a row.
    pub(crate) fn add_row(&mut self, r: SweepRow<'_>) {
        if r.w_tip.is_finite() || r.x_max.is_finite() {
            self.drawn.insert(period_color(r.code));
        }
        if r.first {
            match r.status {
                "periodic" => self.periodic += 1,
                "nonperiodic" => self.nonperiodic += 1,
                _ => {
                    self.errors += 1;
                    let message = r.message.to_string();
                    self.first_error.get_or_insert(message);
                }
            }
        }
        if r.w_tip.is_finite() {
            for (b, v) in self.bounds.iter_mut().zip([r.value, r.w_tip, r.x_max]) {
                *b = (b.0.min(v), b.1.max(v));
            }
        }
    }

    /// Count a record.
    pub fn add(&mut self, r: &SweepRecord) {
        self.add_row(SweepRow::of(r));
    }

    /// The bounds (x0, x1, y0, y1) of the diagram of `column` (W(1,τ) or X_max); the unit
    /// square when no row is drawn.
    #[cfg(feature = "files")]
    pub fn bounds(&self, column: usize) -> (f64, f64, f64, f64) {
        let [x, w, m] = self.bounds;
        let y = if column == COL_W_TIP { w } else { m };
        if x.0.is_finite() {
            (x.0, x.1, y.0, y.1)
        } else {
            (0.0, 1.0, 0.0, 1.0)
        }
    }

    /// The legend of the diagrams coloured by period: the classes drawn.
    #[cfg(feature = "files")]
    pub fn legend(&self) -> Vec<Legend> {
        [
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
        .filter(|(_, c, _)| self.drawn.contains(c))
        .collect()
    }

    /// The document: the parameters, the swept one, the number of values and the points by
    /// status (a front end adds where its files are).
    pub fn document(&self, base: &Params, param: SweepParam, values: usize) -> Value {
        json!({
            "params": base,
            "param": param.name(),
            "values": values,
            "periodic": self.periodic,
            "nonperiodic": self.nonperiodic,
            "errors": self.errors,
        })
    }

    /// [`SimError::EveryRunFailed`] when no point was computed ([`sweep_failure`]).
    #[cfg(feature = "files")]
    pub fn failure(&self) -> Option<SimError> {
        sweep_failure(
            self.periodic + self.nonperiodic,
            self.errors,
            self.first_error.as_deref(),
        )
    }

    /// The warning of failed points, if any.
    #[cfg(feature = "files")]
    pub(crate) fn warning(&self) -> Option<String> {
        self.first_error.as_ref().map(|first| {
            warning!(
                "bifurcation.failed-points",
                "Read the first failure's message; the failed points are missing from the \
                 diagram.",
                "{} of {} sweep points failed; the first: {first}",
                self.errors,
                self.periodic + self.nonperiodic + self.errors
            )
        })
    }

    /// The summary line of `values` values of `param` (the front end adds where the outputs
    /// are).
    #[cfg(feature = "files")]
    pub(crate) fn summary(&self, values: usize, param: SweepParam) -> String {
        format!(
            "{} values of {}: {} periodic, {} nonperiodic, {} failed points",
            values,
            param.name(),
            self.periodic,
            self.nonperiodic,
            self.errors,
        )
    }
}

/// A sweep run into its store's files: the tally of its rows, the finished rows' CSV and its
/// NPY, and the sweep.
#[cfg(feature = "files")]
#[derive(Debug, Clone)]
pub struct SweepFiles {
    /// The sweep.
    pub spec: crate::analysis::bifurcation::SweepSpec,
    /// The tally of its rows.
    pub tally: SweepTally,
    /// The finished rows (`bifurcation.csv`).
    pub csv: std::path::PathBuf,
    /// Their NPY (`bifurcation.npy`).
    pub npy: std::path::PathBuf,
}

/// A diagram's points, streamed from the store's CSV ([`diagram_point`] of each row, read by
/// the store: `crate::study::checkpoint_file`): the memory of a large sweep's figures stays
/// bounded.
#[cfg(feature = "files")]
#[derive(Debug)]
pub(crate) struct StoredDiagram {
    /// The store's CSV of the finished rows.
    pub(crate) csv: std::path::PathBuf,
    /// The column drawn ([`crate::report::sweep::COL_W_TIP`] or `COL_X_MAX`).
    pub(crate) column: usize,
    /// Colour the points by their branch.
    pub(crate) by_branch: bool,
}

/// The presentation of a sweep run into its store ([`SweepFiles`]): its summary line (the
/// directory at its end), the warning of failed points, and the diagrams
/// ([`BIFURCATION_FIGURES`]) streamed from the store's CSV.
#[cfg(feature = "files")]
pub(crate) fn stored_bifurcation(
    files: &SweepFiles,
    param: SweepParam,
) -> crate::report::Presentation {
    use crate::layout::figure::{Plot, StreamedScatter};
    let (spec, tally) = (&files.spec, &files.tally);
    let mut p = crate::report::Presentation {
        outputs_note: crate::report::OutputsNote::Tail,
        ..Default::default()
    };
    p.line(tally.summary(spec.values.len(), param));
    p.warnings.extend(tally.warning());
    let branches = branch_legend(spec.continuation, spec.starts);
    for (stem, column, title, y_label, by_branch) in BIFURCATION_FIGURES {
        let legend = if by_branch {
            branches.clone()
        } else {
            tally.legend()
        };
        let points = StoredDiagram {
            csv: files.csv.clone(),
            column,
            by_branch,
        };
        let scatter = StreamedScatter {
            title: title.into(),
            labels: (
                format!("{} ({})", param.symbol(), param.name()),
                y_label.into(),
            ),
            bounds: tally.bounds(column),
            legend,
            points: std::sync::Arc::new(points),
        };
        p.figure(stem, Plot::Scatter(scatter));
    }
    p
}

/// The legend of the diagram coloured by branch: the continuations and the random starts of a
/// sweep that has them.
#[cfg(feature = "files")]
pub(crate) fn branch_legend(continuation: bool, starts: u32) -> Vec<Legend> {
    let mut legend: Vec<Legend> = Vec::new();
    if continuation {
        legend.push(("forward continuation".into(), 0, true));
        legend.push(("backward continuation".into(), 1, true));
    }
    if starts > 0 {
        legend.push((format!("random starts ({starts} per value)"), 7, true));
    }
    legend
}

/// The point a row draws on a diagram of `column` ([`BIFURCATION_FIGURES`]): (value, y,
/// palette index by branch or by period class); none without a finite y.
#[cfg(feature = "files")]
pub(crate) fn diagram_point(
    r: SweepRow<'_>,
    column: usize,
    by_branch: bool,
) -> Option<(f64, f64, usize)> {
    let y = if column == COL_W_TIP {
        r.w_tip
    } else {
        r.x_max
    };
    if !y.is_finite() {
        return None;
    }
    let c = if by_branch {
        r.branch
    } else {
        period_color(r.code)
    };
    Some((r.value, y, c))
}
