//! The sampled elements of the hyper-reduced model, stored for block kernels.
//!
//! Elements that see the same columns of `V` ([`Cols`]) form a group of `m` elements on `mₑ`
//! local columns (a global basis: one group of every sampled element; one basis block per
//! body: one group per body, plus one per distinct set of joint columns). Per iteration:
//!
//! ```text
//!   update (per element):  xₑ = x_ref,ₑ + Vₑ q,   yⱼ = Sⱼ xₑ,   sⱼ = xₑ·yⱼ,   uₑⱼ = Vₑᵀ yⱼ
//!   force:    Σₑⱼ 2wₑψₑⱼ uₑⱼ, element by element (the earlier sums, to the bit)
//!   tangent:  T = Σₜ aₜ Gₜ + Σₜ wₜ uₜᵀ,   t = (e, j),  aₜ = 2wₑψₑⱼ,  wₜ = Σₖ 4wₑψₑⱼₖ uₑₖ
//! ```
//!
//! The tangent is computed by 4 × 4 blocks of its upper block triangle, each summed over all
//! terms of the group in registers (two accumulators per row: one for the `G` terms, one for
//! the rank-one terms, so that the additions of consecutive terms do not wait on each other)
//! and written once; `Gₜ` is stored by those blocks, the terms of a block in turn, in single
//! precision (it only enters the Newton matrix). The previous kernel added each element to
//! the r × r accumulator row by row: rows of r/2 entries on average, read and written once
//! per element (per pair of elements). Padding to a multiple of 4 adds zeros only.
//!
//! The update and the force are the earlier per-element kernels (the same sums, to the bit);
//! only where their results are stored changed.

use super::columns::Cols;
use crate::linalg::vec_ops::axpy;

/// Block size of the tangent.
pub(super) const L: usize = 4;

/// Elements that see the same columns.
pub(super) struct Group {
    pub(super) cols: Cols,
    /// local columns, and that rounded up to a multiple of [`L`]
    me: usize,
    mp: usize,
    /// the sample indices k of the members, in sample order
    pub(super) members: Vec<usize>,
    /// global column of each local one
    glob: Vec<usize>,
    /// per member: `Vₑ` on the local columns by columns (me · ne, column a at `a ne`), so the
    /// update runs over contiguous short vectors
    vt: Vec<f64>,
    /// per member: `x_ref,ₑ` (ne)
    xr: Vec<f64>,
    /// per member and invariant: `Sⱼ` (column-major ne × ne)
    sm: Vec<f64>,
    /// `Gₜ` (t = member · nj + j) by the 4 × 4 blocks of the upper block triangle, block b
    /// of every term in turn (`[b][t][row]`, rows of L), so that a block's pass over the
    /// terms reads memory in order
    g: Vec<[f32; L]>,
    /// per term: uₜ (mp entries, zero past me) by L
    u: Vec<[f64; L]>,
    /// per term: the rank-one coefficient vectors wₜ by L
    w: Vec<[f64; L]>,
    /// per term: aₜ
    a: Vec<f64>,
    /// the tangent on the local columns (mp × mp row-major, upper blocks)
    t: Vec<f64>,
}

/// `acc += a x`, lane by lane (written out, so that it compiles to one vector multiply and add)
#[inline(always)]
fn axpy4(acc: &mut [f64; L], a: f64, x: [f64; L]) {
    acc[0] += a * x[0];
    acc[1] += a * x[1];
    acc[2] += a * x[2];
    acc[3] += a * x[3];
}

#[inline(always)]
fn widen(x: [f32; L]) -> [f64; L] {
    [f64::from(x[0]), f64::from(x[1]), f64::from(x[2]), f64::from(x[3])]
}

/// The sampled elements by groups, with the invariants and their derivatives of the last
/// update (by sample index k).
pub(super) struct Sampled {
    pub(super) ne: usize,
    pub(super) nj: usize,
    r: usize,
    pub(super) groups: Vec<Group>,
    /// (group, member) of each sample index k
    order: Vec<(usize, usize)>,
    pub(super) weights: Vec<f64>,
    pub(super) s_val: Vec<f64>,
    pub(super) psi: Vec<f64>,
    pub(super) psi2: Vec<f64>,
}

