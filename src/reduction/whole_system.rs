//! The stabilized whole-system reduction: coordinates *and* multipliers reduced, each by a
//! POD of its own, with the coordinate basis enriched by supremizers so that the reduced
//! saddle point is inf-sup stable (the fix used for reduced Stokes/Navier–Stokes problems,
//! Rozza & Veroy 2007, Ballarin et al. 2015). docs/whole-system.md has the measurements.
//!
//! ```text
//!     x ≈ x_ref + V q,   V = [Φ, S]   (n × (r + k), orthonormal columns)
//!     λ ≈ Ψ μ,           Ψ            (n_c × k, orthonormal: POD of the multiplier snapshots)
//!     S = orth((I − ΦΦᵀ) Bᵀ Ψ)        the supremizers of the k multiplier modes
//!
//!     Vᵀ (M ẍ + f(x, ẋ) − g) + (Ψᵀ B V)ᵀ μ = 0,     Ψᵀ (B x − b) = 0        (k equations)
//! ```
//!
//! Why the plain variant (one POD of `[x; λ/w]`, eqs. 18–19) fails: every snapshot
//! satisfies `B x_j = b`, so the coordinate part `V` of any POD mode satisfies
//! `B V = B X W Σ⁻¹ = 0` for reference snapshots (rank one, along `b`, for raw ones). The
//! projected coupling `V_λᵀ B V` — the reduced constraint block — vanishes: no mode can
//! feel a multiplier, the inf-sup constant `β = σ_min(V_λᵀ B V)` is zero, and the modes
//! that carry mostly `λ` have neither mass nor stiffness in `x`: the reduced Newton matrix
//! is singular. The supremizers are the columns that make `Ψᵀ B V` full rank: with `Φ`
//! orthogonal to them, `Ψᵀ B S` is the Gram-like k × k matrix `Ψᵀ B Bᵀ Ψ` restricted to
//! what `Φ` does not already hold, nonsingular because `Bᵀ` is injective (independent
//! joint equations). The reduced multipliers `μ` are then the integrator's Lagrange
//! multipliers (`k` of them instead of `n_c`), and `Ψ μ` gives physical ones back.

pub use super::basis::Stabilization;
use super::basis::{Basis, BasisSpec, Trained};
use super::pod::{pod, ModeRule};
use crate::error::{Error, Result};
use ndarray::{s, Array1, Array2, ArrayView2};

/// Default multiplier mode rule: all modes above 1e-12 of the energy (the multiplier
/// snapshots of a mechanism span few directions; keeping them costs `2k` unknowns).
pub const DEFAULT_MULTIPLIER_MODES: ModeRule = ModeRule::Energy(1e-12);

/// `B` of constraint rows given as `(dof, coefficient)` terms.
pub fn constraint_matrix(n: usize, rows: &[Vec<(usize, f64)>]) -> Array2<f64> {
    let mut b = Array2::zeros((rows.len(), n));
    for (c, terms) in rows.iter().enumerate() {
        for &(d, v) in terms {
            b[[c, d]] += v;
        }
    }
    b
}

/// Orthonormalizes the columns of `a` against the orthonormal `q` and each other
/// (modified Gram–Schmidt, two passes for round-off); `Err(j)` when column `j` lies
/// (to 1e-10 of its length) in the span of what precedes it.
pub fn orthonormalize_against(q: &Array2<f64>, a: &Array2<f64>) -> std::result::Result<Array2<f64>, usize> {
    let mut out = Array2::<f64>::zeros(a.dim());
    for j in 0..a.ncols() {
        let mut v = a.column(j).to_owned();
        let norm0 = v.dot(&v).sqrt();
        for _ in 0..2 {
            for i in 0..q.ncols() {
                let c = q.column(i).dot(&v);
                v.scaled_add(-c, &q.column(i));
            }
            for i in 0..j {
                let c = out.column(i).dot(&v);
                v.scaled_add(-c, &out.column(i));
            }
        }
        let norm = v.dot(&v).sqrt();
        if !(norm > 1e-10 * norm0 && norm > 0.0) {
            return Err(j);
        }
        out.column_mut(j).assign(&(v / norm));
    }
    Ok(out)
}

/// [`super::train_basis`] for [`super::Variant::WholeSystemStabilized`]: `centred` are the
/// coordinate snapshots minus `reference`, `lambda` the multiplier snapshots.
pub(crate) fn train_stabilized(
    centred: Array2<f64>,
    lambda: ArrayView2<f64>,
    reference: Array1<f64>,
    spec: &BasisSpec,
) -> Result<Trained> {
    let n = centred.nrows();
    let stab = spec.stabilization.as_ref().ok_or_else(|| {
        Error::usage("the whole-system-stabilized variant needs the joint equations B (none were given)")
    })?;
    let b = &stab.constraints;
    let nc = b.nrows();
    if nc == 0 {
        return Err(Error::usage(
            "the model has no joints: the whole-system-stabilized variant has no multipliers to reduce; use galerkin",
        ));
    }
    if b.ncols() != n || lambda.nrows() != nc || lambda.ncols() != centred.ncols() {
        return Err(Error::usage(format!(
            "B is {:?}, the snapshots are {:?} and the multiplier snapshots {:?}: they do not fit",
            b.dim(),
            centred.dim(),
            lambda.dim()
        )));
    }
    if let ModeRule::Counts(_) = spec.modes {
        return Err(Error::usage(format!("{} gives one count per block, and the basis has no blocks", spec.modes)));
    }
    let p = pod(centred.view())?;
    let r = spec.modes.count(n, p.energy.as_slice().expect("contiguous"))?;
    if lambda.iter().all(|&v| v == 0.0) {
        return Err(Error::usage(
            "the multiplier snapshots are all zero (the joints carry no load): nothing to reduce",
        ));
    }
    let pl = pod(lambda).map_err(|e| e.context("multiplier POD"))?;
    let k = stab
        .multiplier_modes
        .count(nc, pl.energy.as_slice().expect("contiguous"))
        .map_err(|e| e.context("reduction.multiplier_modes"))?;
    let phi = p.leading(r);
    let psi = pl.leading(k);
    let supremizers = orthonormalize_against(&phi, &b.t().dot(&psi)).map_err(|j| {
        Error::usage(format!(
            "supremizer {} (Bᵀ of multiplier mode {}) lies in the span of the coordinate modes",
            j + 1,
            j + 1
        ))
    })?;
    let mut modes = Array2::zeros((n, r + k));
    modes.slice_mut(s![.., ..r]).assign(&phi);
    modes.slice_mut(s![.., r..]).assign(&supremizers);
    let basis = Basis {
        variant: spec.variant,
        snapshots: spec.snapshots,
        reference,
        modes,
        kept: Vec::new(),
        multiplier_modes: Some(psi),
        multiplier_scale: 1.0,
        n_pod_modes: r,
        hyper: None,
    };
    Ok(Trained { basis, pods: vec![p], block_modes: vec![r], output_modes: vec![0], reduced_dofs: (0..n).collect() })
}

