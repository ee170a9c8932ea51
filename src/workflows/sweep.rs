//! `sweep`: runs at many load scales, in parallel across cores (rayon; BLAS stays on one
//! thread inside each run): the reduced model, optionally validated against full runs, or
//! (`--full`, [`Route::Full`]) the full model itself, exact, one full model per worker.
//!
//! One load scale that fails (Newton, a singular matrix) does not stop the sweep: its status
//! and message are stored and the others run on. The file is written as the sweep goes
//! (rewritten whole, atomically, after the first finished scale, then at most every
//! [`CHECKPOINT_SECONDS`] or more when writing is slow, and at the end), so a
//! killed sweep leaves a valid file of the finished scales at the final path; `--resume`
//! ([`sweep_to_file`]) takes the finished scales from it and runs the rest.
//!
//! What each load scale became is in `crate::records::sweep_outcome` ([`Sweep`],
//! [`ScaleResult`]), the sweep file's layout and its writing and reading (`--resume`) in
//! `crate::records::sweep_file`, one run of it with its basis (for drawing) in
//! `crate::records::sweep_run`, the table printed on stdout in `sweep/table.rs`; the
//! fallback policy in `crate::pipeline::fallback`.

mod table;

pub use crate::pipeline::fallback::Fallback;
pub use crate::records::sweep_file::{point_names, read_sweep, write_sweep, write_sweep_with, Extra, SweepBasis};
pub use crate::records::sweep_outcome::{
    Outcome, ScaleResult, Sweep, SweepPoint, STATUS_FAILED, STATUS_OK, STATUS_PENDING,
};
pub use crate::records::sweep_run::{is_sweep_file, open_sweep_run, SweepPick, SweepRun};
pub use table::table;

use crate::error::{Result, Text};
use crate::linalg::kkt::LinearSolverKind;
use crate::model::Model;
use crate::records::sweep_outcome::clone_point;
use crate::rom::pool::Pool;
use crate::rom::{Output, ReducedRun, Rom};
use crate::simulate::{simulate, FullModel, Overrides, Settings};
use crate::solver::model::Parameters;
use crate::workflows::validate::compare;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use ndarray::{Array1, Array2};
use rayon::prelude::*;
use std::path::Path;
use std::sync::Mutex;

/// The sweep file is rewritten at most this often while the sweep runs, and at most every
/// [`CHECKPOINT_COST_FACTOR`] times the last rewrite's duration: rewriting takes at most
/// 1/50 = 2 % of the sweep's time (four-bar, 100 scales: a 9.4 MB file).
pub const CHECKPOINT_SECONDS: f64 = 2.0;
pub const CHECKPOINT_COST_FACTOR: f64 = 50.0;

/// How a sweep runs (default: independent runs, no validation, no progress bar).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SweepOptions {
    /// also run the full model at every load scale and compare
    pub validate: bool,
    /// continuation in the load scale: each thread takes two contiguous parts of the list
    /// (one from each end) and starts every Newton solve from the previous points'
    /// increments
    /// ([`crate::rom::ReducedRunner::solve`]); off (the default): every load scale on its own, exactly as
    /// `online` runs it
    pub continuation: bool,
    /// a progress bar on stderr
    pub progress: bool,
    /// what a reduced sweep does at a point whose reduced answer it cannot stand behind
    /// ([`crate::pipeline::fallback`]); a full or validated sweep has no such point
    pub fallback: Fallback,
}

impl SweepOptions {
    /// The options a sweep runs with: a full sweep (`full`) is neither validated nor
    /// continued, and neither it nor a validated sweep (which measures the reduced model at
    /// every point) falls back.
    pub fn settled(self, full: bool) -> Self {
        match (full, self.validate) {
            (true, _) => SweepOptions { validate: false, continuation: false, fallback: Fallback::None, ..self },
            (false, true) => SweepOptions { fallback: Fallback::None, ..self },
            (false, false) => self,
        }
    }
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

/// What a sweep runs at every load scale.
#[derive(Clone, Copy)]
pub enum Route<'a> {
    /// the reduced model of a basis file (its estimate with every run, when it has an
    /// estimator), and the file it was read from
    Reduced { rom: &'a Rom, basis: SweepBasis<'a> },
    /// the full model (`sweep --full`): exact, no basis, no estimate
    Full(&'a Model),
}

impl<'a> Route<'a> {
    pub fn model(&self) -> &'a Model {
        match self {
            Route::Reduced { rom, .. } => rom.model(),
            Route::Full(model) => model,
        }
    }

