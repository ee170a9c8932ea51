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

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt;
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Conj, MatMut, MatRef, Par};

use super::vec_ops::{axpy, dot};

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
    /// upper triangle as filled
    copy: Vec<f64>,
    /// the first nonzero column of each row's lower triangle
    first: Vec<usize>,
    /// the bordered block form of the last factorization: block starts then the border start
    blocks: Vec<usize>,
    border: usize,
    /// the border rows of `L`, `W = C L_D⁻ᵀ`, row-major (k × t)
    w: Vec<f64>,
    /// `1 / L_jj` of the bordered factorization
    inv_diag: Vec<f64>,
    /// whether `first` has a bordered block form (`blocks`), once it has been looked for
    blocks_known: Option<bool>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Factors {
    Lu,
    Cholesky,
    /// `L Lᵀ` of a bordered block-diagonal matrix (`blocks`, `border`)
    Bordered,
}

/// The bordered block form is used when its flop count is below this share of the dense
/// Cholesky's (it makes a few more, smaller calls).
const BORDERED_SHARE: f64 = 0.6;
/// What one more diagonal block costs beyond its flops (calls, short loops), in flops.
const BLOCK_OVERHEAD: f64 = 400.0;

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
    pub fn factor_symmetric(&mut self) -> Result<(), String> {
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

    /// Looks for a bordered block-diagonal form `[D, Cᵀ; C, E]`: `D` block-diagonal on
    /// `0..t`, a dense border of `k = n − t` rows. With `first[i]` the first nonzero column
    /// of row i (lower triangle), the rows `0..t` split into independent blocks where no row
    /// of `i..t` reaches left of i. Every border size up to `n / 4` is tried, and the form
    /// is kept (in `blocks`, `border`) when its flop count is below [`BORDERED_SHARE`] of
    /// the dense factorization's.
    fn find_blocks(&mut self) -> bool {
        let n = self.n;
        let mut same = true;
        for i in 0..n {
            // row i of the lower triangle is column i of the upper one: contiguous
            let f = self.a[n * i..n * i + i].iter().position(|&x| x != 0.0).unwrap_or(i);
            same &= f == self.first[i];
            self.first[i] = f;
        }
        if same && self.blocks_known.is_some() {
            return self.blocks_known == Some(true);
        }
        self.blocks_known = Some(self.choose_blocks());
        self.blocks_known == Some(true)
    }

    /// [`Self::find_blocks`] for a new `first`.
    fn choose_blocks(&mut self) -> bool {
        let n = self.n;
        let dense = (n * n * n) as f64 / 3.0;
        let mut best = (BORDERED_SHARE * dense, None);
        for k in 0..=n / 4 {
            let t = n - k;
            let (mut cost, mut end, mut min) = ((k * k * t + k * k * k / 3) as f64, t, usize::MAX);
            for i in (0..t).rev() {
                min = min.min(self.first[i]);
                if min == i {
                    let nb = (end - i) as f64;
                    cost += nb * nb * nb / 3.0 + k as f64 * nb * nb + BLOCK_OVERHEAD;
                    end = i;
                }
            }
            if cost < best.0 {
                best = (cost, Some(t));
            }
        }
        let Some(t) = best.1 else { return false };
        self.border = t;
        self.blocks.clear();
        let mut min = usize::MAX;
        for i in (0..t).rev() {
            min = min.min(self.first[i]);
            if min == i {
                self.blocks.push(i);
            }
        }
        self.blocks.reverse();
        self.blocks.push(t);
        true
    }

    /// `A = L Lᵀ` in the bordered block form: `Dᵦ = Lᵦ Lᵦᵀ` block by block, the border
    /// `W = C L_D⁻ᵀ` (rows kept in `w`), and `E − W Wᵀ = L_E L_Eᵀ`; the zero blocks of D
    /// and of L (no fill outside the blocks) are never touched. False when a block or the
    /// Schur complement is not positive definite.
    fn bordered_cholesky(&mut self) -> bool {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, checked just above
            return unsafe { self.bordered_cholesky_avx2() };
        }
        self.bordered_cholesky_with()
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn bordered_cholesky_avx2(&mut self) -> bool {
        self.bordered_cholesky_with()
    }

    #[inline(always)]
    fn bordered_cholesky_with(&mut self) -> bool {
        let (n, t) = (self.n, self.border);
        let k = n - t;
        for w in self.blocks.windows(2) {
            if !cholesky_lower(&mut self.a, &mut self.inv_diag, n, w[0], w[1] - w[0]) {
                return false;
            }
        }
        // W = C L_D⁻ᵀ, the k rows together (k independent chains per column of L)
        for i in 0..k {
            for c in 0..t {
                self.w[i * t + c] = self.a[t + i + n * c];
            }
        }
        for c in 0..t {
            let col = &self.a[n * c + c + 1..n * c + self.end_of_block(c)];
            for i in 0..k {
                let wi = &mut self.w[i * t + c..(i + 1) * t];
                wi[0] *= self.inv_diag[c];
                let x = wi[0];
                axpy(-x, col, &mut wi[1..]);
            }
        }
        for i in 0..k {
            for j in 0..=i {
                self.a[t + i + n * (t + j)] -= dot(&self.w[i * t..(i + 1) * t], &self.w[j * t..(j + 1) * t]);
            }
        }
        cholesky_lower(&mut self.a, &mut self.inv_diag, n, t, k)
    }

    /// The end of the diagonal block that column `c < border` belongs to.
    fn end_of_block(&self, c: usize) -> usize {
        self.blocks[self.blocks.partition_point(|&b| b <= c)]
    }

    /// `L Lᵀ x = b` in place with the bordered factors.
    fn bordered_solve(&self, x: &mut [f64]) {
        let (n, t) = (self.n, self.border);
        let (xd, xe) = x.split_at_mut(t);
        let inv = &self.inv_diag;
        for b in self.blocks.windows(2) {
            forward_lower(&self.a, &inv[b[0]..b[1]], n, b[0], &mut xd[b[0]..b[1]]);
        }
        for (i, xi) in xe.iter_mut().enumerate() {
            *xi -= dot(&self.w[i * t..(i + 1) * t], xd);
        }
        forward_lower(&self.a, &inv[t..], n, t, xe);
        backward_lower(&self.a, &inv[t..], n, t, xe);
        for (i, &xi) in xe.iter().enumerate() {
            axpy(-xi, &self.w[i * t..(i + 1) * t], xd);
        }
        for b in self.blocks.windows(2) {
            backward_lower(&self.a, &inv[b[0]..b[1]], n, b[0], &mut xd[b[0]..b[1]]);
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
        factor::lu_in_place(
            a,
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
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
        if kind == Factors::Bordered {
            self.bordered_solve(rhs);
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
            Factors::Bordered => unreachable!("solved above"),
        }
        Ok(())
    }
}

/// `A = L Lᵀ` of the block `A[s.., s..]` of size m of a column-major matrix with leading
/// dimension `ld`, L written over its lower triangle (the upper one is left as it is).
/// Left-looking, four earlier columns at a time: column j is updated by
/// `A[j.., j] −= Σ_k L[j, k] L[j.., k]` reading each column piece once, then scaled by
/// `1/√L_jj`. Small blocks (a per-body basis's 12–40 modes) are where faer's blocked
/// kernel has its overheads: 35 × 35 took 4.7 µs there and about 1.3 µs here. False when
/// a pivot is not positive.
#[inline(always)]
fn cholesky_lower(a: &mut [f64], inv_diag: &mut [f64], ld: usize, s: usize, m: usize) -> bool {
    for j in 0..m {
        let (left, right) = a.split_at_mut(ld * (s + j));
        let colj = &mut right[s + j..s + m];
        let col = |k: usize| &left[ld * (s + k) + s + j..ld * (s + k) + s + m];
        let mut k = 0;
        while k + 4 <= j {
            let (c0, c1, c2, c3) = (col(k), col(k + 1), col(k + 2), col(k + 3));
            let (f0, f1, f2, f3) = (c0[0], c1[0], c2[0], c3[0]);
            for (o, ((x0, x1), (x2, x3))) in colj.iter_mut().zip(c0.iter().zip(c1).zip(c2.iter().zip(c3))) {
                *o -= (f0 * x0 + f1 * x1) + (f2 * x2 + f3 * x3);
            }
            k += 4;
        }
        for kk in k..j {
            let c = col(kk);
            axpy(-c[0], c, colj);
        }
        let d = colj[0];
        // written so that a NaN pivot fails too
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(d > 0.0) {
            return false;
        }
        let l = d.sqrt();
        let inv = 1.0 / l;
        colj[0] = l;
        inv_diag[s + j] = inv;
        colj[1..].iter_mut().for_each(|x| *x *= inv);
    }
    true
}

/// `x ← L⁻¹ x` with L the lower triangle of the block at `s` (size `x.len()`), by columns.
#[inline(always)]
fn forward_lower(a: &[f64], inv_diag: &[f64], ld: usize, s: usize, x: &mut [f64]) {
    let m = x.len();
    for j in 0..m {
        let col = &a[ld * (s + j) + s + j..ld * (s + j) + s + m];
        x[j] *= inv_diag[j];
        let xj = x[j];
        axpy(-xj, &col[1..], &mut x[j + 1..]);
    }
}

/// `x ← L⁻ᵀ x` with L the lower triangle of the block at `s`, by dot products.
#[inline(always)]
fn backward_lower(a: &[f64], inv_diag: &[f64], ld: usize, s: usize, x: &mut [f64]) {
    let m = x.len();
    for j in (0..m).rev() {
        let col = &a[ld * (s + j) + s + j..ld * (s + j) + s + m];
        x[j] = (x[j] - dot(&col[1..], &x[j + 1..])) * inv_diag[j];
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

    /// A block-diagonal matrix (blocks of 9, 7, 8 and 8) with a coupling border of k = 2
    /// rows, like a block basis's Newton matrix with its joints, and without one (k = 0):
    /// the blocks and the border are found from the zero pattern and factored block by
    /// block; the matrix is diagonally dominant, hence positive definite. With one diagonal
    /// entry made negative it is not: the LU fallback takes the matrix restored from its
    /// upper triangle. All give the x that b was built from. Bound: round-off of a 34 × 34
    /// solve, 1e-12.
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
            for (flip, kind) in [(false, Factors::Bordered), (true, Factors::Lu)] {
                let a = |i: usize, j: usize| if flip && i == 7 && j == 7 { -entry(i, j) } else { entry(i, j) };
                let mut lu = DenseLu::new(n);
                let m = lu.matrix_mut();
                for j in 0..n {
                    for i in 0..n {
                        m[i + n * j] = a(i, j);
                    }
                }
                let mut b: Vec<f64> = (0..n).map(|i| (0..n).map(|j| a(i, j) * x[j]).sum()).collect();
                lu.factor_symmetric().unwrap();
                assert_eq!(lu.factored, Some(kind), "k = {k}");
                assert_eq!((&lu.blocks[..], lu.border), (&blocks[..], 32), "k = {k}");
                lu.solve(&mut b).unwrap();
                for (bi, xi) in b.iter().zip(&x) {
                    assert!((bi - xi).abs() < 1e-12, "k = {k}, {kind:?}: {b:?}");
                }
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
