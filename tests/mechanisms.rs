//! Sliders, welds and point masses (SPEC §6) against closed forms, each on a mechanism the
//! parts were not tuned on:
//!
//! * a free beam carrying a point mass falls at exactly `g`: mass and weight of the point
//!   mass enter together (the integrator is exact for constant acceleration, so the bound is
//!   round-off, 1e-9 of the distance fallen);
//! * a stiff pendulum with a tip mass swings with the physical pendulum's period
//!   `T = 2π √(I_O / (g (m_r L/2 + M L)))`, `I_O = m_r L²/3 + M L²`, corrected for the
//!   amplitude θ₀ by `1 + θ₀²/16` (any dynamics text, e.g. Meriam & Kraige §8/4); the beam's
//!   flexibility and Δt = T/400 leave well under 0.2 %;
//! * two collinear segments welded end to end move as one body of the same mesh: ANCF
//!   elements share exactly position and slope at a node, which is what the weld's rows hold
//!   (to Newton's tolerance, 1e-10 of the length);
//! * a stiff slider-crank keeps its slider on its line to round-off and follows the rigid
//!   crank-rod relation `x = c cos θ + √(L² − c² sin² θ)` to the rod's stretch (≪ 1e-6 m);
//! * a free beam thrown with a velocity and a spin (no gravity) moves rigidly: its centre at
//!   `v_c = v₀ + ω × (r_c − r_start)`, turning at ω about it (SPEC §6's initial velocity field;
//!   the spin stretches a steel beam by ρω²L²/E ~ 1e-7, so the bound is 1e-6 m);
//! * a reduced model of the tip-mass pendulum, started swinging with an angular velocity,
//!   stays within rel_error 1e-3 of the full one at a held-out load: its mass carries the
//!   point mass and its start the initial velocity;
//! * the tip-mass pendulum thrown at 1.5 rad/s with ρ∞ = 1 keeps its energy (kinetic with
//!   the point mass, gravity with its weight): the total drifts by under 1e-3 of the
//!   kinetic energy's peak (the trapezoidal rule's bound on the shipped pendulum,
//!   tests/pendulum.rs); the point mass carries three quarters of the mass;
//! * `modes --at static` of the stiff tip-mass pendulum hanging straight down: its lowest
//!   frequency is the physical pendulum's `√(g (m_r L/2 + M L)/I_O)/2π` (gravity enters
//!   through the tension's geometric stiffness at the sagged state, the point mass through
//!   the mass and the weight; measured 1.2e-7 apart, bound 1e-5);
//! * bad input: a slider of zero direction, a slider on a pinned node (dependent rows), a
//!   negative mass, an initial velocity that moves a pinned node — each refused naming its
//!   field.

use flexrom::model::Model;
use flexrom::simulate::{simulate, with_energies, Overrides, SimulationResult};
use ndarray::Array2;
use std::path::Path;
use std::process::Command;

const STEEL: &str = "density = 7850.0\narea = 1.0e-4\ninertia = 8.33e-10\nyoungs_modulus = 2.1e11";

fn model(text: &str) -> Model {
    Model::from_text(text, "test.toml").unwrap()
}

fn run(text: &str) -> SimulationResult {
    simulate(&model(text), &Overrides::default()).unwrap()
}

/// A probe's positions, (time, [x, y]).
fn probe<'a>(r: &'a SimulationResult, name: &str) -> &'a Array2<f64> {
    &r.probes.iter().find(|(n, _)| n == name).expect("probe").1
}

#[test]
fn a_free_beam_with_a_point_mass_falls_at_g() {
    let text = format!(
        "[time]\nt_end = 0.2\ndt = 0.01\nrho_inf = 0.9\n\
         [[bodies]]\nname = \"b\"\nstart = [0.0, 0.0]\nangle = 0.3\nlength = 1.0\nelements = 3\n{STEEL}\n\
         [[masses]]\nbody = \"b\"\nnode = 1\nmass = 5.0\n\
         [[loads]]\ntype = \"gravity\"\ng = [0.0, -9.81]\n"
    );
    let r = run(&text);
    let (nt, t) = (r.t.len(), r.t[r.t.len() - 1]);
    let fallen = 0.5 * 9.81 * t * t;
    for node in 0..4 {
        let (x0, y0) = (r.q[[4 * node, 0]], r.q[[4 * node + 1, 0]]);
        let (x, y) = (r.q[[4 * node, nt - 1]], r.q[[4 * node + 1, nt - 1]]);
        assert!((x - x0).abs() < 1e-9 * fallen, "node {node}: x moved by {}", x - x0);
        assert!(((y0 - y) - fallen).abs() < 1e-9 * fallen, "node {node}: fell {} against {fallen}", y0 - y);
    }
}

