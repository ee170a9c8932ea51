//! Time integration and linear algebra, generic over [`model::DynamicModel`].
pub mod generalized_alpha;
pub mod model;
pub mod parameters;
pub mod statics;

// transitional re-export (remove after merge)
pub use crate::linalg::{banded, dense_lu, kkt};
// transitional re-export (remove after merge)
#[allow(unused_imports)]
pub(crate) use crate::linalg::vec_ops;
