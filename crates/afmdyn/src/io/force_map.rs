//! The force maps `fit-map` fits (feature `files`): a force-volume or QI map's curves, indexed
//! in one streamed pass and read back one curve at a time, so that memory holds the index and
//! the curves under way, never the map ([`ForceMap`]).
//!
//! Two files hold a map:
//! - **a long-format CSV** (`.csv`, [`InputKind::ForceMap`]): a header naming the columns `x`,
//!   `y` (m, the curve's position on the map), `height` (m, the piezo height, decreasing into
//!   the sample), `force` (N, repulsion positive), and optionally `segment` (0 on the approach,
//!   1 on the retract, as afmformats' `segment` column) and `time` (s); the rows of one curve
//!   are consecutive (a curve is a run of rows of one position). The grid is the sorted
//!   distinct `x` and `y`.
//! - **a NetCDF-3 file** (`afmdyn.export_map` writes it from Python): the unlimited dimension
//!   `curve` and the dimension `row` (the longest curve's rows); per curve `x`, `y` (m), `ix`,
//!   `iy` (the grid indices), `rows` (its rows; the rest of `row` is padding),
//!   `approach_rows` (its approach's rows, 0 when unknown) and `spring_constant` (N/m, 0
//!   when unknown); per curve and row `height`, `force` and optionally `time`.
//!
//! This module knows no request: its refusals are [`InputFileError`]s naming the file.

// without the `files` feature a map is refused before it is read
#![cfg_attr(not(feature = "files"), allow(dead_code))]

use super::InputFileError;
#[cfg(feature = "files")]
use super::{open, refusal, InputKind};
use std::collections::HashSet;
#[cfg(feature = "files")]
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
#[cfg(feature = "files")]
use std::sync::atomic::{AtomicBool, Ordering};
#[cfg(feature = "files")]
use std::sync::Arc;

/// The most curves a map may have: a 1024 × 1024 map (its index ~64 MiB).
pub const MAX_MAP_CURVES: usize = 1 << 20;

/// The most rows one curve may have (a 1 MHz record of one second).
pub const MAX_CURVE_ROWS: usize = 1_000_000;

/// The most bytes a NetCDF header may take before it parses.
#[cfg(feature = "files")]
const MAX_NETCDF_HEADER_BYTES: u64 = 1 << 20;

/// Where a curve's rows are in its file.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Location {
    /// The byte offset of its first row in the CSV.
    Csv(u64),
    /// Its record in the NetCDF file.
    Record(usize),
}

/// One curve of a map: its grid indices and position, its rows and where they are.
#[derive(Debug, Clone, PartialEq)]
pub struct MapCurve {
    /// The column on the grid (x increasing).
    pub ix: usize,
    /// The line on the grid (y increasing).
    pub iy: usize,
    /// The position x (m).
    pub x: f64,
    /// The position y (m).
    pub y: f64,
    /// Its rows.
    pub rows: usize,
    /// Its approach's rows, where the file records its segments.
    pub approach_rows: Option<usize>,
    /// The lever's spring constant (N/m), where the file records it.
    pub spring_constant: Option<f64>,
    at: Location,
}

/// A curve's rows: piezo heights (m), forces (N), and the rows' times (s) where the file has
/// them.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveRows {
    /// The piezo heights (m).
    pub height: Vec<f64>,
    /// The forces (N).
    pub force: Vec<f64>,
    /// The rows' times (s).
    pub time: Option<Vec<f64>>,
}

/// The columns of a long-format CSV.
#[derive(Debug, Clone, Copy, PartialEq)]
struct CsvColumns {
    x: usize,
    y: usize,
    height: usize,
    force: usize,
    segment: Option<usize>,
    time: Option<usize>,
}

/// A map indexed (the module doc): its grid and its curves, line by line.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceMap {
    path: PathBuf,
    csv: Option<CsvColumns>,
    /// The grid's x positions (m), increasing.
    pub xs: Vec<f64>,
    /// The grid's y positions (m), increasing.
    pub ys: Vec<f64>,
    /// Every curve, line by line (iy), then x increasing.
    pub curves: Vec<MapCurve>,
    /// The curves of each line: ranges into `curves`.
    pub lines: Vec<std::ops::Range<usize>>,
    /// The file's size in bytes (what a resumed run's fingerprint holds).
    pub bytes: u64,
}

