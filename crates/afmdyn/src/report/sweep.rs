//! The records of a bifurcation sweep, the same for every front end: the rows of a
//! [`SweepPoint`] with their columns (names, units, meaning), the status and branch codes, the
//! one row order (the fingerprint of a request that a resumed sweep must match is
//! `crate::request::sweep`'s).
//!
//! A point gives one row per Poincaré point of its steady state (one row when it failed). The
//! rows of a finished sweep are ordered by value index, then branch (forward, backward,
//! start 0, 1, …), then Poincaré point (`order_key`), whatever order the workers finished in.
//! The command line writes them as `bifurcation.csv` (`SweepRecord::csv_line`, `HEADER`);
//! Python returns them as columns.

#[cfg(feature = "files")]
use crate::analysis::bifurcation::SweepSpec;
use crate::analysis::bifurcation::{Branch, SweepPoint};
#[cfg(feature = "files")]
use crate::layout::{Layout, Values, Variable};
use crate::params::SweepParam;

/// A column of the sweep's records: name (as in the CSV header), unit and meaning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RecordColumn {
    /// Name, as in the CSV header.
    pub name: &'static str,
    /// Unit (`g0`: the gap g0; `τ`: dimensionless time; `text`: not a number; `code`: see the
    /// meaning).
    pub unit: &'static str,
    /// Meaning.
    pub meaning: &'static str,
}

const fn col(name: &'static str, unit: &'static str, meaning: &'static str) -> RecordColumn {
    RecordColumn {
        name,
        unit,
        meaning,
    }
}

/// The 18 columns of a record, in the order of `bifurcation.csv`.
pub const COLUMNS: [RecordColumn; 18] = [
    col(
        "param",
        "text",
        "name of the swept parameter (omega, alpha1 … alpha6)",
    ),
    col("value", "as the parameter", "value of the swept parameter"),
    col(
        "index",
        "count",
        "index of the value in the sweep (0-based)",
    ),
    col(
        "branch",
        "text",
        "forward, backward or start-k (random start k)",
    ),
    col("status", "text", "periodic, nonperiodic or error"),
    col(
        "period",
        "drive periods",
        "period n of a periodic motion (empty otherwise)",
    ),
    col(
        "point",
        "count",
        "index of the Poincaré point in the recorded cycle",
    ),
    col(
        "points",
        "count",
        "Poincaré points of this sweep point (rows of its group)",
    ),
    col(
        "tau",
        "τ",
        "time of the Poincaré point (a multiple of the drive period 2π/Ω)",
    ),
    col("v_t", "g0", "V_T at the Poincaré point (eq. 8)"),
    col("w_tip", "g0", "tip deflection W(1,τ) at the Poincaré point"),
    col(
        "x_max",
        "g0",
        "largest tip deflection W(1,τ) over the recorded steady state",
    ),
    col(
        "v_t_min",
        "g0",
        "smallest V_T over the recorded steady state (≤ 0: contact)",
    ),
    col("contact_fraction", "1", "fraction of the time in contact"),
    col(
        "contacts_per_period",
        "1/period",
        "contact entries per drive period",
    ),
    col(
        "transient_periods",
        "drive periods",
        "length of the transient discarded",
    ),
    col("message", "text", "why the point failed (empty otherwise)"),
    col(
        "state",
        "modal",
        "state (a_1…a_N, ȧ_1…ȧ_N) at the Poincaré point, space-separated",
    ),
];

/// The records as numbers (the command line's `bifurcation.npy`): the numeric columns of
/// [`COLUMNS`] with the branch (`branch_code`) and the status ([`PointStatus::code`]) as codes.
pub const NUMERIC_COLUMNS: [RecordColumn; 12] = [
    COLUMNS[COL_VALUE],
    COLUMNS[COL_INDEX],
    col(
        "branch",
        "code",
        "0 forward continuation, 1 backward, 2 + k random start k",
    ),
    col(
        "period",
        "drive periods",
        "period n of a periodic motion; −1 nonperiodic; −2 failed point",
    ),
    COLUMNS[COL_POINT],
    COLUMNS[COL_TAU],
    COLUMNS[9],
    COLUMNS[COL_W_TIP],
    COLUMNS[COL_X_MAX],
    COLUMNS[12],
    COLUMNS[13],
    COLUMNS[14],
];

