//! The checks of a stored basis that need no model ([`check_content`]): finite values,
//! orthonormal modes (per block named in the message), a non-increasing spectrum, energies
//! in [0, 1], kept coordinates with their unit columns, a consistent ECSW set.

use super::basis_file::StoredBasis;
use crate::reduction::{Basis, Variant};
use ndarray::{s, Array2};

/// ‖VᵀV − I‖_max allowed: LAPACK's SVD gives orthonormal columns to ~1e-14; 1e-8 leaves
/// room for any honest round-off and refuses edited modes.
pub const ORTHONORMALITY_TOLERANCE: f64 = 1e-8;
/// Smallest ECSW weight accepted. A sampled element of weight w stands for w copies of
/// itself; ECSW's NNLS keeps an element only when it matters (trained weights are O(0.1–10)),
/// so 1e-8 and below is an edited or corrupted file.
pub const MIN_WEIGHT: f64 = 1e-8;

/// What a check finds wrong: `Err((dataset, problem))`.
type Found = std::result::Result<(), (String, String)>;

fn bad(dataset: &str, problem: String) -> Found {
    Err((dataset.to_string(), problem))
}

/// The first entry that is not finite, with its index in iteration order.
fn first_non_finite<'a>(values: impl Iterator<Item = &'a f64>) -> Option<(usize, f64)> {
    values.enumerate().find(|(_, v)| !v.is_finite()).map(|(i, v)| (i, *v))
}

/// Checks that need no model: values, orthonormality, the spectrum, the ECSW set's own
/// consistency, in that order (the first problem found is the one reported).
/// `Err((dataset, problem))`.
pub fn check_content(s: &StoredBasis) -> Found {
    let b = &s.basis;
    check_finite(b)?;
    check_multiplier_modes(b)?;
    check_column_counts(b)?;
    check_spectrum(s)?;
    check_kept_columns(b)?;
    check_orthonormal(s)?;
    check_hyper(s)
}

/// Every entry of the modes and the reference finite.
fn check_finite(b: &Basis) -> Found {
    if let Some((i, v)) = first_non_finite(b.modes.iter()) {
        return bad(
            "basis/modes",
            format!(
                "entry ({}, {}) is {v}; every entry must be finite",
                i / b.modes.ncols().max(1),
                i % b.modes.ncols().max(1)
            ),
        );
    }
    if let Some((i, v)) = first_non_finite(b.reference.iter()) {
        return bad("basis/reference", format!("entry {i} is {v}; every entry must be finite"));
    }
    Ok(())
}

/// The multiplier modes: finite; whole-system-stabilized's supremizers orthonormal and of a
/// count that fits; whole-system's as many columns as the modes.
fn check_multiplier_modes(b: &Basis) -> Found {
    if let Some(vl) = &b.multiplier_modes {
        if let Some((i, v)) = first_non_finite(vl.iter()) {
            return bad("basis/multiplier_modes", format!("entry {i} is {v}; every entry must be finite"));
        }
        if b.variant == Variant::WholeSystemStabilized {
            if vl.ncols() == 0 || vl.ncols() > vl.nrows() || b.n_pod_modes + vl.ncols() != b.modes.ncols() {
                return bad(
                    "basis/multiplier_modes",
                    format!(
                        "has {} columns; whole-system-stabilized needs 1 ≤ k ≤ {} and n_pod_modes ({}) + k = {} columns of basis/modes",
                        vl.ncols(),
                        vl.nrows(),
                        b.n_pod_modes,
                        b.modes.ncols()
                    ),
                );
            }
            let (worst, (i, j)) = max_off_identity(&vl.t().dot(vl));
            if !(worst <= ORTHONORMALITY_TOLERANCE) {
                return bad(
                    "basis/multiplier_modes",
                    format!("are not orthonormal: ΨᵀΨ − I is {worst:.3e} at columns ({i}, {j}); the limit is {ORTHONORMALITY_TOLERANCE:e}"),
                );
            }
        } else if vl.ncols() != b.modes.ncols() {
            return bad(
                "basis/multiplier_modes",
                format!("has {} columns, basis/modes has {}", vl.ncols(), b.modes.ncols()),
            );
        }
    }
    Ok(())
}

/// The multiplier scale, and the columns of the modes: at least one, as many as the POD modes,
/// supremizers and kept coordinates together.
fn check_column_counts(b: &Basis) -> Found {
    if b.variant == Variant::WholeSystem && !(b.multiplier_scale.is_finite() && b.multiplier_scale > 0.0) {
        return bad("multiplier_scale", format!("is {}; it must be positive and finite", b.multiplier_scale));
    }
    if b.modes.ncols() == 0 {
        return bad("basis/modes", "has no columns (r = 0)".into());
    }
    // whole-system-stabilized: its k supremizer columns follow the POD modes (checked above)
    let supremizers = match (&b.multiplier_modes, b.variant) {
        (Some(psi), Variant::WholeSystemStabilized) => psi.ncols(),
        _ => 0,
    };
    if b.n_pod_modes + supremizers + b.kept.len() != b.modes.ncols() {
        return bad(
            "basis/kept_dofs",
            format!(
                "{} POD modes and {} kept coordinates do not make the {} columns of basis/modes",
                b.n_pod_modes,
                b.kept.len(),
                b.modes.ncols()
            ),
        );
    }
    Ok(())
}

