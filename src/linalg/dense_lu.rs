//! A small dense LU with partial pivoting (faer) whose storage is allocated once: the
//! reduced models factor an r×r (plus constraints) matrix in every Newton iteration, and
//! their time loop must not touch the heap.
//!
//! `P A = L U`; `solve` applies `x = U⁻¹ L⁻¹ P b` in place. A symmetric matrix may be
//! factored as `A = L Lᵀ` (Cholesky, half the flops: on the thesis four-bar's 54 × 54 Newton
//! matrix 5 instead of 10 µs) with LU as the fallback when it is not positive definite.
//! A symmetric matrix that is block-diagonal apart from a few dense border rows (the
//! Newton matrix of a basis made of one block of modes per body, its joints last) is
//! factored block by block (George & Liu, *Computer Solution of Large Sparse Positive
//! Definite Systems*, §6.2, bordered block-diagonal form): the Cholesky factor has no fill
//! outside the blocks and the border, so the blocks cost what they would on their own.

use super::simd::{dispatch, Kernel};
use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt;
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Conj, MatMut, MatRef, Par};

mod bordered;
mod triangular;

/// Up to this order a symmetric matrix is factored by [`SmallCholesky`] instead of faer's
/// blocked Cholesky, whose set-up dominates at such sizes (measured on the pendulum's 18 × 18
/// reduced matrix: 11 % of the reduced run in faer).
const SMALL: usize = 32;

/// `A = L Lᵀ` in place on the lower triangle of the column-major n × n `A` (the layout of
/// faer's Cholesky) by [`triangular::cholesky_lower`], `1 / l_jj` kept aside and `Lᵀ`
/// mirrored into the upper triangle (the input is kept in [`DenseLu`]'s copy) for the
/// backward substitution. False when a pivot is not positive (or NaN).
struct SmallCholesky<'a>(&'a mut [f64], &'a mut [f64], usize);

impl Kernel for SmallCholesky<'_> {
    type Output = bool;
    #[inline(always)]
    fn run(self) -> bool {
        let (a, inv_diag, n) = (self.0, self.1, self.2);
        if !triangular::cholesky_lower(a, inv_diag, n, 0, n) {
            return false;
        }
        triangular::mirror_lower(a, n, 0, n);
        true
    }
}

/// `L Lᵀ x = b` in place with the factor of [`SmallCholesky`] (faer's triangular solves cost
/// several times the 2n² flops at such sizes): both substitutions down contiguous columns
/// ([`triangular::forward_lower`], [`triangular::backward_upper`]).
struct SmallCholeskySolve<'a>(&'a [f64], &'a [f64], &'a mut [f64]);

impl Kernel for SmallCholeskySolve<'_> {
    type Output = ();
    #[inline(always)]
    fn run(self) {
        let (l, inv_diag, x) = (self.0, self.1, self.2);
        let n = x.len();
        triangular::forward_lower(l, inv_diag, n, 0, x);
        triangular::backward_upper(l, inv_diag, n, 0, x);
    }
}

pub struct DenseLu {
    /// the matrix to factor (filled by the caller, column-major), then its factors
    a: Vec<f64>,
    n: usize,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
    factored: Option<Factors>,
    /// the matrix as filled, kept while a dense Cholesky factorization is tried; the
    /// bordered one keeps only the diagonal here (its first n entries), as it leaves the
    /// upper triangle as filled until it has succeeded (then it holds `Lᵀ` there)
    copy: Vec<f64>,
    /// the first nonzero column of each row's lower triangle
    first: Vec<usize>,
    /// the bordered block form of the last factorization: block starts then the border start
    blocks: Vec<usize>,
    border: usize,
    /// the border rows of `L`, `W = C L_D⁻ᵀ`, row-major (k × t)
    w: Vec<f64>,
    /// `1 / L_jj` of the bordered and of the small Cholesky factorization
    inv_diag: Vec<f64>,
    /// whether `first` has a bordered block form (`blocks`), once it has been looked for
    blocks_known: Option<bool>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Factors {
    Lu,
    Cholesky,
    /// `L Lᵀ` of a matrix of order ≤ [`SMALL`], `Lᵀ` also in the upper triangle
    SmallCholesky,
    /// `L Lᵀ` of a bordered block-diagonal matrix (`blocks`, `border`)
    Bordered,
}

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
            first: vec![0; n],
            blocks: Vec::with_capacity(n + 1),
            border: n,
            w: vec![0.0; n * n / 4],
            inv_diag: vec![0.0; n],
            blocks_known: None,
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
    /// [`Self::factor`]; in bordered block form when that saves flops. Every matrix is
    /// tried by Cholesky first: on the block-basis four-bar, 44 of its ~620 Newton
    /// matrices are indefinite, one at a time, so going on with LU after a failure (16 in
    /// a row was tried) cost more than the failed attempts. A dense attempt works on a
    /// copy: faer's Cholesky may write the upper triangle too.
    pub fn factor_symmetric(&mut self) -> Result<()> {
        self.check_finite()?;
        let n = self.n;
        if self.find_blocks() {
            // the bordered factorization writes the lower triangle only: the upper one and
            // the diagonal restore the matrix if it fails
            for i in 0..n {
                self.copy[i] = self.a[i + n * i];
            }
            if self.bordered_cholesky() {
                self.factored = Some(Factors::Bordered);
                return Ok(());
            }
            for j in 0..n {
                self.a[j + n * j] = self.copy[j];
                for i in j + 1..n {
                    self.a[i + n * j] = self.a[j + n * i];
                }
            }
            return self.factor_lu();
        }
        self.copy.copy_from_slice(&self.a);
        if n <= SMALL {
            if dispatch(SmallCholesky(&mut self.a, &mut self.inv_diag, n)) {
                self.factored = Some(Factors::SmallCholesky);
                return Ok(());
            }
            self.a.copy_from_slice(&self.copy);
            return self.factor_lu();
        }
        let a = MatMut::from_column_major_slice_mut(&mut self.a, n, n);
        match llt::factor::cholesky_in_place(
            a,
            Default::default(),
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        ) {
            Ok(_) => {
                self.factored = Some(Factors::Cholesky);
                Ok(())
            }
            Err(_) => {
                self.a.copy_from_slice(&self.copy);
                self.factor_lu()
            }
        }
    }

