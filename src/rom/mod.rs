//! The reduced model as one object ([`Rom`]), pyMOR's reduced model: a basis, the model's
//! shared physics, the time grid and the error estimator, owned, so that it can be kept,
//! shared between threads and handed to another language. Every command that runs a
//! reduced model (`online`, `sweep`, `validate`, greedy training, the report) does it
//! through [`Rom::solve`] and [`Rom::estimate_error`].
//!
//! `run` holds the reduced runs themselves, `estimator` the error estimators (one
//! [`estimator::ErrorEstimator`] per method), `trust` what a run tells besides its answer
//! (extrapolation, tolerance, the result file's attributes).

pub mod estimator;
pub(crate) mod pool;
pub mod probes;
pub mod quantities;
pub mod reactions;
pub mod run;
pub mod trust;
pub mod warnings;

pub use run::{check_reduced_memory, settings_at, Output, ReducedRun, ReducedRunner};
pub use trust::Trust;

use crate::error::{Error, Result};
use crate::io::basis_file::StoredBasis;
use crate::model::Model;
use crate::reduction::Basis;
use crate::solver::model::{Parameters, ParametricModel};
use crate::solver::parameter_space::ParameterSpace;
use estimator::{ErrorEstimator, Estimate, EstimateMethod};
use pool::Pool;
use std::path::Path;
use std::sync::Arc;

/// A reduced model: run it at any parameters with [`Rom::solve`], estimate how far a run
/// may be from the full model with [`Rom::estimate_error`]. Shared by reference across
/// threads: each concurrent run gets its own work space.
pub struct Rom {
    model: Arc<Model>,
    basis: Arc<Basis>,
    estimator: Option<Arc<dyn ErrorEstimator>>,
    /// the training range and tolerance of a basis read from its file; `None` for one built
    /// in this process (training)
    trust: Option<Trust>,
    runners: Pool<'static, ReducedRunner>,
}

/// How [`Rom::load`] reads a basis file's estimator.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LoadOptions {
    /// the estimate's method (`[online] estimate`, `--estimate`); `None`: the one the basis
    /// file names
    pub method: Option<EstimateMethod>,
    /// the tolerance estimates are held to (`[online] tolerance`); `None`: greedy training's
    pub tolerance: Option<f64>,
    /// the error `tolerance` is on (`[online] tolerance_measure`); `None`: the measure the
    /// basis file records for its training tolerance
    pub tolerance_measure: Option<estimator::ErrorMeasure>,
    /// no estimate at all (`--no-estimate`)
    pub no_estimate: bool,
}

impl Rom {
    /// The reduced model of `basis` (projected now: a model it cannot be built for fails
    /// here), with an optional estimator, held to `trust` when given.
    pub fn new(
        model: &Arc<Model>,
        basis: &Arc<Basis>,
        estimator: Option<Arc<dyn ErrorEstimator>>,
        trust: Option<Trust>,
    ) -> Result<Self> {
        let (m, b) = (Arc::clone(model), Arc::clone(basis));
        let runners = Pool::new(move || ReducedRunner::new(&m, &b));
        runners.put(ReducedRunner::new(model, basis)?);
        Ok(Rom { model: Arc::clone(model), basis: Arc::clone(basis), estimator, trust, runners })
    }

    /// The plain reduced model of `basis` (no estimator, no training range): a basis built in
    /// this process.
    pub fn of(model: &Arc<Model>, basis: &Basis) -> Result<Self> {
        Rom::new(model, &Arc::new(basis.clone()), None, None)
    }

    /// The reduced model of a basis file already read and checked as `stored`
    /// (`io::basis_check`, at `path`, named in messages), with the estimator the file holds,
    /// by the method `o` asks for (else the one the file names), and its training range and
    /// tolerance. Returns the warnings a user should see (a method whose own check failed
    /// for this basis).
    pub fn load(model: &Arc<Model>, path: &Path, stored: &StoredBasis, o: LoadOptions) -> Result<(Self, Vec<String>)> {
        let mut warnings = Vec::new();
        let data = if o.no_estimate { None } else { stored.estimator.as_ref() };
        let estimator = match data {
            Some(d) => {
                let sys = &*model.physics()?.sys;
                let err =
                    |(field, problem): (String, String)| Error::input(path, format!("estimator/{field}"), problem);
                d.enriched.validate(sys.n_dof(), sys.n_constraints()).map_err(err)?;
                if let Some(h) = &d.enriched.hyper {
                    h.validate(sys.n_elements()).map_err(err)?;
                }
                let method = o.method.unwrap_or(d.default_method());
                let e = estimator::build(method, model, &stored.basis, d)?;
                if let Some(why) = e.self_check() {
                    warnings.push(format!("{}: estimate = \"{}\": {why}", path.display(), e.name()));
                }
                Some(e)
            }
            None => None,
        };
        let t = &stored.training;
        let (tolerance, measure) = match o.tolerance {
            Some(tol) => (Some(tol), o.tolerance_measure.unwrap_or(t.measure)),
            None => (t.tolerance, t.measure),
        };
        let sensitivity = t.sensitivity.as_ref().map(|s| trust::LoadSensitivity::of_stored(s, &t.space));
        let trust =
            Trust { range: t.range, tolerance, measure, skipped: o.no_estimate, sensitivity, space: t.space.clone() };
        Ok((Rom::new(model, &stored.basis, estimator, Some(trust))?, warnings))
    }

