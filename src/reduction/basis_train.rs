//! Training of the plain variants' bases (galerkin, constraint-preserving, whole-system):
//! the POD of the snapshots, per block when the coordinates are split into blocks, and
//! the unit columns of the kept joint coordinates (`crate::reduction::train_basis`
//! dispatches the stabilized whole-system variant to `whole_system`).

use super::basis::{Basis, BasisSpec, SnapshotKind, Trained, Variant};
use super::pod::{pod, ModeRule};
use crate::error::{Error, Result};
use ndarray::{s, Array1, Array2, ArrayView1, ArrayView2, Axis};

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
) -> Result<Trained> {
    let (variant, multiplier_scale) = (spec.variant, spec.multiplier_scale);
    let n = x.nrows();
    if x.ncols() == 0 {
        return Err(Error::usage("the training set is empty (no snapshots)"));
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
        return Err(Error::usage("the stabilized variant is trained by reduction::train_basis"));
    }
    if !spec.blocks.is_empty() {
        return train_blocks(centred, reference, joint_dofs, reduced_dofs, spec);
    }
    if let ModeRule::Counts(_) = spec.modes {
        return Err(Error::usage(format!("{} gives one count per block, and the basis has no blocks", spec.modes)));
    }
    let rows = match variant {
        Variant::WholeSystem => {
            if !(multiplier_scale.is_finite() && multiplier_scale > 0.0) {
                return Err(Error::usage(format!("the multiplier scale must be positive, got {multiplier_scale}")));
            }
            ndarray::concatenate(Axis(0), &[centred.view(), (&lambda / multiplier_scale).view()])
                .map_err(|e| Error::numerical("POD", e.to_string()))?
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
        Variant::WholeSystemStabilized => {
            return Err(Error::usage("the stabilized variant is trained by whole_system"))
        }
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
    Ok(Trained { basis, pods: vec![p], block_modes: vec![r], output_modes: vec![0], reduced_dofs })
}

/// [`train_basis`] with blocks (galerkin or constraint-preserving).
fn train_blocks(
    centred: Array2<f64>,
    reference: Array1<f64>,
    joint_dofs: &[usize],
    reduced_dofs: Vec<usize>,
    spec: &BasisSpec,
) -> Result<Trained> {
    let n = centred.nrows();
    if matches!(spec.variant, Variant::WholeSystem | Variant::WholeSystemStabilized) {
        return Err(Error::usage("a basis with blocks needs the galerkin or the constraint-preserving variant"));
    }
    if let ModeRule::Counts(c) = &spec.modes {
        if c.len() != spec.blocks.len() {
            return Err(Error::usage(format!(
                "{} gives {} counts for {} blocks",
                spec.modes,
                c.len(),
                spec.blocks.len()
            )));
        }
    }
    let mut owner = vec![None; n];
    for (b, block) in spec.blocks.iter().enumerate() {
        for &d in block {
            match owner.get(d) {
                None => return Err(Error::usage(format!("block {} holds coordinate {d}, the model has {n}", b + 1))),
                Some(Some(o)) => {
                    return Err(Error::usage(format!("coordinate {d} is in blocks {} and {}", o + 1, b + 1)))
                }
                Some(None) => owner[d] = Some(b),
            }
        }
    }
    if let Some(d) = reduced_dofs.iter().find(|&&d| owner[d].is_none()) {
        return Err(Error::usage(format!("coordinate {d} is in no block")));
    }
    let kept = if spec.variant == Variant::ConstraintPreserving { joint_dofs.to_vec() } else { Vec::new() };
    let (mut pods, mut block_modes, mut columns) = (Vec::new(), Vec::new(), Vec::new());
    for (b, block) in spec.blocks.iter().enumerate() {
        let rows: Vec<usize> = block.iter().copied().filter(|d| !kept.contains(d)).collect();
        let p = pod(centred.select(Axis(0), &rows).view()).map_err(|e| e.context(format_args!("block {}", b + 1)))?;
        let r = spec
            .modes
            .count_in_block(b, block.len(), p.energy.as_slice().expect("contiguous"))
            .map_err(|e| e.context(format_args!("block {}", b + 1)))?;
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
    let output_modes = vec![0; block_modes.len()];
    Ok(Trained { basis, pods, block_modes, output_modes, reduced_dofs })
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
            let err = train_basis(x.view(), lam.view(), &[4, 5], xref.view(), &bad).err().expect("refused").to_string();
            assert!(err.contains(needle), "{err}");
        }
    }
}
