//! The warning of a time step that does not resolve the model (src/analysis/resolution.rs):
//! `dt` above a tenth of the lowest elastic natural period, or of a load's sine period.

use std::path::Path;
use std::process::{Command, Output};

/// A cantilever of L = 1 m, ρA = 1 kg/m, EI = 319.4 N m²: its first bending frequency is
/// f₁ = (1.8751²/2π) √(EI/ρA)/L² = 0.55959 · 17.872 = 10.00 Hz (Euler–Bernoulli), T₁ = 0.1 s.
const CANTILEVER: &str = r#"
[time]
t_end = 0.2
dt = 0.1
rho_inf = 1.0

[[bodies]]
name = "beam"
start = [0.0, 0.0]
angle = 0.0
length = 1.0
elements = 8
density = 1000.0
area = 1.0e-3
inertia = 1.0e-8
youngs_modulus = 3.194e10

[[joints]]
type = "clamp"
body = "beam"
node = "start"

[[loads]]
type = "gravity"
g = [0.0, -9.81]
scaled = true
"#;

fn flexrom(dir: &Path, args: &[&str]) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_flexrom")).current_dir(dir).args(args).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

/// The lines of a run's stderr that warn of its time step.
fn unresolved(dir: &Path, args: &[&str]) -> Vec<String> {
    let o = flexrom(dir, args);
    String::from_utf8_lossy(&o.stderr).lines().filter(|l| l.contains("does not resolve")).map(String::from).collect()
}

#[test]
fn a_step_of_the_first_period_is_warned_of_and_a_tenth_of_it_is_not() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    std::fs::write(dir.join("c.toml"), CANTILEVER).unwrap();
    // the model's first period is the one the warning measures against: 10 Hz within 1 %
    // (8 elements of the cubic beam converge to the beam-theory frequency from above)
    let modes = String::from_utf8_lossy(&flexrom(dir, &["modes", "c.toml", "--count", "1"]).stderr).into_owned();
    let f1: f64 = modes
        .lines()
        .find_map(|l| l.trim().strip_prefix("mode 1: ")?.strip_suffix(" Hz")?.parse().ok())
        .unwrap_or_else(|| panic!("no mode 1 in {modes}"));
    assert!((f1 - 10.0).abs() < 0.1, "f₁ = {f1} Hz");

    // dt = 0.1 s = T₁: one line naming the model file and dt
    let w = unresolved(dir, &["simulate", "c.toml", "--csv"]);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("c.toml") && w[0].contains("dt = 0.1 s"), "{w:?}");
    let t1: f64 = w[0].split("T₁ = ").nth(1).and_then(|r| r.split(" s").next()).unwrap().parse().unwrap();
    assert!((t1 - 1.0 / f1).abs() < 1e-3 * t1, "the period named is 1/f₁: {t1} s");
    // just above T₁/10 = 0.01 s: warned; just below: not
    assert_eq!(unresolved(dir, &["simulate", "c.toml", "--csv", "--dt", "0.011"]).len(), 1);
    assert!(unresolved(dir, &["simulate", "c.toml", "--csv", "--dt", "0.009", "--t-end", "0.018"]).is_empty());
}

#[test]
fn a_rigid_swing_is_no_period_to_resolve_and_a_fast_sine_is() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let pendulum = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/pendulum.toml");
    let text = std::fs::read_to_string(&pendulum).unwrap();
    std::fs::write(dir.join("p.toml"), &text).unwrap();
    // the shipped pendulum: its first mode is the rigid swing about the pin (ω = 0); its
    // lowest elastic period is resolved by its own dt = 0.005 s
    assert!(unresolved(dir, &["simulate", "p.toml", "--csv", "--t-end", "0.01"]).is_empty());
    // a moment of 5 Hz at the tip: 1/(10 · 5 Hz) = 0.02 s; dt = 0.005 s resolves it
    let driven = format!(
        "{text}\n[[loads]]\ntype = \"moment\"\nbody = \"beam\"\nnode = \"end\"\nfunction = {{ type = \"sine\", amplitude = 0.1, frequency = 5.0 }}\n"
    );
    std::fs::write(dir.join("s.toml"), driven).unwrap();
    assert!(unresolved(dir, &["simulate", "s.toml", "--csv", "--t-end", "0.01"]).is_empty());
    // dt = 0.025 s > 0.02 s: the sine is named
    let w = unresolved(dir, &["simulate", "s.toml", "--csv", "--dt", "0.025", "--t-end", "0.05"]);
    assert!(
        w.iter().any(|l| l.contains("s.toml") && l.contains("sine of 5 Hz") && l.contains("dt = 0.025 s")),
        "{w:?}"
    );
}
