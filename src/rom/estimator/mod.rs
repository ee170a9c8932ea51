//! An error estimate for every reduced run, without a full run (docs/error-estimate.md).
//!
//! Every method compares the reduced run with a second reduced model on the *enriched*
//! basis `V⁺`: the same POD with `k` more modes (per block for a block basis), its own ECSW
//! set when the basis is hyper-reduced. Both start from the same `x_ref` and solve the same
//! equations; the richer one is closer to the full model, and their distance predicts the
//! smaller one's error:
//!
//! ```text
//!     η_raw = ‖X_r − X_{r+k}‖_F / ‖X_{r+k}‖_F            (all coordinates, all instants)
//!     error_estimate = c · η_raw
//! ```
//!
//! — the quantity `validate` measures, `rel_error = ‖X_r − X_full‖_F / ‖X_full‖_F`, with the
//! full model replaced by the enriched one ([`norms`]). The same distance over the
//! enriched model's displacement from the initial configuration X₀,
//!
//! ```text
//!     error_estimate_displacement = c · ‖X_r − X_{r+k}‖_F / ‖X_{r+k} − X₀‖_F
//! ```
//!
//! estimates `displacement_error` ([`ErrorMeasure`]) with the same `c`: calibrated on
//! `rel_error`, it is the ratio of the true distance to the enriched one, and both measures
//! divide that distance by norms of nearly the same trajectory (the enriched model's for the
//! estimate, the full model's for the error). `c` is calibrated at training time
//! on full runs at loads the basis did not see ([`training::calibrate`]); without such data
//! it is [`DEFAULT_FACTOR`] and the estimator is marked uncalibrated. Both the estimate up
//! to the end of each fifth of the run and the whole run's are reported ([`ByFifth`]).
//!
//! The methods differ in how they obtain `X_{r+k}`, each an [`ErrorEstimator`] in a file of
//! its own: [`enriched`] integrates the richer model to convergence, [`corrected`] takes
//! one Newton iteration of it per step along the reduced run, [`defects`] sums its local
//! corrections at every 10th step. The basis file names the method its estimates default
//! to; [`build`] picks the implementation by that name.

pub mod corrected;
pub mod defects;
pub mod enriched;
pub mod norms;
pub mod training;

use crate::error::Result;
use crate::model::Model;
pub use crate::reduction::estimator::{
    Calibration, CalibrationPoint, DefectsCalibration, ErrorMeasure, EstimateMethod, Estimator, DEFAULT_FACTOR,
};
use crate::reduction::Basis;
use crate::rom::quantities::{self, Quantity};
use crate::rom::reactions::{ReactionReader, ReactionReading};
use crate::rom::run::ReducedRun;
use crate::simulate::SimulationResult;
use crate::solver::model::Parameters;
use std::sync::Arc;

/// Estimates and errors are reported over the instants up to the end of each fifth of the
/// run: how the error grows in time, the last entry the whole run's.
pub const FIFTHS: usize = crate::reduction::estimator::FIFTHS;
/// A value for each fifth of the run ([`FIFTHS`]), the last the whole run's.
pub type ByFifth = crate::reduction::estimator::ByFifth;

/// `η_raw` by fifth of the run in both measures (the last entry of each the whole run's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawByFifth {
    /// `‖X_r − X⁺‖_F / ‖X⁺‖_F`
    pub relative: ByFifth,
    /// `‖X_r − X⁺‖_F / ‖X⁺ − X₀‖_F`
    pub displacement: ByFifth,
}

impl RawByFifth {
    /// Both ∞: an estimator whose model failed.
    pub const INFINITE: RawByFifth =
        RawByFifth { relative: [f64::INFINITY; FIFTHS], displacement: [f64::INFINITY; FIFTHS] };

    /// The values in `measure`.
    pub fn get(&self, measure: ErrorMeasure) -> &ByFifth {
        match measure {
            ErrorMeasure::Relative => &self.relative,
            ErrorMeasure::Displacement => &self.displacement,
        }
    }
}