/// A failed Newton solve (or singular matrix) of the plain whole-system variant, with the
/// reason and the way out in the message; other errors and variants pass unchanged.
pub fn explain_failure(
    e: crate::error::Error,
    variant: super::Variant,
    mu: &crate::solver::parameters::Parameters,
) -> crate::error::Error {
    use crate::error::Error;
    match e {
        Error::NewtonFailed { .. } | Error::LinearSolve { .. } if variant == super::Variant::WholeSystem => {
            Error::Stage {
                stage:
                    "reduced run of the plain whole-system variant (its reduced saddle point is not inf-sup stable: \
                    B V = 0 for POD modes of constraint-satisfying snapshots, docs/whole-system.md; \
                    use variant = \"whole-system-stabilized\")"
                        .into(),
                parameters: mu.to_string(),
                source: Box::new(e),
            }
        }
        other => other,
    }
}

/// The inf-sup constant of the reduced saddle point, `β = σ_min(Ψᵀ B V) / (‖Ψ‖ ‖V‖)` with
/// orthonormal `Ψ`, `V` (the reduced constraint block's smallest singular value): zero
/// means some reduced multiplier acts on nothing and the reduced Newton matrix is singular.
pub fn inf_sup(b: &Array2<f64>, psi: &Array2<f64>, v: &Array2<f64>) -> f64 {
    use crate::linalg::lapack::SVD;
    let c = psi.t().dot(&b.dot(v));
    if c.is_empty() {
        return 0.0;
    }
    match c.svd(false, false) {
        Ok((_, s, _)) => s.iter().copied().fold(f64::INFINITY, f64::min),
        Err(_) => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reduction::{train_basis, SnapshotKind, Variant};

    /// Snapshots of a two-coordinate-pair "pin" `x₀ − x₂ = 0` in a 5-dof family: the POD
    /// modes have `B Φ = 0` (β = 0), the supremizer makes β > 0, `V` is orthonormal, and
    /// `reduce∘reconstruct` is the identity on the snapshots.
    #[test]
    fn supremizers_restore_inf_sup() {
        let (n, m) = (5, 7);
        let x = Array2::from_shape_fn((n, m), |(i, j)| {
            let t = j as f64 * 0.4;
            match i {
                0 | 2 => t.sin(),
                1 => t.cos() + 0.1 * t,
                3 => (2.0 * t).sin(),
                _ => t * t,
            }
        });
        let lam = Array2::from_shape_fn((1, m), |(_, j)| 3.0 + (j as f64).cos());
        let b = constraint_matrix(n, &[vec![(0, 1.0), (2, -1.0)]]);
        let spec = BasisSpec {
            variant: Variant::WholeSystemStabilized,
            snapshots: SnapshotKind::Reference,
            modes: ModeRule::Energy(1e-14),
            multiplier_scale: 1.0,
            blocks: vec![],
            stabilization: Some(Stabilization { constraints: b.clone(), multiplier_modes: ModeRule::Count(1) }),
        };
        let x0 = x.column(0).to_owned();
        let t = train_basis(x.view(), lam.view(), &[0, 2], x0.view(), &spec).unwrap();
        let v = &t.basis.modes;
        let r = t.basis.n_pod_modes;
        let psi = t.basis.multiplier_modes.as_ref().unwrap();
        assert_eq!(v.ncols(), r + 1);
        assert!(inf_sup(&b, psi, &v.slice(s![.., ..r]).to_owned()) < 1e-12, "POD modes alone: β = 0");
        assert!(inf_sup(&b, psi, v) > 0.5, "with the supremizer: β = {}", inf_sup(&b, psi, v));
        let gram = v.t().dot(v);
        assert!((&gram - &Array2::<f64>::eye(r + 1)).iter().all(|g| g.abs() < 1e-12));
        for j in 0..m {
            let back = t.basis.reconstruct(t.basis.reduce(x.column(j)).view());
            assert!((&back - &x.column(j)).iter().all(|e| e.abs() < 1e-10));
        }
        let none = BasisSpec { stabilization: None, ..spec.clone() };
        assert!(train_basis(x.view(), lam.view(), &[0, 2], x0.view(), &none)
            .err()
            .expect("refused")
            .to_string()
            .contains("joint equations"));
    }
}
