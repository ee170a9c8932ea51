//! The basis file written by `train` and read by `online`, `validate`, `sweep`:
//!
//! ```text
//! /snapshots                 (n_dof, m)   column k = all coordinates at one time of one run
//! /snapshot_multipliers      (n_c, m)     Lagrange multipliers at the same instants
//! /snapshot_load_scale       (m)          load scale of the run each column comes from
//! /snapshot_t                (m)          time of each column, s
//! /basis/modes               (n_dof, r)   V: orthonormal columns (whole-system: the
//!                                         coordinate rows of the joint POD)
//! /basis/singular_values     (k)          all singular values of the POD, non-increasing
//!                                         (a block basis: those of each block's POD in turn)
//! /basis/energy              (k)          cumulative captured fraction Σ_{i≤j} σᵢ² / Σ σᵢ²
//!                                         (a block basis: within each block)
//! /basis/block_modes         (n_b)        modes kept from each block's POD (columns of V in
//!                                         this order; one block without reduction.blocks;
//!                                         absent in older files: one block)
//! /basis/block_values        (n_b)        singular values of each block's POD
//! /basis/reference           (n_dof)      x_ref (zeros for raw snapshots)
//! /basis/reduced_dofs        (n_f)        coordinates whose rows entered the POD
//! /basis/kept_dofs           (n_k)        coordinates kept unreduced (last n_k columns of V)
//! /basis/multiplier_modes    (n_c, r)     whole-system only: λ ≈ w V_λ q
//!                            (n_c, k)     whole-system-stabilized: Ψ, λ ≈ Ψ μ (orthonormal);
//!                                         then V = [Φ (n_pod_modes), S (k supremizers)]
//! /hyper/elements            (|E|)        hyper-reduction only: sampled element indices,
//!                                         increasing (elements numbered body by body)
//! /hyper/weights             (|E|)        their ECSW weights, positive
//!   attributes on /hyper: tolerance (τ), training_residual (‖Cw − b‖/‖b‖), n_training
//! /training/...                          greedy training only (src/pipeline/greedy.rs):
//!   range (2) [A, B]; tolerance (scalar) T; load_scales (n_runs) the loads whose
//!   snapshots the basis holds, in run order; candidates (N); per iteration i:
//!   worst_estimate, worst_load, run_load (where its full run was: the worst candidate
//!   without a run yet), true_error (rel_error of that iteration's basis at run_load from
//!   the full run there; both NaN without a run), energy_tolerance ε,
//!   hyper_tolerance τ, n_modes, n_elements, bound (between the candidates),
//!   between_points; estimates (iterations, N) every candidate's
//!   estimate; attributes: method = "greedy", iterations, max_runs, full_runs, converged
//! /labels/...                            names of the coordinates and constraint rows
//!                                         (src/io/labels.rs)
//! every dataset: attributes units, dims ("dof, snapshot", "dof, mode", …: src/io/attrs.rs)
//! attributes on /: flexrom_layout, flexrom_file = "basis", schema_version, model (TOML
//!   text), model_path, model_fingerprint, settings_hash, content_hash (SHA-256 of the content: src/io/basis_check.rs),
//!   pipeline (TOML text), variant, snapshots, mode_rule, n_modes (= r), n_pod_modes,
//!   multiplier_scale (w), n_dof, creation_time (RFC 3339, UTC), program_version
//! ```

use super::attrs::{check_layout, write_atomically_as, Kind};
use super::basis_hash::{content_hash, HashInput};
use super::basis_layout::check_file;
use super::basis_training::{read_training, BasisTraining};
use super::h5::{attr_f64, attr_str, attr_u64, read_attr_f64, read_attr_str};
use crate::error::{Error, Result};
use crate::reduction::estimator::Estimator;
use crate::reduction::{Basis, Hyper, SnapshotKind, Trained, Variant};
use ndarray::{Array1, Array2};
use std::path::Path;

