//! Greedy training over a load range (`[train] greedy = { range = [A, B], tolerance = T,
//! max_runs = K, candidates = N }`, issue 15 item 1; docs/greedy-training.md).
//!
//! ```text
//!     Λ = {λ₁ … λ_N}, N evenly spaced loads of [A, B]        (the candidates)
//!     S = full runs at A, (A + B)/2, B                        (at most K of them)
//!     repeat:
//!         for ε = 10⁻², 10⁻³, … (loose → tight):              (the mode search)
//!             V_ε = POD of S per block, the fewest modes with energy ≥ 1 − ε,
//!             ECSW at τ = √ε, and the estimator of V_ε (k more modes, its own ECSW);
//!             η_ε(λ) = the estimate of rel_error at every λ ∈ Λ (reduced runs, rayon);
//!             keep the first ε with max_Λ η_ε ≤ T / 2, else the one with the least max;
//!         λ* = argmax η(λ) over the candidates without a full run;  stop when |S| = K;
//!         full run at λ*  →  e* = true rel_error of V at λ*   (V never saw λ*: held out)
//!         calibration pair (raw estimate at λ*, e*);  c = calibrate(all pairs so far)
//!         stop when max_Λ η ≤ T and e* ≤ T  (V is kept, the run at λ* stays held out)
//!         else S ← S ∪ {run at λ*}
//! ```
//!
//! Why these choices:
//! - τ = √ε: the energy criterion bounds the squared relative projection error of the
//!   snapshots by ε, ECSW's τ bounds a relative force error in norm; √ε puts both at the
//!   same relative size, so neither dominates the other as the search tightens.
//! - the factor 2 under T leaves room for loads between the candidates and for the
//!   estimate's own scatter, while the stopping test itself is against T.
//! - a tighter ε whose estimator basis cannot get its `k` extra modes in every block (the
//!   snapshots span too little) ends the search: its estimate would compare the basis with
//!   itself and read zero.
//! - the calibration factor c is recomputed from every held-out pair before each
//!   iteration's estimates, so an estimator that read low at one full run reads higher at
//!   the next iteration.
//!
//! - from the second iteration on, the ladder starts two rungs looser than the rung chosen
//!   the iteration before (more snapshots need as many modes or more for the same error).
//!
//! - what the loop holds to T is the *score* of a candidate, not its whole-run estimate:
//!
//!   ```text
//!       score(λ) = T · max_i η_i(λ) / max(T, s_i(λ)),     i = 1 … 5 (fifths of the run)
//!   ```
//!
//!   with `η_i` the estimate and `s_i` the reduced model's own *sensitivity* over the run
//!   up to the end of fifth `i`: `s_i(λ) = ‖X_r(λ(1 + δ)) − X_r(λ)‖ / ‖X_r(λ)‖` over those
//!   instants, δ = [`SENSITIVITY_STEP`] (the issue's 0.1 %). Where the model is not
//!   sensitive (`s_i ≤ T`) the score is the estimate itself. Where its answer changes by
//!   more than T when the load changes by 0.1 % (the four-bar after t ≈ 0.7 s), the
//!   estimate there is held to `s_i` instead: any estimate compares two trajectories of
//!   the same chaotic dynamics, so below `s_i` it measures how the dynamics amplify small
//!   differences (the estimator's own among them) more than the reduction error, and full
//!   runs spent there do not make the basis better. The whole-run estimate is still what
//!   every reduced run reports; `/training/whole_run_estimates` keeps it.
//!
//! Nothing here is fitted to a model: the ladder, √ε and the factor 2 are the same for
//! every model; a reduced run that fails (Newton diverges) counts as an infinite estimate.

use super::basis_build::{build_basis, training_data};
use super::config::{GreedySpec, Pipeline};
use super::estimate::{
    calibrate, raw_estimate_by_time, rel_error_by_time, CalibrationPoint, EstimatingRunner, Estimator,
    DEFAULT_EXTRA_MODES,
};
use super::online::Output;
use super::training_record::{modes_text, TrainSummary};
pub use super::training_record::{write_training, GreedyRecord, Iteration};
use super::validate::compare;
use crate::error::{Error, Result};
use crate::io::basis_file::TrainingData;
use crate::model::Model;
use crate::reduction::{Basis, ModeRule, Trained};
use crate::simulate::{simulate, Overrides, SimulationResult};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

