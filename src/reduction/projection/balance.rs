//! A reduced model's joint reactions from each body's balance of momentum.
//!
//! A reduced model's multipliers come from its rows at the joints' coordinates, where the
//! elastic force of the elements beside a joint is a difference of large axial forces: on a
//! stiff link a position error of 1e-4 of the range reads as a reaction off by more than the
//! reaction's range. Each body's balance of momentum holds the same reactions without the
//! elastic forces, which do no work in a rigid motion of the body ([`RigidBody`]). With the
//! virtual motions of body `b` — its translations `t_x`, `t_y` and its turn about a point
//! `p_b`, `t_θ(q) = J (q − p_b) / L_b` per unit length `L_b` (`J` turns each (x, y) pair a
//! quarter turn; slopes turn about no point), so that all three read in N —
//!
//! ```text
//!     T_bᵀ Bᵀ λ = −T_bᵀ (M q̈ + C q̇ + g₀ + A_lᵀ g_l)        (the elastic forces: T_bᵀ Q_e = 0)
//! ```
//!
//! Stacked over the bodies, `A λ = b`. The reduced model's own multipliers are moved to the
//! nearest that hold it, `λ ← λ + A⁺ (b − A λ)`: reactions the balance determines come from
//! it alone, and the part of `λ` it cannot tell (a body held twice over, as a beam clamped at
//! both ends) stays the reduced model's. A full trajectory's multipliers hold the balance to
//! the Newton tolerance, and the correction leaves them (tests below).
//!
//! With `x = x_ref + V z`, each term is projected once, per body: for an n × k matrix `Y`
//! (`M V`, `C V`, or a constant force) `t_xᵀ Y`, `t_yᵀ Y` and
//! `t_θ(x)ᵀ Y w = (d_bᵀ Y w + zᵀ W_bᵀ Y w) / L_b`, `d_b = J (x_ref − p_b)`, `W_b = J V` on
//! the body's rows — three r-vectors and an r × r matrix a body for the mass, so that a
//! reading costs `O(r²)` a body and no full vector.

use super::{dot, expand, FactorOf};
use crate::reduction::damping::{damping_parts, part_factor};
use crate::solver::model::{ConstantForces, ElementModel, Parameters, RigidBody};
use ndarray::{Array1, Array2, ArrayView1, ArrayView2, ArrayViewMut2, Axis};

/// One body's coordinate pairs, the point it turns about and its length's inverse.
struct Body {
    /// (x, y) coordinates, and whether they are a position (else a slope)
    pairs: Vec<([usize; 2], bool)>,
    point: [f64; 2],
    inv_length: f64,
}

impl Body {
    /// `t_θ` at the coordinate pair's component `i` (0: x, 1: y) from the pair's coordinates.
    fn turn(&self, (xy, position): ([f64; 2], bool), i: usize) -> f64 {
        let p = if position { self.point } else { [0.0; 2] };
        let r = if i == 0 { -(xy[1] - p[1]) } else { xy[0] - p[0] };
        r * self.inv_length
    }
}

/// One body's tests of a term `Y` (n × k): `t_xᵀY`, `t_yᵀY`, `d_bᵀY / L_b` and the turn's
/// part that moves with the coordinates, `W_bᵀY / L_b` — kept on the columns of `Y` and the
/// rows of `W_bᵀY` that are not zero on the body (a block basis: the body's own modes and
/// joint coordinates), so that a reading costs what the body's modes cost.
struct BodyTests {
    /// the columns of `Y` kept (indices into `w` of [`Tested::add`])
    cols: Vec<usize>,
    /// the rows of `W_bᵀY` kept (indices into `z`)
    rows: Vec<usize>,
    x: Vec<f64>,
    y: Vec<f64>,
    turn: Vec<f64>,
    /// `W_bᵀY / L_b` on `rows × cols`, row-major
    moving: Vec<f64>,
}

/// Per body, the tests of an n × k matrix `Y` ([`BodyTests`]).
struct Tested(Vec<BodyTests>);

impl Tested {
    fn of(bodies: &[Body], y: ArrayView2<f64>, (v, x_ref): (&Array2<f64>, &Array1<f64>)) -> Self {
        Tested(bodies.iter().map(|b| body_tests(b, y, (v, x_ref))).collect())
    }

