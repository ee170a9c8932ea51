//! The system under a fraction of its loads, for load stepping: with the internal forces
//! `F_int(q, q̇)` (elastic and damping) and the external ones `Q_ext(q, t; μ)`,
//!
//! ```text
//! F_s(q) = F_int(q, q̇) − s Q_ext(q, t; μ) = s F(q) + (1 − s) F_int(q),   F = F_int − Q_ext,
//! K_s(q) = ∂F_int/∂q − s ∂Q_ext/∂q
//! ```
//!
//! for every load at once (gravity, forces and moments, whatever scales them), which the
//! parameters cannot express (a load marked fixed does not scale with `λ`). Its KKT
//! matrix `[K_s, σBᵀ; σB, 0]` is factored by a solver of its own ([`super::assembly`]).

use super::assembly;
use crate::error::Result;
use crate::linalg::kkt::{Block, KktSolver, LinearSolverKind};
use crate::physics::system::FlexibleSystem;
use crate::solver::model::{DynamicModel, ElementModel, IterationCoefficients, Parameters, ParametricModel};

/// `sys` at the parameters `mu` with its loads times `factor`, as a [`DynamicModel`].
pub struct Ramped<'a> {
    sys: &'a mut FlexibleSystem,
    mu: Parameters,
    /// the load factor `s`
    pub factor: f64,
    kkt: Box<dyn KktSolver>,
    kind: LinearSolverKind,
}

impl<'a> Ramped<'a> {
    pub fn new(sys: &'a mut FlexibleSystem, mu: &Parameters, solver: LinearSolverKind) -> Self {
        sys.bind(mu);
        let kkt = assembly::solver(sys, solver);
        Ramped { sys, mu: mu.clone(), factor: 1.0, kkt, kind: solver }
    }

    pub fn system(&self) -> &FlexibleSystem {
        self.sys
    }

    pub fn parameters(&self) -> &Parameters {
        &self.mu
    }

    /// The kind of linear solver its factorizations use.
    pub fn solver_kind(&self) -> LinearSolverKind {
        self.kind
    }

    /// `F_int(q, q̇)`: the elements' elastic and damping forces at `μ`.
    fn internal_force(&self, q: &[f64], v: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        let mut fe = [0.0; 8];
        for e in 0..self.sys.n_elements() {
            let d = self.sys.element_dofs(e);
            let (qe, ve): (Vec<f64>, Vec<f64>) = d.iter().map(|&i| (q[i], v[i])).unzip();
            self.sys.element_force(e, &qe, &ve, &mut fe);
            // the elastic force is linear in E (the damping part is not rescaled by a
            // stiffness parameter: statics has no velocities)
            let k = self.sys.stiffness_factor(e, &self.mu);
            for (i, &di) in d.iter().enumerate() {
                out[di] += k * fe[i];
            }
        }
    }

    /// The external load `Q_ext(q, t; μ)` at the full load (factor 1).
    pub fn external_force(&mut self, q: &[f64], t: f64) -> Vec<f64> {
        let n = ParametricModel::n_dof(self.sys);
        let zero = vec![0.0; n];
        let (mut f, mut fi) = (vec![0.0; n], vec![0.0; n]);
        self.sys.force(&self.mu, q, &zero, t, &mut f);
        self.internal_force(q, &zero, &mut fi);
        f.iter().zip(&fi).map(|(f, fi)| fi - f).collect()
    }
}

impl DynamicModel for Ramped<'_> {
    fn n_dof(&self) -> usize {
        ParametricModel::n_dof(self.sys)
    }

    fn n_constraints(&self) -> usize {
        ParametricModel::n_constraints(self.sys)
    }

    fn mass_mul(&self, a: &[f64], out: &mut [f64]) {
        self.sys.mass_mul(a, out)
    }

    fn force(&mut self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        self.sys.force(&self.mu, q, v, t, out);
        if self.factor != 1.0 {
            let mut fi = vec![0.0; out.len()];
            self.internal_force(q, v, &mut fi);
            let s = self.factor;
            out.iter_mut().zip(&fi).for_each(|(o, fi)| *o = s * *o + (1.0 - s) * fi);
        }
    }

    fn constraint_residual(&self, q: &[f64], t: f64, out: &mut [f64]) {
        self.sys.constraint_residual(&self.mu, q, t, out)
    }

    fn add_constraint_force(&self, lambda: &[f64], t: f64, out: &mut [f64]) {
        self.sys.add_constraint_force(&self.mu, lambda, t, out)
    }

    /// `c_k K_s(q) + c_m M` (statics asks for `c_k = 1`, `c_m = 0`); the constraint rows are
    /// scaled by the largest diagonal entry, as the integrator's.
    fn factor(&mut self, q: &[f64], _v: &[f64], t: f64, coef: IterationCoefficients) -> Result<f64> {
        let mut blocks = assembly::tangent_blocks(self.sys, &self.mu, q, t, self.factor);
        if coef.stiffness != 1.0 {
            blocks.iter_mut().for_each(|b| *b *= coef.stiffness);
        }
        if coef.mass != 0.0 {
            for (b, m) in blocks.iter_mut().zip(assembly::mass_blocks(self.sys, &self.mu)) {
                *b += m * coef.mass;
            }
        }
        let scale = diagonal_scale(&blocks);
        self.sys.set_moving_rows(&self.mu, t, &mut *self.kkt);
        self.kkt.factor(&blocks, scale)?;
        Ok(scale)
    }

    fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
        self.kkt.solve(rhs)
    }

    fn length_scale(&self) -> f64 {
        ParametricModel::length_scale(self.sys)
    }

    fn max_strain(&self, q: &[f64]) -> Option<(f64, usize)> {
        ParametricModel::max_strain(self.sys, q)
    }
}

/// The largest diagonal entry of the blocks (1 if none is positive): the constraint rows'
/// scale, so that both block rows of the KKT matrix have one magnitude.
pub fn diagonal_scale(blocks: &[Block]) -> f64 {
    let d = blocks.iter().flat_map(|b| (0..8).map(move |i| b[(i, i)])).fold(0.0_f64, f64::max);
    if d > 0.0 {
        d
    } else {
        1.0
    }
}
