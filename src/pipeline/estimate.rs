//! An error estimate for every reduced run, without a full run (docs/error-estimate.md).
//!
//! The estimator is a second reduced model on the *enriched* basis `V⁺`: the same POD with
//! `k` more modes (per block for a block basis), its own ECSW set when the basis is
//! hyper-reduced. Both runs start from the same `x_ref` and solve the same equations; the
//! richer one is closer to the full model, and their distance predicts the smaller one's
//! error:
//!
//! ```text
//!     η_raw = ‖X_r − X_{r+k}‖_F / ‖X_{r+k}‖_F            (all coordinates, all instants)
//!     error_estimate = c · η_raw
//! ```
//!
//! — the quantity `validate` measures, `rel_error = ‖X_r − X_full‖_F / ‖X_full‖_F`, with the
//! full model replaced by the enriched one. `c` is calibrated at training time on full runs
//! at loads the basis did not see (`c = max(1, m · max_i e_i/η_i)`, margin `m` =
//! [`CALIBRATION_MARGIN`]); without such data it is [`DEFAULT_FACTOR`] and the estimator is
//! marked uncalibrated.
//!
//! With orthonormal `V` and `V⁺` (galerkin, constraint-preserving, block bases) the norms
//! need no full-size reconstruction: with `M = V⁺ᵀV`,
//!
//! ```text
//!     ‖V q − V⁺ q⁺‖² = ‖M q − q⁺‖² + qᵀ(I − MᵀM) q,
//!     ‖x_ref + V⁺ q⁺‖² = ‖x_ref‖² + 2 (V⁺ᵀx_ref)·q⁺ + ‖q⁺‖².
//! ```

use super::estimate_corrected::CorrectedRunner;
use super::estimate_defects::DefectRunner;
use super::online::{Output, ReducedRun, ReducedRunner};
use crate::error::Result;
use crate::model::Model;
use crate::physics::system::FlexibleSystem;
pub use crate::reduction::estimator::{Calibration, CalibrationPoint, EstimateMethod, Estimator, DEFAULT_FACTOR};
use crate::reduction::{ecsw, train_basis, Basis, BasisSpec, ModeRule, Trained, Variant};
use ndarray::{Array1, Array2, ArrayView1, ArrayView2, Axis};

/// `k`: extra POD modes per block of the enriched basis.
pub const DEFAULT_EXTRA_MODES: usize = 10;
/// The enriched model's ECSW tolerance relative to the basis's τ: its force integration
/// must be more accurate than the error it measures. At τ itself the four-bar (trained at
/// 0.7, 0.95, 1.2) gave effectivities of 312 and 9.7 at two of 13 loads (the enriched
/// model's own hyper-reduction error); at τ/10 all 13 lay in 1.40–1.58, as without ECSW.
pub const ENRICHED_HYPER_FACTOR: f64 = 0.1;
/// Safety margin over the largest ratio true/raw seen in calibration.
pub const CALIBRATION_MARGIN: f64 = 1.25;

/// The constant `c` from held-out pairs `(η_i, e_i)`:
///
/// ```text
///     c = max(DEFAULT_FACTOR, CALIBRATION_MARGIN · max_i e_i / η_i)
/// ```
///
/// so that every calibration load is covered with margin. Calibration only raises `c` above
/// the uncalibrated default, never lowers it: the pairs come from few full runs (greedy
/// training: often one, made with an *earlier* iteration's basis), and an overestimate
/// there says nothing about the final basis. With a floor of 1 the shipped four-bar (one
/// pair, η = 5.5 e) stored c = 1 and its final basis's estimate then fell below the true
/// error at 5 of 5 validation loads (effectivity 0.89–1.00; measured before commit d42c82a). Pairs with
/// a non-finite or non-positive value are ignored (an exact reduced run says nothing about
/// `c`); with none left, `c` = [`DEFAULT_FACTOR`], uncalibrated. The points are kept either way.
pub fn calibrate(points: Vec<CalibrationPoint>) -> Calibration {
    let ratios: Vec<f64> = points
        .iter()
        .filter(|p| p.raw_estimate.is_finite() && p.rel_error.is_finite() && p.raw_estimate > 0.0 && p.rel_error > 0.0)
        .map(|p| p.rel_error / p.raw_estimate)
        .collect();
    if ratios.is_empty() {
        return Calibration { points, ..Calibration::default() };
    }
    let worst = ratios.iter().copied().fold(0.0, f64::max);
    Calibration { factor: (CALIBRATION_MARGIN * worst).max(DEFAULT_FACTOR), calibrated: true, points }
}