/// The CSV header: the names of [`COLUMNS`].
#[cfg(any(test, feature = "files"))]
pub(crate) const HEADER: [&str; 18] = {
    let mut h = [""; 18];
    let mut i = 0;
    while i < 18 {
        h[i] = COLUMNS[i].name;
        i += 1;
    }
    h
};

/// [`crate::SimError::EveryRunFailed`] when no point of a sweep was computed (the exit-code
/// rule of `docs/outputs.md`: a sweep with no answer is a failure), else `None`; from the
/// counts of its points (the first row of each, `point` = 0) computed and failed, and the
/// first failure's message.
#[cfg(feature = "files")]
pub(crate) fn sweep_failure(
    computed: usize,
    failed: usize,
    first: Option<&str>,
) -> Option<crate::SimError> {
    match first {
        Some(first) if computed == 0 && failed > 0 => Some(crate::SimError::EveryRunFailed {
            what: "sweep points",
            runs: failed,
            first: first.to_string(),
        }),
        _ => None,
    }
}

/// [`sweep_failure`] of a sweep's `records`.
#[cfg(feature = "files")]
pub(crate) fn every_point_failed(records: &[SweepRecord]) -> Option<crate::SimError> {
    let points = records.iter().filter(|r| r.point == 0);
    let (failed, computed): (Vec<&SweepRecord>, Vec<&SweepRecord>) =
        points.partition(|r| r.status == PointStatus::Error);
    sweep_failure(
        computed.len(),
        failed.len(),
        failed.first().map(|r| r.message.as_str()),
    )
}

/// Position of `value` in [`COLUMNS`].
pub const COL_VALUE: usize = 1;
/// Position of `index`.
pub(crate) const COL_INDEX: usize = 2;
/// Position of `branch`.
#[cfg(any(test, feature = "files"))]
pub(crate) const COL_BRANCH: usize = 3;
/// Position of `status`.
#[cfg(any(test, feature = "files"))]
pub(crate) const COL_STATUS: usize = 4;
/// Position of `period`.
#[cfg(any(test, feature = "files"))]
pub(crate) const COL_PERIOD: usize = 5;
/// Position of `point`.
pub(crate) const COL_POINT: usize = 6;
/// Position of `points`.
#[cfg(any(test, feature = "files"))]
pub(crate) const COL_POINTS: usize = 7;
/// Position of `tau`.
pub(crate) const COL_TAU: usize = 8;
/// Position of `w_tip`.
pub const COL_W_TIP: usize = 10;
/// Position of `x_max`.
pub(crate) const COL_X_MAX: usize = 11;
/// Position of `message`.
#[cfg(feature = "files")]
pub(crate) const COL_MESSAGE: usize = 16;
/// Position of `state`.
#[cfg(any(test, feature = "files"))]
pub(crate) const COL_STATE: usize = 17;

/// The numeric code of a branch: 0 forward, 1 backward, 2 + k random start k.
#[cfg(any(test, feature = "files"))]
pub(crate) fn branch_code(b: Branch) -> f64 {
    match b {
        Branch::Forward => 0.0,
        Branch::Backward => 1.0,
        Branch::Start(k) => 2.0 + f64::from(k),
    }
}

/// How a point ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointStatus {
    /// A periodic motion of period n (drive periods).
    Periodic(usize),
    /// No period up to the largest searched.
    Nonperiodic,
    /// The point failed (its message says why).
    Error,
}

