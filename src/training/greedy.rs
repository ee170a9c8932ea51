//! Greedy training over a load range (`[train] greedy = { range = [A, B], tolerance = T,
//! max_runs = K, candidates = N }`) or over a `[parameters]` box (`greedy = { tolerance = T,
//! max_runs = K }`); docs/greedy-training.md.
//!
//! ```text
//!     Λ = {λ₁ … λ_N}, N evenly spaced loads of [A, B]        (the candidates;
//!         in a box N points drawn in the unit cube: `candidate_set.rs`)
//!     S = full runs at A, (A + B)/2, B                        (at most K of them;
//!         in a box the lower and upper corners and the centre)
//!     repeat:
//!         for ε = 10⁻², 10⁻³, … (loose → tight):              (the mode search)
//!             V_ε = POD of S per block, the fewest modes with energy ≥ 1 − ε,
//!             ECSW at τ = √ε, and the estimator of V_ε (k more modes, its own ECSW);
//!             η_ε(λ) = the estimate of rel_error at every λ ∈ Λ (reduced runs, rayon);
//!             keep the first ε with B(η_ε) ≤ T, else the tightest tried whose runs
//!             did not fail (`search::fallback`);
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
//!   (`between::pair_bound`; in a box over each candidate and its d + 1 nearest
//!   neighbours in the unit cube): the tolerance is a promise for every load of the
//!   range, and between two candidates the estimate is taken to rise above the larger by
//!   as much as it changes between them (a few per cent for a smooth estimate, 33
//!   candidates); between two *sensitive* candidates (amplifying, below) the
//!   larger of the two alone, as their scores jump with the dynamics. The search and the stopping test hold the same bound to T: an earlier
//!   fixed T / 2 in the search chose bases twice as costly as needed (the pendulum: 23
//!   sampled elements where 10 keep every estimate within T).
//! - the stopping test rescales the estimates by the calibration the held-out run just
//!   changed (c/c_old, the estimate is linear in c): a held-out run that shows the
//!   estimator reading low sends the loop on instead of certifying estimates made with the
//!   old factor.
//! - a tighter ε whose estimator basis is no richer than the basis in some block (the
//!   block's snapshots span no more) ends the search: its estimate would compare the basis with
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
//!       score(λ) = T · max_i η_i(λ) / h_i(λ),     i = 1 … 5 (fifths of the run)
//!       h_i = s_i  where s_i > max(T, 10 δ) (the model amplifies changes of the load),
//!       h_i = T    elsewhere
//!   ```
//!
//!   with `η_i` the estimate and `s_i` the reduced model's own *sensitivity* over the run
//!   up to the end of fifth `i`: `s_i(λ) = ‖X_r(λ(1 + δ)) − X_r(λ)‖ / ‖X_r(λ)‖` over those
//!   instants, δ = [`SENSITIVITY_STEP`] (0.1 %; in a box every parameter of the box
//!   times 1 + δ). Where the model does not amplify the score is the estimate itself. Where
//!   its answer changes by more than T and more than 10 δ when the load changes by δ (the
//!   four-bar after t ≈ 0.7 s; `rom::trust::amplifying`, the rule of the online warning), the
//!   estimate there is held to `s_i` instead: any estimate compares two trajectories of
//!   the same chaotic dynamics, so below `s_i` it measures how the dynamics amplify small
//!   differences (the estimator's own among them) more than the reduction error, and full
//!   runs spent there do not make the basis better. The whole-run estimate is still what
//!   every reduced run reports; `/training/whole_run_estimates` keeps it. A response
//!   proportional to the load moves by about δ (in the displacement measure by δ exactly):
//!   that is no amplification, and a tolerance below it is held as given (relaxed by any
//!   `s_i > T`, a clamped beam held to 1e-4 in the displacement measure "converged" with a
//!   held-out error of 3.0e-4).
//!
//! Nothing here is fitted to a model: the ladder, √ε and the bound B are the same for
//! every model; a reduced run that fails (Newton diverges) counts as an infinite estimate.
//!
//! The loop is here; the mode and hyper-reduction search of one iteration is in `search.rs`,
//! the estimates, sensitivities and scores at the candidates in `candidates.rs`.

mod between;
mod candidate_set;
mod candidates;
mod search;

pub use candidate_set::CandidateSet;
pub use candidates::{score, SENSITIVITY_STEP};
pub use search::{ENERGY_LADDER, TAU_LADDER};

use crate::error::Result;
use crate::io::basis_file::TrainingData;
use crate::model::Model;
use crate::pipeline::config::{GreedyMeasure, GreedySpec, Pipeline};
use crate::reduction::Basis;
use crate::rom::estimator::norms::rel_error_by_time;
use crate::rom::estimator::training::{calibrate, calibrate_quantities, CalibrationPoint, QuantityPoint};
use crate::rom::estimator::{quantity_key, ByFifth, ErrorMeasure, EstimateMethod, FIFTHS};
use crate::rom::trust::amplifying;
use crate::rom::Rom;
use crate::simulate::{simulate, Overrides, SimulationResult};
use crate::solver::model::Parameters;
use crate::training::basis_build::training_data;
use crate::training::training_record::{modes_text, TrainSummary};
pub use crate::training::training_record::{write_training, GreedyRecord, Iteration};
use crate::workflows::validate::compare;
use rayon::prelude::*;
use search::{search, Level, Round};
use std::sync::Arc;

/// Greedy training (module documentation); nothing is written.
pub fn train(p: &Pipeline, g: &GreedySpec) -> Result<(TrainingData, TrainSummary)> {
    let candidates = CandidateSet::new(g, &p.space());
    let mut state = Greedy::start(p, g, &candidates)?;
    let (chosen, converged) = loop {
        crate::interrupt::check()?;
        let data = training_data(&state.runs);
        let previous_energy = state.iterations.last().map(|i: &Iteration| i.energy);
        let prior = state.iterations.last().map(|i: &Iteration| i.estimates.as_slice());
        let n = state.iterations.len() + 1;
        let settled = settled(&candidates, &state.runs);
        let (points, method) = (&state.points, state.method);
        let round = Round { p, data: &data, candidates: &candidates, points, n, method, prior, settled: &settled };
        let level = search(&round, g, previous_energy)?;
        if let Some(stop) = state.step(p, g, &candidates, level)? {
            break stop;
        }
    };
    state.finish(p, g, candidates, chosen, converged)
}

