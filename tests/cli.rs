//! The `flexrom simulate` command as a user meets it: the result-file layout that outside
//! scripts read (velocities and the probes' strain and curvature included), and bad input —
//! a message naming the file, the field and the problem, a non-zero exit, and no output
//! file.

use std::path::{Path, PathBuf};
use std::process::Command;

fn flexrom() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flexrom"))
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models").join(name)
}

#[test]
fn simulate_writes_the_documented_layout() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p.h5");
    let o = flexrom()
        .args([
            "simulate",
            data("pendulum.toml").to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--t-end",
            "0.05",
            "--csv",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = String::from_utf8(o.stdout).unwrap();
    assert_eq!(csv.lines().next(), Some("t,tip_x,tip_y,energy_kinetic,energy_strain,energy_strain_axial,energy_strain_bending,energy_gravity,energy_springs,energy_external_work,energy_drive_work,joint 0 (ground_pin beam node 0) on beam node 0: Fx,joint 0 (ground_pin beam node 0) on beam node 0: Fy,joint 0 (ground_pin beam node 0) on beam node 0: M"));
    assert_eq!(csv.lines().count(), 1 + 11, "header + t = 0 and 10 steps");
    let f = flexrom::io::h5_open::open(&out).unwrap();
    let t = f.dataset("t").unwrap().read_1d::<f64>().unwrap();
    assert_eq!(t.len(), 11);
    assert!((t[10] - 0.05).abs() < 1e-12);
    // time first (layout 2, docs/file-formats.md)
    assert_eq!(f.dataset("q").unwrap().shape(), vec![11, 204]);
    assert_eq!(f.dataset("multipliers").unwrap().shape(), vec![11, 2]);
    let tip = f.dataset("probes/tip").unwrap().read_2d::<f64>().unwrap();
    assert_eq!(tip.shape(), &[11, 2]);
    // the tip probe is the last node's position: row 10, columns 200 and 201 of /q
    let q = f.dataset("q").unwrap().read_2d::<f64>().unwrap();
    assert_eq!(tip[[10, 0]], q[[10, 200]]);
    assert_eq!(tip[[10, 1]], q[[10, 201]]);
    // /qd: the velocities, laid out as /q; the pendulum's ρ∞ = 1 makes generalized-α the
    // average-acceleration rule (β = ¼, γ = ½), whose two updates give
    // q_{k+1} − q_k = h (q̇_k + q̇_{k+1}) / 2 at every step, to round-off; the run starts at rest
    let qd = f.dataset("qd").unwrap();
    assert_eq!(flexrom::io::h5::read_attr_str(&qd, "units").unwrap(), "m/s (positions x, y), 1/s (slopes x', y')");
    assert_eq!(flexrom::io::h5::read_attr_str(&qd, "dims").unwrap(), "time, dof");
    let qd = qd.read_2d::<f64>().unwrap();
    assert_eq!(qd.shape(), q.shape());
    assert!(qd.row(0).iter().all(|&v| v == 0.0) && qd.row(10).iter().any(|&v| v.abs() > 1e-3));
    for k in 0..10 {
        for i in 0..204 {
            let gap = q[[k + 1, i]] - q[[k, i]] - 0.0025 * (qd[[k, i]] + qd[[k + 1, i]]);
            assert!(gap.abs() < 1e-12, "step {k}, coordinate {i}: {gap:e}");
        }
    }
    assert!(flexrom::io::h5::read_attr_str(&f, "model").unwrap().contains("[[bodies]]"));
    assert_eq!(flexrom::io::h5::read_attr_f64(&f, "dt").unwrap(), 0.005);
    assert_eq!(flexrom::io::h5::read_attr_f64(&f, "load_scale").unwrap(), 1.0);
    assert!(f.attr("newton_iterations").unwrap().read_scalar::<u64>().unwrap() >= 10);
    assert!(flexrom::io::h5::read_attr_f64(&f, "wall_seconds").unwrap() > 0.0);
}

/// Probes that list `strain` and `curvature` in `quantities` write `/probe_strain/<name>`
/// (1) and `/probe_curvature/<name>` (1/m), the values the element's formulas give from the
/// file's own `/q` (src/physics/section.rs), and print them as CSV columns; a probe without
/// the key records its position only.
#[test]
fn probes_record_strain_and_curvature_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(data("pendulum.toml")).unwrap()
        + "\n[[probes]]\nname = \"mid\"\nbody = \"beam\"\nat = 0.33\nquantities = [\"position\", \"strain\", \"curvature\"]\n";
    let model = dir.path().join("m.toml");
    std::fs::write(&model, &text).unwrap();
    let out = dir.path().join("r.h5");
    let args = ["simulate", model.to_str().unwrap(), "--t-end", "0.05"];
    let o = flexrom().args(args).args(["-o", out.to_str().unwrap(), "--csv"]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = String::from_utf8(o.stdout).unwrap();
    assert_eq!(csv.lines().next(), Some("t,tip_x,tip_y,mid_x,mid_y,mid_strain,mid_curvature,energy_kinetic,energy_strain,energy_strain_axial,energy_strain_bending,energy_gravity,energy_springs,energy_external_work,energy_drive_work,joint 0 (ground_pin beam node 0) on beam node 0: Fx,joint 0 (ground_pin beam node 0) on beam node 0: Fy,joint 0 (ground_pin beam node 0) on beam node 0: M"));
    let f = flexrom::io::h5_open::open(&out).unwrap();
    let m = flexrom::model::Model::from_text(&text, "m.toml").unwrap();
    let sys = m.system(Default::default());
    let q = f.dataset("q").unwrap().read_2d::<f64>().unwrap();
    let strain = f.dataset("probe_strain/mid").unwrap();
    let curvature = f.dataset("probe_curvature/mid").unwrap();
    assert_eq!(flexrom::io::h5::read_attr_str(&strain, "units").unwrap(), "1");
    assert_eq!(flexrom::io::h5::read_attr_str(&curvature, "units").unwrap(), "1/m");
    let (strain, curvature) = (strain.read_1d::<f64>().unwrap(), curvature.read_1d::<f64>().unwrap());
    let mid = &m.probes()[1];
    for k in 0..q.nrows() {
        let (e, c) = sys.probe_section(mid, q.row(k).as_slice().unwrap());
        assert_eq!((strain[k], curvature[k]), (e, c), "instant {k}");
    }
    // straight at rest, bent as it falls
    assert!(curvature[0] == 0.0 && curvature[10].abs() > 1e-6, "{curvature}");
    assert!(f.link_exists("probe_strain") && !f.link_exists("probe_strain/tip"), "tip: position only");
}

/// Runs `simulate` on a broken copy of the pendulum file and returns stderr; asserts the
/// exit is non-zero and that no output (nor temporary) file is left behind.
fn broken(edit: impl Fn(&str) -> String) -> String {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("broken.toml");
    std::fs::write(&model, edit(&std::fs::read_to_string(data("pendulum.toml")).unwrap())).unwrap();
    let out = dir.path().join("out.h5");
    let o = flexrom().args(["simulate", model.to_str().unwrap(), "-o", out.to_str().unwrap()]).output().unwrap();
    assert!(!o.status.success());
    assert!(!out.exists(), "no output file on error");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "only the model file remains");
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(err.contains("broken.toml"), "message names the file: {err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

#[test]
#[allow(clippy::type_complexity)]
fn bad_model_files_are_refused_with_file_field_and_problem() {
    let cases: Vec<(Box<dyn Fn(&str) -> String>, &[&str])> = vec![
        (Box::new(|s: &str| s.replace("length = 1.2", "length = 1.2\nlenght = 3")), &["lenght", "unknown field"]),
        (Box::new(|s: &str| s.replace("density = 5540.0\n", "")), &["density", "missing"]),
        (Box::new(|s: &str| s.replace("length = 1.2", "length = 0.0")), &["bodies[0].length", "positive"]),
        (Box::new(|s: &str| s.replace("length = 1.2", "length = -1.2")), &["bodies[0].length", "positive"]),
        (
            Box::new(|s: &str| s.replace("youngs_modulus = 0.7e9", "youngs_modulus = nan")),
            &["bodies[0].youngs_modulus", "finite"],
        ),
        (Box::new(|s: &str| s.replace("area = 1.8e-3", "area = inf")), &["bodies[0].area"]),
        (Box::new(|s: &str| s.replace("inertia = 1.215e-8", "inertia = 0")), &["bodies[0].inertia"]),
        (Box::new(|s: &str| s.replace("density = 5540.0", "density = -1.0")), &["bodies[0].density"]),
        (Box::new(|s: &str| s.replace("elements = 50", "elements = 0")), &["bodies[0].elements", "positive"]),
        (Box::new(|s: &str| s.replace("elements = 50", "elements = -3")), &["bodies[0].elements"]),
        (Box::new(|s: &str| s.replace("dt = 0.005", "dt = 0.0")), &["time.dt", "positive"]),
        (Box::new(|s: &str| s.replace("dt = 0.005", "dt = -0.005")), &["time.dt"]),
        (Box::new(|s: &str| s.replace("rho_inf = 1.0", "rho_inf = 1.5")), &["time.rho_inf"]),
        (
            Box::new(|s: &str| s.replace("rho_inf = 1.0", "rho_inf = 1.0\njacobian_reuse = \"always\"")),
            &["time.jacobian_reuse", "within-step"],
        ),
        (
            Box::new(|s: &str| s.replace("rho_inf = 1.0", "rho_inf = 1.0\npredictor = \"linear\"")),
            &["time.predictor", "constant-velocity", "linear"],
        ),
        (
            Box::new(|s: &str| s.replace("body = \"beam\"\nnode = \"start\"", "body = \"bean\"\nnode = \"start\"")),
            &["joints[0].body", "bean"],
        ),
        (Box::new(|s: &str| s.replace("node = \"start\"", "node = 51")), &["joints[0].node", "outside"]),
        (Box::new(|s: &str| s.replace("node = \"end\"", "node = 77")), &["probes[0].node", "outside"]),
        (Box::new(|s: &str| s.replace("node = \"end\"", "at = 1.5")), &["probes[0].at", "outside"]),
        (
            Box::new(|s: &str| s.replace("type = \"ground_pin\"", "type = \"ground_pin\"\npoint = [0.5, 0.0]")),
            &["joints[0].point"],
        ),
    ];
    for (edit, needles) in cases {
        let err = broken(edit);
        for n in needles {
            assert!(err.contains(n), "expected `{n}` in: {err}");
        }
    }
}

/// Every command creates a missing output folder (tests/safety.rs checks the others).
#[test]
fn output_into_a_missing_directory_creates_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("no/such/dir/out.h5");
    let o = flexrom()
        .args(["simulate", data("pendulum.toml").to_str().unwrap(), "-o", out.to_str().unwrap(), "--t-end", "0.01"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(flexrom::io::h5_open::open(&out).is_ok());
}

#[test]
fn a_failed_run_keeps_the_previous_good_result() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("keep.h5");
    std::fs::write(&out, b"previous good data").unwrap();
    let o = flexrom()
        .args(["simulate", data("pendulum.toml").to_str().unwrap(), "-o", out.to_str().unwrap(), "--dt", "-1"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert_eq!(std::fs::read(&out).unwrap(), b"previous good data");
    // the result file begun beside the run (src/io/result_file.rs) is gone with it
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(left, ["keep.h5"], "only the previous result is left");
}

#[test]
fn missing_model_file_is_named() {
    let o = flexrom().args(["simulate", "/no/such/model.toml", "-o", "/tmp/x.h5"]).output().unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8(o.stderr).unwrap().contains("/no/such/model.toml"));
}

/// A time step longer than the run names where each value came from (the option or the
/// model file's key), and an output where no file can be made names that output, not the
/// temporary file beside it that the user never gave.
#[test]
fn a_step_longer_than_the_run_and_an_unwritable_output_are_named() {
    let model = data("pendulum.toml");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.h5");
    let o = flexrom()
        .args(["simulate", model.to_str().unwrap(), "-o", out.to_str().unwrap(), "--dt", "2"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(!o.status.success());
    assert!(err.contains("--dt = 2") && err.contains("pendulum.toml: time.t_end = 1.1"), "{err}");
    assert!(!out.exists());
    // /proc takes no new files (Linux)
    let o = flexrom().args(["simulate", model.to_str().unwrap(), "-o", "/proc/flexrom-x.h5"]).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(!o.status.success());
    assert!(err.starts_with("error: /proc/flexrom-x.h5: cannot write there"), "{err}");
}
