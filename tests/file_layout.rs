//! The HDF5 files flexrom writes, as h5py and xarray users open them (layout in docs/file-formats.md and src/io/attrs.rs), through the `flexrom` command.
//!
//! Checks, and where each expectation comes from:
//! - every kind of file a short run writes — `simulate` and `online` results, fixed-load and
//!   greedy bases (ECSW set, estimator, `/training`), a validated sweep, shard parts and
//!   their `merge`, `train --snapshots-only` files and the basis `--from-snapshots` — carries
//!   `flexrom_layout` = 2 and its kind (`flexrom_file`) on `/`, and on EVERY dataset a
//!   non-empty `units` and a `dims` naming one axis per dimension (none for a scalar);
//! - time first: a result's `/q` is (n_t, n_dof), `/multipliers` (n_t, n_c), `/reduced/q`
//!   (n_t, r), with n_t the length of `/t`; a sweep's `/reduced_q` (N, n_t, r); snapshot and
//!   mode matrices keep one column per snapshot/mode (dims "dof, snapshot", "dof, mode").
//!   Sizes from the model: the coarse pendulum has 8 elements → 9 nodes → 36 coordinates,
//!   one ground pin → 2 multipliers; t_end 0.1 s at dt 0.005 s → 21 instants;
//! - `/labels`: 36 coordinate names, the first "beam node 0 x", the 6th "beam node 1 y";
//!   the two constraint rows "joint 0 (ground_pin beam node 0) x" / "… y"
//!   (data/models/pendulum.toml: body "beam", joints[0] a ground pin at its start);
//! - a sweep file of layout 1 (the attribute removed, `/reduced_q` stored (N, r, n_t) as
//!   before) is still read by `sweep --resume`, which writes the same `/reduced_q`; a basis,
//!   a sweep and a snapshot file claiming layout 3 are refused with one line naming the
//!   file, `flexrom_layout`, the version found (3), the version read (2) and the command to
//!   re-run.

use hdf5::types::VarLenUnicode;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn flexrom() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_flexrom"));
    c.env("HDF5_USE_FILE_LOCKING", "FALSE");
    c
}

fn run(args: &[&str]) -> Output {
    let o = flexrom().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_ne!(o.status.code(), Some(101), "panic: {err}");
    o
}

