//! `y = A x` for a fixed matrix `A` and an `x` that moves in small steps, kept by increments.
//!
//! Where `A` has large entries and `x` large components that `A` nearly annihilates — the
//! projected bending stiffness of a reduced model and the rigid rotation in its modal
//! amplitudes (the ×10 four-bar: ‖|A||x|‖∞ = 1.8e11 against ‖A x‖∞ = 50) — the direct
//! product carries a rounding error of about ε_mach ‖|A||x|‖∞ (2e-5 there), far above
//! Newton's tolerance and different at every `x`: Newton's increments stall at that noise
//! (the round-off floor `simulate -v` counts) and only the stagnation test ends the step,
//! iterations later. Kept as `y ← y + A (x − x_last)`, each product rounds at
//! ε ‖|A||x − x_last|‖, which shrinks with Newton's corrections; the error already in `y`
//! stays as it is, a bias of the direct product's size that Newton converges through.
//! The product is formed directly again once the path `Σ ‖x_k − x_{k−1}‖∞` since the last
//! direct product exceeds the `‖x‖∞` it was formed at, or the current one: from there the
//! rounding of the increments, summed, could exceed a direct product's.

use super::sparse_rows::SparseRows;
use super::vec_ops::max_abs;

pub(crate) struct IncrementalProduct {
    /// the `x` of `y`, and `y = A x`
    x: Vec<f64>,
    y: Vec<f64>,
    dx: Vec<f64>,
    /// `Σ ‖x_k − x_{k−1}‖∞` since the last direct product (∞: none yet, or reset), and
    /// `‖x‖∞` there
    path: f64,
    scale: f64,
}

impl IncrementalProduct {
    /// For an `A` of `rows` × `cols`.
    pub(crate) fn new(rows: usize, cols: usize) -> Self {
        IncrementalProduct {
            x: vec![0.0; cols],
            y: vec![0.0; rows],
            dx: vec![0.0; cols],
            path: f64::INFINITY,
            scale: 0.0,
        }
    }

    /// Forgets `y`: the next product is direct (after `A` changed, or where a run must not
    /// depend on the evaluations before it).
    pub(crate) fn reset(&mut self) {
        self.path = f64::INFINITY;
    }

    /// `out += A x`, `A` the matrix of every call since the last [`Self::reset`].
    pub(crate) fn add_product(&mut self, a: &SparseRows, x: &[f64], out: &mut [f64]) {
        for ((d, &xi), &xl) in self.dx.iter_mut().zip(x).zip(&self.x) {
            *d = xi - xl;
        }
        // NaN reads as ∞ (max_abs): a non-finite x takes the direct product
        let (step, size) = (max_abs(&self.dx), max_abs(x));
        // the smaller of ‖x‖∞ at the last direct product and now: a direct product at a
        // far iterate (a Newton attempt that diverged, then the step retried from its start)
        // must not license a long path back
        if !(self.path + step <= self.scale.min(size)) {
            a.mul(x, &mut self.y, false);
            (self.path, self.scale) = (0.0, size);
        } else if step > 0.0 {
            a.mul(&self.dx, &mut self.y, true);
            self.path += step;
        }
        self.x.copy_from_slice(x);
        out.iter_mut().zip(&self.y).for_each(|(o, y)| *o += y);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    /// The products along a path of small steps equal the direct ones (to the rounding of
    /// the direct product), also across a reset and a return to a point passed before.
    #[test]
    fn follows_the_direct_product() {
        let n = 6;
        let a = Array2::from_shape_fn((n, n), |(i, j)| ((i * n + j) as f64 * 0.7).sin() * 10f64.powi((i % 3) as i32));
        let rows = SparseRows::new(&a);
        let mut p = IncrementalProduct::new(n, n);
        let point =
            |k: usize| -> Vec<f64> { (0..n).map(|i| 5.0 + (i as f64) + 1e-2 * ((k * 7 + i) as f64).cos()).collect() };
        for k in 0..50 {
            if k == 30 {
                p.reset();
            }
            let x = if k == 40 { point(3) } else { point(k) };
            let mut out = vec![1.0; n];
            p.add_product(&rows, &x, &mut out);
            let mut direct = vec![0.0; n];
            rows.mul(&x, &mut direct, false);
            for (o, d) in out.iter().zip(&direct) {
                // |A||x| ≤ 6 · 100 · 11: the bound of the direct product's rounding
                assert!((o - 1.0 - d).abs() < 1e-11, "step {k}: {o} against {}", d + 1.0);
            }
        }
    }

    /// Why it exists: `A` nearly annihilates the large part of `x` (a constant vector
    /// times 1e6 against a matrix whose rows sum to zero up to 1e-9): along Newton-like
    /// corrections that halve, the direct product's rounding stays at ε‖|A||x|‖ while the
    /// kept one's changes shrink with the corrections, so that the changes of the product
    /// follow `A Δx` to a relative 1e-6 long after the direct ones have become noise.
    #[test]
    fn its_changes_shrink_with_the_steps() {
        let n = 8;
        let mut a = Array2::from_shape_fn((n, n), |(i, j)| {
            if i == j {
                2e9
            } else if i.abs_diff(j) == 1 {
                -1e9
            } else {
                0.0
            }
        });
        a[[0, 0]] = 1e9;
        a[[n - 1, n - 1]] = 1e9;
        let rows = SparseRows::new(&a);
        let mut p = IncrementalProduct::new(n, n);
        let mut x: Vec<f64> = (0..n).map(|i| 1e6 + 1e-3 * i as f64).collect();
        let mut prev = vec![0.0; n];
        p.add_product(&rows, &x, &mut prev);
        let mut direct_prev = vec![0.0; n];
        rows.mul(&x, &mut direct_prev, false);
        let mut step = 1e-3;
        let mut direct_miss = 0.0_f64;
        for _ in 0..20 {
            step *= 0.5;
            let old = x.clone();
            x.iter_mut().enumerate().for_each(|(i, x)| *x += step * ((i as f64) * 1.3 + 0.4).sin());
            // the step as stored (x itself rounds at 1e-10): exact, by Sterbenz
            let dx: Vec<f64> = x.iter().zip(&old).map(|(a, b)| a - b).collect();
            let mut now = vec![0.0; n];
            p.add_product(&rows, &x, &mut now);
            let mut exact = vec![0.0; n];
            rows.mul(&dx, &mut exact, false);
            let mut direct = vec![0.0; n];
            rows.mul(&x, &mut direct, false);
            let scale = max_abs(&exact);
            for i in 0..n {
                let c = now[i] - prev[i];
                assert!((c - exact[i]).abs() <= 1e-6 * scale, "change {c} against A Δx {} at step {step:e}", exact[i]);
                direct_miss = direct_miss.max(((direct[i] - direct_prev[i]) - exact[i]).abs() / scale);
            }
            (prev, direct_prev) = (now, direct);
        }
        // the direct products' changes are noise by the last steps (|A||x| ≈ 4e15 rounds at ~1)
        assert!(direct_miss > 1e-3, "the direct product stayed exact ({direct_miss:e}): the test shows nothing");
    }
}
