//! Non-negative least squares by the active-set method of Lawson & Hanson (Solving Least
//! Squares Problems, 1974, ch. 23, algorithm NNLS), stopped early as ECSW needs it
//! (Farhat, Chapman & Avery 2015, §3.3): as soon as `‖A x − b‖₂ ≤ τ ‖b‖₂`.
//!
//! ```text
//!     min ‖A x − b‖₂  subject to  x ≥ 0
//! ```
//!
//! Columns enter the passive set one at a time (the one with the largest gradient
//! `wⱼ = aⱼᵀ(b − A x)`), so an early stop leaves a sparse `x`. The unconstrained
//! subproblems on the passive set `P` are solved through the Gram matrix `A_Pᵀ A_P`,
//! updated by one column per entry, on unit-norm columns (the sizes here: thousands of
//! rows, a few hundred passive columns at most).

use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};
use ndarray::{Array1, Array2, ArrayView1, ArrayView2, ShapeBuilder};
use rayon::prelude::*;

/// Parameters of [`nnls`]; `validate()` checks them.
#[derive(Clone, Debug, PartialEq)]
pub struct NnlsParams {
    /// stop when `‖A x − b‖ ≤ tolerance · ‖b‖` (0 runs to the Kuhn–Tucker point)
    pub tolerance: f64,
    /// at most this many columns enter the passive set
    pub max_iterations: usize,
}

impl Default for NnlsParams {
    fn default() -> Self {
        NnlsParams { tolerance: 0.0, max_iterations: 10_000 }
    }
}

impl NnlsParams {
    pub fn validate(&self) -> Result<()> {
        if !(self.tolerance.is_finite() && (0.0..1.0).contains(&self.tolerance)) {
            return Err(Error::usage(format!("the NNLS tolerance must lie in [0, 1), got {}", self.tolerance)));
        }
        if self.max_iterations == 0 {
            return Err(Error::usage("max_iterations must be at least 1"));
        }
        Ok(())
    }
}

#[derive(Clone, Debug)]
pub struct NnlsSolution {
    pub x: Array1<f64>,
    /// `‖A x − b‖ / ‖b‖` (0 when b = 0)
    pub relative_residual: f64,
    /// outer iterations (columns that entered the passive set)
    pub iterations: usize,
}

/// Solves `min ‖A x − b‖, x ≥ 0` (see the module documentation).
pub fn nnls(a: ArrayView2<f64>, b: ArrayView1<f64>, params: &NnlsParams) -> Result<NnlsSolution> {
    check(a, b, params)?;
    // unit-norm columns, copied once into column-major storage: every iteration reads whole
    // columns (the gains, the new column's products with the passive ones, the residual),
    // which a row-major A would give strided
    let norms = column_norms(a);
    let mut unit = column_major(a);
    scale_columns(&mut unit, &norms);
    let (x, _, iterations) = solve_unit(unit.view(), &norms, b, params)?;
    let b_norm = b.dot(&b).sqrt();
    if b_norm == 0.0 {
        return Ok(NnlsSolution { x, relative_residual: 0.0, iterations });
    }
    let r = &a.dot(&x) - &b;
    Ok(NnlsSolution { relative_residual: r.dot(&r).sqrt() / b_norm, x, iterations })
}

/// [`nnls`] on an `a` it scales in place (no copy of a column-major `a`: ECSW's matrices run
/// to gigabytes on refined meshes): returns the solution, `a` column-major with its columns
/// scaled to unit norm, and the columns' norms. The residual is the iteration's own,
/// `b − Σ aⱼ xⱼ`.
pub fn nnls_scaling(
    a: Array2<f64>,
    b: ArrayView1<f64>,
    params: &NnlsParams,
) -> Result<(NnlsSolution, Array2<f64>, Vec<f64>)> {
    check(a.view(), b, params)?;
    let mut a = if a.t().is_standard_layout() { a } else { column_major(a.view()) };
    let norms = column_norms(a.view());
    scale_columns(&mut a, &norms);
    let (x, residual, iterations) = solve_unit(a.view(), &norms, b, params)?;
    let b_norm = b.dot(&b).sqrt();
    let relative_residual = if b_norm == 0.0 { 0.0 } else { residual.dot(&residual).sqrt() / b_norm };
    Ok((NnlsSolution { x, relative_residual, iterations }, a, norms))
}