    /// `out[3b..3b+3] += f T_bᵀ Y w` at the reduced coordinates `z`; `wc` is scratch.
    fn add(&self, f: f64, (z, w): (&[f64], &[f64]), wc: &mut Vec<f64>, out: &mut [f64]) {
        for (b, o) in self.0.iter().zip(out.chunks_exact_mut(3)) {
            // every column kept (a basis whose modes span the bodies): `w` as it is
            let wc: &[f64] = if b.cols.len() == w.len() {
                w
            } else {
                wc.clear();
                wc.extend(b.cols.iter().map(|&j| w[j]));
                wc
            };
            let k = wc.len();
            let moving: f64 =
                b.rows.iter().zip(b.moving.chunks_exact(k.max(1))).map(|(&i, row)| z[i] * dot(row, wc)).sum();
            o[0] += f * dot(&b.x, wc);
            o[1] += f * dot(&b.y, wc);
            o[2] += f * (dot(&b.turn, wc) + moving);
        }
    }
}

impl Tested {
    /// For a vector `Y` (k = 1): `f T_bᵀ Y` into each body's constant part (x, y, turn) and
    /// the turn's coefficients of `z`, so that terms constant along a run are summed once.
    fn add_vector(&self, f: f64, constant: &mut [[f64; 3]], linear: &mut [Vec<f64>]) {
        for ((b, c), l) in self.0.iter().zip(constant).zip(linear) {
            if b.cols.is_empty() {
                continue;
            }
            c[0] += f * b.x[0];
            c[1] += f * b.y[0];
            c[2] += f * b.turn[0];
            b.rows.iter().zip(&b.moving).for_each(|(&i, m)| l[i] += f * m);
        }
    }
}

/// The tests of `Y` on body `b` ([`BodyTests`]), with `W_b = J V` on its pairs.
fn body_tests(b: &Body, y: ArrayView2<f64>, (v, x_ref): (&Array2<f64>, &Array1<f64>)) -> BodyTests {
    let xs: Vec<usize> = b.pairs.iter().map(|(p, _)| p[0]).collect();
    let ys: Vec<usize> = b.pairs.iter().map(|(p, _)| p[1]).collect();
    let nonzero = |a: ndarray::ArrayView1<f64>| a.iter().any(|x| *x != 0.0);
    let both: Vec<usize> = xs.iter().chain(&ys).copied().collect();
    let on_body = y.select(Axis(0), &both);
    let cols: Vec<usize> = (0..y.ncols()).filter(|&j| nonzero(on_body.column(j))).collect();
    let (yx, yy) = (y.select(Axis(0), &xs).select(Axis(1), &cols), y.select(Axis(0), &ys).select(Axis(1), &cols));
    let positions: Vec<usize> = (0..b.pairs.len()).filter(|&p| b.pairs[p].1).collect();
    let x = yx.select(Axis(0), &positions).sum_axis(Axis(0));
    let yv = yy.select(Axis(0), &positions).sum_axis(Axis(0));
    // d_b on the pairs' x and y rows
    let at = |p: usize| ([x_ref[xs[p]], x_ref[ys[p]]], b.pairs[p].1);
    let dx: Array1<f64> = (0..xs.len()).map(|p| b.turn(at(p), 0)).collect();
    let dy: Array1<f64> = (0..xs.len()).map(|p| b.turn(at(p), 1)).collect();
    let turn = dx.dot(&yx) + dy.dot(&yy);
    // W_b = J V on the pairs: rows −V_y (x rows), V_x (y rows)
    let mut moving = v.select(Axis(0), &xs).t().dot(&yy);
    moving -= &v.select(Axis(0), &ys).t().dot(&yx);
    moving *= b.inv_length;
    let rows: Vec<usize> = (0..moving.nrows()).filter(|&i| nonzero(moving.row(i))).collect();
    let moving = moving.select(Axis(0), &rows);
    BodyTests {
        cols,
        rows,
        x: x.to_vec(),
        y: yv.to_vec(),
        turn: turn.to_vec(),
        moving: moving.as_standard_layout().iter().copied().collect(),
    }
}

/// Where a term's factor at μ is read: a mass group's, an element's damping part's.
enum Factor {
    Mass(FactorOf),
    Damping { member: Option<usize>, follows_mass: bool },
}

impl Factor {
    fn at<M: ElementModel>(&self, full: &M, mu: &Parameters) -> f64 {
        match self {
            Factor::Mass(f) => f.at(full, mu),
            Factor::Damping { member, follows_mass } => part_factor(full, (*member, *follows_mass), mu),
        }
    }
}

/// A mass group's constant forces, tested: `fixed + λ scaled + Σ μ_name named`.
struct TestedForces {
    fixed: Tested,
    scaled: Tested,
    named: Vec<(String, Tested)>,
}

