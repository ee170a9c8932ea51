//! `sweep`: reduced runs at many load scales, in parallel across cores (rayon; BLAS stays
//! on one thread inside each run), optionally validated against full runs.
//!
//! One load scale that fails (Newton, a singular matrix) does not stop the sweep: its status
//! and message are stored and the others run on. The file is written as the sweep goes
//! (rewritten whole, atomically, after the first finished scale, then at most every
//! [`CHECKPOINT_SECONDS`] or more when writing is slow, and at the end), so a
//! killed sweep leaves a valid file of the finished scales at the final path; `--resume`
//! ([`sweep_to_file`]) takes the finished scales from it and runs the rest.
//!
//! The sweep file (N load scales; rows of scales that failed or did not run yet hold NaN,
//! and 0 in the counters):
//!
//! ```text
//! /load_scales        (N)
//! /status             (N)            0 = ok, 1 = failed, 2 = not run yet
//! /message            (N)            why it failed ("" when ok)
//! /t                  (n_t)
//! /probes/<name>      (N, n_t, 2)    reduced-model probe positions, m
//! /reduced_q          (N, n_t, r)    reduced coordinates (time first; layout 1: (N, r, n_t))
//! /rom_seconds        (N)            reduced time loop of each run
//! /newton_iterations  (N)
//! /factorizations     (N)            iteration matrices factorized
//! /error_estimate     (N)            the estimate of rel_error of each run (NaN: no estimator)
//! /error_estimate_by_time (N, 5)     the estimate up to the end of each fifth of the run (the
//!                                    last column is /error_estimate; NaN: no estimator)
//! /extrapolated       (N)            1 where the load scale is outside the training range
//! /estimate_seconds   (N)            the estimator's enriched run and norms, s
//! with --validate:    /rel_error, /max_probe_error, /max_constraint_violation,
//!                     /full_seconds, /speedup  (N each)
//! every dataset: units, dims (src/io/attrs.rs)
//! attributes on /: flexrom_layout, flexrom_file = "sweep", basis, basis_content_hash, model_fingerprint, variant, n_modes,
//!   validated (0/1), wall_seconds (whole sweep), threads, continuation (1 when the runs
//!   were continued from their neighbours), n_failed, n_pending, program_version
//! ```

use super::estimate::{is_extrapolated, Estimate, EstimatingRunner, TrustInfo};
use super::online::{Output, ReducedRun};
use super::validate::{compare, Validation};
use crate::error::{Error, Result};
use crate::io::attrs::{check_layout, write_atomically_as, Kind};
use crate::io::basis_file::StoredBasis;
use crate::io::h5::{attr_f64, attr_str, attr_u64, read_attr_str};
use crate::model::Model;
use crate::reduction::Basis;
use crate::simulate::{simulate, Overrides, Settings, SimulationResult};
use crate::solver::generalized_alpha::Stats;
use hdf5::types::VarLenUnicode;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use ndarray::{Array1, Array2, Array3};
use rayon::prelude::*;
use std::path::Path;
use std::sync::Mutex;

/// The sweep file is rewritten at most this often while the sweep runs, and at most every
/// [`CHECKPOINT_COST_FACTOR`] times the last rewrite's duration: rewriting takes at most
/// 1/50 = 2 % of the sweep's time (four-bar, 100 scales: a 9.4 MB file).
pub const CHECKPOINT_SECONDS: f64 = 2.0;
pub const CHECKPOINT_COST_FACTOR: f64 = 50.0;

/// Status codes of `/status`.
pub const STATUS_OK: u8 = 0;
pub const STATUS_FAILED: u8 = 1;
pub const STATUS_PENDING: u8 = 2;

pub struct SweepPoint {
    pub rom: ReducedRun,
    pub validation: Option<Validation>,
    /// the run's error estimate (None: no estimator)
    pub estimate: Option<Estimate>,
    /// outside the training range
    pub extrapolated: bool,
}

/// What became of one load scale.
// one per load scale, built once and moved into place: the size difference costs nothing
#[allow(clippy::large_enum_variant)]
pub enum Outcome {
    Done(SweepPoint),
    /// the error message of its run
    Failed(String),
    /// not run (yet)
    Pending,
}

pub struct ScaleResult {
    pub load_scale: f64,
    pub outcome: Outcome,
}

impl ScaleResult {
    pub fn point(&self) -> Option<&SweepPoint> {
        match &self.outcome {
            Outcome::Done(p) => Some(p),
            _ => None,
        }
    }