fn ok(args: &[&str]) {
    let o = run(args);
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

const N_DOF: usize = 36;
const N_T: usize = 21;

/// The coarse pendulum (8 elements, 0.1 s) and two pipelines: fixed loads with ECSW, greedy.
fn setup(dir: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let model = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/pendulum.toml"))
        .unwrap()
        .replace("elements = 50", "elements = 8")
        .replace("t_end = 1.1", "t_end = 0.1")
        .replace("name = \"tip\"", "name = \"tip\"\nquantities = [\"strain\", \"curvature\"]");
    assert!(model.contains("elements = 8") && model.contains("t_end = 0.1") && model.contains("quantities"));
    let m = dir.join("model.toml");
    std::fs::write(&m, model).unwrap();
    let p = dir.join("pipe.toml");
    std::fs::write(
        &p,
        "model = \"model.toml\"\nbasis = \"basis.h5\"\nreport = \"report\"\n[train]\nload_scales = [0.9, 1.1]\n[reduction]\nvariant = \"galerkin\"\nmodes = { count = 6 }\nhyper = { tolerance = 1e-2 }\n",
    )
    .unwrap();
    let g = dir.join("greedy.toml");
    std::fs::write(
        &g,
        "model = \"model.toml\"\nbasis = \"greedy.h5\"\nreport = \"report_g\"\n[train]\ngreedy = { range = [0.8, 1.2], tolerance = 1e-6, max_runs = 2, candidates = 3 }\n[reduction]\nvariant = \"galerkin\"\nmodes = { count = 4 }\n",
    )
    .unwrap();
    (m, p, g)
}

/// Every dataset under `g`, with its path.
fn datasets(g: &hdf5::Group, prefix: &str, out: &mut Vec<(String, hdf5::Dataset)>) {
    for name in g.member_names().unwrap() {
        let full = if prefix.is_empty() { name.clone() } else { format!("{prefix}/{name}") };
        if let Ok(sub) = g.group(&name) {
            datasets(&sub, &full, out);
        } else if let Ok(d) = g.dataset(&name) {
            out.push((full, d));
        }
    }
}

fn text_attr(loc: &hdf5::Location, name: &str) -> Option<String> {
    loc.attr(name).ok().map(|a| a.read_scalar::<VarLenUnicode>().unwrap().as_str().to_string())
}

/// Every dataset has units and dims that fit its rank; the root has the layout and kind.
/// Returns the dataset paths seen.
fn check_units(path: &Path, kind: &str) -> Vec<String> {
    let f = flexrom::io::h5_open::open(path).unwrap();
    let layout = f.attr("flexrom_layout").unwrap_or_else(|_| panic!("{}: no flexrom_layout", path.display()));
    assert_eq!(layout.read_scalar::<u64>().unwrap(), 2, "{}", path.display());
    assert_eq!(text_attr(&f, "flexrom_file").as_deref(), Some(kind), "{}", path.display());
    let mut all = Vec::new();
    datasets(&f, "", &mut all);
    assert!(!all.is_empty());
    for (name, d) in &all {
        let units = text_attr(d, "units").unwrap_or_else(|| panic!("{}: /{name} has no `units`", path.display()));
        assert!(!units.trim().is_empty(), "{}: /{name}: empty units", path.display());
        let dims = text_attr(d, "dims").unwrap_or_else(|| panic!("{}: /{name} has no `dims`", path.display()));
        let n = if dims.is_empty() { 0 } else { dims.split(", ").count() };
        assert_eq!(n, d.ndim(), "{}: /{name}: dims `{dims}` for shape {:?}", path.display(), d.shape());
    }
    all.into_iter().map(|(n, _)| n).collect()
}

fn shape(path: &Path, name: &str) -> Vec<usize> {
    flexrom::io::h5_open::open(path).unwrap().dataset(name).unwrap_or_else(|_| panic!("{name}")).shape()
}

fn dims(path: &Path, name: &str) -> String {
    text_attr(&flexrom::io::h5_open::open(path).unwrap().dataset(name).unwrap(), "dims").unwrap()
}

fn texts(path: &Path, name: &str) -> Vec<String> {
    let d = flexrom::io::h5_open::open(path).unwrap().dataset(name).unwrap();
    d.read_raw::<VarLenUnicode>().unwrap().iter().map(|x| x.as_str().to_string()).collect()
}

fn check_labels(path: &Path) {
    let dof = texts(path, "labels/dof");
    assert_eq!(dof.len(), N_DOF, "{}", path.display());
    assert_eq!((dof[0].as_str(), dof[5].as_str()), ("beam node 0 x", "beam node 1 y"));
    assert_eq!(
        texts(path, "labels/multiplier"),
        vec!["joint 0 (ground_pin beam node 0) x", "joint 0 (ground_pin beam node 0) y"]
    );
    assert_eq!(texts(path, "labels/body"), vec!["beam"]);
}

#[test]
fn every_dataset_of_every_file_has_units_and_time_comes_first() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();
    let (m, p, g) = setup(d);
    let out = |n: &str| d.join(n);
    ok(&["simulate", s(&m), "-o", s(&out("sim.h5"))]);
    ok(&["train", s(&p)]);
    ok(&["train", s(&g)]);
    ok(&["online", s(&p), "--load-scale", "1.0", "-o", s(&out("online.h5"))]);
    ok(&["sweep", s(&p), "--load-scales", "0.9:1.1:3", "--validate", "-o", s(&out("sweep.h5"))]);
    for k in 1..=2 {
        let part = out(&format!("part{k}.h5"));
        ok(&["sweep", s(&p), "--load-scales", "0.9:1.1:3", "--shard", &format!("{k}/2"), "-o", s(&part)]);
    }
    ok(&["merge", s(&out("part1.h5")), s(&out("part2.h5")), "-o", s(&out("merged.h5"))]);
    ok(&["train", s(&p), "--snapshots-only", "--shard", "1/2", "-o", s(&out("snaps1.h5"))]);
    ok(&["train", s(&p), "--snapshots-only", "--shard", "2/2", "-o", s(&out("snaps2.h5"))]);
    ok(&[
        "train",
        s(&p),
        "--basis",
        s(&out("from_snaps.h5")),
        "--from-snapshots",
        s(&out("snaps1.h5")),
        s(&out("snaps2.h5")),
    ]);

    // units everywhere
    for f in ["sim.h5", "online.h5"] {
        let set = check_units(&out(f), "result");
        for name in ["qd", "probe_strain/tip", "probe_curvature/tip"] {
            assert!(set.iter().any(|n| n == name), "{f}: no /{name}");
        }
        check_labels(&out(f));
    }
    let basis_sets: Vec<Vec<String>> =
        ["basis.h5", "greedy.h5", "from_snaps.h5"].iter().map(|f| check_units(&out(f), "basis")).collect();
    for f in ["sweep.h5", "part1.h5", "part2.h5", "merged.h5"] {
        let set = check_units(&out(f), "sweep");
        // the validated sweep keeps the full runs' probes beside the reduced ones
        assert_eq!(set.iter().any(|n| n == "full_probes/tip"), f == "sweep.h5", "{f}");
    }
    for f in ["snaps1.h5", "snaps2.h5"] {
        check_units(&out(f), "snapshots");
        check_labels(&out(f));
    }
    // the kinds of dataset the brief names were there to be checked
    let has = |set: &[String], name: &str| set.iter().any(|n| n == name);
    assert!(has(&basis_sets[0], "hyper/weights") && has(&basis_sets[0], "basis/singular_values"));
    assert!(has(&basis_sets[0], "estimator/modes") && has(&basis_sets[0], "estimator/calibration/rel_error"));
    assert!(has(&basis_sets[1], "training/estimates") && has(&basis_sets[1], "training/load_scales"));
    check_labels(&out("basis.h5"));

    // time first in results and sweeps
    let sim = out("sim.h5");
    assert_eq!(shape(&sim, "t"), vec![N_T]);
    assert_eq!((shape(&sim, "q"), dims(&sim, "q")), (vec![N_T, N_DOF], "time, dof".to_string()));
    assert_eq!(shape(&sim, "multipliers"), vec![N_T, 2]);
    assert_eq!((shape(&sim, "qd"), dims(&sim, "qd")), (vec![N_T, N_DOF], "time, dof".to_string()));
    assert_eq!(
        (shape(&sim, "probe_curvature/tip"), dims(&sim, "probe_curvature/tip")),
        (vec![N_T], "time".to_string())
    );
    assert_eq!(shape(&sim, "probes/tip"), vec![N_T, 2]);
    let on = out("online.h5");
    assert_eq!((shape(&on, "reduced/q"), dims(&on, "reduced/q")), (vec![N_T, 6], "time, mode".to_string()));
    let sw = out("sweep.h5");
    assert_eq!(shape(&sw, "reduced_q"), vec![3, N_T, 6]);
    assert_eq!(dims(&sw, "reduced_q"), "load, time, mode");
    assert_eq!(shape(&sw, "probes/tip"), vec![3, N_T, 2]);
    // the result's rows are the states: its first row is the initial state, the basis's
    // reference (raw snapshots: the first snapshot column)
    let b = out("basis.h5");
    assert_eq!((shape(&b, "basis/modes"), dims(&b, "basis/modes")), (vec![N_DOF, 6], "dof, mode".to_string()));
    assert_eq!((shape(&b, "snapshots"), dims(&b, "snapshots")), (vec![N_DOF, 2 * N_T], "dof, snapshot".to_string()));
    let q = flexrom::io::h5_open::open(&sim).unwrap().dataset("q").unwrap().read_2d::<f64>().unwrap();
    let snaps = flexrom::io::h5_open::open(&b).unwrap().dataset("snapshots").unwrap().read_2d::<f64>().unwrap();
    assert_eq!(q.row(0), snaps.column(0), "t = 0 is the same state at every load");
    // x of node 1 at rest: the pendulum starts horizontal along +x (data/models/pendulum.toml)
    assert!(q[[0, 4]] > 0.0 && q[[0, 5]] == 0.0, "{:?}", q.row(0));
    assert_eq!(
        text_attr(&flexrom::io::h5_open::open(&sim).unwrap().dataset("q").unwrap(), "units").unwrap(),
        "m (positions x, y), 1 (slopes x', y')"
    );
}

