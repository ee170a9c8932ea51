//! The Galerkin-projected model: a [`DynamicModel`] in reduced coordinates `q`, built on
//! any [`ElementModel`], so it shares the integrator (and its step halving) with the full
//! model. With `x = x_ref + V q` (SPEC §3, thesis eqs. 11–12, 18–21):
//!
//! ```text
//!     M_r = VᵀMV (once),   g₀,r = Vᵀg₀ (once),
//!     g_r(q, q̇, t) = g₀,r + Σ_e wₑ Vₑᵀ fₑ(xₑ, ẋₑ) + V_lᵀ g_l(x_l, t),   xₑ = x_ref,ₑ + Vₑ q,
//!     S_r = m M_r + Σ_e wₑ Vₑᵀ (c Cₑ + k Kₑ) Vₑ + k V_lᵀ J_l V_l,
//! ```
//!
//! where `Vₑ` are the rows of `V` on element `e`'s dofs: nothing of the full size is
//! touched per iteration. The element weights `wₑ` are 1 for plain Galerkin.
//!
//! Joints: *constraint-preserving* keeps `B V q = b − B x_ref` with exact multipliers
//! (`B V = [0, B_c]`); *galerkin* keeps the independent combinations of the projected
//! joint equations (none when the basis cannot move the joint's coordinates, as for a
//! ground pin whose rows are zero in every snapshot); *whole-system* has no separate multipliers:
//! `λ = w V_λ q` and the projected saddle point adds `Vᵀ Bᵀ λ + w V_λᵀ (B x − b)`, i.e.
//! `(P + Pᵀ) q + c₀` with `P = w V_λᵀ B V`, `c₀ = w V_λᵀ (B x_ref − b)`.

use super::basis::{Basis, Variant};
use crate::solver::model::{DynamicModel, ElementModel, IterationCoefficients};
use ndarray::{linalg::general_mat_mul, s, Array1, Array2, ArrayView1, Axis};
use crate::solver::kkt::dense_lu_solve;
use ndarray_linalg::{FactorizeInto, LUFactorized, SVD};

pub struct ReducedModel<M: ElementModel> {
    full: M,
    variant: Variant,
    r: usize,
    /// constraint rows kept in reduced form (constraint-preserving only)
    nc: usize,
    /// dofs per element
    ne: usize,
    elements: Vec<usize>,
    weights: Vec<f64>,
    /// rows of V on each element's dofs, stacked: (elements.len()·ne) × r
    v_el: Array2<f64>,
    x_ref_el: Array1<f64>,
    load_dofs: Vec<usize>,
    v_load: Array2<f64>,
    x_ref_load: Array1<f64>,
    mass: Array2<f64>,
    g0: Array1<f64>,
    /// B V and B x_ref − b
    b_r: Array2<f64>,
    c_r: Array1<f64>,
    /// whole-system: P + Pᵀ and c₀
    coupling: Option<(Array2<f64>, Array1<f64>)>,
    /// whole-system: w V_λ (λ = w V_λ q); galerkin: Uₖ (λ = Uₖ λ̃), to recover the multipliers
    multiplier_map: Option<Array2<f64>>,
    /// V itself and the global dofs of each visited element, for the tangent
    v: Array2<f64>,
    el_dofs: Vec<usize>,
    // work space: Y = (Σ_e wₑ Aₑᵀ Sₑ Vₑ), n × r
    y: Array2<f64>,
    kkt: Array2<f64>,
    lu: Option<LUFactorized<ndarray::OwnedRepr<f64>>>,
    /// `x_ref,ₑ + Vₑ q` for every visited element, and the `q` it was computed at: the
    /// integrator evaluates the force and then the matrix at the same `q`
    x_el: Vec<f64>,
    x_el_at: Option<Vec<f64>>,
    ve: Vec<f64>,
    fe: Vec<f64>,
    se: Vec<f64>,
    xl: Vec<f64>,
    gl: Vec<f64>,
    jl: Vec<f64>,
}

impl<M: ElementModel> ReducedModel<M> {
    /// Projects `full` on `basis`, visiting every element with weight 1.
    pub fn new(full: M, basis: &Basis) -> Result<Self, String> {
        let all: Vec<usize> = (0..full.n_elements()).collect();
        let ones = vec![1.0; all.len()];
        Self::with_elements(full, basis, all, ones)
    }

