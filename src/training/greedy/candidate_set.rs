//! Where greedy training reads its estimates: the candidates, on a line of load scales or
//! in a `[parameters]` box, and which of them are neighbours.
//!
//! ```text
//!     line:  λᵢ = A + (B − A) i/(N − 1)                 neighbours: (i, i + 1)
//!     box:   the 2ᵈ corners and 2d face centres of [0, 1]ᵈ (when they are no more than N),
//!            then N points uᵢ ∈ [0, 1)ᵈ drawn by Sobol (or LHS, random) from a fixed seed,
//!            μᵢ = the box's point at uᵢ                  neighbours: each point and its d + 1 nearest
//! ```
//!
//! In a box the candidates live in the unit cube, so parameters of different units (a
//! load factor, a Young's modulus on a log scale) weigh alike in the distances, and their
//! count grows with the dimension (32 per parameter by default), not as countᵈ: a grid of
//! 33 per axis would be 1089 reduced runs per rung in two dimensions. Drawn points stay
//! about 1/N^(1/d) inside the faces, where a response is often at its largest (the largest
//! loads), so the corners and the faces' centres are candidates too — as long as they do not
//! outnumber the drawn points. Pairing each point with its d + 1 nearest (a simplex's worth)
//! and joining any islands left keeps the pairs one connected graph; pairing each with
//! its single nearest split a 64-point plane into about 19 islands with no bound between
//! them. The first full runs are the line's ends and middle, in a box the lower and upper
//! corners and the centre (the same three points on a line).

use crate::pipeline::config::{GreedySpec, DEFAULT_BOX_CANDIDATES_PER_PARAMETER};
use crate::solver::parameter_space::ParameterSpace;
use crate::solver::parameters::Parameters;

/// The candidates of greedy training and their neighbour pairs (the module documentation).
#[derive(Clone, Debug)]
pub struct CandidateSet {
    /// the candidates' parameters
    pub points: Vec<Parameters>,
    /// the candidates in the unit cube (one coordinate on a line)
    pub unit: Vec<Vec<f64>>,
    /// the pairs the bound between candidates runs over, `i < j`
    pub pairs: Vec<(usize, usize)>,
    /// the box; empty on a line of load scales
    pub space: ParameterSpace,
}

impl CandidateSet {
    /// The candidates of `g`: evenly spaced loads of its range, or, when `space` is not
    /// empty, points drawn from the box.
    pub fn new(g: &GreedySpec, space: &ParameterSpace) -> Self {
        if space.is_empty() {
            return Self::line(&g.candidate_loads());
        }
        let d = space.ranges.len();
        let n = g.candidates.unwrap_or(DEFAULT_BOX_CANDIDATES_PER_PARAMETER * d);
        let mut unit = boundary_points(d, n);
        unit.extend(space.sample_unit(n, g.sampling.unwrap_or_default(), g.seed.unwrap_or(1)));
        let points = unit.iter().map(|u| space.at(u)).collect();
        let pairs = nearest_pairs(&unit, d + 1);
        CandidateSet { points, unit, pairs, space: space.clone() }
    }

    /// Candidates at the loads `loads` (ascending), neighbours in order.
    pub fn line(loads: &[f64]) -> Self {
        let (a, b) = (loads[0], loads[loads.len() - 1]);
        CandidateSet {
            points: loads.iter().map(|&x| Parameters::load_scale(x)).collect(),
            unit: loads.iter().map(|&x| vec![if b > a { (x - a) / (b - a) } else { 0.0 }]).collect(),
            pairs: (1..loads.len()).map(|i| (i - 1, i)).collect(),
            space: ParameterSpace::default(),
        }
    }

    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// A box (not a line of load scales).
    pub fn is_box(&self) -> bool {
        !self.space.is_empty()
    }

    /// The load scales of a line (a box's λ values, 1 unless the box holds λ).
    pub fn loads(&self) -> Vec<f64> {
        self.points.iter().map(Parameters::scale).collect()
    }

    /// The first full runs: the ends and the middle of the line, the lower and upper corners
    /// and the centre of a box (the middle alone for one run, the ends for two).
    pub fn first(&self, g: &GreedySpec, max_runs: usize) -> Vec<Parameters> {
        let at: Vec<f64> = match max_runs {
            1 => vec![0.5],
            2 => vec![0.0, 1.0],
            _ => vec![0.0, 0.5, 1.0],
        };
        if self.is_box() {
            let d = self.space.ranges.len();
            return at.iter().map(|&u| self.space.at(&vec![u; d])).collect();
        }
        let (a, b) = g.range();
        // the line's own numbers: the ends exactly, the middle as (A + B)/2
        at.iter()
            .map(|&u| {
                Parameters::load_scale(if u == 0.0 {
                    a
                } else if u == 1.0 {
                    b
                } else {
                    0.5 * (a + b)
                })
            })
            .collect()
    }

    /// How messages name a point: `λ = 1.2` on a line, `drive = 1.1, E_lower = 2.5e8` in a box.
    pub fn label(&self, mu: &Parameters) -> String {
        if !self.is_box() {
            return format!("λ = {}", mu.scale());
        }
        self.space.label(mu)
    }

