//! The planar ANCF beam element of SPEC §1 (thesis §2), Berzeri–Shabana simple model.
//!
//! Element vector `e = [x_A, y_A, x'_A, y'_A, x_B, y_B, x'_B, y'_B]`; every matrix is a 4×4
//! scalar block ⊗ I₂, so the x and y components never mix in the constant matrices.
//!
//! * mass `M = ρA ∫₀ˡ SᵀS ds` (constant),
//! * bending `K_t = EI ∫ S''ᵀS'' ds` (constant), `U_t = ½ eᵀK_t e`,
//! * axial `S_l = ∫ S'ᵀS' ds`, mean Green strain `ε̄ = eᵀS_l e/(2l) − ½`, `U_l = ½ EA l ε̄²`,
//!   `Q_l = EA ε̄ S_l e`, `K_l = EA ε̄ S_l + (EA/l)(S_l e)(S_l e)ᵀ`,
//! * elastic force `Q_e = K_t e + Q_l`, tangent `K_T = K_t + K_l`.

use nalgebra::{SMatrix, SVector};

pub type Vec8 = SVector<f64, 8>;
pub type Mat8 = SMatrix<f64, 8, 8>;

/// Cross-section and material of a beam.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    /// ρ, kg/m³
    pub density: f64,
    /// A, m²
    pub area: f64,
    /// I, m⁴
    pub inertia: f64,
    /// E, N/m²
    pub youngs_modulus: f64,
}

impl Section {
    pub fn mass_per_length(&self) -> f64 {
        self.density * self.area
    }
    pub fn ea(&self) -> f64 {
        self.youngs_modulus * self.area
    }
    pub fn ei(&self) -> f64 {
        self.youngs_modulus * self.inertia
    }
}

/// Expands a 4×4 scalar block to the 8×8 element matrix `B ⊗ I₂`.
fn kron_i2(b: &[[f64; 4]; 4]) -> Mat8 {
    let mut m = Mat8::zeros();
    for i in 0..4 {
        for j in 0..4 {
            m[(2 * i, 2 * j)] = b[i][j];
            m[(2 * i + 1, 2 * j + 1)] = b[i][j];
        }
    }
    m
}

/// A 4×4 scalar block `B` laid out for `(B ⊗ I₂) e` in 8-wide vector arithmetic: column
/// `j` of `B`, each entry twice (`[B₀ⱼ, B₀ⱼ, B₁ⱼ, B₁ⱼ, B₂ⱼ, B₂ⱼ, B₃ⱼ, B₃ⱼ]`).
type KronCols = [[f64; 8]; 4];

fn kron_cols(b: &[[f64; 4]; 4]) -> KronCols {
    std::array::from_fn(|j| std::array::from_fn(|k| b[k / 2][j]))
}

/// `(B ⊗ I₂) e`: x and y components separately, 32 multiply-adds instead of 64, as four
/// 8-wide multiply-adds (column j of `B` times the pair `(e_{2j}, e_{2j+1})`). Entry `2i + c`
/// sums `B_ij e_{2j+c}` over j = 0..3 from zero, in that order.
#[inline(always)]
fn kron_i2_mul(b: &KronCols, e: &[f64; 8]) -> [f64; 8] {
    let mut out = [0.0; 8];
    for (j, col) in b.iter().enumerate() {
        for k in 0..8 {
            out[k] += col[k] * e[2 * j + (k & 1)];
        }
    }
    out
}

/// `e` less the rigid translation that puts node A at the origin. The elastic terms do not
/// change (`K_t` and `S_l` annihilate translations), their rounding does: with absolute
/// positions `K_t e` sums terms of size EI|x|/l³ that cancel to a curvature's force, and
/// rounds at a few ε_mach EI|x|/l³ — 4e-4 N for the 5000-element pendulum's 0.24 mm
/// elements a metre from the origin, where a 1e-13 m move of a node changes the force by
/// 0.74 N (12 EI/l³ · 1e-13 m). That rounding changes with every iterate, so it, not the
/// Newton tolerance, decided where Newton stopped (the "steps at the round-off floor" of
/// `simulate -v`: 123 of that pendulum's 220 steps at λ = 1).
/// The differences of nearby positions are exact (Sterbenz), and from them every term is
/// of the size of the result.
#[inline(always)]
pub fn without_translation(e: &[f64; 8]) -> [f64; 8] {
    [0.0, 0.0, e[2], e[3], e[4] - e[0], e[5] - e[1], e[6], e[7]]
}