/// The mode rule of the enriched basis: each block's count plus `extra`, capped by the
/// block's numerical rank (singular values above 1e-10 of its largest) but never below the
/// basis's own count.
fn enriched_rule(trained: &Trained, blocks: bool, extra: usize) -> ModeRule {
    let counts: Vec<usize> = trained
        .pods
        .iter()
        .zip(&trained.block_modes)
        .map(|(p, &r)| {
            let s0 = p.singular_values.first().copied().unwrap_or(0.0);
            let rank = p.singular_values.iter().filter(|&&s| s > 1e-10 * s0).count();
            (r + extra).min(rank).max(r)
        })
        .collect();
    if blocks {
        ModeRule::Counts(counts)
    } else {
        ModeRule::Count(counts[0])
    }
}

/// Builds the estimator at training time from the snapshots and spec the basis was built
/// from: the POD again with `block_modes + extra` modes, and ECSW for `V⁺` at
/// `ENRICHED_HYPER_FACTOR · hyper_tolerance` when given (`hyper_tolerance` is the basis's
/// own τ). Uncalibrated: see [`calibrate`].
#[allow(clippy::too_many_arguments)]
pub fn build_estimator(
    sys: &FlexibleSystem,
    trained: &Trained,
    spec: &BasisSpec,
    x: ArrayView2<f64>,
    multipliers: ArrayView2<f64>,
    joint_dofs: &[usize],
    x_ref: ArrayView1<f64>,
    hyper_tolerance: Option<f64>,
    extra: usize,
) -> std::result::Result<Estimator, String> {
    let spec = BasisSpec { modes: enriched_rule(trained, !spec.blocks.is_empty(), extra), ..spec.clone() };
    let mut richer =
        train_basis(x, multipliers, joint_dofs, x_ref, &spec).map_err(|e| format!("enriched basis: {e}"))?;
    if let Some(tol) = hyper_tolerance {
        richer.basis.hyper = Some(
            ecsw(sys, &richer.basis, x, ENRICHED_HYPER_FACTOR * tol)
                .map_err(|e| format!("ECSW of the enriched basis: {e}"))?,
        );
    }
    Ok(Estimator {
        enriched: richer.basis,
        block_modes: richer.block_modes,
        extra_modes: extra,
        calibration: Calibration::default(),
        defects: None,
        // training steers greedy and calibrates `c` with the tight method; runs read from
        // the basis file use the pipeline's `[online] estimate` (default: the defects method
        // where greedy training calibrated it, else this one: `estimate_trust::load_trust`)
        method: EstimateMethod::Corrected,
    })
}

/// `η_raw = ‖X_r − X⁺‖_F / ‖X⁺‖_F` of two finished runs of the same load, from their
/// reduced coordinates: by the module documentation's identities when both bases are
/// orthonormal, by reconstructing `x_ref + V q` otherwise (whole-system).
pub fn raw_estimate(basis: &Basis, est: &Estimator, rom: &ReducedRun, enriched: &ReducedRun) -> f64 {
    raw_estimate_by_time(basis, &est.enriched, &rom.reduced_q, &enriched.reduced_q)[4]
}

/// [`raw_estimate`] from the reduced coordinates `q` (r × n_t) of `basis` and `qp`
/// (r⁺ × n_t) of `enriched`, both with orthonormal columns and the same reference.
pub fn raw_estimate_reduced(basis: &Basis, enriched: &Basis, q: &Array2<f64>, qp: &Array2<f64>) -> f64 {
    raw_estimate_by_time(basis, enriched, q, qp)[4]
}

