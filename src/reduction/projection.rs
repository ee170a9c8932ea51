//! What every reduced model shares: the parts of the full model that are projected once
//! (mass, constant loads, joints), the few state- or time-dependent nodal loads, and the
//! reduced KKT matrix with its allocation-free LU (assembled and factored in
//! `projection/newton.rs`). The element terms are left to the
//! model (all elements in [`super::ReducedModel`], a sampled set in
//! [`super::HyperReducedModel`]). With `x = x_ref + V q`:
//!
//! ```text
//!     M_r = VᵀMV,  g₀,r(μ) = Vᵀg₀,fixed + λ Vᵀg₀,scaled,
//!     g_l,r = V_lᵀ g_l(x_ref,l + V_l q, t; μ),  J_l,r = V_lᵀ J_l V_l
//! ```
//!
//! Both parts of the constant force are projected once, unscaled, and combined at the load
//! scale `λ` of each evaluation's parameters μ: one reduced model runs at every load. Where
//! a parameter scales some elements' mass (a body's density), the mass and the constant
//! force are projected per group `g` of such elements, `M_r(μ) = Σ_g m_g(μ) M_r,g` and
//! `g₀,r(μ) = Σ_g m_g(μ) g₀,r,g(μ)`, and summed again when μ changes ([`Projection::bind`]).
//!
//! Joints: *constraint-preserving* keeps `B V q = b − B x_ref` with exact multipliers
//! (`B V = [0, B_c]`), and solves each Newton system in the null space of its joint rows
//! ([`super::joint_elimination`]: an LU of r − nc instead of r + nc); *galerkin* keeps the independent combinations of the projected
//! joint equations (none when the basis cannot move the joint's coordinates, as for a
//! ground pin whose rows are zero in every snapshot); *whole-system* has no separate multipliers:
//! `λ = w V_λ q` and the projected saddle point adds `Vᵀ Bᵀ λ + w V_λᵀ (B x − b)`, i.e.
//! `(P + Pᵀ) q + c₀` with `P = w V_λᵀ B V`, `c₀ = w V_λᵀ (B x_ref − b)`.

mod balance;
mod moving;
mod newton;

use super::basis::{Basis, Variant};
use super::joint_elimination::JointElimination;
use crate::error::{Error, Result};
use crate::linalg::dense_lu::DenseLu;
use crate::linalg::lapack::SVD;
use crate::linalg::sparse_rows::SparseRows;
pub(crate) use crate::linalg::vec_ops::{axpy, dot, mat_vec};
use crate::solver::model::{mass_groups, ConstantForces, ElementModel, IterationCoefficients, Parameters};
use ndarray::{s, Array1, Array2, ArrayView1, ArrayView2, ArrayViewMut2, Axis};

/// The [`crate::solver::model::ParametricModel`] methods a reduced model with fields
/// `p: Projection` and `full: M` forwards unchanged (mass, joints, Newton solve, length
/// scale); the model writes `force` and `factor` itself.
macro_rules! forward_to_projection {
    () => {
        fn n_dof(&self) -> usize {
            self.p.r
        }
        fn n_constraints(&self) -> usize {
            self.p.nc
        }
        fn mass_mul(&self, a: &[f64], out: &mut [f64]) {
            self.p.mass_mul(a, out);
        }
        fn constraint_residual(&self, mu: &Parameters, q: &[f64], t: f64, out: &mut [f64]) {
            self.p.constraint_residual_at(&*self.full, mu, q, t, out);
        }
        fn constraint_velocity_rhs(&self, mu: &Parameters, q: &[f64], t: f64, out: &mut [f64]) {
            out.iter_mut().for_each(|x| *x = 0.0);
            self.p.moving.velocity_rhs(&*self.full, mu, q, t, out);
        }
        fn constraint_acceleration_rhs(&self, mu: &Parameters, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
            out.iter_mut().for_each(|x| *x = 0.0);
            self.p.moving.acceleration_rhs(&*self.full, mu, q, v, t, out);
        }
        fn add_constraint_force(&self, mu: &Parameters, lambda: &[f64], t: f64, out: &mut [f64]) {
            self.p.add_constraint_force_at(&*self.full, mu, lambda, t, out);
        }
        fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
            self.p.solve(rhs)
        }
        fn length_scale(&self) -> f64 {
            self.full.length_scale()
        }
    };
}
pub(crate) use forward_to_projection;