impl PointStatus {
    /// `periodic`, `nonperiodic` or `error` (the `status` column).
    pub fn name(self) -> &'static str {
        match self {
            PointStatus::Periodic(_) => "periodic",
            PointStatus::Nonperiodic => "nonperiodic",
            PointStatus::Error => "error",
        }
    }

    /// The numeric code: the period n, −1 nonperiodic, −2 failed.
    pub fn code(self) -> i64 {
        match self {
            PointStatus::Periodic(n) => n as i64,
            PointStatus::Nonperiodic => -1,
            PointStatus::Error => -2,
        }
    }
}

/// The numeric code of the `status` and `period` cells of a CSV row: the period n, −1
/// nonperiodic, −2 anything else; NaN for `periodic` without a readable period.
#[cfg(feature = "files")]
pub(crate) fn status_code(status: &str, period: &str) -> f64 {
    match status {
        "periodic" => period.parse().unwrap_or(f64::NAN),
        "nonperiodic" => -1.0,
        _ => -2.0,
    }
}

/// One row: one Poincaré point of a sweep point (or the one row of a failed point).
/// Lengths in units of the gap g0, times in τ; the numbers of a failed point are NaN.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRecord {
    /// The swept parameter.
    pub param: SweepParam,
    /// Its value.
    pub value: f64,
    /// Index of the value in the sweep.
    pub index: usize,
    /// How the point was reached.
    pub branch: Branch,
    /// How it ended.
    pub status: PointStatus,
    /// Index of this Poincaré point in the recorded cycle (0 for a failed point).
    pub point: usize,
    /// Poincaré points of the sweep point (1 for a failed point).
    pub points: usize,
    /// τ of the Poincaré point.
    pub tau: f64,
    /// V_T at the Poincaré point.
    pub v_t: f64,
    /// W(1,τ) at the Poincaré point.
    pub w_tip: f64,
    /// Largest W(1,τ) over the recorded steady state.
    pub x_max: f64,
    /// Smallest V_T over the recorded steady state.
    pub v_t_min: f64,
    /// Fraction of the time in contact.
    pub contact_fraction: f64,
    /// Contact entries per drive period.
    pub contacts_per_period: f64,
    /// Transient discarded, in drive periods (`None` for a failed point).
    pub transient_periods: Option<usize>,
    /// Why the point failed, with newlines and commas replaced by spaces (empty otherwise).
    pub message: String,
    /// Modal state (length 2N) at the Poincaré point (empty for a failed point).
    pub state: Vec<f64>,
}

/// The records of a point, one per Poincaré point (one for a failed point), in order.
pub(crate) fn records(param: SweepParam, p: &SweepPoint) -> Vec<SweepRecord> {
    let base = |status, point, points| SweepRecord {
        param,
        value: p.value,
        index: p.index,
        branch: p.branch,
        status,
        point,
        points,
        tau: f64::NAN,
        v_t: f64::NAN,
        w_tip: f64::NAN,
        x_max: f64::NAN,
        v_t_min: f64::NAN,
        contact_fraction: f64::NAN,
        contacts_per_period: f64::NAN,
        transient_periods: None,
        message: String::new(),
        state: Vec::new(),
    };
    match &p.result {
        Err(msg) => vec![SweepRecord {
            message: msg.replace(['\n', ','], " "),
            ..base(PointStatus::Error, 0, 1)
        }],
        Ok(s) => {
            let status = s
                .period()
                .map_or(PointStatus::Nonperiodic, PointStatus::Periodic);
            let n = s.poincare.len();
            s.poincare
                .iter()
                .enumerate()
                .map(|(i, q)| SweepRecord {
                    tau: q.tau,
                    v_t: q.v_t,
                    w_tip: q.w_tip,
                    x_max: s.stats.x_max,
                    v_t_min: s.stats.v_t_min,
                    contact_fraction: s.stats.contact_fraction,
                    contacts_per_period: s.stats.contacts_per_period,
                    transient_periods: Some(s.transient_periods),
                    state: q.state.iter().copied().collect(),
                    ..base(status, i, n)
                })
                .collect()
        }
    }
}