/// The loop accepts a level whose worst estimate is at most T / `MARGIN`.
pub const MARGIN: f64 = 2.0;
/// Energy tolerances ε tried, loose to tight: 10⁻², 10⁻³, …, 10⁻¹⁰.
pub const ENERGY_LADDER: [f64; 9] = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10];
/// ECSW tolerances τ tried with the chosen modes, loose to tight: 10^(−1 − i/2), down to 10⁻⁶
/// (also the τ with given modes and no given τ).
pub const TAU_LADDER: [f64; 11] =
    [1e-1, 3.162e-2, 1e-2, 3.162e-3, 1e-3, 3.162e-4, 1e-4, 3.162e-5, 1e-5, 3.162e-6, 1e-6];
/// δ of the sensitivity `s(λ) = ‖X_r(λ(1 + δ)) − X_r(λ)‖ / ‖X_r(λ)‖` (the issue's
/// definition of `sensitivity`, 0.1 %).
pub const SENSITIVITY_STEP: f64 = 1e-3;

/// The score of one candidate (module documentation): `T · max_i η_i / max(T, s_i)`; NaN
/// counts as ∞.
pub fn score(tolerance: f64, estimate_by_time: &[f64; 5], sensitivity_by_time: &[f64; 5]) -> f64 {
    let mut worst = 0.0_f64;
    for (&e, &s) in estimate_by_time.iter().zip(sensitivity_by_time) {
        let e = if e.is_nan() { f64::INFINITY } else { e };
        let s = if s.is_finite() { s } else { 0.0 };
        worst = worst.max(tolerance * e / tolerance.max(s));
    }
    worst
}

/// A basis of one rung of the ladder with its estimator and its estimates at the candidates.
struct Level {
    energy: f64,
    hyper_tolerance: Option<f64>,
    trained: Trained,
    estimator: Estimator,
    /// scores (module documentation)
    estimates: Vec<f64>,
    whole: Vec<f64>,
    raws: Vec<f64>,
    sensitivity: Vec<[f64; 5]>,
    /// the estimator got its `k` extra modes in every block
    fully_enriched: bool,
}

impl Level {
    /// The candidate with the largest estimate and that estimate (NaN counts as ∞).
    fn worst(&self) -> (usize, f64) {
        self.worst_where(|_| true).expect("at least two candidates")
    }

    /// [`Self::worst`] among the candidates `keep` accepts.
    fn worst_where(&self, keep: impl Fn(usize) -> bool) -> Option<(usize, f64)> {
        let mut w: Option<(usize, f64)> = None;
        for (i, &e) in self.estimates.iter().enumerate().filter(|(i, _)| keep(*i)) {
            let e = if e.is_nan() { f64::INFINITY } else { e };
            if w.is_none_or(|w| e > w.1) {
                w = Some((i, e));
            }
        }
        w
    }
}

/// The first loads: the range's ends and middle (middle only for K = 1, the ends for K = 2).
pub fn initial_loads(range: (f64, f64), max_runs: usize) -> Vec<f64> {
    let (a, b) = range;
    match max_runs {
        1 => vec![0.5 * (a + b)],
        2 => vec![a, b],
        _ => vec![a, 0.5 * (a + b), b],
    }
}

