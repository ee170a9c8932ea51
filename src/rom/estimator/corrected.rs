//! The tight error estimator (`estimate = "corrected"`, docs/error-estimate.md; the online
//! default unless greedy training calibrated the cheap `defects` one reliably): the
//! enriched model's trajectory, not integrated on its own but *corrected from the reduced
//! run's*, one Newton iteration per step.
//!
//! The enriched estimator (`estimate = "enriched"`, [`super::enriched`]) integrates the
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
//! iteration matrix at the predictor: the integrator's own step pieces
//! ([`GeneralizedAlpha::start_step_at`], [`GeneralizedAlpha::residual`],
//! [`GeneralizedAlpha::correction`]), so that the estimate follows the scheme the runs use. (A matrix kept over several steps is not enough:
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
//! Why one iteration usually suffices: the predictor is the reduced run's own converged
//! step, so the correction is of the size of the reduced model's error, and a second
//! iteration changes it by a fraction θ (the contraction of the matrix) of that. That
//! argument needs θ small, and on some models it is not (a soft body whose enriched modes
//! the reduced run does not excite: the correction is then large against the contraction,
//! and one iteration per step leaves a residual that accumulates through the velocities
//! into estimates hundreds of times the error, or several times below it). So every step
//! checks it: the correction the same matrix gives from the corrected state, `δ₂`, is
//! computed (one residual and one solve, no new matrix), and
//!
//! ```text
//!     ‖δ₂‖ ≤ ACCEPT · ‖δ₁‖  or  ‖δ₂‖ ≤ tol · L     one iteration is kept (δ₂ not applied)
//!     otherwise                                      Newton goes on until ‖δ_k‖ ≤ ACCEPT · ‖δ₁‖
//!                                                    (or the integrator's tolerance)
//! ```
//!
//! so that what a step leaves uncorrected is at most [`ACCEPT`] of its own correction: the
//! estimate then follows the enriched model's converged trajectory to within that fraction,
//! well inside the calibration factor's margin (≥ 1.5). The matrix is refreshed when it
//! contracts slower than ½ (as the integrator's modified Newton does). A step that does not
//! get there in the integrator's `max_iterations` makes the run's reading doubtful: the
//! estimator then runs the enriched model on its own instead ([`Corrected`]). So does a
//! step whose second correction exceeds its first, `‖δ₂‖ > ‖δ₁‖` (above the tolerance):
//! Newton does not contract from the reduced run's step, which then lies outside the
//! region where the enriched step converges, and where it converges after more iterations
//! it need not be to the root the reduced run approximates — the correction is no longer
//! the reduced model's error, which is what the method reads. Measured on a clamped boom
//! with a pinned link (128 coordinates, not tuned on), over 151 loads: such steps came
//! before each of the 4 estimates that read more than 10× the enriched model's (up to
//! 309×); with the rule 30 of the 151 runs fall back (17 did before, on unconverged steps),
//! 9 of the 13 new ones had read within 1.2–3× of it. Where no step fell back `‖δ₂‖/‖δ₁‖`
//! stayed ≤ 0.45.

use super::{ErrorEstimator, Estimator, QuantityRaw, Raw};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::physics::system::FlexibleSystem;
use crate::reduction::{Basis, Hyper, HyperReducedModel, Reduced, Variant};
use crate::rom::pool::Pool;
use crate::rom::run::{physical_multipliers, ReducedRun};
use crate::simulate::{Overrides, Settings};
use crate::solver::generalized_alpha::{GeneralizedAlpha, State, StepConstants};
use crate::solver::model::{Bound, DynamicModel, ParametricModel};
use ndarray::{Array1, Array2, ArrayView1, ArrayView2};
use std::sync::Arc;

/// What a step's correction may leave uncorrected, relative to the correction itself
/// (module documentation): a tenth, well inside the 1.5 margin of the calibration factor.
pub const ACCEPT: f64 = 0.1;

