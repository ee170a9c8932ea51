//! The reference error estimator (`estimate = "enriched"`, docs/error-estimate.md): the
//! enriched model `V⁺` integrated on its own, to convergence at every step, as any reduced
//! model runs (about two reduced runs' cost). The others approximate its trajectory more
//! cheaply; it is also what runs where they are not available (whole-system bases, models
//! without the invariant-based reduced model).

use super::norms::NormProjection;
use super::{ErrorEstimator, Estimator, QuantityRaw, Raw};
use crate::error::Result;
use crate::model::Model;
use crate::reduction::Basis;
use crate::rom::pool::Pool;
use crate::rom::reactions::ReactionReader;
use crate::rom::run::{Output, ReducedRun, ReducedRunner};
use std::sync::Arc;

/// The `enriched` method: η_raw against the enriched model's own run, times the calibrated `c`.
pub struct Enriched {
    basis: Arc<Basis>,
    data: Arc<Estimator>,
    runners: Pool<'static, ReducedRunner>,
    /// the initial configuration X₀ of the displacement measure
    x0: Arc<Vec<f64>>,
    /// the norms' projections of the basis pair, made once
    norms: NormProjection,
    /// the model's length scale `L` (the displacement measure's resolution is `tol · L`)
    length: f64,
    /// the model's reaction points
    reactions: ReactionReader,
}

impl Enriched {
    /// With one runner built now (as [`super::corrected::Corrected::new`]).
    pub fn new(model: &Arc<Model>, basis: &Arc<Basis>, data: &Arc<Estimator>) -> Result<Self> {
        let enriched = Arc::new(data.enriched.clone());
        let (m, e) = (Arc::clone(model), Arc::clone(&enriched));
        let runners = Pool::new(move || ReducedRunner::new(&m, &e));
        runners.put(ReducedRunner::new(model, &enriched)?);
        let physics = model.physics()?;
        let x0 = Arc::clone(&physics.x0);
        let length = physics.length_scale();
        let norms = NormProjection::new(basis, &data.enriched, ndarray::ArrayView1::from(&x0[..]));
        let reactions = ReactionReader::new(model);
        Ok(Enriched { basis: Arc::clone(basis), data: Arc::clone(data), runners, x0, norms, length, reactions })
    }
}

impl ErrorEstimator for Enriched {
    fn name(&self) -> &'static str {
        "enriched"
    }
    fn data(&self) -> &Estimator {
        &self.data
    }
    fn reactions(&self) -> Option<&crate::rom::reactions::ReactionReader> {
        Some(&self.reactions)
    }
    fn raw(&self, run: &ReducedRun) -> Result<Raw> {
        let mu = run.result.settings.parameters();
        let e = self.runners.with(|r| r.solve(mu, Output::ReducedAndProbes, &[]))??;
        let x0 = ndarray::ArrayView1::from(&self.x0[..]);
        let res = super::norms::resolution(run, self.length);
        let norms = self.norms.raw_by_time(&self.basis, &self.data.enriched, &run.reduced_q, &e.reduced_q, x0, res);
        let reference = crate::rom::quantities::readings(&e.result);
        let tol = run.result.settings.params.tolerance;
        let mut quantities = QuantityRaw::between(&run.result, &reference, tol, self.length);
        let t = e.result.t.as_slice().unwrap_or(&[]);
        let enriched = self.reactions.of_trajectory(
            (mu, t),
            (&self.data.enriched, e.reduced_q.view()),
            None,
            e.result.multipliers.view(),
        );
        let own = super::run_reactions(&self.reactions, &self.basis, run);
        quantities.extend(QuantityRaw::between_reactions(&self.reactions, own, enriched, tol));
        Ok(Raw { norms, quantities })
    }
}