#[test]
fn a_thrown_spinning_beam_moves_rigidly() {
    let (v, w, t_end) = ([0.4, -0.3], 2.0, 0.5);
    let text = format!(
        "[time]\nt_end = {t_end}\ndt = 0.001\nrho_inf = 1.0\n\
         [[bodies]]\nname = \"b\"\nstart = [1.0, 2.0]\nangle = 0.5\nlength = 1.0\nelements = 4\n{STEEL}\n\
         velocity = [{}, {}]\nangular_velocity = {w}\n",
        v[0], v[1]
    );
    let r = run(&text);
    let nt = r.t.len();
    let node = |k: usize, i: usize| [r.q[[4 * k, i]], r.q[[4 * k + 1, i]]];
    // the centre is the middle node (4 elements); its velocity from the field ω × (r − start)
    let c0 = node(2, 0);
    let vc = [v[0] - w * (c0[1] - 2.0), v[1] + w * (c0[0] - 1.0)];
    let (c, s) = ((w * t_end).cos(), (w * t_end).sin());
    for k in 0..5 {
        let p0 = node(k, 0);
        let (dx, dy) = (p0[0] - c0[0], p0[1] - c0[1]);
        let expected = [c0[0] + vc[0] * t_end + c * dx - s * dy, c0[1] + vc[1] * t_end + s * dx + c * dy];
        let got = node(k, nt - 1);
        let err = (got[0] - expected[0]).hypot(got[1] - expected[1]);
        assert!(err < 1e-6, "node {k}: at {got:?} against {expected:?} ({err:.2e} m)");
    }
}

fn tip_mass_pendulum(t_end: f64, dt: f64, theta0: f64) -> String {
    // hanging at −π/2 + θ₀, pinned at the origin; E 100× steel's: stiff, a rigid pendulum
    let a = -std::f64::consts::FRAC_PI_2 + theta0;
    format!(
        "[time]\nt_end = {t_end}\ndt = {dt}\nrho_inf = 1.0\n\
         [[bodies]]\nname = \"rod\"\nstart = [0.0, 0.0]\nangle = {a}\nlength = 1.0\nelements = 4\n\
         density = 7850.0\narea = 1.0e-4\ninertia = 8.33e-10\nyoungs_modulus = 2.1e13\n\
         [[joints]]\ntype = \"ground_pin\"\nbody = \"rod\"\nnode = \"start\"\n\
         [[masses]]\nbody = \"rod\"\nnode = \"end\"\nmass = 2.355\n\
         [[loads]]\ntype = \"gravity\"\ng = [0.0, -9.81]\nscaled = true\n\
         [[probes]]\nname = \"tip\"\nbody = \"rod\"\nnode = \"end\"\n"
    )
}

/// The physical pendulum's small-amplitude period with the amplitude correction.
fn pendulum_period(theta0: f64) -> f64 {
    let (m_r, m, l, g): (f64, f64, f64, f64) = (7850.0 * 1e-4, 2.355, 1.0, 9.81);
    let i_o = m_r * l * l / 3.0 + m * l * l;
    2.0 * std::f64::consts::PI * (i_o / (g * (m_r * l / 2.0 + m * l))).sqrt() * (1.0 + theta0 * theta0 / 16.0)
}

#[test]
fn a_pendulum_with_a_tip_mass_swings_with_the_physical_pendulum_period() {
    let theta0 = 0.05;
    let period = pendulum_period(theta0);
    let r = run(&tip_mass_pendulum(2.2 * period, period / 400.0, theta0));
    let x = probe(&r, "tip").column(0).to_owned();
    // downward crossings of x = 0 (the tip passes the vertical from +x to −x), interpolated
    let crossings: Vec<f64> = (1..x.len())
        .filter(|&k| x[k - 1] > 0.0 && x[k] <= 0.0)
        .map(|k| r.t[k - 1] + (r.t[k] - r.t[k - 1]) * x[k - 1] / (x[k - 1] - x[k]))
        .collect();
    assert!(crossings.len() >= 2, "{crossings:?}");
    let measured = crossings[1] - crossings[0];
    let rel = (measured - period).abs() / period;
    assert!(rel < 2e-3, "period {measured} s against {period} s (rel {rel:.2e})");
}

