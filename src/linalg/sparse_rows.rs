//! A small matrix stored as runs of nonzero entries row by row: the projected mass and
//! linear stiffness of a block basis are block-diagonal apart from the kept coordinates'
//! rows and columns, and their products with a vector run in every Newton iteration.

use super::vec_ops::{dot, mat_vec};
use ndarray::Array2;

pub(crate) struct SparseRows {
    /// `(row, first column, offset in values, length)` of each run
    runs: Vec<(usize, usize, usize, usize)>,
    values: Vec<f64>,
    /// the matrix itself when it has no zero runs worth skipping (a global basis)
    dense: Option<Array2<f64>>,
}

impl SparseRows {
    /// The runs of `a` between exact zeros (a dense matrix gives one run a row).
    pub fn new(a: &Array2<f64>) -> Self {
        let (mut runs, mut values) = (Vec::new(), Vec::new());
        for (i, row) in a.rows().into_iter().enumerate() {
            let mut j = 0;
            while j < row.len() {
                if row[j] == 0.0 {
                    j += 1;
                    continue;
                }
                let end = (j..row.len()).find(|&k| row[k] == 0.0).unwrap_or(row.len());
                runs.push((i, j, values.len(), end - j));
                values.extend(row.iter().skip(j).take(end - j));
                j = end;
            }
        }
        // below ~3/4 of the entries the runs pay for their bookkeeping
        let dense = (4 * values.len() > 3 * a.len()).then(|| a.as_standard_layout().to_owned());
        SparseRows { runs, values, dense }
    }

    /// `out (+)= A x`
    pub fn mul(&self, x: &[f64], out: &mut [f64], accumulate: bool) {
        if let Some(a) = &self.dense {
            return mat_vec(a, x, out, accumulate);
        }
        if !accumulate {
            out.fill(0.0);
        }
        for &(i, c, off, len) in &self.runs {
            out[i] += dot(&self.values[off..off + len], &x[c..c + len]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block matrix with zero blocks, a zero row and an isolated entry: the product
    /// equals the dense one (ndarray's `dot`) to round-off, with and without accumulation;
    /// and so does that of a matrix without zeros, kept dense.
    #[test]
    fn product_equals_the_dense_one() {
        let a = Array2::from_shape_fn((7, 7), |(i, j)| {
            let block = |k: usize| if k < 3 { 0 } else { 1 };
            if i == 5 || (block(i) != block(j) && j != 6) {
                0.0
            } else {
                1.0 + (i * 7 + j) as f64 * 0.1
            }
        });
        let x: Vec<f64> = (0..7).map(|i| (i as f64).sin() + 0.3).collect();
        let dense = a.dot(&ndarray::ArrayView1::from(&x));
        let m = SparseRows::new(&a);
        let mut out = vec![1.0; 7];
        m.mul(&x, &mut out, false);
        for (o, d) in out.iter().zip(&dense) {
            assert!((o - d).abs() < 1e-12, "{out:?} {dense:?}");
        }
        m.mul(&x, &mut out, true);
        for (o, d) in out.iter().zip(&dense) {
            assert!((o - 2.0 * d).abs() < 1e-12);
        }
        assert!(m.dense.is_none(), "stored by runs");
        // a dense matrix is kept as it is, with the same product
        let full = a.mapv(|v| v + 0.5);
        let m = SparseRows::new(&full);
        assert!(m.dense.is_some());
        m.mul(&x, &mut out, false);
        let d = full.dot(&ndarray::ArrayView1::from(&x));
        assert!(out.iter().zip(&d).all(|(o, d)| (o - d).abs() < 1e-12));
    }
}
