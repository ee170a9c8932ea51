//! What a validation found: the reduced run against the full one at the same parameters and
//! Δt ([`Validation`], the fixed keys of `validate --json`, which a validated sweep's file
//! keeps point by point), with each probe's error over its travel, each probe quantity's
//! and each joint reaction's error over its range. The runs and the comparison that fill it
//! are `crate::workflows::validate`'s; its module documentation gives the measures'
//! equations.

use crate::model::Model;
use crate::rom::estimator::norms::against_motion;
use crate::rom::estimator::Estimate;
use crate::rom::quantities::{self, Apart, Quantity};
use crate::rom::reactions::ReactionReader;
use crate::rom::Rom;
use crate::simulate::SimulationResult;
use crate::solver::model::Parameters;
use ndarray::ArrayView2;

/// The fixed keys of `validate --json`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Validation {
    pub load_scale: f64,
    /// every parameter of the run by name: `load_scale` and the model's named ones
    pub parameters: std::collections::BTreeMap<String, f64>,
    pub variant: String,
    pub n_dof: usize,
    pub n_modes: usize,
    pub rel_error: f64,
    pub max_probe_error: f64,
    pub max_probe_error_probe: String,
    pub max_probe_error_t: f64,
    pub max_constraint_violation: f64,
    /// full model, our default (banded) linear solver: time loop only, the median of up to
    /// seven runs interleaved with the reduced ones ([`crate::cost::timing::TIMING_BUDGET`])
    pub full_seconds: f64,
    /// full model with dense LAPACK LU; `None` when not measured
    pub full_dense_seconds: Option<f64>,
    /// reduced time loop, basis loaded and projected beforehand (median, as `full_seconds`)
    pub rom_seconds: f64,
    pub speedup: f64,
    pub speedup_vs_dense: Option<f64>,
    /// `full_seconds / (rom_seconds + estimate_seconds)`: the reduced route as `online` and
    /// `sweep` run it, estimate included (null: no estimate). The time loops are medians of
    /// interleaved runs, the estimate's time that of its one run
    pub speedup_with_estimate: Option<f64>,
    pub full_newton_iterations: usize,
    pub rom_newton_iterations: usize,
    pub rom_step_cuts: usize,
    pub full_step_cuts: usize,
    /// the earliest time from which the two runs took different steps (one halved a step
    /// the other did not; null: the same steps): after it rel_error holds a difference of
    /// time discretization as well as the reduction's
    pub steps_differ_from: Option<f64>,
    /// start times of the steps the full run halved (Newton failed at the full step); in
    /// the text output only (a list of any length has no CSV columns)
    #[serde(skip)]
    pub full_step_cut_times: Vec<f64>,
    /// start times of the steps the reduced run halved (text output only)
    #[serde(skip)]
    pub rom_step_cut_times: Vec<f64>,
    /// the estimate of `rel_error` without a full run (null: the basis has no estimator)
    pub error_estimate: Option<f64>,
    /// `error_estimate / rel_error`
    pub effectivity: Option<f64>,
    /// whether the estimate's factor was calibrated on held-out full runs
    pub estimate_calibrated: Option<bool>,
    /// the estimator's extra cost: its enriched reduced run and norms, s
    pub estimate_seconds: Option<f64>,
    /// the load scale lies outside the basis's training range
    pub extrapolated: bool,
    /// `[min, max]` training load scale (null when unknown; over a box λ's range, `[1, 1]`
    /// unless the box holds λ: `training_box` names the box)
    pub training_range: Option<[f64; 2]>,
    /// relative difference of full runs at λ and 1.001 λ (null when not measured); for a
    /// basis trained over a box, at μ and every parameter of the box times 1.001
    pub sensitivity: Option<f64>,
    /// the box the basis was trained over, `drive ∈ [0.5, 1.5], E ∈ [1e8, 4e8] (log)`
    /// (left out for a line of load scales)
    #[serde(skip_serializing_if = "Option::is_none")]
    pub training_box: Option<String>,
    /// the reduced model's sensitivity at greedy training's candidates beside the load
    /// ([`crate::rom::trust::LoadSensitivity`]; null for other bases)
    pub sensitivity_near: Option<f64>,
    /// `online`, `validate` and `sweep` warn that the model amplifies changes of the load
    /// here beyond what the estimate sees ([`crate::rom::Trust::amplifying_near`]; in
    /// `validate` also from the sensitivity its full runs measured here)
    pub amplifying: bool,
    /// rel_error up to the end of each fifth of the run (the last is rel_error)
    pub rel_error_by_time: Vec<f64>,
    /// error_estimate up to the end of each fifth of the run, the estimate of
    /// `rel_error_by_time` (the last is error_estimate; null: no estimator)
    pub error_estimate_by_time: Option<Vec<f64>>,
    /// `‖X_rom − X_full‖_F / ‖X_full − X₀‖_F`: the error against the motion from the
    /// initial configuration X₀ (`ErrorMeasure::Displacement`); NaN where the full run
    /// does not move beyond the Newton tolerance, ∞ where only the reduced one does (JSON
    /// writes both as null; `max_error_over_travel` and the probes tell them apart)
    pub displacement_error: f64,
    /// why `displacement_error` is not a number, in words (the text output's; JSON writes the
    /// error itself as null): [`displacement_note`]; null where it is one
    pub displacement_error_note: Option<String>,
    /// displacement_error up to the end of each fifth of the run (the last is displacement_error)
    pub displacement_error_by_time: Vec<f64>,
    /// the estimate of `displacement_error` (null: the basis has no estimator)
    pub error_estimate_displacement: Option<f64>,
    /// `error_estimate_displacement / displacement_error`
    pub effectivity_displacement: Option<f64>,
    /// error_estimate_displacement up to the end of each fifth of the run
    pub error_estimate_displacement_by_time: Option<Vec<f64>>,
    /// the largest `error_over_travel` of the probes (null: no probe moved)
    pub max_error_over_travel: Option<f64>,
    pub max_error_over_travel_probe: String,
    /// every probe's error over its travel
    pub probe_errors_over_travel: Vec<ProbeTravel>,
    /// every probe quantity (position, strain, curvature) against the full run's, over its
    /// range, with its estimate
    pub probe_quantity_errors: Vec<ProbeQuantityError>,
    /// every joint's reaction force and moment against the full run's, over its range
    pub reaction_errors: Vec<ReactionError>,
    /// how the estimate was computed (`corrected`, `defects`, `enriched`; null: no estimate)
    pub error_estimate_method: Option<String>,
    /// why the estimator's own run failed, when it did (`error_estimate` is then ∞, which
    /// JSON writes as null)
    pub estimate_failure: Option<String>,
}

