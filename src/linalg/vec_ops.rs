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

/// `max |xᵢ|` (0 for an empty slice), NaN when an entry is NaN: `f64::max` passes a NaN
/// by, so a plain fold would read a NaN vector as 0, and a Newton loop take it for
/// converged. Four lanes, so that it vectorizes; the maximum is exact, so the lanes give
/// the value one running maximum would.
#[inline]
pub fn max_abs(x: &[f64]) -> f64 {
    let mut m = [0.0_f64; 4];
    let mut nan = false;
    let chunks = x.chunks_exact(4);
    for v in chunks.remainder() {
        m[0] = m[0].max(v.abs());
        nan |= v.is_nan();
    }
    for c in chunks {
        for k in 0..4 {
            m[k] = m[k].max(c[k].abs());
            nan |= c[k].is_nan();
        }
    }
    if nan {
        f64::NAN
    } else {
        m[0].max(m[1]).max(m[2].max(m[3]))
    }
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

#[cfg(test)]
mod tests {
    /// The largest magnitude wherever it sits (each lane, the remainder), 0 for nothing,
    /// and NaN for a NaN anywhere, where `f64::max` would have passed it by.
    #[test]
    fn max_abs_finds_the_largest_and_keeps_nan() {
        assert_eq!(super::max_abs(&[]), 0.0);
        for len in 1..11 {
            for at in 0..len {
                let mut x: Vec<f64> = (0..len).map(|i| 0.1 * i as f64 - 0.3).collect();
                x[at] = -7.5;
                assert_eq!(super::max_abs(&x), 7.5, "len {len} at {at}");
                x[at] = f64::NAN;
                assert!(super::max_abs(&x).is_nan(), "len {len} at {at}");
                assert!(!x.iter().fold(0.0_f64, |m, v| m.max(v.abs())).is_nan(), "f64::max passes NaN by");
            }
        }
        assert_eq!(super::max_abs(&[1.0, f64::NEG_INFINITY]), f64::INFINITY);
    }
}
