//! The linear-algebra floor under `solver` and `reduction`: sparse and banded KKT solvers,
//! dense LU and bordered Cholesky, non-negative least squares, run-sparse matrices and the
//! vector kernels. Knows nothing of the physics, the integrator or the reduction.
pub mod banded;
pub mod banded_ldlt;
pub mod banded_order;
pub mod dense_lu;
pub(crate) mod incremental_product;
pub mod kkt;
pub mod kkt_pattern;
pub mod lapack;
pub mod nnls;
pub mod simd;
pub(crate) mod sparse_rows;
pub mod tall_qr;
pub(crate) mod vec_ops;