/// The greedy loop's state between its iterations.
struct Greedy<'a> {
    /// the full runs whose snapshots the next basis is built from
    runs: Vec<SimulationResult>,
    /// the later full runs, one at a time, on one full model
    full_model: crate::simulate::FullModel<'a>,
    full_seconds: f64,
    /// full runs made, the held-out checks included
    full_runs: usize,
    /// the held-out pairs (raw estimate, true error) the estimator is calibrated with
    points: Vec<CalibrationPoint>,
    /// the same pairs for each probe quantity and joint reaction (`c_q`)
    quantity_points: Vec<QuantityPoint>,
    iterations: Vec<Iteration>,
    warnings: Vec<String>,
    /// warnings that the training's method over-reads: moot once the loop switches method
    over_reading: Vec<String>,
    /// the estimate the loop steers by, until a held-out check finds it off
    method: EstimateMethod,
    /// what the converged held-out check found above the tolerance, in words (`/training`)
    held_out_note: Option<String>,
}

impl<'a> Greedy<'a> {
    /// The first full runs (in parallel), at the candidate set's first points.
    fn start(p: &'a Pipeline, g: &GreedySpec, candidates: &CandidateSet) -> Result<Self> {
        let full = |mu: &Parameters| {
            simulate(&p.model, &Overrides::at(mu)).map_err(|e| e.at_stage("train (greedy full run)", mu))
        };
        let first = candidates.first(g, g.max_runs);
        if candidates.is_box() {
            log::info!(
                "greedy training over the box {}, tolerance {:e}, {} candidates: full runs at {}",
                candidates.space.describe(),
                g.tolerance,
                candidates.len(),
                first.iter().map(|mu| format!("({})", candidates.label(mu))).collect::<Vec<_>>().join(", ")
            );
        } else {
            let range = g.range();
            log::info!(
                "greedy training over [{}, {}], tolerance {:e}, {} candidates: full runs at {:?}",
                range.0,
                range.1,
                g.tolerance,
                candidates.len(),
                first.iter().map(Parameters::scale).collect::<Vec<_>>()
            );
        }
        let runs: Vec<SimulationResult> = first.par_iter().map(full).collect::<Result<_>>()?;
        let full_model = crate::simulate::FullModel::new(&p.model, crate::linalg::kkt::LinearSolverKind::Banded)?;
        let full_seconds: f64 = runs.iter().map(|r| r.wall_seconds).sum();
        let full_runs = runs.len();
        Ok(Greedy {
            runs,
            full_model,
            full_seconds,
            full_runs,
            points: Vec::new(),
            quantity_points: Vec::new(),
            iterations: Vec::new(),
            warnings: Vec::new(),
            over_reading: Vec::new(),
            method: EstimateMethod::Corrected,
            held_out_note: None,
        })
    }

    /// One iteration after its search found `level`: the full run at the worst candidate
    /// without one, the held-out check there and the decision. `Some((basis, converged))`
    /// ends the loop.
    fn step(
        &mut self,
        p: &Pipeline,
        g: &GreedySpec,
        candidates: &CandidateSet,
        mut level: Level,
    ) -> Result<Option<(Level, bool)>> {
        let (wi, worst) = level.worst();
        // where to run the full model: the worst candidate without a full run yet (a
        // training point's own run is already in the snapshots)
        let runs = &self.runs;
        let fresh = |i: usize| runs.iter().all(|r| !candidates.is_at(i, &r.settings.mu));
        let next = level.worst_where(fresh);
        let mut it = self.iteration_of(p, &level, (wi, worst));
        let shape = shape_text(&level, &it);
        let n = self.iterations.len() + 1;
        let Some((ni, next_estimate)) = next.filter(|_| self.full_runs < g.max_runs) else {
            let converged = self.out_of_runs(g, candidates, &it, (wi, worst), &shape);
            self.iterations.push(it);
            return Ok(Some((level, converged)));
        };
        // the full run at the worst candidate: snapshots for the next basis, and the true
        // error of this one there (it never saw that point)
        let mu = candidates.points[ni].clone();
        let at = candidates.label(&mu);
        let truth =
            self.full_model.simulate(&Overrides::at(&mu)).map_err(|e| e.at_stage("train (greedy full run)", &mu))?;
        let (e_measured, e_score, sens) = self.held_out(p, g, candidates, (&mut level, &mut it), (ni, &at), &truth);
        // the held-out check may have re-read the candidates with another estimate
        let worst = it.worst_estimate;
        let cmp = if worst <= g.tolerance { "≤" } else { ">" };
        // the held-out pair may have raised the calibration factor: the estimates this
        // basis will report are the candidates' scaled by it (the estimate is linear in c)
        let rescale = calibrate(self.points.clone()).factor / level.estimator.calibration.factor;
        let bound = it.bound * rescale.max(1.0);
        let done = bound <= g.tolerance && e_score <= g.tolerance;
        if done {
            let name = g.measure.error_name();
            self.held_out_note = above_tolerance_note(g.measure, g.tolerance, (&at, e_measured), (e_score, sens));
            let check = match &self.held_out_note {
                Some(note) => note.clone(),
                None => format!("{name} {e_measured:.2e} (score {e_score:.2e}, sensitivity {sens:.1e})"),
            };
            log::info!("iteration {n}: worst score {worst:.2e} ≤ {:e}; held-out check at {at} (score {next_estimate:.2e}): {check}; {shape}", g.tolerance);
        } else {
            // with every score within T, say what keeps the loop going
            let why = if worst > g.tolerance {
                String::new()
            } else if bound > g.tolerance {
                format!("; the bound between candidates is {bound:.2e} > {:e}", g.tolerance)
            } else {
                format!("; the held-out run's own score is above {:e}", g.tolerance)
            };
            log::info!("iteration {n}: full run at {at} (worst score {worst:.2e} {cmp} {:e}; {next_estimate:.2e} there, true error {e_measured:.2e}, its score {e_score:.2e}, sensitivity {sens:.1e}){why}, {shape}", g.tolerance);
        }
        self.iterations.push(it);
        if done {
            return Ok(Some((level, true)));
        }
        self.runs.push(truth);
        Ok(None)
    }