/// Cubic Hermite shape functions `[S1, S2, S3, S4]` at `ξ = s/l` (SPEC §1).
pub fn shape_functions(xi: f64, l: f64) -> [f64; 4] {
    let (x2, x3) = (xi * xi, xi * xi * xi);
    [1.0 - 3.0 * x2 + 2.0 * x3, l * (xi - 2.0 * x2 + x3), 3.0 * x2 - 2.0 * x3, l * (x3 - x2)]
}

/// One element's constant matrices; all elements of a body share one.
#[derive(Clone, Debug)]
pub struct BeamElement {
    pub length: f64,
    pub section: Section,
    /// scalar 4×4 block of `S_l`
    sl: [[f64; 4]; 4],
    /// `S_l`, `M` and `K_t` laid out for the fast products `(B ⊗ I₂) e`
    sl_cols: KronCols,
    mass_cols: KronCols,
    bending_cols: KronCols,
    mass: Mat8,
    bending: Mat8,
    axial: Mat8,
}

impl BeamElement {
    pub fn new(length: f64, section: Section) -> Self {
        let l = length;
        let (l2, l3) = (l * l, l * l * l);
        let m = section.mass_per_length() * l / 420.0;
        let mass = [
            [156.0 * m, 22.0 * l * m, 54.0 * m, -13.0 * l * m],
            [22.0 * l * m, 4.0 * l2 * m, 13.0 * l * m, -3.0 * l2 * m],
            [54.0 * m, 13.0 * l * m, 156.0 * m, -22.0 * l * m],
            [-13.0 * l * m, -3.0 * l2 * m, -22.0 * l * m, 4.0 * l2 * m],
        ];
        let k = section.ei() / l3;
        let bending = [
            [12.0 * k, 6.0 * l * k, -12.0 * k, 6.0 * l * k],
            [6.0 * l * k, 4.0 * l2 * k, -6.0 * l * k, 2.0 * l2 * k],
            [-12.0 * k, -6.0 * l * k, 12.0 * k, -6.0 * l * k],
            [6.0 * l * k, 2.0 * l2 * k, -6.0 * l * k, 4.0 * l2 * k],
        ];
        let sl = [
            [6.0 / (5.0 * l), 0.1, -6.0 / (5.0 * l), 0.1],
            [0.1, 2.0 * l / 15.0, -0.1, -l / 30.0],
            [-6.0 / (5.0 * l), -0.1, 6.0 / (5.0 * l), -0.1],
            [0.1, -l / 30.0, -0.1, 2.0 * l / 15.0],
        ];
        BeamElement {
            length,
            section,
            sl,
            sl_cols: kron_cols(&sl),
            mass_cols: kron_cols(&mass),
            bending_cols: kron_cols(&bending),
            mass: kron_i2(&mass),
            bending: kron_i2(&bending),
            axial: kron_i2(&sl),
        }
    }

    /// Constant mass matrix `M = ρA ∫ SᵀS ds`.
    pub fn mass(&self) -> &Mat8 {
        &self.mass
    }

    /// Constant bending stiffness `K_t`.
    pub fn bending_stiffness(&self) -> &Mat8 {
        &self.bending
    }

    /// Axial matrix `S_l = ∫ S'ᵀS' ds`.
    pub fn axial_matrix(&self) -> &Mat8 {
        &self.axial
    }

    /// `S_l e`, using the ⊗ I₂ structure (32 multiply-adds instead of 64).
    #[inline]
    pub fn axial_product(&self, e: &Vec8) -> Vec8 {
        Vec8::from(kron_i2_mul(&self.sl_cols, &(*e).into()))
    }

    /// `M a`, using the ⊗ I₂ structure.
    #[inline]
    pub fn mass_product(&self, a: &Vec8) -> Vec8 {
        Vec8::from(kron_i2_mul(&self.mass_cols, &(*a).into()))
    }

