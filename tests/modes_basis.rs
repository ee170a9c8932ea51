//! The frequencies a reduced basis keeps (`flexrom modes --basis`,
//! src/analysis/reduced_modes.rs): Rayleigh–Ritz on the basis's span in the null space of
//! the constraints.
//!
//! * a basis spanning exact eigenvectors gives their frequencies (a Ritz pair of an invariant
//!   subspace is exact), with or without the kept unit columns of the clamped coordinates
//!   (which the constraint rows then remove);
//! * every reduced `ω²_i` is at least the full `ω²_i` (Courant–Fischer: the reduced space is
//!   a subspace of ker B), and a basis without mode 2 reports mode 3's frequency in its place;
//! * the command: a basis trained by POD on a clamped beam released under gravity keeps its
//!   lowest bending frequency to 5e-3 (POD modes are not eigenmodes) and none of its
//!   frequencies falls below the full one.

mod common;

use flexrom::analysis::modes::compute;
use flexrom::analysis::reduced_modes::compute as reduced;
use flexrom::solver::model::Parameters;
use ndarray::Array2;
use std::process::Command;

const L: f64 = 1.0;
const E: f64 = 2.1e11;
const A: f64 = 1e-4;
const I: f64 = 1e-8 / 12.0;

/// The cantilever's system, its initial state and its lowest `count` modes.
fn cantilever(count: usize) -> (flexrom::physics::system::FlexibleSystem, Vec<f64>, flexrom::analysis::modes::Modes) {
    let m = common::cantilever(12, L, E, A, I, 0.0);
    let sys = m.system(Default::default());
    let q = sys.initial_state();
    let modes = compute(&sys, &Parameters::default(), &q, 0.0, count, Default::default()).expect("modes converge");
    (sys, q, modes)
}

/// The columns `shapes[i]` for `i` in `which`, then `extra` columns.
fn basis_of(modes: &flexrom::analysis::modes::Modes, which: &[usize], extra: &[Vec<f64>]) -> Array2<f64> {
    let n = modes.shapes.ncols();
    let cols: Vec<Vec<f64>> = which.iter().map(|&i| modes.shape(i)).chain(extra.iter().cloned()).collect();
    Array2::from_shape_fn((n, cols.len()), |(d, j)| cols[j][d])
}

fn unit(n: usize, d: usize) -> Vec<f64> {
    let mut v = vec![0.0; n];
    v[d] = 1.0;
    v
}

#[test]
fn a_basis_of_eigenvectors_keeps_their_frequencies() {
    let (sys, q, modes) = cantilever(4);
    let n = q.len();
    // the mode shapes alone, then with the clamp's four coordinates as kept unit columns
    // (constraint-preserving bases carry them; the clamp's rows remove them again)
    let clamp: Vec<Vec<f64>> = (0..4).map(|d| unit(n, d)).collect();
    for v in [basis_of(&modes, &[0, 1, 2], &[]), basis_of(&modes, &[0, 1, 2], &clamp)] {
        let r = reduced(&sys, &Parameters::default(), &q, 0.0, v.view(), 6).unwrap();
        assert_eq!(r.dimension, 3, "{} columns", v.ncols());
        assert_eq!(r.frequencies.len(), 3, "no more frequencies than the space has");
        for i in 0..3 {
            let rel = (r.frequencies[i] / modes.frequencies[i] - 1.0).abs();
            assert!(rel < 1e-8, "mode {}: {} Hz against {} Hz", i + 1, r.frequencies[i], modes.frequencies[i]);
        }
        assert!(!r.rigid.iter().any(|&x| x));
    }
}

#[test]
fn reduced_frequencies_are_upper_bounds() {
    let (sys, q, modes) = cantilever(4);
    let n = q.len();
    // modes 1, 3, 4 and two smooth fields that leave the clamped coordinates at rest
    let bend = |p: i32| -> Vec<f64> {
        let mut v = vec![0.0; n];
        for k in 1..n / 4 {
            let x = k as f64 / (n / 4 - 1) as f64;
            v[4 * k + 1] = x.powi(p);
            v[4 * k + 3] = p as f64 * x.powi(p - 1);
        }
        v
    };
    let v = basis_of(&modes, &[0, 2, 3], &[bend(5), bend(7)]);
    let r = reduced(&sys, &Parameters::default(), &q, 0.0, v.view(), 4).unwrap();
    assert_eq!(r.dimension, 5);
    let full = &modes.omega_squared;
    for (i, (w, f)) in r.omega_squared.iter().zip(full).enumerate() {
        assert!(*w >= f * (1.0 - 1e-10), "mode {}: {w} < {f}", i + 1);
    }
    // mode 1 is in the span; mode 2 is not, and the polynomials x⁵, x⁷ do not make it up
    assert!((r.omega_squared[0] / full[0] - 1.0).abs() < 1e-8);
    assert!(r.omega_squared[1] > full[1] * 1.01, "ω²_2 = {} against the full {}", r.omega_squared[1], full[1]);
}

#[test]
fn modes_basis_compares_a_trained_basis_with_the_full_model() {
    let dir = tempfile::tempdir().unwrap();
    let root = env!("CARGO_MANIFEST_DIR");
    std::fs::copy(format!("{root}/data/models/clamped_beam.toml"), dir.path().join("m.toml")).unwrap();
    std::fs::write(
        dir.path().join("p.toml"),
        "model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n[train]\nload_scales = [0.01]\n[reduction]\nmodes = { count = 4 }\n",
    )
    .unwrap();
    let flexrom = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_flexrom"))
            .args(args)
            .current_dir(dir.path())
            .env("HDF5_USE_FILE_LOCKING", "FALSE")
            .output()
            .unwrap();
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        out
    };
    flexrom(&["train", "p.toml", "-q"]);
    let out = flexrom(&["modes", "m.toml", "--count", "3", "--basis", "b.h5", "--json", "-q"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let full: Vec<f64> = serde_json::from_value(v["omega_squared"].clone()).unwrap();
    let kept: Vec<f64> = serde_json::from_value(v["reduced_omega_squared"].clone()).unwrap();
    let dimension = v["reduced_dimension"].as_u64().unwrap() as usize;
    assert_eq!(kept.len(), 3.min(dimension), "{v}");
    for (i, (k, f)) in kept.iter().zip(&full).enumerate() {
        assert!(*k >= f * (1.0 - 1e-9), "mode {}: reduced ω² {k} below the full {f}", i + 1);
    }
    // released under (a hundredth of) gravity the beam swings about its sag mostly in its
    // first bending mode; the POD's modes mix it with the sag's shape, so f1 comes out a
    // little high: 1.75e-3 here (7.4e-3 under the whole of gravity, a large swing)
    let f1 = (kept[0] / full[0]).sqrt();
    assert!((f1 - 1.0).abs() < 5e-3, "f1: reduced/full = {f1}");
    // and a basis of another model is refused, naming the file
    std::fs::copy(format!("{root}/data/models/pendulum.toml"), dir.path().join("other.toml")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(["modes", "other.toml", "--basis", "b.h5"])
        .current_dir(dir.path())
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("b.h5") && err.contains("another model"), "{err}");
}
