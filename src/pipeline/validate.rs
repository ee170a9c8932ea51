//! `validate`: the reduced model against the full one at the same load scale and Δt.
//!
//! ```text
//!     rel_error = ‖X_rom − X_full‖_F / ‖X_full‖_F      (all coordinates, all instants)
//!     max_probe_error = max_{probe, k} |r_rom(t_k) − r_full(t_k)|
//!     max_constraint_violation = max_k ‖B x_rom(t_k) − b‖∞
//!     error_estimate = c ‖X_r − X_{r+k}‖_F / ‖X_{r+k}‖_F   (no full run: crate::rom::estimator)
//!     effectivity = error_estimate / rel_error               (≥ 1: the estimate bounds the error)
//!     sensitivity = ‖X_full(1.001 λ) − X_full(λ)‖_F / ‖X_full(λ)‖_F
//!     rel_error_by_time[i] = rel_error over t ≤ the end of fifth i + 1 of the run
//!     error_estimate_by_time[i] = error_estimate over the same instants (the last is error_estimate)
//! ```
//!
//! `sensitivity` puts the error in context: how much the full model's own answer moves for
//! a 0.1 % change of the load.

use crate::error::Result;
use crate::linalg::kkt::LinearSolverKind;
use crate::model::Model;
use crate::rom::estimator::norms::{distance_and_norm, rel_error_by_time};
use crate::rom::estimator::Estimate;
use crate::rom::{Output, ReducedRun, Rom};
use crate::simulate::{simulate, FullModel, Overrides, SimulationResult};
use crate::solver::model::Parameters;
use crate::solver::model::ParametricModel;

/// The fixed keys of `validate --json`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Validation {
    pub load_scale: f64,
    pub variant: String,
    pub n_dof: usize,
    pub n_modes: usize,
    pub rel_error: f64,
    pub max_probe_error: f64,
    pub max_probe_error_probe: String,
    pub max_probe_error_t: f64,
    pub max_constraint_violation: f64,
    /// full model, our default (banded) linear solver: time loop only, the median of up to
    /// seven runs interleaved with the reduced ones (`TIMING_BUDGET`)
    pub full_seconds: f64,
    /// full model with dense LAPACK LU; `None` when not measured
    pub full_dense_seconds: Option<f64>,
    /// reduced time loop, basis loaded and projected beforehand (median, as `full_seconds`)
    pub rom_seconds: f64,
    pub speedup: f64,
    pub speedup_vs_dense: Option<f64>,
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
    /// `[min, max]` training load scale (null when unknown)
    pub training_range: Option<[f64; 2]>,
    /// relative difference of full runs at λ and 1.001 λ (null when not measured)
    pub sensitivity: Option<f64>,
    /// rel_error up to the end of each fifth of the run (the last is rel_error)
    pub rel_error_by_time: Vec<f64>,
    /// error_estimate up to the end of each fifth of the run, the estimate of
    /// `rel_error_by_time` (the last is error_estimate; null: no estimator)
    pub error_estimate_by_time: Option<Vec<f64>>,
}

/// Compares a reduced run with a full run of the same model, load scale and Δt.
pub fn compare(
    model: &Model,
    full: &SimulationResult,
    rom: &ReducedRun,
    dense_seconds: Option<f64>,
    n_modes: usize,
    variant: &str,
) -> Validation {
    let r = &rom.result;
    let (diff, norm) = distance_and_norm(&r.q, &full.q);
    let (mut pe, mut pe_name, mut pe_t) = (0.0_f64, String::new(), 0.0);
    for ((name, a), (_, b)) in full.probes.iter().zip(&r.probes) {
        for k in 0..a.nrows() {
            let d = ((a[[k, 0]] - b[[k, 0]]).powi(2) + (a[[k, 1]] - b[[k, 1]]).powi(2)).sqrt();
            if d > pe {
                (pe, pe_name, pe_t) = (d, name.clone(), full.t[k]);
            }
        }
    }
    let owned;
    let sys = match model.physics() {
        Ok(ph) => &*ph.sys,
        Err(_) => {
            owned = model.system(LinearSolverKind::Banded);
            &owned
        }
    };
    let mut res = vec![0.0; sys.n_constraints()];
    let mut viol = 0.0_f64;
    for k in 0..r.q.ncols() {
        sys.constraint_residual(&r.q.column(k).to_vec(), &mut res);
        viol = res.iter().fold(viol, |m, v| m.max(v.abs()));
    }
    Validation {
        load_scale: r.settings.load_scale,
        variant: variant.to_string(),
        n_dof: full.q.nrows(),
        n_modes,
        rel_error: diff / norm,
        max_probe_error: pe,
        max_probe_error_probe: pe_name,
        max_probe_error_t: pe_t,
        max_constraint_violation: viol,
        // set by with_timings below
        full_seconds: f64::NAN,
        full_dense_seconds: dense_seconds,
        rom_seconds: f64::NAN,
        speedup: f64::NAN,
        speedup_vs_dense: None,
        full_newton_iterations: full.stats.newton_iterations,
        rom_newton_iterations: r.stats.newton_iterations,
        rom_step_cuts: r.stats.step_cuts,
        full_step_cuts: full.stats.step_cuts,
        steps_differ_from: first_different_step(&full.stats.step_cut_times, &r.stats.step_cut_times),
        full_step_cut_times: full.stats.step_cut_times.clone(),
        rom_step_cut_times: r.stats.step_cut_times.clone(),
        error_estimate: None,
        effectivity: None,
        estimate_calibrated: None,
        estimate_seconds: None,
        extrapolated: false,
        training_range: None,
        sensitivity: None,
        rel_error_by_time: rel_error_by_time(&r.q, &full.q).to_vec(),
        error_estimate_by_time: None,
    }
    .with_timings(full.wall_seconds, r.wall_seconds)
}

