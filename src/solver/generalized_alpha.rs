//! Generalized-α for index-3 constrained mechanical systems (Arnold & Brüls 2007,
//! "Convergence of the generalized-α scheme for constrained mechanical systems",
//! Multibody Syst. Dyn. 18:185–202).
//!
//! With `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`, `γ = ½ + α_f − α_m`,
//! `β = ¼(γ + ½)²` and the pseudo-acceleration `a`:
//!
//! ```text
//!   q_{n+1} = q_n + h q̇_n + h²(½ − β) a_n + h² β a_{n+1}
//!   q̇_{n+1} = q̇_n + h(1 − γ) a_n + h γ a_{n+1}
//!   (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) q̈_{n+1} + α_f q̈_n
//! ```
//!
//! and the equations of motion and the constraints hold exactly at `t_{n+1}`. Newton on
//! `Δq` uses `Δq̇ = γ' Δq`, `Δq̈ = β' Δq` with `β' = (1 − α_m)/(β h² (1 − α_f))`,
//! `γ' = γ/(β h)`. The momentum rows are divided by `β'` (Bottasso, Bauchau & Cardona 2007
//! scaling), so the iteration matrix `M + (γ'/β') C + K/β'` stays well conditioned as
//! `h → 0`; the model scales the constraint rows to match. ρ∞ = 1 gives the trapezoidal
//! rule (no numerical damping).
//!
//! On a failed Newton iteration the step is halved (recursively, `max_cuts` times) and the
//! nominal step is completed with the smaller steps.

pub use super::integrator_params::{IntegratorParams, JacobianReuse};
use super::model::{DynamicModel, IterationCoefficients};
pub use super::predictor::Predictor;
use crate::error::{Error, Result};
use crate::linalg::vec_ops::max_abs;

/// The integrator's state; `lambda` are the Lagrange multipliers (physical units).
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub t: f64,
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    /// pseudo-acceleration `a`
    pub a: Vec<f64>,
    /// true acceleration `q̈`
    pub qdd: Vec<f64>,
    pub lambda: Vec<f64>,
}

/// Counters reported with every result file.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Stats {
    pub steps: usize,
    pub newton_iterations: usize,
    pub factorizations: usize,
    pub step_cuts: usize,
    pub max_iterations_in_a_step: usize,
    /// steps accepted at the round-off floor ([`IntegratorParams::stagnation`])
    pub steps_at_round_off: usize,
    /// steps (halved ones each) whose Newton started at the constant-velocity guess, by
    /// [`Predictor::ConstantVelocity`] or by the adaptive start's choice
    pub constant_velocity_starts: usize,
    /// the same for the constant-position guess ([`Predictor::ConstantPosition`])
    pub constant_position_starts: usize,
    /// the same for the zero-acceleration start ([`Predictor::ZeroAcceleration`])
    pub zero_acceleration_starts: usize,
    /// the start time of every step that was halved, once per step however deep its cuts
    /// went: where a run's time grid left the regular one (two runs compared step by step,
    /// e.g. full and reduced, solve different discretizations after a cut one of them
    /// alone took)
    pub step_cut_times: Vec<f64>,
    /// the largest mean axial strain `|ε̄|` the blow-up checks met (every few steps and the
    /// last), with its element and time (a hyper-reduced run: over its sampled elements);
    /// `None` where the model cannot tell
    pub largest_strain: Option<LargestStrain>,
}

/// Where a run strained most, as far as its blow-up checks saw ([`Stats::largest_strain`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LargestStrain {
    /// `|ε̄|`, the element's mean axial strain
    pub strain: f64,
    /// the element's index over the whole model (bodies in file order)
    pub element: usize,
    /// s
    pub t: f64,
}

impl Stats {
    /// Which guess Newton started from, for `-v` (a halved step's parts count each):
    /// `constant velocity at 3, constant position at 0, zero acceleration at 217`.
    pub fn starts(&self) -> String {
        format!(
            "constant velocity at {}, constant position at {}, zero acceleration at {}",
            self.constant_velocity_starts, self.constant_position_starts, self.zero_acceleration_starts
        )
    }
}

struct Failure {
    iterations: usize,
    increment: f64,
    residual: f64,
}

/// The constants of one step of size `h`: `β' = (1 − α_m)/(β h² (1 − α_f))`, `γ' = γ/(β h)`,
/// the iteration matrix's coefficients `M + (γ'/β') C + K/β'` and `c = (1 − α_f)/(1 − α_m)`
/// (`a_{n+1} = a₀ + c q̈_{n+1}`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepConstants {
    pub h: f64,
    pub beta_p: f64,
    pub gamma_p: f64,
    pub c: f64,
    pub coef: IterationCoefficients,
}

pub struct GeneralizedAlpha {
    params: IntegratorParams,
    alpha_m: f64,
    alpha_f: f64,
    gamma: f64,
    beta: f64,
    /// (h, s) of the factorization currently held by the model, if reusable
    factored: Option<(f64, f64)>,
    rhs: Vec<f64>,
    work: Vec<f64>,
    backup: Option<State>,
    /// [`Predictor::Adaptive`]'s start for the next step without a guess: one of the three
    /// fixed ones ([`Self::closer_start`])
    next_start: Predictor,
    pub stats: Stats,
}

