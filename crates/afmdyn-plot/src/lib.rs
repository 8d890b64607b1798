//! Plots (PNG and SVG) with plotters, using the bundled DejaVu Sans font (no system libraries).
//!
//! The one plotting module of the front ends: the command line renders every figure with it.
//!
//! * Every figure is rendered in memory and written atomically
//!   ([`afmdyn::layout::files::write_bytes`]), so a failed write names its file and never
//!   surfaces a backend's debug text ([`PlotError`]).
//! * Series are decimated to the canvas before drawing: a monotone series (a time series, a
//!   spectrum) keeps per pixel column its first, lowest, highest and last point, which draws the
//!   same picture as all points; any other line drops repeated pixels and already drawn
//!   segments; markers keep one per pixel. Files stay small whatever the number of points.
//! * Legends sit in a panel right of the data area, never over the data.

#![warn(missing_docs)]

use afmdyn::layout::files::{write_bytes, FileError};
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
/// The colour type of the figures' palettes, re-exported for the front ends' cell maps.
pub use plotters::style::RGBColor;
use std::collections::HashSet;
use std::path::Path;
use std::sync::Once;

/// Why a figure was not written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The backend failed to draw (its message, with the file it was drawing).
    #[error("cannot draw {path}: {message}")]
    Draw {
        /// The file being drawn.
        path: String,
        /// The backend's message.
        message: String,
    },
    /// The file could not be written.
    #[error(transparent)]
    File(#[from] FileError),
    /// A streamed scatter's points could not be read.
    #[error(transparent)]
    Feed(#[from] afmdyn::layout::figure::FeedError),
}

static PLAIN_SI: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Label axes and values in plain SI units (m, N, Hz) instead of prefixed ones (nm, pN, kHz):
/// the process's display units, set once by the front end.
pub fn set_plain_si(plain: bool) {
    PLAIN_SI.store(plain, std::sync::atomic::Ordering::Relaxed);
}

/// Whether the process displays plain SI units ([`set_plain_si`]).
pub fn plain_si() -> bool {
    PLAIN_SI.load(std::sync::atomic::Ordering::Relaxed)
}

/// The SI prefix for a magnitude in the process's display units
/// ([`afmdyn::report::si_prefix`]; none when [`set_plain_si`] asked for plain SI).
pub fn si_prefix(mag: f64) -> (i32, &'static str) {
    afmdyn::report::si_prefix(mag, plain_si())
}

static FONT: Once = Once::new();

fn register_font() {
    FONT.call_once(|| {
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            include_bytes!("../assets/DejaVuSans.ttf"),
        );
    });
}

pub use afmdyn::layout::figure::{
    AfmImage, CellMap, Figure, IdSeries, Plot, Rgb, Series, StackedFractions, Style,
};

/// Palette colour `i` ([`afmdyn::layout::figure::palette`]).
pub fn color(i: usize) -> RGBColor {
    rgb(afmdyn::layout::figure::palette(i))
}

/// A figure's colour as the backend's.
pub fn rgb(c: Rgb) -> RGBColor {
    RGBColor(c.0, c.1, c.2)
}

/// A legend entry: label, palette index, marker (true) or line swatch.
pub type LegendEntry = (String, usize, bool);

/// Something drawn on a canvas of any backend.
trait Painter {
    /// Paint on `root`; `bitmap` for the raster backend.
    fn paint<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
        bitmap: bool,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static;
}

fn png<P: Painter>(size: (u32, u32), p: &P) -> Result<Vec<u8>, String> {
    use image::ImageEncoder;
    let mut buf = vec![255u8; size.0 as usize * size.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        p.paint(root, true)?;
    }
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&buf, size.0, size.1, image::ColorType::Rgb8)
        .map_err(|e| e.to_string())?;
    Ok(out)
}

fn svg<P: Painter>(size: (u32, u32), p: &P) -> Result<String, String> {
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        p.paint(root, false)?;
    }
    Ok(text)
}

/// Write `stem.png` and `stem.svg` of `p` in `dir`, each atomically.
fn write_both<P: Painter>(
    dir: &Path,
    stem: &str,
    size: (u32, u32),
    p: &P,
) -> Result<(), PlotError> {
    register_font();
    let fail = |ext: &str, message: String| PlotError::Draw {
        path: dir.join(format!("{stem}.{ext}")).display().to_string(),
        message,
    };
    let bytes = png(size, p).map_err(|e| fail("png", e))?;
    write_bytes(&dir.join(format!("{stem}.png")), &bytes)?;
    let text = svg(size, p).map_err(|e| fail("svg", e))?;
    Ok(write_bytes(
        &dir.join(format!("{stem}.svg")),
        text.as_bytes(),
    )?)
}

