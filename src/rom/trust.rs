//! What a reduced run tells its user besides the answer: the error estimate's method and
//! cost, whether the parameters left the training range, and whether the estimate stays
//! within the tolerance (`--strict`). Warnings are returned as lines for the caller to show.

use super::estimator::{ErrorMeasure, Estimate};
use crate::error::{Error, Result};

/// What the online tools hold a basis's runs to.
#[derive(Clone, Debug, PartialEq)]
pub struct Trust {
    /// `[min, max]` of the training load scales
    pub range: (f64, f64),
    /// `[online] tolerance`, else greedy training's tolerance, else none
    pub tolerance: Option<f64>,
    /// the error `tolerance` is on: `[online] tolerance_measure`, else greedy training's
    /// `measure` (relative for other bases)
    pub measure: ErrorMeasure,
    /// the user asked for no estimate (`--no-estimate`): no warnings about its absence
    pub skipped: bool,
}

impl Trust {
    /// Trust in a basis trained over `range` with no tolerance to hold its estimates to.
    pub fn range(range: (f64, f64)) -> Self {
        Trust { range, tolerance: None, measure: ErrorMeasure::Relative, skipped: false }
    }
}

/// Whether `load_scale` lies outside `[lo, hi]` (with a relative slack of 1e-9 for the
/// ends, which are training loads themselves).
pub fn is_extrapolated(range: (f64, f64), load_scale: f64) -> bool {
    let slack = 1e-9 * range.0.abs().max(range.1.abs()).max(1e-300);
    load_scale < range.0 - slack || load_scale > range.1 + slack
}

/// One line: the estimate, its method, whether calibrated, and its cost against the
/// reduced run.
pub fn describe(e: &Estimate, method: &str, rom_seconds: f64) -> String {
    format!(
        "error_estimate {:.3e}, displacement {:.3e} ({method} method, {}, factor {:.3}), estimator {:.4} s ({:.0} % of the reduced run)",
        e.error_estimate,
        e.error_estimate_displacement,
        if e.calibrated { "calibrated" } else { "uncalibrated" },
        e.factor,
        e.seconds,
        100.0 * e.seconds / rom_seconds
    )
}

/// Attributes of a reduced run's result file: `error_estimate` (NaN without an estimator),
/// `error_estimate_by_time` (5 values: the estimate up to the end of each fifth of the run,
/// the last = `error_estimate`; NaN without an estimator), `error_estimate_raw`,
/// `error_estimate_factor`, `error_estimate_calibrated` (0/1), `extrapolated` (0/1),
/// `training_range` ([min, max]), `tolerance` and `tolerance_measure` (`relative` or
/// `displacement`: which estimate the tolerance holds; when set), `error_estimate_method`
/// (`corrected`, `defects` or `enriched`; when there is an estimate),
/// `error_estimate_displacement` and `error_estimate_displacement_by_time` (the estimate of
/// the displacement-relative error, NaN without an estimator).
pub fn write_run_attributes(
    f: &hdf5::File,
    e: Option<&Estimate>,
    method: Option<&str>,
    trust: &Trust,
    extrapolated: bool,
) -> hdf5::Result<()> {
    use crate::io::h5::{attr_f64, attr_u64};
    use crate::reduction::estimator::FIFTHS;
    attr_f64(f, "error_estimate", e.map_or(f64::NAN, |e| e.error_estimate))?;
    f.new_attr::<f64>()
        .shape(FIFTHS)
        .create("error_estimate_by_time")?
        .write(&e.map_or([f64::NAN; FIFTHS], |e| e.by_time))?;
    attr_f64(f, "error_estimate_raw", e.map_or(f64::NAN, |e| e.raw))?;
    attr_f64(f, "error_estimate_factor", e.map_or(f64::NAN, |e| e.factor))?;
    attr_u64(f, "error_estimate_calibrated", e.is_some_and(|e| e.calibrated) as u64)?;
    attr_u64(f, "extrapolated", extrapolated as u64)?;
    f.new_attr::<f64>().shape(2).create("training_range")?.write(&[trust.range.0, trust.range.1])?;
    if let Some(t) = trust.tolerance {
        attr_f64(f, "tolerance", t)?;
        crate::io::h5::attr_str(f, "tolerance_measure", trust.measure.name())?;
    }
    if let (Some(_), Some(m)) = (e, method) {
        crate::io::h5::attr_str(f, "error_estimate_method", m)?;
    }
    attr_f64(f, "error_estimate_displacement", e.map_or(f64::NAN, |e| e.error_estimate_displacement))?;
    f.new_attr::<f64>()
        .shape(FIFTHS)
        .create("error_estimate_displacement_by_time")?
        .write(&e.map_or([f64::NAN; FIFTHS], |e| e.displacement_by_time))?;
    Ok(())
}