impl GeneralizedAlpha {
    pub fn new(params: IntegratorParams) -> Result<Self> {
        params.validate()?;
        let r = params.rho_inf;
        let alpha_m = (2.0 * r - 1.0) / (r + 1.0);
        let alpha_f = r / (r + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        Ok(GeneralizedAlpha {
            params,
            alpha_m,
            alpha_f,
            gamma,
            beta,
            factored: None,
            rhs: Vec::new(),
            work: Vec::new(),
            backup: None,
            next_start: Predictor::ConstantVelocity,
            stats: Stats::default(),
        })
    }

    pub fn params(&self) -> &IntegratorParams {
        &self.params
    }

    /// [`StepConstants`] of a step of `h`.
    pub fn step_constants(&self, h: f64) -> StepConstants {
        let (am, af, g, b) = (self.alpha_m, self.alpha_f, self.gamma, self.beta);
        let beta_p = (1.0 - am) / (b * h * h * (1.0 - af));
        let gamma_p = g / (b * h);
        let coef = IterationCoefficients { mass: 1.0, damping: gamma_p / beta_p, stiffness: 1.0 / beta_p };
        StepConstants { h, beta_p, gamma_p, c: (1.0 - af) / (1.0 - am), coef }
    }

    /// Starts the step of coordinate `i`: `a₀ = (α_f q̈_n − α_m a_n)/(1 − α_m)`, the part of
    /// `a_{n+1}` that does not depend on `q̈_{n+1}` (kept in `a` while Newton runs; `c q̈_{n+1}` is
    /// added at convergence, [`Self::finish_step`]), and the `q̈_{n+1}` that puts the increment
    /// at `d` (`None`: `q̈_{n+1} = 0`), with `q̇_{n+1}` from it. Returns the increment the
    /// scheme's update gives, `Δq₀ + h²βc q̈_{n+1}` (`d` to round-off); `q` is not moved.
    #[inline]
    fn start_coordinate(&self, st: &mut State, i: usize, k: &StepConstants, d: Option<f64>) -> f64 {
        let (g, b, h, c) = (self.gamma, self.beta, k.h, k.c);
        let (a0, dq0) = self.zero_acceleration_start(st, i, k);
        let qdd = d.map_or(0.0, |d| (d - dq0) / (h * h * b * c));
        st.v[i] += h * ((1.0 - g) * st.a[i] + g * (a0 + c * qdd));
        st.a[i] = a0;
        st.qdd[i] = qdd;
        dq0 + h * h * b * c * qdd
    }

    /// `(a₀, Δq₀)` of coordinate `i`: the part of `a_{n+1}` that does not depend on
    /// `q̈_{n+1}`, and the increment at `q̈_{n+1} = 0`.
    #[inline]
    fn zero_acceleration_start(&self, st: &State, i: usize, k: &StepConstants) -> (f64, f64) {
        let (am, af, b, h) = (self.alpha_m, self.alpha_f, self.beta, k.h);
        let a0 = (af * st.qdd[i] - am * st.a[i]) / (1.0 - am);
        (a0, h * st.v[i] + h * h * ((0.5 - b) * st.a[i] + b * a0))
    }

    /// [`Predictor::Adaptive`]'s choice after a step from `start` (the state the step began
    /// at, which [`Self::advance`] keeps) that ended at `q`: the fixed start whose guess of
    /// the increment came closest to `q − q_n`, in ‖·‖∞ (Newton's own measure); ties go to
    /// zero acceleration, then constant velocity. What separates the three: the
    /// acceleration term `h²((½ − β) a_n + β a₀)` of the zero-acceleration guess, close to
    /// the motion where the accelerations are smooth (damped, `rho_inf` < 1), far from it
    /// where undamped vibrations of stiff elements (`rho_inf` near 1) make `q̈` alternate
    /// from step to step at amplitudes the positions never reach; the velocity term `h q̇_n`
    /// of the constant-velocity guess, close where the motion is resolved, far where the
    /// velocities of vibrations the step does not resolve are large and their positions
    /// small — there the position the step started from is the closest guess. One pass over
    /// the coordinates; the guesses are formed again from the start rather than kept.
    fn closer_start(&self, start: &State, q: &[f64], k: &StepConstants) -> Predictor {
        // in order of preference on a tie; each guess as the start itself makes it
        const STARTS: [Predictor; 3] =
            [Predictor::ZeroAcceleration, Predictor::ConstantVelocity, Predictor::ConstantPosition];
        let mut misses = [0.0_f64; 3];
        for (i, &qi) in q.iter().enumerate() {
            let d = qi - start.q[i];
            for (miss, p) in misses.iter_mut().zip(STARTS) {
                let guess = p.increment(k.h, start.v[i]).unwrap_or_else(|| self.zero_acceleration_start(start, i, k).1);
                *miss = miss.max((d - guess).abs());
            }
        }
        STARTS[(1..3).fold(0, |best, j| if misses[j] < misses[best] { j } else { best })]
    }

    /// Starts the step to `t + h` at the increment `d` exactly (`q ← q + d`), with `q̇`, `q̈`
    /// and `a` as the scheme has them for that increment: the state from which
    /// [`Self::correction`] measures how far `d` is from the step's solution (the error
    /// estimator lifts a reduced run's step into a richer model this way). `st.t` is not
    /// moved.
    pub fn start_step_at(&self, st: &mut State, k: &StepConstants, d: &[f64]) {
        for (i, &di) in d.iter().enumerate() {
            self.start_coordinate(st, i, k, Some(di));
            st.q[i] += di;
        }
    }

    /// Ends a step whose Newton iterations are done: `a_{n+1} = a₀ + c q̈_{n+1}`. `st.t` is
    /// not moved.
    pub fn finish_step(&self, st: &mut State, k: &StepConstants) {
        for (a, qdd) in st.a.iter_mut().zip(&st.qdd) {
            *a += k.c * qdd;
        }
    }

    /// The residual of the equations of motion at `st` and time `t`, `r_q = M q̈ + g + Bᵀλ`,
    /// into `rhs[..n]` (`work`: n entries).
    pub fn residual<M: DynamicModel>(model: &mut M, st: &State, t: f64, rhs: &mut [f64], work: &mut [f64]) {
        let n = st.q.len();
        model.force_and_inertia(&st.q, &st.v, &st.qdd, t, (&mut rhs[..n], work));
        for i in 0..n {
            rhs[i] += work[i];
        }
        model.add_constraint_force(&st.lambda, t, &mut rhs[..n]);
    }

    /// One Newton correction from the residual [`Self::residual`] left in `rhs[..n]`, with the
    /// model's current factorization of scale `s`: the rows scaled as the iteration matrix
    /// is (momentum by `1/β'`, constraints by `s`),
    ///
    /// ```text
    ///     [S, Bᵀ; B, 0] [Δq; Δμ] = −[r_q / β'; s (B(t) q − b(t))]        (rhs ← [Δq; Δμ])
    /// ```
    ///
    /// and, with `apply`, the update of [`Self::apply_correction`]. Returns `‖Δq‖∞` (NaN
    /// kept: `f64::max` would pass it by and call a NaN increment converged).
    pub fn correction<M: DynamicModel>(
        model: &mut M,
        st: &mut State,
        t: f64,
        k: &StepConstants,
        s: f64,
        rhs: &mut [f64],
        apply: bool,
    ) -> Result<f64> {
        let n = st.q.len();
        let (rq, rc) = rhs.split_at_mut(n);
        rq.iter_mut().for_each(|x| *x *= -1.0 / k.beta_p);
        model.constraint_residual(&st.q, t, rc);
        rc.iter_mut().for_each(|x| *x *= -s);
        model.solve(rhs)?;
        if apply {
            Self::apply_correction(st, k, s, rhs);
        }
        Ok(max_abs(&rhs[..n]))
    }

    /// The Newton update from a solved correction `rhs = [Δq; Δμ]` ([`Self::correction`]):
    /// `q += Δq`, `q̇ += γ'Δq`, `q̈ += β'Δq`, `λ += β' s Δμ`.
    pub fn apply_correction(st: &mut State, k: &StepConstants, s: f64, rhs: &[f64]) {
        let (dq, dmu) = rhs.split_at(st.q.len());
        for (((q, v), a), d) in st.q.iter_mut().zip(&mut st.v).zip(&mut st.qdd).zip(dq) {
            *q += d;
            *v += k.gamma_p * d;
            *a += k.beta_p * d;
        }
        for (l, m) in st.lambda.iter_mut().zip(dmu) {
            *l += k.beta_p * s * m;
        }
    }

    /// Consistent initial accelerations and multipliers from
    /// `[M, Bᵀ; B, 0] [q̈₀; λ₀] = [−g(q₀, q̇₀, t₀); c(q₀, q̇₀, t₀)]`, `c` the constraints'
    /// acceleration level ([`DynamicModel::constraint_acceleration_rhs`]; 0 for constant ones).
    pub fn initialize<M: DynamicModel>(&mut self, model: &mut M, q0: Vec<f64>, v0: Vec<f64>, t0: f64) -> Result<State> {
        let (n, nc) = (model.n_dof(), model.n_constraints());
        assert_eq!(q0.len(), n);
        assert_eq!(v0.len(), n);
        self.rhs = vec![0.0; n + nc];
        self.work = vec![0.0; n];
        // the first step has no step before it to judge by, whatever an earlier run chose:
        // it starts from constant velocity (at rest: where the run starts), as the
        // zero-acceleration guess carries the initial accelerations, which a load applied at
        // t₀ makes largest in the stiffest parts the step resolves least (a moment on a
        // slender glass-fibre arm put that guess 10² m off, its residual 4e11 against 1.5e2)
        self.next_start = Predictor::ConstantVelocity;
        let coef = IterationCoefficients { mass: 1.0, damping: 0.0, stiffness: 0.0 };
        let s = model.factor(&q0, &v0, t0, coef).map_err(|e| e.at_time(t0))?;
        self.factored = None;
        self.stats.factorizations += 1;
        model.force(&q0, &v0, t0, &mut self.work);
        for i in 0..n {
            self.rhs[i] = -self.work[i];
        }
        // the constraint rows are factored as s B: their right-hand side is s c
        model.constraint_acceleration_rhs(&q0, &v0, t0, &mut self.rhs[n..]);
        self.rhs[n..].iter_mut().for_each(|x| *x *= s);
        model.solve(&mut self.rhs).map_err(|e| e.at_time(t0))?;
        let qdd = self.rhs[..n].to_vec();
        let lambda = self.rhs[n..].iter().map(|m| m * s).collect();
        Ok(State { t: t0, q: q0, v: v0, a: qdd.clone(), qdd, lambda })
    }

    /// Advances `state` by `h`, halving the step on Newton failure.
    pub fn step<M: DynamicModel>(&mut self, model: &mut M, state: &mut State, h: f64) -> Result<()> {
        self.step_guided(model, state, h, None)
    }

    /// [`Self::step`] with a guess of the step's increment `q_{n+1} − q_n` (e.g. the same
    /// step of a run at a nearby load scale) as Newton's starting point instead of the
    /// predictor ([`IntegratorParams::predictor`]). The guess only moves the start: the step
    /// still stops on the same tolerance. Halved sub-steps, if any, use the predictor (the
    /// adaptive one from constant position).
    pub fn step_guided<M: DynamicModel>(
        &mut self,
        model: &mut M,
        state: &mut State,
        h: f64,
        guess: Option<&[f64]>,
    ) -> Result<()> {
        self.advance(model, state, h, 0, guess)?;
        self.stats.steps += 1;
        Ok(())
    }

    fn advance<M: DynamicModel>(
        &mut self,
        model: &mut M,
        state: &mut State,
        h: f64,
        depth: u32,
        guess: Option<&[f64]>,
    ) -> Result<()> {
        match &mut self.backup {
            Some(b) => b.clone_from(state),
            None => self.backup = Some(state.clone()),
        }
        let reuse = self.params.reuse;
        let mut result = self.try_step(model, state, h, reuse, guess);
        if result.is_err() {
            self.restart_failed_step_from_its_position();
        }
        if result.is_err() && reuse != JacobianReuse::Never {
            // a stale matrix may be what failed: retry once with full Newton before halving
            state.clone_from(self.backup.as_ref().expect("backup taken"));
            self.factored = None;
            result = self.try_step(model, state, h, JacobianReuse::Never, guess);
        }
        match result {
            Ok(()) => Ok(()),
            Err(fail) => {
                state.clone_from(self.backup.as_ref().expect("backup taken"));
                self.factored = None;
                if depth >= self.params.max_cuts {
                    return Err(Error::NewtonFailed {
                        t: state.t + h,
                        dt: h,
                        cuts: depth,
                        iterations: fail.iterations,
                        increment: fail.increment,
                        residual: fail.residual,
                    });
                }
                self.stats.step_cuts += 1;
                if depth == 0 {
                    self.stats.step_cut_times.push(state.t);
                }
                self.advance(model, state, 0.5 * h, depth + 1, None)?;
                self.advance(model, state, 0.5 * h, depth + 1, None)
            }
        }
    }

    /// After a step failed from the adaptive start's choice, its retry (full Newton, before
    /// halving) and its halves start from the position the step started at: the chosen
    /// guess was off in some stiff direction its velocity or acceleration term carried it
    /// into, and the step's start is off by no more than the step's own motion
    /// (docs/reduced-speed.md, "The adaptive start"). A guided step's retry keeps its
    /// guess; its halves start here too. The next converged step chooses again.
    fn restart_failed_step_from_its_position(&mut self) {
        if self.params.predictor == Predictor::Adaptive {
            self.next_start = Predictor::ConstantPosition;
        }
    }

    fn try_step<M: DynamicModel>(
        &mut self,
        model: &mut M,
        st: &mut State,
        h: f64,
        policy: JacobianReuse,
        guess: Option<&[f64]>,
    ) -> std::result::Result<(), Failure> {
        let n = model.n_dof();
        let k = self.step_constants(h);
        let t = st.t + h;
        // predictor (super::predictor): with a guessed increment (given, or the predictor's),
        // the q̈_{n+1} that puts q_{n+1} there; else q̈_{n+1} = 0, and a_{n+1} from the α
        // relation (Self::start_coordinate)
        assert!(guess.is_none_or(|d| d.len() == n), "a guessed increment needs {n} entries");
        // the adaptive start judges every step, guided ones too (the choice carries on to
        // the next step); it chooses only where no guess is given
        let judging = self.params.predictor == Predictor::Adaptive;
        let adaptive = judging && guess.is_none();
        let predictor = if adaptive { self.next_start } else { self.params.predictor };
        // ‖guess‖∞, for keeping the first matrix of a good guess (below)
        let guess_size = match guess {
            Some(d) => Some(max_abs(d)),
            // the adaptive start keeps no first matrix: on a swinging pendulum the kept
            // matrix of a constant-velocity start costs two more iterations a step than the
            // factorization it saves
            None if adaptive => None,
            None => predictor.increment_size(h, &st.v),
        };
        for i in 0..n {
            let d = guess.map_or_else(|| predictor.increment(h, st.v[i]), |d| Some(d[i]));
            st.q[i] += self.start_coordinate(st, i, &k, d);
        }
        if policy != JacobianReuse::AcrossSteps {
            self.factored = None;
        }
        let tol = self.params.tolerance * model.length_scale();
        let floor = self.params.stagnation * model.length_scale();
        let mut last_increment = f64::INFINITY;
        let mut fresh_before = false;
        let mut residual = f64::NAN;
        for it in 1..=self.params.max_iterations {
            self.stats.newton_iterations += 1;
            Self::residual(model, st, t, &mut self.rhs, &mut self.work);
            residual = max_abs(&self.rhs[..n]);
            if !residual.is_finite() {
                return Err(Failure { iterations: it, increment: last_increment, residual });
            }
            let reuse = policy != JacobianReuse::Never && self.factored.is_some_and(|(fh, _)| fh == h);
            let s = if reuse {
                self.factored.expect("checked").1
            } else {
                let s = model.factor(&st.q, &st.v, t, k.coef).map_err(|_| Failure {
                    iterations: it,
                    increment: last_increment,
                    residual,
                })?;
                self.stats.factorizations += 1;
                self.factored = Some((h, s));
                s
            };
            let inc = Self::correction(model, st, t, &k, s, &mut self.rhs, true).map_err(|_| Failure {
                iterations: it,
                increment: last_increment,
                residual,
            })?;
            if !inc.is_finite() {
                return Err(Failure { iterations: it, increment: inc, residual });
            }
            // converged when the increment, or the error still left after it as estimated
            // from the contraction θ = ‖Δq_k‖/‖Δq_{k−1}‖, is below tolerance: θ/(1−θ)‖Δq_k‖
            // (Hairer & Wanner, Solving ODEs II, §IV.8); saves the confirming iteration
            let theta = inc / last_increment;
            let converged = inc <= tol || (it > 1 && theta < 0.5 && theta / (1.0 - theta) * inc <= tol);
            // no longer contracting, far below any increment that matters: the round-off
            // floor of the residual, where more iterations only shuffle round-off. Only
            // between two fresh matrices: a kept one that stopped contracting is stale, not
            // at the floor (it is refreshed below), and the first step after a refresh
            // corrects what the stale ones left, so its θ says nothing about the floor
            // (across steps a fresh matrix is always used twice, so there the second use
            // of a fresh one is what tells)
            let judged_fresh = fresh_before && (!reuse || policy == JacobianReuse::AcrossSteps);
            let stagnated = !converged && judged_fresh && it > 3 && theta > 0.5 && inc <= floor;
            if converged || stagnated {
                if judging {
                    let start = self.backup.as_ref().expect("advance keeps the step's start");
                    self.next_start = self.closer_start(start, &st.q, &k);
                }
                self.stats.steps_at_round_off += stagnated as usize;
                if guess.is_none() {
                    *match predictor {
                        Predictor::ZeroAcceleration => &mut self.stats.zero_acceleration_starts,
                        Predictor::ConstantVelocity => &mut self.stats.constant_velocity_starts,
                        Predictor::ConstantPosition => &mut self.stats.constant_position_starts,
                        Predictor::Adaptive => unreachable!("the adaptive start chose one of the others"),
                    } += 1;
                }
                self.finish_step(st, &k);
                st.t = t;
                self.stats.max_iterations_in_a_step = self.stats.max_iterations_in_a_step.max(it);
                return Ok(());
            }
            // modified Newton: refresh the matrix when the contraction is slow (a fresh
            // tangent gives quadratic convergence)
            let refresh = match policy {
                JacobianReuse::Never => true,
                // a fresh matrix until one contracted fast; a kept one while it still does
                JacobianReuse::WithinStep => {
                    if reuse {
                        theta > 0.3
                    } else if it == 1 {
                        // keep the first matrix only when the guess was good: its
                        // correction small next to the step it guessed
                        guess_size.is_none_or(|g| inc > 0.05 * g)
                    } else {
                        theta >= 0.1
                    }
                }
                // a fresh matrix is always kept once (the next θ judges it); a kept one is
                // refreshed when it contracts slowly or would need too many more iterations
                JacobianReuse::AcrossSteps => reuse && it > 1 && slow_contraction(theta, inc, tol),
            };
            if refresh {
                self.factored = None;
            }
            fresh_before = !reuse;
            last_increment = inc;
        }
        Err(Failure { iterations: self.params.max_iterations, increment: last_increment, residual })
    }
}

/// Whether a kept matrix contracting at `theta` (last increment `inc`) should be refreshed:
/// when `θ > ½` (the error estimate `θ/(1−θ)‖Δq‖` no longer holds, and the matrix may be
/// diverging), or when reaching the tolerance at that rate would take more than
/// [`KEPT_ITERATIONS`] further iterations, `j ≥ ln(tol (1−θ)/(θ ‖Δq‖)) / ln θ`, more than a
/// refresh costs (one factorization, after which Newton converges quadratically in one or
/// two iterations).
fn slow_contraction(theta: f64, inc: f64, tol: f64) -> bool {
    if !(theta <= 0.5) {
        return true;
    }
    if theta <= 0.0 {
        return false;
    }
    let left = theta / (1.0 - theta) * inc;
    left > tol && (tol / left).ln() / theta.ln() > KEPT_ITERATIONS
}

/// How many more iterations a kept matrix may need before a refresh is cheaper.
const KEPT_ITERATIONS: f64 = 3.0;

#[cfg(test)]
mod tests {
    use super::*;