/// The distinct grid indices (`index`) of `curves` renumbered 0, 1, … in order, and the mean
/// position (`at`) of each.
fn used(
    curves: &mut [MapCurve],
    index: impl Fn(&mut MapCurve) -> &mut usize,
    at: impl Fn(&MapCurve) -> f64,
) -> Vec<f64> {
    let mut ids: Vec<usize> = curves.iter_mut().map(|c| *index(c)).collect();
    ids.sort_unstable();
    ids.dedup();
    let mut sums = vec![(0.0, 0usize); ids.len()];
    for c in curves.iter_mut() {
        let k = ids.binary_search(index(c)).unwrap_or(0);
        *index(c) = k;
        sums[k].0 += at(c);
        sums[k].1 += 1;
    }
    sums.into_iter().map(|(s, n)| s / n as f64).collect()
}

/// A refusal naming `path`.
fn invalid(path: &Path, message: impl std::fmt::Display) -> InputFileError {
    InputFileError::Invalid {
        path: path.display().to_string(),
        message: message.to_string(),
    }
}

#[cfg(feature = "files")]
/// An I/O failure reading `path`: the bounded reader's refusal, or the failure itself.
fn failure(path: &Path, e: &std::io::Error) -> InputFileError {
    refusal(e).cloned().unwrap_or_else(|| invalid(path, e))
}

impl ForceMap {
    /// Index the map in `path` (the module doc): a NetCDF-3 file by its signature, else a
    /// long-format CSV, read in one streamed pass.
    ///
    /// # Errors
    /// [`InputFileError`] naming the file: refused by the bounded reader, unreadable, a
    /// missing column or variable, a field that is not a number, a curve whose rows are not
    /// consecutive, too many curves or rows, or positions that are no grid.
    #[cfg(not(feature = "files"))]
    pub fn index(path: &Path) -> Result<ForceMap, InputFileError> {
        Err(invalid(path, "this build reads no files"))
    }

    /// Index the map in `path` (the module doc): a NetCDF-3 file by its signature, else a
    /// long-format CSV, read in one streamed pass.
    ///
    /// # Errors
    /// [`InputFileError`] naming the file: refused by the bounded reader, unreadable, a
    /// missing column or variable, a field that is not a number, a curve whose rows are not
    /// consecutive, too many curves or rows, or positions that are no grid.
    #[cfg(feature = "files")]
    pub fn index(path: &Path) -> Result<ForceMap, InputFileError> {
        let mut head = [0u8; 4];
        let mut file = open(path, InputKind::ForceMap)?;
        let n = file.read(&mut head).map_err(|e| failure(path, &e))?;
        let bytes = std::fs::metadata(path).map_or(0, |m| m.len());
        drop(file);
        let (csv, curves) = if n == 4 && &head[..3] == b"CDF" {
            (None, netcdf_index(path)?)
        } else {
            let (columns, curves) = csv_index(path)?;
            (Some(columns), curves)
        };
        Self::on_grid(path.to_path_buf(), csv, curves, bytes)
    }

