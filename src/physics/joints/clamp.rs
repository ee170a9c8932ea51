//! A node clamped to the ground: `r_node − point = 0` and `r'_node − slope = 0`, four rows
//! (x, y, x', y'). Holding the whole slope vector, not only its direction, also fixes the
//! axial stretch at the node: the rows stay linear and constant in ANCF coordinates (SPEC §2).

use super::row::{fixed_coordinate, JointKind, NodeIndex, Row};
use crate::physics::parts::NodeId;

#[derive(Clone, Debug, PartialEq)]
pub struct Clamp {
    pub node: NodeId,
    /// where the node is held, m
    pub point: [f64; 2],
    /// the slope it keeps (the body's initial unit tangent)
    pub slope: [f64; 2],
}

impl JointKind for Clamp {
    fn type_name(&self) -> &'static str {
        "clamp"
    }

    fn nodes(&self) -> Vec<NodeId> {
        vec![self.node]
    }

    fn rows(&self, first: NodeIndex) -> Vec<Row> {
        let d = first(self.node);
        let value = [self.point[0], self.point[1], self.slope[0], self.slope[1]];
        (0..4).map(|c| fixed_coordinate(d, c, value[c])).collect()
    }

    fn couples_bodies(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::joints::row::RowKind;

    #[test]
    fn holds_position_and_slope() {
        let j = Clamp { node: (0, 0), point: [1.0, 2.0], slope: [0.6, 0.8] };
        let rows = j.rows(&|_| 8);
        let got: Vec<_> = rows.iter().map(|r| (r.terms[0], r.rhs, r.kind)).collect();
        assert_eq!(
            got,
            [
                ((8, 1.0), 1.0, RowKind::Position),
                ((9, 1.0), 2.0, RowKind::Position),
                ((10, 1.0), 0.6, RowKind::Slope),
                ((11, 1.0), 0.8, RowKind::Slope),
            ]
        );
    }
}
