//! Loads, one file per kind: gravity (a body force, assembled once into the constant forces),
//! moments and forces at nodes, and the spring-dampers between nodes (translational and
//! torsional), which act on their nodes as loads that depend on the coordinates and
//! velocities and store energy. A load that acts on a few coordinates is lowered to a
//! [`NodalLoad`]: its generalized force `−Q_ext` and, where it depends on the coordinates,
//! its Jacobian, over any set of global coordinates, times its amplitude factor (the load
//! scale or a named parameter, [`Scaling`]): every load is affine in that factor.
//!
//! Adding a kind: a file here (the load and its [`NodalLoad`]), a variant of [`Load`], its
//! entry in the model file's schema and checks.

mod force;
mod gravity;
mod moment;
mod nodal;
mod spring;
mod torsional_spring;

pub use force::{Force, NodalForce};
pub use gravity::{assemble as assemble_weight, DensityWeight, Gravity, Weight, WeightParts};
pub use moment::{moment_force, moment_jacobian, Moment, NodalMoment};

pub use nodal::{NodalLoad, NodeIndex, Read, Scaling};
pub use spring::{NodalSpring, Spring, SpringEnd};
pub use torsional_spring::{NodalTorsionalSpring, TorsionalSpring};

/// A load of a model, one variant per kind.
#[derive(Clone, Debug, PartialEq)]
pub enum Load {
    Gravity(Gravity),
    Moment(Moment),
    Force(Force),
    /// a translational spring-damper (a `[[springs]]` entry)
    Spring(Spring),
    /// a torsional spring-damper (a `[[springs]]` entry of `type = "torsional"`)
    TorsionalSpring(TorsionalSpring),
}

impl Load {
    /// What multiplies the load: fixed, the load scale or a named parameter; for a spring,
    /// what scales its stiffness (fixed, or the parameter that sets it: the load scale never
    /// stretches a spring).
    pub fn scaling(&self) -> &Scaling {
        match self {
            Load::Gravity(l) => &l.scaled,
            Load::Moment(l) => &l.scaled,
            Load::Force(l) => &l.scaled,
            Load::Spring(l) => &l.scaled,
            Load::TorsionalSpring(l) => &l.scaled,
        }
    }

    /// The load on global coordinates; `None` for gravity, which acts on every element and
    /// is assembled into the constant forces ([`assemble_weight`]).
    pub fn lower(&self, first: NodeIndex) -> Option<Box<dyn NodalLoad>> {
        match self {
            Load::Gravity(_) => None,
            Load::Moment(m) => Some(Box::new(m.lower(first))),
            Load::Force(f) => Some(Box::new(f.lower(first))),
            Load::Spring(s) => Some(Box::new(s.lower(first))),
            Load::TorsionalSpring(s) => Some(Box::new(s.lower(first))),
        }
    }
}
