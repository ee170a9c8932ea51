//! What a reduced run tells its user besides the answer: the error estimate's method and
//! cost, whether the parameters left the training range, and whether the estimate stays
//! within the tolerance (`--strict`). Warnings are returned as lines for the caller to show.

use super::estimator::{ErrorMeasure, Estimate, QuantityEstimate};
use super::quantities::Quantity;
use crate::error::{Error, Result};
use crate::io::basis_training::StoredSensitivity;
use crate::solver::parameter_space::ParameterSpace;
use crate::solver::parameters::Parameters;

/// What the online tools hold a basis's runs to. Serde: a Python `Result` carries it when
/// pickled (python/src/pickle.rs).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
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
    /// the reduced model's sensitivity to the load along the training range (greedy bases)
    pub sensitivity: Option<LoadSensitivity>,
    /// the box of parameters the basis was trained over (`/parameters`); empty: the load
    /// scale alone, every named parameter at 1
    #[serde(with = "space_serde")]
    pub space: ParameterSpace,
}

impl Trust {
    /// Trust in a basis trained over `range` with no tolerance to hold its estimates to.
    pub fn range(range: (f64, f64)) -> Self {
        Trust {
            range,
            tolerance: None,
            measure: ErrorMeasure::Relative,
            skipped: false,
            sensitivity: None,
            space: ParameterSpace::default(),
        }
    }

    /// The tolerance the estimates are held to: none without one, or when the estimate is
    /// skipped (`--no-estimate`).
    pub fn held_tolerance(&self) -> Option<f64> {
        self.tolerance.filter(|_| !self.skipped)
    }

    /// The sensitivity near `mu` when the model amplifies changes of the load
    /// there beyond what `estimate` (in the trust's measure; `None`: no estimate) can see:
    /// above the tolerance, above [`AMPLIFYING`]` · δ` and above the estimate
    /// ([`LoadSensitivity`]). `None` otherwise, or without a tolerance or the training record.
    pub fn amplifying_near(&self, mu: &Parameters, estimate: Option<f64>) -> Option<f64> {
        let s = self.sensitivity.as_ref()?.near(mu)?;
        self.amplifies(s, estimate).then_some(s)
    }

    /// Whether a sensitivity `s` (training's beside a point, or one measured there by full
    /// runs) counts as amplifying beyond `estimate`: above the tolerance, above
    /// [`AMPLIFYING`]` · δ` and above the estimate. False without a tolerance.
    pub fn amplifies(&self, s: f64, estimate: Option<f64>) -> bool {
        let Some(tol) = self.tolerance else { return false };
        amplifying(s, tol) && estimate.is_none_or(|e| !(e >= s))
    }
}

/// Whether the model amplifies changes of the load where its sensitivity is `s`, for a
/// tolerance `tol`: `s` above the tolerance and above [`AMPLIFYING`]` · δ`. Only there does
/// greedy training hold an error to the sensitivity instead of the tolerance (a response
/// proportional to the load moves by about δ, which a tolerance below δ asks to resolve).
pub fn amplifying(s: f64, tol: f64) -> bool {
    s > tol.max(AMPLIFYING * SENSITIVITY_STEP)
}

/// δ of the sensitivity `s(λ) = ‖X_r(λ(1 + δ)) − X_r(λ)‖ / ‖X_r(λ)‖`: how much the answer
/// moves for a 0.1 % change of the load (the `sensitivity` `validate` reports).
pub const SENSITIVITY_STEP: f64 = 1e-3;

/// How much more than the load's own relative change `δ` the answer must move before the
/// model counts as amplifying it: an order of magnitude. A response that follows the load
/// moves the answer by `δ ‖λ ∂X/∂λ‖ / ‖X‖`, about `δ` or less (the load-driven part of the
/// answer is no larger than the answer; the period of a swinging pendulum shifting with
/// its amplitude adds a few times that: `s/δ` ≤ 2.7 over the zoo's calm models and the
/// shipped pendulums, docs/zoo.md); chaotic dynamics amplify it tens to hundreds of times
/// (the four-bar after t ≈ 0.7 s: `s/δ` 9–160).
pub const AMPLIFYING: f64 = 10.0;