    /// The basis file of a reduced sweep.
    pub fn basis(&self) -> Option<SweepBasis<'a>> {
        match self {
            Route::Reduced { basis, .. } => Some(*basis),
            Route::Full(_) => None,
        }
    }
}

/// What a sweep's runs are called in messages: "points" when some set a named parameter,
/// else "load scales".
pub fn runs_noun<'a>(points: impl IntoIterator<Item = &'a Parameters>) -> &'static str {
    if points.into_iter().any(|mu| mu.named().next().is_some()) {
        "points"
    } else {
        "load scales"
    }
}

/// Runs the reduced model at every point, in parallel; with `validate`, also the full one.
/// A point whose run fails is recorded as failed and the others go on. Every point gets the
/// reduced model's error estimate (when it has an estimator) and extrapolation flag.
pub fn sweep(rom: &Rom, points: &[Parameters], o: SweepOptions) -> Result<Sweep> {
    let o = o.settled(false);
    let start = pending(rom.model(), rom.basis().n_reduced(), false, points, o)?;
    let sw = run_reduced(rom, start, o, None)?;
    // a stop asked for left the points it reached pending: the caller's stop
    crate::interrupt::check()?;
    Ok(sw)
}

/// Where and how a sweep is written as it goes ([`sweep_to_file`]).
pub struct SweepFile<'a> {
    pub out: &'a Path,
    /// take the scales `out` already holds as finished from it, run only the others
    pub resume: bool,
    /// written into the file at every checkpoint (a shard's own group)
    pub extra: Extra<'a>,
}

/// The runs of `route` at every scale, writing `f.out` as it goes (see the module
/// documentation); with `f.resume`, the scales that `f.out` already holds as finished
/// (same route, basis content and model) are taken from it, and only the others run. The
/// returned sweep is written to `f.out`. A full sweep takes no options: it is neither
/// validated (it is the reference itself) nor continued.
pub fn sweep_to_file(route: Route, points: &[Parameters], o: SweepOptions, f: SweepFile) -> Result<Sweep> {
    let SweepFile { out, resume, extra } = f;
    let model = route.model();
    let full = matches!(route, Route::Full(_));
    let o = o.settled(full);
    let n_reduced = match route {
        Route::Reduced { rom, .. } => rom.basis().n_reduced(),
        Route::Full(_) => 0,
    };
    let mut start = pending(model, n_reduced, full, points, o)?;
    if resume {
        if out.exists() {
            // its full answers would stand in a file that says it has none
            if !full
                && !o.validate
                && o.fallback == Fallback::None
                && crate::records::sweep_file::fallback_of(out)? == Fallback::Full
            {
                return Err(crate::error::Error::input(
                    out,
                    "fallback",
                    Text::new("is \"full\": the sweep was written with ")
                        .option("fallback", Some("full"))
                        .then("; resume it with ")
                        .option("fallback", Some("full"))
                        .then(" (or the pipeline's [online] fallback), or write another file"),
                ));
            }
            let old = read_sweep(out, model, route.basis().map(|b| b.stored), o.validate)?;
            let mut reused = 0;
            for s in start.scales.iter_mut() {
                if let Some(i) = old.iter().position(|(x, _)| *x == s.mu) {
                    if let Some(p) = old[i].1.as_ref().filter(|p| !falls_back_now(&route, o, &s.mu, p)) {
                        s.outcome = Outcome::Done(clone_point(p));
                        reused += 1;
                    }
                }
            }
            start.resumed = reused;
            let dropped = old.iter().filter(|(x, p)| p.is_some() && !points.contains(x)).count();
            let runs = runs_noun(points);
            log::info!(
                "resuming {}: {reused} of {} {runs} already finished, running {}{}",
                out.display(),
                points.len(),
                points.len() - reused,
                if dropped > 0 {
                    format!(" ({dropped} finished {runs} of the file are not in the list and are left out)")
                } else {
                    String::new()
                }
            );
        } else {
            log::info!("resuming {}: no such file yet, running all {} load scales", out.display(), points.len());
        }
    }
    let basis = route.basis();
    let runs = runs_noun(points);
    // a stop once a checkpoint is written leaves that file: say what it keeps and how to go
    // on (set after the first write, it stands through the later ones)
    let note = format!(
        "{} is this sweep's last checkpoint (written every few seconds): it keeps the {runs} \
         finished by then, and the same command with --resume runs the others",
        out.display()
    );
    // whether this sweep has written its output yet (a checkpoint)
    let wrote = std::sync::atomic::AtomicBool::new(false);
    let write = |s: &Sweep| {
        write_sweep_with(out, s, basis, extra)?;
        wrote.store(true, std::sync::atomic::Ordering::SeqCst);
        crate::io::atomic::set_stop_note(Some(note.clone()));
        Ok(())
    };
    let resumed = start.resumed;
    // a first signal stops the runs, and what is finished is written below (the command line)
    let graceful = crate::io::atomic::GracefulStop::on();
    let sw = match route {
        Route::Reduced { rom, .. } => run_reduced(rom, start, o, Some(&write)),
        Route::Full(model) => run_full(model, start, o, Some(&write)),
    };
    let stopped = graceful.release();
    if stopped {
        // the runs have stopped (the request was set before the stop was claimed); the final
        // write commits only once it is withdrawn
        crate::interrupt::clear();
    }
    let sw = sw?;
    let pending = sw.scales.iter().filter(|x| x.status() == STATUS_PENDING).count();
    let finished_here = sw.done().count() - resumed;
    // stopped before this sweep first wrote its output: an earlier file there is left as
    // it was (as a stop without a graceful reach would leave it), and none is begun for
    // nothing
    if stopped && !wrote.load(std::sync::atomic::Ordering::SeqCst) && (out.exists() || finished_here == 0) {
        crate::io::atomic::set_stop_note(Some(if out.exists() {
            format!(
                "the stop came before this sweep first wrote {}: it is left as it was ({finished_here} {runs} finished here are not kept)",
                out.display()
            )
        } else {
            format!("nothing was finished before the stop; no {} written", out.display())
        }));
        return Err(crate::error::Error::Interrupted);
    }
    let written = write(&sw);
    crate::io::atomic::set_stop_note(None);
    written?;
    // a stop that came once every point had run changes nothing
    if stopped && pending > 0 {
        let done = sw.done().count();
        crate::io::atomic::set_stop_note(Some(format!(
            "{} keeps the {done} {runs} finished; the same command with --resume runs the other {pending}",
            out.display()
        )));
        return Err(crate::error::Error::Interrupted);
    }
    Ok(sw)
}

