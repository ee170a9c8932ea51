//! Joint reactions read as quantities ([`crate::analysis::reactions`]): each joint's force
//! and moment on each node it holds, from a run's coordinates and multipliers — a full run's,
//! a reduced trajectory's `x = x_ref + V z` (only the slopes the moments read are formed),
//! an enriched model's — and how far two runs lie apart in them, relative to the
//! reference's range as every probe quantity is ([`crate::rom::quantities`]).
//!
//! A reaction's resolution is the Newton tolerance relative to its own largest value, and
//! never below what the most flexible body's bending resolves at that tolerance
//! ([`resolution_floors`]): a model at rest has reactions of round-off.

use super::quantities::{Apart, Quantity};
use crate::analysis::reactions::{resolution_floors, ReactionMap, Reactions};
use crate::model::Model;
use crate::reduction::Basis;
use crate::simulate::SimulationResult;
use crate::solver::model::Parameters;
use ndarray::{Array2, ArrayView2, Axis};

/// One reaction point's force (n_t × 2, N) or moment (n_t × 1, N m) over a run.
#[derive(Clone, Debug, PartialEq)]
pub struct ReactionReading {
    /// the reaction point, "joint 0 (clamp arm node 0) on arm node 0"
    pub point: String,
    /// [`Quantity::Force`] or [`Quantity::Moment`]
    pub quantity: Quantity,
    pub values: Array2<f64>,
}

impl ReactionReading {
    /// The largest magnitude over the run.
    fn largest(&self) -> f64 {
        self.values.outer_iter().map(|v| v.dot(&v).sqrt()).fold(0.0, f64::max)
    }
}

/// A model's reaction points and the resolution floors of its reactions: built once per
/// model, read for every run.
#[derive(Clone, Debug)]
pub struct ReactionReader {
    map: ReactionMap,
    /// `[force, moment]` per unit Newton tolerance ([`resolution_floors`] at `tol = 1`)
    floors: [f64; 2],
    /// the coordinates the moments read, and a coordinate's slot among them
    read: Vec<usize>,
}

impl ReactionReader {
    pub fn new(model: &Model) -> Self {
        let map = ReactionMap::of(model);
        let mut read = map.read_coordinates();
        read.sort_unstable();
        read.dedup();
        ReactionReader { floors: resolution_floors(model, 1.0), map, read }
    }

    /// The reactions of a run whose multipliers are `multipliers` (n_c × n_t) and whose
    /// coordinates `coordinate(i, k)` gives; `None` where the multipliers are not the
    /// model's rows or not all finite (a variant that computes none).
    fn readings_by(
        &self,
        (mu, t): (&Parameters, &[f64]),
        coordinate: impl Fn(usize, usize) -> f64,
        multipliers: ArrayView2<f64>,
    ) -> Option<Vec<ReactionReading>> {
        let fits = multipliers.nrows() == self.map.n_rows() && multipliers.ncols() == t.len();
        if !fits || self.map.points.is_empty() || !multipliers.iter().all(|x| x.is_finite()) {
            return None;
        }
        let r = self.map.series_by((mu, t), coordinate, |c, k| multipliers[(c, k)]);
        Some(self.split(r))
    }

    /// The reactions of a result with every coordinate and its multipliers.
    pub fn of_result(&self, r: &SimulationResult) -> Option<Vec<ReactionReading>> {
        let t = r.t.as_slice()?;
        if r.q.ncols() != t.len() || self.read.last().is_some_and(|&i| i >= r.q.nrows()) {
            return None;
        }
        self.readings_by((r.settings.parameters(), t), |i, k| r.q[(i, k)], r.multipliers.view())
    }

    /// The reactions along the reduced trajectory `z` (r × n_t) of `basis` with the physical
    /// multipliers `multipliers`: `x_i = x_ref,i + V_i z` at the slopes the moments read,
    /// plus `V⁺_i δ` where a `correction` (an enriched basis and its coordinates δ, r⁺ × n_t)
    /// is given.
    pub fn of_trajectory(
        &self,
        (mu, t): (&Parameters, &[f64]),
        (basis, z): (&Basis, ArrayView2<f64>),
        correction: Option<(&Basis, ArrayView2<f64>)>,
        multipliers: ArrayView2<f64>,
    ) -> Option<Vec<ReactionReading>> {
        let fits = |b: &Basis, z: &ArrayView2<f64>| z.nrows() == b.modes.ncols() && z.ncols() == t.len();
        if !fits(basis, &z) || correction.as_ref().is_some_and(|(b, d)| !fits(b, d)) {
            return None;
        }
        // the rows of V the moments read, times z (plus the correction's): |read| × n_t
        let mut rows = basis.modes.select(Axis(0), &self.read).dot(&z);
        if let Some((enriched, delta)) = correction {
            rows += &enriched.modes.select(Axis(0), &self.read).dot(&delta);
        }
        let slot = |i: usize| self.read.binary_search(&i).ok();
        let coordinate = |i: usize, k: usize| slot(i).map_or(f64::NAN, |s| basis.reference[i] + rows[(s, k)]);
        self.readings_by((mu, t), coordinate, multipliers)
    }

