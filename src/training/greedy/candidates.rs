//! What the greedy loop knows of every candidate load: the error estimate and the reduced
//! model's sensitivity by fifth of the run (reduced runs in parallel), and the score of a
//! candidate that the loop holds to the tolerance (the greedy module documentation).

use super::candidate_set::CandidateSet;
use crate::error::Result;
use crate::model::Model;
use crate::pipeline::config::GreedyMeasure;
use crate::reduction::Basis;
use crate::rom::estimator::corrected::CorrectedRunner;
use crate::rom::estimator::defects::Defects;
use crate::rom::estimator::norms::{raw_by_time, resolution};
use crate::rom::estimator::{self, ByFifth, DefectsCalibration, ErrorEstimator, EstimateMethod, Estimator, FIFTHS};
use crate::rom::{Output, Rom};
use crate::solver::parameters::Parameters;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use std::sync::Arc;

use crate::rom::trust::amplifying;
pub use crate::rom::trust::SENSITIVITY_STEP;

/// The score of one candidate (the greedy module documentation): `max_i η_i · T / s_i` over
/// the fifths `i` of the run, `s_i` the sensitivity where the model amplifies changes of the
/// load ([`amplifying`]: above T and 10 δ) and T elsewhere; NaN counts as ∞.
pub fn score(tolerance: f64, estimate_by_time: &ByFifth, sensitivity_by_time: &ByFifth) -> f64 {
    let mut worst = 0.0_f64;
    for (&e, &s) in estimate_by_time.iter().zip(sensitivity_by_time) {
        let e = if e.is_nan() { f64::INFINITY } else { e };
        // an infinite sensitivity (the moved run could not be compared) holds nothing
        let held_to = if s.is_finite() && amplifying(s, tolerance) { s } else { tolerance };
        worst = worst.max(tolerance * e / held_to);
    }
    worst
}

/// What the loop knows of one candidate, in the training's measure.
#[derive(Clone)]
pub(super) struct CandidateRun {
    /// the error estimate by fifth of the run (the last: the whole run's)
    pub(super) by_time: ByFifth,
    /// the whole run's raw estimate of rel_error (what `c` is calibrated with)
    pub(super) raw: f64,
    /// the reduced model's sensitivity by fifth of the run (the greedy module documentation)
    pub(super) sensitivity: ByFifth,
    /// why no estimate could be computed, when none could (the estimates are then ∞)
    pub(super) failure: Option<String>,
    /// each probe quantity's and reaction's raw estimate, by key `quantity:probe` (what
    /// `c_q` is calibrated with)
    pub(super) quantity_raws: Vec<(String, f64)>,
}

/// The reduced model training steers by: `basis` with the estimator of `est` by `method`
/// (`corrected`, or `enriched` once a held-out check found the correction off; the enriched
/// model also where the correction cannot run), the method `c` is calibrated for.
pub(super) fn training_rom(model: &Arc<Model>, basis: &Basis, est: &Estimator, method: EstimateMethod) -> Result<Rom> {
    let (basis, data) = (Arc::new(basis.clone()), Arc::new(est.clone()));
    let e = estimator::build(method, model, &basis, &data)?;
    Rom::new(model, &basis, Some(e), None)
}

/// [`training_rom`] and the model's physics (for X₀), or why they cannot be had, as the
/// failure every candidate of the rung then reads.
fn training_setup<'m>(
    model: &'m Arc<Model>,
    basis: &Basis,
    est: &Estimator,
    method: EstimateMethod,
) -> std::result::Result<(Rom, &'m crate::model::SharedPhysics), Box<CandidateRun>> {
    let cannot = |e: crate::error::Error| Box::new(failed(format!("the reduced model cannot be built: {e}")));
    Ok((training_rom(model, basis, est, method).map_err(cannot)?, model.physics().map_err(cannot)?))
}