#[test]
fn a_thrown_tip_mass_pendulum_keeps_its_energy() {
    let text = tip_mass_pendulum(1.0, 0.001, 0.3)
        .replace("youngs_modulus = 2.1e13\n", "youngs_modulus = 2.1e13\nangular_velocity = 1.5\n");
    let r = with_energies(&model(&text), run(&text)).unwrap();
    let e = r.energy.as_ref().expect("a full run's energies");
    let peak = e.kinetic.iter().fold(0.0_f64, |m, v| m.max(*v));
    assert!(peak > 1.0, "kinetic peak {peak} J");
    let total = e.total();
    let drift = total.iter().map(|v| (v - total[0]).abs()).fold(0.0_f64, f64::max);
    assert!(drift < 1e-3 * peak, "energy drift {drift:.3e} J against a kinetic peak of {peak:.3e} J");
}

#[test]
fn a_hanging_tip_mass_pendulum_s_lowest_mode_is_the_physical_pendulum_s() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "m.toml", &tip_mass_pendulum(1.0, 0.001, 0.0));
    let out = Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(["modes", path.to_str().unwrap(), "--count", "2", "--at", "static", "--json", "-q"])
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let f1 = v["frequencies"][0].as_f64().expect("a frequency");
    let expected = 1.0 / pendulum_period(0.0);
    assert!((f1 - expected).abs() < 1e-5 * expected, "f1 = {f1} Hz against {expected} Hz");
}

fn cantilever_pieces(pieces: usize) -> String {
    // a 1 m steel cantilever of 6 elements under a tip force, as 1, 2 or 3 welded segments
    let mut s = String::from("[time]\nt_end = 0.05\ndt = 0.0005\nrho_inf = 0.8\n");
    let len = 1.0 / pieces as f64;
    for k in 0..pieces {
        s += &format!(
            "[[bodies]]\nname = \"s{k}\"\nstart = [{}, 0.0]\nangle = 0.0\nlength = {len}\nelements = {}\n{STEEL}\n",
            k as f64 * len,
            6 / pieces
        );
    }
    s += "[[joints]]\ntype = \"clamp\"\nbody = \"s0\"\nnode = \"start\"\n";
    for k in 1..pieces {
        s += &format!(
            "[[joints]]\ntype = \"weld\"\na = {{ body = \"s{}\", node = \"end\" }}\nb = {{ body = \"s{k}\", node = \"start\" }}\n",
            k - 1
        );
    }
    s + &format!(
        "[[loads]]\ntype = \"force\"\nbody = \"s{}\"\nnode = \"end\"\nvalue = [0.0, -50.0]\n\
         [[probes]]\nname = \"tip\"\nbody = \"s{}\"\nnode = \"end\"\n",
        pieces - 1,
        pieces - 1
    )
}

#[test]
fn collinear_welded_segments_move_as_one_body() {
    let one = run(&cantilever_pieces(1));
    let tip = |r: &SimulationResult| probe(r, "tip").to_owned();
    let reference = tip(&one);
    let scale = reference.column(1).iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!(scale > 1e-3, "the tip moves: {scale}");
    for pieces in [2, 3] {
        let welded = tip(&run(&cantilever_pieces(pieces)));
        let diff = (&welded - &reference).iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(diff < 1e-8, "{pieces} segments: tip differs by {diff:.2e} m (deflection {scale:.2e} m)");
    }
}

const SLIDER_CRANK: &str = r#"
[time]
t_end = 0.3
dt = 0.001
rho_inf = 0.9

[[bodies]]
name = "crank"
start = [0.0, 0.0]
angle = 0.7853981633974483
length = 0.15
elements = 2
density = 7850.0
area = 2.827e-5
inertia = 6.362e-11
youngs_modulus = 2.1e13

[[bodies]]
name = "rod"
start = [0.10606601717798213, 0.10606601717798213]
angle = -0.36136712390670783
length = 0.30
elements = 4
density = 7850.0
area = 2.827e-5
inertia = 6.362e-11
youngs_modulus = 2.1e13

[[joints]]
type = "ground_pin"
body = "crank"
node = "start"

[[joints]]
type = "pin"
a = { body = "crank", node = "end" }
b = { body = "rod", node = "start" }

[[joints]]
type = "slider"
body = "rod"
node = "end"
direction = [1.0, 0.0]

[[masses]]
body = "rod"
node = "end"
mass = 0.0333

[[loads]]
type = "moment"
body = "crank"
node = "start"
function = { type = "constant", value = 0.05 }
scaled = true

[[probes]]
name = "crank_tip"
body = "crank"
node = "end"

[[probes]]
name = "slider"
body = "rod"
node = "end"
"#;

