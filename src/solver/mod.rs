//! Time integration and linear algebra, generic over [`model::DynamicModel`].
pub mod banded;
pub mod dense_lu;
pub mod generalized_alpha;
pub mod kkt;
pub mod model;
pub mod parameters;
pub mod statics;
pub(crate) mod vec_ops;
