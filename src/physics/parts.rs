//! What a planar flexible multibody system is made of: beams, loads, probes, damping and
//! the scalar constraints the joints become (the joints themselves: [`super::joints`]).

use super::element::Section;
use super::time_function::TimeFunction;
use crate::solver::parameters::Scaling;

/// A straight beam in its undeformed configuration.
#[derive(Clone, Debug)]
pub struct BeamBody {
    pub name: String,
    pub start: [f64; 2],
    /// angle of the beam axis to +x, rad
    pub angle: f64,
    pub length: f64,
    pub n_elements: usize,
    /// the section at the model file's values
    pub section: Section,
    /// the parameter that sets the body's Young's modulus, if any: at μ the modulus is
    /// `μ[name]` (the file's `section.youngs_modulus` where μ does not set it)
    pub youngs_modulus_parameter: Option<String>,
    /// the parameter that sets the body's density, if any: at μ the density is `μ[name]`
    /// (the file's `section.density` where μ does not set it); mass and weight scale with it
    pub density_parameter: Option<String>,
    /// the initial velocity of the body's start, m/s
    pub velocity: [f64; 2],
    /// the initial angular velocity about the body's start, rad/s
    pub angular_velocity: f64,
}

impl BeamBody {
    /// The initial rigid-body velocity at a node of position `r` and slope `r'` (SPEC §6):
    /// `ṙ = v₀ + ω × (r − r_start)`, `ṙ' = ω × r'`, with `ω × a = (−ω a_y, ω a_x)`.
    pub fn rigid_velocity(&self, node: [f64; 4]) -> [f64; 4] {
        let w = self.angular_velocity;
        let (dx, dy) = (node[0] - self.start[0], node[1] - self.start[1]);
        [self.velocity[0] - w * dy, self.velocity[1] + w * dx, -w * node[3], w * node[2]]
    }

    /// Position and slope `(x, y, x', y')` of node `k` in the straight, undeformed body.
    pub fn undeformed_node(&self, k: usize) -> [f64; 4] {
        let (c, s) = (self.angle.cos(), self.angle.sin());
        let d = k as f64 * self.length / self.n_elements as f64;
        [self.start[0] + d * c, self.start[1] + d * s, c, s]
    }
}

/// A node is addressed by body index and node index within the body (0..=n_elements).
pub type NodeId = (usize, usize);

#[derive(Clone, Debug)]
pub enum Load {
    /// body force `ρA g` on every element
    Gravity { g: [f64; 2], scaled: Scaling },
    /// moment `M(t)` at a node, acting on its slope
    Moment { node: NodeId, function: TimeFunction, scaled: Scaling },
    /// force `F f(t)` at a node (f = 1 without a function)
    Force { node: NodeId, value: [f64; 2], function: Option<TimeFunction>, scaled: Scaling },
}

/// A material point whose position is recorded: element index and `ξ` in [0, 1]; with
/// `strain` and `curvature` also those of the centre line there ([`super::section`]).
#[derive(Clone, Debug)]
pub struct Probe {
    pub name: String,
    pub element: usize,
    pub xi: f64,
    pub strain: bool,
    pub curvature: bool,
}

/// Rayleigh damping `C = a M + b K_t` on the constant parts of the element matrices.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rayleigh {
    pub mass: f64,
    pub stiffness: f64,
}

/// One scalar constraint `Σ coef · q[dof] = rhs`.
#[derive(Clone, Debug)]
pub struct Constraint {
    pub terms: Vec<(usize, f64)>,
    pub rhs: f64,
}
