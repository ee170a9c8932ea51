//! A box of parameters ([`ParameterSpace`]): for each parameter a range and a scale
//! (linear or logarithmic), as the pipeline's `[parameters]` table gives them; the training
//! points drawn from it, and which parameters a run's `μ` takes outside it.
//!
//! Points are drawn in the unit cube `[0, 1)^d` and mapped to the box per parameter,
//!
//! ```text
//!     linear:  μ_i = a_i + u_i (b_i − a_i)
//!     log:     μ_i = a_i (b_i / a_i)^u_i
//! ```
//!
//! so that parameters of different units weigh alike. Sobol points are the Owen-scrambled
//! sequence of Burley (2020) (`sobol_burley`, seeded); Latin hypercube points put one point
//! in each of `n` equal slices of every axis, slices paired at random; random points are
//! uniform. The random streams are ChaCha8 from the seed, the same on every platform.

use super::parameters::{Parameters, LOAD_SCALE};
use crate::error::{show_number, Error, Result};
use rand_chacha::rand_core::{RngCore, SeedableRng};

/// How a parameter's range is spanned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Spacing {
    /// evenly in the value
    #[default]
    Linear,
    /// evenly in the logarithm of the value (a range of positive values)
    Log,
}

impl Spacing {
    pub fn name(self) -> &'static str {
        match self {
            Spacing::Linear => "linear",
            Spacing::Log => "log",
        }
    }
}

/// One parameter's range.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterRange {
    pub name: String,
    pub lower: f64,
    pub upper: f64,
    pub spacing: Spacing,
}

impl ParameterRange {
    /// Refuses a range no sample can be drawn from: non-finite ends, `lower ≥ upper`, or a
    /// logarithmic range that does not lie above zero.
    pub fn validate(&self) -> Result<()> {
        let (a, b) = (self.lower, self.upper);
        if !(a.is_finite() && b.is_finite() && a < b) {
            return Err(Error::usage(format!("range [{a}, {b}] must be finite with lower < upper")));
        }
        if self.spacing == Spacing::Log && a <= 0.0 {
            return Err(Error::usage(format!("range [{a}, {b}] with scale = \"log\" must lie above zero")));
        }
        Ok(())
    }

    /// The value at `u ∈ [0, 1]` of the range (the module's mapping).
    pub fn at(&self, u: f64) -> f64 {
        match self.spacing {
            Spacing::Linear => self.lower + u * (self.upper - self.lower),
            Spacing::Log => self.lower * (self.upper / self.lower).powf(u),
        }
    }

    /// The inverse of [`Self::at`]: where `x` lies in the range's unit interval (outside
    /// [0, 1] for a value outside the range).
    pub fn unit(&self, x: f64) -> f64 {
        match self.spacing {
            Spacing::Linear => (x - self.lower) / (self.upper - self.lower),
            Spacing::Log => (x / self.lower).ln() / (self.upper / self.lower).ln(),
        }
    }

    /// Whether `x` lies outside the range by more than round-off (1e-9 of the larger end).
    pub fn excludes(&self, x: f64) -> bool {
        let slack = 1e-9 * self.lower.abs().max(self.upper.abs()).max(1e-300);
        !(x >= self.lower - slack && x <= self.upper + slack)
    }
}

/// How training points are drawn from the box.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    /// Owen-scrambled Sobol points (low discrepancy: the box is covered evenly at any count)
    #[default]
    Sobol,
    /// Latin hypercube: every axis cut into `n` slices, one point in each
    Lhs,
    /// independent uniform points
    Random,
}

/// The most Sobol points one sample holds (`sobol_burley`'s sequence length, 2¹⁶).
pub const MAX_SOBOL_POINTS: usize = 1 << 16;

/// `x` to four significant digits ([`show_number`] of the rounded value): 1.315, 0.2086, 2e8.
pub fn short_number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return show_number(x);
    }
    // scaled by an exact power of ten either way, so 2e8 stays 2e8
    let e = 3 - x.abs().log10().floor() as i32;
    let k = 10f64.powi(e.abs());
    show_number(if e >= 0 { (x * k).round() / k } else { (x / k).round() * k })
}

