//! Symmetric band `LDLᵀ` for the KKT matrix, with the band LU of [`super::banded`] as the
//! fallback.
//!
//! The iteration matrix `[S, s Bᵀ; s B, 0]` is symmetric (mass, Rayleigh damping, the
//! elastic tangent of an energy and the moment load's Jacobian all are). Ordered so that
//! every constraint row comes right after the last of its coordinates (reverse
//! Cuthill–McKee on the coordinates, each constraint then inserted behind its last one),
//! every leading principal block is `[S₁₁, s B₁ᵀ; s B₁, 0]` with `B₁` whole rows of `B`.
//! When `S` is positive definite and `B` has full row rank, such a block is nonsingular
//! with `n₁` positive and `m₁` negative eigenvalues, so the factorization
//!
//! ```text
//!     P A Pᵀ = L D Lᵀ,   L unit lower triangular with half-bandwidth b, D diagonal,
//!     d_j > 0 on coordinate rows, d_j < 0 on constraint rows
//! ```
//!
//! exists without pivoting (the matrix is symmetric quasi-definite in this order;
//! Vanderbei 1995, "Symmetric quasidefinite matrices", SIAM J. Optim. 5:100–113) and costs
//! `n b(b+1)/2` multiply-adds against the LU's `n b²` plus its pivot searches. Every pivot
//! is checked: a coordinate pivot below `PIVOT_RATIO` (1e-8) of its diagonal entry, a constraint
//! pivot of the wrong sign or below `PIVOT_RATIO · s`, a non-finite one, or blocks that are
//! not symmetric send that factorization to the band LU with threshold pivoting instead,
//! so nothing is assumed that a matrix does not satisfy (a stiff compressed configuration
//! can make `S` indefinite).

use super::banded::{solve_permuted, BandedKkt};
pub use super::banded_order::quasi_definite_order;
use super::kkt_pattern::{Block, KktPattern, KktSolver};

/// A coordinate pivot must keep at least this fraction of its diagonal entry (a smaller one
/// means `S₁₁` is nearly singular or indefinite there), a constraint pivot this fraction of
/// the constraint scale.
const PIVOT_RATIO: f64 = 1e-8;

/// Relative asymmetry `|a_ij − a_ji| / max|a|` of an element block above which the LU is
/// used.
const SYMMETRY_TOL: f64 = 1e-13;

pub struct BandedLdlt {
    n: usize,
    /// half-bandwidth after ordering
    band: usize,
    /// position of each original row/column in the band ordering
    new_of: Vec<usize>,
    /// `A(i, j)`, `i ≥ j` (new numbering), at `ab[j (b+1) + i − j]`; after factoring, `D`
    /// on the diagonal and `L` below it
    ab: Vec<f64>,
    /// per element e, `elem[elem_start[e]..elem_start[e + 1]]`: (entry k = 8 j + i of its
    /// block, slot in `ab`) for the entries on or below the diagonal in the new numbering
    /// (one flat list: 36 entries an element, no pointer to follow per element)
    elem: Vec<(u32, usize)>,
    elem_start: Vec<usize>,
    /// per constraint entry: (slot, coefficient)
    cons: Vec<(usize, f64)>,
    /// whether each new row is a coordinate (true) or a constraint row
    is_dof: Vec<bool>,
    work: Vec<f64>,
    /// scratch: the diagonal before factoring
    diag: Vec<f64>,
    fallback: BandedKkt,
    state: Factored,
    /// factorizations that went to the LU (reported by tests)
    pub lu_fallbacks: usize,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Factored {
    No,
    Ldlt,
    Lu,
}

impl BandedLdlt {
    pub fn new(pattern: KktPattern) -> Self {
        let n = pattern.size();
        let nd = pattern.n_dof;
        let order = quasi_definite_order(&pattern);
        let mut new_of = vec![0; n];
        for (new, &old) in order.iter().enumerate() {
            new_of[old] = new;
        }
        let mut band = 0;
        for dofs in &pattern.element_dofs {
            for &i in dofs {
                for &j in dofs {
                    band = band.max(new_of[i].abs_diff(new_of[j]));
                }
            }
        }
        for (c, row) in pattern.constraint_rows.iter().enumerate() {
            for &(d, _) in row {
                band = band.max(new_of[nd + c].abs_diff(new_of[d]));
            }
        }
        let ld = band + 1;
        let slot = |i: usize, j: usize| {
            let (i, j) = (new_of[i], new_of[j]);
            debug_assert!(i >= j);
            j * ld + i - j
        };
        let mut elem = Vec::with_capacity(36 * pattern.element_dofs.len());
        let mut elem_start = vec![0];
        for dofs in &pattern.element_dofs {
            for j in 0..8 {
                for i in 0..8 {
                    if new_of[dofs[i]] >= new_of[dofs[j]] {
                        elem.push(((8 * j + i) as u32, slot(dofs[i], dofs[j])));
                    }
                }
            }
            elem_start.push(elem.len());
        }
        let mut cons = Vec::new();
        for (c, row) in pattern.constraint_rows.iter().enumerate() {
            for &(d, coef) in row {
                // the constraint row comes after all its coordinates: entry (row, d) is below
                cons.push((slot(nd + c, d), coef));
            }
        }
        let is_dof = (0..n).map(|new| order[new] < nd).collect();
        BandedLdlt {
            n,
            band,
            new_of,
            ab: vec![0.0; ld * n],
            elem,
            elem_start,
            cons,
            is_dof,
            work: vec![0.0; n],
            diag: vec![0.0; n],
            fallback: BandedKkt::new(pattern),
            state: Factored::No,
            lu_fallbacks: 0,
        }
    }

