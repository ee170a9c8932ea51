//! The reduced Newton matrix of a [`Projection`]: assembled from its constant part (kept
//! for the last iteration coefficients), the loads' Jacobian and the model's element terms,
//! completed with the scaled joint rows (or reduced to the joints' null space) and factored
//! by Cholesky or LU; [`Projection::solve`] solves with the last factorization.

use super::{expand, Projection};
use crate::error::Result;
use crate::linalg::dense_lu::DenseLu;
use crate::linalg::vec_ops::axpy;
use crate::reduction::joint_elimination::JointElimination;
use crate::solver::model::{ElementModel, IterationCoefficients, Parameters};
use ndarray::Array2;

impl Projection {
    /// Declares the model's part of the Newton matrix (mass, element tangents, damping)
    /// symmetric, as it is for elastic forces from an energy with Rayleigh damping. The
    /// matrix is then factored by Cholesky, at half the flops of LU, whenever it is
    /// positive definite and holds no constraint rows (joints eliminated, or none), with
    /// LU as the fallback; and of the loads' Jacobian (a follower moment's is not
    /// symmetric) only the symmetric part enters it. That makes Newton a modified one
    /// whose iterations still stop on the same tolerance: the thesis four-bar's moment
    /// Jacobian is ~1e-4 of the matrix, and its runs take the same 900 iterations.
    pub fn symmetric_newton_matrix(&mut self) {
        self.symmetric = self.elim.is_some() || self.nc == 0;
    }

    /// Adds constant r×r terms to the iteration matrix: `stiffness` enters with `k`,
    /// `damping` with `c` (the hyper-reduced model's projected linear element parts).
    pub fn set_linear_terms(&mut self, stiffness: Option<Array2<f64>>, damping: Option<Array2<f64>>) {
        self.linear = (stiffness, damping);
        self.base_coef = None;
    }

    /// Replaces the constant stiffness term, keeping the damping term (a stiffness parameter
    /// changed).
    pub fn set_linear_stiffness(&mut self, stiffness: Array2<f64>) {
        self.linear.0 = Some(stiffness);
        self.base_coef = None;
    }

    /// Replaces the constant damping term, keeping the stiffness term (a mass or stiffness
    /// parameter changed).
    pub fn set_linear_damping(&mut self, damping: Array2<f64>) {
        self.linear.1 = Some(damping);
        self.base_coef = None;
    }

    /// The buffer the iteration matrix is assembled in (column-major) and its leading
    /// dimension: `S` (r × r) when the joints are eliminated, else the KKT matrix.
    fn matrix(&mut self) -> (&mut [f64], usize) {
        matrix_of(&mut self.elim, &mut self.lu, self.r, self.nc)
    }

