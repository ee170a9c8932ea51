//! A torsional spring-damper between two nodes' slopes (SPEC §6): a pin with a torsion
//! spring. With the node angles `θ = atan2(y', x')`, the relative angle is
//! `φ = atan2(r'_a × r'_b, r'_a · r'_b) − φ₀` (locally `θ_b − θ_a − φ₀`, wrapped to
//! (−π, π] before `φ₀` is taken off) and its rate `φ̇ = ∇φ · q̇`, where over
//! `(x'_a, y'_a, x'_b, y'_b)`
//!
//! ```text
//!     ∇φ = (y'_a/|r'_a|², −x'_a/|r'_a|², −y'_b/|r'_b|², x'_b/|r'_b|²).
//! ```
//!
//! The moment `M = −(k φ + c φ̇)` acts on b's slope and `−M` on a's, as §1's nodal moments:
//! in the sign of `g = … − Q_ext` the spring adds `N ∇φ`, `N = k φ + c φ̇`. Its Jacobians,
//! with `H` the Hessian of `φ` (block-diagonal: `−H_θ(r'_a)`, `H_θ(r'_b)`,
//! `H_θ = [[2x'y', y'² − x'²], [y'² − x'², −2x'y']]/|r'|⁴`, [`super::moment_jacobian`]):
//!
//! ```text
//!     ∂g/∂q = k ∇φ ∇φᵀ + N H + c ∇φ (H q̇)ᵀ,      ∂g/∂q̇ = c ∇φ ∇φᵀ,
//! ```
//!
//! symmetric without damping. Its stored energy is `½ k φ²`.

use super::moment::moment_jacobian;
use super::nodal::{NodalLoad, NodeIndex, Read, Scaling};
use crate::physics::parts::NodeId;

/// A torsional spring-damper between two nodes' slopes, as the model file gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct TorsionalSpring {
    pub a: NodeId,
    pub b: NodeId,
    /// `k`, N m/rad
    pub stiffness: f64,
    /// `c`, N m s/rad
    pub damping: f64,
    /// `φ₀`, the relative angle at which it is relaxed (the initial one), rad
    pub angle: f64,
    /// what scales `k`: fixed, or the parameter that sets it ([`Scaling::Property`])
    pub scaled: Scaling,
}

impl TorsionalSpring {
    /// The spring on the global slope coordinates of its nodes.
    pub fn lower(&self, first: NodeIndex) -> NodalTorsionalSpring {
        let (a, b) = (first(self.a), first(self.b));
        NodalTorsionalSpring {
            dofs: [a + 2, a + 3, b + 2, b + 3],
            k: self.stiffness,
            c: self.damping,
            phi0: self.angle,
            scaled: self.scaled.clone(),
        }
    }
}

/// [`TorsionalSpring`] on global coordinates.
#[derive(Clone, Debug)]
pub struct NodalTorsionalSpring {
    /// a's `x'`, `y'`, then b's
    dofs: [usize; 4],
    k: f64,
    c: f64,
    phi0: f64,
    /// always fixed: the load scale does not wind a spring
    scaled: Scaling,
}

/// `φ`, `∇φ` and the slopes at a state.
struct Twist {
    phi: f64,
    grad: [f64; 4],
    slopes: [f64; 4],
}

impl NodalTorsionalSpring {
    fn twist(&self, q: Read) -> Twist {
        let s: [f64; 4] = std::array::from_fn(|i| q(self.dofs[i]));
        let (na, nb) = (s[0] * s[0] + s[1] * s[1], s[2] * s[2] + s[3] * s[3]);
        let (cross, dot) = (s[0] * s[3] - s[1] * s[2], s[0] * s[2] + s[1] * s[3]);
        Twist { phi: cross.atan2(dot) - self.phi0, grad: [s[1] / na, -s[0] / na, -s[3] / nb, s[2] / nb], slopes: s }
    }

    /// `φ̇ = ∇φ · q̇`
    fn rate(&self, tw: &Twist, v: Read) -> f64 {
        (0..4).map(|i| tw.grad[i] * v(self.dofs[i])).sum()
    }

    /// `H` of `φ` as two 2×2 blocks, a's and b's.
    fn hessian(tw: &Twist) -> [[[f64; 2]; 2]; 2] {
        let (ha, hb) =
            (moment_jacobian(1.0, [tw.slopes[0], tw.slopes[1]]), moment_jacobian(1.0, [tw.slopes[2], tw.slopes[3]]));
        [ha.map(|r| r.map(|x| -x)), hb]
    }
}

impl NodalLoad for NodalTorsionalSpring {
    fn dofs(&self) -> &[usize] {
        &self.dofs
    }

    fn scaling(&self) -> &Scaling {
        &self.scaled
    }

