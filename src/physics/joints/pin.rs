//! Two bodies' nodes pinned together: `r_a − r_b = 0`, two rows (x, y); both slopes stay
//! free, so the bodies turn relative to each other.

use super::row::{JointKind, NodeIndex, Row, RowKind, COORDINATES};
use crate::physics::parts::NodeId;

#[derive(Clone, Debug, PartialEq)]
pub struct Pin {
    pub a: NodeId,
    pub b: NodeId,
}

impl JointKind for Pin {
    fn type_name(&self) -> &'static str {
        "pin"
    }

    fn nodes(&self) -> Vec<NodeId> {
        vec![self.a, self.b]
    }

    fn rows(&self, first: NodeIndex) -> Vec<Row> {
        let (a, b) = (first(self.a), first(self.b));
        (0..2)
            .map(|c| Row {
                terms: vec![(a + c, 1.0), (b + c, -1.0)],
                rhs: 0.0,
                component: COORDINATES[c],
                kind: RowKind::Position,
                motion: None,
            })
            .collect()
    }

    fn couples_bodies(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_two_nodes_share_their_position() {
        let j = Pin { a: (0, 1), b: (1, 0) };
        let first = |(b, k): NodeId| 4 * (2 * b + k);
        let rows = j.rows(&first);
        // q = node a at (0.3, 0.4), node b at the same point: both rows vanish
        let mut q = [0.0; 16];
        q[4..6].copy_from_slice(&[0.3, 0.4]);
        q[8..10].copy_from_slice(&[0.3, 0.4]);
        for r in &rows {
            let res: f64 = r.terms.iter().map(|&(d, k)| k * q[d]).sum::<f64>() - r.rhs;
            assert_eq!(res, 0.0, "{}", r.component);
        }
        assert!(j.couples_bodies());
    }
}
