//! Measures of the unpredictability of a basin map (a grid of attractor labels over a plane of
//! initial conditions): basin entropy, boundary basin entropy and the uncertainty exponent.
//!
//! - **Basin entropy** S_b and **boundary basin entropy** S_bb (Daza, Wagemakers, Georgeot,
//!   Guéry-Odelin & Sanjuán, "Basin entropy: a new tool to analyze uncertainty in dynamical
//!   systems", Sci. Rep. 6, 31416 (2016), eqs. 1–4): the map is cut into boxes of n × n cells;
//!   in box i the labels occur with frequencies p_ij, its Gibbs entropy is
//!   S_i = Σ_j p_ij ln(1/p_ij); S_b is the mean of S_i over all N boxes and S_bb over the N_b
//!   boxes that hold more than one label (the boxes on a basin boundary). S_bb > ln 2 is a
//!   sufficient condition for a fractal boundary (the "ln 2 criterion").
//! - **Uncertainty exponent** α (Grebogi, McDonald, Ott & Yorke, "Final state sensitivity: an
//!   obstruction to predictability", Phys. Lett. A 99, 415 (1983)): the fraction f(ε) of
//!   initial conditions whose label changes within a distance ε scales as f ~ ε^α; the boundary
//!   has dimension d = D − α (D = 2 for a map over a plane). α = 1 for a smooth boundary, α → 0
//!   for a riddled or strongly fractal one. Here ε runs over 1, 2, 4, … cells and a cell is
//!   ε-uncertain when a cell ε cells away along x or y has another label (the grid version of
//!   the perturbation test); α is the least-squares slope of ln f against ln ε.
//!
//! Every label value counts as an outcome, the codes of starts that did not converge (−1) or
//! failed (−2) included: they are as unpredictable as any basin.

use std::collections::HashMap;

/// Basin entropy S_b, boundary basin entropy S_bb and the number of boxes of each.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BasinEntropy {
    /// S_b: the mean Gibbs entropy of all boxes (nats).
    pub basin_entropy: f64,
    /// S_bb: the mean over the boxes with more than one label (nats; 0 when there are none).
    pub boundary_basin_entropy: f64,
    /// N: boxes.
    pub boxes: usize,
    /// N_b: boxes with more than one label.
    pub boundary_boxes: usize,
}

/// S_b and S_bb of the `labels` (row-major, `nx` per row) in boxes of `n` × `n` cells (Daza et
/// al. use n = 5); cells of incomplete boxes at the right and top edges are left out. `None`
/// when no whole box fits or the labels are not `nx` × rows.
pub(crate) fn basin_entropy(labels: &[i64], nx: usize, n: usize) -> Option<BasinEntropy> {
    if nx == 0 || n == 0 || !labels.len().is_multiple_of(nx) {
        return None;
    }
    let ny = labels.len() / nx;
    let (bx, by) = (nx / n, ny / n);
    if bx == 0 || by == 0 {
        return None;
    }
    let (mut total, mut boundary, mut boundary_boxes) = (0.0, 0.0, 0usize);
    let mut counts: HashMap<i64, usize> = HashMap::new();
    for j in 0..by {
        for i in 0..bx {
            counts.clear();
            for y in j * n..(j + 1) * n {
                for x in i * n..(i + 1) * n {
                    *counts.entry(labels[y * nx + x]).or_insert(0) += 1;
                }
            }
            let cells = (n * n) as f64;
            let s: f64 = counts
                .values()
                .map(|&c| {
                    let p = c as f64 / cells;
                    -p * p.ln()
                })
                .sum();
            total += s;
            if counts.len() > 1 {
                boundary += s;
                boundary_boxes += 1;
            }
        }
    }
    let boxes = bx * by;
    Some(BasinEntropy {
        basin_entropy: total / boxes as f64,
        boundary_basin_entropy: if boundary_boxes > 0 {
            boundary / boundary_boxes as f64
        } else {
            0.0
        },
        boxes,
        boundary_boxes,
    })
}