impl Sampled {
    /// `v_el[k]`: the rows of `V` on element k's dofs (ne × r), `x_ref[k]` its reference,
    /// `s_mat[k][j]` its invariant matrices (column-major ne × ne).
    pub(super) fn new(
        r: usize,
        v_el: &[ndarray::ArrayView2<f64>],
        x_ref: &[&[f64]],
        s_mat: &[Vec<Vec<f64>>],
        weights: &[f64],
    ) -> Sampled {
        let m = v_el.len();
        let ne = v_el.first().map_or(0, |v| v.nrows());
        let nj = s_mat.first().map_or(0, |s| s.len());
        let cols: Vec<Cols> = v_el.iter().map(|v| Cols::of(*v)).collect();
        let mut groups: Vec<Group> = Vec::new();
        for (k, c) in cols.iter().enumerate() {
            match groups.iter_mut().find(|g| g.cols == *c) {
                Some(g) => g.members.push(k),
                None => {
                    let me = c.len();
                    let mp = me.div_ceil(L) * L;
                    groups.push(Group {
                        cols: *c,
                        me,
                        mp,
                        members: vec![k],
                        glob: c.iter().collect(),
                        vt: Vec::new(),
                        xr: Vec::new(),
                        sm: Vec::new(),
                        g: Vec::new(),
                        u: Vec::new(),
                        w: Vec::new(),
                        a: Vec::new(),
                        t: vec![0.0; mp * mp],
                    })
                }
            }
        }
        for g in &mut groups {
            let (me, mp, nm) = (g.me, g.mp, g.members.len());
            g.vt = vec![0.0; nm * me * ne];
            g.xr = vec![0.0; nm * ne];
            g.sm = vec![0.0; nm * nj * ne * ne];
            let nb = mp / L;
            let nblk = nb * (nb + 1) / 2;
            g.g = vec![[0.0; L]; nm * nj * nblk * L];
            g.u = vec![[0.0; L]; nm * nj * nb];
            g.w = vec![[0.0; L]; nm * nj * nb];
            g.a = vec![0.0; nm * nj];
            for (mi, &k) in g.members.iter().enumerate() {
                let ve = &v_el[k];
                for (a, col) in g.glob.iter().enumerate() {
                    for i in 0..ne {
                        g.vt[(mi * me + a) * ne + i] = ve[[i, *col]];
                    }
                }
                g.xr[mi * ne..(mi + 1) * ne].copy_from_slice(x_ref[k]);
                for j in 0..nj {
                    let sm = &s_mat[k][j];
                    g.sm[(mi * nj + j) * ne * ne..(mi * nj + j + 1) * ne * ne].copy_from_slice(sm);
                    // Gₑⱼ = Vₑᵀ Sⱼ Vₑ on the local columns (the products of the earlier kernel,
                    // so that its single-precision copy is the same to the bit)
                    let ves = ve.select(ndarray::Axis(1), &g.glob);
                    let smat = ndarray::Array2::from_shape_fn((ne, ne), |(a, b)| sm[b * ne + a]);
                    let gfull = ves.t().dot(&smat.dot(&ves));
                    let gm = |a: usize, b: usize| gfull[[a, b]];
                    let (t, nt) = (mi * nj + j, nm * nj);
                    let mut b = 0;
                    for bi in 0..nb {
                        for bj in bi..nb {
                            for ii in 0..L {
                                for jj in 0..L {
                                    let (ia, ib) = (bi * L + ii, bj * L + jj);
                                    if ia < me && ib < me {
                                        g.g[(b * nt + t) * L + ii][jj] = gm(ia, ib) as f32;
                                    }
                                }
                            }
                            b += 1;
                        }
                    }
                }
            }
        }
        let mut order = vec![(0, 0); m];
        for (gi, g) in groups.iter().enumerate() {
            for (mi, &k) in g.members.iter().enumerate() {
                order[k] = (gi, mi);
            }
        }
        Sampled {
            ne,
            nj,
            r,
            groups,
            order,
            weights: weights.to_vec(),
            s_val: vec![0.0; m * nj],
            psi: vec![0.0; m * nj],
            psi2: vec![0.0; m * nj * nj],
        }
    }

