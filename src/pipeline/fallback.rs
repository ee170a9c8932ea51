//! `sweep --fallback full`: the full model's answer in place of a reduced one the sweep
//! cannot stand behind at its point. A reduced model can fail (blow up, Newton not
//! converge) where the full one does not, its estimate can read above the tolerance, and
//! where the model amplifies changes of the load the estimate does not see the error at
//! all (`Trust::amplifying_near`). At such a point the full model is the exact route; with
//! the fallback the sweep takes it there by itself and says so in the point's `/message`
//! and `/fallback`, so that an overnight sweep has an answer within the tolerance (by its
//! estimate) or an exact one at every point.

use crate::error::{Error, Result};
use crate::rom::estimator::Estimate;
use crate::rom::{ReducedRun, Trust};
use crate::solver::parameters::Parameters;

/// What a sweep does at a point whose reduced answer it cannot stand behind
/// (`[online] fallback`, `sweep --fallback`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Fallback {
    /// keep the reduced answer with its warning, or the failure (the default)
    #[default]
    #[value(help = "keep the reduced answer with its warning, or the failure")]
    None,
    /// run the full model there and keep its answer (exact: error estimate 0)
    #[value(
        help = "run the full model where the reduced run fails, its estimate exceeds the tolerance, or the model amplifies load changes beyond it; keep that exact answer"
    )]
    Full,
}

impl Fallback {
    /// The value in a pipeline, on the command line and in a sweep file's `fallback`.
    pub fn name(self) -> &'static str {
        match self {
            Fallback::None => "none",
            Fallback::Full => "full",
        }
    }
}

/// The prefix of a point's `/message` when the full model answered it in place of the
/// reduced one; what follows says why.
pub const FULL_IN_PLACE: &str = "full model in place of the reduced one";

/// The start of a reduced answer's `/message` where the full model was run in its place
/// and failed (the reduced answer then stands, as without the fallback).
pub const FULL_TRIED: &str = "the full model, run in place of this reduced answer";

/// The kinds of [`why`], as a sweep's summary counts them: (how the reason starts, what
/// the summary calls it).
const KINDS: [(&str, &str); 5] = [
    ("the reduced run failed", "reduced run failed"),
    ("error estimate ", "error estimate above the tolerance"),
    ("displacement error estimate ", "error estimate above the tolerance"),
    ("the error estimate could not", "no estimate"),
    ("the model amplifies", "the model amplifies load changes"),
];

/// What a sweep's summary calls the reason of a point's `/message` (a fallback's, starting
/// [`FULL_IN_PLACE`], or a tried one's, starting [`FULL_TRIED`]).
pub fn kind(message: &str) -> Option<&'static str> {
    let why = message
        .strip_prefix(FULL_IN_PLACE)
        .map(|m| m.trim_start_matches(": "))
        .or_else(|| message.strip_prefix(FULL_TRIED).map(|m| m.trim_start_matches(" (")))?;
    KINDS.iter().find(|(start, _)| why.starts_with(start)).map(|&(_, name)| name)
}

/// A point's answer under a [`Fallback`]: the reduced run and its estimate (with `note`
/// where the full model was tried in its place and failed too), or the full model's run in
/// its place (`fallback`: why; no reduced coordinates, the estimate of an exact answer).
pub struct Settled {
    pub run: ReducedRun,
    pub estimate: Option<Estimate>,
    pub fallback: Option<String>,
    pub note: Option<String>,
}

/// The answer at `mu` from the reduced run `reduced` (its failure already named with its
/// stage) under `fallback`: where `why` gives a reason, `full` runs the full model there
/// (its failure named too). Where the full run fails as well, a reduced answer stands with
/// a note, and a failed reduced run fails the point with both messages: never worse than
/// without the fallback. One rule for `sweep` and `online`.
pub fn settle(
    reduced: Result<(ReducedRun, Option<Estimate>)>,
    fallback: Fallback,
    trust: Option<&Trust>,
    mu: &Parameters,
    full: impl FnOnce() -> Result<ReducedRun>,
) -> Result<Settled> {
    let Some(why) = why(&reduced, fallback, trust, mu) else {
        let (run, estimate) = reduced?;
        return Ok(Settled { run, estimate, fallback: None, note: None });
    };
    match (full(), reduced) {
        (Ok(run), reduced) => {
            // what the estimate of the reduced attempt cost before it was set aside
            let seconds = reduced.ok().and_then(|(_, e)| e).map_or(0.0, |e| e.seconds);
            let estimate = Some(Estimate::exact(seconds));
            Ok(Settled { run, estimate, fallback: Some(format!("{FULL_IN_PLACE}: {why}")), note: None })
        }
        (Err(e), Ok((run, estimate))) => {
            Ok(Settled { run, estimate, fallback: None, note: Some(format!("{FULL_TRIED} ({why}) failed: {e}")) })
        }
        (Err(e), Err(r)) => Err(Error::Hinted {
            source: Box::new(e),
            hint: format!("the full model ran in place of the reduced one, which had failed: {r}").into(),
        }),
    }
}