    /// The element block of the Newton iteration matrix `m M + c C + k K_T(e)` from its
    /// constant part `constant = m M + c C + k K_t`:
    /// `constant + k EA ε̄ S_l + k (EA/l)(S_l e)(S_l e)ᵀ` (the ⊗ I₂ structure of `S_l` used;
    /// one pass instead of the three 8×8 sums of [`Self::tangent`]).
    #[inline]
    pub fn iteration_block(&self, constant: &Mat8, k: f64, e: &Vec8) -> Mat8 {
        let mut out = Mat8::zeros();
        let (sle, a, b) = self.iteration_scalars(k, e);
        self.iteration_block_from(constant, &sle, a, b, &mut out);
        out
    }

    /// The state-dependent part of [`Self::iteration_block`]: `S_l e`, `a = k EA ε̄` and
    /// `b = k EA/l` (a dependency chain, dot product to division, which a loop over the
    /// elements runs for several elements at once before it writes their blocks).
    #[inline(always)]
    pub fn iteration_scalars(&self, k: f64, e: &Vec8) -> (Vec8, f64, f64) {
        let (_, sle, eps) = self.axial_state(e);
        let ea = self.section.ea();
        (sle, k * ea * eps, k * ea / self.length)
    }

    /// `e` without its translation ([`without_translation`]), `S_l e` and `ε̄` from it.
    #[inline(always)]
    fn axial_state(&self, e: &Vec8) -> (Vec8, Vec8, f64) {
        let e = Vec8::from(without_translation(&(*e).into()));
        let sle = self.axial_product(&e);
        let eps = e.dot(&sle) / (2.0 * self.length) - 0.5;
        (e, sle, eps)
    }

    /// The block `constant + a S_l + b (S_l e)(S_l e)ᵀ` from [`Self::iteration_scalars`].
    #[inline(always)]
    pub fn iteration_block_from(&self, constant: &Mat8, sle: &Vec8, a: f64, b: f64, out: &mut Mat8) {
        let (c, o) = (constant.as_slice(), out.as_mut_slice());
        // (sᵢ sⱼ) b: the same rounding for (i, j) and (j, i), so a symmetric `constant`
        // gives a block symmetric to the bit (the band LDLᵀ checks it); column-major, k = 8 j + i
        for j in 0..8 {
            for i in 0..8 {
                o[8 * j + i] = c[8 * j + i] + sle[i] * sle[j] * b;
            }
        }
        for j in 0..4 {
            for i in 0..4 {
                let v = a * self.sl[i][j];
                o[8 * (2 * j) + 2 * i] += v;
                o[8 * (2 * j + 1) + 2 * i + 1] += v;
            }
        }
    }

    /// Mean Green strain `ε̄ = eᵀS_l e/(2l) − ½`; zero under rigid motion.
    pub fn mean_axial_strain(&self, e: &Vec8) -> f64 {
        self.axial_state(e).2
    }

    /// Strain energy `U = ½ eᵀK_t e + ½ EA l ε̄²`.
    pub fn strain_energy(&self, e: &Vec8) -> f64 {
        let (e, _, eps) = self.axial_state(e);
        0.5 * e.dot(&(self.bending * e)) + 0.5 * self.section.ea() * self.length * eps * eps
    }

    /// The strain energy's parts `(½ eᵀK_t e, ½ EA l ε̄²)`: bending, axial.
    pub fn strain_energy_parts(&self, e: &Vec8) -> (f64, f64) {
        let (e, _, eps) = self.axial_state(e);
        (0.5 * e.dot(&(self.bending * e)), 0.5 * self.section.ea() * self.length * eps * eps)
    }

    /// Elastic force `Q_e = K_t e + EA ε̄ S_l e` (thesis eq. 7).
    pub fn elastic_force(&self, e: &Vec8) -> Vec8 {
        Vec8::from(self.elastic(&(*e).into()))
    }

    #[inline(always)]
    fn elastic(&self, e: &[f64; 8]) -> [f64; 8] {
        let e = &without_translation(e);
        let sle = kron_i2_mul(&self.sl_cols, e);
        let eps = Vec8::from(*e).dot(&Vec8::from(sle)) / (2.0 * self.length) - 0.5;
        let s = self.section.ea() * eps;
        let kb = kron_i2_mul(&self.bending_cols, e);
        std::array::from_fn(|k| kb[k] + sle[k] * s)
    }