/// Greedy training (module documentation); nothing is written.
pub fn train(p: &Pipeline, g: &GreedySpec) -> Result<(TrainingData, TrainSummary)> {
    let range = g.range();
    let candidates = g.candidate_loads();
    let full = |x: f64| {
        simulate(&p.model, &Overrides { load_scale: Some(x), ..Default::default() })
            .map_err(|e| e.at_stage("train (greedy full run)", x))
    };
    let first = initial_loads(range, g.max_runs);
    crate::output::info(&format!(
        "greedy training over [{}, {}], tolerance {:e}, {} candidates: full runs at {:?}",
        range.0,
        range.1,
        g.tolerance,
        candidates.len(),
        first
    ));
    let mut runs: Vec<SimulationResult> = first.par_iter().map(|&x| full(x)).collect::<Result<_>>()?;
    // the later full runs, one at a time, on one full model
    let mut full_model = crate::simulate::FullModel::new(&p.model, crate::linalg::kkt::LinearSolverKind::Banded)?;
    let mut full_seconds: f64 = runs.iter().map(|r| r.wall_seconds).sum();
    let mut full_runs = runs.len();
    let mut points: Vec<CalibrationPoint> = Vec::new();
    let mut iterations: Vec<Iteration> = Vec::new();
    let converged;
    let chosen = loop {
        let data = training_data(&runs);
        let previous_energy = iterations.last().map(|i: &Iteration| i.energy);
        let level = search(p, g, &data, &candidates, &points, iterations.len() + 1, previous_energy)?;
        let (wi, worst) = level.worst();
        // where to run the full model: the worst candidate whose load has no full run yet
        // (a training load's own run is already in the snapshots)
        let fresh = |i: usize| {
            runs.iter().all(|r| (r.settings.load_scale - candidates[i]).abs() > 1e-12 * candidates[i].abs().max(1.0))
        };
        let next = level.worst_where(fresh);
        let b = &level.trained.basis;
        let mut it = Iteration {
            energy: level.energy,
            hyper_tolerance: level.hyper_tolerance.unwrap_or(f64::NAN),
            block_modes: level.trained.block_modes.clone(),
            n_modes: b.n_reduced(),
            n_elements: b
                .hyper
                .as_ref()
                .map_or_else(|| p.model.physics().map_or(0, |ph| ph.sys.n_elements()), |h| h.elements.len()),
            estimates: level.estimates.clone(),
            whole_run_estimates: level.whole.clone(),
            sensitivity: level.sensitivity.iter().map(|s| s[4]).collect(),
            worst_load: candidates[wi],
            worst_estimate: worst,
            run_load: f64::NAN,
            true_error: f64::NAN,
            true_score: f64::NAN,
        };
        let shape = format!(
            "{}{}, {} elements",
            modes_text(&it.block_modes),
            if b.kept.is_empty() { String::new() } else { format!(" + {} joint coordinates", b.kept.len()) },
            it.n_elements
        );
        let n = iterations.len() + 1;
        let cmp = if worst <= g.tolerance { "≤" } else { ">" };
        let Some((ni, next_estimate)) = next.filter(|_| full_runs < g.max_runs) else {
            let why = if full_runs >= g.max_runs {
                format!("no full run left (max_runs = {})", g.max_runs)
            } else {
                "every candidate has a full run".into()
            };
            crate::output::info(&format!(
                "iteration {n}: {why}, worst estimate {worst:.2e} {cmp} {:e} at λ = {}, {shape}",
                g.tolerance, it.worst_load
            ));
            converged = worst <= g.tolerance;
            iterations.push(it);
            break level;
        };
        // the full run at the worst candidate: snapshots for the next basis, and the true
        // error of this one there (it never saw that load)
        let at = candidates[ni];
        let truth = full_model
            .simulate(&Overrides { load_scale: Some(at), ..Default::default() })
            .map_err(|e| e.at_stage("train (greedy full run)", at))?;
        full_seconds += truth.wall_seconds;
        full_runs += 1;
        let (e, e_by_time) = true_error(&p.model, &level.trained.basis, &level.estimator, &truth, at);
        let e_score = score(g.tolerance, &e_by_time, &level.sensitivity[ni]);
        (it.run_load, it.true_error, it.true_score) = (at, e, e_score);
        if level.raws[ni].is_finite() && e.is_finite() {
            points.push(CalibrationPoint { load_scale: at, raw_estimate: level.raws[ni], rel_error: e });
        }
        let done = worst <= g.tolerance && e_score <= g.tolerance;
        let sens = level.sensitivity[ni][4];
        if done {
            crate::output::info(&format!("iteration {n}: worst score {worst:.2e} ≤ {:e}; held-out check at λ = {at} (score {next_estimate:.2e}): rel_error {e:.2e} (score {e_score:.2e}, sensitivity {sens:.1e}); {shape}", g.tolerance));
        } else {
            crate::output::info(&format!("iteration {n}: full run at λ = {at} (worst score {worst:.2e} {cmp} {:e}; {next_estimate:.2e} there, true error {e:.2e}, its score {e_score:.2e}, sensitivity {sens:.1e}), {shape}", g.tolerance));
        }
        iterations.push(it);
        if done {
            converged = true;
            break level;
        }
        runs.push(truth);
    };
    if !converged {
        eprintln!(
            "warning: greedy training stopped after {full_runs} full runs (max_runs = {}) with worst estimate {:.2e} > tolerance {:e}; raise max_runs or the tolerance",
            g.max_runs,
            iterations.last().map_or(f64::NAN, |i| i.worst_estimate),
            g.tolerance
        );
    }
    let Level { trained, mut estimator, .. } = chosen;
    estimator.calibration = calibrate(points);
    let data = training_data(&runs);
    let record = GreedyRecord {
        range,
        tolerance: g.tolerance,
        max_runs: g.max_runs,
        candidates,
        load_scales: runs.iter().map(|r| r.settings.load_scale).collect(),
        iterations,
        converged,
        full_runs,
    };
    let n_snapshots = data.x.ncols();
    Ok((
        data,
        TrainSummary {
            trained,
            n_snapshots,
            full_seconds,
            n_runs: full_runs,
            greedy: Some(record),
            estimator: Some(estimator),
        },
    ))
}

