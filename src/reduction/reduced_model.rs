//! The Galerkin-projected model: a [`ParametricModel`] in reduced coordinates `q`, built on
//! any [`ElementModel`], so it shares the integrator (and its step halving) with the full
//! model. With `x = x_ref + V q` (SPEC §3, thesis eqs. 11–12, 18–21):
//!
//! ```text
//!     M_r = VᵀMV (once; per group where density is a parameter),   g₀,r(μ) = Vᵀg₀,fixed + λ Vᵀg₀,scaled (both parts once),
//!     g_r(q, q̇, t; μ) = g₀,r(μ) + Σ_e wₑ Vₑᵀ fₑ(xₑ, ẋₑ) + V_lᵀ g_l(x_l, t),   xₑ = x_ref,ₑ + Vₑ q,
//!     S_r = m M_r + Σ_e wₑ Vₑᵀ (c Cₑ + k Kₑ) Vₑ + k V_lᵀ J_l V_l,
//! ```
//!
//! where `Vₑ` are the rows of `V` on element `e`'s dofs: nothing of the full size is
//! touched per iteration except the tangent's `Vᵀ Y` (Y = Σ Aₑᵀ Sₑ Vₑ, n × r): plain Galerkin
//! costs as much as the mesh. The element weights `wₑ` are 1 for plain Galerkin; an
//! element whose stiffness is a parameter weighs `sₑ(μ) wₑ`
//! ([`ElementModel::stiffness_factor`]). A damped model with mass or stiffness parameters
//! keeps its damping apart, `C_r(μ)` over every element (`super::damping`), and evaluates
//! its elements without velocities: `fₑ(xₑ, 0)`, scaled by `sₑ(μ)`, is elastic alone.
//!
//! Joints, mass and nodal loads: see `reduction::projection` (private).

use super::basis::Basis;
use super::damping::DampingSplit;
use super::projection::{axpy, expand, forward_to_projection, impl_reduced, mat_vec, project_add, Projection};
use crate::error::Result;
use crate::solver::model::{ElementModel, IterationCoefficients, Parameters, ParametricModel};
use ndarray::{linalg::general_mat_mul, Array1, Array2, Axis};
use std::sync::Arc;

pub struct ReducedModel<M: ElementModel> {
    /// the full model, shared (read only) with every other reduced model of it
    full: Arc<M>,
    p: Projection,
    /// dofs per element
    ne: usize,
    elements: Vec<usize>,
    /// the weights at μ: `sₑ(μ) wₑ`, with `wₑ` in `base_weights` and μ in `bound` (`None`
    /// for a model without stiffness parameters: the weights are `wₑ`)
    weights: Vec<f64>,
    base_weights: Vec<f64>,
    bound: Option<Parameters>,
    /// rows of V on each element's dofs, stacked: (elements.len()·ne) × r
    v_el: Array2<f64>,
    x_ref_el: Array1<f64>,
    /// V itself and the global dofs of each visited element, for the tangent
    v: Array2<f64>,
    el_dofs: Vec<usize>,
    // work space: Y = (Σ_e wₑ Aₑᵀ Sₑ Vₑ), n × r, and Vᵀ Y
    y: Array2<f64>,
    vty: Array2<f64>,
    /// `x_ref,ₑ + Vₑ q` for every visited element, and the `q` it was computed at: the
    /// integrator evaluates the force and then the matrix at the same `q`
    x_el: Vec<f64>,
    x_el_at: Vec<f64>,
    x_el_valid: bool,
    ve: Vec<f64>,
    fe: Vec<f64>,
    se: Vec<f64>,
    /// the damping split by mass and stiffness parameters, `C_r(μ)` (`None`: the element
    /// forces carry the damping)
    damping: Option<DampingSplit>,
}

impl<M: ElementModel> ReducedModel<M> {
    /// Projects `full` (a model, or an `Arc` of one shared with other reduced models) on
    /// `basis`, visiting every element with weight 1.
    pub fn new(full: impl Into<Arc<M>>, basis: &Basis) -> Result<Self> {
        let full = full.into();
        let all: Vec<usize> = (0..full.n_elements()).collect();
        let ones = vec![1.0; all.len()];
        Self::with_elements(full, basis, all, ones)
    }

    /// Projects `full` on `basis`, summing the element terms over `elements` with
    /// `weights` only (the constant mass and loads stay exact).
    pub fn with_elements(
        full: impl Into<Arc<M>>,
        basis: &Basis,
        elements: Vec<usize>,
        weights: Vec<f64>,
    ) -> Result<Self> {
        let full: Arc<M> = full.into();
        let mut p = Projection::new(&*full, basis)?;
        let v = &basis.modes;
        let damping = DampingSplit::new(&*full, v.view());
        if let Some(d) = &damping {
            p.set_linear_terms(None, Some(d.matrix().clone()));
        }
        let (n, r) = (v.nrows(), v.ncols());
        let ne = if full.n_elements() > 0 { full.element_dofs(0).len() } else { 0 };
        let rows: Vec<usize> = elements.iter().flat_map(|&e| full.element_dofs(e).to_vec()).collect();
        let n_rows = rows.len();
        let full_elements = full.n_elements();
        let stiffness_parameter: Vec<bool> =
            (0..full_elements).map(|e| full.stiffness_parameter(e).is_some()).collect();
        Ok(ReducedModel {
            v_el: v.select(Axis(0), &rows),
            x_ref_el: basis.reference.select(Axis(0), &rows),
            y: Array2::zeros((n, r)),
            vty: Array2::zeros((r, r)),
            v: v.as_standard_layout().into_owned(),
            el_dofs: rows,
            x_el: vec![0.0; n_rows],
            x_el_at: vec![0.0; r],
            x_el_valid: false,
            ve: vec![0.0; ne],
            fe: vec![0.0; ne],
            se: vec![0.0; ne * ne],
            damping,
            full,
            p,
            ne,
            bound: (0..full_elements).any(|e| stiffness_parameter[e]).then(Parameters::default),
            elements,
            base_weights: weights.clone(),
            weights,
        })
    }

