//! `train`: full runs at the training load scales → snapshot matrix → POD basis → HDF5.

use super::config::{Blocks, Pipeline};
use super::estimate::{build_estimator, Estimator, DEFAULT_EXTRA_MODES};
use crate::error::{Error, Result};
use crate::io::basis_file::{write_basis_with, BasisMeta, TrainingData};
use crate::linalg::kkt::LinearSolverKind;
use crate::physics::system::FlexibleSystem;
use crate::reduction::{ecsw, train_basis, BasisSpec, ModeRule, Trained};
use crate::simulate::{FullModel, Overrides, SimulationResult};
use ndarray::{concatenate, Array1, Axis};
use std::path::Path;

pub struct TrainSummary {
    pub trained: Trained,
    pub n_snapshots: usize,
    pub full_seconds: f64,
    /// full runs made (greedy: with the last, held-out check run)
    pub n_runs: usize,
    /// what the greedy loop did (`/training` in the basis file); `None` for `load_scales`
    pub greedy: Option<super::greedy::GreedyRecord>,
    /// the error estimator (uncalibrated for `load_scales` training: no held-out runs;
    /// greedy training calibrates it on its held-out full runs)
    pub estimator: Option<Estimator>,
}

/// The coordinates that appear in any joint, sorted.
pub fn joint_dofs(p: &Pipeline) -> Vec<usize> {
    joint_dofs_of(&p.model.system(LinearSolverKind::Banded))
}

fn joint_dofs_of(sys: &FlexibleSystem) -> Vec<usize> {
    let mut d: Vec<usize> = sys.constraints.iter().flat_map(|c| c.terms.iter().map(|&(dof, _)| dof)).collect();
    d.sort_unstable();
    d.dedup();
    d
}

/// The joint equations and multiplier mode rule of the whole-system-stabilized variant
/// (`None` for the others).
fn stabilization_for(p: &Pipeline, sys: &FlexibleSystem) -> Option<crate::reduction::Stabilization> {
    use crate::reduction::whole_system::{constraint_matrix, DEFAULT_MULTIPLIER_MODES};
    (p.variant() == crate::reduction::Variant::WholeSystemStabilized).then(|| {
        let rows: Vec<Vec<(usize, f64)>> = sys.constraints.iter().map(|c| c.terms.clone()).collect();
        crate::reduction::Stabilization {
            constraints: constraint_matrix(crate::solver::model::ParametricModel::n_dof(sys), &rows),
            multiplier_modes: p.file.reduction.multiplier_modes.clone().unwrap_or(DEFAULT_MULTIPLIER_MODES),
        }
    })
}

/// Runs the training simulations and builds the basis (nothing is written); greedy
/// training (`train.greedy`) is [`super::greedy::train`].
pub fn train(p: &Pipeline) -> Result<(TrainingData, TrainSummary)> {
    if let Some(g) = &p.file.train.greedy {
        return super::greedy::train(p, g);
    }
    let scales = p.file.train.load_scales.clone().unwrap_or_default();
    if scales.is_empty() {
        return Err(Error::input(&p.path, "train.load_scales", "is empty: no training run, no snapshots"));
    }
    // the runs, their concatenated snapshots and the POD's working copy
    let n_steps = crate::simulate::Settings::resolve(&p.model, &Overrides::default())?.n_steps;
    let z = p.model.sizes();
    let snapshots = scales.len() as f64 * (n_steps as f64 + 1.0);
    crate::limits::check_memory(
        &format!("training on {} snapshots × {} coordinates", snapshots, z.n_dof),
        3.0 * 8.0 * snapshots * (z.n_dof + z.n_constraints) + z.n_elements * crate::limits::BYTES_PER_ELEMENT,
    )?;
    let mut runs = Vec::new();
    let mut full_seconds = 0.0;
    // the full model assembled once for every training load
    let mut full = FullModel::new(&p.model, LinearSolverKind::Banded)?;
    for &s in &scales {
        let r = full
            .simulate(&Overrides { load_scale: Some(s), ..Default::default() })
            .map_err(|e| e.at_stage("train (full run)", s))?;
        full_seconds += r.wall_seconds;
        runs.push(r);
    }
    basis_from_snapshots(p, training_data(&runs), full_seconds, scales.len())
}

/// The basis and estimator of fixed-load training (`train.load_scales`, the pipeline's
/// `[reduction]` rule) from the snapshots of `n_runs` full runs, on one machine or gathered
/// from sharded jobs ([`super::snapshots`]).
pub(crate) fn basis_from_snapshots(
    p: &Pipeline,
    data: TrainingData,
    full_seconds: f64,
    n_runs: usize,
) -> Result<(TrainingData, TrainSummary)> {
    let modes = p.file.reduction.modes.clone().ok_or_else(|| Error::input(&p.path, "reduction.modes", "is missing"))?;
    let tol = p.file.reduction.hyper.as_ref().map(|h| h.tolerance);
    let (trained, estimator) = build_basis(p, &data, modes, tol).map_err(|(f, e)| Error::input(&p.path, f, e))?;
    let n_snapshots = data.x.ncols();
    let summary = TrainSummary { trained, n_snapshots, full_seconds, n_runs, greedy: None, estimator: Some(estimator) };
    Ok((data, summary))
}

