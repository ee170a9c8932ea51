//! A small dense LU with partial pivoting (faer) whose storage is allocated once: the
//! reduced models factor an r×r (plus constraints) matrix in every Newton iteration, and
//! their time loop must not touch the heap.
//!
//! `P A = L U`; `solve` applies `x = U⁻¹ L⁻¹ P b` in place.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Conj, MatMut, MatRef, Par};

pub struct DenseLu {
    /// the matrix to factor (filled by the caller, column-major), then its L and U factors
    a: Vec<f64>,
    n: usize,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
    factored: bool,
}

impl DenseLu {
    pub fn new(n: usize) -> Self {
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default()),
            solve::solve_in_place_scratch::<usize, f64>(n, 1, Par::Seq),
        ]);
        DenseLu { a: vec![0.0; n * n], n, perm: vec![0; n], perm_inv: vec![0; n], mem: MemBuffer::new(req), factored: false }
    }

    pub fn dim(&self) -> usize {
        self.n
    }

    /// The matrix to be factored next, column-major (entry (i, j) at `i + n j`); writing
    /// to it invalidates the last factorization.
    pub fn matrix_mut(&mut self) -> &mut [f64] {
        self.factored = false;
        &mut self.a
    }

    /// Factors the matrix in place; refuses non-finite entries and exact zero pivots.
    pub fn factor(&mut self) -> Result<(), String> {
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
        let a = MatMut::from_column_major_slice_mut(&mut self.a, n, n);
        factor::lu_in_place(a, &mut self.perm, &mut self.perm_inv, Par::Seq, MemStack::new(&mut self.mem), Default::default());
        if let Some(i) = (0..n).find(|&i| self.a[i + n * i] == 0.0) {
            return Err(format!("the iteration matrix is singular (zero pivot {i} of {n})"));
        }
        self.factored = true;
        Ok(())
    }

    /// Solves `A x = b` in place with the last factorization.
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<(), String> {
        if !self.factored {
            return Err("no valid factorization to solve with".into());
        }
        let n = self.dim();
        if rhs.len() != n {
            return Err(format!("right-hand side has {} entries, the matrix {n} rows", rhs.len()));
        }
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, n);
        let b = MatMut::from_column_major_slice_mut(rhs, n, 1);
        let a = MatRef::from_column_major_slice(&self.a, n, n);
        solve::solve_in_place_with_conj(a, a, perm, Conj::No, b, Par::Seq, MemStack::new(&mut self.mem));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3×3 system that needs pivoting (zero leading entry); the solution x = (1, 2, 3) is
    /// built into b = A x by hand.
    #[test]
    fn solves_a_system_that_needs_pivoting() {
        let a = [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [4.0, -1.0, 2.0]];
        let x = [1.0, 2.0, 3.0];
        let mut b: Vec<f64> = a.iter().map(|row| row.iter().zip(&x).map(|(p, q)| p * q).sum()).collect();
        let mut lu = DenseLu::new(3);
        {
            let m = lu.matrix_mut();
            for i in 0..3 {
                for j in 0..3 {
                    m[i + 3 * j] = a[i][j];
                }
            }
        }
        lu.factor().unwrap();
        lu.solve(&mut b).unwrap();
        for (bi, xi) in b.iter().zip(&x) {
            assert!((bi - xi).abs() < 1e-14, "{b:?}");
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