/// A column-major copy of `a` (what LAPACK-style kernels and column sweeps read).
pub(crate) fn column_major(a: ArrayView2<f64>) -> Array2<f64> {
    let mut f = Array2::zeros(a.raw_dim().f());
    f.assign(&a);
    f
}

fn column_norms(a: ArrayView2<f64>) -> Vec<f64> {
    (0..a.ncols()).map(|j| a.column(j).dot(&a.column(j)).sqrt()).collect()
}

/// Divides each column by its norm; zero columns, which can never help, stay as they are
/// (and out of the passive set).
fn scale_columns(a: &mut Array2<f64>, norms: &[f64]) {
    for (j, mut c) in a.columns_mut().into_iter().enumerate() {
        if norms[j] > 0.0 {
            c.mapv_inplace(|v| v / norms[j]);
        }
    }
}

fn check(a: ArrayView2<f64>, b: ArrayView1<f64>, params: &NnlsParams) -> Result<()> {
    params.validate()?;
    if b.len() != a.nrows() {
        return Err(Error::numerical("NNLS", format!("A has {} rows but b has {} entries", a.nrows(), b.len())));
    }
    if a.iter().chain(b.iter()).any(|v| !v.is_finite()) {
        return Err(Error::numerical("NNLS", "A or b holds non-finite values"));
    }
    Ok(())
}

/// The active-set iteration on `unit` (column-major, unit-norm columns of `A`, zero ones
/// where `norms` is 0): the solution `x` (in `A`'s scaling), the last residual
/// `b − A x`, and the iterations; an error where a stop was asked for.
fn solve_unit(
    unit: ArrayView2<f64>,
    norms: &[f64],
    b: ArrayView1<f64>,
    params: &NnlsParams,
) -> Result<(Array1<f64>, Array1<f64>, usize)> {
    let n = unit.ncols();
    let b_norm = b.dot(&b).sqrt();
    let mut x = Array1::<f64>::zeros(n);
    if b_norm == 0.0 {
        return Ok((x, b.to_owned(), 0));
    }
    let col = |j: usize| unit.column(j);
    let mut passive: Vec<usize> = Vec::new();
    let mut excluded = vec![false; n];
    for (j, &nj) in norms.iter().enumerate() {
        excluded[j] = nj == 0.0;
    }
    let mut in_p = vec![false; n];
    // z = x in scaled variables: x_j = z_j / ‖a_j‖
    let mut z = vec![0.0; n];
    let mut residual = b.to_owned();
    let mut gram: Vec<Vec<f64>> = Vec::new(); // rows of A_Pᵀ A_P, in passive order
    let mut atb: Vec<f64> = Vec::new();
    let mut iterations = 0;
    let tol = params.tolerance * b_norm;
    loop {
        // a fit of a refined mesh takes seconds: a stop asked for ends it ([`crate::interrupt`])
        if crate::interrupt::requested() {
            return Err(Error::Interrupted);
        }
        let res_norm = residual.dot(&residual).sqrt();
        if res_norm <= tol || iterations >= params.max_iterations {
            break;
        }
        // the most promising column outside P: the largest aⱼᵀr/‖aⱼ‖, one contiguous unit
        // column at a time on every core (a row-major Aᵀr has no BLAS behind it here and
        // was most of an ECSW training's time on 1100 elements)
        let gain: Vec<f64> = (0..n)
            .into_par_iter()
            .map(|j| if in_p[j] || excluded[j] { f64::NEG_INFINITY } else { col(j).dot(&residual) })
            .collect();
        let best =
            (0..n).filter(|&j| !in_p[j] && !excluded[j]).map(|j| (j, gain[j])).max_by(|p, q| p.1.total_cmp(&q.1));
        let Some((j, wj)) = best else { break };
        if wj <= 0.0 {
            break; // Kuhn–Tucker point: no column can lower the residual
        }
        iterations += 1;
        let cj = col(j);
        let row: Vec<f64> = passive.iter().map(|&p| col(p).dot(&cj)).collect();
        for (g, v) in gram.iter_mut().zip(&row) {
            g.push(*v);
        }
        let mut new_row = row;
        new_row.push(1.0);
        gram.push(new_row);
        atb.push(cj.dot(&b));
        passive.push(j);
        in_p[j] = true;
        // inner loop: keep the subproblem solution feasible
        loop {
            let Some(s) = solve_gram(&gram, &atb) else {
                // the new column depends on the passive ones: take it out for good
                let k = passive.iter().position(|&p| p == j).expect("just added");
                remove(&mut passive, &mut gram, &mut atb, &mut in_p, k);
                excluded[j] = true;
                break;
            };
            if s.iter().all(|&v| v > 0.0) {
                for (k, &p) in passive.iter().enumerate() {
                    z[p] = s[k];
                }
                break;
            }
            // step from z towards s as far as feasibility allows
            let mut alpha = f64::INFINITY;
            for (k, &p) in passive.iter().enumerate() {
                if s[k] <= 0.0 {
                    alpha = alpha.min(z[p] / (z[p] - s[k]));
                }
            }
            for (k, &p) in passive.iter().enumerate() {
                z[p] += alpha * (s[k] - z[p]);
            }
            // drop the columns that reached zero
            let mut k = 0;
            while k < passive.len() {
                let p = passive[k];
                if z[p] <= 1e-14 * (1.0 + z[p].abs()) || (s[k] <= 0.0 && z[p] <= 0.0) {
                    z[p] = 0.0;
                    remove(&mut passive, &mut gram, &mut atb, &mut in_p, k);
                } else {
                    k += 1;
                }
            }
            if passive.is_empty() {
                break;
            }
        }
        residual.assign(&b);
        for &p in &passive {
            residual.scaled_add(-z[p], &col(p));
        }
    }
    for &p in &passive {
        x[p] = z[p] / norms[p];
    }
    Ok((x, residual, iterations))
}

