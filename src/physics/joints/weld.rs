//! Two bodies' nodes rigidly joined: the same position, and slopes that keep their initial
//! angle `Δθ = θ_b − θ_a` to each other,
//!
//! ```text
//!     r_a − r_b = 0,        R(Δθ) r'_a − r'_b = 0,        R(Δθ) = [cos Δθ, −sin Δθ; sin Δθ, cos Δθ],
//! ```
//!
//! four rows, linear and constant. As a clamp does, the rows hold the whole slope vector, so
//! the two sides also share their axial stretch at the node (the linear form of a rigid
//! connection in ANCF coordinates; the direction condition alone would be nonlinear).

use super::row::{JointKind, NodeIndex, Row, RowKind, COORDINATES};
use crate::physics::parts::NodeId;

#[derive(Clone, Debug, PartialEq)]
pub struct Weld {
    pub a: NodeId,
    pub b: NodeId,
    /// the initial angle of b's slope to a's, rad
    pub angle: f64,
}

impl JointKind for Weld {
    fn type_name(&self) -> &'static str {
        "weld"
    }

    fn nodes(&self) -> Vec<NodeId> {
        vec![self.a, self.b]
    }

    fn rows(&self, first: NodeIndex) -> Vec<Row> {
        let (a, b) = (first(self.a), first(self.b));
        let (c, s) = (self.angle.cos(), self.angle.sin());
        let position = (0..2).map(|k| Row {
            terms: vec![(a + k, 1.0), (b + k, -1.0)],
            rhs: 0.0,
            component: COORDINATES[k],
            kind: RowKind::Position,
            motion: None,
        });
        // rows of R(Δθ) applied to (x'_a, y'_a), minus b's slope
        let rotation = [[c, -s], [s, c]];
        let slope = (0..2).map(move |k| Row {
            terms: vec![(a + 2, rotation[k][0]), (a + 3, rotation[k][1]), (b + 2 + k, -1.0)],
            rhs: 0.0,
            component: COORDINATES[2 + k],
            kind: RowKind::Slope,
            motion: None,
        });
        position.chain(slope).collect()
    }

    fn couples_bodies(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An L-frame: a at 0 rad, b at 90°. Turning the whole frame rigidly by φ (both slopes
    /// turned, the shared node moved alike) keeps all four rows at zero; turning b alone
    /// breaks the slope rows by the rotation's size.
    #[test]
    fn a_rigid_turn_of_both_sides_keeps_the_rows_and_a_relative_one_does_not() {
        let j = Weld { a: (0, 1), b: (1, 0), angle: std::f64::consts::FRAC_PI_2 };
        let first = |(b, k): NodeId| 4 * (2 * b + k);
        let rows = j.rows(&first);
        let res = |q: &[f64]| -> Vec<f64> {
            rows.iter().map(|r| r.terms.iter().map(|&(d, k)| k * q[d]).sum::<f64>() - r.rhs).collect()
        };
        let phi: f64 = 0.3;
        let mut q = [0.0; 16];
        let (sa, sb) = ([phi.cos(), phi.sin()], [-phi.sin(), phi.cos()]);
        q[4..8].copy_from_slice(&[0.5, 0.1, sa[0], sa[1]]);
        q[8..12].copy_from_slice(&[0.5, 0.1, sb[0], sb[1]]);
        assert!(res(&q).iter().all(|r| r.abs() < 1e-15), "{:?}", res(&q));
        // b turned by a further 1e-3 rad: the slope rows read R(Δθ) r'_a − r'_b ≈ 1e-3 in size
        let psi: f64 = phi + std::f64::consts::FRAC_PI_2 + 1e-3;
        q[10..12].copy_from_slice(&[psi.cos(), psi.sin()]);
        let r = res(&q);
        assert!(((r[2] * r[2] + r[3] * r[3]).sqrt() - 1e-3).abs() < 1e-9, "{r:?}");
        assert!(j.couples_bodies());
    }
}