    /// Half-bandwidth after ordering.
    pub fn bandwidth(&self) -> usize {
        self.band
    }

    /// Whether the last factorization was the LU fallback.
    pub fn used_lu(&self) -> bool {
        self.state == Factored::Lu
    }

    /// Assembles the lower band of `[Σ P_eᵀ blocks[e] P_e, s Bᵀ; s B, 0]` (new numbering)
    /// into `ab`; returns whether every block is symmetric to the bit (checked in the same
    /// pass, while each block is at hand).
    fn scatter(&mut self, blocks: &[Block], scale: f64) -> bool {
        self.ab.iter_mut().for_each(|v| *v = 0.0);
        let mut exact = true;
        for (block, range) in blocks.iter().zip(self.elem_start.windows(2)) {
            exact &= exactly_symmetric(block);
            let b = block.as_slice();
            for &(k, s) in &self.elem[range[0]..range[1]] {
                self.ab[s] += b[k as usize];
            }
        }
        for &(s, coef) in &self.cons {
            self.ab[s] += scale * coef;
        }
        exact
    }
}

/// Whether `b = bᵀ` to the bit: all 28 pairs compared, without a branch per pair (the
/// early exit of `all` costs more than the comparisons it could skip).
#[inline]
fn exactly_symmetric(b: &Block) -> bool {
    let s = b.as_slice();
    let mut same = true;
    for j in 0..8 {
        for i in j + 1..8 {
            same &= s[8 * j + i] == s[8 * i + j];
        }
    }
    same
}

/// Whether every block is symmetric within [`SYMMETRY_TOL`]. Blocks built as sums of
/// symmetric matrices are symmetric to the bit ([`BandedLdlt::scatter`] tells); only others
/// need the tolerance.
fn symmetric(blocks: &[Block]) -> bool {
    blocks.iter().all(|b| {
        if exactly_symmetric(b) {
            return true;
        }
        let tol = SYMMETRY_TOL * b.amax();
        (0..8).all(|j| (j + 1..8).all(|i| (b[(i, j)] - b[(j, i)]).abs() <= tol))
    })
}

impl KktSolver for BandedLdlt {
    fn factor(&mut self, blocks: &[Block], scale: f64) -> Result<(), String> {
        self.state = Factored::No;
        // assembled first: the bit-exact symmetry check comes with it, the tolerant one only
        // when some block fails that
        let exact = self.scatter(blocks, scale);
        if exact || symmetric(blocks) {
            let cons_min = PIVOT_RATIO * scale.abs();
            if band_ldlt(&mut self.ab, self.n, self.band, &self.is_dof, cons_min, &mut self.diag) {
                self.state = Factored::Ldlt;
                return Ok(());
            }
        }
        self.lu_fallbacks += 1;
        self.fallback.factor(blocks, scale)?;
        self.state = Factored::Lu;
        Ok(())
    }

