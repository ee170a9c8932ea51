//! The error estimator of a reduced basis, as the basis file stores it under `/estimator`
//! (`crate::io::estimator_file`): the *enriched* basis `V⁺` (the same POD with `k` more
//! modes per block) and the calibration constant `c` of
//!
//! ```text
//!     error_estimate = c · ‖X_r − X_{r+k}‖_F / ‖X_{r+k}‖_F
//! ```
//!
//! How it is built, calibrated and run is `crate::rom::estimator`'s.

use super::basis::Basis;
use crate::error::{Error, Result};
use crate::solver::parameter_space::ParameterSpace;
use crate::solver::parameters::Parameters;

/// Estimates and errors are reported over the instants up to the end of each fifth of the
/// run (how the error grows in time; the last entry is the whole run's).
pub const FIFTHS: usize = 5;
/// One value per fifth of the run ([`FIFTHS`]).
pub type ByFifth = [f64; FIFTHS];

/// `c` without calibration data (1.5 covered every test load on both benchmark models with
/// effectivity 1.1–1.5 when the estimate was first probed, docs/error-estimate.md).
pub const DEFAULT_FACTOR: f64 = 1.5;

/// What the basis file stores under `/estimator`.
#[derive(Clone, Debug)]
pub struct Estimator {
    /// `V⁺`: same variant, reference and kept coordinates as the basis, `k` more POD modes
    /// per block; its own ECSW set when the basis is hyper-reduced
    pub enriched: Basis,
    /// POD modes per block of `V⁺`
    pub block_modes: Vec<usize>,
    /// `k` requested per block (capped by the rank of each block's snapshots)
    pub extra_modes: usize,
    pub calibration: Calibration,
    /// the `defects` method put on the `corrected` one's scale, per fifth of the run and
    /// load (greedy training: [`DefectsCalibration`]); `None`: the defect sum is used as
    /// the bound it is where the dynamics do not amplify differences
    pub defects: Option<DefectsCalibration>,
    /// the method training chose for this basis's online estimates (the basis file's
    /// `/estimator@default_method`); `None`: the rule of [`Estimator::default_method`]
    pub method: Option<EstimateMethod>,
}

/// How the cheap `defects` estimate is put on the scale of the `corrected` one: at the
/// candidate loads `λ_j` of greedy training both are computed from the same reduced run,
///
/// ```text
///     ρ_ji = corrected_i(λ_j) / defects_raw_i(λ_j)          (fifth i of the run)
/// ```
///
/// and an online `defects` estimate at λ is `f_i(λ) · defects_raw_i` with `f_i` the ratio
/// interpolated linearly between the candidates around λ: at a candidate exactly the
/// corrected estimate, between two what the ratio's trend says, outside the candidates the
/// largest ratio of all (`factors`). The ratio is the model's own: where the dynamics do not amplify
/// differences the defect sum overestimates (ρ ≈ 0.03–0.5), where they do (the four-bar
/// after t ≈ 0.7 s) it can read below the corrected estimate (ρ up to ≈ 4), and a
/// single constant would be loose at some loads or low at others.
///
/// Whether the rule holds for a model is checked on the candidates themselves, leaving each
/// interior one out: its ratio predicted from its two neighbours (the mean: the linear
/// interpolation over twice the spacing online runs see) must reach `ρ_ji /
/// DEFAULT_FACTOR` — the corrected estimate without its margin, i.e. about the true error —
/// at ≥ [`DEFECTS_RELIABLE_SHARE`] of them, in every fifth. Where it does (`reliable`), `defects` is the default online estimate; where the
/// ratio jumps between neighbours (the four-bar's chaotic last fifths) it is not, and the
/// default stays `corrected`.
#[derive(Clone, Debug, PartialEq)]
pub struct DefectsCalibration {
    /// the candidate loads, ascending; empty for scattered candidates (a parameter box:
    /// [`Self::scattered`])
    pub load_scales: Vec<f64>,
    /// `ρ_ji` (loads × 5); NaN where either estimate was not finite and positive
    pub ratios: Vec<ByFifth>,
    /// the largest ratio of each fifth
    pub factors: ByFifth,
    /// the leave-one-out check passed
    pub reliable: bool,
    /// scattered candidates (a parameter box): where they lie ([`Self::scattered`])
    pub scattered: Option<Scattered>,
    /// the same calibration for each probe quantity's estimate (its key `quantity:probe`,
    /// e.g. `curvature:root`), from the whole run's ratio at the same candidates (every
    /// fifth holding it): the defect sum reads a quantity on a scale of its own — on a
    /// clamped arm 0.6–0.8 of the corrected estimate where the coordinates read 1, on a
    /// spun-up beam's root curvature 150–290 (docs/error-estimate.md)
    pub quantities: Vec<(String, DefectsCalibration)>,
}

