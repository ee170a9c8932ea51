//! The rotary inertia of a point mass (SPEC §6, src/physics/masses.rs) against closed forms,
//! on the bar of tests/springs.rs: a 0.5 m stiff steel bar pinned to a clamped stub by a
//! torsional spring `k`, with a point mass at the pin carrying a rotary inertia `J_p`. The
//! pin's position is held, so only `J_p` of the point mass acts:
//!
//! * `flexrom modes`: the lowest frequency `√(k/(J + J_p))/2π`, `J = ρAL³/3` the bar's about
//!   its end (the stub's and the bar's bending soften it by ~1e-4, as in tests/springs.rs);
//! * a run started turning at ω₀: the angle `θ = (ω₀/ω) sin ωt`; the inertia is linearized
//!   about the initial slope, off by `θ²/2` ≈ 1.3e-4 at the amplitude ω₀/ω = 0.016 rad, and
//!   the bending and the integrator's period error add 2.8e-4 (tests/springs.rs), so after two
//!   periods the phase is off by 2π·2·4e-4 = 5e-3 rad per rad of amplitude: the bound 6e-3;
//! * the energies: at t = 0 the kinetic energy is `½ (J + J_p) ω₀²` (the cubic ANCF mass
//!   carries the rigid rotation exactly; the slope's velocity `ω₀ × r'` feeds `J_p`), and at
//!   ρ∞ = 1 the total `T + U + V_s` keeps to 1e-3 of it;
//! * an explicit `rotary_inertia = 0` gives the same bits as none;
//! * bad input: a negative or NaN rotary inertia, refused naming `masses[0].rotary_inertia`.

mod common;

use common::lowest_frequency;
use flexrom::model::Model;
use flexrom::simulate::{simulate, with_energies, Overrides, SimulationResult};

const STIFF_STEEL: &str = "density = 7850.0\narea = 1.0e-4\ninertia = 8.33e-10\nyoungs_modulus = 2.1e13";
/// `J = ρAL³/3` of the 0.5 m bar about its end.
const BAR_J: f64 = 7850.0 * 1.0e-4 * 0.125 / 3.0;
/// The point's rotary inertia: three times the bar's, so the frequency halves.
const J_P: f64 = 3.0 * BAR_J;

/// The stub and the bar of tests/springs.rs's torsion bar, with `masses` (a TOML entry or
/// nothing) and the bar started turning at `w0` about its start.
fn torsion_bar(k: f64, w0: f64, masses: &str) -> String {
    format!(
        "[time]\nt_end = 0.2\ndt = 0.0005\nrho_inf = 1.0\n\
         [[bodies]]\nname = \"stub\"\nstart = [0.0, 0.0]\nangle = 0.0\nlength = 0.05\nelements = 1\n{STIFF_STEEL}\n\
         [[bodies]]\nname = \"bar\"\nstart = [0.05, 0.0]\nangle = 0.0\nlength = 0.5\nelements = 4\n{STIFF_STEEL}\nangular_velocity = {w0}\n\
         [[joints]]\ntype = \"clamp\"\nbody = \"stub\"\nnode = \"start\"\n\
         [[joints]]\ntype = \"pin\"\na = {{ body = \"stub\", node = \"end\" }}\nb = {{ body = \"bar\", node = \"start\" }}\n\
         [[springs]]\ntype = \"torsional\"\na = {{ body = \"stub\", node = \"end\" }}\nb = {{ body = \"bar\", node = \"start\" }}\nstiffness = {k}\n\
         {masses}\
         [[probes]]\nname = \"tip\"\nbody = \"bar\"\nnode = \"end\"\n"
    )
}

fn hub(rotary: &str) -> String {
    format!("[[masses]]\nbody = \"bar\"\nnode = \"start\"\nmass = 0.2\n{rotary}\n")
}

fn model(text: &str) -> Model {
    Model::from_text(text, "test.toml").unwrap()
}

fn run(text: &str) -> SimulationResult {
    simulate(&model(text), &Overrides::default()).unwrap()
}

#[test]
fn modes_include_the_rotary_inertia() {
    let k = 50.0;
    let f = lowest_frequency(&torsion_bar(k, 0.0, &hub(&format!("rotary_inertia = {J_P}"))));
    let expected = (k / (BAR_J + J_P)).sqrt() / (2.0 * std::f64::consts::PI);
    assert!((f - expected).abs() < 1e-3 * expected, "{f} Hz against {expected} Hz");
}

#[test]
fn a_bar_with_a_rotary_inertia_swings_at_the_root_of_k_over_the_sum_and_keeps_its_energy() {
    let (k, w0) = (50.0, 1.0);
    let text = torsion_bar(k, w0, &hub(&format!("rotary_inertia = {J_P}")));
    let r = with_energies(&model(&text), run(&text)).unwrap();
    let w = (k / (BAR_J + J_P)).sqrt();
    let tip = &r.probes.iter().find(|(n, _)| n == "tip").expect("probe").1;
    let amplitude = w0 / w;
    let dev =
        r.t.iter()
            .enumerate()
            .map(|(i, &t)| (tip[(i, 1)].atan2(tip[(i, 0)] - 0.05) - amplitude * (w * t).sin()).abs())
            .fold(0.0, f64::max);
    assert!(dev < 6e-3 * amplitude, "deviation {dev:.3e} rad against an amplitude of {amplitude:.3e} rad");
    let e = r.energy.as_ref().expect("a full run's energies");
    let t0 = 0.5 * (BAR_J + J_P) * w0 * w0;
    assert!((e.kinetic[0] - t0).abs() < 1e-9 * t0, "kinetic {} J against {t0} J", e.kinetic[0]);
    let total = e.total();
    let drift = total.iter().map(|v| (v - total[0]).abs()).fold(0.0_f64, f64::max);
    assert!(drift < 1e-3 * t0, "drift {drift:.3e} J against {t0:.3e} J");
}

#[test]
fn a_zero_rotary_inertia_gives_the_same_bits_as_none() {
    let a = run(&torsion_bar(50.0, 1.0, &hub("")));
    let b = run(&torsion_bar(50.0, 1.0, &hub("rotary_inertia = 0.0")));
    assert_eq!(a.q, b.q);
}

#[test]
fn a_bad_rotary_inertia_is_refused_naming_its_key() {
    for bad in ["-1.0", "nan"] {
        let text = torsion_bar(50.0, 0.0, &hub(&format!("rotary_inertia = {bad}")));
        let e = Model::from_text(&text, "bad.toml").unwrap_err().to_string();
        assert!(e.contains("bad.toml") && e.contains("masses[0].rotary_inertia") && e.contains("line"), "{e}");
    }
}