    pub fn status(&self) -> u8 {
        match self.outcome {
            Outcome::Done(_) => STATUS_OK,
            Outcome::Failed(_) => STATUS_FAILED,
            Outcome::Pending => STATUS_PENDING,
        }
    }

    pub fn message(&self) -> &str {
        match &self.outcome {
            Outcome::Done(_) => "",
            Outcome::Failed(m) => m,
            Outcome::Pending => "not run yet",
        }
    }
}

pub struct Sweep {
    /// every requested load scale, in the order asked for
    pub scales: Vec<ScaleResult>,
    /// the time grid and probe names every run shares (from the model)
    pub t: Array1<f64>,
    pub probe_names: Vec<String>,
    /// reduced coordinates r
    pub n_reduced: usize,
    pub validated: bool,
    pub wall_seconds: f64,
    pub threads: usize,
    pub continuation: bool,
    /// scales taken from an earlier sweep file (`--resume`)
    pub resumed: usize,
}

impl Sweep {
    /// The load scales that ran to the end, in order.
    pub fn done(&self) -> impl Iterator<Item = &SweepPoint> {
        self.scales.iter().filter_map(ScaleResult::point)
    }

    pub fn n_failed(&self) -> usize {
        self.scales.iter().filter(|s| s.status() == STATUS_FAILED).count()
    }

    /// One line when some load scale failed, naming the first few and their errors:
    /// "2 of 100 load scales failed: load scale 1e20: Newton failed at …; …".
    pub fn failure_summary(&self) -> Option<String> {
        let failed: Vec<&ScaleResult> = self.scales.iter().filter(|s| s.status() == STATUS_FAILED).collect();
        if failed.is_empty() {
            return None;
        }
        // each message names its stage and load scale already (`Error::at_stage`)
        let shown: Vec<String> = failed.iter().take(3).map(|s| s.message().to_string()).collect();
        let more = if failed.len() > 3 { format!("; and {} more", failed.len() - 3) } else { String::new() };
        Some(format!("{} of {} load scales failed: {}{more}", failed.len(), self.scales.len(), shown.join("; ")))
    }
}

/// How a sweep runs (default: independent runs, no validation, no progress bar).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SweepOptions {
    /// also run the full model at every load scale and compare
    pub validate: bool,
    /// continuation in the load scale: each thread takes two contiguous parts of the list
    /// (one from each end) and starts every Newton solve from the previous points'
    /// increments
    /// ([`super::online::ReducedRunner::run`]); off (the default): every load scale on its own, exactly as
    /// `online` runs it
    pub continuation: bool,
    /// a progress bar on stderr
    pub progress: bool,
}

/// The chains of a continuation sweep over `n` scales, by thread: the list cut into `2 T`
/// contiguous blocks, thread t taking block t and block 2T − 1 − t (one from each end).
/// The cost of a run usually grows or falls along the list with the load, so each thread
/// gets a cheap and a dear block (four-bar, 100 scales: the threads' time loops 0.75 and
/// 1.09 s with one block each, balanced with two). Fixed by n and T alone, so a sweep
/// repeats exactly on the same machine.
fn continuation_lanes(n: usize, threads: usize) -> Vec<Vec<std::ops::Range<usize>>> {
    let part = n.div_ceil(2 * threads.max(1)).max(1);
    let blocks: Vec<std::ops::Range<usize>> = (0..n).step_by(part).map(|a| a..(a + part).min(n)).collect();
    let nb = blocks.len();
    (0..nb.div_ceil(2))
        .map(|t| {
            if t == nb - 1 - t {
                vec![blocks[t].clone()]
            } else {
                vec![blocks[t].clone(), blocks[nb - 1 - t].clone()]
            }
        })
        .collect()
}

/// Runs the reduced model at every scale, in parallel; with `validate`, also the full one.
/// A scale whose run fails is recorded as failed and the others go on.
pub fn sweep(model: &Model, basis: &Basis, scales: &[f64], o: SweepOptions) -> Result<Sweep> {
    sweep_with(model, basis, None, scales, o)
}

/// [`sweep`] with the basis's estimator and training range: every point gets its error
/// estimate and extrapolation flag.
pub fn sweep_with(
    model: &Model,
    basis: &Basis,
    trust: Option<&TrustInfo>,
    scales: &[f64],
    o: SweepOptions,
) -> Result<Sweep> {
    let start = pending(model, basis, scales, o)?;
    run_pending(model, basis, trust, start, o, None)
}

