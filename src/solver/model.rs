//! The interface between a mechanical model and the time integrator. The full ANCF system
//! and every reduced model implement it, so they share one integrator.
//!
//! The model describes the index-3 DAE
//!
//! ```text
//!     M q̈ + g(q, q̇, t) + Bᵀλ = 0,      B(t) q − b(t) = 0,
//!     g(q, q̇, t) = C q̇ + Q_e(q) − Q_ext(q, t)
//! ```
//!
//! with constant `M` and joints linear in ANCF coordinates (SPEC §2), whose rows may move
//! with time (a prescribed motion). Differentiating the constraints gives the velocity and
//! acceleration levels the start of a run needs:
//!
//! ```text
//!     B q̇ = ḃ − Ḃ q,        B q̈ = b̈ − Ḃ q̇ − (d/dt)(Ḃ q) = b̈ − 2Ḃ q̇ − B̈ q =: c(q, q̇, t)
//! ```
//!
//! (both right-hand sides vanish for constant `B`, `b`, the default). A model's
//! loads depend on the run's parameters μ ([`super::parameters`]): models implement
//! [`ParametricModel`], and the integrator sees one bound to a run's μ.

pub use super::parameters::Parameters;
use crate::error::Result;

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
    /// `(force, inertia) = (g(q, q̇, t), M a)` together, the two parts of every Newton
    /// residual: a model may evaluate both in one pass over its elements (the full system
    /// does). The same values as [`Self::force`] and [`Self::mass_mul`].
    fn force_and_inertia(&mut self, q: &[f64], v: &[f64], a: &[f64], t: f64, out: (&mut [f64], &mut [f64])) {
        let (force, inertia) = out;
        self.mass_mul(a, inertia);
        self.force(q, v, t, force);
    }
    /// `out = B(t) q − b(t)`
    fn constraint_residual(&self, q: &[f64], t: f64, out: &mut [f64]);
    /// `out = ḃ − Ḃ q`, what `B q̇` must equal at `t`: zero for constant constraints.
    fn constraint_velocity_rhs(&self, _q: &[f64], _t: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
    }
    /// `out = c(q, q̇, t) = b̈ − 2Ḃ q̇ − B̈ q`, what `B q̈` must equal: zero for constant
    /// constraints.
    fn constraint_acceleration_rhs(&self, _q: &[f64], _v: &[f64], _t: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
    }
    /// `out += B(t)ᵀ λ`
    fn add_constraint_force(&self, lambda: &[f64], t: f64, out: &mut [f64]);
    /// Assembles and factors `[S, s Bᵀ; s B, 0]` with `S = m M + c ∂g/∂q̇ + k ∂g/∂q`
    /// at `(q, q̇, t)`, choosing the constraint scale `s` so that both block rows are of the
    /// same magnitude; returns `s`.
    fn factor(&mut self, q: &[f64], v: &[f64], t: f64, coef: IterationCoefficients) -> Result<f64>;
    /// Solves in place with the last factorization; `rhs` has `n_dof + n_constraints` entries.
    fn solve(&mut self, rhs: &mut [f64]) -> Result<()>;
    /// A length that sets the absolute scale of coordinate increments (for convergence tests).
    fn length_scale(&self) -> f64;
    /// The largest mean axial strain `max_e |ε̄ₑ|` (SPEC §1) at `q` and its element, over
    /// the elements the model evaluates (a hyper-reduced model: its sampled ones, at the
    /// last Newton iterate); `None` when the model cannot tell. Feeds the blow-up check.
    fn max_strain(&self, _q: &[f64]) -> Option<(f64, usize)> {
        None
    }
}

