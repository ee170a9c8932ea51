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
//!         λ* = argmax_Λ η(λ);  stop when |S| = K;
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
//! Nothing here is fitted to a model: the ladder, √ε and the factor 2 are the same for
//! every model; a reduced run that fails (Newton diverges) counts as an infinite estimate.

use super::config::{GreedySpec, Pipeline};
use super::estimate::{build_estimator, calibrate, CalibrationPoint, EstimatingRunner, Estimator, DEFAULT_EXTRA_MODES};
use super::online::Output;
use super::train::{build_basis, joint_dofs, training_data, TrainSummary};
use super::validate::compare;
use crate::error::{Error, Result};
use crate::io::basis_file::TrainingData;
use crate::model::Model;
use crate::reduction::{Basis, ModeRule, Trained};
use crate::simulate::{simulate, Overrides, SimulationResult};
use crate::solver::kkt::LinearSolverKind;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

/// The loop accepts a level whose worst estimate is at most T / `MARGIN`.
pub const MARGIN: f64 = 2.0;
/// Energy tolerances ε tried, loose to tight: 10⁻², 10⁻³, …, 10⁻¹⁰.
pub const ENERGY_LADDER: [f64; 9] = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10];

/// One pass of the loop: the basis it chose and where its estimate was worst.
#[derive(Clone, Debug)]
pub struct Iteration {
    /// the energy tolerance ε chosen (NaN when `reduction.modes` is given)
    pub energy: f64,
    /// ECSW τ (NaN without hyper-reduction)
    pub hyper_tolerance: f64,
    /// POD modes per block
    pub block_modes: Vec<usize>,
    /// reduced coordinates (POD modes and kept joint coordinates)
    pub n_modes: usize,
    /// sampled elements (all of them without hyper-reduction)
    pub n_elements: usize,
    /// the estimate at every candidate (`GreedyRecord::candidates` order)
    pub estimates: Vec<f64>,
    pub worst_load: f64,
    pub worst_estimate: f64,
    /// the true rel_error of this iteration's basis at `worst_load`, from the full run
    /// there (NaN when the budget allowed no run)
    pub true_error: f64,
}

/// What the greedy loop did: written under `/training` in the basis file.
#[derive(Clone, Debug)]
pub struct GreedyRecord {
    pub range: (f64, f64),
    pub tolerance: f64,
    pub max_runs: usize,
    pub candidates: Vec<f64>,
    /// the loads whose snapshots the basis holds, in run order
    pub load_scales: Vec<f64>,
    pub iterations: Vec<Iteration>,
    /// every candidate's estimate ≤ T and the held-out check run within T
    pub converged: bool,
    /// full runs made, the held-out check included
    pub full_runs: usize,
}

impl GreedyRecord {
    /// The `mode_rule` attribute of the basis file.
    pub fn mode_rule(&self) -> String {
        match self.iterations.last() {
            Some(it) if it.energy.is_finite() => {
                format!("greedy: energy = {:e} per block ({}), hyper tolerance {:e}", it.energy, modes_text(&it.block_modes), it.hyper_tolerance)
            }
            Some(it) => format!("greedy: {}", modes_text(&it.block_modes)),
            None => "greedy".into(),
        }
    }
}

fn modes_text(block_modes: &[usize]) -> String {
    let v: Vec<String> = block_modes.iter().map(|m| m.to_string()).collect();
    format!("{} modes", v.join(" + "))
}

/// A basis of one rung of the ladder with its estimator and its estimates at the candidates.
struct Level {
    energy: f64,
    hyper_tolerance: Option<f64>,
    trained: Trained,
    estimator: Estimator,
    estimates: Vec<f64>,
    raws: Vec<f64>,
    /// the estimator got its `k` extra modes in every block
    fully_enriched: bool,
}