    /// The record of this iteration's basis and estimates (`(wi, worst)`: the candidate
    /// with the largest score), before any held-out run.
    fn iteration_of(&self, p: &Pipeline, level: &Level, (wi, worst): (usize, f64)) -> Iteration {
        let b = &level.trained.basis;
        Iteration {
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
            worst_candidate: wi,
            worst_estimate: worst,
            run_candidate: None,
            true_error: f64::NAN,
            true_score: f64::NAN,
            held_out_effectivity: f64::NAN,
            method: self.method,
            bound: level.between_candidates(),
            between_points: level.between_points,
        }
    }

    /// The loop's end where no full run is left to make (`max_runs` reached, or every
    /// candidate has one): converged when the bound between candidates meets the tolerance,
    /// with no held-out run to check the basis (a warning says so).
    fn out_of_runs(
        &mut self,
        g: &GreedySpec,
        candidates: &CandidateSet,
        it: &Iteration,
        (wi, worst): (usize, f64),
        shape: &str,
    ) -> bool {
        let n = self.iterations.len() + 1;
        let cmp = if worst <= g.tolerance { "≤" } else { ">" };
        let why = if self.full_runs >= g.max_runs {
            format!("no full run left (max_runs = {})", g.max_runs)
        } else {
            "every candidate has a full run".into()
        };
        // the same test as the stop after a held-out run, without a held-out run to
        // recalibrate with
        let bound = it.bound;
        log::info!(
            "iteration {n}: {why}, worst estimate {worst:.2e} {cmp} {:e} at {} (bound between candidates {bound:.2e}), {shape}",
            g.tolerance,
            candidates.label_of(wi)
        );
        let converged = bound <= g.tolerance;
        if converged {
            // the basis kept is built from every run: none is left to hold out against it
            self.warnings.push(format!(
                "greedy training met its tolerance {:e} with its last basis, which no held-out full run checked ({why}): its estimates alone certify it; `validate` a few loads of the range",
                g.tolerance
            ));
        }
        converged
    }

    /// The held-out check of this iteration's basis at candidate `ni` (named `at`) against
    /// the full run `truth` there: its true error (calibrating the estimator), its score,
    /// and the check of the estimate itself, which may switch the loop to the enriched
    /// estimate (re-reading the candidates). Returns the true error in the training's
    /// measure, its score and the model's sensitivity there.
    fn held_out(
        &mut self,
        p: &Pipeline,
        g: &GreedySpec,
        candidates: &CandidateSet,
        (level, it): (&mut Level, &mut Iteration),
        (ni, at): (usize, &str),
        truth: &SimulationResult,
    ) -> (f64, f64, f64) {
        let mu = &candidates.points[ni];
        self.full_seconds += truth.wall_seconds;
        self.full_runs += 1;
        // rel_error `e` calibrates the estimator; the error in the training's measure is held to T
        let truth_error = true_error(&p.model, &level.trained.basis, truth, mu);
        let (e, e_measured) = (truth_error.rel_error, truth_error.in_measure(g.measure));
        let by_time =
            candidates::at_rest_as_relative(&truth_error.by_time_in(g.measure), &truth_error.rel_error_by_time);
        let e_score = score(g.tolerance, &by_time, &level.sensitivity[ni]);
        let c = level.estimator.calibration.factor;
        (it.run_candidate, it.true_error, it.true_score) = (Some(ni), e_measured, e_score);
        it.held_out_effectivity = c * level.raws[ni] / e;
        if level.raws[ni].is_finite() && e.is_finite() {
            self.points.push(CalibrationPoint { load_scale: mu.scale(), raw_estimate: level.raws[ni], rel_error: e });
        }
        self.quantity_points.extend(level.quantity_raws(ni).iter().filter_map(|(key, raw)| {
            let error = truth_error.by_quantity.iter().find(|(k, _)| k == key)?.1;
            Some(QuantityPoint { key: key.clone(), raw_estimate: *raw, error })
        }));
        // the held-out check of the estimate itself: off by more than the method assumes, the
        // loop reads the candidates with the enriched model (the reference the correction
        // approximates) from here on, when that reads closer at this point; not for an
        // under-reading the dynamics explain (check_method)
        let sens = level.sensitivity[ni][FIFTHS - 1];
        let under = it.held_out_effectivity < 1.0;
        let dynamics = if under { dynamics_error(sens, g.tolerance, e_measured) } else { None };
        let found = (e, it.held_out_effectivity, dynamics.map(|s| (s, e_measured)));
        if let Some(checked) = check_method(p, level, self.method, (mu, at), found) {
            log::info!("{}", checked.message);
            if !checked.switch && it.held_out_effectivity > MAX_HELD_OUT_OVERESTIMATE {
                self.over_reading.push(checked.message);
            } else if checked.switch {
                self.over_reading.clear();
                self.method = EstimateMethod::Enriched;
                // the earlier pairs were the other method's readings (and its quantities'
                // readings at this point are not known)
                self.points =
                    vec![CalibrationPoint { load_scale: mu.scale(), raw_estimate: checked.raw, rel_error: e }];
                self.quantity_points.clear();
                level.estimator.calibration = calibrate(self.points.clone());
                level.estimate(
                    p,
                    candidates,
                    &format!("iteration {}, enriched estimates", self.iterations.len() + 1),
                    self.method,
                );
                it.estimates = level.estimates.clone();
                it.whole_run_estimates = level.whole.clone();
                it.worst_estimate = level.worst().1;
                it.method = self.method;
                (it.bound, it.between_points) = (level.between_candidates(), level.between_points);
            }
        }
        (e_measured, e_score, sens)
    }

