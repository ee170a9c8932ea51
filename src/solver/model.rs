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
    /// The largest mean axial strain `max_e |ε̄ₑ|` (SPEC §1) at `q` and its element, over
    /// the elements the model evaluates (a hyper-reduced model: its sampled ones, at the
    /// last Newton iterate); `None` when the model cannot tell. Feeds the blow-up check.
    fn max_strain(&self, _q: &[f64]) -> Option<(f64, usize)> {
        None
    }
}

/// A model assembled from elements with fixed dof lists and a few nodal loads, opened up so
/// that a reduction can project it element by element (and hyper-reduction can visit only
/// some elements). The physics implements it; the reduction knows nothing else about it.
///
/// ```text
///     g(q, q̇, t) = Σ_e Aₑᵀ fₑ(qₑ, q̇ₑ) + g₀ + A_lᵀ g_l(q_l, t)
/// ```
///
/// with `fₑ` the element forces (internal and damping), `g₀` the constant applied loads
/// (gravity, entering with a minus sign) and `g_l` the state- or time-dependent nodal loads
/// on the dofs `load_dofs()`.
pub trait ElementModel: DynamicModel {
    fn n_elements(&self) -> usize;
    /// Global dofs of element `e`; every element has the same number of them.
    fn element_dofs(&self, e: usize) -> &[usize];
    /// `fₑ = Cₑ q̇ₑ + Qₑ(qₑ)` from the element's own coordinates.
    fn element_force(&self, e: usize, qe: &[f64], ve: &[f64], out: &mut [f64]);
    /// `c Cₑ + k ∂Qₑ/∂qₑ` (no mass term), column-major.
    fn element_matrix(&self, e: usize, qe: &[f64], coef: IterationCoefficients, out: &mut [f64]);
    /// `g₀`: the part of `g` that depends on neither `q`, `q̇` nor `t`.
    fn constant_force(&self, out: &mut [f64]);
    /// The dofs the state- or time-dependent loads act on (and depend on).
    fn load_dofs(&self) -> Vec<usize>;
    /// `g_l(q_l, t)` on `load_dofs()`, given `q` on the same dofs.
    fn load_force(&self, ql: &[f64], t: f64, out: &mut [f64]);
    /// `∂g_l/∂q_l` (column-major, `load_dofs().len()` square).
    fn load_jacobian(&self, ql: &[f64], t: f64, out: &mut [f64]);
}

/// An [`ElementModel`] whose element forces are a constant linear part plus a part that
/// depends on the coordinates only through a few quadratic invariants `s_j = qₑᵀ Sⱼ qₑ`
/// (constant symmetric `Sⱼ`) of an energy `Û(s)`:
///
/// ```text
///     fₑ(qₑ, q̇ₑ) = Cₑ q̇ₑ + Lₑ qₑ + Σ_j 2ψⱼ Sⱼ qₑ,          ψⱼ = ∂Û/∂s_j,
///     ∂fₑ/∂qₑ   = Lₑ + Σ_j 2ψⱼ Sⱼ + Σ_jk 4ψⱼₖ (Sⱼ qₑ)(Sₖ qₑ)ᵀ,   ψⱼₖ = ∂²Û/∂s_j∂s_k.
/// ```
///
/// A reduction can then project `Lₑ`, `Cₑ` once and precompute `Vₑᵀ Sⱼ Vₑ` per element,
/// so that the reduced tangent of an element costs O(r²) instead of O(8 r²) (SPEC §1:
/// Berzeri–Shabana has `L = K_t`, one invariant `s = eᵀS_l e`, `Û = ½EAl(s/(2l) − ½)²`).
pub trait InvariantElementModel: ElementModel {
    /// Number of invariants per element (the same for every element).
    fn n_invariants(&self) -> usize;
    /// `Lₑ` and `Cₑ`, column-major; both symmetric (elastic stiffness from an energy,
    /// Rayleigh damping), so that the reduced Newton matrix is.
    fn element_linear(&self, e: usize, stiffness: &mut [f64], damping: &mut [f64]);
    /// `Sⱼ` of element `e`, column-major.
    fn element_invariant_matrix(&self, e: usize, j: usize, out: &mut [f64]);
    /// `ψⱼ` and `ψⱼₖ` (column-major, `n_invariants()` square) at the invariants `s`.
    fn invariant_derivatives(&self, e: usize, s: &[f64], d1: &mut [f64], d2: &mut [f64]);
    /// The element's mean axial strain from its invariants, when the model defines one
    /// (the blow-up check); `None` by default.
    fn invariant_strain(&self, _e: usize, _s: &[f64]) -> Option<f64> {
        None
    }
}