    /// The map of `curves` laid on their grid: the sorted distinct positions (a CSV's), or
    /// the file's indices.
    fn on_grid(
        path: PathBuf,
        csv: Option<CsvColumns>,
        mut curves: Vec<MapCurve>,
        bytes: u64,
    ) -> Result<ForceMap, InputFileError> {
        if curves.is_empty() {
            return Err(invalid(&path, "no curve: the map has no rows"));
        }
        let distinct = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v.dedup();
        };
        let (xs, ys) = if csv.is_some() {
            // the sorted distinct positions
            let (mut xs, mut ys): (Vec<f64>, Vec<f64>) = curves.iter().map(|c| (c.x, c.y)).unzip();
            distinct(&mut xs);
            distinct(&mut ys);
            for c in &mut curves {
                c.ix = xs.partition_point(|v| *v < c.x);
                c.iy = ys.partition_point(|v| *v < c.y);
            }
            (xs, ys)
        } else {
            // the file's grid indices that hold a curve, each at its curves' mean position (an
            // instrument's positions jitter along a column)
            let xs = used(&mut curves, |c| &mut c.ix, |c| c.x);
            let ys = used(&mut curves, |c| &mut c.iy, |c| c.y);
            (xs, ys)
        };
        if xs.len().saturating_mul(ys.len()) > MAX_MAP_CURVES.max(4 * curves.len()) {
            return Err(invalid(
                &path,
                format!(
                    "{} curves at {} distinct x and {} distinct y: the positions are no grid",
                    curves.len(),
                    xs.len(),
                    ys.len()
                ),
            ));
        }
        let mut seen = HashSet::new();
        if let Some(c) = curves.iter().find(|c| !seen.insert((c.ix, c.iy))) {
            return Err(invalid(
                &path,
                format!("two curves at x = {} m, y = {} m", c.x, c.y),
            ));
        }
        curves.sort_by_key(|c| (c.iy, c.ix));
        let lines = (0..ys.len())
            .map(|iy| curves.partition_point(|c| c.iy < iy)..curves.partition_point(|c| c.iy <= iy))
            .collect();
        Ok(ForceMap {
            path,
            csv,
            xs,
            ys,
            curves,
            lines,
            bytes,
        })
    }

    /// The curves' largest number of rows.
    pub fn max_rows(&self) -> usize {
        self.curves.iter().map(|c| c.rows).max().unwrap_or(0)
    }

    /// A reader of the map's curves (one per worker: it holds the open file).
    ///
    /// # Errors
    /// [`InputFileError`] naming the file when it cannot be opened again.
    pub fn reader(&self) -> Result<CurveReader<'_>, InputFileError> {
        #[cfg(not(feature = "files"))]
        return Err(invalid(&self.path, "this build reads no files"));
        #[cfg(feature = "files")]
        let file = match self.csv {
            Some(_) => {
                Source::Csv(std::fs::File::open(&self.path).map_err(|e| failure(&self.path, &e))?)
            }
            None => Source::NetCdf(Box::new(open_netcdf(&self.path)?)),
        };
        #[cfg(feature = "files")]
        Ok(CurveReader { map: self, file })
    }
}

#[cfg(feature = "files")]
/// An open map file.
enum Source {
    Csv(std::fs::File),
    NetCdf(Box<netcdf3::FileReader>),
}

/// The reader of a map's curves ([`ForceMap::reader`]).
pub struct CurveReader<'a> {
    #[cfg(feature = "files")]
    map: &'a ForceMap,
    #[cfg(feature = "files")]
    file: Source,
    #[cfg(not(feature = "files"))]
    map: std::marker::PhantomData<&'a ForceMap>,
}

impl CurveReader<'_> {
    /// The rows of `curve` (one of the map's).
    ///
    /// # Errors
    /// [`InputFileError`] naming the file: unreadable, changed since it was indexed, or a
    /// field that is not a number.
    #[cfg(not(feature = "files"))]
    pub fn read(&mut self, _curve: &MapCurve) -> Result<CurveRows, InputFileError> {
        Err(invalid(Path::new("map"), "this build reads no files"))
    }

    /// The rows of `curve` (one of the map's).
    ///
    /// # Errors
    /// [`InputFileError`] naming the file: unreadable, changed since it was indexed, or a
    /// field that is not a number.
    #[cfg(feature = "files")]
    pub fn read(&mut self, curve: &MapCurve) -> Result<CurveRows, InputFileError> {
        let path = &self.map.path;
        match (&mut self.file, curve.at, self.map.csv) {
            (Source::Csv(file), Location::Csv(offset), Some(columns)) => {
                file.seek(SeekFrom::Start(offset))
                    .map_err(|e| failure(path, &e))?;
                csv_rows(path, file, columns, curve)
            }
            (Source::NetCdf(reader), Location::Record(record), None) => {
                netcdf_rows(path, reader, record, curve.rows)
            }
            _ => Err(invalid(path, "a curve of another map")),
        }
    }
}

#[cfg(feature = "files")]
/// The column `name` of the CSV header `names`.
fn column(path: &Path, names: &csv::StringRecord, name: &str) -> Result<usize, InputFileError> {
    names.iter().position(|c| c.trim() == name).ok_or_else(|| {
        let all: Vec<&str> = names.iter().collect();
        invalid(
            path,
            format!(
                "no column {name} among {} (a force map's CSV has the columns x, y (m), height \
                 (m), force (N), optionally segment and time (s))",
                all.join(", ")
            ),
        )
    })
}