/// Break a legend label into lines of at most ~26 characters.
fn wrap(label: &str) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in label.split(' ') {
        let cur = lines.last_mut().expect("a line");
        if !cur.is_empty() && cur.chars().count() + 1 + word.chars().count() > 26 {
            lines.push(word.to_string());
        } else {
            if !cur.is_empty() {
                cur.push(' ');
            }
            cur.push_str(word);
        }
    }
    lines
}

/// Title on top; the rest split into the data area and, when there are legend entries, a
/// legend panel on the right (drawn here).
fn layout<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    legend: &[LegendEntry],
) -> Result<DrawingArea<DB, Shift>, String>
where
    DB::ErrorType: 'static,
{
    let entries: Vec<(String, RGBColor, bool)> = legend
        .iter()
        .map(|(l, c, m)| (l.clone(), color(*c), *m))
        .collect();
    layout_rgb(root, title, &entries)
}

/// [`layout`] with the legend's colours given (marker: a dot; else a swatch).
fn layout_rgb<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    legend: &[(String, RGBColor, bool)],
) -> Result<DrawingArea<DB, Shift>, String>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let body = root
        .titled(title, ("sans-serif", 22))
        .map_err(|e| e.to_string())?;
    if legend.is_empty() {
        return Ok(body);
    }
    let (w, _) = body.dim_in_pixel();
    let (plot, panel) = body.split_horizontally(w.saturating_sub(215));
    let font = ("sans-serif", 14).into_font().color(&BLACK);
    let mut y = 40;
    for (label, col, marker) in legend {
        if *marker {
            panel
                .draw(&Circle::new((20, y), 4, col.filled()))
                .map_err(|e| e.to_string())?;
        } else {
            panel
                .draw(&Rectangle::new([(10, y - 6), (30, y + 6)], col.filled()))
                .map_err(|e| e.to_string())?;
            // an outline, so that a white swatch (λ₁ = 0 on a diverging scale) shows
            panel
                .draw(&Rectangle::new(
                    [(10, y - 6), (30, y + 6)],
                    RGBColor(120, 120, 120).stroke_width(1),
                ))
                .map_err(|e| e.to_string())?;
        }
        for line in wrap(label) {
            panel
                .draw_text(&line, &font, (38, y - 8))
                .map_err(|e| e.to_string())?;
            y += 18;
        }
        y += 6;
    }
    Ok(plot)
}

fn bounds(fig: &Figure) -> (f64, f64, f64, f64) {
    let mut b = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for s in &fig.series {
        for &(x, y) in &s.points {
            if x.is_finite() && y.is_finite() {
                b = (b.0.min(x), b.1.max(x), b.2.min(y), b.3.max(y));
            }
        }
    }
    if !b.0.is_finite() {
        return (0.0, 1.0, 0.0, 1.0);
    }
    if b.3 - b.2 < fig.y_min_span {
        let mid = 0.5 * (b.2 + b.3);
        b.2 = mid - 0.5 * fig.y_min_span;
        b.3 = mid + 0.5 * fig.y_min_span;
    }
    padded(b, 0.03)
}

/// Merge shaded x-intervals whose pixel columns touch.
fn merge_shade(shade: &[(f64, f64)], px: impl Fn(f64) -> i32) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64, i32)> = Vec::new();
    let mut sorted = shade.to_vec();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (a, b) in sorted {
        match out.last_mut() {
            Some(last) if px(a) <= last.2 + 1 => {
                if b > last.1 {
                    last.1 = b;
                    last.2 = px(b);
                }
            }
            _ => out.push((a, b, px(b))),
        }
    }
    out.into_iter().map(|(a, b, _)| (a, b)).collect()
}

