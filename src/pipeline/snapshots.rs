//! Sharded training (docs/scaling.md): the full runs of `train` as separate jobs
//! (`train --snapshots-only --load-scale X | --shard K/N -o snaps.h5`), and the basis built
//! from their snapshot files (`train --from-snapshots snaps*.h5`).
//!
//! The basis from the files is the one a single `train` builds: the runs are put side by
//! side in the order of the pipeline's `train.load_scales` (as [`super::train::train`] does),
//! whatever order the files come in, and the POD, ECSW and estimator that follow are the
//! same code on the same matrix. A full run does not depend on the process it runs in.
//!
//! What stays sequential: the POD of the whole snapshot matrix (one SVD, on one machine; its
//! memory is that of `train`), and greedy training (`train.greedy`): each greedy step picks
//! the next full run from the error estimates of the basis built from the runs before it,
//! so the full runs follow each other. Only the reduced runs over the candidates inside a
//! step are independent (a sweep); they take a small part of a step's time.
//!
//! The snapshot file (m runs of n_t instants each, runs side by side as in the basis file's
//! `/training`):
//!
//! ```text
//! /x            (n_dof, m n_t)     coordinates
//! /multipliers  (n_c, m n_t)       Lagrange multipliers
//! /load_scale   (m n_t)            each column's load scale
//! /t            (m n_t)            each column's time, s
//! /labels/...                      names of the coordinates and constraint rows
//! every dataset: units, dims ("dof, snapshot": src/io/attrs.rs)
//! attributes on /: flexrom_layout, flexrom_file = "snapshots", kind = "flexrom snapshots", model_fingerprint, settings_hash (of the
//!   pipeline: [train] and [reduction]), pipeline, full_seconds, program_version
//! ```

use super::basis_build::{basis_from_snapshots, training_data};
use super::config::Pipeline;
use super::shard::Shard;
use super::training_record::TrainSummary;
use crate::error::{Error, Result};
use crate::io::attrs::{check_layout, write_atomically_as, Kind};
use crate::io::basis_file::TrainingData;
use crate::io::h5::{attr_f64, attr_str, read_attr_f64, read_attr_str};
use crate::simulate::{simulate, Overrides, Settings};
use crate::solver::parameters::Parameters;
use ndarray::{concatenate, s, Array1, Array2, Axis};
use std::path::{Path, PathBuf};

const KIND: &str = "flexrom snapshots";

/// The training loads a `--snapshots-only` job runs: `x` alone, or the `shard` of the
/// pipeline's `train.load_scales` ([`Shard::indices`]).
pub fn job_scales(p: &Pipeline, x: Option<f64>, shard: Option<Shard>) -> Result<Vec<f64>> {
    p.refuse_box(
        "training in separate jobs (--snapshots-only, --from-snapshots)",
        "run `flexrom train` in one process",
    )?;
    match (x, shard) {
        (Some(x), None) if x.is_finite() => Ok(vec![x]),
        (Some(x), None) => Err(Error::Usage(format!("--load-scale must be finite, got {x}"))),
        (None, Some(k)) => {
            let all = fixed_scales(p)?;
            let idx = k.indices(all.len());
            if idx.is_empty() {
                return Err(Error::Usage(format!(
                    "--shard {k}: train.load_scales has {} loads, none for shard {}; use at most {} shards",
                    all.len(),
                    k.index,
                    all.len()
                )));
            }
            Ok(idx.iter().map(|&i| all[i]).collect())
        }
        _ => Err(Error::Usage("--snapshots-only needs either --load-scale X or --shard K/N".into())),
    }
}

/// The pipeline's fixed training loads (greedy training has none to split).
fn fixed_scales(p: &Pipeline) -> Result<Vec<f64>> {
    p.refuse_box(
        "training in separate jobs (--snapshots-only, --from-snapshots)",
        "run `flexrom train` in one process",
    )?;
    if p.file.train.greedy.is_some() {
        return Err(Error::input(
            &p.path,
            "train.greedy",
            "greedy training is sequential (each full run is chosen from the basis of the runs before it); \
             shard it by --load-scale runs only with train.load_scales",
        ));
    }
    let scales = p.file.train.load_scales.clone().unwrap_or_default();
    if scales.is_empty() {
        return Err(Error::input(&p.path, "train.load_scales", "is empty: no training run, no snapshots"));
    }
    Ok(scales)
}

