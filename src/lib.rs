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
pub mod pipeline;
pub mod reduction;
pub mod simulate;
pub mod solver;

pub use error::{Error, Result};

extern "C" {
    fn openblas_set_num_threads(n: std::os::raw::c_int);
    fn blas_thread_shutdown_() -> std::os::raw::c_int;
}

/// Keeps OpenBLAS on one thread: the dense reference solver then measures one core, like
/// everything else, and parallel sweeps do not oversubscribe the machine.
///
/// OpenBLAS (linked statically, build.rs) starts its worker threads in a constructor before
/// `main`; setting the count to 1 only stops handing them work, and each keeps polling its
/// queue with `sched_yield` (a third of a pendulum run's CPU samples). `blas_thread_shutdown_`
/// joins them; with one thread no call starts them again (OpenBLAS's `exec_blas` is reached
/// only for more than one thread).
pub fn single_threaded_blas() {
    // SAFETY: plain calls into OpenBLAS's thread server, which is idle here (nothing has
    // called BLAS yet, and with one thread nothing will hand work to a worker afterwards).
    unsafe {
        openblas_set_num_threads(1);
        blas_thread_shutdown_();
    }
}
