//! Linear solvers for the saddle-point (KKT) iteration matrix
//!
//! ```text
//!     [ Σ_e P_eᵀ K_e P_e   s Bᵀ ] [Δq]   [r_q]
//!     [ s B                0    ] [Δμ] = [r_c]
//! ```
//!
//! where `K_e` are 8×8 element blocks scattered through their dof maps `P_e` and `B` is the
//! constant constraint Jacobian scaled by `s` (the integrator picks `s` so that both block
//! rows have the same magnitude). The sparsity pattern is fixed at construction, so the
//! symbolic analysis (COLAMD ordering) is done once and every Newton iteration only scatters
//! values and refactors numerically: cost linear in the number of elements.

use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, NumericLu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};

pub(crate) use super::kkt_pattern::SlotMap;
pub use super::kkt_pattern::{Block, KktPattern, KktSolver, LinearSolverKind};

pub fn make_solver(kind: LinearSolverKind, pattern: KktPattern) -> Box<dyn KktSolver> {
    match kind {
        LinearSolverKind::Banded => Box::new(super::banded_ldlt::BandedLdlt::new(pattern)),
        LinearSolverKind::Sparse => Box::new(SparseKkt::new(pattern)),
        LinearSolverKind::Dense => Box::new(DenseKkt::new(pattern)),
    }
}

/// Sparse KKT solver on faer's supernodal/simplicial LU.
pub struct SparseKkt {
    pattern: KktPattern,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    slots: SlotMap,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    factor_mem: MemBuffer,
    solve_mem: MemBuffer,
    factored: bool,
}

impl SparseKkt {
    pub fn new(pattern: KktPattern) -> Self {
        let n = pattern.size();
        let nd = pattern.n_dof;
        // Collect the (row, col) pairs column by column, then sort and deduplicate.
        let mut cols: Vec<Vec<usize>> = vec![Vec::new(); n];
        for dofs in &pattern.element_dofs {
            for &j in dofs {
                cols[j].extend_from_slice(dofs);
            }
        }
        for (c, row) in pattern.constraint_rows.iter().enumerate() {
            for &(dof, _) in row {
                cols[dof].push(nd + c);
                cols[nd + c].push(dof);
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for col in cols.iter_mut() {
            col.sort_unstable();
            col.dedup();
            row_idx.extend_from_slice(col);
            col_ptr.push(row_idx.len());
        }
        let slots = SlotMap::new(&pattern, |i, j| {
            let r = &row_idx[col_ptr[j]..col_ptr[j + 1]];
            col_ptr[j] + r.binary_search(&i).expect("entry in pattern")
        });
        let symbolic = {
            let sym = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
            factorize_symbolic_lu(sym, Default::default()).expect("symbolic LU of a valid pattern")
        };
        let factor_mem = MemBuffer::new(symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()));
        let solve_mem = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        let values = vec![0.0; row_idx.len()];
        SparseKkt {
            pattern,
            col_ptr,
            row_idx,
            values,
            slots,
            symbolic,
            numeric: NumericLu::new(),
            factor_mem,
            solve_mem,
            factored: false,
        }
    }
}

impl KktSolver for SparseKkt {
    fn factor(&mut self, blocks: &[Block], scale: f64) -> Result<()> {
        debug_assert_eq!(blocks.len(), self.pattern.element_dofs.len());
        self.slots.scatter(&mut self.values, blocks, scale);
        let n = self.pattern.size();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        let mat = SparseColMatRef::new(sym, &self.values);
        self.factored = false;
        self.symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                mat,
                Par::Seq,
                MemStack::new(&mut self.factor_mem),
                Default::default(),
            )
            .map_err(|e| Error::linear_solve(format!("sparse LU failed: {e:?}")))?;
        self.factored = true;
        Ok(())
    }

    fn set_constraint_row(&mut self, c: usize, coefs: &[f64]) {
        self.pattern.set_row(c, coefs);
        self.slots.set_row(c, coefs);
    }

    fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
        if !self.factored {
            return Err(Error::linear_solve("solve called without a valid factorization"));
        }
        let n = rhs.len();
        let lu = faer::sparse::linalg::lu::LuRef::new_unchecked(&self.symbolic, &self.numeric);
        let mat = MatMut::from_column_major_slice_mut(rhs, n, 1);
        lu.solve_in_place_with_conj(Conj::No, mat, Par::Seq, MemStack::new(&mut self.solve_mem));
        if rhs.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(Error::linear_solve("the iteration matrix is singular (non-finite solution)"))
        }
    }
}

/// Dense KKT solver through LAPACK (getrf/getrs via ndarray-linalg, through `linalg::lapack`).
pub struct DenseKkt {
    pattern: KktPattern,
    lu: Option<crate::linalg::lapack::LUFactorized<ndarray::OwnedRepr<f64>>>,
}

impl DenseKkt {
    pub fn new(pattern: KktPattern) -> Self {
        DenseKkt { pattern, lu: None }
    }
}

impl KktSolver for DenseKkt {
    fn factor(&mut self, blocks: &[Block], scale: f64) -> Result<()> {
        use crate::linalg::lapack::FactorizeInto;
        let n = self.pattern.size();
        let nd = self.pattern.n_dof;
        let mut a = ndarray::Array2::<f64>::zeros((n, n));
        for (dofs, block) in self.pattern.element_dofs.iter().zip(blocks) {
            for j in 0..8 {
                for i in 0..8 {
                    a[[dofs[i], dofs[j]]] += block[(i, j)];
                }
            }
        }
        for (c, row) in self.pattern.constraint_rows.iter().enumerate() {
            for &(dof, coef) in row {
                a[[nd + c, dof]] += scale * coef;
                a[[dof, nd + c]] += scale * coef;
            }
        }
        self.lu = Some(a.factorize_into().map_err(|e| Error::linear_solve(format!("dense LU failed: {e}")))?);
        Ok(())
    }

    fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
        dense_lu_solve(self.lu.as_ref(), rhs)
    }

    fn set_constraint_row(&mut self, c: usize, coefs: &[f64]) {
        self.pattern.set_row(c, coefs);
    }
}