/// The balance of every body of a reduced model, projected once ([`Self::new`]) and read at
/// each instant ([`Self::correct`]).
pub(crate) struct Balance {
    bodies: Vec<Body>,
    /// per full coordinate: its body, pair and component, if a body holds it
    owner: Vec<Option<(usize, usize, usize)>>,
    /// the rows of `V` and `x_ref`, to reconstruct a coordinate
    v: Array2<f64>,
    x_ref: Array1<f64>,
    /// per mass group: `M_g V` tested and its constant forces tested
    inertia: Vec<(Factor, Tested, TestedForces)>,
    /// per damping part: `C_part V` tested
    damping: Vec<(Factor, Tested)>,
    /// per body, the constant joint rows tested ([`JointTests`])
    rows: Vec<JointTests>,
    /// the rows that move with time: (row, its coordinates), their coefficients read at t
    moving: Vec<(usize, Vec<usize>)>,
    /// the loads' coordinates, and the rows of `V` and `x_ref` there
    load_dofs: Vec<usize>,
    load_rows: (Array2<f64>, Array1<f64>),
    /// per body, the joint rows on it (ascending): the columns of `A` its rows may fill
    pattern: Vec<Vec<usize>>,
}

/// One body's joint rows tested: `B t_x`, `B t_y`, `B d_b / L_b` (n_c each) and
/// `B W_b / L_b` (n_c × r, row-major); the moving rows' are replaced at each instant.
struct JointTests {
    x: Vec<f64>,
    y: Vec<f64>,
    turn: Vec<f64>,
    moving: Vec<f64>,
}

/// What [`Balance::correct`] works in, allocated once a trajectory.
struct Scratch {
    /// the balances' right-hand side, then their residual (3 n_b)
    b: Vec<f64>,
    /// `A` row-major (3 n_b × n_c)
    a: Vec<f64>,
    /// `AᵀA` (n_c × n_c, row-major, lower triangle), the Cholesky factor of `AᵀA + δ I`,
    /// `Aᵀ r` (then the correction), a copy of it and a refinement's step
    normal: Vec<f64>,
    factor: Vec<f64>,
    rhs: Vec<f64>,
    refine: [Vec<f64>; 2],
    /// the instant's `z`, `ż`, `z̈`, and a term's columns of `w`
    state: [Vec<f64>; 3],
    wc: Vec<f64>,
    /// the loads' coordinates, velocities and forces
    loads: [Vec<f64>; 3],
    /// along the run (μ fixed): the mass groups' and damping parts' factors, and per body
    /// the constant forces' tests, constant and in `z` ([`Tested::add_vector`])
    factors: (Vec<f64>, Vec<f64>),
    constant: Vec<[f64; 3]>,
    linear: Vec<Vec<f64>>,
}

impl Balance {
    /// The balance of `full`'s bodies under the basis `(V, x_ref)`, with each mass group's
    /// factor, `M_g V` and constant forces; `None` for a model without bodies or joints.
    pub(super) fn new<M: ElementModel>(
        full: &M,
        (v, x_ref): (&Array2<f64>, &Array1<f64>),
        groups: Vec<(FactorOf, Array2<f64>, ConstantForces)>,
    ) -> Option<Self> {
        let n = full.n_dof();
        let bodies: Vec<Body> = full.rigid_bodies().iter().map(|b| body(b, x_ref)).collect();
        if bodies.is_empty() || full.n_constraints() == 0 {
            return None;
        }
        let mut owner = vec![None; n];
        for (bi, b) in bodies.iter().enumerate() {
            for (p, (pair, _)) in b.pairs.iter().enumerate() {
                owner[pair[0]] = Some((bi, p, 0));
                owner[pair[1]] = Some((bi, p, 1));
            }
        }
        let basis = (v, x_ref);
        let vector = |g: &[f64]| Tested::of(&bodies, ArrayView1::from(g).insert_axis(Axis(1)), basis);
        let inertia = groups
            .into_iter()
            .map(|(f, mv, g)| {
                let forces = TestedForces {
                    fixed: vector(&g.fixed),
                    scaled: vector(&g.scaled),
                    named: g.named.iter().map(|(name, x)| (name.clone(), vector(x))).collect(),
                };
                (Factor::Mass(f), Tested::of(&bodies, mv.view(), basis), forces)
            })
            .collect();
        let damping =
            damping_products(full, v).into_iter().map(|(f, cv)| (f, Tested::of(&bodies, cv.view(), basis))).collect();
        let rows: Vec<JointTests> = bodies.iter().map(|b| constant_rows(full, b, v, x_ref)).collect();
        let moving = full.moving_rows();
        let pattern =
            (0..bodies.len()).map(|b| joint_pattern(&rows[b], &moving, |i| owner[i].map(|o| o.0) == Some(b))).collect();
        let load_dofs = full.load_dofs();
        let load_rows = (v.select(Axis(0), &load_dofs), x_ref.select(Axis(0), &load_dofs));
        Some(Balance {
            pattern,
            owner,
            v: v.as_standard_layout().into_owned(),
            x_ref: x_ref.clone(),
            inertia,
            damping,
            rows,
            moving,
            load_dofs,
            load_rows,
            bodies,
        })
    }