/// `η_raw` over the instants up to the end of each fifth of the run (the last entry is the
/// whole run's), as [`rel_error_by_time`] splits the true error; ∞ when the shapes differ.
pub fn raw_estimate_by_time(basis: &Basis, enriched: &Basis, q: &Array2<f64>, qp: &Array2<f64>) -> [f64; 5] {
    let nt = qp.ncols();
    if q.ncols() != nt || nt == 0 {
        return [f64::INFINITY; 5];
    }
    let (diff2, norm2): (Array1<f64>, Array1<f64>) = if basis.variant == Variant::WholeSystem {
        // V is not orthonormal: reconstruct x_ref + V q of both
        let full = |b: &Basis, z: &Array2<f64>| b.modes.dot(z) + b.reference.view().insert_axis(Axis(1));
        let (a, b) = (full(basis, q), full(enriched, qp));
        ((&a - &b).mapv(|v| v * v).sum_axis(Axis(0)), b.mapv(|v| v * v).sum_axis(Axis(0)))
    } else {
        let vp = &enriched.modes;
        let m = vp.t().dot(&basis.modes); // r⁺ × r
        let mq = m.dot(q);
        let q2 = q.mapv(|v| v * v).sum_axis(Axis(0));
        let mq2 = mq.mapv(|v| v * v).sum_axis(Axis(0));
        let d = (&mq - qp).mapv(|v| v * v).sum_axis(Axis(0)) + (&q2 - &mq2).mapv(|v| v.max(0.0));
        let xr = &enriched.reference;
        let vtx = vp.t().dot(xr);
        let norm = xr.dot(xr) + 2.0 * vtx.dot(qp) + qp.mapv(|v| v * v).sum_axis(Axis(0));
        (d, norm)
    };
    let mut out = [0.0; 5];
    for (i, o) in out.iter_mut().enumerate() {
        let end = ((nt as f64 * (i + 1) as f64 / 5.0).round() as usize).clamp(1, nt);
        let (d, n) = (diff2.slice(ndarray::s![..end]).sum(), norm2.slice(ndarray::s![..end]).sum());
        *o = d.max(0.0).sqrt() / n.max(0.0).sqrt();
    }
    out
}

/// A reduced model and its estimator's model, built once, run at many load scales (a sweep
/// keeps one per thread).
pub struct EstimatingRunner<'a> {
    basis: &'a Basis,
    rom: ReducedRunner<'a>,
    est: Option<(&'a Estimator, EstimatorModel<'a>)>,
}

