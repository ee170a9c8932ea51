//! Reaction forces and moments by joint (src/analysis/reactions.rs) against the statics of
//! the whole body, which hold whatever the mesh: the joints' forces and the loads on a body
//! at rest sum to zero, and so do their moments (a rigid translation or rotation does no
//! internal work).
//!
//! * a pendulum with a tip mass hanging at rest, pinned at the top: the ground pin holds up
//!   the weight, `F = (0, (ρ A L + m) g)`, with no moment (a pin has no slope rows); in
//!   `statics` and in a dynamic run started from the static equilibrium (`[initial] static`);
//! * a cantilever under a tip force `(0, −P)`: the clamp's force is `(0, P)` and its moment
//!   `P x_tip` (the moment of the tip force about the clamp, `x_tip` the deflected tip's x),
//!   which is `P L` to the small deflection's order (Euler–Bernoulli: the clamping moment of a
//!   tip-loaded cantilever);
//! * the result file's `/reactions` and `/labels/reaction`, and `--csv`'s columns.

mod common;

use flexrom::analysis::reactions::ReactionMap;
use flexrom::analysis::statics::StaticOptions;
use std::process::Command;

const G: f64 = 9.81;
// the rod: 1 m of 1 cm² steel (7850 kg/m³), a tip mass of 2.355 kg
const ROD_MASS: f64 = 7850.0 * 1e-4 * 1.0;
const TIP_MASS: f64 = 2.355;

fn hanging_pendulum(initial_static: bool) -> String {
    let initial = if initial_static { "[initial]\nstatic = true\n" } else { "" };
    format!(
        "[time]\nt_end = 0.05\ndt = 0.001\nrho_inf = 0.8\n{initial}\
         [[bodies]]\nname = \"rod\"\nstart = [0.0, 0.0]\nangle = -1.5707963267948966\nlength = 1.0\nelements = 4\n\
         density = 7850.0\narea = 1.0e-4\ninertia = 8.33e-10\nyoungs_modulus = 2.1e11\n\
         [[joints]]\ntype = \"ground_pin\"\nbody = \"rod\"\nnode = \"start\"\n\
         [[masses]]\nbody = \"rod\"\nnode = \"end\"\nmass = {TIP_MASS}\n\
         [[loads]]\ntype = \"gravity\"\ng = [0.0, -{G}]\nscaled = true\n\
         [[probes]]\nname = \"tip\"\nbody = \"rod\"\nnode = \"end\"\n"
    )
}

fn flexrom(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    let out = Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(args)
        .current_dir(dir)
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    out
}

#[test]
fn a_hanging_pendulum_s_pin_holds_up_its_weight() {
    let weight = (ROD_MASS + TIP_MASS) * G;
    let model = common::model(&hanging_pendulum(false));
    let (r, _) = flexrom::simulate::statics(&model, &StaticOptions::default()).unwrap();
    let map = ReactionMap::of(&model);
    assert_eq!(map.names(), ["joint 0 (ground_pin rod node 0) on rod node 0"]);
    let v = map.series((&r.settings.mu, r.t.as_slice().unwrap()), &r.q, &r.multipliers);
    let last = r.t.len() - 1;
    let (fx, fy, m) = (v.force[(last, 0, 0)], v.force[(last, 0, 1)], v.moment[(last, 0)]);
    // the equilibrium of the whole body, to Newton's tolerance
    assert!(fx.abs() < 1e-9 * weight, "Fx = {fx} N");
    assert!((fy - weight).abs() < 1e-9 * weight, "Fy = {fy} N against (ρAL + m) g = {weight} N");
    assert_eq!(m, 0.0, "a pin transmits no moment");
}

/// Started from its static equilibrium, the pendulum stays at rest: its pin holds up the
/// weight at every instant of the run (the result file's `/reactions/force`).
#[test]
fn a_pendulum_at_rest_holds_its_weight_at_every_instant_of_a_run() {
    let weight = (ROD_MASS + TIP_MASS) * G;
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.toml"), hanging_pendulum(true)).unwrap();
    flexrom(dir.path(), &["simulate", "m.toml", "-o", "r.h5", "-q"]);
    let f = flexrom::io::h5_open::open(dir.path().join("r.h5")).unwrap();
    let force = f.dataset("reactions/force").unwrap();
    assert_eq!(flexrom::io::h5::read_attr_str(&force, "units").unwrap(), "N");
    assert_eq!(flexrom::io::h5::read_attr_str(&force, "dims").unwrap(), "time, reaction, xy");
    let force = force.read_dyn::<f64>().unwrap().into_dimensionality::<ndarray::Ix3>().unwrap();
    let nt = f.dataset("t").unwrap().size();
    assert_eq!(force.dim(), (nt, 1, 2));
    for k in 0..nt {
        let (fx, fy) = (force[(k, 0, 0)], force[(k, 0, 1)]);
        assert!(fx.abs() < 1e-6 * weight && (fy - weight).abs() < 1e-6 * weight, "t_{k}: ({fx}, {fy}) N");
    }
    let names = f.dataset("labels/reaction").unwrap().read_1d::<hdf5::types::VarLenUnicode>().unwrap();
    assert_eq!(names[0].as_str(), "joint 0 (ground_pin rod node 0) on rod node 0");
    let joints = f.dataset("labels/reaction_joint").unwrap().read_1d::<u64>().unwrap();
    assert_eq!(joints.to_vec(), [0]);
    let moment = f.dataset("reactions/moment").unwrap();
    assert_eq!(flexrom::io::h5::read_attr_str(&moment, "units").unwrap(), "N·m");
}

