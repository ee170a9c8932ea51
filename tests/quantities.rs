//! What engineers read off a reduced run — each probe's position, strain and curvature —
//! measured against the full run relative to the quantity's range over the run, and
//! estimated (src/rom/quantities.rs, docs/error-estimate.md), through the binary as a
//! user runs it:
//!
//! * `validate_measures_each_quantity_over_its_range`: `validate --json`'s
//!   `probe_quantity_errors` equal the errors recomputed here from the result files of
//!   `simulate` and `online` at the same load (max |κ_r − κ_f| over max κ_f − min κ_f), and
//!   `online`'s result file carries each quantity's estimate as the dataset's
//!   `error_estimate`, the value `validate` reports for the same reduced run.
//! * `every_method_covers_every_quantity`: with each method — `enriched` (the reference the
//!   cheaper ones approximate), `corrected`, and `defects` on the scale greedy training
//!   calibrated per quantity — every quantity's estimate is at least its error, at loads the
//!   basis did not see (measured: effectivity 1.46–1.69 for all three).
//! * `validate_measures_each_reaction_over_its_range`: with a constraint-preserving basis
//!   (which keeps the clamp's multipliers), `reaction_errors` equal the errors recomputed
//!   from the `/reactions` of `simulate`'s and `online`'s result files; `online`'s file
//!   carries each reaction's estimate (`error_estimate` of `/reactions/force`, `/moment`),
//!   `validate`'s value, as does a sweep file's `/reaction_error_estimate` (and after
//!   `--resume`); every method's estimate covers each reaction's error within 3×.
//! * `a_sweep_carries_strains_curvatures_and_their_estimates`: a validated sweep's
//!   `/probe_curvature/root` row is the online run's series at that load, its
//!   `/probe_error_estimate` and `/probe_error` columns are `validate`'s, and `--resume`
//!   reads them back and writes them again unchanged.

use std::path::Path;
use std::process::{Command, Output};

/// A clamped aluminium arm, 1 m, 12 elements, under a tip force that swings it (a sine at
/// 3 Hz, near its first bending frequency ≈ 4.6 Hz: E I = 7e10 · 2e-9 = 140 N m², m̄ = 1.35
/// kg/m, ω₁ = 3.516 √(EI/(m̄ L⁴)) ≈ 35.8 rad/s), with a probe at the tip and one at the
/// root recording strain and curvature (the root's bending moment is what the arm is sized by).
const MODEL: &str = r#"
description = "clamped arm, tip force"
[time]
t_end = 0.5
dt = 0.002
rho_inf = 0.9
[[bodies]]
name = "arm"
start = [0.0, 0.0]
angle = 0.0
length = 1.0
elements = 12
density = 2700.0
area = 5e-4
inertia = 2e-9
youngs_modulus = 7e10
[[joints]]
type = "clamp"
body = "arm"
node = "start"
[[loads]]
type = "force"
body = "arm"
node = "end"
value = [0.0, -20.0]
function = { type = "sine", amplitude = 1.0, frequency = 3.0 }
[[probes]]
name = "tip"
body = "arm"
node = "end"
[[probes]]
name = "root"
body = "arm"
node = "start"
quantities = ["strain", "curvature"]
[[probes]]
name = "mid"
body = "arm"
at = 0.5
quantities = ["strain", "curvature"]
"#;

const PIPELINE: &str = r#"
model = "arm.toml"
basis = "arm.h5"
[train]
greedy = { range = [0.5, 1.5], tolerance = 1e-3, max_runs = 4 }
[validate]
load_scales = [0.8, 1.3]
"#;

fn flexrom(dir: &Path, args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(args)
        .current_dir(dir)
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    out
}

/// A trained arm in a fresh directory.
fn trained(name: &str) -> std::path::PathBuf {
    trained_with(name, PIPELINE)
}

/// The arm trained by `pipeline` in a fresh directory.
fn trained_with(name: &str, pipeline: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("flexrom-quantities-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("arm.toml"), MODEL).unwrap();
    std::fs::write(dir.join("p.toml"), pipeline).unwrap();
    flexrom(&dir, &["train", "p.toml"]);
    dir
}

fn validations(dir: &Path, method: &str) -> Vec<serde_json::Value> {
    let out = flexrom(dir, &["validate", "p.toml", "--json", "--no-dense", "--estimate", method]);
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The entry of `v`'s `probe_quantity_errors` for `probe` and `quantity`.
fn entry<'a>(v: &'a serde_json::Value, probe: &str, quantity: &str) -> &'a serde_json::Value {
    let all = v["probe_quantity_errors"].as_array().unwrap();
    all.iter()
        .find(|q| q["probe"] == probe && q["quantity"] == quantity)
        .unwrap_or_else(|| panic!("{probe} {quantity}"))
}