/// The points around `u` (unit-cube coordinates): in each of the 2ᵈ orthants about `u`
/// (a point counts on the upper side of an axis where its coordinate is ≥ `u`'s), the
/// nearest point there (Euclidean distance), `skip` left out; in index order. What a point of
/// a box reads from the candidates about it: on a line the two that bracket it, on a face of
/// the box the candidates on that face as well as those inside — where the `d + 1` nearest
/// can all lie on one side of it.
pub fn around(points: &[Vec<f64>], u: &[f64], skip: Option<usize>) -> Vec<usize> {
    let d2 = |v: &[f64]| u.iter().zip(v).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
    let mut best: std::collections::BTreeMap<Vec<bool>, (f64, usize)> = std::collections::BTreeMap::new();
    for (j, p) in points.iter().enumerate().filter(|&(j, _)| Some(j) != skip) {
        let side: Vec<bool> = p.iter().zip(u).map(|(c, x)| c >= x).collect();
        let dist = d2(p);
        let e = best.entry(side).or_insert((dist, j));
        if dist < e.0 {
            *e = (dist, j);
        }
    }
    let mut out: Vec<usize> = best.into_values().map(|(_, j)| j).collect();
    out.sort_unstable();
    out
}

/// The `k` points of `points` (unit-cube coordinates) nearest to `u` (Euclidean distance),
/// nearest first, `skip` left out.
pub fn nearest(points: &[Vec<f64>], u: &[f64], k: usize, skip: Option<usize>) -> Vec<usize> {
    let d2 = |v: &[f64]| u.iter().zip(v).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
    let mut order: Vec<usize> = (0..points.len()).filter(|&j| Some(j) != skip).collect();
    order.sort_by(|&a, &b| d2(&points[a]).total_cmp(&d2(&points[b])));
    order.truncate(k);
    order
}

/// The box of a pipeline's `[parameters]`, parameters in name order.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ParameterSpace {
    pub ranges: Vec<ParameterRange>,
}