    /// After the loop: the chosen basis's estimator calibrated on every held-out pair, the
    /// cheap `defects` estimate calibrated against it, the notes and the record.
    fn finish(
        mut self,
        p: &Pipeline,
        g: &GreedySpec,
        candidates: CandidateSet,
        chosen: Level,
        converged: bool,
    ) -> Result<(TrainingData, TrainSummary)> {
        let (method, iterations) = (self.method, &self.iterations);
        if !converged {
            self.warnings.push(format!(
                "greedy training stopped after {} full runs (max_runs = {}) above its tolerance {:e} (worst score {:.2e}, bound between candidates {:.2e}): {}",
                self.full_runs,
                g.max_runs,
                g.tolerance,
                iterations.last().map_or(f64::NAN, |i| i.worst_estimate),
                iterations.last().map_or(f64::NAN, |i| i.bound),
                why_not_converged(g.tolerance, iterations, &candidates, &chosen.failures(), &settled(&candidates, &self.runs))
            ));
        }
        let pair_bounds = chosen.pair_bounds().map(<[f64]>::to_vec);
        let Level { trained, mut estimator, .. } = chosen;
        let level_factor = estimator.calibration.factor;
        estimator.calibration = calibrate_quantities(calibrate(self.points), &self.quantity_points);
        // the cheap online estimate on the training estimate's scale (`DefectsCalibration`)
        estimator.defects = candidates::calibrate_defects(&p.model, &trained.basis, &estimator, &candidates, method);
        if method == EstimateMethod::Enriched && !estimator.defects.as_ref().is_some_and(|d| d.reliable) {
            // the correction was found off for this basis: its online estimates read the reference
            estimator.method = Some(EstimateMethod::Enriched);
        }
        log::info!("{}", defects_line(&estimator, method));
        // what the online default reads between the candidates, where training met T with
        // its own estimate there
        let estimate_note = match (&estimator.defects, &pair_bounds) {
            (Some(d), Some(b)) if converged && estimator.default_method() == EstimateMethod::Defects => {
                let rescale = (estimator.calibration.factor / level_factor).max(1.0);
                let bounds: Vec<f64> = b.iter().map(|x| x * rescale).collect();
                defects_note(g.tolerance, method, &candidates.pairs, &bounds, &d.ratios)
            }
            _ => None,
        };
        if let Some(note) = &estimate_note {
            log::info!("{note}");
        }
        let data = training_data(&self.runs);
        let record = GreedyRecord {
            range: if candidates.is_box() { None } else { Some(g.range()) },
            tolerance: g.tolerance,
            max_runs: g.max_runs,
            candidates,
            runs: self.runs.iter().map(|r| r.settings.mu.clone()).collect(),
            iterations: self.iterations,
            converged,
            full_runs: self.full_runs,
            method,
            measure: g.measure.coordinates(),
            held_out_note: self.held_out_note,
            estimate_note,
        };
        let mut warnings = self.warnings;
        warnings.splice(0..0, self.over_reading);
        let n_snapshots = data.x.ncols();
        Ok((
            data,
            TrainSummary {
                trained,
                n_snapshots,
                full_seconds: self.full_seconds,
                n_runs: self.full_runs,
                greedy: Some(record),
                estimator: Some(estimator),
                warnings,
            },
        ))
    }
}

/// The basis's shape in words: modes per block, output modes, kept joint coordinates and
/// elements.
fn shape_text(level: &Level, it: &Iteration) -> String {
    let b = &level.trained.basis;
    let outputs = &level.trained.output_modes;
    format!(
        "{}{}{}, {} elements",
        modes_text(&it.block_modes),
        if outputs.iter().all(|&k| k == 0) {
            String::new()
        } else {
            format!(" + {} output modes", outputs.iter().map(|k| k.to_string()).collect::<Vec<_>>().join(" + "))
        },
        if b.kept.is_empty() { String::new() } else { format!(" + {} joint coordinates", b.kept.len()) },
        it.n_elements
    )
}

/// The line on the cheap `defects` estimate's calibration against the training's `method`.
fn defects_line(estimator: &crate::rom::estimator::training::Estimator, method: EstimateMethod) -> String {
    match &estimator.defects {
        Some(d) if d.reliable => format!(
            "error estimate: the cheap `defects` method calibrated at the {} candidates against the `{}` estimate (factors {}), the online default",
            d.ratios.len(),
            method.name(),
            d.factors.iter().map(|&f| crate::solver::parameter_space::short_number(f)).collect::<Vec<_>>().join(", ")
        ),
        Some(_) => format!("error estimate: the `defects` method's ratio to the {} estimate jumps between candidates (its leave-one-out check failed): the online default stays `{}`", method.name(), estimator.default_method().name()),
        None => format!("error estimate: the `defects` method could not be calibrated: the online default stays `{}`", estimator.default_method().name()),
    }
}

/// The sentence for a converged held-out check whose error (`error`, in `measure`, at `at`)
/// is above the tolerance: the check passed because where the model amplifies changes of
/// the load its score holds the error to the model's own sensitivity there instead of the
/// tolerance (`score ≤ T`, the module documentation), and the line says so instead of
/// leaving "≤ T" to read as the error's; `None` when the error is within the tolerance.
fn above_tolerance_note(
    measure: GreedyMeasure,
    tolerance: f64,
    (at, error): (&str, f64),
    (score, sensitivity): (f64, f64),
) -> Option<String> {
    (error > tolerance).then(|| {
        format!(
            "held-out {} {error:.2e} at {at} is above the tolerance {tolerance:e}; the model's own sensitivity there is {sensitivity:.1e} (a 0.1 % change of the load moves its answer by that much), so errors of that size come from the dynamics: where the model amplifies, the check holds the error to that sensitivity instead of the tolerance (score {score:.2e} ≤ {tolerance:e}), and the basis was kept; the tolerance is met where the model does not amplify",
            measure.error_name()
        )
    })
}

/// The sentence for a basis whose online default, the `defects` estimate, may read above
/// the tolerance between neighbouring candidates where training's own estimate (`method`)
/// met it; `None` where it stays within. Between the candidates `i` and `j` of a pair the
/// `defects` estimate reads its raw value times the larger of their ratios `ρ` to `method`
/// (last fifth: the whole run's, `DefectsCalibration`), and `method` reads the raw value
/// times `ρ(λ)` there; where `ρ` runs between its two ends,
///
/// ```text
///     defects(λ) ≤ method(λ) · max(ρᵢ, ρⱼ) / min(ρᵢ, ρⱼ) ≤ bound_ij · max(ρᵢ, ρⱼ) / min(ρᵢ, ρⱼ)
/// ```
///
/// with `bound_ij` the pair's bound the loop held to T (`pair_bounds`, `pairs` order): a
/// reading, not a bound, as `ρ` may dip below both ends (the tutorial's double pendulum:
/// 1.01e-3 by this rule, 1.02e-3 read at λ = 1.475). A pair without two finite positive
/// ratios counts at its bound.
fn defects_note(
    tolerance: f64,
    method: EstimateMethod,
    pairs: &[(usize, usize)],
    pair_bounds: &[f64],
    ratios: &[ByFifth],
) -> Option<String> {
    let last = |i: usize| ratios.get(i).map_or(f64::NAN, |r| r[FIFTHS - 1]);
    let spread = |i: usize, j: usize| {
        let (a, b) = (last(i), last(j));
        if a.is_finite() && b.is_finite() && a > 0.0 && b > 0.0 {
            a.max(b) / a.min(b)
        } else {
            1.0
        }
    };
    let (reads, at, spread) = pairs
        .iter()
        .zip(pair_bounds)
        .map(|(&(i, j), &b)| (b * spread(i, j), b, spread(i, j)))
        .fold((0.0_f64, f64::NAN, 1.0), |m, x| if x.0 > m.0 { x } else { m });
    (reads > tolerance && at <= tolerance).then(|| {
        let m = method.name();
        format!(
            "the online default, the cheap `defects` estimate, reads above the tolerance {tolerance:e} between some neighbouring candidates where the `{m}` estimate met it: between two candidates it takes the larger of their ratios to `{m}`, up to {spread:.2}× apart, which over the bound {at:.2e} reads about {reads:.2e} (more where the ratio dips between them); `--estimate {m}` (`[online] estimate = \"{m}\"`) reads what training held to the tolerance"
        )
    })
}

