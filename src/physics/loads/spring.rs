//! A translational spring-damper between two nodes, or a node and a ground point (SPEC §6).
//! With `d = r_a − r_b`, `L = |d|`, `e = d/L` and the rate of stretch `L̇ = e·(ṙ_a − ṙ_b)`,
//! the tension is `N = k (L − L₀) + c L̇` and the force on a is `f = −N e` (`+N e` on b). In
//! the sign of the model's force `g = … − Q_ext` it adds `N e` on a's position and `−N e` on
//! b's. Its Jacobians, with `P = I − e eᵀ`, over `d`:
//!
//! ```text
//!     ∂(N e)/∂d = k e eᵀ + (N/L) P + (c/L) e (P Δv)ᵀ,      ∂(N e)/∂Δv = c e eᵀ
//! ```
//!
//! (`∂d/∂r_a = I`, `∂d/∂r_b = −I`): symmetric without damping. Its stored energy is
//! `½ k (L − L₀)²`; the damper dissipates `c L̇²`. A stiffness that is a parameter
//! (`stiffness = { value, parameter }`) enters as `k = k_file · f`, `f` its factor
//! ([`Scaling::Property`]); the damping is the file's. At `L = 0` the direction is undefined
//! and the spring exerts nothing (a model starts its springs between distinct points, or
//! with a free length, `model::check`).

use super::nodal::{NodalLoad, NodeIndex, Read, Scaling};
use crate::physics::parts::NodeId;

/// The second end of a spring: a node, or a fixed point of the ground.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpringEnd {
    Node(NodeId),
    Point([f64; 2]),
}

/// A translational spring-damper, as the model file gives it (free length resolved).
#[derive(Clone, Debug, PartialEq)]
pub struct Spring {
    pub a: NodeId,
    pub b: SpringEnd,
    /// `k`, N/m
    pub stiffness: f64,
    /// `c`, N s/m
    pub damping: f64,
    /// `L₀`, m
    pub length: f64,
    /// what scales `k`: fixed, or the parameter that sets it ([`Scaling::Property`])
    pub scaled: Scaling,
}

impl Spring {
    /// The spring on the global position coordinates of its nodes.
    pub fn lower(&self, first: NodeIndex) -> NodalSpring {
        let a = first(self.a);
        let (dofs, ground) = match self.b {
            SpringEnd::Node(b) => {
                let b = first(b);
                (vec![a, a + 1, b, b + 1], None)
            }
            SpringEnd::Point(p) => (vec![a, a + 1], Some(p)),
        };
        NodalSpring { dofs, ground, k: self.stiffness, c: self.damping, l0: self.length, scaled: self.scaled.clone() }
    }
}

/// [`Spring`] on global coordinates.
#[derive(Clone, Debug)]
pub struct NodalSpring {
    /// a's `x`, `y`, then b's (a node) or nothing (a ground point)
    dofs: Vec<usize>,
    ground: Option<[f64; 2]>,
    k: f64,
    c: f64,
    l0: f64,
    /// fixed, or the parameter that sets `k` (the load scale never stretches a spring)
    scaled: Scaling,
}

/// The state of a spring: `d`, `L`, `e`, `Δv = ṙ_a − ṙ_b`, `L̇`.
struct Stretch {
    len: f64,
    e: [f64; 2],
    dv: [f64; 2],
    rate: f64,
}

impl NodalSpring {
    fn stretch(&self, q: Read, v: Read) -> Stretch {
        let d = &self.dofs;
        let (rb, vb) = match self.ground {
            Some(p) => (p, [0.0; 2]),
            None => ([q(d[2]), q(d[3])], [v(d[2]), v(d[3])]),
        };
        let dx = [q(d[0]) - rb[0], q(d[1]) - rb[1]];
        let len = dx[0].hypot(dx[1]);
        let e = if len > 0.0 { [dx[0] / len, dx[1] / len] } else { [0.0; 2] };
        // an undamped spring does not read the velocities
        let dv = if self.c != 0.0 { [v(d[0]) - vb[0], v(d[1]) - vb[1]] } else { [0.0; 2] };
        Stretch { len, e, dv, rate: e[0] * dv[0] + e[1] * dv[1] }
    }

    /// The tension `N = k (L − L₀) + c L̇` at the stiffness `k`.
    fn tension(&self, k: f64, s: &Stretch) -> f64 {
        k * (s.len - self.l0) + self.c * s.rate
    }

    /// Adds the 2×2 block `m` over `d` to every pair of ends with the sign `∂d/∂r`.
    fn add_block(&self, m: [[f64; 2]; 2], add: &mut dyn FnMut(usize, usize, f64)) {
        let ends = self.dofs.len() / 2;
        for i in 0..ends {
            for j in 0..ends {
                let sign = if i == j { 1.0 } else { -1.0 };
                for (r, mr) in m.iter().enumerate() {
                    for (c, &x) in mr.iter().enumerate() {
                        add(self.dofs[2 * i + r], self.dofs[2 * j + c], sign * x);
                    }
                }
            }
        }
    }
}

impl NodalLoad for NodalSpring {
    fn dofs(&self) -> &[usize] {
        &self.dofs
    }

    fn scaling(&self) -> &Scaling {
        &self.scaled
    }

    fn add_force(&self, factor: f64, _t: f64, q: Read, v: Read, add: &mut dyn FnMut(usize, f64)) {
        let s = self.stretch(q, v);
        let n = self.tension(self.k * factor, &s);
        add(self.dofs[0], n * s.e[0]);
        add(self.dofs[1], n * s.e[1]);
        if self.ground.is_none() {
            add(self.dofs[2], -n * s.e[0]);
            add(self.dofs[3], -n * s.e[1]);
        }
    }

