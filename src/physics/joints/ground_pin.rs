//! A node pinned to the ground: `r_node − point = 0`, two rows (x, y). The node's slope stays
//! free, so the body turns about the point.

use super::row::{fixed_coordinate, JointKind, NodeIndex, Row};
use crate::physics::parts::NodeId;

#[derive(Clone, Debug, PartialEq)]
pub struct GroundPin {
    pub node: NodeId,
    /// where the node is held, m
    pub point: [f64; 2],
}

impl JointKind for GroundPin {
    fn type_name(&self) -> &'static str {
        "ground_pin"
    }

    fn nodes(&self) -> Vec<NodeId> {
        vec![self.node]
    }

    fn rows(&self, first: NodeIndex) -> Vec<Row> {
        let d = first(self.node);
        (0..2).map(|c| fixed_coordinate(d, c, self.point[c])).collect()
    }

    fn couples_bodies(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_the_node_at_its_point() {
        let j = GroundPin { node: (0, 3), point: [0.25, -1.0] };
        let rows = j.rows(&|(_, k)| 4 * k);
        // node 3 owns coordinates 12..16: x = 0.25 and y = −1
        assert_eq!(
            rows.iter().map(|r| (r.terms.clone(), r.rhs)).collect::<Vec<_>>(),
            [(vec![(12, 1.0)], 0.25), (vec![(13, 1.0)], -1.0)]
        );
    }
}
