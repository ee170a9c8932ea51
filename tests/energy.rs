//! The energies of a full run (`simulate::with_energies`, src/analysis/energy.rs) against
//! the energy balance of SPEC §6, on the shipped pendulum (data/models/pendulum.toml:
//! gravity only, ρ∞ = 1, no damping) over its first 0.2 s, where it falls from rest:
//!
//! * at t = 0 the kinetic and strain energies are 0 (at rest, undeformed; the strain
//!   energy to round-off, 1e-9 of the energy released);
//! * `T + U + V − W` stays constant to the integrator's order: its largest change, relative
//!   to the gravity energy released, is below 1e-3 at dt = 5 ms and falls at least threefold
//!   when dt is halved (second order gives four);
//! * with Rayleigh damping (`[damping] mass = 2`) the total never rises (dissipation ≥ 0,
//!   up to 1e-9 of the energy released) and ends below the undamped run's.
//!
//! And on the shipped spin-up beam (data/models/spin_up.toml at ρ∞ = 1, its first 4 s), whose
//! hub angle is prescribed: the drive's work `W_d` is what the beam gains, so that
//! `T + U + V − W − W_d` stays constant — its largest change below 1e-3 of the work put in
//! at dt = 20 ms, falling at least threefold at 10 ms (second order) — while without `W_d`
//! the balance would be off by all of it.

use flexrom::model::Model;
use flexrom::simulate::{simulate, with_energies, Overrides};

fn pendulum(damping: bool) -> Model {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/models/pendulum.toml");
    let mut text = std::fs::read_to_string(path).unwrap();
    if damping {
        text.push_str("\n[damping]\nmass = 2.0\nstiffness = 0.0\n");
    }
    Model::from_text(&text, path).unwrap()
}

/// (largest |total − total₀| / energy released, final total) of a run to 0.2 s at `dt`.
fn drift(model: &Model, dt: f64) -> (f64, Vec<f64>) {
    let r = simulate(model, &Overrides { dt: Some(dt), t_end: Some(0.2), ..Default::default() }).unwrap();
    let r = with_energies(model, r).unwrap();
    let e = r.energy.expect("a full run records its energies");
    assert_eq!(e.kinetic[0], 0.0, "at rest at t = 0");
    assert!(e.springs.iter().all(|&s| s == 0.0) && e.external_work.iter().all(|&w| w == 0.0), "gravity only");
    assert!(e.drive_work.iter().all(|&w| w == 0.0), "no drive, no drive work");
    let total = e.total();
    let released = e.gravity[0] - e.gravity[e.gravity.len() - 1];
    assert!(released > 0.0, "the pendulum falls");
    // undeformed at t = 0: round-off of ½ eᵀK e (its terms are ~1e3 J) only
    assert!(e.strain[0].abs() < 1e-9 * released, "strain energy at t = 0: {}", e.strain[0]);
    let worst = total.iter().map(|x| (x - total[0]).abs()).fold(0.0, f64::max);
    (worst / released, total.to_vec())
}

#[test]
fn total_energy_is_conserved_to_second_order_without_damping() {
    let model = pendulum(false);
    let (coarse, _) = drift(&model, 0.005);
    let (fine, _) = drift(&model, 0.0025);
    assert!(coarse < 1e-3, "relative drift {coarse:.2e} at dt = 5 ms");
    assert!(fine <= coarse / 3.0, "drift {fine:.2e} at 2.5 ms vs {coarse:.2e} at 5 ms");
}

#[test]
fn damping_only_dissipates() {
    let (_, free) = drift(&pendulum(false), 0.005);
    let damped = pendulum(true);
    let r = with_energies(&damped, simulate(&damped, &Overrides { t_end: Some(0.2), ..Default::default() }).unwrap())
        .unwrap();
    let e = r.energy.unwrap();
    let total = e.total();
    let released = e.gravity[0] - e.gravity[e.gravity.len() - 1];
    for k in 1..total.len() {
        assert!(
            total[k] <= total[k - 1] + 1e-9 * released,
            "the total rose at step {k}: {} -> {}",
            total[k - 1],
            total[k]
        );
    }
    assert!(total[total.len() - 1] < free[free.len() - 1], "damping removed energy");
}

