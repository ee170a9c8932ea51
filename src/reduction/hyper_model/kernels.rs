//! The hyper-reduced model's per-iteration kernels: the invariants and their derivatives
//! at `q` (`update`) and the sampled elements' tangent (`tangent`), each compiled for the
//! CPU's best instruction set through [`crate::linalg::simd`].

use super::columns::{add_element, add_row_pair};
use super::HyperReducedModel;
use crate::linalg::simd::{dispatch, Kernel};
use crate::reduction::projection::axpy;
use crate::solver::model::InvariantElementModel;

impl<M: InvariantElementModel> HyperReducedModel<M> {
    /// s_j = xₑᵀSⱼxₑ, ψⱼ, ψⱼₖ and uⱼ = Vₑᵀ Sⱼ xₑ of every sampled element at `q`, with
    /// xₑ = x_ref,ₑ + Vₑ q (once per q: the integrator asks for the force and then the
    /// matrix at the same q).
    pub(super) fn update(&mut self, q: &[f64]) {
        if self.valid && self.at == q {
            return;
        }
        // the kernel, inlined whole into the dispatched function (see crate::linalg::simd)
        struct Update<'a, T: InvariantElementModel, const N: usize>(&'a mut HyperReducedModel<T>, &'a [f64]);
        impl<T: InvariantElementModel, const N: usize> Kernel for Update<'_, T, N> {
            type Output = ();
            #[inline(always)]
            fn run(self) {
                self.0.update_with::<N>(self.1)
            }
        }
        match self.ne {
            4 => dispatch(Update::<M, 4>(self, q)),
            6 => dispatch(Update::<M, 6>(self, q)),
            8 => dispatch(Update::<M, 8>(self, q)),
            12 => dispatch(Update::<M, 12>(self, q)),
            _ => unreachable!("element size checked in new()"),
        }
        self.at.copy_from_slice(q);
        self.valid = true;
    }

    /// [`Self::accumulate_tangent`], compiled for the CPU's best instruction set
    /// ([`crate::linalg::simd`]): the row passes are plain multiply-adds that the compiler
    /// vectorizes 4 wide with AVX2 instead of SSE2's 2, with the same sums to the last bit.
    pub(super) fn tangent(&mut self) {
        struct Tangent<'a, T: InvariantElementModel>(&'a mut HyperReducedModel<T>);
        impl<T: InvariantElementModel> Kernel for Tangent<'_, T> {
            type Output = ();
            #[inline(always)]
            fn run(self) {
                self.0.accumulate_tangent()
            }
        }
        dispatch(Tangent(self))
    }

    /// `acc` = the upper triangle of Σ_E wₑ [Σⱼ 2ψⱼ Gₑⱼ + Σⱼₖ 4ψⱼₖ uⱼ uₖᵀ] at the cached point
    /// (both terms are symmetric), on the runs that elements reach (the rest stays zero).
    #[inline(always)]
    fn accumulate_tangent(&mut self) {
        let (r, nj) = (self.p.r, self.nj);
        for &(i, j0, j1) in &self.runs {
            self.acc[i * r + j0..i * r + j1].fill(0.0);
        }
        if nj == 1 {
            return self.accumulate_tangent_pairs();
        }
        for (k, &w) in self.weights.iter().enumerate() {
            let c = self.cols[k];
            let me = c.len();
            for j in 0..nj {
                let a = 2.0 * w * self.psi[k * nj + j];
                let b = 4.0 * w * self.psi2[k * nj * nj + j * nj + j];
                let g = &self.g_el[self.g_off[k * nj + j]..];
                let uj = &self.u_el[(k * nj + j) * r..(k * nj + j) * r + me];
                add_element(&mut self.acc, &c, r, g, uj, a, b);
                // the mixed terms of models with several invariants
                for jj in (0..nj).filter(|&jj| jj != j) {
                    let b = 4.0 * w * self.psi2[k * nj * nj + jj * nj + j];
                    let ujj = &self.u_el[(k * nj + jj) * r..(k * nj + jj) * r + me];
                    for l in 0..me {
                        let (at, len, at2, len2) = c.row(l, r);
                        axpy(b * uj[l], &ujj[l..l + len], &mut self.acc[at..at + len]);
                        axpy(b * uj[l], &ujj[me - len2..me], &mut self.acc[at2..at2 + len2]);
                    }
                }
            }
        }
    }

    /// [`Self::accumulate_tangent`] for one invariant per element: two consecutive elements
    /// that see the same columns share one pass over the rows, so `acc` is read and
    /// written half as often (four at a time measured no faster).
    #[inline(always)]
    fn accumulate_tangent_pairs(&mut self) {
        let r = self.p.r;
        let n = self.weights.len();
        let coefs = |k: usize| (2.0 * self.weights[k] * self.psi[k], 4.0 * self.weights[k] * self.psi2[k]);
        let mut k = 0;
        while k < n {
            let c = self.cols[k];
            let me = c.len();
            let g = |kk: usize| &self.g_el[self.g_off[kk]..self.g_off[kk] + me * (me + 1) / 2];
            let u = |kk: usize| &self.u_el[kk * r..kk * r + me];
            let mut p = 0;
            if k + 1 < n && self.cols[k + 1] == c {
                let (ab1, ab2) = (coefs(k), coefs(k + 1));
                let (g1, g2, u1, u2) = (g(k), g(k + 1), u(k), u(k + 1));
                for l in 0..me {
                    let (a, cu) = ((ab1.0, ab2.0), (ab1.1 * u1[l], ab2.1 * u2[l]));
                    let (at, len, at2, len2) = c.row(l, r);
                    add_row_pair(
                        &mut self.acc[at..at + len],
                        (&g1[p..p + len], &g2[p..p + len]),
                        (&u1[l..l + len], &u2[l..l + len]),
                        a,
                        cu,
                    );
                    if len2 > 0 {
                        let (q, v) = (p + len, me - len2);
                        add_row_pair(
                            &mut self.acc[at2..at2 + len2],
                            (&g1[q..q + len2], &g2[q..q + len2]),
                            (&u1[v..me], &u2[v..me]),
                            a,
                            cu,
                        );
                    }
                    p += len + len2;
                }
                k += 2;
            } else {
                let (a1, b1) = coefs(k);
                add_element(&mut self.acc, &c, r, g(k), u(k), a1, b1);
                k += 1;
            }
        }
    }

    /// `update` for elements of `N` dofs: fixed-size kernels, unrolled and vectorized by the
    /// compiler (a quarter faster than the same sums over slices of run-time length).
    #[inline(always)]
    fn update_with<const N: usize>(&mut self, q: &[f64]) {
        let (nj, r) = (self.nj, self.p.r);
        let x_ref = self.x_ref_el.as_slice().expect("contiguous");
        for (k, &e) in self.elements.iter().enumerate() {
            let ce = self.cols[k];
            let me = ce.len();
            let cols = &self.vt_el[self.vt_off[k]..self.vt_off[k] + me * N];
            let mut x: [f64; N] = x_ref[k * N..(k + 1) * N].try_into().expect("N entries");
            let (c1, c2) = cols.split_at(ce.n1() * N);
            for (c, &qa) in c1.chunks_exact(N).zip(&q[ce.a.0..ce.a.1]) {
                for i in 0..N {
                    x[i] += qa * c[i];
                }
            }
            // the second run, when there is one (a chained iterator would branch per column)
            for (c, &qa) in c2.chunks_exact(N).zip(&q[ce.b.0..ce.b.1]) {
                for i in 0..N {
                    x[i] += qa * c[i];
                }
            }
            for j in 0..nj {
                let s = &self.s_el[(k * nj + j) * N * N..(k * nj + j + 1) * N * N];
                let mut y = [0.0; N];
                for (sc, &xc) in s.chunks_exact(N).zip(&x) {
                    for i in 0..N {
                        y[i] += sc[i] * xc;
                    }
                }
                self.s_val[k * nj + j] = (0..N).map(|i| x[i] * y[i]).sum();
                let u = &mut self.u_el[(k * nj + j) * r..(k * nj + j) * r + me];
                for (ua, c) in u.iter_mut().zip(cols.chunks_exact(N)) {
                    *ua = (0..N).map(|i| c[i] * y[i]).sum();
                }
            }
            self.full.invariant_derivatives(
                e,
                &self.s_val[k * nj..(k + 1) * nj],
                &mut self.psi[k * nj..(k + 1) * nj],
                &mut self.psi2[k * nj * nj..(k + 1) * nj * nj],
            );
        }
    }
}
