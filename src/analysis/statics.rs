//! Static equilibrium by load stepping (SPEC §6):
//!
//! ```text
//! F_int(q) − s Q_ext(q, t; μ) + Bᵀλ = 0,   B q = b,   s = 1/N, 2/N, …, 1
//! ```
//!
//! each step solved by Newton on the KKT system with the tangent `K_s` ([`super::ramp`],
//! [`crate::solver::statics::solve_static`]) from the previous equilibrium. A step whose
//! Newton fails is halved (from the last equilibrium reached), up to [`MAX_CUTS`] times in a
//! row; a step that succeeds lets the next one grow back toward `1/N`. One equilibrium is
//! kept per load step `k/N`, the full load's last. Where no step can be taken, the
//! tangent's free motions at the last equilibrium ([`super::free_motion`]) say why.

use super::free_motion::{describe_failure, free_motions};
use super::ramp::Ramped;
use crate::error::{Error, Result};
use crate::linalg::kkt::LinearSolverKind;
use crate::physics::system::FlexibleSystem;
use crate::solver::model::Parameters;
use crate::solver::statics::solve_static;

/// Halvings of one load step before statics gives up: a step of 2⁻¹² of the nominal one.
pub const MAX_CUTS: u32 = 12;
/// Newton iterations per attempt.
pub const MAX_ITERATIONS: usize = 30;
/// Newton's convergence bound on the increment, relative to the system's length scale.
pub const TOLERANCE: f64 = 1e-11;

/// What statics is asked for.
#[derive(Clone, Debug)]
pub struct StaticOptions {
    /// the parameters of the loads
    pub mu: Parameters,
    /// the time at which the loads are taken, s
    pub t: f64,
    /// the number of equal load steps `N ≥ 1`
    pub steps: usize,
    pub solver: LinearSolverKind,
}

impl Default for StaticOptions {
    fn default() -> Self {
        StaticOptions { mu: Parameters::default(), t: 0.0, steps: 1, solver: LinearSolverKind::Banded }
    }
}

/// One equilibrium of the load stepping.
#[derive(Clone, Debug)]
pub struct StaticStep {
    /// the fraction `s` of the loads
    pub load_factor: f64,
    pub q: Vec<f64>,
    /// the multipliers `λ` (N; N·m on clamp slope rows)
    pub lambda: Vec<f64>,
    /// Newton iterations of the attempts that reached it (since the previous kept step)
    pub iterations: usize,
}

/// The equilibria at `1/N, …, 1` of the loads and the work it took.
#[derive(Clone, Debug)]
pub struct StaticSolution {
    pub steps: Vec<StaticStep>,
    pub newton_iterations: usize,
    pub factorizations: usize,
    pub step_cuts: usize,
}

impl StaticSolution {
    /// The equilibrium under the whole load.
    pub fn equilibrium(&self) -> &StaticStep {
        self.steps.last().expect("at least one load step")
    }
}

/// The static equilibrium of `sys` under `o`'s loads, from `q0` (a consistent state, at
/// rest under no load: the undeformed one). Fails with [`Error::Option`] for `N = 0` or a
/// time that is not finite, and with a numerical error naming the load reached and the
/// free motions of the tangent when a step cannot be taken.
pub fn solve(sys: &mut FlexibleSystem, q0: Vec<f64>, o: &StaticOptions) -> Result<StaticSolution> {
    if o.steps == 0 {
        return Err(Error::option("steps", None, "must be at least 1"));
    }
    if !o.t.is_finite() {
        return Err(Error::option("time", None, format!("must be finite, got {}", o.t)));
    }
    o.mu.validate()?;
    let nominal = 1.0 / o.steps as f64;
    let mut model = Ramped::new(sys, &o.mu, o.solver);
    let mut out =
        StaticSolution { steps: Vec::with_capacity(o.steps), newton_iterations: 0, factorizations: 0, step_cuts: 0 };
    let (mut q, mut s, mut ds, mut cuts, mut since) = (q0, 0.0_f64, nominal, 0_u32, 0_usize);
    let mut k = 1;
    while k <= o.steps {
        crate::interrupt::check()?;
        let target = k as f64 / o.steps as f64;
        let next = if s + ds >= target * (1.0 - 1e-12) { target } else { s + ds };
        model.factor = next;
        let mut trial = q.clone();
        match solve_static(&mut model, &mut trial, o.t, TOLERANCE, MAX_ITERATIONS) {
            Ok((lambda, it)) => {
                out.newton_iterations += it;
                out.factorizations += it;
                since += it;
                q = trial;
                s = next;
                cuts = 0;
                ds = (2.0 * ds).min(nominal);
                if next == target {
                    out.steps.push(StaticStep { load_factor: next, q: q.clone(), lambda, iterations: since });
                    since = 0;
                    k += 1;
                }
            }
            Err(e) if e.is_numerical() => {
                out.step_cuts += 1;
                cuts += 1;
                ds *= 0.5;
                if cuts > MAX_CUTS {
                    let motions = free_motions(&mut model, &q, o.t)?;
                    return Err(describe_failure(s, next, MAX_CUTS, &motions, e));
                }
            }
            Err(e) => return Err(e),
        }
    }
    Ok(out)
}
