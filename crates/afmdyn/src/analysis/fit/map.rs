//! A fitted force map as data ([`FitMap`]): each curve's fit ([`CurveFit`]) with its flag
//! ([`CurveFlag`]) on the map's grid — what `fit-map` computes (`crate::study::fit_map`) and
//! its documents, layout and figures show (`crate::report::fit_map`).

use crate::contact::LawKind;
use serde::{Deserialize, Serialize};

/// The most points a shown curve keeps.
pub(crate) const SHOWN_POINTS: usize = 400;

/// How a curve's fit ended (the dataset's `flag`, CF `flag_values` 0–4 in this order; 5: no
/// curve at that grid point).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveFlag {
    /// Fitted: every estimate inside its range, with a finite standard error.
    Fitted,
    /// An estimate at a bound of its physical range (the probe key's, e.g. E ≥ 1 Pa).
    AtBound,
    /// No contact above the noise, or an estimate the data do not constrain (no finite
    /// standard error, or one as large as the value).
    NotConstrained,
    /// Fewer than 8 rows (the fit's fewest) indented beyond the fitted contact point.
    TooFewContactRows,
    /// No fit (too few rows in the segment or range, a curve that could not be read), or a
    /// minimiser that did not converge (its values kept).
    Failed,
}

impl CurveFlag {
    /// The flags' names, in the order of their codes.
    pub const NAMES: [&'static str; 6] = [
        "fitted",
        "at_bound",
        "not_constrained",
        "too_few_contact_rows",
        "failed",
        "no_curve",
    ];

    /// The flag's code (its place in [`CurveFlag::NAMES`]).
    pub fn code(self) -> i32 {
        self as i32
    }
}

/// A curve drawn in the figure of curves: its fitted rows' tip positions (m), forces and fit
/// (N), at most 400 of them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShownCurve {
    /// Tip positions (m).
    pub tip_position: Vec<f64>,
    /// Forces measured (N).
    pub force: Vec<f64>,
    /// Forces fitted (N).
    pub fit: Vec<f64>,
}

/// One curve's fit, as the store keeps it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CurveFit {
    /// The grid column.
    pub ix: usize,
    /// The grid line.
    pub iy: usize,
    /// The position x (m).
    pub x: f64,
    /// The position y (m).
    pub y: f64,
    /// Each fitted parameter's value, in the request's `fit` order (`None`: no fit).
    pub values: Vec<Option<f64>>,
    /// Their standard errors.
    pub standard_errors: Vec<Option<f64>>,
    /// Their 95 % intervals (Wald's, ±1.96 standard errors).
    pub intervals: Vec<[Option<f64>; 2]>,
    /// χ²/dof (N², the force noise's variance, as no σ is given).
    pub chi2_dof: Option<f64>,
    /// The fitted rows indented beyond the fitted contact point.
    pub contact_rows: usize,
    /// The contact point's piezo height (m): the topography.
    pub contact_height: Option<f64>,
    /// The lever's spring constant the curve was fitted with (N/m): the map file's for the
    /// curve, else the probe's.
    #[serde(default)]
    pub spring_constant: Option<f64>,
    /// The sample's thickness the curve was fitted with (m; `None`: infinitely thick).
    #[serde(default)]
    pub thickness: Option<f64>,
    /// How the fit ended.
    pub flag: CurveFlag,
    /// Why it is flagged (`None` when fitted).
    pub reason: Option<String>,
    /// The first of the curve's columns held against the probe that looks off (a unit slip,
    /// a lever of another spring constant: `fit`'s data warning), whatever its flag.
    #[serde(default)]
    pub data_warning: Option<String>,
    /// The curve with its fit, for the few shown.
    pub shown: Option<ShownCurve>,
}

/// A fitted map: its grid, the parameters fitted and every curve's fit (line by line).
#[derive(Debug, Clone)]
pub struct FitMap {
    /// The law fitted.
    pub law: LawKind,
    /// The grid's x positions (m).
    pub xs: Vec<f64>,
    /// The grid's y positions (m).
    pub ys: Vec<f64>,
    /// The fitted parameters' probe keys.
    pub names: Vec<String>,
    /// Every curve's fit, ordered by line then column.
    pub curves: Vec<CurveFit>,
    /// The segment fitted (`approach`, `retract` or `whole`).
    pub segment: &'static str,
    /// The range of tip positions fitted (m, relative to each curve's contact point by the
    /// deviation from the baseline), `None`: the whole segment.
    pub range: Option<[f64; 2]>,
    /// The bottom-effect correction: how each curve's thickness was given (`None`: an
    /// infinitely thick sample).
    pub layer: Option<String>,
}

/// The median and the 16th and 84th percentiles of `v` (finite values; `None` when empty).
pub fn median_spread(v: &[f64]) -> Option<[f64; 3]> {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return None;
    }
    s.sort_by(f64::total_cmp);
    let q = |p: f64| s[((s.len() - 1) as f64 * p).round() as usize];
    Some([q(0.5), q(0.16), q(0.84)])
}

impl FitMap {
    /// The curves of each flag but `no_curve`, in the flags' order: (name, count).
    pub fn counts(&self) -> Vec<(&'static str, usize)> {
        CurveFlag::NAMES[..5]
            .iter()
            .enumerate()
            .map(|(code, name)| {
                let n = self.curves.iter().filter(|c| c.flag.code() == code as i32);
                (*name, n.count())
            })
            .collect()
    }
}