/// (largest |total − total₀| / drive work, drive work, kinetic and strain energy gained) of
/// the spin-up beam's first 4 s at `dt`, ρ∞ = 1.
fn spin_up_drift(dt: f64) -> (f64, f64, f64) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/models/spin_up.toml");
    let text = std::fs::read_to_string(path).unwrap().replace("rho_inf = 0.8", "rho_inf = 1.0");
    let model = Model::from_text(&text, path).unwrap();
    let r = simulate(&model, &Overrides { dt: Some(dt), t_end: Some(4.0), ..Default::default() }).unwrap();
    let e = with_energies(&model, r).unwrap().energy.unwrap();
    let total = e.total();
    let work = e.drive_work[e.drive_work.len() - 1];
    let last = e.kinetic.len() - 1;
    let gained = e.kinetic[last] + e.strain[last] - e.kinetic[0] - e.strain[0];
    let worst = total.iter().map(|x| (x - total[0]).abs()).fold(0.0, f64::max);
    (worst / work, work, gained)
}

#[test]
fn a_drive_puts_in_the_energy_the_beam_gains() {
    let (coarse, work, gained) = spin_up_drift(0.02);
    let (fine, ..) = spin_up_drift(0.01);
    assert!(work > 0.0, "the motor spins the beam up: {work}");
    assert!((work - gained).abs() < 1e-3 * work, "work {work:.6e} J, kinetic and strain gained {gained:.6e} J");
    assert!(coarse < 1e-3, "relative drift {coarse:.2e} at dt = 20 ms");
    assert!(fine <= coarse / 3.0, "drift {fine:.2e} at 10 ms vs {coarse:.2e} at 20 ms");
}

/// A reduced run's energies (`online`'s result file): the shipped pendulum's basis trained
/// at 0.9 and 1.1 g with 10 modes, hyper-reduced by ECSW to 1e-2, run at 1 g over the whole
/// 1.1 s. The reduced model conserves its own energy (its internal force is the gradient of
/// `Σ_{e∈S} w_e U_e(x_ref + V z)`, the trapezoidal rule at ρ∞ = 1): the total's largest
/// change stays below 1e-3 of the energy released, and its kinetic energy follows the full
/// run's within 2e-3 of it (the basis's error; 3.1e-4 and 3.4e-4 measured).
#[test]
fn a_reduced_run_keeps_its_own_energy() {
    let dir = tempfile::tempdir().unwrap();
    let model = concat!(env!("CARGO_MANIFEST_DIR"), "/data/models/pendulum.toml");
    std::fs::copy(model, dir.path().join("m.toml")).unwrap();
    std::fs::write(
        dir.path().join("p.toml"),
        "model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n[train]\nload_scales = [0.9, 1.1]\n\
         [reduction]\nmodes = { count = 10 }\nhyper = { tolerance = 1e-2 }\n",
    )
    .unwrap();
    let flexrom = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_flexrom"))
            .args(args)
            .current_dir(dir.path())
            .env("HDF5_USE_FILE_LOCKING", "FALSE")
            .output()
            .unwrap();
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    };
    flexrom(&["train", "p.toml", "-q"]);
    flexrom(&["online", "p.toml", "--load-scale", "1.0", "-o", "reduced.h5", "-q"]);
    flexrom(&["simulate", "m.toml", "-o", "full.h5", "-q"]);
    let energy = |file: &str, name: &str| {
        let f = flexrom::io::h5_open::open(dir.path().join(file)).unwrap();
        f.dataset(&format!("energy/{name}")).unwrap().read_1d::<f64>().unwrap()
    };
    let f = flexrom::io::h5_open::open(dir.path().join("reduced.h5")).unwrap();
    assert!(f.attr("n_modes").is_ok(), "a reduced run's file");
    let total = ["kinetic", "strain", "gravity", "springs"]
        .iter()
        .fold(-energy("reduced.h5", "external_work"), |acc, n| acc + energy("reduced.h5", n));
    let gravity = energy("reduced.h5", "gravity");
    let released = gravity.iter().fold(0.0_f64, |m, g| m.max(gravity[0] - g));
    assert!(released > 1.0, "the pendulum falls: {released} J");
    let drift = total.iter().map(|x| (x - total[0]).abs()).fold(0.0, f64::max);
    assert!(drift < 1e-3 * released, "reduced total drifts by {drift:.3e} J of {released:.3e} J released");
    let (kr, kf) = (energy("reduced.h5", "kinetic"), energy("full.h5", "kinetic"));
    let gap = kr.iter().zip(&kf).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(gap < 2e-3 * released, "reduced kinetic energy {gap:.3e} J from the full run's");
}