/// The model side of the DAE of [`DynamicModel`] with the parameters an argument of the
/// evaluations that depend on them (`force`, `factor`), so that one model runs at any
/// parameters without being changed between runs. The full system and every reduced model
/// implement it; [`Bound`] hands one, at fixed parameters, to the integrator.
///
/// The methods take `&mut self` where the model keeps its Newton work space (the KKT
/// factorization, cached element coordinates): one model serves one run at a time, so a
/// parallel sweep keeps one model per thread. What depends on the parameters and is kept
/// between calls (a body property's element prototypes, a reduced model's mass) is set by
/// [`ParametricModel::bind`] and again by every evaluation that takes μ, so nothing of one
/// run's parameters leaks into the next.
pub trait ParametricModel {
    /// Sets what the model keeps between evaluations to the parameters `mu` (a body's
    /// density changes its mass, which [`Self::mass_mul`] applies without taking μ); the
    /// integrator's [`Bound`] calls it first. Nothing to do by default.
    fn bind(&mut self, _mu: &Parameters) {}
    fn n_dof(&self) -> usize;
    fn n_constraints(&self) -> usize;
    /// `out = M a`
    fn mass_mul(&self, a: &[f64], out: &mut [f64]);
    /// `out = g(q, q̇, t; μ)`
    fn force(&mut self, mu: &Parameters, q: &[f64], v: &[f64], t: f64, out: &mut [f64]);
    /// [`DynamicModel::force_and_inertia`] at the parameters `mu`.
    fn force_and_inertia(
        &mut self,
        mu: &Parameters,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        t: f64,
        out: (&mut [f64], &mut [f64]),
    ) {
        let (force, inertia) = out;
        // the mass at μ (a density parameter), before mass_mul, which does not take μ
        self.bind(mu);
        self.mass_mul(a, inertia);
        self.force(mu, q, v, t, force);
    }
    /// `out = B(t) q − b(t)` at the parameters `mu` (a prescribed motion's factor)
    fn constraint_residual(&self, mu: &Parameters, q: &[f64], t: f64, out: &mut [f64]);
    /// `out = ḃ − Ḃ q`, what `B q̇` must equal at `t`: zero for constant constraints.
    fn constraint_velocity_rhs(&self, _mu: &Parameters, _q: &[f64], _t: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
    }
    /// `out = c(q, q̇, t) = b̈ − 2Ḃ q̇ − B̈ q`, what `B q̈` must equal: zero for constant
    /// constraints.
    fn constraint_acceleration_rhs(&self, _mu: &Parameters, _q: &[f64], _v: &[f64], _t: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
    }
    /// `out += B(t)ᵀ λ`
    fn add_constraint_force(&self, mu: &Parameters, lambda: &[f64], t: f64, out: &mut [f64]);
    /// [`DynamicModel::factor`] at the parameters `mu`.
    fn factor(&mut self, mu: &Parameters, q: &[f64], v: &[f64], t: f64, coef: IterationCoefficients) -> Result<f64>;
    /// [`DynamicModel::solve`]
    fn solve(&mut self, rhs: &mut [f64]) -> Result<()>;
    fn length_scale(&self) -> f64;
    /// [`DynamicModel::max_strain`]
    fn max_strain(&self, _q: &[f64]) -> Option<(f64, usize)> {
        None
    }
    /// A run starts: forget what was kept from earlier evaluations (products kept by
    /// increments), so that a run does not depend on the runs before it. Nothing by default.
    fn start_run(&mut self) {}
}

/// A model bound to the parameters of one run: what the integrator sees.
pub struct Bound<'a, M: ?Sized> {
    pub model: &'a mut M,
    pub mu: Parameters,
}

impl<'a, M: ParametricModel + ?Sized> Bound<'a, M> {
    pub fn new(model: &'a mut M, mu: &Parameters) -> Self {
        model.start_run();
        model.bind(mu);
        Bound { model, mu: mu.clone() }
    }
}