    /// xₑ, sⱼ and uₑⱼ of every sampled element at `q` (elements of `N` dofs), then ψ and ψ'
    /// from `derivatives(k, s, ψ, ψ')`: fixed-size kernels per element, unrolled and
    /// vectorized over the dofs by the compiler (four elements side by side in the vector
    /// lanes measured no faster on the pendulum and slower on the four-bar, whose groups of
    /// one or two elements leave lanes empty).
    #[inline(always)]
    pub(super) fn update<const N: usize>(
        &mut self,
        q: &[f64],
        mut derivatives: impl FnMut(usize, &[f64], &mut [f64], &mut [f64]),
    ) {
        let nj = self.nj;
        debug_assert_eq!(N, self.ne);
        for g in &mut self.groups {
            let (me, nb, n1) = (g.me, g.mp / L, g.cols.n1());
            let (qa_run, qb_run) = (&q[g.cols.a.0..g.cols.a.1], &q[g.cols.b.0..g.cols.b.1]);
            for (mi, &k) in g.members.iter().enumerate() {
                let cols = &g.vt[mi * me * N..(mi + 1) * me * N];
                let mut x: [f64; N] = g.xr[mi * N..(mi + 1) * N].try_into().expect("N entries");
                let (c1, c2) = cols.split_at(n1 * N);
                for (c, &qa) in c1.chunks_exact(N).zip(qa_run) {
                    for i in 0..N {
                        x[i] += qa * c[i];
                    }
                }
                // the second run, when there is one (a chained iterator would branch per column)
                for (c, &qa) in c2.chunks_exact(N).zip(qb_run) {
                    for i in 0..N {
                        x[i] += qa * c[i];
                    }
                }
                for j in 0..nj {
                    let s = &g.sm[(mi * nj + j) * N * N..(mi * nj + j + 1) * N * N];
                    let mut y = [0.0; N];
                    for (sc, &xc) in s.chunks_exact(N).zip(&x) {
                        for i in 0..N {
                            y[i] += sc[i] * xc;
                        }
                    }
                    self.s_val[k * nj + j] = (0..N).map(|i| x[i] * y[i]).sum();
                    let t = mi * nj + j;
                    let u = &mut g.u[t * nb..(t + 1) * nb].as_flattened_mut()[..me];
                    for (ua, c) in u.iter_mut().zip(cols.chunks_exact(N)) {
                        *ua = (0..N).map(|i| c[i] * y[i]).sum();
                    }
                }
                derivatives(
                    k,
                    &self.s_val[k * nj..(k + 1) * nj],
                    &mut self.psi[k * nj..(k + 1) * nj],
                    &mut self.psi2[k * nj * nj..(k + 1) * nj * nj],
                );
            }
        }
    }

    /// `out += Σₑ wₑ Σⱼ 2ψₑⱼ uₑⱼ` on the elements' columns, element by element in sample
    /// order (the sums of the earlier kernel, to the bit: the force decides where Newton
    /// stops, and the four-bar's late trajectory amplifies any change of it).
    #[inline(always)]
    pub(super) fn add_force(&mut self, out: &mut [f64]) {
        let nj = self.nj;
        for &(gi, mi) in &self.order {
            let g = &self.groups[gi];
            let (k, nb) = (g.members[mi], g.mp / L);
            for j in 0..nj {
                let c = 2.0 * self.weights[k] * self.psi[k * nj + j];
                let t = mi * nj + j;
                // on the (at most two) runs of columns: contiguous, vectorized
                let u = &g.u[t * nb..(t + 1) * nb].as_flattened()[..g.me];
                let ((a0, a1), (b0, b1)) = (g.cols.a, g.cols.b);
                axpy(c, &u[..a1 - a0], &mut out[a0..a1]);
                axpy(c, &u[a1 - a0..], &mut out[b0..b1]);
            }
        }
    }