/// The estimator's model: the enriched model corrected along the reduced run, or run on its
/// own (the `enriched` method, and the fallback where the corrected one is not available).
enum EstimatorModel<'a> {
    Corrected(Box<CorrectedRunner<'a>>),
    Defects(Box<DefectRunner<'a>>),
    Enriched(ReducedRunner<'a>),
}

impl<'a> EstimatingRunner<'a> {
    /// The estimator runs by `est.method`.
    pub fn new(model: &'a Model, basis: &'a Basis, est: Option<&'a Estimator>) -> Result<Self> {
        let rom = ReducedRunner::new(model, basis)?;
        let est = match est {
            Some(e) => {
                let m = match e.method {
                    EstimateMethod::Corrected => {
                        CorrectedRunner::new(model, basis, &e.enriched)?.map(|c| EstimatorModel::Corrected(Box::new(c)))
                    }
                    EstimateMethod::Defects => {
                        DefectRunner::new(model, basis, &e.enriched)?.map(|c| EstimatorModel::Defects(Box::new(c)))
                    }
                    EstimateMethod::Enriched => None,
                };
                let m = match m {
                    Some(m) => m,
                    None => EstimatorModel::Enriched(ReducedRunner::new(model, &e.enriched)?),
                };
                Some((e, m))
            }
            None => None,
        };
        Ok(EstimatingRunner { basis, rom, est })
    }

    /// Experiments with the `defects` method (examples/estimate_table.rs): its sampling
    /// interval; no effect with another method.
    pub fn set_defect_sample(&mut self, sample: usize) {
        if let Some((_, EstimatorModel::Defects(d))) = &mut self.est {
            d.set_sample(sample);
        }
    }

    /// The reduced model alone (no estimate), e.g. for the reduced model's own sensitivity.
    pub fn reduced(&mut self) -> &mut ReducedRunner<'a> {
        &mut self.rom
    }

    /// The reduced run at `load_scale` and, when the basis has an estimator, its estimate.
    /// A failure of the estimator's model gives an infinite estimate, not an error: the
    /// reduced answer itself exists.
    pub fn run(&mut self, load_scale: f64, output: Output) -> Result<(ReducedRun, Option<Estimate>)> {
        self.run_with(load_scale, output, &[])
    }

    /// [`Self::run`] with continuation from `previous` runs of the main model (see
    /// [`ReducedRunner::run`]); the estimator's model runs on its own.
    pub fn run_with(
        &mut self,
        load_scale: f64,
        output: Output,
        previous: &[&ReducedRun],
    ) -> Result<(ReducedRun, Option<Estimate>)> {
        let run = self.rom.run(load_scale, output, previous)?;
        let Some((est, model)) = &mut self.est else { return Ok((run, None)) };
        let start = std::time::Instant::now();
        // the norms come from the reduced coordinates: nothing of full size is written
        let raw = match model {
            EstimatorModel::Corrected(c) => {
                c.run(&run).ok().map(|qp| raw_estimate_by_time(self.basis, &est.enriched, &run.reduced_q, &qp))
            }
            EstimatorModel::Defects(d) => d.raw_by_time(&run).ok(),
            EstimatorModel::Enriched(r) => r
                .run(load_scale, Output::ReducedAndProbes, &[])
                .ok()
                .map(|e| raw_estimate_by_time(self.basis, &est.enriched, &run.reduced_q, &e.reduced_q)),
        };
        let raw = raw.unwrap_or([f64::INFINITY; 5]);
        let c = &est.calibration;
        // the defect sum is a bound by itself: factor 1, raised in the proportion that
        // calibration raised the corrected method's c above its default, or put on the
        // corrected method's scale fifth by fifth where greedy training measured how
        // (`DefectsCalibration`)
        let factors = match (model, &est.defects) {
            // interpolated in the load only where the calibration's check passed; else
            // (a pipeline asking for `defects` on such a basis) the largest ratio measured
            (EstimatorModel::Defects(_), Some(d)) if d.reliable => d.factors_at(load_scale),
            (EstimatorModel::Defects(_), Some(d)) => d.factors,
            (EstimatorModel::Defects(_), None) => [c.factor / DEFAULT_FACTOR; 5],
            _ => [c.factor; 5],
        };
        let by_time: [f64; 5] = std::array::from_fn(|i| factors[i] * raw[i]);
        let e = Estimate {
            error_estimate: by_time[4],
            raw: raw[4],
            factor: factors[4],
            calibrated: c.calibrated,
            seconds: start.elapsed().as_secs_f64(),
            by_time,
        };
        Ok((run, Some(e)))
    }
}

/// `rel_error` of `a` against `b` over the instants `..k`, for the end of each fifth of
/// the run: `‖A[:, ..k] − B[:, ..k]‖_F / ‖B[:, ..k]‖_F`.
/// `‖a − b‖_F` and `‖b‖_F`, summed in the arrays' logical order (rows, then columns)
/// whatever their memory layout (a full run keeps its coordinates column-major, a reduced
/// one row-major), so that the same two runs always give the same bits.
pub fn distance_and_norm(a: &Array2<f64>, b: &Array2<f64>) -> (f64, f64) {
    assert_eq!(a.dim(), b.dim(), "arrays of one shape");
    let (mut d, mut n) = (0.0, 0.0);
    for (x, y) in a.iter().zip(b.iter()) {
        d += (x - y) * (x - y);
        n += y * y;
    }
    (d.sqrt(), n.sqrt())
}

pub fn rel_error_by_time(a: &Array2<f64>, b: &Array2<f64>) -> Vec<f64> {
    let nt = b.ncols();
    let (mut diff, mut norm) = (Array1::<f64>::zeros(nt), Array1::<f64>::zeros(nt));
    for k in 0..nt {
        diff[k] = a.column(k).iter().zip(b.column(k)).map(|(x, y)| (x - y) * (x - y)).sum::<f64>();
        norm[k] = b.column(k).iter().map(|y| y * y).sum::<f64>();
    }
    (1..=5)
        .map(|i| {
            let end = ((nt as f64 * i as f64 / 5.0).round() as usize).clamp(1, nt);
            (diff.slice(ndarray::s![..end]).sum() / norm.slice(ndarray::s![..end]).sum()).sqrt()
        })
        .collect()
}

pub use super::estimate_trust::{
    check_runs, describe, is_extrapolated, load_trust, write_run_attributes, Estimate, TrustInfo,
};

#[cfg(test)]
mod tests {
    use super::*;

    /// c = 1.25 · max(e/η) over the usable pairs; the uncalibrated 1.5 at least (an
    /// overestimating pair does not lower it); the default without data.
    #[test]
    fn calibration_covers_every_point_with_margin() {
        let p = |raw, err| CalibrationPoint { load_scale: 1.0, raw_estimate: raw, rel_error: err };
        let c = calibrate(vec![p(1e-3, 2e-3), p(2e-3, 1e-3), p(0.0, 1e-3), p(f64::NAN, 1.0)]);
        assert!(c.calibrated);
        assert!((c.factor - 1.25 * 2.0).abs() < 1e-12, "{}", c.factor);
        assert_eq!(c.points.len(), 4);
        let low = calibrate(vec![p(1e-2, 1e-4)]);
        assert!(low.calibrated);
        assert_eq!(low.factor, DEFAULT_FACTOR);
        let none = calibrate(vec![p(0.0, 0.0)]);
        assert!(!none.calibrated);
        assert_eq!(none.factor, DEFAULT_FACTOR);
    }

    /// The reduced-coordinate norms equal the full-coordinate ones for nested orthonormal
    /// bases and for bases that are not nested (random rotations of a 3-column basis).
    #[test]
    fn reduced_norms_match_full_reconstruction() {
        let n = 7;
        let nt = 4;
        let a =
            Array2::from_shape_fn((n, 5), |(i, j)| ((i * 5 + j) as f64 * 0.37).sin() + if i == j { 2.0 } else { 0.0 });
        let (qf, _) = ndarray_linalg::QR::qr(&a).unwrap();
        let vp = qf.slice(ndarray::s![.., ..5]).to_owned();
        let reference = Array1::from_shape_fn(n, |i| 0.1 * i as f64 + 1.0);
        let mk = |modes: Array2<f64>| Basis {
            variant: Variant::Galerkin,
            snapshots: crate::reduction::SnapshotKind::Reference,
            reference: reference.clone(),
            n_pod_modes: modes.ncols(),
            modes,
            kept: vec![],
            multiplier_modes: None,
            multiplier_scale: 1.0,
            hyper: None,
        };
        let plus = mk(vp.clone());
        let est = Estimator {
            enriched: plus.clone(),
            block_modes: vec![5],
            extra_modes: 2,
            calibration: Calibration::default(),
            defects: None,
            method: EstimateMethod::default(),
        };
        // nested (first 3 columns) and not nested (mixing columns 2..5)
        let nested = vp.slice(ndarray::s![.., ..3]).to_owned();
        let mixed = {
            let (q, _) =
                ndarray_linalg::QR::qr(&(&vp.slice(ndarray::s![.., 1..4]) + &(0.3 * &qf.slice(ndarray::s![.., 4..5]))))
                    .unwrap();
            q
        };
        for small in [nested, mixed] {
            let b = mk(small);
            let q = Array2::from_shape_fn((b.n_reduced(), nt), |(i, k)| (i as f64 + 1.0) * (k as f64 * 0.5).cos());
            let qp = Array2::from_shape_fn((5, nt), |(i, k)| (i as f64 - 1.0) * (k as f64 * 0.3).sin());
            let full =
                |basis: &Basis, z: &Array2<f64>| basis.modes.dot(z) + basis.reference.view().insert_axis(Axis(1));
            let (x1, x2) = (full(&b, &q), full(&plus, &qp));
            let want = (&x1 - &x2).mapv(|v| v * v).sum().sqrt() / x2.mapv(|v| v * v).sum().sqrt();
            let got = raw_estimate_reduced(&b, &est.enriched, &q, &qp);
            assert!((got - want).abs() < 1e-12 * want.max(1.0), "{got} vs {want}");
        }
    }

    /// The estimate over prefixes of the run: zero while the two runs agree; non-decreasing
    /// when the distance per instant grows and the norm per instant is constant (then each
    /// prefix value is the RMS of a growing sequence); the last is the whole run's.
    #[test]
    fn estimate_by_time_follows_a_growing_error() {
        let (n, nt) = (4, 20);
        let eye = Array2::from_shape_fn((n, n), |(i, j)| if i == j { 1.0 } else { 0.0 });
        let mk = |modes: Array2<f64>| Basis {
            variant: Variant::Galerkin,
            snapshots: crate::reduction::SnapshotKind::Reference,
            reference: Array1::zeros(n),
            n_pod_modes: modes.ncols(),
            modes,
            kept: vec![],
            multiplier_modes: None,
            multiplier_scale: 1.0,
            hyper: None,
        };
        let (b, plus) = (mk(eye.clone()), mk(eye));
        // X⁺ rotates at unit norm; X_r lags it by nothing for 8 instants, then by a growing angle
        let lag = |k: usize| if k < 8 { 0.0 } else { 0.01 * (k - 7) as f64 };
        let qp = Array2::from_shape_fn((n, nt), |(i, k)| match i {
            0 => (0.1 * k as f64).cos(),
            1 => (0.1 * k as f64).sin(),
            _ => 0.0,
        });
        let q = Array2::from_shape_fn((n, nt), |(i, k)| match i {
            0 => (0.1 * k as f64 - lag(k)).cos(),
            1 => (0.1 * k as f64 - lag(k)).sin(),
            _ => 0.0,
        });
        let by = raw_estimate_by_time(&b, &plus, &q, &qp);
        assert_eq!(&by[..2], &[0.0, 0.0], "{by:?}");
        assert!(by.windows(2).all(|w| w[1] >= w[0]) && by[4] > by[2], "{by:?}");
        let whole = (&q - &qp).mapv(|v| v * v).sum().sqrt() / qp.mapv(|v| v * v).sum().sqrt();
        assert!((by[4] - whole).abs() < 1e-14, "{} vs {whole}", by[4]);
        assert_eq!(by[4], raw_estimate_reduced(&b, &plus, &q, &qp));
    }

    /// The distance and the norm are the Frobenius ones (3-4-5 numbers), and the same bits
    /// for row- and column-major copies of the same arrays (the full run keeps q
    /// column-major, a file or a reduced run row-major).
    #[test]
    fn distance_and_norm_do_not_depend_on_the_layout() {
        let b = ndarray::array![[3.0, 0.0], [0.0, 4.0]];
        assert_eq!(distance_and_norm(&Array2::zeros((2, 2)), &b), (5.0, 5.0));
        let b = Array2::from_shape_fn((7, 33), |(i, k)| (0.3 * i as f64 + 0.17 * k as f64).sin() * 1e3);
        let a = Array2::from_shape_fn((7, 33), |(i, k)| b[[i, k]] + 1e-3 * ((i * k) as f64).cos());
        let f = |x: &Array2<f64>| {
            let mut y = Array2::zeros(ndarray::ShapeBuilder::f(x.dim()));
            y.assign(x);
            y
        };
        let (af, bf) = (f(&a), f(&b));
        assert!(af.as_slice().is_none() && af.t().as_slice().is_some(), "column-major copy");
        let bits = |(d, n): (f64, f64)| (d.to_bits(), n.to_bits());
        assert_eq!(bits(distance_and_norm(&a, &b)), bits(distance_and_norm(&af, &bf)));
        assert_eq!(bits(distance_and_norm(&a, &b)), bits(distance_and_norm(&af, &b)));
    }

    /// rel_error over growing prefixes; the last one is the whole run's.
    #[test]
    fn rel_error_by_time_ends_with_the_whole_run() {
        let b = Array2::from_shape_fn((3, 10), |(i, k)| 1.0 + i as f64 + k as f64);
        let a = Array2::from_shape_fn((3, 10), |(i, k)| b[[i, k]] + if k >= 8 { 0.5 } else { 0.0 });
        let r = rel_error_by_time(&a, &b);
        assert_eq!(r.len(), 5);
        assert!(r[..4].iter().all(|&v| v == 0.0), "{r:?}");
        let whole = (&a - &b).mapv(|v| v * v).sum().sqrt() / b.mapv(|v| v * v).sum().sqrt();
        assert!((r[4] - whole).abs() < 1e-15);
        assert!(
            is_extrapolated((0.5, 1.5), 1.6) && is_extrapolated((0.5, 1.5), 0.49) && !is_extrapolated((0.5, 1.5), 1.5)
        );
    }
}