impl<M: ParametricModel + ?Sized> DynamicModel for Bound<'_, M> {
    fn n_dof(&self) -> usize {
        self.model.n_dof()
    }
    fn n_constraints(&self) -> usize {
        self.model.n_constraints()
    }
    fn mass_mul(&self, a: &[f64], out: &mut [f64]) {
        self.model.mass_mul(a, out)
    }
    fn force(&mut self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        self.model.force(&self.mu, q, v, t, out)
    }
    fn force_and_inertia(&mut self, q: &[f64], v: &[f64], a: &[f64], t: f64, out: (&mut [f64], &mut [f64])) {
        self.model.force_and_inertia(&self.mu, q, v, a, t, out)
    }
    fn constraint_residual(&self, q: &[f64], t: f64, out: &mut [f64]) {
        self.model.constraint_residual(&self.mu, q, t, out)
    }
    fn constraint_velocity_rhs(&self, q: &[f64], t: f64, out: &mut [f64]) {
        self.model.constraint_velocity_rhs(&self.mu, q, t, out)
    }
    fn constraint_acceleration_rhs(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        self.model.constraint_acceleration_rhs(&self.mu, q, v, t, out)
    }
    fn add_constraint_force(&self, lambda: &[f64], t: f64, out: &mut [f64]) {
        self.model.add_constraint_force(&self.mu, lambda, t, out)
    }
    fn factor(&mut self, q: &[f64], v: &[f64], t: f64, coef: IterationCoefficients) -> Result<f64> {
        self.model.factor(&self.mu, q, v, t, coef)
    }
    fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
        self.model.solve(rhs)
    }
    fn length_scale(&self) -> f64 {
        self.model.length_scale()
    }
    fn max_strain(&self, q: &[f64]) -> Option<(f64, usize)> {
        self.model.max_strain(q)
    }
}