/// What an estimator reads off a run before its factor: `η_raw` by fifth in both measures,
/// and the distance in each quantity the probes record and each joint reaction
/// ([`QuantityRaw`]: the probes' in [`quantities::readings`]'s order, then each reaction
/// point's force, then each one's moment).
#[derive(Clone, Debug, PartialEq)]
pub struct Raw {
    pub norms: RawByFifth,
    pub quantities: Vec<QuantityRaw>,
}

/// A probe quantity's or a joint reaction's `η_raw`: the reduced run's distance from the
/// enriched model in it over the enriched model's range ([`crate::rom::quantities`],
/// [`crate::rom::reactions`]); NaN where neither moves beyond the quantity's resolution.
#[derive(Clone, Debug, PartialEq)]
pub struct QuantityRaw {
    pub probe: String,
    pub quantity: Quantity,
    pub raw: f64,
}

impl QuantityRaw {
    /// The raw distance of `run` from the reference `reference` in every quantity, over
    /// the reference's ranges (the same probes, in [`quantities::readings`]'s order).
    pub fn between(run: &SimulationResult, reference: &[quantities::Reading], tol: f64, length: f64) -> Vec<Self> {
        quantities::readings(run)
            .iter()
            .zip(reference)
            .map(|(v, w)| QuantityRaw {
                probe: v.probe.to_string(),
                quantity: v.quantity,
                raw: quantities::Apart::of(v.values, w.values, v.quantity.resolution(tol, length)).relative,
            })
            .collect()
    }

    /// The quantity's key in calibrations and messages ([`quantity_key`]).
    pub fn key(&self) -> String {
        quantity_key(self.quantity, &self.probe)
    }

    /// The raw distance of a run's reactions `run` from the reference's `reference`, over
    /// the reference's ranges ([`ReactionReader::apart`]); none where either run has no
    /// reactions (a variant without physical multipliers).
    pub fn between_reactions(
        reader: &ReactionReader,
        run: Option<Vec<ReactionReading>>,
        reference: Option<Vec<ReactionReading>>,
        tol: f64,
    ) -> Vec<Self> {
        let (Some(run), Some(reference)) = (run, reference) else { return Vec::new() };
        run.iter()
            .zip(&reference)
            .map(|(v, w)| QuantityRaw {
                probe: v.point.clone(),
                quantity: v.quantity,
                raw: reader.apart(v, w, tol).relative,
            })
            .collect()
    }

    /// ∞ in every quantity of `run` and, where the run has them, every reaction the reader
    /// `reactions` names: an estimator whose model failed.
    pub fn infinite(run: &SimulationResult, reactions: Option<&ReactionReader>) -> Vec<Self> {
        let infinite = |probe: String, quantity| QuantityRaw { probe, quantity, raw: f64::INFINITY };
        let probes = quantities::readings(run).into_iter().map(|v| infinite(v.probe.to_string(), v.quantity));
        let has_reactions = run.multipliers.iter().all(|x| x.is_finite()) && !run.multipliers.is_empty();
        let fits = |r: &&ReactionReader| has_reactions && run.multipliers.nrows() == r.n_rows();
        let points = reactions.filter(fits).map(ReactionReader::points).unwrap_or_default();
        probes.chain(points.into_iter().map(|(point, quantity)| infinite(point, quantity))).collect()
    }
}

/// The estimate of a probe quantity's error over its range (the `rel_error` of the
/// quantity `validate` measures, [`crate::rom::quantities`]): `c · η_raw,q`, the factor the
/// run's estimate has.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct QuantityEstimate {
    pub probe: String,
    pub quantity: Quantity,
    /// `c · η_raw,q`; ∞ where the estimator's model failed, NaN where the quantity does not
    /// move beyond its resolution in either run
    pub estimate: f64,
    pub raw: f64,
}

