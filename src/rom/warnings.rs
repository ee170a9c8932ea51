//! What a reader of reduced answers must be told after the runs: one function,
//! [`Rom::warnings_after`], that `online`, `sweep` and `validate` call on the command line
//! and in Python alike, so that both say the same things in the same order.

use super::estimator::Estimate;
use super::{trust, Rom};
use crate::error::Result;
use crate::solver::model::Parameters;

/// A reduced answer as the warnings read it.
pub struct Answered<'a> {
    /// where it was run
    pub mu: &'a Parameters,
    /// its error estimate in the measure the tolerance holds ([`super::Rom::tolerance_measure`],
    /// [`super::estimator::Estimate::in_measure`]); `None` without one
    pub estimate: Option<f64>,
    /// why the estimator's own run failed, when it did (the estimate then reads ∞)
    pub failure: Option<&'a str>,
    /// the estimates of what engineers read — each probe quantity and joint reaction,
    /// relative to its range over the run — named as a message names them (`strain at
    /// tip`)
    pub quantities: Vec<(String, f64)>,
}

impl<'a> Answered<'a> {
    /// The answer at `mu` with its estimate as `rom`'s tolerance reads it.
    pub fn new(rom: &Rom, mu: &'a Parameters, estimate: Option<&'a Estimate>) -> Self {
        Answered {
            mu,
            estimate: estimate.map(|e| e.in_measure(rom.tolerance_measure())),
            failure: estimate.and_then(|e| e.failure.as_deref()),
            quantities: estimate.map_or_else(Vec::new, |e| {
                e.quantities.iter().map(|q| (reading(q.quantity.name(), &q.probe), q.estimate)).collect()
            }),
        }
    }
}

/// A probe quantity or reaction as a message names it: `strain at tip`.
pub fn reading(quantity: &str, name: &str) -> String {
    format!("{quantity} at {name}")
}

