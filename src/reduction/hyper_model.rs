//! The hyper-reduced model: Galerkin projection on `x = x_ref + V q` with the element
//! terms summed over a sampled set `E` with weights `wₑ` (ECSW, [`mod@super::ecsw`]), built on
//! an [`InvariantElementModel`] so that the online cost depends on r and |E| only:
//!
//! ```text
//!     offline (all elements):  L_r = Σ Vₑᵀ Lₑ Vₑ,  l_r = Σ Vₑᵀ Lₑ x_ref,ₑ,  C_r = Σ Vₑᵀ Cₑ Vₑ,
//!                              M_r, g₀,r, joints (super::projection)
//!     offline (e ∈ E):         Gₑⱼ = Vₑᵀ Sⱼ Vₑ   (r × r)
//!     online, per iteration:   xₑ = x_ref,ₑ + Vₑ q,  yⱼ = Sⱼ xₑ,  s_j = xₑ·yⱼ,  uⱼ = Vₑᵀ yⱼ
//!        g_r = g₀,r + g_l,r + L_r q + l_r + C_r q̇ + Σ_E wₑ Σⱼ 2ψⱼ uⱼ
//!        S_r = m M_r + c C_r + k (L_r + J_l,r + Σ_E wₑ [Σⱼ 2ψⱼ Gₑⱼ + Σⱼₖ 4ψⱼₖ uⱼ uₖᵀ])
//! ```
//!
//! The force takes the element route (4 ne r flops per element and invariant); the tangent
//! takes the `Gₑⱼ` route (r² instead of the 16 r² of `Vₑᵀ Kₑ Vₑ`), `G_e = Φ_eᵀ S_l Φ_e`.
//! Each element keeps only the columns of `V` it sees, as at most two runs (unreduced
//! joint coordinates are unit columns that touch one or two
//! elements; a block basis gives an element its own block's modes) and the 4 × 4 blocks of
//! the upper block triangle of `Gₑⱼ` on them; elements on the same columns are grouped, and
//! the tangent is summed over a group block by block in registers (sampled.rs): on the
//! thesis four-bar with a global basis that is ~1300 instead of 3844 numbers per element,
//! with one block per body ~900 on the coupler, read once per tangent. `Gₑⱼ` is stored in single precision: it
//! enters only the Newton matrix, where a relative error of 6e-8 changes how Newton gets
//! to the solution, not where it stops (the force is summed in double precision); it halves
//! the tangent's memory traffic (four-bar at 30 %: 7 → 3.5 MB per tangent). Work space is
//! allocated once: the time loop does not touch the heap, and nothing of size n_dof is
//! visited.
//!
//! A model whose elements' stiffness is a parameter
//! ([`crate::solver::model::ElementModel::stiffness_factor`],
//! Young's modulus) is affine in it: `L_r(μ) = Σ_g s_g(μ) L_r,g`, `l_r(μ)` alike, over the
//! groups `g` of elements that share a parameter, and each sampled weight becomes
//! `s_g(μ) wₑ`; both are set again when μ changes (once per run). Its damping, where it
//! has some, is split likewise by mass and stiffness (`super::damping`): `C_r(μ)`.

mod columns;
mod kernels;
mod sampled;

use super::basis::Basis;
use super::damping::DampingSplit;
use super::projection::{forward_to_projection, impl_reduced, Projection};
use super::sample::Hyper;
use crate::error::{Error, Result};
use crate::linalg::incremental_product::IncrementalProduct;
use crate::linalg::sparse_rows::SparseRows;
use crate::solver::model::{
    stiffness_groups, InvariantElementModel, IterationCoefficients, Parameters, ParametricModel,
};
use ndarray::{Array1, Array2, Axis};
use sampled::Sampled;
use std::sync::Arc;

