//! The triangular factor of a tall matrix, to shrink a least-squares problem with many more
//! rows than columns before it is solved (Golub & Van Loan, Matrix Computations, 4th ed.,
//! §5.3.3): with `A = Q R` (Householder, `Q` m × n with orthonormal columns, `R` n × n upper
//! triangular) and `b = A c` in the range of `A`,
//!
//! ```text
//!     ‖A x − b‖₂ = ‖Q R (x − c)‖₂ = ‖R x − R c‖₂      for every x,
//! ```
//!
//! so any method that reads the problem through residuals and column products (NNLS's
//! gains `aⱼᵀ r`, its Gram matrix) sees the same problem in `R`, at `n²` numbers instead of
//! `m n`. ECSW's training matrix is such a case: a few hundred elements against hundreds of
//! thousands of rows (snapshots × modes), where every NNLS iteration otherwise streams the
//! whole matrix from memory.

use crate::error::Result;
use crate::linalg::nnls::{column_major, nnls, nnls_scaling, NnlsParams, NnlsSolution};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::qr::no_pivoting::factor::{qr_in_place, qr_in_place_scratch, recommended_block_size};
use faer::{Mat, MatMut, Par};
use ndarray::{Array1, Array2, Axis};

/// `R` (n × n, upper triangular) of `a = Q R` for `a` with at least as many rows as columns;
/// `a` is consumed (factored in place, in column-major order). Column norms and products
/// are those of `a`: `RᵀR = aᵀa`. The signs of R's rows are LAPACK's/faer's (`Q` is not kept).
pub fn triangular_factor(a: Array2<f64>) -> Array2<f64> {
    let (m, n) = a.dim();
    assert!(m >= n, "triangular_factor: {m} rows < {n} columns");
    // column-major storage, as faer (and LAPACK) factor it; a copy only if `a` is row-major
    let mut a = if a.t().is_standard_layout() { a } else { column_major(a.view()) };
    if n == 0 {
        return Array2::zeros((0, 0));
    }
    {
        let slice = a.as_slice_memory_order_mut().expect("a contiguous column-major array");
        let mat = MatMut::from_column_major_slice_mut(slice, m, n);
        let block = recommended_block_size::<f64>(m, n);
        let mut coeff = Mat::<f64>::zeros(block, n);
        let mut mem = MemBuffer::new(qr_in_place_scratch::<f64>(m, n, block, Par::Seq, Default::default()));
        qr_in_place(mat, coeff.as_mut(), Par::Seq, MemStack::new(&mut mem), Default::default());
    }
    Array2::from_shape_fn((n, n), |(i, j)| if i <= j { a[[i, j]] } else { 0.0 })
}

/// The factorization's cost in direct NNLS iterations, per column of `A` and per thread the
/// direct iterations run on: a Householder QR is `2 m n²` flops at the speed of blocked,
/// cache-resident kernels (on one thread), a direct iteration streams the `m × n` matrix
/// from memory (the gains `Aᵀr`, on every thread), so the ratio grows with `n` and with the
/// threads. Measured on a 2-core machine (random matrices, two
/// threads for the gains): the QR took as long as the direct route's set-up and 31
/// iterations at 321 000 × 146, 99 at 75 000 × 1100 — `n/4.7` and `n/11` on two threads,
/// `n/9` and `n/22` per thread; at 75 000 × 5000 40 s against 12 s for the direct set-up
/// and a few dozen iterations. `n/16` per thread lies within a factor of about 1.5 of both,
/// which keeps the rule's bound near twice the better route; an error in it costs time,
/// never accuracy (both routes solve one problem).
pub const FACTOR_ITERATIONS_PER_COLUMN: f64 = 1.0 / 16.0;

