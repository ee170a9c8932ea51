//! The constraint-preserving Newton system solved in the null space of its joint rows.
//!
//! The reduced KKT system of a Newton iteration (scaled constraint rows, `s > 0`)
//!
//! ```text
//!     [S    s Bᵀ] [Δq]   [r_q]
//!     [s B   0  ] [Δμ] = [r_c]
//! ```
//!
//! has `B = [0, B_c]` when the joint coordinates are kept unreduced (SPEC §3, thesis eqs.
//! 20–21): only the `j` joint columns `J` carry entries. With the SVD `B_c = U Σ R_cᵀ`
//! (`nc` × `j`, full row rank) and `N_c` an orthonormal basis of the null space of `B_c`,
//! `P = blockdiag(I_F, N_c)` spans the null space of `B`, and (Gill, Murray & Wright,
//! *Practical Optimization*, §5.1, the null-space method)
//!
//! ```text
//!     Δq_p = [0; R_c Σ⁻¹ Uᵀ r_c / s]                    (B Δq_p = r_c / s)
//!     (Pᵀ S P) Δz = Pᵀ (r_q − S Δq_p),   Δq = Δq_p + P Δz
//!     Δμ = U Σ⁻¹ R_cᵀ (r_q − S Δq)_J / s               (= (s B Bᵀ)⁻¹ s B (r_q − S Δq))
//! ```
//!
//! solve the same system exactly: `Pᵀ S P` is `r − nc` square instead of `r + nc` (the
//! thesis four-bar: 54 instead of 70, an LU 40 % as costly), and forming it touches only the
//! `j` joint rows and columns of `S`. The multipliers stay exact.

use crate::error::{Error, Result};
use crate::linalg::dense_lu::DenseLu;
use crate::linalg::lapack::SVD;
use crate::linalg::vec_ops::{axpy, dot};
use ndarray::Array2;

pub(crate) struct JointElimination {
    r: usize,
    nc: usize,
    /// the free columns are `0..f`, the joint ones `f..r` (the constraint-preserving basis
    /// puts its unreduced joint coordinates last)
    f: usize,
    /// `N_c` (j × k, k = j − nc), `R_c` (j × nc), `U` (nc × nc), all column-major, and `Σ⁻¹`
    null: Vec<f64>,
    range: Vec<f64>,
    u: Vec<f64>,
    sigma_inv: Vec<f64>,
    /// `S` of the last factorization, r × r column-major (filled by the caller)
    pub s: Vec<f64>,
    scale: f64,
    // work space
    w: Vec<f64>,
    dqj: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    t: Vec<f64>,
}

impl JointElimination {
    /// For `b` (nc × r) whose nonzero columns are the last `j ≤ r/2` ones and which has
    /// full row rank; `None` otherwise (the caller keeps the KKT system).
    pub fn new(b: &Array2<f64>) -> Option<Self> {
        let (nc, r) = b.dim();
        let f = (0..r).find(|&c| b.column(c).iter().any(|&x| x != 0.0))?;
        let j = r - f;
        if nc == 0 || 2 * j > r || (f..r).any(|c| b.column(c).iter().all(|&x| x == 0.0)) {
            return None;
        }
        let bc = b.slice(ndarray::s![.., f..]).to_owned();
        let (u, sigma, vt) = bc.svd(true, true).ok()?;
        let (u, vt) = (u?, vt?);
        // full row rank, relative to the largest singular value (B has unit entries)
        if sigma.len() < nc || sigma[nc - 1] <= 1e-10 * sigma[0] {
            return None;
        }
        let k = j - nc;
        let col_major = |rows: usize, cols: usize, at: &dyn Fn(usize, usize) -> f64| -> Vec<f64> {
            (0..cols).flat_map(|c| (0..rows).map(move |i| (i, c))).map(|(i, c)| at(i, c)).collect()
        };
        Some(JointElimination {
            r,
            nc,
            f,
            null: col_major(j, k, &|i, c| vt[[nc + c, i]]),
            range: col_major(j, nc, &|i, a| vt[[a, i]]),
            u: col_major(nc, nc, &|c, a| u[[c, a]]),
            sigma_inv: (0..nc).map(|a| 1.0 / sigma[a]).collect(),
            s: vec![0.0; r * r],
            scale: 1.0,
            w: vec![0.0; nc],
            dqj: vec![0.0; j],
            y: vec![0.0; r],
            z: vec![0.0; r - nc],
            t: vec![0.0; j],
        })
    }