/// Solves in place with a LAPACK LU factorization (getrs); a non-finite solution means the
/// matrix was singular. Shared by the dense KKT solver and the reduced models.
pub fn dense_lu_solve(
    lu: Option<&crate::linalg::lapack::LUFactorized<ndarray::OwnedRepr<f64>>>,
    rhs: &mut [f64],
) -> Result<()> {
    use crate::linalg::lapack::Solve;
    let lu = lu.ok_or_else(|| Error::linear_solve("solve called without a valid factorization"))?;
    let mut b = ndarray::ArrayViewMut1::from(rhs);
    let x = lu.solve(&b.view()).map_err(|e| Error::linear_solve(format!("dense solve failed: {e}")))?;
    if x.iter().any(|v| !v.is_finite()) {
        return Err(Error::linear_solve("the iteration matrix is singular (non-finite solution)"));
    }
    b.assign(&x);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain of two "elements" sharing 4 dofs with one pin-like constraint: the sparse and
    /// dense solvers must agree, and both must satisfy the system (residual check).
    #[test]
    fn sparse_banded_and_dense_agree_and_solve_the_system() {
        let pattern = KktPattern {
            n_dof: 12,
            element_dofs: vec![[0, 1, 2, 3, 4, 5, 6, 7], [4, 5, 6, 7, 8, 9, 10, 11]],
            constraint_rows: vec![vec![(0, 1.0)], vec![(1, 1.0)], vec![(8, 1.0), (0, -1.0)]],
        };
        let blocks: Vec<Block> = (0..2)
            .map(|e| {
                let r = Block::from_fn(|i, j| ((i * 3 + j * 5 + e) % 7) as f64 * 0.1);
                r * r.transpose() + Block::identity() * 2.0
            })
            .collect();
        let rhs: Vec<f64> = (0..15).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut x1 = rhs.clone();
        let mut x2 = rhs.clone();
        let mut s = SparseKkt::new(pattern.clone());
        s.factor(&blocks, 3.0).unwrap();
        s.solve(&mut x1).unwrap();
        let mut d = DenseKkt::new(pattern.clone());
        d.factor(&blocks, 3.0).unwrap();
        d.solve(&mut x2).unwrap();
        let mut x3 = rhs.clone();
        let mut b = super::super::banded::BandedKkt::new(pattern.clone());
        b.factor(&blocks, 3.0).unwrap();
        b.solve(&mut x3).unwrap();
        for i in 0..15 {
            assert!((x1[i] - x2[i]).abs() < 1e-12, "{i}: {} vs {}", x1[i], x2[i]);
            assert!((x3[i] - x2[i]).abs() < 1e-12, "{i}: {} vs {}", x3[i], x2[i]);
        }
        // residual of the dense matrix built by hand
        let mut a = vec![vec![0.0; 15]; 15];
        for (dofs, b) in pattern.element_dofs.iter().zip(&blocks) {
            for i in 0..8 {
                for j in 0..8 {
                    a[dofs[i]][dofs[j]] += b[(i, j)];
                }
            }
        }
        for (c, row) in pattern.constraint_rows.iter().enumerate() {
            for &(dof, coef) in row {
                a[12 + c][dof] += 3.0 * coef;
                a[dof][12 + c] += 3.0 * coef;
            }
        }
        for i in 0..15 {
            let ax: f64 = (0..15).map(|j| a[i][j] * x1[j]).sum();
            assert!((ax - rhs[i]).abs() < 1e-12);
        }
    }

    /// A row whose coefficients move (a driven angle's (−sin θ, cos θ)): every solver, built
    /// with the row at θ = 0 and then set to θ = 0.7, solves as a dense solver built with the
    /// row at 0.7 does (same matrix: agreement to round-off, 1e-12).
    #[test]
    fn a_row_set_after_building_solves_as_one_built_with_it() {
        let row = |th: f64| vec![(2, -th.sin()), (3, th.cos())];
        let pattern = |th: f64| KktPattern {
            n_dof: 12,
            element_dofs: vec![[0, 1, 2, 3, 4, 5, 6, 7], [4, 5, 6, 7, 8, 9, 10, 11]],
            constraint_rows: vec![vec![(0, 1.0)], vec![(1, 1.0)], row(th)],
        };
        let blocks: Vec<Block> = (0..2)
            .map(|e| {
                let r = Block::from_fn(|i, j| ((i * 5 + j * 3 + e) % 7) as f64 * 0.1);
                r * r.transpose() + Block::identity() * 2.0
            })
            .collect();
        let rhs: Vec<f64> = (0..15).map(|i| (i as f64 * 0.61).cos()).collect();
        let mut reference = DenseKkt::new(pattern(0.7));
        reference.factor(&blocks, 2.0).unwrap();
        let mut want = rhs.clone();
        reference.solve(&mut want).unwrap();
        let solvers: Vec<Box<dyn KktSolver>> = vec![
            Box::new(SparseKkt::new(pattern(0.0))),
            Box::new(DenseKkt::new(pattern(0.0))),
            Box::new(super::super::banded::BandedKkt::new(pattern(0.0))),
            Box::new(super::super::banded_ldlt::BandedLdlt::new(pattern(0.0))),
        ];
        let coefs: Vec<f64> = row(0.7).iter().map(|t| t.1).collect();
        for mut s in solvers {
            s.set_constraint_row(2, &coefs);
            s.factor(&blocks, 2.0).unwrap();
            let mut x = rhs.clone();
            s.solve(&mut x).unwrap();
            for i in 0..15 {
                assert!((x[i] - want[i]).abs() < 1e-12, "{i}: {} vs {}", x[i], want[i]);
            }
        }
    }
}