/// Why the full model answers at `mu` in place of the reduced run `reduced` (its result,
/// its estimate): none under [`Fallback::None`]; under [`Fallback::Full`] the reduced
/// run's numerical failure (Newton, a linear solve, a blow-up: not a stop that was asked
/// for, a limit or a file), or [`reason`].
fn why<T>(
    reduced: &Result<(T, Option<Estimate>)>,
    fallback: Fallback,
    trust: Option<&Trust>,
    mu: &Parameters,
) -> Option<String> {
    match (reduced, fallback) {
        (_, Fallback::None) => None,
        (Err(e), Fallback::Full) => e.is_numerical().then(|| format!("the reduced run failed: {e}")),
        (Ok((_, estimate)), Fallback::Full) => reason(trust, mu, estimate.as_ref()),
    }
}

/// Why the reduced answer at `mu` is not kept under [`Fallback::Full`], when it is not:
/// its estimate (`estimate`, in the trust's measure) is above the tolerance or infinite
/// (the estimator's own run failed), or the model amplifies changes of the load there
/// beyond the tolerance and the estimate. `None` where the answer stands, and always
/// without a tolerance to hold it to. A NaN estimate (a displacement estimate where nothing
/// moved beyond the Newton tolerance) is not above any tolerance.
pub fn reason(trust: Option<&Trust>, mu: &Parameters, estimate: Option<&Estimate>) -> Option<String> {
    let trust = trust?;
    let tol = trust.tolerance?;
    let e = estimate.map(|e| e.in_measure(trust.measure));
    if let Some(e) = e.filter(|e| !e.is_nan() && !(*e <= tol)) {
        let what = match trust.measure {
            crate::reduction::estimator::ErrorMeasure::Relative => "",
            crate::reduction::estimator::ErrorMeasure::Displacement => "displacement ",
        };
        return Some(if e.is_infinite() {
            format!("the error estimate could not be computed (its own run failed), tolerance {tol:e}")
        } else {
            format!("{what}error estimate {e:.2e} above the tolerance {tol:e}")
        });
    }
    trust.amplifying_near(mu, e).map(|s| {
        format!(
            "the model amplifies changes of the load here (a 0.1 % change moved the answer by {s:.1e} in training, \
             more than the tolerance {tol:e}); the error estimate does not see such errors"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reduction::estimator::ErrorMeasure;

    fn estimate(relative: f64, displacement: f64) -> Estimate {
        Estimate {
            error_estimate: relative,
            raw: relative,
            factor: 1.0,
            calibrated: false,
            seconds: 0.0,
            by_time: [relative; 5],
            error_estimate_displacement: displacement,
            displacement_by_time: [displacement; 5],
            failure: None,
            quantities: Vec::new(),
        }
    }

    /// The fallback reads the estimate in the tolerance's own measure: above the tolerance
    /// (or ∞) falls back, at or below it does not, NaN (nothing moved) does not, and without
    /// a tolerance nothing does.
    #[test]
    fn the_estimate_is_held_to_the_tolerance_in_its_measure() {
        let mu = Parameters::load_scale(1.0);
        let mut trust = Trust::range((0.5, 1.5));
        assert_eq!(reason(Some(&trust), &mu, Some(&estimate(1.0, 1.0))), None, "no tolerance");
        assert_eq!(reason(None, &mu, Some(&estimate(1.0, 1.0))), None, "no trust record");
        trust.tolerance = Some(1e-2);
        let above = reason(Some(&trust), &mu, Some(&estimate(2e-2, 1e-3))).expect("2e-2 > 1e-2");
        assert!(above.contains("2.00e-2 above the tolerance 1e-2"), "{above}");
        assert_eq!(reason(Some(&trust), &mu, Some(&estimate(1e-2, 1.0))), None, "at the tolerance");
        let failed = reason(Some(&trust), &mu, Some(&estimate(f64::INFINITY, f64::INFINITY))).expect("∞");
        assert!(failed.contains("could not be computed"), "{failed}");
        assert_eq!(reason(Some(&trust), &mu, None), None, "no estimate, no sensitivity record");
        trust.measure = ErrorMeasure::Displacement;
        let displacement = reason(Some(&trust), &mu, Some(&estimate(1e-3, 2e-2))).expect("displacement 2e-2");
        assert!(displacement.starts_with("displacement error estimate 2.00e-2 above"), "{displacement}");
        assert_eq!(kind(&format!("{FULL_IN_PLACE}: {displacement}")), Some("error estimate above the tolerance"));
        assert_eq!(reason(Some(&trust), &mu, Some(&estimate(1.0, f64::NAN))), None, "at rest");
    }

    /// A fallback runs on a reduced run's numerical failure, not on a stop that was asked
    /// for; and the summary names each reason [`why`] gives by its own kind (the words of
    /// one reason must not read as another's).
    #[test]
    fn the_reasons_and_their_kinds() {
        let mu = Parameters::load_scale(1.0);
        let failed: Result<((), Option<Estimate>)> = Err(crate::error::Error::Interrupted);
        assert_eq!(why(&failed, Fallback::Full, None, &mu), None, "a stop asked for");
        let newton = crate::error::Error::NewtonFailed {
            t: 0.5,
            dt: 1e-3,
            cuts: 8,
            iterations: 25,
            increment: 1.0,
            residual: 1.0,
        };
        let failed: Result<((), Option<Estimate>)> = Err(newton.at_stage("sweep (reduced run)", &mu));
        let w = why(&failed, Fallback::Full, None, &mu).expect("Newton failed");
        assert_eq!(why(&failed, Fallback::None, None, &mu), None);
        let mut trust = Trust::range((0.5, 1.5));
        trust.tolerance = Some(5e-3);
        trust.sensitivity = Some(crate::rom::trust::LoadSensitivity::new(vec![1.0], vec![0.2]));
        let reasons = [
            (w, "reduced run failed"),
            (reason(Some(&trust), &mu, Some(&estimate(1e-2, 1e-2))).unwrap(), "error estimate above the tolerance"),
            (reason(Some(&trust), &mu, Some(&estimate(f64::INFINITY, f64::INFINITY))).unwrap(), "no estimate"),
            (reason(Some(&trust), &mu, Some(&estimate(1e-3, 1e-3))).unwrap(), "the model amplifies load changes"),
        ];
        for (r, name) in reasons {
            assert_eq!(kind(&format!("{FULL_IN_PLACE}: {r}")), Some(name), "{r}");
            assert_eq!(kind(&format!("{FULL_TRIED} ({r}) failed: …")), Some(name), "{r}");
        }
        assert_eq!(kind("sweep (reduced run) at load scale 2: Newton failed"), None);
    }

    /// Where training measured a sensitivity above the tolerance and above the estimate
    /// (0.2 at the candidate 1.0; `AMPLIFYING · δ` = 1e-2), an estimate below the tolerance
    /// does not keep the reduced answer; beside a candidate that does not amplify (0.5:
    /// 1e-3) it does.
    #[test]
    fn an_amplifying_load_falls_back_below_the_tolerance() {
        let mut trust = Trust::range((0.5, 1.5));
        trust.tolerance = Some(5e-3);
        trust.sensitivity = Some(crate::rom::trust::LoadSensitivity::new(vec![0.5, 1.0, 1.5], vec![1e-3, 0.2, 1e-3]));
        let why = reason(Some(&trust), &Parameters::load_scale(1.0), Some(&estimate(1e-3, 1e-3))).expect("0.2");
        assert!(why.contains("amplifies") && why.contains("2.0e-1"), "{why}");
        assert_eq!(reason(Some(&trust), &Parameters::load_scale(0.5), Some(&estimate(1e-3, 1e-3))), None);
    }
}
