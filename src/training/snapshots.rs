//! Sharded training (docs/scaling.md): the full runs of `train` as separate jobs
//! (`train --snapshots-only --load-scale X | --shard K/N -o snaps.h5`), and the basis built
//! from their snapshot files (`train --from-snapshots snaps*.h5`).
//!
//! The basis from the files is the one a single `train` builds: the runs are put side by
//! side in the order of the pipeline's `train.load_scales` (as [`crate::training::train::train`] does),
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
//! /point_index  (m)                a pipeline with a [parameters] box only: each run's index
//!                                  in the pipeline's training points (`train.points`)
//! /points       (m, d)             and its parameters (attribute `parameters`, the names)
//! /labels/...                      names of the coordinates and constraint rows
//! every dataset: units, dims ("dof, snapshot": src/io/attrs.rs)
//! attributes on /: flexrom_layout, flexrom_file = "snapshots", kind = "flexrom snapshots", model_fingerprint, settings_hash (of the
//!   pipeline: [train] and [reduction]), pipeline, full_seconds, program_version
//! ```

use crate::error::{Error, Result, Text};
use crate::io::attrs::{check_layout, write_atomically_as, Kind};
use crate::io::basis_file::TrainingData;
use crate::io::h5::{attr_f64, attr_str, read_attr_f64, read_attr_str};
use crate::pipeline::config::Pipeline;
use crate::simulate::{simulate, Overrides, Settings};
use crate::solver::parameters::Parameters;
use crate::training::basis_build::{basis_from_snapshots, training_data};
use crate::training::training_record::TrainSummary;
use crate::workflows::shard::Shard;
use ndarray::{concatenate, s, Array1, Array2, Axis};
use std::path::{Path, PathBuf};

const KIND: &str = "flexrom snapshots";

/// The training runs a `--snapshots-only` job makes: the load scale `x` alone, or the
/// `shard` of the pipeline's `train.load_scales` ([`Shard::indices`]), or of its
/// `train.points` for a pipeline with a `[parameters]` box.
pub fn job_points(p: &Pipeline, x: Option<f64>, shard: Option<Shard>) -> Result<Vec<Parameters>> {
    match (x, shard) {
        (Some(_), None) if !p.file.parameters.is_empty() => Err(Error::input(
            &p.path,
            "parameters",
            Text::new("trains at the points of its box: split them with ")
                .option("shard", Some("K/N"))
                .then(", not ")
                .option("load_scale", None),
        )),
        (Some(x), None) if x.is_finite() => Ok(vec![Parameters::load_scale(x)]),
        (Some(x), None) => Err(Error::option("load_scale", None, format!("must be finite, got {x}"))),
        (None, Some(k)) => {
            let all = fixed_points(p)?;
            let idx = k.indices(all.len());
            if idx.is_empty() {
                let what = if p.file.parameters.is_empty() { "train.load_scales has" } else { "train.points has" };
                return Err(Error::option(
                    "shard",
                    Some(k.to_string()),
                    format!("{what} {} runs, none for shard {}; use at most {} shards", all.len(), k.index, all.len()),
                ));
            }
            Ok(idx.iter().map(|&i| all[i].clone()).collect())
        }
        _ => Err(Error::option(
            "snapshots_only",
            None,
            Text::new("needs either ").option("load_scale", Some("X")).then(" or ").option("shard", Some("K/N")),
        )),
    }
}

/// The pipeline's fixed training runs: its load scales, or the points of its box (greedy
/// training has none to split).
fn fixed_points(p: &Pipeline) -> Result<Vec<Parameters>> {
    if p.file.train.greedy.is_some() {
        return Err(Error::input(
            &p.path,
            "train.greedy",
            Text::new(
                "greedy training is sequential (each full run is chosen from the basis of the runs before it); \
                 shard it by ",
            )
            .option("load_scale", None)
            .then(" runs only with train.load_scales"),
        ));
    }
    if !p.file.parameters.is_empty() {
        return Ok(p.training_points());
    }
    let scales = p.file.train.load_scales.clone().unwrap_or_default();
    if scales.is_empty() {
        return Err(Error::input(&p.path, "train.load_scales", "is empty: no training run, no snapshots"));
    }
    Ok(scales.into_iter().map(Parameters::load_scale).collect())
}