/// A model assembled from elements with fixed dof lists and a few nodal loads, opened up so
/// that a reduction can project it element by element (and hyper-reduction can visit only
/// some elements). The physics implements it; the reduction knows nothing else about it.
///
/// ```text
///     g(q, q̇, t) = Σ_e Aₑᵀ fₑ(qₑ, q̇ₑ) + g₀ + A_lᵀ g_l(q_l, q̇_l, t)
/// ```
///
/// with `fₑ` the element forces (internal and damping), `g₀` the constant applied loads
/// (gravity, entering with a minus sign) and `g_l` the state- or time-dependent nodal loads
/// on the dofs `load_dofs()` (moments, forces, and spring-dampers, which read the velocities
/// too). Both are affine in the load scale `λ` of the parameters μ:
/// `g₀(μ) = g₀,fixed + λ g₀,scaled`, and `g_l` takes μ.
///
/// The element terms are those of the model file's own values. A parameter may scale an
/// element's stiffness (Young's modulus as a parameter): then the model's elastic force at μ
/// is `sₑ(μ) Qₑ` and its tangent `sₑ(μ) ∂Qₑ/∂qₑ`, with `sₑ` = [`ElementModel::stiffness_factor`],
/// so the model stays affine in `sₑ`: a reduction sums the elements that share a parameter
/// apart and scales each sum at μ. A parameter may scale an element's mass likewise
/// (density as a parameter, [`ElementModel::mass_factor`]): its mass and its share of `g₀`
/// (gravity) scale by `mₑ(μ)`, and a reduction projects them per group
/// ([`ElementModel::group_mass_mul`], [`ElementModel::group_constant_forces`]). The damping
/// of such an element splits into a part that follows its mass and one that follows its
/// stiffness (Rayleigh `a Mₑ + b Kₑ`, [`ElementModel::element_damping_parts`]):
///
/// ```text
///     fₑ(qₑ, q̇ₑ; μ) = sₑ(μ) Qₑ(qₑ) + (mₑ(μ) Cₑ,m + sₑ(μ) Cₑ,s) q̇ₑ,    Cₑ = Cₑ,m + Cₑ,s.
/// ```
pub trait ElementModel: ParametricModel {
    fn n_elements(&self) -> usize;
    /// Global dofs of element `e`; every element has the same number of them.
    fn element_dofs(&self, e: usize) -> &[usize];
    /// `fₑ = Cₑ q̇ₑ + Qₑ(qₑ)` from the element's own coordinates.
    fn element_force(&self, e: usize, qe: &[f64], ve: &[f64], out: &mut [f64]);
    /// `c Cₑ + k ∂Qₑ/∂qₑ` (no mass term), column-major.
    fn element_matrix(&self, e: usize, qe: &[f64], coef: IterationCoefficients, out: &mut [f64]);
    /// The dofs the state- or time-dependent loads act on (and depend on).
    fn load_dofs(&self) -> Vec<usize>;
    /// `g_l(q_l, q̇_l, t; μ)` on `load_dofs()`, given `q` and `q̇` on the same dofs (`q̇`
    /// is read only when [`Self::load_has_damping`]: a caller may pass zeros otherwise).
    fn load_force(&self, mu: &Parameters, ql: &[f64], vl: &[f64], t: f64, out: &mut [f64]);
    /// `∂g_l/∂q_l` at μ (column-major, `load_dofs().len()` square).
    fn load_jacobian(&self, mu: &Parameters, ql: &[f64], vl: &[f64], t: f64, out: &mut [f64]);
    /// Whether `g_l` depends on the velocities (a damper between nodes).
    fn load_has_damping(&self) -> bool {
        false
    }
    /// `∂g_l/∂q̇_l` at μ (column-major, `load_dofs().len()` square), when
    /// [`Self::load_has_damping`].
    fn load_damping_jacobian(&self, _mu: &Parameters, _ql: &[f64], _vl: &[f64], _t: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
    }
    /// The parameter that scales element `e`'s stiffness, if any (elements that name the
    /// same parameter scale alike).
    fn stiffness_parameter(&self, _e: usize) -> Option<&str> {
        None
    }
    /// `sₑ(μ)`, the factor of element `e`'s force and tangent at μ (1 at the model file's
    /// values, and for an element no parameter scales).
    fn stiffness_factor(&self, _e: usize, _mu: &Parameters) -> f64 {
        1.0
    }
    /// The parameter that scales element `e`'s mass (and weight), if any.
    fn mass_parameter(&self, _e: usize) -> Option<&str> {
        None
    }
    /// `mₑ(μ)`, the factor of element `e`'s mass and weight at μ (1 at the file's values).
    fn mass_factor(&self, _e: usize, _mu: &Parameters) -> f64 {
        1.0
    }
    /// `Cₑ` in its two parts at the model file's values (column-major): `by_mass` scales with
    /// the element's mass factor `mₑ(μ)` (Rayleigh `a Mₑ`), `by_stiffness` with its stiffness
    /// factor `sₑ(μ)` (`b Kₑ`); their sum is the `Cₑ` of [`Self::element_force`]. A damped
    /// model gives them, so that a reduction can scale each part at μ; zeros by default (an
    /// undamped model).
    fn element_damping_parts(&self, _e: usize, by_mass: &mut [f64], by_stiffness: &mut [f64]) {
        by_mass.iter_mut().for_each(|x| *x = 0.0);
        by_stiffness.iter_mut().for_each(|x| *x = 0.0);
    }
    /// `out = M_g a` at the model file's values, `M_g` the mass of the elements whose
    /// [`Self::mass_parameter`] is `group` (`None`: those no parameter scales, every element
    /// of a model without mass parameters).
    fn group_mass_mul(&self, group: Option<&str>, a: &[f64], out: &mut [f64]);
    /// The part of `g₀` (what depends on neither `q`, `q̇` nor `t`) of the elements whose mass
    /// parameter is `group`, at the model file's values, in the parts `g₀,fixed`, `g₀,scaled`
    /// (times `λ`) and one per named parameter (`scaled = "name"`, times `μ_name`, 1 where μ
    /// does not set it): a reduction projects each once.
    fn group_constant_forces(&self, group: Option<&str>) -> ConstantForces;
    /// Whether the model has mass outside its elements that no parameter scales (point
    /// masses): [`Self::group_mass_mul`] and [`Self::group_constant_forces`] of the group
    /// `None` then carry it even where every element's mass is a parameter's.
    fn has_lumped_mass(&self) -> bool {
        false
    }
    /// The parameters that set mass outside the elements (a point mass's kg), each once: a
    /// group of [`mass_groups`] of its own, with no element, whose factor is
    /// [`Self::lumped_mass_factor`]. None by default.
    fn lumped_mass_parameters(&self) -> Vec<String> {
        Vec::new()
    }
    /// The factor `m(μ)/m_file` of the lumped mass the parameter `name` sets (1 where μ does
    /// not set it).
    fn lumped_mass_factor(&self, _name: &str, _mu: &Parameters) -> f64 {
        1.0
    }
    /// The constraint rows whose coefficients or right-hand side move with time (prescribed
    /// motions), each as (row index, the coordinates of its terms); none by default. A
    /// reduction evaluates these rows through [`Self::moving_row_at`] and projects the
    /// others once.
    fn moving_rows(&self) -> Vec<(usize, Vec<usize>)> {
        Vec::new()
    }
    /// The `order`-th time derivative (0, 1, 2) of moving row `k` (an index into
    /// [`Self::moving_rows`]) at μ and `t`: its coefficients into `coefs`, in the order of its
    /// coordinates; returns that of its right-hand side.
    fn moving_row_at(&self, _mu: &Parameters, _k: usize, _t: f64, _order: u32, coefs: &mut [f64]) -> f64 {
        coefs.iter_mut().for_each(|c| *c = 0.0);
        0.0
    }
    /// Each body's coordinates as a rigid motion moves them ([`RigidBody`]), for the balance
    /// of each body's momentum that reduced models read their joint reactions from; none by
    /// default (the reduced models' multipliers are then given as they come).
    fn rigid_bodies(&self) -> Vec<RigidBody> {
        Vec::new()
    }
}