fn series(path: &Path, name: &str) -> Vec<f64> {
    flexrom::io::h5_open::open(path).unwrap().dataset(name).unwrap().read_raw::<f64>().unwrap()
}

#[test]
fn validate_measures_each_quantity_over_its_range() {
    let dir = trained("range");
    let vs = validations(&dir, "corrected");
    flexrom(&dir, &["simulate", "arm.toml", "--load-scale", "0.8", "-o", "full.h5"]);
    flexrom(&dir, &["online", "p.toml", "--load-scale", "0.8", "--estimate", "corrected", "-o", "rom.h5"]);
    let v = vs.iter().find(|v| v["load_scale"] == 0.8).unwrap();
    // at the clamp the slope is held, so the root's strain stays 0 (no entry); at mid-span
    // the beam stretches as it bends
    for (probe, quantity, dataset) in [
        ("root", "curvature", "probe_curvature/root"),
        ("mid", "strain", "probe_strain/mid"),
        ("mid", "curvature", "probe_curvature/mid"),
    ] {
        let (f, r) = (series(&dir.join("full.h5"), dataset), series(&dir.join("rom.h5"), dataset));
        let error = f.iter().zip(&r).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        let range =
            f.iter().copied().fold(f64::NEG_INFINITY, f64::max) - f.iter().copied().fold(f64::INFINITY, f64::min);
        let q = entry(v, probe, quantity);
        let relative = q["relative"].as_f64().unwrap();
        // the same runs, the same arithmetic: to round-off
        assert!((relative - error / range).abs() <= 1e-9 * relative, "{quantity}: {relative} vs {}", error / range);
        let attr: f64 = flexrom::io::h5_open::open(dir.join("rom.h5"))
            .unwrap()
            .dataset(dataset)
            .unwrap()
            .attr("error_estimate")
            .unwrap()
            .read_scalar()
            .unwrap();
        let estimate = q["estimate"].as_f64().unwrap();
        assert!((attr - estimate).abs() <= 1e-12 * estimate, "{quantity}: online {attr} vs validate {estimate}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn validate_measures_each_reaction_over_its_range() {
    let pipeline = format!("{PIPELINE}[reduction]\nvariant = \"constraint-preserving\"\n");
    let dir = trained_with("reactions", &pipeline);
    let vs = validations(&dir, "corrected");
    flexrom(&dir, &["simulate", "arm.toml", "--load-scale", "1.3", "-o", "full.h5"]);
    flexrom(&dir, &["online", "p.toml", "--load-scale", "1.3", "-o", "rom.h5", "--estimate", "corrected"]);
    let v = vs.iter().find(|v| v["load_scale"] == 1.3).unwrap();
    let read = |path: &str, name: &str| -> ndarray::ArrayD<f64> {
        flexrom::io::h5_open::open(dir.join(path)).unwrap().dataset(name).unwrap().read_dyn::<f64>().unwrap()
    };
    // the clamp's force (n_t, 1, 2) and moment (n_t, 1): max distance over the full run's range
    let (ff, rf) = (read("full.h5", "reactions/force"), read("rom.h5", "reactions/force"));
    let (fm, rm) = (read("full.h5", "reactions/moment"), read("rom.h5", "reactions/moment"));
    let nt = ff.shape()[0];
    let force = |a: &ndarray::ArrayD<f64>, k: usize, c: usize| a[[k, 0, c]];
    let dist = (0..nt).map(|k| {
        ((force(&ff, k, 0) - force(&rf, k, 0)).powi(2) + (force(&ff, k, 1) - force(&rf, k, 1)).powi(2)).sqrt()
    });
    let span = |c: usize| {
        let v: Vec<f64> = (0..nt).map(|k| force(&ff, k, c)).collect();
        v.iter().copied().fold(f64::NEG_INFINITY, f64::max) - v.iter().copied().fold(f64::INFINITY, f64::min)
    };
    let force_error = dist.fold(0.0, f64::max) / (span(0).powi(2) + span(1).powi(2)).sqrt();
    let m: Vec<f64> = (0..nt).map(|k| fm[[k, 0]]).collect();
    let moment_error = (0..nt).map(|k| (fm[[k, 0]] - rm[[k, 0]]).abs()).fold(0.0, f64::max)
        / (m.iter().copied().fold(f64::NEG_INFINITY, f64::max) - m.iter().copied().fold(f64::INFINITY, f64::min));
    let errors = v["reaction_errors"].as_array().unwrap();
    assert_eq!(errors.len(), 2, "{errors:?}");
    for (e, want) in errors.iter().zip([force_error, moment_error]) {
        let got = e["relative"].as_f64().unwrap();
        assert!((got - want).abs() <= 1e-9 * want, "{e}: recomputed {want}");
    }
    // online's result file carries each reaction's estimate, the value validate reports
    for (e, dataset) in errors.iter().zip(["reactions/force", "reactions/moment"]) {
        let file = hdf5::File::open(dir.join("rom.h5")).unwrap();
        let attr: Vec<f64> = file.dataset(dataset).unwrap().attr("error_estimate").unwrap().read_raw().unwrap();
        let estimate = e["estimate"].as_f64().unwrap();
        assert!((attr[0] - estimate).abs() <= 1e-12 * estimate, "{dataset}: online {attr:?} vs validate {estimate}");
    }
    // a sweep's file carries each reaction's estimate, validate's at the same load, and
    // --resume reads them back and writes them again as they were
    let sweep = ["sweep", "p.toml", "--load-scales", "0.8,1.3", "--estimate", "corrected", "-o", "s.h5"];
    flexrom(&dir, &sweep);
    let column = |q: &str| {
        series(&dir.join("s.h5"), &format!("reaction_error_estimate/{q}/{}", errors[0]["reaction"].as_str().unwrap()))
    };
    let before = [column("force"), column("moment")];
    for (e, stored) in errors.iter().zip(&before) {
        assert_eq!(Some(stored[1]), e["estimate"].as_f64(), "{e}");
    }
    flexrom(&dir, &[&sweep[..], &["--resume"]].concat());
    assert_eq!([column("force"), column("moment")], before);
    // every method's estimate covers each reaction's error at loads training did not see
    // (measured: effectivity 1.45–1.56 for all three; `defects` on the scale greedy training
    // calibrated per reaction)
    for method in ["enriched", "corrected", "defects"] {
        for v in validations(&dir, method) {
            for e in v["reaction_errors"].as_array().unwrap() {
                let error = e["relative"].as_f64().unwrap();
                let estimate = e["estimate"].as_f64().unwrap_or(f64::NAN);
                assert!(estimate >= error && estimate <= 3.0 * error, "{method}, λ = {}: {e}", v["load_scale"]);
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The held-out full run calibrates each quantity as it calibrates the coordinates
/// (`/estimator/calibration/quantity_factor`, src/rom/estimator/training.rs): the keys are
/// quantities the arm measures that move (the root's position and a clamped root's strain
/// have no swing: no pair), no factor is below the coordinates' `c`, and the corrected
/// estimate of each quantity is its raw estimate times that factor (`c_q · η_q`). A
/// factor that is not finite is refused, naming the dataset, before any output is begun.
#[test]
fn held_out_runs_calibrate_each_quantity() {
    let dir = trained("held-out");
    let basis = dir.join("arm.h5");
    let (keys, factors, c) = {
        let f = flexrom::io::h5_open::open(&basis).unwrap();
        assert_eq!(series(&basis, "estimator/calibration/load_scale").len(), 1, "one held-out check");
        let ds = f.dataset("estimator/calibration/quantity_factor").unwrap();
        let keys: hdf5::types::VarLenUnicode = ds.attr("quantities").unwrap().read_scalar().unwrap();
        let keys: Vec<String> = keys.as_str().lines().map(str::to_string).collect();
        let c = f.group("estimator").unwrap().attr("factor").unwrap().read_scalar::<f64>().unwrap();
        (keys, ds.read_raw::<f64>().unwrap(), c)
    };
    let measured = ["position:tip", "position:mid", "strain:mid", "curvature:root", "curvature:mid"];
    assert_eq!(
        keys, measured,
        "the quantities that move, in the model's order, then no reaction (a Galerkin basis keeps no multipliers)"
    );
    assert!(factors.iter().all(|&f| f >= c), "{factors:?} against c = {c}");

    let p = flexrom::pipeline::Pipeline::load(dir.join("p.toml")).unwrap();
    let method = Some(flexrom::rom::estimator::EstimateMethod::Corrected);
    let (_, rom, _) = flexrom::workflows::online::load_rom(&p, &basis, method, false).unwrap();
    let mu = flexrom::solver::model::Parameters::load_scale(1.2);
    let (_, e) = rom.solve_and_estimate(&mu, flexrom::rom::Output::Full, &[]).unwrap();
    let e = e.unwrap();
    for (key, factor) in keys.iter().zip(&factors) {
        let q = e.quantities.iter().find(|q| &q.key() == key).unwrap();
        assert!((q.estimate - factor * q.raw).abs() <= 1e-12 * q.estimate.abs(), "{key}: {q:?} against c_q = {factor}");
    }

    let bad = dir.join("bad.h5");
    std::fs::copy(&basis, &bad).unwrap();
    {
        let f = flexrom::io::h5_open::open_rw(&bad).unwrap();
        let ds = f.dataset("estimator/calibration/quantity_factor").unwrap();
        let mut v = factors.clone();
        v[0] = f64::NAN;
        ds.write_raw(&v).unwrap();
    }
    let o = Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(["online", "p.toml", "--basis", "bad.h5", "-o", "bad_run.h5"])
        .current_dir(&dir)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("estimator/calibration/quantity_factor") && err.contains("NaN"), "{err}");
    assert!(!dir.join("bad_run.h5").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_method_covers_every_quantity() {
    let dir = trained("cover");
    for method in ["enriched", "corrected", "defects"] {
        for v in validations(&dir, method) {
            for q in v["probe_quantity_errors"].as_array().unwrap() {
                let Some(error) = q["relative"].as_f64() else { continue };
                let estimate = q["estimate"].as_f64().unwrap_or(f64::NAN);
                assert!(estimate >= error, "{method}, λ = {}: {q}", v["load_scale"]);
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_sweep_carries_strains_curvatures_and_their_estimates() {
    let dir = trained("sweep");
    flexrom(
        &dir,
        &["sweep", "p.toml", "--load-scales", "0.8,1.3", "--validate", "--estimate", "corrected", "-o", "s.h5"],
    );
    flexrom(&dir, &["online", "p.toml", "--load-scale", "1.3", "--estimate", "corrected", "-o", "rom.h5"]);
    let vs = validations(&dir, "corrected");
    let read2 = |name: &str| {
        let d = flexrom::io::h5_open::open(dir.join("s.h5")).unwrap().dataset(name).unwrap();
        d.read_2d::<f64>().unwrap()
    };
    let read1 = |name: &str| series(&dir.join("s.h5"), name);
    let kappa = read2("probe_curvature/root");
    assert_eq!(kappa.row(1).to_vec(), series(&dir.join("rom.h5"), "probe_curvature/root"));
    for (k, v) in vs.iter().enumerate() {
        for (quantity, probe) in [("position", "tip"), ("strain", "mid"), ("curvature", "root")] {
            let q = entry(v, probe, quantity);
            let est = read1(&format!("probe_error_estimate/{quantity}/{probe}"))[k];
            let err = read1(&format!("probe_error/{quantity}/{probe}"))[k];
            assert_eq!(Some(est), q["estimate"].as_f64(), "{quantity} {probe}");
            assert_eq!(Some(err), q["relative"].as_f64(), "{quantity} {probe}");
            // the root's strain is held at 0 by the clamp: no error to measure (NaN)
            assert!(read1("probe_error/strain/root")[k].is_nan());
        }
    }
    // --resume takes both points from the file and writes them again as they were
    let before =
        (read2("probe_curvature/root"), read1("probe_error_estimate/curvature/root"), read1("probe_error/strain/mid"));
    flexrom(
        &dir,
        &[
            "sweep",
            "p.toml",
            "--load-scales",
            "0.8,1.3",
            "--validate",
            "--estimate",
            "corrected",
            "--resume",
            "-o",
            "s.h5",
        ],
    );
    let after =
        (read2("probe_curvature/root"), read1("probe_error_estimate/curvature/root"), read1("probe_error/strain/mid"));
    assert_eq!(before, after);
    let _ = std::fs::remove_dir_all(&dir);
}