pub struct HyperReducedModel<M: InvariantElementModel> {
    /// the full model, shared (read only) with every other reduced model of it
    full: Arc<M>,
    p: Projection,
    ne: usize,
    elements: Vec<usize>,
    /// `L_r` and `C_r` by runs of nonzeros (the projection keeps them dense for the matrix)
    l_rows: SparseRows,
    l0: Array1<f64>,
    c_rows: Option<SparseRows>,
    /// `L_r q` and `C_r q̇`, kept by increments: with the rigid motion in `q` their direct
    /// products round far above Newton's tolerance ([`IncrementalProduct`])
    l_q: IncrementalProduct,
    c_v: IncrementalProduct,
    /// the sampled elements by groups that see the same columns of `V`, with `Sⱼ`, `Gₑⱼ`
    /// and the invariants of the last update ([`Sampled`])
    sampled: Sampled,
    // cache at `at` (valid when `valid`)
    at: Vec<f64>,
    valid: bool,
    /// tangent accumulator: upper triangle, row-major r × r
    acc: Vec<f64>,
    /// the runs `(row, first, end)` of `acc` that any sampled element reaches
    runs: Vec<(usize, usize, usize)>,
    /// the affine split in the elements' stiffness parameters; `None` without any
    stiffness: Option<StiffnessSplit>,
    /// the damping split by mass and stiffness parameters; `None` without damping or
    /// without such parameters (`C_r` is then constant)
    damping: Option<DampingSplit>,
}

/// `L_r,g` and `l_r,g` of the module documentation, with the sampled weights at `s = 1` and
/// the factors the model is set to.
struct StiffnessSplit {
    /// per group: an element of it (to ask its factor), `L_r,g`, `l_r,g`
    groups: Vec<(usize, Array2<f64>, Array1<f64>)>,
    /// per sampled element: its group and its weight at `s = 1`
    sample_group: Vec<usize>,
    weights: Vec<f64>,
    factors: Vec<f64>,
}

impl<M: InvariantElementModel> HyperReducedModel<M> {
    /// Whether `full` has elements this model supports (4, 6, 8 or 12 dofs).
    pub fn supports(full: &M) -> bool {
        full.n_elements() > 0 && [4, 6, 8, 12].contains(&full.element_dofs(0).len())
    }

