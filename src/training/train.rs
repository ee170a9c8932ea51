//! `train`: full runs at the training load scales → snapshot matrix → POD basis → HDF5.

use crate::error::{Error, Result};
use crate::io::atomic::TempPath;
use crate::io::attrs::Kind;
use crate::io::basis_file::{write_basis_with, BasisMeta, TrainingData};
use crate::io::output::{check_output, Origin};
use crate::linalg::kkt::LinearSolverKind;
use crate::pipeline::config::Pipeline;
use crate::simulate::{FullModel, Overrides};
use crate::solver::parameters::Parameters;
use crate::training::basis_build::joint_dofs_of;
pub use crate::training::basis_build::{build_basis, training_data};
pub use crate::training::training_record::TrainSummary;
use std::path::{Path, PathBuf};

/// The coordinates that appear in any joint, sorted.
pub fn joint_dofs(p: &Pipeline) -> Vec<usize> {
    joint_dofs_of(&p.model.system(LinearSolverKind::Banded))
}

/// Runs the training simulations and builds the basis (nothing is written); greedy
/// training (`train.greedy`) is [`crate::training::greedy::train`].
pub fn train(p: &Pipeline) -> Result<(TrainingData, TrainSummary)> {
    if let Some(g) = &p.file.train.greedy {
        return crate::training::greedy::train(p, g);
    }
    // the training runs' parameters: the load scales, or the points of the box
    let points: Vec<Parameters> = match &p.file.train.load_scales {
        Some(scales) => scales.iter().map(|&s| Parameters::load_scale(s)).collect(),
        None => p.training_points(),
    };
    if points.is_empty() {
        return Err(Error::input(&p.path, "train.load_scales", "is empty: no training run, no snapshots"));
    }
    // the runs, their concatenated snapshots and the POD's working copy
    let n_steps = crate::simulate::Settings::resolve(&p.model, &Overrides::default())?.n_steps;
    let z = p.model.sizes();
    let snapshots = points.len() as f64 * (n_steps as f64 + 1.0);
    p.model.limits.check_memory(
        &format!("training on {} snapshots × {} coordinates", snapshots, z.n_dof),
        3.0 * 8.0 * snapshots * (z.n_dof + z.n_constraints) + z.n_elements * crate::limits::BYTES_PER_ELEMENT,
    )?;
    let mut runs = Vec::new();
    let mut full_seconds = 0.0;
    // the full model assembled once for every training load
    let mut full = FullModel::new(&p.model, LinearSolverKind::Banded)?;
    for mu in &points {
        let r = full.simulate(&Overrides::at(mu)).map_err(|e| e.at_stage("train (full run)", mu))?;
        full_seconds += r.wall_seconds;
        runs.push(r);
    }
    crate::training::basis_build::basis_from_snapshots(p, training_data(&runs), full_seconds, points.len())
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
            crate::training::training_record::write_training(f, g).map_err(|e| Error::hdf5(out, e))?;
        }
        let space = p.space();
        if !space.is_empty() {
            // the runs whose snapshots the basis holds: greedy's, or the sampled points
            let runs = summary.greedy.as_ref().map_or_else(|| p.training_points(), |g| g.runs.clone());
            crate::io::parameter_space_file::write_parameter_space(f, &space, &runs)
                .map_err(|e| Error::hdf5(out, e))?;
        }
        Ok(())
    })
}

/// `train` as a whole: checks that `out` may be written (not an input of the pipeline, not
/// a file flexrom did not create: [`check_output`], `origin` names where the path came
/// from), trains (from the full runs, or from the snapshot files `from_snapshots` when
/// given) into a temporary file beside `out`, reads that back and checks it as every
/// reader of a basis does, times the full and the reduced route at a training load into
/// its `/timing` ([`crate::cost::route::time_and_store`]), and only then renames it over `out`:
/// a failure at any stage leaves the previous basis as it was.
pub fn train_to_file(p: &Pipeline, out: &Path, origin: Origin, from_snapshots: &[PathBuf]) -> Result<TrainSummary> {
    check_output(out, origin, &[(&p.path, "pipeline file"), (&p.model.path, "model file")], &[Kind::Basis])?;
    let staged = TempPath::file_for(out)?;
    let s = stage(p, &staged, out, from_snapshots).map_err(|e| as_written(e, staged.path(), out))?;
    staged.commit()?;
    Ok(s)
}

/// Trains into the temporary file `staged`, reads it back and times both routes.
fn stage(p: &Pipeline, staged: &TempPath, out: &Path, from_snapshots: &[PathBuf]) -> Result<TrainSummary> {
    let mut s = if from_snapshots.is_empty() {
        train_and_write(p, staged.path())?
    } else {
        for f in from_snapshots {
            if crate::io::output::resolve(f) == crate::io::output::resolve(out) {
                return Err(Error::input(out, "--basis", "is one of the --from-snapshots files"));
            }
        }
        let (data, s) = crate::training::snapshots::train_from_snapshots(p, from_snapshots)?;
        write_trained(p, staged.path(), &data, &s)?;
        s
    };
    // read back and checked as every reader does, then both routes timed as users run them
    let (stored, rom, _) = crate::workflows::online::load_rom(p, staged.path(), None, false)?;
    s.warnings.extend(crate::cost::route::time_and_store(&stored, &rom, staged.path())?);
    Ok(s)
}

/// An error about the temporary basis names the basis the user asked for, which keeps its
/// previous content: the temporary name is gone by the time the message is read.
fn as_written(e: Error, tmp: &Path, out: &Path) -> Error {
    let tmp = tmp.display().to_string();
    let named = || format!("{} (the basis just trained; not written)", out.display());
    match e {
        Error::Input { file, field, problem } if file == tmp => Error::Input { file: named(), field, problem },
        Error::Hdf5 { file, problem } if file == tmp => Error::Hdf5 { file: named(), problem },
        Error::Io { file, source } if file == tmp => Error::Io { file: named(), source },
        Error::Hinted { source, hint } => {
            Error::Hinted { source: Box::new(as_written(*source, tmp.as_ref(), out)), hint }
        }
        other => other,
    }
}
