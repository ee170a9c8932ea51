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
    /// [`Self::multipliers`] at every instant of a run: `q` by instant (n_t × r), `own` the
    /// model's own multipliers (columns: instants).
    fn multipliers_along(
        &self,
        q: ndarray::ArrayView2<f64>,
        own: ndarray::ArrayView2<f64>,
    ) -> Option<ndarray::Array2<f64>>;
    /// Moves the physical multipliers `lambda` (n_c × n_t) along the reduced trajectory
    /// `[q, q̇, q̈]` by instant (n_t × r each, at the times `t`) to the nearest that hold every body's balance
    /// of momentum, where the joint reactions are read without the stiff elastic forces
    /// beside the joints.
    fn balance(
        &self,
        mu: &crate::solver::model::Parameters,
        t: &[f64],
        states: [ndarray::ArrayView2<f64>; 3],
        lambda: ndarray::ArrayViewMut2<f64>,
    );
}