impl Level {
    /// The candidate with the largest estimate and that estimate (NaN counts as ∞).
    fn worst(&self) -> (usize, f64) {
        let mut w = (0, f64::NEG_INFINITY);
        for (i, &e) in self.estimates.iter().enumerate() {
            let e = if e.is_nan() { f64::INFINITY } else { e };
            if e > w.1 {
                w = (i, e);
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
    let full = |x: f64| simulate(&p.model, &Overrides { load_scale: Some(x), ..Default::default() });
    let first = initial_loads(range, g.max_runs);
    eprintln!("greedy training over [{}, {}], tolerance {:e}, {} candidates: full runs at {:?}", range.0, range.1, g.tolerance, candidates.len(), first);
    let mut runs: Vec<SimulationResult> = first.par_iter().map(|&x| full(x)).collect::<Result<_>>()?;
    let mut full_seconds: f64 = runs.iter().map(|r| r.wall_seconds).sum();
    let mut full_runs = runs.len();
    let mut points: Vec<CalibrationPoint> = Vec::new();
    let mut iterations: Vec<Iteration> = Vec::new();
    let converged;
    let chosen = loop {
        let data = training_data(&runs);
        let level = search(p, g, &data, &candidates, &points, iterations.len() + 1)?;
        let (wi, worst) = level.worst();
        let b = &level.trained.basis;
        let mut it = Iteration {
            energy: level.energy,
            hyper_tolerance: level.hyper_tolerance.unwrap_or(f64::NAN),
            block_modes: level.trained.block_modes.clone(),
            n_modes: b.n_reduced(),
            n_elements: b.hyper.as_ref().map_or_else(|| p.model.system(LinearSolverKind::Banded).n_elements(), |h| h.elements.len()),
            estimates: level.estimates.clone(),
            worst_load: candidates[wi],
            worst_estimate: worst,
            true_error: f64::NAN,
        };
        let shape = format!("{}{}, {} elements", modes_text(&it.block_modes), if b.kept.is_empty() { String::new() } else { format!(" + {} joint coordinates", b.kept.len()) }, it.n_elements);
        let n = iterations.len() + 1;
        let cmp = if worst <= g.tolerance { "≤" } else { ">" };
        if full_runs >= g.max_runs {
            eprintln!("iteration {n}: no full run left (max_runs = {}), worst estimate {worst:.2e} {cmp} {:e} at λ = {}, {shape}", g.max_runs, g.tolerance, it.worst_load);
            converged = worst <= g.tolerance;
            iterations.push(it);
            break level;
        }
        // the full run at the worst candidate: snapshots for the next basis, and the true
        // error of this one there (it never saw that load)
        let at = candidates[wi];
        let truth = full(at)?;
        full_seconds += truth.wall_seconds;
        full_runs += 1;
        let e = true_error(&p.model, &level.trained.basis, &level.estimator, &truth, at);
        it.true_error = e;
        if level.raws[wi].is_finite() && e.is_finite() {
            points.push(CalibrationPoint { load_scale: at, raw_estimate: level.raws[wi], rel_error: e });
        }
        let done = worst <= g.tolerance && e <= g.tolerance;
        if done {
            eprintln!("iteration {n}: worst estimate {worst:.2e} ≤ {:e}; held-out check at λ = {at}: rel_error {e:.2e}; {shape}", g.tolerance);
        } else {
            eprintln!("iteration {n}: full run at λ = {at} (worst estimate {worst:.2e} {cmp} {:e}, true error there {e:.2e}), {shape}", g.tolerance);
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
    Ok((data, TrainSummary { trained, n_snapshots, full_seconds, n_runs: full_runs, greedy: Some(record), estimator: Some(estimator) }))
}

/// rel_error of `basis` at `load` against the full run `truth` (∞ when the reduced run fails).
fn true_error(model: &Model, basis: &Basis, est: &Estimator, truth: &SimulationResult, load: f64) -> f64 {
    let run = EstimatingRunner::new(model, basis, Some(est)).and_then(|mut r| r.run(load, Output::Full));
    match run {
        Ok((rom, _)) => compare(model, truth, &rom, None, basis.n_reduced(), basis.variant.name()).rel_error,
        Err(_) => f64::INFINITY,
    }
}

/// The mode search of one iteration (module documentation): the given modes and τ when the
/// pipeline fixes them, else the energy ladder loose → tight.
fn search(p: &Pipeline, g: &GreedySpec, data: &TrainingData, candidates: &[f64], points: &[CalibrationPoint], n: usize) -> Result<Level> {
    let given_hyper = p.file.reduction.hyper.as_ref().map(|h| h.tolerance);
    if let Some(m) = &p.file.reduction.modes {
        return level(p, data, candidates, points, m.clone(), f64::NAN, given_hyper, n).map_err(|(f, e)| Error::input(&p.path, f, e));
    }
    let mut best: Option<Level> = None;
    let mut last_error = None;
    for &eps in &ENERGY_LADDER {
        let tau = given_hyper.unwrap_or(eps.sqrt());
        let l = match level(p, data, candidates, points, ModeRule::Energy(eps), eps, Some(tau), n) {
            Ok(l) => l,
            Err(e) => {
                last_error = Some(e);
                continue;
            }
        };
        if !l.fully_enriched && best.is_some() {
            // the snapshots span too little for a tighter basis with an honest estimate
            break;
        }
        let w = l.worst().1;
        let accept = w <= g.tolerance / MARGIN;
        let enriched = l.fully_enriched;
        if best.as_ref().is_none_or(|b| w < b.worst().1) {
            best = Some(l);
        }
        if accept || !enriched {
            break;
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
    let (trained, spec) = build_basis(p, data, modes, hyper_tolerance)?;
    let sys = p.model.system(LinearSolverKind::Banded);
    let x_ref = data.x.column(0);
    let mut estimator = build_estimator(&sys, &trained, &spec, data.x.view(), data.multipliers.view(), &joint_dofs(p), x_ref, hyper_tolerance, DEFAULT_EXTRA_MODES)
        .map_err(|e| ("reduction", format!("cannot build the error estimator: {e}")))?;
    estimator.calibration = calibrate(points.to_vec());
    let fully_enriched = estimator.block_modes.iter().zip(&trained.block_modes).all(|(&e, &r)| e >= r + DEFAULT_EXTRA_MODES);
    let label = if energy.is_finite() { format!("iteration {n}, energy {energy:.0e}") } else { format!("iteration {n}") };
    let (estimates, raws) = estimate_candidates(&p.model, &trained.basis, &estimator, candidates, &label);
    Ok(Level { energy, hyper_tolerance, trained, estimator, estimates, raws, fully_enriched })
}

/// The seam to the error estimator: `(error_estimate, raw estimate)` of `basis` at every
/// load, reduced runs in parallel (one reduced model and its estimator's per worker, as
/// `sweep` does); a run that fails gives ∞.
fn estimate_candidates(model: &Model, basis: &Basis, est: &Estimator, loads: &[f64], label: &str) -> (Vec<f64>, Vec<f64>) {
    let bar = ProgressBar::with_draw_target(Some(loads.len() as u64), ProgressDrawTarget::stderr());
    bar.set_style(ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} candidates, {elapsed}").expect("valid template").progress_chars("=> "));
    bar.set_prefix(label.to_string());
    let out: Vec<(f64, f64)> = loads
        .par_iter()
        .map_init(
            || EstimatingRunner::new(model, basis, Some(est)).ok(),
            |runner, &x| {
                let r = match runner {
                    Some(r) => match r.run(x, Output::ReducedAndProbes) {
                        Ok((_, Some(e))) => (e.error_estimate, e.raw),
                        _ => (f64::INFINITY, f64::INFINITY),
                    },
                    None => (f64::INFINITY, f64::INFINITY),
                };
                bar.inc(1);
                r
            },
        )
        .collect();
    bar.finish_and_clear();
    out.into_iter().unzip()
}

/// Writes `/training` (the basis file's layout: src/io/basis_file.rs).
pub fn write_training(f: &hdf5::File, r: &GreedyRecord) -> hdf5::Result<()> {
    use crate::io::h5::{attr_str, attr_u64};
    use ndarray::{arr0, Array1, Array2};
    let g = f.create_group("training")?;
    let col = |get: &dyn Fn(&Iteration) -> f64| Array1::from_iter(r.iterations.iter().map(get));
    g.new_dataset_builder().with_data(&Array1::from(vec![r.range.0, r.range.1])).create("range")?;
    g.new_dataset_builder().with_data(&arr0(r.tolerance)).create("tolerance")?;
    g.new_dataset_builder().with_data(&Array1::from(r.load_scales.clone())).create("load_scales")?;
    g.new_dataset_builder().with_data(&Array1::from(r.candidates.clone())).create("candidates")?;
    g.new_dataset_builder().with_data(&col(&|i| i.worst_estimate)).create("worst_estimate")?;
    g.new_dataset_builder().with_data(&col(&|i| i.worst_load)).create("worst_load")?;
    g.new_dataset_builder().with_data(&col(&|i| i.true_error)).create("true_error")?;
    g.new_dataset_builder().with_data(&col(&|i| i.energy)).create("energy_tolerance")?;
    g.new_dataset_builder().with_data(&col(&|i| i.hyper_tolerance)).create("hyper_tolerance")?;
    g.new_dataset_builder().with_data(&Array1::from_iter(r.iterations.iter().map(|i| i.n_modes as u64))).create("n_modes")?;
    g.new_dataset_builder().with_data(&Array1::from_iter(r.iterations.iter().map(|i| i.n_elements as u64))).create("n_elements")?;
    let (ni, nc) = (r.iterations.len(), r.candidates.len());
    let est = Array2::from_shape_fn((ni, nc), |(i, j)| r.iterations[i].estimates.get(j).copied().unwrap_or(f64::NAN));
    g.new_dataset_builder().with_data(&est).create("estimates")?;
    attr_str(&g, "method", "greedy")?;
    attr_u64(&g, "iterations", ni as u64)?;
    attr_u64(&g, "max_runs", r.max_runs as u64)?;
    attr_u64(&g, "full_runs", r.full_runs as u64)?;
    attr_u64(&g, "converged", r.converged as u64)
}