/// One probe's error against its own motion.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ProbeTravel {
    pub probe: String,
    /// `max_k |r_rom(t_k) − r_full(t_k)|`, m
    pub max_error: f64,
    /// `max_k |r_full(t_k) − r_full(t₀)|`, m: how far the probe moved from where it started
    pub travel: f64,
    /// `max_error / travel` (null for a probe that did not move)
    pub error_over_travel: Option<f64>,
}

impl ProbeTravel {
    /// The error of the probe positions `rom` against `full` (n_t × 2 each) over the
    /// full run's travel; for a probe whose travel is within `resolution` (the coordinates'
    /// resolution, the Newton tolerance `tol · L`) none, or ∞ where the reduced one moved
    /// by more than that.
    pub fn of(name: &str, full: &ndarray::Array2<f64>, rom: &ndarray::Array2<f64>, resolution: f64) -> ProbeTravel {
        let dist = |a: [f64; 2], b: [f64; 2]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
        let at = |x: &ndarray::Array2<f64>, k: usize| [x[[k, 0]], x[[k, 1]]];
        let (mut max_error, mut travel) = (0.0_f64, 0.0_f64);
        for k in 0..full.nrows() {
            max_error = max_error.max(dist(at(rom, k), at(full, k)));
            travel = travel.max(dist(at(full, k), at(full, 0)));
        }
        let ratio = against_motion(travel > resolution, max_error > resolution, || max_error / travel);
        let error_over_travel = (!ratio.is_nan()).then_some(ratio);
        ProbeTravel { probe: name.to_string(), max_error, travel, error_over_travel }
    }
}