/// What following one reduced run found about its corrections.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FollowStats {
    /// steps corrected
    pub steps: usize,
    /// steps where one iteration left more than [`ACCEPT`] of the correction, and Newton went on
    pub iterated: usize,
    /// steps that did not converge in the integrator's `max_iterations`
    pub unconverged: usize,
    /// steps whose first correction the matrix did not contract (`‖δ₂‖ > ‖δ₁‖`, above the
    /// tolerance): the reduced run's step lies outside the region where the enriched step's
    /// Newton converges, so where it converges it need not be to the root the reduced run
    /// approximates
    pub diverged: usize,
    /// iterations beyond the first, and the matrices refreshed for them
    pub extra_iterations: usize,
    pub refreshed: usize,
    /// the largest `‖δ₂‖ / ‖δ₁‖` seen
    pub worst_ratio: f64,
}

impl FollowStats {
    /// Whether every step was corrected as the method assumes (converged, and contracting
    /// from the reduced run's step): else the trajectory is abandoned at the first step that
    /// was not, and the estimate read from the enriched model on its own.
    pub fn followed(&self) -> bool {
        self.unconverged == 0 && self.diverged == 0
    }
}

/// The enriched model, built once, corrected along reduced runs at many parameters.
pub struct CorrectedRunner {
    model: Arc<Model>,
    rom: Box<HyperReducedModel<FlexibleSystem>>,
    /// `M = V⁺ᵀ V` (r⁺ × r)
    lift: Array2<f64>,
    /// the initial configuration in the enriched coordinates, `V⁺ᵀ(x₀ − x_ref)`, projected
    /// once (O(n_dof r⁺): on a refined mesh, most of a run's estimate otherwise)
    q0: Vec<f64>,
    /// the initial velocities in the enriched coordinates
    v0: Vec<f64>,
    /// the initial configuration in the basis's coordinates, `Vᵀ(x₀ − x_ref)`: where a
    /// reduced run starts unless it starts from its own static equilibrium
    z0: Vec<f64>,
    /// [`ACCEPT`]; ∞ keeps one iteration per step whatever it leaves (experiments)
    accept: f64,
}

impl CorrectedRunner {
    /// Whether the correction can run for `basis`: it needs the invariant-based reduced
    /// model of the enriched basis (sampled, or the physics supports it over every element)
    /// and orthonormal bases (not whole-system); elsewhere the enriched model runs on its own.
    pub fn supports(model: &Model, basis: &Basis, enriched: &Basis) -> Result<bool> {
        if basis.variant == Variant::WholeSystem {
            return Ok(false);
        }
        let sys = &model.physics()?.sys;
        Ok(enriched.hyper.is_some() || HyperReducedModel::<FlexibleSystem>::supports(sys))
    }

    /// Projects the model on the enriched basis of `data` (see [`Self::supports`]).
    pub fn new(model: &Arc<Model>, basis: &Basis, data: &Arc<Estimator>) -> Result<Self> {
        let physics = model.physics()?;
        let sys = physics.sys.clone();
        let enriched = &data.enriched;
        let all;
        let h = match &enriched.hyper {
            Some(h) => h,
            None => {
                all = Hyper::all(sys.n_elements());
                &all
            }
        };
        let rom = HyperReducedModel::new(sys, enriched, h)
            .map_err(|e| Error::usage(format!("cannot build the estimator's reduced model: {e}")))?;
        let lift = enriched.modes.t().dot(&basis.modes);
        let q0 = enriched.reduce(ArrayView1::from(&physics.x0[..])).to_vec();
        let v0 = enriched.reduce_increment(ArrayView1::from(&physics.v0[..])).to_vec();
        let z0 = basis.reduce(ArrayView1::from(&physics.x0[..])).to_vec();
        Ok(CorrectedRunner { model: Arc::clone(model), rom: Box::new(rom), lift, q0, v0, z0, accept: ACCEPT })
    }

    /// Another acceptance ratio ([`ACCEPT`]; ∞: one iteration per step, unchecked).
    pub fn set_accept(&mut self, accept: f64) {
        self.accept = accept;
    }