    /// The adaptive start takes, for the next step, the start that came closest to this
    /// step's solution in the largest coordinate, and starts a run at constant velocity.
    #[test]
    fn the_adaptive_start_keeps_the_closer_guess() {
        let params = IntegratorParams { rho_inf: 1.0, predictor: Predictor::Adaptive, ..IntegratorParams::default() };
        let integ = GeneralizedAlpha::new(params).unwrap();
        assert_eq!(integ.next_start, Predictor::ConstantVelocity);
        let k = integ.step_constants(0.01);
        // ρ∞ = 1: a₀ = q̈_n − a_n = 0, so the zero-acceleration guess is h v + h²/4 a_n =
        // (0.3, 0.05); the constant-velocity guess h v = (0.1, 0); the constant-position
        // guess (0, 0)
        let start = State {
            t: 0.0,
            q: vec![1.0, 2.0],
            v: vec![10.0, 0.0],
            a: vec![8000.0, 2000.0],
            qdd: vec![8000.0, 2000.0],
            lambda: vec![],
        };
        // misses (zero acceleration, constant velocity, constant position): 0.18, 0.02, 0.12
        assert_eq!(integ.closer_start(&start, &[1.12, 2.0], &k), Predictor::ConstantVelocity);
        // 0.01, 0.19, 0.29
        assert_eq!(integ.closer_start(&start, &[1.29, 2.04], &k), Predictor::ZeroAcceleration);
        // 0.28, 0.08, 0.02: the velocity overshot a step that hardly moved
        assert_eq!(integ.closer_start(&start, &[1.02, 2.0], &k), Predictor::ConstantPosition);
    }

