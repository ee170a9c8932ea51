//! `[reduction] probe_modes` (src/reduction/output_modes.rs): a basis enriched until the
//! strains and curvatures its probes record are reproduced on the training snapshots.
//!
//! The model: a two-link aluminium arm (30 elements a link, 248 coordinates) swung by a
//! shoulder moment (load scale) with a tip force (`payload`), a probe recording strain and
//! curvature at the shoulder root; trained at 5 Sobol points of the box
//! load_scale ∈ [0.6, 1.4] × payload ∈ [0, 2], one POD per body to the energy tolerance
//! 1e-12, constraint-preserving, no ECSW; validated at (1.305, 1.097), a point of no run.
//!
//! - `output_modes_bring_the_root_curvature_within_the_tolerance`: without output modes the
//!   root curvature is off by 2.4e-3 of its range and the root strain by 3.9e-2 (measured
//!   when this test was written: the POD's 27 modes capture all but 7e-13 of the snapshots'
//!   energy, yet a stiff link's stretch and its root's bending wave lie in directions of
//!   smaller energy). With `probe_modes = { tolerance = 1e-3 }` the upper link gets output
//!   modes (8 when written) and the lower link none (the probe reads the upper link only);
//!   the curvature must come within the tolerance 1e-3 of its range (6.0e-5 when written)
//!   and at least ten times closer than without, the strain closer than without (1.2e-2
//!   when written: the reduced dynamics, not the basis, is what is left — the basis
//!   reproduces the training snapshots' root strain within 1e-3), and the error estimate
//!   of each quantity at least its error (every estimate here read 1.5× its error).
//! - `greedy_holds_the_probes_with_measure_probes`: `greedy = { measure = "probes" }` on
//!   the arm of 4 elements a link (4 full runs, tolerance 1e-3): every basis of the loop gets
//!   output modes for the root's strain and curvature (the upper link some, the lower none),
//!   and training's lines name them (the held-out check's error in this measure, the larger
//!   of rel_error and the worst probe quantity: `the_probes_measure_holds_the_worst_quantity`
//!   in src/training/greedy.rs).
//! - `probe_modes_are_refused_where_they_cannot_apply`: a model whose probes record neither
//!   quantity, a tolerance outside (0, 1) — each named as
//!   `reduction.probe_modes`; `measure = "probes"` on a model without probes, named as
//!   `train.greedy.measure`.

mod common;

use std::path::Path;
use std::process::{Command, Output};

fn flexrom(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flexrom")).args(args).env("HDF5_USE_FILE_LOCKING", "FALSE").output().unwrap()
}

/// The arm of `common::two_link_arm` (30 elements a link, Δt 1 ms) with a probe at the
/// shoulder root recording `quantities`.
fn arm(quantities: &str) -> String {
    common::two_link_arm(30, 0.001)
        + &format!(
            "[[probes]]\nname = \"shoulder_root\"\nbody = \"upper\"\nnode = \"start\"\nquantities = {quantities}\n"
        )
}

fn pipeline(dir: &Path, name: &str, model: &str, reduction: &str) -> String {
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(
        &p,
        format!(
            "model = \"{model}\"\nbasis = \"{name}.h5\"\nreport = \"{name}_report\"\n[parameters]\nload_scale = [0.6, 1.4]\npayload = [0.0, 2.0]\n[train]\npoints = {{ count = 5, sampling = \"sobol\" }}\n[reduction]\nvariant = \"constraint-preserving\"\nblocks = \"bodies\"\nmodes = {{ energy = 1e-12 }}\n{reduction}\n"
        ),
    )
    .unwrap();
    p.to_str().unwrap().to_string()
}

/// (relative error over the range, its estimate) of the shoulder root's `quantity`.
fn root_error(json: &serde_json::Value, quantity: &str) -> (f64, f64) {
    let r = if json.is_array() { &json[0] } else { json };
    let e = r["probe_quantity_errors"]
        .as_array()
        .unwrap()
        .iter()
        .find(|q| q["probe"] == "shoulder_root" && q["quantity"] == quantity)
        .unwrap_or_else(|| panic!("no {quantity} entry in {r}"));
    (e["relative"].as_f64().unwrap(), e["estimate"].as_f64().unwrap())
}

