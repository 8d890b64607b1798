//! Plots over cells: a map of coloured cells over two axes ([`CellMap`]: charts, basins) and
//! stacked basin fractions along a sweep ([`StackedFractions`]).

use super::*;

/// The edges of the cells of an axis: midpoints between values, half a spacing beyond the
/// ends (a single value gets ±0.5 of its magnitude's order, at least ±0.5).
pub(crate) fn cell_edges(v: &[f64]) -> Vec<f64> {
    let n = v.len();
    if n == 1 {
        let h = if v[0] != 0.0 { 0.05 * v[0].abs() } else { 0.5 };
        return vec![v[0] - h, v[0] + h];
    }
    let mut e = Vec::with_capacity(n + 1);
    e.push(v[0] - (v[1] - v[0]) / 2.0);
    for w in v.windows(2) {
        e.push((w[0] + w[1]) / 2.0);
    }
    e.push(v[n - 1] + (v[n - 1] - v[n - 2]) / 2.0);
    e
}

/// The cell edges of both axes ([`cell_edges`]) and the extent they span, (x0, x1, y0, y1)
/// with x0 < x1 and y0 < y1 whatever the axes' order.
pub(crate) fn cell_grid(x: &[f64], y: &[f64]) -> (Vec<f64>, Vec<f64>, (f64, f64, f64, f64)) {
    let (ex, ey) = (cell_edges(x), cell_edges(y));
    let lo_hi = |e: &[f64]| {
        let (a, b) = (e[0], e[e.len() - 1]);
        (a.min(b), a.max(b))
    };
    let ((x0, x1), (y0, y1)) = (lo_hi(&ex), lo_hi(&ey));
    (ex, ey, (x0, x1, y0, y1))
}

impl Painter for CellMap {
    fn paint<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
        _bitmap: bool,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let entries: Vec<(String, RGBColor, bool)> = self
            .legend
            .iter()
            .map(|(l, c)| (l.clone(), rgb(*c), false))
            .collect();
        let area = layout_rgb(root, &self.title, &entries)?;
        let (ex, ey, (x0, x1, y0, y1)) = cell_grid(&self.x, &self.y);
        let labels = (self.labels.0.as_str(), self.labels.1.as_str());
        let mut chart = chart(&area, (x0, x1, y0, y1), labels)?;
        let nx = self.x.len();
        let rects = self.cells.iter().enumerate().filter_map(|(i, c)| {
            let (ix, iy) = (i % nx, i / nx);
            let c = (*c)?;
            Some(Rectangle::new(
                [(ex[ix], ey[iy]), (ex[ix + 1], ey[iy + 1])],
                rgb(c).filled(),
            ))
        });
        chart.draw_series(rects).map_err(|x| x.to_string())?;
        chart
            .draw_series(
                self.points
                    .iter()
                    .filter(|&&(x, y)| (x0..=x1).contains(&x) && (y0..=y1).contains(&y))
                    .map(|&p| Circle::new(p, 5, WHITE.stroke_width(2))),
            )
            .map_err(|x| x.to_string())?;
        area.present().map_err(|x| x.to_string())?;
        Ok(())
    }
}

/// Write `stem.png` and `stem.svg` of a cell map in `dir`, each atomically.
pub fn save_map(dir: &Path, stem: &str, map: &CellMap) -> Result<(), PlotError> {
    write_both(dir, stem, (1100, 700), map)
}

impl Painter for StackedFractions {
    fn paint<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
        _bitmap: bool,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let e = |x: &dyn std::fmt::Display| x.to_string();
        let legend: Vec<LegendEntry> = self
            .ids
            .iter()
            .enumerate()
            .map(|(i, (l, _))| (l.clone(), i, false))
            .collect();
        let area = layout(root, &self.title, &legend)?;
        let (top, bottom) = area.split_vertically(area.dim_in_pixel().1 / 2);
        let (x0, x1) = self
            .values
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let (x0, x1) = if x0.is_finite() { (x0, x1) } else { (0.0, 1.0) };
        let xb = padded((x0, x1, 0.0, 1.0), 0.0);
        let mut upper = chart(
            &top,
            (xb.0, xb.1, 0.0, 1.0),
            (&self.x_label, "basin fraction"),
        )?;
        // bands: the cumulative fractions below and above each id
        let mut below = vec![0.0; self.values.len()];
        for (i, (_, per_value)) in self.ids.iter().enumerate() {
            let above: Vec<f64> = below
                .iter()
                .zip(per_value)
                .map(|(b, p)| b + p.map_or(0.0, |(f, _)| f))
                .collect();
            let mut outline: Vec<(f64, f64)> = self
                .values
                .iter()
                .copied()
                .zip(above.iter().copied())
                .collect();
            outline.extend(self.values.iter().copied().zip(below.iter().copied()).rev());
            upper
                .draw_series(std::iter::once(Polygon::new(
                    outline,
                    color(i).mix(0.8).filled(),
                )))
                .map_err(|x| e(&x))?;
            below = above;
        }
        let ys: Vec<f64> = self
            .ids
            .iter()
            .flat_map(|(_, v)| v.iter().flatten().map(|&(_, x)| x))
            .filter(|x| x.is_finite())
            .collect();
        let (y0, y1) = ys
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let yb = if y0.is_finite() {
            padded((x0, x1, y0, y1), 0.05)
        } else {
            (xb.0, xb.1, 0.0, 1.0)
        };
        let mut lower = chart(&bottom, (xb.0, xb.1, yb.2, yb.3), (&self.x_label, "X_max"))?;
        for (i, (_, per_value)) in self.ids.iter().enumerate() {
            let c = color(i);
            let pts: Vec<Option<(f64, f64)>> = self
                .values
                .iter()
                .zip(per_value)
                .map(|(&v, p)| p.map(|(_, x)| (v, x)))
                .collect();
            for w in pts.windows(2) {
                if let (Some(a), Some(b)) = (w[0], w[1]) {
                    lower
                        .draw_series(std::iter::once(PathElement::new(
                            vec![a, b],
                            c.stroke_width(2),
                        )))
                        .map_err(|x| e(&x))?;
                }
            }
            lower
                .draw_series(pts.iter().flatten().map(|&p| Circle::new(p, 3, c.filled())))
                .map_err(|x| e(&x))?;
        }
        area.present().map_err(|x| e(&x))?;
        Ok(())
    }
}

/// Write `stem.png` and `stem.svg` of a [`StackedFractions`] figure in `dir`, each atomically.
pub fn save_stacked(dir: &Path, stem: &str, fig: &StackedFractions) -> Result<(), PlotError> {
    write_both(dir, stem, (1100, 850), fig)
}
