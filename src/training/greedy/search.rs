//! The mode and hyper-reduction search of one greedy iteration (the greedy module
//! documentation): the energy ladder of POD tolerances ε, τ = √ε for ECSW, the half step back,
//! then the loosest τ whose estimates still meet T between the candidates
//! ([`Level::between_candidates`]); each rung a `Level`.

use super::candidate_set::CandidateSet;
use super::candidates::{estimate_candidates, estimate_points, score, screen_candidates, CandidateRun};
use crate::error::{Error, Result};
use crate::io::basis_file::TrainingData;
use crate::pipeline::config::{GreedyMeasure, GreedySpec, Pipeline};
use crate::reduction::{ModeRule, Trained};
use crate::rom::estimator::training::{calibrate, CalibrationPoint, Estimator};
use crate::rom::estimator::{ByFifth, EstimateMethod, FIFTHS};
use crate::rom::trust::amplifying;
use crate::training::basis_build::build_basis;
use crate::training::training_record::modes_text;

/// Energy tolerances ε tried, loose to tight: 10⁻², 10⁻³, …, 10⁻¹⁴. The tight end is where
/// the captured energy `1 − ε`, a sum of squared singular values, still has two digits in
/// double precision; a tolerance far below the relative error measure's (a displacement
/// of a few per cent of the coordinates held to 1e-4) needs it: a clamped beam in the
/// displacement measure at 1e-4 needs 25 modes, ε = 1.2e-13 (a ladder ending at 10⁻¹⁰
/// gives it 15 modes, and training spent its runs at a 2e-4 error).
pub const ENERGY_LADDER: [f64; 13] =
    [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14];
/// ECSW tolerances τ tried with the chosen modes, loose to tight: 10^(−1 − i/2), down to 10⁻⁶
/// (also the τ with given modes and no given τ).
pub const TAU_LADDER: [f64; 11] =
    [1e-1, 3.162e-2, 1e-2, 3.162e-3, 1e-3, 3.162e-4, 1e-4, 3.162e-5, 1e-5, 3.162e-6, 1e-6];

/// A basis of one rung of the ladder with its estimator and its estimates at the candidates.
pub(super) struct Level {
    pub(super) energy: f64,
    pub(super) hyper_tolerance: Option<f64>,
    pub(super) trained: Trained,
    pub(super) estimator: Estimator,
    /// scores (the greedy module documentation), in the training's measure as `whole`
    pub(super) estimates: Vec<f64>,
    pub(super) whole: Vec<f64>,
    /// the raw estimates of rel_error (calibration)
    pub(super) raws: Vec<f64>,
    pub(super) sensitivity: Vec<ByFifth>,
    /// the estimator's basis is richer than the basis in every block
    fully_enriched: bool,
    /// which candidates have been run (a screened rung stops at its first score above T:
    /// [`super::candidates::screen_candidates`])
    evaluated: Vec<bool>,
    /// the neighbouring candidates ([`CandidateSet::pairs`])
    pairs: Vec<(usize, usize)>,
    /// the candidates whose error is settled by a full run in the snapshots ([`Round::settled`])
    settled: Vec<bool>,
    /// the bound of every pair once looked at between its candidates ([`super::between`]),
    /// `pairs` order; `None` before
    pair_bounds: Option<Vec<f64>>,
    /// the points between candidates that looking took (reduced runs with an estimate, and
    /// as many for their sensitivity)
    pub(super) between_points: usize,
    /// the candidates' runs the scores above come from (`None`: not run)
    runs: Vec<Option<CandidateRun>>,
}

impl Level {
    /// The candidate with the largest estimate and that estimate (NaN counts as ∞), among
    /// the candidates run.
    pub(super) fn worst(&self) -> (usize, f64) {
        self.worst_where(|_| true).expect("at least two candidates")
    }

    /// The candidates whose reduced run or estimate failed, with why (the runs' order).
    pub(super) fn failures(&self) -> Vec<(usize, &str)> {
        (self.runs.iter().enumerate()).filter_map(|(i, r)| Some((i, r.as_ref()?.failure.as_deref()?))).collect()
    }

    /// Every candidate has been run.
    pub(super) fn complete(&self) -> bool {
        self.evaluated.iter().all(|&e| e)
    }