/// At most five entries of a list for a one-line message, then "…".
fn few(v: &[String]) -> String {
    if v.len() <= 5 {
        v.join(", ")
    } else {
        format!("{}, …, {}", v[..4].join(", "), v[v.len() - 1])
    }
}

/// The warnings about finished runs, one line each (without the `warning: ` prefix): the
/// load scales outside the training range, a basis without an estimator, and estimates
/// above the tolerance; `runs` are `(load scale, the estimate in the trust's measure)`
/// ([`Estimate::in_measure`]) and `has_estimator` says whether the basis has one. With `strict`, an estimate above the tolerance (or none at
/// all when a tolerance is set) is an [`Error::Strict`] instead, for after the output is
/// written.
pub fn check_runs(
    trust: &Trust,
    has_estimator: bool,
    runs: &[(f64, Option<f64>)],
    strict: bool,
) -> Result<Vec<String>> {
    let mut warnings = Vec::new();
    let (a, b) = trust.range;
    let out: Vec<String> = runs
        .iter()
        .filter(|r| is_extrapolated(trust.range, r.0))
        .map(|r| format!("{:.4}", r.0).trim_end_matches('0').trim_end_matches('.').to_string())
        .collect();
    if !out.is_empty() {
        let what = if runs.len() == 1 {
            format!("load scale {}", out[0])
        } else {
            format!("{} of {} load scales ({})", out.len(), runs.len(), few(&out))
        };
        warnings.push(format!(
            "{what} outside the basis's training range [{a}, {b}]: extrapolated, the reduced model was never trained there"
        ));
    }
    if !has_estimator && runs.iter().all(|r| r.1.is_none()) && !trust.skipped {
        warnings.push("the basis file has no error estimator (/estimator; written by `flexrom train` since this version): no error_estimate; train again".into());
    }
    let Some(tol) = trust.tolerance.filter(|_| !trust.skipped) else {
        if strict {
            warnings.push(
                "--strict: no tolerance to hold the estimates to (set [online] tolerance in the pipeline)".into(),
            );
        }
        return Ok(warnings);
    };
    let over: Vec<String> = runs
        .iter()
        .filter(|r| r.1.is_none_or(|e| !(e <= tol)))
        .map(|r| match r.1 {
            Some(e) => format!("{:.4} ({e:.2e})", r.0),
            None => format!("{:.4} (no estimate)", r.0),
        })
        .collect();
    if over.is_empty() {
        return Ok(warnings);
    }
    let what = if runs.len() == 1 {
        format!("load scale {}", over[0])
    } else {
        format!("{} of {} load scales: {}", over.len(), runs.len(), few(&over))
    };
    let kind = match trust.measure {
        ErrorMeasure::Relative => "error estimate",
        ErrorMeasure::Displacement => "displacement error estimate",
    };
    let msg = format!("{kind} above the tolerance {tol:e} at {what}");
    if strict {
        return Err(Error::Strict(format!("--strict: {msg}")));
    }
    warnings.push(msg);
    Ok(warnings)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The training range's ends are inside (they are training loads), anything beyond by
    /// more than round-off is outside.
    #[test]
    fn extrapolation_is_outside_the_range_by_more_than_round_off() {
        assert!(is_extrapolated((0.5, 1.5), 1.6) && is_extrapolated((0.5, 1.5), 0.49));
        assert!(!is_extrapolated((0.5, 1.5), 1.5) && !is_extrapolated((0.5, 1.5), 0.5 * (1.0 - 1e-12)));
    }

    /// One warning per kind, returned rather than printed; `--strict` turns the tolerance's
    /// into an error.
    #[test]
    fn warnings_are_returned_and_strict_fails() {
        let t = Trust { range: (0.5, 1.5), tolerance: Some(1e-3), measure: ErrorMeasure::Relative, skipped: false };
        let w = check_runs(&t, true, &[(1.7, Some(1e-4)), (1.0, Some(2e-3))], false).unwrap();
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(w[0].contains("1 of 2 load scales (1.7)") && w[1].contains("above the tolerance 1e-3"), "{w:?}");
        let d = Trust { measure: ErrorMeasure::Displacement, ..t.clone() };
        let w = check_runs(&d, true, &[(1.0, Some(2e-3))], false).unwrap();
        assert!(w.len() == 1 && w[0].starts_with("displacement error estimate above the tolerance 1e-3"), "{w:?}");
        assert!(matches!(check_runs(&t, true, &[(1.0, Some(2e-3))], true), Err(Error::Strict(_))));
        assert!(check_runs(&t, true, &[(1.0, Some(1e-4))], true).unwrap().is_empty());
        let none = check_runs(&Trust::range((0.5, 1.5)), false, &[(1.0, None)], false).unwrap();
        assert!(none.len() == 1 && none[0].contains("no error estimator"), "{none:?}");
    }
}
