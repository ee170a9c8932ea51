//! The one place where a basis file is checked before a reduced model is built from it.
//! Every command that reads a basis (`online`, `validate`, `sweep`, `run`) goes through
//! [`check`]; it refuses, with the file and the dataset or attribute named:
//!
//! - links other than hard links (soft, external, user-defined), datasets stored in
//!   external files or as virtual datasets: a basis is one self-contained file
//!   ([`check_file`], before anything is read);
//! - datasets of the wrong type: integer or single-precision modes, floating-point indices
//!   ([`check_file`]);
//! - shapes that do not fit each other or the model, non-finite values;
//! - modes that are not orthonormal, ‖VᵀV − I‖_max ≤ [`ORTHONORMALITY_TOLERANCE`]
//!   (whole-system: the stacked `[V; V_λ]`, whose columns the POD made orthonormal), with
//!   the block named for a block basis; kept coordinates without their unit column;
//! - singular values that are negative or increase within a block, energies outside [0, 1];
//! - a reference state `x_ref` that is not the model's: zero for raw snapshots, the model's
//!   consistent initial state `x₀` otherwise, ‖x_ref − x₀‖_∞ ≤ [`REFERENCE_TOLERANCE`] ·
//!   max(1, ‖x₀‖_∞) (training takes `x_ref` from the first column of a full run, which is
//!   `x₀` itself);
//! - ECSW element indices out of range or repeated, weights outside
//!   [[`MIN_WEIGHT`], [`MAX_WEIGHT_PER_ELEMENT`] · n_elements];
//! - a basis trained on another model (`model_fingerprint`), and a file whose content does
//!   not hash to its `content_hash` (SHA-256 over the modes, reference, singular values,
//!   energies, kept and reduced coordinates, ECSW set, variant, settings and the model
//!   fingerprint): an edited basis, or a fingerprint copied from another basis, fails.
//!
//! A basis trained with other `[train]`/`[reduction]` settings than the pipeline has now
//! (`settings_hash`) is still used, with a one-line warning on stderr.

pub use super::basis_content::{check_content, MIN_WEIGHT, ORTHONORMALITY_TOLERANCE};
use super::basis_file::{open_basis, read_core, read_rest, StoredBasis};
pub use super::basis_hash::{content_hash, settings_hash, HashInput};
pub use super::basis_layout::check_file;
use crate::error::{Error, Result, Text};
use crate::model::Model;
use crate::reduction::{SnapshotKind, Variant};
use crate::solver::model::ParametricModel;
use std::path::Path;

/// ‖x_ref − x₀‖_∞ allowed, relative to max(1, ‖x₀‖_∞).
pub const REFERENCE_TOLERANCE: f64 = 1e-9;
/// Smallest inf-sup constant `σ_min(Ψᵀ B V)` accepted for a whole-system-stabilized basis:
/// trained ones are O(0.1–1) (B has unit entries, Ψ and V orthonormal, and the supremizers
/// are `Bᵀ Ψ` orthonormalized), a basis without supremizers has ~1e-15.
pub const INF_SUP_MIN: f64 = 1e-6;
/// Largest ECSW weight accepted, per element of the model: the weights sum to about the
/// number of elements, so a single weight above 1e4 × that is not a trained one.
pub const MAX_WEIGHT_PER_ELEMENT: f64 = 1e4;

/// Reads the basis at `path` whole (its estimator and training record too, with one open)
/// and checks it against `model`; `settings_hash` is the pipeline's [`settings_hash`] (a
/// mismatch only warns). The only way commands read a basis.
pub fn check(path: &Path, model: &Model, settings_hash: Option<&str>) -> Result<StoredBasis> {
    check_open(&open_basis(path)?, path, model, settings_hash)
}