    /// The elastic force `Q_e = K_t e + EA ε̄ S_l e` and the inertia `M a` of the element in
    /// one pass, on plain arrays (the residual's loop over the elements,
    /// `FlexibleSystem::force_and_inertia`).
    #[inline(always)]
    pub fn force_and_inertia(&self, e: &[f64; 8], a: &[f64; 8]) -> ([f64; 8], [f64; 8]) {
        (self.elastic(e), kron_i2_mul(&self.mass_cols, a))
    }

    /// Exact tangent `K_T = K_t + EA ε̄ S_l + (EA/l)(S_l e)(S_l e)ᵀ` alone (the Newton matrix
    /// needs no force: the residual has computed it already).
    pub fn tangent(&self, e: &Vec8) -> Mat8 {
        let (_, sle, eps) = self.axial_state(e);
        let ea = self.section.ea();
        self.bending + self.axial * (ea * eps) + (sle * sle.transpose()) * (ea / self.length)
    }

    /// Generalized gravity force `Q_g = ρA ∫ Sᵀ g ds` for an acceleration field `g = (g_x, g_y)`.
    pub fn gravity_force(&self, g: [f64; 2]) -> Vec8 {
        let l = self.length;
        let w = self.section.mass_per_length();
        let ints = [l / 2.0, l * l / 12.0, l / 2.0, -l * l / 12.0];
        let mut q = Vec8::zeros();
        for i in 0..4 {
            q[2 * i] = w * ints[i] * g[0];
            q[2 * i + 1] = w * ints[i] * g[1];
        }
        q
    }

    /// Position `r(ξ) = S(ξ) e` of the material point at `s = ξ l`.
    pub fn position(&self, e: &Vec8, xi: f64) -> [f64; 2] {
        let s = shape_functions(xi, self.length);
        let mut r = [0.0; 2];
        for i in 0..4 {
            r[0] += s[i] * e[2 * i];
            r[1] += s[i] * e[2 * i + 1];
        }
        r
    }
}

#[cfg(test)]
mod tests {
    //! References: closed forms are checked against Gauss–Legendre quadrature of the
    //! defining integrals (SPEC §1) with the shape functions' own derivatives; the tangent
    //! against central finite differences of the force.
    use super::*;

    const SEC: Section = Section { density: 5540.0, area: 1.8e-3, inertia: 1.215e-8, youngs_modulus: 0.7e9 };

    /// 5-point Gauss–Legendre on [0, 1] (exact for degree ≤ 9; every integrand here is ≤ 6).
    fn gauss5() -> [(f64, f64); 5] {
        let p = [0.0, -0.538_469_310_105_683_1, 0.538_469_310_105_683_1, -0.906_179_845_938_664, 0.906_179_845_938_664];
        let w = [
            0.568_888_888_888_888_9,
            0.478_628_670_499_366_5,
            0.478_628_670_499_366_5,
            0.236_926_885_056_189_1,
            0.236_926_885_056_189_1,
        ];
        std::array::from_fn(|i| (0.5 * (p[i] + 1.0), 0.5 * w[i]))
    }

    /// dS/dξ and d²S/dξ² of the shape functions, derived by hand from `shape_functions`.
    fn dshape(xi: f64, l: f64) -> ([f64; 4], [f64; 4]) {
        let d1 = [
            -6.0 * xi + 6.0 * xi * xi,
            l * (1.0 - 4.0 * xi + 3.0 * xi * xi),
            6.0 * xi - 6.0 * xi * xi,
            l * (3.0 * xi * xi - 2.0 * xi),
        ];
        let d2 = [-6.0 + 12.0 * xi, l * (-4.0 + 6.0 * xi), 6.0 - 12.0 * xi, l * (6.0 * xi - 2.0)];
        (d1, d2)
    }

    fn quadrature(l: f64, f: impl Fn(f64) -> [[f64; 4]; 4]) -> Mat8 {
        let mut acc = [[0.0; 4]; 4];
        for (xi, w) in gauss5() {
            let v = f(xi);
            for i in 0..4 {
                for j in 0..4 {
                    acc[i][j] += w * l * v[i][j];
                }
            }
        }
        kron_i2(&acc)
    }

    fn outer(a: [f64; 4], b: [f64; 4]) -> [[f64; 4]; 4] {
        std::array::from_fn(|i| std::array::from_fn(|j| a[i] * b[j]))
    }

