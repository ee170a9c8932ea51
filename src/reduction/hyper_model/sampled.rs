//! The sampled elements of the hyper-reduced model, stored for block kernels.
//!
//! Elements that see the same columns of `V` ([`Cols`]) form a group of `m` elements on `mₑ`
//! local columns (a global basis: one group of every sampled element; one basis block per
//! body: one group per body, plus one per distinct set of joint columns). Per iteration:
//!
//! ```text
//!   update (4 elements side by side, one per SIMD lane, no horizontal sums):
//!       xₑ = x_ref,ₑ + Vₑ q,   yⱼ = Sⱼ xₑ,   sⱼ = xₑ·yⱼ,   uₑⱼ = Vₑᵀ yⱼ
//!   force:    f_loc = Σₑⱼ 2wₑψₑⱼ uₑⱼ  (one pass over the group's uₑⱼ), scattered to the group's columns
//!   tangent:  T = Σₜ aₜ Gₜ + Σₜ wₜ uₜᵀ,   t = (e, j),  aₜ = 2wₑψₑⱼ,  wₜ = Σₖ 4wₑψₑⱼₖ uₑₖ
//! ```
//!
//! The tangent is computed by 4 × 4 blocks of its upper block triangle, each summed over all
//! terms of the group in registers (two accumulators per row: one for the `G` terms, one for
//! the rank-one terms, so that the additions of consecutive terms do not wait on each other)
//! and written once; `Gₜ` is stored by those blocks, contiguous per term, in single
//! precision (it only enters the Newton matrix). The previous kernel added each element to
//! the r × r accumulator row by row: rows of r/2 entries on average, read and written once
//! per element (per pair of elements). Padding to a multiple of 4 adds zeros only.
//!
//! The update stores `Vₑ` of four elements interleaved, `[column][dof][lane]`: the sums run
//! over columns and dofs with the four elements in the four lanes of one vector, in the
//! same order as the per-element formulas (the same bits for `x`, `y`, `s` and `u`).

use super::columns::Cols;

/// Block size of the tangent and number of lanes of the update.
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
    /// per chunk of L members: `Vₑ` as `[a][i][lane]` (me · ne vectors of L)
    v: Vec<[f64; L]>,
    /// per chunk: `x_ref,ₑ` as `[i][lane]`
    x_ref: Vec<[f64; L]>,
    /// per chunk and invariant: `Sⱼ` (column-major ne × ne) as `[c][i][lane]`
    s: Vec<[f64; L]>,
    /// `Gₜ` (t = member · nj + j) by the 4 × 4 blocks of the upper block triangle, block b
    /// of every term in turn (`[b][t][row]`, rows of L), so that a block's pass over the
    /// terms reads memory in order
    g: Vec<[f32; L]>,
    /// per term: uₜ (mp entries, zero past me) by L
    u: Vec<[f64; L]>,
    /// uⱼ of one chunk, `[a][lane]` (me vectors)
    ut: Vec<[f64; L]>,
    /// per term: the rank-one coefficient vectors wₜ by L
    w: Vec<[f64; L]>,
    /// per term: aₜ
    a: Vec<f64>,
    /// the force on the local columns
    f: Vec<f64>,
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