    /// The enriched trajectory `q⁺` (r⁺ × n_t) corrected along `run` (module documentation)
    /// and what the corrections were like. `Err` when a solve fails or the trajectory stops
    /// being finite.
    pub fn trajectory(&mut self, run: &ReducedRun) -> Result<(Array2<f64>, FollowStats)> {
        self.follow(run, 0).map(|f| (f.q, f.stats))
    }

    /// [`Self::trajectory`] with the enriched model's physical multipliers along it (n_c × n_t;
    /// NaN where its variant has none): what its reactions are read from.
    pub fn trajectory_with_multipliers(&mut self, run: &ReducedRun) -> Result<Followed> {
        self.follow(run, 0)
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
        let mut out = self.follow(run, sample.max(1))?.q;
        out.column_mut(0).fill(0.0);
        Ok(out)
    }

    /// [`Self::defects`] with the enriched model's physical multipliers after each sampled
    /// correction (n_c × n_t, the other columns NaN): `λ⁺ = β' s Δμ` from multipliers started
    /// at zero, the enriched step's multipliers at the lifted reduced state.
    pub fn defects_with_multipliers(&mut self, run: &ReducedRun, sample: usize) -> Result<Followed> {
        let mut f = self.follow(run, sample.max(1))?;
        f.q.column_mut(0).fill(0.0);
        Ok(f)
    }

    /// Where the enriched model starts along `run`: the projected initial configuration, or,
    /// where runs start from the static equilibrium of their loads (`[initial] static`),
    /// that projection moved by the lifted change the reduced run made to reach its own,
    /// `q₀⁺ + M (z₀ − Vᵀ(x₀ − x_ref))`, and, when `equilibrium` (the corrected trajectory),
    /// the enriched model's own static equilibrium from there — as full and reduced runs
    /// start from theirs, so that the start's difference is the reduced model's static
    /// error and not the whole static deflection. The defects read the lifted reduced state.
    fn start(&mut self, run: &ReducedRun, s: &Settings, equilibrium: bool) -> Result<Vec<f64>> {
        if !self.model.starts_static() {
            return Ok(self.q0.clone());
        }
        let dz: Array1<f64> = run.reduced_q.column(0).iter().zip(&self.z0).map(|(a, b)| a - b).collect();
        let q: Vec<f64> = self.lift.dot(&dz).iter().zip(&self.q0).map(|(d, q)| q + d).collect();
        if !equilibrium {
            return Ok(q);
        }
        crate::rom::run::static_start(self.rom.as_mut(), s, q, "the error estimator's enriched model's")
    }

