//! Point masses at nodes: a payload, a slider's block, a hub. A mass `m` at a node adds
//! `m I₂` to the mass matrix on the node's position coordinates (its kinetic energy
//! `½ m |ṙ|²`), and, under gravity, its weight `m g` there (SPEC §6).

use super::joints::NodeIndex;
use super::parts::NodeId;

/// A point mass, as the model file gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct PointMass {
    pub node: NodeId,
    /// kg
    pub mass: f64,
}

impl PointMass {
    /// The node's position coordinates `(x, y)` and the mass.
    pub fn lower(&self, first: NodeIndex) -> ([usize; 2], f64) {
        let d = first(self.node);
        ([d, d + 1], self.mass)
    }
}