/// One probe quantity — position, strain or curvature (`quantities` in the model file) —
/// of the reduced run against the full run's, relative to the full run's range over the
/// run ([`crate::rom::quantities`]): what an engineer reads off a link (its bending moment
/// is `E I κ`, so its relative error is the curvature's). Derivatives of the coordinates
/// along the beam, strain and curvature converge more slowly in the modes than the
/// coordinates `rel_error` is of: each has its own estimate (docs/error-estimate.md).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ProbeQuantityError {
    pub probe: String,
    pub quantity: Quantity,
    /// `max_k ‖v_rom(t_k) − v_full(t_k)‖` (m, 1 or 1/m)
    pub max_error: f64,
    /// the full run's range, `‖max_k v_full − min_k v_full‖`
    pub range: f64,
    /// `max_k ‖v_full(t_k)‖`: the largest value of the full run
    pub largest: f64,
    /// `max_error / range`; none where the full run's range stays within the quantity's
    /// resolution (the Newton tolerance carried to it) and so does the error; ∞ where only
    /// the error leaves it (JSON writes ∞ as null too: `max_error` tells them apart)
    pub relative: Option<f64>,
    /// the estimate of `relative` (null: no estimator, or no swing to measure against)
    pub estimate: Option<f64>,
    /// `estimate / relative`
    pub effectivity: Option<f64>,
}

impl ProbeQuantityError {
    /// The error of the series `rom` against `full` (n_t × components each) over the full
    /// run's range; `resolution` is the quantity's ([`Quantity::resolution`]).
    pub fn of(probe: &str, quantity: Quantity, full: ArrayView2<f64>, rom: ArrayView2<f64>, resolution: f64) -> Self {
        let apart = Apart::of(rom, full, resolution);
        let largest = full.outer_iter().map(|v| v.dot(&v).sqrt()).fold(0.0, f64::max);
        ProbeQuantityError {
            probe: probe.to_string(),
            quantity,
            max_error: apart.distance,
            range: apart.range,
            largest,
            relative: (!apart.relative.is_nan()).then_some(apart.relative),
            estimate: None,
            effectivity: None,
        }
    }

    /// A quantity's error as a sweep file stores it: the relative error alone (NaN: none).
    pub fn stored(probe: &str, quantity: Quantity, relative: f64) -> Self {
        ProbeQuantityError {
            probe: probe.to_string(),
            quantity,
            max_error: f64::NAN,
            range: f64::NAN,
            largest: f64::NAN,
            relative: (!relative.is_nan()).then_some(relative),
            estimate: None,
            effectivity: None,
        }
    }

    /// Every probe quantity of `rom` against `full`, at the Newton tolerance `tol` of a
    /// model of length scale `length`.
    pub(crate) fn all(full: &SimulationResult, rom: &SimulationResult, tol: f64, length: f64) -> Vec<Self> {
        quantities::readings(full)
            .iter()
            .zip(quantities::readings(rom))
            .map(|(f, r)| Self::of(f.probe, f.quantity, f.values, r.values, f.quantity.resolution(tol, length)))
            .collect()
    }

    /// With its estimate from `e` (matched by probe and quantity).
    fn with_estimate(mut self, e: &Estimate) -> Self {
        (self.estimate, self.effectivity) = estimate_for(e, &self.probe, self.quantity, self.relative);
        self
    }

    /// Whether the estimate covers the error (an undefined error is covered; a missing
    /// estimate is not).
    pub fn covered(&self) -> bool {
        match (self.relative, self.estimate) {
            (None, _) => true,
            (Some(r), Some(e)) => e >= r,
            (Some(_), None) => false,
        }
    }
}