    /// Projects `full` on `basis`, summing the element terms over `elements` with
    /// `weights` only (hyper-reduction; the constant mass and loads stay exact).
    pub fn with_elements(full: M, basis: &Basis, elements: Vec<usize>, weights: Vec<f64>) -> Result<Self, String> {
        let (n, nc_full) = (full.n_dof(), full.n_constraints());
        basis.validate(n, nc_full).map_err(|(field, problem)| format!("{field} {problem}"))?;
        let v = &basis.modes;
        let r = v.ncols();
        let ne = if full.n_elements() > 0 { full.element_dofs(0).len() } else { 0 };
        let rows: Vec<usize> = elements.iter().flat_map(|&e| full.element_dofs(e).to_vec()).collect();
        let v_el = v.select(Axis(0), &rows);
        let x_ref_el = basis.reference.select(Axis(0), &rows);
        let load_dofs = full.load_dofs();
        let v_load = v.select(Axis(0), &load_dofs);
        let x_ref_load = basis.reference.select(Axis(0), &load_dofs);

        // constant parts, projected once
        let mut mv = Array2::zeros((n, r));
        let mut col = vec![0.0; n];
        for j in 0..r {
            full.mass_mul(&v.column(j).to_vec(), &mut col);
            mv.column_mut(j).assign(&ArrayView1::from(&col));
        }
        let mass = v.t().dot(&mv);
        full.constant_force(&mut col);
        let g0 = v.t().dot(&ArrayView1::from(&col));

        // constraints are linear: B y − b, so B V_j = res(V_j) − res(0)
        let mut res0 = vec![0.0; nc_full];
        full.constraint_residual(&vec![0.0; n], &mut res0);
        let mut bv = Array2::<f64>::zeros((nc_full, r));
        let mut res = vec![0.0; nc_full];
        for j in 0..r {
            full.constraint_residual(&v.column(j).to_vec(), &mut res);
            for c in 0..nc_full {
                bv[[c, j]] = res[c] - res0[c];
            }
        }
        full.constraint_residual(basis.reference.as_slice().expect("contiguous"), &mut res);
        let mut c_ref = Array1::from(res);

        let (nc, coupling, multiplier_map) = match basis.variant {
            Variant::ConstraintPreserving => (nc_full, None, None),
            Variant::Galerkin => {
                // keep the combinations of joint equations the basis can move: B V = U Σ Wᵀ,
                // rows Uₖᵀ(B V q + B x_ref − b) for σ > 1e-8 (B has unit entries, V is
                // orthonormal, so σ ≤ √2); the rest hold as well as the basis represents them
                let (u, sigma, _) = if nc_full > 0 { bv.svd(true, false).map_err(|e| format!("SVD of B V failed: {e}"))? } else { (None, Array1::zeros(0), None) };
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
        let n_rows = rows.len();
        Ok(ReducedModel {
            y: Array2::zeros((n, r)),
            v: v.as_standard_layout().into_owned(),
            el_dofs: rows,
            kkt: Array2::zeros((r + nc, r + nc)),
            lu: None,
            x_el: vec![0.0; n_rows],
            x_el_at: None,
            ve: vec![0.0; ne],
            fe: vec![0.0; ne],
            se: vec![0.0; ne * ne],
            xl: vec![0.0; nl],
            gl: vec![0.0; nl],
            jl: vec![0.0; nl * nl],
            full,
            variant: basis.variant,
            r,
            nc,
            ne,
            elements,
            weights,
            v_el,
            x_ref_el,
            load_dofs,
            v_load,
            x_ref_load,
            mass,
            g0,
            b_r,
            c_r,
            coupling,
            multiplier_map,
        })
    }

    pub fn full(&self) -> &M {
        &self.full
    }

    pub fn variant(&self) -> Variant {
        self.variant
    }

    /// The sampled elements and their weights.
    pub fn elements(&self) -> (&[usize], &[f64]) {
        (&self.elements, &self.weights)
    }

    /// Physical multipliers of the full model's constraints, when this variant has them:
    /// constraint-preserving returns the integrator's own, whole-system `w V_λ q`.
    pub fn multipliers(&self, q: &[f64], lambda: &[f64]) -> Option<Array1<f64>> {
        match self.variant {
            Variant::ConstraintPreserving => Some(Array1::from(lambda.to_vec())),
            Variant::WholeSystem => Some(self.multiplier_map.as_ref().expect("set").dot(&ArrayView1::from(q))),
            Variant::Galerkin => self.multiplier_map.as_ref().map(|uk| uk.dot(&ArrayView1::from(lambda))),
        }
    }

    /// Element coordinates `x_ref,ₑ + Vₑ q` of every visited element, computed once per `q`.
    fn update_element_coordinates(&mut self, q: &[f64]) {
        if self.x_el_at.as_deref() == Some(q) {
            return;
        }
        let n_rows = self.x_el.len();
        Self::expand(&self.v_el, Some(&self.x_ref_el), 0, q, &mut self.x_el[..n_rows]);
        match &mut self.x_el_at {
            Some(at) => at.copy_from_slice(q),
            None => self.x_el_at = Some(q.to_vec()),
        }
    }

    /// `out_i = x_ref[first + i] + V[first + i, :] · q` (pass no `x_ref` for velocities).
    fn expand(v: &Array2<f64>, x_ref: Option<&Array1<f64>>, first: usize, q: &[f64], out: &mut [f64]) {
        let r = q.len();
        let rows = &v.as_slice().expect("standard layout")[first * r..(first + out.len()) * r];
        for (i, (o, row)) in out.iter_mut().zip(rows.chunks_exact(r)).enumerate() {
            *o = x_ref.map_or(0.0, |x| x[first + i]) + dot(row, q);
        }
    }

    /// `out += Σ_i f_i V[first + i, :]`
    fn project_add(v: &Array2<f64>, first: usize, f: &[f64], out: &mut [f64]) {
        let r = out.len();
        let rows = &v.as_slice().expect("standard layout")[first * r..(first + f.len()) * r];
        for (fi, row) in f.iter().zip(rows.chunks_exact(r)) {
            axpy(*fi, row, out);
        }
    }
}

/// Dot product with four independent partial sums, so that it vectorizes (a single
/// running sum is a chain of dependent additions).
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca.remainder().iter().zip(cb.remainder()).map(|(x, y)| x * y).sum();
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

#[inline]
fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
    }
}

