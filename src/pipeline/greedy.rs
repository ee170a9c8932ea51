//! Greedy training over a load range (`[train] greedy = { range = [A, B], tolerance = T,
//! max_runs = K, candidates = N }`; docs/greedy-training.md).
//!
//! ```text
//!     Λ = {λ₁ … λ_N}, N evenly spaced loads of [A, B]        (the candidates)
//!     S = full runs at A, (A + B)/2, B                        (at most K of them)
//!     repeat:
//!         for ε = 10⁻², 10⁻³, … (loose → tight):              (the mode search)
//!             V_ε = POD of S per block, the fewest modes with energy ≥ 1 − ε,
//!             ECSW at τ = √ε, and the estimator of V_ε (k more modes, its own ECSW);
//!             η_ε(λ) = the estimate of rel_error at every λ ∈ Λ (reduced runs, rayon);
//!             keep the first ε with B(η_ε) ≤ T, else the one with the least max;
//!         then the loosest τ with B(η) ≤ T for those modes (fewest sampled elements);
//!         λ* = argmax η(λ) over the candidates without a full run;  stop when |S| = K;
//!         full run at λ*  →  e* = true rel_error of V at λ*   (V never saw λ*: held out)
//!         calibration pair (raw estimate at λ*, e*);  c = calibrate(all pairs so far)
//!         stop when B(c/c_old · η) ≤ T and e* ≤ T  (V is kept, the run at λ* stays held out)
//!         else S ← S ∪ {run at λ*}
//! ```
//!
//! Why these choices:
//! - τ = √ε: the energy criterion bounds the squared relative projection error of the
//!   snapshots by ε, ECSW's τ bounds a relative force error in norm; √ε puts both at the
//!   same relative size, so neither dominates the other as the search tightens.
//! - B(η) = max over neighbouring candidates of max(ηᵢ, ηᵢ₊₁)² / min(ηᵢ, ηᵢ₊₁)
//!   (`search::between_candidates`): the tolerance is a promise for every load of the
//!   range, and between two candidates the estimate is taken to rise above the larger by
//!   as much as it changes between them (a few per cent for a smooth estimate, 33
//!   candidates). The search and the stopping test hold the same bound to T: an earlier
//!   fixed T / 2 in the search chose bases twice as costly as needed (the pendulum: 23
//!   sampled elements where 10 keep every estimate within T).
//! - the stopping test rescales the estimates by the calibration the held-out run just
//!   changed (c/c_old, the estimate is linear in c): a held-out run that shows the
//!   estimator reading low sends the loop on instead of certifying estimates made with the
//!   old factor.
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
//!   instants, δ = [`SENSITIVITY_STEP`] (0.1 %). Where the model is not
//!   sensitive (`s_i ≤ T`) the score is the estimate itself. Where its answer changes by
//!   more than T when the load changes by 0.1 % (the four-bar after t ≈ 0.7 s), the
//!   estimate there is held to `s_i` instead: any estimate compares two trajectories of
//!   the same chaotic dynamics, so below `s_i` it measures how the dynamics amplify small
//!   differences (the estimator's own among them) more than the reduction error, and full
//!   runs spent there do not make the basis better. The whole-run estimate is still what
//!   every reduced run reports; `/training/whole_run_estimates` keeps it.
//!
//! Nothing here is fitted to a model: the ladder, √ε and the bound B are the same for
//! every model; a reduced run that fails (Newton diverges) counts as an infinite estimate.
//!
//! The loop is here; the mode and hyper-reduction search of one iteration is in `search.rs`,
//! the estimates, sensitivities and scores at the candidates in `candidates.rs`.

mod candidates;
mod search;

pub use candidates::{score, SENSITIVITY_STEP};
pub use search::{ENERGY_LADDER, TAU_LADDER};

use super::basis_build::training_data;
use super::config::{GreedySpec, Pipeline};
use super::estimate::{calibrate, rel_error_by_time, CalibrationPoint, EstimatingRunner, Estimator};
use super::online::Output;
use super::training_record::{modes_text, TrainSummary};
pub use super::training_record::{write_training, GreedyRecord, Iteration};
use super::validate::compare;
use crate::error::Result;
use crate::io::basis_file::TrainingData;
use crate::model::Model;
use crate::reduction::Basis;
use crate::simulate::{simulate, Overrides, SimulationResult};
use rayon::prelude::*;
use search::{search, Level};

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
            // the same test as the stop below, without a held-out run to recalibrate with
            let bound = level.between_candidates();
            crate::output::info(&format!(
                "iteration {n}: {why}, worst estimate {worst:.2e} {cmp} {:e} at λ = {} (bound between candidates {bound:.2e}), {shape}",
                g.tolerance, it.worst_load
            ));
            converged = bound <= g.tolerance;
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
        // the held-out pair may have raised the calibration factor: the estimates this
        // basis will report are the candidates' scaled by it (the estimate is linear in c)
        let rescale = calibrate(points.clone()).factor / level.estimator.calibration.factor;
        let bound = level.between_candidates() * rescale.max(1.0);
        let done = bound <= g.tolerance && e_score <= g.tolerance;
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
    // the cheap online estimate on the corrected one's scale (`DefectsCalibration`)
    estimator.defects = candidates::calibrate_defects(&p.model, &trained.basis, &estimator, &candidates);
    crate::output::info(&match &estimator.defects {
        Some(d) if d.reliable => format!(
            "error estimate: the cheap `defects` method calibrated at the {} candidates (factors {}), the online default",
            d.load_scales.len(),
            d.factors.iter().map(|f| format!("{f:.3}")).collect::<Vec<_>>().join(", ")
        ),
        Some(_) => "error estimate: the `defects` method's ratio to the corrected estimate jumps between candidates (its leave-one-out check failed): the online default stays `corrected`".into(),
        None => "error estimate: the `defects` method could not be calibrated: the online default stays `corrected`".into(),
    });
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
