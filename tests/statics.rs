//! Static cantilever checks of the element and the KKT machinery.
//!
//! * small tip load: Euler–Bernoulli tip deflection δ = PL³/(3EI) (any strength-of-materials
//!   text, e.g. Timoshenko & Gere, *Mechanics of Materials*); cubic Hermite elements are
//!   nodally exact for this load, so the bound is 0.1 %;
//! * large deflection: the elastica of a tip-loaded cantilever, Mattiasson (1981),
//!   *Int. J. Numer. Meth. Eng.* 17:145–153, Table 1: PL²/EI = 1 gives v/L = 0.30172,
//!   u/L = 0.05643, tip rotation 0.46135 rad; PL²/EI = 10 gives v/L = 0.81061, u/L = 0.55500
//!   (reproduced to all five digits by an independent shooting solution of θ'' = −k cos θ).

mod common;

use flexrom::solver::model::{Bound, Parameters, ParametricModel};
use flexrom::solver::statics::solve_static;

const L: f64 = 1.0;
const E: f64 = 2.1e11;
// 10 mm × 10 mm steel section: EA/EI = 1.2e5 m⁻², a slender beam (axial strain ≪ 1e-3)
const A: f64 = 1e-4;
const I: f64 = 1e-8 / 12.0;

/// Tip position and slope after `steps` load increments to the full load.
fn solve(elements: usize, p: f64, steps: usize) -> ([f64; 2], [f64; 2]) {
    let m = common::cantilever(elements, L, E, A, I, p);
    let mut sys = m.system(Default::default());
    let mut q = sys.initial_state();
    for k in 1..=steps {
        let mu = Parameters::new(k as f64 / steps as f64);
        solve_static(&mut Bound::new(&mut sys, &mu), &mut q, 0.0, 1e-12, 30).expect("static Newton converges");
    }
    let n = sys.n_dof();
    ([q[n - 4], q[n - 3]], [q[n - 2], q[n - 1]])
}

#[test]
fn small_tip_load_matches_beam_theory() {
    let p = 1e-4 * 3.0 * E * I / (L * L * L); // δ/L = 1e-4: geometric effects ~1e-8
    let expected = p * L.powi(3) / (3.0 * E * I);
    for elements in [1, 4, 10] {
        let (tip, _) = solve(elements, p, 1);
        let rel = (-tip[1] - expected).abs() / expected;
        assert!(rel < 1e-3, "{elements} elements: δ = {} vs PL³/3EI = {expected} (rel {rel:.2e})", -tip[1]);
    }
}

#[test]
fn large_deflection_matches_the_elastica() {
    let ei = E * I;
    // (PL²/EI, v/L, u/L) from Mattiasson (1981)
    for (k, v_ref, u_ref) in [(1.0, 0.30172, 0.05643), (10.0, 0.81061, 0.55500)] {
        let (tip, slope) = solve(20, k * ei / (L * L), 20);
        let (v, u) = (-tip[1] / L, (L - tip[0]) / L);
        assert!((v - v_ref).abs() < 5e-3 * v_ref, "k = {k}: v/L = {v} vs {v_ref}");
        assert!((u - u_ref).abs() < 5e-3 * u_ref, "k = {k}: u/L = {u} vs {u_ref}");
        if k == 1.0 {
            let phi = (-slope[1]).atan2(slope[0]);
            assert!((phi - 0.46135).abs() < 5e-3 * 0.46135, "tip rotation {phi}");
        }
    }
}
