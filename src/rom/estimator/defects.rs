//! The cheap error estimator (`estimate = "defects"`, docs/error-estimate.md): the reduced
//! run's local defects against the enriched model at sampled steps, accumulated.
//!
//! The corrected estimator ([`super::corrected`]) assembles and factorizes one
//! enriched matrix per step (≈ 100 % of the reduced run on the pendulum, 30–45 % on the
//! four-bar). Here the enriched model's one-iteration correction is taken only at every
//! `s`-th step, from the reduced run's own lifted state ([`CorrectedRunner::defects`]):
//! `δ_n` is how far the reduced step to `n` lies from the richer model's step from the same
//! state. The reduced run's distance to the richer model's trajectory is then bounded, as
//! for any one-step method whose error propagation does not amplify (the discrete Gronwall
//! bound with growth factor 1), by the sum of the defects made so far, each sampled one
//! standing for the `s` steps it represents:
//!
//! ```text
//!     e_k = s · Σ_{n ≤ k, n ∈ {s, 2s, …}} ‖δ_n‖,
//!     η_raw = ( Σ_k e_k² )^½ / ‖X_r‖_F         (and the same up to each fifth of the run)
//!     η_raw, displacement = ( Σ_k e_k² )^½ / ‖X_r − X₀‖_F
//! ```
//!
//! The triangle inequality ignores that defects of alternating sign cancel, so the bound
//! is loose (measured: 1.2–46× the true error, docs/error-estimate.md), but it needs no
//! constant fitted to a model; where the dynamics amplify differences (the four-bar after
//! t ≈ 0.7 s) it is tighter than elsewhere and held there by its margin. `s` is
//! [`DEFECT_SAMPLE`], lowered so that a run keeps at least [`MIN_SAMPLES`] samples: fixed
//! numbers, not fitted.

use super::corrected::{CorrectedRunner, Followed};
use super::norms::{against_motion, resolution, ConfigurationNorms, RawByFifth};
use super::{ByFifth, ErrorEstimator, Estimator, QuantityRaw, Raw, FIFTHS};
use crate::error::Result;
use crate::model::Model;
use crate::physics::element::Vec8;
use crate::physics::system::FlexibleSystem;
use crate::reduction::Basis;
use crate::rom::pool::Pool;
use crate::rom::quantities::{max_distance, range, readings, Quantity};
use crate::rom::reactions::ReactionReader;
use crate::rom::run::ReducedRun;
use crate::solver::model::Parameters;
use ndarray::Axis;
use std::sync::Arc;

/// `s`: reduced-run steps per sampled defect.
pub const DEFECT_SAMPLE: usize = 10;
/// The fewest defects a run is estimated from (short runs sample more often).
pub const MIN_SAMPLES: usize = 16;

/// The sampling interval for a run of `steps` steps: `sample`, at most `steps / MIN_SAMPLES`, at least 1.
pub fn sample_for(steps: usize, sample: usize) -> usize {
    sample.min(steps / MIN_SAMPLES).max(1)
}

/// The `defects` method: the defect sum of the module documentation, put on the corrected
/// method's scale fifth by fifth where greedy training calibrated it
/// ([`crate::reduction::estimator::DefectsCalibration`]).
pub struct Defects {
    data: Arc<Estimator>,
    basis: Arc<Basis>,
    sys: Arc<FlexibleSystem>,
    runners: Pool<'static, CorrectedRunner>,
    sample: usize,
    /// the configuration norms' constants, projected once: an estimate costs O(r n_t),
    /// not O(n_dof r)
    norms: ConfigurationNorms,
    /// the model's length scale `L` (the displacement measure's resolution is `tol · L`)
    length: f64,
    /// the model's reaction points
    reactions: ReactionReader,
}

impl Defects {
    /// With one runner built now (as [`super::corrected::Corrected::new`]).
    pub fn new(model: &Arc<Model>, basis: &Arc<Basis>, data: &Arc<Estimator>) -> Result<Self> {
        let (m, b, d) = (Arc::clone(model), Arc::clone(basis), Arc::clone(data));
        let runners = Pool::new(move || CorrectedRunner::new(&m, &b, &d));
        runners.put(CorrectedRunner::new(model, basis, data)?);
        let physics = model.physics()?;
        let norms = ConfigurationNorms::new(basis, ndarray::ArrayView1::from(&physics.x0[..]));
        let length = physics.length_scale();
        let sys = Arc::clone(&physics.sys);
        Ok(Defects {
            data: Arc::clone(data),
            basis: Arc::clone(basis),
            sys,
            runners,
            sample: DEFECT_SAMPLE,
            norms,
            length,
            reactions: ReactionReader::new(model),
        })
    }