    /// Moves `lambda` (the full model's multipliers, n_c × n_t) to the nearest that hold every
    /// body's balance along the reduced trajectory `[z, ż, z̈]` by instant (n_t × r each, at
    /// the times `t`): `λ ← λ + d`, `d` the least-squares correction of `A d = b − A λ` in
    /// the directions the balance sees ([`least_squares`]), the others left alone.
    pub(crate) fn correct<M: ElementModel>(
        &self,
        full: &M,
        mu: &Parameters,
        t: &[f64],
        states: [ArrayView2<f64>; 3],
        mut lambda: ArrayViewMut2<f64>,
    ) {
        let (m, nc, nl, r) = (3 * self.bodies.len(), lambda.nrows(), self.load_dofs.len(), states[0].ncols());
        let nb = self.bodies.len();
        let mut w = Scratch {
            b: vec![0.0; m],
            a: vec![0.0; m * nc],
            normal: vec![0.0; nc * nc],
            factor: vec![0.0; nc * nc],
            rhs: vec![0.0; nc],
            refine: [vec![0.0; nc], vec![0.0; nc]],
            state: [vec![0.0; r], vec![0.0; r], vec![0.0; r]],
            wc: Vec::with_capacity(r),
            loads: [vec![0.0; nl], vec![0.0; nl], vec![0.0; nl]],
            factors: (
                self.inertia.iter().map(|(f, ..)| f.at(full, mu)).collect(),
                self.damping.iter().map(|(f, _)| f.at(full, mu)).collect(),
            ),
            constant: vec![[0.0; 3]; nb],
            linear: vec![vec![0.0; r]; nb],
        };
        for ((_, _, g), f) in self.inertia.iter().zip(&w.factors.0) {
            g.fixed.add_vector(*f, &mut w.constant, &mut w.linear);
            g.scaled.add_vector(f * mu.scale(), &mut w.constant, &mut w.linear);
            for (name, g) in &g.named {
                g.add_vector(f * mu.get(name).unwrap_or(1.0), &mut w.constant, &mut w.linear);
            }
        }
        let mut l = vec![0.0; nc];
        for (k, mut column) in lambda.columns_mut().into_iter().enumerate() {
            for (to, from) in w.state.iter_mut().zip(&states) {
                match from.row(k).as_slice() {
                    Some(row) => to.copy_from_slice(row),
                    None => to.iter_mut().zip(from.row(k)).for_each(|(a, b)| *a = *b),
                }
            }
            self.balances(full, mu, t[k], &mut w);
            self.joint_rows(full, mu, t[k], &w.state[0], &mut w.a);
            l.iter_mut().zip(column.iter()).for_each(|(l, c)| *l = *c);
            if least_squares(&mut w, &l, &self.pattern) {
                column.iter_mut().zip(&w.rhs).for_each(|(c, d)| *c += d);
            }
        }
    }

    /// `w.b = −T_bᵀ (M q̈ + C q̇ + g₀ + A_lᵀ g_l)` at the instant `t` of `w.state`.
    fn balances<M: ElementModel>(&self, full: &M, mu: &Parameters, t: f64, w: &mut Scratch) {
        let (s, [z, zd, zdd], wc) = (&mut w.b, &w.state, &mut w.wc);
        for ((o, c), l) in s.chunks_exact_mut(3).zip(&w.constant).zip(&w.linear) {
            o.copy_from_slice(c);
            o[2] += dot(l, z);
        }
        for ((_, mv, _), f) in self.inertia.iter().zip(&w.factors.0) {
            mv.add(*f, (z, zdd), wc, s);
        }
        for ((_, cv), f) in self.damping.iter().zip(&w.factors.1) {
            cv.add(*f, (z, zd), wc, s);
        }
        if !self.load_dofs.is_empty() {
            let [ql, vl, gl] = &mut w.loads;
            let (rows, x_ref) = &self.load_rows;
            expand(rows, Some(x_ref), 0, z, ql);
            expand(rows, None, 0, zd, vl);
            full.load_force(mu, ql, vl, t, gl);
            for (&i, g) in self.load_dofs.iter().zip(gl.iter()) {
                self.add_term(i, *g, z, s, 1);
            }
        }
        s.iter_mut().for_each(|x| *x = -*x);
    }