/// [`sweep`] writing `out` as it goes (see the module documentation); with `resume`, the
/// scales that `out` already holds as finished (same basis content and model) are taken
/// from it, and only the others run. The returned sweep is written to `out`.
#[allow(clippy::too_many_arguments)]
pub fn sweep_to_file(
    model: &Model,
    stored: &StoredBasis,
    trust: Option<&TrustInfo>,
    basis_path: &Path,
    scales: &[f64],
    o: SweepOptions,
    out: &Path,
    resume: bool,
) -> Result<Sweep> {
    sweep_to_file_with(model, stored, trust, basis_path, scales, o, out, resume, &|_| Ok(()))
}

/// Extra content written into every version of a sweep file (a shard's `/shard` group).
pub type Extra<'a> = &'a (dyn Fn(&hdf5::File) -> Result<()> + Sync);

/// [`sweep_to_file`] with `extra` written into the file at every checkpoint.
#[allow(clippy::too_many_arguments)]
pub fn sweep_to_file_with(
    model: &Model,
    stored: &StoredBasis,
    trust: Option<&TrustInfo>,
    basis_path: &Path,
    scales: &[f64],
    o: SweepOptions,
    out: &Path,
    resume: bool,
    extra: Extra,
) -> Result<Sweep> {
    let basis = &stored.basis;
    let mut start = pending(model, basis, scales, o)?;
    if resume {
        if out.exists() {
            let old = read_sweep(out, model, stored, o.validate)?;
            let mut reused = 0;
            for s in start.scales.iter_mut() {
                if let Some(i) = old.iter().position(|(x, _)| *x == s.load_scale) {
                    if let Some(p) = old[i].1.as_ref() {
                        s.outcome = Outcome::Done(clone_point(p));
                        reused += 1;
                    }
                }
            }
            start.resumed = reused;
            let dropped = old.iter().filter(|(x, p)| p.is_some() && !scales.contains(x)).count();
            crate::output::info(&format!(
                "resuming {}: {reused} of {} load scales already finished, running {}{}",
                out.display(),
                scales.len(),
                scales.len() - reused,
                if dropped > 0 {
                    format!(" ({dropped} finished load scales of the file are not in the list and are left out)")
                } else {
                    String::new()
                }
            ));
        } else {
            crate::output::info(&format!(
                "resuming {}: no such file yet, running all {} load scales",
                out.display(),
                scales.len()
            ));
        }
    }
    let write = |s: &Sweep| write_sweep_with(out, s, stored, basis_path, extra);
    let sw = run_pending(model, basis, trust, start, o, Some(&write))?;
    write(&sw)?;
    Ok(sw)
}

/// Every scale pending, with the model's time grid and probe names.
fn pending(model: &Model, basis: &Basis, scales: &[f64], o: SweepOptions) -> Result<Sweep> {
    let s = Settings::resolve(model, &Overrides::default())?;
    let t = Array1::from_iter((0..=s.n_steps).map(|k| k as f64 * s.dt));
    Ok(Sweep {
        scales: scales.iter().map(|&x| ScaleResult { load_scale: x, outcome: Outcome::Pending }).collect(),
        t,
        probe_names: model.probe_names(),
        n_reduced: basis.n_reduced(),
        validated: o.validate,
        wall_seconds: 0.0,
        threads: rayon::current_num_threads().max(1),
        continuation: o.continuation,
        resumed: 0,
    })
}

type Checkpoint<'a> = &'a (dyn Fn(&Sweep) -> Result<()> + Sync);

