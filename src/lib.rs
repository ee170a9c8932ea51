//! flexrom: planar flexible multibody dynamics with ANCF beams (SPEC §1–2) and the
//! model files, simulation and result files built on it.
//!
//! Layout follows the flow of data:
//! `model` (files) → `physics` (element, system) → `solver` (integrator, linear solvers)
//! → `simulate` (full runs) → `io` (HDF5).

pub mod error;
pub mod io;
pub mod limits;
pub mod model;
pub mod output;
pub mod physics;
pub mod pipeline;
pub mod reduction;
pub mod simulate;
pub mod solver;

pub use error::{Error, Result};

extern "C" {
    fn openblas_set_num_threads(n: std::os::raw::c_int);
}

/// Keeps OpenBLAS on one thread: the dense reference solver then measures one core, like
/// everything else, and parallel sweeps do not oversubscribe the machine.
pub fn single_threaded_blas() {
    // SAFETY: plain setter of OpenBLAS's global thread count, linked through ndarray-linalg.
    unsafe { openblas_set_num_threads(1) }
}