    /// The loop of both: `sample` 0 corrects the trajectory, `s > 0` records the defects at
    /// every s-th step from the lifted reduced state.
    fn follow(&mut self, run: &ReducedRun, sample: usize) -> Result<Followed> {
        let s = Settings::resolve(&self.model, &Overrides::at(run.result.settings.parameters()))?;
        let q0 = self.start(run, &s, sample == 0)?;
        let mut bound = Bound::new(self.rom.as_mut(), s.parameters());
        let rom = &mut bound;
        let z = &run.reduced_q;
        let nt = z.ncols();
        let (n, nc) = (rom.n_dof(), rom.n_constraints());
        let fail = |t: f64, e: Error| e.at_time_in(t, "error estimator");
        let (tol, max_iterations) = (s.params.tolerance * rom.length_scale(), s.params.max_iterations);
        let mut integ = GeneralizedAlpha::new(s.params.clone()).map_err(|p| fail(0.0, p))?;
        let mut stats = FollowStats::default();
        let h = s.dt;
        let k = integ.step_constants(h);

        // consistent start: [M, Bᵀ; B, 0][q̈; λ] = [−g; c]
        let mut st: State = integ.initialize(rom, q0, self.v0.clone(), 0.0)?;
        let mut rhs = vec![0.0; n + nc];
        let mut work = vec![0.0; n];

        let mut out = Array2::zeros((n, nt));
        out.column_mut(0).assign(&ArrayView1::from(&st.q));
        let nc_full = rom.model.full().n_constraints();
        let mut lambda = Array2::from_elem((nc_full, nt), f64::NAN);
        // following: the model's own multipliers at each step, turned into physical ones
        // after the loop, so that the loop allocates nothing for them
        let mut own = Array2::zeros((if sample == 0 { nc } else { 0 }, nt));
        // the corrected trajectory by instant (q, q̇, q̈), which the multipliers' balance reads
        let rows = if sample == 0 { nt } else { 0 };
        let mut by_instant = [Array2::zeros((rows, n)), Array2::zeros((rows, n)), Array2::zeros((rows, n))];
        if sample == 0 {
            own.column_mut(0).assign(&ArrayView1::from(&st.lambda));
            keep_state(&mut by_instant, 0, &st);
        }
        let mu = s.parameters();
        let times: Vec<f64> = (0..nt).map(|k| k as f64 * h).collect();
        let mut corrected = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let mut dz = vec![0.0; z.nrows()];
        let mut d = vec![0.0; n];
        for step in 1..nt {
            let t = step as f64 * h;
            // the reduced run's increment, lifted: the predictor
            for (i, o) in dz.iter_mut().enumerate() {
                *o = z[[i, step]] - z[[i, step - 1]];
            }
            ndarray::linalg::general_mat_vec_mul(
                1.0,
                &self.lift,
                &ArrayView1::from(&dz),
                0.0,
                &mut ndarray::ArrayViewMut1::from(&mut d[..]),
            );
            integ.start_step_at(&mut st, &k, &d);
            // defect mode: the state follows the lifted reduced run; at every sample-th step
            // the one-iteration correction from it is recorded, not applied
            let record = sample > 0 && step % sample == 0;
            if sample == 0 || record {
                if record {
                    st.lambda.iter_mut().for_each(|l| *l = 0.0);
                }
                GeneralizedAlpha::residual(rom, &st, t, &mut rhs, &mut work);
                let sc = rom.factor(&st.q, &st.v, t, k.coef).map_err(|p| fail(t, p))?;
                let inc = GeneralizedAlpha::correction(rom, &mut st, t, &k, sc, &mut rhs, sample == 0)
                    .map_err(|p| fail(t, p))?;
                if record {
                    if !rhs[..n].iter().all(|x| x.is_finite()) {
                        return Err(fail(t, Error::linear_solve("the defect is not finite")));
                    }
                    out.column_mut(step).assign(&ArrayView1::from(&rhs[..n]));
                    // the lifted state's step multipliers λ⁺ = β' s Δμ from zero (at sampled
                    // steps only, each of which factors a matrix anyway)
                    rhs[n..].iter_mut().for_each(|m| *m *= k.beta_p * sc);
                    if let Some(mut l) = Reduced::multipliers(&*rom.model, &st.q, &rhs[n..]) {
                        // balanced at the corrected state, where λ⁺ belongs
                        corrected_state(&st, &k, &rhs[..n], &mut corrected);
                        let state = corrected.each_ref().map(|x| ArrayView2::from_shape((1, n), x).expect("n"));
                        let l_mut = l.view_mut().insert_axis(ndarray::Axis(1));
                        Reduced::balance(&*rom.model, mu, &[t], state, l_mut);
                        lambda.column_mut(step).assign(&l);
                    }
                } else if !inc.is_finite() {
                    return Err(fail(t, Error::linear_solve("the corrected trajectory is no longer finite")));
                } else if self.accept.is_finite() {
                    let c = Check { k, t, tol, max_iterations, accept: self.accept };
                    check_step(rom, &mut st, &c, sc, inc, (&mut rhs, &mut work), &mut stats).map_err(|p| fail(t, p))?;
                    if !stats.followed() {
                        // what follows this step is no reading of the reduced run's error
                        if sample == 0 {
                            let along = by_instant.each_ref().map(|x| x.view());
                            lambda = physical_multipliers(&*rom.model, nc_full, (mu, &times), along, own.view(), step);
                        }
                        return Ok(Followed { q: out, lambda, stats });
                    }
                }
            }
            integ.finish_step(&mut st, &k);
            if sample == 0 {
                out.column_mut(step).assign(&ArrayView1::from(&st.q));
                own.column_mut(step).assign(&ArrayView1::from(&st.lambda));
                keep_state(&mut by_instant, step, &st);
            }
        }
        if sample == 0 {
            let along = by_instant.each_ref().map(|x| x.view());
            lambda = physical_multipliers(&*rom.model, nc_full, (mu, &times), along, own.view(), nt);
        }
        Ok(Followed { q: out, lambda, stats })
    }
}

