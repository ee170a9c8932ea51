//! The interface between a mechanical model and the time integrator. The full ANCF system
//! and every reduced model implement it, so they share one integrator.
//!
//! The model describes the index-3 DAE
//!
//! ```text
//!     M q̈ + g(q, q̇, t) + Bᵀλ = 0,      B q − b = 0,
//!     g(q, q̇, t) = C q̇ + Q_e(q) − Q_ext(q, t)
//! ```
//!
//! with constant `M`, `B`, `b` (joints are linear in ANCF coordinates, SPEC §2).

/// Coefficients of the iteration matrix `S = m·M + c·C_t + k·K_t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterationCoefficients {
    pub mass: f64,
    pub damping: f64,
    pub stiffness: f64,
}

pub trait DynamicModel {
    fn n_dof(&self) -> usize;
    fn n_constraints(&self) -> usize;
    /// `out = M a`
    fn mass_mul(&self, a: &[f64], out: &mut [f64]);
    /// `out = g(q, q̇, t) = C q̇ + Q_e(q) − Q_ext(q, t)`
    fn force(&mut self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]);
    /// `out = B q − b`
    fn constraint_residual(&self, q: &[f64], out: &mut [f64]);
    /// `out += Bᵀ λ`
    fn add_constraint_force(&self, lambda: &[f64], out: &mut [f64]);
    /// Assembles and factors `[S, s Bᵀ; s B, 0]` with `S = m M + c ∂g/∂q̇ + k ∂g/∂q`
    /// at `(q, q̇, t)`, choosing the constraint scale `s` so that both block rows are of the
    /// same magnitude; returns `s`.
    fn factor(&mut self, q: &[f64], v: &[f64], t: f64, coef: IterationCoefficients) -> Result<f64, String>;
    /// Solves in place with the last factorization; `rhs` has `n_dof + n_constraints` entries.
    fn solve(&mut self, rhs: &mut [f64]) -> Result<(), String>;
    /// A length that sets the absolute scale of coordinate increments (for convergence tests).
    fn length_scale(&self) -> f64;
}