/// [`check`] on the basis file `f`, already open (at `path`, for messages).
pub fn check_open(f: &hdf5::File, path: &Path, model: &Model, settings_hash: Option<&str>) -> Result<StoredBasis> {
    let bad = |field: &str, problem: String| Error::input(path, field, problem);
    // sizes before anything is read: a crafted shape must not make us allocate terabytes
    // (after the link walk: opening a dataset follows its link)
    let ours = |f: &hdf5::File| {
        f.attr("schema_version")
            .and_then(|a| a.read_scalar::<u64>())
            .is_ok_and(|v| v == super::basis_file::SCHEMA_VERSION)
    };
    if ours(f) {
        check_file(f, path)?;
        let sys = &*model.physics()?.sys;
        let (n, nc, ne) = (sys.n_dof(), sys.n_constraints(), sys.n_elements());
        let (cols, values) = (n + nc, n + nc);
        let limits: [(&str, &[usize]); 16] = [
            ("basis/modes", &[n, cols]),
            ("basis/reference", &[n]),
            ("basis/multiplier_modes", &[nc, cols]),
            ("basis/singular_values", &[values]),
            ("basis/energy", &[values]),
            ("basis/block_modes", &[values]),
            ("basis/block_values", &[values]),
            ("basis/reduced_dofs", &[n]),
            ("basis/kept_dofs", &[n]),
            ("hyper/elements", &[ne]),
            ("hyper/weights", &[ne]),
            ("estimator/modes", &[n, cols]),
            ("estimator/multiplier_modes", &[nc, cols]),
            ("estimator/block_modes", &[values]),
            ("estimator/hyper/elements", &[ne]),
            ("estimator/hyper/weights", &[ne]),
        ];
        for (name, max) in limits {
            let Ok(d) = f.dataset(name) else { continue };
            let shape = d.shape();
            if shape.len() != max.len() || shape.iter().zip(max).any(|(s, m)| s > m) {
                let model = format!("for this model ({n} coordinates, {nc} constraints, {ne} elements)");
                return Err(bad(
                    name,
                    match (shape.as_slice(), max) {
                        ([len], [m]) => format!("has {len} entries; {model} it holds at most {m}"),
                        _ => format!(
                            "has shape {shape:?}; {model} it must be {}",
                            max.iter().map(|m| format!("≤ {m}")).collect::<Vec<_>>().join(" × ")
                        ),
                    },
                ));
            }
        }
        bounded_by_memory(f, path, model)?;
    }
    let stored = read_core(f, path)?;
    // the model first: a basis of another model is the commonest mistake, and the shape
    // checks below would otherwise report its symptoms
    let mine = model.fingerprint();
    if stored.model_fingerprint != mine {
        return Err(bad(
            "model_fingerprint",
            format!(
                "the basis was trained on a different model than `{}` (fingerprint {} ≠ {}); run `flexrom train` on its pipeline again",
                model.path.display(),
                short(&stored.model_fingerprint),
                short(&mine)
            ),
        ));
    }
    check_content(&stored).map_err(|(f, p)| bad(&f, p))?;
    check_against_model(&stored, model).map_err(|(f, p)| bad(&f, p))?;
    // last, so that the checks above name the dataset that is wrong
    let content = content_hash(&HashInput::of_stored(&stored));
    if stored.content_hash != content {
        return Err(bad(
            "content_hash",
            format!(
                "is {} but the basis content hashes to {}: the file was edited after training or its fingerprint copied from another basis; run `flexrom train` again",
                short(&stored.content_hash),
                short(&content)
            ),
        ));
    }
    // the estimator and the training record once the basis is known to be this model's
    let mut stored = read_rest(f, path, stored)?;
    if let Some(h) = settings_hash {
        if stored.settings_hash != h {
            let w = format!(
                "{}: trained with other [train]/[reduction] settings than the pipeline has now (settings_hash {} ≠ {}); run `flexrom train` to bring it up to date",
                path.display(),
                short(&stored.settings_hash),
                short(h)
            );
            stored.warnings.push(w);
        }
    }
    Ok(stored)
}

/// Every dataset of the file within the memory bound before any is read: those the model
/// does not size (the estimator's calibration, the training record, the snapshot loads, the
/// routes' timing) have only the file's word for their length, which a flipped bit makes 2³¹.
fn bounded_by_memory(f: &hdf5::File, path: &Path, model: &Model) -> Result<()> {
    let all =
        super::h5::datasets_below(f).map_err(|e| Error::input(path, "(file)", format!("cannot be listed: {e}")))?;
    for (name, shape, bytes) in all {
        model
            .limits
            .check_memory(&format!("its shape {shape:?}"), bytes)
            // a bound, not a damaged file: the options that raise it stay the front end's to spell
            .map_err(|e| {
                Error::Resource(Text::new(format!("{}: {name}: ", path.display())).append(e.problem_text()))
            })?;
    }
    Ok(())
}