/// Runs the full model at `scales` and writes their snapshots to `out` (atomically).
/// Returns (runs, seconds of the time loops).
pub fn write_snapshots(p: &Pipeline, scales: &[f64], out: &Path) -> Result<(usize, f64)> {
    let mut runs = Vec::new();
    let mut seconds = 0.0;
    for &x in scales {
        let mu = Parameters::load_scale(x);
        let r = simulate(&p.model, &Overrides::at(&mu))
            .map_err(|e| e.at_stage("train --snapshots-only (full run)", &mu))?;
        seconds += r.wall_seconds;
        runs.push(r);
    }
    let data = training_data(&runs);
    let settings_hash = p.settings_hash();
    let pipeline = crate::io::output::resolve(&p.path).display().to_string();
    write_atomically_as(out, Kind::Snapshots, |f| {
        let e = |err: hdf5::Error| Error::hdf5(out, err);
        crate::io::labels::Labels::of(&p.model).write(f).map_err(e)?;
        f.new_dataset_builder().with_data(&data.x.as_standard_layout()).create("x").map_err(e)?;
        f.new_dataset_builder().with_data(&data.multipliers.as_standard_layout()).create("multipliers").map_err(e)?;
        f.new_dataset_builder().with_data(&data.load_scale).create("load_scale").map_err(e)?;
        f.new_dataset_builder().with_data(&data.t).create("t").map_err(e)?;
        attr_str(f, "kind", KIND).map_err(e)?;
        attr_str(f, "model_fingerprint", &p.model.fingerprint()).map_err(e)?;
        attr_str(f, "settings_hash", &settings_hash).map_err(e)?;
        attr_str(f, "pipeline", &pipeline).map_err(e)?;
        attr_f64(f, "full_seconds", seconds).map_err(e)?;
        attr_str(f, "program_version", env!("CARGO_PKG_VERSION")).map_err(e)
    })?;
    Ok((runs.len(), seconds))
}

/// One run of a snapshot file.
struct Run {
    file: PathBuf,
    load_scale: f64,
    x: Array2<f64>,
    multipliers: Array2<f64>,
    t: Array1<f64>,
}

/// The runs of one snapshot file, checked against the pipeline (model, settings, sizes).
fn read_runs(p: &Pipeline, path: &Path, n_t: usize) -> Result<(Vec<Run>, f64)> {
    let bad = |field: &str, problem: String| Error::input(path, field, problem);
    let f = hdf5::File::open(path).map_err(|e| bad("(file)", format!("is not a readable HDF5 file: {e}")))?;
    // layouts 1 and 2 store snapshots alike (one column each)
    check_layout(&f, path, "flexrom train --snapshots-only")?;
    let text = |name: &str| read_attr_str(&f, name).map_err(|e| bad(name, format!("cannot be read: {e}")));
    if text("kind").ok().as_deref() != Some(KIND) {
        return Err(bad("kind", "is not \"flexrom snapshots\": not a file of `train --snapshots-only`".into()));
    }
    if text("model_fingerprint")? != p.model.fingerprint() {
        return Err(bad("model_fingerprint", format!("comes from another model than {}'s", p.path.display())));
    }
    if text("settings_hash")? != p.settings_hash() {
        return Err(bad(
            "settings_hash",
            format!("comes from other [train]/[reduction] settings than {}'s", p.path.display()),
        ));
    }
    let z = p.model.sizes();
    let (n_dof, n_c) = (z.n_dof as usize, z.n_constraints as usize);
    let shape = |name: &str| f.dataset(name).map(|d| d.shape()).map_err(|e| bad(name, format!("cannot be read: {e}")));
    let (sx, sm) = (shape("x")?, shape("multipliers")?);
    let cols = sx.get(1).copied().unwrap_or(0);
    if sx.len() != 2 || sx[0] != n_dof || cols == 0 || cols % n_t != 0 {
        return Err(bad("x", format!("is {sx:?}; the model needs ({n_dof}, a multiple of {n_t})")));
    }
    if sm != [n_c, cols] {
        return Err(bad("multipliers", format!("is {sm:?}, expected [{n_c}, {cols}]")));
    }
    let read2 = |name: &str| {
        f.dataset(name).and_then(|d| d.read_2d::<f64>()).map_err(|e| bad(name, format!("cannot be read: {e}")))
    };
    let read1 = |name: &str| {
        f.dataset(name).and_then(|d| d.read_1d::<f64>()).map_err(|e| bad(name, format!("cannot be read: {e}")))
    };
    let (x, mult, ls, t) = (read2("x")?, read2("multipliers")?, read1("load_scale")?, read1("t")?);
    if ls.len() != cols || t.len() != cols {
        return Err(bad("load_scale", format!("has {} entries and /t {}, for {cols} columns", ls.len(), t.len())));
    }
    let mut runs = Vec::new();
    for k in 0..cols / n_t {
        let c = s![.., k * n_t..(k + 1) * n_t];
        let col = ls.slice(s![k * n_t..(k + 1) * n_t]);
        if col.iter().any(|v| v.to_bits() != col[0].to_bits()) {
            return Err(bad("load_scale", format!("varies inside run {k} (columns of {n_t} instants)")));
        }
        runs.push(Run {
            file: path.to_path_buf(),
            load_scale: col[0],
            x: x.slice(c).to_owned(),
            multipliers: mult.slice(c).to_owned(),
            t: t.slice(s![k * n_t..(k + 1) * n_t]).to_owned(),
        });
    }
    Ok((runs, read_attr_f64(&f, "full_seconds").unwrap_or(f64::NAN)))
}