/// A joint's reaction on one node — its force (both components) or its moment — of the
/// reduced run against the full run's, relative to the full run's range over the run
/// (`crate::rom::reactions`; as [`ProbeQuantityError`] for the probes), with its estimate.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ReactionError {
    /// the reaction point, "joint 0 (clamp arm node 0) on arm node 0"
    pub reaction: String,
    /// `"force"` (N) or `"moment"` (N m)
    pub quantity: Quantity,
    /// `max_k ‖v_rom(t_k) − v_full(t_k)‖`
    pub max_error: f64,
    /// the full run's range, `‖max_k v_full − min_k v_full‖`
    pub range: f64,
    /// `max_error / range`; none where the full run's range is within the reaction's
    /// resolution (`ReactionReader::resolution`) and so is the error
    pub relative: Option<f64>,
    /// the estimate of `relative` (none: no estimator, or no swing to measure against)
    pub estimate: Option<f64>,
    /// `estimate / relative`
    pub effectivity: Option<f64>,
}

impl ReactionError {
    /// Every joint's force and moment of `rom` against `full`, where both runs carry
    /// coordinates and multipliers (a variant that computes none, or a sweep that kept no
    /// coordinates, gives none).
    pub(crate) fn all(model: &Model, full: &SimulationResult, rom: &SimulationResult) -> Vec<Self> {
        let reader = ReactionReader::new(model);
        let (Some(f), Some(r)) = (reader.of_result(full), reader.of_result(rom)) else { return Vec::new() };
        let tol = full.settings.params.tolerance;
        f.iter()
            .zip(&r)
            .map(|(f, r)| {
                let apart = reader.apart(r, f, tol);
                ReactionError {
                    reaction: f.point.clone(),
                    quantity: f.quantity,
                    max_error: apart.distance,
                    range: apart.range,
                    relative: (!apart.relative.is_nan()).then_some(apart.relative),
                    estimate: None,
                    effectivity: None,
                }
            })
            .collect()
    }

    /// With its estimate from `e` (matched by reaction point and quantity).
    fn with_estimate(mut self, e: &Estimate) -> Self {
        (self.estimate, self.effectivity) = estimate_for(e, &self.reaction, self.quantity, self.relative);
        self
    }
}

/// The estimate `e` gives `quantity` of `name` (a probe or a reaction point) and its
/// effectivity against the error `relative`; none where `e` has none (NaN: nothing moved to
/// measure against).
fn estimate_for(e: &Estimate, name: &str, quantity: Quantity, relative: Option<f64>) -> (Option<f64>, Option<f64>) {
    let found = e.quantities.iter().find(|q| q.probe == name && q.quantity == quantity);
    let estimate = found.map(|q| q.estimate).filter(|x| !x.is_nan());
    (estimate, estimate.zip(relative).map(|(e, r)| e / r))
}

/// Why a displacement_error is not a number, in words: NaN where the full run does not move
/// beyond the Newton tolerance (‖X_full − X₀‖ is zero to it: the ratio is 0/0, at λ = 0
/// for a model whose loads all scale with λ), ∞ where only the reduced run moves; `None`
/// for a number.
pub fn displacement_note(e: f64) -> Option<&'static str> {
    if e.is_nan() {
        Some("none (the full run does not move beyond the Newton tolerance: nothing to measure against)")
    } else if e.is_infinite() {
        Some("∞ (the reduced run moves where the full one does not beyond the Newton tolerance)")
    } else {
        None
    }
}

impl Validation {
    /// With each probe quantity's estimate from `e`.
    pub fn with_quantity_estimates(mut self, e: &Estimate) -> Self {
        let errors = std::mem::take(&mut self.probe_quantity_errors);
        self.probe_quantity_errors = errors.into_iter().map(|q| q.with_estimate(e)).collect();
        let errors = std::mem::take(&mut self.reaction_errors);
        self.reaction_errors = errors.into_iter().map(|q| q.with_estimate(e)).collect();
        self
    }

