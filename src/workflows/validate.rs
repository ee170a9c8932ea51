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
//!     displacement_error = ‖X_rom − X_full‖_F / ‖X_full − X₀‖_F   (X₀ = X_full(t₀) at every instant)
//!     error_estimate_displacement = c ‖X_r − X_{r+k}‖_F / ‖X_{r+k} − X₀‖_F
//!     error_over_travel(probe) = max_k |r_rom(t_k) − r_full(t_k)| / max_k |r_full(t_k) − r_full(t₀)|
//! ```
//!
//! `sensitivity` puts the error in context: how much the full model's own answer moves for
//! a 0.1 % change of the load. `rel_error` divides by a norm that holds the undeformed
//! geometry and the unit slopes; `displacement_error` and a probe's error over its travel
//! measure the error against the motion itself (docs/error-estimate.md, "Two measures of
//! the error").

pub use crate::records::validation::{displacement_note, ProbeQuantityError, ProbeTravel, ReactionError, Validation};

use crate::cost::timing::{median, repeat_timing};
use crate::error::Result;
use crate::linalg::kkt::LinearSolverKind;
use crate::model::Model;
use crate::rom::estimator::norms::{displacement_error_by_time, distance_and_norm, rel_error_by_time};
use crate::rom::{Output, ReducedRun, Rom};
use crate::simulate::{simulate, FullModel, Overrides, SimulationResult};
use crate::solver::model::Parameters;
use crate::solver::model::ParametricModel;

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
    // the coordinates' resolution: the Newton tolerance, in length units
    let resolution = full.settings.params.tolerance * sys.length_scale();
    let travels: Vec<ProbeTravel> = (full.probes.iter().zip(&r.probes))
        .map(|((name, a), (_, b))| ProbeTravel::of(name, a, b, resolution))
        .collect();
    let worst_travel = travels
        .iter()
        .filter_map(|p| p.error_over_travel.map(|e| (e, p.probe.clone())))
        .fold(None::<(f64, String)>, |w, (e, n)| if w.as_ref().is_none_or(|w| e > w.0) { Some((e, n)) } else { w });
    let x0 = full.q.column(0);
    let displacement_error_by_time = displacement_error_by_time(&r.q, &full.q, x0, resolution).to_vec();
    let mut res = vec![0.0; sys.n_constraints()];
    let mut viol = 0.0_f64;
    for k in 0..r.q.ncols() {
        sys.constraint_residual(&r.settings.mu, &r.q.column(k).to_vec(), r.t[k], &mut res);
        viol = res.iter().fold(viol, |m, v| m.max(v.abs()));
    }
    Validation {
        load_scale: r.settings.mu.scale(),
        parameters: r.settings.mu.iter().map(|(n, v)| (n.to_string(), v)).collect(),
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
        speedup_with_estimate: None,
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
        training_box: None,
        sensitivity_near: None,
        amplifying: false,
        rel_error_by_time: rel_error_by_time(&r.q, &full.q).to_vec(),
        error_estimate_by_time: None,
        displacement_error: displacement_error_by_time[displacement_error_by_time.len() - 1],
        displacement_error_note: displacement_note(displacement_error_by_time[displacement_error_by_time.len() - 1])
            .map(str::to_string),
        displacement_error_by_time,
        error_estimate_displacement: None,
        effectivity_displacement: None,
        error_estimate_displacement_by_time: None,
        max_error_over_travel: worst_travel.as_ref().map(|w| w.0),
        max_error_over_travel_probe: worst_travel.map_or(String::new(), |w| w.1),
        probe_errors_over_travel: travels,
        probe_quantity_errors: ProbeQuantityError::all(full, r, full.settings.params.tolerance, sys.length_scale()),
        reaction_errors: ReactionError::all(model, full, r),
        error_estimate_method: None,
        estimate_failure: None,
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

/// Runs full (banded, and dense LU when `with_dense`) and reduced at the parameters `mu`,
/// with the reduced model's estimate (when it has an estimator), its training range (when
/// read from a basis file), and the full model's sensitivity (one more full run at 1.001 λ).
pub fn validate(rom: &Rom, mu: &Parameters, with_dense: bool) -> Result<(Validation, SimulationResult, ReducedRun)> {
    let (model, basis) = (&**rom.model(), &**rom.basis());
    let o = Overrides::at(mu);
    let stage = |what: &'static str| move |e: crate::Error| e.at_stage(what, mu);
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
    // a box's basis: every parameter of the box moves (λ alone on a line)
    let moved = rom.trust().map_or_else(|| mu.scaled_by(1.001), |t| t.space.moved(mu, 1.001));
    let nearby =
        full_model.simulate(&Overrides { mu: Some(moved), ..o }).map_err(stage("validate (full run at 1.001 μ)"))?;
    let (run, estimate) = rom
        .solve_and_estimate(mu, Output::Full, &[])
        .map_err(|e| e.at_reduced_stage("validate (reduced run)", mu, true))?;
    // the time loops again, interleaved, for the medians that `speedup` compares
    let (mut full_times, mut rom_times) = (vec![full.wall_seconds], vec![run.result.wall_seconds]);
    while repeat_timing(&[&full_times, &rom_times]) {
        full_times.push(full_model.simulate(&o).map_err(stage("validate (full run)"))?.wall_seconds);
        let again = rom.solve_with(mu, Output::Full, &[]).map_err(stage("validate (reduced run)"))?;
        rom_times.push(again.result.wall_seconds);
    }
    let mut v = compare(model, &full, &run, dense, basis.n_reduced(), basis.variant.name())
        .with_trust(estimate.as_ref(), Some(rom))
        .with_timings(median(&mut full_times), median(&mut rom_times));
    let (distance, norm) = distance_and_norm(&nearby.q, &full.q);
    let measured = distance / norm;
    v.sensitivity = Some(measured);
    // the full runs here measured the sensitivity itself: it counts as training's beside it does
    if let Some(t) = rom.trust() {
        v.amplifying |= t.amplifies(measured, estimate.as_ref().map(|e| e.in_measure(t.measure)));
    }
    Ok((v, full, run))
}

#[cfg(test)]
mod tests {
    use super::first_different_step;

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
