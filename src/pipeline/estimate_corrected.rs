//! The tight error estimator (`estimate = "corrected"`, docs/error-estimate.md; the online
//! default unless greedy training calibrated the cheap `defects` one reliably): the
//! enriched model's trajectory, not integrated on its own but *corrected from the reduced
//! run's*, one modified-Newton iteration per step.
//!
//! The enriched estimator (`estimate = "enriched"`, [`super::estimate`]) integrates the
//! richer model `V⁺` (`r + k` modes, its own ECSW set) to convergence at every step, which
//! costs about two reduced runs. Here the enriched model takes each step of generalized-α
//! (the same scheme and step as the reduced run) from its own state `q⁺_n`, with the reduced
//! run's increment as the predictor,
//!
//! ```text
//!     q⁺_{n+1}⁽⁰⁾ = q⁺_n + M (q_{n+1} − q_n),          M = V⁺ᵀ V,
//!     q⁺_{n+1}    = q⁺_{n+1}⁽⁰⁾ − S⁺⁻¹ R⁺(q⁺_{n+1}⁽⁰⁾)        (one iteration),
//! ```
//!
//! `R⁺ = V⁺ᵀ R` the enriched model's step residual at its sampled elements and `S⁺` its
//! iteration matrix at the predictor. (A matrix kept over several steps is not enough:
//! with one iteration per step the residual it leaves feeds the velocities and
//! accelerations, and on the pendulum the corrected trajectory diverged within 60–100
//! steps with the matrix refreshed every 2–8 steps.) The correction is the reduced run's *local defect* (how far
//! its step lies from the richer model's step from the same state), and `q⁺_n − M q_n`
//! carries the defects of earlier steps forward through the enriched model's dynamics, so
//! growth of the error in time (and its decay) is the model's own, not a fixed rule. The
//! estimate is then the enriched one's,
//!
//! ```text
//!     η_raw = ‖X_r − X⁺‖_F / ‖X⁺‖_F,       error_estimate = c · η_raw,
//! ```
//!
//! with the same calibration `c`. Cost per step: one residual, one matrix and one
//! factorization of the enriched model, against the reduced run's two to three residuals
//! and one to two factorizations of the smaller one, and no step halvings (measured:
//! docs/error-estimate.md).
//! Why one iteration suffices: the predictor is the reduced run's own converged step, so
//! the correction is of the size of the reduced model's error, and a second iteration
//! changes it by a fraction (the contraction of the kept matrix) of that: a 10–30 %
//! change of an estimate that is read as an order of magnitude.

use super::online::ReducedRun;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::physics::system::FlexibleSystem;
use crate::reduction::{Basis, Hyper, HyperReducedModel};
use crate::simulate::{Overrides, Settings};
use crate::solver::model::{Bound, DynamicModel, IterationCoefficients};
use ndarray::{Array2, ArrayView1};

/// The enriched model, built once, corrected along reduced runs at many load scales.
pub struct CorrectedRunner<'a> {
    model: &'a Model,
    enriched: &'a Basis,
    rom: Box<HyperReducedModel<FlexibleSystem>>,
    /// `M = V⁺ᵀ V` (r⁺ × r)
    lift: Array2<f64>,
    x0: Vec<f64>,
    /// 0: the corrected trajectory; s > 0: the defects at every s-th step ([`Self::defects`])
    sample: usize,
}

impl<'a> CorrectedRunner<'a> {
    /// `None` when the enriched basis needs the generic (non-invariant) reduced model or is
    /// not orthonormal (whole-system): the caller then runs the enriched model itself.
    pub fn new(model: &'a Model, basis: &Basis, enriched: &'a Basis) -> Result<Option<Self>> {
        if basis.variant == crate::reduction::Variant::WholeSystem {
            return Ok(None);
        }
        let physics = model.physics()?;
        let (sys, x0) = (physics.sys.clone(), physics.x0.to_vec());
        if enriched.hyper.is_none() && !HyperReducedModel::<FlexibleSystem>::supports(&sys) {
            return Ok(None);
        }
        let all;
        let h = match &enriched.hyper {
            Some(h) => h,
            None => {
                all = Hyper::all(sys.n_elements());
                &all
            }
        };
        let rom = HyperReducedModel::new(sys, enriched, h)
            .map_err(|e| Error::Usage(format!("cannot build the estimator's reduced model: {e}")))?;
        let lift = enriched.modes.t().dot(&basis.modes);
        Ok(Some(CorrectedRunner { model, enriched, rom: Box::new(rom), lift, x0, sample: 0 }))
    }