/// Whether a finished reduced answer read back for `--resume` is one this sweep's
/// fallback would not keep (the earlier sweep ran without it, or with another tolerance):
/// it runs again, and falls back.
fn falls_back_now(route: &Route, o: SweepOptions, mu: &Parameters, p: &SweepPoint) -> bool {
    let Route::Reduced { rom, .. } = route else { return false };
    o.fallback == Fallback::Full
        && p.fallback.is_none()
        && p.note.is_none()
        && crate::pipeline::fallback::reason(rom.trust(), mu, p.estimate.as_ref()).is_some()
}

/// Every scale pending, with the model's time grid and probe names.
fn pending(model: &Model, n_reduced: usize, full: bool, points: &[Parameters], o: SweepOptions) -> Result<Sweep> {
    let s = Settings::resolve(model, &Overrides::default())?;
    let t = Array1::from_iter((0..=s.n_steps).map(|k| k as f64 * s.dt));
    Ok(Sweep {
        scales: points.iter().map(|mu| ScaleResult { mu: mu.clone(), outcome: Outcome::Pending }).collect(),
        t,
        probe_names: model.probe_names(),
        section_names: model.section_names(),
        reactions: crate::rom::reactions::ReactionReader::new(model).points(),
        n_reduced,
        full,
        model_fingerprint: model.fingerprint(),
        validated: o.validate,
        fallback: o.fallback,
        wall_seconds: 0.0,
        threads: rayon::current_num_threads().max(1),
        continuation: o.continuation,
        resumed: 0,
    })
}

type Checkpoint<'a> = &'a (dyn Fn(&Sweep) -> Result<()> + Sync);
/// One point of a sweep: the run at a load scale, given the last good runs of its chain
/// (continuation only; empty otherwise).
type RunPoint<'a> = &'a (dyn Fn(&Parameters, &[&ReducedRun]) -> Result<SweepPoint> + Sync);