impl<M: ElementModel> DynamicModel for ReducedModel<M> {
    fn n_dof(&self) -> usize {
        self.r
    }

    fn n_constraints(&self) -> usize {
        self.nc
    }

    fn mass_mul(&self, a: &[f64], out: &mut [f64]) {
        let mut o = ndarray::ArrayViewMut1::from(out);
        general_mat_vec(&self.mass, a, &mut o);
    }

    fn force(&mut self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        out.copy_from_slice(self.g0.as_slice().expect("contiguous"));
        let ne = self.ne;
        self.update_element_coordinates(q);
        for (k, (&e, &w)) in self.elements.iter().zip(&self.weights).enumerate() {
            Self::expand(&self.v_el, None, k * ne, v, &mut self.ve);
            self.full.element_force(e, &self.x_el[k * ne..(k + 1) * ne], &self.ve, &mut self.fe);
            self.fe.iter_mut().for_each(|f| *f *= w);
            Self::project_add(&self.v_el, k * ne, &self.fe, out);
        }
        if !self.load_dofs.is_empty() {
            Self::expand(&self.v_load, Some(&self.x_ref_load), 0, q, &mut self.xl);
            self.full.load_force(&self.xl, t, &mut self.gl);
            Self::project_add(&self.v_load, 0, &self.gl, out);
        }
        if let Some((pp, c0)) = &self.coupling {
            let mut o = ndarray::ArrayViewMut1::from(out);
            o += c0;
            o += &pp.dot(&ArrayView1::from(q));
        }
    }

    fn constraint_residual(&self, q: &[f64], out: &mut [f64]) {
        let mut o = ndarray::ArrayViewMut1::from(out);
        general_mat_vec(&self.b_r, q, &mut o);
        o += &self.c_r;
    }

    fn add_constraint_force(&self, lambda: &[f64], out: &mut [f64]) {
        let mut o = ndarray::ArrayViewMut1::from(out);
        o += &self.b_r.t().dot(&ArrayView1::from(lambda));
    }

    fn factor(&mut self, q: &[f64], _v: &[f64], t: f64, coef: IterationCoefficients) -> Result<f64, String> {
        let (r, ne) = (self.r, self.ne);
        if coef.stiffness != 0.0 || coef.damping != 0.0 {
            self.update_element_coordinates(q);
        }
        self.kkt.fill(0.0);
        {
            let mut k = self.kkt.slice_mut(s![..r, ..r]);
            k.scaled_add(coef.mass, &self.mass);
            if coef.stiffness != 0.0 || coef.damping != 0.0 {
                let ecoef = IterationCoefficients { mass: 0.0, ..coef };
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
                general_mat_mul(1.0, &self.v.t(), &self.y, 1.0, &mut k);
            }
            if coef.stiffness != 0.0 && !self.load_dofs.is_empty() {
                let nl = self.load_dofs.len();
                Self::expand(&self.v_load, Some(&self.x_ref_load), 0, q, &mut self.xl);
                self.full.load_jacobian(&self.xl, t, &mut self.jl);
                let j = Array2::from_shape_fn((nl, nl), |(a, b)| self.jl[b * nl + a]);
                k.scaled_add(coef.stiffness, &self.v_load.t().dot(&j.dot(&self.v_load)));
            }
            if let Some((pp, _)) = &self.coupling {
                k.scaled_add(coef.stiffness, pp);
            }
        }
        let scale = (0..r).map(|i| self.kkt[[i, i]].abs()).fold(0.0, f64::max);
        let scale = if scale > 0.0 { scale } else { 1.0 };
        if self.nc > 0 {
            self.kkt.slice_mut(s![r.., ..r]).scaled_add(scale, &self.b_r);
            self.kkt.slice_mut(s![..r, r..]).scaled_add(scale, &self.b_r.t());
        }
        if self.kkt.iter().any(|x| !x.is_finite()) {
            return Err("the reduced iteration matrix holds non-finite values".into());
        }
        self.lu = Some(self.kkt.clone().factorize_into().map_err(|e| format!("reduced LU failed: {e}"))?);
        Ok(scale)
    }

    fn solve(&mut self, rhs: &mut [f64]) -> Result<(), String> {
        dense_lu_solve(self.lu.as_ref(), rhs)
    }

    fn length_scale(&self) -> f64 {
        self.full.length_scale()
    }
}

/// `out = A x`
fn general_mat_vec(a: &Array2<f64>, x: &[f64], out: &mut ndarray::ArrayViewMut1<f64>) {
    ndarray::linalg::general_mat_vec_mul(1.0, a, &ArrayView1::from(x), 0.0, out);
}