    /// Solves the Newton system `[S, s Bᵀ; s B, 0] [Δq; Δμ] = rhs` in place with the last
    /// factorization (in the joints' null space when they are eliminated).
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
        match &mut self.elim {
            Some(e) => e.solve(&mut self.lu, rhs),
            None => self.lu.solve(rhs),
        }
    }

    /// Starts the reduced iteration matrix (column-major, (r + nc)²): the constant part
    /// `m M_r + k (L_r + P + Pᵀ) + c C_r` (kept for the last coefficients, since they change
    /// only with the step size) plus `k J_l,r(q, q̇, t)` and, for dampers between nodes,
    /// `c D_l,r(q, q̇, t)` (the loads' velocity Jacobian); the model adds its element terms.
    pub fn start_matrix<M: ElementModel>(
        &mut self,
        full: &M,
        mu: &Parameters,
        (q, v): (&[f64], &[f64]),
        t: f64,
        coef: IterationCoefficients,
    ) {
        let (r, n) = (self.r, if self.elim.is_some() { self.r } else { self.r + self.nc });
        if self.base_coef != Some(coef) {
            self.base.fill(0.0);
            let mut add = |m: &Array2<f64>, f: f64| {
                if f != 0.0 {
                    for j in 0..r {
                        for i in 0..r {
                            self.base[i + n * j] += f * m[[i, j]];
                        }
                    }
                }
            };
            add(&self.mass, coef.mass);
            if let Some((pp, _)) = &self.coupling {
                add(pp, coef.stiffness);
            }
            if let Some(l) = &self.linear.0 {
                add(l, coef.stiffness);
            }
            if let Some(c) = &self.linear.1 {
                add(c, coef.damping);
            }
            self.base_coef = Some(coef);
        }
        if !self.moving.is_empty() {
            self.moving.set_rows(full, mu, t, &mut self.b_r);
        }
        let (a, _) = matrix_of(&mut self.elim, &mut self.lu, r, self.nc);
        a.copy_from_slice(&self.base);
        if self.load_dofs.is_empty() {
            return;
        }
        let damping = if self.load_damping { coef.damping } else { 0.0 };
        if coef.stiffness == 0.0 && damping == 0.0 {
            return;
        }
        expand(&self.v_load, Some(&self.x_ref_load), 0, q, &mut self.xl);
        if self.load_damping {
            expand(&self.v_load, None, 0, v, &mut self.vl);
        }
        let loads = LoadBlock { v_load: &self.v_load, symmetric: self.symmetric, r, n };
        if coef.stiffness != 0.0 {
            full.load_jacobian(mu, &self.xl, &self.vl, t, &mut self.jl);
            loads.add(&mut self.jl, &mut self.jv, coef.stiffness, a);
        }
        if damping != 0.0 {
            full.load_damping_jacobian(mu, &self.xl, &self.vl, t, &mut self.jl);
            loads.add(&mut self.jl, &mut self.jv, damping, a);
        }
    }

    /// Adds the symmetric r×r block given by its upper triangle (row-major `upper[i r + j]`,
    /// j ≥ i) times `f` to the iteration matrix, where it is nonzero: on the `runs`
    /// `(i, first, end)`, columns `first..end` of row i.
    pub fn add_symmetric_upper(&mut self, upper: &[f64], f: f64, runs: &[(usize, usize, usize)]) {
        let r = self.r;
        let (a, n) = self.matrix();
        for &(i, j0, j1) in runs {
            let row = &upper[i * r..(i + 1) * r];
            let j0 = if j0 == i {
                a[i + n * i] += f * row[i];
                i + 1
            } else {
                j0
            };
            for j in j0..j1 {
                let v = f * row[j];
                a[i + n * j] += v;
                a[j + n * i] += v;
            }
        }
    }

    /// Adds the r×r matrix `m` (row-major) to the iteration matrix.
    pub fn add_block(&mut self, m: &[f64]) {
        let r = self.r;
        let (a, n) = self.matrix();
        for i in 0..r {
            for j in 0..r {
                a[i + n * j] += m[i * r + j];
            }
        }
    }

    /// Completes the matrix with the scaled constraint rows `s B_r`, `s B_rᵀ` (s = the largest
    /// diagonal entry, so both block rows are of one magnitude) and factors it; returns `s`.
    /// With the joints eliminated it factors `Pᵀ S P` instead.
    pub fn finish_matrix(&mut self) -> Result<f64> {
        let (r, nc) = (self.r, self.nc);
        let (a, n) = self.matrix();
        let scale = (0..r).map(|i| a[i + n * i].abs()).fold(0.0, f64::max);
        let scale = if scale > 0.0 && scale.is_finite() { scale } else { 1.0 };
        if let Some(e) = &mut self.elim {
            e.reduce(scale, self.lu.matrix_mut());
            self.factor_matrix()?;
            return Ok(scale);
        }
        let a = self.lu.matrix_mut();
        for c in 0..nc {
            for j in 0..r {
                let b = scale * self.b_r[[c, j]];
                a[(r + c) + n * j] = b;
                a[j + n * (r + c)] = b;
            }
        }
        self.factor_matrix()?;
        Ok(scale)
    }

    fn factor_matrix(&mut self) -> Result<()> {
        let done = if self.symmetric { self.lu.factor_symmetric() } else { self.lu.factor() };
        done.map_err(|e| e.context("reduced Newton matrix"))
    }
}

/// [`Projection::matrix`] on the two fields it needs, so that the rest of the projection
/// can be read while the matrix is written.
fn matrix_of<'a>(
    elim: &'a mut Option<JointElimination>,
    lu: &'a mut DenseLu,
    r: usize,
    nc: usize,
) -> (&'a mut [f64], usize) {
    match elim {
        Some(e) => (&mut e.s, r),
        None => (lu.matrix_mut(), r + nc),
    }
}

/// Projects a load Jacobian `J` (on the load dofs, column-major) into the iteration matrix:
/// `a += f V_lᵀ J V_l` (with [`Projection::symmetric_newton_matrix`], of `J`'s symmetric
/// part).
struct LoadBlock<'a> {
    v_load: &'a Array2<f64>,
    symmetric: bool,
    r: usize,
    /// the leading dimension of `a`
    n: usize,
}

impl LoadBlock<'_> {
    fn add(&self, jl: &mut [f64], jv: &mut [f64], f: f64, a: &mut [f64]) {
        let (r, n, nl) = (self.r, self.n, self.v_load.nrows());
        if self.symmetric {
            for a_ in 0..nl {
                for b in 0..a_ {
                    let m = 0.5 * (jl[a_ * nl + b] + jl[b * nl + a_]);
                    jl[a_ * nl + b] = m;
                    jl[b * nl + a_] = m;
                }
            }
        }
        // J V_l (nl × r, row-major), then V_lᵀ (J V_l)
        for a_ in 0..nl {
            let row = &mut jv[a_ * r..(a_ + 1) * r];
            row.fill(0.0);
            for b in 0..nl {
                axpy(jl[b * nl + a_], self.v_load.row(b).as_slice().expect("standard layout"), row);
            }
        }
        // column by column (contiguous in the column-major matrix)
        for a_ in 0..nl {
            let (jv, vl) = (&jv[a_ * r..(a_ + 1) * r], self.v_load.row(a_));
            let vl = vl.as_slice().expect("standard layout");
            for (j, &x) in jv.iter().enumerate() {
                if x != 0.0 {
                    axpy(f * x, vl, &mut a[n * j..n * j + r]);
                }
            }
        }
    }
}
