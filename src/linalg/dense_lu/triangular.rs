//! The triangular kernels of the dense Cholesky factorizations (the small dense one of
//! [`super::DenseLu`] and each block of the bordered one): a left-looking Cholesky of a
//! diagonal block, the mirror of its factor into the block's upper triangle, and the two
//! substitutions, each down contiguous columns. At the orders of reduced models (10–60)
//! these are chains of dependent operations more than streams of flops; the comments say
//! where the chain is cut.

use crate::linalg::vec_ops::axpy;

/// `A = L Lᵀ` of the block `A[s.., s..]` of size m of a column-major matrix with leading
/// dimension `ld`, L written over its lower triangle (the upper one is left as it is).
/// Left-looking, four earlier columns at a time: column j is updated by
/// `A[j.., j] −= Σ_k L[j, k] L[j.., k]` reading each column piece once, then scaled by
/// `1/√L_jj`. Small blocks (a per-body basis's 12–40 modes) are where faer's blocked
/// kernel has its overheads: 35 × 35 took 4.7 µs there and about 1.3 µs here. False when
/// a pivot is not positive.
#[inline(always)]
pub(super) fn cholesky_lower(a: &mut [f64], inv_diag: &mut [f64], ld: usize, s: usize, m: usize) -> bool {
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
pub(super) fn forward_lower(a: &[f64], inv_diag: &[f64], ld: usize, s: usize, x: &mut [f64]) {
    let m = x.len();
    for j in 0..m {
        let col = &a[ld * (s + j) + s + j..ld * (s + j) + s + m];
        x[j] *= inv_diag[j];
        let xj = x[j];
        axpy(-xj, &col[1..], &mut x[j + 1..]);
    }
}

/// Writes `Lᵀ` of the block at `s` (size m) into the block's upper triangle:
/// `A[s + k, s + j] = L[s + j, s + k]` for k < j, so that column j of the upper triangle is
/// row j of L, contiguous.
#[inline(always)]
pub(super) fn mirror_lower(a: &mut [f64], ld: usize, s: usize, m: usize) {
    for j in 1..m {
        for k in 0..j {
            a[ld * (s + j) + s + k] = a[ld * (s + k) + s + j];
        }
    }
}

/// `x ← L⁻ᵀ x` with `Lᵀ` in the upper triangle of the block at `s` ([`mirror_lower`]), by
/// columns: `x_j ← x_j / L_jj`, `x_{0:j} −= x_j (Lᵀ)_{0:j, j}`. The step to the next j waits
/// on one multiply-add; a sweep by dot products also waited on each dot's horizontal sum.
#[inline(always)]
pub(super) fn backward_upper(a: &[f64], inv_diag: &[f64], ld: usize, s: usize, x: &mut [f64]) {
    let m = x.len();
    for j in (0..m).rev() {
        x[j] *= inv_diag[j];
        let xj = x[j];
        axpy(-xj, &a[ld * (s + j) + s..ld * (s + j) + s + j], &mut x[..j]);
    }
}
