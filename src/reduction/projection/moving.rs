//! Constraint rows that move with time (prescribed motions) in a reduced model. With
//! `x = x_ref + V q` a moving row `B_c(t) x = b_c(t)` reads
//!
//! ```text
//!     B_c(t) V q = b_c(t) − B_c(t) x_ref,
//! ```
//!
//! its coefficients `B_c(t) V` re-evaluated at each time from the few rows of `V` on its
//! coordinates; the velocity and acceleration levels follow as in the full model with
//! `x(q)` and `V q̇` in place of `q` and `q̇`. The constraint-preserving basis keeps every
//! coordinate a joint touches unreduced, so the reduced rows hold the motion exactly.

use super::{dot, Projection};
use crate::error::{Error, Result};
use crate::solver::model::{ElementModel, Parameters};
use ndarray::{Array1, Array2, Axis};

/// The most terms a moving row may have here (a turning slope row has two).
const MAX_TERMS: usize = 4;

/// The moving rows of a reduced model: per row its index, the rows of `V` and of `x_ref` on
/// its coordinates.
pub(crate) struct MovingRows {
    rows: Vec<(usize, Array2<f64>, Array1<f64>)>,
    is_moving: Vec<bool>,
}

impl MovingRows {
    /// The full model's moving rows under the basis `(V, x_ref)`; `nc` rows in all.
    pub fn new<M: ElementModel>(full: &M, v: &Array2<f64>, x_ref: &Array1<f64>, nc: usize) -> Result<Self> {
        let mut is_moving = vec![false; nc];
        let mut rows = Vec::new();
        for (c, dofs) in full.moving_rows() {
            if dofs.len() > MAX_TERMS {
                return Err(Error::usage(format!(
                    "constraint row {c} moves with {} terms; at most {MAX_TERMS}",
                    dofs.len()
                )));
            }
            is_moving[c] = true;
            rows.push((c, v.select(Axis(0), &dofs), x_ref.select(Axis(0), &dofs)));
        }
        Ok(MovingRows { rows, is_moving })
    }

    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Whether row `c` moves.
    pub fn moves(&self, c: usize) -> bool {
        !self.rows.is_empty() && self.is_moving[c]
    }

    /// Row `k`'s coefficients' and right-hand side's `order`-th time derivative.
    fn at<M: ElementModel>(&self, full: &M, mu: &Parameters, k: usize, t: f64, order: u32) -> ([f64; MAX_TERMS], f64) {
        let mut b = [0.0; MAX_TERMS];
        let len = self.rows[k].1.nrows();
        let rhs = full.moving_row_at(mu, k, t, order, &mut b[..len]);
        (b, rhs)
    }

    /// `x_ref + V q` (with `x_ref`) or `V q` on row `k`'s coordinates.
    fn expand(&self, k: usize, q: &[f64], with_ref: bool) -> [f64; MAX_TERMS] {
        let (_, v, x_ref) = &self.rows[k];
        let mut x = [0.0; MAX_TERMS];
        for (i, xi) in x.iter_mut().take(v.nrows()).enumerate() {
            let row = v.row(i);
            *xi = dot(row.as_slice().expect("standard layout"), q) + if with_ref { x_ref[i] } else { 0.0 };
        }
        x
    }

    /// Overwrites the moving rows of `out` with `B(t) x(q) − b(t)`.
    pub fn residual<M: ElementModel>(&self, full: &M, mu: &Parameters, q: &[f64], t: f64, out: &mut [f64]) {
        for k in 0..self.rows.len() {
            let (b, rhs) = self.at(full, mu, k, t, 0);
            let x = self.expand(k, q, true);
            out[self.rows[k].0] = dot(&b, &x) - rhs;
        }
    }

    /// Moving rows of `out` set to `ḃ − Ḃ x(q)`.
    pub fn velocity_rhs<M: ElementModel>(&self, full: &M, mu: &Parameters, q: &[f64], t: f64, out: &mut [f64]) {
        for k in 0..self.rows.len() {
            let (b1, rhs1) = self.at(full, mu, k, t, 1);
            out[self.rows[k].0] = rhs1 - dot(&b1, &self.expand(k, q, true));
        }
    }

    /// Moving rows of `out` set to `b̈ − 2 Ḃ V q̇ − B̈ x(q)`.
    pub fn acceleration_rhs<M: ElementModel>(
        &self,
        full: &M,
        mu: &Parameters,
        q: &[f64],
        v: &[f64],
        t: f64,
        out: &mut [f64],
    ) {
        for k in 0..self.rows.len() {
            let (b1, _) = self.at(full, mu, k, t, 1);
            let (b2, rhs2) = self.at(full, mu, k, t, 2);
            let (x, xd) = (self.expand(k, q, true), self.expand(k, v, false));
            out[self.rows[k].0] = rhs2 - 2.0 * dot(&b1, &xd) - dot(&b2, &x);
        }
    }

    /// `out += (B_c(t) V)ᵀ λ_c` over the moving rows.
    pub fn add_force<M: ElementModel>(&self, full: &M, mu: &Parameters, lambda: &[f64], t: f64, out: &mut [f64]) {
        for (k, (c, v, _)) in self.rows.iter().enumerate() {
            let (b, _) = self.at(full, mu, k, t, 0);
            for (i, row) in v.rows().into_iter().enumerate() {
                let f = b[i] * lambda[*c];
                row.iter().zip(out.iter_mut()).for_each(|(vi, o)| *o += f * vi);
            }
        }
    }

    /// Sets the moving rows of `b_r` to `B_c(t) V`, for the Newton matrix at `t`.
    pub fn set_rows<M: ElementModel>(&self, full: &M, mu: &Parameters, t: f64, b_r: &mut Array2<f64>) {
        for (k, (c, v, _)) in self.rows.iter().enumerate() {
            let (b, _) = self.at(full, mu, k, t, 0);
            let mut row = b_r.row_mut(*c);
            row.fill(0.0);
            for (i, vrow) in v.rows().into_iter().enumerate() {
                row.scaled_add(b[i], &vrow);
            }
        }
    }
}

impl Projection {
    /// `out = B_r(t) q + c_r(t)`: the constant rows as projected, the moving ones at `t`.
    pub fn constraint_residual_at<M: ElementModel>(
        &self,
        full: &M,
        mu: &Parameters,
        q: &[f64],
        t: f64,
        out: &mut [f64],
    ) {
        self.constraint_residual(q, out);
        self.moving.residual(full, mu, q, t, out);
    }

    /// `out += B_r(t)ᵀ λ`.
    pub fn add_constraint_force_at<M: ElementModel>(
        &self,
        full: &M,
        mu: &Parameters,
        lambda: &[f64],
        t: f64,
        out: &mut [f64],
    ) {
        if self.moving.is_empty() {
            return self.add_constraint_force(lambda, out);
        }
        for (c, (row, l)) in self.b_r.rows().into_iter().zip(lambda).enumerate() {
            if !self.moving.moves(c) {
                row.iter().zip(out.iter_mut()).for_each(|(b, o)| *o += b * l);
            }
        }
        self.moving.add_force(full, mu, lambda, t, out);
    }
}