    /// Dimension of the eliminated system, `r − nc`.
    pub fn dim(&self) -> usize {
        self.r - self.nc
    }

    /// Writes `Pᵀ S P` (column-major, `dim()` square) into `out`; `scale` is the `s` the
    /// constraint rows of the right-hand sides will carry.
    pub fn reduce(&mut self, scale: f64, out: &mut [f64]) {
        let (r, f) = (self.r, self.f);
        let (j, m) = (r - f, self.dim());
        let k = m - f;
        self.scale = scale;
        let (s, null) = (&self.s, &self.null);
        for b in 0..f {
            let (col, scol) = (&mut out[m * b..m * (b + 1)], &s[r * b..r * (b + 1)]);
            // S_FF, then N_cᵀ S_JF
            col[..f].copy_from_slice(&scol[..f]);
            for c in 0..k {
                col[f + c] = dot(&null[j * c..j * (c + 1)], &scol[f..]);
            }
        }
        for c in 0..k {
            let nc_col = &null[j * c..j * (c + 1)];
            let col = &mut out[m * (f + c)..m * (f + c + 1)];
            col.fill(0.0);
            // S_FJ N_c and S_JJ N_c (the latter in the work vector)
            self.t.fill(0.0);
            for (i, &n) in nc_col.iter().enumerate() {
                let scol = &s[r * (f + i)..r * (f + i + 1)];
                axpy(n, &scol[..f], &mut col[..f]);
                axpy(n, &scol[f..], &mut self.t);
            }
            for d in 0..k {
                col[f + d] = dot(&null[j * d..j * (d + 1)], &self.t);
            }
        }
    }