#[cfg(feature = "files")]
/// The number in `field` at `at` (a line of the file, a row of a curve), column `name`.
fn number(
    path: &Path,
    field: &[u8],
    at: impl std::fmt::Display,
    name: &str,
) -> Result<f64, InputFileError> {
    std::str::from_utf8(field)
        .ok()
        .and_then(|s| s.trim().parse::<f64>().ok())
        .ok_or_else(|| {
            invalid(
                path,
                format!(
                    "{at}, column {name}: {:?} is not a number",
                    String::from_utf8_lossy(field)
                ),
            )
        })
}

#[cfg(feature = "files")]
/// The columns and curves of the long-format CSV `path`, streamed once.
fn csv_index(path: &Path) -> Result<(CsvColumns, Vec<MapCurve>), InputFileError> {
    let file = open(path, InputKind::ForceMap)?;
    let mut rdr = csv::ReaderBuilder::new().flexible(true).from_reader(file);
    let io = |e: csv::Error| {
        let text = e.to_string();
        match e.into_kind() {
            csv::ErrorKind::Io(e) => failure(path, &e),
            csv::ErrorKind::Utf8 { .. } => invalid(
                path,
                format!(
                    "not a CSV map ({text}): the command line reads a long-format CSV (x, y, \
                     height, force) or the NetCDF file afmdyn.export_map writes from an \
                     instrument's map (JPK and the others afmformats reads)"
                ),
            ),
            _ => invalid(path, text),
        }
    };
    let names = rdr.headers().map_err(io)?.clone();
    let columns = CsvColumns {
        x: column(path, &names, "x")?,
        y: column(path, &names, "y")?,
        height: column(path, &names, "height")?,
        force: column(path, &names, "force")?,
        segment: column(path, &names, "segment").ok(),
        time: column(path, &names, "time").ok(),
    };
    let mut curves: Vec<MapCurve> = Vec::new();
    let mut key: (Vec<u8>, Vec<u8>) = (Vec::new(), Vec::new());
    let mut seen = HashSet::new();
    let mut record = csv::ByteRecord::new();
    while rdr.read_byte_record(&mut record).map_err(io)? {
        let line = record.position().map_or(0, |p| p.line());
        let field = |i: usize| record.get(i).unwrap_or(b"");
        let (fx, fy) = (field(columns.x), field(columns.y));
        if curves.is_empty() || fx != key.0.as_slice() || fy != key.1.as_slice() {
            let (x, y) = (
                number(path, fx, format_args!("line {line}"), "x")?,
                number(path, fy, format_args!("line {line}"), "y")?,
            );
            if !seen.insert((x.to_bits(), y.to_bits())) {
                return Err(invalid(
                    path,
                    format!(
                        "line {line}: the rows of the curve at x = {x} m, y = {y} m are not \
                         consecutive (a curve is a run of rows of one position)"
                    ),
                ));
            }
            if curves.len() == MAX_MAP_CURVES {
                return Err(invalid(
                    path,
                    format!("more than {MAX_MAP_CURVES} curves (a 1024 × 1024 map)"),
                ));
            }
            key = (fx.to_vec(), fy.to_vec());
            curves.push(MapCurve {
                ix: 0,
                iy: 0,
                x,
                y,
                rows: 0,
                approach_rows: None,
                spring_constant: None,
                at: Location::Csv(record.position().map_or(0, |p| p.byte())),
            });
        }
        let c = curves.last_mut().expect("pushed");
        c.rows += 1;
        if c.rows > MAX_CURVE_ROWS {
            return Err(invalid(
                path,
                format!("line {line}: a curve of more than {MAX_CURVE_ROWS} rows"),
            ));
        }
        if let Some(s) = columns.segment {
            if number(path, field(s), format_args!("line {line}"), "segment")? == 0.0 {
                *c.approach_rows.get_or_insert(0) += 1;
            }
        }
    }
    Ok((columns, curves))
}

/// Row `.0` of the curve `.1`, as a refusal names it.
#[cfg(feature = "files")]
struct Row<'a>(u64, &'a MapCurve);