/// The reduced runs of the pending scales of `state` (with `o.validate`, the full ones
/// beside them), each with its estimate and extrapolation flag.
fn run_reduced(rom: &Rom, state: Sweep, o: SweepOptions, checkpoint: Option<Checkpoint>) -> Result<Sweep> {
    let (model, basis) = (&**rom.model(), &**rom.basis());
    // every point's trajectories are kept until the file is written; without validation
    // nothing of full size is reconstructed
    let n_steps = Settings::resolve(model, &Overrides::default())?.n_steps;
    let output = if o.validate { Output::Full } else { Output::ReducedAndProbes };
    crate::rom::check_reduced_memory(model, basis.n_reduced(), n_steps, output, state.n_todo() as f64)?;
    // the fallback's full runs, one full model per worker that needs one
    let full_models = Pool::new(|| FullModel::new(model, LinearSolverKind::Banded));
    let point = |mu: &Parameters, previous: &[&ReducedRun]| -> Result<SweepPoint> {
        let reduced = rom.solve_and_estimate(mu, output, previous).map_err(|e| e.at_stage("sweep (reduced run)", mu));
        let full = || models_run(&full_models, mu);
        let crate::pipeline::fallback::Settled { run, estimate, fallback, note } =
            crate::pipeline::fallback::settle(reduced, o.fallback, rom.trust(), mu, full)?;
        // a validated sweep does not fall back (`SweepOptions::settled`)
        let (validation, full_probes) = if o.validate {
            let full = simulate(model, &Overrides::at(mu)).map_err(|e| e.at_stage("sweep (full run)", mu))?;
            let v = compare(model, &full, &run, None, basis.n_reduced(), basis.variant.name())
                .with_trust(estimate.as_ref(), Some(rom));
            (Some(v), Some(full.probes))
        } else {
            (None, None)
        };
        // where the load lies against the basis's range, whichever model answered
        let extrapolated = rom.is_extrapolated(mu);
        Ok(SweepPoint { run, validation, full_probes, estimate, extrapolated, fallback, note })
    };
    let label = if o.validate { "sweep + validate" } else { "sweep" };
    run_pending(state, o, label, &point, checkpoint)
}

/// The full runs of the pending scales of `state`, one full model (system and work space)
/// per worker ([`FullModel`]): each run is what `simulate` gives at its load, and only its
/// probes and statistics are kept.
fn run_full(model: &Model, state: Sweep, o: SweepOptions, checkpoint: Option<Checkpoint>) -> Result<Sweep> {
    let n_steps = Settings::resolve(model, &Overrides::default())?.n_steps;
    // a run too large is refused before any runs; the kept part of each is its probes and t
    model.check_full_run_memory(n_steps, false)?;
    let z = model.sizes();
    let kept = state.n_todo() as f64 * 8.0 * (n_steps as f64 + 1.0) * (z.n_probe_values + 1.0);
    model.limits.check_memory(&format!("the probes of {} full runs of {n_steps} steps", state.n_todo()), kept)?;
    let models = Pool::new(|| FullModel::new(model, LinearSolverKind::Banded));
    let point = |mu: &Parameters, _: &[&ReducedRun]| -> Result<SweepPoint> {
        let run = models_run(&models, mu)?;
        Ok(SweepPoint {
            run,
            validation: None,
            full_probes: None,
            estimate: None,
            extrapolated: false,
            fallback: None,
            note: None,
        })
    };
    run_pending(state, o, "full sweep", &point, checkpoint)
}

/// The full run at `mu` on one of `models` (what `simulate` gives there), kept as a sweep
/// keeps it: its probes and statistics, no coordinates (dropped now, not after the whole
/// sweep).
fn models_run(models: &Pool<'_, FullModel>, mu: &Parameters) -> Result<ReducedRun> {
    let run = models.with(|full| full.simulate(&Overrides::at(mu)));
    let mut r = run.and_then(|r| r).map_err(|e| e.at_stage("sweep (full run)", mu))?;
    let nt = r.t.len();
    (r.q, r.qd, r.multipliers) = (Array2::zeros((0, nt)), Array2::zeros((0, nt)), Array2::zeros((0, nt)));
    (r.strains, r.curvatures) = (Vec::new(), Vec::new());
    Ok(ReducedRun { result: r, reduced_q: Array2::zeros((0, nt)) })
}