    /// [`Self::label`] of candidate `i`.
    pub fn label_of(&self, i: usize) -> String {
        self.label(&self.points[i])
    }

    /// Whether `mu` is the candidate `i` (to round-off: 1e-12 relative per parameter).
    pub fn is_at(&self, i: usize, mu: &Parameters) -> bool {
        let c = &self.points[i];
        let same = |x: f64, y: f64| (x - y).abs() <= 1e-12 * y.abs().max(1.0);
        if !self.is_box() {
            return same(mu.scale(), c.scale());
        }
        self.space.names().all(|n| same(mu.get(n).unwrap_or(1.0), c.get(n).unwrap_or(1.0)))
    }

    /// The neighbouring run of a sensitivity check at candidate `i`: every parameter of the
    /// box (λ on a line) times `1 + step`.
    pub fn moved(&self, i: usize, step: f64) -> Parameters {
        self.moved_point(&self.points[i], step)
    }

    /// Any point `mu` moved as [`Self::moved`] moves a candidate.
    pub fn moved_point(&self, mu: &Parameters, step: f64) -> Parameters {
        self.space.moved(mu, 1.0 + step)
    }

    /// The point at `u` in the candidates' unit coordinates ([`Self::unit`]): on a line the
    /// load `a + u (b − a)` between the first and the last candidate, in a box its point
    /// (log-spaced parameters stay log-spaced).
    pub fn at_unit(&self, u: &[f64]) -> Parameters {
        if self.is_box() {
            return self.space.at(u);
        }
        let (a, b) = (self.points[0].scale(), self.points[self.len() - 1].scale());
        Parameters::load_scale(a + u[0] * (b - a))
    }
}

/// The 2ᵈ corners of the unit cube (the lower corner first, the upper one last), then the
/// centres of its 2d faces; none when they would outnumber the `n` drawn points.
fn boundary_points(d: usize, n: usize) -> Vec<Vec<f64>> {
    if d >= usize::BITS as usize || (1usize << d) + 2 * d > n {
        return Vec::new();
    }
    let mut out: Vec<Vec<f64>> = (0..1usize << d).map(|c| (0..d).map(|j| ((c >> j) & 1) as f64).collect()).collect();
    // the faces' centres (on a line they are the corners)
    for j in (0..d).filter(|_| d > 1) {
        for side in [0.0, 1.0] {
            let mut u = vec![0.5; d];
            u[j] = side;
            out.push(u);
        }
    }
    out
}