/// Where scattered candidates lie: the box and each candidate in its unit cube, in the
/// order of [`DefectsCalibration::ratios`].
#[derive(Clone, Debug, PartialEq)]
pub struct Scattered {
    pub space: ParameterSpace,
    pub unit: Vec<Vec<f64>>,
}

impl Scattered {
    /// The candidates around the unit-cube point `u`, the nearest in each orthant (on a line
    /// the two that bracket it: [`crate::solver::parameter_space::around`]), `skip` left out.
    fn around(&self, u: &[f64], skip: Option<usize>) -> Vec<usize> {
        crate::solver::parameter_space::around(&self.unit, u, skip)
    }
}

/// The share of interior candidates whose left-out ratio must be predicted well enough
/// (the coverage the estimate is held to per fifth of the run, 90 %).
pub const DEFECTS_RELIABLE_SHARE: f64 = 0.9;

impl DefectsCalibration {
    /// From the ratios at the candidates; `None` when some fifth has no usable ratio.
    pub fn new(load_scales: Vec<f64>, ratios: Vec<ByFifth>) -> Option<Self> {
        let mut factors = [0.0_f64; FIFTHS];
        for (i, f) in factors.iter_mut().enumerate() {
            *f = ratios.iter().map(|r| r[i]).filter(|x| usable(*x)).fold(f64::NAN, f64::max);
            if !f.is_finite() {
                return None;
            }
        }
        let reliable = leave_one_out(&ratios);
        Some(DefectsCalibration { load_scales, ratios, factors, reliable, scattered: None, quantities: Vec::new() })
    }

    /// With the probe quantities' calibrations: `keys` (`quantity:probe`) and their whole-run
    /// ratios at the same candidates (`ratios[j][q]`: candidate j, quantity q), each
    /// calibrated as the coordinates are ([`Self::new`] or [`Self::scattered`] with the ratio
    /// in every fifth); a quantity without a usable ratio has none.
    pub fn with_quantities(mut self, keys: &[String], ratios: &[Vec<f64>]) -> Self {
        self.quantities = keys
            .iter()
            .enumerate()
            .filter_map(|(q, key)| {
                let r: Vec<ByFifth> =
                    ratios.iter().map(|row| [row.get(q).copied().unwrap_or(f64::NAN); FIFTHS]).collect();
                let c = match &self.scattered {
                    Some(s) => Self::scattered(s.space.clone(), s.unit.clone(), r),
                    None => Self::new(self.load_scales.clone(), r),
                };
                c.map(|c| (key.clone(), c))
            })
            .collect();
        self
    }

    /// The factor of the quantity `key`'s whole-run defect sum at `mu`: interpolated where
    /// its calibration passed its check, else its largest ratio; `None` without one.
    pub fn quantity_factor(&self, key: &str, mu: &Parameters) -> Option<f64> {
        let (_, c) = self.quantities.iter().find(|(k, _)| k == key)?;
        Some(if c.reliable { c.factors_at(mu)[FIFTHS - 1] } else { c.factors[FIFTHS - 1] })
    }