    /// The estimate of the error in `measure` (`None` without an estimator).
    pub fn estimate_in(&self, measure: crate::rom::estimator::ErrorMeasure) -> Option<f64> {
        match measure {
            crate::rom::estimator::ErrorMeasure::Relative => self.error_estimate,
            crate::rom::estimator::ErrorMeasure::Displacement => self.error_estimate_displacement,
        }
    }

    /// This validation's reduced answer at `mu` as the warnings after it read it
    /// ([`crate::rom::Rom::warnings_after`]).
    pub fn answered<'a>(&'a self, rom: &Rom, mu: &'a Parameters) -> crate::rom::warnings::Answered<'a> {
        use crate::rom::warnings::reading;
        let probes = self.probe_quantity_errors.iter().map(|q| (reading(q.quantity.name(), &q.probe), q.estimate));
        let reactions = self.reaction_errors.iter().map(|q| (reading(q.quantity.name(), &q.reaction), q.estimate));
        crate::rom::warnings::Answered {
            mu,
            estimate: self.estimate_in(rom.tolerance_measure()),
            failure: self.estimate_failure.as_deref(),
            quantities: probes.chain(reactions).filter_map(|(name, e)| Some((name, e?))).collect(),
        }
    }

    /// The time loops' seconds and the speedups derived from them (against the dense run
    /// too, when it was timed).
    pub fn with_timings(mut self, full_seconds: f64, rom_seconds: f64) -> Self {
        self.full_seconds = full_seconds;
        self.rom_seconds = rom_seconds;
        self.with_speedups()
    }

    /// The speedups, from the seconds measured so far (the estimate's once it is known).
    fn with_speedups(mut self) -> Self {
        self.speedup = self.full_seconds / self.rom_seconds;
        self.speedup_vs_dense = self.full_dense_seconds.map(|d| d / self.rom_seconds);
        self.speedup_with_estimate = self.estimate_seconds.map(|e| self.full_seconds / (self.rom_seconds + e));
        self
    }

    /// Adds the estimate and, for a reduced model read from its basis file, the
    /// extrapolation flag and training range of a run.
    pub fn with_trust(mut self, estimate: Option<&Estimate>, rom: Option<&Rom>) -> Self {
        if let Some(e) = estimate {
            self.error_estimate = Some(e.error_estimate);
            self.effectivity = Some(e.error_estimate / self.rel_error);
            self.estimate_calibrated = Some(e.calibrated);
            self.estimate_seconds = Some(e.seconds);
            self.error_estimate_by_time = Some(e.by_time.to_vec());
            self.error_estimate_displacement = Some(e.error_estimate_displacement);
            self.effectivity_displacement = Some(e.error_estimate_displacement / self.displacement_error);
            self.error_estimate_displacement_by_time = Some(e.displacement_by_time.to_vec());
            self.estimate_failure = e.failure.clone();
            self = self.with_quantity_estimates(e);
        }
        if let Some((rom, t)) = rom.and_then(|r| Some((r, r.trust()?))) {
            let mu = self.mu();
            self.extrapolated = rom.is_extrapolated(&mu);
            self.training_range = Some([t.range.0, t.range.1]);
            self.training_box = Some(t.space.describe()).filter(|_| !t.space.is_empty());
            self.sensitivity_near = t.sensitivity.as_ref().and_then(|s| s.near(&mu));
            let in_measure = estimate.map(|e| e.in_measure(t.measure));
            self.amplifying = t.amplifying_near(&mu, in_measure).is_some();
        }
        if estimate.is_some() {
            self.error_estimate_method = rom.and_then(|r| r.method()).map(str::to_string);
        }
        self.with_speedups()
    }
}

impl Validation {
    /// The parameters of the run (from `parameters`).
    pub fn mu(&self) -> Parameters {
        self.parameters.iter().fold(Parameters::default(), |mu, (n, &v)| mu.with(n, v))
    }
}