/// The earliest start of a step that one run halved and the other did not, from the two
/// runs' lists of halved steps (`None`: both took the same steps).
fn first_different_step(a: &[f64], b: &[f64]) -> Option<f64> {
    // both lists hold starts of the same regular grid, computed alike: equal to round-off
    let only = |x: &[f64], y: &[f64]| x.iter().copied().find(|t| !y.iter().any(|u| (u - t).abs() < 1e-9));
    match (only(a, b), only(b, a)) {
        (Some(x), Some(y)) => Some(x.min(y)),
        (x, y) => x.or(y),
    }
}

/// Time loops of a few milliseconds move by ±30 % from one run to the next on a shared
/// machine (other processes, page faults of a first run), so `validate` times the full and
/// the reduced loop repeatedly, interleaved (a busy spell falls on both), and compares
/// medians: while both kinds together have taken less than this, s…
const TIMING_BUDGET: f64 = 0.25;
/// …and each kind has fewer runs than this (odd: the median is a run). A full run that
/// alone exceeds the budget is timed once, as before.
const TIMING_RUNS: usize = 7;

/// Whether to time one more pair of runs ([`TIMING_BUDGET`], [`TIMING_RUNS`]).
fn repeat_timing(full: &[f64], rom: &[f64]) -> bool {
    let spent: f64 = full.iter().chain(rom).sum();
    full.len() < TIMING_RUNS && spent + full[full.len() - 1] + rom[rom.len() - 1] <= TIMING_BUDGET
}

/// The median (the middle of an odd count, the mean of the middle two of an even one).
fn median(x: &mut [f64]) -> f64 {
    x.sort_by(f64::total_cmp);
    let n = x.len();
    if n % 2 == 1 {
        x[n / 2]
    } else {
        0.5 * (x[n / 2 - 1] + x[n / 2])
    }
}

impl Validation {
    /// The time loops' seconds and the speedups derived from them (against the dense run
    /// too, when it was timed).
    pub fn with_timings(mut self, full_seconds: f64, rom_seconds: f64) -> Self {
        self.full_seconds = full_seconds;
        self.rom_seconds = rom_seconds;
        self.speedup = full_seconds / rom_seconds;
        self.speedup_vs_dense = self.full_dense_seconds.map(|d| d / rom_seconds);
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
        }
        if let Some(t) = rom.and_then(|r| r.trust()) {
            self.extrapolated = crate::rom::trust::is_extrapolated(t.range, self.load_scale);
            self.training_range = Some([t.range.0, t.range.1]);
        }
        self
    }
}

/// Runs full (banded, and dense LU when `with_dense`) and reduced at `load_scale`, with the
/// reduced model's estimate (when it has an estimator), its training range (when read from
/// a basis file), and the full model's sensitivity (one more full run at 1.001 λ).
pub fn validate(rom: &Rom, load_scale: f64, with_dense: bool) -> Result<(Validation, SimulationResult, ReducedRun)> {
    let (model, basis) = (&**rom.model(), &**rom.basis());
    let mu = Parameters::new(load_scale);
    let o = Overrides { load_scale: Some(load_scale), ..Default::default() };
    let stage = |what: &'static str| move |e: crate::Error| e.at_stage(what, load_scale);
    // the full model assembled once for the run at λ and the sensitivity run at 1.001 λ
    let mut full_model = FullModel::new(model, LinearSolverKind::Banded).map_err(stage("validate (full run)"))?;
    let full = full_model.simulate(&o).map_err(stage("validate (full run)"))?;
    let dense = if with_dense {
        Some(
            simulate(model, &Overrides { solver: LinearSolverKind::Dense, ..o.clone() })
                .map_err(stage("validate (dense full run)"))?
                .wall_seconds,
        )
    } else {
        None
    };
    let nearby = full_model
        .simulate(&Overrides { load_scale: Some(1.001 * load_scale), ..o })
        .map_err(stage("validate (full run at 1.001 λ)"))?;
    let (run, estimate) = rom.solve_and_estimate(&mu, Output::Full, &[]).map_err(stage("validate (reduced run)"))?;
    // the time loops again, interleaved, for the medians that `speedup` compares
    let (mut full_times, mut rom_times) = (vec![full.wall_seconds], vec![run.result.wall_seconds]);
    while repeat_timing(&full_times, &rom_times) {
        full_times.push(full_model.simulate(&o).map_err(stage("validate (full run)"))?.wall_seconds);
        let again = rom.solve_with(&mu, Output::Full, &[]).map_err(stage("validate (reduced run)"))?;
        rom_times.push(again.result.wall_seconds);
    }
    let mut v = compare(model, &full, &run, dense, basis.n_reduced(), basis.variant.name())
        .with_trust(estimate.as_ref(), Some(rom))
        .with_timings(median(&mut full_times), median(&mut rom_times));
    let (distance, norm) = distance_and_norm(&nearby.q, &full.q);
    v.sensitivity = Some(distance / norm);
    Ok((v, full, run))
}