    /// From the ratios at scattered candidates (points `unit` of the box `space`'s unit
    /// cube, no order to interpolate along): a point reads, fifth by fifth, the largest
    /// ratio of the candidates around it, the nearest in each orthant (on a line: the two
    /// that bracket it, the larger of the two where [`Self::new`] interpolates), and the leave-one-out check asks
    /// that this reading from the *other* candidates reach `ρ_ji / DEFAULT_FACTOR` at ≥
    /// [`DEFECTS_RELIABLE_SHARE`] of the candidates, in every fifth. `load_scales` is
    /// empty. `None` as [`Self::new`].
    pub fn scattered(space: ParameterSpace, unit: Vec<Vec<f64>>, ratios: Vec<ByFifth>) -> Option<Self> {
        let mut c = Self::new(Vec::new(), ratios)?;
        let s = Scattered { space, unit };
        c.reliable = c.ratios.len() >= 3
            && (0..FIFTHS).all(|i| {
                let n = c.ratios.len();
                let passed = (0..n)
                    .filter(|&j| {
                        // no usable neighbour is a failed prediction: the global factor
                        // would include the left-out ratio itself
                        let own = c.ratios[j][i];
                        usable(own)
                            && c.largest_usable(&s.around(&s.unit[j], Some(j)), i)
                                .is_some_and(|r| r >= own / DEFAULT_FACTOR)
                    })
                    .count();
                passed as f64 >= DEFECTS_RELIABLE_SHARE * n as f64
            });
        c.scattered = Some(s);
        Some(c)
    }

    /// The largest usable ratio of fifth `i` among the candidates `js` (the largest of all
    /// when none is usable).
    fn largest(&self, js: &[usize], i: usize) -> f64 {
        self.largest_usable(js, i).unwrap_or(self.factors[i])
    }

    /// The largest usable ratio of fifth `i` among the candidates `js`, if any is usable.
    fn largest_usable(&self, js: &[usize], i: usize) -> Option<f64> {
        js.iter().map(|&j| self.ratios[j][i]).filter(|x| usable(*x)).reduce(f64::max)
    }

    /// `f_i(λ)` at the parameters `mu` (the type's documentation).
    pub fn factors_at(&self, mu: &Parameters) -> ByFifth {
        if let Some(s) = &self.scattered {
            // outside the box, as beyond a line's ends, no candidate brackets the point
            if !s.space.holds(mu) {
                return self.factors;
            }
            let near = s.around(&s.space.unit_of(mu), None);
            return std::array::from_fn(|i| self.largest(&near, i));
        }
        let load_scale = mu.scale();
        let l = &self.load_scales;
        let j = l.partition_point(|&x| x <= load_scale);
        if l.len() < 2 || j == 0 || (j == l.len() && l[j - 1] != load_scale) {
            return self.factors;
        }
        // the interval [λ_k, λ_(k+1)] holding λ (the last one for the last candidate)
        let k = (j - 1).min(l.len() - 2);
        let width = l[k + 1] - l[k];
        if !(width > 0.0) {
            // not ascending (a basis file checks this when read): no interpolation
            return self.factors;
        }
        let w = (load_scale - l[k]) / width;
        std::array::from_fn(|i| {
            let (a, b) = (self.ratios[k][i], self.ratios[k + 1][i]);
            if usable(a) && usable(b) {
                a + w * (b - a)
            } else {
                self.factors[i]
            }
        })
    }
}

fn usable(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

/// The leave-one-out check of [`DefectsCalibration`]: false with fewer than three loads.
fn leave_one_out(ratios: &[ByFifth]) -> bool {
    let n = ratios.len();
    if n < 3 {
        return false;
    }
    (0..FIFTHS).all(|i| {
        let passed = (1..n - 1)
            .filter(|&j| {
                let (a, b, own) = (ratios[j - 1][i], ratios[j + 1][i], ratios[j][i]);
                usable(a) && usable(b) && usable(own) && 0.5 * (a + b) >= own / DEFAULT_FACTOR
            })
            .count();
        passed as f64 >= DEFECTS_RELIABLE_SHARE * (n - 2) as f64
    })
}

impl Estimator {
    /// The online method when the pipeline names none: the one training chose, else
    /// `defects` where greedy training calibrated it and the calibration passed its check,
    /// else `corrected`.
    pub fn default_method(&self) -> EstimateMethod {
        if let Some(m) = self.method {
            return m;
        }
        if self.defects.as_ref().is_some_and(|d| d.reliable) {
            EstimateMethod::Defects
        } else {
            EstimateMethod::Corrected
        }
    }
}

/// One held-out load: the raw estimate of a basis there and its true `rel_error`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CalibrationPoint {
    pub load_scale: f64,
    pub raw_estimate: f64,
    pub rel_error: f64,
}

