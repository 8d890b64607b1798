//! Series decimated to the canvas before drawing: per pixel column the first, lowest, highest
//! and last point of a monotone series; repeated pixels and drawn segments dropped otherwise.

use super::*;

pub use afmdyn::layout::figure::PixelColumns;

/// Decimate a line to the pixel grid `px` maps to. A series monotone in x keeps per pixel
/// column its first, lowest, highest and last point (in their order), which draws the same
/// picture; any other line drops points on the pixel of the previous one and segments already
/// drawn, splitting into runs. Non-finite points split runs too.
pub fn decimate_line(
    points: &[(f64, f64)],
    px: impl Fn(f64, f64) -> (i32, i32),
) -> Vec<Vec<(f64, f64)>> {
    let finite = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    let monotone = points
        .iter()
        .filter(|p| finite(p))
        .collect::<Vec<_>>()
        .windows(2)
        .all(|w| w[0].0 <= w[1].0);
    let mut runs: Vec<Vec<(f64, f64)>> = vec![];
    let mut run: Vec<(f64, f64)> = vec![];
    if monotone {
        let mut cols = PixelColumns::default();
        for &q in points {
            if !finite(&q) {
                cols.flush(&mut run);
                if !run.is_empty() {
                    runs.push(std::mem::take(&mut run));
                }
                continue;
            }
            cols.push(px(q.0, q.1).0, q, &mut run);
        }
        cols.flush(&mut run);
    } else {
        let mut drawn: HashSet<(i32, i32, i32, i32)> = HashSet::new();
        let mut last_px: Option<(i32, i32)> = None;
        for &q in points {
            if !finite(&q) {
                if run.len() > 1 {
                    runs.push(std::mem::take(&mut run));
                }
                run.clear();
                last_px = None;
                continue;
            }
            let p = px(q.0, q.1);
            match last_px {
                Some(l) if l == p => continue,
                Some(l) => {
                    let key = if l <= p {
                        (l.0, l.1, p.0, p.1)
                    } else {
                        (p.0, p.1, l.0, l.1)
                    };
                    if drawn.insert(key) {
                        run.push(q);
                    } else {
                        // a segment already drawn: end the run, restart from here
                        if run.len() > 1 {
                            runs.push(std::mem::take(&mut run));
                        }
                        run.clear();
                        run.push(q);
                    }
                }
                None => run.push(q),
            }
            last_px = Some(p);
        }
    }
    if !run.is_empty() {
        runs.push(run);
    }
    runs
}

/// One marker per pixel.
pub fn decimate_points(
    points: &[(f64, f64)],
    px: impl Fn(f64, f64) -> (i32, i32),
) -> Vec<(f64, f64)> {
    let mut seen = HashSet::new();
    points
        .iter()
        .copied()
        .filter(|q| q.0.is_finite() && q.1.is_finite() && seen.insert(px(q.0, q.1)))
        .collect()
}
