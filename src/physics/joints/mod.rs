//! Joints, one file per kind. Each kind turns its nodes into scalar constraint rows
//!
//! ```text
//!     Σ_d B_cd(t) q_d = b_c(t)          (one row c; constant but for the driven kinds)
//! ```
//!
//! with a name and a unit per row, and says what a reduction needs to know (the coordinates
//! it touches, whether it couples bodies). The assembled system, the model's rank check and
//! the result files' labels all read the rows [`lower`] builds, so they cannot disagree on
//! their number, order or meaning.
//!
//! Adding a kind: a file here implementing [`JointKind`], a variant of [`Joint`], its entry in
//! the model file's schema (`model::schema::JointSpec`) and checks (`model::check`).

mod clamp;
mod driven_angle;
mod driven_point;
mod ground_pin;
mod pin;
mod row;
mod slider;
mod weld;

pub use clamp::Clamp;
pub use driven_angle::DrivenAngle;
pub use driven_point::DrivenPoint;
pub use ground_pin::GroundPin;
pub use pin::Pin;
pub use row::{Drive, JointKind, Motion, NodeIndex, Row, RowKind, COORDINATES};
pub use slider::Slider;
pub use weld::Weld;

use super::parts::NodeId;

/// A joint of a model, one variant per kind.
#[derive(Clone, Debug)]
pub enum Joint {
    GroundPin(GroundPin),
    Pin(Pin),
    Clamp(Clamp),
    Slider(Slider),
    Weld(Weld),
    DrivenAngle(DrivenAngle),
    DrivenPoint(DrivenPoint),
}

impl Joint {
    /// The kind behind the variant: the one place that matches on it.
    pub fn kind(&self) -> &dyn JointKind {
        match self {
            Joint::GroundPin(j) => j,
            Joint::Pin(j) => j,
            Joint::Clamp(j) => j,
            Joint::Slider(j) => j,
            Joint::Weld(j) => j,
            Joint::DrivenAngle(j) => j,
            Joint::DrivenPoint(j) => j,
        }
    }

    /// `ground_pin crank node 0`, `pin upper node 8 – lower node 0`: the kind and its nodes,
    /// each named by `node`.
    pub fn describe(&self, node: &dyn Fn(NodeId) -> String) -> String {
        let kind = self.kind();
        let nodes: Vec<String> = kind.nodes().into_iter().map(node).collect();
        format!("{} {}", kind.type_name(), nodes.join(" – "))
    }
}

/// The rows of `joints` in the order the system assembles them, each with the index of its
/// joint: first the rows of the joints that hold a node to the ground, then those of the
/// joints that couple bodies, each group in file order (the order of every result file's
/// multipliers since the first; `io::labels` names them in it).
pub fn lower(joints: &[Joint], first: NodeIndex) -> Vec<(usize, Row)> {
    let grounding = joints.iter().enumerate().filter(|(_, j)| !j.kind().couples_bodies());
    let coupling = joints.iter().enumerate().filter(|(_, j)| j.kind().couples_bodies());
    grounding.chain(coupling).flat_map(|(i, j)| j.kind().rows(first).into_iter().map(move |r| (i, r))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two bodies of 3 nodes each: body 1's nodes start at global node 3.
    fn first((b, k): NodeId) -> usize {
        4 * (3 * b + k)
    }

    #[test]
    fn grounding_rows_come_before_coupling_rows_in_file_order() {
        let joints = vec![
            Joint::Pin(Pin { a: (0, 2), b: (1, 0) }),
            Joint::GroundPin(GroundPin { node: (0, 0), point: [0.0, 0.5] }),
            Joint::Clamp(Clamp { node: (1, 2), point: [1.0, 0.0], slope: [0.0, 1.0] }),
        ];
        let rows = lower(&joints, &first);
        let order: Vec<(usize, &str)> = rows.iter().map(|(j, r)| (*j, r.component)).collect();
        assert_eq!(order, [(1, "x"), (1, "y"), (2, "x"), (2, "y"), (2, "x'"), (2, "y'"), (0, "x"), (0, "y")]);
        // the pin: +1 on body 0's node 2, −1 on body 1's node 0 (global node 3), rhs 0
        assert_eq!(rows[6].1.terms, vec![(8, 1.0), (12, -1.0)]);
        assert_eq!(rows[7].1.terms, vec![(9, 1.0), (13, -1.0)]);
        // the ground pin at its point, the clamp's slope rows dimensionless
        assert_eq!((rows[1].1.terms.clone(), rows[1].1.rhs), (vec![(1, 1.0)], 0.5));
        assert_eq!((rows[5].1.kind, rows[5].1.rhs), (RowKind::Slope, 1.0));
        assert_eq!(rows[5].1.kind.multiplier_unit(), "N m");
    }

    #[test]
    fn description_names_the_kind_and_its_nodes() {
        let name = |(b, k): NodeId| format!("{} node {k}", ["upper", "lower"][b]);
        let pin = Joint::Pin(Pin { a: (0, 2), b: (1, 0) });
        assert_eq!(pin.describe(&name), "pin upper node 2 – lower node 0");
        let clamp = Joint::Clamp(Clamp { node: (1, 2), point: [0.0; 2], slope: [1.0, 0.0] });
        assert_eq!(clamp.describe(&name), "clamp lower node 2");
    }
}