    /// Another sampling interval (experiments: examples/estimate_table.rs).
    pub fn with_sample(mut self, sample: usize) -> Self {
        self.sample = sample.max(1);
        self
    }
}

impl Defects {
    /// The defect sum in each probe quantity: the change `Δv_n = v(x_n + V⁺δ_n) − v(x_n)`
    /// the enriched correction `δ_n` makes to the quantity at the reduced run's state `x_n`
    /// (on the probe's element alone), summed as the coordinates' defects are,
    ///
    /// ```text
    ///     η_raw,q = s · Σ_n ‖Δv_n‖ / range_k v(x_k)
    /// ```
    ///
    /// over the reduced run's own range (there is no enriched trajectory to take it from).
    fn quantity_raws(&self, run: &ReducedRun, defects: &ndarray::Array2<f64>, s: usize) -> Vec<QuantityRaw> {
        let (sys, z) = (&self.sys, &run.reduced_q);
        let tol = run.result.settings.params.tolerance;
        // per probe: the summed change in position, strain and curvature
        let sums: Vec<[f64; 3]> = sys
            .probes
            .iter()
            .map(|p| {
                let dofs = sys.element_dofs(p.element);
                let rows = |b: &Basis| b.modes.select(Axis(0), dofs);
                let (ve, vpe) = (rows(&self.basis), rows(&self.data.enriched));
                let xe_ref = self.basis.reference.select(Axis(0), dofs);
                let el = sys.element(p.element);
                let at = |e: &Vec8| {
                    let r = el.position(e, p.xi);
                    [r[0], r[1], el.axial_strain(e, p.xi), el.curvature(e, p.xi)]
                };
                let mut sum = [0.0; 3];
                for k in (s..z.ncols()).step_by(s) {
                    let x = Vec8::from_iterator((ve.dot(&z.column(k)) + &xe_ref).iter().copied());
                    let d = Vec8::from_iterator(vpe.dot(&defects.column(k)).iter().copied());
                    let (a, b) = (at(&x), at(&(x + d)));
                    sum[0] += s as f64 * ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                    sum[1] += s as f64 * (b[2] - a[2]).abs();
                    sum[2] += s as f64 * (b[3] - a[3]).abs();
                }
                sum
            })
            .collect();
        readings(&run.result)
            .iter()
            .map(|v| {
                let slot = match v.quantity {
                    Quantity::Position => 0,
                    Quantity::Strain => 1,
                    Quantity::Curvature => 2,
                    // a run's readings are its probes' ([`Self::reaction_raws`] reads reactions)
                    Quantity::Force | Quantity::Moment => 3,
                };
                let probe = sys.probes.iter().position(|p| p.name == v.probe);
                let sum = probe.and_then(|i| sums.get(i)).and_then(|s| s.get(slot).copied()).unwrap_or(f64::NAN);
                let range = range(v.values);
                let res = v.quantity.resolution(tol, self.length);
                let raw = against_motion(range > res, sum > res, || sum / range);
                QuantityRaw { probe: v.probe.to_string(), quantity: v.quantity, raw }
            })
            .collect()
    }
}

impl Defects {
    /// The largest change in each joint reaction the enriched correction makes at the
    /// sampled steps, `max_n ‖R(x_n + V⁺δ_n, λ⁺_n) − R(x_n, λ_n)‖`, over the reduced run's
    /// range: a reaction is read off each instant's multipliers, so its error is the
    /// instant's, not a sum over the run as the coordinates' is. On no scale of its own
    /// (one Newton iteration's multipliers): calibrated per reaction as the probe
    /// quantities are ([`Self::quantity_factor`]).
    fn reaction_raws(&self, run: &ReducedRun, followed: &Followed, s: usize) -> Vec<QuantityRaw> {
        let Some(own) = super::run_reactions(&self.reactions, &self.basis, run) else { return Vec::new() };
        let (t, nt) = (run.result.t.as_slice().unwrap_or(&[]), run.reduced_q.ncols());
        let sampled: Vec<usize> = (s..nt).step_by(s).collect();
        let ts: Vec<f64> = sampled.iter().map(|&k| t[k]).collect();
        let mu = run.result.settings.parameters();
        let (z, delta) = (run.reduced_q.select(Axis(1), &sampled), followed.q.select(Axis(1), &sampled));
        let corrected = self.reactions.of_trajectory(
            (mu, &ts),
            (&self.basis, z.view()),
            Some((&self.data.enriched, delta.view())),
            followed.lambda.select(Axis(1), &sampled).view(),
        );
        let Some(corrected) = corrected else { return Vec::new() };
        let tol = run.result.settings.params.tolerance;
        own.iter()
            .zip(&corrected)
            .map(|(v, w)| {
                let change = max_distance(v.values.select(Axis(0), &sampled).view(), w.values.view());
                let (range, res) = (range(v.values.view()), self.reactions.resolution(v, tol));
                let raw = against_motion(range > res, change > res, || change / range);
                QuantityRaw { probe: v.point.clone(), quantity: v.quantity, raw }
            })
            .collect()
    }
}