#[cfg(feature = "files")]
impl std::fmt::Display for Row<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "row {} of the curve at x = {} m, y = {} m",
            self.0, self.1.x, self.1.y
        )
    }
}

/// The rows of `curve` from where the CSV `file` stands (its first row).
#[cfg(feature = "files")]
fn csv_rows(
    path: &Path,
    file: &mut std::fs::File,
    columns: CsvColumns,
    curve: &MapCurve,
) -> Result<CurveRows, InputFileError> {
    let rows = curve.rows;
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(std::io::BufReader::new(file));
    let mut out = CurveRows {
        height: Vec::with_capacity(rows),
        force: Vec::with_capacity(rows),
        time: columns.time.map(|_| Vec::with_capacity(rows)),
    };
    let mut record = csv::ByteRecord::new();
    for row in 1..=rows as u64 {
        let read = rdr
            .read_byte_record(&mut record)
            .map_err(|e| invalid(path, e))?;
        if !read {
            return Err(invalid(
                path,
                "changed since it was indexed: rows are missing",
            ));
        }
        let field = |i: usize| record.get(i).unwrap_or(b"");
        out.height.push(number(
            path,
            field(columns.height),
            Row(row, curve),
            "height",
        )?);
        out.force.push(number(
            path,
            field(columns.force),
            Row(row, curve),
            "force",
        )?);
        if let (Some(t), Some(i)) = (out.time.as_mut(), columns.time) {
            t.push(number(path, field(i), Row(row, curve), "time")?);
        }
    }
    Ok(out)
}

#[cfg(feature = "files")]
/// A file whose reads fail past [`MAX_NETCDF_HEADER_BYTES`] until its header has parsed (the
/// NetCDF reader grows its header buffer until the header parses: a corrupt header would read
/// the whole file into memory).
struct HeaderCapped {
    file: std::fs::File,
    parsed: Arc<AtomicBool>,
}

#[cfg(feature = "files")]
impl Read for HeaderCapped {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if !self.parsed.load(Ordering::Relaxed)
            && self.file.stream_position()? > MAX_NETCDF_HEADER_BYTES
        {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("no NetCDF header within its first {MAX_NETCDF_HEADER_BYTES} bytes"),
            ));
        }
        self.file.read(buf)
    }
}

#[cfg(feature = "files")]
impl Seek for HeaderCapped {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.file.seek(pos)
    }
}

#[cfg(feature = "files")]
/// The NetCDF file `path` opened, its header parsed within its cap.
fn open_netcdf(path: &Path) -> Result<netcdf3::FileReader, InputFileError> {
    let file = std::fs::File::open(path).map_err(|e| failure(path, &e))?;
    let parsed = Arc::new(AtomicBool::new(false));
    let capped = HeaderCapped {
        file,
        parsed: Arc::clone(&parsed),
    };
    let name = path.display().to_string();
    let reader = netcdf3::FileReader::open_seek_read(&name, Box::new(capped))
        .map_err(|e| invalid(path, format!("not a NetCDF-3 map: {}", read_error(&e))))?;
    parsed.store(true, Ordering::Relaxed);
    Ok(reader)
}

#[cfg(feature = "files")]
/// A NetCDF reader's error in words (the crate's own `Display` is its `Debug`).
fn read_error(e: &netcdf3::error::ReadError) -> String {
    use netcdf3::error::ReadError as E;
    match e {
        E::ParseHeader(_) if e.header_is_incomplete() => {
            "its header ends early (a truncated file?)".into()
        }
        E::ParseHeader(_) => "its header is not that of a NetCDF-3 file".into(),
        E::DataSet(d) => d.to_string(),
        E::VariableNotDefined(name) => format!("the file has no variable {name}"),
        E::VariableMismatchDataType { var_name, req, get } => {
            format!("{var_name} holds {get}, not {req}")
        }
        E::IOErrorKind(kind) => format!("reading it failed: {kind}"),
        E::RecordIndexExceeded { index, num_records } => {
            format!("record {index} is beyond its {num_records} records")
        }
        E::ComputationNumberOfRecords | E::Unexpected => {
            "its records are malformed (their count or sizes)".into()
        }
    }
}