/// [`super::reduced::Reduced`] for a reduced model `$t<M>` with fields `p: Projection` and
/// `full: M` (`M: $bound`): all of it is the projection's.
macro_rules! impl_reduced {
    ($t:ident, $bound:path) => {
        impl<M: $bound> super::reduced::Reduced<M> for $t<M> {
            fn full(&self) -> &M {
                &self.full
            }
            fn multipliers(&self, q: &[f64], lambda: &[f64]) -> Option<ndarray::Array1<f64>> {
                self.p.multipliers(q, lambda)
            }
            fn multipliers_along(
                &self,
                q: ndarray::ArrayView2<f64>,
                own: ndarray::ArrayView2<f64>,
            ) -> Option<ndarray::Array2<f64>> {
                self.p.multipliers_along(q, own)
            }
            fn balance(
                &self,
                mu: &crate::solver::model::Parameters,
                t: &[f64],
                states: [ndarray::ArrayView2<f64>; 3],
                lambda: ndarray::ArrayViewMut2<f64>,
            ) {
                self.p.balance(&*self.full, mu, t, states, lambda)
            }
        }
    };
}
pub(crate) use impl_reduced;

pub(crate) struct Projection {
    pub variant: Variant,
    pub r: usize,
    /// constraint rows kept in reduced form
    pub nc: usize,
    pub mass: Array2<f64>,
    /// `mass` by runs of nonzeros, for products
    mass_rows: SparseRows,
    /// the mass and the constant forces by group of elements whose mass one parameter scales
    /// (one group, every element, for a model without such parameters): `M_r(μ) = Σ m_g(μ)
    /// M_r,g` (`mass` holds the sum at the factors of the last [`Projection::bind`]) and
    /// `g₀,r(μ) = Σ m_g(μ) g₀,r,g(μ)`
    mass_split: MassSplit,
    /// B V and B x_ref − b (reduced rows; a moving row's at the last Newton matrix's time)
    b_r: Array2<f64>,
    c_r: Array1<f64>,
    /// the rows that move with time, evaluated at each time
    pub(crate) moving: moving::MovingRows,
    /// whole-system: P + Pᵀ and c₀
    coupling: Option<(Array2<f64>, Array1<f64>)>,
    /// whole-system: w V_λ (λ = w V_λ q); galerkin: Uₖ (λ = Uₖ λ̃), to recover the multipliers
    multiplier_map: Option<Array2<f64>>,
    load_dofs: Vec<usize>,
    /// rows of V and x_ref on the load dofs
    v_load: Array2<f64>,
    x_ref_load: Array1<f64>,
    xl: Vec<f64>,
    /// the velocities on the load dofs (zeros unless `load_damping`)
    vl: Vec<f64>,
    /// whether the loads read velocities (`ElementModel::load_has_damping`)
    load_damping: bool,
    gl: Vec<f64>,
    jl: Vec<f64>,
    jv: Vec<f64>,
    /// constant r×r stiffness and damping terms of the model, if any
    linear: (Option<Array2<f64>>, Option<Array2<f64>>),
    /// the constant part of the iteration matrix, for `base_coef`
    base: Vec<f64>,
    base_coef: Option<IterationCoefficients>,
    /// constraint-preserving: the Newton system solved in the null space of the joint rows
    /// (`S` is assembled in it, the LU holds `Pᵀ S P`); otherwise the LU holds the KKT matrix
    elim: Option<JointElimination>,
    lu: DenseLu,
    /// the model's Newton matrix is symmetric apart from the load Jacobian: factor by
    /// Cholesky (see [`Projection::symmetric_newton_matrix`])
    symmetric: bool,
    /// every body's balance of momentum, which the physical multipliers are moved to hold
    balance: Option<balance::Balance>,
}

/// The groups of [`Projection::mass_split`]: per group where its factor is read, `M_r,g`
/// and its projected constant forces; and the factors the mass is set to.
struct MassSplit {
    groups: Vec<(FactorOf, Array2<f64>, ProjectedForces)>,
    factors: Vec<f64>,
}

/// Where a mass group's factor `m_g(μ)` is read: 1 (no parameter), an element of it
/// ([`ElementModel::mass_factor`]), or the parameter of its lumped mass
/// ([`ElementModel::lumped_mass_factor`]).
#[derive(Clone)]
enum FactorOf {
    One,
    Element(usize),
    Lumped(String),
}

impl FactorOf {
    fn new(name: Option<String>, member: Option<usize>) -> Self {
        match (member, name) {
            (Some(e), _) => FactorOf::Element(e),
            (None, Some(name)) => FactorOf::Lumped(name),
            (None, None) => FactorOf::One,
        }
    }

    fn at<M: ElementModel>(&self, full: &M, mu: &Parameters) -> f64 {
        match self {
            FactorOf::One => 1.0,
            FactorOf::Element(e) => full.mass_factor(*e, mu),
            FactorOf::Lumped(name) => full.lumped_mass_factor(name, mu),
        }
    }
}