    /// One mass on a spring, `q̈ + k q + c q³ + A sin(10¹² q) = 0`. The noise term stands
    /// for the round-off of a residual summed from large terms that cancel (chaotic in q, of
    /// size A). With `stale` ≠ 1 the factorization goes stale when kept: the first solve
    /// after each `factor` uses the exact tangent, later ones a tangent `stale` times too
    /// stiff (a kept matrix contracting at θ = 1 − 1/stale, like one from far back). With
    /// `nan_below` the force is NaN for q below it (a force undefined there).
    struct Spring {
        k: f64,
        c: f64,
        noise: f64,
        stale: f64,
        s: f64,
        fresh: bool,
        nan_below: f64,
    }

    impl DynamicModel for Spring {
        fn n_dof(&self) -> usize {
            1
        }
        fn n_constraints(&self) -> usize {
            0
        }
        fn mass_mul(&self, a: &[f64], out: &mut [f64]) {
            out[0] = a[0];
        }
        fn force(&mut self, q: &[f64], _v: &[f64], _t: f64, out: &mut [f64]) {
            out[0] = self.k * q[0] + self.c * q[0].powi(3) + self.noise * (1e12 * q[0]).sin();
            if q[0] < self.nan_below {
                out[0] = f64::NAN;
            }
        }
        fn constraint_residual(&self, _q: &[f64], _t: f64, _out: &mut [f64]) {}
        fn add_constraint_force(&self, _lambda: &[f64], _t: f64, _out: &mut [f64]) {}
        fn factor(&mut self, q: &[f64], _v: &[f64], _t: f64, c: IterationCoefficients) -> Result<f64> {
            self.s = c.mass + c.stiffness * (self.k + 3.0 * self.c * q[0] * q[0]);
            self.fresh = true;
            Ok(1.0)
        }
        fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
            rhs[0] /= if std::mem::take(&mut self.fresh) { self.s } else { self.stale * self.s };
            Ok(())
        }
        fn length_scale(&self) -> f64 {
            1.0
        }
    }