/// Sets `flexrom_layout` of `path` to `v` (or removes it).
fn set_layout(path: &Path, v: Option<u64>) {
    let f = flexrom::io::h5_open::open_rw(path).unwrap();
    if f.attr("flexrom_layout").is_ok() {
        f.delete_attr("flexrom_layout").unwrap();
    }
    if let Some(v) = v {
        f.new_attr::<u64>().create("flexrom_layout").unwrap().write_scalar(&v).unwrap();
    }
}

fn refused(args: &[&str], file: &Path, rerun: &str) {
    let o = run(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{args:?} accepted a layout-3 file");
    for want in [s(file), "flexrom_layout", "is 3", "layout 2", rerun] {
        assert!(err.contains(want), "{args:?}: `{want}` not in: {err}");
    }
    assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
}

#[test]
fn older_layouts_are_read_and_newer_ones_refused() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();
    let (_, p, _) = setup(d);
    let out = |n: &str| d.join(n);
    ok(&["train", s(&p)]);
    let sweep = out("sweep.h5");
    ok(&["sweep", s(&p), "--load-scales", "0.9:1.1:3", "-o", s(&sweep)]);
    let new =
        flexrom::io::h5_open::open(&sweep).unwrap().dataset("reduced_q").unwrap().read::<f64, ndarray::Ix3>().unwrap();
    assert_eq!(new.dim(), (3, N_T, 6));
    assert!(new.iter().all(|x| x.is_finite()));

    // the file as layout 1 wrote it: no attribute, /reduced_q (N, r, n_t)
    let old = out("old.h5");
    std::fs::copy(&sweep, &old).unwrap();
    {
        let f = flexrom::io::h5_open::open_rw(&old).unwrap();
        f.unlink("reduced_q").unwrap();
        let zq = new.view().permuted_axes([0, 2, 1]).as_standard_layout().to_owned();
        f.new_dataset_builder().with_data(&zq).create("reduced_q").unwrap();
    }
    set_layout(&old, None);
    ok(&["sweep", s(&p), "--load-scales", "0.9:1.1:3", "--resume", "-o", s(&old)]);
    let f = flexrom::io::h5_open::open(&old).unwrap();
    assert_eq!(f.attr("flexrom_layout").unwrap().read_scalar::<u64>().unwrap(), 2, "rewritten as layout 2");
    let again = f.dataset("reduced_q").unwrap().read::<f64, ndarray::Ix3>().unwrap();
    assert_eq!(again, new, "the runs were taken from the old file and written time first");
    drop(f);

    // newer layouts: refused, naming file, versions and what to do
    let sweep3 = out("sweep3.h5");
    std::fs::copy(&sweep, &sweep3).unwrap();
    set_layout(&sweep3, Some(3));
    refused(&["sweep", s(&p), "--load-scales", "0.9:1.1:3", "--resume", "-o", s(&sweep3)], &sweep3, "flexrom sweep");
    let snaps = out("snaps.h5");
    ok(&["train", s(&p), "--snapshots-only", "--shard", "1/1", "-o", s(&snaps)]);
    set_layout(&snaps, Some(3));
    refused(
        &["train", s(&p), "--basis", s(&out("b2.h5")), "--from-snapshots", s(&snaps)],
        &snaps,
        "flexrom train --snapshots-only",
    );
    let basis = out("basis.h5");
    set_layout(&basis, Some(3));
    refused(&["online", s(&p), "--load-scale", "1.0", "-o", s(&out("on.h5"))], &basis, "flexrom train");
}