#[test]
fn a_stiff_slider_crank_follows_the_rigid_crank_rod_relation() {
    let r = run(SLIDER_CRANK);
    let (crank, slider) = (probe(&r, "crank_tip"), probe(&r, "slider"));
    let (c, l) = (0.15_f64, 0.30_f64);
    let mut travel = (f64::INFINITY, f64::NEG_INFINITY);
    for k in 0..r.t.len() {
        let theta = crank[[k, 1]].atan2(crank[[k, 0]]);
        let x = c * theta.cos() + (l * l - (c * theta.sin()).powi(2)).sqrt();
        assert!(slider[[k, 1]].abs() < 1e-12, "t = {}: the slider left its line by {}", r.t[k], slider[[k, 1]]);
        assert!((slider[[k, 0]] - x).abs() < 1e-6, "t = {}: slider at {} against {x}", r.t[k], slider[[k, 0]]);
        travel = (travel.0.min(slider[[k, 0]]), travel.1.max(slider[[k, 0]]));
    }
    // the crank turned far enough for the relation to mean something
    assert!(travel.1 - travel.0 > 0.1, "slider travel {travel:?}");
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_reduced_tip_mass_pendulum_carries_its_point_mass() {
    let dir = tempfile::tempdir().unwrap();
    let theta0 = 0.6;
    let model = tip_mass_pendulum(1.5, 0.005, theta0)
        .replace("2.1e13", "7.0e10")
        .replace("youngs_modulus = 7.0e10\n", "youngs_modulus = 7.0e10\nangular_velocity = 1.5\n");
    assert!(model.contains("angular_velocity"));
    write(dir.path(), "model.toml", &model);
    let pipe = write(
        dir.path(),
        "pipe.toml",
        "model = \"model.toml\"\nbasis = \"basis.h5\"\nreport = \"report\"\n\
         [train]\nload_scales = [0.8, 1.2]\n[reduction]\nvariant = \"constraint-preserving\"\nmodes = { energy = 1e-10 }\n",
    );
    let bin = env!("CARGO_BIN_EXE_flexrom");
    let out = Command::new(bin).args(["train", pipe.to_str().unwrap(), "-q"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = Command::new(bin)
        .args(["validate", pipe.to_str().unwrap(), "--load-scale", "1.05", "--json", "-q"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let first = if v.is_array() { v[0].clone() } else { v };
    let rel = first["rel_error"].as_f64().expect("rel_error");
    assert!(rel < 1e-3, "reduced rel_error {rel}");
}

#[test]
fn bad_sliders_and_masses_are_refused_naming_their_field() {
    let base = "[time]\nt_end = 0.1\ndt = 0.01\nrho_inf = 0.9\n\
                [[bodies]]\nname = \"b\"\nstart = [0.0, 0.0]\nangle = 0.0\nlength = 1.0\nelements = 2\n\
                density = 7850.0\narea = 1.0e-4\ninertia = 8.33e-10\nyoungs_modulus = 2.1e11\n";
    let err = |extra: &str| Model::from_text(&format!("{base}{extra}"), "bad.toml").unwrap_err().to_string();
    let e = err("[[joints]]\ntype = \"slider\"\nbody = \"b\"\nnode = \"end\"\ndirection = [0.0, 0.0]\n");
    assert!(e.contains("joints[0].direction") && e.contains("zero length"), "{e}");
    let e = err("[[joints]]\ntype = \"ground_pin\"\nbody = \"b\"\nnode = \"end\"\n\
                 [[joints]]\ntype = \"slider\"\nbody = \"b\"\nnode = \"end\"\ndirection = [1.0, 1.0]\n");
    assert!(e.contains("joints[1]") && e.contains("joints[0]") && e.contains("dependent"), "{e}");
    let e = err("[[masses]]\nbody = \"b\"\nnode = \"end\"\nmass = -1.0\n");
    assert!(e.contains("masses[0].mass") && e.contains("positive"), "{e}");
    let e = err("[[masses]]\nbody = \"b\"\nnode = \"end\"\nmass = nan\n");
    assert!(e.contains("masses[0].mass"), "{e}");
    // spinning about its pinned start is allowed; moving the pinned start is not
    let spun = base.replace("youngs_modulus = 2.1e11\n", "youngs_modulus = 2.1e11\nangular_velocity = 3.0\n");
    let pin = "[[joints]]\ntype = \"ground_pin\"\nbody = \"b\"\nnode = \"start\"\n";
    Model::from_text(&format!("{spun}{pin}"), "ok.toml").expect("a spin about the pin");
    let moved = base.replace("youngs_modulus = 2.1e11\n", "youngs_modulus = 2.1e11\nvelocity = [0.0, 1.0]\n");
    let e = Model::from_text(&format!("{moved}{pin}"), "bad.toml").unwrap_err().to_string();
    assert!(e.contains("joints[0]") && e.contains("initial velocities") && e.contains("ground_pin"), "{e}");
}