    /// What the estimate may reach between the candidates, which are all the loop sees of
    /// the range: the largest of the pairs' bounds ([`super::between::pair_bound`], pairs
    /// whose bound alone would reject the rung looked at between their candidates,
    /// [`Self::look_between`]); ∞ for a rung not run everywhere.
    pub(super) fn between_candidates(&self) -> f64 {
        self.pair_bounds.as_ref().map_or(f64::INFINITY, |b| super::between::largest(&self.estimates, b))
    }

    /// The bound of every pair of neighbouring candidates ([`CandidateSet::pairs`] order),
    /// after looking between them; `None` for a rung not run everywhere.
    pub(super) fn pair_bounds(&self) -> Option<&[f64]> {
        self.pair_bounds.as_deref()
    }

    /// [`Self::worst`] among the candidates `keep` accepts (and that were run).
    pub(super) fn worst_where(&self, keep: impl Fn(usize) -> bool) -> Option<(usize, f64)> {
        let mut w: Option<(usize, f64)> = None;
        let run = |i: usize| self.evaluated[i] && keep(i);
        for (i, &e) in self.estimates.iter().enumerate().filter(|(i, _)| run(*i)) {
            let e = if e.is_nan() { f64::INFINITY } else { e };
            if w.is_none_or(|w| e > w.1) {
                w = Some((i, e));
            }
        }
        w
    }
}

/// What one iteration of the loop searches with: the pipeline, the snapshots so far, the
/// candidate loads, the held-out calibration pairs so far, and the iteration's number.
pub(super) struct Round<'a> {
    pub(super) p: &'a Pipeline,
    pub(super) data: &'a TrainingData,
    pub(super) candidates: &'a CandidateSet,
    pub(super) points: &'a [CalibrationPoint],
    pub(super) n: usize,
    /// the estimate the candidates are read with
    pub(super) method: EstimateMethod,
    /// the scores the previous iteration's basis had at the candidates: where a rung is
    /// screened first
    pub(super) prior: Option<&'a [f64]>,
    /// the candidates at which a full run is in the snapshots: [`super::between::pair_bound`]
    pub(super) settled: &'a [bool],
}

/// The order a rung's candidates are run in: the highest `scores` first (a failed run, NaN,
/// before all), those without a score after them in their order. A rung that fails fails
/// first where the rung before it was worst, so screening stops after a few runs.
fn worst_first(scores: &[f64], evaluated: &[bool]) -> Vec<usize> {
    let key = |i: usize| {
        if !evaluated[i] {
            f64::NEG_INFINITY
        } else if scores[i].is_nan() {
            f64::INFINITY
        } else {
            scores[i]
        }
    };
    let mut order: Vec<usize> = (0..scores.len()).collect();
    order.sort_by(|&a, &b| key(b).total_cmp(&key(a)));
    order
}