/// 2: adds `content_hash` and `settings_hash` (version-1 files are refused: retrain).
pub const SCHEMA_VERSION: u64 = 2;

/// The training data the snapshots come from.
#[derive(Clone, Debug)]
pub struct TrainingData {
    pub x: Array2<f64>,
    pub multipliers: Array2<f64>,
    pub load_scale: Array1<f64>,
    pub t: Array1<f64>,
}

/// Provenance written with a basis.
#[derive(Clone, Debug)]
pub struct BasisMeta {
    pub model_text: String,
    pub model_path: String,
    pub model_fingerprint: String,
    pub pipeline_text: String,
    pub mode_rule: String,
    /// [`super::basis_hash::settings_hash`] of the pipeline that trained the basis
    pub settings_hash: String,
}

/// A basis as read back, with its provenance.
#[derive(Clone, Debug)]
pub struct StoredBasis {
    pub basis: std::sync::Arc<Basis>,
    pub singular_values: Array1<f64>,
    pub energy: Array1<f64>,
    /// modes kept from each block's POD, and how many singular values each has
    pub block_modes: Vec<usize>,
    pub block_values: Vec<usize>,
    /// coordinates whose rows entered the POD
    pub reduced_dofs: Vec<usize>,
    pub model_fingerprint: String,
    /// the training pipeline's `[train]`/`[reduction]` settings, hashed
    pub settings_hash: String,
    /// SHA-256 of the content as written ([`super::basis_check::content_hash`])
    pub content_hash: String,
    pub mode_rule: String,
    pub creation_time: String,
    /// what reading and checking it found worth telling the user (not errors: a basis
    /// trained with other settings than the pipeline has now), one line each
    pub warnings: Vec<String>,
    /// `/estimator` (`None`: the file has none)
    pub estimator: Option<std::sync::Arc<Estimator>>,
    /// what the file says of its training (range, tolerance, notes, timing, …)
    pub training: BasisTraining,
}

/// Chunked, shuffled and deflated (when the HDF5 library has zlib): snapshots compress well.
fn compressible(b: hdf5::DatasetBuilderEmpty, rows: usize, cols: usize) -> hdf5::DatasetBuilderEmpty {
    let mut b = b.chunk((rows.clamp(1, 1024), cols.clamp(1, 64)));
    if hdf5::filters::deflate_available() {
        b = b.shuffle().deflate(4);
    }
    b
}

pub fn write_basis(path: &Path, data: &TrainingData, trained: &Trained, meta: &BasisMeta) -> Result<()> {
    write_basis_with(path, data, trained, meta, |_| Ok(()))
}