    /// The reduced run's local defects against the enriched model at every `sample`-th step
    /// (r⁺ × n_t; columns `sample, 2·sample, …`, the others zero): the enriched model's
    /// first Newton correction `δ_n = −S⁺⁻¹R⁺` of the step to `n` taken from the lifted
    /// reduced state (`M q_{n−1}` and the generalized-α state of the lifted increments) with
    /// the lifted reduced step `M q_n` as predictor. The state is not corrected: every
    /// defect is measured from the reduced run itself. The multipliers start at zero: the
    /// KKT solve's `Δq` does not depend on them (`Bᵀλ` lies in the range `Δq` is orthogonal
    /// to in the solve's metric). Cost: one enriched residual, matrix and factorization per
    /// sampled step, plus O(r⁺ r) per step.
    pub fn defects(&mut self, run: &ReducedRun, sample: usize) -> Result<Array2<f64>> {
        self.sample = sample.max(1);
        let out = self.run(run);
        self.sample = 0;
        let mut out = out?;
        out.column_mut(0).fill(0.0);
        Ok(out)
    }

    /// The enriched trajectory `q⁺` (r⁺ × n_t) corrected along `run` (module documentation).
    /// `Err` when a solve fails or the trajectory stops being finite.
    pub fn run(&mut self, run: &ReducedRun) -> Result<Array2<f64>> {
        let load_scale = run.result.settings.load_scale;
        let s = Settings::resolve(self.model, &Overrides { load_scale: Some(load_scale), ..Default::default() })?;
        let mu = s.parameters();
        let mut bound = Bound::new(self.rom.as_mut(), &mu);
        let rom = &mut bound;
        let z = &run.reduced_q;
        let nt = z.ncols();
        let (n, nc) = (rom.n_dof(), rom.n_constraints());
        let fail = |t: f64, p: String| Error::LinearSolve { t, problem: format!("error estimator: {p}") };

        // generalized-α constants (solver/generalized_alpha.rs)
        let r = s.params.rho_inf;
        let (am, af) = ((2.0 * r - 1.0) / (r + 1.0), r / (r + 1.0));
        let g = 0.5 + af - am;
        let b = 0.25 * (g + 0.5) * (g + 0.5);
        let h = s.dt;
        let beta_p = (1.0 - am) / (b * h * h * (1.0 - af));
        let gamma_p = g / (b * h);
        let coef = IterationCoefficients { mass: 1.0, damping: gamma_p / beta_p, stiffness: 1.0 / beta_p };
        let c = (1.0 - af) / (1.0 - am);

        // consistent start: [M, Bᵀ; B, 0][q̈; λ] = [−g; 0]
        let mut q = self.enriched.reduce(ArrayView1::from(&self.x0)).to_vec();
        let mut v = vec![0.0; n];
        let mut rhs = vec![0.0; n + nc];
        let mut work = vec![0.0; n];
        let s0 = rom
            .factor(&q, &v, 0.0, IterationCoefficients { mass: 1.0, damping: 0.0, stiffness: 0.0 })
            .map_err(|p| fail(0.0, p))?;
        rom.force(&q, &v, 0.0, &mut work);
        rhs[..n].iter_mut().zip(&work).for_each(|(o, w)| *o = -w);
        rom.solve(&mut rhs).map_err(|p| fail(0.0, p))?;
        let mut qdd = rhs[..n].to_vec();
        let mut a = qdd.clone();
        let mut lambda: Vec<f64> = rhs[n..].iter().map(|m| m * s0).collect();

        let mut out = Array2::zeros((n, nt));
        out.column_mut(0).assign(&ArrayView1::from(&q));
        let mut dz = vec![0.0; z.nrows()];
        let mut d = vec![0.0; n];
        for k in 1..nt {
            let t = k as f64 * h;
            // the reduced run's increment, lifted: the predictor
            for (i, o) in dz.iter_mut().enumerate() {
                *o = z[[i, k]] - z[[i, k - 1]];
            }
            ndarray::linalg::general_mat_vec_mul(
                1.0,
                &self.lift,
                &ArrayView1::from(&dz),
                0.0,
                &mut ndarray::ArrayViewMut1::from(&mut d[..]),
            );
            for i in 0..n {
                let a0 = (af * qdd[i] - am * a[i]) / (1.0 - am);
                let dq0 = h * v[i] + h * h * ((0.5 - b) * a[i] + b * a0);
                let qn = (d[i] - dq0) / (h * h * b * c);
                q[i] += d[i];
                v[i] += h * ((1.0 - g) * a[i] + g * (a0 + c * qn));
                a[i] = a0;
                qdd[i] = qn;
            }
            if self.sample > 0 {
                // defect mode: the state follows the lifted reduced run; at every sample-th
                // step the one-iteration correction from it is recorded, not applied
                if k % self.sample == 0 {
                    lambda.iter_mut().for_each(|l| *l = 0.0);
                    newton_correction(rom, &q, &v, &qdd, &lambda, t, coef, beta_p, &mut rhs, &mut work)
                        .map_err(|p| fail(t, p))?;
                    if !rhs[..n].iter().all(|x| x.is_finite()) {
                        return Err(fail(t, "the defect is not finite".into()));
                    }
                    out.column_mut(k).assign(&ArrayView1::from(&rhs[..n]));
                }
                for i in 0..n {
                    a[i] += c * qdd[i];
                }
                continue;
            }
            let sc = newton_correction(rom, &q, &v, &qdd, &lambda, t, coef, beta_p, &mut rhs, &mut work)
                .map_err(|p| fail(t, p))?;
            for i in 0..n {
                let dq = rhs[i];
                q[i] += dq;
                v[i] += gamma_p * dq;
                qdd[i] += beta_p * dq;
            }
            // NaN kept (f64::max would pass it by and call a NaN increment converged)
            let inc = crate::linalg::vec_ops::max_abs(&rhs[..n]);
            for (l, m) in lambda.iter_mut().zip(&rhs[n..]) {
                *l += beta_p * sc * m;
            }
            if !inc.is_finite() {
                return Err(fail(t, "the corrected trajectory is no longer finite".into()));
            }
            for i in 0..n {
                a[i] += c * qdd[i];
            }
            out.column_mut(k).assign(&ArrayView1::from(&q));
        }
        Ok(out)
    }
}