/// A body's coordinates in `(x, y)` pairs as a rigid motion of the plane moves them: its
/// positions translate and turn, its slopes (directions) only turn. The body's elements must
/// be objective — their elastic forces do no work in such a motion — so that its balance of
/// momentum holds the joints' forces on it without them.
#[derive(Clone, Debug, PartialEq)]
pub struct RigidBody {
    pub positions: Vec<[usize; 2]>,
    pub slopes: Vec<[usize; 2]>,
    /// the body's length (m): its turn is read per unit length, in N as its forces
    pub length: f64,
}

/// The constant forces `g₀` of a model, or of a group of its elements, in parts:
/// `g₀(μ) = fixed + λ scaled + Σ μ_name named_name`.
pub struct ConstantForces {
    pub fixed: Vec<f64>,
    pub scaled: Vec<f64>,
    pub named: Vec<(String, Vec<f64>)>,
}

/// The elements of `model` by the parameter that scales their stiffness: `None` (no
/// parameter) first when any element has none, then each parameter in the order its first
/// element comes; empty when no element's stiffness is a parameter (every element then
/// scales by 1, and a reduction need not split its sums).
pub fn stiffness_groups<M: ElementModel + ?Sized>(model: &M) -> Vec<(Option<String>, Vec<usize>)> {
    groups_by(model.n_elements(), |e| model.stiffness_parameter(e))
}

/// The elements of `model` by the parameter that scales their mass, as
/// [`stiffness_groups`] by stiffness; then a group without elements for each parameter that
/// sets a lumped mass ([`ElementModel::lumped_mass_parameters`]).
pub fn mass_groups<M: ElementModel + ?Sized>(model: &M) -> Vec<(Option<String>, Vec<usize>)> {
    let mut groups = groups_by(model.n_elements(), |e| model.mass_parameter(e));
    let lumped = model.lumped_mass_parameters();
    if groups.is_empty() && !lumped.is_empty() {
        groups.push((None, (0..model.n_elements()).collect()));
    }
    // lumped mass belongs to the group `None`, which may then have no element
    if model.has_lumped_mass() && !groups.is_empty() && groups[0].0.is_some() {
        groups.insert(0, (None, Vec::new()));
    }
    for name in lumped {
        if !groups.iter().any(|(g, _)| g.as_deref() == Some(name.as_str())) {
            groups.push((Some(name), Vec::new()));
        }
    }
    groups
}

fn groups_by<'a>(n: usize, parameter: impl Fn(usize) -> Option<&'a str>) -> Vec<(Option<String>, Vec<usize>)> {
    if (0..n).all(|e| parameter(e).is_none()) {
        return Vec::new();
    }
    let mut groups: Vec<(Option<String>, Vec<usize>)> = Vec::new();
    if (0..n).any(|e| parameter(e).is_none()) {
        groups.push((None, Vec::new()));
    }
    for e in 0..n {
        let name = parameter(e).map(str::to_string);
        match groups.iter_mut().find(|(g, _)| *g == name) {
            Some((_, members)) => members.push(e),
            None => groups.push((name, vec![e])),
        }
    }
    groups
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