/// The reduced model's whole-run sensitivity at greedy training's candidates (its last
/// iteration; docs/greedy-training.md):
///
/// ```text
///     s(λ_c) = ‖X_r(λ_c (1 + δ)) − X_r(λ_c)‖ / ‖X_r(λ_c)‖,   δ = 0.1 %
/// ```
///
/// Where `s` exceeds the tolerance and [`AMPLIFYING`]` · δ`, the dynamics amplify a small
/// difference of the load — or of the model, the reduction's among them — to an error
/// above the tolerance, which no estimate that follows the reduced trajectory sees (it
/// compares two trajectories of the same amplifying dynamics). Between candidates the
/// larger neighbour counts: the sensitivity jumps with the dynamics, it does not
/// interpolate. In a box of parameters (every parameter of the box moved by δ) the
/// candidates are points, and the largest of those around the point counts (the nearest
/// in each orthant about it).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LoadSensitivity {
    candidates: Vec<f64>,
    whole_run: Vec<f64>,
    /// a box's candidates: the box and each candidate in its unit cube
    #[serde(serialize_with = "space_serde::serialize_points", deserialize_with = "space_serde::deserialize_points")]
    points: Option<(ParameterSpace, Vec<Vec<f64>>)>,
}

/// The serde form of a box of parameters in [`Trust`] and [`LoadSensitivity`]: its ranges
/// as `(name, lower, upper, spacing)` (the box itself, a training setting of the solver
/// layer, has no serde form of its own).
mod space_serde {
    use crate::solver::parameter_space::{ParameterRange, ParameterSpace, Spacing};
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    type Ranges = Vec<(String, f64, f64, Spacing)>;

    fn ranges(space: &ParameterSpace) -> Ranges {
        // every field named: a field added to a range fails to compile here
        let plain = |r: &ParameterRange| {
            let ParameterRange { name, lower, upper, spacing } = r;
            (name.clone(), *lower, *upper, *spacing)
        };
        space.ranges.iter().map(plain).collect()
    }

    fn space(ranges: Ranges) -> ParameterSpace {
        let ranges =
            ranges.into_iter().map(|(name, lower, upper, spacing)| ParameterRange { name, lower, upper, spacing });
        ParameterSpace { ranges: ranges.collect() }
    }

    pub fn serialize<S: Serializer>(s: &ParameterSpace, to: S) -> Result<S::Ok, S::Error> {
        ranges(s).serialize(to)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(from: D) -> Result<ParameterSpace, D::Error> {
        Ranges::deserialize(from).map(space)
    }

    type Points = Option<(ParameterSpace, Vec<Vec<f64>>)>;

    /// `LoadSensitivity`'s candidate points with their box.
    pub fn serialize_points<S: Serializer>(p: &Points, to: S) -> Result<S::Ok, S::Error> {
        p.as_ref().map(|(s, unit)| (ranges(s), unit)).serialize(to)
    }

    pub fn deserialize_points<'de, D: Deserializer<'de>>(from: D) -> Result<Points, D::Error> {
        Ok(Option::<(Ranges, Vec<Vec<f64>>)>::deserialize(from)?.map(|(r, unit)| (space(r), unit)))
    }
}

impl LoadSensitivity {
    /// `candidates` increasing, one sensitivity each (NaN where it was not measured).
    pub fn new(candidates: Vec<f64>, whole_run: Vec<f64>) -> Self {
        LoadSensitivity { candidates, whole_run, points: None }
    }

    /// Greedy training's record as the basis file stores it ([`StoredSensitivity`]: on a
    /// line its candidate loads, in the box `space` its candidate points).
    pub fn of_stored(s: &StoredSensitivity, space: &ParameterSpace) -> Self {
        match s {
            StoredSensitivity::Loads { candidates, whole_run } => Self::new(candidates.clone(), whole_run.clone()),
            StoredSensitivity::Box { unit, whole_run } => Self::in_box(space.clone(), unit.clone(), whole_run.clone()),
        }
    }