/// `Vᵀg₀,fixed`, `Vᵀg₀,scaled` and each `Vᵀg₀,name` ([`ElementModel::group_constant_forces`]):
/// `g₀,r(μ) = fixed + λ scaled + Σ μ_name named_name`.
struct ProjectedForces {
    fixed: Array1<f64>,
    scaled: Array1<f64>,
    named: Vec<(String, Array1<f64>)>,
}

impl ProjectedForces {
    fn of(v: &Array2<f64>, g: &ConstantForces) -> Self {
        let project = |x: &[f64]| v.t().dot(&ArrayView1::from(x));
        ProjectedForces {
            fixed: project(&g.fixed),
            scaled: project(&g.scaled),
            named: g.named.iter().map(|(name, x)| (name.clone(), project(x))).collect(),
        }
    }
}

impl Projection {
    pub fn new<M: ElementModel>(full: &M, basis: &Basis) -> Result<Self> {
        let (n, nc_full) = (full.n_dof(), full.n_constraints());
        basis.validate(n, nc_full).map_err(|(field, problem)| Error::usage(format!("{field} {problem}")))?;
        let v = &basis.modes;
        let r = v.ncols();
        let load_dofs = full.load_dofs();
        let v_load = v.select(Axis(0), &load_dofs);
        let x_ref_load = basis.reference.select(Axis(0), &load_dofs);

        // constant parts, projected once per group of elements whose mass one parameter scales
        let mut groups: Vec<(Option<String>, Option<usize>)> =
            mass_groups(full).into_iter().map(|(name, members)| (name, members.first().copied())).collect();
        if groups.is_empty() {
            groups.push((None, None));
        }
        let mut col = vec![0.0; n];
        let unprojected: Vec<_> = groups
            .into_iter()
            .map(|(name, member)| {
                let mut mv = Array2::zeros((n, r));
                for j in 0..r {
                    full.group_mass_mul(name.as_deref(), &v.column(j).to_vec(), &mut col);
                    mv.column_mut(j).assign(&ArrayView1::from(&col));
                }
                let forces = full.group_constant_forces(name.as_deref());
                (FactorOf::new(name, member), mv, forces)
            })
            .collect();
        let groups: Vec<_> =
            unprojected.iter().map(|(f, mv, g)| (f.clone(), v.t().dot(mv), ProjectedForces::of(v, g))).collect();
        let balance = balance::Balance::new(full, (v, &basis.reference), unprojected);
        let mass_split = MassSplit { factors: vec![1.0; groups.len()], groups };
        // the file's values, whatever the model was last bound to (one group: its own mass)
        let mass = match &mass_split.groups[..] {
            [(_, m, _)] => m.clone(),
            all => all.iter().fold(Array2::zeros((r, r)), |acc, (_, m, _)| acc + m),
        };

        // constraints are linear: B y − b, so B V_j = res(V_j) − res(0); taken at t = 0 (the
        // rows that move with time are evaluated at each time instead, `moving`)
        let mu0 = Parameters::load_scale(1.0);
        let mut res0 = vec![0.0; nc_full];
        full.constraint_residual(&mu0, &vec![0.0; n], 0.0, &mut res0);
        let mut bv = Array2::<f64>::zeros((nc_full, r));
        let mut res = vec![0.0; nc_full];
        for j in 0..r {
            full.constraint_residual(&mu0, &v.column(j).to_vec(), 0.0, &mut res);
            for c in 0..nc_full {
                bv[[c, j]] = res[c] - res0[c];
            }
        }
        full.constraint_residual(&mu0, basis.reference.as_slice().expect("contiguous"), 0.0, &mut res);
        let moving = moving::MovingRows::new(full, v, &basis.reference, nc_full)?;
        if !moving.is_empty() && basis.variant != Variant::ConstraintPreserving {
            return Err(Error::usage(format!(
                "the model prescribes motions (driven joints), whose rows move with time; the {} variant projects \
                 the joint rows once: train with variant = \"constraint-preserving\"",
                basis.variant.name()
            )));
        }
        let mut c_ref = Array1::from(res);

        let (nc, coupling, multiplier_map) = match basis.variant {
            Variant::ConstraintPreserving => (nc_full, None, None),
            Variant::Galerkin => {
                // keep the combinations of joint equations the basis can move: B V = U Σ Wᵀ,
                // rows Uₖᵀ(B V q + B x_ref − b) for σ > 1e-8 (B has unit entries, V is
                // orthonormal, so σ ≤ √2); the rest hold as well as the basis represents them
                let (u, sigma, _) = if nc_full > 0 {
                    bv.svd(true, false).map_err(|e| Error::numerical("SVD of B V", e.to_string()))?
                } else {
                    (None, Array1::zeros(0), None)
                };
                let k = sigma.iter().filter(|&&x| x > 1e-8).count();
                if k > 0 {
                    let uk = u.expect("requested").slice(s![.., ..k]).to_owned();
                    bv = uk.t().dot(&bv);
                    c_ref = uk.t().dot(&c_ref);
                    (k, None, Some(uk))
                } else {
                    (0, None, None)
                }
            }
            Variant::WholeSystemStabilized => {
                // k reduced joint equations Ψᵀ(B V q + B x_ref − b) with multipliers λ = Ψ μ
                let psi = basis.multiplier_modes.as_ref().expect("validated").clone();
                bv = psi.t().dot(&bv);
                c_ref = psi.t().dot(&c_ref);
                (psi.ncols(), None, Some(psi))
            }
            Variant::WholeSystem => {
                let w = basis.multiplier_scale;
                let vl = basis.multiplier_modes.as_ref().expect("validated") * w;
                let p = vl.t().dot(&bv);
                let c0 = vl.t().dot(&c_ref);
                (0, Some((&p + &p.t(), c0)), Some(vl))
            }
        };
        let (b_r, c_r) = if nc > 0 { (bv, c_ref) } else { (Array2::zeros((0, r)), Array1::zeros(0)) };
        let nl = load_dofs.len();
        // the null space of rows that move would move too: those models keep the KKT form
        let elim = if basis.variant == Variant::ConstraintPreserving && moving.is_empty() {
            JointElimination::new(&b_r)
        } else {
            None
        };
        let (ld, dim) = match &elim {
            Some(e) => (r, e.dim()),
            None => (r + nc, r + nc),
        };
        Ok(Projection {
            variant: basis.variant,
            r,
            nc,
            mass_rows: SparseRows::new(&mass),
            mass,
            mass_split,
            b_r,
            c_r,
            moving,
            coupling,
            multiplier_map,
            load_dofs,
            v_load,
            x_ref_load,
            xl: vec![0.0; nl],
            vl: vec![0.0; nl],
            load_damping: full.load_has_damping(),
            gl: vec![0.0; nl],
            jl: vec![0.0; nl * nl],
            jv: vec![0.0; nl * r],
            linear: (None, None),
            base: vec![0.0; ld * ld],
            base_coef: None,
            elim,
            lu: DenseLu::new(dim),
            symmetric: false,
            balance,
        })
    }

