//! The cheap error estimator (`estimate = "coarse"`, docs/error-estimate.md): the corrected
//! step of [`super::estimate_corrected`] taken only every `m`-th step of the reduced run,
//! over the step `m·Δt`, by both the enriched model and the reduced model itself.
//!
//! The corrected estimator costs one enriched matrix and factorization per step of the
//! reduced run (≈ 100 % of the reduced run on the pendulum). At the step `H = m·Δt` it
//! costs `1/m` of that, but the coarse trajectory `X⁺_H` carries generalized-α's error at
//! `H`, `D⁺`, which can be far larger than the reduced model's error it should measure.
//! The reduced model, corrected in the same way along its own run at the same `H`, carries
//! nearly the same discretisation error `D^r ≈ D⁺` (the two models solve the same equations
//! in nested spaces), so in the difference it cancels:
//!
//! ```text
//!     X⁺_H ≈ X⁺ + D⁺,   X^r_H ≈ X_r + D^r,
//!     η_raw = ‖X^r_H − X⁺_H‖_F / ‖X⁺_H‖_F  ≈  ‖X_r − X⁺‖_F / ‖X⁺‖_F     (instants 0, m, 2m, …)
//! ```
//!
//! Both coarse runs start from the same state as the reduced run and take, per coarse
//! step, the reduced run's increment over the `m` steps (lifted by `V⁺ᵀV`, resp. as it is)
//! as the predictor and one Newton iteration with a fresh matrix. The reduced model's
//! coarse run costs one reduced matrix per coarse step (smaller than the enriched one).
//! `m` is [`COARSE_STRIDE`], lowered so that the run keeps at least [`MIN_COARSE_STEPS`]
//! coarse steps: both are fixed numbers, not fitted to a model.

use super::estimate_corrected::CorrectedRunner;
use super::online::ReducedRun;
use crate::error::Result;
use crate::model::Model;
use crate::reduction::Basis;
use ndarray::{s, Array2};

/// `m`: reduced-run steps per coarse step.
pub const COARSE_STRIDE: usize = 8;
/// The fewest coarse steps a run is estimated with (short runs take a smaller `m`).
pub const MIN_COARSE_STEPS: usize = 16;

/// The stride for a run of `steps` steps: [`COARSE_STRIDE`], at most `steps / MIN_COARSE_STEPS`, at least 1.
pub fn stride_for(steps: usize, stride: usize) -> usize {
    stride.min(steps / MIN_COARSE_STEPS).max(1)
}

/// The enriched and the reduced model, corrected at the coarse step along reduced runs.
pub struct CoarseRunner<'a> {
    plus: CorrectedRunner<'a>,
    /// the reduced model's own coarse run; `None`: compare with the reduced run itself at
    /// the coarse instants (no cancellation; an experiment, `set_cancel(false)`)
    own: Option<CorrectedRunner<'a>>,
    stride: usize,
}

impl<'a> CoarseRunner<'a> {
    /// `None` where [`CorrectedRunner::new`] is not available for either model.
    pub fn new(model: &'a Model, basis: &'a Basis, enriched: &'a Basis) -> Result<Option<Self>> {
        let Some(plus) = CorrectedRunner::new(model, basis, enriched)? else { return Ok(None) };
        let Some(own) = CorrectedRunner::new(model, basis, basis)? else { return Ok(None) };
        Ok(Some(CoarseRunner { plus, own: Some(own), stride: COARSE_STRIDE }))
    }

    /// Experiments (examples/estimate_table.rs): another `m`; without the reduced model's
    /// coarse run (`cancel = false`).
    pub fn configure(&mut self, stride: usize, cancel: bool) {
        self.stride = stride.max(1);
        if !cancel {
            self.own = None;
        }
    }

    /// `(q^r_H, q⁺_H)`: the reduced (r × n_H) and enriched (r⁺ × n_H) coordinates at the
    /// instants `0, m, 2m, …` of `run`, for [`super::estimate::raw_estimate_by_time`].
    pub fn run(&mut self, run: &ReducedRun) -> Result<(Array2<f64>, Array2<f64>)> {
        let m = stride_for(run.reduced_q.ncols().saturating_sub(1), self.stride);
        let qp = self.plus.run_strided(run, m)?;
        let q = match &mut self.own {
            Some(own) => own.run_strided(run, m)?,
            None => run.reduced_q.slice(s![.., ..;m]).to_owned(),
        };
        Ok((q, qp))
    }
}
