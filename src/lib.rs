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
pub use linalg::lapack::single_threaded_blas;