    /// Physical multipliers of the full model's constraints, when this variant has them:
    /// constraint-preserving returns the integrator's own, whole-system `w V_λ q`.
    pub fn multipliers(&self, q: &[f64], lambda: &[f64]) -> Option<Array1<f64>> {
        match self.variant {
            Variant::ConstraintPreserving => Some(Array1::from(lambda.to_vec())),
            Variant::WholeSystem => Some(self.multiplier_map.as_ref().expect("set").dot(&ArrayView1::from(q))),
            Variant::Galerkin | Variant::WholeSystemStabilized => {
                self.multiplier_map.as_ref().map(|uk| uk.dot(&ArrayView1::from(lambda)))
            }
        }
    }

    /// [`Self::multipliers`] at every instant of a run: `q` by instant (n_t × r), `own` the
    /// model's own multipliers (its n_c × n_t), in one product.
    pub fn multipliers_along(&self, q: ArrayView2<f64>, own: ArrayView2<f64>) -> Option<Array2<f64>> {
        match self.variant {
            Variant::ConstraintPreserving => Some(own.to_owned()),
            Variant::WholeSystem => Some(self.multiplier_map.as_ref().expect("set").dot(&q.t())),
            Variant::Galerkin | Variant::WholeSystemStabilized => self.multiplier_map.as_ref().map(|uk| uk.dot(&own)),
        }
    }

    /// Moves the physical multipliers `lambda` (n_c × n_t) along the reduced trajectory
    /// `[q, q̇, q̈]` by instant (n_t × r each, at the times `t`) to the nearest that hold every
    /// body's balance of momentum ([`balance`]); unchanged for a model without bodies or
    /// joints.
    pub fn balance<M: ElementModel>(
        &self,
        full: &M,
        mu: &Parameters,
        t: &[f64],
        states: [ArrayView2<f64>; 3],
        lambda: ArrayViewMut2<f64>,
    ) {
        if let Some(b) = &self.balance {
            b.correct(full, mu, t, states, lambda);
        }
    }

