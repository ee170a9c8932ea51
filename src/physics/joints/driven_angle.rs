//! A motor by angle: the node's slope turns by a prescribed angle from its initial direction,
//! `θ(t) = θ₀ + s f(t)` (`θ₀` the initial slope angle, `s` the drive's factor: 1, the load
//! scale or a named parameter), held by one rheonomic row on the slope's direction (SPEC §6)
//!
//! ```text
//!     −sin θ(t) x'_node + cos θ(t) y'_node = 0,
//! ```
//!
//! linear in the coordinates with coefficients that move: `B(t) q = 0`, whose time
//! derivatives enter the velocity and acceleration levels (`Ḃ q + B q̇ = 0`,
//! `B̈ q + 2 Ḃ q̇ + B q̈ = 0`; [`super::Row::at`]). Only the slope's direction is held, so
//! the node may still stretch axially; with a ground pin at the node it is a motor by angle.
//! Its multiplier `λ` is a force on the slope coordinates along the normal `(−sin θ, cos θ)`;
//! the torque the drive applies to the body is `τ = −λ |r'|` (N m, counter-clockwise
//! positive: the constraint force `−Bᵀλ = λ (sin θ, −cos θ)` is the nodal moment
//! `τ (−sin θ, cos θ)/|r'|` of SPEC §1).

use super::row::{Drive, JointKind, Motion, NodeIndex, Row, RowKind};
use crate::physics::parts::NodeId;

#[derive(Clone, Debug, PartialEq)]
pub struct DrivenAngle {
    pub node: NodeId,
    /// the slope's initial angle θ₀, rad
    pub theta0: f64,
    pub drive: Drive,
}

impl JointKind for DrivenAngle {
    fn type_name(&self) -> &'static str {
        "driven_angle"
    }

    fn nodes(&self) -> Vec<NodeId> {
        vec![self.node]
    }

    fn rows(&self, first: NodeIndex) -> Vec<Row> {
        let d = first(self.node);
        let (s, c) = self.theta0.sin_cos();
        vec![Row {
            terms: vec![(d + 2, -s), (d + 3, c)],
            rhs: 0.0,
            component: "angle",
            kind: RowKind::Slope,
            motion: Some(Motion::Turn { theta0: self.theta0, drive: self.drive.clone() }),
        }]
    }

    fn couples_bodies(&self) -> bool {
        false
    }

    fn drive_scaling(&self) -> Option<&crate::solver::parameters::Scaling> {
        Some(&self.drive.scaled)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::time_function::TimeFunction;
    use crate::solver::parameters::Scaling;

    /// θ(t) = 0.3 + 2 (0.5 t + 0.25 t²) at t = 0.8: the slope (cos θ, sin θ) satisfies the
    /// row (residual 0 to round-off); the row's first and second time derivatives applied to
    /// a slope that turns with the drive, `Ḃ q + B q̇` and `B̈ q + 2 Ḃ q̇ + B q̈`, vanish too
    /// (the slope (cos θ, sin θ) and its derivatives in closed form).
    #[test]
    fn a_slope_turning_with_the_drive_satisfies_every_level() {
        let drive = Drive {
            function: TimeFunction::Polynomial { coefficients: vec![0.0, 0.5, 0.25] },
            scaled: Scaling::LoadScale,
        };
        let j = DrivenAngle { node: (0, 0), theta0: 0.3, drive };
        let row = &j.rows(&|_| 0)[0];
        let (s, t): (f64, f64) = (2.0, 0.8);
        let th = 0.3 + s * (0.5 * t + 0.25 * t * t);
        let (w, a) = (s * (0.5 + 0.5 * t), s * 0.5);
        let q = [th.cos(), th.sin()];
        let v = [-th.sin() * w, th.cos() * w];
        let acc = [-th.cos() * w * w - th.sin() * a, -th.sin() * w * w + th.cos() * a];
        let mut b = [[0.0; 2]; 3];
        let mut rhs = [0.0; 3];
        for k in 0..3 {
            rhs[k] = row.at(s, t, k as u32, &mut b[k]);
        }
        let dot = |x: &[f64; 2], y: &[f64; 2]| x[0] * y[0] + x[1] * y[1];
        assert!((dot(&b[0], &q) - rhs[0]).abs() < 1e-15);
        assert!((dot(&b[1], &q) + dot(&b[0], &v) - rhs[1]).abs() < 1e-14);
        assert!((dot(&b[2], &q) + 2.0 * dot(&b[1], &v) + dot(&b[0], &acc) - rhs[2]).abs() < 1e-13);
        // and a slope that lags the drive by 1e-3 rad gives the residual sin(−1e-3)
        let lag = [(th - 1e-3).cos(), (th - 1e-3).sin()];
        assert!((dot(&b[0], &lag) - (-1e-3f64).sin()).abs() < 1e-15);
    }

    /// The coefficients' time derivatives against central differences of the coefficients
    /// (step 1e-5: O(h²) truncation ≈ 1e-10, bound 1e-7).
    #[test]
    fn coefficient_rates_match_finite_differences() {
        let drive = Drive {
            function: TimeFunction::Sine { amplitude: 0.7, frequency: 1.3, phase: 0.2 },
            scaled: Scaling::Fixed,
        };
        let row = &DrivenAngle { node: (0, 1), theta0: -1.1, drive }.rows(&|_| 0)[0];
        let (t, h) = (0.37, 1e-5);
        let coefs = |t: f64, k: u32| {
            let mut b = [0.0; 2];
            row.at(1.0, t, k, &mut b);
            b
        };
        for k in 1..3 {
            let (p, m) = (coefs(t + h, k - 1), coefs(t - h, k - 1));
            let exact = coefs(t, k);
            for i in 0..2 {
                let fd = (p[i] - m[i]) / (2.0 * h);
                assert!((exact[i] - fd).abs() < 1e-7 * (1.0 + exact[i].abs()), "order {k}, {i}: {} vs {fd}", exact[i]);
            }
        }
    }
}
