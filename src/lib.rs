//! flexrom: planar flexible multibody dynamics with ANCF beams (SPEC §1–2) and the
//! model files, simulation and result files built on it.
//!
//! Layout follows the flow of data:
//! `model` (files) → `physics` (element, system) → `solver` (integrator, linear solvers)
//! → `simulate` (full runs) → `io` (HDF5).

pub mod error;
pub mod io;
pub mod model;
pub mod physics;
pub mod simulate;
pub mod solver;

pub use error::{Error, Result};