/// A tick label: 0 for round-off around zero (never "-0.0"); one notation for the whole axis,
/// chosen by its extent `span` (and the value's size): plain decimals, as many as the extent
/// needs, when both lie in 1e-3..1e5, else scientific notation — an axis over ±0.002 reads
/// 0.0015, 0.001, 0.0005, not 0.0015 beside 1.00e-3.
fn tick(v: f64, span: f64) -> String {
    let a = v.abs();
    if a <= 1e-9 * span {
        return "0".into();
    }
    let m = a.max(span.abs());
    if !(1e-3..1e5).contains(&m) || a < 1e-4 * m {
        return format!("{v:.2e}");
    }
    let decimals = (3 - span.abs().log10().floor() as i32).clamp(0, 8) as usize;
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    s.to_string()
}

/// Pad a data range (x0, x1, y0, y1) by `frac` of its extent on each side. A range of one
/// value (within 1e-12 of its magnitude) gets an extent of 1e-3 of its magnitude (1 around 0):
/// relative, so that data in SI units (energies of 1e-18 J, distances of 1e-9 m) fill the axis
/// (issue 28: an absolute floor of 1e-12 drew them as flat lines on a ±3e-14 axis).
fn padded(b: (f64, f64, f64, f64), frac: f64) -> (f64, f64, f64, f64) {
    let pad = |lo: f64, hi: f64| {
        let (span, scale) = ((hi - lo).abs(), lo.abs().max(hi.abs()));
        let d = if span > 1e-12 * scale {
            span
        } else if scale > 0.0 {
            1e-3 * scale
        } else {
            1.0
        };
        (lo - frac * d, hi + frac * d)
    };
    let (x0, x1) = pad(b.0, b.1);
    let (y0, y1) = pad(b.2, b.3);
    (x0, x1, y0, y1)
}

/// An axis over [lo, hi] whose tick positions are plotters' own, computed at the scale of
/// the data: plotters returns a single tick for a range narrower than f64::EPSILON (so an SI
/// energy axis of 1e-18 J had one label); the key points of the range divided by a power of
/// ten near its magnitude, multiplied back, are the same ticks at any scale.
struct Axis {
    inner: RangedCoordf64,
    /// The power of ten the key points are computed at.
    f: f64,
}

impl Axis {
    fn new(lo: f64, hi: f64) -> Self {
        let mag = lo.abs().max(hi.abs());
        let f = if mag > 0.0 && mag.is_finite() {
            10f64.powf(mag.log10().floor())
        } else {
            1.0
        };
        Axis {
            inner: (lo..hi).into(),
            f,
        }
    }
}

impl Ranged for Axis {
    type ValueType = f64;
    type FormatOption = DefaultFormatting;
    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(v, limit)
    }
    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        let r = self.inner.range();
        let unit: RangedCoordf64 = (r.start / self.f..r.end / self.f).into();
        unit.key_points(hint)
            .into_iter()
            .map(|v| v * self.f)
            .collect()
    }
    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }
}

/// The description and tick divisor of an axis over [lo, hi] labelled `label`: a label that
/// ends in an SI unit in parentheses — " (m)", " (Hz)", " (J)", " (N)", " (W)", " (s)",
/// " (Pa)" — gets the prefix (a … G) of the axis's magnitude, and its ticks are divided by it
/// (an approach curve's z_c axis reads 2, 4, 6 "(nm)" instead of 2.00e-9 "(m)").
fn si_axis(label: &str, lo: f64, hi: f64) -> (String, f64) {
    const UNITS: [&str; 7] = ["m", "Hz", "J", "N", "W", "s", "Pa"];
    let unit = label
        .strip_suffix(')')
        .and_then(|l| l.rsplit_once(" ("))
        .filter(|(_, u)| UNITS.contains(u));
    let mag = lo.abs().max(hi.abs());
    let Some((head, u)) = unit else {
        return (label.to_string(), 1.0);
    };
    if !(mag > 0.0 && mag.is_finite()) {
        return (label.to_string(), 1.0);
    }
    let (e, p) = si_prefix(mag);
    (format!("{head} ({p}{u})"), 10f64.powi(e))
}

/// The width in pixels of a y axis's labels over [y0, y1] described by `label`: room for the
/// widest tick label beside the axis description (never overprinted).
fn y_label_width(y0: f64, y1: f64, label: &str) -> u32 {
    let (_, fy) = si_axis(label, y0, y1);
    let ys = (y1 - y0) / fy;
    let widest = [y0, y1, 0.5 * (y0 + y1), 0.25 * y0 + 0.75 * y1]
        .iter()
        .map(|v| tick(*v / fy, ys).chars().count())
        .max()
        .unwrap_or(4) as u32;
    (widest * 9 + 34).max(70)
}