/// The mode and hyper-reduction search of one iteration (the greedy module documentation): the modes
/// the pipeline gives, or the energy ladder loose → tight with τ = √ε (and a half step
/// before the first accepted rung); then, unless the pipeline gives τ, the loosest τ that
/// still meets T with those modes (the fewest sampled elements: the cheapest reduced run).
pub(super) fn search(r: &Round, g: &GreedySpec, previous_energy: Option<f64>) -> Result<Level> {
    let (p, candidates, n) = (r.p, r.candidates, r.n);
    let given_hyper = p.file.reduction.hyper.as_ref().map(|h| h.tolerance);
    // what the tolerance promises is every load of the range, not the candidates alone
    let accepts = |l: &Level| l.between_candidates() <= g.tolerance;
    let mut last_error: Option<(&'static str, String)> = None;
    let mut order = match r.prior {
        Some(s) if s.len() == candidates.len() => worst_first(s, &vec![true; s.len()]),
        _ => (0..candidates.len()).collect(),
    };
    let mut attempt = |modes: ModeRule, eps: f64, tau: f64| -> Option<Level> {
        // a stop asked for: no more rungs (their runs would fail at once and read as ∞)
        if crate::interrupt::requested() {
            return None;
        }
        match level(r, modes, eps, Some(tau), &order) {
            Ok(l) => {
                order = worst_first(&l.estimates, &l.evaluated);
                log::debug!("{}", rung_text(r, &l, eps, tau, g.tolerance));
                Some(l)
            }
            Err(e) => {
                log::debug!(
                    "  iteration {n}, rung {}: rejected, the basis could not be built ({}: {})",
                    rung_name(eps, tau),
                    e.0,
                    e.1
                );
                last_error = Some(e);
                None
            }
        }
    };
    // no rung met T: the tightest rung tried (the ladder goes loose → tight) whose screened
    // runs did not fail; only where every rung's did, the smallest worst score ([`fallback`])
    let better = |best: &Option<Level>, l: &Level| best.as_ref().is_none_or(|b| fallback(b.worst().1, l.worst().1));
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
    // the cheapest hyper-reduction that keeps the accepted modes within T
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
    crate::interrupt::check()?;
    let mut best = best.ok_or_else(|| {
        let (f, e) = last_error.unwrap_or(("reduction", "no basis could be built".into()));
        Error::input(&p.path, f, format!("greedy training, iteration {n}: {e}"))
    })?;
    // no rung met T: the one kept was screened, and the loop needs it everywhere
    if !best.complete() {
        best.complete_screening(p, candidates, &format!("iteration {n}"), r.method);
    }
    log::debug!(
        "  iteration {n} keeps rung {}: {}{}",
        rung_name(best.energy, best.hyper_tolerance.unwrap_or(f64::NAN)),
        modes_text(&best.trained.block_modes),
        if accepts(&best) { "" } else { " (no rung met the tolerance: the tightest whose reduced runs did not fail)" }
    );
    Ok(best)
}

/// Whether a tighter rung whose worst score is `tighter` replaces the rung kept so far
/// (worst score `kept`) when no rung meets the tolerance: yes unless its screened runs
/// failed somewhere (∞) where the kept one's did not; between two such rungs, the smaller
/// worst score.
///
/// Not the smallest worst score alone: a rung's screening stops at its first candidate above
/// T, so its worst score is over a few candidates, different ones at each rung and at each
/// tolerance, and ranking rungs by it let a looser tolerance keep more modes than a tighter
/// one on the same runs (docs/greedy-training.md, "A looser tolerance, a bigger basis": a
/// two-link arm at 1e-2 kept ε = 1e-8 for a worst score 5 % below ε = 1e-7's, at 1e-3
/// ε = 1e-7). With the tightest rung tried the choice does not depend on T where every rung
/// fails it: the rungs tried end where the estimator is no richer than the basis, which
/// the snapshots decide; and a rung that meets a looser T is no tighter than the last one tried.
fn fallback(kept: f64, tighter: f64) -> bool {
    match (kept.is_finite(), tighter.is_finite()) {
        (_, true) => true,
        (true, false) => false,
        (false, false) => tighter < kept,
    }
}

/// "ε = 1.0e-4, τ = 1.0e-2" (ε is NaN where the pipeline gives the modes).
fn rung_name(eps: f64, tau: f64) -> String {
    if eps.is_nan() {
        format!("of the given modes, τ = {tau:.1e}")
    } else {
        format!("ε = {eps:.1e}, τ = {tau:.1e}")
    }
}

/// One rung of the search for `train -v`: its modes per block, sampled elements, the
/// estimator's modes, the worst estimate and where, and whether it meets `tolerance` or
/// why not (the order of the checks is the search's: a rung screened out at a candidate
/// above T, the bound between the candidates, an estimator no richer than the basis).
fn rung_text(r: &Round, l: &Level, eps: f64, tau: f64, tolerance: f64) -> String {
    let (wi, w) = l.worst();
    let elements = match &l.trained.basis.hyper {
        Some(h) => format!("{} sampled element{}", h.elements.len(), if h.elements.len() == 1 { "" } else { "s" }),
        None => "every element".to_string(),
    };
    let run = l.evaluated.iter().filter(|&&e| e).count();
    let poor: Vec<String> = (l.estimator.block_modes.iter().zip(&l.trained.block_columns()).enumerate())
        .filter(|(_, (&e, &m))| e <= m)
        .map(|(i, _)| match &r.p.model.file.bodies[..] {
            bodies if l.trained.block_modes.len() > 1 => {
                bodies.get(i).map_or_else(|| format!("block {i}"), |b| b.name.clone())
            }
            _ => "the basis".to_string(),
        })
        .collect();
    let mut verdict = if !l.complete() {
        format!(
            "above the tolerance {tolerance:e} at {} ({run} of {} candidates run)",
            r.candidates.label_of(wi),
            r.candidates.len()
        )
    } else if l.between_candidates() > tolerance {
        format!("above the tolerance {tolerance:e} between the candidates (bound {:.2e})", l.between_candidates())
    } else {
        format!("within the tolerance {tolerance:e} (bound between the candidates {:.2e})", l.between_candidates())
    };
    if l.between_points > 0 {
        verdict += &format!(
            "; {} point{} looked at between candidates whose bound alone was above it",
            l.between_points,
            if l.between_points == 1 { "" } else { "s" }
        );
    }
    if !poor.is_empty() {
        // the search stops at such a rung: a tighter one would have nothing to be checked against
        verdict +=
            &format!("; the estimator is no richer than the basis in {}: no tighter rung is tried", poor.join(", "));
    }
    format!(
        "  iteration {}, rung {}: {}, {elements}, estimator {}; worst score {w:.2e} at {}: {verdict}",
        r.n,
        rung_name(eps, tau),
        modes_text(&l.trained.block_modes),
        modes_text(&l.estimator.block_modes),
        r.candidates.label_of(wi)
    )
}

/// Builds the basis and estimator of one rung and estimates at every candidate.
fn level(
    r: &Round,
    modes: ModeRule,
    energy: f64,
    hyper_tolerance: Option<f64>,
    order: &[usize],
) -> std::result::Result<Level, (&'static str, String)> {
    let Round { p, data, candidates, points, method, .. } = *r;
    let (trained, mut estimator) =
        build_basis(p, data, modes, (hyper_tolerance, p.probe_mode_tolerance(Some(energy))))?;
    estimator.calibration = calibrate(points.to_vec());
    // a block whose snapshots span no more than the basis already holds leaves the estimator
    // nothing richer to compare with there; a block with fewer than `k` more (a stiff body:
    // its snapshots have low rank) is enriched by all it has
    let fully_enriched = estimator.block_modes.iter().zip(&trained.block_columns()).all(|(&e, &r)| e > r);
    let mut l = Level {
        energy,
        hyper_tolerance,
        trained,
        estimator,
        estimates: Vec::new(),
        whole: Vec::new(),
        raws: Vec::new(),
        sensitivity: Vec::new(),
        fully_enriched,
        evaluated: Vec::new(),
        pairs: candidates.pairs.clone(),
        settled: r.settled.to_vec(),
        pair_bounds: None,
        between_points: 0,
        runs: Vec::new(),
    };
    l.screen(p, candidates, order, method);
    Ok(l)
}

impl Level {
    /// The estimates, scores and sensitivities at every candidate, with `method`.
    pub(super) fn estimate(&mut self, p: &Pipeline, candidates: &CandidateSet, label: &str, method: EstimateMethod) {
        (self.runs, self.evaluated) = (vec![None; candidates.len()], vec![false; candidates.len()]);
        self.complete_screening(p, candidates, label, method);
    }

    /// [`Self::estimate`] at the candidates a screening did not run, keeping the runs it did
    /// with the same `method` (a reduced run and its estimate are deterministic: the same
    /// numbers as running every candidate again).
    fn complete_screening(&mut self, p: &Pipeline, candidates: &CandidateSet, label: &str, method: EstimateMethod) {
        let missing: Vec<usize> = (0..candidates.len()).filter(|&i| !self.evaluated[i]).collect();
        let (basis, est) = (&self.trained.basis, &self.estimator);
        let new = estimate_candidates(&p.model, basis, est, candidates, label, (method, measure_of(p)), &missing);
        let runs = self.runs.iter().zip(new).map(|(old, new)| new.or_else(|| old.clone())).collect();
        self.record(p, runs);
        self.look_between(p, candidates, method);
    }

    /// [`Self::estimate`] in `order` until a candidate scores above the tolerance
    /// ([`super::candidates::screen_candidates`]); [`Self::complete`] says whether it got
    /// through.
    fn screen(&mut self, p: &Pipeline, candidates: &CandidateSet, order: &[usize], method: EstimateMethod) {
        let (basis, est) = (&self.trained.basis, &self.estimator);
        let runs = screen_candidates(&p.model, basis, est, candidates, order, (method, measure_of(p)), p_tolerance(p));
        self.record(p, runs);
        self.look_between(p, candidates, method);
    }

    /// Where every candidate's score is within the tolerance but the bound between two of
    /// them is not, looks between them ([`super::between`]): at most as many points as there
    /// are candidates, read as the candidates are (`method`, the training's measure).
    fn look_between(&mut self, p: &Pipeline, candidates: &CandidateSet, method: EstimateMethod) {
        (self.pair_bounds, self.between_points) = (None, 0);
        if !self.complete() {
            return;
        }
        let tolerance = p_tolerance(p);
        let sensitive: Vec<bool> = self.sensitivity.iter().map(|s| amplifying(s[FIFTHS - 1], tolerance)).collect();
        let (basis, est, measure) = (&self.trained.basis, &self.estimator, measure_of(p));
        let mut look = |units: &[Vec<f64>]| -> Vec<(f64, bool)> {
            estimate_points(&p.model, basis, est, candidates, units, (method, measure))
                .iter()
                .map(|r| {
                    (score(tolerance, &r.by_time, &r.sensitivity), amplifying(r.sensitivity[FIFTHS - 1], tolerance))
                })
                .collect()
        };
        let (bounds, used) = super::between::resolve(
            (&self.estimates, &sensitive, &self.settled),
            &self.pairs,
            &candidates.unit,
            tolerance,
            candidates.len(),
            &mut look,
        );
        (self.pair_bounds, self.between_points) = (Some(bounds), used);
    }

    /// The raw estimates of candidate `i`'s probe quantities and reactions, by key (none
    /// where it was not run).
    pub(super) fn quantity_raws(&self, i: usize) -> &[(String, f64)] {
        self.runs.get(i).and_then(Option::as_ref).map_or(&[], |r| &r.quantity_raws)
    }

    fn record(&mut self, p: &Pipeline, runs: Vec<Option<CandidateRun>>) {
        self.runs = runs.clone();
        let get = |f: &dyn Fn(&CandidateRun) -> f64| -> Vec<f64> {
            runs.iter().map(|r| r.as_ref().map_or(f64::NAN, f)).collect()
        };
        self.estimates = get(&|r| score(p_tolerance(p), &r.by_time, &r.sensitivity));
        self.whole = get(&|r| r.by_time[FIFTHS - 1]);
        self.raws = get(&|r| r.raw);
        self.sensitivity = runs.iter().map(|r| r.as_ref().map_or([f64::NAN; FIFTHS], |r| r.sensitivity)).collect();
        self.evaluated = runs.iter().map(|r| r.is_some()).collect();
    }
}

/// The greedy tolerance of the pipeline (`[train] greedy`).
fn p_tolerance(p: &Pipeline) -> f64 {
    p.file.train.greedy.as_ref().map_or(f64::INFINITY, |g| g.tolerance)
}

/// The error measure greedy's tolerance is on (`[train] greedy.measure`).
fn measure_of(p: &Pipeline) -> GreedyMeasure {
    p.file.train.greedy.as_ref().map_or(GreedyMeasure::Relative, |g| g.measure)
}

#[cfg(test)]
mod tests {
    use super::fallback;

    /// With no rung meeting T, a tighter rung replaces the kept one unless its screened runs
    /// failed (∞) where the kept one's did not; two failed rungs keep the looser; the worst
    /// scores' sizes otherwise do not matter (the two-link arm's 1.54e-2 at ε = 1e-7 against
    /// 1.47e-2 at ε = 1e-8, and the reverse).
    #[test]
    fn the_fallback_is_the_tightest_rung_whose_runs_did_not_fail() {
        assert!(fallback(1.54e-2, 1.47e-2));
        assert!(fallback(5.85e-3, 6.19e-3), "a larger worst score over other candidates");
        assert!(fallback(f64::INFINITY, 6.19e-3));
        assert!(!fallback(5.85e-3, f64::INFINITY), "a tighter rung whose runs failed");
        assert!(!fallback(f64::INFINITY, f64::INFINITY));
    }
}
