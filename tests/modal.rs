//! Bending frequencies of a clamped–free beam, 20 elements, linearized about the straight
//! state, against Euler–Bernoulli theory: ω_i = (β_i L)² √(EI/(ρA L⁴)) with
//! β_i L = 1.8751, 4.6941, 7.8548 (roots of cos βL cosh βL = −1; e.g. Rao, *Mechanical
//! Vibrations*, Table 8.4). Bound: 0.5 % (20 cubic elements resolve the first three modes
//! to well within it).

mod common;

use flexrom::linalg::lapack::{Eigh, UPLO};
use ndarray::Array2;

#[test]
fn clamped_free_bending_frequencies_match_euler_bernoulli() {
    let (l, e, a, i, rho): (f64, f64, f64, f64, f64) = (1.2, 0.7e9, 1.8e-3, 1.215e-8, 5540.0);
    let m = common::cantilever_with_density(20, l, e, a, i, rho, 0.0);
    let sys = m.system(Default::default());
    let q0 = sys.initial_state();
    let n = q0.len();
    let (mm, kk) = sys.dense_mass_and_stiffness(&q0);
    // About the straight state along x, bending (y, y') and axial (x, x') decouple.
    let bending: Vec<usize> = (1..n / 4).flat_map(|k| [4 * k + 1, 4 * k + 3]).collect();
    let axial: Vec<usize> = (1..n / 4).flat_map(|k| [4 * k, 4 * k + 2]).collect();
    for &r in &bending {
        for &c in &axial {
            assert!(kk[r * n + c].abs() < 1e-9 * kk[r * n + r].abs(), "bending–axial coupling at ({r}, {c})");
        }
    }
    let pick =
        |src: &[f64]| Array2::from_shape_fn((bending.len(), bending.len()), |(r, c)| src[bending[r] * n + bending[c]]);
    let (w2, _) = (pick(&kk), pick(&mm)).eigh(UPLO::Lower).expect("generalized symmetric eigenproblem");
    let scale = (e * i / (rho * a * l.powi(4))).sqrt();
    for (k, bl) in [1.8751_f64, 4.6941, 7.8548].iter().enumerate() {
        let exact = bl * bl * scale;
        let omega = w2[k].sqrt();
        let rel = (omega - exact).abs() / exact;
        assert!(rel < 5e-3, "mode {}: ω = {omega} rad/s vs {exact} (rel {rel:.2e})", k + 1);
    }
}
