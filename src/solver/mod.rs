//! Time integration (generalized-α, statics), generic over [`model::DynamicModel`]; the linear
//! algebra it solves with is [`crate::linalg`]'s.
pub mod generalized_alpha;
pub mod integrator_params;
pub mod model;
pub mod parameter_space;
pub mod parameters;
pub mod predictor;
pub mod statics;