/// Builds the basis from snapshot files: every load of `train.load_scales` exactly once
/// among the files (a missing, doubled or foreign load is an error naming it), runs in the
/// pipeline's order.
pub fn train_from_snapshots(p: &Pipeline, files: &[PathBuf]) -> Result<(TrainingData, TrainSummary)> {
    let scales = fixed_scales(p)?;
    let n_t = Settings::resolve(&p.model, &Overrides::default())?.n_steps + 1;
    let z = p.model.sizes();
    let snapshots = scales.len() as f64 * n_t as f64;
    p.model.limits.check_memory(
        &format!("training on {} snapshots × {} coordinates", snapshots, z.n_dof),
        3.0 * 8.0 * snapshots * (z.n_dof + z.n_constraints) + z.n_elements * crate::limits::BYTES_PER_ELEMENT,
    )?;
    let mut runs: Vec<Run> = Vec::new();
    let mut full_seconds = 0.0;
    for f in files {
        let (r, s) = read_runs(p, f, n_t)?;
        full_seconds += s;
        for run in r {
            if !scales.iter().any(|x| x.to_bits() == run.load_scale.to_bits()) {
                return Err(Error::input(
                    &run.file,
                    "load_scale",
                    format!("{} is not in {}'s train.load_scales {scales:?}", run.load_scale, p.path.display()),
                ));
            }
            if let Some(other) = runs.iter().find(|o| o.load_scale.to_bits() == run.load_scale.to_bits()) {
                return Err(Error::input(
                    &run.file,
                    "load_scale",
                    format!("{} is also in {}: give each training load once", run.load_scale, other.file.display()),
                ));
            }
            runs.push(run);
        }
    }
    let missing: Vec<f64> =
        scales.iter().copied().filter(|x| !runs.iter().any(|r| r.load_scale.to_bits() == x.to_bits())).collect();
    if !missing.is_empty() {
        return Err(Error::Usage(format!(
            "--from-snapshots: no file holds the training load(s) {missing:?} of {}",
            p.path.display()
        )));
    }
    // the pipeline's order, as a single `train` concatenates its runs
    let ordered: Vec<&Run> =
        scales.iter().map(|x| runs.iter().find(|r| r.load_scale.to_bits() == x.to_bits()).expect("checked")).collect();
    let cat = |g: &dyn Fn(&Run) -> ndarray::ArrayView2<f64>| {
        concatenate(Axis(1), &ordered.iter().map(|r| g(r)).collect::<Vec<_>>()).expect("same row counts")
    };
    let data = TrainingData {
        x: cat(&|r| r.x.view()),
        multipliers: cat(&|r| r.multipliers.view()),
        load_scale: Array1::from_iter(ordered.iter().flat_map(|r| std::iter::repeat_n(r.load_scale, n_t))),
        t: Array1::from_iter(ordered.iter().flat_map(|r| r.t.iter().copied())),
    };
    basis_from_snapshots(p, data, full_seconds, scales.len())
}
