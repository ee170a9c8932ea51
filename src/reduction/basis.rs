//! The reduced basis and the map between full and reduced coordinates (pyMOR's
//! reductor vocabulary: `reduce` projects a full state, `reconstruct` maps back).
//!
//! ```text
//!     x ≈ x_ref + V q                         (V: n × r)
//!     galerkin:              V = Φ, the POD of all coordinates (thesis eqs. 11–12)
//!     constraint-preserving: V = blockdiag(Φ*, I) on (free, joint) coordinates (eqs. 20–21)
//!     whole-system:          [x; λ/w] ≈ [x_ref; 0] + [V; V_λ] q (eqs. 18–19)
//! ```

use super::ecsw::Hyper;
use super::pod::{pod, ModeRule, Pod};
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
}

impl Variant {
    pub fn name(&self) -> &'static str {
        match self {
            Variant::Galerkin => "galerkin",
            Variant::WholeSystem => "whole-system",
            Variant::ConstraintPreserving => "constraint-preserving",
        }
    }

    pub fn parse(s: &str) -> Option<Variant> {
        [Variant::Galerkin, Variant::WholeSystem, Variant::ConstraintPreserving].into_iter().find(|v| v.name() == s)
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

/// The POD and the basis built from it.
pub struct Trained {
    pub basis: Basis,
    /// the decomposition the modes come from (of the rows the variant reduces)
    pub pod: Pod,
    /// the dofs whose snapshot rows entered the POD
    pub reduced_dofs: Vec<usize>,
}

/// Builds a basis from snapshots `x` (n × m) and, for whole-system, multipliers `λ`
/// (n_c × m). `joint_dofs` are the coordinates that appear in a joint; `x_ref` is used
/// when `kind` is `Reference`.
pub fn train_basis(
    x: ArrayView2<f64>,
    lambda: ArrayView2<f64>,
    joint_dofs: &[usize],
    x_ref: ArrayView1<f64>,
    variant: Variant,
    kind: SnapshotKind,
    rule: ModeRule,
    multiplier_scale: f64,
) -> Result<Trained, String> {
    let n = x.nrows();
    if x.ncols() == 0 {
        return Err("the training set is empty (no snapshots)".into());
    }
    let reference = match kind {
        SnapshotKind::Raw => Array1::zeros(n),
        SnapshotKind::Reference => x_ref.to_owned(),
    };
    let centred = &x - &reference.view().insert_axis(Axis(1));
    let reduced_dofs: Vec<usize> = match variant {
        Variant::ConstraintPreserving => (0..n).filter(|d| !joint_dofs.contains(d)).collect(),
        _ => (0..n).collect(),
    };
    let rows = match variant {
        Variant::WholeSystem => {
            if !(multiplier_scale.is_finite() && multiplier_scale > 0.0) {
                return Err(format!("the multiplier scale must be positive, got {multiplier_scale}"));
            }
            ndarray::concatenate(Axis(0), &[centred.view(), (&lambda / multiplier_scale).view()]).map_err(|e| e.to_string())?
        }
        _ => centred.select(Axis(0), &reduced_dofs),
    };
    let p = pod(rows.view())?;
    let r = rule.count(n, p.energy.as_slice().expect("contiguous"))?;
    let lead = p.leading(r);
    let (modes, kept, multiplier_modes) = match variant {
        Variant::Galerkin => (lead, Vec::new(), None),
        Variant::WholeSystem => (lead.slice(s![..n, ..]).to_owned(), Vec::new(), Some(lead.slice(s![n.., ..]).to_owned())),
        Variant::ConstraintPreserving => {
            let kept: Vec<usize> = joint_dofs.to_vec();
            let mut v = Array2::zeros((n, r + kept.len()));
            for (i, &d) in reduced_dofs.iter().enumerate() {
                v.slice_mut(s![d, ..r]).assign(&lead.row(i));
            }
            for (k, &d) in kept.iter().enumerate() {
                v[[d, r + k]] = 1.0;
            }
            (v, kept, None)
        }
    };
    let basis = Basis { variant, snapshots: kind, reference, modes, kept, multiplier_modes, multiplier_scale, n_pod_modes: r, hyper: None };
    Ok(Trained { basis, pod: p, reduced_dofs })
}

impl Basis {
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
            return bad("basis/reference", format!("has {} entries, the model has {n_dof} coordinates", self.reference.len()));
        }
        if self.modes.iter().chain(self.reference.iter()).any(|x| !x.is_finite()) {
            return bad("basis/modes", "holds non-finite values".into());
        }
        if self.n_pod_modes + self.kept.len() != self.modes.ncols() {
            return bad("basis/kept_dofs", format!("{} POD modes and {} kept coordinates do not make {} columns", self.n_pod_modes, self.kept.len(), self.modes.ncols()));
        }
        if let Some(&d) = self.kept.iter().find(|&&d| d >= n_dof) {
            return bad("basis/kept_dofs", format!("coordinate {d} does not exist (the model has {n_dof})"));
        }
        match (&self.multiplier_modes, self.variant) {
            (Some(vl), Variant::WholeSystem) if vl.dim() == (n_constraints, self.modes.ncols()) => Ok(()),
            (Some(vl), Variant::WholeSystem) => bad("basis/multiplier_modes", format!("is {:?}, expected ({n_constraints}, {})", vl.dim(), self.modes.ncols())),
            (None, Variant::WholeSystem) => bad("basis/multiplier_modes", "is missing (whole-system variant)".into()),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Snapshots of a known 2-dimensional family: reconstruct∘reduce is the identity on the
    /// span (to round-off), the constraint-preserving basis has unit columns on the joint
    /// coordinates and its POD part is zero there, and its columns are orthonormal.
    #[test]
    fn reduce_then_reconstruct_is_identity_on_the_span() {
        let n = 6;
        let m = 5;
        let x = Array2::from_shape_fn((n, m), |(i, j)| (i as f64 + 1.0) * (j as f64 * 0.3).sin() + (i * i) as f64 * (j as f64 * 0.7).cos());
        let lam = Array2::zeros((0, m));
        let xref = x.column(0).to_owned();
        for (variant, joints) in [(Variant::Galerkin, vec![]), (Variant::ConstraintPreserving, vec![0, 3])] {
            let t = train_basis(x.view(), lam.view(), &joints, xref.view(), variant, SnapshotKind::Reference, ModeRule::Energy(1e-14), 1.0).unwrap();
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
}
