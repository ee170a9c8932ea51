//! Natural frequencies and mode shapes of the constrained system linearized at a
//! configuration `q*` (SPEC §6):
//!
//! ```text
//! K_T(q*) φ = ω² M φ,   B φ = 0
//! ```
//!
//! with `K_T` the tangent stiffness including its geometric part (the axial force's) and the
//! follower moments' Jacobian ([`super::assembly`]), `M` the mass. The lowest `N` pairs
//! come from subspace iteration with shift-invert (Bathe, *Finite Element Procedures*,
//! §11.6): the KKT matrix `[K_T − σM, Bᵀ; B, 0]` is factored once by the project's KKT
//! solvers, and each iteration solves `[K_T − σM, Bᵀ; B, 0] [Y; Λ] = [M X; 0]`, whose `Y`
//! lies in `ker B`, for `p = min(n_free, max(2N, N + 8))` vectors, `M`-orthonormalizes
//! them and takes the Ritz pairs of `Yᵀ K_T Y z = ω² z` (LAPACK's `dsyev` through
//! ndarray-linalg). Mode `i` converges at the rate `(ω_i² − σ)/(ω_{p+1}² − σ)` per
//! iteration. Each Ritz vector's `ω²` is then taken from the next solve, `σ + xᵀMx / xᵀMy`
//! (`inverse_quotient`: accurate where `xᵀK_T x` loses digits); the loop stops when every
//! wanted `ω²` changes by less than `10⁻⁹ (|ω²| + |σ|) + 10 ε d` from one iteration to the
//! next. The last term is the round-off floor: `K_T` is known to `ε ‖K_T‖`, so every `ω²`
//! only to about `ε d` (s⁻²; [`Modes::roundoff`]), which fine meshes feel in their lowest
//! modes (`d/ω₁²` grows as the fourth power of the number of elements).
//! Where `p = n_free` (small models) the subspace is all of `ker B` and the first Ritz
//! pairs are exact: a dense solve.
//!
//! The shift `σ = −10⁻¹² d`, `d` about the largest `ω²` (`stiffest_ratio`), keeps the
//! matrix regular where `K_T` has rigid-body modes (`ω = 0`, amplified by `1/|σ|` in each
//! solve) and stays below the lowest elastic `ω²` of the shipped meshes (the 5000-element
//! pendulum: `σ ≈ −12 s⁻²` against `ω₂² = 97.8 s⁻²`; a larger `|σ|` slows the lowest
//! modes' convergence, it does not change them). A mode is rigid, frequency 0, when
//! `|ω²| ≤ 10⁻³ |σ|` (a rigid mode's computed `ω²` is round-off, about `10⁻⁵ |σ|`); a
//! negative `ω²` (a configuration past buckling) gives a negative frequency `−√|ω²|/2π`.

use super::assembly::{self, block_mul};
use crate::error::{Error, Result};
use crate::linalg::kkt::{Block, LinearSolverKind};
use crate::linalg::lapack::{Eigh, UPLO};
use crate::physics::system::FlexibleSystem;
use crate::solver::model::{Parameters, ParametricModel};
use ndarray::Array2;

/// A mode is rigid when `|ω²| ≤ RIGID · |σ|` (a rigid mode's `ω²` from
/// [`inverse_quotient`] is round-off, about `10⁻⁵ |σ|`).
const RIGID: f64 = 1e-3;

/// Iterations of the subspace before it gives up.
pub const MAX_ITERATIONS: usize = 300;

