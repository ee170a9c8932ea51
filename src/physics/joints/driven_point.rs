//! A node moved along a prescribed path: its position is its initial position `p` plus
//! `s (x(t), y(t))` (`s` the drive's factor: 1, the load scale or a named parameter),
//!
//! ```text
//!     x_node = p_x + s x(t),        y_node = p_y + s y(t),
//! ```
//!
//! two rows with constant coefficients and a moving right-hand side `b(t)` (SPEC §6): a
//! support excitation, or the hub of a link carried along a path. The multipliers are the
//! forces (N) the path applies to the node.

use super::row::{Drive, JointKind, Motion, NodeIndex, Row};
use crate::physics::parts::NodeId;

#[derive(Clone, Debug, PartialEq)]
pub struct DrivenPoint {
    pub node: NodeId,
    /// the node's initial position, m
    pub point: [f64; 2],
    /// the displacements along x and y, m
    pub path: [Drive; 2],
}

impl JointKind for DrivenPoint {
    fn type_name(&self) -> &'static str {
        "driven_point"
    }

    fn nodes(&self) -> Vec<NodeId> {
        vec![self.node]
    }

    fn rows(&self, first: NodeIndex) -> Vec<Row> {
        let d = first(self.node);
        (0..2)
            .map(|c| Row {
                motion: Some(Motion::Shift(self.path[c].clone())),
                ..super::row::fixed_coordinate(d, c, self.point[c])
            })
            .collect()
    }

    fn couples_bodies(&self) -> bool {
        false
    }

    fn drive_scaling(&self) -> Option<&crate::solver::parameters::Scaling> {
        Some(&self.path[0].scaled)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::time_function::TimeFunction;
    use crate::solver::parameters::Scaling;

    /// x(t) = 0.01 sin(2π 5 t) scaled by s = 0.5, y(t) = 0: at t = 0.03 the right-hand sides
    /// are p + s x(t) and its derivatives s x'(t) = s 0.01 (10π) cos(10π t), s x''(t) =
    /// −s 0.01 (10π)² sin(10π t); the coefficients stay the unit rows (rates 0).
    #[test]
    fn the_right_hand_side_follows_the_path() {
        let sine = TimeFunction::Sine { amplitude: 0.01, frequency: 5.0, phase: 0.0 };
        let zero = TimeFunction::Constant { value: 0.0 };
        let path = [
            Drive { function: sine, scaled: Scaling::LoadScale },
            Drive { function: zero, scaled: Scaling::LoadScale },
        ];
        let rows = DrivenPoint { node: (0, 0), point: [1.0, 2.0], path }.rows(&|_| 4);
        let (s, t, w) = (0.5, 0.03, 10.0 * std::f64::consts::PI);
        let mut b = [0.0];
        let want = [1.0 + s * 0.01 * (w * t).sin(), s * 0.01 * w * (w * t).cos(), -s * 0.01 * w * w * (w * t).sin()];
        for (k, want) in want.iter().enumerate() {
            let rhs = rows[0].at(s, t, k as u32, &mut b);
            assert!((rhs - want).abs() < 1e-12 * (1.0 + want.abs()), "order {k}: {rhs} vs {want}");
            assert_eq!(b[0], if k == 0 { 1.0 } else { 0.0 });
        }
        assert_eq!((rows[1].terms.clone(), rows[1].at(s, t, 0, &mut b)), (vec![(5, 1.0)], 2.0));
    }
}
