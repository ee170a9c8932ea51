//! The deformed centre lines of a model's beams, sampled within the elements for drawing
//! and for ParaView: at a sample `ξ` of an element with nodal vector `e`
//!
//! ```text
//!     r(ξ) = S(ξ) e          position (cubic Hermite interpolation, SPEC §1), m
//!     ṙ(ξ) = S(ξ) ė          velocity, m/s
//!     ε(ξ), κ(ξ)             axial Green strain and curvature ([`super::section`])
//! ```
//!
//! so a bent element is drawn bent, not as the chord between its nodes. Every element
//! gets [`POINTS_PER_ELEMENT`] samples (`ξ = 0, ¼, ½, ¾`, and the body's last node);
//! where a model has more elements than a drawing can show, the samples are spread
//! evenly by arc length along each body instead ([`CentreLines::new`]'s `max_points`).

use super::element::{shape_functions, BeamElement, Vec8};
use super::parts::{BeamBody, NodeId};

/// Samples per element where the point budget allows.
pub const POINTS_PER_ELEMENT: usize = 4;

/// Where one sample sits: its element's first coordinate and `ξ`, and the body's element
/// prototype (its length sets the interpolation).
#[derive(Clone, Copy, Debug)]
struct Sample {
    dof: usize,
    xi: f64,
    body: usize,
}

/// The sample points of every body, body after body (node `k` of body `b` owns the
/// coordinates `4 (first_node_b + k) ..+ 4`, as in [`super::system::FlexibleSystem`]).
#[derive(Clone, Debug)]
pub struct CentreLines {
    elements: Vec<BeamElement>,
    samples: Vec<Sample>,
    /// the first sample of each body, then the number of samples
    starts: Vec<usize>,
    first_node: Vec<usize>,
    first_element: Vec<usize>,
}

impl CentreLines {
    /// The samples of `bodies`: [`POINTS_PER_ELEMENT`] per element and the last node where
    /// that makes at most `max_points`; else each body gets its share of `max_points` (in
    /// proportion to its elements, but at least 9, so the total may pass `max_points` by
    /// 9 a body), evenly spaced by arc length.
    pub fn new(bodies: &[BeamBody], max_points: usize) -> CentreLines {
        let full: usize = bodies.iter().map(|b| POINTS_PER_ELEMENT * b.n_elements + 1).sum();
        let share = (max_points as f64 / full.max(1) as f64).min(1.0);
        let (mut samples, mut starts, mut first_node, mut first_element) = (vec![], vec![], vec![], vec![]);
        let (mut node, mut element) = (0, 0);
        for (b, body) in bodies.iter().enumerate() {
            let n = body.n_elements;
            let all = POINTS_PER_ELEMENT * n + 1;
            let m = if share >= 1.0 { all } else { ((all as f64 * share) as usize).clamp(9.min(all), all) };
            starts.push(samples.len());
            for j in 0..m {
                // position along the body in elements: element k, ξ = u − k (the last
                // sample is ξ = 1 of the last element)
                let u = j as f64 * n as f64 / (m - 1) as f64;
                let k = (u.floor() as usize).min(n - 1);
                samples.push(Sample { dof: 4 * (node + k), xi: u - k as f64, body: b });
            }
            first_node.push(node);
            first_element.push(element);
            node += n + 1;
            element += n;
        }
        starts.push(samples.len());
        let elements = bodies.iter().map(|b| BeamElement::new(b.length / b.n_elements as f64, b.section)).collect();
        CentreLines { elements, samples, starts, first_node, first_element }
    }

    /// The number of sample points over all bodies.
    pub fn n_points(&self) -> usize {
        self.samples.len()
    }

    /// The samples of each body, as index ranges into the arrays the methods return.
    pub fn bodies(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        self.starts.windows(2).map(|w| w[0]..w[1])
    }

    fn element_vector(v: &[f64], dof: usize) -> Vec8 {
        Vec8::from_column_slice(&v[dof..dof + 8])
    }

    /// `S(ξ) e` of every sample, from the coordinates `q` (positions) or their rates `q̇`
    /// (velocities).
    pub fn interpolate(&self, q: &[f64]) -> Vec<[f64; 2]> {
        self.samples.iter().map(|s| interpolate_at(&q[s.dof..s.dof + 8], s.xi, self.elements[s.body].length)).collect()
    }

    /// The axial Green strain `ε` at every sample.
    pub fn strains(&self, q: &[f64]) -> Vec<f64> {
        self.samples.iter().map(|s| self.elements[s.body].axial_strain(&Self::element_vector(q, s.dof), s.xi)).collect()
    }

    /// The signed curvature `κ` (1/m) at every sample.
    pub fn curvatures(&self, q: &[f64]) -> Vec<f64> {
        self.samples.iter().map(|s| self.elements[s.body].curvature(&Self::element_vector(q, s.dof), s.xi)).collect()
    }

    /// The position of node `(b, k)`.
    pub fn node_position(&self, q: &[f64], (b, k): NodeId) -> [f64; 2] {
        let d = 4 * (self.first_node[b] + k);
        [q[d], q[d + 1]]
    }

    /// The position of the material point `ξ` of element `element` (global numbering, as a
    /// probe's).
    pub fn point_position(&self, q: &[f64], element: usize, xi: f64) -> [f64; 2] {
        let b = self.first_element.partition_point(|&f| f <= element) - 1;
        let d = 4 * (self.first_node[b] + element - self.first_element[b]);
        interpolate_at(&q[d..d + 8], xi, self.elements[b].length)
    }
}