    /// Sets the mass to the elements' mass at `mu` and the weights to their stiffness (see
    /// the module documentation).
    fn bind_parameters(&mut self, mu: &Parameters) {
        self.p.bind(&*self.full, mu);
        if let Some(c) = self.damping.as_mut().and_then(|d| d.bind(&*self.full, mu)) {
            self.p.set_linear_damping(c.clone());
        }
        match &self.bound {
            Some(at) if at != mu => {}
            _ => return,
        }
        for ((w, &e), &base) in self.weights.iter_mut().zip(&self.elements).zip(&self.base_weights) {
            *w = self.full.stiffness_factor(e, mu) * base;
        }
        self.bound = Some(mu.clone());
    }

    /// Element coordinates `x_ref,ₑ + Vₑ q` of every visited element, computed once per `q`.
    fn update_element_coordinates(&mut self, q: &[f64]) {
        if self.x_el_valid && self.x_el_at == q {
            return;
        }
        let n_rows = self.x_el.len();
        expand(&self.v_el, Some(&self.x_ref_el), 0, q, &mut self.x_el[..n_rows]);
        self.x_el_at.copy_from_slice(q);
        self.x_el_valid = true;
    }
}

impl<M: ElementModel> ParametricModel for ReducedModel<M> {
    forward_to_projection!();

    fn bind(&mut self, mu: &Parameters) {
        self.bind_parameters(mu);
    }

    fn force(&mut self, mu: &Parameters, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        self.bind_parameters(mu);
        self.p.constant_and_load_force(&*self.full, mu, (q, v), t, out);
        let ne = self.ne;
        self.update_element_coordinates(q);
        let damping_apart = self.damping.is_some();
        for (k, (&e, &w)) in self.elements.iter().zip(&self.weights).enumerate() {
            // with the damping apart `ve` stays zero: the elastic force alone
            if !damping_apart {
                expand(&self.v_el, None, k * ne, v, &mut self.ve);
            }
            self.full.element_force(e, &self.x_el[k * ne..(k + 1) * ne], &self.ve, &mut self.fe);
            self.fe.iter_mut().for_each(|f| *f *= w);
            project_add(&self.v_el, k * ne, &self.fe, out);
        }
        if let Some(d) = &self.damping {
            mat_vec(d.matrix(), v, out, true);
        }
    }

    fn factor(&mut self, mu: &Parameters, q: &[f64], v: &[f64], t: f64, coef: IterationCoefficients) -> Result<f64> {
        let (r, ne) = (self.p.r, self.ne);
        self.bind_parameters(mu);
        self.p.start_matrix(&*self.full, mu, (q, v), t, coef);
        if coef.stiffness != 0.0 || coef.damping != 0.0 {
            self.update_element_coordinates(q);
            // the damping kept apart enters with the projection's constant part
            let damping = if self.damping.is_some() { 0.0 } else { coef.damping };
            let ecoef = IterationCoefficients { mass: 0.0, damping, ..coef };
            // assemble Y = S V over the global dofs first, then one product Vᵀ Y: about
            // half the flops of projecting every element block separately (shared nodes)
            let vs = self.v_el.as_slice().expect("standard layout");
            let ys = self.y.as_slice_mut().expect("standard layout");
            ys.fill(0.0);
            for (kk, (&e, &w)) in self.elements.iter().zip(&self.weights).enumerate() {
                self.full.element_matrix(e, &self.x_el[kk * ne..(kk + 1) * ne], ecoef, &mut self.se);
                let ve = &vs[kk * ne * r..(kk + 1) * ne * r];
                let dofs = &self.el_dofs[kk * ne..(kk + 1) * ne];
                for j in 0..ne {
                    let vrow = &ve[j * r..(j + 1) * r];
                    for (i, &di) in dofs.iter().enumerate() {
                        // S_e is column-major
                        let sij = w * self.se[j * ne + i];
                        if sij != 0.0 {
                            axpy(sij, vrow, &mut ys[di * r..(di + 1) * r]);
                        }
                    }
                }
            }
            general_mat_mul(1.0, &self.v.t(), &self.y, 0.0, &mut self.vty);
            self.p.add_block(self.vty.as_slice().expect("standard layout"));
        }
        self.p.finish_matrix()
    }
}

impl_reduced!(ReducedModel, ElementModel);