/// Runs the pending scales of `state`; after each one, `checkpoint` (when given, and at
/// most every [`CHECKPOINT_SECONDS`]) writes what is done so far.
fn run_pending(
    model: &Model,
    basis: &Basis,
    trust: Option<&TrustInfo>,
    state: Sweep,
    o: SweepOptions,
    checkpoint: Option<Checkpoint>,
) -> Result<Sweep> {
    let est = trust.and_then(|t| t.estimator.as_ref());
    let todo: Vec<usize> = (0..state.scales.len()).filter(|&i| state.scales[i].status() != STATUS_OK).collect();
    let scales: Vec<f64> = todo.iter().map(|&i| state.scales[i].load_scale).collect();
    let bar = ProgressBar::with_draw_target(
        Some(scales.len() as u64),
        if o.progress { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() },
    );
    bar.set_style(
        ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} load scales, {elapsed} elapsed, ETA {eta}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_prefix(if o.validate { "sweep + validate" } else { "sweep" });
    let ticker = crate::output::ticker::Ticker::new(
        if o.validate { "sweep + validate" } else { "sweep" },
        scales.len() as u64,
        o.progress,
    );
    // every point's trajectories are kept until the file is written
    let n_steps = crate::simulate::Settings::resolve(model, &Overrides::default())?.n_steps;
    let output = if o.validate { Output::Full } else { Output::ReducedAndProbes };
    super::online::check_reduced_memory(model, basis.n_reduced(), n_steps, output, scales.len() as f64)?;
    let start = std::time::Instant::now();
    let threads = state.threads;
    // continuation: a few chains of neighbouring scales per thread; otherwise one point per task
    let lanes = if o.continuation {
        continuation_lanes(scales.len(), threads)
    } else {
        (0..scales.len()).map(|i| std::iter::once(i..i + 1).collect()).collect()
    };
    // the sweep so far, and when the next write is due (None: now, so the first finished
    // scale is written at once)
    let shared = Mutex::new((state, None::<std::time::Instant>));
    let record = |i: usize, outcome: Outcome| -> Result<()> {
        let mut guard = shared.lock().unwrap_or_else(|e| e.into_inner());
        let (sw, due) = &mut *guard;
        sw.scales[todo[i]].outcome = outcome;
        if let Some(write) = checkpoint {
            if due.is_none_or(|d| std::time::Instant::now() >= d) {
                sw.wall_seconds = start.elapsed().as_secs_f64();
                let began = std::time::Instant::now();
                write(sw)?;
                let wait = CHECKPOINT_SECONDS.max(CHECKPOINT_COST_FACTOR * began.elapsed().as_secs_f64());
                *due = Some(std::time::Instant::now() + std::time::Duration::from_secs_f64(wait));
            }
        }
        Ok(())
    };
    let results: Result<Vec<()>> = lanes
        .par_iter()
        // one reduced model per worker, built at its first lane, its loads changed per scale
        .map_init(
            || None,
            |slot: &mut Option<EstimatingRunner>, chains| {
                let runner = match slot {
                    Some(r) => r,
                    // built at the model's own load scale, 1
                    None => slot.insert(
                        EstimatingRunner::new(model, basis, est)
                            .map_err(|e| e.at_stage("sweep (building the reduced model)", 1.0))?,
                    ),
                };
                for chain in chains {
                    // the last two good runs of this chain (continuation only)
                    let mut previous: Vec<ReducedRun> = Vec::new();
                    for i in chain.clone() {
                        let x = scales[i];
                        // without validation nothing of full size is reconstructed
                        let output = if o.validate { Output::Full } else { Output::ReducedAndProbes };
                        let run = (|| -> Result<SweepPoint> {
                            let (rom, estimate) = runner
                                .run_with(x, output, &previous.iter().collect::<Vec<_>>())
                                .map_err(|e| e.at_stage("sweep (reduced run)", x))?;
                            let validation = if o.validate {
                                let full = simulate(model, &Overrides { load_scale: Some(x), ..Default::default() })
                                    .map_err(|e| e.at_stage("sweep (full run)", x))?;
                                Some(
                                    compare(model, &full, &rom, None, basis.n_reduced(), basis.variant.name())
                                        .with_trust(estimate.as_ref(), trust),
                                )
                            } else {
                                None
                            };
                            let extrapolated = trust.is_some_and(|t| is_extrapolated(t.range, x));
                            Ok(SweepPoint { rom, validation, estimate, extrapolated })
                        })();
                        bar.inc(1);
                        ticker.tick();
                        match run {
                            Ok(p) => {
                                if o.continuation {
                                    previous.push(p.rom.clone());
                                    if previous.len() > 2 {
                                        previous.remove(0);
                                    }
                                }
                                record(i, Outcome::Done(p))?;
                            }
                            Err(e) => record(i, Outcome::Failed(e.to_string()))?,
                        }
                    }
                }
                Ok(())
            },
        )
        .collect();
    bar.finish_and_clear();
    results?;
    let (mut sw, _) = shared.into_inner().unwrap_or_else(|e| e.into_inner());
    sw.wall_seconds = start.elapsed().as_secs_f64();
    Ok(sw)
}

fn clone_point(p: &SweepPoint) -> SweepPoint {
    SweepPoint {
        rom: p.rom.clone(),
        validation: p.validation.clone(),
        estimate: p.estimate,
        extrapolated: p.extrapolated,
    }
}

/// Writes the sweep file (atomically: a temporary file renamed over `path`).
pub fn write_sweep(path: &Path, s: &Sweep, stored: &StoredBasis, basis_path: &Path) -> Result<()> {
    write_sweep_with(path, s, stored, basis_path, &|_| Ok(()))
}