    fn has_stiffness(&self) -> bool {
        true
    }

    fn add_stiffness(&self, factor: f64, _t: f64, q: Read, v: Read, add: &mut dyn FnMut(usize, usize, f64)) {
        let s = self.stretch(q, v);
        if s.len == 0.0 {
            return;
        }
        let k = self.k * factor;
        let n_l = self.tension(k, &s) / s.len;
        let c_l = self.c / s.len;
        let e = s.e;
        // P Δv = Δv − e L̇
        let pdv = [s.dv[0] - e[0] * s.rate, s.dv[1] - e[1] * s.rate];
        // each entry from the same products in the same order as its mirror where the
        // matrix is symmetric (c = 0): e_i e_j = e_j e_i
        let m = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let ee = e[i] * e[j];
                let p = if i == j { 1.0 - ee } else { -ee };
                let mut x = k * ee + n_l * p;
                if self.c != 0.0 {
                    x += c_l * e[i] * pdv[j];
                }
                x
            })
        });
        self.add_block(m, add);
    }

    fn has_damping(&self) -> bool {
        self.c != 0.0
    }

    fn add_damping(&self, _factor: f64, _t: f64, q: Read, v: Read, add: &mut dyn FnMut(usize, usize, f64)) {
        let e = self.stretch(q, v).e;
        let m = std::array::from_fn(|i| std::array::from_fn(|j| self.c * (e[i] * e[j])));
        self.add_block(m, add);
    }

    fn symmetric(&self) -> bool {
        self.c == 0.0
    }

    fn stored_energy(&self, factor: f64, q: Read, v: Read) -> Option<(f64, f64)> {
        let s = self.stretch(q, v);
        let k = self.k * factor;
        let stretch = s.len - self.l0;
        // V̇ = k (L − L₀) L̇ needs L̇ even without damping
        let rate = {
            let d = &self.dofs;
            let vb = if self.ground.is_some() { [0.0; 2] } else { [v(d[2]), v(d[3])] };
            s.e[0] * (v(d[0]) - vb[0]) + s.e[1] * (v(d[1]) - vb[1])
        };
        Some((0.5 * k * stretch * stretch, k * stretch * rate))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::loads::nodal::tests::{check_jacobians, Dense};

    fn between_nodes(c: f64) -> NodalSpring {
        Spring {
            a: (0, 1),
            b: SpringEnd::Node((1, 0)),
            stiffness: 400.0,
            damping: c,
            length: 0.2,
            scaled: Scaling::Fixed,
        }
        .lower(&|(b, k)| 4 * (3 * b + k))
    }

    /// A state with the ends 0.3 m apart along (0.6, 0.8) · 0.5: stretched by 0.1 m from
    /// L₀ = 0.2, moving apart at 0.6·1 + 0.8·(−0.5) = 0.2 m/s.
    fn state() -> (Dense, Dense) {
        let mut q = vec![0.0; 24];
        let mut v = vec![0.0; 24];
        (q[4], q[5]) = (0.18, 0.24);
        (v[4], v[5]) = (1.0, -0.5);
        // b at the origin with a velocity of its own
        (v[12], v[13]) = (0.3, 0.1);
        (q, v)
    }

    #[test]
    fn the_force_is_the_tension_along_the_spring() {
        let (q, mut v) = state();
        (v[12], v[13]) = (0.0, 0.0);
        let s = between_nodes(0.5);
        let mut g = [0.0; 24];
        s.add_force(1.0, 0.0, &|d| q[d], &|d| v[d], &mut |d, x| g[d] += x);
        // L = 0.3, e = (0.6, 0.8), L̇ = 0.6·1 − 0.8·0.5 = 0.2: N = 400·0.1 + 0.5·0.2 = 40.1 N
        let n = 40.1;
        for (d, want) in [(4, n * 0.6), (5, n * 0.8), (12, -n * 0.6), (13, -n * 0.8)] {
            assert!((g[d] - want).abs() < 1e-12, "dof {d}: {} vs {want}", g[d]);
        }
        // V = ½ k (L − L₀)² = ½·400·0.01 = 2 J, V̇ = k (L − L₀) L̇ = 400·0.1·0.2 = 8 W
        let (e, rate) = s.stored_energy(1.0, &|d| q[d], &|d| v[d]).unwrap();
        assert!((e - 2.0).abs() < 1e-12 && (rate - 8.0).abs() < 1e-12, "{e} {rate}");
    }

    #[test]
    fn tangents_match_finite_differences() {
        let (q, v) = state();
        for c in [0.0, 0.5] {
            check_jacobians(&between_nodes(c), &q, &v);
            let ground = Spring {
                a: (0, 1),
                b: SpringEnd::Point([-0.1, 0.05]),
                stiffness: 400.0,
                damping: c,
                length: 0.2,
                scaled: Scaling::Fixed,
            };
            check_jacobians(&ground.lower(&|(b, k)| 4 * (3 * b + k)), &q, &v);
        }
    }

    #[test]
    fn undamped_stiffness_is_symmetric_to_the_bit() {
        let (q, v) = state();
        let s = between_nodes(0.0);
        let mut k = vec![0.0; 24 * 24];
        s.add_stiffness(1.0, 0.0, &|d| q[d], &|d| v[d], &mut |r, c, x| k[r * 24 + c] += x);
        for r in 0..24 {
            for c in 0..24 {
                assert_eq!(k[r * 24 + c].to_bits(), k[c * 24 + r].to_bits(), "({r}, {c})");
            }
        }
        assert!(s.symmetric() && !between_nodes(0.5).symmetric());
    }
}