    /// Candidates at the points `unit` of the box `space`'s unit cube, one sensitivity each.
    pub fn in_box(space: ParameterSpace, unit: Vec<Vec<f64>>, whole_run: Vec<f64>) -> Self {
        LoadSensitivity { candidates: Vec::new(), whole_run, points: Some((space, unit)) }
    }

    /// The larger sensitivity of the candidates beside `mu` (the candidate itself when `mu` is
    /// one, the end candidate outside their range; in a box the largest of those around it,
    /// the nearest in each orthant: [`crate::solver::parameter_space::around`]); `None` when none was measured.
    pub fn near(&self, mu: &Parameters) -> Option<f64> {
        if let Some((space, unit)) = &self.points {
            let near = crate::solver::parameter_space::around(unit, &space.unit_of(mu), None);
            return near.iter().map(|&i| self.whole_run[i]).filter(|s| s.is_finite()).reduce(f64::max);
        }
        let x = mu.scale();
        let c = &self.candidates;
        if c.is_empty() || !x.is_finite() {
            return None;
        }
        let k = c.partition_point(|&y| y < x);
        let beside: &[usize] = if k < c.len() && c[k] == x {
            &[k]
        } else if k == 0 {
            &[0]
        } else if k == c.len() {
            &[c.len() - 1]
        } else {
            &[k - 1, k]
        };
        beside.iter().map(|&i| self.whole_run[i]).filter(|s| s.is_finite()).reduce(f64::max)
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
    // undefined where nothing moved beyond the Newton tolerance (norms::against_motion)
    let displacement = match e.error_estimate_displacement {
        d if d.is_nan() => "none".to_string(),
        d => format!("{d:.3e}"),
    };
    format!(
        "error_estimate {:.3e}, displacement {displacement} ({method} method, {}, factor {}), estimator {:.4} s ({:.0} % of the reduced run)",
        e.error_estimate,
        if e.calibrated { "calibrated" } else { "uncalibrated" },
        crate::solver::parameter_space::short_number(e.factor),
        e.seconds,
        100.0 * e.seconds / rom_seconds
    )
}

/// The warning for an estimate whose estimator's own model failed at `at` (a load, or a
/// point of a box) for the reason `why` (the estimate's `failure`): the estimate reads ∞;
/// `None` when it was computed.
pub fn estimate_failed(at: &str, why: Option<&str>) -> Option<String> {
    let why = why?;
    Some(format!(
        "no error estimate at {at}: the estimator's own run failed ({why}); the estimate reads ∞ and nothing bounds \
         this reduced answer's error but a full run there (`validate`, `sweep --full`)"
    ))
}

/// Attributes of a reduced run's result file: `error_estimate` (NaN without an estimator),
/// `error_estimate_by_time` (5 values: the estimate up to the end of each fifth of the run,
/// the last = `error_estimate`; NaN without an estimator), `error_estimate_raw`,
/// `error_estimate_factor`, `error_estimate_calibrated` (0/1), `extrapolated` (0/1),
/// `training_range` ([min, max]), `tolerance` and `tolerance_measure` (`relative` or
/// `displacement`: which estimate the tolerance holds; when set), `error_estimate_method`
/// (`corrected`, `defects` or `enriched`; when there is an estimate),
/// `error_estimate_displacement` and `error_estimate_displacement_by_time` (the estimate of
/// the displacement-relative error, NaN without an estimator), `sensitivity_near` (the
/// reduced model's sensitivity at greedy training's candidates beside the load, NaN for
/// other bases: [`LoadSensitivity`]), `error_estimate_failure` (why the estimator's own run
/// failed, when it did: the estimates are then ∞).
pub fn write_run_attributes(
    f: &hdf5::File,
    e: Option<&Estimate>,
    method: Option<&str>,
    trust: &Trust,
    mu: &Parameters,
    extrapolated: bool,
) -> hdf5::Result<()> {
    let sensitivity_near = trust.sensitivity.as_ref().and_then(|s| s.near(mu));
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
    if let Some(why) = e.and_then(|e| e.failure.as_deref()) {
        crate::io::h5::attr_str(f, "error_estimate_failure", why)?;
    }
    attr_f64(f, "error_estimate_displacement", e.map_or(f64::NAN, |e| e.error_estimate_displacement))?;
    f.new_attr::<f64>()
        .shape(FIFTHS)
        .create("error_estimate_displacement_by_time")?
        .write(&e.map_or([f64::NAN; FIFTHS], |e| e.displacement_by_time))?;
    attr_f64(f, "sensitivity_near", sensitivity_near.unwrap_or(f64::NAN))?;
    let quantities = e.map_or(&[][..], |e| &e.quantities[..]);
    for q in quantities.iter().filter(|q| !q.quantity.is_reaction()) {
        write_quantity_estimate(f, q)?;
    }
    write_reaction_estimates(f, quantities)
}

/// The estimates of the joints' reactions as the attribute `error_estimate` (one per
/// reaction point, in `/labels/reaction`'s order) of `/reactions/force` and
/// `/reactions/moment`, where the file holds them and the estimate has them.
fn write_reaction_estimates(f: &hdf5::File, quantities: &[QuantityEstimate]) -> hdf5::Result<()> {
    for (quantity, path) in [(Quantity::Force, "reactions/force"), (Quantity::Moment, "reactions/moment")] {
        let values: Vec<f64> = quantities.iter().filter(|q| q.quantity == quantity).map(|q| q.estimate).collect();
        if values.is_empty() || !f.link_exists(path) {
            continue;
        }
        let d = f.dataset(path)?;
        if d.shape().get(1) == Some(&values.len()) {
            d.new_attr::<f64>().shape(values.len()).create("error_estimate")?.write(&values)?;
        }
    }
    Ok(())
}

/// The estimate of a probe quantity's error over its range ([`crate::rom::quantities`]) as
/// the attribute `error_estimate` of the quantity's dataset (`/probes/<name>`,
/// `/probe_strain/<name>`, `/probe_curvature/<name>`), where the file holds it.
fn write_quantity_estimate(f: &hdf5::File, q: &QuantityEstimate) -> hdf5::Result<()> {
    let group = match q.quantity {
        Quantity::Position => "probes",
        Quantity::Strain => "probe_strain",
        Quantity::Curvature => "probe_curvature",
        Quantity::Force | Quantity::Moment => return Ok(()),
    };
    let path = format!("{group}/{}", q.probe);
    if f.link_exists(&path) {
        let d = f.dataset(&path)?;
        crate::io::h5::attr_f64(&d, "error_estimate", q.estimate)?;
    }
    Ok(())
}

/// A load scale in a list of a message: four decimals at most, no trailing zeros.
pub fn short(x: f64) -> String {
    format!("{x:.4}").trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The loads a warning is about, of `of` runs: "load scale X" for a single run, else
/// "K of N load scales" and the list, after `sep` ("point", "points" in a box).
fn which(named: &[String], of: usize, sep: (&str, &str), in_box: bool) -> String {
    let (one, many) = if in_box { ("point", "points") } else { ("load scale", "load scales") };
    if of == 1 {
        format!("{one} {}", named[0])
    } else {
        format!("{} of {of} {many}{}{}{}", named.len(), sep.0, few(named), sep.1)
    }
}

/// A run's parameters in a list of a message: its load scale ([`short`]), in a box the
/// box's parameters, `(g = 1.1, push = 0.3)`, and with named parameters outside a box all
/// of them, `(load scale 1, payload = 1)`.
/// `whole`: some run of the list has named parameters outside a box (each is then named by
/// all its parameters, λ alone as `(load scale 3)`).
fn label(trust: &Trust, mu: &Parameters, whole: bool) -> String {
    match (trust.space.is_empty(), whole) {
        (true, false) => short(mu.scale()),
        // named parameters the basis was not trained over: they are part of where it ran
        (true, true) => format!("({mu})"),
        (false, _) => format!("({})", trust.space.label(mu)),
    }
}

/// At most five entries of a list for a one-line message, then "…".
pub(crate) fn few(v: &[String]) -> String {
    if v.len() <= 5 {
        v.join(", ")
    } else {
        format!("{}, …, {}", v[..4].join(", "), v[v.len() - 1])
    }
}

/// The warnings about finished runs, one line each (without the `warning: ` prefix): the
/// load scales outside the training range, a basis without an estimator, load scales where
/// the model is sensitive beyond the tolerance and the estimate below that sensitivity
/// ([`LoadSensitivity`]), and estimates above the tolerance; `runs` are `(parameters, the estimate in the trust's measure)`
/// ([`Estimate::in_measure`]) and `has_estimator` says whether the basis has one; they
/// follow the warnings `before`. With `strict`, an estimate above the tolerance (or none at
/// all when a tolerance is set) is an [`Error::Strict`] instead, carrying the other
/// warnings, for after the output is written (without a tolerance there is nothing to
/// hold them to: [`Trust::held_tolerance`]).
pub fn check_runs(
    trust: &Trust,
    has_estimator: bool,
    runs: &[(Parameters, Option<f64>)],
    strict: bool,
    before: Vec<String>,
) -> Result<Vec<String>> {
    let mut warnings = before;
    let (a, b) = trust.range;
    // runs named by their points where they have parameters besides λ
    let named = !trust.space.is_empty() || runs.iter().any(|r| r.0.named().next().is_some());
    // λ outside its range (a box's other parameters are the caller's to name; named
    // parameters outside a box are part of where it ran)
    let whole = trust.space.is_empty() && named;
    let outside = runs.iter().filter(|r| is_extrapolated(trust.range, r.0.scale()));
    let out: Vec<String> =
        outside.map(|r| if whole { label(trust, &r.0, whole) } else { short(r.0.scale()) }).collect();
    if !out.is_empty() {
        let what = which(&out, runs.len(), (" (", ")"), whole);
        warnings.push(format!(
            "{what} outside the basis's training range [{a}, {b}]: extrapolated, the reduced model was never trained there"
        ));
    }
    if let Some(tol) = trust.tolerance {
        let sensitive: Vec<String> = runs
            .iter()
            .filter_map(|r| {
                trust.amplifying_near(&r.0, r.1).map(|s| format!("{} ({s:.1e})", label(trust, &r.0, whole)))
            })
            .collect();
        if !sensitive.is_empty() {
            let what = which(&sensitive, runs.len(), (": ", ""), named);
            let load = if trust.space.is_empty() { "the load" } else { "the parameters" };
            warnings.push(format!(
                "the model amplifies changes of {load} at {what}: near there a 0.1 % change of {load} moved \
                 the reduced answer by more than the tolerance {tol:e} and more than 1 % over the run (training's \
                 sensitivity, in brackets); errors up to that size come from the dynamics, and the error estimate \
                 does not see them. Where it matters, run the full model there (`validate`, `sweep --full`)"
            ));
        }
    }
    if !has_estimator && runs.iter().all(|r| r.1.is_none()) && !trust.skipped {
        warnings.push("the basis file has no error estimator (/estimator; written by `flexrom train` since this version): no error_estimate; train again".into());
    }
    let Some(tol) = trust.held_tolerance() else { return Ok(warnings) };
    let over: Vec<String> = runs
        .iter()
        // NaN: a displacement estimate where nothing moved beyond the Newton tolerance
        // (norms::against_motion): nothing to hold to the tolerance
        .filter(|r| r.1.is_none_or(|e| !e.is_nan() && !(e <= tol)))
        .map(|r| {
            let at = label(trust, &r.0, whole);
            match r.1 {
                Some(e) if e.is_infinite() => format!(
                    "{at} (∞: the estimator's own run failed{})",
                    if trust.measure == ErrorMeasure::Displacement {
                        ", or only the reduced run moved beyond the Newton tolerance"
                    } else {
                        ""
                    }
                ),
                Some(e) => format!("{at} ({e:.2e})"),
                None => format!("{at} (no estimate)"),
            }
        })
        .collect();
    if over.is_empty() {
        return Ok(warnings);
    }
    let what = which(&over, runs.len(), (": ", ""), named);
    let kind = match trust.measure {
        ErrorMeasure::Relative => "error estimate",
        ErrorMeasure::Displacement => "displacement error estimate",
    };
    let msg = format!("{kind} above the tolerance {tol:e} at {what}");
    if strict {
        // the error ends the command: the other warnings (extrapolation, amplification)
        // travel with it, to be said first, as without strict
        return Err(Error::Strict { message: msg, warnings });
    }
    warnings.push(msg);
    Ok(warnings)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn l(x: f64) -> Parameters {
        Parameters::load_scale(x)
    }

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
        let t = Trust {
            range: (0.5, 1.5),
            tolerance: Some(1e-3),
            measure: ErrorMeasure::Relative,
            skipped: false,
            sensitivity: None,
            space: ParameterSpace::default(),
        };
        let w = check_runs(&t, true, &[(l(1.7), Some(1e-4)), (l(1.0), Some(2e-3))], false, Vec::new()).unwrap();
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(w[0].contains("1 of 2 load scales (1.7)") && w[1].contains("above the tolerance 1e-3"), "{w:?}");
        let d = Trust { measure: ErrorMeasure::Displacement, ..t.clone() };
        let w = check_runs(&d, true, &[(l(1.0), Some(2e-3))], false, Vec::new()).unwrap();
        assert!(w.len() == 1 && w[0].starts_with("displacement error estimate above the tolerance 1e-3"), "{w:?}");
        assert!(matches!(check_runs(&t, true, &[(l(1.0), Some(2e-3))], true, Vec::new()), Err(Error::Strict { .. })));
        // strict: the error carries the warnings said before it, those given and its own
        let runs = [(l(1.7), Some(1e-4)), (l(1.0), Some(2e-3))];
        match check_runs(&t, true, &runs, true, vec!["given".into()]) {
            Err(Error::Strict { message, warnings }) => {
                assert!(message.starts_with("error estimate above the tolerance 1e-3 at 1 of 2"), "{message}");
                assert!(warnings.len() == 2 && warnings[0] == "given" && warnings[1].contains("(1.7)"), "{warnings:?}");
            }
            other => panic!("expected the strict error, got {other:?}"),
        }
        assert!(check_runs(&t, true, &[(l(1.0), Some(1e-4))], true, Vec::new()).unwrap().is_empty());
        // a named parameter the basis was not trained over is part of where the run was
        let named = [(l(1.0).with("payload", 1.0), Some(3.9e-3))];
        let w = check_runs(&t, true, &named, false, Vec::new()).unwrap();
        assert_eq!(w, ["error estimate above the tolerance 1e-3 at point (load scale 1, payload = 1) (3.90e-3)"]);
        let twice = [(l(3.0), Some(1e-4)), (l(3.0).with("payload", 1.0), Some(1e-4))];
        let w = check_runs(&t, true, &twice, false, Vec::new()).unwrap();
        assert!(w[0].starts_with("2 of 2 points ((load scale 3), (load scale 3, payload = 1)) outside"), "{w:?}");
        let none = check_runs(&Trust::range((0.5, 1.5)), false, &[(l(1.0), None)], false, Vec::new()).unwrap();
        assert!(none.len() == 1 && none[0].contains("no error estimator"), "{none:?}");
    }
}

#[cfg(test)]
mod sensitivity_tests {
    use super::*;