    /// A stiff undamped oscillator stepped far beyond its period (ωh = 10, ρ∞ = 1), the
    /// regime of a stiff element's axial vibration in a multibody run: the zero-acceleration
    /// start carries the alternating acceleration into its guess, the constant-velocity one
    /// the vibration's velocity; the adaptive start takes mostly the position the step
    /// started from, also after guided steps, and needs about that start's iterations.
    #[test]
    fn the_adaptive_start_leaves_a_stiff_undamped_vibration_s_accelerations_out() {
        let spring = || Spring { k: 1e6, c: 1e8, noise: 0.0, stale: 1.0, s: 0.0, fresh: false, nan_below: -1e9 };
        let with = |predictor| IntegratorParams { rho_inf: 1.0, predictor, ..IntegratorParams::default() };
        let its = |p| run(spring(), 1e-2, 1e-2, with(p)).1.newton_iterations;
        let (za, cv, cp, ad) = (
            its(Predictor::ZeroAcceleration),
            its(Predictor::ConstantVelocity),
            its(Predictor::ConstantPosition),
            its(Predictor::Adaptive),
        );
        eprintln!("iterations: zero acceleration {za}, constant velocity {cv}, constant position {cp}, adaptive {ad}");
        // measured: 328, 247, 163, 173
        assert!(
            ad < za.min(cv) && ad as f64 <= 1.1 * cp as f64,
            "adaptive {ad}, zero acceleration {za}, constant velocity {cv}, constant position {cp}"
        );
        // which start each step took: the adaptive one, mostly the position it started from
        // (the vibration's velocity ω|q| carries the constant-velocity guess ωh = 10 times
        // its amplitude away)
        let starts = |p| {
            let s = run(spring(), 1e-2, 1e-2, with(p)).1;
            (s.constant_velocity_starts, s.constant_position_starts)
        };
        assert_eq!(starts(Predictor::ZeroAcceleration), (0, 0));
        assert_eq!(starts(Predictor::ConstantVelocity), (50, 0));
        assert_eq!(starts(Predictor::ConstantPosition), (0, 50));
        let (velocity, position) = starts(Predictor::Adaptive);
        eprintln!("adaptive: {velocity} of 50 steps from constant velocity, {position} from constant position");
        // measured: 8 and 39 (the first step is always one of the constant-velocity ones)
        assert!(position >= 30, "{velocity}, {position}");
        // a guided step (a continuation sweep's) judges too: a zero-acceleration choice gives
        // way after one (measured: q₁ = −9.3e-3 from q₀ = 1e-2 at rest, where the
        // zero-acceleration guess h²/4 q̈₀ = −0.25 misses by 0.23, the two others by 0.019:
        // a tie, to constant velocity)
        let (mut m, mut integ) = (spring(), GeneralizedAlpha::new(with(Predictor::Adaptive)).unwrap());
        let mut st = integ.initialize(&mut m, vec![1e-2], vec![0.0], 0.0).unwrap();
        assert_eq!(integ.next_start, Predictor::ConstantVelocity);
        integ.next_start = Predictor::ZeroAcceleration;
        integ.step_guided(&mut m, &mut st, 1e-2, Some(&[0.0])).unwrap();
        assert_eq!(integ.next_start, Predictor::ConstantVelocity);
    }