/// What an estimate at a held-out load may read against the true error there: at least the
/// error (a bound), at most this many times it. Beyond it the estimate no longer steers the
/// loop (every candidate reads far above the tolerance) and the calibration factor, which
/// only ever raises it, cannot bring it back.
pub const MAX_HELD_OUT_OVERESTIMATE: f64 = 10.0;

/// The sensitivity `s` of a held-out point (how much a 0.1 % change of the load moves the
/// answer there, in the training's measure) where the model amplifies load changes
/// (`amplifying(s, tolerance)`, as greedy's scores judge it) by at least the `error` found
/// there; `None` otherwise, and for an infinite `s` (the moved run could not be compared:
/// it holds nothing, as in the scores).
fn dynamics_error(s: f64, tolerance: f64, error: f64) -> Option<f64> {
    (s.is_finite() && amplifying(s, tolerance) && error <= s).then_some(s)
}

/// What a held-out check found of the estimate's method ([`check_method`]).
struct MethodCheck {
    /// read the candidates with the enriched model from here on
    switch: bool,
    /// the enriched model's raw estimate at the held-out load
    raw: f64,
    message: String,
}

/// The held-out check of the estimate itself: at the point `mu` (named `at` in messages),
/// where the full run gave the true error `e`, the estimate by `method` read `eff` times it. Outside
/// `[1, MAX_HELD_OUT_OVERESTIMATE]` the enriched model (integrated to convergence, the
/// reference the `corrected` method approximates) reads the same load; when it is closer
/// to that range, the loop switches to it. Not for an estimate below the error at a point
/// where the model amplifies load changes by at least that error (`dynamics`: the
/// sensitivity there and the error, both in the training's measure): a 0.1 % change of the
/// load moves the answer by as much, so how close either method comes to that error says
/// little about the method, and switching would make every later estimate cost an enriched
/// run; the calibration factor takes the point instead, as at any held-out run. `None`:
/// nothing to check or nothing found.
fn check_method(
    p: &Pipeline,
    level: &search::Level,
    method: EstimateMethod,
    (mu, at): (&Parameters, &str),
    (e, eff, dynamics): (f64, f64, Option<(f64, f64)>),
) -> Option<MethodCheck> {
    if method == EstimateMethod::Enriched || !(e.is_finite() && e > 0.0) {
        return None;
    }
    if (1.0..=MAX_HELD_OUT_OVERESTIMATE).contains(&eff) {
        return None;
    }
    if let Some((s, error)) = dynamics {
        let message = format!(
            "held-out check at {at}: the {} estimate read {eff:.3}× the true error {e:.2e} (1–{MAX_HELD_OUT_OVERESTIMATE}× expected), where a 0.1 % change of the load moves the answer by {s:.1e}, at least the error ({error:.2e} in the training's measure): the error is the dynamics' there; the method stays, the calibration factor is raised to cover it",
            method.name()
        );
        return Some(MethodCheck { switch: false, raw: f64::NAN, message });
    }

    let rom =
        candidates::training_rom(&p.model, &level.trained.basis, &level.estimator, EstimateMethod::Enriched).ok()?;
    let run = rom.solve_with(mu, crate::rom::Output::ReducedAndProbes, &[]).ok()?;
    let reading = rom.estimate_error(&run, mu)?;
    let eff_ref = reading.error_estimate / e;
    // how far outside [1, MAX] (in orders of magnitude); NaN counts as infinitely far
    let off = |x: f64| {
        if !(x > 0.0) {
            f64::INFINITY
        } else if x < 1.0 {
            -x.ln()
        } else {
            (x / MAX_HELD_OUT_OVERESTIMATE).ln().max(0.0)
        }
    };
    let switch = off(eff_ref) < off(eff);
    let head = format!(
        "held-out check at {at}: the {} estimate read {eff:.3}× the true error {e:.2e} (1–{MAX_HELD_OUT_OVERESTIMATE}× expected)",
        method.name()
    );
    let message = if !eff.is_finite() && !eff_ref.is_finite() {
        format!(
            "held-out check at {at}: neither the {} estimate nor the enriched model's could be computed there (their richer model's run failed; true error {e:.2e})",
            method.name()
        )
    } else if switch {
        format!("{head}; the enriched model reads {eff_ref:.3}× there: the loop and this basis's estimates use `enriched` from here")
    } else {
        // the same reading to the last digits: the method read the enriched model itself
        // there (a `corrected` run whose correction did not converge falls back to it)
        let reference = if (eff - eff_ref).abs() <= 1e-12 * eff.abs() {
            "the enriched model's own reading there, which it fell back to".to_string()
        } else {
            format!("the enriched model {eff_ref:.3}×")
        };
        if eff < 1.0 {
            format!("{head}, {reference}: the calibration factor is raised to cover it")
        } else {
            format!("{head}, {reference}: on this model the estimate reads far above the error, and greedy training may spend its full runs where the basis is already good enough")
        }
    };
    Some(MethodCheck { switch, raw: reading.raw, message })
}

/// Which candidates have a full run among `runs` ([`between::pair_bound`]).
fn settled(candidates: &CandidateSet, runs: &[SimulationResult]) -> Vec<bool> {
    (0..candidates.len()).map(|i| runs.iter().any(|r| candidates.is_at(i, &r.settings.mu))).collect()
}