    fn assert_close(a: &Mat8, b: &Mat8, rtol: f64) {
        let scale = b.amax();
        assert!((a - b).amax() <= rtol * scale, "max diff {} vs scale {}", (a - b).amax(), scale);
    }

    #[test]
    fn mass_matches_its_defining_integral() {
        let l = 0.37;
        let el = BeamElement::new(l, SEC);
        let q = quadrature(l, |xi| outer(shape_functions(xi, l), shape_functions(xi, l))) * SEC.mass_per_length();
        assert_close(el.mass(), &q, 1e-13);
        // total mass: the translation mode (1,0,0,0,1,0,0,0) carries ρAl
        let t = Vec8::from_column_slice(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
        assert!((t.dot(&(el.mass() * t)) - SEC.mass_per_length() * l).abs() < 1e-12);
    }

    #[test]
    fn bending_and_axial_match_their_integrals() {
        let l = 0.37;
        let el = BeamElement::new(l, SEC);
        let kt = quadrature(l, |xi| {
            let d2 = dshape(xi, l).1.map(|v| v / (l * l));
            outer(d2, d2)
        }) * SEC.ei();
        assert_close(el.bending_stiffness(), &kt, 1e-12);
        let sl = quadrature(l, |xi| {
            let d1 = dshape(xi, l).0.map(|v| v / l);
            outer(d1, d1)
        });
        assert_close(el.axial_matrix(), &sl, 1e-13);
        let e = Vec8::from_fn(|i, _| (i as f64 * 0.7).sin());
        assert!((el.axial_product(&e) - el.axial_matrix() * e).amax() < 1e-14);
    }

    #[test]
    fn gravity_matches_spec_closed_form() {
        // SPEC §1: Q_g = −ρAg [0, l/2, 0, l²/12, 0, l/2, 0, −l²/12]
        let l = 0.024;
        let el = BeamElement::new(l, SEC);
        let q = el.gravity_force([0.0, -9.81]);
        let w = SEC.mass_per_length() * 9.81;
        let expected = [0.0, -w * l / 2.0, 0.0, -w * l * l / 12.0, 0.0, -w * l / 2.0, 0.0, w * l * l / 12.0];
        for i in 0..8 {
            assert!((q[i] - expected[i]).abs() < 1e-15, "entry {i}");
        }
    }

    fn rigid_state(l: f64, p: [f64; 2], theta: f64) -> Vec8 {
        let (c, s) = (theta.cos(), theta.sin());
        Vec8::from_column_slice(&[p[0], p[1], c, s, p[0] + l * c, p[1] + l * s, c, s])
    }

    #[test]
    fn rigid_motion_gives_zero_force() {
        // A straight unstretched beam in any position and orientation stores no energy.
        let l = 0.3;
        let el = BeamElement::new(l, SEC);
        for (p, th) in [([0.0, 0.0], 0.0), ([1.3, -0.4], 0.7), ([-2.0, 5.0], 2.9), ([0.1, 0.2], -1.3)] {
            let e = rigid_state(l, p, th);
            let f = el.elastic_force(&e);
            assert!(el.mean_axial_strain(&e).abs() < 1e-14);
            assert!(f.amax() < 1e-9 * SEC.ea(), "force {f} at {p:?}, {th}");
        }
    }

    #[test]
    fn uniform_stretch_gives_expected_strain() {
        // r' = (1+δ)(cos θ, sin θ) along the whole element: Green strain ((1+δ)² − 1)/2.
        let (l, d, th): (f64, f64, f64) = (0.5, 0.01, 0.4);
        let el = BeamElement::new(l, SEC);
        let (c, s) = ((1.0 + d) * th.cos(), (1.0 + d) * th.sin());
        let e = Vec8::from_column_slice(&[0.0, 0.0, c, s, l * c, l * s, c, s]);
        let expected = ((1.0 + d).powi(2) - 1.0) / 2.0;
        assert!((el.mean_axial_strain(&e) - expected).abs() < 1e-14);
    }

    #[test]
    fn tangent_matches_finite_differences_of_force() {
        let l = 0.2;
        let el = BeamElement::new(l, SEC);
        let e = rigid_state(l, [0.1, 0.3], 0.6) + Vec8::from_fn(|i, _| 0.01 * ((i * 7 % 5) as f64 - 2.0));
        let kt = el.tangent(&e);
        let h = 1e-6;
        let mut fd = Mat8::zeros();
        for j in 0..8 {
            let mut ep = e;
            let mut em = e;
            ep[j] += h;
            em[j] -= h;
            fd.set_column(j, &((el.elastic_force(&ep) - el.elastic_force(&em)) / (2.0 * h)));
        }
        let rel = (kt - fd).amax() / kt.amax();
        assert!(rel < 1e-6, "relative tangent error {rel}");
    }

    /// A 0.24 mm element (the 5000-element pendulum's) a metre from the origin, bent and
    /// stretched a little: moving one node by 1e-13 m changes its elastic force (by 0.74 N)
    /// as the tangent says, to 1e-6 of the change (measured 8e-9). The force summed over the
    /// absolute coordinates rounds at a few ε_mach |K_t||x| and misses the change by 5e-4 of
    /// it: that noise, not the tolerance, would decide where Newton stops on fine meshes. The test fails without [`without_translation`].
    #[test]
    fn the_force_of_a_small_element_far_from_the_origin_follows_its_tangent() {
        let (l, angle) = (1.2 / 5000.0, 0.6_f64);
        let el = BeamElement::new(l, SEC);
        let (c, s) = (angle.cos(), angle.sin());
        let e = Vec8::from_column_slice(&[
            1.0,
            0.5,
            c,
            s,
            1.0 + l * (1.0 + 1e-5) * c,
            0.5 + l * (1.0 + 1e-5) * s,
            c - 1e-4 * s,
            s + 1e-4 * c,
        ]);
        let mut moved = e;
        moved[4] += 1e-13;
        let delta = moved[4] - e[4];
        let expected = el.tangent(&e).column(4) * delta;
        let change = el.elastic_force(&moved) - el.elastic_force(&e);
        let miss = (change - expected).amax() / expected.amax();
        assert!(miss < 1e-6, "the force's change missed the tangent's by {miss:e}");
        let direct = |e: &Vec8| {
            let sle = el.axial_matrix() * e;
            el.bending_stiffness() * e + sle * (SEC.youngs_modulus * SEC.area * (e.dot(&sle) / (2.0 * l) - 0.5))
        };
        let direct_miss = (direct(&moved) - direct(&e) - expected).amax() / expected.amax();
        assert!(direct_miss > 1e-4, "the direct sum followed the tangent ({direct_miss:e}): the test shows nothing");
    }

    /// The fused iteration block equals `m M + c C + k K_T` summed the plain way.
    #[test]
    fn iteration_block_matches_mass_damping_and_tangent() {
        let l = 0.2;
        let el = BeamElement::new(l, SEC);
        let e = rigid_state(l, [0.1, 0.3], 0.6) + Vec8::from_fn(|i, _| 0.01 * ((i * 7 % 5) as f64 - 2.0));
        let (m, c, k) = (1.0, 0.7, 3e-5);
        let damping = el.mass() * 0.2 + el.bending_stiffness() * 1e-3;
        let constant = el.mass() * m + damping * c + el.bending_stiffness() * k;
        let plain = el.mass() * m + damping * c + el.tangent(&e) * k;
        let fused = el.iteration_block(&constant, k, &e);
        assert_close(&fused, &plain, 1e-14);
        assert_eq!(fused, fused.transpose(), "symmetric to the bit");
        let a = Vec8::from_fn(|i, _| (i as f64 * 1.3).cos());
        assert!((el.mass_product(&a) - el.mass() * a).amax() <= 1e-15 * (el.mass() * a).amax());
    }

    #[test]
    fn force_is_gradient_of_energy() {
        let l = 0.2;
        let el = BeamElement::new(l, SEC);
        let e = rigid_state(l, [0.0, 0.0], 0.2) + Vec8::from_fn(|i, _| 0.003 * (i as f64).cos());
        let f = el.elastic_force(&e);
        let h = 1e-7;
        for j in 0..8 {
            let mut ep = e;
            let mut em = e;
            ep[j] += h;
            em[j] -= h;
            let g = (el.strain_energy(&ep) - el.strain_energy(&em)) / (2.0 * h);
            assert!((g - f[j]).abs() <= 1e-6 * f.amax(), "dof {j}: {g} vs {}", f[j]);
        }
    }
}