    /// Each point's force, then each point's moment.
    fn split(&self, r: Reactions) -> Vec<ReactionReading> {
        let names = self.map.names();
        let forces = names.iter().enumerate().map(|(p, name)| ReactionReading {
            point: name.to_string(),
            quantity: Quantity::Force,
            values: r.force.index_axis(Axis(1), p).to_owned(),
        });
        let moments = names.iter().enumerate().map(|(p, name)| ReactionReading {
            point: name.to_string(),
            quantity: Quantity::Moment,
            values: r.moment.column(p).insert_axis(Axis(1)).to_owned(),
        });
        forces.chain(moments).collect()
    }

    /// The resolution of `reference` at the Newton tolerance `tol`: `tol` relative to its
    /// largest value, never below the floor of its kind.
    pub fn resolution(&self, reference: &ReactionReading, tol: f64) -> f64 {
        let floor = if reference.quantity == Quantity::Force { self.floors[0] } else { self.floors[1] };
        (tol * reference.largest()).max(tol * floor)
    }

    /// How far `v` lies from the reference `w`, over `w`'s range.
    pub fn apart(&self, v: &ReactionReading, w: &ReactionReading, tol: f64) -> Apart {
        Apart::of(v.values.view(), w.values.view(), self.resolution(w, tol))
    }

    /// Each reaction point's force, then each one's moment: (point, quantity), in the order a
    /// run's readings come.
    pub fn points(&self) -> Vec<(String, Quantity)> {
        let names = self.map.names();
        let each = |q: Quantity| names.iter().map(move |n| (n.to_string(), q));
        each(Quantity::Force).chain(each(Quantity::Moment)).collect()
    }

    /// The keys of the reactions' estimates (`QuantityRaw::key`: `force:<point>`, then
    /// `moment:<point>`), in the order a run's readings come.
    pub fn keys(&self) -> Vec<String> {
        self.points().into_iter().map(|(point, q)| format!("{}:{point}", q.name())).collect()
    }

    /// The number of constraint rows the reactions read multipliers of.
    pub fn n_rows(&self) -> usize {
        self.map.n_rows()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rom::estimator::QuantityRaw;
    use crate::simulate::{simulate, Overrides};

    /// A bar clamped at one end and pinned to a link: the clamp and the pin's two nodes are
    /// three reaction points.
    const MODEL: &str = "[time]\nt_end = 0.02\ndt = 0.01\nrho_inf = 0.8\n\
        [[bodies]]\nname = \"bar\"\nstart = [0.0, 0.0]\nangle = 0.0\nlength = 1.0\nelements = 2\n\
        density = 7800.0\narea = 1e-4\ninertia = 1e-9\nyoungs_modulus = 2e11\n\
        [[bodies]]\nname = \"link\"\nstart = [1.0, 0.0]\nangle = 0.0\nlength = 1.0\nelements = 2\n\
        density = 7800.0\narea = 1e-4\ninertia = 1e-9\nyoungs_modulus = 2e11\n\
        [[joints]]\ntype = \"clamp\"\nbody = \"bar\"\nnode = \"start\"\n\
        [[joints]]\ntype = \"pin\"\na = { body = \"bar\", node = \"end\" }\nb = { body = \"link\", node = 0 }\n\
        [[loads]]\ntype = \"gravity\"\ng = [0.0, -9.81]\n";

    /// A full run's reactions read through the reduced trajectory of the identity basis are
    /// the run's own (`x_ref = 0`, `V = I`): the same coordinates, the same multipliers.
    #[test]
    fn a_trajectory_reads_the_reactions_a_result_does() {
        let model = Model::from_text(MODEL, "m.toml").unwrap();
        let r = simulate(&model, &Overrides::default()).unwrap();
        let reader = ReactionReader::new(&model);
        let full = reader.of_result(&r).unwrap();
        let n = r.q.nrows();
        let identity = Basis::identity(n, crate::reduction::Variant::Galerkin);
        let t = r.t.as_slice().unwrap();
        let via = reader
            .of_trajectory((r.settings.parameters(), t), (&identity, r.q.view()), None, r.multipliers.view())
            .unwrap();
        assert_eq!(full.len(), 6, "three points, force and moment each");
        for (a, b) in full.iter().zip(&via) {
            assert_eq!((&a.point, a.quantity), (&b.point, b.quantity));
            assert!((&a.values - &b.values).iter().all(|d| d.abs() <= 1e-9 * (1.0 + a.largest())), "{}", a.point);
        }
        // the gravity swings both: every force moves (the pin carries no moment)
        assert!(full[..3].iter().all(|f| f.largest() > 0.0));
    }

    /// An estimator whose own model failed reads ∞ in every reaction of a run that has
    /// multipliers, and names none for a run without (a variant that computes none).
    #[test]
    fn a_failed_estimator_reads_every_reaction_infinite() {
        let model = Model::from_text(MODEL, "m.toml").unwrap();
        let mut r = simulate(&model, &Overrides::default()).unwrap();
        let reader = ReactionReader::new(&model);
        let raws = QuantityRaw::infinite(&r, Some(&reader));
        let reactions: Vec<_> = raws.iter().filter(|q| q.quantity.is_reaction()).collect();
        assert_eq!(reactions.len(), 6);
        assert!(reactions.iter().all(|q| q.raw == f64::INFINITY));
        r.multipliers.fill(f64::NAN);
        assert!(QuantityRaw::infinite(&r, Some(&reader)).iter().all(|q| !q.quantity.is_reaction()));
    }
}