    fn solve(&mut self, rhs: &mut [f64]) -> Result<(), String> {
        match self.state {
            Factored::No => return Err("solve called without a valid factorization".into()),
            Factored::Lu => return self.fallback.solve(rhs),
            Factored::Ldlt => {}
        }
        let (ab, n, band) = (&self.ab, self.n, self.band);
        solve_permuted(&self.new_of, &mut self.work, rhs, |w| band_ldlt_solve(ab, n, band, w))
    }
}

/// `LDLᵀ` without pivoting of a symmetric band matrix in place: `A(i, j)`, `0 ≤ i − j ≤ b`,
/// at `ab[j (b+1) + i − j]`; on return `D` on the diagonal and `L` (unit diagonal not
/// stored) below. Right-looking: for column j, `d_j = a_jj`, `l_ij = a_ij/d_j`, and
/// `a_ik −= l_ij d_j l_kj` for `j < k ≤ i ≤ j + b`. Returns false, leaving `ab` spoilt, as
/// soon as a pivot fails the checks of the module doc (`is_dof[j]` tells which sign row j
/// needs; `cons_min` is the smallest constraint pivot magnitude accepted).
/// `diag` (n entries) is scratch for the diagonal before the updates, against which a
/// coordinate pivot is checked.
pub fn band_ldlt(ab: &mut [f64], n: usize, b: usize, is_dof: &[bool], cons_min: f64, diag: &mut [f64]) -> bool {
    for (j, d) in diag[..n].iter_mut().enumerate() {
        *d = ab[j * (b + 1)];
    }
    let diag: &[f64] = diag;
    // monomorphized for the common half-bandwidths, as band_lu
    macro_rules! dispatch {
        ($($k:literal)*) => {
            match b {
                $($k => band_ldlt_impl::<$k>(ab, n, b, is_dof, cons_min, diag),)*
                _ => band_ldlt_impl::<0>(ab, n, b, is_dof, cons_min, diag),
            }
        };
    }
    dispatch!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16)
}

fn band_ldlt_impl<const B: usize>(
    ab: &mut [f64],
    n: usize,
    b: usize,
    is_dof: &[bool],
    cons_min: f64,
    diag: &[f64],
) -> bool {
    let ld = b + 1;
    let mut w = [0.0_f64; 64];
    let mut l = [0.0_f64; 64];
    let mut wv = vec![0.0; if b > 64 { b } else { 0 }];
    let mut lv = vec![0.0; if b > 64 { b } else { 0 }];
    // the next pivot as computed by the last column's update, held in a register: the
    // chain from pivot to pivot (divide, scale, update) is what bounds this loop, and
    // reading the pivot back from memory would add a store-to-load round trip to it
    let mut next_pivot = None;
    for j in 0..n {
        let km = b.min(n - 1 - j);
        let (head, rest) = ab.split_at_mut((j + 1) * ld);
        let col = &mut head[j * ld..(j + 1) * ld];
        let d = next_pivot.take().unwrap_or(col[0]);
        let ok = if is_dof[j] { d.is_finite() && d > PIVOT_RATIO * diag[j] } else { d.is_finite() && d < -cons_min };
        if !ok {
            return false;
        }
        let inv = 1.0 / d;
        if B != 0 && km == B {
            // w (the column before scaling) and l as values, not through the scratch arrays:
            // stored one by one and reloaded two at a time by the vectorized update, they
            // stall on store-to-load forwarding (a fifth of this function's time)
            let w: [f64; B] = std::array::from_fn(|r| col[1 + r]);
            let l: [f64; B] = std::array::from_fn(|r| w[r] * inv);
            col[1..=B].copy_from_slice(&l);
            // the value the update below gives entry (j+1, j+1), the same operation
            next_pivot = Some(rest[0] - l[0] * w[0]);
            // column j+1+k holds rows j+1+k..: entry (j+1+i, j+1+k) at k ld + i − k
            for k in 0..B {
                let wk = w[k];
                let tgt = &mut rest[k * ld..k * ld + B - k];
                for i in k..B {
                    tgt[i - k] -= l[i] * wk;
                }
            }
        } else {
            let (w, l): (&mut [f64], &mut [f64]) =
                if b > 64 { (&mut wv[..km], &mut lv[..km]) } else { (&mut w[..km], &mut l[..km]) };
            for r in 0..km {
                w[r] = col[1 + r];
                l[r] = w[r] * inv;
                col[1 + r] = l[r];
            }
            for k in 0..km {
                let wk = w[k];
                let tgt = &mut rest[k * ld..k * ld + km - k];
                for i in k..km {
                    tgt[i - k] -= l[i] * wk;
                }
            }
        }
    }
    true
}

