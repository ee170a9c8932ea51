//! A moment `M(t)` at a node, acting on its slope (SPEC §1): the node angle is
//! `θ = atan2(y', x')`, so `δW = M δθ` with `δθ = (x' δy' − y' δx')/|r'|²`, giving
//! `Q = M/|r'|² · (−y', x')`, which depends on the slope: the load has a stiffness.

use super::nodal::{NodalLoad, NodeIndex, Read, Scaling};
use crate::physics::parts::NodeId;
use crate::physics::time_function::TimeFunction;

/// A moment on a node, as the model file gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct Moment {
    pub node: NodeId,
    /// `M(t)` in N m, counter-clockwise
    pub function: TimeFunction,
    pub scaled: Scaling,
}

impl Moment {
    /// The moment on the global slope coordinates of its node.
    pub fn lower(&self, first: NodeIndex) -> NodalMoment {
        let d = first(self.node);
        NodalMoment { slope: [d + 2, d + 3], function: self.function.clone(), scaled: self.scaled.clone() }
    }
}

/// [`Moment`] on global coordinates.
#[derive(Clone, Debug)]
pub struct NodalMoment {
    /// the node's `x'` and `y'`
    slope: [usize; 2],
    function: TimeFunction,
    scaled: Scaling,
}

impl NodalLoad for NodalMoment {
    fn dofs(&self) -> &[usize] {
        &self.slope
    }

    fn scaling(&self) -> &Scaling {
        &self.scaled
    }

    fn add_force(&self, factor: f64, t: f64, q: Read, _v: Read, add: &mut dyn FnMut(usize, f64)) {
        let [a, b] = self.slope;
        let qm = moment_force(factor * self.function.eval(t), [q(a), q(b)]);
        add(a, -qm[0]);
        add(b, -qm[1]);
    }

    fn has_stiffness(&self) -> bool {
        true
    }

    fn add_stiffness(&self, factor: f64, t: f64, q: Read, _v: Read, add: &mut dyn FnMut(usize, usize, f64)) {
        let j = moment_jacobian(factor * self.function.eval(t), [q(self.slope[0]), q(self.slope[1])]);
        // g carries −Q_ext, so its Jacobian enters with a minus sign
        for (r, &dr) in self.slope.iter().enumerate() {
            for (c, &dc) in self.slope.iter().enumerate() {
                add(dr, dc, -j[r][c]);
            }
        }
    }
}

/// Generalized force of a moment `M` on a node's slope `r' = (x', y')`.
///
/// The node angle is `θ = atan2(y', x')`, so `δW = M δθ` with
/// `δθ = (x' δy' − y' δx')/|r'|²`, giving `Q = M/|r'|² · (−y', x')` (SPEC §1).
#[inline]
pub fn moment_force(m: f64, slope: [f64; 2]) -> [f64; 2] {
    let [a, b] = slope;
    let n = a * a + b * b;
    [-m * b / n, m * a / n]
}

/// Jacobian `∂Q/∂(x', y')` of [`moment_force`]: with `n = x'² + y'²`,
/// `[[2M x'y', M(y'² − x'²)], [M(y'² − x'²), −2M x'y']] / n²`.
#[inline]
pub fn moment_jacobian(m: f64, slope: [f64; 2]) -> [[f64; 2]; 2] {
    let [a, b] = slope;
    let n = a * a + b * b;
    let n2 = n * n;
    let off = m * (b * b - a * a) / n2;
    [[2.0 * m * a * b / n2, off], [off, -2.0 * m * a * b / n2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moment_does_the_work_of_a_rotation() {
        // Rotating the slope by dθ (any length) must absorb work M dθ: Q · dr' = M dθ.
        let (m, len, th, dth) = (3.0, 1.3_f64, 0.4_f64, 1e-7);
        let s0 = [len * th.cos(), len * th.sin()];
        let s1 = [len * (th + dth).cos(), len * (th + dth).sin()];
        let q = moment_force(m, s0);
        let work = q[0] * (s1[0] - s0[0]) + q[1] * (s1[1] - s0[1]);
        assert!((work - m * dth).abs() < 1e-12, "{work}");
        // stretching the slope along itself does no work
        let q = moment_force(m, s0);
        assert!((q[0] * s0[0] + q[1] * s0[1]).abs() < 1e-14);
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let (m, s) = (2.5, [0.8, -0.35]);
        let j = moment_jacobian(m, s);
        let h = 1e-7;
        for c in 0..2 {
            let mut p = s;
            let mut n = s;
            p[c] += h;
            n[c] -= h;
            let (fp, fm) = (moment_force(m, p), moment_force(m, n));
            for r in 0..2 {
                let fd = (fp[r] - fm[r]) / (2.0 * h);
                assert!((fd - j[r][c]).abs() < 1e-6 * (1.0 + fd.abs()), "({r},{c}): {fd} vs {}", j[r][c]);
            }
        }
    }
}