fn train_and_validate(p: &str) -> serde_json::Value {
    let o = flexrom(&["train", p]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = flexrom(&["validate", p, "--load-scale", "1.305", "--param", "payload=1.097", "--no-dense", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn output_modes_bring_the_root_curvature_within_the_tolerance() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("arm.toml"), arm("[\"strain\", \"curvature\"]")).unwrap();
    let plain = train_and_validate(&pipeline(dir.path(), "plain", "arm.toml", ""));
    let enriched =
        train_and_validate(&pipeline(dir.path(), "enriched", "arm.toml", "probe_modes = { tolerance = 1e-3 }"));
    let (k0, _) = root_error(&plain, "curvature");
    let (k1, k1_est) = root_error(&enriched, "curvature");
    let (s0, _) = root_error(&plain, "strain");
    let (s1, s1_est) = root_error(&enriched, "strain");
    assert!(k1 <= 1e-3 && k1 * 10.0 <= k0, "root curvature over its range: {k0:.2e} without, {k1:.2e} with");
    assert!(s1 < s0, "root strain over its range: {s0:.2e} without, {s1:.2e} with");
    assert!(k1_est >= k1 && s1_est >= s1, "estimates {k1_est:.2e} ≥ {k1:.2e}, {s1_est:.2e} ≥ {s1:.2e}");
    let f = flexrom::io::h5_open::open(dir.path().join("enriched.h5")).unwrap();
    let added = f.dataset("basis/output_modes").unwrap().read_1d::<u64>().unwrap().to_vec();
    assert!(added[0] > 0 && added[1] == 0, "output modes per link: {added:?}");
    let plain_file = flexrom::io::h5_open::open(dir.path().join("plain.h5")).unwrap();
    assert!(plain_file.dataset("basis/output_modes").is_err(), "a basis without output modes has no such dataset");
}

#[test]
fn probe_modes_are_refused_where_they_cannot_apply() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("arm.toml"), arm("[\"position\"]")).unwrap();
    std::fs::write(dir.path().join("arm_q.toml"), arm("[\"curvature\"]")).unwrap();
    std::fs::write(dir.path().join("bare_model.toml"), arm("[\"position\"]").split("[[probes]]").next().unwrap())
        .unwrap();
    let p = pipeline(dir.path(), "bare", "bare_model.toml", "");
    let text = std::fs::read_to_string(&p).unwrap().replace(
        "points = { count = 5, sampling = \"sobol\" }",
        "greedy = { tolerance = 1e-3, max_runs = 3, measure = \"probes\" }",
    );
    std::fs::write(&p, text.replace("modes = { energy = 1e-12 }\n", "")).unwrap();
    let o = flexrom(&["train", &p]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("train.greedy.measure") && err.contains("no [[probes]]"), "{err}");
    for (model, reduction, needle) in [
        ("arm.toml", "probe_modes = { tolerance = 1e-3 }", "no probe of the model records"),
        ("arm_q.toml", "probe_modes = { tolerance = 1.5 }", "strictly between 0 and 1"),
    ] {
        let p = pipeline(dir.path(), "refused", model, reduction);
        let o = flexrom(&["train", &p]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{reduction} on {model} was accepted");
        assert!(err.contains("reduction.probe_modes") && err.contains(needle), "{err}");
    }
}

#[test]
fn greedy_holds_the_probes_with_measure_probes() {
    let dir = tempfile::tempdir().unwrap();
    let model = common::two_link_arm(4, 0.005)
        + "[[probes]]\nname = \"shoulder_root\"\nbody = \"upper\"\nnode = \"start\"\nquantities = [\"strain\", \"curvature\"]\n";
    std::fs::write(dir.path().join("arm.toml"), model).unwrap();
    let p = dir.path().join("greedy.toml");
    std::fs::write(&p, "model = \"arm.toml\"\nbasis = \"greedy.h5\"\nreport = \"r\"\n[parameters]\nload_scale = [0.6, 1.4]\npayload = [0.0, 2.0]\n[train]\ngreedy = { tolerance = 1e-3, max_runs = 4, measure = \"probes\" }\n").unwrap();
    let o = flexrom(&["train", p.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.lines().any(|l| l.starts_with("iteration 1") && l.contains("output modes")), "{err}");
    let f = flexrom::io::h5_open::open(dir.path().join("greedy.h5")).unwrap();
    let added = f.dataset("basis/output_modes").unwrap().read_1d::<u64>().unwrap().to_vec();
    assert!(added[0] > 0 && added[1] == 0, "output modes per link: {added:?}");
    // the held-out checks hold the worst probe quantity too: at least rel_error's share
    let g = f.group("training").unwrap();
    let true_errors = g.dataset("true_error").unwrap().read_1d::<f64>().unwrap();
    assert!(true_errors.iter().any(|e| e.is_finite() && *e > 0.0), "{true_errors:?}");
}