fn remove(passive: &mut Vec<usize>, gram: &mut Vec<Vec<f64>>, atb: &mut Vec<f64>, in_p: &mut [bool], k: usize) {
    in_p[passive[k]] = false;
    passive.remove(k);
    gram.remove(k);
    for g in gram.iter_mut() {
        g.remove(k);
    }
    atb.remove(k);
}

/// Solves `G s = c` by Cholesky; `None` when `G` is numerically singular.
fn solve_gram(gram: &[Vec<f64>], c: &[f64]) -> Option<Vec<f64>> {
    let k = c.len();
    let g = DMatrix::from_fn(k, k, |i, j| gram[i][j]);
    let chol = g.cholesky()?;
    // a pivot far below the unit diagonal means a nearly dependent column
    if (0..k).any(|i| chol.l_dirty()[(i, i)] < 1e-7) {
        return None;
    }
    Some(chol.solve(&DVector::from_column_slice(c)).iter().copied().collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::{array, Array2};

    /// Lawson & Hanson's problem shape with a known answer worked by hand: A = I₃ and
    /// b = (1, −2, 3) give x = max(b, 0) = (1, 0, 3) with residual ‖(0, −2, 0)‖ = 2.
    #[test]
    fn projects_onto_the_nonnegative_orthant_for_the_identity() {
        let a = Array2::eye(3);
        let b = array![1.0, -2.0, 3.0];
        let s = nnls(a.view(), b.view(), &NnlsParams::default()).unwrap();
        assert_eq!(s.x, array![1.0, 0.0, 3.0]);
        assert!((s.relative_residual - 2.0 / 14f64.sqrt()).abs() < 1e-14);
    }

    /// A = [[1, 0], [1, 1], [0, 1]], b = (2, 1, −1), worked by hand: the unconstrained
    /// solution (AᵀA)⁻¹Aᵀb = (2, −1) is infeasible; the optimum puts x₂ = 0 and
    /// x₁ = a₁·b / a₁·a₁ = 3/2, a Kuhn–Tucker point since a₂·(b − A x) = −0.5 − 1 < 0.
    #[test]
    fn finds_the_kuhn_tucker_point_of_a_small_problem() {
        let a = array![[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let b = array![2.0, 1.0, -1.0];
        let s = nnls(a.view(), b.view(), &NnlsParams::default()).unwrap();
        assert!((s.x[0] - 1.5).abs() < 1e-14 && s.x[1] == 0.0, "{:?}", s.x);
    }

    /// b = A·1 with positive A: the exact answer x = 1 is feasible, so with tolerance 0
    /// the residual must vanish; with tolerance 0.3 the method stops early, at a residual
    /// below 0.3 ‖b‖ and with fewer nonzero entries.
    #[test]
    fn meets_its_relative_tolerance_and_stops_early() {
        let a = Array2::from_shape_fn((40, 12), |(i, j)| {
            1.0 + ((i * 7 + j * 13) % 11) as f64 / 5.0 + if i % 12 == j { 3.0 } else { 0.0 }
        });
        let b = a.dot(&Array1::ones(12));
        let exact = nnls(a.view(), b.view(), &NnlsParams::default()).unwrap();
        assert!(exact.relative_residual < 1e-10, "{}", exact.relative_residual);
        let early = nnls(a.view(), b.view(), &NnlsParams { tolerance: 0.3, ..Default::default() }).unwrap();
        assert!(early.relative_residual <= 0.3);
        assert!(early.x.iter().all(|&v| v >= 0.0));
        assert!(early.x.iter().filter(|&&v| v > 0.0).count() < 12);
    }

    /// `nnls_scaling` is `nnls` without the copy: the same columns enter, the weights and
    /// the residual agree to round-off (the norms are summed over a contiguous copy of this
    /// row-major `A`, in another order), and it hands back the columns scaled to unit norm
    /// with their norms.
    #[test]
    fn scaling_in_place_solves_the_same_problem() {
        let a = Array2::from_shape_fn((40, 12), |(i, j)| {
            1.0 + ((i * 7 + j * 13) % 11) as f64 / 5.0 + if i % 12 == j { 3.0 } else { 0.0 }
        });
        let b = a.dot(&Array1::ones(12));
        for tol in [0.3, 1e-3, 0.0] {
            let p = NnlsParams { tolerance: tol, ..Default::default() };
            let plain = nnls(a.view(), b.view(), &p).unwrap();
            let (s, unit, norms) = nnls_scaling(a.clone(), b.view(), &p).unwrap();
            assert_eq!(s.iterations, plain.iterations, "τ = {tol}");
            for (x, y) in s.x.iter().zip(plain.x.iter()) {
                assert!((x > &0.0) == (y > &0.0) && (x - y).abs() <= 1e-12 * (1.0 + y.abs()), "τ = {tol}: {x} vs {y}");
            }
            assert!((s.relative_residual - plain.relative_residual).abs() <= 1e-12, "τ = {tol}");
            for j in 0..12 {
                assert!((norms[j] - a.column(j).dot(&a.column(j)).sqrt()).abs() <= 1e-12 * norms[j]);
                assert!((unit.column(j).dot(&unit.column(j)) - 1.0).abs() <= 1e-12);
            }
        }
    }

    #[test]
    fn refuses_bad_input() {
        let a = Array2::<f64>::eye(2);
        assert!(nnls(a.view(), array![1.0].view(), &NnlsParams::default()).is_err());
        assert!(nnls(a.view(), array![1.0, f64::NAN].view(), &NnlsParams::default()).is_err());
        assert!(nnls(a.view(), array![1.0, 1.0].view(), &NnlsParams { tolerance: 1.5, ..Default::default() }).is_err());
    }
}