#[cfg(feature = "files")]
/// The per-curve variable `name` of a NetCDF map as numbers.
fn per_curve(
    path: &Path,
    r: &mut netcdf3::FileReader,
    name: &str,
) -> Result<Vec<f64>, InputFileError> {
    use netcdf3::DataVector as D;
    let v = r
        .read_var(name)
        .map_err(|e| invalid(path, format!("variable {name}: {}", read_error(&e))))?;
    Ok(match v {
        D::I8(v) => v.into_iter().map(f64::from).collect(),
        D::U8(v) => v.into_iter().map(f64::from).collect(),
        D::I16(v) => v.into_iter().map(f64::from).collect(),
        D::I32(v) => v.into_iter().map(f64::from).collect(),
        D::F32(v) => v.into_iter().map(f64::from).collect(),
        D::F64(v) => v,
    })
}

#[cfg(feature = "files")]
/// The curves of the NetCDF map `path` (the module doc).
fn netcdf_index(path: &Path) -> Result<Vec<MapCurve>, InputFileError> {
    let mut r = open_netcdf(path)?;
    let ds = r.data_set();
    let dim = |name: &str| ds.dim_size(name);
    let (Some(curves), Some(rows)) = (dim("curve"), dim("row")) else {
        return Err(invalid(
            path,
            "no dimensions curve and row: not a map afmdyn.export_map wrote",
        ));
    };
    if curves > MAX_MAP_CURVES || rows > MAX_CURVE_ROWS {
        return Err(invalid(
            path,
            format!(
                "{curves} curves of up to {rows} rows: at most {MAX_MAP_CURVES} curves of \
                 {MAX_CURVE_ROWS} rows"
            ),
        ));
    }
    for name in ["height", "force"] {
        let dims = ds.get_var(name).map(|v| v.dim_names());
        if dims.as_deref() != Some(&["curve".to_string(), "row".to_string()][..]) {
            return Err(invalid(
                path,
                format!("no variable {name} over (curve, row)"),
            ));
        }
    }
    let [x, y, ix, iy, n, approach, k] = [
        "x",
        "y",
        "ix",
        "iy",
        "rows",
        "approach_rows",
        "spring_constant",
    ]
    .map(|name| per_curve(path, &mut r, name));
    let (x, y, ix, iy, n, approach, k) = (x?, y?, ix?, iy?, n?, approach?, k?);
    let index = |v: f64, what: &str| -> Result<usize, InputFileError> {
        (v >= 0.0 && v.fract() == 0.0 && v < 4096.0)
            .then_some(v as usize)
            .ok_or_else(|| invalid(path, format!("{what} = {v}: an index 0..4096")))
    };
    (0..curves)
        .map(|i| {
            let count = (n[i] >= 0.0 && n[i].fract() == 0.0 && n[i] <= rows as f64)
                .then_some(n[i] as usize)
                .ok_or_else(|| {
                    invalid(path, format!("curve {i}: rows = {}, not 0..={rows}", n[i]))
                })?;
            Ok(MapCurve {
                ix: index(ix[i], "ix")?,
                iy: index(iy[i], "iy")?,
                x: x[i],
                y: y[i],
                rows: count,
                approach_rows: (approach[i] >= 1.0).then_some(approach[i] as usize),
                spring_constant: (k[i] > 0.0).then_some(k[i]),
                at: Location::Record(i),
            })
        })
        .collect()
}

#[cfg(feature = "files")]
/// The first `rows` rows of record `record` of a NetCDF map.
fn netcdf_rows(
    path: &Path,
    r: &mut netcdf3::FileReader,
    record: usize,
    rows: usize,
) -> Result<CurveRows, InputFileError> {
    let has_time = r.data_set().has_var("time");
    let mut row = |name: &str| -> Result<Vec<f64>, InputFileError> {
        let mut v = r
            .read_record_f64(name, record)
            .map_err(|e| invalid(path, format!("{name}, curve {record}: {}", read_error(&e))))?;
        v.truncate(rows);
        Ok(v)
    };
    let height = row("height")?;
    let force = row("force")?;
    let time = if has_time { Some(row("time")?) } else { None };
    Ok(CurveRows {
        height,
        force,
        time,
    })
}
