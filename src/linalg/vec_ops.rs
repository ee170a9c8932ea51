//! The vector kernels every small dense solve here is made of.

use ndarray::Array2;

/// Dot product with four independent partial sums, so that it vectorizes (a single
/// running sum is a chain of dependent additions).
#[inline]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca.remainder().iter().zip(cb.remainder()).map(|(x, y)| x * y).sum();
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// `y += alpha x`
#[inline]
pub(crate) fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
    }
}

/// `out (+)= A x`
pub(crate) fn mat_vec(a: &Array2<f64>, x: &[f64], out: &mut [f64], accumulate: bool) {
    for (o, row) in out.iter_mut().zip(a.rows()) {
        let d = match row.as_slice() {
            Some(rs) => dot(rs, x),
            None => row.iter().zip(x).map(|(p, q)| p * q).sum(),
        };
        *o = if accumulate { *o + d } else { d };
    }
}