/// [`write_sweep`] with `extra` written into the file before it is renamed into place.
pub fn write_sweep_with(path: &Path, s: &Sweep, stored: &StoredBasis, basis_path: &Path, extra: Extra) -> Result<()> {
    let basis = &stored.basis;
    let (n, nt, r) = (s.scales.len(), s.t.len(), s.n_reduced);
    if n == 0 {
        return Err(Error::Usage("the sweep has no load scales".into()));
    }
    write_atomically_as(path, Kind::Sweep, |f| {
        let e = |err: hdf5::Error| Error::hdf5(path, err);
        // one value per load scale: NaN where it did not run to the end
        let col =
            |g: &dyn Fn(&SweepPoint) -> f64| Array1::from_iter(s.scales.iter().map(|x| x.point().map_or(f64::NAN, g)));
        let count = |g: &dyn Fn(&SweepPoint) -> usize| {
            Array1::from_iter(s.scales.iter().map(|x| x.point().map_or(0, g) as u64))
        };
        f.new_dataset_builder()
            .with_data(&Array1::from_iter(s.scales.iter().map(|x| x.load_scale)))
            .create("load_scales")
            .map_err(e)?;
        f.new_dataset_builder()
            .with_data(&Array1::from_iter(s.scales.iter().map(ScaleResult::status)))
            .create("status")
            .map_err(e)?;
        let messages: Vec<VarLenUnicode> = s
            .scales
            .iter()
            .map(|x| x.message().replace('\0', " ").parse::<VarLenUnicode>().unwrap_or_default())
            .collect();
        f.new_dataset_builder().with_data(&Array1::from(messages)).create("message").map_err(e)?;
        f.new_dataset_builder().with_data(&s.t).create("t").map_err(e)?;
        let g = f.create_group("probes").map_err(e)?;
        for (i, name) in s.probe_names.iter().enumerate() {
            let mut a = Array3::from_elem((n, nt, 2), f64::NAN);
            for (k, x) in s.scales.iter().enumerate() {
                if let Some(p) = x.point() {
                    a.index_axis_mut(ndarray::Axis(0), k).assign(&p.rom.result.probes[i].1);
                }
            }
            g.new_dataset_builder().with_data(&a).create(name.as_str()).map_err(e)?;
        }
        // time first: (load, time, mode); the runs keep r × n_t
        let mut zq = Array3::from_elem((n, nt, r), f64::NAN);
        for (k, x) in s.scales.iter().enumerate() {
            if let Some(p) = x.point() {
                zq.index_axis_mut(ndarray::Axis(0), k).assign(&p.rom.reduced_q.t());
            }
        }
        // one chunk per run, not compressed: deflate took 15 % off the size of these
        // trajectories for 0.15 s of a 1.5 s four-bar sweep
        f.new_dataset_builder().chunk((1, nt.max(1), r.max(1))).with_data(&zq).create("reduced_q").map_err(e)?;
        f.new_dataset_builder().with_data(&col(&|p| p.rom.result.wall_seconds)).create("rom_seconds").map_err(e)?;
        f.new_dataset_builder()
            .with_data(&count(&|p| p.rom.result.stats.newton_iterations))
            .create("newton_iterations")
            .map_err(e)?;
        f.new_dataset_builder()
            .with_data(&count(&|p| p.rom.result.stats.factorizations))
            .create("factorizations")
            .map_err(e)?;
        f.new_dataset_builder()
            .with_data(&col(&|p| p.estimate.map_or(f64::NAN, |e| e.error_estimate)))
            .create("error_estimate")
            .map_err(e)?;
        let mut by_time = Array2::from_elem((n, 5), f64::NAN);
        for (k, x) in s.scales.iter().enumerate() {
            if let Some(est) = x.point().and_then(|p| p.estimate) {
                by_time.row_mut(k).assign(&ndarray::ArrayView1::from(&est.by_time));
            }
        }
        f.new_dataset_builder().with_data(&by_time).create("error_estimate_by_time").map_err(e)?;
        f.new_dataset_builder()
            .with_data(&col(&|p| p.estimate.map_or(f64::NAN, |e| e.seconds)))
            .create("estimate_seconds")
            .map_err(e)?;
        f.new_dataset_builder()
            .with_data(&Array1::from_iter(s.scales.iter().map(|x| x.point().is_some_and(|p| p.extrapolated) as u8)))
            .create("extrapolated")
            .map_err(e)?;
        if s.validated {
            let v = |g: &dyn Fn(&Validation) -> f64| col(&|p: &SweepPoint| p.validation.as_ref().map_or(f64::NAN, g));
            f.new_dataset_builder().with_data(&v(&|x| x.rel_error)).create("rel_error").map_err(e)?;
            f.new_dataset_builder().with_data(&v(&|x| x.max_probe_error)).create("max_probe_error").map_err(e)?;
            f.new_dataset_builder()
                .with_data(&v(&|x| x.max_constraint_violation))
                .create("max_constraint_violation")
                .map_err(e)?;
            f.new_dataset_builder().with_data(&v(&|x| x.full_seconds)).create("full_seconds").map_err(e)?;
            f.new_dataset_builder().with_data(&v(&|x| x.speedup)).create("speedup").map_err(e)?;
        }
        attr_str(f, "basis", &basis_path.display().to_string()).map_err(e)?;
        attr_str(f, "basis_content_hash", &stored.content_hash).map_err(e)?;
        attr_str(f, "model_fingerprint", &stored.model_fingerprint).map_err(e)?;
        attr_str(f, "variant", basis.variant.name()).map_err(e)?;
        attr_u64(f, "n_modes", basis.n_reduced() as u64).map_err(e)?;
        attr_u64(f, "validated", s.validated as u64).map_err(e)?;
        attr_f64(f, "wall_seconds", s.wall_seconds).map_err(e)?;
        attr_u64(f, "threads", s.threads as u64).map_err(e)?;
        attr_u64(f, "continuation", s.continuation as u64).map_err(e)?;
        attr_u64(f, "n_failed", s.n_failed() as u64).map_err(e)?;
        attr_u64(f, "n_pending", s.scales.iter().filter(|x| x.status() == STATUS_PENDING).count() as u64).map_err(e)?;
        attr_str(f, "program_version", env!("CARGO_PKG_VERSION")).map_err(e)?;
        extra(f)
    })
}