/// The seam to the error estimator: the estimate and the reduced model's sensitivity of
/// `basis` at the candidates `which` (`None` at the others) in `measure` (the sensitivity's
/// displacement form divides by `‖X_r(λ) − X₀‖`), reduced runs in parallel (one reduced
/// model and its estimator's per worker, as `sweep` does); a run that fails gives ∞
/// estimates (and sensitivity 0, which holds its estimate to T).
pub(super) fn estimate_candidates(
    model: &Arc<Model>,
    basis: &Basis,
    est: &Estimator,
    cands: &CandidateSet,
    label: &str,
    (method, measure): (EstimateMethod, GreedyMeasure),
    which: &[usize],
) -> Vec<Option<CandidateRun>> {
    let mut out = vec![None; cands.len()];
    let target =
        if crate::output::progress_wanted() { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() };
    let bar = ProgressBar::with_draw_target(Some(which.len() as u64), target);
    bar.set_style(
        ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} candidates, {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_prefix(label.to_string());
    // no log lines of its own (the loop says what each iteration did): the count for a host
    let ticker = crate::output::ticker::Ticker::new(label, which.len() as u64, false);
    let (rom, physics) = match training_setup(model, basis, est, method) {
        Ok(s) => s,
        Err(f) => {
            which.iter().for_each(|&i| out[i] = Some((*f).clone()));
            return out;
        }
    };
    let x0 = ndarray::ArrayView1::from(&physics.x0[..]);
    let runs: Vec<CandidateRun> = which
        .par_iter()
        .map(|&i| {
            let r = candidate_run(&rom, cands, i, measure, x0);
            bar.inc(1);
            ticker.tick();
            r
        })
        .collect();
    bar.finish_and_clear();
    for (&i, r) in which.iter().zip(runs) {
        out[i] = Some(r);
    }
    out
}

/// What a candidate whose reduced run or estimate fails counts as, and why.
fn failed(why: String) -> CandidateRun {
    CandidateRun {
        by_time: [f64::INFINITY; FIFTHS],
        raw: f64::INFINITY,
        sensitivity: [0.0; FIFTHS],
        failure: Some(why),
        quantity_raws: Vec::new(),
    }
}

/// One candidate, `i`: [`point_run`] at its parameters.
fn candidate_run(
    rom: &Rom,
    cands: &CandidateSet,
    i: usize,
    measure: GreedyMeasure,
    x0: ndarray::ArrayView1<f64>,
) -> CandidateRun {
    point_run(rom, &cands.points[i], &cands.moved(i, SENSITIVITY_STEP), measure, x0)
}

/// One point `mu`: the reduced run there with its estimate, and the run at `moved` (its
/// parameters times `1 + δ`, [`CandidateSet::moved_point`]), in `measure` (`x0`: the
/// initial configuration X₀ of the displacement measure).
fn point_run(
    rom: &Rom,
    mu: &Parameters,
    moved: &Parameters,
    measure: GreedyMeasure,
    x0: ndarray::ArrayView1<f64>,
) -> CandidateRun {
    let coordinates = measure.coordinates();
    match rom.solve_and_estimate(mu, Output::ReducedAndProbes, &[]) {
        Ok((run, Some(e))) => {
            // the same reduced model at μ(1 + δ): how much its answer moves
            let basis = rom.basis();
            let res = rom.model().physics().map_or(0.0, |p| resolution(&run, p.length_scale()));
            let sensitivity = match rom.solve_with(moved, Output::ReducedAndProbes, &[]) {
                Ok(moved) => *raw_by_time(basis, basis, &moved.reduced_q, &run.reduced_q, x0, res).get(coordinates),
                Err(_) => [0.0; FIFTHS],
            };
            let failure = e.failure.as_ref().map(|why| format!("its error estimate failed: {why}"));
            let mut by_time = at_rest_as_relative(e.by_time_in(coordinates), &e.by_time);
            if measure.probes() {
                by_time[FIFTHS - 1] = by_time[FIFTHS - 1].max(worst_quantity(e.quantities.iter().map(|q| q.estimate)));
            }
            let quantity_raws = e.quantities.iter().map(|q| (q.key(), q.raw)).collect();
            CandidateRun { by_time, raw: e.raw, sensitivity, failure, quantity_raws }
        }
        Ok((_, None)) => failed("the reduced model has no estimator".into()),
        Err(e) => failed(format!("the reduced run failed: {e}")),
    }
}

/// The largest of the probe quantities' errors or estimates over their ranges; those
/// undefined (NaN: no swing beyond the resolution in either run) say nothing, ∞ counts.
pub(super) fn worst_quantity(values: impl Iterator<Item = f64>) -> f64 {
    values.filter(|v| !v.is_nan()).fold(0.0, f64::max)
}

/// The estimate by fifth of a run for the loop. A displacement estimate is undefined (NaN)
/// where neither run moved beyond the coordinates' resolution and they do not differ by
/// more ([`crate::rom::estimator::norms::against_motion`]): a run at rest, which the loop
/// must not take for a failed one (NaN counts as ∞, [`score`]). There the relative
/// estimate (finite where the runs ran: rounding against ‖X‖) stands in — next to a
/// training load a pair counts with its larger value ([`super::between::pair_bound`]),
/// elsewhere the jump to its neighbours asks for a full run there, once. The held-out
/// check reads the true errors of a run at rest alike.
pub(super) fn at_rest_as_relative(estimate: &ByFifth, relative: &ByFifth) -> ByFifth {
    std::array::from_fn(|i| if estimate[i].is_nan() && relative[i].is_finite() { relative[i] } else { estimate[i] })
}

/// What the loop knows at points between the candidates (in the candidates' unit
/// coordinates, [`CandidateSet::at_unit`]), as [`estimate_candidates`] at candidates:
/// reduced runs in parallel, a run that fails as ∞.
pub(super) fn estimate_points(
    model: &Arc<Model>,
    basis: &Basis,
    est: &Estimator,
    cands: &CandidateSet,
    units: &[Vec<f64>],
    (method, measure): (EstimateMethod, GreedyMeasure),
) -> Vec<CandidateRun> {
    let (rom, physics) = match training_setup(model, basis, est, method) {
        Ok(s) => s,
        Err(f) => return vec![*f; units.len()],
    };
    let x0 = ndarray::ArrayView1::from(&physics.x0[..]);
    units
        .par_iter()
        .map(|u| {
            let mu = cands.at_unit(u);
            point_run(&rom, &mu, &cands.moved_point(&mu, SENSITIVITY_STEP), measure, x0)
        })
        .collect()
}

/// [`estimate_candidates`] in the order `order`, a few at a time (as many as there are
/// worker threads), stopping as soon as one candidate's score is above `tolerance`: such a
/// rung cannot meet the tolerance, whatever the others read, so a rung that fails is
/// rejected after a few reduced runs instead of all of them. The candidates not run are
/// `None`.
pub(super) fn screen_candidates(
    model: &Arc<Model>,
    basis: &Basis,
    est: &Estimator,
    cands: &CandidateSet,
    order: &[usize],
    (method, measure): (EstimateMethod, GreedyMeasure),
    tolerance: f64,
) -> Vec<Option<CandidateRun>> {
    let mut out = vec![None; cands.len()];
    let (rom, physics) = match training_setup(model, basis, est, method) {
        Ok(s) => s,
        Err(f) => {
            // like a failed run at every candidate: one is enough to reject
            out[order[0]] = Some(*f);
            return out;
        }
    };
    let x0 = ndarray::ArrayView1::from(&physics.x0[..]);
    let chunk = rayon::current_num_threads().max(1);
    for part in order.chunks(chunk) {
        let runs: Vec<CandidateRun> = part.par_iter().map(|&i| candidate_run(&rom, cands, i, measure, x0)).collect();
        let over = runs.iter().any(|r| !(score(tolerance, &r.by_time, &r.sensitivity) <= tolerance));
        for (&i, r) in part.iter().zip(runs) {
            out[i] = Some(r);
        }
        if over {
            break;
        }
    }
    out
}

/// The `defects` method's calibration (`DefectsCalibration`) of the final basis: at every
/// candidate one reduced run, its estimate by the training's `method` (the estimator's
/// calibration `c` included) and its raw defect sum, fifth by fifth, reduced runs in
/// parallel. `None` when the estimator has no defects runner or some fifth has no usable
/// ratio. On a line the ratios are interpolated between neighbouring loads online; in a
/// box a point reads the largest of its nearest candidates' ([`DefectsCalibration::scattered`]).
pub(super) fn calibrate_defects(
    model: &Arc<Model>,
    basis: &Basis,
    est: &Estimator,
    cands: &CandidateSet,
    method: EstimateMethod,
) -> Option<DefectsCalibration> {
    let rom = training_rom(model, basis, est, method).ok()?;
    let defects = match CorrectedRunner::supports(model, basis, &est.enriched) {
        Ok(true) => Defects::new(model, rom.basis(), &Arc::new(est.clone())).ok(),
        _ => None,
    };
    // per candidate: the ratio by fifth, and each probe quantity's and reaction's whole-run ratio
    let mut keys: Vec<String> = model.quantity_keys();
    keys.extend(crate::rom::reactions::ReactionReader::new(model).keys());
    let unusable = || ([f64::NAN; FIFTHS], vec![f64::NAN; keys.len()]);
    let measured: Vec<(ByFifth, Vec<f64>)> = cands
        .points
        .par_iter()
        .map(|mu| {
            let Some(d) = &defects else { return unusable() };
            let Ok((run, Some(e))) = rom.solve_and_estimate(mu, Output::ReducedAndProbes, &[]) else {
                return unusable();
            };
            let Ok(raw) = d.raw(&run) else { return unusable() };
            let quantity = |key: &String| {
                let r = raw.quantities.iter().find(|q| q.key() == *key)?;
                let c = e.quantities.iter().find(|q| q.quantity == r.quantity && q.probe == r.probe)?;
                Some(c.estimate / r.raw)
            };
            let by_fifth = std::array::from_fn(|i| e.by_time[i] / raw.norms.relative[i]);
            (by_fifth, keys.iter().map(|k| quantity(k).unwrap_or(f64::NAN)).collect())
        })
        .collect();
    let (ratios, quantity_ratios): (Vec<ByFifth>, Vec<Vec<f64>>) = measured.into_iter().unzip();
    let c = if cands.is_box() {
        DefectsCalibration::scattered(cands.space.clone(), cands.unit.clone(), ratios)
    } else {
        DefectsCalibration::new(cands.loads(), ratios)
    };
    c.map(|c| c.with_quantities(&keys, &quantity_ratios))
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
        // a sensitivity above T but no more than 10 δ = 1e-2 is a response that follows the
        // load, not amplification: at T = 1e-4 an estimate of 3e-4 where s = 1e-3 (a linear
        // beam in the displacement measure) scores 3e-4, above T, not T · 3e-4 / 1e-3
        let linear = [1e-3; 5];
        assert_eq!(score(1e-4, &[1e-4, 1e-4, 2e-4, 3e-4, 3e-4], &linear), 3e-4);
    }
}