    /// Projects `full` (a model, or an `Arc` of one shared with other reduced models) on
    /// `basis`, summing the element terms over the sample `hyper`.
    pub fn new(full: impl Into<Arc<M>>, basis: &Basis, hyper: &Hyper) -> Result<Self> {
        let full: Arc<M> = full.into();
        hyper.validate(full.n_elements()).map_err(|(f, p)| Error::usage(format!("{f} {p}")))?;
        let mut p = Projection::new(&*full, basis)?;
        let v = basis.modes.as_standard_layout();
        let r = v.ncols();
        let n_el = full.n_elements();
        let ne = if n_el > 0 { full.element_dofs(0).len() } else { 0 };
        let nj = full.n_invariants();
        if ![4, 6, 8, 12].contains(&ne) {
            return Err(Error::usage(format!("hyper-reduction supports elements of 4, 6, 8 or 12 dofs, not {ne}")));
        }

        // the elements by stiffness parameter, each group's linear part summed apart
        let split = stiffness_groups(&*full);
        let mut group_of = vec![0; n_el];
        for (g, (_, members)) in split.iter().enumerate() {
            members.iter().for_each(|&e| group_of[e] = g);
        }
        let mut group_l: Vec<(Array2<f64>, Array1<f64>)> =
            split.iter().map(|_| (Array2::zeros((r, r)), Array1::zeros(r))).collect();
        // linear element parts, exact over all elements
        let mut l_r = Array2::zeros((r, r));
        let mut c_r = Array2::zeros((r, r));
        let mut l0 = Array1::zeros(r);
        let (mut le, mut ce) = (vec![0.0; ne * ne], vec![0.0; ne * ne]);
        let mut lv = Array2::zeros((ne, r));
        let mut cv = Array2::zeros((ne, r));
        let damping = DampingSplit::new(&*full, v.view());
        for e in 0..n_el {
            let dofs = full.element_dofs(e).to_vec();
            full.element_linear(e, &mut le, &mut ce);
            let ve = v.select(Axis(0), &dofs);
            let xe = basis.reference.select(Axis(0), &dofs);
            let lm = Array2::from_shape_fn((ne, ne), |(i, j)| le[j * ne + i]);
            let cm = Array2::from_shape_fn((ne, ne), |(i, j)| ce[j * ne + i]);
            ndarray::linalg::general_mat_mul(1.0, &lm, &ve, 0.0, &mut lv);
            let (l_sum, l0_sum) = match group_l.get_mut(group_of[e]) {
                Some((lg, l0g)) => (lg, l0g),
                None => (&mut l_r, &mut l0),
            };
            ndarray::linalg::general_mat_mul(1.0, &ve.t(), &lv, 1.0, l_sum);
            // undamped models (both benchmarks) skip half the work of every run's set-up
            if damping.is_none() && ce.iter().any(|&x| x != 0.0) {
                ndarray::linalg::general_mat_mul(1.0, &cm, &ve, 0.0, &mut cv);
                ndarray::linalg::general_mat_mul(1.0, &ve.t(), &cv, 1.0, &mut c_r);
            }
            *l0_sum += &ve.t().dot(&lm.dot(&xe));
        }
        for (lg, l0g) in &group_l {
            l_r += lg;
            l0 += l0g;
        }
        let c_r = match &damping {
            Some(d) => Some(d.matrix().clone()),
            None => c_r.iter().any(|&x| x != 0.0).then_some(c_r),
        };
        let stiffness = (!split.is_empty()).then(|| StiffnessSplit {
            groups: split.iter().zip(group_l).map(|((_, members), (lg, l0g))| (members[0], lg, l0g)).collect(),
            sample_group: hyper.elements.iter().map(|&e| group_of[e]).collect(),
            weights: hyper.weights.clone(),
            factors: vec![1.0; split.len()],
        });
        let (l_rows, c_rows) = (SparseRows::new(&l_r), c_r.as_ref().map(SparseRows::new));
        p.set_linear_terms(Some(l_r), c_r);
        // invariant-based element forces derive from an energy: symmetric tangents
        p.symmetric_newton_matrix();

        // sampled elements: their rows of V, references and Sⱼ, stored by groups (sampled.rs)
        let m = hyper.elements.len();
        let mut v_el = Vec::with_capacity(m);
        let mut x_el = Vec::with_capacity(m);
        let mut s_mat = Vec::with_capacity(m);
        for &e in &hyper.elements {
            let dofs = full.element_dofs(e).to_vec();
            v_el.push(v.select(Axis(0), &dofs));
            x_el.push(basis.reference.select(Axis(0), &dofs).to_vec());
            s_mat.push(
                (0..nj)
                    .map(|j| {
                        let mut s = vec![0.0; ne * ne];
                        full.element_invariant_matrix(e, j, &mut s);
                        s
                    })
                    .collect::<Vec<_>>(),
            );
        }
        let views: Vec<_> = v_el.iter().map(|a| a.view()).collect();
        let xr: Vec<&[f64]> = x_el.iter().map(|x| x.as_slice()).collect();
        let sampled = Sampled::new(r, &views, &xr, &s_mat, &hyper.weights);
        // the parts of the accumulator any element reaches, row by row
        let mut reached = vec![false; r * r];
        for g in &sampled.groups {
            let c = g.cols;
            for l in 0..c.len() {
                let (at, len, at2, len2) = c.row(l, r);
                reached[at..at + len].iter_mut().for_each(|x| *x = true);
                reached[at2..at2 + len2].iter_mut().for_each(|x| *x = true);
            }
        }
        let mut runs = Vec::new();
        for i in 0..r {
            let mut j = i;
            while j < r {
                if reached[i * r + j] {
                    let end = (j..r).find(|&jj| !reached[i * r + jj]).unwrap_or(r);
                    runs.push((i, j, end));
                    j = end;
                } else {
                    j += 1;
                }
            }
        }
        Ok(HyperReducedModel {
            runs,
            ne,
            l_rows,
            l0,
            c_rows,
            l_q: IncrementalProduct::new(r, r),
            c_v: IncrementalProduct::new(r, r),
            sampled,
            at: vec![0.0; r],
            valid: false,
            acc: vec![0.0; r * r],
            elements: hyper.elements.clone(),
            full,
            p,
            stiffness,
            damping,
        })
    }

