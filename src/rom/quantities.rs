//! The quantities engineers read off a run, probe by probe — its position (m) and, where
//! the probe records them, the axial strain (1) and the curvature (1/m; the bending moment
//! is `E I κ`) — and how far two runs of one model lie apart in each.
//!
//! A run `v` (the reduced one) is compared with a reference `w` (the full model in
//! `validate`, the enriched model in the error estimate) relative to the reference's
//! *range* over the run,
//!
//! ```text
//!     e = max_k ‖v(t_k) − w(t_k)‖ / ‖max_k w(t_k) − min_k w(t_k)‖
//! ```
//!
//! (max and min componentwise: a position's range is the diagonal of the box its path
//! spans). The range, not the value: where a quantity stays near zero — a free tip's
//! curvature — its error over its largest value reads tens of per cent for differences no
//! plot shows, while a root's bending moment errs by its share of the moment's swing, the
//! number a link is sized by. Where the reference's range lies within the quantity's
//! resolution (the Newton tolerance carried to it, [`Quantity::resolution`]) there is no
//! swing to measure against: the ratio is undefined, or ∞ where the distance is above the
//! resolution ([`against_motion`]).

use super::probes::ProbeValues;
use crate::simulate::{Series, SimulationResult};
use ndarray::{Array2, ArrayView2, Axis};

/// What a probe records.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Quantity {
    /// the point's position, m (two components)
    Position,
    /// the centre line's axial strain there, 1
    Strain,
    /// the centre line's curvature there, 1/m
    Curvature,
    /// a joint's reaction force on a node it holds, N (two components; [`crate::rom::reactions`])
    Force,
    /// a joint's reaction moment on a node it holds, N m
    Moment,
}

impl Quantity {
    /// The name files, JSON and messages use.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Position => "position",
            Quantity::Strain => "strain",
            Quantity::Curvature => "curvature",
            Quantity::Force => "force",
            Quantity::Moment => "moment",
        }
    }

    /// The unit as printed after a value (strain: none).
    pub fn unit(self) -> &'static str {
        match self {
            Quantity::Position => " m",
            Quantity::Strain => "",
            Quantity::Curvature => " 1/m",
            Quantity::Force => " N",
            Quantity::Moment => " N m",
        }
    }

    /// The quantity's resolution at the Newton tolerance `tol` of a model of length scale
    /// `length`: coordinates resolve to `tol · L`, slopes (unit vectors) to `tol`, so a
    /// position to `tol · L`, a strain to `tol`, a curvature (a slope's change over a
    /// length) to `tol / L`. A reaction's resolution depends on the model's stiffness and
    /// the reaction's size ([`crate::rom::reactions::ReactionReader::resolution`]): 0 here.
    pub fn resolution(self, tol: f64, length: f64) -> f64 {
        match self {
            Quantity::Position => tol * length,
            Quantity::Strain => tol,
            Quantity::Curvature => tol / length,
            Quantity::Force | Quantity::Moment => 0.0,
        }
    }

    /// Whether it is a joint's reaction, not a probe's quantity.
    pub fn is_reaction(self) -> bool {
        matches!(self, Quantity::Force | Quantity::Moment)
    }
}

/// One probe's quantity over a run: n_t × components.
#[derive(Clone, Debug)]
pub struct Reading<'a> {
    pub probe: &'a str,
    pub quantity: Quantity,
    pub values: ArrayView2<'a, f64>,
}

/// Every quantity the probes record, in a fixed order (all positions, then the strains,
/// then the curvatures, each in probe order), from a result's series.
pub fn readings_of<'a>(
    positions: &'a [(String, Array2<f64>)],
    strains: &'a Series,
    curvatures: &'a Series,
) -> Vec<Reading<'a>> {
    let mut out: Vec<Reading> =
        positions.iter().map(|(p, xy)| Reading { probe: p, quantity: Quantity::Position, values: xy.view() }).collect();
    for (quantity, series) in [(Quantity::Strain, strains), (Quantity::Curvature, curvatures)] {
        out.extend(series.iter().map(|(p, v)| Reading { probe: p, quantity, values: v.view().insert_axis(Axis(1)) }));
    }
    out
}