/// `S(ξ) e` of one element vector `e` of length `l`.
fn interpolate_at(e: &[f64], xi: f64, l: f64) -> [f64; 2] {
    let s = shape_functions(xi, l);
    let mut r = [0.0; 2];
    for (i, si) in s.iter().enumerate() {
        r[0] += si * e[2 * i];
        r[1] += si * e[2 * i + 1];
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::element::Section;

    const SEC: Section = Section { density: 7800.0, area: 1e-4, inertia: 1e-8, youngs_modulus: 2.1e11 };

    fn body(n: usize, length: f64, angle: f64) -> BeamBody {
        BeamBody {
            name: "b".into(),
            start: [0.5, -0.25],
            angle,
            length,
            n_elements: n,
            section: SEC,
            youngs_modulus_parameter: None,
            density_parameter: None,
            velocity: [0.0; 2],
            angular_velocity: 0.0,
        }
    }

    fn undeformed(bodies: &[BeamBody]) -> Vec<f64> {
        bodies.iter().flat_map(|b| (0..=b.n_elements).flat_map(move |k| b.undeformed_node(k))).collect()
    }

    /// On straight bodies the samples lie on the bodies at `ξ` steps of ¼ (positions exact
    /// to round-off: the cubic interpolation reproduces a straight line), with no strain
    /// and no curvature; a rigid rotation's rates `q̇ = ω × (r, r')` interpolate to
    /// `ω × r` at every sample.
    #[test]
    fn straight_bodies_are_sampled_on_their_axes() {
        let bodies = [body(3, 1.5, 0.3), body(2, 0.8, -1.0)];
        let lines = CentreLines::new(&bodies, 1000);
        assert_eq!(lines.n_points(), (4 * 3 + 1) + (4 * 2 + 1));
        let q = undeformed(&bodies);
        let r = lines.interpolate(&q);
        for (b, range) in lines.bodies().enumerate() {
            let (c, s) = (bodies[b].angle.cos(), bodies[b].angle.sin());
            let step = bodies[b].length / (range.len() - 1) as f64;
            for (j, i) in range.enumerate() {
                let d = j as f64 * step;
                let want = [bodies[b].start[0] + d * c, bodies[b].start[1] + d * s];
                assert!((r[i][0] - want[0]).abs() < 1e-14 && (r[i][1] - want[1]).abs() < 1e-14, "{b} {j}");
            }
        }
        assert!(lines.strains(&q).iter().all(|e| e.abs() < 1e-14));
        assert!(lines.curvatures(&q).iter().all(|k| k.abs() < 1e-12));
        let w = 2.0;
        let qd: Vec<f64> = q.chunks(4).flat_map(|n| [-w * n[1], w * n[0], -w * n[3], w * n[2]]).collect();
        for (v, p) in lines.interpolate(&qd).iter().zip(&r) {
            assert!((v[0] + w * p[1]).abs() < 1e-13 && (v[1] - w * p[0]).abs() < 1e-13);
        }
        // a probe's point and a node's position
        let p = lines.point_position(&q, 4, 0.5);
        // element 4 is body 1's second (elements of 0.4 m): ξ = ½ there is 1.5 lengths in
        let d = 1.5 * 0.4;
        assert!(
            (p[0] - (0.5 + d * (-1.0f64).cos())).abs() < 1e-14 && (p[1] - (-0.25 + d * (-1.0f64).sin())).abs() < 1e-14
        );
        assert_eq!(lines.node_position(&q, (1, 0)), [0.5, -0.25]);
    }

    /// Nodes on a circle of radius R with tangent slopes: the samples between the nodes lie
    /// on the arc to the cubic interpolation's error (second order in the element's angle
    /// φ: within R φ⁴/100 here, where the chord's midpoint is R φ²/8 off), which is the point
    /// of sampling within the elements.
    #[test]
    fn a_bent_body_is_drawn_bent() {
        let (r, n) = (1.0_f64, 8);
        let b = body(n, r * std::f64::consts::PI, 0.0);
        let phi = std::f64::consts::PI / n as f64;
        let q: Vec<f64> = (0..=n)
            .flat_map(|k| {
                let a = k as f64 * phi;
                [r * a.cos(), r * a.sin(), -a.sin(), a.cos()]
            })
            .collect();
        let lines = CentreLines::new(&[b], 1000);
        let worst =
            lines.interpolate(&q).iter().map(|p| ((p[0] * p[0] + p[1] * p[1]).sqrt() - r).abs()).fold(0.0, f64::max);
        assert!(worst < r * phi.powi(4) / 100.0, "{worst}");
        assert!(r * phi * phi / 8.0 > 100.0 * worst, "a chord would be far off");
    }

    /// Over the budget, each body keeps its share of it, evenly by arc length, ends
    /// included.
    #[test]
    fn a_big_body_is_subsampled_evenly() {
        let bodies = [body(5000, 1.0, 0.0), body(10, 1.0, 0.0)];
        let lines = CentreLines::new(&bodies, 2000);
        let ranges: Vec<_> = lines.bodies().collect();
        // the budget, plus at most the 9 points each body keeps whatever its share
        assert!(lines.n_points() <= 2000 + 2 * 9, "{}", lines.n_points());
        assert_eq!(ranges[1].len(), 9, "at least 9 a body");
        let r = lines.interpolate(&undeformed(&bodies));
        assert!((r[ranges[0].start][0] - 0.5).abs() < 1e-15 && (r[ranges[0].end - 1][0] - 1.5).abs() < 1e-12);
        let dx = r[1][0] - r[0][0];
        assert!(ranges[0].clone().skip(1).all(|i| ((r[i][0] - r[i - 1][0]) - dx).abs() < 1e-12));
    }
}