    /// A step that fails from the adaptive start's choice is retried from the position it
    /// started at before it is halved. The stiff undamped spring's first step from q₀ =
    /// 1e-2 at rest, with 6 Newton iterations allowed: from zero acceleration (the guess
    /// h²/4 q̈₀ = −0.25, 25 times the amplitude, deep in the cubic force, where Newton
    /// crawls at θ = ⅔) it fails and is halved; the adaptive start made to choose zero
    /// acceleration fails the same way, takes the step from q₀ at its retry, and halves
    /// nothing. With full Newton (no retry) its halves start from q₀.
    #[test]
    fn a_failed_start_is_retried_from_the_step_s_start_before_halving() {
        let spring = || Spring { k: 1e6, c: 1e8, noise: 0.0, stale: 1.0, s: 0.0, fresh: false, nan_below: -1e9 };
        let step = |predictor, reuse, choice| {
            let params = IntegratorParams { rho_inf: 1.0, predictor, reuse, max_iterations: 6, ..Default::default() };
            let (mut m, mut integ) = (spring(), GeneralizedAlpha::new(params).unwrap());
            let mut st = integ.initialize(&mut m, vec![1e-2], vec![0.0], 0.0).unwrap();
            integ.next_start = choice;
            integ.step(&mut m, &mut st, 1e-2).unwrap();
            eprintln!("{predictor:?} {reuse:?}: {:?}", integ.stats);
            integ.stats
        };
        let za = Predictor::ZeroAcceleration;
        let fixed = step(za, JacobianReuse::WithinStep, za);
        assert!(fixed.step_cuts >= 1, "{fixed:?}");
        let adaptive = step(Predictor::Adaptive, JacobianReuse::WithinStep, za);
        assert_eq!((adaptive.step_cuts, adaptive.constant_position_starts), (0, 1), "{adaptive:?}");
        let full_newton = step(Predictor::Adaptive, JacobianReuse::Never, za);
        assert!(full_newton.step_cuts >= 1, "{full_newton:?}");
        assert_eq!(full_newton.zero_acceleration_starts, 0, "the halves start from q₀: {full_newton:?}");
    }

