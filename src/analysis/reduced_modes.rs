//! The natural frequencies a reduced basis keeps (`flexrom modes --basis`): the eigenproblem
//! of [`super::modes`] restricted to the basis's span by Rayleigh–Ritz,
//!
//! ```text
//! K_r = Vᵀ K_T V,   M_r = Vᵀ M V,   C = B V,   N a basis of ker C,
//! Nᵀ K_r N y = ω² Nᵀ M_r N y
//! ```
//!
//! `V` (n_dof × r) the basis's columns (the POD modes and, constraint-preserving, the unit
//! columns of the joint coordinates), the increments `V z` the reduced model can take with
//! its constraint rows held (`B V z = 0`). Since `span(V N) ⊂ ker B`, the Courant–Fischer
//! min-max principle makes each reduced `ω²_i` an upper bound of the full `ω²_i`: a basis
//! that keeps a mode gives its frequency, one that lost it gives a higher one. The
//! projection is that of the full stiffness and mass (hyper-reduction's sampled elements are
//! not used: the question is what the modes can represent, not what ECSW integrates).

use super::assembly::{self, block_mul};
use crate::error::{Error, Result};
use crate::linalg::lapack::{Eigh, SVD, UPLO};
use crate::physics::system::FlexibleSystem;
use crate::solver::model::{Parameters, ParametricModel};
use ndarray::{Array2, ArrayView2};

/// A singular value of `B V` counts toward its rank above `RANK · max(σ_max, ‖B‖ ‖V‖)`
/// (POD modes satisfy `B φ = 0` to the training's Newton tolerance, the kept unit columns
/// give `σ ≈ 1`; `‖B‖` its largest coefficient, `‖V‖` its longest column).
const RANK: f64 = 1e-8;
/// A reduced mode is rigid when `|ω²| ≤ RIGID · max ω²` of the reduced problem (a rigid
/// mode's `ω²` is the dense solver's round-off, about `ε max ω²`).
const RIGID: f64 = 1e-9;

/// The frequencies of the reduced space, ascending.
#[derive(Clone, Debug, PartialEq)]
pub struct ReducedModes {
    /// `ω²`, 1/s²
    pub omega_squared: Vec<f64>,
    /// `√ω²/2π`, Hz (0 for a rigid mode, negative for a negative `ω²`)
    pub frequencies: Vec<f64>,
    pub rigid: Vec<bool>,
    /// the dimension of the reduced space with the constraints held, `r − rank(B V)`:
    /// how many frequencies the basis has at all
    pub dimension: usize,
}

/// The lowest `count` (or all the space has, if fewer) frequencies of `sys` at `μ`,
/// linearized at `q` (the loads at `t`), in the span of `v` (n_dof × r).
pub fn compute(
    sys: &FlexibleSystem,
    mu: &Parameters,
    q: &[f64],
    t: f64,
    v: ArrayView2<f64>,
    count: usize,
) -> Result<ReducedModes> {
    let n = v.nrows();
    if n != ParametricModel::n_dof(sys) {
        return Err(Error::usage(format!("the basis has {n} coordinates, the model {}", ParametricModel::n_dof(sys))));
    }
    let kr = project(sys, &assembly::tangent_blocks(sys, mu, q, t, 1.0), v);
    let mr = project(sys, &assembly::mass_blocks(sys, mu), v);
    let null = constrained_space(sys, v)?;
    let (kn, mn) = (null.t().dot(&kr).dot(&null), null.t().dot(&mr).dot(&null));
    let dimension = null.ncols();
    if dimension == 0 {
        return Ok(ReducedModes { omega_squared: vec![], frequencies: vec![], rigid: vec![], dimension });
    }
    let (values, _) = (kn, mn).eigh(UPLO::Lower).map_err(|e| Error::LinearSolve {
        t,
        problem: format!(
            "modes --basis: the projected mass Vᵀ M V is not positive definite in the {dimension} reduced coordinates \
             the constraints leave ({e}): the basis's columns are dependent"
        ),
    })?;
    let mut w: Vec<f64> = values.to_vec();
    w.sort_by(f64::total_cmp);
    let top = w.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    w.truncate(count.min(dimension));
    let frequencies = w.iter().map(|&x| x.signum() * x.abs().sqrt() / (2.0 * std::f64::consts::PI)).collect();
    let rigid = w.iter().map(|x| x.abs() <= RIGID * top).collect();
    Ok(ReducedModes { omega_squared: w, frequencies, rigid, dimension })
}

/// `Vᵀ A V` of the element blocks `a`, symmetrized (½(X + Xᵀ), the blocks' round-off).
fn project(sys: &FlexibleSystem, a: &[crate::linalg::kkt::Block], v: ArrayView2<f64>) -> Array2<f64> {
    let (n, r) = v.dim();
    let mut av = Array2::zeros((n, r));
    let mut y = vec![0.0; n];
    for j in 0..r {
        let x = v.column(j).to_vec();
        block_mul(sys, a, &x, &mut y);
        av.column_mut(j).assign(&ndarray::ArrayView1::from(&y));
    }
    let p = v.t().dot(&av);
    (&p + &p.t()) * 0.5
}

/// `N` (r × d): an orthonormal basis of `ker(B V)`, from the SVD of `B V`.
fn constrained_space(sys: &FlexibleSystem, v: ArrayView2<f64>) -> Result<Array2<f64>> {
    let r = v.ncols();
    let nc = sys.constraints.len();
    if nc == 0 {
        return Ok(Array2::eye(r));
    }
    let mut c = Array2::zeros((nc.max(r), r));
    for (i, row) in sys.constraints.iter().enumerate() {
        for &(d, coef) in &row.terms {
            c.row_mut(i).scaled_add(coef, &v.row(d));
        }
    }
    // rows padded with zeros to at least r: the SVD's V then has all r right vectors
    let (_, s, vt) = c
        .svd(false, true)
        .map_err(|e| Error::LinearSolve { t: 0.0, problem: format!("modes --basis: the SVD of B V: {e}") })?;
    let vt = vt.expect("right singular vectors asked for");
    // relative to ‖B‖ ‖V‖ (a POD basis has B V at round-off only: not rank by itself)
    let coef = sys.constraints.iter().flat_map(|c| c.terms.iter()).fold(0.0_f64, |m, t| m.max(t.1.abs()));
    let column = v.columns().into_iter().fold(0.0_f64, |m, c| m.max(c.dot(&c).sqrt()));
    let top = s.iter().fold(coef * column, |m, x| m.max(*x));
    let rank = s.iter().filter(|&&x| x > RANK * top).count();
    Ok(vt.slice(ndarray::s![rank.., ..]).t().to_owned())
}
