//! A small dense LU with partial pivoting (faer) whose storage is allocated once: the
//! reduced models factor an r×r (plus constraints) matrix in every Newton iteration, and
//! their time loop must not touch the heap.
//!
//! `P A = L U`; `solve` applies `x = U⁻¹ L⁻¹ P b` in place. A symmetric matrix may be
//! factored as `A = L Lᵀ` (Cholesky, half the flops: on the thesis four-bar's 54 × 54 Newton
//! matrix 5 instead of 10 µs) with LU as the fallback when it is not positive definite.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt;
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Conj, MatMut, MatRef, Par};

pub struct DenseLu {
    /// the matrix to factor (filled by the caller, column-major), then its factors
    a: Vec<f64>,
    n: usize,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
    factored: Option<Factors>,
    /// the matrix as filled, kept while a Cholesky factorization is tried
    copy: Vec<f64>,
    /// factorizations left before Cholesky is tried again after it failed
    skip_cholesky: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Factors {
    Lu,
    Cholesky,
}

/// After a matrix turned out not to be positive definite, the next ones (Newton matrices
/// of neighbouring iterations) likely are not either: go straight to LU for this many.
const CHOLESKY_RETRY: u32 = 16;

impl DenseLu {
    pub fn new(n: usize) -> Self {
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default()),
            solve::solve_in_place_scratch::<usize, f64>(n, 1, Par::Seq),
            llt::factor::cholesky_in_place_scratch::<f64>(n, Par::Seq, Default::default()),
            llt::solve::solve_in_place_scratch::<f64>(n, 1, Par::Seq),
        ]);
        DenseLu {
            a: vec![0.0; n * n],
            n,
            perm: vec![0; n],
            perm_inv: vec![0; n],
            mem: MemBuffer::new(req),
            factored: None,
            copy: vec![0.0; n * n],
            skip_cholesky: 0,
        }
    }

    pub fn dim(&self) -> usize {
        self.n
    }

    /// The matrix to be factored next, column-major (entry (i, j) at `i + n j`); writing
    /// to it invalidates the last factorization.
    pub fn matrix_mut(&mut self) -> &mut [f64] {
        self.factored = None;
        &mut self.a
    }

    /// Factors a symmetric matrix as `L Lᵀ` when it is positive definite, else by LU like
    /// [`Self::factor`] (from a copy: faer's Cholesky may write the upper triangle too, so
    /// the failed attempt cannot be undone from the matrix itself).
    pub fn factor_symmetric(&mut self) -> Result<(), String> {
        self.check_finite()?;
        if self.skip_cholesky > 0 {
            self.skip_cholesky -= 1;
            return self.factor_lu();
        }
        self.copy.copy_from_slice(&self.a);
        let n = self.n;
        let a = MatMut::from_column_major_slice_mut(&mut self.a, n, n);
        match llt::factor::cholesky_in_place(a, Default::default(), Par::Seq, MemStack::new(&mut self.mem), Default::default()) {
            Ok(_) => {
                self.factored = Some(Factors::Cholesky);
                Ok(())
            }
            Err(_) => {
                self.a.copy_from_slice(&self.copy);
                self.skip_cholesky = CHOLESKY_RETRY;
                self.factor_lu()
            }
        }
    }

    /// Factors the matrix in place; refuses non-finite entries and exact zero pivots.
    pub fn factor(&mut self) -> Result<(), String> {
        self.check_finite()?;
        self.factor_lu()
    }

    fn factor_lu(&mut self) -> Result<(), String> {
        let n = self.n;
        let a = MatMut::from_column_major_slice_mut(&mut self.a, n, n);
        factor::lu_in_place(a, &mut self.perm, &mut self.perm_inv, Par::Seq, MemStack::new(&mut self.mem), Default::default());
        if let Some(i) = (0..n).find(|&i| self.a[i + n * i] == 0.0) {
            return Err(format!("the iteration matrix is singular (zero pivot {i} of {n})"));
        }
        self.factored = Some(Factors::Lu);
        Ok(())
    }

    fn check_finite(&self) -> Result<(), String> {
        let n = self.n;
        // x·0 is NaN exactly for infinite or NaN x; eight independent sums vectorize (a
        // position() scan with early exit does not), and the column is found only on failure
        let mut acc = [0.0_f64; 8];
        let chunks = self.a.chunks_exact(8);
        let tail = chunks.remainder().iter().fold(0.0, |s, x| s + x * 0.0);
        for c in chunks {
            for (s, x) in acc.iter_mut().zip(c) {
                *s += x * 0.0;
            }
        }
        if (acc.iter().sum::<f64>() + tail).is_nan() {
            let k = self.a.iter().position(|x| !x.is_finite()).unwrap_or(0);
            return Err(format!("the iteration matrix holds non-finite values (column {})", k / n.max(1)));
        }
        Ok(())
    }

    /// Solves `A x = b` in place with the last factorization.
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<(), String> {
        let Some(kind) = self.factored else {
            return Err("no valid factorization to solve with".into());
        };
        let n = self.dim();
        if rhs.len() != n {
            return Err(format!("right-hand side has {} entries, the matrix {n} rows", rhs.len()));
        }
        let b = MatMut::from_column_major_slice_mut(rhs, n, 1);
        let a = MatRef::from_column_major_slice(&self.a, n, n);
        match kind {
            Factors::Lu => {
                let perm = PermRef::new_checked(&self.perm, &self.perm_inv, n);
                solve::solve_in_place_with_conj(a, a, perm, Conj::No, b, Par::Seq, MemStack::new(&mut self.mem));
            }
            Factors::Cholesky => llt::solve::solve_in_place_with_conj(a, Conj::No, b, Par::Seq, MemStack::new(&mut self.mem)),
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3×3 solver holding `a`, and `b = a x`.
    fn system(a: &[[f64; 3]; 3], x: &[f64; 3]) -> (DenseLu, Vec<f64>) {
        let b: Vec<f64> = a.iter().map(|row| row.iter().zip(x).map(|(p, q)| p * q).sum()).collect();
        let mut lu = DenseLu::new(3);
        let m = lu.matrix_mut();
        for i in 0..3 {
            for j in 0..3 {
                m[i + 3 * j] = a[i][j];
            }
        }
        (lu, b)
    }

    /// A 3×3 system that needs pivoting (zero leading entry); the solution x = (1, 2, 3) is
    /// built into b = A x by hand.
    #[test]
    fn solves_a_system_that_needs_pivoting() {
        let x = [1.0, 2.0, 3.0];
        let (mut lu, mut b) = system(&[[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [4.0, -1.0, 2.0]], &x);
        lu.factor().unwrap();
        lu.solve(&mut b).unwrap();
        for (bi, xi) in b.iter().zip(&x) {
            assert!((bi - xi).abs() < 1e-14, "{b:?}");
        }
    }

    /// A symmetric positive definite 3×3 system (diagonally dominant) goes through
    /// Cholesky, a symmetric indefinite one (eigenvalues of both signs: det of the leading
    /// 2×2 block is negative) falls back to LU; both give the x = (1, −2, 3) that b was
    /// built from. Bound: round-off, 1e-14.
    #[test]
    fn symmetric_systems_by_cholesky_or_by_the_lu_fallback() {
        let x = [1.0, -2.0, 3.0];
        for (a, kind) in [
            ([[4.0, 1.0, 0.5], [1.0, 3.0, -0.5], [0.5, -0.5, 2.0]], Factors::Cholesky),
            ([[1.0, 2.0, 0.0], [2.0, 1.0, 1.0], [0.0, 1.0, 3.0]], Factors::Lu),
        ] {
            let (mut lu, mut b) = system(&a, &x);
            lu.factor_symmetric().unwrap();
            assert_eq!(lu.factored, Some(kind));
            lu.solve(&mut b).unwrap();
            for (bi, xi) in b.iter().zip(&x) {
                assert!((bi - xi).abs() < 1e-14, "{kind:?}: {b:?}");
            }
        }
    }

    #[test]
    fn refuses_singular_and_non_finite_matrices() {
        let mut lu = DenseLu::new(2);
        lu.matrix_mut()[0] = 1.0; // second row and column stay zero
        assert!(lu.factor().unwrap_err().contains("singular"));
        lu.matrix_mut()[3] = f64::NAN;
        assert!(lu.factor().unwrap_err().contains("non-finite"));
        assert!(lu.solve(&mut [1.0, 1.0]).is_err());
    }
}
