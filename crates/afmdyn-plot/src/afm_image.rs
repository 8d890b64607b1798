//! AFM images as an instrument's software shows them ([`AfmImage`]): a dark-to-bright colour
//! map (dark = low, as Gwyddion's and NanoScope's defaults), a colour bar with the quantity's
//! unit beside the image, and the scan's true aspect ratio (one metre is as long along y as
//! along x).

use super::*;

/// The colour map of AFM images at t ∈ [0, 1]: black → red → yellow → white, matplotlib's
/// `afmhot` (r = 2t, g = 2t − ½, b = 2t − 1, each clipped to [0, 1]), monotone in lightness so
/// that dark is low.
pub fn afmhot(t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let c = |v: f64| (255.0 * v.clamp(0.0, 1.0)).round() as u8;
    RGBColor(c(2.0 * t), c(2.0 * t - 0.5), c(2.0 * t - 1.0))
}

/// Width of the colour bar's panel, pixels.
const BAR_PANEL: u32 = 190;

/// Sizing of an AFM image's canvas.
pub(crate) trait ImageExt {
    fn range(&self) -> (f64, f64);
    fn canvas(&self) -> (u32, u32);
}

impl ImageExt for AfmImage {
    /// The finite range of the values (lo, hi), hi > lo (a flat image gets ±½ of its level's
    /// magnitude, or ±½).
    fn range(&self) -> (f64, f64) {
        let finite = self.values.iter().copied().filter(|v| v.is_finite());
        let lo = finite.clone().fold(f64::INFINITY, f64::min);
        let hi = finite.fold(f64::NEG_INFINITY, f64::max);
        if !lo.is_finite() {
            return (0.0, 1.0);
        }
        if hi > lo {
            return (lo, hi);
        }
        let h = if lo != 0.0 { 0.5 * lo.abs() } else { 0.5 };
        (lo - h, hi + h)
    }

    /// The canvas (width, height) in pixels whose data area has the scan's aspect ratio
    /// (Ly/Lx of the pixel edges, kept within [0.08, 1.5]: a single line is drawn as a strip).
    fn canvas(&self) -> (u32, u32) {
        let (_, _, (x0, x1, y0, y1)) = cell_grid(&self.x, &self.y);
        let aspect = if self.y.len() < 2 {
            0.08
        } else {
            ((y1 - y0) / (x1 - x0)).clamp(0.08, 1.5)
        };
        // the data area is the canvas less the colour bar, the y labels and the margins
        // (chart's: 12 each side); the height adds the title (about 40), the x labels (45)
        // and the margins
        let labels = y_label_width(y0, y1, "y (m)");
        let data_w = 700u32;
        (
            data_w + BAR_PANEL + labels + 24,
            (f64::from(data_w) * aspect).round() as u32 + 40 + 45 + 24,
        )
    }
}

impl Painter for AfmImage {
    fn paint<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
        _bitmap: bool,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let s = |x: &dyn std::fmt::Display| x.to_string();
        let body = layout_rgb(root, &self.title, &[])?;
        let (w, _) = body.dim_in_pixel();
        let (plot, bar) = body.split_horizontally(w.saturating_sub(BAR_PANEL));
        let (lo, hi) = self.range();
        let (ex, ey, (x0, x1, y0, y1)) = cell_grid(&self.x, &self.y);
        let mut chart = chart(&plot, (x0, x1, y0, y1), ("x (m)", "y (m)"))?;
        let nx = self.x.len();
        let missing = RGBColor(190, 190, 190);
        let rects = self.values.iter().enumerate().map(|(k, &v)| {
            let (i, j) = (k % nx, k / nx);
            let c = if v.is_finite() {
                afmhot((v - lo) / (hi - lo))
            } else {
                missing
            };
            Rectangle::new([(ex[i], ey[j]), (ex[i + 1], ey[j + 1])], c.filled())
        });
        chart.draw_series(rects).map_err(|x| s(&x))?;
        // the colour bar: 256 bands from lo to hi, its axis in the quantity's unit
        let mut scale = chart_on_bar(&bar, lo, hi, &self.label)?;
        let bands = 256;
        let step = (hi - lo) / f64::from(bands);
        scale
            .draw_series((0..bands).map(|b| {
                let v = lo + step * f64::from(b);
                Rectangle::new(
                    [(0.0, v), (1.0, v + step)],
                    afmhot((f64::from(b) + 0.5) / f64::from(bands)).filled(),
                )
            }))
            .map_err(|x| s(&x))?;
        plot.present().map_err(|x| s(&x))?;
        Ok(())
    }
}

/// The colour bar's chart: x over [0, 1] without labels, y over [lo, hi] described by
/// `label` (SI prefixed as every axis).
fn chart_on_bar<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    lo: f64,
    hi: f64,
    label: &str,
) -> Result<ChartContext<'a, DB, Cartesian2d<Axis, Axis>>, String>
where
    DB::ErrorType: 'static,
{
    let (yd, fy) = si_axis(label, lo, hi);
    let ys = (hi - lo) / fy;
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .margin_right(40)
        .x_label_area_size(45)
        .y_label_area_size(y_label_width(lo, hi, label))
        .build_cartesian_2d(Axis::new(0.0, 1.0), Axis::new(lo, hi))
        .map_err(|x| x.to_string())?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(yd)
        .y_label_formatter(&|v| tick(*v / fy, ys))
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(|x| x.to_string())?;
    Ok(chart)
}

/// Write `stem.png` and `stem.svg` of an AFM image in `dir`, each atomically, on a canvas of
/// the scan's aspect ratio.
pub fn save_image(dir: &Path, stem: &str, image: &AfmImage) -> Result<(), PlotError> {
    write_both(dir, stem, image.canvas(), image)
}