    pub fn model(&self) -> &Arc<Model> {
        &self.model
    }

    pub fn basis(&self) -> &Arc<Basis> {
        &self.basis
    }

    /// The error estimator, when the basis has one (and it was not turned off).
    pub fn estimator(&self) -> Option<&Arc<dyn ErrorEstimator>> {
        self.estimator.as_ref()
    }

    /// The estimate's method name, when there is an estimator.
    pub fn method(&self) -> Option<&'static str> {
        self.estimator.as_ref().map(|e| e.name())
    }

    /// The training range and tolerance, for a basis read from its file.
    pub fn trust(&self) -> Option<&Trust> {
        self.trust.as_ref()
    }

    /// The error the tolerance is on ([`Trust::measure`]; relative without a trust).
    pub fn tolerance_measure(&self) -> estimator::ErrorMeasure {
        self.trust.as_ref().map_or(estimator::ErrorMeasure::Relative, |t| t.measure)
    }

    /// Whether `mu` lies outside the parameters the basis was trained on (false when they
    /// are not known).
    pub fn is_extrapolated(&self, mu: &Parameters) -> bool {
        self.trust.as_ref().is_some_and(|t| trust::is_extrapolated(t.range, mu.scale()))
            || !self.named_outside(mu).is_empty()
    }

    /// The parameters of `mu` other than the load scale outside what the basis was trained
    /// on, one line each ([`ParameterSpace::outside_named_of`]: a body's property the box
    /// does not hold counts as trained at the model file's value).
    pub fn named_outside(&self, mu: &Parameters) -> Vec<String> {
        let file_value = |name: &str| self.model.property_value(name);
        match &self.trust {
            Some(t) => t.space.outside_named_of(mu, &file_value),
            None => ParameterSpace::default().outside_named_of(mu, &file_value),
        }
    }

    /// One warning naming the parameters of `mu` other than the load scale that lie
    /// outside what the basis was trained on: outside the `[parameters]` box it was trained
    /// over, or, for a parameter training did not vary, anywhere but 1 (the model file's
    /// load). Empty when there are none (the load scale's range is [`trust::check_runs`]'s).
    pub fn untrained_parameters(&self, mu: &Parameters) -> Vec<String> {
        let away = self.named_outside(mu);
        if away.is_empty() {
            return Vec::new();
        }
        vec![format!(
            "outside what the basis was trained on: {}; the reduced model extrapolates there (`validate` measures it against the full model)",
            away.join(", ")
        )]
    }

    /// How far the reduced answer moves for a 0.1 % change of the load near `mu`, as
    /// greedy training measured it at the candidates beside it ([`trust::LoadSensitivity`]);
    /// `None` for bases without that record.
    pub fn sensitivity_near(&self, mu: &Parameters) -> Option<f64> {
        self.trust.as_ref()?.sensitivity.as_ref()?.near(mu)
    }

    /// The reduced run at `mu`, reconstructed in full coordinates.
    pub fn solve(&self, mu: &Parameters) -> Result<ReducedRun> {
        self.solve_with(mu, Output::Full, &[])
    }

    /// The reduced run at `mu` with a choice of output and, in `previous`, up to two
    /// earlier runs at nearby parameters to start Newton from ([`ReducedRunner::solve`]).
    pub fn solve_with(&self, mu: &Parameters, output: Output, previous: &[&ReducedRun]) -> Result<ReducedRun> {
        self.runners.with(|r| r.solve(mu, output, previous))?
    }

    /// The estimate of how far `run` (made at `mu`) may be from the full model; `None`
    /// without an estimator. A failure of the estimator's own model reads as an infinite
    /// estimate.
    pub fn estimate_error(&self, run: &ReducedRun, mu: &Parameters) -> Option<Estimate> {
        self.estimator.as_ref().map(|e| e.estimate(run, mu))
    }

    /// [`Self::solve_with`] and [`Self::estimate_error`] together.
    pub fn solve_and_estimate(
        &self,
        mu: &Parameters,
        output: Output,
        previous: &[&ReducedRun],
    ) -> Result<(ReducedRun, Option<Estimate>)> {
        let run = self.solve_with(mu, output, previous)?;
        let e = self.estimate_error(&run, mu);
        Ok((run, e))
    }

    /// The same reduced model with another estimator (or none), sharing basis and model.
    pub fn with_estimator(&self, estimator: Option<Arc<dyn ErrorEstimator>>) -> Result<Self> {
        Rom::new(&self.model, &self.basis, estimator, self.trust.clone())
    }
}
