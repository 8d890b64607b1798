//! The dense grid step y += Φ x, monomorphised for the small state dimensions.
//!
//! With the dimension a compile-time constant the column loop is unrolled and the accumulator
//! lives in registers; the dynamic loop ([`super::matvec_cols`]) re-reads and
//! re-writes y for every column. Chosen once per propagator by [`for_dim`].

use super::matvec_cols;

/// y += A x for a column-major dim×dim A (`a.len() == dim²`, `x.len() == y.len() == dim`).
pub(crate) type MatVec = fn(&[f64], &[f64], &mut [f64]);

/// The kernel for a state dimension `dim`: fixed-size for 2N ≤ 12 (N ≤ 6), else dynamic.
pub(crate) fn for_dim(dim: usize) -> MatVec {
    match dim {
        2 => fixed::<2>,
        4 => fixed::<4>,
        6 => fixed::<6>,
        8 => fixed::<8>,
        10 => fixed::<10>,
        12 => fixed::<12>,
        _ => dynamic,
    }
}

fn dynamic(a: &[f64], x: &[f64], y: &mut [f64]) {
    matvec_cols(a, y.len(), x, y, 1.0, true);
}

fn fixed<const D: usize>(a: &[f64], x: &[f64], y: &mut [f64]) {
    let (Some(a), Some(x), Some(y)) = (a.get(..D * D), x.get(..D), y.get_mut(..D)) else {
        return dynamic(a, x, y);
    };
    let (cols, _) = a.as_chunks::<D>();
    let mut acc = [0.0; D];
    acc.copy_from_slice(y);
    for (col, &xj) in cols.iter().zip(x) {
        for (s, &aij) in acc.iter_mut().zip(col) {
            *s += aij * xj;
        }
    }
    y.copy_from_slice(&acc);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every fixed-size kernel equals the dynamic loop bit for bit (same operation order).
    #[test]
    fn fixed_kernels_match_the_dynamic_loop() {
        for dim in [2usize, 4, 6, 8, 10, 12, 14] {
            let a: Vec<f64> = (0..dim * dim)
                .map(|k| ((k * 37 % 11) as f64).sin())
                .collect();
            let x: Vec<f64> = (0..dim).map(|k| (k as f64 + 0.5).cos()).collect();
            let y0: Vec<f64> = (0..dim).map(|k| k as f64 * 0.25 - 1.0).collect();
            let (mut y1, mut y2) = (y0.clone(), y0.clone());
            for_dim(dim)(&a, &x, &mut y1);
            dynamic(&a, &x, &mut y2);
            assert_eq!(y1, y2, "dim {dim}");
        }
    }
}