/// `acc += x y`, lane by lane
#[inline(always)]
fn mul_add4(acc: &mut [f64; L], x: [f64; L], y: [f64; L]) {
    acc[0] += x[0] * y[0];
    acc[1] += x[1] * y[1];
    acc[2] += x[2] * y[2];
    acc[3] += x[3] * y[3];
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
                        v: Vec::new(),
                        x_ref: Vec::new(),
                        s: Vec::new(),
                        g: Vec::new(),
                        u: Vec::new(),
                        ut: vec![[0.0; L]; me],
                        w: Vec::new(),
                        a: Vec::new(),
                        f: vec![0.0; mp],
                        t: vec![0.0; mp * mp],
                    })
                }
            }
        }
        for g in &mut groups {
            let (me, mp, nm) = (g.me, g.mp, g.members.len());
            let nch = nm.div_ceil(L);
            g.v = vec![[0.0; L]; nch * me * ne];
            g.x_ref = vec![[0.0; L]; nch * ne];
            g.s = vec![[0.0; L]; nch * nj * ne * ne];
            let nb = mp / L;
            let nblk = nb * (nb + 1) / 2;
            g.g = vec![[0.0; L]; nm * nj * nblk * L];
            g.u = vec![[0.0; L]; nm * nj * nb];
            g.w = vec![[0.0; L]; nm * nj * nb];
            g.a = vec![0.0; nm * nj];
            for (mi, &k) in g.members.iter().enumerate() {
                let (ch, l) = (mi / L, mi % L);
                let ve = &v_el[k];
                for (a, col) in g.glob.iter().enumerate() {
                    for i in 0..ne {
                        g.v[(ch * me + a) * ne + i][l] = ve[[i, *col]];
                    }
                }
                for i in 0..ne {
                    g.x_ref[ch * ne + i][l] = x_ref[k][i];
                }
                for j in 0..nj {
                    let sm = &s_mat[k][j];
                    for (ci, &x) in sm.iter().enumerate() {
                        g.s[(ch * nj + j) * ne * ne + ci][l] = x;
                    }
                    // Gₑⱼ = Vₑᵀ Sⱼ Vₑ on the local columns
                    let gm = |a: usize, b: usize| -> f64 {
                        let (ca, cb) = (g.glob[a], g.glob[b]);
                        let mut sum = 0.0;
                        for c in 0..ne {
                            let mut sv = 0.0;
                            for i in 0..ne {
                                sv += sm[c * ne + i] * ve[[i, ca]];
                            }
                            sum += sv * ve[[c, cb]];
                        }
                        sum
                    };
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
        Sampled {
            ne,
            nj,
            r,
            groups,
            weights: weights.to_vec(),
            s_val: vec![0.0; m * nj],
            psi: vec![0.0; m * nj],
            psi2: vec![0.0; m * nj * nj],
        }
    }

    /// xₑ, sⱼ and uₑⱼ of every sampled element at `q` (elements of `N` dofs), then ψ and ψ'
    /// from `derivatives(k, s, ψ, ψ')`.
    #[inline(always)]
    pub(super) fn update<const N: usize>(&mut self, q: &[f64], mut derivatives: impl FnMut(usize, &[f64], &mut [f64], &mut [f64])) {
        let nj = self.nj;
        debug_assert_eq!(N, self.ne);
        for g in &mut self.groups {
            let (me, nb) = (g.me, g.mp / L);
            let nm = g.members.len();
            for ch in 0..nm.div_ceil(L) {
                let v = &g.v[ch * me * N..(ch + 1) * me * N];
                let mut x: [[f64; L]; N] = g.x_ref[ch * N..(ch + 1) * N].try_into().expect("N rows");
                for (va, &col) in v.chunks_exact(N).zip(&g.glob) {
                    let qa = q[col];
                    for i in 0..N {
                        axpy4(&mut x[i], qa, va[i]);
                    }
                }
                let lanes = (nm - ch * L).min(L);
                for j in 0..nj {
                    let s = &g.s[(ch * nj + j) * N * N..(ch * nj + j + 1) * N * N];
                    let mut y = [[0.0; L]; N];
                    for (c, sc) in s.chunks_exact(N).enumerate() {
                        for i in 0..N {
                            mul_add4(&mut y[i], sc[i], x[c]);
                        }
                    }
                    let mut sv = [0.0; L];
                    for i in 0..N {
                        mul_add4(&mut sv, x[i], y[i]);
                    }
                    for (l, &s) in sv.iter().enumerate().take(lanes) {
                        let k = g.members[ch * L + l];
                        self.s_val[k * nj + j] = s;
                    }
                    // whole vectors first (stored lane by lane, the compiler would sum each lane
                    // on its own), then to the terms' rows
                    for (ua, va) in g.ut.iter_mut().zip(v.chunks_exact(N)) {
                        *ua = [0.0; L];
                        for i in 0..N {
                            mul_add4(ua, va[i], y[i]);
                        }
                    }
                    for l in 0..lanes {
                        let row = &mut g.u[((ch * L + l) * nj + j) * nb..((ch * L + l) * nj + j + 1) * nb];
                        for (o, ua) in row.as_flattened_mut().iter_mut().zip(&g.ut) {
                            *o = ua[l];
                        }
                    }
                }
            }
            for &k in &g.members {
                derivatives(
                    k,
                    &self.s_val[k * nj..(k + 1) * nj],
                    &mut self.psi[k * nj..(k + 1) * nj],
                    &mut self.psi2[k * nj * nj..(k + 1) * nj * nj],
                );
            }
        }
    }

    /// `out += Σₑ wₑ Σⱼ 2ψₑⱼ uₑⱼ` on the elements' columns.
    #[inline(always)]
    pub(super) fn add_force(&mut self, out: &mut [f64]) {
        let nj = self.nj;
        for g in &mut self.groups {
            g.f.fill(0.0);
            for (mi, &k) in g.members.iter().enumerate() {
                for j in 0..nj {
                    let c = 2.0 * self.weights[k] * self.psi[k * nj + j];
                    let t = mi * nj + j;
                    let nb = g.mp / L;
                    for (f, u) in g.f.iter_mut().zip(g.u[t * nb..(t + 1) * nb].as_flattened()) {
                        *f += c * u;
                    }
                }
            }
            for (&col, f) in g.glob.iter().zip(&g.f) {
                out[col] += f;
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

#[cfg(test)]
mod timing_tmp {
    use super::*;
    #[test]
    #[ignore]
    fn time_kernels() {
        for &(r, m) in &[(18usize, 23usize), (50, 20)] {
            let ne = 8;
            let v: Vec<ndarray::Array2<f64>> =
                (0..m).map(|k| ndarray::Array2::from_shape_fn((ne, r), |(i, j)| ((i * 7 + j * 3 + k) % 11) as f64 * 0.1 + 0.01)).collect();
            let views: Vec<_> = v.iter().map(|a| a.view()).collect();
            let x: Vec<Vec<f64>> = vec![vec![0.5; ne]; m];
            let xr: Vec<&[f64]> = x.iter().map(|x| x.as_slice()).collect();
            let s = vec![vec![(0..ne * ne).map(|i| (i % 5) as f64 * 0.1).collect::<Vec<_>>()]; m];
            let mut sm = Sampled::new(r, &views, &xr, &s, &vec![1.0; m]);
            let q: Vec<f64> = (0..r).map(|i| i as f64 * 0.01).collect();
            let mut acc = vec![0.0; r * r];
            let n = 200;
            let (mut t1, mut t2) = (f64::MAX, f64::MAX);
            for _ in 0..100 {
                let t0 = std::time::Instant::now();
                for _ in 0..n {
                    crate::linalg::simd::dispatch(U(&mut sm, &q));
                }
                t1 = t1.min(t0.elapsed().as_secs_f64() / n as f64);
                let t0 = std::time::Instant::now();
                for _ in 0..n {
                    crate::linalg::simd::dispatch(T(&mut sm, &mut acc));
                }
                t2 = t2.min(t0.elapsed().as_secs_f64() / n as f64);
            }
            eprintln!("r {r} m {m}: update {:.3} us, tangent {:.3} us", t1 * 1e6, t2 * 1e6);
        }
        struct U<'a>(&'a mut Sampled, &'a [f64]);
        impl crate::linalg::simd::Kernel for U<'_> {
            type Output = ();
            #[inline(always)]
            fn run(self) {
                self.0.update::<8>(self.1, |_, s, d1, d2| {
                    d1[0] = s[0];
                    d2[0] = 1.0;
                })
            }
        }
        struct T<'a>(&'a mut Sampled, &'a mut [f64]);
        impl crate::linalg::simd::Kernel for T<'_> {
            type Output = ();
            #[inline(always)]
            fn run(self) {
                self.0.add_tangent(self.1)
            }
        }
    }
}
