//! Point masses at nodes: a payload, a slider's block, a hub. A mass `m` at a node adds
//! `m I₂` to the mass matrix on the node's position coordinates (its kinetic energy
//! `½ m |ṙ|²`), and, under gravity, its weight `m g` there (SPEC §6).
//!
//! An optional rotary inertia `J` (kg m²) adds the kinetic energy `½ J θ̇²` of the node's
//! slope angle `θ = atan2(y', x')`. With `θ̇ = (x' ẏ' − y' ẋ')/|r'|²` this is
//! `½ J/|r'|⁴ · ṙ'ᵀ (−y', x')ᵀ(−y', x') ṙ'`; the mass matrix is constant (it is factored
//! once, and the reductions project it once), so the block is evaluated at the node's
//! undeformed slope `r'₀ = (cos α, sin α)` of the body's angle `α`, where `|r'₀| = 1`:
//! `M_J = J (−sin α, cos α)ᵀ(−sin α, cos α)` on the slope coordinates `(x', y')`. This is
//! the exact inertia while the slope turns little from its initial direction and keeps its
//! length (the axial strain is small); a crank spinning through whole turns needs a body,
//! not a rotary inertia.

use super::joints::NodeIndex;
use super::parts::NodeId;

/// A point mass, as the model file gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct PointMass {
    pub node: NodeId,
    /// kg
    pub mass: f64,
    /// kg m², about the node (0: none)
    pub rotary_inertia: f64,
    /// the parameter that sets `mass` (kg; `mass` where a run does not set it), if any; the
    /// rotary inertia stays the file's
    pub parameter: Option<String>,
}

/// One entry `(row dof, column dof, value)` of a point mass's part of the mass matrix.
pub type MassEntry = (usize, usize, f64);

/// A point mass on its position coordinates: `([x, y], kg, the parameter that sets it)`.
pub type Lumped<'a> = ([usize; 2], f64, Option<&'a str>);

impl PointMass {
    /// The node's position coordinates `(x, y)`, the mass and the parameter that sets it.
    pub fn lower(&self, first: NodeIndex) -> Lumped<'_> {
        let d = first(self.node);
        ([d, d + 1], self.mass, self.parameter.as_deref())
    }

    /// The mass-matrix entries: `m` on the two position coordinates, then, with a rotary
    /// inertia, the 2×2 slope block `J (−sin α, cos α)ᵀ(−sin α, cos α)` at the body's
    /// angle `alpha` (module docs).
    pub fn entries(&self, first: NodeIndex, alpha: f64) -> Vec<MassEntry> {
        let d = first(self.node);
        let mut out = vec![(d, d, self.mass), (d + 1, d + 1, self.mass)];
        if self.rotary_inertia != 0.0 {
            let n = [-alpha.sin(), alpha.cos()];
            for i in 0..2 {
                for j in 0..2 {
                    out.push((d + 2 + i, d + 2 + j, self.rotary_inertia * n[i] * n[j]));
                }
            }
        }
        out
    }
}