/// Why the loop ended above its tolerance, from what it saw, in the order a user can act on:
/// candidates where no estimate could be computed; the full model's own sensitivity to the
/// load (where a 0.1 % change of the load moves the answer by more than T, the held-out
/// errors and the estimates there measure the dynamics as much as the basis); held-out
/// checks that found the estimate off by more than its method allows; else too few runs.
fn why_not_converged(
    tolerance: f64,
    iterations: &[Iteration],
    candidates: &CandidateSet,
    failures: &[(usize, &str)],
    trained: &[bool],
) -> String {
    let Some(last) = iterations.last() else { return "no iteration ran".into() };
    let n = candidates.len();
    let failed = last.estimates.iter().filter(|e| e.is_infinite() || e.is_nan()).count();
    if failed > 0 {
        // the first failure named with its cause: a reduced run that fails at a load whose
        // full run is in the snapshots is the reduced model's own instability there
        let first = failures.first().map_or(String::new(), |&(i, why)| {
            format!(
                "; at {}{}, {why}",
                candidates.label_of(i),
                if trained[i] { " (a training load: its full run is in the snapshots)" } else { "" }
            )
        });
        return format!(
            "no estimate could be computed at {failed} of {n} candidates (a reduced or richer-model run failed there; `train -v` names them){first}; validate those loads with full runs, or narrow the range"
        );
    }
    // the largest sensitivity the loop met, over the candidates of every iteration
    let (mut s_max, mut at_max) = (0.0_f64, String::new());
    for it in iterations {
        for (i, &s) in it.sensitivity.iter().enumerate() {
            if s > s_max {
                (s_max, at_max) = (s, candidates.label_of(i));
            }
        }
    }
    let sensitive_held_out =
        iterations.iter().filter(|it| it.true_error > tolerance && it.true_score <= tolerance).count();
    // the full model amplifies changes of the load: above T, and above what a response
    // proportional to the load moves for the step δ (δ itself) by `AMPLIFYING` (the rule
    // of the online warning, `rom::trust`); a tolerance below δ meets every linear response
    let amplifies = amplifying(s_max, tolerance);
    // every score within T, but neighbours far apart: the loads between them are not certified
    if last.worst_estimate <= tolerance && last.bound > tolerance {
        let e = &last.estimates;
        let (ratio, at) = candidates
            .pairs
            .iter()
            .map(|&(i, j)| (e[i].max(e[j]) / e[i].min(e[j]), i))
            .fold((0.0_f64, 0), |a, b| if b.0 > a.0 { b } else { a });
        return format!(
            "every candidate's score is within it, but neighbouring scores differ by up to {ratio:.0}× (from {}), and the {} point{} looked at between such neighbours left the loads between them uncertified{}; there the error changes faster with the load than {} bisections of the candidates' spacing resolve: a narrower range or a looser tolerance certifies",
            candidates.label_of(at),
            last.between_points,
            if last.between_points == 1 { "" } else { "s" },
            if amplifies {
                format!(" (the full model is sensitive to the load: a 0.1 % change moves its answer by up to {s_max:.1e}, at {at_max})")
            } else {
                String::new()
            },
            between::MAX_BISECTIONS
        );
    }
    if amplifies {
        return format!(
            "the full model is sensitive to the load (a 0.1 % change moves its answer by up to {s_max:.1e} over the run, at {at_max}{}): there the tolerance asks more than the load determines; a looser tolerance, a shorter run (`[time] t_end`) or a narrower range certifies, and `error_estimate_by_time` shows the early part of the run",
            if sensitive_held_out > 0 { format!("; {sensitive_held_out} held-out errors above T were within it") } else { String::new() }
        );
    }
    let off = iterations
        .iter()
        .filter(|it| {
            it.held_out_effectivity.is_finite() && !(1.0..=MAX_HELD_OUT_OVERESTIMATE).contains(&it.held_out_effectivity)
        })
        .count();
    if off > 0 {
        return format!(
            "at {off} of its held-out runs the estimate read outside 1–{MAX_HELD_OUT_OVERESTIMATE}× the true error (the lines above); validate a few loads before trusting the basis"
        );
    }
    // the last runs left the basis as it was and the worst score nearly so: their snapshots
    // held little the basis did not (as when the response is proportional to the load)
    let tail = &iterations[iterations.len().saturating_sub(STALLED_RUNS)..];
    let (first, last_score) = (tail[0].worst_estimate, tail[tail.len() - 1].worst_estimate);
    if tail.len() == STALLED_RUNS
        && tail.iter().all(|it| it.block_modes == tail[0].block_modes)
        && last_score > STALLED_FALL * first
    {
        return format!(
            "its last {STALLED_RUNS} iterations kept the basis at {} and lowered the worst score only from {first:.2e} to {last_score:.2e}: the full runs added little the basis did not hold (as when the response is proportional to the load), so more runs are unlikely to help; a looser tolerance certifies{}",
            modes_text(&tail[0].block_modes),
            if s_max > tolerance {
                format!(" (a 0.1 % change of the load moves the answer by up to {s_max:.1e}, no more than a response proportional to it: the measure, not the dynamics)")
            } else {
                String::new()
            }
        );
    }
    "each full run lowered the worst estimate less than the tolerance needs; raise max_runs (or the tolerance)".into()
}

/// Iterations in a row with the same modes after which the stop line calls the runs
/// stalled, and the fraction of the first's worst score the last must still be above (the
/// runs took off less than half of it).
const STALLED_RUNS: usize = 3;
const STALLED_FALL: f64 = 0.5;

/// The true errors of a basis at a held-out point: rel_error (what calibrates the estimator)
/// and both measures by fifth of the run.
struct TrueError {
    rel_error: f64,
    rel_error_by_time: ByFifth,
    displacement_error_by_time: ByFifth,
    /// the largest error of a probe quantity or a joint reaction over its range (0 without
    /// probes or joints)
    quantities: f64,
    /// each probe quantity's and reaction's error over its range, by key `quantity:probe`
    /// (none where it has no swing to measure against)
    by_quantity: Vec<(String, f64)>,
}

impl TrueError {
    /// The whole run's error in `measure` (rel_error as `validate` sums it; with the probes'
    /// measure the larger of it and the worst probe quantity's).
    fn in_measure(&self, measure: GreedyMeasure) -> f64 {
        match measure {
            GreedyMeasure::Relative => self.rel_error,
            GreedyMeasure::Displacement => self.displacement_error_by_time[FIFTHS - 1],
            GreedyMeasure::Probes => self.rel_error.max(self.quantities),
        }
    }