    /// The full coordinate `i` at the reduced coordinates `z`.
    fn coordinate(&self, i: usize, z: &[f64]) -> f64 {
        self.x_ref[i] + dot(self.v.row(i).as_slice().expect("standard layout"), z)
    }

    /// `t_θ` of the body holding coordinate `i` there, at the reduced coordinates `z`.
    fn turn_at(&self, (b, p, c): (usize, usize, usize), z: &[f64]) -> f64 {
        let body = &self.bodies[b];
        let (pair, position) = body.pairs[p];
        body.turn(([self.coordinate(pair[0], z), self.coordinate(pair[1], z)], position), c)
    }

    /// `out[(3b + j) stride] += k T_b,j[i]`: a term `k` at the full coordinate `i`, on the
    /// body holding it (`stride` > 1: into a column of a row-major `A`).
    fn add_term(&self, i: usize, k: f64, z: &[f64], out: &mut [f64], stride: usize) {
        let Some((b, p, c)) = self.owner[i] else { return };
        if self.bodies[b].pairs[p].1 {
            out[(3 * b + c) * stride] += k;
        }
        out[(3 * b + 2) * stride] += k * self.turn_at((b, p, c), z);
    }

    /// `a = T_bᵀ Bᵀ` stacked over the bodies (3 n_b × n_c, row-major) at `z` and `t`.
    fn joint_rows<M: ElementModel>(&self, full: &M, mu: &Parameters, t: f64, z: &[f64], a: &mut [f64]) {
        let (nc, r) = (a.len() / (3 * self.bodies.len()), z.len());
        for (b, (rows, pattern)) in self.rows.iter().zip(&self.pattern).enumerate() {
            for &c in pattern {
                a[3 * b * nc + c] = rows.x[c];
                a[(3 * b + 1) * nc + c] = rows.y[c];
                a[(3 * b + 2) * nc + c] = rows.turn[c] + dot(&rows.moving[c * r..(c + 1) * r], z);
            }
        }
        let mut coefs = [0.0; 4];
        for (k, (c, dofs)) in self.moving.iter().enumerate() {
            let coefs = &mut coefs[..dofs.len().min(4)];
            full.moving_row_at(mu, k, t, 0, coefs);
            a[*c..].iter_mut().step_by(nc).for_each(|x| *x = 0.0);
            for (&i, &coef) in dofs.iter().zip(coefs.iter()) {
                self.add_term(i, coef, z, &mut a[*c..], nc);
            }
        }
    }
}

/// Sweeps of iterated regularization (below): each leaves `(δ/(σ² + δ))` of the last one's
/// error in a direction of `A` of singular value `σ`.
const REFINEMENTS: usize = 2;

/// The least-squares correction of [`Balance::correct`] into `w.rhs` (`w.a`, `w.b` set; each
/// body's three rows of `A` zero off its `pattern`); whether it is there (finite, and `A`
/// not zero). The normal equations `AᵀA d = Aᵀ(b − Aλ)` are singular where the balance
/// cannot tell a multiplier (the part of a clamp's slope rows along the slope, a body held
/// twice over): they are solved with `AᵀA + δ I`, `δ = √ε max diag AᵀA` — far above the
/// round-off of forming `AᵀA`, so that no direction the balance cannot see picks up noise —
/// and refined ([`REFINEMENTS`]), so that the directions it sees are solved to round-off.
fn least_squares(w: &mut Scratch, lambda: &[f64], pattern: &[Vec<usize>]) -> bool {
    let nc = lambda.len();
    let (a, n) = (&w.a, &mut w.normal);
    n.iter_mut().for_each(|x| *x = 0.0);
    w.rhs.iter_mut().for_each(|x| *x = 0.0);
    // AᵀA's lower triangle and Aᵀ(b − Aλ), row by row over the row's body's joints
    for (i, (row, bi)) in a.chunks_exact(nc.max(1)).zip(w.b.iter_mut()).enumerate() {
        let cols = &pattern[i / 3];
        *bi -= cols.iter().map(|&c| row[c] * lambda[c]).sum::<f64>();
        for (p, &c) in cols.iter().enumerate() {
            w.rhs[c] += row[c] * *bi;
            for &d in &cols[..=p] {
                n[c * nc + d] += row[c] * row[d];
            }
        }
    }
    let largest = (0..nc).map(|i| n[i * nc + i]).fold(0.0, f64::max);
    let delta = f64::EPSILON.sqrt() * largest;
    let (factor, [g, dx], x) = (&mut w.factor, &mut w.refine, &mut w.rhs);
    factor.copy_from_slice(n);
    if largest == 0.0 || !cholesky(factor, nc, delta) {
        return false;
    }
    g.copy_from_slice(x);
    solve_factored(factor, nc, x);
    for _ in 0..REFINEMENTS {
        // the residual g − AᵀA x of the unregularized equations, then its correction
        for (i, r) in dx.iter_mut().enumerate() {
            *r = g[i] - (0..nc).map(|j| n[i.max(j) * nc + i.min(j)] * x[j]).sum::<f64>();
        }
        solve_factored(factor, nc, dx);
        x.iter_mut().zip(dx.iter()).for_each(|(x, d)| *x += d);
    }
    x.iter().all(|v| v.is_finite())
}