impl Validation {
    /// A few human-readable lines.
    pub fn describe(&self) -> String {
        let dense = match (self.full_dense_seconds, self.speedup_vs_dense) {
            (Some(d), Some(s)) => format!("; full dense LU {:.4} s, speedup vs dense {:.2}×", d, s),
            _ => String::new(),
        };
        format!(
            "load scale {}{}: {} reduction, {} of {} coordinates\n  rel_error {:.3e}, max probe error {:.3e} m ({} at t = {:.4} s), max constraint violation {:.3e}\n  full {:.4} s, reduced {:.4} s, speedup {:.2}×{}{}{}",
            self.load_scale,
            self.parameters
                .iter()
                .filter(|(n, _)| n.as_str() != crate::solver::parameters::LOAD_SCALE)
                .map(|(n, v)| format!(", {n} = {}", crate::error::show_number(*v)))
                .collect::<String>(),
            self.variant,
            self.n_modes,
            self.n_dof,
            self.rel_error,
            self.max_probe_error,
            self.max_probe_error_probe,
            self.max_probe_error_t,
            self.max_constraint_violation,
            self.full_seconds,
            self.rom_seconds,
            self.speedup,
            dense,
            slower_line(self.speedup, self.speedup_with_estimate),
            self.trust_lines()
        )
    }

    /// The estimate, extrapolation, sensitivity and error-by-time lines of `describe`.
    fn trust_lines(&self) -> String {
        let mut s = String::new();
        match (self.error_estimate, self.effectivity) {
            (Some(e), Some(f)) => s.push_str(&format!(
                "\n  error_estimate {:.3e} ({}{}), effectivity {:.2}{}",
                e,
                if self.estimate_calibrated == Some(true) { "calibrated" } else { "uncalibrated" },
                self.error_estimate_method.as_ref().map_or(String::new(), |m| format!(", {m} method")),
                f,
                self.estimate_seconds.zip(self.speedup_with_estimate).map_or(String::new(), |(t, s)| format!(
                    ", estimator {:.4} s ({:.0} % of the reduced run; speedup with it {s:.2}×)",
                    t,
                    100.0 * t / self.rom_seconds,
                ))
            )),
            _ => s.push_str("\n  error_estimate: none (the basis file has no /estimator; train again)"),
        }
        let out = if self.extrapolated { ": EXTRAPOLATED" } else { "" };
        match (&self.training_box, self.training_range) {
            (Some(b), _) => s.push_str(&format!("\n  training box {b}{out}")),
            (None, Some([a, b])) => s.push_str(&format!("\n  training range [{a}, {b}]{out}")),
            (None, None) => {}
        }
        if let Some(x) = self.sensitivity {
            let runs = if self.training_box.is_some() {
                "full runs here and with every parameter of the box times 1.001"
            } else {
                "full runs at λ and 1.001 λ"
            };
            s.push_str(&format!("\n  sensitivity {x:.3e} ({runs})"));
        }
        if self.amplifying {
            let x = self.sensitivity_near.into_iter().chain(self.sensitivity).fold(f64::NAN, f64::max);
            let load = if self.training_box.is_some() { "the parameters" } else { "the load" };
            s.push_str(&format!(
                "\n  the model amplifies changes of {load} here (sensitivity up to {x:.1e}, training's beside it \
                 and the full runs here): the estimate does not see errors up to that size"
            ));
        }
        if let Some(t) = self.steps_differ_from {
            let list = |v: &[f64]| {
                if v.is_empty() {
                    "none".to_string()
                } else {
                    let at: Vec<String> = v.iter().map(|t| format!("{t:.4}")).collect();
                    format!("t = {} s", at.join(", "))
                }
            };
            s.push_str(&format!(
                "\n  the runs halved different steps (full: {}; reduced: {}): from t = {t:.4} s they solve \
                 different time discretizations, and rel_error after it holds their difference as well as \
                 the reduction's (docs/benchmarks.md, \"Halved steps\")",
                list(&self.full_step_cut_times),
                list(&self.rom_step_cut_times),
            ));
        }
        let by: Vec<String> = self.rel_error_by_time.iter().map(|e| format!("{e:.2e}")).collect();
        s.push_str(&format!(
            "\n  rel_error up to each fifth of the run (each over the motion so far, so it can fall): {}",
            by.join(", ")
        ));
        if let Some(e) = &self.error_estimate_by_time {
            let by: Vec<String> = e.iter().map(|e| format!("{e:.2e}")).collect();
            s.push_str(&format!("\n  error_estimate up to each fifth of the run: {}", by.join(", ")));
        }
        s.push_str(&self.motion_lines());
        s
    }