/// Each point paired with its `k` nearest other points (Euclidean distance in the unit
/// cube), and, where that leaves islands, each island joined to the rest by its shortest
/// pair; each pair once, `i < j`, sorted.
fn nearest_pairs(unit: &[Vec<f64>], k: usize) -> Vec<(usize, usize)> {
    let mut pairs: Vec<(usize, usize)> = (0..unit.len())
        .flat_map(|i| {
            crate::solver::parameter_space::nearest(unit, &unit[i], k, Some(i))
                .into_iter()
                .map(move |j| (i.min(j), i.max(j)))
        })
        .collect();
    // the island holding point 0 grows by the shortest pair out of it until it holds all
    let d2 = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>();
    let mut island = reached(unit.len(), &pairs);
    while let Some(bridge) = (0..unit.len())
        .filter(|&i| island[i])
        .flat_map(|i| (0..unit.len()).filter(|&j| !island[j]).map(move |j| (i, j)))
        .min_by(|&(a, b), &(c, e)| d2(&unit[a], &unit[b]).total_cmp(&d2(&unit[c], &unit[e])))
    {
        pairs.push((bridge.0.min(bridge.1), bridge.0.max(bridge.1)));
        island = reached(unit.len(), &pairs);
    }
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// Which of `n` points a walk along `pairs` from point 0 reaches.
fn reached(n: usize, pairs: &[(usize, usize)]) -> Vec<bool> {
    let mut seen = vec![false; n];
    let mut stack = if n > 0 { vec![0] } else { vec![] };
    while let Some(i) = stack.pop() {
        if !std::mem::replace(&mut seen[i], true) {
            stack.extend(pairs.iter().filter_map(|&(a, b)| (a == i).then_some(b).or((b == i).then_some(a))));
        }
    }
    seen
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::parameter_space::{ParameterRange, Spacing};

    fn spec(candidates: Option<usize>, range: Vec<f64>) -> GreedySpec {
        GreedySpec {
            range,
            tolerance: 1e-2,
            max_runs: 8,
            candidates,
            measure: Default::default(),
            sampling: None,
            seed: None,
        }
    }

    fn plane() -> ParameterSpace {
        ParameterSpace {
            ranges: vec![
                ParameterRange { name: "drive".into(), lower: 0.5, upper: 1.5, spacing: Spacing::Linear },
                ParameterRange { name: "stiff".into(), lower: 1e8, upper: 4e8, spacing: Spacing::Log },
            ],
        }
    }

    /// On a line the candidates are the evenly spaced loads, neighbours in order, the first
    /// runs the ends and the middle: what greedy training over a range has always used.
    #[test]
    fn a_line_is_the_evenly_spaced_loads() {
        let g = spec(Some(5), vec![0.5, 1.5]);
        let c = CandidateSet::new(&g, &ParameterSpace::default());
        assert_eq!(c.loads(), vec![0.5, 0.75, 1.0, 1.25, 1.5]);
        assert_eq!(c.pairs, vec![(0, 1), (1, 2), (2, 3), (3, 4)]);
        let first: Vec<f64> = c.first(&g, 8).iter().map(Parameters::scale).collect();
        assert_eq!(first, vec![0.5, 1.0, 1.5]);
        assert_eq!(c.label_of(1), "λ = 0.75");
        assert_eq!(c.moved(2, 1e-3).scale(), 1.0 * (1.0 + 1e-3));
    }

    /// In a box: the 4 corners, 4 face centres and 32 drawn candidates per parameter by
    /// default, inside
    /// the box, the pairs one connected graph; the first runs are the corners and the
    /// centre (a log axis's centre is the geometric mean: √(1e8 · 4e8) = 2e8).
    #[test]
    fn a_box_is_sampled_in_the_unit_cube() {
        let g = spec(None, vec![]);
        let c = CandidateSet::new(&g, &plane());
        assert_eq!(c.len(), 4 + 4 + 64);
        assert!(c.points.iter().all(|mu| plane().outside(mu).is_empty()));
        assert_eq!((c.points[0].get("drive"), c.points[0].get("stiff")), (Some(0.5), Some(1e8)));
        assert_eq!((c.points[3].get("drive"), c.points[3].get("stiff")), (Some(1.5), Some(4e8)));
        assert!(connected(c.len(), &c.pairs), "the pairs split the candidates");
        let first = c.first(&g, 8);
        assert_eq!(first[0].get("drive"), Some(0.5));
        assert_eq!(first[2].get("stiff"), Some(4e8));
        assert!((first[1].get("stiff").unwrap() - 2e8).abs() < 1e-6 * 2e8);
        assert_eq!(c.label(&first[1]), "drive = 1, stiff = 2e8");
        assert_eq!(crate::solver::parameter_space::short_number(1.3148486614227295), "1.315");
        assert_eq!(crate::solver::parameter_space::short_number(0.20863951807746545), "0.2086");
        // the sensitivity's neighbour moves every parameter by the step
        let m = c.moved(3, 1e-3);
        assert_eq!(m.get("drive"), Some(c.points[3].get("drive").unwrap() * 1.001));
        assert!(c.is_at(3, &c.points[3]) && !c.is_at(3, &m));
    }

    fn connected(n: usize, pairs: &[(usize, usize)]) -> bool {
        reached(n, pairs).iter().all(|&s| s)
    }

    /// The nearest-neighbour pairs of four points on a line of the cube, 0, 0.1, 0.5, 1:
    /// with one neighbour each (0, 1) twice, (1, 2) from 0.5, (2, 3) from 1 — each once;
    /// with two, 0 also reaches 0.5 and 1 reaches 0.1.
    #[test]
    fn nearest_pairs_are_each_points_nearest() {
        let unit = vec![vec![0.0, 0.0], vec![0.1, 0.0], vec![0.5, 0.0], vec![1.0, 0.0]];
        assert_eq!(nearest_pairs(&unit, 1), vec![(0, 1), (1, 2), (2, 3)]);
        assert_eq!(nearest_pairs(&unit, 2), vec![(0, 1), (0, 2), (1, 2), (1, 3), (2, 3)]);
        // two far clusters: each point's nearest is in its own, and the shortest pair
        // between them, (1, 2), joins them
        let unit = vec![vec![0.0, 0.0], vec![0.1, 0.0], vec![0.9, 0.0], vec![1.0, 0.0]];
        assert_eq!(nearest_pairs(&unit, 1), vec![(0, 1), (1, 2), (2, 3)]);
    }

    /// The corners, 2ᵈ of them, lower first and upper last, then the 2d face centres; none
    /// when they would outnumber the drawn points (2⁶ + 12 = 76 > 40).
    #[test]
    fn the_boundary_comes_first_unless_it_outnumbers_the_draws() {
        let square = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0], [0.0, 0.5], [1.0, 0.5], [0.5, 0.0], [0.5, 1.0]];
        assert_eq!(boundary_points(2, 8), square.map(|u| u.to_vec()).to_vec());
        assert_eq!(boundary_points(3, 96).len(), 8 + 6);
        assert!(boundary_points(6, 40).is_empty());
        // in every dimension the default set's pairs stay connected (1 to 4 parameters)
        for d in 1..=4 {
            let space = ParameterSpace {
                ranges: (0..d)
                    .map(|j| ParameterRange { name: format!("p{j}"), lower: 0.0, upper: 1.0, spacing: Spacing::Linear })
                    .collect(),
            };
            let c = CandidateSet::new(&spec(None, vec![]), &space);
            let faces = if d > 1 { 2 * d } else { 0 };
            assert_eq!(c.len(), (1 << d) + faces + 32 * d);
            assert!(connected(c.len(), &c.pairs), "{d} parameters: the pairs split the candidates");
        }
    }
}
