//! What a probe records at a material point besides its position: the axial strain and the
//! curvature of the beam's centre line there (SPEC §1), from the derivatives of the
//! element's cubic Hermite interpolation `r(ξ) = S(ξ) e` at `s = ξ l`:
//!
//! ```text
//!     r'  = ∂r/∂s   = (1/l)  dS/dξ  e
//!     r'' = ∂²r/∂s² = (1/l²) d²S/dξ² e
//!     ε = ½ (r'·r' − 1)                 axial Green strain at ξ (dimensionless)
//!     κ = (r' × r'')_z / |r'|³          signed curvature, 1/m: positive where the tangent
//!                                        turns counter-clockwise along s
//! ```
//!
//! `|κ| = |r' × r''| / |r'|³` is the curvature of the deformed centre line whatever its
//! stretch; an Euler–Bernoulli section carries the bending moment `M = E I κ`
//! (counter-clockwise positive on the face whose outward normal points along +s). The
//! element's own axial force uses the strain averaged over the element, `ε̄`
//! ([`BeamElement::mean_axial_strain`]); `ε` here is the pointwise value, equal to it under
//! a uniform stretch.

use super::element::{BeamElement, Vec8};

impl BeamElement {
    /// `(r', r'')` at `ξ`: the slope and the second derivative of the centre line by arc
    /// length of the undeformed element.
    pub fn derivatives(&self, e: &Vec8, xi: f64) -> ([f64; 2], [f64; 2]) {
        let l = self.length;
        let (x2, l2) = (xi * xi, l * l);
        // dS/dξ / l and d²S/dξ² / l² of `shape_functions` (SPEC §1)
        let d1 = [(6.0 * x2 - 6.0 * xi) / l, 1.0 - 4.0 * xi + 3.0 * x2, (6.0 * xi - 6.0 * x2) / l, 3.0 * x2 - 2.0 * xi];
        let d2 = [(12.0 * xi - 6.0) / l2, (6.0 * xi - 4.0) / l, (6.0 - 12.0 * xi) / l2, (6.0 * xi - 2.0) / l];
        let (mut r1, mut r2) = ([0.0; 2], [0.0; 2]);
        for i in 0..4 {
            for c in 0..2 {
                r1[c] += d1[i] * e[2 * i + c];
                r2[c] += d2[i] * e[2 * i + c];
            }
        }
        (r1, r2)
    }

    /// Axial Green strain `ε = ½ (r'·r' − 1)` at `ξ`.
    pub fn axial_strain(&self, e: &Vec8, xi: f64) -> f64 {
        let (r1, _) = self.derivatives(e, xi);
        0.5 * (r1[0] * r1[0] + r1[1] * r1[1] - 1.0)
    }

    /// Signed curvature `κ = (r' × r'')_z / |r'|³` at `ξ`, 1/m.
    pub fn curvature(&self, e: &Vec8, xi: f64) -> f64 {
        let (r1, r2) = self.derivatives(e, xi);
        let norm = (r1[0] * r1[0] + r1[1] * r1[1]).sqrt();
        (r1[0] * r2[1] - r1[1] * r2[0]) / (norm * norm * norm)
    }
}

#[cfg(test)]
mod tests {
    use crate::physics::element::{BeamElement, Section, Vec8};

    const SEC: Section = Section { density: 7800.0, area: 1e-4, inertia: 1e-8, youngs_modulus: 2.1e11 };

    /// A straight element stretched by 1 + δ along angle θ: r' = (1 + δ)(cos θ, sin θ) at
    /// every ξ, so ε = ((1 + δ)² − 1)/2 exactly and κ = 0.
    #[test]
    fn a_stretched_element_has_its_green_strain_and_no_curvature() {
        let (l, th) = (0.5_f64, 0.4_f64);
        let el = BeamElement::new(l, SEC);
        for d in [0.01, -0.02, 0.0] {
            let (c, s) = ((1.0 + d) * th.cos(), (1.0 + d) * th.sin());
            let e = Vec8::from_column_slice(&[0.3, -0.1, c, s, 0.3 + l * c, -0.1 + l * s, c, s]);
            let expected = ((1.0 + d) * (1.0 + d) - 1.0) / 2.0;
            for xi in [0.0, 0.3, 0.5, 1.0] {
                assert!((el.axial_strain(&e, xi) - expected).abs() < 1e-14, "δ = {d}, ξ = {xi}");
                assert!(el.curvature(&e, xi).abs() < 1e-12, "δ = {d}, ξ = {xi}: κ = {}", el.curvature(&e, xi));
            }
        }
    }

    /// The nodes and unit tangents of an arc of radius R and angle φ (an element of length
    /// Rφ): the curvature is 1/R, counter-clockwise positive, and clockwise −1/R. The cubic
    /// interpolation of the arc is second order in φ: the error found is φ²/12 at the nodes
    /// and φ²/24 at the middle, so it stays under φ²/11 and falls fourfold when φ halves;
    /// the strain of the unstretched arc is of order φ⁴ (below φ²/100 here).
    #[test]
    fn an_element_bent_into_a_circular_arc_has_curvature_one_over_r() {
        let r = 2.0;
        let mut last = None;
        for phi in [0.2_f64, 0.1, 0.05] {
            let el = BeamElement::new(r * phi, SEC);
            let arc = |sign: f64| {
                let (c, s) = (phi.cos(), phi.sin());
                // counter-clockwise from (R, 0); clockwise: mirrored in y
                Vec8::from_column_slice(&[r, 0.0, 0.0, sign, r * c, sign * r * s, -s, sign * c])
            };
            let mut worst: f64 = 0.0;
            for xi in [0.0, 0.25, 0.5, 0.75, 1.0] {
                let k = el.curvature(&arc(1.0), xi);
                worst = worst.max((k * r - 1.0).abs());
                assert!((k * r - 1.0).abs() <= phi * phi / 11.0, "φ = {phi}, ξ = {xi}: κR = {}", k * r);
                assert!((el.curvature(&arc(-1.0), xi) + k).abs() < 1e-12, "clockwise: −κ");
                assert!(el.axial_strain(&arc(1.0), xi).abs() <= phi * phi / 100.0);
            }
            if let Some(w) = last {
                let ratio: f64 = w / worst;
                assert!((ratio - 4.0).abs() < 0.1, "second order: the error fell {ratio}× when φ halved");
            }
            last = Some(worst);
        }
    }
}