/// The chart of a data area with its axes, mesh and labels over (x0, x1, y0, y1).
fn chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    labels: (&str, &str),
) -> Result<ChartContext<'a, DB, Cartesian2d<Axis, Axis>>, String>
where
    DB::ErrorType: 'static,
{
    // an axis in an SI unit reads in the prefixed unit of its magnitude (nm, kHz, aJ)
    let ((xd, fx), (yd, fy)) = (si_axis(labels.0, x0, x1), si_axis(labels.1, y0, y1));
    let (xs, ys) = ((x1 - x0) / fx, (y1 - y0) / fy);
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(y_label_width(y0, y1, labels.1))
        .build_cartesian_2d(Axis::new(x0, x1), Axis::new(y0, y1))
        .map_err(|x| x.to_string())?;
    chart
        .configure_mesh()
        .x_desc(xd)
        .y_desc(yd)
        .x_label_formatter(&|v| tick(*v / fx, xs))
        .y_label_formatter(&|v| tick(*v / fy, ys))
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(|x| x.to_string())?;
    Ok(chart)
}

impl Painter for Figure {
    fn paint<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
        bitmap: bool,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let e = |x: &dyn std::fmt::Display| x.to_string();
        let legend: Vec<LegendEntry> = self
            .series
            .iter()
            .filter(|s| !s.label.is_empty())
            .map(|s| {
                (
                    s.label.clone(),
                    s.color,
                    matches!(s.style, Style::Points | Style::Dots),
                )
            })
            .collect();
        let area = layout(root, &self.title, &legend)?;
        let (x0, x1, y0, y1) = bounds(self);
        let mut chart = chart(&area, (x0, x1, y0, y1), (&self.x_label, &self.y_label))?;
        let px = |x: f64, y: f64| chart.backend_coord(&(x, y));
        let shade_color = RGBColor(200, 200, 200).mix(0.5);
        let shade = merge_shade(&self.shade, |x| px(x, y0).0);
        let mut shapes = Vec::new();
        for s in &self.series {
            let c = color(s.color);
            match s.style {
                Style::Line | Style::Dashed | Style::Dotted => {
                    for run in decimate_line(&s.points, px) {
                        shapes.push((run, c, s.style));
                    }
                }
                Style::Points | Style::Dots => {
                    shapes.push((decimate_points(&s.points, px), c, s.style));
                }
            }
        }
        chart
            .draw_series(
                shade
                    .iter()
                    .map(|&(a, b)| Rectangle::new([(a, y0), (b, y1)], shade_color.filled())),
            )
            .map_err(|x| e(&x))?;
        for (pts, c, style) in shapes {
            match style {
                // thick polylines get miter spikes at sharp turns in the bitmap backend: there,
                // short lines are drawn segment by segment and dense (decimated) ones 1 px wide
                Style::Line if bitmap && pts.len() <= 1500 => chart
                    .draw_series(
                        pts.windows(2)
                            .map(|w| PathElement::new(vec![w[0], w[1]], c.stroke_width(2))),
                    )
                    .map(|_| ()),
                Style::Line => chart
                    .draw_series(LineSeries::new(
                        pts,
                        c.stroke_width(if bitmap { 1 } else { 2 }),
                    ))
                    .map(|_| ()),
                Style::Dashed => chart
                    .draw_series(DashedLineSeries::new(pts, 6, 4, c.stroke_width(2)))
                    .map(|_| ()),
                Style::Dotted => chart
                    .draw_series(DashedLineSeries::new(pts, 2, 4, c.stroke_width(2)))
                    .map(|_| ()),
                Style::Points => chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 4, c.filled())))
                    .map(|_| ()),
                Style::Dots => chart
                    .draw_series(
                        pts.into_iter()
                            .map(|p| Circle::new(p, 1, c.mix(0.6).filled())),
                    )
                    .map(|_| ()),
            }
            .map_err(|x| e(&x))?;
        }
        area.present().map_err(|x| e(&x))?;
        Ok(())
    }
}

/// Write `stem.png` and `stem.svg` in `dir`, each atomically.
pub fn save(dir: &Path, stem: &str, fig: &Figure) -> Result<(), PlotError> {
    write_both(dir, stem, (1000, 650), fig)
}