    /// `acc += Σₑ wₑ [Σⱼ 2ψⱼ Gₑⱼ + Σⱼₖ 4ψⱼₖ uⱼ uₖᵀ]` on the upper triangle of the row-major
    /// r × r `acc` (the element's columns are increasing, so local upper is global upper).
    #[inline(always)]
    pub(super) fn add_tangent(&mut self, acc: &mut [f64]) {
        let (nj, r) = (self.nj, self.r);
        for g in &mut self.groups {
            let (me, mp) = (g.me, g.mp);
            // the coefficients: aₜ = 2wψⱼ, wₜ = Σⱼ 4wψⱼₖ uⱼ for t = (e, k)
            for (mi, &k) in g.members.iter().enumerate() {
                let w = self.weights[k];
                for kk in 0..nj {
                    let t = mi * nj + kk;
                    g.a[t] = 2.0 * w * self.psi[k * nj + kk];
                    let nb = mp / L;
                    let wt = g.w[t * nb..(t + 1) * nb].as_flattened_mut();
                    let rest = g.u[mi * nj * nb..(mi + 1) * nj * nb].as_flattened();
                    if nj == 1 {
                        let c = 4.0 * w * self.psi2[k];
                        wt.iter_mut().zip(rest).for_each(|(o, u)| *o = c * u);
                    } else {
                        wt.fill(0.0);
                        for j in 0..nj {
                            let c = 4.0 * w * self.psi2[k * nj * nj + kk * nj + j];
                            wt.iter_mut().zip(&rest[j * mp..(j + 1) * mp]).for_each(|(o, u)| *o += c * u);
                        }
                    }
                }
            }
            let nt = g.members.len() * nj;
            let nb = mp / L;
            let mut b = 0;
            for bi in 0..nb {
                for bj in bi..nb {
                    // one pass over the terms, G and rank-one parts in separate accumulators
                    let mut cg = [[0.0; L]; L];
                    let mut cu = [[0.0; L]; L];
                    let gb = &g.g[b * nt * L..(b + 1) * nt * L];
                    for ((gt, &a), t) in gb.chunks_exact(L).zip(&g.a).zip(0..nt) {
                        let (wt, ut) = (g.w[t * nb + bi], g.u[t * nb + bj]);
                        for ii in 0..L {
                            axpy4(&mut cg[ii], a, widen(gt[ii]));
                            axpy4(&mut cu[ii], wt[ii], ut);
                        }
                    }
                    for ii in 0..L {
                        let row = &mut g.t[(bi * L + ii) * mp + bj * L..(bi * L + ii) * mp + (bj + 1) * L];
                        for jj in 0..L {
                            row[jj] = cg[ii][jj] + cu[ii][jj];
                        }
                    }
                    b += 1;
                }
            }
            // local row i to the global rows: its upper part on the first run, then the second
            let (n1, (a0, _), (b0, _)) = (g.cols.n1(), g.cols.a, g.cols.b);
            for i in 0..me {
                let (t, o) = (&g.t[i * mp..i * mp + me], &mut acc[g.glob[i] * r..(g.glob[i] + 1) * r]);
                if i < n1 {
                    o[a0 + i..a0 + n1].iter_mut().zip(&t[i..n1]).for_each(|(o, t)| *o += t);
                    o[b0..b0 + me - n1].iter_mut().zip(&t[n1..]).for_each(|(o, t)| *o += t);
                } else {
                    o[b0 + i - n1..b0 + me - n1].iter_mut().zip(&t[i..]).for_each(|(o, t)| *o += t);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    //! The block kernels against the per-element formulas, written out directly, on random
    //! data: global bases (one group), block bases with shared joint columns (elements on two
    //! runs of columns, several groups, groups whose size is not a multiple of 4), one and two
    //! invariants, 4, 6, 8 and 12 dofs. Expected: the same `s`, force and tangent up to
    //! round-off (relative 1e-12 for the double-precision force; 1e-6 for the tangent, whose
    //! `G` is stored in single precision, 6e-8 relative per entry).
    use super::*;
    use ndarray::Array2;

    /// xorshift, uniform in [-1, 1)
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    /// Element k's rows of V: nonzero on the columns of its "body" block and on a few joint
    /// columns at the end (the layout of a block basis), or on every column (global).
    fn element_rows(rng: &mut Rng, ne: usize, r: usize, k: usize, layout: usize) -> Array2<f64> {
        let mut v = Array2::zeros((ne, r));
        let (nb, nj_cols) = (3, 5);
        let body = (r - nj_cols) / nb;
        for c in 0..r {
            let on = match layout {
                0 => true,
                _ => {
                    let b = (k * 7 / 3) % nb;
                    (c >= b * body && c < (b + 1) * body) || (c >= r - nj_cols && (c + k) % 3 != 0)
                }
            };
            if on {
                for i in 0..ne {
                    v[[i, c]] = rng.next();
                }
            }
        }
        v
    }

    fn check(ne: usize, r: usize, m: usize, nj: usize, layout: usize, seed: u64) {
        let mut rng = Rng(seed);
        let v: Vec<Array2<f64>> = (0..m).map(|k| element_rows(&mut rng, ne, r, k, layout)).collect();
        let x_ref: Vec<Vec<f64>> = (0..m).map(|_| (0..ne).map(|_| rng.next()).collect()).collect();
        let s_mat: Vec<Vec<Vec<f64>>> = (0..m)
            .map(|_| {
                (0..nj)
                    .map(|_| {
                        let mut s = vec![0.0; ne * ne];
                        for i in 0..ne {
                            for j in 0..=i {
                                let x = rng.next();
                                s[i * ne + j] = x;
                                s[j * ne + i] = x;
                            }
                        }
                        s
                    })
                    .collect()
            })
            .collect();
        let w: Vec<f64> = (0..m).map(|_| 1.5 + rng.next()).collect();
        let q: Vec<f64> = (0..r).map(|_| rng.next()).collect();
        // ψ(s) = (1 + j) sⱼ² + Σ_{j<k} sⱼ sₖ: a smooth function with a full symmetric Hessian
        let derivs = |_k: usize, s: &[f64], d1: &mut [f64], d2: &mut [f64]| {
            let nj = s.len();
            for j in 0..nj {
                d1[j] = 2.0 * (1.0 + j as f64) * s[j] + (0..nj).filter(|&i| i != j).map(|i| s[i]).sum::<f64>();
                for i in 0..nj {
                    d2[j * nj + i] = if i == j { 2.0 * (1.0 + j as f64) } else { 1.0 };
                }
            }
        };
        let views: Vec<_> = v.iter().map(|a| a.view()).collect();
        let xr: Vec<&[f64]> = x_ref.iter().map(|x| x.as_slice()).collect();
        let mut sm = Sampled::new(r, &views, &xr, &s_mat, &w);
        match ne {
            4 => sm.update::<4>(&q, derivs),
            6 => sm.update::<6>(&q, derivs),
            8 => sm.update::<8>(&q, derivs),
            12 => sm.update::<12>(&q, derivs),
            _ => unreachable!(),
        }
        let mut force = vec![0.0; r];
        sm.add_force(&mut force);
        let mut acc = vec![0.0; r * r];
        sm.add_tangent(&mut acc);

        // the formulas, element by element, on all r columns
        let mut force_ref = vec![0.0; r];
        let mut tan_ref = Array2::<f64>::zeros((r, r));
        let qa = ndarray::ArrayView1::from(&q);
        for k in 0..m {
            let x = &ndarray::ArrayView1::from(&x_ref[k]) + &v[k].dot(&qa);
            let smats: Vec<Array2<f64>> =
                s_mat[k].iter().map(|s| Array2::from_shape_fn((ne, ne), |(i, j)| s[j * ne + i])).collect();
            let s: Vec<f64> = smats.iter().map(|sj| x.dot(&sj.dot(&x))).collect();
            let u: Vec<_> = smats.iter().map(|sj| v[k].t().dot(&sj.dot(&x))).collect();
            let (mut d1, mut d2) = (vec![0.0; nj], vec![0.0; nj * nj]);
            derivs(k, &s, &mut d1, &mut d2);
            for j in 0..nj {
                assert!((sm.s_val[k * nj + j] - s[j]).abs() <= 1e-12 * s[j].abs().max(1.0), "s of element {k}");
                for c in 0..r {
                    force_ref[c] += w[k] * 2.0 * d1[j] * u[j][c];
                }
                tan_ref = tan_ref + v[k].t().dot(&smats[j].dot(&v[k])) * (2.0 * w[k] * d1[j]);
                for i in 0..nj {
                    for a in 0..r {
                        for b in 0..r {
                            tan_ref[[a, b]] += 4.0 * w[k] * d2[j * nj + i] * u[j][a] * u[i][b];
                        }
                    }
                }
            }
        }
        let fmax = force_ref.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        for c in 0..r {
            assert!((force[c] - force_ref[c]).abs() <= 1e-12 * fmax, "force {c}: {} vs {}", force[c], force_ref[c]);
        }
        let tmax = tan_ref.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        for a in 0..r {
            for b in 0..r {
                let want = if b >= a { tan_ref[[a, b]] } else { 0.0 };
                assert!(
                    (acc[a * r + b] - want).abs() <= 1e-6 * tmax,
                    "tangent ({a}, {b}) of ne {ne}, r {r}, m {m}, nj {nj}: {} vs {want}",
                    acc[a * r + b]
                );
            }
        }
    }

    #[test]
    fn block_kernels_match_the_per_element_formulas() {
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        for &(ne, r, m) in &[(8, 18, 23), (8, 17, 5), (4, 9, 1), (6, 23, 9), (12, 30, 13), (8, 67, 52)] {
            for nj in 1..=2 {
                for layout in 0..2 {
                    seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407) | 1;
                    check(ne, r, m, nj, layout, seed);
                }
            }
        }
    }

    #[test]
    fn block_layouts_make_several_groups() {
        let mut rng = Rng(7);
        let v: Vec<Array2<f64>> = (0..10).map(|k| element_rows(&mut rng, 8, 20, k, 1)).collect();
        let views: Vec<_> = v.iter().map(|a| a.view()).collect();
        let x: Vec<Vec<f64>> = vec![vec![0.0; 8]; 10];
        let xr: Vec<&[f64]> = x.iter().map(|x| x.as_slice()).collect();
        let s = vec![vec![vec![0.0; 64]]; 10];
        let sm = Sampled::new(20, &views, &xr, &s, &[1.0; 10]);
        assert!(sm.groups.len() > 2, "{} groups", sm.groups.len());
        assert!(sm.groups.iter().any(|g| g.cols.b.1 > g.cols.b.0), "no element on two runs of columns");
        assert_eq!(sm.groups.iter().map(|g| g.members.len()).sum::<usize>(), 10);
    }
}
