//! The checks of `[[springs]]`: nodes that exist, a second end that is a node or a ground
//! point (a node for a torsional spring), stiffness and damping finite and non-negative,
//! and a free length that gives the spring a direction; a stiffness that is a parameter
//! (`{ value, parameter }`) is checked as `value_parameters` says. A checked spring becomes
//! a load
//! ([`Load::Spring`], [`Load::TorsionalSpring`]) with its free length or relaxed angle
//! resolved from the initial configuration.

use super::value_parameters::ValueKind;
use crate::error::Result;
use crate::model::schema::{SpringEndSpec, SpringKind, SpringSpec};
use crate::model::Model;
use crate::physics::loads::{Load, Spring, SpringEnd, TorsionalSpring};
use crate::physics::system::NodeId;
use crate::solver::parameters::Scaling;

/// Below this distance, relative to the longest body, two points coincide.
const COINCIDENT: f64 = 1e-12;

impl Model {
    pub(super) fn check_springs(&mut self, springs: &[SpringSpec]) -> Result<()> {
        for (i, s) in springs.iter().enumerate() {
            let p = |k: &str| format!("springs[{i}].{k}");
            if let Some(name) = &s.name {
                if name.trim().is_empty() || name.chars().any(char::is_control) {
                    return Err(self.err(p("name"), "must be non-empty and hold no control character"));
                }
            }
            for (key, v) in [("stiffness", s.stiffness.value()), ("damping", s.damping)] {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(self.err(p(key), format!("must be finite and non-negative, got {v}")));
                }
            }
            let scaled = self.stiffness_scaling(i, s)?;
            let a = self.node_id(&p("a.body"), &p("a.node"), &s.a.body, &s.a.node)?;
            let b = self.spring_end(&p("b"), &s.b)?;
            if b == SpringEnd::Node(a) {
                return Err(
                    self.err(p("b"), "is the same node as `a`: a spring joins two nodes, or a node and a point")
                );
            }
            let load = match s.r#type.unwrap_or(SpringKind::Translational) {
                SpringKind::Translational => Load::Spring(self.translational(i, s, (a, b), scaled)?),
                SpringKind::Torsional => Load::TorsionalSpring(self.torsional(i, s, (a, b), scaled)?),
            };
            self.loads.push(load);
        }
        Ok(())
    }

    /// What scales spring `i`'s stiffness: fixed, or the parameter its `stiffness = { value,
    /// parameter }` names (`value_parameters`).
    fn stiffness_scaling(&self, i: usize, s: &SpringSpec) -> Result<Scaling> {
        let field = format!("springs[{i}].stiffness");
        Ok(match self.value_parameter(&field, &s.stiffness, ValueKind::SpringStiffness)? {
            Some((name, file)) => Scaling::Property { name, file },
            None => Scaling::Fixed,
        })
    }

    /// `{ body, node }` or `{ point = [x, y] }`.
    fn spring_end(&self, field: &str, end: &SpringEndSpec) -> Result<SpringEnd> {
        match (&end.body, &end.node, end.point) {
            (Some(body), Some(node), None) => {
                Ok(SpringEnd::Node(self.node_id(&format!("{field}.body"), &format!("{field}.node"), body, node)?))
            }
            (None, None, Some(point)) => {
                self.finite2(&format!("{field}.point"), point)?;
                Ok(SpringEnd::Point(point))
            }
            _ => Err(self.err(field, "give either `{ body = \"…\", node = … }` or `{ point = [x, y] }`")),
        }
    }

    /// The undeformed position `(x, y)` and slope `(x', y')` of a node.
    fn node_at(&self, (b, k): NodeId) -> [f64; 4] {
        self.bodies[b].undeformed_node(k)
    }

    /// A translational spring: its free length `length`, or the initial distance; a spring
    /// whose ends start at one point needs a positive free length (its direction comes from
    /// the stretch).
    fn translational(&self, i: usize, s: &SpringSpec, (a, b): (NodeId, SpringEnd), scaled: Scaling) -> Result<Spring> {
        let p = |k: &str| format!("springs[{i}].{k}");
        let ra = self.node_at(a);
        let rb = match b {
            SpringEnd::Node(b) => {
                let r = self.node_at(b);
                [r[0], r[1]]
            }
            SpringEnd::Point(x) => x,
        };
        let distance = (ra[0] - rb[0]).hypot(ra[1] - rb[1]);
        let lmax = self.bodies.iter().map(|b| b.length).fold(0.0, f64::max);
        let coincident = distance <= COINCIDENT * lmax;
        let length = match s.length {
            Some(l) => {
                if !(l.is_finite() && l >= 0.0) {
                    return Err(self.err(p("length"), format!("must be finite and non-negative, got {l}")));
                }
                if coincident && l == 0.0 {
                    return Err(self.err(p("length"), "is 0 and the ends start at one point: the spring has no direction; give a positive free length"));
                }
                l
            }
            None if coincident => {
                return Err(self.err(p("b"), format!("starts at the same point as `a` ({:?}): the spring has no direction; give a positive free length `length`", [ra[0], ra[1]])));
            }
            None => distance,
        };
        Ok(Spring { a, b, stiffness: s.stiffness.value(), damping: s.damping, length, scaled })
    }

    /// A torsional spring between two nodes' slopes, relaxed at their initial angle.
    fn torsional(
        &self,
        i: usize,
        s: &SpringSpec,
        (a, b): (NodeId, SpringEnd),
        scaled: Scaling,
    ) -> Result<TorsionalSpring> {
        let p = |k: &str| format!("springs[{i}].{k}");
        let SpringEnd::Node(b) = b else {
            return Err(self.err(p("b"), "is a point: a torsional spring joins two nodes' slopes; give `b = { body = \"…\", node = … }` (to hold a slope against the ground, clamp a short stub body and join it)"));
        };
        if s.length.is_some() {
            return Err(self.err(
                p("length"),
                "is a translational spring's free length; a torsional spring is relaxed at its nodes' initial angle",
            ));
        }
        let (sa, sb) = (self.node_at(a), self.node_at(b));
        // φ₀ as the spring computes φ, so that it starts at exactly 0
        let angle = (sa[2] * sb[3] - sa[3] * sb[2]).atan2(sa[2] * sb[2] + sa[3] * sb[3]);
        Ok(TorsionalSpring { a, b, stiffness: s.stiffness.value(), damping: s.damping, angle, scaled })
    }
}
