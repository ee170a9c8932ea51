//! What the online tools tell a user about a reduced run besides the estimate itself
//! (docs/error-estimate.md): the extrapolation flag, the tolerance check and `--strict`, the
//! estimator read from a basis file, the result file's attributes. Moved from
//! [`super::estimate`], which re-exports everything here (the struct [`Estimate`] too).

use crate::error::Result;
use crate::reduction::estimator::{EstimateMethod, Estimator};

/// One estimate.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Estimate {
    /// `c · η_raw`; infinite when the enriched model failed to run
    pub error_estimate: f64,
    /// `η_raw`
    pub raw: f64,
    pub factor: f64,
    pub calibrated: bool,
    /// wall time of the enriched run's time loop and the norms, s
    pub seconds: f64,
    /// `c · η_raw` over the instants up to the end of each fifth of the run (as
    /// `estimate::rel_error_by_time` for the true error); NaN where unknown
    pub by_time: [f64; 5],
}

/// Whether `load_scale` lies outside `[lo, hi]` (with a relative slack of 1e-9 for the
/// ends, which are training loads themselves).
pub fn is_extrapolated(range: (f64, f64), load_scale: f64) -> bool {
    let slack = 1e-9 * range.0.abs().max(range.1.abs()).max(1e-300);
    load_scale < range.0 - slack || load_scale > range.1 + slack
}

/// What the online tools know about a basis beyond the basis itself: its estimator, the
/// training range and the tolerance a run's estimate is held to.
#[derive(Clone, Debug)]
pub struct TrustInfo {
    pub estimator: Option<Estimator>,
    pub range: (f64, f64),
    /// `[online] tolerance`, else greedy training's tolerance, else none
    pub tolerance: Option<f64>,
    /// the user asked for no estimate (`--no-estimate`): no warnings about its absence
    pub skipped: bool,
}

/// Reads the estimator (checked against the model), the training range and tolerance of
/// the basis file `path` already read as `stored`.
pub fn load_trust(
    p: &super::Pipeline,
    path: &std::path::Path,
    stored: &crate::io::basis_file::StoredBasis,
) -> Result<TrustInfo> {
    use crate::error::Error;
    use crate::io::estimator_file::{read_estimator, read_training_range, read_training_tolerance};
    use crate::solver::model::ParametricModel;
    let mut estimator = read_estimator(path, &stored.basis)?;
    if let Some(e) = &mut estimator {
        e.method = p.file.online.as_ref().and_then(|o| o.estimate).unwrap_or(e.default_method());
    }
    if let Some(e) = &estimator {
        if e.method == EstimateMethod::Defects && e.defects.as_ref().is_some_and(|d| !d.reliable) {
            eprintln!(
                "warning: {}: [online] estimate = \"defects\" on a basis whose defects calibration failed its check between the candidate loads (docs/error-estimate.md): the estimate uses the largest ratio measured and may read far above the error; \"corrected\" is the tighter choice here",
                p.path.display()
            );
        }
        let sys = &*p.model.physics()?.sys;
        let err = |(field, problem): (String, String)| Error::input(path, format!("estimator/{field}"), problem);
        e.enriched.validate(sys.n_dof(), sys.n_constraints()).map_err(err)?;
        if let Some(h) = &e.enriched.hyper {
            h.validate(sys.n_elements()).map_err(err)?;
        }
    }
    let tolerance = match p.online_tolerance() {
        Some(t) => Some(t),
        None => read_training_tolerance(path)?,
    };
    Ok(TrustInfo { estimator, range: read_training_range(path)?, tolerance, skipped: false })
}

/// One line for stderr: the estimate, its method, whether calibrated, and its cost against
/// the reduced run.
pub fn describe(e: &Estimate, method: &str, rom_seconds: f64) -> String {
    format!(
        "error_estimate {:.3e} ({method} method, {}, factor {:.3}), estimator {:.4} s ({:.0} % of the reduced run)",
        e.error_estimate,
        if e.calibrated { "calibrated" } else { "uncalibrated" },
        e.factor,
        e.seconds,
        100.0 * e.seconds / rom_seconds
    )
}

/// Attributes of an `online` result file: `error_estimate` (NaN without an estimator),
/// `error_estimate_by_time` (5 values: the estimate up to the end of each fifth of the run,
/// the last = `error_estimate`; NaN without an estimator), `error_estimate_raw`, `error_estimate_factor`, `error_estimate_calibrated` (0/1),
/// `extrapolated` (0/1), `training_range` ([min, max]), `tolerance` (when set),
/// `error_estimate_method` (`corrected`, `defects` or `enriched`; when there is an estimator).
pub fn write_run_attributes(
    f: &hdf5::File,
    e: Option<&Estimate>,
    trust: &TrustInfo,
    extrapolated: bool,
) -> hdf5::Result<()> {
    use crate::io::h5::{attr_f64, attr_u64};
    attr_f64(f, "error_estimate", e.map_or(f64::NAN, |e| e.error_estimate))?;
    f.new_attr::<f64>().shape(5).create("error_estimate_by_time")?.write(&e.map_or([f64::NAN; 5], |e| e.by_time))?;
    attr_f64(f, "error_estimate_raw", e.map_or(f64::NAN, |e| e.raw))?;
    attr_f64(f, "error_estimate_factor", e.map_or(f64::NAN, |e| e.factor))?;
    attr_u64(f, "error_estimate_calibrated", e.is_some_and(|e| e.calibrated) as u64)?;
    attr_u64(f, "extrapolated", extrapolated as u64)?;
    f.new_attr::<f64>().shape(2).create("training_range")?.write(&[trust.range.0, trust.range.1])?;
    if let Some(t) = trust.tolerance {
        attr_f64(f, "tolerance", t)?;
    }
    if let (Some(_), Some(est)) = (e, &trust.estimator) {
        crate::io::h5::attr_str(f, "error_estimate_method", est.method.name())?;
    }
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

/// Prints one warning line on stderr for extrapolated load scales and one for estimates
/// above the tolerance (or for a basis without an estimator); `runs` are
/// `(load scale, error_estimate)`. With `strict`, an estimate above the tolerance (or none
/// at all when a tolerance is set) is an [`crate::Error::Strict`], for after the output is
/// written.
pub fn check_runs(trust: &TrustInfo, runs: &[(f64, Option<f64>)], strict: bool) -> Result<()> {
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
        eprintln!("warning: {what} outside the basis's training range [{a}, {b}]: extrapolated, the reduced model was never trained there");
    }
    if trust.estimator.is_none() && runs.iter().all(|r| r.1.is_none()) && !trust.skipped {
        eprintln!("warning: the basis file has no error estimator (/estimator; written by `flexrom train` since this version): no error_estimate; train again");
    }
    let Some(tol) = trust.tolerance.filter(|_| !trust.skipped) else {
        if strict {
            eprintln!(
                "warning: --strict: no tolerance to hold the estimates to (set [online] tolerance in the pipeline)"
            );
        }
        return Ok(());
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
        return Ok(());
    }
    let what = if runs.len() == 1 {
        format!("load scale {}", over[0])
    } else {
        format!("{} of {} load scales: {}", over.len(), runs.len(), few(&over))
    };
    let msg = format!("error estimate above the tolerance {tol:e} at {what}");
    if strict {
        return Err(crate::Error::Strict(format!("--strict: {msg}")));
    }
    eprintln!("warning: {msg}");
    Ok(())
}
