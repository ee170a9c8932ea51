//! What every joint kind builds and answers: its rows ([`Row`], [`RowKind`]) and the
//! [`JointKind`] trait; the kinds' files import it, [`super`] re-exports it.

use crate::physics::parts::NodeId;

/// What a constraint row holds fixed, which sets the units of its residual and multiplier.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowKind {
    /// a position coordinate: residual in m, multiplier a force in N
    Position,
    /// a slope coordinate (dimensionless): multiplier a moment-like force in N m
    Slope,
}

impl RowKind {
    /// Unit of the row's residual.
    pub fn residual_unit(self) -> &'static str {
        match self {
            RowKind::Position => "m",
            RowKind::Slope => "1",
        }
    }

    /// Unit of the row's Lagrange multiplier (the generalized force the joint transmits).
    pub fn multiplier_unit(self) -> &'static str {
        match self {
            RowKind::Position => "N",
            RowKind::Slope => "N m",
        }
    }
}

/// One scalar constraint `Σ coef · q[dof] = rhs` as a joint builds it.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub terms: Vec<(usize, f64)>,
    pub rhs: f64,
    /// what the row holds: a coordinate (`x`, `y`, `x'`, `y'`), or `normal` and `angle`
    /// (a slider's distance from its line and its slope's turn)
    pub component: &'static str,
    pub kind: RowKind,
}

/// The global coordinate index of a node's first coordinate: `4 · node` (SPEC §1 numbering).
pub type NodeIndex<'a> = &'a dyn Fn(NodeId) -> usize;

/// Names of the four coordinates of a node, in their order.
pub const COORDINATES: [&str; 4] = ["x", "y", "x'", "y'"];

/// Row `c` (0..4) of a node held at `value`: one unit coefficient on the coordinate.
pub(super) fn fixed_coordinate(first: usize, c: usize, value: f64) -> Row {
    let kind = if c < 2 { RowKind::Position } else { RowKind::Slope };
    Row { terms: vec![(first + c, 1.0)], rhs: value, component: COORDINATES[c], kind }
}

/// A kind of joint: its rows and what the rest of the program asks of it.
pub trait JointKind {
    /// The model file's `type` of this kind (`ground_pin`).
    fn type_name(&self) -> &'static str;
    /// The nodes it acts on, in the order its description names them.
    fn nodes(&self) -> Vec<NodeId>;
    /// Its constraint rows; `first` gives a node's first global coordinate.
    fn rows(&self, first: NodeIndex) -> Vec<Row>;
    /// Whether it joins two bodies (a reduction then keeps multipliers of its own).
    fn couples_bodies(&self) -> bool;
}