/// `L Lᵀ = N + δ I` in place, `N` symmetric in the lower triangle of `n` (row-major); whether
/// every pivot was positive.
fn cholesky(n: &mut [f64], k: usize, delta: f64) -> bool {
    for i in 0..k {
        for j in 0..=i {
            let s = n[i * k + j] + if i == j { delta } else { 0.0 } - dot(&n[i * k..i * k + j], &n[j * k..j * k + j]);
            if i == j {
                if s <= 0.0 || !s.is_finite() {
                    return false;
                }
                n[i * k + i] = s.sqrt();
            } else {
                n[i * k + j] = s / n[j * k + j];
            }
        }
    }
    true
}

/// Solves `L Lᵀ x = rhs` in place with the factor of [`cholesky`].
fn solve_factored(l: &[f64], k: usize, rhs: &mut [f64]) {
    for i in 0..k {
        rhs[i] = (rhs[i] - dot(&l[i * k..i * k + i], &rhs[..i])) / l[i * k + i];
    }
    for i in (0..k).rev() {
        let s: f64 = (i + 1..k).map(|j| l[j * k + i] * rhs[j]).sum();
        rhs[i] = (rhs[i] - s) / l[i * k + i];
    }
}

/// The joint rows that may act on a body: those its constant rows' tests do not read as zero,
/// and the moving rows with a coordinate `on_body` (ascending).
fn joint_pattern(rows: &JointTests, moving: &[(usize, Vec<usize>)], on_body: impl Fn(usize) -> bool) -> Vec<usize> {
    let r = if rows.x.is_empty() { 0 } else { rows.moving.len() / rows.x.len() };
    let mut cols: Vec<usize> = (0..rows.x.len())
        .filter(|&c| {
            let moves = rows.moving[c * r..(c + 1) * r].iter().any(|x| *x != 0.0);
            rows.x[c] != 0.0 || rows.y[c] != 0.0 || rows.turn[c] != 0.0 || moves
        })
        .collect();
    cols.extend(moving.iter().filter(|(_, dofs)| dofs.iter().any(|&i| on_body(i))).map(|(c, _)| *c));
    cols.sort_unstable();
    cols.dedup();
    cols
}

/// The body's pairs, its first position of reference as the point it turns about.
fn body(b: &RigidBody, x_ref: &Array1<f64>) -> Body {
    let point = b.positions.first().map_or([0.0; 2], |&[x, y]| [x_ref[x], x_ref[y]]);
    let pairs = b.positions.iter().map(|&p| (p, true)).chain(b.slopes.iter().map(|&p| (p, false))).collect();
    Body { pairs, point, inv_length: if b.length > 0.0 { 1.0 / b.length } else { 1.0 } }
}

/// The constant rows' `B t_x`, `B t_y`, `B d_b / L_b` and `B W_b / L_b` of one body: the
/// rows are linear, `B y = res(y) − res(0)` (the moving ones are replaced at each time).
fn constant_rows<M: ElementModel>(full: &M, b: &Body, v: &Array2<f64>, x_ref: &Array1<f64>) -> JointTests {
    let (n, nc, r) = (full.n_dof(), full.n_constraints(), v.ncols());
    let mu0 = Parameters::load_scale(1.0);
    let mut res0 = vec![0.0; nc];
    full.constraint_residual(&mu0, &vec![0.0; n], 0.0, &mut res0);
    let times_b = |y: &[f64]| -> Vec<f64> {
        let mut res = vec![0.0; nc];
        full.constraint_residual(&mu0, y, 0.0, &mut res);
        res.iter().zip(&res0).map(|(a, b)| a - b).collect()
    };
    let (mut tx, mut ty, mut d) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for &([ix, iy], position) in &b.pairs {
        if position {
            tx[ix] = 1.0;
            ty[iy] = 1.0;
        }
        let at = ([x_ref[ix], x_ref[iy]], position);
        (d[ix], d[iy]) = (b.turn(at, 0), b.turn(at, 1));
    }
    // W_b's columns, one at a time in one buffer: J V_j on the body's pairs
    let mut w = vec![0.0; n];
    let mut moving = vec![0.0; nc * r];
    for j in 0..r {
        for &([ix, iy], _) in &b.pairs {
            (w[ix], w[iy]) = (-v[[iy, j]] * b.inv_length, v[[ix, j]] * b.inv_length);
        }
        for (c, x) in times_b(&w).into_iter().enumerate() {
            moving[c * r + j] = x;
        }
    }
    JointTests { x: times_b(&tx), y: times_b(&ty), turn: times_b(&d), moving }
}