impl ParameterSpace {
    pub fn is_empty(&self) -> bool {
        self.ranges.is_empty()
    }

    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.ranges.iter().map(|r| r.name.as_str())
    }

    /// The parameters at the unit-cube point `u` (one coordinate per range); `λ` is 1
    /// unless the box holds it.
    pub fn at(&self, u: &[f64]) -> Parameters {
        self.ranges.iter().zip(u).fold(Parameters::default(), |mu, (r, &x)| mu.with(&r.name, r.at(x)))
    }

    /// Where `mu` lies in the unit cube ([`ParameterRange::unit`]; a parameter `mu` does not
    /// set counts as 1).
    pub fn unit_of(&self, mu: &Parameters) -> Vec<f64> {
        self.ranges.iter().map(|r| r.unit(mu.get(&r.name).unwrap_or(1.0))).collect()
    }

    /// `n` points of the box drawn by `sampling` from `seed`.
    pub fn sample(&self, n: usize, sampling: Sampling, seed: u64) -> Vec<Parameters> {
        self.sample_unit(n, sampling, seed).iter().map(|u| self.at(u)).collect()
    }

    /// [`Self::sample`]'s points in the unit cube (one coordinate per range, in `[0, 1)`),
    /// where parameters of different units weigh alike.
    pub fn sample_unit(&self, n: usize, sampling: Sampling, seed: u64) -> Vec<Vec<f64>> {
        let d = self.ranges.len();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        // uniform in [0, 1) from 53 random bits
        let mut uniform = move || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let cube: Vec<Vec<f64>> = match sampling {
            Sampling::Sobol => (0..n)
                .map(|i| (0..d).map(|j| sobol_burley::sample(i as u32, j as u32, seed as u32) as f64).collect())
                .collect(),
            Sampling::Random => (0..n).map(|_| (0..d).map(|_| uniform()).collect()).collect(),
            Sampling::Lhs => {
                let mut cube = vec![vec![0.0; d]; n];
                for j in 0..d {
                    // a random permutation of the slices (Fisher–Yates), a random point in each
                    let mut slices: Vec<usize> = (0..n).collect();
                    for i in (1..n).rev() {
                        let k = (uniform() * (i + 1) as f64) as usize;
                        slices.swap(i, k.min(i));
                    }
                    for (i, s) in slices.into_iter().enumerate() {
                        cube[i][j] = (s as f64 + uniform()) / n as f64;
                    }
                }
                cube
            }
        };
        cube
    }

    /// The parameters of `mu` outside what a basis trained on this box covers, one line
    /// each (`drive = 1.7 (trained over [0.5, 1.5])`): a parameter of the box outside its
    /// range, and a named parameter the box does not hold set to anything but 1 (training
    /// kept it at the model file's load). `λ` outside the box is said by the load-scale
    /// checks when the box does not hold it.
    pub fn outside(&self, mu: &Parameters) -> Vec<String> {
        self.outside_of(mu, true, &|_| None)
    }

    /// [`Self::outside`] without the load scale (the range checks of λ say that one).
    pub fn outside_named(&self, mu: &Parameters) -> Vec<String> {
        self.outside_of(mu, false, &|_| None)
    }

    /// Whether `mu` lies in the box: each of its parameters within its range (one `mu` does
    /// not set counts as 1). Parameters the box does not hold are not looked at (a
    /// calibration over the box reads its position in the box alone).
    pub fn holds(&self, mu: &Parameters) -> bool {
        self.ranges.iter().all(|r| !r.excludes(mu.get(&r.name).unwrap_or(1.0)))
    }

    /// [`Self::outside_named`] for a model some of whose parameters are bodies' properties:
    /// `file_value(name)` is the value such a parameter has where μ does not set it (the
    /// model file's modulus or density; `None` for a load's factor, 1), the value a box
    /// that does not hold it was trained at.
    pub fn outside_named_of(&self, mu: &Parameters, file_value: &dyn Fn(&str) -> Option<f64>) -> Vec<String> {
        self.outside_of(mu, false, file_value)
    }

    fn outside_of(
        &self,
        mu: &Parameters,
        with_load_scale: bool,
        file_value: &dyn Fn(&str) -> Option<f64>,
    ) -> Vec<String> {
        let mut out = Vec::new();
        for r in self.ranges.iter().filter(|r| with_load_scale || r.name != LOAD_SCALE) {
            let x = mu.get(&r.name).or_else(|| file_value(&r.name)).unwrap_or(1.0);
            if r.excludes(x) {
                out.push(format!(
                    "{} = {} (trained over [{}, {}])",
                    r.name,
                    show_number(x),
                    show_number(r.lower),
                    show_number(r.upper)
                ));
            }
        }
        for (name, x) in mu.named() {
            let (trained, what) = match file_value(name) {
                Some(v) => (v, "value"),
                None => (1.0, "load"),
            };
            if x != trained && !self.names().any(|n| n == name) {
                out.push(format!(
                    "{name} = {} (trained at {}, the model file's {what})",
                    show_number(x),
                    show_number(trained)
                ));
            }
        }
        out
    }

    /// The neighbouring point of a sensitivity check: every parameter of the box times
    /// `factor` (λ alone for an empty box, as a line of load scales moves it). A parameter
    /// at 0 (a moment's range [−1, 1] at its centre) moves by `factor − 1` of its range's
    /// larger end instead, so that the check sees it too.
    pub fn moved(&self, mu: &Parameters, factor: f64) -> Parameters {
        if self.is_empty() {
            return mu.scaled_by(factor);
        }
        self.ranges.iter().fold(mu.clone(), |m, r| {
            let x = mu.get(&r.name).unwrap_or(1.0);
            let to = if x == 0.0 { (factor - 1.0) * r.lower.abs().max(r.upper.abs()) } else { x * factor };
            m.with(&r.name, to)
        })
    }

    /// `drive = 1.1, E = 2.5e8`: the point `mu` as messages name it, the box's parameters
    /// to four significant digits (drawn points have sixteen; files keep them).
    pub fn label(&self, mu: &Parameters) -> String {
        let one = |n: &str| format!("{n} = {}", short_number(mu.get(n).unwrap_or(1.0)));
        self.names().map(one).collect::<Vec<_>>().join(", ")
    }

    /// `drive ∈ [0.5, 1.5], E ∈ [1e8, 4e8] (log)`: the box as messages name it.
    pub fn describe(&self) -> String {
        let one = |r: &ParameterRange| {
            format!(
                "{} ∈ [{}, {}]{}",
                r.name,
                show_number(r.lower),
                show_number(r.upper),
                if r.spacing == Spacing::Log { " (log)" } else { "" }
            )
        };
        self.ranges.iter().map(one).collect::<Vec<_>>().join(", ")
    }

    /// The range of the parameter `name`, if the box holds it.
    pub fn range(&self, name: &str) -> Option<&ParameterRange> {
        self.ranges.iter().find(|r| r.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn space() -> ParameterSpace {
        ParameterSpace {
            ranges: vec![
                ParameterRange { name: "drive".into(), lower: 0.5, upper: 1.5, spacing: Spacing::Linear },
                ParameterRange { name: "stiff".into(), lower: 1e8, upper: 4e8, spacing: Spacing::Log },
            ],
        }
    }

    #[test]
    fn the_unit_cube_maps_onto_each_range_by_its_scale() {
        // the ends and the middle: linear midpoint 1.0; log midpoint the geometric mean
        // √(1e8 · 4e8) = 2e8
        let s = space();
        let mid = s.at(&[0.5, 0.5]);
        assert_eq!(mid.get("drive"), Some(1.0));
        assert!((mid.get("stiff").unwrap() - 2e8).abs() < 1e-6 * 2e8);
        assert_eq!(s.at(&[0.0, 0.0]).get("stiff"), Some(1e8));
        assert_eq!(s.at(&[1.0, 0.0]).get("drive"), Some(1.5));
        assert_eq!(mid.scale(), 1.0, "λ stays 1 when the box does not hold it");
        // and back: unit_of inverts at (to round-off), also beyond the box
        for u in [[0.0, 0.0], [0.25, 0.75], [1.0, 1.0], [1.5, -0.5]] {
            let back = s.unit_of(&s.at(&u));
            assert!(back.iter().zip(u).all(|(a, b)| (a - b).abs() < 1e-12), "{u:?} → {back:?}");
        }
    }

    #[test]
    fn every_sampling_stays_in_the_box_and_is_reproducible_from_its_seed() {
        let s = space();
        for sampling in [Sampling::Sobol, Sampling::Lhs, Sampling::Random] {
            let a = s.sample(16, sampling, 7);
            assert_eq!(a, s.sample(16, sampling, 7), "{sampling:?}: not reproducible");
            assert_ne!(a, s.sample(16, sampling, 8), "{sampling:?}: the seed is not used");
            for mu in &a {
                assert!(s.outside(mu).is_empty(), "{sampling:?}: {mu} left the box");
            }
        }
        // Latin hypercube: exactly one point in each of the 16 slices of every axis
        let lhs = s.sample(16, Sampling::Lhs, 3);
        for r in &s.ranges {
            let mut slices: Vec<usize> = lhs
                .iter()
                .map(|mu| {
                    let x = mu.get(&r.name).unwrap();
                    let u = match r.spacing {
                        Spacing::Linear => (x - r.lower) / (r.upper - r.lower),
                        Spacing::Log => (x / r.lower).ln() / (r.upper / r.lower).ln(),
                    };
                    (u * 16.0).floor() as usize
                })
                .collect();
            slices.sort_unstable();
            assert_eq!(slices, (0..16).collect::<Vec<_>>(), "{}", r.name);
        }
        // Sobol: the first 4 points of a scrambled 2-D Sobol sequence fall one in each
        // quadrant of the unit square (its (0, 2)-net property, Owen scrambling keeps it)
        let sobol = s.sample(4, Sampling::Sobol, 11);
        let mut quadrants: Vec<(bool, bool)> = sobol
            .iter()
            .map(|mu| (mu.get("drive").unwrap() >= 1.0, mu.get("stiff").unwrap() >= 2e8 * (1.0 - 1e-12)))
            .collect();
        quadrants.sort_unstable();
        assert_eq!(quadrants, [(false, false), (false, true), (true, false), (true, true)]);
    }

    #[test]
    fn outside_names_each_parameter_that_left_the_box() {
        let s = space();
        let mu = Parameters::default().with("drive", 1.7).with("stiff", 2e8).with("other", 0.5);
        let out = s.outside(&mu);
        assert_eq!(out, ["drive = 1.7 (trained over [0.5, 1.5])", "other = 0.5 (trained at 1, the model file's load)"]);
        // the load scale is left to its own range check where asked
        let with_lambda = ParameterSpace {
            ranges: vec![ParameterRange { name: LOAD_SCALE.into(), lower: 0.5, upper: 1.5, spacing: Spacing::Linear }],
        };
        assert_eq!(with_lambda.outside(&Parameters::load_scale(2.0)), ["load_scale = 2 (trained over [0.5, 1.5])"]);
        assert!(with_lambda.outside_named(&Parameters::load_scale(2.0)).is_empty());
        // round-off at an end is inside
        assert!(s.outside(&Parameters::default().with("drive", 1.5 * (1.0 + 1e-12)).with("stiff", 4e8)).is_empty());
        // a body's property is trained at the model file's value: unset, it reads that
        // value (inside the box), and set outside a box that does not hold it, it is named
        // against that value, not against 1
        let file_value = |name: &str| match name {
            "stiff" => Some(2e8),
            "rho" => Some(2700.0),
            _ => None,
        };
        assert!(s.outside_named_of(&Parameters::default().with("drive", 1.0), &file_value).is_empty());
        assert_eq!(s.outside_named(&Parameters::default().with("drive", 1.0)), ["stiff = 1 (trained over [1e8, 4e8])"]);
        assert!(s.outside_named_of(&Parameters::default().with("rho", 2700.0), &file_value).is_empty());
        assert_eq!(
            s.outside_named_of(&Parameters::default().with("rho", 1.0), &file_value),
            ["rho = 1 (trained at 2700, the model file's value)"]
        );
        assert!(ParameterRange { name: "x".into(), lower: 0.0, upper: 1.0, spacing: Spacing::Log }.validate().is_err());
        assert!(ParameterRange { name: "x".into(), lower: 1.0, upper: 1.0, spacing: Spacing::Linear }
            .validate()
            .is_err());
    }

    /// The sensitivity's neighbour moves every box parameter by the step, relatively — and a
    /// parameter at 0 by the step times its range's larger end (|−2| here), which a
    /// relative step would leave where it was.
    #[test]
    fn moved_moves_every_parameter_even_at_zero() {
        let s = ParameterSpace {
            ranges: vec![
                ParameterRange { name: "drive".into(), lower: 0.5, upper: 1.5, spacing: Spacing::Linear },
                ParameterRange { name: "pin".into(), lower: -2.0, upper: 1.0, spacing: Spacing::Linear },
            ],
        };
        let m = s.moved(&Parameters::default().with("drive", 1.2).with("pin", 0.0), 1.001);
        assert_eq!(m.get("drive"), Some(1.2 * 1.001));
        assert_eq!(m.get("pin"), Some((1.001 - 1.0) * 2.0));
        let m = s.moved(&Parameters::default().with("drive", 1.2).with("pin", -0.5), 1.001);
        assert_eq!(m.get("pin"), Some(-0.5 * 1.001));
    }

    /// The points around a point: the nearest in each orthant. On a line, 0.35 among 0, 0.2,
    /// 0.4, 0.9 reads 0.2 and 0.4 (the two that bracket it); on the square's upper face at
    /// (0.8, 1), with the corner (1, 1), the face's centre (0.5, 1) and three points inside
    /// just below it, it reads both face points and the nearest inside on each side, where
    /// its three nearest, (0.84, 0.97), (0.72, 0.88), (0.8, 0.85), all lie below it.
    #[test]
    fn around_reads_the_nearest_on_every_side() {
        let line: Vec<Vec<f64>> = [0.0, 0.2, 0.4, 0.9].iter().map(|&x| vec![x]).collect();
        assert_eq!(around(&line, &[0.35], None), vec![1, 2]);
        assert_eq!(around(&line, &[0.35], Some(2)), vec![1, 3]);
        assert_eq!(around(&line, &[1.2], None), vec![3], "beyond the end: the end");
        let square = vec![vec![1.0, 1.0], vec![0.5, 1.0], vec![0.84, 0.97], vec![0.72, 0.88], vec![0.8, 0.85]];
        let u = [0.8, 1.0];
        assert_eq!(nearest(&square, &u, 3, None), vec![2, 3, 4]);
        assert_eq!(around(&square, &u, None), vec![0, 1, 2, 3]);
    }
}
