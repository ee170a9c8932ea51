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
//! not symmetric (checked by `factor`; `factor_symmetric` takes the word of a caller that
//! builds them symmetric to the bit, as the full system does) send that factorization to
//! the band LU with threshold pivoting instead,
//! so nothing is assumed that a matrix does not satisfy (a stiff compressed configuration
//! can make `S` indefinite).

mod kernels;

use super::banded::{solve_permuted, BandedKkt};
pub use super::banded_order::quasi_definite_order;
use super::kkt_pattern::{Block, KktPattern, KktSolver};
use crate::error::{Error, Result};
use kernels::PIVOT_RATIO;
pub use kernels::{band_ldlt, band_ldlt_solve};

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
    /// where each constraint row's entries start in `cons`
    row_offsets: Vec<usize>,
    /// whether each new row is a coordinate (true) or a constraint row
    is_dof: Vec<bool>,
    work: Vec<f64>,
    /// scratch: the diagonal before factoring
    diag: Vec<f64>,
    /// the band LU, built from `pattern` at the first factorization that needs it (most
    /// runs never do)
    fallback: Option<BandedKkt>,
    pattern: KktPattern,
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
            row_offsets: pattern.row_offsets(),
            is_dof,
            work: vec![0.0; n],
            diag: vec![0.0; n],
            fallback: None,
            pattern,
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

    /// Assembles and factors; with `check`, blocks that are not symmetric (to the bit, or
    /// else within [`SYMMETRY_TOL`]) go to the LU, without it they are taken as symmetric
    /// ([`KktSolver::factor_symmetric`]).
    fn factor_checked(&mut self, blocks: &[Block], scale: f64, check: bool) -> Result<()> {
        self.state = Factored::No;
        // assembled first: the bit-exact symmetry check comes with it, the tolerant one only
        // when some block fails that
        let exact = self.scatter(blocks, scale, check);
        if exact || symmetric(blocks) {
            let cons_min = PIVOT_RATIO * scale.abs();
            if band_ldlt(&mut self.ab, self.n, self.band, &self.is_dof, cons_min, &mut self.diag) {
                self.state = Factored::Ldlt;
                return Ok(());
            }
        }
        self.lu_fallbacks += 1;
        let pattern = &self.pattern;
        self.fallback.get_or_insert_with(|| BandedKkt::new(pattern.clone())).factor(blocks, scale)?;
        self.state = Factored::Lu;
        Ok(())
    }

    /// Assembles the lower band of `[Σ P_eᵀ blocks[e] P_e, s Bᵀ; s B, 0]` (new numbering)
    /// into `ab`; returns whether every block is symmetric to the bit (checked in the same
    /// pass, while each block is at hand, when `check`; else taken to be).
    fn scatter(&mut self, blocks: &[Block], scale: f64, check: bool) -> bool {
        self.ab.iter_mut().for_each(|v| *v = 0.0);
        let mut exact = true;
        for (block, range) in blocks.iter().zip(self.elem_start.windows(2)) {
            if check {
                exact &= exactly_symmetric(block);
            }
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
    fn factor(&mut self, blocks: &[Block], scale: f64) -> Result<()> {
        self.factor_checked(blocks, scale, true)
    }

    fn factor_symmetric(&mut self, blocks: &[Block], scale: f64) -> Result<()> {
        // to the bit, NaN included (a diverging state gives NaN entries, built alike)
        debug_assert!(
            blocks.iter().all(|b| (0..8).all(|j| (j + 1..8).all(|i| b[(i, j)].to_bits() == b[(j, i)].to_bits()))),
            "blocks said symmetric are not"
        );
        self.factor_checked(blocks, scale, false)
    }

    fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
        match self.state {
            Factored::No => return Err(Error::linear_solve("solve called without a valid factorization")),
            Factored::Lu => {
                return self
                    .fallback
                    .as_mut()
                    .map_or(Err(Error::linear_solve("the LU fallback was never built")), |f| f.solve(rhs))
            }
            Factored::Ldlt => {}
        }
        let (ab, n, band) = (&self.ab, self.n, self.band);
        solve_permuted(&self.new_of, &mut self.work, rhs, |w| band_ldlt_solve(ab, n, band, w))
    }

    fn set_constraint_row(&mut self, c: usize, coefs: &[f64]) {
        let start = self.row_offsets[c];
        self.cons[start..start + coefs.len()].iter_mut().zip(coefs).for_each(|(e, &k)| e.1 = k);
        self.pattern.set_row(c, coefs);
        if let Some(lu) = self.fallback.as_mut() {
            lu.set_constraint_row(c, coefs);
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