/// [`write_basis`], then `extra` adds groups (the estimator, greedy's `/training`) in the
/// same atomic write.
pub fn write_basis_with(
    path: &Path,
    data: &TrainingData,
    trained: &Trained,
    meta: &BasisMeta,
    extra: impl FnOnce(&hdf5::File) -> Result<()>,
) -> Result<()> {
    write_atomically_as(path, Kind::Basis, |f| {
        let e = |err: hdf5::Error| Error::hdf5(path, err);
        let big = |name: &str, a: &Array2<f64>| -> Result<()> {
            let (r, c) = a.dim();
            if r == 0 || c == 0 {
                f.new_dataset_builder().with_data(&a.as_standard_layout()).create(name).map_err(e)?;
            } else {
                compressible(f.new_dataset::<f64>(), r, c)
                    .shape((r, c))
                    .create(name)
                    .map_err(e)?
                    .write(&a.as_standard_layout())
                    .map_err(e)?;
            }
            Ok(())
        };
        big("snapshots", &data.x)?;
        big("snapshot_multipliers", &data.multipliers)?;
        f.new_dataset_builder().with_data(&data.load_scale).create("snapshot_load_scale").map_err(e)?;
        f.new_dataset_builder().with_data(&data.t).create("snapshot_t").map_err(e)?;
        let g = f.create_group("basis").map_err(e)?;
        let b = &trained.basis;
        g.new_dataset_builder().with_data(&b.modes.as_standard_layout()).create("modes").map_err(e)?;
        let cat = |f: &dyn Fn(&crate::reduction::Pod) -> &Array1<f64>| {
            Array1::from_iter(trained.pods.iter().flat_map(|p| f(p).iter().copied()))
        };
        g.new_dataset_builder().with_data(&cat(&|p| &p.singular_values)).create("singular_values").map_err(e)?;
        g.new_dataset_builder().with_data(&cat(&|p| &p.energy)).create("energy").map_err(e)?;
        g.new_dataset_builder().with_data(&b.reference).create("reference").map_err(e)?;
        let idx = |v: &[usize]| Array1::from_iter(v.iter().map(|&d| d as u64));
        let block_columns = trained.block_columns();
        g.new_dataset_builder().with_data(&idx(&block_columns)).create("block_modes").map_err(e)?;
        if trained.output_modes.iter().any(|&k| k > 0) {
            g.new_dataset_builder().with_data(&idx(&trained.output_modes)).create("output_modes").map_err(e)?;
        }
        let values: Vec<usize> = trained.pods.iter().map(|p| p.singular_values.len()).collect();
        g.new_dataset_builder().with_data(&idx(&values)).create("block_values").map_err(e)?;
        g.new_dataset_builder().with_data(&idx(&trained.reduced_dofs)).create("reduced_dofs").map_err(e)?;
        g.new_dataset_builder().with_data(&idx(&b.kept)).create("kept_dofs").map_err(e)?;
        if let Some(vl) = &b.multiplier_modes {
            g.new_dataset_builder().with_data(&vl.as_standard_layout()).create("multiplier_modes").map_err(e)?;
        }
        if let Some(h) = &b.hyper {
            let g = f.create_group("hyper").map_err(e)?;
            g.new_dataset_builder().with_data(&idx(&h.elements)).create("elements").map_err(e)?;
            g.new_dataset_builder().with_data(&Array1::from(h.weights.clone())).create("weights").map_err(e)?;
            attr_f64(&g, "tolerance", h.tolerance).map_err(e)?;
            attr_f64(&g, "training_residual", h.training_residual).map_err(e)?;
            attr_u64(&g, "n_training", h.n_training as u64).map_err(e)?;
        }
        attr_u64(f, "schema_version", SCHEMA_VERSION).map_err(e)?;
        attr_str(f, "model", &meta.model_text).map_err(e)?;
        attr_str(f, "model_path", &meta.model_path).map_err(e)?;
        attr_str(f, "model_fingerprint", &meta.model_fingerprint).map_err(e)?;
        attr_str(f, "settings_hash", &meta.settings_hash).map_err(e)?;
        let (sv, en) = (cat(&|p| &p.singular_values), cat(&|p| &p.energy));
        let content = content_hash(&HashInput {
            basis: b,
            singular_values: sv.as_slice().expect("contiguous"),
            energy: en.as_slice().expect("contiguous"),
            block_modes: &block_columns,
            block_values: &values,
            reduced_dofs: &trained.reduced_dofs,
            model_fingerprint: &meta.model_fingerprint,
            settings_hash: &meta.settings_hash,
        });
        attr_str(f, "content_hash", &content).map_err(e)?;
        attr_str(f, "pipeline", &meta.pipeline_text).map_err(e)?;
        attr_str(f, "variant", b.variant.name()).map_err(e)?;
        attr_str(f, "snapshots", b.snapshots.name()).map_err(e)?;
        attr_str(f, "mode_rule", &meta.mode_rule).map_err(e)?;
        attr_u64(f, "n_modes", b.n_reduced() as u64).map_err(e)?;
        attr_u64(f, "n_pod_modes", b.n_pod_modes as u64).map_err(e)?;
        attr_f64(f, "multiplier_scale", b.multiplier_scale).map_err(e)?;
        attr_u64(f, "n_dof", b.n_dof() as u64).map_err(e)?;
        attr_str(f, "creation_time", &humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string())
            .map_err(e)?;
        attr_str(f, "program_version", env!("CARGO_PKG_VERSION")).map_err(e)?;
        super::labels::write_labels_of_text(f, &meta.model_text, &meta.model_path).map_err(e)?;
        extra(f)
    })
}