/// docs/file-formats.md shows, for every dataset of the code's tables (src/io/attrs.rs), a
/// row in its file kind's section with the same dims and units.
#[test]
fn the_documented_tables_are_the_written_ones() {
    use flexrom::io::attrs::{table, Kind};
    let doc = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/file-formats.md")).unwrap();
    let section = |heading: &str| -> String {
        let start = doc.find(&format!("\n## {heading}\n")).unwrap_or_else(|| panic!("no section {heading}"));
        let rest = &doc[start + heading.len() + 5..];
        rest[..rest.find("\n## ").unwrap_or(rest.len())].to_string()
    };
    let check = |heading: &str, entries: &[(&str, &str, &str)]| {
        let sec = section(heading);
        for (path, units, dims) in entries {
            let shown = format!("| `/{}` |", path.replace('*', "<name>"));
            let row = sec
                .lines()
                .find(|l| l.starts_with(&shown))
                .unwrap_or_else(|| panic!("docs/file-formats.md, {heading}: no row for `/{path}`"));
            // cells between unescaped `|`: path, dims, shape, units, meaning
            let row = row.replace("\\|", "¦");
            let cells: Vec<&str> = row.split('|').map(str::trim).collect();
            assert_eq!(cells[2], *dims, "{heading}: /{path} dims");
            assert_eq!(cells[4], *units, "{heading}: /{path} units");
        }
    };
    check("Result file", table(Kind::Result));
    check("Basis file", table(Kind::Basis));
    check("Sweep file", table(Kind::Sweep));
    check("Snapshot file", table(Kind::Snapshots));
    check("Modes file", table(Kind::Modes));
    // /labels: the result's table of names is every file's
    let labels: Vec<_> = flexrom::io::attrs::LABELS.to_vec();
    check("Labels", &labels);
}