/// NNLS of `(A, A 1)` — the right-hand side the sum of `A`'s columns, as ECSW's — directly
/// on `A` for as many iterations as factoring `A` would cost, then (if it has not stopped)
/// again from the start on the triangular factor `R` with `R 1` (module documentation; the
/// same problem). This is the ski-rental rule: whatever the number of iterations the
/// problem needs, the time is at most about twice that of the better of the two routes
/// chosen in hindsight — the direct one wins where few columns enter (a refined mesh with
/// few sampled elements), the factored one where many do (a coarse mesh sampled densely).
pub fn nnls_of_column_sum(a: Array2<f64>, params: &NnlsParams) -> Result<NnlsSolution> {
    let (m, n) = a.dim();
    let threads = rayon::current_num_threads().max(1) as f64;
    let rent = (FACTOR_ITERATIONS_PER_COLUMN * n as f64 * threads).ceil() as usize;
    let b = a.sum_axis(Axis(1));
    if m <= n || rent >= params.max_iterations {
        return nnls(a.view(), b.view(), params);
    }
    let (direct, scaled, norms) = nnls_scaling(a, b.view(), &NnlsParams { max_iterations: rent, ..params.clone() })?;
    if direct.iterations < rent || direct.relative_residual <= params.tolerance {
        return Ok(direct);
    }
    // the problem in the scaled columns Â = A D⁻¹ (D = diag(norms)): b = Â d, and with
    // Â = Q R̂ it is min ‖R̂ x̂ − R̂ d‖ over x̂ = D x ≥ 0
    let r = triangular_factor(scaled);
    let d = Array1::from(norms);
    let rb = r.dot(&d);
    let s = nnls(r.view(), rb.view(), params)?;
    let x = Array1::from_shape_fn(n, |j| if d[j] > 0.0 { s.x[j] / d[j] } else { 0.0 });
    Ok(NnlsSolution { x, ..s })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::nnls::{nnls, NnlsParams};
    use ndarray::{Array1, Axis, ShapeBuilder};

    /// A deterministic tall matrix with entries in [−1, 1] (a linear congruential stream).
    fn tall(m: usize, n: usize, seed: u64) -> Array2<f64> {
        let mut s = seed;
        Array2::from_shape_fn((m, n), |_| {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
    }

    /// RᵀR = AᵀA (the defining property: Q has orthonormal columns), R upper triangular;
    /// round-off of the Householder QR, a few ulps of ‖A‖² (Golub & Van Loan §5.2.2).
    #[test]
    fn the_gram_matrix_is_kept() {
        let a = tall(400, 12, 7);
        let gram = a.t().dot(&a);
        let r = triangular_factor(a);
        assert_eq!(r.dim(), (12, 12));
        for i in 0..12 {
            for j in 0..i {
                assert_eq!(r[[i, j]], 0.0);
            }
        }
        let rr = r.t().dot(&r);
        let scale = gram.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (x, y) in rr.iter().zip(gram.iter()) {
            assert!((x - y).abs() <= 1e-13 * scale, "{x} vs {y}");
        }
    }

    /// NNLS of (A, A c) and of (R, R c) is one problem (module documentation): the same
    /// columns enter, the same weights within round-off, the same relative residual, at a
    /// tolerance that stops it early (as ECSW does) and at the Kuhn–Tucker point.
    #[test]
    fn nnls_on_the_factor_solves_the_same_problem() {
        let a = tall(600, 20, 3).mapv(f64::abs);
        let b = a.sum_axis(Axis(1));
        let r = triangular_factor(a.clone());
        let rb: Array1<f64> = r.sum_axis(Axis(1));
        for tol in [1e-2, 1e-4, 0.0] {
            let p = NnlsParams { tolerance: tol, max_iterations: 20 };
            let (full, small) = (nnls(a.view(), b.view(), &p).unwrap(), nnls(r.view(), rb.view(), &p).unwrap());
            assert_eq!(full.iterations, small.iterations, "τ = {tol}");
            for (x, y) in full.x.iter().zip(small.x.iter()) {
                assert_eq!(*x > 0.0, *y > 0.0, "τ = {tol}: the same columns");
                assert!((x - y).abs() <= 1e-9 * (1.0 + x.abs()), "τ = {tol}: {x} vs {y}");
            }
            let d = (full.relative_residual - small.relative_residual).abs();
            assert!(d <= 1e-9 * full.relative_residual + 1e-13, "τ = {tol}: {d}");
        }
    }

    /// `nnls_of_column_sum` gives what NNLS of `(A, A 1)` gives, on either route: a loose
    /// tolerance met within the direct iterations it may take (5 for 40 columns on two
    /// threads), and the Kuhn–Tucker point (every column enters: 40 iterations), reached on
    /// the factor after the direct iterations ran out.
    #[test]
    fn either_route_solves_the_problem_of_the_column_sum() {
        // two threads: 5 direct iterations before the factor, on any machine
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        pool.install(|| {
            let a = tall(800, 40, 5).mapv(f64::abs);
            let rent = (FACTOR_ITERATIONS_PER_COLUMN * 40.0 * rayon::current_num_threads() as f64).ceil();
            assert_eq!(rent, 5.0, "the case this test builds");
            let b = a.sum_axis(Axis(1));
            for tol in [0.3, 0.0] {
                let p = NnlsParams { tolerance: tol, max_iterations: 40 };
                let (plain, routed) =
                    (nnls(a.view(), b.view(), &p).unwrap(), nnls_of_column_sum(a.clone(), &p).unwrap());
                assert_eq!(plain.iterations, routed.iterations, "τ = {tol}");
                let direct = (plain.iterations as f64) < rent;
                assert!(if tol > 0.0 { direct } else { plain.iterations == 40 }, "{} iterations", plain.iterations);
                for (x, y) in plain.x.iter().zip(routed.x.iter()) {
                    assert_eq!(*x > 0.0, *y > 0.0, "τ = {tol}: the same columns");
                    assert!((x - y).abs() <= 1e-9 * (1.0 + x.abs()), "τ = {tol}: {x} vs {y}");
                }
            }
        });
    }

    /// A row-major input is factored as its column-major copy.
    #[test]
    fn the_layout_of_the_input_does_not_matter() {
        let a = tall(50, 4, 11);
        let mut f = Array2::zeros((50, 4).f());
        f.assign(&a);
        assert_eq!(triangular_factor(a), triangular_factor(f));
    }
}