    fn l(x: f64) -> Parameters {
        Parameters::load_scale(x)
    }

    /// Between two candidates the larger neighbour counts; at a candidate, its own value;
    /// outside, the end one; unmeasured (NaN) neighbours are left out.
    #[test]
    fn the_sensitivity_near_a_load_is_its_larger_neighbour() {
        let s = LoadSensitivity::new(vec![0.5, 1.0, 1.5], vec![1e-3, 3e-2, f64::NAN]);
        assert_eq!(s.near(&l(0.75)), Some(3e-2));
        assert_eq!(s.near(&l(0.5)), Some(1e-3));
        assert_eq!(s.near(&l(1.0)), Some(3e-2));
        assert_eq!(s.near(&l(0.1)), Some(1e-3));
        assert_eq!(s.near(&l(1.25)), Some(3e-2));
        assert_eq!(s.near(&l(1.5)), None);
        assert_eq!(s.near(&l(9.0)), None);
        assert_eq!(LoadSensitivity::new(vec![], vec![]).near(&l(1.0)), None);
        // in a box (here one parameter, p over [0, 2]) the largest of the candidates around
        // the point: p = 0.5 lies between 0 and 1, p = 0.1 between 0 and 1 too
        use crate::solver::parameter_space::{ParameterRange, ParameterSpace, Spacing};
        let space = ParameterSpace {
            ranges: vec![ParameterRange { name: "p".into(), lower: 0.0, upper: 2.0, spacing: Spacing::Linear }],
        };
        let b = LoadSensitivity::in_box(space, vec![vec![0.0], vec![0.5], vec![1.0]], vec![1e-3, 3e-2, f64::NAN]);
        let p = |x: f64| Parameters::default().with("p", x);
        assert_eq!(b.near(&p(0.5)), Some(3e-2));
        assert_eq!(b.near(&p(0.1)), Some(3e-2));
        assert_eq!(b.near(&p(1.8)), Some(3e-2));
    }

