//! Analyses around a run that are not a time integration: static equilibrium by load
//! stepping ([`statics`]), natural frequencies and mode shapes ([`modes`]) and those a reduced basis keeps ([`reduced_modes`]), the energies of
//! a state ([`energy`]), the joints' reaction forces and moments ([`reactions`]), whether a time step resolves the model ([`resolution`]). They work on the assembled [`crate::physics::system::FlexibleSystem`]
//! through its public accessors and the solver's traits, with their own KKT factorizations
//! ([`assembly`]) where the matrix is not the integrator's.
pub mod assembly;
pub mod energy;
pub mod free_motion;
pub mod modes;
pub mod ramp;
pub mod reactions;
pub mod reduced_modes;
pub mod resolution;
pub mod statics;