impl QuantityEstimate {
    /// The quantity's key in calibrations ([`quantity_key`]).
    pub fn key(&self) -> String {
        quantity_key(self.quantity, &self.probe)
    }
}

/// A probe quantity's or joint reaction's key in calibrations and messages,
/// `quantity:probe` (`curvature:root`, `force:joint 0 … on arm node 0`).
pub fn quantity_key(quantity: Quantity, name: &str) -> String {
    format!("{}:{name}", quantity.name())
}

/// One estimate.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Estimate {
    /// `c · η_raw`; infinite when the enriched model failed to run
    pub error_estimate: f64,
    /// `η_raw`
    pub raw: f64,
    pub factor: f64,
    pub calibrated: bool,
    /// wall time of the estimator's run and the norms, s
    pub seconds: f64,
    /// `c · η_raw` over the instants up to the end of each fifth of the run (as
    /// [`norms::rel_error_by_time`] for the true error); NaN where unknown
    pub by_time: ByFifth,
    /// `c · ‖X_r − X⁺‖_F / ‖X⁺ − X₀‖_F`: the estimate of `displacement_error`; infinite
    /// when the enriched model failed to run, NaN where unknown
    pub error_estimate_displacement: f64,
    /// the same up to the end of each fifth of the run (as
    /// [`norms::displacement_error_by_time`] for the true error)
    pub displacement_by_time: ByFifth,
    /// why the estimator's own model failed, when it did (the estimates are then ∞)
    pub failure: Option<String>,
    /// each probe quantity's estimate, in [`crate::rom::quantities::readings`]'s order
    pub quantities: Vec<QuantityEstimate>,
}

impl Estimate {
    /// The estimate of an answer that is the full model's own (a sweep's fallback): its
    /// error against the full model is zero in both measures; `seconds` is what the
    /// estimate of the reduced attempt cost before it was set aside (0 when it had none).
    pub fn exact(seconds: f64) -> Self {
        Estimate {
            error_estimate: 0.0,
            raw: 0.0,
            factor: 1.0,
            calibrated: false,
            seconds,
            by_time: [0.0; 5],
            error_estimate_displacement: 0.0,
            displacement_by_time: [0.0; 5],
            failure: None,
            quantities: Vec::new(),
        }
    }

    /// The whole run's estimate in `measure`.
    pub fn in_measure(&self, measure: ErrorMeasure) -> f64 {
        match measure {
            ErrorMeasure::Relative => self.error_estimate,
            ErrorMeasure::Displacement => self.error_estimate_displacement,
        }
    }

    /// The estimate up to the end of each fifth of the run in `measure`.
    pub fn by_time_in(&self, measure: ErrorMeasure) -> &ByFifth {
        match measure {
            ErrorMeasure::Relative => &self.by_time,
            ErrorMeasure::Displacement => &self.displacement_by_time,
        }
    }
}

/// An error estimator of one basis: how it reads a reduced run, and how far it can be trusted.
/// Implementations keep their own work spaces, so one estimator serves runs on any number
/// of threads.
pub trait ErrorEstimator: Send + Sync {
    /// The method's name, as the basis file, `[online] estimate` and `--estimate` spell it.
    fn name(&self) -> &'static str;

    /// The data training made (enriched basis, calibration).
    fn data(&self) -> &Estimator;

    /// The model's reaction points, whose reactions the method estimates.
    fn reactions(&self) -> Option<&ReactionReader> {
        None
    }

    /// `η_raw` of `run` by fifth of the run, in both measures, and in each probe quantity.
    /// `Err` when the estimator's model fails.
    fn raw(&self, run: &ReducedRun) -> Result<Raw>;

    /// The factor each fifth's `η_raw` is multiplied by at the parameters `mu`: the
    /// calibrated `c` unless the method knows better.
    fn factors(&self, _mu: &Parameters) -> ByFifth {
        [self.data().calibration.factor; FIFTHS]
    }