impl Validation {
    /// A few human-readable lines.
    pub fn describe(&self) -> String {
        let dense = match (self.full_dense_seconds, self.speedup_vs_dense) {
            (Some(d), Some(s)) => format!("; full dense LU {:.4} s, speedup vs dense {:.2}×", d, s),
            _ => String::new(),
        };
        format!(
            "load scale {}: {} reduction, {} of {} coordinates\n  rel_error {:.3e}, max probe error {:.3e} m ({} at t = {:.4} s), max constraint violation {:.3e}\n  full {:.4} s, reduced {:.4} s, speedup {:.2}×{}{}",
            self.load_scale,
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
            self.trust_lines()
        )
    }

    /// The estimate, extrapolation, sensitivity and error-by-time lines of `describe`.
    fn trust_lines(&self) -> String {
        let mut s = String::new();
        match (self.error_estimate, self.effectivity) {
            (Some(e), Some(f)) => s.push_str(&format!(
                "\n  error_estimate {:.3e} ({}), effectivity {:.2}{}",
                e,
                if self.estimate_calibrated == Some(true) { "calibrated" } else { "uncalibrated" },
                f,
                self.estimate_seconds.map_or(String::new(), |t| format!(
                    ", estimator {:.4} s ({:.0} % of the reduced run)",
                    t,
                    100.0 * t / self.rom_seconds
                ))
            )),
            _ => s.push_str("\n  error_estimate: none (the basis file has no /estimator; train again)"),
        }
        if let Some([a, b]) = self.training_range {
            s.push_str(&format!(
                "\n  training range [{a}, {b}]{}",
                if self.extrapolated { ": EXTRAPOLATED" } else { "" }
            ));
        }
        if let Some(x) = self.sensitivity {
            s.push_str(&format!("\n  sensitivity {x:.3e} (full runs at λ and 1.001 λ)"));
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
        s.push_str(&format!("\n  rel_error up to each fifth of the run: {}", by.join(", ")));
        if let Some(e) = &self.error_estimate_by_time {
            let by: Vec<String> = e.iter().map(|e| format!("{e:.2e}")).collect();
            s.push_str(&format!("\n  error_estimate up to each fifth of the run: {}", by.join(", ")));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::{first_different_step, median, repeat_timing, TIMING_BUDGET, TIMING_RUNS};

    /// Medians of odd and even counts, in any order; the timing repeats while another pair
    /// fits the budget and stops at the run count, and a single run over the budget is
    /// timed once.
    #[test]
    fn timing_medians_and_their_budget() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(repeat_timing(&[5e-3], &[1e-3]));
        assert!(!repeat_timing(&[5e-3; TIMING_RUNS], &[1e-3; TIMING_RUNS]));
        assert!(!repeat_timing(&[TIMING_BUDGET], &[1e-3]));
        // 0.1 + 0.05 spent, a next pair of 0.15 would exceed 0.25
        assert!(!repeat_timing(&[0.1], &[0.05]));
    }

    /// Which step the runs first took differently: a cut only one of them made, the
    /// earlier of two such, and none when both halved the same steps.
    #[test]
    fn the_first_step_taken_differently() {
        assert_eq!(first_different_step(&[], &[]), None);
        assert_eq!(first_different_step(&[0.875], &[]), Some(0.875));
        assert_eq!(first_different_step(&[], &[0.931]), Some(0.931));
        assert_eq!(first_different_step(&[0.1, 0.875], &[0.1]), Some(0.875));
        assert_eq!(first_different_step(&[0.1, 0.875], &[0.1, 0.875]), None);
        assert_eq!(first_different_step(&[0.931], &[0.5, 0.931]), Some(0.5));
        assert_eq!(first_different_step(&[0.875], &[0.931]), Some(0.875));
    }
}
