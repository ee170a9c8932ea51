//! The sampled element set of a hyper-reduced model (what `ecsw` trains and the basis file
//! stores under `/hyper`): a plain record, so that the basis that holds it and the training
//! that makes it both depend on it and not on each other.

/// A sampled set of elements: what the basis file stores under `/hyper`.
#[derive(Clone, Debug, PartialEq)]
pub struct Hyper {
    /// element indices, increasing
    pub elements: Vec<usize>,
    /// their positive weights
    pub weights: Vec<f64>,
    /// the relative tolerance τ the set was trained to
    pub tolerance: f64,
    /// `‖C w − b‖ / ‖b‖` reached on the training snapshots
    pub training_residual: f64,
    /// snapshots used
    pub n_training: usize,
}

impl Hyper {
    /// Every element with weight 1: plain Galerkin.
    pub fn all(n_elements: usize) -> Hyper {
        Hyper {
            elements: (0..n_elements).collect(),
            weights: vec![1.0; n_elements],
            tolerance: 0.0,
            training_residual: 0.0,
            n_training: 0,
        }
    }

    /// Checks the set against a model of `n_elements`; `Err((dataset, problem))`.
    pub fn validate(&self, n_elements: usize) -> Result<(), (String, String)> {
        let bad = |f: &str, p: String| Err((format!("hyper/{f}"), p));
        if self.elements.len() != self.weights.len() {
            return bad(
                "weights",
                format!("has {} entries but hyper/elements has {}", self.weights.len(), self.elements.len()),
            );
        }
        if self.elements.is_empty() {
            return bad("elements", "is empty: a hyper-reduced model needs at least one element".into());
        }
        if let Some(&e) = self.elements.iter().find(|&&e| e >= n_elements) {
            return bad(
                "elements",
                format!("names element {e}, but the model has {n_elements} elements (0..{})", n_elements),
            );
        }
        if self.elements.windows(2).any(|w| w[0] >= w[1]) {
            return bad("elements", "must be strictly increasing (each element once)".into());
        }
        if let Some((k, w)) = self.weights.iter().enumerate().find(|(_, w)| !(w.is_finite() && **w > 0.0)) {
            return bad("weights", format!("entry {k} is {w}; weights must be positive and finite"));
        }
        if !(self.tolerance.is_finite() && (0.0..1.0).contains(&self.tolerance)) {
            return bad("tolerance", format!("is {}; it must lie in [0, 1)", self.tolerance));
        }
        Ok(())
    }
}