    /// A load whose neighbouring sensitivity is above the tolerance, ten times δ and the estimate
    /// is named (the estimate cannot see the errors the dynamics amplify there); an estimate
    /// at or above that sensitivity, or a calm neighbourhood, says nothing.
    #[test]
    fn loads_where_the_model_is_sensitive_beyond_the_estimate_are_named() {
        let t = Trust {
            range: (0.5, 1.5),
            tolerance: Some(1e-2),
            measure: ErrorMeasure::Relative,
            skipped: false,
            sensitivity: Some(LoadSensitivity::new(vec![0.5, 1.0, 1.5], vec![1e-3, 3e-2, 1e-3])),
            space: ParameterSpace::default(),
        };
        let w = check_runs(&t, true, &[(l(1.2), Some(1e-4))], false, Vec::new()).unwrap();
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains("amplifies changes of the load at load scale 1.2 (3.0e-2)"), "{}", w[0]);
        // below the first candidate only its own, calm value counts
        assert!(check_runs(&t, true, &[(l(0.4), Some(1e-4))], false, Vec::new())
            .unwrap()
            .iter()
            .all(|w| !w.contains("amplifies")));
        // an estimate already as large as the sensitivity (but within T) covers it
        let t2 = Trust { tolerance: Some(5e-2), ..t.clone() };
        assert!(
            check_runs(&t2, true, &[(l(1.2), Some(1e-4))], false, Vec::new()).unwrap().is_empty(),
            "s below T: calm enough"
        );
        let w = check_runs(&t, true, &[(l(1.2), Some(4e-2)), (l(0.7), None), (l(0.3), Some(1e-4))], false, Vec::new())
            .unwrap();
        let sens: Vec<_> = w.iter().filter(|w| w.contains("amplifies")).collect();
        assert_eq!(sens.len(), 1);
        assert!(sens[0].contains("1 of 3 load scales: 0.7 (3.0e-2)"), "{}", sens[0]);
        // above a tight tolerance but a response that follows the load (s = 5 δ, as a
        // swinging pendulum's): not amplifying, nothing said
        let calm = Trust {
            tolerance: Some(1e-3),
            sensitivity: Some(LoadSensitivity::new(vec![0.5, 1.5], vec![5e-3, 5e-3])),
            ..t.clone()
        };
        assert!(check_runs(&calm, true, &[(l(1.2), Some(1e-4))], false, Vec::new()).unwrap().is_empty());
        // not an error under --strict: the estimates themselves are within the tolerance
        assert!(check_runs(&t, true, &[(l(1.2), Some(1e-4))], true, Vec::new()).is_ok());
    }
}