fn short(h: &str) -> &str {
    h.get(..12).unwrap_or(h)
}

/// Checks that need the model: sizes, the reference state, kept coordinates, elements.
fn check_against_model(s: &StoredBasis, model: &Model) -> std::result::Result<(), (String, String)> {
    let b = &s.basis;
    let bad = |f: &str, p: String| Err((f.to_string(), p));
    let physics = model
        .physics()
        .map_err(|e| ("basis/reference".to_string(), format!("cannot compute the model's initial state: {e}")))?;
    let sys = &*physics.sys;
    let (n, nc, ne) = (sys.n_dof(), sys.n_constraints(), sys.n_elements());
    b.validate(n, nc)?;
    if let Some(&d) = s.reduced_dofs.iter().find(|&&d| d >= n) {
        return bad("basis/reduced_dofs", format!("coordinate {d} does not exist (the model has {n})"));
    }
    if s.reduced_dofs.windows(2).any(|w| w[0] >= w[1]) {
        return bad("basis/reduced_dofs", "must be strictly increasing (each coordinate once)".into());
    }
    if let (Variant::WholeSystemStabilized, Some(psi)) = (b.variant, &b.multiplier_modes) {
        // the reduced saddle point must be inf-sup stable: the supremizers make β of order 1
        let rows: Vec<Vec<(usize, f64)>> = sys.constraints.iter().map(|c| c.terms.clone()).collect();
        let bm = crate::reduction::whole_system::constraint_matrix(n, &rows);
        let beta = crate::reduction::whole_system::inf_sup(&bm, psi, &b.modes);
        if !(beta >= INF_SUP_MIN) {
            return bad(
                "basis/modes, basis/multiplier_modes",
                format!("give an inf-sup constant σ_min(Ψᵀ B V) = {beta:.3e} below {INF_SUP_MIN:e}: the supremizer columns are missing or edited, and the reduced saddle point would be singular"),
            );
        }
    }
    if b.variant == Variant::ConstraintPreserving {
        let mut joints: Vec<usize> = sys.constraints.iter().flat_map(|c| c.terms.iter().map(|&(dof, _)| dof)).collect();
        joints.sort_unstable();
        joints.dedup();
        if b.kept != joints {
            return bad(
                "basis/kept_dofs",
                format!(
                    "are not the model's {} joint coordinates (constraint-preserving keeps exactly those)",
                    joints.len()
                ),
            );
        }
    }
    match b.snapshots {
        SnapshotKind::Raw => {
            if let Some((i, v)) = b.reference.iter().enumerate().find(|(_, v)| **v != 0.0) {
                return bad(
                    "basis/reference",
                    format!("entry {i} is {v}; a basis of raw snapshots has a zero reference"),
                );
            }
        }
        SnapshotKind::Reference => {
            let x0: &[f64] = &physics.x0;
            let scale = x0.iter().fold(1.0_f64, |a, v| a.max(v.abs()));
            let (i, d) = b
                .reference
                .iter()
                .zip(x0.iter())
                .map(|(r, x)| (r - x).abs())
                .enumerate()
                .fold((0, 0.0), |a, (i, d)| if d > a.1 { (i, d) } else { a });
            if d > REFERENCE_TOLERANCE * scale {
                return bad(
                    "basis/reference",
                    format!("differs from the model's initial state by {d:.3e} at coordinate {i} (limit {:.1e}): the basis is not centred on this model's x₀", REFERENCE_TOLERANCE * scale),
                );
            }
        }
    }
    if let Some(h) = &b.hyper {
        h.validate(ne)?;
        let max = MAX_WEIGHT_PER_ELEMENT * ne as f64;
        if let Some((k, w)) = h.weights.iter().enumerate().find(|(_, w)| **w > max) {
            return bad(
                "hyper/weights",
                format!("entry {k} is {w:e}; with {ne} elements an ECSW weight above {max:e} is not a trained one"),
            );
        }
    }
    Ok(())
}
