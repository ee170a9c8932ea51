//! `validate`: the reduced model against the full one at the same load scale and Δt.
//!
//! ```text
//!     rel_error = ‖X_rom − X_full‖_F / ‖X_full‖_F      (all coordinates, all instants)
//!     max_probe_error = max_{probe, k} |r_rom(t_k) − r_full(t_k)|
//!     max_constraint_violation = max_k ‖B x_rom(t_k) − b‖∞
//! ```

use super::online::{run_reduced, ReducedRun};
use crate::error::Result;
use crate::model::Model;
use crate::reduction::Basis;
use crate::simulate::{simulate, Overrides, SimulationResult};
use crate::solver::kkt::LinearSolverKind;
use crate::solver::model::DynamicModel;

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
    /// full model, our default (banded) linear solver: time loop only
    pub full_seconds: f64,
    /// full model with dense LAPACK LU; `None` when not measured
    pub full_dense_seconds: Option<f64>,
    /// reduced time loop, basis loaded and projected beforehand
    pub rom_seconds: f64,
    pub speedup: f64,
    pub speedup_vs_dense: Option<f64>,
    pub full_newton_iterations: usize,
    pub rom_newton_iterations: usize,
    pub rom_step_cuts: usize,
}

/// Compares a reduced run with a full run of the same model, load scale and Δt.
pub fn compare(model: &Model, full: &SimulationResult, rom: &ReducedRun, dense_seconds: Option<f64>, n_modes: usize, variant: &str) -> Validation {
    let r = &rom.result;
    let diff = (&r.q - &full.q).mapv(|v| v * v).sum().sqrt();
    let norm = full.q.mapv(|v| v * v).sum().sqrt();
    let (mut pe, mut pe_name, mut pe_t) = (0.0_f64, String::new(), 0.0);
    for ((name, a), (_, b)) in full.probes.iter().zip(&r.probes) {
        for k in 0..a.nrows() {
            let d = ((a[[k, 0]] - b[[k, 0]]).powi(2) + (a[[k, 1]] - b[[k, 1]]).powi(2)).sqrt();
            if d > pe {
                (pe, pe_name, pe_t) = (d, name.clone(), full.t[k]);
            }
        }
    }
    let sys = model.system(LinearSolverKind::Banded);
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
        full_seconds: full.wall_seconds,
        full_dense_seconds: dense_seconds,
        rom_seconds: r.wall_seconds,
        speedup: full.wall_seconds / r.wall_seconds,
        speedup_vs_dense: dense_seconds.map(|d| d / r.wall_seconds),
        full_newton_iterations: full.stats.newton_iterations,
        rom_newton_iterations: r.stats.newton_iterations,
        rom_step_cuts: r.stats.step_cuts,
    }
}

/// Runs full (banded, and dense LU when `with_dense`) and reduced at `load_scale`.
pub fn validate(model: &Model, basis: &Basis, load_scale: f64, with_dense: bool) -> Result<(Validation, SimulationResult, ReducedRun)> {
    let o = Overrides { load_scale: Some(load_scale), ..Default::default() };
    let stage = |what: &'static str| move |e: crate::Error| e.at_stage(what, load_scale);
    let full = simulate(model, &o).map_err(stage("validate (full run)"))?;
    let dense = if with_dense {
        Some(simulate(model, &Overrides { solver: LinearSolverKind::Dense, ..o }).map_err(stage("validate (dense full run)"))?.wall_seconds)
    } else {
        None
    };
    let rom = run_reduced(model, basis, load_scale).map_err(stage("validate (reduced run)"))?;
    let v = compare(model, &full, &rom, dense, basis.n_reduced(), basis.variant.name());
    Ok((v, full, rom))
}

impl Validation {
    /// A few human-readable lines.
    pub fn describe(&self) -> String {
        let dense = match (self.full_dense_seconds, self.speedup_vs_dense) {
            (Some(d), Some(s)) => format!("; full dense LU {:.4} s, speedup vs dense {:.2}×", d, s),
            _ => String::new(),
        };
        format!(
            "load scale {}: {} reduction, {} of {} coordinates\n  rel_error {:.3e}, max probe error {:.3e} m ({} at t = {:.4} s), max constraint violation {:.3e}\n  full {:.4} s, reduced {:.4} s, speedup {:.2}×{}",
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
            dense
        )
    }
}