    /// Factors the matrix in place; refuses non-finite entries and exact zero pivots.
    pub fn factor(&mut self) -> Result<()> {
        self.check_finite()?;
        self.factor_lu()
    }

    fn factor_lu(&mut self) -> Result<()> {
        let n = self.n;
        let a = MatMut::from_column_major_slice_mut(&mut self.a, n, n);
        factor::lu_in_place(
            a,
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
        if let Some(i) = (0..n).find(|&i| self.a[i + n * i] == 0.0) {
            return Err(Error::linear_solve(format!("the iteration matrix is singular (zero pivot {i} of {n})")));
        }
        self.factored = Some(Factors::Lu);
        Ok(())
    }

    fn check_finite(&self) -> Result<()> {
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
            return Err(Error::linear_solve(format!(
                "the iteration matrix holds non-finite values (column {})",
                k / n.max(1)
            )));
        }
        Ok(())
    }

    /// Solves `A x = b` in place with the last factorization.
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
        let Some(kind) = self.factored else {
            return Err(Error::linear_solve("no valid factorization to solve with"));
        };
        let n = self.dim();
        if rhs.len() != n {
            return Err(Error::linear_solve(format!("right-hand side has {} entries, the matrix {n} rows", rhs.len())));
        }
        if kind == Factors::Bordered {
            self.bordered_solve(rhs);
            return Ok(());
        }
        if kind == Factors::SmallCholesky {
            dispatch(SmallCholeskySolve(&self.a, &self.inv_diag, rhs));
            return Ok(());
        }
        let b = MatMut::from_column_major_slice_mut(rhs, n, 1);
        let a = MatRef::from_column_major_slice(&self.a, n, n);
        match kind {
            Factors::Lu => {
                let perm = PermRef::new_checked(&self.perm, &self.perm_inv, n);
                solve::solve_in_place_with_conj(a, a, perm, Conj::No, b, Par::Seq, MemStack::new(&mut self.mem));
            }
            Factors::Cholesky => {
                llt::solve::solve_in_place_with_conj(a, Conj::No, b, Par::Seq, MemStack::new(&mut self.mem))
            }
            Factors::Bordered | Factors::SmallCholesky => unreachable!("solved above"),
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
            ([[4.0, 1.0, 0.5], [1.0, 3.0, -0.5], [0.5, -0.5, 2.0]], Factors::SmallCholesky),
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

    /// The small-matrix Cholesky against faer's on dense symmetric positive definite
    /// matrices `A = B Bᵀ + n I` (B with entries in [-1, 1)), n = 1 … 40 (the small path up
    /// to 32, faer's above): the same factor `L` to round-off (1e-12 relative to its largest
    /// entry) and solves that give back the x the right-hand side was built from (1e-11).
    #[test]
    fn small_cholesky_matches_faer() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        };
        for n in 1..=40 {
            let b: Vec<f64> = (0..n * n).map(|_| rnd()).collect();
            let mut a = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    a[i + n * j] =
                        (0..n).map(|k| b[i + n * k] * b[j + n * k]).sum::<f64>() + if i == j { n as f64 } else { 0.0 };
                }
            }
            let mut lu = DenseLu::new(n);
            lu.matrix_mut().copy_from_slice(&a);
            lu.factor_symmetric().unwrap();
            let small = n <= SMALL;
            assert_eq!(lu.factored, Some(if small { Factors::SmallCholesky } else { Factors::Cholesky }), "n = {n}");
            let mut reference = a.clone();
            let mut mem =
                MemBuffer::new(llt::factor::cholesky_in_place_scratch::<f64>(n, Par::Seq, Default::default()));
            let m = MatMut::from_column_major_slice_mut(&mut reference, n, n);
            llt::factor::cholesky_in_place(
                m,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .unwrap();
            let big = (0..n).map(|j| reference[j + n * j].abs()).fold(0.0, f64::max);
            for j in 0..n {
                for i in j..n {
                    let (x, y) = (lu.a[i + n * j], reference[i + n * j]);
                    assert!((x - y).abs() <= 1e-12 * big, "n = {n}, L[{i}, {j}]: {x} vs {y}");
                }
            }
            let x: Vec<f64> = (0..n).map(|_| rnd()).collect();
            let mut rhs: Vec<f64> = (0..n).map(|i| (0..n).map(|j| a[i + n * j] * x[j]).sum()).collect();
            lu.solve(&mut rhs).unwrap();
            for (r, xi) in rhs.iter().zip(&x) {
                assert!((r - xi).abs() < 1e-11, "n = {n}: {r} vs {xi}");
            }
        }
    }

    /// A block-diagonal matrix (blocks of 9, 7, 8 and 8) with a coupling border of k = 2
    /// rows, like a block basis's Newton matrix with its joints, and without one (k = 0):
    /// the blocks and the border are found from the zero pattern and factored block by
    /// block; the matrix is diagonally dominant, hence positive definite. With one diagonal
    /// entry made negative it is not: in a block (entry 7) or in the border (the last
    /// entry: the blocks factor and the Schur complement fails) the LU fallback takes the
    /// matrix restored from its upper triangle. One solver serves the cases in turn,
    /// positive definite again at the end (the upper triangle a success leaves holds `Lᵀ`,
    /// and the next matrix is written whole). All give the x that b was built from. Bound:
    /// round-off of a 34 × 34 solve, 1e-12.
    #[test]
    fn bordered_block_systems_by_blocks_or_the_lu_fallback() {
        let blocks = [0usize, 9, 16, 24, 32];
        for k in [2, 0] {
            let n = 32 + k;
            let block = |i: usize| blocks.iter().rposition(|&b| i >= b).expect("in a block");
            let entry = |i: usize, j: usize| -> f64 {
                let coupled = block(i) == block(j) || i >= 32 || j >= 32;
                match (i == j, coupled) {
                    (true, _) => 20.0 + i as f64,
                    (false, true) => ((i * j + 3 * (i + j)) % 7) as f64 / 7.0 - 0.4,
                    (false, false) => 0.0,
                }
            };
            let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.9).cos() + 0.1).collect();
            let mut lu = DenseLu::new(n);
            let cases = [
                (None, Factors::Bordered),
                (Some(7), Factors::Lu),
                (Some(n - 1), Factors::Lu),
                (None, Factors::Bordered),
            ];
            for (flip, kind) in cases {
                let a = |i: usize, j: usize| if flip == Some(i) && i == j { -entry(i, j) } else { entry(i, j) };
                let m = lu.matrix_mut();
                for j in 0..n {
                    for i in 0..n {
                        m[i + n * j] = a(i, j);
                    }
                }
                let mut b: Vec<f64> = (0..n).map(|i| (0..n).map(|j| a(i, j) * x[j]).sum()).collect();
                lu.factor_symmetric().unwrap();
                assert_eq!(lu.factored, Some(kind), "k = {k}, flip {flip:?}");
                assert_eq!((&lu.blocks[..], lu.border), (&blocks[..], 32), "k = {k}");
                lu.solve(&mut b).unwrap();
                for (bi, xi) in b.iter().zip(&x) {
                    assert!((bi - xi).abs() < 1e-12, "k = {k}, flip {flip:?}, {kind:?}: {b:?}");
                }
            }
        }
    }

    #[test]
    fn refuses_singular_and_non_finite_matrices() {
        let mut lu = DenseLu::new(2);
        lu.matrix_mut()[0] = 1.0; // second row and column stay zero
        assert!(lu.factor().unwrap_err().to_string().contains("singular"));
        lu.matrix_mut()[3] = f64::NAN;
        assert!(lu.factor().unwrap_err().to_string().contains("non-finite"));
        assert!(lu.solve(&mut [1.0, 1.0]).is_err());
    }
}