    /// By fifth of the run; the probe quantities are measured over the whole run and enter
    /// its last fifth, as the candidates' estimates do.
    fn by_time_in(&self, measure: GreedyMeasure) -> ByFifth {
        let mut e = match measure.coordinates() {
            ErrorMeasure::Relative => self.rel_error_by_time,
            ErrorMeasure::Displacement => self.displacement_error_by_time,
        };
        if measure.probes() {
            e[FIFTHS - 1] = e[FIFTHS - 1].max(self.quantities);
        }
        e
    }
}

/// The errors of `basis` at `mu` against the full run `truth`, whole and by fifth of the
/// run (∞ when the reduced run fails).
fn true_error(model: &Arc<Model>, basis: &Basis, truth: &SimulationResult, mu: &Parameters) -> TrueError {
    let run = Rom::new(model, &Arc::new(basis.clone()), None, None).and_then(|r| r.solve(mu));
    match run {
        Ok(rom) => {
            let v = compare(model, truth, &rom, None, basis.n_reduced(), basis.variant.name());
            let reactions = v.reaction_errors.iter().map(|q| (q.quantity, &q.reaction, q.relative));
            let all: Vec<_> =
                v.probe_quantity_errors.iter().map(|q| (q.quantity, &q.probe, q.relative)).chain(reactions).collect();
            let quantities = all.iter().map(|q| q.2.unwrap_or(f64::NAN));
            let by_quantity = all.iter().filter_map(|(q, name, e)| Some((quantity_key(*q, name), (*e)?)));
            TrueError {
                rel_error: v.rel_error,
                rel_error_by_time: rel_error_by_time(&rom.result.q, &truth.q),
                displacement_error_by_time: std::array::from_fn(|i| v.displacement_error_by_time[i]),
                quantities: candidates::worst_quantity(quantities),
                by_quantity: by_quantity.collect(),
            }
        }
        Err(_) => TrueError {
            rel_error: f64::INFINITY,
            rel_error_by_time: [f64::INFINITY; FIFTHS],
            displacement_error_by_time: [f64::INFINITY; FIFTHS],
            quantities: f64::INFINITY,
            by_quantity: Vec::new(),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The gate of the held-out method check: the ×20 four-bar's held-out point at
    /// λ = 1.175 (2026-11-28: sensitivity 0.13, true error 3.2e-2, T = 1e-2) is the
    /// dynamics'; an error above the sensitivity, a sensitivity within the tolerance or
    /// within 10 δ = 1e-2 (a response that follows the load), an infinite one and NaNs are
    /// not.
    #[test]
    fn a_held_out_error_within_an_amplifying_sensitivity_is_the_dynamics() {
        assert_eq!(dynamics_error(0.13, 1e-2, 3.2e-2), Some(0.13));
        assert_eq!(dynamics_error(0.13, 1e-2, 0.13), Some(0.13));
        assert_eq!(dynamics_error(0.13, 1e-2, 0.2), None, "more error than the dynamics explain");
        assert_eq!(dynamics_error(8e-3, 1e-2, 1e-3), None, "within the tolerance");
        assert_eq!(dynamics_error(8e-3, 1e-4, 1e-3), None, "within 10 δ: the load's own response");
        assert_eq!(dynamics_error(f64::NAN, 1e-2, 1e-3), None);
        assert_eq!(dynamics_error(f64::INFINITY, 1e-2, 1e-3), None, "a sensitivity that could not be measured");
        assert_eq!(dynamics_error(0.13, 1e-2, f64::NAN), None);
    }

    /// The probes' measure holds the larger of rel_error and the worst probe quantity (over
    /// its range) to the tolerance, in the whole run and in the run's last fifth (where the
    /// candidates' quantity estimates enter too); the other measures ignore the quantities.
    #[test]
    fn the_probes_measure_holds_the_worst_quantity() {
        let t = TrueError {
            rel_error: 2e-5,
            rel_error_by_time: [1e-5, 1e-5, 2e-5, 2e-5, 2.1e-5],
            displacement_error_by_time: [3e-4; FIFTHS],
            quantities: 1.2e-2,
            by_quantity: Vec::new(),
        };
        assert_eq!(t.in_measure(GreedyMeasure::Probes), 1.2e-2);
        assert_eq!(t.in_measure(GreedyMeasure::Relative), 2e-5);
        assert_eq!(t.in_measure(GreedyMeasure::Displacement), 3e-4);
        assert_eq!(t.by_time_in(GreedyMeasure::Probes), [1e-5, 1e-5, 2e-5, 2e-5, 1.2e-2]);
        assert_eq!(t.by_time_in(GreedyMeasure::Relative), t.rel_error_by_time);
        let none = TrueError { quantities: 0.0, ..t };
        assert_eq!(none.in_measure(GreedyMeasure::Probes), 2e-5, "without probe quantities: rel_error");
        assert_eq!(candidates::worst_quantity([f64::NAN, 3e-3, 1e-3].into_iter()), 3e-3, "NaN: no swing, says nothing");
        assert_eq!(candidates::worst_quantity([f64::INFINITY, 1e-3].into_iter()), f64::INFINITY);
    }

    /// The converged check's line in words: a two-link arm of 30 elements a link (T = 1e-3,
    /// held-out rel_error 2.93e-3, sensitivity 1.9e-2, score 1.55e-4 = T · 2.93e-3 / 1.9e-2,
    /// the score rule of the module documentation) says the error is above the tolerance and
    /// why the check passed; an error within T says nothing more.
    #[test]
    fn a_held_out_error_above_the_tolerance_is_said_in_words() {
        let note = above_tolerance_note(GreedyMeasure::Relative, 1e-3, ("λ = 1.3", 2.93e-3), (1.55e-4, 1.9e-2));
        let note = note.expect("above T");
        assert!(note.starts_with("held-out rel_error 2.93e-3 at λ = 1.3 is above the tolerance 1e-3;"), "{note}");
        assert!(note.contains("sensitivity there is 1.9e-2") && note.contains("come from the dynamics"), "{note}");
        assert!(note.contains("score 1.55e-4 ≤ 1e-3"), "{note}");
        let d = above_tolerance_note(GreedyMeasure::Displacement, 1e-3, ("λ = 1.3", 2.93e-3), (1.55e-4, 1.9e-2));
        assert!(d.unwrap().starts_with("held-out displacement_error"));
        assert_eq!(above_tolerance_note(GreedyMeasure::Relative, 1e-3, ("λ = 1.3", 9e-4), (9e-4, 1.9e-2)), None);
    }

    /// The online default's reading between candidates: the tutorial's double pendulum
    /// (pipelines/double_pendulum.toml, T = 1e-3) held the pair 1.46875–1.5 to a bound of
    /// 9.79e-4; with `defects` ratios 1.1× apart there it may read 9.79e-4 · 1.1 = 1.077e-3,
    /// above T, and says so; ratios alike, or a pair without two finite ratios, read at the
    /// bound, within T.
    #[test]
    fn the_online_default_above_the_tolerance_between_candidates_is_said() {
        let pairs = [(0, 1), (1, 2)];
        let fifth = |x: f64| [x; FIFTHS];
        let ratios = [fifth(0.2), fifth(0.22), fifth(0.22)];
        let note = defects_note(1e-3, EstimateMethod::Corrected, &pairs, &[9.79e-4, 5e-4], &ratios).expect("above T");
        assert!(note.contains("bound 9.79e-4 reads about 1.08e-3"), "{note}");
        assert!(note.contains("1.10× apart") && note.contains("--estimate corrected"), "{note}");
        let alike = [fifth(0.2), fifth(0.2), fifth(0.3)];
        assert_eq!(defects_note(1e-3, EstimateMethod::Corrected, &pairs, &[9.79e-4, 5e-4], &alike), None);
        let failed = [fifth(0.2), fifth(f64::NAN), fifth(0.3)];
        assert_eq!(defects_note(1e-3, EstimateMethod::Corrected, &pairs, &[9.79e-4, 5e-4], &failed), None);
    }

    fn iteration(estimates: Vec<f64>, sensitivity: Vec<f64>, held_out_effectivity: f64) -> Iteration {
        Iteration {
            energy: 1e-4,
            hyper_tolerance: 1e-2,
            block_modes: vec![4],
            n_modes: 4,
            n_elements: 3,
            whole_run_estimates: estimates.clone(),
            worst_candidate: 1,
            worst_estimate: estimates.iter().cloned().fold(0.0, f64::max),
            estimates,
            sensitivity,
            run_candidate: Some(1),
            true_error: 2e-3,
            true_score: 2e-3,
            held_out_effectivity,
            method: EstimateMethod::Corrected,
            bound: f64::NAN,
            between_points: 0,
        }
        .with_bound()
    }

    impl Iteration {
        /// The bound between the candidates of a line of three, as the loop would have it
        /// without looking between them (the stop line reads it from the iteration).
        fn with_bound(mut self) -> Self {
            self.bound = between::between_candidates(
                &self.estimates,
                &self.sensitivity.iter().map(|&s| s > 1e-2).collect::<Vec<_>>(),
                &[],
                &between::line_pairs(self.estimates.len()),
            );
            self
        }
    }

    /// The stop line names the cause a user can act on, in order: candidates without an
    /// estimate, then the model's own sensitivity above T, then held-out checks outside
    /// [1, MAX_HELD_OUT_OVERESTIMATE], else too few runs (the cases the zoo of docs/zoo.md
    /// met: a clamped chain whose richer model failed at some loads, an n-pendulum whose
    /// answer moved by 1.6e-1 for a 0.1 % change of the load).
    #[test]
    fn the_stop_line_names_the_cause() {
        let loads = CandidateSet::line(&[0.5, 1.0, 1.5]);
        let t = 1e-2;
        let failed = iteration(vec![1e-3, f64::INFINITY, 2e-2], vec![1e-3; 3], 1.5);
        let blew_up = [(1, "the reduced run failed: blow-up at t = 1.48 s")];
        let why = why_not_converged(t, std::slice::from_ref(&failed), &loads, &blew_up, &[true, true, false]);
        assert!(why.contains("no estimate could be computed at 1 of 3"), "{why}");
        assert!(why.contains("at λ = 1 (a training load: its full run is in the snapshots), the reduced run failed: blow-up at t = 1.48 s"), "{why}");
        let why = why_not_converged(t, &[failed], &loads, &blew_up, &[false; 3]);
        assert!(why.contains("; at λ = 1, the reduced run failed"), "{why}");
        let sensitive = iteration(vec![1e-3, 2e-2, 1e-3], vec![1e-3, 1.6e-1, 1e-3], 1.5);
        let why = why_not_converged(t, &[sensitive], &loads, &[], &[false; 3]);
        assert!(why.contains("sensitive to the load") && why.contains("1.6e-1") && why.contains("λ = 1"), "{why}");
        let off = iteration(vec![1e-3, 2e-2, 1e-3], vec![1e-3; 3], 250.0);
        assert!(why_not_converged(t, &[off], &loads, &[], &[false; 3]).contains("at 1 of its held-out runs"));
        let jumpy = iteration(vec![1e-3, 2e-5, 1e-3], vec![1e-3; 3], 1.5);
        let why = why_not_converged(t, &[jumpy], &loads, &[], &[false; 3]);
        assert!(why.contains("differ by up to 50×") && why.contains("λ = 0.5"), "{why}");
        let slow = iteration(vec![1e-3, 2e-2, 1e-3], vec![1e-3; 3], 1.5);
        assert!(why_not_converged(t, &[slow], &loads, &[], &[false; 3]).contains("raise max_runs"));
        // a cantilever whose displacement is proportional to the load, held to 1e-4 in the
        // displacement measure: its sensitivity is δ = 1e-3 exactly, above T but no
        // amplification; three runs left 4 modes and took 8 % off the worst score
        let t = 1e-4;
        let linear = |worst: f64| iteration(vec![worst, 1e-4, 5e-5], vec![1e-3; 3], 1.2);
        let why = why_not_converged(t, &[linear(1.83e-4), linear(1.77e-4), linear(1.68e-4)], &loads, &[], &[false; 3]);
        assert!(!why.contains("sensitive to the load") && why.contains("kept the basis at 4 modes"), "{why}");
        assert!(why.contains("the measure, not the dynamics"), "{why}");
        // the same with modes growing: not stalled
        let mut grown = linear(1.68e-4);
        grown.block_modes = vec![6];
        let why = why_not_converged(t, &[linear(1.83e-4), linear(1.77e-4), grown], &loads, &[], &[false; 3]);
        assert!(why.contains("raise max_runs"), "{why}");
    }
}