/// Reads an earlier sweep file for `--resume`: (load scale, the finished run) for every
/// scale it holds, `None` for those that failed or did not run. Refuses a file of another
/// basis or model, and one without the validation a `--validate` sweep needs.
pub fn read_sweep(
    path: &Path,
    model: &Model,
    stored: &StoredBasis,
    validate: bool,
) -> Result<Vec<(f64, Option<SweepPoint>)>> {
    let cannot = |field: &str, problem: String| {
        Error::input(path, field, format!("{problem}; cannot resume from it (remove it, or run without --resume)"))
    };
    let f = hdf5::File::open(path).map_err(|e| cannot("(file)", format!("is not a readable HDF5 file: {e}")))?;
    // layout 1 stored /reduced_q as (N, r, n_t): converted below; newer layouts are refused
    let layout = check_layout(&f, path, "flexrom sweep")?;
    let text = |name: &str| {
        read_attr_str(&f, name).map_err(|e| cannot(name, format!("cannot be read ({e}): not a flexrom sweep file?")))
    };
    if text("basis_content_hash")? != stored.content_hash {
        return Err(cannot("basis_content_hash", "comes from another basis than the one given".into()));
    }
    if text("model_fingerprint")? != model.fingerprint() {
        return Err(cannot("model_fingerprint", "comes from another model than the pipeline's".into()));
    }
    let vec = |name: &str| {
        f.dataset(name).and_then(|d| d.read_1d::<f64>()).map_err(|e| cannot(name, format!("cannot be read: {e}")))
    };
    let ints = |name: &str| {
        f.dataset(name).and_then(|d| d.read_1d::<u64>()).map_err(|e| cannot(name, format!("cannot be read: {e}")))
    };
    let scales = vec("load_scales")?;
    let status = f
        .dataset("status")
        .and_then(|d| d.read_1d::<u8>())
        .map_err(|e| cannot("status", format!("cannot be read: {e}")))?;
    let t = vec("t")?;
    let s = Settings::resolve(model, &Overrides::default())?;
    let (n, nt, r) = (scales.len(), s.n_steps + 1, stored.basis.n_reduced());
    if status.len() != n || t.len() != nt {
        return Err(cannot(
            "status",
            format!("has {} entries for {n} load scales, or /t {} for {nt} instants", status.len(), t.len()),
        ));
    }
    let zq = f
        .dataset("reduced_q")
        .and_then(|d| d.read::<f64, ndarray::Ix3>())
        .map_err(|e| cannot("reduced_q", format!("cannot be read: {e}")))?;
    let zq = if layout == 1 {
        if zq.dim() != (n, r, nt) {
            return Err(cannot("reduced_q", format!("is {:?}, expected ({n}, {r}, {nt}) (layout 1)", zq.dim())));
        }
        zq
    } else {
        if zq.dim() != (n, nt, r) {
            return Err(cannot("reduced_q", format!("is {:?}, expected ({n}, {nt}, {r})", zq.dim())));
        }
        // back to the runs' r × n_t
        zq.permuted_axes([0, 2, 1]).as_standard_layout().to_owned()
    };
    let mut probes = Vec::new();
    for name in model.probe_names() {
        let a = f
            .dataset(&format!("probes/{name}"))
            .and_then(|d| d.read::<f64, ndarray::Ix3>())
            .map_err(|e| cannot(&format!("probes/{name}"), format!("cannot be read: {e}")))?;
        if a.dim() != (n, nt, 2) {
            return Err(cannot(&format!("probes/{name}"), format!("is {:?}, expected ({n}, {nt}, 2)", a.dim())));
        }
        probes.push((name, a));
    }
    let rom_seconds = vec("rom_seconds")?;
    // the estimate columns of the file (absent in files written before them: no estimate)
    let optional = |name: &str| if f.link_exists(name) { vec(name).map(Some) } else { Ok(None) };
    let (estimates, estimate_seconds, extrapolated) = (
        optional("error_estimate")?,
        optional("estimate_seconds")?,
        if f.link_exists("extrapolated") {
            Some(
                f.dataset("extrapolated")
                    .and_then(|d| d.read_1d::<u8>())
                    .map_err(|e| cannot("extrapolated", format!("cannot be read: {e}")))?,
            )
        } else {
            None
        },
    );
    let by_time = if f.link_exists("error_estimate_by_time") {
        let a = f
            .dataset("error_estimate_by_time")
            .and_then(|d| d.read::<f64, ndarray::Ix2>())
            .map_err(|e| cannot("error_estimate_by_time", format!("cannot be read: {e}")))?;
        if a.dim() != (n, 5) {
            return Err(cannot("error_estimate_by_time", format!("is {:?}, expected ({n}, 5)", a.dim())));
        }
        Some(a)
    } else {
        None
    };
    let (newton, factorizations) = (ints("newton_iterations")?, ints("factorizations")?);
    let validation = if validate && f.link_exists("rel_error") {
        Some([
            vec("rel_error")?,
            vec("max_probe_error")?,
            vec("max_constraint_violation")?,
            vec("full_seconds")?,
            vec("speedup")?,
        ])
    } else {
        None
    };
    for a in [&rom_seconds]
        .into_iter()
        .chain(validation.iter().flatten())
        .chain(estimates.iter())
        .chain(estimate_seconds.iter())
    {
        if a.len() != n {
            return Err(cannot(
                "rom_seconds",
                format!("a per-scale dataset has {} entries for {n} load scales", a.len()),
            ));
        }
    }
    let mut out = Vec::new();
    for k in 0..n {
        let x = scales[k];
        // a finished run counts only when it has what this sweep writes
        if status[k] != STATUS_OK || (validate && validation.is_none()) {
            out.push((x, None));
            continue;
        }
        let settings = Settings::resolve(model, &Overrides { load_scale: Some(x), ..Default::default() })?;
        let stats = Stats {
            steps: settings.n_steps,
            newton_iterations: newton[k] as usize,
            factorizations: factorizations[k] as usize,
            ..Default::default()
        };
        let result = SimulationResult {
            model_text: model.text.clone(),
            model_path: model.path.display().to_string(),
            settings,
            t: t.clone(),
            q: Array2::zeros((0, nt)),
            multipliers: Array2::zeros((0, nt)),
            probes: probes
                .iter()
                .map(|(name, a)| (name.clone(), a.index_axis(ndarray::Axis(0), k).to_owned()))
                .collect(),
            stats,
            wall_seconds: rom_seconds[k],
        };
        let v = validation.as_ref().map(|c| Validation {
            load_scale: x,
            variant: stored.basis.variant.name().to_string(),
            n_dof: stored.basis.n_dof(),
            n_modes: r,
            rel_error: c[0][k],
            max_probe_error: c[1][k],
            max_probe_error_probe: String::new(),
            max_probe_error_t: f64::NAN,
            max_constraint_violation: c[2][k],
            full_seconds: c[3][k],
            full_dense_seconds: None,
            rom_seconds: rom_seconds[k],
            speedup: c[4][k],
            speedup_vs_dense: None,
            full_newton_iterations: 0,
            rom_newton_iterations: newton[k] as usize,
            rom_step_cuts: 0,
            // the estimate and the flags are set below from the file's columns
            error_estimate: None,
            effectivity: None,
            estimate_calibrated: None,
            estimate_seconds: None,
            extrapolated: false,
            training_range: None,
            sensitivity: None,
            rel_error_by_time: Vec::new(),
            error_estimate_by_time: None,
        });
        // the stored estimate: its value and cost (the factor it was made with is the basis's)
        let estimate = estimates.as_ref().map(|a| a[k]).filter(|e| !e.is_nan()).map(|error_estimate| Estimate {
            error_estimate,
            raw: f64::NAN,
            factor: f64::NAN,
            calibrated: false,
            seconds: estimate_seconds.as_ref().map_or(f64::NAN, |a| a[k]),
            by_time: by_time.as_ref().map_or([f64::NAN; 5], |a| std::array::from_fn(|i| a[[k, i]])),
        });
        let extrapolated = extrapolated.as_ref().is_some_and(|a| a.get(k).is_some_and(|&v| v != 0));
        let v = v.map(|mut v| {
            if let Some(e) = &estimate {
                v.error_estimate = Some(e.error_estimate);
                v.effectivity = Some(e.error_estimate / v.rel_error);
                v.estimate_seconds = Some(e.seconds);
                v.error_estimate_by_time = Some(e.by_time.to_vec());
            }
            v.extrapolated = extrapolated;
            v
        });
        let rom = ReducedRun { result, reduced_q: zq.index_axis(ndarray::Axis(0), k).to_owned() };
        out.push((x, Some(SweepPoint { rom, validation: v, estimate, extrapolated })));
    }
    Ok(out)
}