/// Row `k` of the trajectory by instant: the state's `q`, `q̇`, `q̈`.
fn keep_state(by_instant: &mut [Array2<f64>; 3], k: usize, st: &State) {
    for (to, from) in by_instant.iter_mut().zip([&st.q, &st.v, &st.qdd]) {
        to.row_mut(k).assign(&ArrayView1::from(from));
    }
}

/// The state a Newton correction `dq` (not applied) would give:
/// `(q + dq, q̇ + γ' dq, q̈ + β' dq)` ([`GeneralizedAlpha::apply_correction`]).
fn corrected_state(st: &State, k: &StepConstants, dq: &[f64], out: &mut [Vec<f64>; 3]) {
    let [q, v, a] = out;
    for (i, d) in dq.iter().enumerate() {
        q[i] = st.q[i] + d;
        v[i] = st.v[i] + k.gamma_p * d;
        a[i] = st.qdd[i] + k.beta_p * d;
    }
}

/// What following a reduced run gives: the enriched coordinates (the corrected trajectory,
/// or the defects), the enriched model's physical multipliers there, and the corrections'
/// statistics.
pub struct Followed {
    /// r⁺ × n_t
    pub q: Array2<f64>,
    /// n_c × n_t, NaN where none was taken
    pub lambda: Array2<f64>,
    pub stats: FollowStats,
}

/// What [`check_step`] holds a step to.
struct Check {
    k: StepConstants,
    t: f64,
    /// the integrator's absolute Newton tolerance, `tolerance · L`
    tol: f64,
    max_iterations: usize,
    accept: f64,
}

/// The self-check of a step whose first correction `first = ‖δ₁‖` has been applied with
/// the matrix of scale `s` (module documentation): `δ₂` from the corrected state with the
/// same matrix; kept unapplied when it is at most `accept · ‖δ₁‖` (or the tolerance), else
/// Newton goes on, refreshing the matrix when it contracts slower than ½.
fn check_step<M: DynamicModel>(
    rom: &mut M,
    st: &mut State,
    c: &Check,
    mut s: f64,
    first: f64,
    (rhs, work): (&mut [f64], &mut [f64]),
    stats: &mut FollowStats,
) -> Result<()> {
    stats.steps += 1;
    let limit = (c.accept * first).max(c.tol);
    let mut last = first;
    for it in 2..=c.max_iterations.max(2) {
        GeneralizedAlpha::residual(rom, st, c.t, rhs, work);
        let next = GeneralizedAlpha::correction(rom, st, c.t, &c.k, s, rhs, false)?;
        if !next.is_finite() {
            return Err(Error::linear_solve("the corrected trajectory is no longer finite"));
        }
        if it == 2 && first > 0.0 {
            stats.worst_ratio = stats.worst_ratio.max(next / first);
        }
        if next <= limit {
            return Ok(());
        }
        if it == 2 && next > first {
            stats.diverged += 1;
            return Ok(());
        }
        if it == 2 {
            stats.iterated += 1;
        }
        GeneralizedAlpha::apply_correction(st, &c.k, s, rhs);
        stats.extra_iterations += 1;
        if next > 0.5 * last {
            s = rom.factor(&st.q, &st.v, c.t, c.k.coef)?;
            stats.refreshed += 1;
        }
        last = next;
    }
    stats.unconverged += 1;
    Ok(())
}

