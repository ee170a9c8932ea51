//! The reduced basis and the map between full and reduced coordinates (pyMOR's
//! reductor vocabulary: `reduce` projects a full state, `reconstruct` maps back).
//!
//! ```text
//!     x ≈ x_ref + V q                         (V: n × r)
//!     galerkin:              V = Φ, the POD of all coordinates (thesis eqs. 11–12)
//!     constraint-preserving: V = blockdiag(Φ*, I) on (free, joint) coordinates (eqs. 20–21)
//!     whole-system:          [x; λ/w] ≈ [x_ref; 0] + [V; V_λ] q (eqs. 18–19)
//! ```

use super::pod::{ModeRule, Pod};
use super::sample::Hyper;
use ndarray::{Array1, Array2, ArrayView1, ArrayView2};

/// Which reduction (SPEC §3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Variant {
    /// project all coordinates; the joint equations are projected too, and those the
    /// basis cannot move are dropped (ground pins, whose rows are zero in every snapshot)
    Galerkin,
    /// project coordinates and multipliers together: the whole saddle-point system
    WholeSystem,
    /// keep the joint coordinates unreduced, multipliers exact (the thesis's method)
    ConstraintPreserving,
    /// coordinates and multipliers each by a POD of their own, the coordinate basis
    /// enriched by supremizers `Bᵀ Ψ` (inf-sup stable; `super::whole_system`)
    WholeSystemStabilized,
}

impl Variant {
    pub fn name(&self) -> &'static str {
        match self {
            Variant::Galerkin => "galerkin",
            Variant::WholeSystem => "whole-system",
            Variant::ConstraintPreserving => "constraint-preserving",
            Variant::WholeSystemStabilized => "whole-system-stabilized",
        }
    }

    pub fn parse(s: &str) -> Option<Variant> {
        [Variant::Galerkin, Variant::WholeSystem, Variant::ConstraintPreserving, Variant::WholeSystemStabilized]
            .into_iter()
            .find(|v| v.name() == s)
    }
}

/// What the snapshots are taken of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SnapshotKind {
    /// the coordinates themselves, as in the thesis: `x ≈ V q`
    Raw,
    /// the change from the initial state: `x ≈ x₀ + V q`, which keeps `x₀` exact
    Reference,
}

impl SnapshotKind {
    pub fn name(&self) -> &'static str {
        match self {
            SnapshotKind::Raw => "raw",
            SnapshotKind::Reference => "reference",
        }
    }

    pub fn parse(s: &str) -> Option<SnapshotKind> {
        [SnapshotKind::Raw, SnapshotKind::Reference].into_iter().find(|v| v.name() == s)
    }
}

/// A reduced basis: everything `reduce` and `reconstruct` need.
#[derive(Clone, Debug)]
pub struct Basis {
    pub variant: Variant,
    pub snapshots: SnapshotKind,
    /// `x_ref` (zero for raw snapshots)
    pub reference: Array1<f64>,
    /// `V`, n_dof × r; orthonormal columns except for whole-system
    pub modes: Array2<f64>,
    /// coordinates kept unreduced (constraint-preserving: the joint coordinates); they
    /// are the last `kept.len()` columns of `V`, one unit column each
    pub kept: Vec<usize>,
    /// whole-system: `V_λ`, n_c × r, with `λ ≈ w V_λ q`
    pub multiplier_modes: Option<Array2<f64>>,
    /// `w` of the whole-system variant (N/m): the multipliers' snapshots are `λ/w`
    pub multiplier_scale: f64,
    /// how many columns of `V` come from the POD
    pub n_pod_modes: usize,
    /// the sampled elements of hyper-reduction (ECSW), when trained
    pub hyper: Option<Hyper>,
}

/// The POD(s) and the basis built from them.
pub struct Trained {
    pub basis: Basis,
    /// the decompositions the modes come from (of the rows the variant reduces), one per
    /// block of the basis (one for a basis without blocks)
    pub pods: Vec<Pod>,
    /// how many POD modes each block keeps (columns of `V` in this order, each block's
    /// followed by its output modes, then the kept ones)
    pub block_modes: Vec<usize>,
    /// how many output modes each block adds after its POD modes
    /// ([`super::output_modes`]; zeros without them)
    pub output_modes: Vec<usize>,
    /// the dofs whose snapshot rows entered the POD
    pub reduced_dofs: Vec<usize>,
}

impl Trained {
    /// The columns of `V` each block holds: its POD modes and its output modes.
    pub fn block_columns(&self) -> Vec<usize> {
        self.block_modes.iter().zip(&self.output_modes).map(|(p, o)| p + o).collect()
    }

    /// `1 − Σ_{i≤r} σᵢ² / Σ σᵢ²` of the worst block: the energy fraction the basis misses.
    pub fn uncaptured_energy(&self) -> f64 {
        self.pods.iter().zip(&self.block_modes).map(|(p, &r)| 1.0 - p.energy[r - 1]).fold(0.0, f64::max)
    }
}

/// How to build a basis from snapshots.
#[derive(Clone, Debug)]
pub struct BasisSpec {
    pub variant: Variant,
    pub snapshots: SnapshotKind,
    pub modes: ModeRule,
    /// `w` of the whole-system variant (its multipliers' snapshots are `λ/w`)
    pub multiplier_scale: f64,
    /// groups of coordinates with a POD of their own each (a block-diagonal basis whose
    /// modes each move one group only, e.g. one body; the variant's kept coordinates are
    /// left out of them); empty: one POD of all coordinates
    pub blocks: Vec<Vec<usize>>,
    /// whole-system-stabilized: the joint equations and the multiplier mode rule
    pub stabilization: Option<Stabilization>,
}