/// The table printed on stdout.
pub fn table(s: &Sweep) -> String {
    let mut out = String::new();
    out.push_str("load_scale  rom_ms  newton  error_estimate  est_ms  extrap");
    if s.validated {
        out.push_str("   rel_error  probe_err_m  full_ms  speedup");
    }
    out.push('\n');
    for x in &s.scales {
        let Some(p) = x.point() else {
            out.push_str(&format!(
                "{}  {}: {}\n",
                scale(x.load_scale),
                if x.status() == STATUS_FAILED { "failed" } else { "not run" },
                x.message()
            ));
            continue;
        };
        let r = &p.rom.result;
        out.push_str(&format!(
            "{}  {:>6.2}  {:>6}",
            scale(r.settings.load_scale),
            1e3 * r.wall_seconds,
            r.stats.newton_iterations
        ));
        match &p.estimate {
            Some(e) => out.push_str(&format!("  {:>14.3e}  {:>6.2}", e.error_estimate, 1e3 * e.seconds)),
            None => out.push_str(&format!("  {:>14}  {:>6}", "-", "-")),
        }
        out.push_str(if p.extrapolated { "     yes" } else { "      no" });
        if let Some(v) = &p.validation {
            out.push_str(&format!(
                "  {:>10.3e}  {:>11.3e}  {:>7.2}  {:>7.2}",
                v.rel_error,
                v.max_probe_error,
                1e3 * v.full_seconds,
                v.speedup
            ));
        }
        out.push('\n');
    }
    out
}