/// [`readings_of`] a run's result.
pub fn readings(r: &SimulationResult) -> Vec<Reading<'_>> {
    readings_of(&r.probes, &r.strains, &r.curvatures)
}

/// An error measured against a motion: `ratio()` where the motion is above the
/// coordinates' resolution; where it is not, ∞ if the error is (only the other run moved),
/// else NaN (nothing moved to measure against). `displacement_error`, a probe's error over
/// its travel, and each quantity's error over its range.
pub fn against_motion(moved: bool, differs: bool, ratio: impl FnOnce() -> f64) -> f64 {
    if moved {
        ratio()
    } else if differs {
        f64::INFINITY
    } else {
        f64::NAN
    }
}

/// The quantities the probes of a reduced trajectory record ([`readings_of`]).
pub fn readings_of_probes(v: &ProbeValues) -> Vec<Reading<'_>> {
    readings_of(&v.positions, &v.strains, &v.curvatures)
}

/// `max_k ‖a(t_k) − b(t_k)‖`.
pub fn max_distance(a: ArrayView2<f64>, b: ArrayView2<f64>) -> f64 {
    a.outer_iter()
        .zip(b.outer_iter())
        .map(|(x, y)| x.iter().zip(y).map(|(p, q)| (p - q).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max)
}

/// `‖max_k a(t_k) − min_k a(t_k)‖`, max and min componentwise (a path's bounding-box diagonal).
pub fn range(a: ArrayView2<f64>) -> f64 {
    a.axis_iter(Axis(1))
        .map(|c| {
            let (lo, hi) = c.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| (l.min(x), h.max(x)));
            if hi >= lo {
                (hi - lo).powi(2)
            } else {
                0.0
            }
        })
        .sum::<f64>()
        .sqrt()
}

/// The distance of `v` from the reference `w` and the reference's range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Apart {
    /// `max_k ‖v − w‖`
    pub distance: f64,
    /// the range of `w`
    pub range: f64,
    /// `distance / range`; NaN where `w`'s range is within `resolution` and so is the
    /// distance, ∞ where only the distance is above it
    pub relative: f64,
}

impl Apart {
    pub fn of(v: ArrayView2<f64>, w: ArrayView2<f64>, resolution: f64) -> Self {
        let (distance, range) = (max_distance(v, w), range(w));
        let relative =
            super::estimator::norms::against_motion(range > resolution, distance > resolution, || distance / range);
        Apart { distance, range, relative }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::array;

    /// A sine of amplitude 2 swings over a range of 4; an offset of 0.1 at one instant is
    /// 0.1 / 4 = 0.025 of it, whatever the mean value (an offset of the whole series by
    /// 100 changes nothing).
    #[test]
    fn errors_are_relative_to_the_range_not_the_value() {
        let w =
            ndarray::Array1::from_iter((0..101).map(|k| 100.0 + 2.0 * (k as f64 * 0.0628).sin())).insert_axis(Axis(1));
        let mut v = w.clone();
        v[[30, 0]] += 0.1;
        let a = Apart::of(v.view(), w.view(), 1e-10);
        assert!((a.range - 4.0).abs() < 1e-3, "{}", a.range);
        assert!((a.relative - 0.1 / a.range).abs() < 1e-12);
    }

    /// A path along the unit square's diagonal spans a box of diagonal √2; a point 0.3 off
    /// in x and 0.4 in y is 0.5 away.
    #[test]
    fn a_position_is_measured_in_the_plane() {
        let w = array![[0.0, 0.0], [0.5, 0.5], [1.0, 1.0]];
        let v = array![[0.0, 0.0], [0.8, 0.9], [1.0, 1.0]];
        let a = Apart::of(v.view(), w.view(), 1e-10);
        assert!((a.range - 2.0_f64.sqrt()).abs() < 1e-15);
        assert!((a.distance - 0.5).abs() < 1e-15);
    }

    /// A reference that does not move beyond the resolution gives no ratio where the
    /// other does not either, ∞ where it does.
    #[test]
    fn no_swing_no_ratio() {
        let w = array![[1.0], [1.0 + 1e-12]];
        assert!(Apart::of(w.view(), w.view(), 1e-10).relative.is_nan());
        let v = array![[1.0], [1.5]];
        assert_eq!(Apart::of(v.view(), w.view(), 1e-10).relative, f64::INFINITY);
    }
}