/// The snapshots of full runs, side by side in run order.
pub fn training_data(runs: &[SimulationResult]) -> TrainingData {
    let cat = |f: &dyn Fn(&SimulationResult) -> ndarray::ArrayView2<f64>| {
        concatenate(Axis(1), &runs.iter().map(f).collect::<Vec<_>>()).expect("same row counts")
    };
    TrainingData {
        x: cat(&|r| r.q.view()),
        multipliers: cat(&|r| r.multipliers.view()),
        load_scale: Array1::from_iter(runs.iter().flat_map(|r| std::iter::repeat_n(r.settings.load_scale, r.t.len()))),
        t: Array1::from_iter(runs.iter().flat_map(|r| r.t.iter().copied())),
    }
}

/// The basis of the pipeline's variant and blocks from `data` with `modes`, hyper-reduced
/// by ECSW at `hyper_tolerance` when given, and its error estimator (uncalibrated: the same
/// POD with [`DEFAULT_EXTRA_MODES`] more modes per block); `Err((pipeline field, problem))`.
pub fn build_basis(
    p: &Pipeline,
    data: &TrainingData,
    modes: ModeRule,
    hyper_tolerance: Option<f64>,
) -> std::result::Result<(Trained, Estimator), (&'static str, String)> {
    // the physics, assembled once for the blocks, the joint rows, ECSW and the estimator
    let sys = &*p.model.physics().map_err(|e| ("model", e.to_string()))?.sys;
    // every run starts from the same consistent, undeformed state
    let x_ref = data.x.column(0).to_owned();
    // whole-system: scale the multipliers so both blocks weigh alike in the POD
    let dx = (&data.x - &x_ref.view().insert_axis(Axis(1))).mapv(|v| v * v).sum().sqrt();
    let dl = data.multipliers.mapv(|v| v * v).sum().sqrt();
    let w = if dx > 0.0 && dl > 0.0 { dl / dx } else { 1.0 };
    let blocks = match p.blocks() {
        Some(Blocks::Bodies) => (0..sys.bodies.len()).map(|b| sys.body_dofs(b).collect()).collect(),
        None => Vec::new(),
    };
    let stabilization = stabilization_for(p, sys);
    let spec = BasisSpec {
        variant: p.variant(),
        snapshots: p.file.train.snapshots,
        modes,
        multiplier_scale: w,
        blocks,
        stabilization,
    };
    let joints = joint_dofs_of(sys);
    let mut trained = train_basis(data.x.view(), data.multipliers.view(), &joints, x_ref.view(), &spec)
        .map_err(|e| ("reduction.modes", e))?;
    if let Some(tol) = hyper_tolerance {
        let hyper = ecsw(sys, &trained.basis, data.x.view(), tol)
            .map_err(|e| ("reduction.hyper", format!("ECSW training failed: {e}")))?;
        trained.basis.hyper = Some(hyper);
    }
    let estimator = build_estimator(
        sys,
        &trained,
        &spec,
        data.x.view(),
        data.multipliers.view(),
        &joints,
        x_ref.view(),
        hyper_tolerance,
        DEFAULT_EXTRA_MODES,
    )
    .map_err(|e| ("reduction", format!("cannot build the error estimator: {e}")))?;
    Ok((trained, estimator))
}

/// Trains and writes the basis file atomically (a failed run keeps the previous file).
pub fn train_and_write(p: &Pipeline, out: &Path) -> Result<TrainSummary> {
    let (data, summary) = train(p)?;
    write_trained(p, out, &data, &summary)?;
    Ok(summary)
}

/// Writes the basis file of a finished training atomically.
pub fn write_trained(p: &Pipeline, out: &Path, data: &TrainingData, summary: &TrainSummary) -> Result<()> {
    let meta = BasisMeta {
        model_text: p.model.text.clone(),
        model_path: p.model.path.display().to_string(),
        model_fingerprint: p.model.fingerprint(),
        pipeline_text: p.text.clone(),
        mode_rule: match &summary.greedy {
            Some(g) => g.mode_rule(),
            None => p.file.reduction.modes.as_ref().map(|m| m.to_string()).unwrap_or_default(),
        },
        settings_hash: p.settings_hash(),
    };
    write_basis_with(out, data, &summary.trained, &meta, |f| {
        if let Some(est) = &summary.estimator {
            crate::io::estimator_file::write_estimator(f, est).map_err(|e| Error::hdf5(out, e))?;
        }
        if let Some(g) = &summary.greedy {
            super::greedy::write_training(f, g).map_err(|e| Error::hdf5(out, e))?;
        }
        Ok(())
    })
}