/// Singular values finite, non-negative and non-increasing within each block; energies one
/// per singular value, in [0, 1].
fn check_spectrum(s: &StoredBasis) -> Found {
    // singular values: finite, non-negative, non-increasing within each block
    let mut at = 0;
    for (blk, &k) in s.block_values.iter().enumerate() {
        let sv = s.singular_values.slice(s![at..at + k]);
        if let Some((i, v)) = sv.iter().enumerate().find(|(_, v)| !(v.is_finite() && **v >= 0.0)) {
            return bad(
                "basis/singular_values",
                format!("entry {} is {v}; singular values are finite and non-negative", at + i),
            );
        }
        if let Some(i) = (1..k).find(|&i| sv[i] > sv[i - 1] * (1.0 + 1e-12)) {
            return bad(
                "basis/singular_values",
                format!(
                    "increase at entry {} (block {}): {} after {}; a POD's singular values never increase",
                    at + i,
                    blk + 1,
                    sv[i],
                    sv[i - 1]
                ),
            );
        }
        at += k;
    }
    if s.energy.len() != s.singular_values.len() {
        return bad(
            "basis/energy",
            format!("has {} entries, basis/singular_values has {}", s.energy.len(), s.singular_values.len()),
        );
    }
    if let Some((i, v)) =
        s.energy.iter().enumerate().find(|(_, v)| !(v.is_finite() && (-1e-12..=1.0 + 1e-12).contains(*v)))
    {
        return bad("basis/energy", format!("entry {i} is {v}; captured energy fractions lie in [0, 1]"));
    }
    Ok(())
}

/// Each kept coordinate exists and has its unit column.
fn check_kept_columns(b: &Basis) -> Found {
    // the kept coordinates' unit columns
    for (k, &d) in b.kept.iter().enumerate() {
        if d >= b.modes.nrows() {
            return bad(
                "basis/kept_dofs",
                format!("coordinate {d} does not exist (basis/modes has {} rows)", b.modes.nrows()),
            );
        }
        let c = b.n_pod_modes + k;
        if (b.modes[[d, c]] - 1.0).abs() > ORTHONORMALITY_TOLERANCE {
            return bad(
                "basis/modes",
                format!(
                    "column {c} must be the unit column of kept coordinate {d}, but holds {} there",
                    b.modes[[d, c]]
                ),
            );
        }
    }
    Ok(())
}

/// VᵀV = I (whole-system: the stacked [V; V_λ]), the worst entry named with its block.
fn check_orthonormal(s: &StoredBasis) -> Found {
    let b = &s.basis;
    let mut gram = b.modes.t().dot(&b.modes);
    if let (Variant::WholeSystem, Some(vl)) = (b.variant, &b.multiplier_modes) {
        gram += &vl.t().dot(vl);
    }
    let (worst, (i, j)) = max_off_identity(&gram);
    if !(worst <= ORTHONORMALITY_TOLERANCE) {
        let name = if b.variant == Variant::WholeSystem { "[V; V_λ]ᵀ[V; V_λ]" } else { "VᵀV" };
        let dataset =
            if b.variant == Variant::WholeSystem { "basis/modes, basis/multiplier_modes" } else { "basis/modes" };
        return bad(dataset, format!("are not orthonormal: {name} − I is {:.3e} at columns ({i}, {j}) ({}); the limit is {ORTHONORMALITY_TOLERANCE:e}", gram[[i, j]] - if i == j { 1.0 } else { 0.0 }, block_of(s, i, j)));
    }
    Ok(())
}

/// The ECSW set: its own consistency, trained weights, a finite non-negative residual.
fn check_hyper(s: &StoredBasis) -> Found {
    if let Some(h) = &s.basis.hyper {
        h.validate(usize::MAX)?;
        if let Some((k, w)) = h.weights.iter().enumerate().find(|(_, w)| **w < MIN_WEIGHT) {
            return bad(
                "hyper/weights",
                format!("entry {k} is {w:e}; ECSW weights below {MIN_WEIGHT:e} are not trained ones"),
            );
        }
        if !(h.training_residual.is_finite() && h.training_residual >= 0.0) {
            return bad(
                "hyper/training_residual",
                format!("is {}; it must be finite and non-negative", h.training_residual),
            );
        }
    }
    Ok(())
}

/// The largest |G − I| entry and where it is (NaN counts as largest).
fn max_off_identity(g: &Array2<f64>) -> (f64, (usize, usize)) {
    let mut worst = (0.0, (0, 0));
    for ((i, j), v) in g.indexed_iter() {
        let d = (v - if i == j { 1.0 } else { 0.0 }).abs();
        if d.is_nan() {
            return (f64::NAN, (i, j));
        }
        if d > worst.0 {
            worst = (d, (i, j));
        }
    }
    worst
}

/// Names the block(s) of columns `i` and `j` of a block basis for a message.
fn block_of(s: &StoredBasis, i: usize, j: usize) -> String {
    let which = |c: usize| -> String {
        let mut at = 0;
        for (b, &k) in s.block_modes.iter().enumerate() {
            if c < at + k {
                return if s.block_modes.len() == 1 { "POD".into() } else { format!("block {}", b + 1) };
            }
            at += k;
        }
        "kept coordinates".into()
    };
    let (a, b) = (which(i), which(j));
    if a == b {
        a
    } else {
        format!("{a} and {b}")
    }
}
