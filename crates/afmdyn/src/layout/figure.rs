//! Figures as data: which variables are drawn against which, with their labels and styles,
//! declared by the library beside each result ([`crate::report::Presentation`]) and rendered
//! by one plotting module (the `afmdyn-plot` crate: PNG and SVG). No drawing happens here.
//!
//! Four kinds ([`Plot`]): line and marker plots ([`Figure`]), maps over a grid of cells
//! ([`CellMap`]: behaviour charts, basins), stacked basin fractions along a sweep
//! ([`StackedFractions`]) and AFM images ([`AfmImage`]).

/// An sRGB colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rgb(pub u8, pub u8, pub u8);

/// Number of palette colours.
pub const PALETTE_LEN: usize = 10;

/// Palette colour `i` (modulo [`PALETTE_LEN`]): matplotlib's `tab10`.
pub fn palette(i: usize) -> Rgb {
    const P: [Rgb; PALETTE_LEN] = [
        Rgb(31, 119, 180),
        Rgb(214, 39, 40),
        Rgb(44, 160, 44),
        Rgb(255, 127, 14),
        Rgb(148, 103, 189),
        Rgb(140, 86, 75),
        Rgb(227, 119, 194),
        Rgb(127, 127, 127),
        Rgb(188, 189, 34),
        Rgb(23, 190, 207),
    ];
    P[i % PALETTE_LEN]
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Style {
    /// Solid line.
    Line,
    /// Large dots (markers).
    Points,
    /// Small dots (a background cloud).
    Dots,
    /// Dashed line.
    Dashed,
    /// Dotted line (dots of 2 px, gaps of 4 px: e.g. an unstable branch).
    Dotted,
}

/// One plotted series.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label (empty: no legend entry).
    pub label: String,
    /// (x, y) points.
    pub points: Vec<(f64, f64)>,
    /// Style.
    pub style: Style,
    /// Palette index ([`palette`]).
    pub color: usize,
}

/// A 2-D figure of series.
#[derive(Debug, Clone)]
pub struct Figure {
    /// Title.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Series.
    pub series: Vec<Series>,
    /// Shaded x-intervals (e.g. contact intervals).
    pub shade: Vec<(f64, f64)>,
    /// The smallest extent of the y-axis (0: the data's own, padded): a physical scale below
    /// which variations are round-off — a conservative law's E_dis of 1e-27 J on a problem
    /// whose energies are 1e-15 J is drawn as the zero it is, not as noise filling the axis.
    pub y_min_span: f64,
}

/// A map over a grid of cells (a behaviour chart, a basin map): cell (ix, iy) is a rectangle
/// centred on (`x[ix]`, `y[iy]`) reaching halfway to its neighbours, filled with its colour
/// (`None`: left white); the legend sits right of the data.
#[derive(Debug, Clone)]
pub struct CellMap {
    /// Title.
    pub title: String,
    /// Axis labels (x, y).
    pub labels: (String, String),
    /// x values (columns).
    pub x: Vec<f64>,
    /// y values (rows).
    pub y: Vec<f64>,
    /// Colour of each cell, row-major (y slowest): `x.len() · y.len()` entries.
    pub cells: Vec<Option<Rgb>>,
    /// Legend: label, colour.
    pub legend: Vec<(String, Rgb)>,
    /// Points drawn over the cells (x, y): white rings.
    pub points: Vec<(f64, f64)>,
}

/// One id of a [`StackedFractions`] figure: its legend label and, per value, (basin fraction,
/// X_max) where it has an attractor.
pub type IdSeries = (String, Vec<Option<(f64, f64)>>);

/// A global continuation's figure: on top, the basin fractions of the attractors stacked over
/// the parameter (each id a band, in id order); below, each attractor's X_max over the
/// parameter (markers joined where consecutive values have the id).
#[derive(Debug, Clone)]
pub struct StackedFractions {
    /// Title.
    pub title: String,
    /// The parameter's axis label.
    pub x_label: String,
    /// The parameter's values.
    pub values: Vec<f64>,
    /// Per id: legend label and, per value, (basin fraction, X_max) where the id has an
    /// attractor.
    pub ids: Vec<IdSeries>,
}