    /// The factor a probe quantity's `η_raw` is multiplied by at `mu`: the run's whole-run
    /// factor `whole`, raised as the held-out runs raised the quantity's `c_q` above `c`
    /// ([`Calibration::quantity_scale`]), unless the method calibrated the quantity on its own.
    fn quantity_factor(&self, _mu: &Parameters, q: &QuantityRaw, whole: f64) -> f64 {
        whole * self.data().calibration.quantity_scale(&q.key())
    }

    /// The estimate of `run` at its parameters `mu`. A failure of the estimator's model gives
    /// an infinite estimate, not an error: the reduced answer itself exists.
    fn estimate(&self, run: &ReducedRun, mu: &Parameters) -> Estimate {
        let start = std::time::Instant::now();
        let (Raw { norms: raw, quantities }, failure) = match self.raw(run) {
            Ok(raw) => (raw, None),
            Err(e) => {
                let quantities = QuantityRaw::infinite(&run.result, self.reactions());
                let infinite = Raw { norms: RawByFifth::INFINITE, quantities };
                (infinite, Some(e.to_string()))
            }
        };
        let factors = self.factors(mu);
        let whole = factors[FIFTHS - 1];
        let quantities = quantities
            .into_iter()
            .map(|q| {
                let estimate = self.quantity_factor(mu, &q, whole) * q.raw;
                QuantityEstimate { probe: q.probe, quantity: q.quantity, estimate, raw: q.raw }
            })
            .collect();
        let by_time: ByFifth = std::array::from_fn(|i| factors[i] * raw.relative[i]);
        let displacement_by_time: ByFifth = std::array::from_fn(|i| factors[i] * raw.displacement[i]);
        Estimate {
            error_estimate: by_time[FIFTHS - 1],
            raw: raw.relative[FIFTHS - 1],
            factor: factors[FIFTHS - 1],
            calibrated: self.data().calibration.calibrated,
            seconds: start.elapsed().as_secs_f64(),
            by_time,
            error_estimate_displacement: displacement_by_time[FIFTHS - 1],
            displacement_by_time,
            failure,
            quantities,
        }
    }

    /// The calibration held-out full runs give this method: `(η_raw, rel_error)` pairs at
    /// loads the basis never saw ([`training::calibrate`]).
    fn calibrate(&self, held_out: Vec<CalibrationPoint>) -> Calibration {
        training::calibrate(held_out)
    }

    /// `Some(why)` when this method's estimates should not be relied on for this basis
    /// (a calibration that failed its own check); `None` otherwise.
    fn self_check(&self) -> Option<String> {
        None
    }
}

/// The reactions of the reduced run `run` of `basis`, from its physical multipliers along its
/// trajectory; none where its variant has none.
pub fn run_reactions(reader: &ReactionReader, basis: &Basis, run: &ReducedRun) -> Option<Vec<ReactionReading>> {
    let t = run.result.t.as_slice()?;
    let (mu, z) = (run.result.settings.parameters(), run.reduced_q.view());
    reader.of_trajectory((mu, t), (basis, z), None, run.result.multipliers.view())
}

/// The estimator of `basis` by `method`: `corrected` and `defects` where the correction can
/// run ([`corrected::CorrectedRunner::supports`]), else the enriched model on its own, which
/// then names itself `enriched`.
pub fn build(
    method: EstimateMethod,
    model: &Arc<Model>,
    basis: &Arc<Basis>,
    data: &Arc<Estimator>,
) -> Result<Arc<dyn ErrorEstimator>> {
    let correctable = || corrected::CorrectedRunner::supports(model, basis, &data.enriched);
    Ok(match method {
        EstimateMethod::Corrected if correctable()? => Arc::new(corrected::Corrected::new(model, basis, data)?),
        EstimateMethod::Defects if correctable()? => Arc::new(defects::Defects::new(model, basis, data)?),
        _ => Arc::new(enriched::Enriched::new(model, basis, data)?),
    })
}