/// The records of a sweep as a layout over the dimension `point` (one per record, in their
/// order), for the Python `xarray.Dataset` (`bifurcation`, `afmdyn.dask.bifurcation`): the
/// columns of [`COLUMNS`] with their units and meanings — `value` (of `spec.param`), `index`,
/// `branch` and `status` (words), `period` (its code, [`PointStatus::code`]), `k` (the CSV's
/// `point`), `n_points` (`points`), `tau` … `contacts_per_period`, `transient_periods` (−1 for
/// a failed point), `message` — and the state as `a_1` … `a_N`, `a_dot_1` … `a_dot_N` (NaN
/// for a failed point).
#[cfg(feature = "files")]
pub(crate) fn layout(spec: &SweepSpec, records: &[SweepRecord]) -> Layout {
    // a number's unit and meaning as the numeric columns give them (`period` as its code),
    // a word's as the CSV's
    let meaning = |name: &str, numeric: bool| {
        let table: &[RecordColumn] = if numeric { &NUMERIC_COLUMNS } else { &COLUMNS };
        table
            .iter()
            .chain(&COLUMNS)
            .find(|c| c.name == name)
            .map_or(("1", ""), |c| (c.unit, c.meaning))
    };
    let point: &[&str] = &["point"];
    let num = |var: &str, col: &str, get: &dyn Fn(&SweepRecord) -> f64| {
        let (unit, long_name) = meaning(col, true);
        let values: Vec<f64> = records.iter().map(get).collect();
        Variable::f64(var, point, unit, long_name, &values)
    };
    let int = |var: &str, col: &str, get: &dyn Fn(&SweepRecord) -> i64| {
        let (unit, long_name) = meaning(col, true);
        let values = records
            .iter()
            .map(|r| i32::try_from(get(r)).unwrap_or(i32::MAX))
            .collect::<Vec<_>>();
        Variable::i32(var, point, unit, long_name, &values)
    };
    let text = |var: &str, get: &dyn Fn(&SweepRecord) -> String| {
        let values = Values::Text(records.iter().map(get).collect());
        Variable::new(var, point, "", meaning(var, false).1, values)
    };
    let (param, n) = (spec.param, spec.base.modes);
    let mut variables = vec![
        Variable::f64(
            "value",
            point,
            "1",
            format!("{} ({})", param.symbol(), param.name()),
            &records.iter().map(|r| r.value).collect::<Vec<_>>(),
        ),
        int("index", "index", &|r| r.index as i64),
        text("branch", &|r| r.branch.to_string()),
        text("status", &|r| r.status.name().to_string()),
        int("period", "period", &|r| r.status.code()),
        int("k", "point", &|r| r.point as i64),
        int("n_points", "points", &|r| r.points as i64),
        num("tau", "tau", &|r| r.tau),
        num("v_t", "v_t", &|r| r.v_t),
        num("w_tip", "w_tip", &|r| r.w_tip),
        num("x_max", "x_max", &|r| r.x_max),
        num("v_t_min", "v_t_min", &|r| r.v_t_min),
        num("contact_fraction", "contact_fraction", &|r| {
            r.contact_fraction
        }),
        num("contacts_per_period", "contacts_per_period", &|r| {
            r.contacts_per_period
        }),
        int("transient_periods", "transient_periods", &|r| {
            r.transient_periods.map_or(-1, |t| t as i64)
        }),
        text("message", &|r| r.message.clone()),
    ];
    for (j, name, unit, what) in (0..2 * n).map(|j| match j < n {
        true => (
            j,
            format!("a_{}", j + 1),
            "g0",
            format!("a_{} at the section", j + 1),
        ),
        false => (
            j,
            format!("a_dot_{}", j - n + 1),
            "g0 per unit τ",
            format!("da_{}/dτ at the section", j - n + 1),
        ),
    }) {
        let values: Vec<f64> = records
            .iter()
            .map(|r| r.state.get(j).copied().unwrap_or(f64::NAN))
            .collect();
        variables.push(Variable::f64(&name, point, unit, what, &values));
    }
    Layout::new(
        format!("afmdyn bifurcation sweep over {}", param.name()),
        &[("point", records.len())],
        variables,
    )
}