/// Runs `point` at the pending scales of `state`, in parallel; after each one,
/// `checkpoint` (when given, and at most every [`CHECKPOINT_SECONDS`]) writes what is done
/// so far. `label` names the sweep on the progress bar.
fn run_pending(
    state: Sweep,
    o: SweepOptions,
    label: &str,
    point: RunPoint,
    checkpoint: Option<Checkpoint>,
) -> Result<Sweep> {
    let todo: Vec<usize> = (0..state.scales.len()).filter(|&i| state.scales[i].status() != STATUS_OK).collect();
    let points: Vec<Parameters> = todo.iter().map(|&i| state.scales[i].mu.clone()).collect();
    let bar = ProgressBar::with_draw_target(
        Some(points.len() as u64),
        if o.progress { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() },
    );
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{prefix}} [{{bar:30}}] {{pos}}/{{len}} {}, {{elapsed}} elapsed, ETA {{eta}}",
            runs_noun(&points)
        ))
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar.set_prefix(label.to_string());
    let ticker = crate::output::ticker::Ticker::new(label, points.len() as u64, o.progress);
    let start = std::time::Instant::now();
    let threads = state.threads;
    // continuation: a few chains of neighbouring scales per thread; otherwise one point per task
    let lanes = if o.continuation {
        continuation_lanes(points.len(), threads)
    } else {
        (0..points.len()).map(|i| std::iter::once(i..i + 1).collect()).collect()
    };
    // the sweep so far, and when the next write is due (None: now, so the first finished
    // scale is written at once)
    let shared = Mutex::new((state, None::<std::time::Instant>));
    let record = |i: usize, outcome: Outcome| -> Result<()> {
        let mut guard = shared.lock().unwrap_or_else(|e| e.into_inner());
        let (sw, due) = &mut *guard;
        sw.scales[todo[i]].outcome = outcome;
        // once a stop was asked for, nothing is committed before the runs have stopped
        if let Some(write) = checkpoint.filter(|_| !crate::interrupt::requested()) {
            if due.is_none_or(|d| std::time::Instant::now() >= d) {
                sw.wall_seconds = start.elapsed().as_secs_f64();
                let began = std::time::Instant::now();
                match write(sw) {
                    // a stop came during this write, which did not commit: the final write
                    // after the runs takes its place
                    Err(crate::error::Error::Interrupted) => {}
                    r => r?,
                }
                let wait = CHECKPOINT_SECONDS.max(CHECKPOINT_COST_FACTOR * began.elapsed().as_secs_f64());
                *due = Some(std::time::Instant::now() + std::time::Duration::from_secs_f64(wait));
            }
        }
        Ok(())
    };
    let results: Result<Vec<()>> = lanes
        .par_iter()
        .map(|chains| {
            for chain in chains {
                // the last two good runs of this chain (continuation only)
                let mut previous: Vec<ReducedRun> = Vec::new();
                for i in chain.clone() {
                    // a stop asked for: the points not begun stay pending
                    if crate::interrupt::requested() {
                        break;
                    }
                    let run = point(&points[i], &previous.iter().collect::<Vec<_>>());
                    bar.inc(1);
                    ticker.tick();
                    match run {
                        // finished as the stop came: parts of it (its estimate) may have been cut
                        Ok(_) if crate::interrupt::requested() => record(i, Outcome::Pending)?,
                        Ok(p) => {
                            // a fallback's full run has no reduced steps to continue from
                            if o.continuation && p.fallback.is_none() {
                                previous.push(p.run.clone());
                                if previous.len() > 2 {
                                    previous.remove(0);
                                }
                            }
                            record(i, Outcome::Done(p))?;
                        }
                        // a run the stop ended is not failed: it has not run (also where the
                        // error that reached here wraps the stop: a fallback's full run)
                        Err(_) if crate::interrupt::requested() => record(i, Outcome::Pending)?,
                        Err(e) => record(i, Outcome::Failed(e.to_string()))?,
                    }
                }
            }
            Ok(())
        })
        .collect();
    bar.finish_and_clear();
    results?;
    let (mut sw, _) = shared.into_inner().unwrap_or_else(|e| e.into_inner());
    sw.wall_seconds = start.elapsed().as_secs_f64();
    Ok(sw)
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