    /// The lines of the errors against the motion: displacement_error (and its estimate),
    /// each probe's error over its travel.
    fn motion_lines(&self) -> String {
        let mut s = match displacement_note(self.displacement_error) {
            Some(why) => format!("\n  displacement_error: {why}"),
            None => format!(
                "\n  displacement_error {:.3e} (against the motion from the initial configuration)",
                self.displacement_error
            ),
        };
        // (no effectivity against an undefined or infinite error)
        if let (Some(e), Some(f), true) = (
            self.error_estimate_displacement,
            self.effectivity_displacement,
            self.displacement_error.is_finite() && self.error_estimate_displacement.is_some_and(|e| !e.is_nan()),
        ) {
            s.push_str(&format!(", error_estimate_displacement {e:.3e}, effectivity {f:.2}"));
        }
        for p in &self.probe_errors_over_travel {
            s.push_str(&format!(
                "\n  probe {}: max error {:.3e} m over a travel of {:.3e} m: {}",
                p.probe,
                p.max_error,
                p.travel,
                p.error_over_travel.map_or("the probe does not move (beyond the Newton tolerance)".to_string(), |e| {
                    format!("{e:.3e} of its travel")
                })
            ));
        }
        // a reaction the joint never carries (a pin's moment) is 0 in both runs: no line
        for q in self.reaction_errors.iter().filter(|q| q.range != 0.0 || q.max_error != 0.0) {
            let unit = q.quantity.unit();
            let estimate = match (q.estimate, q.effectivity) {
                (Some(e), Some(f)) => format!(", estimate {e:.3e} (effectivity {f:.2})"),
                (Some(e), None) => format!(", estimate {e:.3e}"),
                (None, _) if q.relative.is_some() => " (not estimated)".to_string(),
                (None, _) => String::new(),
            };
            s.push_str(&format!(
                "\n  {} {}: max error {:.3e}{unit} over a range of {:.3e}{unit}: {}{estimate}",
                q.reaction,
                q.quantity.name(),
                q.max_error,
                q.range,
                q.relative.map_or("none (it stays within the Newton tolerance)".to_string(), |e| {
                    format!("{e:.3e} of its range")
                }),
            ));
        }
        for q in &self.probe_quantity_errors {
            let unit = q.quantity.unit();
            let estimate = q.estimate.map_or(String::new(), |e| {
                format!(
                    ", estimate {e:.3e}{}",
                    q.effectivity.map_or(String::new(), |f| format!(" (effectivity {f:.2})"))
                )
            });
            s.push_str(&format!(
                "\n  probe {} {}: max error {:.3e}{unit} over a range of {:.3e}{unit}: {}{estimate}",
                q.probe,
                q.quantity.name(),
                q.max_error,
                q.range,
                q.relative.map_or("none (it stays within the Newton tolerance)".to_string(), |e| {
                    format!("{e:.3e} of its range")
                }),
            ));
        }
        s
    }
}

/// The line `validate` adds where the route `online` and `sweep` take — the reduced run
/// with its estimate, or without one where the basis has none — is not faster than the
/// full run (`speedup`, `speedup_with_estimate`: full time over reduced), else nothing.
fn slower_line(speedup: f64, speedup_with_estimate: Option<f64>) -> String {
    let (ratio, what) = match speedup_with_estimate {
        Some(s) => (s, "the reduced run with its estimate"),
        None => (speedup, "the reduced run"),
    };
    if ratio >= 1.0 {
        return String::new();
    }
    format!(
        "\n  {what} is not faster than the full run here ({ratio:.2}×): the full model is exact, \
         `flexrom sweep --full` runs it at every load (docs/basis-and-sweep.md)"
    )
}