/// The lowest modes of a system.
#[derive(Clone, Debug)]
pub struct Modes {
    /// `ω²`, ascending, rad²/s²
    pub omega_squared: Vec<f64>,
    /// `f = √ω²/2π`, Hz (0 for a rigid mode, negative for a negative `ω²`)
    pub frequencies: Vec<f64>,
    /// whether each mode is a rigid-body motion
    pub rigid: Vec<bool>,
    /// mode × coordinate: each `M`-normalized (`φᵀMφ = 1`), its largest entry positive
    pub shapes: Array2<f64>,
    /// subspace iterations taken
    pub iterations: usize,
    /// the round-off of every `ω²`, about `ε d` (1/s²): a perturbation of `K_T` by its
    /// round-off, `ε ‖K_T‖`, moves each eigenvalue by up to `ε ‖K_T‖/‖M‖ ≈ ε ω²_max`
    /// (Weyl); 1.8 s⁻² on the 5000-element pendulum, whose `ω₂² = 97.8 s⁻²`
    pub roundoff: f64,
}

impl Modes {
    pub fn len(&self) -> usize {
        self.frequencies.len()
    }

    pub fn is_empty(&self) -> bool {
        self.frequencies.is_empty()
    }

    /// Mode `i`'s shape, laid out like `q`.
    pub fn shape(&self, i: usize) -> Vec<f64> {
        self.shapes.row(i).to_vec()
    }
}

/// The number of coordinates the constraints leave free, `n_dof − n_c` (the joints'
/// rows are independent: the model checks refuse a joint on a joint).
pub fn unconstrained(sys: &FlexibleSystem) -> usize {
    ParametricModel::n_dof(sys) - ParametricModel::n_constraints(sys)
}

/// The lowest `count` modes of `sys` at `μ`, linearized at `q` (the loads at `t`).
pub fn compute(
    sys: &FlexibleSystem,
    mu: &Parameters,
    q: &[f64],
    t: f64,
    count: usize,
    kind: LinearSolverKind,
) -> Result<Modes> {
    let n_free = unconstrained(sys);
    if count == 0 || count > n_free {
        return Err(Error::option(
            "count",
            Some(count.to_string()),
            format!(
                "the model has {n_free} unconstrained coordinates ({} coordinates, {} constraint rows); \
                 ask for 1 to {n_free} modes",
                ParametricModel::n_dof(sys),
                ParametricModel::n_constraints(sys)
            ),
        ));
    }
    let k = assembly::tangent_blocks(sys, mu, q, t, 1.0);
    let m = assembly::mass_blocks(sys, mu);
    let d = stiffest_ratio(&k, &m);
    let sigma = -1e-12 * d;
    let shifted: Vec<Block> = k.iter().zip(&m).map(|(k, m)| k - m * sigma).collect();
    let mut kkt = assembly::solver(sys, kind);
    kkt.factor(&shifted, super::ramp::diagonal_scale(&shifted))
        .map_err(|e| e.at_time_in(t, "modes: factoring K_T − σM"))?;
    let n = ParametricModel::n_dof(sys);
    let nc = ParametricModel::n_constraints(sys);
    let p = n_free.min((2 * count).max(count + 8));
    let mut solve = |x: &[f64]| -> Result<Vec<f64>> {
        let mut rhs = vec![0.0; n + nc];
        block_mul(sys, &m, x, &mut rhs[..n]);
        kkt.solve(&mut rhs).map_err(|e| e.at_time_in(t, "modes"))?;
        rhs.truncate(n);
        Ok(rhs)
    };
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut x: Vec<Vec<f64>> = (0..p).map(|_| random_vector(n, &mut seed)).collect();
    let mut previous: Option<Vec<f64>> = None;
    let rigid = |w: f64| w.abs() <= RIGID * sigma.abs();
    let roundoff = f64::EPSILON * d;
    for it in 1..=MAX_ITERATIONS {
        crate::interrupt::check()?;
        let mut y = x.iter().map(|xi| solve(xi)).collect::<Result<Vec<_>>>()?;
        if it > 1 {
            // x holds M-normalized Ritz vectors: their inverse Rayleigh quotients
            let theta: Vec<f64> = (0..count).map(|i| inverse_quotient(sys, &m, &x[i], &y[i], sigma)).collect();
            let done = previous.as_ref().is_some_and(|prev| {
                (0..count).all(|i| {
                    (rigid(theta[i]) && rigid(prev[i]))
                        || (theta[i] - prev[i]).abs() <= 1e-9 * (theta[i].abs() + sigma.abs()) + 10.0 * roundoff
                })
            });
            if done {
                let mut modes = finish(sys, &m, &theta, &x[..count], RIGID * sigma.abs(), it);
                modes.roundoff = roundoff;
                return Ok(modes);
            }
            previous = Some(theta);
        }
        m_orthonormalize(sys, &m, &mut y, &mut solve, &mut seed)?;
        let z = ritz(sys, &k, &y)?;
        // X = Y Z: the Ritz vectors, ascending
        x = (0..p).map(|j| combine(&y, &z.column(j).to_vec())).collect();
    }
    Err(Error::usage(format!(
        "modes: the lowest {count} modes did not converge in {MAX_ITERATIONS} subspace iterations"
    )))
}