    /// 50 steps of `h` from q = q₀ at rest; the positions after each step and the stats.
    /// A mass `m` on a spring `k` whose one coordinate a moving constraint prescribes,
    /// `q − b(t) = 0` with `b = v₀ t + ½ a t²`: the rheonomic seam of [`DynamicModel`].
    /// The KKT matrix `[S, s; s, 0]` is solved in closed form.
    struct Prescribed {
        m: f64,
        k: f64,
        v0: f64,
        a: f64,
        s: f64,
        diag: f64,
    }

    impl DynamicModel for Prescribed {
        fn n_dof(&self) -> usize {
            1
        }
        fn n_constraints(&self) -> usize {
            1
        }
        fn mass_mul(&self, a: &[f64], out: &mut [f64]) {
            out[0] = self.m * a[0];
        }
        fn force(&mut self, q: &[f64], _v: &[f64], _t: f64, out: &mut [f64]) {
            out[0] = self.k * q[0];
        }
        fn constraint_residual(&self, q: &[f64], t: f64, out: &mut [f64]) {
            out[0] = q[0] - (self.v0 * t + 0.5 * self.a * t * t);
        }
        fn constraint_velocity_rhs(&self, _q: &[f64], t: f64, out: &mut [f64]) {
            out[0] = self.v0 + self.a * t;
        }
        fn constraint_acceleration_rhs(&self, _q: &[f64], _v: &[f64], _t: f64, out: &mut [f64]) {
            out[0] = self.a;
        }
        fn add_constraint_force(&self, lambda: &[f64], _t: f64, out: &mut [f64]) {
            out[0] += lambda[0];
        }
        fn factor(&mut self, _q: &[f64], _v: &[f64], _t: f64, c: IterationCoefficients) -> Result<f64> {
            self.diag = c.mass * self.m + c.stiffness * self.k;
            Ok(self.s)
        }
        fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
            // [d, s; s, 0] [x; y] = [f; g]: x = g/s, y = (f − d x)/s
            let (f, g) = (rhs[0], rhs[1]);
            let x = g / self.s;
            rhs[0] = x;
            rhs[1] = (f - self.diag * x) / self.s;
            Ok(())
        }
        fn length_scale(&self) -> f64 {
            1.0
        }
    }

    /// The start takes the constraint's acceleration level (`q̈₀ = a`, the multiplier
    /// `λ₀ = −(m a + k q₀)` from `m q̈ + k q + λ = 0`) and each step its position level at
    /// the step's end time: `q(tₙ) = v₀ tₙ + ½ a tₙ²` to round-off (a constraint read at
    /// the step's start would lag a step behind).
    #[test]
    fn a_moving_constraint_is_met_at_each_step_s_end_and_at_the_start_s_acceleration_level() {
        let mut m = Prescribed { m: 2.0, k: 50.0, v0: 0.3, a: -1.5, s: 4.0, diag: 0.0 };
        let mut integ = GeneralizedAlpha::new(IntegratorParams::default()).unwrap();
        let mut st = integ.initialize(&mut m, vec![0.0], vec![0.3], 0.0).unwrap();
        assert!((st.qdd[0] - -1.5).abs() < 1e-15, "{}", st.qdd[0]);
        assert!((st.lambda[0] - 3.0).abs() < 1e-14, "{}", st.lambda[0]);
        let h = 0.01;
        for n in 1..=20 {
            integ.step(&mut m, &mut st, h).unwrap();
            let t = n as f64 * h;
            let b = 0.3 * t - 0.75 * t * t;
            assert!((st.q[0] - b).abs() < 1e-14, "step {n}: q {} against b {b}", st.q[0]);
            // the multiplier holds the mass on its path: λ = −(m a + k b)
            assert!((st.lambda[0] - (3.0 - 50.0 * b)).abs() < 1e-9, "step {n}: λ {}", st.lambda[0]);
        }
    }

    fn run(mut m: Spring, q0: f64, h: f64, params: IntegratorParams) -> (Vec<f64>, Stats) {
        let mut integ = GeneralizedAlpha::new(params).unwrap();
        let mut st = integ.initialize(&mut m, vec![q0], vec![0.0], 0.0).unwrap();
        let mut q = Vec::new();
        for _ in 0..50 {
            integ.step(&mut m, &mut st, h).unwrap();
            q.push(st.q[0]);
        }
        (q, integ.stats)
    }

    /// A residual that turns NaN (a force undefined past q = 0) fails the step instead of
    /// being taken as converged: `f64::max` passes a NaN by, so a maximum of NaN entries
    /// read 0 and the NaN state was accepted.
    #[test]
    fn a_nan_residual_fails_the_step() {
        let mut m = Spring { k: 100.0, c: 0.0, noise: 0.0, stale: 1.0, s: 1.0, fresh: false, nan_below: 0.0 };
        let mut integ = GeneralizedAlpha::new(IntegratorParams { max_cuts: 2, ..IntegratorParams::default() }).unwrap();
        let mut st = integ.initialize(&mut m, vec![0.5], vec![0.0], 0.0).unwrap();
        // q = 0.5 cos(10 t) reaches 0 at t ≈ 0.157: a step ends there or later
        let mut failed = false;
        for _ in 0..20 {
            match integ.step(&mut m, &mut st, 0.02) {
                Ok(()) => assert!(st.q[0].is_finite() && st.q[0] >= 0.0, "accepted q = {} at t = {}", st.q[0], st.t),
                Err(_) => {
                    failed = true;
                    break;
                }
            }
        }
        assert!(failed, "the run went past q = 0");
    }

    /// A kept matrix that stops contracting (θ = 0.6 > ½) is stale, not at the round-off
    /// floor: it is refreshed, and a noise-free residual never has a step accepted at the
    /// floor (each step then ends on the tolerance with a fresh matrix); under full Newton
    /// the stale solves never happen at all.
    #[test]
    fn a_stale_kept_matrix_is_refreshed_not_taken_for_the_floor() {
        for reuse in [JacobianReuse::WithinStep, JacobianReuse::Never] {
            let spring =
                Spring { k: 100.0, c: 1e4, noise: 0.0, stale: 2.5, s: 1.0, fresh: false, nan_below: f64::NEG_INFINITY };
            let (_, stats) = run(spring, 0.5, 0.05, IntegratorParams { reuse, ..IntegratorParams::default() });
            assert_eq!((stats.steps_at_round_off, stats.step_cuts), (0, 0), "{reuse:?}: {stats:?}");
            if reuse == JacobianReuse::WithinStep {
                assert!(stats.factorizations < stats.newton_iterations, "matrices were kept: {stats:?}");
            }
        }
    }

    /// With residual noise A = 0.02 the Newton increments cannot fall below about
    /// A/β' ≈ 6e-7 (β' ≈ 3e4 the iteration matrix's mass coefficient at h = 0.01), between
    /// the tolerance 1e-10 and the default bound 1e-6: without the bound the steps stagnate
    /// and are halved until the noise is small enough; with it they are accepted at the
    /// floor, and the trajectory stays closer to the noise-free one than the halved run.
    #[test]
    fn stagnation_at_the_round_off_floor_is_accepted() {
        let run = |noise: f64, stagnation: f64| {
            let spring =
                Spring { k: 100.0, c: 0.0, noise, stale: 1.0, s: 1.0, fresh: false, nan_below: f64::NEG_INFINITY };
            // a fixed start: the adaptive one retries a failed step from another start, which
            // the noise may let through by chance
            let params = IntegratorParams { stagnation, predictor: Predictor::ZeroAcceleration, ..Default::default() };
            run(spring, 1.0, 0.01, params)
        };
        let (exact, clean) = run(0.0, 1e-6);
        assert_eq!((clean.step_cuts, clean.steps_at_round_off), (0, 0), "{clean:?}");
        let (cut, strict) = run(0.02, 0.0);
        assert!(strict.step_cuts > 0 && strict.steps_at_round_off == 0, "{strict:?}");
        // each halved step is listed once, by its start: a point of the regular grid k h
        // (k < 50 steps of h = 0.01), in increasing order, never more than the cuts
        let times = &strict.step_cut_times;
        assert!(!times.is_empty() && times.len() <= strict.step_cuts, "{strict:?}");
        assert!(times.windows(2).all(|w| w[0] < w[1]), "{times:?}");
        assert!(times.iter().all(|t| (t / 0.01 - (t / 0.01).round()).abs() < 1e-9 && *t < 0.5), "{times:?}");
        assert!(clean.step_cut_times.is_empty(), "{clean:?}");
        let (floor, stats) = run(0.02, 1e-6);
        assert_eq!(stats.step_cuts, 0, "{stats:?}");
        assert!(stats.steps_at_round_off > 0, "{stats:?}");
        let err = |a: &[f64]| a.iter().zip(&exact).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        // the noise itself moves each step's root by about A/β' ≈ 6e-7 in q and γ' times
        // that (≈ 1e-4) in q̇, so over 0.5 s the trajectory is off by ~1e-4 either way; the
        // halved steps add a change of discretization on top
        assert!(err(&floor) < 3e-4 && err(&floor) < err(&cut), "{} {}", err(&floor), err(&cut));
    }
}