impl ErrorEstimator for Defects {
    fn name(&self) -> &'static str {
        "defects"
    }
    fn data(&self) -> &Estimator {
        &self.data
    }
    fn reactions(&self) -> Option<&crate::rom::reactions::ReactionReader> {
        Some(&self.reactions)
    }

    /// `η_raw` over the instants up to the end of each fifth of `run`, in both measures
    /// (module documentation).
    fn raw(&self, run: &ReducedRun) -> Result<Raw> {
        let z = &run.reduced_q;
        let nt = z.ncols();
        let s = sample_for(nt.saturating_sub(1), self.sample);
        let followed = self.runners.with(|r| r.defects_with_multipliers(run, s))??;
        let defects = &followed.q;
        // ‖x_ref + V z_k‖² and ‖x_ref + V z_k − x₀‖² from the reduced coordinates (V
        // orthonormal; the corrected runner exists only for such bases): norms.rs
        let (mut err2, mut norm2, mut disp2) = (vec![0.0; nt], vec![0.0; nt], vec![0.0; nt]);
        let mut acc = 0.0;
        for k in 0..nt {
            let zk = z.column(k);
            let zk2 = zk.dot(&zk);
            (norm2[k], disp2[k]) = self.norms.at(zk, zk2);
            if k > 0 && k % s == 0 {
                acc += s as f64 * defects.column(k).dot(&defects.column(k)).sqrt();
            }
            err2[k] = acc * acc;
        }
        let resolution = resolution(run, self.length);
        let norms = RawByFifth::from_sums(nt, self.norms.n_dof(), resolution, |displacement, end| {
            let per_instant = if displacement { &disp2 } else { &norm2 };
            (err2[..end].iter().sum(), per_instant[..end].iter().sum::<f64>().max(0.0))
        });
        let mut quantities = self.quantity_raws(run, defects, s);
        quantities.extend(self.reaction_raws(run, &followed, s));
        Ok(Raw { norms, quantities })
    }

    /// The defect sum is a bound by itself: factor 1, raised in the proportion that
    /// calibration raised the corrected method's `c` above its default; or put on the
    /// corrected method's scale fifth by fifth where greedy training measured how
    /// (`DefectsCalibration`): interpolated in the load where that calibration passed its
    /// check, else the largest ratio measured.
    fn factors(&self, mu: &Parameters) -> ByFifth {
        let c = &self.data.calibration;
        match &self.data.defects {
            Some(d) if d.reliable => d.factors_at(mu),
            Some(d) => d.factors,
            None => [c.factor / super::DEFAULT_FACTOR; FIFTHS],
        }
    }

    /// A quantity's defect sum on the corrected method's scale where greedy training
    /// calibrated it (`DefectsCalibration::quantities`); NaN (no estimate) where it did not:
    /// read as a bound, the uncalibrated sum fell below the error at most of the zoo's tip
    /// positions (docs/error-estimate.md), and no estimate is better than a low one.
    fn quantity_factor(&self, mu: &Parameters, q: &QuantityRaw, _whole: f64) -> f64 {
        let calibrated = self.data.defects.as_ref().and_then(|d| d.quantity_factor(&q.key(), mu));
        calibrated.unwrap_or(f64::NAN)
    }

    fn self_check(&self) -> Option<String> {
        self.data.defects.as_ref().filter(|d| !d.reliable).map(|_| {
            "the defects calibration failed its check between the candidate loads (docs/error-estimate.md): the estimate uses the largest ratio measured and may read far above the error; \"corrected\" is the tighter choice here".to_string()
        })
    }
}