/// An image over a scan: pixel (i, j) centred on (`x[i]`, `y[j]`), reaching halfway to its
/// neighbours, coloured by the `afmhot` colour map from the smallest to the largest finite
/// value; NaN pixels (no operating point) are left grey; drawn at the scan's aspect ratio.
#[derive(Debug, Clone)]
pub struct AfmImage {
    /// Title.
    pub title: String,
    /// Pixel centres along the fast axis x (m).
    pub x: Vec<f64>,
    /// Line positions y (m).
    pub y: Vec<f64>,
    /// The values, row-major (y slowest): `values[j * x.len() + i]`.
    pub values: Vec<f64>,
    /// The colour bar's description with its unit in parentheses, e.g. `"height (m)"` (an SI
    /// unit gets the prefix of the values' magnitude, as every axis).
    pub label: String,
}

/// A figure of any kind, as data.
#[derive(Debug, Clone)]
pub enum Plot {
    /// Series against one x axis.
    Lines(Figure),
    /// Coloured cells over two axes.
    Cells(CellMap),
    /// Stacked basin fractions and X_max along a sweep.
    Stacked(StackedFractions),
    /// An AFM image with its colour bar.
    Image(AfmImage),
    /// Points streamed from their source in chunks.
    Scatter(StreamedScatter),
}

/// One chunk of (x, y, palette index) points of a streamed scatter, drawn; a drawing failure
/// is its message.
pub type PointSink<'a> = dyn FnMut(&[(f64, f64, usize)]) -> Result<(), String> + 'a;

/// Where a streamed scatter's points come from, chunk by chunk (a store's table, read again
/// for each figure): the figure holds no points, so memory does not grow with them.
pub trait PointSource: std::fmt::Debug + Send + Sync {
    /// Every point, in chunks, into `draw`.
    ///
    /// # Errors
    /// The source's read error; `draw`'s as [`FeedError::Io`].
    fn feed(&self, draw: &mut PointSink<'_>) -> Result<(), FeedError>;
}

/// Why a streamed scatter's points could not be fed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum FeedError {
    /// The source is not what was written there, or is past its size cap (bad input).
    #[error("{0}")]
    Refused(String),
    /// Reading the source, or drawing, failed.
    #[error("{0}")]
    Io(String),
}

/// A scatter of many points streamed from their source (a bifurcation diagram over the
/// store's rows), on fixed bounds with a fixed legend.
#[derive(Debug, Clone)]
pub struct StreamedScatter {
    /// The title.
    pub title: String,
    /// The x and y axis labels.
    pub labels: (String, String),
    /// The axes' bounds (x0, x1, y0, y1).
    pub bounds: (f64, f64, f64, f64),
    /// The legend: label, palette index, drawn as a marker.
    pub legend: Vec<(String, usize, bool)>,
    /// The points.
    pub points: std::sync::Arc<dyn PointSource>,
}

/// A pixel column of a monotone line: column, (first, lowest, highest, last) point, and the
/// position of each in the input.
type PixelColumn = (i32, [(f64, f64); 4], [usize; 4]);

/// The pixel columns of a line monotone in x, point by point: per column its first, lowest,
/// highest and last point, written out (in their order, each once) when the next column
/// starts — the monotone case of the plotting module's `decimate_line`, also streamed by a
/// caller that gathers a long line (`simulate`'s plots, [`crate::request::simulate_stream`]).
#[derive(Debug, Clone, Default)]
pub struct PixelColumns {
    /// The open column.
    col: Option<PixelColumn>,
    k: usize,
}

impl PixelColumns {
    /// Add the finite point `q` of pixel column `cx` (columns non-decreasing), writing the
    /// column before into `out` when `cx` starts a new one.
    #[inline]
    pub fn push(&mut self, cx: i32, q: (f64, f64), out: &mut Vec<(f64, f64)>) {
        self.k += 1;
        let k = self.k;
        match &mut self.col {
            Some((c, p, order)) if *c == cx => {
                if q.1 < p[1].1 {
                    (p[1], order[1]) = (q, k);
                }
                if q.1 > p[2].1 {
                    (p[2], order[2]) = (q, k);
                }
                (p[3], order[3]) = (q, k);
            }
            _ => {
                self.flush(out);
                self.col = Some((cx, [q; 4], [k; 4]));
            }
        }
    }

    /// Write the open column into `out`.
    pub fn flush(&mut self, out: &mut Vec<(f64, f64)>) {
        if let Some((_, p, order)) = self.col.take() {
            let mut idx = [0usize, 1, 2, 3];
            idx.sort_by_key(|&i| order[i]);
            let mut last = None;
            for i in idx {
                if last != Some(order[i]) {
                    out.push(p[i]);
                    last = Some(order[i]);
                }
            }
        }
    }
}