/// One held-out load's reading of one probe quantity or joint reaction (its key
/// `quantity:probe`): the raw estimate of a basis there and the true error over the
/// quantity's range.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct QuantityPoint {
    pub key: String,
    pub raw_estimate: f64,
    pub error: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Calibration {
    /// `c`
    pub factor: f64,
    /// false: [`DEFAULT_FACTOR`], no usable held-out data
    pub calibrated: bool,
    pub points: Vec<CalibrationPoint>,
    /// `c_q` of each probe quantity and reaction the held-out runs measured (key
    /// `quantity:probe`), never below `c`; a quantity not listed reads `c`
    pub quantities: Vec<(String, f64)>,
}

impl Default for Calibration {
    fn default() -> Self {
        Calibration { factor: DEFAULT_FACTOR, calibrated: false, points: Vec::new(), quantities: Vec::new() }
    }
}

impl Calibration {
    /// `c_q / c` of the quantity `key`: how much more than the coordinates' factor its raw
    /// estimate is multiplied by; 1 for a quantity without its own calibration.
    pub fn quantity_scale(&self, key: &str) -> f64 {
        self.quantities.iter().find(|(k, _)| k == key).map_or(1.0, |(_, c)| c / self.factor)
    }
}

/// How the enriched model's trajectory `X⁺` is obtained (docs/error-estimate.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EstimateMethod {
    /// one Newton iteration of the enriched model per step, from the reduced run's
    /// increments (`rom::estimator::corrected`); ≈ 1.5× the error at 45–130 % of
    /// the reduced run; what training (greedy steering, calibration) uses, so that an
    /// online estimate reads on the scale of the training tolerance. The default online
    /// estimate unless greedy training calibrated `Defects` reliably (`DefectsCalibration`)
    #[default]
    Corrected,
    /// the enriched model integrated on its own to convergence (about 2× the reduced run)
    Enriched,
    /// the cheap method: the reduced run's local defects against the enriched model at
    /// every 10th step, summed (`rom::estimator::defects`), 7–16 % of the reduced run.
    /// Uncalibrated a loose bound (1.2–46× the error measured); calibrated by greedy training
    /// ([`DefectsCalibration`]) the corrected estimate's reading at its candidates, and
    /// then the online default where its leave-one-out check passed (docs/error-estimate.md)
    Defects,
}

impl EstimateMethod {
    /// Every method, in the order the front ends list them.
    pub const ALL: [EstimateMethod; 3] = [EstimateMethod::Corrected, EstimateMethod::Enriched, EstimateMethod::Defects];

    pub fn name(self) -> &'static str {
        match self {
            EstimateMethod::Corrected => "corrected",
            EstimateMethod::Enriched => "enriched",
            EstimateMethod::Defects => "defects",
        }
    }

    pub fn parse(s: &str) -> Result<Self> {
        match s {
            "corrected" => Ok(EstimateMethod::Corrected),
            "enriched" => Ok(EstimateMethod::Enriched),
            "defects" => Ok(EstimateMethod::Defects),
            _ => {
                Err(Error::usage(format!("is \"{s}\"; expected \"corrected\" (default), \"defects\" or \"enriched\"")))
            }
        }
    }
}

/// Which error a tolerance is on (docs/error-estimate.md, "Two measures of the error"):
///
/// ```text
///     relative:      ‖X_r − X_f‖_F / ‖X_f‖_F          (rel_error, the thesis's comparison)
///     displacement:  ‖X_r − X_f‖_F / ‖X_f − X₀‖_F     (displacement_error; X₀ the initial
///                                                      configuration at every instant)
/// ```
///
/// `‖X_f‖` holds the undeformed geometry and the unit slopes, so the relative error of a
/// run is smaller than its error against the motion itself, by as much as the motion is
/// smaller than the configuration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ErrorMeasure {
    /// `rel_error`: against the whole configuration (the default)
    #[default]
    Relative,
    /// `displacement_error`: against the displacement from the initial configuration
    Displacement,
}