    /// Sets the mass to the elements' mass at `mu` (nothing to do for a model without mass
    /// parameters, or at the same factors).
    pub fn bind<M: ElementModel>(&mut self, full: &M, mu: &Parameters) {
        let split = &mut self.mass_split;
        // the same factors (every evaluation of a run): nothing to do, nothing allocated
        if split.groups.iter().zip(&split.factors).all(|((g, ..), &f)| g.at(full, mu) == f) {
            return;
        }
        let factors: Vec<f64> = split.groups.iter().map(|(g, ..)| g.at(full, mu)).collect();
        let mut mass = Array2::zeros((self.r, self.r));
        for ((_, m, _), &f) in split.groups.iter().zip(&factors) {
            mass.scaled_add(f, m);
        }
        self.mass_rows = SparseRows::new(&mass);
        self.mass = mass;
        self.base_coef = None;
        split.factors = factors;
    }

    /// `out = M_r a`
    pub fn mass_mul(&self, a: &[f64], out: &mut [f64]) {
        self.mass_rows.mul(a, out, false);
    }

    /// `out = g₀,r(μ) + g_l,r(q, q̇, t; μ)` (+ the whole-system coupling `(P + Pᵀ) q + c₀`):
    /// the loads evaluated exactly on the coordinates and velocities reconstructed on their
    /// few dofs (`x_ref + V_l q`, `V_l q̇`; the velocities only for dampers).
    pub fn constant_and_load_force<M: ElementModel>(
        &mut self,
        full: &M,
        mu: &Parameters,
        (q, v): (&[f64], &[f64]),
        t: f64,
        out: &mut [f64],
    ) {
        let x = mu.scale();
        let split = &self.mass_split;
        for (k, ((g, _, g0), &m)) in split.groups.iter().zip(&split.factors).enumerate() {
            debug_assert_eq!(m, g.at(full, mu), "bind() before evaluating");
            // the first group is assigned, the others added (one group at factor 1: `f + λ s`
            // to the bit)
            for (o, (f, s)) in out.iter_mut().zip(g0.fixed.iter().zip(&g0.scaled)) {
                let part = m * (f + x * s);
                *o = if k == 0 { part } else { *o + part };
            }
            for (name, g) in &g0.named {
                let x = m * mu.get(name).unwrap_or(1.0);
                out.iter_mut().zip(g).for_each(|(o, g)| *o += x * g);
            }
        }
        if !self.load_dofs.is_empty() {
            expand(&self.v_load, Some(&self.x_ref_load), 0, q, &mut self.xl);
            if self.load_damping {
                expand(&self.v_load, None, 0, v, &mut self.vl);
            }
            full.load_force(mu, &self.xl, &self.vl, t, &mut self.gl);
            project_add(&self.v_load, 0, &self.gl, out);
        }
        if let Some((pp, c0)) = &self.coupling {
            mat_vec(pp, q, out, true);
            out.iter_mut().zip(c0).for_each(|(o, c)| *o += c);
        }
    }

    /// `out = B_r q + c_r`
    pub fn constraint_residual(&self, q: &[f64], out: &mut [f64]) {
        mat_vec(&self.b_r, q, out, false);
        out.iter_mut().zip(&self.c_r).for_each(|(o, c)| *o += c);
    }

    /// `out += B_rᵀ λ`
    pub fn add_constraint_force(&self, lambda: &[f64], out: &mut [f64]) {
        for (row, l) in self.b_r.rows().into_iter().zip(lambda) {
            row.iter().zip(out.iter_mut()).for_each(|(b, o)| *o += b * l);
        }
    }
}

/// `out_i = x_ref[first + i] + V[first + i, :] · q` (pass no `x_ref` for velocities).
pub(crate) fn expand(v: &Array2<f64>, x_ref: Option<&Array1<f64>>, first: usize, q: &[f64], out: &mut [f64]) {
    let r = q.len();
    let rows = &v.as_slice().expect("standard layout")[first * r..(first + out.len()) * r];
    for (i, (o, row)) in out.iter_mut().zip(rows.chunks_exact(r)).enumerate() {
        *o = x_ref.map_or(0.0, |x| x[first + i]) + dot(row, q);
    }
}

/// `out += Σ_i f_i V[first + i, :]`
pub(crate) fn project_add(v: &Array2<f64>, first: usize, f: &[f64], out: &mut [f64]) {
    let r = out.len();
    let rows = &v.as_slice().expect("standard layout")[first * r..(first + f.len()) * r];
    for (fi, row) in f.iter().zip(rows.chunks_exact(r)) {
        axpy(*fi, row, out);
    }
}
