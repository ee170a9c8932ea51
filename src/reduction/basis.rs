//! The reduced basis and the map between full and reduced coordinates (pyMOR's
//! reductor vocabulary: `reduce` projects a full state, `reconstruct` maps back).
//!
//! ```text
//!     x ≈ x_ref + V q                         (V: n × r)
//!     galerkin:              V = Φ, the POD of all coordinates (thesis eqs. 11–12)
//!     constraint-preserving: V = blockdiag(Φ*, I) on (free, joint) coordinates (eqs. 20–21)
//!     whole-system:          [x; λ/w] ≈ [x_ref; 0] + [V; V_λ] q (eqs. 18–19)
//! ```

use super::pod::{pod, ModeRule, Pod};
use super::sample::Hyper;
use ndarray::{s, Array1, Array2, ArrayView1, ArrayView2, Axis};

/// Which reduction (SPEC §3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize, clap::ValueEnum)]
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
    /// how many modes each block keeps (columns of `V` in this order, then the kept ones)
    pub block_modes: Vec<usize>,
    /// the dofs whose snapshot rows entered the POD
    pub reduced_dofs: Vec<usize>,
}

impl Trained {
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

/// Builds a basis from snapshots `x` (n × m) and, for whole-system, multipliers `λ`
/// (n_c × m). `joint_dofs` are the coordinates that appear in a joint; `x_ref` is used
/// when the snapshots are `Reference`.
///
/// With blocks, `V = [blockdiag(Φ₁, …, Φ_B), kept]`: the rows of block b's coordinates
/// get the leading modes of their own POD, so that an element sees its own block's modes
/// only and the Newton matrix is block-diagonal apart from the kept coordinates.
pub(crate) fn train_plain(
    x: ArrayView2<f64>,
    lambda: ArrayView2<f64>,
    joint_dofs: &[usize],
    x_ref: ArrayView1<f64>,
    spec: &BasisSpec,
) -> Result<Trained, String> {
    let (variant, multiplier_scale) = (spec.variant, spec.multiplier_scale);
    let n = x.nrows();
    if x.ncols() == 0 {
        return Err("the training set is empty (no snapshots)".into());
    }
    let reference = match spec.snapshots {
        SnapshotKind::Raw => Array1::zeros(n),
        SnapshotKind::Reference => x_ref.to_owned(),
    };
    let centred = &x - &reference.view().insert_axis(Axis(1));
    let reduced_dofs: Vec<usize> = match variant {
        Variant::ConstraintPreserving => (0..n).filter(|d| !joint_dofs.contains(d)).collect(),
        _ => (0..n).collect(),
    };
    if variant == Variant::WholeSystemStabilized {
        return Err("the stabilized variant is trained by reduction::train_basis".into());
    }
    if !spec.blocks.is_empty() {
        return train_blocks(centred, reference, joint_dofs, reduced_dofs, spec);
    }
    if let ModeRule::Counts(_) = spec.modes {
        return Err(format!("{} gives one count per block, and the basis has no blocks", spec.modes));
    }
    let rows = match variant {
        Variant::WholeSystem => {
            if !(multiplier_scale.is_finite() && multiplier_scale > 0.0) {
                return Err(format!("the multiplier scale must be positive, got {multiplier_scale}"));
            }
            ndarray::concatenate(Axis(0), &[centred.view(), (&lambda / multiplier_scale).view()])
                .map_err(|e| e.to_string())?
        }
        _ => centred.select(Axis(0), &reduced_dofs),
    };
    let p = pod(rows.view())?;
    let r = spec.modes.count(n, p.energy.as_slice().expect("contiguous"))?;
    let lead = p.leading(r);
    let (modes, kept, multiplier_modes) = match variant {
        Variant::Galerkin => (lead, Vec::new(), None),
        Variant::WholeSystem => {
            (lead.slice(s![..n, ..]).to_owned(), Vec::new(), Some(lead.slice(s![n.., ..]).to_owned()))
        }
        Variant::WholeSystemStabilized => return Err("the stabilized variant is trained by whole_system".into()),
        Variant::ConstraintPreserving => {
            let mut v = Array2::zeros((n, r + joint_dofs.len()));
            for (i, &d) in reduced_dofs.iter().enumerate() {
                v.slice_mut(s![d, ..r]).assign(&lead.row(i));
            }
            (v, joint_dofs.to_vec(), None)
        }
    };
    let mut basis = Basis {
        variant,
        snapshots: spec.snapshots,
        reference,
        modes,
        kept,
        multiplier_modes,
        multiplier_scale,
        n_pod_modes: r,
        hyper: None,
    };
    basis.set_kept_columns();
    Ok(Trained { basis, pods: vec![p], block_modes: vec![r], reduced_dofs })
}

/// [`train_basis`] with blocks (galerkin or constraint-preserving).
fn train_blocks(
    centred: Array2<f64>,
    reference: Array1<f64>,
    joint_dofs: &[usize],
    reduced_dofs: Vec<usize>,
    spec: &BasisSpec,
) -> Result<Trained, String> {
    let n = centred.nrows();
    if matches!(spec.variant, Variant::WholeSystem | Variant::WholeSystemStabilized) {
        return Err("a basis with blocks needs the galerkin or the constraint-preserving variant".into());
    }
    if let ModeRule::Counts(c) = &spec.modes {
        if c.len() != spec.blocks.len() {
            return Err(format!("{} gives {} counts for {} blocks", spec.modes, c.len(), spec.blocks.len()));
        }
    }
    let mut owner = vec![None; n];
    for (b, block) in spec.blocks.iter().enumerate() {
        for &d in block {
            match owner.get(d) {
                None => return Err(format!("block {} holds coordinate {d}, the model has {n}", b + 1)),
                Some(Some(o)) => return Err(format!("coordinate {d} is in blocks {} and {}", o + 1, b + 1)),
                Some(None) => owner[d] = Some(b),
            }
        }
    }
    if let Some(d) = reduced_dofs.iter().find(|&&d| owner[d].is_none()) {
        return Err(format!("coordinate {d} is in no block"));
    }
    let kept = if spec.variant == Variant::ConstraintPreserving { joint_dofs.to_vec() } else { Vec::new() };
    let (mut pods, mut block_modes, mut columns) = (Vec::new(), Vec::new(), Vec::new());
    for (b, block) in spec.blocks.iter().enumerate() {
        let rows: Vec<usize> = block.iter().copied().filter(|d| !kept.contains(d)).collect();
        let p = pod(centred.select(Axis(0), &rows).view()).map_err(|e| format!("block {}: {e}", b + 1))?;
        let r = spec
            .modes
            .count_in_block(b, block.len(), p.energy.as_slice().expect("contiguous"))
            .map_err(|e| format!("block {}: {e}", b + 1))?;
        columns.push((rows, p.leading(r)));
        pods.push(p);
        block_modes.push(r);
    }
    let r: usize = block_modes.iter().sum();
    let mut v = Array2::zeros((n, r + kept.len()));
    let mut c0 = 0;
    for (rows, lead) in &columns {
        for (i, &d) in rows.iter().enumerate() {
            v.slice_mut(s![d, c0..c0 + lead.ncols()]).assign(&lead.row(i));
        }
        c0 += lead.ncols();
    }
    let mut basis = Basis {
        variant: spec.variant,
        snapshots: spec.snapshots,
        reference,
        modes: v,
        kept,
        multiplier_modes: None,
        multiplier_scale: spec.multiplier_scale,
        n_pod_modes: r,
        hyper: None,
    };
    basis.set_kept_columns();
    Ok(Trained { basis, pods, block_modes, reduced_dofs })
}

impl Basis {
    /// Writes the unit columns of the kept coordinates (the last `kept.len()` columns).
    fn set_kept_columns(&mut self) {
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
        let d = &x - &self.reference;
        let vtd = self.modes.t().dot(&d);
        match self.variant {
            Variant::WholeSystem => {
                use ndarray_linalg::Solve;
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

#[cfg(test)]
mod tests {
    use super::train_plain as train_basis;
    use super::*;

    /// Snapshots of a known 2-dimensional family: reconstruct∘reduce is the identity on the
    /// span (to round-off), the constraint-preserving basis has unit columns on the joint
    /// coordinates and its POD part is zero there, and its columns are orthonormal.
    #[test]
    fn reduce_then_reconstruct_is_identity_on_the_span() {
        let n = 6;
        let m = 5;
        let x = Array2::from_shape_fn((n, m), |(i, j)| {
            (i as f64 + 1.0) * (j as f64 * 0.3).sin() + (i * i) as f64 * (j as f64 * 0.7).cos()
        });
        let lam = Array2::zeros((0, m));
        let xref = x.column(0).to_owned();
        for (variant, joints) in [(Variant::Galerkin, vec![]), (Variant::ConstraintPreserving, vec![0, 3])] {
            let spec = BasisSpec {
                variant,
                snapshots: SnapshotKind::Reference,
                modes: ModeRule::Energy(1e-14),
                multiplier_scale: 1.0,
                blocks: vec![],
                stabilization: None,
            };
            let t = train_basis(x.view(), lam.view(), &joints, xref.view(), &spec).unwrap();
            let b = &t.basis;
            let gram = b.modes.t().dot(&b.modes);
            let eye = Array2::<f64>::eye(b.n_reduced());
            assert!((&gram - &eye).iter().all(|v| v.abs() < 1e-12), "{variant:?}: VᵀV = I");
            for j in 0..m {
                let back = b.reconstruct(b.reduce(x.column(j)).view());
                let err = (&back - &x.column(j)).iter().fold(0.0_f64, |a, v| a.max(v.abs()));
                assert!(err < 1e-10, "{variant:?}: column {j} error {err}");
            }
            for (k, &d) in b.kept.iter().enumerate() {
                assert_eq!(b.modes[[d, b.n_pod_modes + k]], 1.0);
                assert!(b.modes.slice(s![d, ..b.n_pod_modes]).iter().all(|v| *v == 0.0));
            }
        }
    }

    /// A block basis of two blocks (coordinates 0–4 and 5–9, joints 4 and 5 kept): each
    /// block's modes vanish outside its rows, the kept coordinates have their unit columns,
    /// the columns are orthonormal (blocks are disjoint), every snapshot is reproduced
    /// when the blocks keep all their modes (energy 1e-14), and counts that do not fit
    /// the blocks, or blocks that overlap, are refused.
    #[test]
    fn block_basis_keeps_each_block_to_its_rows() {
        let (n, m) = (10, 6);
        let x = Array2::from_shape_fn((n, m), |(i, j)| {
            ((i + 1) as f64 * 0.37 * (j + 1) as f64).sin() + 0.1 * i as f64 * j as f64
        });
        let lam = Array2::zeros((0, m));
        let xref = x.column(0).to_owned();
        let blocks = vec![(0..5).collect::<Vec<_>>(), (5..10).collect()];
        let spec = BasisSpec {
            variant: Variant::ConstraintPreserving,
            snapshots: SnapshotKind::Reference,
            modes: ModeRule::Energy(1e-14),
            multiplier_scale: 1.0,
            blocks: blocks.clone(),
            stabilization: None,
        };
        let t = train_basis(x.view(), lam.view(), &[4, 5], xref.view(), &spec).unwrap();
        let b = &t.basis;
        assert_eq!(t.pods.len(), 2);
        assert_eq!(t.block_modes.iter().sum::<usize>(), b.n_pod_modes);
        let gram = b.modes.t().dot(&b.modes);
        assert!((&gram - &Array2::<f64>::eye(b.n_reduced())).iter().all(|v| v.abs() < 1e-12), "VᵀV = I");
        let r1 = t.block_modes[0];
        assert!(b.modes.slice(s![5.., ..r1]).iter().all(|&v| v == 0.0), "block 1 modes on block 2 rows");
        assert!(b.modes.slice(s![..5, r1..b.n_pod_modes]).iter().all(|&v| v == 0.0), "block 2 modes on block 1 rows");
        assert!(b.modes.slice(s![4..6, ..b.n_pod_modes]).iter().all(|&v| v == 0.0), "modes on kept rows");
        assert_eq!((b.modes[[4, b.n_pod_modes]], b.modes[[5, b.n_pod_modes + 1]]), (1.0, 1.0));
        for j in 0..m {
            let back = b.reconstruct(b.reduce(x.column(j)).view());
            let err = (&back - &x.column(j)).iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            assert!(err < 1e-10, "column {j} error {err}");
        }
        let counts = BasisSpec { modes: ModeRule::Counts(vec![2, 3]), ..spec.clone() };
        assert_eq!(train_basis(x.view(), lam.view(), &[4, 5], xref.view(), &counts).unwrap().block_modes, vec![2, 3]);
        for (bad, needle) in [
            (BasisSpec { modes: ModeRule::Counts(vec![2]), ..spec.clone() }, "1 counts for 2 blocks"),
            (BasisSpec { blocks: vec![(0..6).collect(), (5..10).collect()], ..spec.clone() }, "in blocks 1 and 2"),
            (BasisSpec { blocks: vec![(0..5).collect()], ..spec.clone() }, "in no block"),
            (BasisSpec { blocks: vec![], ..counts.clone() }, "no blocks"),
        ] {
            let err = train_basis(x.view(), lam.view(), &[4, 5], xref.view(), &bad).err().expect("refused");
            assert!(err.contains(needle), "{err}");
        }
    }
}
