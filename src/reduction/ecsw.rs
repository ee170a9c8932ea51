//! Energy-conserving sampling and weighting (ECSW; Farhat, Avery, Chapman & Cortial 2014,
//! IJNME 98:625–662; Farhat, Chapman & Avery 2015, IJNME 102:1077–1110): pick a few
//! elements and positive weights so that, on the training snapshots, the weighted sum of
//! their reduced forces reproduces the sum over all elements:
//!
//! ```text
//!     c_{k,e} = Vₑᵀ f̂ₑ(x_ref,ₑ + Vₑ q_k)            (r entries per snapshot k),
//!     b = Σ_e c_{·,e},      min ‖C w − b‖₂, w ≥ 0,  stopped at ‖C w − b‖ ≤ τ ‖b‖,
//! ```
//!
//! (once the iterations cost as much as factoring `C`, solved in its triangular factor `R`:
//! `‖C w − b‖ = ‖R w − R 1‖` since `b = C 1`, `linalg::tall_qr`), with `q_k` the reduced coordinates of snapshot `k` (the training
//! trajectory as the basis sees it) and `f̂ₑ = fₑ − Lₑ xₑ` the part of the element force
//! that is not linear in the coordinates: the linear part (bending, damping), the mass and
//! the loads are projected exactly over every element and need no sampling. Positive weights keep each sampled
//! term a true element force, so the hyper-reduced model keeps the energy structure
//! (symmetric tangent, conservative internal forces).
//!
//! Where elements' stiffness is a parameter ([`stiffness_groups`]), each group `g` of
//! elements that share one gets rows of its own, `b_g = Σ_{e∈g} c_{·,e}`: the weighted sum
//! then reproduces each group's force apart, so that it stays right when the groups scale
//! differently at another μ (the model is affine in each group's factor). The tolerance
//! bounds the stacked residual: a group whose force is small against the others' is fitted
//! to the same absolute residual, so relatively more loosely, and that part scales with its
//! factor at μ (the error estimate sees it like any other).

use super::basis::Basis;
use super::sample::Hyper;
use crate::error::{Error, Result};
use crate::linalg::nnls::NnlsParams;
use crate::linalg::tall_qr::nnls_of_column_sum;
use crate::solver::model::{stiffness_groups, InvariantElementModel};
use ndarray::{Array2, ArrayView2, ShapeBuilder};

/// The ECSW training matrix `C` (n_groups·n_snapshots·r × n_elements) of the module
/// documentation: element `e`'s column holds its terms in the rows of its stiffness group
/// (one group, all rows, for a model without stiffness parameters).
pub fn training_matrix<M: InvariantElementModel>(full: &M, basis: &Basis, snapshots: ArrayView2<f64>) -> Array2<f64> {
    let (r, ns, n_el) = (basis.n_reduced(), snapshots.ncols(), full.n_elements());
    let groups = stiffness_groups(full);
    let mut group_of = vec![0; n_el];
    for (g, (_, members)) in groups.iter().enumerate() {
        members.iter().for_each(|&e| group_of[e] = g);
    }
    let ne = if n_el > 0 { full.element_dofs(0).len() } else { 0 };
    let v = basis.modes.as_standard_layout();
    // the snapshots as the basis represents them: x_ref + V q_k, all at once
    let mut q = Array2::zeros((r, ns));
    for k in 0..ns {
        q.column_mut(k).assign(&basis.reduce(snapshots.column(k)));
    }
    let x = v.dot(&q) + basis.reference.view().insert_axis(ndarray::Axis(1));
    // column-major: an element's terms fill its column, and the QR of `ecsw` reads it so
    let mut c = Array2::zeros((groups.len().max(1) * ns * r, n_el).f());
    let (mut xe, ve, mut fe, mut l, mut d) =
        (vec![0.0; ne], vec![0.0; ne], vec![0.0; ne], vec![0.0; ne * ne], vec![0.0; ne * ne]);
    for e in 0..n_el {
        let dofs = full.element_dofs(e);
        full.element_linear(e, &mut l, &mut d);
        let rows = group_of[e] * ns * r;
        for k in 0..ns {
            for (i, &dof) in dofs.iter().enumerate() {
                xe[i] = x[[dof, k]];
            }
            full.element_force(e, &xe, &ve, &mut fe);
            for j in 0..ne {
                for i in 0..ne {
                    fe[i] -= l[j * ne + i] * xe[j];
                }
            }
            for (i, &dof) in dofs.iter().enumerate() {
                for a in 0..r {
                    c[[rows + k * r + a, e]] += v[[dof, a]] * fe[i];
                }
            }
        }
    }
    c
}

/// Trains the sampled set on `snapshots` (n_dof × n_snapshots) with relative tolerance τ.
pub fn ecsw<M: InvariantElementModel>(
    full: &M,
    basis: &Basis,
    snapshots: ArrayView2<f64>,
    tolerance: f64,
) -> Result<Hyper> {
    if snapshots.ncols() == 0 {
        return Err(Error::usage("no training snapshots"));
    }
    // b = C 1 lies in C's range: once NNLS has taken as long as factoring C would, it goes
    // on in C's triangular factor R (n_elements², not rows × n_elements, per iteration)
    let c = training_matrix(full, basis, snapshots);
    let sol = nnls_of_column_sum(c, &NnlsParams { tolerance, max_iterations: full.n_elements().max(1) })?;
    let elements: Vec<usize> = (0..sol.x.len()).filter(|&e| sol.x[e] > 0.0).collect();
    let weights = elements.iter().map(|&e| sol.x[e]).collect();
    if elements.is_empty() {
        // b = 0: the snapshots never strain the elements; keep one so the model is defined
        return Ok(Hyper {
            elements: vec![0],
            weights: vec![1.0],
            tolerance,
            training_residual: 0.0,
            n_training: snapshots.ncols(),
        });
    }
    Ok(Hyper { elements, weights, tolerance, training_residual: sol.relative_residual, n_training: snapshots.ncols() })
}
