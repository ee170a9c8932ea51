//! The KKT system's structure, independent of how it is solved: the 8×8 element blocks, the
//! pattern (element dof maps and constraint rows), where each entry lands in a solver's
//! storage (`SlotMap`), the choice of solver and the interface every solver implements.

use crate::error::Result;
use nalgebra::SMatrix;

pub type Block = SMatrix<f64, 8, 8>;

/// Structure of a KKT system: element dof maps and constraint rows `Σ coef·q[dof]`.
#[derive(Clone, Debug)]
pub struct KktPattern {
    pub n_dof: usize,
    pub element_dofs: Vec<[usize; 8]>,
    pub constraint_rows: Vec<Vec<(usize, f64)>>,
}

impl KktPattern {
    pub fn size(&self) -> usize {
        self.n_dof + self.constraint_rows.len()
    }

    /// Where each constraint row's entries start in a list of all rows' entries in order.
    pub(crate) fn row_offsets(&self) -> Vec<usize> {
        let mut start = 0;
        self.constraint_rows
            .iter()
            .map(|row| {
                let s = start;
                start += row.len();
                s
            })
            .collect()
    }

    /// Sets row `c`'s coefficients (its coordinates unchanged), in the order of its terms.
    pub(crate) fn set_row(&mut self, c: usize, coefs: &[f64]) {
        let row = &mut self.constraint_rows[c];
        debug_assert_eq!(row.len(), coefs.len());
        row.iter_mut().zip(coefs).for_each(|(term, &k)| term.1 = k);
    }
}

/// Which linear solver the full-order model uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LinearSolverKind {
    /// Symmetric band LDLᵀ after reverse Cuthill–McKee ordering (each constraint row behind
    /// its coordinates), falling back to a band LU with threshold pivoting (LAPACK dgbtf2's
    /// algorithm) when a pivot or the symmetry check fails: linear in the number of elements
    /// for chains and loops, the fastest here.
    #[default]
    Banded,
    /// faer general sparse LU (COLAMD + partial pivoting), symbolic analysis reused: for
    /// topologies whose band after ordering is wide (trees with many branches).
    Sparse,
    /// Dense LU through LAPACK: the O(n³) reference the thesis's timings most likely had.
    Dense,
}

/// Where each entry of the element blocks and of the scaled constraint rows lands in a
/// solver's value array; shared by the sparse and band storages.
pub(crate) struct SlotMap {
    /// for element e, entry (i, j) of its block lands at `elem[64 e + 8 j + i]`
    elem: Vec<usize>,
    /// per constraint entry: the slots of (row c, dof) and (dof, row c), and the coefficient
    cons: Vec<(usize, usize, f64)>,
    /// where each row's entries start in `cons`
    row_offsets: Vec<usize>,
}

impl SlotMap {
    /// `slot(i, j)` gives the storage index of matrix entry (i, j).
    pub(crate) fn new(pattern: &KktPattern, slot: impl Fn(usize, usize) -> usize) -> Self {
        let mut elem = Vec::with_capacity(64 * pattern.element_dofs.len());
        for dofs in &pattern.element_dofs {
            for j in 0..8 {
                for i in 0..8 {
                    elem.push(slot(dofs[i], dofs[j]));
                }
            }
        }
        let nd = pattern.n_dof;
        let mut cons = Vec::new();
        for (c, row) in pattern.constraint_rows.iter().enumerate() {
            for &(dof, coef) in row {
                cons.push((slot(nd + c, dof), slot(dof, nd + c), coef));
            }
        }
        SlotMap { elem, cons, row_offsets: pattern.row_offsets() }
    }

    /// Sets constraint row `c`'s coefficients ([`KktPattern::set_row`]).
    pub(crate) fn set_row(&mut self, c: usize, coefs: &[f64]) {
        let start = self.row_offsets[c];
        self.cons[start..start + coefs.len()].iter_mut().zip(coefs).for_each(|(e, &k)| e.2 = k);
    }

    /// Adds the blocks and `scale ×` the constraint entries into `values` (zeroed first).
    pub(crate) fn scatter(&self, values: &mut [f64], blocks: &[Block], scale: f64) {
        values.iter_mut().for_each(|v| *v = 0.0);
        for (block, slots) in blocks.iter().zip(self.elem.chunks_exact(64)) {
            // nalgebra storage is column-major: k = 8 j + i
            for (&s, &v) in slots.iter().zip(block.as_slice()) {
                values[s] += v;
            }
        }
        for &(a, b, coef) in &self.cons {
            values[a] += scale * coef;
            values[b] += scale * coef;
        }
    }
}

pub trait KktSolver: Send + Sync {
    /// Assembles `[Σ P_eᵀ blocks[e] P_e, s Bᵀ; s B, 0]` and factors it.
    fn factor(&mut self, blocks: &[Block], scale: f64) -> Result<()>;
    /// [`Self::factor`] of blocks their builder made symmetric to the bit (each entry and
    /// its mirror computed by the same operations), so that a solver that would check the
    /// symmetry need not; the default is [`Self::factor`].
    fn factor_symmetric(&mut self, blocks: &[Block], scale: f64) -> Result<()> {
        self.factor(blocks, scale)
    }
    /// Solves in place with the last factorization; `rhs` has `n_dof + n_c` entries.
    fn solve(&mut self, rhs: &mut [f64]) -> Result<()>;
    /// Sets constraint row `c`'s coefficients for the next factorization, its coordinates
    /// unchanged (rows that move with time, `B(t)`): the pattern and ordering stay.
    fn set_constraint_row(&mut self, c: usize, coefs: &[f64]);
}