/// Runs the full model at `points` and writes their snapshots to `out` (atomically); for a
/// pipeline with a box, each run's index among its training points too. Returns (runs,
/// seconds of the time loops).
pub fn write_snapshots(p: &Pipeline, points: &[Parameters], out: &Path) -> Result<(usize, f64)> {
    let space = p.space();
    // where each run lies in the box's training points (they come from that list)
    let index: Vec<u64> = if space.is_empty() {
        Vec::new()
    } else {
        let all = p.training_points();
        points
            .iter()
            .map(|mu| all.iter().position(|a| a == mu).map(|i| i as u64))
            .collect::<Option<_>>()
            .ok_or_else(|| Error::usage("--snapshots-only: a point is not among the pipeline's training points"))?
    };
    let mut runs = Vec::new();
    let mut seconds = 0.0;
    for mu in points {
        let r =
            simulate(&p.model, &Overrides::at(mu)).map_err(|e| e.at_stage("train --snapshots-only (full run)", mu))?;
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
        if !index.is_empty() {
            f.new_dataset_builder().with_data(&Array1::from(index.clone())).create("point_index").map_err(e)?;
            let names: Vec<&str> = space.names().collect();
            let table =
                Array2::from_shape_fn((points.len(), names.len()), |(k, j)| points[k].get(names[j]).unwrap_or(1.0));
            let d = f.new_dataset_builder().with_data(&table).create("points").map_err(e)?;
            attr_str(&d, "parameters", &names.join(",")).map_err(e)?;
        }
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
    /// the run's index among a box pipeline's training points (`/point_index`)
    point: Option<usize>,
    x: Array2<f64>,
    multipliers: Array2<f64>,
    t: Array1<f64>,
}

/// The runs of one snapshot file, checked against the pipeline (model, settings, sizes).
fn read_runs(p: &Pipeline, path: &Path, n_t: usize) -> Result<(Vec<Run>, f64)> {
    let bad = |field: &str, problem: String| Error::input(path, field, problem);
    let f = crate::io::h5_open::open(path).map_err(|e| bad("(file)", crate::io::h5_open::unreadable(&e)))?;
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
    // the file alone sets the number of columns: bounded before they are read
    p.model
        .limits
        .check_memory(&format!("its {cols} snapshots"), 8.0 * cols as f64 * (n_dof + n_c + 2) as f64)
        .map_err(|e| bad("x", e.to_string()))?;
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
    let index: Option<Vec<usize>> = match f.dataset("point_index") {
        Ok(d) => {
            let i = d.read_1d::<u64>().map_err(|e| bad("point_index", format!("cannot be read: {e}")))?;
            if i.len() != cols / n_t {
                return Err(bad("point_index", format!("has {} entries for {} runs", i.len(), cols / n_t)));
            }
            Some(i.iter().map(|&k| k as usize).collect())
        }
        Err(_) => None,
    };
    check_values(p, &x, &mult, n_t).map_err(|(field, problem)| bad(field, problem))?;
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
            point: index.as_ref().map(|i| i[k]),
            x: x.slice(c).to_owned(),
            multipliers: mult.slice(c).to_owned(),
            t: t.slice(s![k * n_t..(k + 1) * n_t]).to_owned(),
        });
    }
    Ok((runs, read_attr_f64(&f, "full_seconds").unwrap_or(f64::NAN)))
}

/// The snapshots' values as a run makes them: finite, and each run starting from the model's
/// consistent initial state (to the tolerance the basis check holds the basis's reference to):
/// an altered file is named here, not by the check of the basis built from it.
fn check_values(
    p: &Pipeline,
    x: &ndarray::Array2<f64>,
    mult: &ndarray::Array2<f64>,
    n_t: usize,
) -> std::result::Result<(), (&'static str, String)> {
    for (name, a) in [("x", x), ("multipliers", mult)] {
        if let Some(((i, j), v)) = a.indexed_iter().find(|(_, v)| !v.is_finite()) {
            return Err((name, format!("entry ({i}, {j}) is {v}: snapshots of a run are finite")));
        }
    }
    let physics = p.model.physics().map_err(|e| ("x", format!("cannot compute the model's initial state: {e}")))?;
    let x0: &[f64] = &physics.x0;
    let tol = crate::io::basis_check::REFERENCE_TOLERANCE * x0.iter().fold(1.0_f64, |a, v| a.max(v.abs()));
    for k in 0..x.ncols() / n_t {
        let first = x.column(k * n_t);
        if let Some((i, d)) = first.iter().zip(x0).map(|(a, b)| (a - b).abs()).enumerate().find(|(_, d)| !(*d <= tol)) {
            return Err((
                "x",
                format!(
                    "column {} (the start of run {k}) differs from the model's initial state by {d:.3e} at coordinate {i} (limit {tol:.1e}): not the snapshots of a run of this model",
                    k * n_t
                ),
            ));
        }
    }
    Ok(())
}