/// rel_error of `basis` at `load` against the full run `truth`, whole and by fifth of the
/// run (∞ when the reduced run fails).
fn true_error(model: &Model, basis: &Basis, est: &Estimator, truth: &SimulationResult, load: f64) -> (f64, [f64; 5]) {
    let run = EstimatingRunner::new(model, basis, Some(est)).and_then(|mut r| r.run(load, Output::Full));
    match run {
        Ok((rom, _)) => {
            let by = rel_error_by_time(&rom.result.q, &truth.q);
            let mut by_time = [f64::INFINITY; 5];
            by_time.iter_mut().zip(&by).for_each(|(o, &v)| *o = v);
            (compare(model, truth, &rom, None, basis.n_reduced(), basis.variant.name()).rel_error, by_time)
        }
        Err(_) => (f64::INFINITY, [f64::INFINITY; 5]),
    }
}

/// The mode and hyper-reduction search of one iteration (module documentation): the modes
/// the pipeline gives, or the energy ladder loose → tight with τ = √ε (and a half step
/// before the first accepted rung); then, unless the pipeline gives τ, the loosest τ that
/// still meets T / 2 with those modes.
fn search(
    p: &Pipeline,
    g: &GreedySpec,
    data: &TrainingData,
    candidates: &[f64],
    points: &[CalibrationPoint],
    n: usize,
    previous_energy: Option<f64>,
) -> Result<Level> {
    let given_hyper = p.file.reduction.hyper.as_ref().map(|h| h.tolerance);
    let debug = std::env::var_os("FLEXROM_GREEDY_DEBUG").is_some();
    let accepts = |l: &Level| l.worst().1 <= g.tolerance / MARGIN;
    let mut last_error: Option<(&'static str, String)> = None;
    let mut attempt = |modes: ModeRule, eps: f64, tau: f64| -> Option<Level> {
        match level(p, data, candidates, points, modes, eps, Some(tau), n) {
            Ok(l) => {
                if debug {
                    let (wi, w) = l.worst();
                    let h = l.trained.basis.hyper.as_ref().map_or(0, |h| h.elements.len());
                    crate::output::info(&format!("  rung ε = {eps:.1e}, τ = {tau:.1e}: {}, {h} elements, estimator {:?}, worst estimate {w:.3e} at λ = {}", modes_text(&l.trained.block_modes), l.estimator.block_modes, candidates[wi]));
                }
                Some(l)
            }
            Err(e) => {
                last_error = Some(e);
                None
            }
        }
    };
    let better = |best: &Option<Level>, l: &Level| best.as_ref().is_none_or(|b| l.worst().1 < b.worst().1);
    let mut best: Option<Level> = None;
    if let Some(m) = &p.file.reduction.modes {
        best = attempt(m.clone(), f64::NAN, given_hyper.unwrap_or(TAU_LADDER[TAU_LADDER.len() - 1]));
    } else {
        let mut failed_eps: Option<f64> = None;
        // after the first iteration the ladder starts two rungs looser than the rung chosen
        // last time: more snapshots need as many modes or more for the same error, and the
        // rungs far looser than that were already far off
        let start = previous_energy
            .and_then(|e| ENERGY_LADDER.iter().position(|&x| x <= e * (1.0 + 1e-9)))
            .map_or(0, |i| i.saturating_sub(2));
        for &eps in &ENERGY_LADDER[start..] {
            let Some(l) = attempt(ModeRule::Energy(eps), eps, given_hyper.unwrap_or(eps.sqrt())) else { continue };
            if !l.fully_enriched && best.is_some() {
                // the snapshots span too little for a tighter basis with an honest estimate
                break;
            }
            let (ok, enriched) = (accepts(&l), l.fully_enriched);
            if ok {
                // a half step back towards the last rung that failed: fewer modes may do
                if let Some(f) = failed_eps {
                    let half = (f * eps).sqrt();
                    if let Some(h) = attempt(ModeRule::Energy(half), half, given_hyper.unwrap_or(half.sqrt())) {
                        if accepts(&h) && h.fully_enriched && h.trained.basis.n_reduced() < l.trained.basis.n_reduced()
                        {
                            best = Some(h);
                            break;
                        }
                    }
                }
                best = Some(l);
                break;
            }
            failed_eps = Some(eps);
            if better(&best, &l) {
                best = Some(l);
            }
            if !enriched {
                break;
            }
        }
    }
    // the cheapest hyper-reduction that keeps the accepted modes within T / 2
    if let (Some(b), None) = (&best, given_hyper) {
        if accepts(b) {
            let modes = if p.blocks().is_some() {
                ModeRule::Counts(b.trained.block_modes.clone())
            } else {
                ModeRule::Count(b.trained.block_modes[0])
            };
            let (eps, tau0) = (b.energy, b.hyper_tolerance.unwrap_or(0.0));
            for &tau in TAU_LADDER.iter().filter(|&&t| t > tau0 * (1.0 + 1e-9)) {
                if let Some(l) = attempt(modes.clone(), eps, tau) {
                    if accepts(&l) {
                        best = Some(l);
                        break;
                    }
                }
            }
        }
    }
    best.ok_or_else(|| {
        let (f, e) = last_error.unwrap_or(("reduction", "no basis could be built".into()));
        Error::input(&p.path, f, format!("greedy training, iteration {n}: {e}"))
    })
}

/// Builds the basis and estimator of one rung and estimates at every candidate.
#[allow(clippy::too_many_arguments)]
fn level(
    p: &Pipeline,
    data: &TrainingData,
    candidates: &[f64],
    points: &[CalibrationPoint],
    modes: ModeRule,
    energy: f64,
    hyper_tolerance: Option<f64>,
    n: usize,
) -> std::result::Result<Level, (&'static str, String)> {
    let (trained, mut estimator) = build_basis(p, data, modes, hyper_tolerance)?;
    estimator.calibration = calibrate(points.to_vec());
    let fully_enriched =
        estimator.block_modes.iter().zip(&trained.block_modes).all(|(&e, &r)| e >= r + DEFAULT_EXTRA_MODES);
    let label =
        if energy.is_finite() { format!("iteration {n}, energy {energy:.0e}") } else { format!("iteration {n}") };
    let runs = estimate_candidates(&p.model, &trained.basis, &estimator, candidates, &label);
    let estimates = runs.iter().map(|r| score(p_tolerance(p), &r.by_time, &r.sensitivity)).collect();
    let whole = runs.iter().map(|r| r.by_time[4]).collect();
    let raws = runs.iter().map(|r| r.raw).collect();
    let sensitivity = runs.iter().map(|r| r.sensitivity).collect();
    Ok(Level { energy, hyper_tolerance, trained, estimator, estimates, whole, raws, sensitivity, fully_enriched })
}

/// What the loop knows of one candidate.
#[derive(Clone, Copy)]
struct CandidateRun {
    /// the error estimate by fifth of the run (the last: the whole run's)
    by_time: [f64; 5],
    /// the whole run's raw estimate
    raw: f64,
    /// the reduced model's sensitivity by fifth of the run (module documentation)
    sensitivity: [f64; 5],
}

/// The greedy tolerance of the pipeline (`[train] greedy`).
fn p_tolerance(p: &Pipeline) -> f64 {
    p.file.train.greedy.as_ref().map_or(f64::INFINITY, |g| g.tolerance)
}

/// The seam to the error estimator: the estimate and the reduced model's sensitivity of
/// `basis` at every load, reduced runs in parallel (one reduced model and its estimator's
/// per worker, as `sweep` does); a run that fails gives ∞ estimates (and sensitivity 0,
/// which holds its estimate to T).
fn estimate_candidates(model: &Model, basis: &Basis, est: &Estimator, loads: &[f64], label: &str) -> Vec<CandidateRun> {
    let target =
        if crate::output::show_progress() { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() };
    let bar = ProgressBar::with_draw_target(Some(loads.len() as u64), target);
    bar.set_style(
        ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} candidates, {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_prefix(label.to_string());
    let failed = CandidateRun { by_time: [f64::INFINITY; 5], raw: f64::INFINITY, sensitivity: [0.0; 5] };
    let out: Vec<CandidateRun> = loads
        .par_iter()
        .map_init(
            || EstimatingRunner::new(model, basis, Some(est)).ok(),
            |runner, &x| {
                let r = match runner {
                    Some(r) => match r.run(x, Output::ReducedAndProbes) {
                        Ok((run, Some(e))) => {
                            // the same reduced model at λ(1 + δ): how much its answer moves
                            let sensitivity =
                                match r.reduced().run(x * (1.0 + SENSITIVITY_STEP), Output::ReducedAndProbes, &[]) {
                                    Ok(moved) => raw_estimate_by_time(basis, basis, &moved.reduced_q, &run.reduced_q),
                                    Err(_) => [0.0; 5],
                                };
                            CandidateRun { by_time: e.by_time, raw: e.raw, sensitivity }
                        }
                        _ => failed,
                    },
                    None => failed,
                };
                bar.inc(1);
                r
            },
        )
        .collect();
    bar.finish_and_clear();
    out
}

#[cfg(test)]
mod tests {
    use super::score;

    /// Where the sensitivity stays below T the score is the largest estimate; a window
    /// whose sensitivity exceeds T holds its estimate to that sensitivity instead; NaN
    /// counts as ∞.
    #[test]
    fn score_holds_sensitive_windows_to_their_sensitivity() {
        let t = 1e-2;
        let calm = [1e-4; 5];
        assert_eq!(score(t, &[1e-3, 2e-3, 3e-3, 4e-3, 5e-3], &calm), 5e-3);
        // the last two fifths are sensitive (s = 0.2): an estimate of 0.1 there scores
        // T·0.1/0.2 = 5e-3, below the early windows' 6e-3
        let s = [1e-4, 1e-4, 1e-3, 0.2, 0.2];
        assert!((score(t, &[1e-3, 2e-3, 6e-3, 0.1, 0.1], &s) - 6e-3).abs() < 1e-15);
        // above the sensitivity it still counts, scaled: 0.4 against 0.2 scores 2 T
        assert!((score(t, &[1e-3, 2e-3, 6e-3, 0.1, 0.4], &s) - 2e-2).abs() < 1e-15);
        assert!(score(t, &[f64::NAN, 0.0, 0.0, 0.0, 0.0], &calm).is_infinite());
    }
}
