//! flexrom: planar flexible multibody dynamics with ANCF beams (SPEC §1–2) and the
//! model files, simulation and result files built on it.
//!
//! Layout follows the flow of data:
//! `model` (files) → `physics` (element, system) → `solver` (integrator, linear solvers)
//! → `simulate` (full runs) → `io` (HDF5).

// `!(x > 0.0)` is how the input checks say "positive, and not NaN": the negated comparison is
// the point, so clippy's preference for `partial_cmp` is off; index loops in the numeric
// kernels follow the equations' indices (several arrays indexed alike)
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

pub mod analysis;
pub mod cost;
pub mod error;
pub mod interrupt;
pub mod io;
pub mod limits;
pub mod linalg;
pub mod model;
pub mod output;
pub mod physics;
pub mod pipeline;
pub mod records;
pub mod reduction;
pub mod report;
pub mod rom;
pub mod simulate;
pub mod solver;
pub mod training;
pub mod workflows;

pub use error::{Error, Result};

extern "C" {
    fn openblas_set_num_threads(n: std::os::raw::c_int);
    fn blas_thread_shutdown_() -> std::os::raw::c_int;
}

/// Keeps OpenBLAS on one thread: the dense reference solver then measures one core, like
/// everything else, and parallel sweeps do not oversubscribe the machine.
///
/// In the `flexrom` binary OpenBLAS has usually started no worker at all (its
/// `BLAS_ONE_THREAD_AT_START` sets `OPENBLAS_NUM_THREADS=1` before OpenBLAS's constructor
/// runs). When the user's `OPENBLAS_NUM_THREADS` asked for more, or in another program
/// linking this library, the constructor has started them before `main`;
/// setting the count to 1 only stops handing them work, and each keeps polling its queue with
/// `sched_yield` (about a third of a pendulum run's CPU time). `blas_thread_shutdown_` joins
/// them; with one thread no call starts them again (OpenBLAS's `exec_blas` is reached only
/// for more than one thread).
pub fn single_threaded_blas() {
    // SAFETY: plain calls into OpenBLAS's thread server, which is idle here (nothing has
    // called BLAS yet, and with one thread nothing will hand work to a worker afterwards).
    unsafe {
        openblas_set_num_threads(1);
        blas_thread_shutdown_();
    }
}