/// The position of a record in the one row order: (value index, branch, Poincaré point).
pub(crate) fn order_key(r: &SweepRecord) -> (usize, Branch, usize) {
    (r.index, r.branch, r.point)
}

impl SweepRecord {
    /// The row as a CSV line of [`HEADER`]'s columns, without its newline (numbers in Rust's
    /// shortest round-trip form, empty cells for what a failed point lacks).
    #[cfg(any(test, feature = "files"))]
    pub(crate) fn csv_line(&self) -> String {
        let num = |v: f64| {
            if self.status == PointStatus::Error {
                String::new()
            } else {
                format!("{v}")
            }
        };
        let period = match self.status {
            PointStatus::Periodic(n) => n.to_string(),
            _ => String::new(),
        };
        let state: Vec<String> = self.state.iter().map(|v| format!("{v}")).collect();
        [
            self.param.name().to_string(),
            format!("{}", self.value),
            self.index.to_string(),
            self.branch.to_string(),
            self.status.name().to_string(),
            period,
            self.point.to_string(),
            self.points.to_string(),
            num(self.tau),
            num(self.v_t),
            num(self.w_tip),
            num(self.x_max),
            num(self.v_t_min),
            num(self.contact_fraction),
            num(self.contacts_per_period),
            self.transient_periods
                .map_or(String::new(), |t| t.to_string()),
            self.message.clone(),
            state.join(" "),
        ]
        .join(",")
    }

    /// Read a line written by [`SweepRecord::csv_line`].
    ///
    /// # Errors
    /// A message naming the column that cannot be read.
    #[cfg(any(test, feature = "files"))]
    pub(crate) fn parse_csv(line: &str) -> Result<SweepRecord, String> {
        let c: Vec<&str> = line.split(',').collect();
        if c.len() != HEADER.len() {
            return Err(format!("{} cells, expected {}", c.len(), HEADER.len()));
        }
        let bad = |i: usize| format!("{} = '{}' cannot be read", HEADER[i], c[i]);
        let int = |i: usize| c[i].parse::<usize>().map_err(|_| bad(i));
        let num = |i: usize| match c[i] {
            "" => Ok(f64::NAN),
            s => s.parse::<f64>().map_err(|_| bad(i)),
        };
        let status = match (c[COL_STATUS], c[COL_PERIOD]) {
            ("periodic", _) => PointStatus::Periodic(int(COL_PERIOD)?),
            ("nonperiodic", _) => PointStatus::Nonperiodic,
            ("error", _) => PointStatus::Error,
            _ => return Err(bad(COL_STATUS)),
        };
        Ok(SweepRecord {
            param: c[0].parse().map_err(|_| bad(0))?,
            value: num(COL_VALUE)?,
            index: int(COL_INDEX)?,
            branch: c[COL_BRANCH].parse().map_err(|_| bad(COL_BRANCH))?,
            status,
            point: int(COL_POINT)?,
            points: int(COL_POINTS)?,
            tau: num(COL_TAU)?,
            v_t: num(9)?,
            w_tip: num(COL_W_TIP)?,
            x_max: num(COL_X_MAX)?,
            v_t_min: num(12)?,
            contact_fraction: num(13)?,
            contacts_per_period: num(14)?,
            transient_periods: match c[15] {
                "" => None,
                _ => Some(int(15)?),
            },
            message: c[16].to_string(),
            state: match c[COL_STATE] {
                "" => Vec::new(),
                s => s
                    .split(' ')
                    .map(|v| v.parse::<f64>().map_err(|_| bad(COL_STATE)))
                    .collect::<Result<_, _>>()?,
            },
        })
    }
}