impl ErrorMeasure {
    pub fn name(self) -> &'static str {
        match self {
            ErrorMeasure::Relative => "relative",
            ErrorMeasure::Displacement => "displacement",
        }
    }

    pub fn parse(s: &str) -> Result<Self> {
        match s {
            "relative" => Ok(ErrorMeasure::Relative),
            "displacement" => Ok(ErrorMeasure::Displacement),
            _ => Err(Error::usage(format!("is \"{s}\"; expected \"relative\" (default) or \"displacement\""))),
        }
    }

    /// Whether this is the default (a pipeline that leaves the key out means it).
    pub fn is_relative(&self) -> bool {
        *self == ErrorMeasure::Relative
    }

    /// The name of the true error in this measure, as `validate` reports it.
    pub fn error_name(self) -> &'static str {
        match self {
            ErrorMeasure::Relative => "rel_error",
            ErrorMeasure::Displacement => "displacement_error",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::DefectsCalibration;
    use crate::solver::parameters::Parameters;

    /// Each quantity is calibrated on its own ratios at the same candidates: at a candidate
    /// its own ratio, between two the interpolation (0.2 and 0.4 → 0.3 midway); a quantity
    /// without a usable ratio, or a key not calibrated, has no factor (no estimate).
    #[test]
    fn each_quantity_reads_its_own_ratios() {
        let r = |a: f64| [a; 5];
        let c = DefectsCalibration::new(vec![1.0, 2.0, 3.0], vec![r(0.1), r(0.3), r(0.2)]).unwrap();
        let keys = ["curvature:root".to_string(), "strain:root".to_string()];
        let c = c.with_quantities(&keys, &[vec![0.2, f64::NAN], vec![0.4, f64::NAN], vec![0.4, f64::NAN]]);
        assert_eq!(c.quantities.len(), 1, "the strain has no usable ratio");
        let at = |l: f64| c.quantity_factor("curvature:root", &Parameters::load_scale(l));
        assert_eq!(at(2.0), Some(0.4));
        assert!((at(1.5).unwrap() - 0.3).abs() < 1e-15);
        assert_eq!(c.quantity_factor("strain:root", &Parameters::load_scale(1.5)), None);
        assert_eq!(c.quantity_factor("position:tip", &Parameters::load_scale(1.5)), None);
    }

    /// At a candidate its own ratio, between two the linear interpolation, outside the
    /// candidates the largest of all; a fifth without a usable ratio anywhere gives no
    /// calibration, an unusable one in a pair the largest.
    #[test]
    fn defect_factors_interpolate_between_candidates() {
        let r = |a: f64| [a, 2.0 * a, 3.0 * a, 4.0 * a, 5.0 * a];
        let c = DefectsCalibration::new(vec![1.0, 2.0, 3.0], vec![r(0.1), r(0.3), r(0.2)]).unwrap();
        assert_eq!(c.factors, r(0.3));
        assert_eq!(c.factors_at(&Parameters::load_scale(1.0)), r(0.1));
        assert_eq!(c.factors_at(&Parameters::load_scale(2.0)), r(0.3));
        assert_eq!(c.factors_at(&Parameters::load_scale(3.0)), r(0.2));
        let mid = c.factors_at(&Parameters::load_scale(1.5));
        assert!(mid.iter().zip(r(0.2)).all(|(a, b)| (a - b).abs() < 1e-15), "{mid:?}");
        let late = c.factors_at(&Parameters::load_scale(2.75));
        assert!(late.iter().zip(r(0.225)).all(|(a, b)| (a - b).abs() < 1e-15), "{late:?}");
        assert_eq!(c.factors_at(&Parameters::load_scale(0.5)), r(0.3));
        assert_eq!(c.factors_at(&Parameters::load_scale(3.5)), r(0.3));
        let mut gap = r(0.1);
        gap[2] = f64::NAN;
        let g = DefectsCalibration::new(vec![1.0, 2.0], vec![gap, r(0.05)]).unwrap();
        assert_eq!(g.factors_at(&Parameters::load_scale(1.5))[2], r(0.05)[2]);
        assert!(DefectsCalibration::new(vec![1.0], vec![[f64::NAN; 5]]).is_none());
    }

    /// Smooth ratios pass the leave-one-out check; a ratio 1.5× above its neighbours'
    /// mean passes only at the margin (own / 1.5 = their mean), a spike of 2× fails it, as
    /// does a calibration of fewer than three loads.
    #[test]
    fn the_leave_one_out_check_refuses_jumpy_ratios() {
        let r = |a: f64| [a; 5];
        let loads = |n: usize| (0..n).map(|j| j as f64).collect::<Vec<_>>();
        let smooth: Vec<_> = (0..11).map(|j| r(0.1 + 0.01 * j as f64)).collect();
        assert!(DefectsCalibration::new(loads(11), smooth.clone()).unwrap().reliable);
        let mut edge = smooth.clone();
        edge[5] = r(1.5 * 0.15);
        assert!(DefectsCalibration::new(loads(11), edge).unwrap().reliable);
        let mut spike = smooth.clone();
        spike[5] = r(2.0 * 0.15);
        assert!(!DefectsCalibration::new(loads(11), spike).unwrap().reliable);
        assert!(!DefectsCalibration::new(loads(2), smooth[..2].to_vec()).unwrap().reliable);
    }

    /// Scattered candidates (a box, here a line of the unit cube to keep the numbers
    /// plain): a point reads the largest ratio of the two candidates that bracket it; the
    /// check passes while that reading from the others reaches own / DEFAULT_FACTOR (1.5)
    /// at 90 % of the candidates: smooth ratios 0.10 … 0.19 pass; spikes of 0.5 at 2 and 6
    /// fail (each is read from neighbours of 0.11–0.17, far below 0.5/1.5: 8 of 10 pass).
    #[test]
    fn scattered_ratios_read_their_nearest() {
        use crate::solver::parameter_space::{ParameterRange, ParameterSpace, Spacing};
        let r = |a: f64| [a; 5];
        let space = ParameterSpace {
            ranges: vec![ParameterRange { name: "p".into(), lower: 0.0, upper: 9.0, spacing: Spacing::Linear }],
        };
        let unit: Vec<Vec<f64>> = (0..10).map(|j| vec![j as f64 / 9.0]).collect();
        let calm: Vec<_> = (0..10).map(|j| r(0.1 + 0.01 * j as f64)).collect();
        let c = DefectsCalibration::scattered(space.clone(), unit.clone(), calm.clone()).unwrap();
        assert!(c.reliable && c.load_scales.is_empty());
        // p = 3.4 lies between the candidates 3 and 4: the larger of their ratios, 0.14
        assert_eq!(c.factors_at(&Parameters::default().with("p", 3.4)), r(0.14));
        // beyond the box: the largest ratio of all (here the last candidate's, 0.19), as
        // beyond a line's ends
        assert_eq!(c.factors_at(&Parameters::default().with("p", 12.0)), r(0.19));
        assert_eq!(c.factors_at(&Parameters::default().with("p", -3.0)), r(0.19));
        let mut spike = calm;
        spike[2] = r(0.5);
        spike[6] = r(0.5);
        assert!(!DefectsCalibration::scattered(space, unit, spike).unwrap().reliable);
    }

    /// A candidate whose nearest candidates have no usable ratio is not predicted, so it
    /// fails the check: of 20 calm candidates with no ratio at 9 and 11, those two and 10
    /// (which they bracket) fail — 17 of 20 pass, below 90 %. Reading 10 from the
    /// largest ratio of all, its own among them, would have passed it (18 of 20).
    #[test]
    fn a_candidate_without_usable_neighbours_fails_the_scattered_check() {
        use crate::solver::parameter_space::{ParameterRange, ParameterSpace, Spacing};
        let space = ParameterSpace {
            ranges: vec![ParameterRange { name: "p".into(), lower: 0.0, upper: 19.0, spacing: Spacing::Linear }],
        };
        let unit: Vec<Vec<f64>> = (0..20).map(|j| vec![j as f64 / 19.0]).collect();
        let mut ratios: Vec<[f64; 5]> = (0..20).map(|j| [0.1 + 0.001 * j as f64; 5]).collect();
        ratios[9] = [f64::NAN; 5];
        ratios[11] = [f64::NAN; 5];
        assert!(!DefectsCalibration::scattered(space, unit, ratios).unwrap().reliable);
    }
}