/// Reads a basis file whole (the basis, its estimator and its training record) with one
/// open; every missing or malformed part is reported with the file and the dataset or
/// attribute it concerns.
pub fn read_basis(path: &Path) -> Result<StoredBasis> {
    let f = open_basis(path)?;
    let s = read_core(&f, path)?;
    read_rest(&f, path, s)
}

/// Opens the basis file at `path` to read: an error naming it when it does not exist or
/// cannot be read.
pub fn open_basis(path: &Path) -> Result<hdf5::File> {
    if !path.is_file() {
        return Err(Error::input(path, "(file)", "does not exist; run `flexrom train` first"));
    }
    super::h5_open::open_to_read(path)
}

/// The estimator and the training record of the open basis file `f`, added to its basis
/// `s` as [`read_core`] read it.
pub fn read_rest(f: &hdf5::File, path: &Path, s: StoredBasis) -> Result<StoredBasis> {
    let estimator = super::estimator_file::read_estimator(f, path, &s.basis)?.map(std::sync::Arc::new);
    Ok(StoredBasis { estimator, training: read_training(f, path)?, ..s })
}

/// The basis of the open basis file `f` and its provenance, without its estimator and
/// training record ([`read_rest`] adds them).
pub fn read_core(f: &hdf5::File, path: &Path) -> Result<StoredBasis> {
    let field = |name: &str, problem: String| Error::input(path, name, problem);
    // layouts 1 and 2 store a basis alike (snapshots and modes one column each); a newer
    // one is refused
    check_layout(f, path, "flexrom train")?;
    let version = f.attr("schema_version").and_then(|a| a.read_scalar::<u64>()).map_err(|_| {
        // another flexrom file says what it is (`flexrom_file`): name it
        let kind = crate::io::h5::read_attr_str(f, "flexrom_file")
            .map_or(String::new(), |k| format!(" (it is a flexrom {k} file)"));
        field("schema_version", format!("is missing: this is not a flexrom basis file{kind}"))
    })?;
    if version == 1 {
        return Err(field("schema_version", format!("is 1 (an older flexrom's basis, without a content hash); this program reads version {SCHEMA_VERSION}: run `flexrom train` again")));
    }
    if version != SCHEMA_VERSION {
        return Err(field("schema_version", format!("is {version}; this program reads version {SCHEMA_VERSION}")));
    }
    // links, external storage and dataset types, before any dataset is read
    check_file(f, path)?;
    let text = |name: &str| read_attr_str(f, name).map_err(|err| field(name, format!("cannot be read: {err}")));
    let num = |name: &str| read_attr_f64(f, name).map_err(|err| field(name, format!("cannot be read: {err}")));
    let count = |name: &str| {
        f.attr(name)
            .and_then(|a| a.read_scalar::<u64>())
            .map(|v| v as usize)
            .map_err(|err| field(name, format!("cannot be read: {err}")))
    };
    let mat = |name: &str| {
        f.dataset(name).and_then(|d| d.read_2d::<f64>()).map_err(|err| field(name, format!("cannot be read: {err}")))
    };
    let vec = |name: &str| {
        f.dataset(name).and_then(|d| d.read_1d::<f64>()).map_err(|err| field(name, format!("cannot be read: {err}")))
    };
    let idx = |name: &str| -> Result<Vec<usize>> {
        Ok(f.dataset(name)
            .and_then(|d| d.read_1d::<u64>())
            .map_err(|err| field(name, format!("cannot be read: {err}")))?
            .iter()
            .map(|&d| d as usize)
            .collect())
    };
    let variant_name = text("variant")?;
    let variant = Variant::parse(&variant_name)
        .ok_or_else(|| field("variant", format!("`{variant_name}` is not a known variant")))?;
    let kind_name = text("snapshots")?;
    let snapshots = SnapshotKind::parse(&kind_name)
        .ok_or_else(|| field("snapshots", format!("`{kind_name}` is not raw or reference")))?;
    let multiplier_modes = if matches!(variant, Variant::WholeSystem | Variant::WholeSystemStabilized) {
        Some(mat("basis/multiplier_modes")?)
    } else {
        None
    };
    let basis = Basis {
        variant,
        snapshots,
        reference: vec("basis/reference")?,
        modes: mat("basis/modes")?,
        kept: idx("basis/kept_dofs")?,
        multiplier_modes,
        multiplier_scale: num("multiplier_scale")?,
        n_pod_modes: count("n_pod_modes")?,
        hyper: read_hyper(f, path)?,
    };
    let singular_values = vec("basis/singular_values")?;
    let energy = vec("basis/energy")?;
    if basis.n_pod_modes == 0 || basis.n_pod_modes > singular_values.len() {
        return Err(field(
            "n_pod_modes",
            format!("is {} but the POD has {} singular values", basis.n_pod_modes, singular_values.len()),
        ));
    }
    // files written before block bases have one block
    let (block_modes, block_values) = if f.link_exists("basis/block_modes") {
        (idx("basis/block_modes")?, idx("basis/block_values")?)
    } else {
        (vec![basis.n_pod_modes], vec![singular_values.len()])
    };
    if block_modes.iter().sum::<usize>() != basis.n_pod_modes {
        return Err(field(
            "basis/block_modes",
            format!("{block_modes:?} do not add up to the {} POD modes (n_pod_modes)", basis.n_pod_modes),
        ));
    }
    if block_values.len() != block_modes.len() || block_values.iter().sum::<usize>() != singular_values.len() {
        return Err(field(
            "basis/block_values",
            format!(
                "{block_values:?} do not split the {} singular values into {} blocks",
                singular_values.len(),
                block_modes.len()
            ),
        ));
    }
    Ok(StoredBasis {
        basis: std::sync::Arc::new(basis),
        singular_values,
        energy,
        block_modes,
        block_values,
        reduced_dofs: idx("basis/reduced_dofs")?,
        model_fingerprint: text("model_fingerprint")?,
        settings_hash: text("settings_hash")?,
        content_hash: text("content_hash")?,
        mode_rule: text("mode_rule")?,
        creation_time: text("creation_time")?,
        warnings: Vec::new(),
        estimator: None,
        training: BasisTraining::default(),
    })
}

