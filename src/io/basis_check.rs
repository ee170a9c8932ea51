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

use super::basis_file::{read_basis, StoredBasis};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::reduction::{Basis, SnapshotKind, Variant};
use crate::simulate::{prepare, Overrides, Settings};
use crate::solver::kkt::LinearSolverKind;
use crate::solver::model::DynamicModel;
use hdf5::types::{FloatSize, TypeDescriptor};
use ndarray::{s, Array2};
use sha2::{Digest, Sha256};
use std::path::Path;

/// ‖VᵀV − I‖_max allowed: LAPACK's SVD gives orthonormal columns to ~1e-14; 1e-8 leaves
/// room for any honest round-off and refuses edited modes.
pub const ORTHONORMALITY_TOLERANCE: f64 = 1e-8;
/// ‖x_ref − x₀‖_∞ allowed, relative to max(1, ‖x₀‖_∞).
pub const REFERENCE_TOLERANCE: f64 = 1e-9;
/// Smallest inf-sup constant `σ_min(Ψᵀ B V)` accepted for a whole-system-stabilized basis:
/// trained ones are O(0.1–1) (B has unit entries, Ψ and V orthonormal, and the supremizers
/// are `Bᵀ Ψ` orthonormalized), a basis without supremizers has ~1e-15.
pub const INF_SUP_MIN: f64 = 1e-6;
/// Smallest ECSW weight accepted. A sampled element of weight w stands for w copies of
/// itself; ECSW's NNLS keeps an element only when it matters (trained weights are O(0.1–10)),
/// so 1e-8 and below is an edited or corrupted file.
pub const MIN_WEIGHT: f64 = 1e-8;
/// Largest ECSW weight accepted, per element of the model: the weights sum to about the
/// number of elements, so a single weight above 1e4 × that is not a trained one.
pub const MAX_WEIGHT_PER_ELEMENT: f64 = 1e4;

/// Datasets read as `f64` (the basis proper); anything else than 8-byte floats is refused.
const FLOAT_DATASETS: [&str; 6] = [
    "basis/modes",
    "basis/reference",
    "basis/singular_values",
    "basis/energy",
    "basis/multiplier_modes",
    "hyper/weights",
];
/// Datasets read as indices; floating-point ones are refused.
const INDEX_DATASETS: [&str; 5] =
    ["basis/block_modes", "basis/block_values", "basis/reduced_dofs", "basis/kept_dofs", "hyper/elements"];
/// Links deeper than this, or more than [`MAX_LINKS`] of them, are not a basis file.
const MAX_DEPTH: usize = 8;
const MAX_LINKS: usize = 10_000;