/// The `corrected` method: η_raw from the corrected trajectory, times the calibrated `c`.
/// A run whose corrections do not converge at some step, do not contract from the reduced
/// run's step ([`FollowStats::diverged`]), or blow up (a trajectory no longer finite, a
/// matrix that cannot be factored), is read by the enriched model on its own
/// instead (the `enriched` method's reading, the reference the correction approximates,
/// which integrates to convergence and halves its steps where it must).
pub struct Corrected {
    model: Arc<Model>,
    basis: Arc<Basis>,
    data: Arc<Estimator>,
    runners: Pool<'static, CorrectedRunner>,
    /// built at the first run that needs it
    fallback: std::sync::OnceLock<Option<super::enriched::Enriched>>,
    /// the initial configuration X₀ of the displacement measure
    x0: Arc<Vec<f64>>,
    /// the norms' projections of the basis pair, made once
    norms: super::norms::NormProjection,
    /// the model's length scale `L` (the displacement measure's resolution is `tol · L`)
    length: f64,
    /// the model's reaction points
    reactions: crate::rom::reactions::ReactionReader,
}

impl Corrected {
    /// With one runner built now, so that a model the estimator cannot be built for fails
    /// here rather than at the first estimate.
    pub fn new(model: &Arc<Model>, basis: &Arc<Basis>, data: &Arc<Estimator>) -> Result<Self> {
        let (m, b, d) = (Arc::clone(model), Arc::clone(basis), Arc::clone(data));
        let runners = Pool::new(move || CorrectedRunner::new(&m, &b, &d));
        runners.put(CorrectedRunner::new(model, basis, data)?);
        let physics = model.physics()?;
        let x0 = Arc::clone(&physics.x0);
        let length = physics.length_scale();
        let norms = super::norms::NormProjection::new(basis, &data.enriched, ndarray::ArrayView1::from(&x0[..]));
        Ok(Corrected {
            length,
            reactions: crate::rom::reactions::ReactionReader::new(model),
            model: Arc::clone(model),
            basis: Arc::clone(basis),
            data: Arc::clone(data),
            runners,
            fallback: std::sync::OnceLock::new(),
            x0,
            norms,
        })
    }
}

impl ErrorEstimator for Corrected {
    fn name(&self) -> &'static str {
        "corrected"
    }
    fn data(&self) -> &Estimator {
        &self.data
    }
    fn reactions(&self) -> Option<&crate::rom::reactions::ReactionReader> {
        Some(&self.reactions)
    }
    fn raw(&self, run: &ReducedRun) -> Result<Raw> {
        let why = match self.runners.with(|r| r.trajectory_with_multipliers(run))? {
            Ok(Followed { q: qp, lambda, stats }) if stats.followed() => {
                let x0 = ndarray::ArrayView1::from(&self.x0[..]);
                let res = super::norms::resolution(run, self.length);
                let norms = self.norms.raw_by_time(&self.basis, &self.data.enriched, &run.reduced_q, &qp, x0, res);
                let sys = &self.model.physics()?.sys;
                let enriched = crate::rom::probes::probe_values(sys, &self.data.enriched, qp.view());
                let reference = crate::rom::quantities::readings_of_probes(&enriched);
                let tol = run.result.settings.params.tolerance;
                let mut quantities = QuantityRaw::between(&run.result, &reference, tol, self.length);
                let t = run.result.t.as_slice().unwrap_or(&[]);
                let mu = run.result.settings.parameters();
                let enriched =
                    self.reactions.of_trajectory((mu, t), (&self.data.enriched, qp.view()), None, lambda.view());
                let own = super::run_reactions(&self.reactions, &self.basis, run);
                quantities.extend(QuantityRaw::between_reactions(&self.reactions, own, enriched, tol));
                return Ok(Raw { norms, quantities });
            }
            Ok(Followed { stats, .. }) if stats.diverged > 0 => {
                "left the reduced run's step (a step's first correction was not contracted)".to_string()
            }
            Ok(_) => "did not converge".to_string(),
            Err(e) => format!("failed ({e})"),
        };
        let fallback =
            self.fallback.get_or_init(|| super::enriched::Enriched::new(&self.model, &self.basis, &self.data).ok());
        match fallback {
            Some(e) => e.raw(run).map_err(|e| {
                crate::error::Error::usage(format!(
                    "the corrected estimate {why}, and the enriched model run instead failed too ({e})"
                ))
            }),
            None => Err(crate::error::Error::usage(format!(
                "the corrected estimate {why} and the enriched model cannot be built"
            ))),
        }
    }
}
