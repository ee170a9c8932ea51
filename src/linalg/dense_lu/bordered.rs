//! The bordered block-diagonal Cholesky factorization of [`DenseLu`] (George & Liu,
//! *Computer Solution of Large Sparse Positive Definite Systems*, §6.2): a symmetric matrix
//! `[D, Cᵀ; C, E]` with `D` block-diagonal (one block of modes per body) and a few dense
//! border rows (the joints) is factored as
//!
//! ```text
//!     Dᵦ = Lᵦ Lᵦᵀ (each block),   W = C L_D⁻ᵀ,   E − W Wᵀ = L_E L_Eᵀ,
//! ```
//!
//! with no fill outside the blocks and the border, so the blocks cost what they would on
//! their own.

use super::triangular::{backward_upper, cholesky_lower, forward_lower, mirror_lower};
use super::DenseLu;
use crate::linalg::simd::{dispatch, Kernel};
use crate::linalg::vec_ops::{axpy, dot};

/// The bordered block form is used when its flop count is below this share of the dense
/// Cholesky's (it makes a few more, smaller calls).
const BORDERED_SHARE: f64 = 0.6;
/// What one more diagonal block costs beyond its flops (calls, short loops), in flops.
const BLOCK_OVERHEAD: f64 = 400.0;

impl DenseLu {
    /// Looks for a bordered block-diagonal form `[D, Cᵀ; C, E]`: `D` block-diagonal on
    /// `0..t`, a dense border of `k = n − t` rows. With `first[i]` the first nonzero column
    /// of row i (lower triangle), the rows `0..t` split into independent blocks where no row
    /// of `i..t` reaches left of i. Every border size up to `n / 4` is tried, and the form
    /// is kept (in `blocks`, `border`) when its flop count is below [`BORDERED_SHARE`] of
    /// the dense factorization's.
    pub(super) fn find_blocks(&mut self) -> bool {
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
    pub(super) fn bordered_cholesky(&mut self) -> bool {
        // the kernel, inlined whole into the dispatched function (see crate::linalg::simd)
        struct Factor<'a>(&'a mut DenseLu);
        impl Kernel for Factor<'_> {
            type Output = bool;
            #[inline(always)]
            fn run(self) -> bool {
                self.0.bordered_cholesky_with()
            }
        }
        dispatch(Factor(self))
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
        if !cholesky_lower(&mut self.a, &mut self.inv_diag, n, t, k) {
            return false;
        }
        // factored: the input's upper triangle is no longer needed (it restored the matrix
        // after a failure); Lᵀ there lets the backward sweeps run down contiguous columns
        for w in self.blocks.windows(2) {
            mirror_lower(&mut self.a, n, w[0], w[1] - w[0]);
        }
        mirror_lower(&mut self.a, n, t, k);
        true
    }

    /// The end of the diagonal block that column `c < border` belongs to.
    fn end_of_block(&self, c: usize) -> usize {
        self.blocks[self.blocks.partition_point(|&b| b <= c)]
    }

    /// `L Lᵀ x = b` in place with the bordered factors.
    pub(super) fn bordered_solve(&self, x: &mut [f64]) {
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
        backward_upper(&self.a, &inv[t..], n, t, xe);
        for (i, &xi) in xe.iter().enumerate() {
            axpy(-xi, &self.w[i * t..(i + 1) * t], xd);
        }
        for b in self.blocks.windows(2) {
            backward_upper(&self.a, &inv[b[0]..b[1]], n, b[0], &mut xd[b[0]..b[1]]);
        }
    }
}
