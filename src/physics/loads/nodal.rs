//! The form a load on a few coordinates is lowered to; the kinds' files import it,
//! [`super`] re-exports it.

pub use crate::physics::joints::NodeIndex;
pub use crate::solver::parameters::Scaling;

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