    /// Sets the mass to the elements' mass at `mu`, the linear parts and the sampled weights
    /// to their stiffness, the damping to both (nothing to do for a model without such
    /// parameters, or at the same factors).
    fn bind_parameters(&mut self, mu: &Parameters) {
        self.p.bind(&*self.full, mu);
        if let Some(c) = self.damping.as_mut().and_then(|d| d.bind(&*self.full, mu)) {
            self.c_rows = Some(SparseRows::new(c));
            self.c_v.reset();
            self.p.set_linear_damping(c.clone());
        }
        let Some(split) = &mut self.stiffness else { return };
        // the same factors (every evaluation of a run): nothing to do, nothing allocated
        if split.groups.iter().zip(&split.factors).all(|((e, ..), &f)| self.full.stiffness_factor(*e, mu) == f) {
            return;
        }
        let factors: Vec<f64> = split.groups.iter().map(|(e, ..)| self.full.stiffness_factor(*e, mu)).collect();
        let r = self.p.r;
        let (mut l_r, mut l0) = (Array2::zeros((r, r)), Array1::zeros(r));
        for ((_, lg, l0g), &f) in split.groups.iter().zip(&factors) {
            l_r.scaled_add(f, lg);
            l0.scaled_add(f, l0g);
        }
        self.l_rows = SparseRows::new(&l_r);
        self.l_q.reset();
        self.l0 = l0;
        self.p.set_linear_stiffness(l_r);
        for (k, (w, &g)) in split.weights.iter().zip(&split.sample_group).enumerate() {
            self.sampled.weights[k] = factors[g] * w;
        }
        split.factors = factors;
    }
}

impl<M: InvariantElementModel> ParametricModel for HyperReducedModel<M> {
    forward_to_projection!();

    fn bind(&mut self, mu: &Parameters) {
        self.bind_parameters(mu);
    }

    fn start_run(&mut self) {
        self.l_q.reset();
        self.c_v.reset();
    }

    fn force(&mut self, mu: &Parameters, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        self.bind_parameters(mu);
        self.p.constant_and_load_force(&*self.full, mu, (q, v), t, out);
        self.l_q.add_product(&self.l_rows, q, out);
        out.iter_mut().zip(&self.l0).for_each(|(o, l)| *o += l);
        if let Some(c) = &self.c_rows {
            self.c_v.add_product(c, v, out);
        }
        self.update(q);
        self.add_force(out);
    }

    fn factor(&mut self, mu: &Parameters, q: &[f64], v: &[f64], t: f64, coef: IterationCoefficients) -> Result<f64> {
        // m M_r + k (L_r + J_l,r) + c C_r
        self.bind_parameters(mu);
        self.p.start_matrix(&*self.full, mu, (q, v), t, coef);
        if coef.stiffness != 0.0 {
            self.update(q);
            self.tangent();
            self.p.add_symmetric_upper(&self.acc, coef.stiffness, &self.runs);
        }
        self.p.finish_matrix()
    }

    /// From the invariants cached at the last force or matrix evaluation: at a converged
    /// step the last Newton iterate, within the tolerance of the final state, at no cost.
    fn max_strain(&self, _q: &[f64]) -> Option<(f64, usize)> {
        if !self.valid {
            return None;
        }
        let nj = self.sampled.nj;
        let mut worst: Option<(f64, usize)> = None;
        for (k, &e) in self.elements.iter().enumerate() {
            let eps = self.full.invariant_strain(e, &self.sampled.s_val[k * nj..(k + 1) * nj])?.abs();
            if !worst.is_some_and(|w| eps <= w.0) {
                worst = Some((eps, e));
            }
        }
        worst
    }
}

impl_reduced!(HyperReducedModel, InvariantElementModel);