/// `C_part V` per damping part ([`damping_parts`]), each with where its factor is read;
/// none for an undamped model.
fn damping_products<M: ElementModel>(full: &M, v: &Array2<f64>) -> Vec<(Factor, Array2<f64>)> {
    let parts = damping_parts(full).into_iter().map(|part| {
        let mut cv = Array2::zeros((full.n_dof(), v.ncols()));
        part.each_element(full, |dofs, ce| {
            for (row, &d) in ce.dot(&v.select(Axis(0), dofs)).outer_iter().zip(dofs) {
                let mut target = cv.row_mut(d);
                target += &row;
            }
        });
        (Factor::Damping { member: part.member, follows_mass: part.follows_mass }, cv)
    });
    parts.filter(|(_, cv)| cv.iter().any(|x| *x != 0.0)).collect()
}

#[cfg(test)]
mod tests {
    use super::super::Projection;
    use crate::linalg::kkt::LinearSolverKind;
    use crate::model::Model;
    use crate::reduction::{Basis, Variant};
    use crate::simulate::{simulate, Overrides};
    use crate::solver::generalized_alpha::GeneralizedAlpha;
    use crate::solver::model::{Bound, ParametricModel};
    use ndarray::{Array2, ArrayView2};

    /// An arm turned by a motor at its ground pin (a driven angle), a link pinned to its end
    /// carrying a point mass and hung from a spring-damper, a force on the arm, gravity and
    /// Rayleigh damping: every term of the balance. Five multipliers, six balances: the
    /// reactions are determinate.
    const MODEL: &str = "[time]\nt_end = 0.05\ndt = 0.005\nrho_inf = 0.8\n\
        [damping]\nmass = 0.5\nstiffness = 2e-4\n\
        [[bodies]]\nname = \"arm\"\nstart = [0.0, 0.0]\nangle = 0.3\nlength = 0.5\nelements = 3\n\
        density = 2700.0\narea = 1e-4\ninertia = 1e-9\nyoungs_modulus = 7e10\n\
        [[bodies]]\nname = \"link\"\nstart = [0.0, 0.0]\nangle = -0.4\nlength = 0.4\nelements = 2\n\
        density = 7800.0\narea = 1e-4\ninertia = 2e-9\nyoungs_modulus = 2e11\n\
        [[joints]]\ntype = \"ground_pin\"\nbody = \"arm\"\nnode = \"start\"\n\
        [[joints]]\ntype = \"driven_angle\"\nbody = \"arm\"\nnode = \"start\"\n\
        function = { type = \"polynomial\", coefficients = [0.0, 0.0, 30.0] }\n\
        [[joints]]\ntype = \"pin\"\na = { body = \"arm\", node = \"end\" }\nb = { body = \"link\", node = \"start\" }\n\
        [[masses]]\nbody = \"link\"\nnode = \"end\"\nmass = 0.3\n\
        [[springs]]\na = { body = \"link\", node = \"end\" }\nb = { point = [0.9, -0.6] }\nstiffness = 400.0\ndamping = 2.0\n\
        [[loads]]\ntype = \"gravity\"\ng = [0.0, -9.81]\n\
        [[loads]]\ntype = \"force\"\nbody = \"arm\"\nnode = 2\nvalue = [3.0, -1.0]\n";

