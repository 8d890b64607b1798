//! Plots (PNG and SVG) with plotters, using the bundled DejaVu Sans font (no system libraries).

use crate::error::CliError;
use crate::output::atomic;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

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
    /// Palette index.
    pub color: usize,
}

/// A 2-D figure.
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
}

/// Number of palette colours.
const PALETTE: usize = 10;

/// Palette colour `i`.
pub fn color(i: usize) -> RGBColor {
    const P: [RGBColor; PALETTE] = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(127, 127, 127),
        RGBColor(188, 189, 34),
        RGBColor(23, 190, 207),
    ];
    P[i % P.len()]
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
    let pad = |lo: f64, hi: f64| {
        let d = (hi - lo).abs().max(1e-12);
        (lo - 0.03 * d, hi + 0.03 * d)
    };
    let (x0, x1) = pad(b.0, b.1);
    let (y0, y1) = pad(b.2, b.3);
    (x0, x1, y0, y1)
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    fig: &Figure,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let (x0, x1, y0, y1) = bounds(fig);
    let mut chart = ChartBuilder::on(&root)
        .caption(&fig.title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(fig.x_label.as_str())
        .y_desc(fig.y_label.as_str())
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(|e| e.to_string())?;
    let shade = RGBColor(200, 200, 200).mix(0.5);
    chart
        .draw_series(
            fig.shade
                .iter()
                .map(|&(a, b)| Rectangle::new([(a, y0), (b, y1)], shade.filled())),
        )
        .map_err(|e| e.to_string())?;
    let mut legend = false;
    for s in &fig.series {
        let c = color(s.color);
        let anno = match s.style {
            Style::Line => chart
                .draw_series(LineSeries::new(s.points.iter().copied(), c.stroke_width(2)))
                .map_err(|e| e.to_string())?,
            Style::Points => chart
                .draw_series(s.points.iter().map(|&p| Circle::new(p, 4, c.filled())))
                .map_err(|e| e.to_string())?,
            Style::Dots => chart
                .draw_series(
                    s.points
                        .iter()
                        .map(|&p| Circle::new(p, 1, c.mix(0.6).filled())),
                )
                .map_err(|e| e.to_string())?,
            Style::Dashed => chart
                .draw_series(DashedLineSeries::new(
                    s.points.iter().copied(),
                    6,
                    4,
                    c.stroke_width(2),
                ))
                .map_err(|e| e.to_string())?,
        };
        if !s.label.is_empty() {
            legend = true;
            anno.label(s.label.clone())
                .legend(move |(x, y)| Rectangle::new([(x, y - 4), (x + 16, y + 4)], c.filled()));
        }
    }
    if legend {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())?;
    Ok(())
}

/// Write `stem.png` and `stem.svg` in `dir`, each atomically.
pub fn save(dir: &Path, stem: &str, fig: &Figure) -> Result<(), CliError> {
    register_font();
    let size = (1000, 650);
    atomic(&dir.join(format!("{stem}.png")), |tmp| {
        draw(BitMapBackend::new(tmp, size).into_drawing_area(), fig)
            .map_err(|e| CliError::Io(format!("plot {stem}.png: {e}")))
    })?;
    atomic(&dir.join(format!("{stem}.svg")), |tmp| {
        draw(SVGBackend::new(tmp, size).into_drawing_area(), fig)
            .map_err(|e| CliError::Io(format!("plot {stem}.svg: {e}")))
    })
}

/// Draws one chunk of (x, y, palette index) points.
pub type ChunkSink<'a> = dyn FnMut(&[(f64, f64, usize)]) -> Result<(), String> + 'a;
/// Streams all chunks of a scatter plot into a [`ChunkSink`].
pub type ChunkFeed<'a> = dyn Fn(&mut ChunkSink<'_>) -> Result<(), CliError> + 'a;

/// A scatter plot drawn from a stream of points in chunks (the bifurcation diagram), so that the
/// points are never all in memory. `bounds` = (x0, x1, y0, y1); `feed` is called once per
/// backend and hands chunks of (x, y, palette index) to its callback.
pub fn save_scatter_stream(
    dir: &Path,
    stem: &str,
    title: &str,
    labels: (&str, &str),
    bounds: (f64, f64, f64, f64),
    legend: &[(String, usize)],
    feed: &ChunkFeed<'_>,
) -> Result<(), CliError> {
    register_font();
    fn go<DB: DrawingBackend>(
        root: DrawingArea<DB, plotters::coord::Shift>,
        title: &str,
        labels: (&str, &str),
        b: (f64, f64, f64, f64),
        legend: &[(String, usize)],
        feed: &ChunkFeed<'_>,
    ) -> Result<(), CliError>
    where
        DB::ErrorType: 'static,
    {
        let e = |x: String| CliError::Io(format!("plot: {x}"));
        root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
        let pad = |lo: f64, hi: f64| {
            let d = (hi - lo).abs().max(1e-9);
            (lo - 0.02 * d, hi + 0.02 * d)
        };
        let (x0, x1) = pad(b.0, b.1);
        let (y0, y1) = pad(b.2, b.3);
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|x| e(x.to_string()))?;
        chart
            .configure_mesh()
            .x_desc(labels.0)
            .y_desc(labels.1)
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(|x| e(x.to_string()))?;
        // one marker per (pixel, colour): memory and file size stay bounded by the canvas,
        // not by the number of points (an SVG would otherwise grow with the sweep)
        let (w, h) = root.dim_in_pixel();
        let (w, h) = (w as usize + 1, h as usize + 1);
        let mut seen = vec![0u64; (w * h * PALETTE).div_ceil(64)];
        feed(&mut |chunk| {
            let fresh: Vec<(f64, f64, usize)> = chunk
                .iter()
                .copied()
                .filter(|&(x, y, c)| {
                    let (px, py) = chart.backend_coord(&(x, y));
                    if px < 0 || py < 0 || px as usize >= w || py as usize >= h {
                        return false;
                    }
                    let bit = (py as usize * w + px as usize) * PALETTE + c % PALETTE;
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
        })?;
        for (label, c) in legend {
            let col = color(*c);
            chart
                .draw_series(std::iter::once(Circle::new(
                    (f64::NAN, f64::NAN),
                    0,
                    col.filled(),
                )))
                .map_err(|x| e(x.to_string()))?
                .label(label.clone())
                .legend(move |(x, y)| Circle::new((x + 8, y), 4, col.filled()));
        }
        if !legend.is_empty() {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 14))
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(|x| e(x.to_string()))?;
        }
        root.present().map_err(|x| e(x.to_string()))?;
        Ok(())
    }
    let size = (1200, 750);
    atomic(&dir.join(format!("{stem}.png")), |tmp| {
        go(
            BitMapBackend::new(tmp, size).into_drawing_area(),
            title,
            labels,
            bounds,
            legend,
            feed,
        )
    })?;
    atomic(&dir.join(format!("{stem}.svg")), |tmp| {
        go(
            SVGBackend::new(tmp, size).into_drawing_area(),
            title,
            labels,
            bounds,
            legend,
            feed,
        )
    })
}