impl Rom {
    /// The warnings after the reduced answers `answers` (answers the full model gave in a
    /// fallback are exact and not among them), one line each, without the `warning: `
    /// prefix, in this order:
    /// 1. estimates that could not be computed ([`trust::estimate_failed`]): each, for one or
    ///    two answers; for more, how many and the first;
    /// 2. parameters other than the load scale outside what the basis was trained on
    ///    ([`Rom::untrained_parameters`] for one answer; for more, how many points and the
    ///    first's);
    /// 3. readings whose estimate exceeds their whole range over the run
    ///    ([`unreadable_quantities`]): the reduced model cannot tell them;
    /// 4. [`trust::check_runs`]: the load scale outside its training range, a model that
    ///    amplifies load changes, no estimator, estimates above the tolerance.
    ///
    /// With `strict`, an estimate above the tolerance is an [`crate::Error::Strict`]
    /// carrying the other warnings, for the caller to say before it.
    pub fn warnings_after(&self, answers: &[Answered<'_>], strict: bool) -> Result<Vec<String>> {
        let mut warnings = failed_estimates(answers);
        warnings.extend(self.outside_training(answers));
        warnings.extend(unreadable_quantities(answers));
        let Some(trust) = self.trust() else { return Ok(warnings) };
        let runs: Vec<(Parameters, Option<f64>)> = answers.iter().map(|a| (a.mu.clone(), a.estimate)).collect();
        trust::check_runs(trust, self.estimator().is_some(), &runs, strict, warnings)
    }

    /// The warning about answers at parameters the basis was not trained over (not the
    /// load scale's range, which [`trust::check_runs`] names).
    fn outside_training(&self, answers: &[Answered<'_>]) -> Vec<String> {
        if let [one] = answers {
            return self.untrained_parameters(one.mu);
        }
        let outside: Vec<Vec<String>> =
            answers.iter().map(|a| self.named_outside(a.mu)).filter(|w| !w.is_empty()).collect();
        let Some(first) = outside.first() else { return Vec::new() };
        vec![format!(
            "{} of {} points lie outside what the basis was trained on (the first: {}); the reduced model extrapolates there",
            outside.len(),
            answers.len(),
            first.join(", ")
        )]
    }
}

/// The warning about probe quantities and reactions whose estimate exceeds 1 — their whole
/// range over the run — at some answers: the reduced answer may be off by more than the
/// reading moves, so nothing of it can be read off (a stiff link's axial strain, which a
/// rotation by a combination of modes stretches). One line: how many readings, at how many
/// points, and the largest. Estimates that could not be computed (∞) are said apart.
pub fn unreadable_quantities(answers: &[Answered<'_>]) -> Option<String> {
    let mut names: Vec<String> = Vec::new();
    let (mut points, mut largest) = (0, None::<(f64, &str, &Parameters)>);
    for a in answers {
        let over: Vec<&(String, f64)> = a.quantities.iter().filter(|(_, e)| e.is_finite() && *e > 1.0).collect();
        points += usize::from(!over.is_empty());
        for (name, e) in over {
            if !names.contains(name) {
                names.push(name.clone());
            }
            if largest.is_none_or(|(l, _, _)| *e > l) {
                largest = Some((*e, name, a.mu));
            }
        }
    }
    let (e, name, mu) = largest?;
    let at = if answers.len() == 1 { format!("{mu}") } else { format!("{points} of {} points", answers.len()) };
    Some(format!(
        "at {at} the error estimates of {} exceed their whole range over the run (the largest, {name}: {e:.2e} times its range, at {mu}): the reduced model cannot tell those readings; the full model gives them (`validate`), and greedy training with measure = \"probes\" holds them to the tolerance",
        trust::few(&names)
    ))
}

/// The warnings of estimates whose estimator's run failed: each for up to two answers (a
/// validation's few points), else one line with their number and the first.
fn failed_estimates(answers: &[Answered<'_>]) -> Vec<String> {
    let failed: Vec<String> =
        answers.iter().filter_map(|a| trust::estimate_failed(&format!("{}", a.mu), a.failure)).collect();
    if failed.len() <= 2 {
        return failed;
    }
    vec![format!(
        "{} of {} estimates could not be computed (they read ∞); the first: {}",
        failed.len(),
        answers.len(),
        failed[0]
    )]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(mu: &Parameters, failure: Option<&'static str>) -> (Parameters, Option<&'static str>) {
        (mu.clone(), failure)
    }

    /// One line each for one or two failures, one summary line for more (a sweep of a
    /// hundred loads does not print a hundred lines).
    #[test]
    fn failed_estimates_are_listed_or_counted() {
        let runs: Vec<_> =
            [1.0, 1.1, 1.2].iter().map(|&x| at(&Parameters::load_scale(x), Some("Newton failed"))).collect();
        let answers: Vec<Answered> = runs
            .iter()
            .map(|(mu, f)| Answered { mu, estimate: Some(f64::INFINITY), failure: *f, quantities: Vec::new() })
            .collect();
        let two = failed_estimates(&answers[..2]);
        assert_eq!(two.len(), 2);
        assert!(
            two[0].starts_with("no error estimate at load scale 1:") && two[1].contains("load scale 1.1"),
            "{two:?}"
        );
        let three = failed_estimates(&answers);
        assert_eq!(three.len(), 1);
        assert!(
            three[0].starts_with("3 of 3 estimates could not be computed") && three[0].contains("load scale 1:"),
            "{three:?}"
        );
        let fine = Answered { mu: &runs[0].0, estimate: Some(1e-3), failure: None, quantities: Vec::new() };
        assert!(failed_estimates(&[fine]).is_empty());
    }

    /// A reading whose estimate exceeds its range is named, with the largest and where; one
    /// line for all points; within the range (≤ 1), NaN (no swing) and ∞ (said apart) are not.
    #[test]
    fn readings_estimated_beyond_their_range_are_named_once() {
        let (a, b) = (Parameters::load_scale(0.7), Parameters::load_scale(1.2));
        let q = |v: &[(&str, f64)]| v.iter().map(|(n, e)| (n.to_string(), *e)).collect::<Vec<_>>();
        let one = Answered {
            mu: &a,
            estimate: Some(1e-4),
            failure: None,
            quantities: q(&[("strain at tip", 388.0), ("curvature at tip", 0.5), ("strain at root", 8.7)]),
        };
        let w = unreadable_quantities(std::slice::from_ref(&one)).unwrap();
        assert!(w.starts_with("at load scale 0.7 the error estimates of strain at tip, strain at root exceed"), "{w}");
        assert!(w.contains("the largest, strain at tip: 3.88e2 times its range, at load scale 0.7"), "{w}");
        let calm = Answered {
            mu: &b,
            estimate: Some(1e-4),
            failure: None,
            quantities: q(&[
                ("strain at tip", 0.9),
                ("position at tip", f64::NAN),
                ("curvature at root", f64::INFINITY),
            ]),
        };
        assert_eq!(unreadable_quantities(std::slice::from_ref(&calm)), None);
        let w = unreadable_quantities(&[calm, one]).unwrap();
        assert!(w.starts_with("at 1 of 2 points the error estimates of strain at tip, strain at root"), "{w}");
    }
}
