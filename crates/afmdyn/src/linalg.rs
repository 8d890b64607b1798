//! Small dense linear algebra shared by the model, the hybrid-system interface and the
//! integrators: the matrix–vector product y ← α A x (+ y), its fixed-size kernels for the
//! small state dimensions ([`kernel`]), and the product of square matrices A B. A leaf: it
//! uses nothing else of the crate.

pub(crate) mod kernel;

use nalgebra::DMatrix;

/// y ← α A x (+ y when `accumulate`), A column-major with `x.len()` columns. Hand-written:
/// nalgebra's dynamic gemv has a per-call overhead comparable to the 36 multiply–adds of N = 3,
/// and this is the inner loop of the propagators and of the model's vector field.
#[inline]
pub(crate) fn matvec(a: &DMatrix<f64>, x: &[f64], y: &mut [f64], alpha: f64, accumulate: bool) {
    debug_assert_eq!(a.nrows(), y.len());
    debug_assert_eq!(a.ncols(), x.len());
    matvec_cols(a.as_slice(), a.nrows(), x, y, alpha, accumulate);
}

/// [`matvec`] on the column-major storage `a` of a matrix with `rows` rows.
#[inline]
pub(crate) fn matvec_cols(
    a: &[f64],
    rows: usize,
    x: &[f64],
    y: &mut [f64],
    alpha: f64,
    accumulate: bool,
) {
    if !accumulate {
        y.fill(0.0);
    }
    for (col, &xj) in a.chunks_exact(rows.max(1)).zip(x) {
        let s = alpha * xj;
        for (yi, aij) in y.iter_mut().zip(col) {
            *yi += aij * s;
        }
    }
}

/// out = α A B for square column-major A, B of one size: up to 12×12 column by column with the
/// fixed-size kernel (a blocked product packs, and allocates, per call), above by nalgebra's
/// blocked product.
pub(crate) fn matmul_into(a: &DMatrix<f64>, b: &DMatrix<f64>, alpha: f64, out: &mut DMatrix<f64>) {
    let dim = a.nrows();
    if dim > 12 {
        return out.gemm(alpha, a, b, 0.0);
    }
    let kernel = kernel::for_dim(dim);
    out.as_mut_slice().fill(0.0);
    for (bj, oj) in b
        .as_slice()
        .chunks_exact(dim.max(1))
        .zip(out.as_mut_slice().chunks_exact_mut(dim.max(1)))
    {
        kernel(a.as_slice(), bj, oj);
    }
    if alpha != 1.0 {
        *out *= alpha;
    }
}

/// A B for square matrices of one size ([`matmul_into`]).
pub(crate) fn matmul(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(a.nrows(), b.ncols());
    matmul_into(a, b, 1.0, &mut out);
    out
}