/// A load scale in the table's first column: fixed point, or exponent form when that would
/// not fit (|x| ≥ 1e6) or show nothing (|x| < 1e-3).
fn scale(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
        format!("{x:>10.3e}")
    } else {
        format!("{x:>10.4}")
    }
}

#[cfg(test)]
mod tests {
    use super::continuation_lanes;

    /// Every scale once, in chains of neighbours, at most two chains per thread and no
    /// more lanes than threads; with two threads and 100 scales the blocks pair as 0–24 with
    /// 75–99 and 25–49 with 50–74 (one from each end).
    #[test]
    fn continuation_lanes_cover_the_list_from_both_ends() {
        for (n, threads) in [(100, 2), (7, 2), (3, 4), (1, 2), (10, 3), (0, 2)] {
            let lanes = continuation_lanes(n, threads);
            assert!(lanes.len() <= threads.max(1), "{n} {threads}: {lanes:?}");
            let mut seen: Vec<usize> = lanes.iter().flatten().flat_map(|c| c.clone()).collect();
            seen.sort();
            assert_eq!(seen, (0..n).collect::<Vec<_>>(), "{n} {threads}: {lanes:?}");
            assert!(lanes.iter().all(|l| l.len() <= 2 && l.iter().all(|c| !c.is_empty())));
        }
        assert_eq!(continuation_lanes(100, 2), vec![vec![0..25, 75..100], vec![25..50, 50..75]]);
    }
}
