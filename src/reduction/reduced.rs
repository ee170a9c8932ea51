//! What the online stage needs of a reduced model besides the dynamics: the full model it
//! was projected from and the physical multipliers of its joints. Both reduced models
//! ([`super::ReducedModel`], [`super::HyperReducedModel`]) implement it through
//! `projection::impl_reduced`.

/// What the online stage needs of a reduced model besides the dynamics.
pub trait Reduced<M>: crate::solver::model::ParametricModel {
    /// The full model it was projected from.
    fn full(&self) -> &M;
    /// Physical multipliers of the full model's constraints, when the variant has them.
    fn multipliers(&self, q: &[f64], lambda: &[f64]) -> Option<ndarray::Array1<f64>>;
}
