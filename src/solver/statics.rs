//! Static equilibrium `Q_e(q) − Q_ext(q, t) + Bᵀλ = 0`, `B q = b`, by Newton on the KKT
//! system with the tangent `K_T` (no mass). Load stepping is the caller's (set a load scale,
//! solve, repeat), so this stays generic over [`DynamicModel`].

use super::model::{DynamicModel, IterationCoefficients};
use crate::error::{Error, Result};

/// Solves in place from the guess `q`; returns the multipliers and the iteration count.
pub fn solve_static<M: DynamicModel>(
    model: &mut M,
    q: &mut [f64],
    t: f64,
    tolerance: f64,
    max_iterations: usize,
) -> Result<(Vec<f64>, usize)> {
    let (n, nc) = (model.n_dof(), model.n_constraints());
    let zero = vec![0.0; n];
    let mut lambda = vec![0.0; nc];
    let mut rhs = vec![0.0; n + nc];
    let coef = IterationCoefficients { mass: 0.0, damping: 0.0, stiffness: 1.0 };
    let tol = tolerance * model.length_scale();
    let mut inc = f64::INFINITY;
    let mut residual = f64::NAN;
    for it in 1..=max_iterations {
        model.force(q, &zero, t, &mut rhs[..n]);
        model.add_constraint_force(&lambda, t, &mut rhs[..n]);
        residual = crate::linalg::vec_ops::max_abs(&rhs[..n]);
        if !residual.is_finite() {
            // diverged: no matrix to factor at a NaN or infinite state
            break;
        }
        let s = model.factor(q, &zero, t, coef).map_err(|e| e.at_time(t))?;
        let (rq, rc) = rhs.split_at_mut(n);
        rq.iter_mut().for_each(|x| *x = -*x);
        model.constraint_residual(q, t, rc);
        rc.iter_mut().for_each(|x| *x *= -s);
        model.solve(&mut rhs).map_err(|e| e.at_time(t))?;
        inc = crate::linalg::vec_ops::max_abs(&rhs[..n]);
        if !inc.is_finite() {
            break;
        }
        for i in 0..n {
            q[i] += rhs[i];
        }
        for (l, m) in lambda.iter_mut().zip(&rhs[n..]) {
            *l += s * m;
        }
        if inc <= tol {
            return Ok((lambda, it));
        }
    }
    Err(Error::NewtonFailed { t, dt: 0.0, cuts: 0, iterations: max_iterations, increment: inc, residual })
}