    /// The identity basis's projection of `text`'s model and a full run of it; at the run's
    /// instants `steps`, the consistent accelerations and multipliers
    /// (`[M, Bᵀ; B, 0] [q̈; λ] = [−g; c]`), each given to `check` with the projection's
    /// correction of multipliers (`λ ↦` the corrected ones).
    fn at_full_states(text: &str, steps: &[usize], check: impl Fn(&[f64], &dyn Fn(Vec<f64>) -> Vec<f64>)) {
        let model = Model::from_text(text, "m.toml").unwrap();
        let r = simulate(&model, &Overrides::default()).unwrap();
        let mu = r.settings.parameters().clone();
        let mut full = model.system(LinearSolverKind::Banded);
        let n = full.n_dof();
        let p = Projection::new(&full, &Basis::identity(n, Variant::ConstraintPreserving)).unwrap();
        assert!(p.balance.is_some());
        for &k in steps {
            let (q, v, t) = (r.q.column(k).to_vec(), r.qd.column(k).to_vec(), r.t[k]);
            let st = {
                let mut bound = Bound::new(&mut full, &mu);
                GeneralizedAlpha::new(r.settings.params.clone()).unwrap().initialize(&mut bound, q, v, t).unwrap()
            };
            let state = [&st.q, &st.v, &st.qdd].map(|x| ArrayView2::from_shape((1, n), x).unwrap());
            let correct = |l: Vec<f64>| {
                let mut l = Array2::from_shape_vec((l.len(), 1), l).unwrap();
                p.balance(&full, &mu, &[t], state, l.view_mut());
                l.into_raw_vec_and_offset().0
            };
            check(&st.lambda, &correct);
        }
    }

    /// At states of a full run the multipliers hold every body's balance: the identity
    /// basis's correction leaves them as they are, and brings multipliers moved off them back
    /// (determinate reactions). Bound: round-off on the largest multiplier.
    #[test]
    fn a_full_state_holds_every_balance_and_moved_multipliers_come_back() {
        // the link starts at the arm's end
        let end = [0.5 * 0.3f64.cos(), 0.5 * 0.3f64.sin()];
        let text = MODEL
            .replace("start = [0.0, 0.0]\nangle = -0.4", &format!("start = [{}, {}]\nangle = -0.4", end[0], end[1]));
        at_full_states(&text, &[2, 4, 10], |lambda, correct| {
            let largest = lambda.iter().fold(0.0f64, |m, l| m.max(l.abs()));
            assert!(largest > 1.0, "the joints carry the motor's torque and the weights: {lambda:?}");
            let close = |l: &[f64]| l.iter().zip(lambda).all(|(a, b)| (a - b).abs() <= 1e-9 * largest);
            let kept = correct(lambda.to_vec());
            assert!(close(&kept), "{kept:?} against {lambda:?}");
            let moved = correct(lambda.iter().enumerate().map(|(i, l)| l + 5.0 * (i as f64 + 1.0).sin()).collect());
            assert!(close(&moved), "{moved:?} against {lambda:?}");
        });
    }

    /// A beam clamped at both ends under gravity and a sine force: eight multipliers, three
    /// balances, and each clamp's slope rows seen by the turn only across the slope. The
    /// correction keeps a full state's multipliers, and a move along what the balance cannot
    /// tell (the clamps' slope rows along the slope, the same force taken at one end and given
    /// at the other) stays as it was; no direction picks up noise. Bound: round-off on the
    /// largest multiplier.
    #[test]
    fn what_the_balance_cannot_tell_is_left_alone() {
        let text = "[time]\nt_end = 0.02\ndt = 0.002\nrho_inf = 0.8\n\
            [[bodies]]\nname = \"beam\"\nstart = [0.0, 0.0]\nangle = 0.0\nlength = 1.0\nelements = 4\n\
            density = 7800.0\narea = 1e-4\ninertia = 1e-9\nyoungs_modulus = 2e11\n\
            [[joints]]\ntype = \"clamp\"\nbody = \"beam\"\nnode = \"start\"\n\
            [[joints]]\ntype = \"clamp\"\nbody = \"beam\"\nnode = \"end\"\n\
            [[loads]]\ntype = \"gravity\"\ng = [0.0, -9.81]\n\
            [[loads]]\ntype = \"force\"\nbody = \"beam\"\nnode = 2\nvalue = [0.0, -50.0]\n\
            function = { type = \"sine\", amplitude = 1.0, frequency = 20.0 }\n";
        at_full_states(text, &[3, 10], |lambda, correct| {
            let largest = lambda.iter().fold(0.0f64, |m, l| m.max(l.abs()));
            let close = |l: &[f64], to: &[f64]| l.iter().zip(to).all(|(a, b)| (a - b).abs() <= 1e-9 * largest);
            let kept = correct(lambda.to_vec());
            assert!(close(&kept, lambda), "{kept:?} against {lambda:?}");
            // rows: start x, y, x', y', end x, y, x', y'; the slopes start along +x and both
            // ends stay on y = 0: a move of both clamps' x' rows, and an x force taken at one
            // end and given at the other (no net force, no moment about any point on y = 0)
            let mut blind = lambda.to_vec();
            for (i, d) in [(2, 3.0), (6, -2.0), (0, 7.0), (4, -7.0)] {
                blind[i] += d;
            }
            let left = correct(blind.clone());
            assert!(close(&left, &blind), "{left:?} against {blind:?}");
        });
    }
}
