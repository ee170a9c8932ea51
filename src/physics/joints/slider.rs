//! A node sliding on a ground line: the line through the node's initial position `r₀`
//! along `direction` `d`, held by one row on its unit normal `n = (−d_y, d_x)/|d|`,
//!
//! ```text
//!     n · r_node − n · r₀ = 0,
//! ```
//!
//! linear and constant. With `lock_rotation` (a prismatic joint) the node's slope keeps its
//! initial direction `e = (cos θ₀, sin θ₀)` as well: `e⊥ · r'_node = 0`, `e⊥ = (−sin θ₀,
//! cos θ₀)` — a condition on the slope's direction only, so the node may still stretch.

use super::row::{JointKind, NodeIndex, Row, RowKind};
use crate::physics::parts::NodeId;

#[derive(Clone, Debug, PartialEq)]
pub struct Slider {
    pub node: NodeId,
    /// a point of the line, m (the node's initial position)
    pub point: [f64; 2],
    /// the line's direction; any nonzero length
    pub direction: [f64; 2],
    /// the node's initial unit slope, kept in direction when `Some` (a prismatic joint)
    pub locked_slope: Option<[f64; 2]>,
}

impl Slider {
    /// The line's unit normal `n`.
    pub fn normal(&self) -> [f64; 2] {
        let [dx, dy] = self.direction;
        let len = dx.hypot(dy);
        [-dy / len, dx / len]
    }
}

impl JointKind for Slider {
    fn type_name(&self) -> &'static str {
        "slider"
    }

    fn nodes(&self) -> Vec<NodeId> {
        vec![self.node]
    }

    fn rows(&self, first: NodeIndex) -> Vec<Row> {
        let d = first(self.node);
        let n = self.normal();
        let mut rows = vec![Row {
            terms: vec![(d, n[0]), (d + 1, n[1])],
            rhs: n[0] * self.point[0] + n[1] * self.point[1],
            component: "normal",
            kind: RowKind::Position,
            motion: None,
        }];
        if let Some([c, s]) = self.locked_slope {
            rows.push(Row {
                terms: vec![(d + 2, -s), (d + 3, c)],
                rhs: 0.0,
                component: "angle",
                kind: RowKind::Slope,
                motion: None,
            });
        }
        rows
    }

    fn couples_bodies(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn residual(rows: &[Row], q: &[f64]) -> Vec<f64> {
        rows.iter().map(|r| r.terms.iter().map(|&(d, k)| k * q[d]).sum::<f64>() - r.rhs).collect()
    }

    /// On a line at 30° through (1, 2): moving along it keeps the row at zero, moving across
    /// it by δ gives the residual δ (the normal has unit length).
    #[test]
    fn the_node_moves_along_the_line_only() {
        let th = 30f64.to_radians();
        let j =
            Slider { node: (0, 0), point: [1.0, 2.0], direction: [2.0 * th.cos(), 2.0 * th.sin()], locked_slope: None };
        let rows = j.rows(&|_| 0);
        assert_eq!(rows.len(), 1);
        let along = [1.0 + 0.7 * th.cos(), 2.0 + 0.7 * th.sin(), 1.0, 0.0];
        assert!(residual(&rows, &along)[0].abs() < 1e-15);
        let across = [1.0 - 0.2 * th.sin(), 2.0 + 0.2 * th.cos(), 1.0, 0.0];
        assert!((residual(&rows, &across)[0] - 0.2).abs() < 1e-15);
    }

    /// Locked: a slope stretched along its initial direction satisfies the angle row, a
    /// slope turned by a small angle φ gives the residual |r'| sin φ.
    #[test]
    fn a_locked_slope_keeps_its_direction_and_may_stretch() {
        let (c, s) = (0.6, 0.8);
        let j = Slider { node: (0, 0), point: [0.0; 2], direction: [1.0, 0.0], locked_slope: Some([c, s]) };
        let rows = j.rows(&|_| 0);
        assert_eq!((rows[1].component, rows[1].kind), ("angle", RowKind::Slope));
        assert!(residual(&rows, &[0.5, 0.0, 1.01 * c, 1.01 * s])[1].abs() < 1e-15);
        let phi: f64 = 1e-3;
        let turned = [c * phi.cos() - s * phi.sin(), s * phi.cos() + c * phi.sin()];
        assert!((residual(&rows, &[0.0, 0.0, turned[0], turned[1]])[1] - phi.sin()).abs() < 1e-15);
    }
}