    /// Solves the KKT system in place (`rhs = [r_q; r_c]` → `[Δq; Δμ]`) with `lu` holding
    /// the factorized `Pᵀ S P` of the last [`Self::reduce`].
    pub fn solve(&mut self, lu: &mut DenseLu, rhs: &mut [f64]) -> Result<()> {
        let (r, nc, f) = (self.r, self.nc, self.f);
        let (j, k) = (r - f, self.dim() - f);
        if rhs.len() != r + nc {
            return Err(Error::linear_solve(format!(
                "right-hand side has {} entries, the system {}",
                rhs.len(),
                r + nc
            )));
        }
        let (rq, rc) = rhs.split_at_mut(r);
        let s = &self.s;
        // Δq_p on the joint columns: R_c Σ⁻¹ Uᵀ r_c / s
        for (a, w) in self.w.iter_mut().enumerate() {
            *w = self.sigma_inv[a] * dot(&self.u[nc * a..nc * (a + 1)], rc) / self.scale;
        }
        self.dqj.fill(0.0);
        for (a, &w) in self.w.iter().enumerate() {
            axpy(w, &self.range[j * a..j * (a + 1)], &mut self.dqj);
        }
        // y = r_q − S[:, J] Δq_p,J ; z = Pᵀ y
        self.y.copy_from_slice(rq);
        for (i, &d) in self.dqj.iter().enumerate() {
            axpy(-d, &s[r * (f + i)..r * (f + i + 1)], &mut self.y);
        }
        self.z[..f].copy_from_slice(&self.y[..f]);
        for c in 0..k {
            self.z[f + c] = dot(&self.null[j * c..j * (c + 1)], &self.y[f..]);
        }
        lu.solve(&mut self.z)?;
        // Δq = Δq_p + P Δz, written over r_q once r_q − S Δq is known on the joint rows
        for c in 0..k {
            axpy(self.z[f + c], &self.null[j * c..j * (c + 1)], &mut self.dqj);
        }
        let dq = |col: usize| if col < f { self.z[col] } else { self.dqj[col - f] };
        // t = (r_q − S Δq)_J
        self.t.copy_from_slice(&rq[f..]);
        for col in 0..r {
            axpy(-dq(col), &s[r * col + f..r * (col + 1)], &mut self.t);
        }
        rq[..f].copy_from_slice(&self.z[..f]);
        rq[f..].copy_from_slice(&self.dqj);
        // Δμ = U Σ⁻¹ R_cᵀ t / s
        for (a, w) in self.w.iter_mut().enumerate() {
            *w = self.sigma_inv[a] * dot(&self.range[j * a..j * (a + 1)], &self.t) / self.scale;
        }
        rc.fill(0.0);
        for (a, &w) in self.w.iter().enumerate() {
            axpy(w, &self.u[nc * a..nc * (a + 1)], rc);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The null-space solve equals the KKT solve by LU on a system built by hand: a
    /// nonsymmetric, diagonally dominant 10×10 `S`, and three joint rows on columns 6–9 (a
    /// pin between 6–7 and 8–9, and 9 held) as a joint pattern; both solved with the
    /// constraint scale s = 3. Bound: round-off of two small LUs, 1e-12.
    #[test]
    fn null_space_solve_equals_the_kkt_solve() {
        let r = 10;
        let mut b = Array2::zeros((3, r));
        // pins between joint columns 6–9 and a ground pin on 9 (columns 0–5 free)
        b[[0, 6]] = 1.0;
        b[[0, 8]] = -1.0;
        b[[1, 7]] = 1.0;
        b[[1, 9]] = -1.0;
        b[[2, 9]] = 1.0;
        let mut el = JointElimination::new(&b).expect("eligible");
        assert_eq!(el.dim(), r - 3);
        let s_mat = Array2::from_shape_fn((r, r), |(i, j)| {
            if i == j {
                5.0 + i as f64
            } else {
                ((3 * i + 7 * j) % 5) as f64 / 7.0 - 0.3
            }
        });
        for j in 0..r {
            for i in 0..r {
                el.s[i + r * j] = s_mat[[i, j]];
            }
        }
        let scale = 3.0;
        let mut lu = DenseLu::new(el.dim());
        el.reduce(scale, lu.matrix_mut());
        lu.factor().unwrap();
        let rhs: Vec<f64> = (0..r + 3).map(|i| (i as f64 * 0.7).sin() + 0.5).collect();
        let mut x = rhs.clone();
        el.solve(&mut lu, &mut x).unwrap();

        let n = r + 3;
        let mut kkt = DenseLu::new(n);
        {
            let a = kkt.matrix_mut();
            for j in 0..r {
                for i in 0..r {
                    a[i + n * j] = s_mat[[i, j]];
                }
            }
            for c in 0..3 {
                for j in 0..r {
                    a[(r + c) + n * j] = scale * b[[c, j]];
                    a[j + n * (r + c)] = scale * b[[c, j]];
                }
            }
        }
        kkt.factor().unwrap();
        let mut y = rhs.clone();
        kkt.solve(&mut y).unwrap();
        for (a, e) in x.iter().zip(&y) {
            assert!((a - e).abs() < 1e-12 * (1.0 + e.abs()), "{x:?}\n{y:?}");
        }
    }

    /// Dense constraint rows (every column), joint columns that are not the last ones, or
    /// dependent rows keep the KKT system.
    #[test]
    fn refuses_dense_scattered_or_rank_deficient_rows() {
        assert!(JointElimination::new(&Array2::from_elem((2, 6), 1.0)).is_none());
        let mut b = Array2::zeros((2, 8));
        b[[0, 7]] = 1.0;
        b[[1, 7]] = 2.0;
        assert!(JointElimination::new(&b).is_none());
        let mut b = Array2::zeros((1, 8));
        b[[0, 5]] = 1.0;
        b[[0, 7]] = 1.0;
        assert!(JointElimination::new(&b).is_none());
    }
}