/// `/hyper`, when present (checked by [`super::basis_check::check`]).
fn read_hyper(f: &hdf5::File, path: &Path) -> Result<Option<Hyper>> {
    let Ok(g) = f.group("hyper") else { return Ok(None) };
    let field = |name: &str, problem: String| Error::input(path, name, problem);
    let elements: Vec<usize> = g
        .dataset("elements")
        .and_then(|d| d.read_1d::<u64>())
        .map_err(|err| field("hyper/elements", format!("cannot be read: {err}")))?
        .iter()
        .map(|&e| e as usize)
        .collect();
    let weights = g
        .dataset("weights")
        .and_then(|d| d.read_1d::<f64>())
        .map_err(|err| field("hyper/weights", format!("cannot be read: {err}")))?
        .to_vec();
    let num = |name: &str| {
        read_attr_f64(&g, name).map_err(|err| field(&format!("hyper/{name}"), format!("cannot be read: {err}")))
    };
    let n_training = g
        .attr("n_training")
        .and_then(|a| a.read_scalar::<u64>())
        .map_err(|err| field("hyper/n_training", format!("cannot be read: {err}")))? as usize;
    Ok(Some(Hyper {
        elements,
        weights,
        tolerance: num("tolerance")?,
        training_residual: num("training_residual")?,
        n_training,
    }))
}

/// The hash input of a basis as read back, to check its `content_hash`.
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