/// Solves `A x = rhs` in place with the factors of [`band_ldlt`]: `L y = rhs`, `D z = y`,
/// `Lᵀ x = z`.
pub fn band_ldlt_solve(ab: &[f64], n: usize, b: usize, x: &mut [f64]) {
    macro_rules! dispatch {
        ($($k:literal)*) => {
            match b {
                $($k => band_ldlt_solve_impl::<$k>(ab, n, b, x),)*
                _ => band_ldlt_solve_impl::<0>(ab, n, b, x),
            }
        };
    }
    dispatch!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16)
}

fn band_ldlt_solve_impl<const B: usize>(ab: &[f64], n: usize, b: usize, x: &mut [f64]) {
    // Row-oriented substitutions that carry the last b solved values in a window of
    // registers (`win`): the column-oriented form (`x[j+1..j+b] −= l x_j`) stores each
    // entry and reloads it, two at a time, one row later, across two stores, and stalls on
    // store-to-load forwarding at every row. The operations and their order are those of
    // the column form, so the bits are the same: row i subtracts the terms of columns
    // j = i−b, …, i−1 in that order, and only the last waits for the row just solved.
    let ld = b + 1;
    // L y = rhs: y_i = rhs_i − Σ_{j = i−b}^{i−1} L(i, j) y_j, L(i, j) at ab[j ld + i − j]
    let full = if B != 0 { B.min(n) } else { n };
    for i in 0..full {
        let mut acc = x[i];
        for j in i.saturating_sub(b)..i {
            acc -= ab[j * ld + i - j] * x[j];
        }
        x[i] = acc;
    }
    if B != 0 && n > B {
        // win[m] = y_{i−B+m}
        let mut win: [f64; B] = std::array::from_fn(|m| x[m]);
        for i in B..n {
            let mut acc = x[i];
            for m in 0..B {
                acc -= ab[(i - B + m) * ld + B - m] * win[m];
            }
            x[i] = acc;
            win = std::array::from_fn(|m| if m + 1 < B { win[m + 1] } else { acc });
        }
    }
    // D z = y and Lᵀ x = z: x_j = y_j / d_j − Σ_{r=1}^{b} L(j+r, j) x_{j+r}
    let short = if B != 0 { n.min(B) } else { n };
    for j in (n - short..n).rev() {
        let km = b.min(n - 1 - j);
        let l = &ab[j * ld + 1..j * ld + 1 + km];
        let s: f64 = x[j + 1..j + 1 + km].iter().zip(l).map(|(a, m)| a * m).sum();
        x[j] = x[j] / ab[j * ld] - s;
    }
    if B != 0 && n > B {
        // win[m] = x_{j+1+m}
        let mut win: [f64; B] = std::array::from_fn(|m| x[n - B + m]);
        for j in (0..n - B).rev() {
            let l: &[f64; B] = (&ab[j * ld + 1..j * ld + 1 + B]).try_into().expect("length B");
            // x_{j+1}, just solved, enters last: the terms of the rows further down do not
            // wait for it (two partial sums, the chain from row to row one multiply-add)
            let (mut s0, mut s1) = (0.0, 0.0);
            let mut r = 1;
            while r + 1 < B {
                s0 += win[r] * l[r];
                s1 += win[r + 1] * l[r + 1];
                r += 2;
            }
            if r < B {
                s0 += win[r] * l[r];
            }
            let xj = x[j] / ab[j * ld] - (s0 + s1) - win[0] * l[0];
            x[j] = xj;
            win = std::array::from_fn(|m| if m == 0 { xj } else { win[m - 1] });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::kkt::DenseKkt;

    /// Three "elements" in a chain sharing 4 dofs, a ground pin (two single-dof rows) and a
    /// pin-like row between the ends: the quasi-definite order must be taken (no fallback)
    /// and the solution must equal the dense LAPACK LU's.
    fn chain() -> (KktPattern, Vec<Block>) {
        let pattern = KktPattern {
            n_dof: 16,
            element_dofs: vec![[0, 1, 2, 3, 4, 5, 6, 7], [4, 5, 6, 7, 8, 9, 10, 11], [8, 9, 10, 11, 12, 13, 14, 15]],
            constraint_rows: vec![vec![(0, 1.0)], vec![(1, 1.0)], vec![(12, 1.0), (2, -1.0)]],
        };
        let blocks = (0..3)
            .map(|e| {
                let r = Block::from_fn(|i, j| ((i * 3 + j * 5 + e) % 7) as f64 * 0.1 - 0.2);
                r * r.transpose() + Block::identity() * 0.5
            })
            .collect();
        (pattern, blocks)
    }

    fn dense_solution(pattern: &KktPattern, blocks: &[Block], scale: f64, rhs: &[f64]) -> Vec<f64> {
        let mut d = DenseKkt::new(pattern.clone());
        d.factor(blocks, scale).unwrap();
        let mut x = rhs.to_vec();
        d.solve(&mut x).unwrap();
        x
    }

    #[test]
    fn ldlt_matches_the_dense_lu_without_fallback() {
        let (pattern, blocks) = chain();
        let rhs: Vec<f64> = (0..19).map(|i| (i as f64 * 0.37).sin()).collect();
        let expected = dense_solution(&pattern, &blocks, 3.0, &rhs);
        let mut s = BandedLdlt::new(pattern);
        s.factor(&blocks, 3.0).unwrap();
        assert!(!s.used_lu(), "a positive definite S with independent constraints needs no pivoting");
        let mut x = rhs.clone();
        s.solve(&mut x).unwrap();
        for i in 0..19 {
            assert!((x[i] - expected[i]).abs() < 1e-11, "{i}: {} vs {}", x[i], expected[i]);
        }
        assert_eq!(s.lu_fallbacks, 0);
    }

    /// An indefinite `S` (a negative diagonal shift) and a non-symmetric block both go to
    /// the LU, which still solves the system.
    #[test]
    fn indefinite_or_unsymmetric_matrices_fall_back_to_lu() {
        let (pattern, blocks) = chain();
        let rhs: Vec<f64> = (0..19).map(|i| (i as f64 * 0.11).cos()).collect();
        let indefinite: Vec<Block> = blocks.iter().map(|b| b - Block::identity() * 3.0).collect();
        let mut unsym = blocks.clone();
        unsym[1][(0, 5)] += 0.3;
        for (case, bl) in [("indefinite", indefinite), ("unsymmetric", unsym)] {
            let expected = dense_solution(&pattern, &bl, 3.0, &rhs);
            let mut s = BandedLdlt::new(pattern.clone());
            s.factor(&bl, 3.0).unwrap();
            assert!(s.used_lu(), "{case}");
            let mut x = rhs.clone();
            s.solve(&mut x).unwrap();
            for i in 0..19 {
                assert!((x[i] - expected[i]).abs() < 1e-10, "{case} {i}: {} vs {}", x[i], expected[i]);
            }
        }
    }

    /// A chain of beam elements (the pendulum's pattern) keeps the band of its coordinates,
    /// 7: the ground pin's rows go where they widen nothing.
    #[test]
    fn a_pinned_chain_keeps_half_bandwidth_seven() {
        for ne in [1, 2, 50] {
            let pattern = KktPattern {
                n_dof: 4 * (ne + 1),
                element_dofs: (0..ne).map(|e| std::array::from_fn(|i| 4 * e + i)).collect(),
                constraint_rows: vec![vec![(0, 1.0)], vec![(1, 1.0)]],
            };
            let order = quasi_definite_order(&pattern);
            let mut pos = vec![0; pattern.size()];
            for (p, &o) in order.iter().enumerate() {
                pos[o] = p;
            }
            for (c, row) in pattern.constraint_rows.iter().enumerate() {
                assert!(row.iter().all(|&(d, _)| pos[d] < pos[pattern.n_dof + c]), "{ne}: row {c} behind its dofs");
            }
            assert_eq!(BandedLdlt::new(pattern).bandwidth(), 7, "{ne} elements");
        }
    }

    /// The textbook column-oriented `LDLᵀ` and substitutions (the form the doc comments
    /// state, with no register windows or carried pivots), as the reference the kernels
    /// must match to the bit.
    fn reference_factor_and_solve(ab: &mut [f64], n: usize, b: usize, x: &mut [f64]) {
        let ld = b + 1;
        for j in 0..n {
            let km = b.min(n - 1 - j);
            let inv = 1.0 / ab[j * ld];
            let w: Vec<f64> = (0..km).map(|r| ab[j * ld + 1 + r]).collect();
            let l: Vec<f64> = w.iter().map(|w| w * inv).collect();
            ab[j * ld + 1..j * ld + 1 + km].copy_from_slice(&l);
            for k in 0..km {
                for i in k..km {
                    ab[(j + 1 + k) * ld + i - k] -= l[i] * w[k];
                }
            }
        }
        for j in 0..n {
            let km = b.min(n - 1 - j);
            for r in 0..km {
                x[j + 1 + r] -= ab[j * ld + 1 + r] * x[j];
            }
        }
        for j in 0..n {
            x[j] /= ab[j * ld];
        }
        for j in (0..n).rev() {
            let km = b.min(n - 1 - j);
            let l = &ab[j * ld + 1..j * ld + 1 + km];
            let (head, tail) = x.split_at_mut(j + 1);
            let (xj, t) = (&mut head[j], &tail[..km]);
            // the kernel's order: the odd and the even terms from the second on in two
            // sums, then the first term (the general path: one sum in order)
            let s = if km == b && (1..=16).contains(&b) {
                let (mut s0, mut s1) = (0.0, 0.0);
                let mut r = 1;
                while r + 1 < b {
                    s0 += t[r] * l[r];
                    s1 += t[r + 1] * l[r + 1];
                    r += 2;
                }
                if r < b {
                    s0 += t[r] * l[r];
                }
                *xj -= s0 + s1;
                t[0] * l[0]
            } else {
                t.iter().zip(l).map(|(a, m)| a * m).sum()
            };
            *xj -= s;
        }
    }

    /// Factors and solutions of [`band_ldlt`] and [`band_ldlt_solve`] equal the reference
    /// to the bit, for half-bandwidths with a monomorphized kernel (1, 2, 7, 16), without
    /// one (17, 23), and matrices shorter than their band: the rewritten kernels compute
    /// the same operations in the same order. Matrix: symmetric, diagonally dominant,
    /// entries from a fixed sequence.
    #[test]
    fn kernels_match_the_column_oriented_reference_to_the_bit() {
        for b in [1, 2, 7, 16, 17, 23] {
            for n in [b / 2 + 1, b + 1, 3 * b + 5, 60] {
                let ld = b + 1;
                let mut ab: Vec<f64> = (0..n * ld)
                    .map(|s| if s % ld == 0 { 10.0 + 2.0 * b as f64 } else { ((s * 7919) % 97) as f64 / 97.0 - 0.5 })
                    .collect();
                for j in 0..n {
                    for r in n - j..ld {
                        ab[j * ld + r] = 0.0; // outside the matrix
                    }
                }
                let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 0.1).collect();
                let (mut ab_ref, mut x_ref) = (ab.clone(), rhs.clone());
                reference_factor_and_solve(&mut ab_ref, n, b, &mut x_ref);
                let mut diag = vec![0.0; n];
                assert!(band_ldlt(&mut ab, n, b, &vec![true; n], 0.0, &mut diag), "b {b} n {n}");
                let mut x = rhs.clone();
                band_ldlt_solve(&ab, n, b, &mut x);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&ab), bits(&ab_ref), "factors, b {b} n {n}");
                assert_eq!(bits(&x), bits(&x_ref), "solution, b {b} n {n}");
            }
        }
    }

    /// The monomorphized (full band) path and the general path give the same factors: a long
    /// chain exercises both (full columns in the middle, short ones at the end).
    #[test]
    fn long_chain_matches_dense() {
        let ne = 12;
        let pattern = KktPattern {
            n_dof: 4 * (ne + 1),
            element_dofs: (0..ne).map(|e| std::array::from_fn(|i| 4 * e + i)).collect(),
            constraint_rows: vec![vec![(0, 1.0)], vec![(1, 1.0)]],
        };
        let blocks: Vec<Block> = (0..ne)
            .map(|e| {
                let r = Block::from_fn(|i, j| (((i + 2 * j + e) * 7) % 11) as f64 * 0.05);
                r * r.transpose() + Block::identity()
            })
            .collect();
        let n = pattern.size();
        let rhs: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64).sqrt()).collect();
        let expected = dense_solution(&pattern, &blocks, 2.0, &rhs);
        let mut s = BandedLdlt::new(pattern);
        s.factor(&blocks, 2.0).unwrap();
        assert!(!s.used_lu());
        let mut x = rhs.clone();
        s.solve(&mut x).unwrap();
        for i in 0..n {
            assert!((x[i] - expected[i]).abs() < 1e-11 * (1.0 + expected[i].abs()), "{i}: {} vs {}", x[i], expected[i]);
        }
    }
}