/// `ω² ≈ σ + xᵀMx / xᵀMy` for `y = (K_T − σM)⁻¹ M x` (on `ker B`): exact for an eigenvector,
/// and, unlike `xᵀK_T x`, free of the cancellation in `K_T x` (whose entries are about
/// `max K_ii` while the product is `ω² M x`), which limits the direct quotient to a
/// relative accuracy of about `ε d/ω²` (5·10⁻⁶ for the lowest mode of a 5000-element beam).
fn inverse_quotient(sys: &FlexibleSystem, m: &[Block], x: &[f64], y: &[f64], sigma: f64) -> f64 {
    let mut mx = vec![0.0; x.len()];
    block_mul(sys, m, x, &mut mx);
    sigma + dot(x, &mx) / dot(y, &mx)
}

/// `d = max_e max_i K_e,ii / M_e,ii` over the position coordinates `i` (x, y of both
/// nodes) of every element: about the largest `ω²` of the mesh (an element's axial
/// frequency). The slope coordinates are left out: their mass is of order `l²` times
/// theirs, and their ratio would overstate `ω²_max` by a factor of a hundred or more.
fn stiffest_ratio(k: &[Block], m: &[Block]) -> f64 {
    let mut d = 0.0_f64;
    for (k, m) in k.iter().zip(m) {
        for i in [0, 1, 4, 5] {
            if m[(i, i)] > 0.0 {
                d = d.max(k[(i, i)].abs() / m[(i, i)]);
            }
        }
    }
    if d > 0.0 {
        d
    } else {
        1.0
    }
}