/// One Newton iteration's correction at the state `(q, q̇, q̈, λ)` with a fresh matrix: the
/// residuals `r_q = M q̈ + g + Bᵀλ`, `r_c = B q − b`, scaled as the integrator scales them
/// (momentum rows by `1/β'`, constraint rows by the matrix's scale `s`), solved in place:
///
/// ```text
///     [S, Bᵀ; B, 0] [Δq; Δμ] = −[r_q / β'; s r_c]        (rhs ← [Δq; Δμ])
/// ```
///
/// Returns `s` (the multipliers change by `β' s Δμ`). `work` holds `n` entries.
#[allow(clippy::too_many_arguments)]
fn newton_correction<M: DynamicModel>(
    rom: &mut M,
    q: &[f64],
    v: &[f64],
    qdd: &[f64],
    lambda: &[f64],
    t: f64,
    coef: IterationCoefficients,
    beta_p: f64,
    rhs: &mut [f64],
    work: &mut [f64],
) -> std::result::Result<f64, String> {
    let n = q.len();
    rom.mass_mul(qdd, work);
    rom.force(q, v, t, &mut rhs[..n]);
    rhs[..n].iter_mut().zip(work.iter()).for_each(|(o, w)| *o += w);
    rom.add_constraint_force(lambda, &mut rhs[..n]);
    let sc = rom.factor(q, v, t, coef)?;
    let (rq, rc) = rhs.split_at_mut(n);
    rq.iter_mut().for_each(|x| *x *= -1.0 / beta_p);
    rom.constraint_residual(q, rc);
    rc.iter_mut().for_each(|x| *x *= -sc);
    rom.solve(rhs)?;
    Ok(sc)
}