/// Write `stem.png` and `stem.svg` of a figure of any kind in `dir`, each atomically.
pub fn save_plot(dir: &Path, stem: &str, plot: &Plot) -> Result<(), PlotError> {
    match plot {
        Plot::Lines(f) => save(dir, stem, f),
        Plot::Cells(m) => save_map(dir, stem, m),
        Plot::Stacked(s) => save_stacked(dir, stem, s),
        Plot::Image(i) => save_image(dir, stem, i),
        Plot::Scatter(s) => {
            let feed = |draw: &mut ChunkSink<'_>| s.points.feed(draw).map_err(PlotError::Feed);
            let labels = (s.labels.0.as_str(), s.labels.1.as_str());
            save_scatter_stream(dir, stem, &s.title, labels, s.bounds, &s.legend, &feed)
        }
    }
}

/// Draws one chunk of (x, y, palette index) points.
pub type ChunkSink<'a> = dyn FnMut(&[(f64, f64, usize)]) -> Result<(), String> + 'a;
/// Streams all chunks of a scatter plot into a [`ChunkSink`], failing with the caller's error
/// `E`.
pub type ChunkFeed<'a, E> = dyn Fn(&mut ChunkSink<'_>) -> Result<(), E> + 'a;

struct Scatter<'a, E> {
    title: &'a str,
    labels: (&'a str, &'a str),
    bounds: (f64, f64, f64, f64),
    legend: &'a [LegendEntry],
    feed: &'a ChunkFeed<'a, E>,
    failure: std::cell::RefCell<Option<E>>,
}

impl<E: std::fmt::Display> Painter for Scatter<'_, E> {
    fn paint<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
        _bitmap: bool,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let e = |x: &dyn std::fmt::Display| x.to_string();
        let area = layout(root, self.title, self.legend)?;
        let mut chart = chart(&area, padded(self.bounds, 0.02), self.labels)?;
        // one marker per (pixel, colour): memory and file size stay bounded by the canvas,
        // not by the number of points (an SVG would otherwise grow with the sweep)
        let (w, h) = area.dim_in_pixel();
        let (w, h) = (w as usize + 1, h as usize + 1);
        let mut seen = vec![0u64; (w * h * afmdyn::layout::figure::PALETTE_LEN).div_ceil(64)];
        let fed = (self.feed)(&mut |chunk| {
            let fresh: Vec<(f64, f64, usize)> = chunk
                .iter()
                .copied()
                .filter(|&(x, y, c)| {
                    let (px, py) = chart.backend_coord(&(x, y));
                    if px < 0 || py < 0 || px as usize >= w || py as usize >= h {
                        return false;
                    }
                    let bit = (py as usize * w + px as usize) * afmdyn::layout::figure::PALETTE_LEN
                        + c % afmdyn::layout::figure::PALETTE_LEN;
                    let (word, mask) = (bit / 64, 1u64 << (bit % 64));
                    let new = seen[word] & mask == 0;
                    seen[word] |= mask;
                    new
                })
                .collect();
            chart
                .draw_series(
                    fresh
                        .iter()
                        .map(|&(x, y, c)| Circle::new((x, y), 1, color(c).filled())),
                )
                .map(|_| ())
                .map_err(|x| x.to_string())
        });
        if let Err(err) = fed {
            let msg = err.to_string();
            *self.failure.borrow_mut() = Some(err);
            return Err(msg);
        }
        area.present().map_err(|x| e(&x))?;
        Ok(())
    }
}

/// A scatter plot drawn from a stream of points in chunks (the bifurcation diagram), so that the
/// points are never all in memory. `bounds` = (x0, x1, y0, y1); `feed` is called once per
/// backend and hands chunks of (x, y, palette index) to its callback.
pub fn save_scatter_stream<E: std::fmt::Display + From<PlotError>>(
    dir: &Path,
    stem: &str,
    title: &str,
    labels: (&str, &str),
    bounds: (f64, f64, f64, f64),
    legend: &[LegendEntry],
    feed: &ChunkFeed<'_, E>,
) -> Result<(), E> {
    let s = Scatter {
        title,
        labels,
        bounds,
        legend,
        feed,
        failure: std::cell::RefCell::new(None),
    };
    write_both(dir, stem, (1200, 750), &s).map_err(|e| s.failure.take().unwrap_or(E::from(e)))
}

mod cells;
pub use cells::*;
mod decimate;
pub use decimate::*;
mod afm_image;
pub use afm_image::*;

#[cfg(test)]
mod tests;