/// Reads the basis at `path` and checks it against `model`; `settings_hash` is the
/// pipeline's [`settings_hash`] (a mismatch only warns). The only way commands read a basis.
pub fn check(path: &Path, model: &Model, settings_hash: Option<&str>) -> Result<StoredBasis> {
    let bad = |field: &str, problem: String| Error::input(path, field, problem);
    // sizes before anything is read: a crafted shape must not make us allocate terabytes
    // (after the link walk: opening a dataset follows its link)
    let ours = |f: &hdf5::File| {
        f.attr("schema_version")
            .and_then(|a| a.read_scalar::<u64>())
            .is_ok_and(|v| v == super::basis_file::SCHEMA_VERSION)
    };
    if let Some(f) = hdf5::File::open(path).ok().filter(ours) {
        check_file(&f, path)?;
        let sys = model.system(LinearSolverKind::Banded);
        let (n, nc, ne) = (sys.n_dof(), sys.n_constraints(), sys.n_elements());
        let (cols, values) = (n + nc, n + nc);
        let limits: [(&str, &[usize]); 11] = [
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
    }
    let stored = read_basis(path)?;
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
    if let Some(h) = settings_hash {
        if stored.settings_hash != h {
            eprintln!(
                "warning: {}: trained with other [train]/[reduction] settings than the pipeline has now (settings_hash {} ≠ {}); run `flexrom train` to bring it up to date",
                path.display(),
                short(&stored.settings_hash),
                short(h)
            );
        }
    }
    Ok(stored)
}

fn short(h: &str) -> &str {
    h.get(..12).unwrap_or(h)
}

/// Refuses anything but hard links, external or virtual storage, and datasets of the wrong
/// type. Runs on the open file before any dataset is read.
pub fn check_file(f: &hdf5::File, path: &Path) -> Result<()> {
    let mut seen = 0;
    walk(f, "", 0, &mut seen, path)?;
    for name in FLOAT_DATASETS.iter().chain(INDEX_DATASETS.iter()) {
        if !f.link_exists(name) {
            continue;
        }
        let Ok(d) = f.dataset(name) else { return Err(Error::input(path, *name, "is not a dataset")) };
        let ty = d
            .dtype()
            .and_then(|t| t.to_descriptor())
            .map_err(|e| Error::input(path, *name, format!("has an unreadable type: {e}")))?;
        let float = FLOAT_DATASETS.contains(name);
        match (&ty, float) {
            (TypeDescriptor::Float(FloatSize::U8), true) => {}
            (_, true) => {
                return Err(Error::input(
                    path,
                    *name,
                    format!("has type {}; it must hold 8-byte floats (f64)", describe(&ty)),
                ))
            }
            (TypeDescriptor::Unsigned(_) | TypeDescriptor::Integer(_), false) => {}
            (_, false) => {
                return Err(Error::input(
                    path,
                    *name,
                    format!("has type {}; it must hold integer indices", describe(&ty)),
                ))
            }
        }
    }
    Ok(())
}

fn describe(t: &TypeDescriptor) -> String {
    match t {
        TypeDescriptor::Integer(s) => format!("{}-byte signed integer", *s as usize),
        TypeDescriptor::Unsigned(s) => format!("{}-byte unsigned integer", *s as usize),
        TypeDescriptor::Float(s) => format!("{}-byte float", *s as usize),
        other => format!("{other}"),
    }
}

/// Visits every link under `prefix`: only hard links; datasets stored in the file itself.
fn walk(g: &hdf5::Group, prefix: &str, depth: usize, seen: &mut usize, path: &Path) -> Result<()> {
    let here = if prefix.is_empty() { "/" } else { prefix };
    if depth > MAX_DEPTH {
        return Err(Error::input(
            path,
            here,
            format!("is nested deeper than {MAX_DEPTH} groups: not a flexrom basis file"),
        ));
    }
    let links = g
        .links(hdf5::IndexType::Name, hdf5::IterationOrder::Native)
        .map_err(|e| Error::input(path, here, format!("cannot list its links: {e}")))?;
    for (name, info) in links {
        let full = if prefix.is_empty() { name.clone() } else { format!("{prefix}/{name}") };
        *seen += 1;
        if *seen > MAX_LINKS {
            return Err(Error::input(
                path,
                "(file)",
                format!("holds more than {MAX_LINKS} links: not a flexrom basis file"),
            ));
        }
        if info.link_type != hdf5::LinkType::Hard {
            let kind =
                if info.link_type == hdf5::LinkType::Soft { "a soft link" } else { "an external or user-defined link" };
            return Err(Error::input(
                path,
                &full,
                format!("is {kind}; a basis file must hold its data itself (hard links only)"),
            ));
        }
        if let Ok(sub) = g.group(&name) {
            walk(&sub, &full, depth + 1, seen, path)?;
        } else if let Ok(d) = g.dataset(&name) {
            let dcpl =
                d.dcpl().map_err(|e| Error::input(path, &full, format!("cannot read its storage properties: {e}")))?;
            if !dcpl.external().is_empty() {
                return Err(Error::input(
                    path,
                    &full,
                    "is stored in an external file; a basis file must hold its data itself",
                ));
            }
            if matches!(dcpl.layout(), hdf5::dataset::Layout::Virtual) {
                return Err(Error::input(
                    path,
                    &full,
                    "is a virtual dataset (data in other files); a basis file must hold its data itself",
                ));
            }
        }
    }
    Ok(())
}

/// Checks that need no model: values, orthonormality, the spectrum, the ECSW set's own
/// consistency. `Err((dataset, problem))`.
pub fn check_content(s: &StoredBasis) -> std::result::Result<(), (String, String)> {
    let b = &s.basis;
    let bad = |f: &str, p: String| Err((f.to_string(), p));
    let first_bad =
        |a: &mut dyn Iterator<Item = &f64>| a.enumerate().find(|(_, v)| !v.is_finite()).map(|(i, v)| (i, *v));
    if let Some((i, v)) = first_bad(&mut b.modes.iter()) {
        return bad(
            "basis/modes",
            format!(
                "entry ({}, {}) is {v}; every entry must be finite",
                i / b.modes.ncols().max(1),
                i % b.modes.ncols().max(1)
            ),
        );
    }
    if let Some((i, v)) = first_bad(&mut b.reference.iter()) {
        return bad("basis/reference", format!("entry {i} is {v}; every entry must be finite"));
    }
    if let Some(vl) = &b.multiplier_modes {
        if let Some((i, v)) = first_bad(&mut vl.iter()) {
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
    // VᵀV = I (whole-system: the stacked [V; V_λ])
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

/// Checks that need the model: sizes, the reference state, kept coordinates, elements.
fn check_against_model(s: &StoredBasis, model: &Model) -> std::result::Result<(), (String, String)> {
    let b = &s.basis;
    let bad = |f: &str, p: String| Err((f.to_string(), p));
    let sys = model.system(LinearSolverKind::Banded);
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
            let settings = Settings::resolve(model, &Overrides::default()).map_err(|e| {
                ("basis/reference".to_string(), format!("cannot compute the model's initial state: {e}"))
            })?;
            let (_, x0) = prepare(model, &settings).map_err(|e| {
                ("basis/reference".to_string(), format!("cannot compute the model's initial state: {e}"))
            })?;
            let scale = x0.iter().fold(1.0_f64, |a, v| a.max(v.abs()));
            let (i, d) = b
                .reference
                .iter()
                .zip(&x0)
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

/// What the content hash covers.
pub struct HashInput<'a> {
    pub basis: &'a Basis,
    pub singular_values: &'a [f64],
    pub energy: &'a [f64],
    pub block_modes: &'a [usize],
    pub block_values: &'a [usize],
    pub reduced_dofs: &'a [usize],
    pub model_fingerprint: &'a str,
    pub settings_hash: &'a str,
}

impl<'a> HashInput<'a> {
    pub fn of_stored(s: &'a StoredBasis) -> Self {
        HashInput {
            basis: &s.basis,
            singular_values: s.singular_values.as_slice().unwrap_or(&[]),
            energy: s.energy.as_slice().unwrap_or(&[]),
            block_modes: &s.block_modes,
            block_values: &s.block_values,
            reduced_dofs: &s.reduced_dofs,
            model_fingerprint: &s.model_fingerprint,
            settings_hash: &s.settings_hash,
        }
    }
}

/// SHA-256 (hex) of the basis content: every part prefixed by its name and shape, floats as
/// little-endian IEEE bytes, so equal content gives equal hashes on every machine.
pub fn content_hash(c: &HashInput) -> String {
    let mut h = Sha256::new();
    let mut part = |name: &str, shape: &[usize], bytes: &mut dyn Iterator<Item = [u8; 8]>| {
        h.update((name.len() as u64).to_le_bytes());
        h.update(name.as_bytes());
        h.update((shape.len() as u64).to_le_bytes());
        for &d in shape {
            h.update((d as u64).to_le_bytes());
        }
        for b in bytes {
            h.update(b);
        }
    };
    let b = c.basis;
    let f = |v: &f64| v.to_le_bytes();
    let u = |v: &usize| (*v as u64).to_le_bytes();
    let modes = b.modes.as_standard_layout();
    part("modes", &[modes.nrows(), modes.ncols()], &mut modes.iter().map(f));
    part("reference", &[b.reference.len()], &mut b.reference.iter().map(f));
    part("singular_values", &[c.singular_values.len()], &mut c.singular_values.iter().map(f));
    part("energy", &[c.energy.len()], &mut c.energy.iter().map(f));
    part("block_modes", &[c.block_modes.len()], &mut c.block_modes.iter().map(u));
    part("block_values", &[c.block_values.len()], &mut c.block_values.iter().map(u));
    part("reduced_dofs", &[c.reduced_dofs.len()], &mut c.reduced_dofs.iter().map(u));
    part("kept_dofs", &[b.kept.len()], &mut b.kept.iter().map(u));
    if let Some(vl) = &b.multiplier_modes {
        let vl = vl.as_standard_layout();
        part("multiplier_modes", &[vl.nrows(), vl.ncols()], &mut vl.iter().map(f));
    }
    part("multiplier_scale", &[], &mut std::iter::once(b.multiplier_scale.to_le_bytes()));
    part("n_pod_modes", &[], &mut std::iter::once((b.n_pod_modes as u64).to_le_bytes()));
    if let Some(hy) = &b.hyper {
        part("hyper/elements", &[hy.elements.len()], &mut hy.elements.iter().map(u));
        part("hyper/weights", &[hy.weights.len()], &mut hy.weights.iter().map(f));
        part("hyper/tolerance", &[], &mut std::iter::once(hy.tolerance.to_le_bytes()));
        part("hyper/training_residual", &[], &mut std::iter::once(hy.training_residual.to_le_bytes()));
        part("hyper/n_training", &[], &mut std::iter::once((hy.n_training as u64).to_le_bytes()));
    }
    for (name, text) in [
        ("variant", b.variant.name()),
        ("snapshots", b.snapshots.name()),
        ("model_fingerprint", c.model_fingerprint),
        ("settings_hash", c.settings_hash),
    ] {
        h.update((name.len() as u64).to_le_bytes());
        h.update(name.as_bytes());
        h.update((text.len() as u64).to_le_bytes());
        h.update(text.as_bytes());
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// SHA-256 (hex) of a pipeline's `[train]` and `[reduction]` tables in canonical form (the
/// parsed values as JSON): comments, layout and number spelling do not change it, any
/// setting that changes the basis does.
pub fn settings_hash(p: &crate::pipeline::Pipeline) -> String {
    let json = serde_json::json!({ "train": p.file.train, "reduction": p.file.reduction });
    Sha256::digest(json.to_string().as_bytes()).iter().map(|b| format!("{b:02x}")).collect()
}