/// What the stabilized variant needs besides the snapshots.
#[derive(Clone, Debug)]
pub struct Stabilization {
    /// `B`, n_c × n: the (constant) joint equations `B x = b`
    pub constraints: Array2<f64>,
    /// how many multiplier modes `k` to keep (of the POD of the multiplier snapshots;
    /// a ratio is of `n_c`)
    pub multiplier_modes: ModeRule,
}

impl Basis {
    /// The identity basis of `n` coordinates (`x_ref = 0`, `V = I`): a reduced model of it is
    /// the full model, which tests compare against.
    #[cfg(test)]
    pub(crate) fn identity(n: usize, variant: Variant) -> Self {
        Basis {
            variant,
            snapshots: super::SnapshotKind::Raw,
            reference: ndarray::Array1::zeros(n),
            modes: ndarray::Array2::eye(n),
            kept: Vec::new(),
            multiplier_modes: None,
            multiplier_scale: 1.0,
            n_pod_modes: n,
            hyper: None,
        }
    }

    /// Writes the unit columns of the kept coordinates (the last `kept.len()` columns).
    pub(super) fn set_kept_columns(&mut self) {
        for (k, &d) in self.kept.iter().enumerate() {
            self.modes[[d, self.n_pod_modes + k]] = 1.0;
        }
    }

    pub fn n_dof(&self) -> usize {
        self.modes.nrows()
    }

    /// Reduced coordinates: `r = n_pod_modes + kept.len()`.
    pub fn n_reduced(&self) -> usize {
        self.modes.ncols()
    }

    /// `q` with `x_ref + V q` closest to `x` in the least-squares sense (`Vᵀ(x − x_ref)`
    /// when `V` is orthonormal).
    pub fn reduce(&self, x: ArrayView1<f64>) -> Array1<f64> {
        self.reduce_increment((&x - &self.reference).view())
    }

    /// The reduced coordinates of a change `dx` of the full ones (a velocity): as
    /// [`Self::reduce`] without the reference.
    pub fn reduce_increment(&self, dx: ArrayView1<f64>) -> Array1<f64> {
        let vtd = self.modes.t().dot(&dx);
        match self.variant {
            Variant::WholeSystem => {
                use crate::linalg::lapack::Solve;
                let gram = self.modes.t().dot(&self.modes);
                gram.solve_into(vtd.clone()).unwrap_or(vtd)
            }
            _ => vtd,
        }
    }

    /// `x = x_ref + V q`.
    pub fn reconstruct(&self, q: ArrayView1<f64>) -> Array1<f64> {
        &self.reference + &self.modes.dot(&q)
    }

    /// [`Self::reconstruct`] of every column of `z` (one instant each): `X = x_ref 1ᵀ + V Z`.
    pub fn reconstruct_columns(&self, z: ArrayView2<f64>) -> Array2<f64> {
        self.modes.dot(&z) + self.reference.view().insert_axis(ndarray::Axis(1))
    }

    /// Checks sizes and values; `what(field)` names a field for the message.
    pub fn validate(&self, n_dof: usize, n_constraints: usize) -> Result<(), (String, String)> {
        let bad = |f: &str, p: String| Err((f.to_string(), p));
        if self.modes.nrows() != n_dof {
            return bad("basis/modes", format!("has {} rows, the model has {n_dof} coordinates", self.modes.nrows()));
        }
        if self.modes.ncols() == 0 {
            return bad("basis/modes", "has no columns (r = 0)".into());
        }
        if self.reference.len() != n_dof {
            return bad(
                "basis/reference",
                format!("has {} entries, the model has {n_dof} coordinates", self.reference.len()),
            );
        }
        if self.modes.iter().chain(self.reference.iter()).any(|x| !x.is_finite()) {
            return bad("basis/modes", "holds non-finite values".into());
        }
        let supremizers = match (&self.multiplier_modes, self.variant) {
            (Some(psi), Variant::WholeSystemStabilized) => psi.ncols(),
            _ => 0,
        };
        if self.n_pod_modes + supremizers + self.kept.len() != self.modes.ncols() {
            return bad(
                "basis/kept_dofs",
                format!(
                    "{} POD modes, {supremizers} supremizers and {} kept coordinates do not make {} columns",
                    self.n_pod_modes,
                    self.kept.len(),
                    self.modes.ncols()
                ),
            );
        }
        if let Some(&d) = self.kept.iter().find(|&&d| d >= n_dof) {
            return bad("basis/kept_dofs", format!("coordinate {d} does not exist (the model has {n_dof})"));
        }
        match (&self.multiplier_modes, self.variant) {
            (Some(vl), Variant::WholeSystem) if vl.dim() == (n_constraints, self.modes.ncols()) => Ok(()),
            (Some(vl), Variant::WholeSystem) => bad(
                "basis/multiplier_modes",
                format!("is {:?}, expected ({n_constraints}, {})", vl.dim(), self.modes.ncols()),
            ),
            (None, Variant::WholeSystem) => bad("basis/multiplier_modes", "is missing (whole-system variant)".into()),
            (Some(psi), Variant::WholeSystemStabilized) if psi.nrows() == n_constraints && psi.ncols() >= 1 => Ok(()),
            (Some(psi), Variant::WholeSystemStabilized) => bad(
                "basis/multiplier_modes",
                format!("is {:?}, expected ({n_constraints}, k) with k ≥ 1 multiplier modes", psi.dim()),
            ),
            (None, Variant::WholeSystemStabilized) => {
                bad("basis/multiplier_modes", "is missing (whole-system-stabilized variant)".into())
            }
            _ => Ok(()),
        }
    }
}