/// Builds the basis from snapshot files: every run of `train.load_scales` (or of a box's
/// `train.points`) exactly once among the files (a missing, doubled or foreign run is an
/// error naming it), runs in the pipeline's order.
pub fn train_from_snapshots(p: &Pipeline, files: &[PathBuf]) -> Result<(TrainingData, TrainSummary)> {
    let points = fixed_points(p)?;
    let in_box = !p.file.parameters.is_empty();
    let n_t = Settings::resolve(&p.model, &Overrides::default())?.n_steps + 1;
    let z = p.model.sizes();
    let snapshots = points.len() as f64 * n_t as f64;
    p.model.limits.check_memory(
        &format!("training on {} snapshots × {} coordinates", snapshots, z.n_dof),
        3.0 * 8.0 * snapshots * (z.n_dof + z.n_constraints) + z.n_elements * crate::limits::BYTES_PER_ELEMENT,
    )?;
    // which training run a file's run is: its load scale on a line, its point index in a box
    let slot = |run: &Run| -> Result<usize> {
        let found = if in_box {
            run.point.filter(|&i| i < points.len())
        } else {
            points.iter().position(|mu| mu.scale().to_bits() == run.load_scale.to_bits())
        };
        found.ok_or_else(|| match (in_box, run.point) {
            (true, None) => Error::input(
                &run.file,
                "point_index",
                format!("is missing: not a snapshot file of {}'s box (written for a line of loads?)", p.path.display()),
            ),
            (true, Some(i)) => Error::input(
                &run.file,
                "point_index",
                format!("{i} is not one of the {} training points of {}", points.len(), p.path.display()),
            ),
            (false, _) => Error::input(
                &run.file,
                "load_scale",
                format!(
                    "{} is not in {}'s train.load_scales {:?}",
                    run.load_scale,
                    p.path.display(),
                    points.iter().map(Parameters::scale).collect::<Vec<_>>()
                ),
            ),
        })
    };
    let mut held: Vec<Option<Run>> = (0..points.len()).map(|_| None).collect();
    let mut full_seconds = 0.0;
    for f in files {
        let (r, s) = read_runs(p, f, n_t)?;
        full_seconds += s;
        for run in r {
            let k = slot(&run)?;
            if let Some(other) = &held[k] {
                let what = if in_box { format!("training point {k}") } else { format!("{}", run.load_scale) };
                return Err(Error::input(
                    &run.file,
                    if in_box { "point_index" } else { "load_scale" },
                    format!("{what} is also in {}: give each training run once", other.file.display()),
                ));
            }
            held[k] = Some(run);
        }
    }
    let missing: Vec<usize> = (0..points.len()).filter(|&k| held[k].is_none()).collect();
    if !missing.is_empty() {
        let what = if in_box {
            let named = missing.iter().map(|&k| format!("{k} ({})", p.space().label(&points[k])));
            format!("training point(s) {}", named.collect::<Vec<_>>().join(", "))
        } else {
            format!("training load(s) {:?}", missing.iter().map(|&k| points[k].scale()).collect::<Vec<_>>())
        };
        return Err(Error::usage(format!("--from-snapshots: no file holds the {what} of {}", p.path.display())));
    }
    // the pipeline's order, as a single `train` concatenates its runs
    let ordered: Vec<&Run> = held.iter().map(|r| r.as_ref().expect("checked above")).collect();
    let cat = |g: &dyn Fn(&Run) -> ndarray::ArrayView2<f64>| {
        concatenate(Axis(1), &ordered.iter().map(|r| g(r)).collect::<Vec<_>>()).expect("same row counts")
    };
    let data = TrainingData {
        x: cat(&|r| r.x.view()),
        multipliers: cat(&|r| r.multipliers.view()),
        load_scale: Array1::from_iter(ordered.iter().flat_map(|r| std::iter::repeat_n(r.load_scale, n_t))),
        t: Array1::from_iter(ordered.iter().flat_map(|r| r.t.iter().copied())),
    };
    basis_from_snapshots(p, data, full_seconds, points.len())
}