/// The uncertainty exponent α of the `labels` (row-major, `nx` per row) and the fractions
/// f(ε) it was fitted to, for ε = 1, 2, 4, … cells up to a quarter of the smaller side. `None`
/// when fewer than two ε fit, or no cell is uncertain at some ε (a map of one label: f = 0).
pub(crate) fn uncertainty_exponent(labels: &[i64], nx: usize) -> Option<(f64, Vec<(usize, f64)>)> {
    if nx == 0 || !labels.len().is_multiple_of(nx) {
        return None;
    }
    let ny = labels.len() / nx;
    let mut fractions = Vec::new();
    let mut eps = 1;
    while eps <= nx.min(ny) / 4 {
        let mut uncertain = 0usize;
        let mut cells = 0usize;
        // cells with all four neighbours at distance ε inside the map
        for y in eps..ny - eps {
            for x in eps..nx - eps {
                let l = labels[y * nx + x];
                cells += 1;
                if labels[y * nx + x - eps] != l
                    || labels[y * nx + x + eps] != l
                    || labels[(y - eps) * nx + x] != l
                    || labels[(y + eps) * nx + x] != l
                {
                    uncertain += 1;
                }
            }
        }
        if uncertain == 0 || cells == 0 {
            return None;
        }
        fractions.push((eps, uncertain as f64 / cells as f64));
        eps *= 2;
    }
    if fractions.len() < 2 {
        return None;
    }
    // least-squares slope of ln f against ln ε
    let pts: Vec<(f64, f64)> = fractions
        .iter()
        .map(|&(e, f)| ((e as f64).ln(), f.ln()))
        .collect();
    let m = pts.len() as f64;
    let (sx, sy) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x, b + y));
    let (mx, my) = (sx / m, sy / m);
    let (num, den) = pts.iter().fold((0.0, 0.0), |(n, d), &(x, y)| {
        (n + (x - mx) * (y - my), d + (x - mx) * (x - mx))
    });
    Some((num / den, fractions))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two basins split by the vertical line between columns c − 1 and c of a 100 × 100 map.
    fn split(c: usize) -> Vec<i64> {
        (0..100 * 100).map(|k| i64::from(k % 100 >= c)).collect()
    }

    /// A boundary along box edges crosses no box: S_b = S_bb = 0. Moved two cells into the
    /// boxes, 20 of the 400 boxes hold 2 and 3 columns of the two labels:
    /// S_i = −(0.4 ln 0.4 + 0.6 ln 0.6) there, S_bb = S_i, S_b = S_i · 20/400 (Daza et al.,
    /// eqs. 2–4, by hand).
    #[test]
    fn a_straight_boundary_has_the_entropy_of_its_boxes() {
        let e = basin_entropy(&split(50), 100, 5).unwrap();
        assert_eq!((e.boxes, e.boundary_boxes), (400, 0));
        assert_eq!((e.basin_entropy, e.boundary_basin_entropy), (0.0, 0.0));
        let e = basin_entropy(&split(52), 100, 5).unwrap();
        let s = -(0.4f64 * 0.4f64.ln() + 0.6 * 0.6f64.ln());
        assert_eq!(e.boundary_boxes, 20);
        assert!((e.boundary_basin_entropy - s).abs() < 1e-15);
        assert!((e.basin_entropy - s * 20.0 / 400.0).abs() < 1e-15);
        assert!(
            e.boundary_basin_entropy < 2f64.ln(),
            "a smooth boundary fails the ln 2 test"
        );
    }

    /// A smooth boundary has α = 1: for a vertical line in a map L cells wide,
    /// f(ε) = 2ε/(L − 2ε) exactly, whose log-log slope is 1 up to the finite-size term
    /// 2ε/(L − 2ε) (≤ 3 % at L = 1000, ε ≤ 16).
    #[test]
    fn a_smooth_boundary_has_uncertainty_exponent_one() {
        let labels: Vec<i64> = (0..1000 * 100)
            .map(|k| i64::from(k % 1000 >= 500))
            .collect();
        let (alpha, f) = uncertainty_exponent(&labels, 1000).unwrap();
        assert_eq!(f.len(), 5); // ε = 1, 2, 4, 8, 16 (up to a quarter of the 100 rows)
        for &(e, frac) in &f {
            let expect = 2.0 * e as f64 / (1000.0 - 2.0 * e as f64);
            assert!((frac - expect).abs() < 1e-15, "ε = {e}: {frac} vs {expect}");
        }
        assert!((alpha - 1.0).abs() < 0.02, "{alpha}");
    }

    /// Labels drawn at random among three (the limit of an infinitely fine fractal boundary):
    /// every cell is uncertain at every ε (α ≈ 0), every box is a boundary box, and S_bb is
    /// near ln 3 (the expected entropy of 25 draws is ln 3 minus a bias of ~(k − 1)/2n² = 0.04),
    /// well above the ln 2 criterion.
    #[test]
    fn random_labels_are_maximally_uncertain() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let labels: Vec<i64> = (0..200 * 200).map(|_| rng.random_range(0..3)).collect();
        let e = basin_entropy(&labels, 200, 5).unwrap();
        assert_eq!(e.boundary_boxes, e.boxes);
        assert!(
            (e.boundary_basin_entropy - (3f64.ln() - 0.04)).abs() < 0.02,
            "{e:?}"
        );
        assert!(e.boundary_basin_entropy > 2f64.ln());
        let (alpha, _) = uncertainty_exponent(&labels, 200).unwrap();
        assert!(alpha.abs() < 0.02, "{alpha}");
    }

    #[test]
    fn degenerate_maps_have_no_measure() {
        assert!(basin_entropy(&[0; 16], 4, 5).is_none());
        assert!(basin_entropy(&[0; 15], 4, 2).is_none());
        assert!(uncertainty_exponent(&[1; 10_000], 100).is_none());
    }
}