/// A reproducible vector of entries in (−1, 1) (xorshift64*): the same modes every run.
fn random_vector(n: usize, seed: &mut u64) -> Vec<f64> {
    (0..n)
        .map(|_| {
            *seed ^= *seed >> 12;
            *seed ^= *seed << 25;
            *seed ^= *seed >> 27;
            let r = seed.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
            2.0 * (r as f64 / (1u64 << 53) as f64) - 1.0
        })
        .collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Modified Gram–Schmidt in the `M` inner product, twice (one pass loses orthogonality
/// when the columns are nearly parallel, as the solves make them). A column that vanishes
/// (dependent on the others) is replaced by the solve of a fresh random vector.
fn m_orthonormalize(
    sys: &FlexibleSystem,
    m: &[Block],
    y: &mut [Vec<f64>],
    solve: &mut impl FnMut(&[f64]) -> Result<Vec<f64>>,
    seed: &mut u64,
) -> Result<()> {
    let n = y.first().map_or(0, |v| v.len());
    let mut my: Vec<Vec<f64>> = Vec::with_capacity(y.len());
    for j in 0..y.len() {
        for attempt in 0..3 {
            let mut mv = vec![0.0; n];
            block_mul(sys, m, &y[j], &mut mv);
            let before = dot(&y[j], &mv).max(0.0).sqrt();
            for _pass in 0..2 {
                let (done, rest) = y.split_at_mut(j);
                for (yi, myi) in done.iter().zip(&my) {
                    let c = dot(myi, &rest[0]);
                    for (a, b) in rest[0].iter_mut().zip(yi) {
                        *a -= c * b;
                    }
                }
            }
            block_mul(sys, m, &y[j], &mut mv);
            let after = dot(&y[j], &mv).max(0.0).sqrt();
            if after > 1e-14 * before && after > 0.0 {
                y[j].iter_mut().for_each(|a| *a /= after);
                mv.iter_mut().for_each(|a| *a /= after);
                my.push(mv);
                break;
            }
            if attempt == 2 {
                return Err(Error::usage("modes: the subspace lost its rank (fewer independent motions than asked)"));
            }
            y[j] = solve(&random_vector(n, seed))?;
        }
    }
    Ok(())
}

/// The Ritz vectors' coefficients of `K` on the `M`-orthonormal columns `y`, as columns
/// in ascending order of their Ritz values.
fn ritz(sys: &FlexibleSystem, k: &[Block], y: &[Vec<f64>]) -> Result<Array2<f64>> {
    let p = y.len();
    let n = y[0].len();
    let ky: Vec<Vec<f64>> = y
        .iter()
        .map(|v| {
            let mut out = vec![0.0; n];
            block_mul(sys, k, v, &mut out);
            out
        })
        .collect();
    let mut kr = Array2::zeros((p, p));
    for i in 0..p {
        for j in 0..=i {
            let v = 0.5 * (dot(&y[i], &ky[j]) + dot(&y[j], &ky[i]));
            kr[(i, j)] = v;
            kr[(j, i)] = v;
        }
    }
    let (_, z) = kr.eigh(UPLO::Lower).map_err(|e| Error::usage(format!("modes: Rayleigh–Ritz eigenproblem: {e}")))?;
    Ok(z)
}

/// `Σ_j y_j c_j`.
fn combine(y: &[Vec<f64>], c: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; y[0].len()];
    for (v, &cj) in y.iter().zip(c) {
        for (o, a) in out.iter_mut().zip(v) {
            *o += cj * a;
        }
    }
    out
}

fn finish(sys: &FlexibleSystem, m: &[Block], w: &[f64], x: &[Vec<f64>], rigid_below: f64, iterations: usize) -> Modes {
    // the refined values may reorder two modes of nearly one frequency
    let mut order: Vec<usize> = (0..w.len()).collect();
    order.sort_by(|&a, &b| w[a].total_cmp(&w[b]));
    let w: Vec<f64> = order.iter().map(|&i| w[i]).collect();
    let x: Vec<&Vec<f64>> = order.iter().map(|&i| &x[i]).collect();
    let n = x[0].len();
    let mut shapes = Array2::zeros((w.len(), n));
    for (i, v) in x.iter().enumerate() {
        let mut mv = vec![0.0; n];
        block_mul(sys, m, v, &mut mv);
        let norm = dot(v, &mv).max(f64::MIN_POSITIVE).sqrt();
        let big = v.iter().copied().fold(0.0_f64, |a, b| if b.abs() > a.abs() { b } else { a });
        let sign = if big < 0.0 { -1.0 } else { 1.0 };
        for (j, a) in v.iter().enumerate() {
            shapes[(i, j)] = sign * a / norm;
        }
    }
    let rigid: Vec<bool> = w.iter().map(|&w| w.abs() <= rigid_below).collect();
    let frequencies = w
        .iter()
        .zip(&rigid)
        .map(|(&w, &r)| if r { 0.0 } else { w.signum() * w.abs().sqrt() / (2.0 * std::f64::consts::PI) })
        .collect();
    Modes { omega_squared: w.to_vec(), frequencies, rigid, shapes, iterations, roundoff: 0.0 }
}