#[cfg(test)]
mod tests {
    use super::{slower_line, ProbeQuantityError, ProbeTravel, Quantity};

    /// The slower-route line: only below 1×, judged on the route with the estimate where
    /// there is one (a reduced run 1.36× faster that its estimate brings to 0.9× is slower).
    #[test]
    fn the_slower_route_is_named_only_where_it_is_slower() {
        assert_eq!(slower_line(1.36, Some(1.14)), "");
        assert_eq!(slower_line(2.0, None), "");
        let l = slower_line(1.36, Some(0.9));
        assert!(
            l.contains("with its estimate is not faster") && l.contains("(0.90×)") && l.contains("sweep --full"),
            "{l}"
        );
        assert!(slower_line(0.63, None).contains("the reduced run is not faster than the full run here (0.63×)"));
    }

    /// A probe moving on a 3-4-5 line, 0.5 m per instant over 4 instants (travel 1.5 m),
    /// against a reduced one off by (0.006, 0.008) m (0.01 m) at one instant: error over
    /// travel 0.01 / 1.5 in closed form; a probe that does not move has none.
    #[test]
    fn a_probe_error_over_its_travel() {
        let full = ndarray::Array2::from_shape_fn((4, 2), |(k, i)| 1.0 + k as f64 * [0.3, 0.4][i]);
        let mut rom = full.clone();
        rom[[2, 0]] += 0.006;
        rom[[2, 1]] += 0.008;
        let p = ProbeTravel::of("tip", &full, &rom, 1e-10);
        assert!((p.travel - 1.5).abs() < 1e-15 && (p.max_error - 0.01).abs() < 1e-15, "{p:?}");
        assert!((p.error_over_travel.unwrap() - 0.01 / 1.5).abs() < 1e-15, "{p:?}");
        let still = ndarray::Array2::from_elem((4, 2), 1.0);
        assert_eq!(ProbeTravel::of("pin", &still, &still, 1e-10).error_over_travel, None);
        // nor one that moved within the resolution; where the reduced one moved: ∞
        let mut crawl = still.clone();
        crawl[[3, 0]] += 1e-11;
        assert_eq!(ProbeTravel::of("pin", &crawl, &(&still + 2e-11), 1e-10).error_over_travel, None);
        assert_eq!(ProbeTravel::of("pin", &crawl, &(&still + 1e-3), 1e-10).error_over_travel, Some(f64::INFINITY));
    }

    /// A curvature series against a reduced one off by 0.02 and 0.03 at two instants: the
    /// largest error 0.03 over the full run's range 0.5 − (−1.0) = 1.5, i.e. 0.02 (closed
    /// form); a series that stays at zero has none, or ∞ where only the reduced one leaves it.
    #[test]
    fn a_probe_quantity_against_its_range() {
        let col = |v: ndarray::Array1<f64>| v.insert_axis(ndarray::Axis(1));
        let full = col(ndarray::array![0.0, 0.5, -1.0, 0.25]);
        let rom = col(ndarray::array![0.0, 0.52, -0.97, 0.25]);
        let q = ProbeQuantityError::of("root", Quantity::Curvature, full.view(), rom.view(), 1e-10);
        assert!((q.max_error - 0.03).abs() < 1e-15 && q.largest == 1.0 && q.range == 1.5, "{q:?}");
        assert!((q.relative.unwrap() - 0.02).abs() < 1e-15, "{q:?}");
        let zero = ndarray::Array2::zeros((4, 1));
        assert_eq!(ProbeQuantityError::of("tip", Quantity::Strain, zero.view(), zero.view(), 1e-10).relative, None);
        let off = ProbeQuantityError::of("tip", Quantity::Strain, zero.view(), (&zero + 1e-3).view(), 1e-10);
        assert_eq!(off.relative, Some(f64::INFINITY));
    }
}
