//! Loads, one file per kind: gravity (a body force, assembled once into the constant forces),
//! moments and forces at nodes. A load that acts on a few coordinates is lowered to a
//! [`NodalLoad`]: its generalized force `−Q_ext` and, where it depends on the coordinates,
//! its Jacobian, over any set of global coordinates, times its amplitude factor (the load
//! scale or a named parameter, [`Scaling`]): every load is affine in that factor.
//!
//! Adding a kind: a file here (the load and its [`NodalLoad`]), a variant of [`Load`], its
//! entry in the model file's schema and checks.

mod force;
mod gravity;
mod moment;

pub use force::{Force, NodalForce};
pub use gravity::{assemble as assemble_weight, DensityWeight, Gravity, Weight, WeightParts};
pub use moment::{moment_force, moment_jacobian, Moment, NodalMoment};

pub use super::joints::NodeIndex;
pub use crate::solver::parameters::Scaling;

/// A load of a model, one variant per kind.
#[derive(Clone, Debug, PartialEq)]
pub enum Load {
    Gravity(Gravity),
    Moment(Moment),
    Force(Force),
}

impl Load {
    /// What multiplies the load: fixed, the load scale or a named parameter.
    pub fn scaling(&self) -> &Scaling {
        match self {
            Load::Gravity(l) => &l.scaled,
            Load::Moment(l) => &l.scaled,
            Load::Force(l) => &l.scaled,
        }
    }

    /// The load on global coordinates; `None` for gravity, which acts on every element and
    /// is assembled into the constant forces ([`assemble_weight`]).
    pub fn lower(&self, first: NodeIndex) -> Option<Box<dyn NodalLoad>> {
        match self {
            Load::Gravity(_) => None,
            Load::Moment(m) => Some(Box::new(m.lower(first))),
            Load::Force(f) => Some(Box::new(f.lower(first))),
        }
    }
}

/// A load on a few global coordinates, at amplitude factor `factor` and time `t`, in the
/// sign of the model's force `g = … − Q_ext`. `q` reads a coordinate (only those of
/// [`NodalLoad::dofs`] are read).
pub trait NodalLoad: std::fmt::Debug + Send + Sync {
    /// The coordinates it acts on and depends on.
    fn dofs(&self) -> &[usize];
    fn scaling(&self) -> &Scaling;
    /// Calls `add(dof, value)` with its contributions `−Q_ext` to `g`.
    fn add_force(&self, factor: f64, t: f64, q: &dyn Fn(usize) -> f64, add: &mut dyn FnMut(usize, f64));
    /// Whether `−Q_ext` depends on the coordinates ([`Self::add_stiffness`] adds something).
    fn has_stiffness(&self) -> bool {
        false
    }
    /// Calls `add(row dof, column dof, value)` with the entries of `∂(−Q_ext)/∂q`.
    fn add_stiffness(&self, _factor: f64, _t: f64, _q: &dyn Fn(usize) -> f64, _add: &mut dyn FnMut(usize, usize, f64)) {
    }
}
