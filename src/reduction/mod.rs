//! Model reduction by POD (SPEC §3) and hyper-reduction by ECSW, knowing nothing of beams:
//! it sees the physics only through [`crate::solver::model::ElementModel`] and
//! [`crate::solver::model::InvariantElementModel`].
//!
//! `pod` (modes and singular values) → [`train_basis`] (`basis_train` for the plain
//! variants, `whole_system` for the stabilized one) → `basis` (the reductor: `reduce`,
//! `reconstruct`) → `reduced_model` (Galerkin over every element) or `ecsw` (a weighted
//! element sample, by `crate::linalg::nnls`) → `hyper_model` (the sampled model); both
//! reduced models are [`crate::solver::model::ParametricModel`]s and [`Reduced`], and share
//! `projection`: they keep the projected constant forces unscaled and take the load scale
//! in each evaluation, so one reduced model runs at any parameters without being projected
//! again. `estimator` holds the error estimator's data (the enriched basis and its
//! calibration) that the basis file stores beside the basis.

pub mod basis;
mod basis_train;
mod damping;
pub mod ecsw;
pub mod estimator;
pub mod hyper_model;
pub(crate) mod joint_elimination;
pub mod output_modes;
pub mod pod;
pub(crate) mod projection;
pub mod reduced;
pub mod reduced_model;
pub mod sample;
pub mod whole_system;

use crate::error::{Error, Result};
pub use basis::{Basis, BasisSpec, SnapshotKind, Stabilization, Trained, Variant};
pub use ecsw::ecsw;
pub use hyper_model::HyperReducedModel;
pub use pod::{pod, ModeRule, Pod};
pub use reduced::Reduced;
pub use reduced_model::ReducedModel;
pub use sample::Hyper;

/// Builds a basis from snapshots `x` (n × m) and multipliers `λ` (n_c × m), for every
/// variant: the stabilized whole-system one by [`whole_system`], the others by
/// [`basis`] (so that `basis` need not know `whole_system`, which builds on it).
pub fn train_basis(
    x: ndarray::ArrayView2<f64>,
    lambda: ndarray::ArrayView2<f64>,
    joint_dofs: &[usize],
    x_ref: ndarray::ArrayView1<f64>,
    spec: &BasisSpec,
) -> Result<Trained> {
    if spec.variant != Variant::WholeSystemStabilized {
        return basis_train::train_plain(x, lambda, joint_dofs, x_ref, spec);
    }
    if !spec.blocks.is_empty() {
        return Err(Error::usage("a basis with blocks needs the galerkin or the constraint-preserving variant"));
    }
    if x.ncols() == 0 {
        return Err(Error::usage("the training set is empty (no snapshots)"));
    }
    let reference = match spec.snapshots {
        SnapshotKind::Raw => ndarray::Array1::zeros(x.nrows()),
        SnapshotKind::Reference => x_ref.to_owned(),
    };
    let centred = &x - &reference.view().insert_axis(ndarray::Axis(1));
    whole_system::train_stabilized(centred, lambda, reference, spec)
}
