//! Natural frequencies from `flexrom::analysis::modes` (shift-invert subspace iteration in
//! the null space of the constraints) against Euler–Bernoulli beam theory, with mesh
//! convergence:
//!
//! * clamped–free: `f_i = (β_i L)²/(2π L²) √(EI/ρA)` with `β_i L = 1.8751, 4.6941, 7.8548`
//!   (roots of `cos βL cosh βL = −1`; Rao, *Mechanical Vibrations*, Table 8.4);
//! * pinned–free (a ground pin at one end, the other free): one rigid rotation, 0 Hz, then
//!   `β_i L = 3.9266, 7.0686` (roots of `tan βL = tanh βL`; Blevins, *Formulas for Natural
//!   Frequency and Mode Shape*, Table 8-1).
//!
//! The bounds: the error of cubic Hermite elements falls as `h⁴` in the frequencies, so the
//! error at 2n elements must be at most a third of the error at n (an eighth would be h³;
//! the table's five digits limit what is seen at the finest mesh), and at 16 elements within
//! 0.1 % for the modes listed. The axial modes of this slender section (`EA/EI = 1.2e5 m⁻²`)
//! lie far above the bending modes asked for.

mod common;

use flexrom::analysis::modes::{compute, unconstrained};
use flexrom::solver::model::Parameters;

const L: f64 = 1.0;
const E: f64 = 2.1e11;
const A: f64 = 1e-4;
const I: f64 = 1e-8 / 12.0;
const RHO: f64 = 7800.0;

fn beam(elements: usize, joint: &str) -> flexrom::model::Model {
    common::model(&format!(
        r#"
        [time]
        t_end = 1.0
        dt = 0.01
        rho_inf = 1.0
        [[bodies]]
        name = "beam"
        start = [0.0, 0.0]
        angle = 0.0
        length = {L}
        elements = {elements}
        density = {RHO}
        area = {A}
        inertia = {I}
        youngs_modulus = {E}
        [[joints]]
        type = "{joint}"
        body = "beam"
        node = "start"
        "#
    ))
}

fn frequencies(elements: usize, joint: &str, count: usize) -> Vec<f64> {
    let m = beam(elements, joint);
    let sys = m.system(Default::default());
    let q = sys.initial_state();
    compute(&sys, &Parameters::default(), &q, 0.0, count, Default::default()).expect("modes converge").frequencies
}

fn exact(bl: f64) -> f64 {
    bl * bl / (2.0 * std::f64::consts::PI * L * L) * (E * I / (RHO * A)).sqrt()
}

fn check_convergence(joint: &str, first: usize, table: &[f64]) {
    let mut last: Option<Vec<f64>> = None;
    for elements in [4, 8, 16] {
        let f = frequencies(elements, joint, first + table.len());
        let errors: Vec<f64> =
            table.iter().enumerate().map(|(i, &bl)| (f[first + i] / exact(bl) - 1.0).abs()).collect();
        if let Some(prev) = &last {
            for (i, (e, p)) in errors.iter().zip(prev).enumerate() {
                // below 1e-5 the table's own digits (5 significant) dominate
                assert!(
                    *e <= p / 3.0 || *e < 1e-5,
                    "{joint}, mode {}: error {e:.2e} at {elements} elements, {p:.2e} at half",
                    i + 1
                );
            }
        }
        if elements == 16 {
            for (i, e) in errors.iter().enumerate() {
                assert!(*e < 1e-3, "{joint}, mode {}: f = {} Hz vs {} Hz", i + 1, f[first + i], exact(table[i]));
            }
        }
        last = Some(errors);
    }
}

#[test]
fn clamped_free_frequencies_converge_to_euler_bernoulli() {
    check_convergence("clamp", 0, &[1.8751, 4.6941, 7.8548]);
}

#[test]
fn pinned_free_beam_has_one_rigid_mode_then_euler_bernoulli() {
    let f = frequencies(16, "ground_pin", 3);
    assert_eq!(f[0], 0.0, "the rotation about the pin is rigid: {f:?}");
    assert!(f[1] > 0.0);
    check_convergence("ground_pin", 1, &[3.9266, 7.0686]);
}

/// The subspace method gives what a dense generalized eigensolver gives on the clamped
/// beam's bending coordinates (tests/modal.rs's reduction: about the straight state the
/// bending and axial coordinates decouple), to 1e-9, for more modes than the subspace
/// iteration resolves at once.
#[test]
fn subspace_iteration_matches_the_dense_eigensolver() {
    use flexrom::linalg::lapack::{Eigh, UPLO};
    use ndarray::Array2;
    let m = beam(12, "clamp");
    let sys = m.system(Default::default());
    let q = sys.initial_state();
    let n = q.len();
    let (mm, kk) = sys.dense_mass_and_stiffness(&q);
    let keep: Vec<usize> = (4..n).collect();
    let pick = |src: &[f64]| Array2::from_shape_fn((keep.len(), keep.len()), |(r, c)| src[keep[r] * n + keep[c]]);
    let (w2, _) = (pick(&kk), pick(&mm)).eigh(UPLO::Lower).unwrap();
    let got = compute(&sys, &Parameters::default(), &q, 0.0, 10, Default::default()).unwrap();
    for i in 0..10 {
        let rel = (got.omega_squared[i] / w2[i] - 1.0).abs();
        assert!(rel < 1e-9, "mode {}: ω² = {} vs dense {}", i + 1, got.omega_squared[i], w2[i]);
    }
}

/// Asking for more modes than the unconstrained coordinates is refused with the count.
#[test]
fn count_above_the_unconstrained_coordinates_is_refused() {
    let m = beam(2, "clamp");
    let sys = m.system(Default::default());
    assert_eq!(unconstrained(&sys), 8);
    let q = sys.initial_state();
    // the library names the option by its key; the command line writes it as its flag
    let e = compute(&sys, &Parameters::default(), &q, 0.0, 9, Default::default()).unwrap_err();
    assert!(e.to_string().starts_with("count = 9: "), "{e}");
    let e = e.render(&|k: &str, v: Option<&str>| format!("--{k} {}", v.unwrap_or_default()));
    assert!(e.contains("--count 9") && e.contains("8 unconstrained coordinates"), "{e}");
    let all = compute(&sys, &Parameters::default(), &q, 0.0, 8, Default::default()).unwrap();
    assert_eq!(all.len(), 8);
}