/// The cantilever of tests/statics.rs under a tip force P: the clamp's force `(0, P)` and its
/// moment `P x_tip ≈ P L` in `statics`' result file and its `--csv` columns.
#[test]
fn a_cantilever_s_clamp_takes_the_tip_force_and_its_moment() {
    let (l, e, a, i) = (1.0, 2.1e11, 1e-4, 1e-8 / 12.0);
    // δ/L = 1e-3: x_tip = L (1 − O(δ²/L²)), the moment P L to 1e-6
    let p = 1e-3 * 3.0 * e * i / (l * l * l);
    let model = common::cantilever(8, l, e, a, i, p);
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("c.toml"), &model.text).unwrap();
    let out = flexrom(dir.path(), &["statics", "c.toml", "-o", "s.h5", "--csv", "-q"]);
    let mut csv = csv::Reader::from_reader(out.stdout.as_slice());
    let header = csv.headers().unwrap().clone();
    let row = csv.records().last().expect("the equilibrium's row").unwrap();
    let column = |name: &str| -> f64 {
        let k = header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name} in {header:?}"));
        row[k].parse().unwrap()
    };
    let clamp = "joint 0 (clamp beam node 0) on beam node 0";
    let (fx, fy, m) =
        (column(&format!("{clamp}: Fx")), column(&format!("{clamp}: Fy")), column(&format!("{clamp}: M")));
    let x_tip = column("tip_x");
    assert!(fx.abs() < 1e-9 * p, "Fx = {fx} N");
    assert!((fy - p).abs() < 1e-9 * p, "Fy = {fy} N against P = {p} N");
    assert!((m - p * x_tip).abs() < 1e-9 * p * l, "M = {m} N m against P x_tip = {} N m", p * x_tip);
    assert!((m - p * l).abs() < 1e-5 * p * l, "M = {m} N m against P L = {} N m", p * l);
    // the file holds the same numbers
    let f = flexrom::io::h5_open::open(dir.path().join("s.h5")).unwrap();
    let force = f.dataset("reactions/force").unwrap().read_dyn::<f64>().unwrap();
    let moment = f.dataset("reactions/moment").unwrap().read_2d::<f64>().unwrap();
    let last = moment.nrows() - 1;
    assert_eq!((force[[last, 0, 0]], force[[last, 0, 1]], moment[(last, 0)]), (fx, fy, m));
}

/// A reduced run's reactions come from each body's balance of momentum
/// (src/reduction/projection/balance.rs): the tutorial's double pendulum (its shipped model
/// and pipeline, trained greedily) at λ = 1.1. Read from the joint rows, the ground pin's
/// force was off by 2.54 times its swing while positions were within 1e-4 of theirs; from
/// the balance it is 0.115, the elbow's 0.127 (docs/error-estimate.md, "Reactions"). The
/// bound, a fifth of the swing, is what an engineer can read a force from; each estimate
/// covers its error.
#[test]
fn a_reduced_double_pendulum_reads_its_pins_from_the_bodies_balance() {
    let d = tempfile::tempdir().unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::copy(root.join("data/models/double_pendulum.toml"), d.path().join("m.toml")).unwrap();
    let pipeline = std::fs::read_to_string(root.join("pipelines/double_pendulum.toml")).unwrap();
    let pipeline = pipeline
        .replace("../data/models/double_pendulum.toml", "m.toml")
        .replace("../data/bases/double_pendulum.h5", "b.h5")
        .replace("../reports/double_pendulum", "report");
    std::fs::write(d.path().join("p.toml"), pipeline).unwrap();
    flexrom(d.path(), &["train", "p.toml"]);
    let out = flexrom(d.path(), &["validate", "p.toml", "--load-scale", "1.1", "--json", "--no-dense"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["rel_error"].as_f64().unwrap() < 1e-3, "{}", v["rel_error"]);
    let forces: Vec<_> = v["reaction_errors"].as_array().unwrap().iter().filter(|e| e["quantity"] == "force").collect();
    assert_eq!(forces.len(), 3, "the ground pin on the upper link, the elbow on each link");
    for e in forces {
        let (error, estimate) = (e["relative"].as_f64().unwrap(), e["estimate"].as_f64().unwrap());
        assert!(error < 0.2, "{e}");
        assert!(estimate >= error, "{e}");
    }
}