    fn add_force(&self, factor: f64, _t: f64, q: Read, v: Read, add: &mut dyn FnMut(usize, f64)) {
        let tw = self.twist(q);
        let k = self.k * factor;
        let mut n = k * tw.phi;
        if self.c != 0.0 {
            n += self.c * self.rate(&tw, v);
        }
        for (&d, g) in self.dofs.iter().zip(tw.grad) {
            add(d, n * g);
        }
    }

    fn has_stiffness(&self) -> bool {
        true
    }

    fn add_stiffness(&self, factor: f64, _t: f64, q: Read, v: Read, add: &mut dyn FnMut(usize, usize, f64)) {
        let tw = self.twist(q);
        let h = Self::hessian(&tw);
        let k = self.k * factor;
        let mut n = k * tw.phi;
        // H q̇, for the damper's c ∇φ (H q̇)ᵀ
        let mut hv = [0.0; 4];
        if self.c != 0.0 {
            n += self.c * self.rate(&tw, v);
            for (blk, hb) in h.iter().enumerate() {
                for r in 0..2 {
                    hv[2 * blk + r] = (0..2).map(|c| hb[r][c] * v(self.dofs[2 * blk + c])).sum();
                }
            }
        }
        for i in 0..4 {
            for j in 0..4 {
                // g_i g_j = g_j g_i and H's off-diagonal entries are one value: symmetric
                // to the bit without damping
                let mut x = k * (tw.grad[i] * tw.grad[j]);
                if i / 2 == j / 2 {
                    x += n * h[i / 2][i % 2][j % 2];
                }
                if self.c != 0.0 {
                    x += self.c * tw.grad[i] * hv[j];
                }
                add(self.dofs[i], self.dofs[j], x);
            }
        }
    }

    fn has_damping(&self) -> bool {
        self.c != 0.0
    }

    fn add_damping(&self, _factor: f64, _t: f64, q: Read, _v: Read, add: &mut dyn FnMut(usize, usize, f64)) {
        let g = self.twist(q).grad;
        for i in 0..4 {
            for j in 0..4 {
                add(self.dofs[i], self.dofs[j], self.c * (g[i] * g[j]));
            }
        }
    }

    fn symmetric(&self) -> bool {
        self.c == 0.0
    }

    fn stored_energy(&self, factor: f64, q: Read, v: Read) -> Option<(f64, f64)> {
        let tw = self.twist(q);
        let k = self.k * factor;
        Some((0.5 * k * tw.phi * tw.phi, k * tw.phi * self.rate(&tw, v)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::loads::nodal::tests::check_jacobians;

    fn spring(c: f64) -> NodalTorsionalSpring {
        TorsionalSpring { a: (0, 1), b: (1, 0), stiffness: 3.0, damping: c, angle: 0.1, scaled: Scaling::Fixed }
            .lower(&|(b, k)| 4 * (2 * b + k))
    }

    /// a's slope at 0.3 rad (length 1.2), b's at 0.9 rad (length 0.8), turning at 0.5 and
    /// −0.25 rad/s: φ = 0.6 − 0.1 = 0.5 rad, φ̇ = −0.75 rad/s.
    fn state() -> (Vec<f64>, Vec<f64>) {
        let (mut q, mut v) = (vec![0.0; 16], vec![0.0; 16]);
        let (ta, tb, la, lb, wa, wb) = (0.3_f64, 0.9_f64, 1.2, 0.8, 0.5, -0.25);
        (q[6], q[7]) = (la * ta.cos(), la * ta.sin());
        (q[10], q[11]) = (lb * tb.cos(), lb * tb.sin());
        // ṙ' = ω × r'
        (v[6], v[7]) = (-wa * q[7], wa * q[6]);
        (v[10], v[11]) = (-wb * q[11], wb * q[10]);
        (q, v)
    }

    #[test]
    fn the_moment_is_the_spring_torque_and_its_energy_half_k_phi_squared() {
        let (q, v) = state();
        let s = spring(0.4);
        // V = ½·3·0.5² = 0.375 J; V̇ = k φ φ̇ = 3·0.5·(−0.75) = −1.125 W
        let (e, rate) = s.stored_energy(1.0, &|d| q[d], &|d| v[d]).unwrap();
        assert!((e - 0.375).abs() < 1e-14 && (rate + 1.125).abs() < 1e-14, "{e} {rate}");
        // turning b's slope by δ at fixed length does the work N δ, N = kφ + cφ̇ = 1.5 − 0.3
        let mut g = [0.0; 16];
        s.add_force(1.0, 0.0, &|d| q[d], &|d| v[d], &mut |d, x| g[d] += x);
        let dr = [-q[11], q[10]];
        let work = g[10] * dr[0] + g[11] * dr[1];
        assert!((work - 1.2).abs() < 1e-13, "{work}");
    }

    #[test]
    fn tangents_match_finite_differences() {
        let (q, v) = state();
        for c in [0.0, 0.4] {
            check_jacobians(&spring(c), &q, &v);
        }
    }
}
