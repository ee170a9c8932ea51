//! Training over a box of parameters (`[parameters]` and `[train] points` or `greedy` in the
//! pipeline): the points are drawn from the box and stored in the basis with it, greedy
//! training converges over it, sharded sweeps over points merge into the single sweep,
//! `run` sweeps and reports over the box, a reduced run inside
//! the box is not extrapolated and one outside names the parameter that left it, a pipeline
//! whose box differs from the basis's is refused, sweeps run grids and lists of points, and
//! training in separate jobs (`--snapshots-only --shard`, `--from-snapshots`) gives the
//! single training's basis.
//!
//! Model: the tutorial's double pendulum (`data/models/double_pendulum.toml`) with gravity
//! scaled by `g` and a horizontal tip force scaled by `push`. The accuracy bound at held-out
//! points (rel_error ≤ 1e-3) is the tutorial's own tolerance (pipelines/double_pendulum.toml,
//! greedy tolerance 1e-3), which 12 modes meet on the line with room to spare (5.6e-5 at
//! λ = 1.1, `flexrom validate` at commit a455e23).

mod common;

use std::path::Path;
use std::process::{Command, Output};

const TIP_FORCE: &str =
    "\n[[loads]]\ntype = \"force\"\nbody = \"lower\"\nnode = \"end\"\nvalue = [0.5, 0.0]\nscaled = \"push\"\n";

const BOX: &str = "[parameters]\ng = [0.8, 1.2]\npush = { range = [0.2, 2.0], scale = \"log\" }\n";

const TRAIN: &str =
    "[train]\npoints = { count = 6 }\n[reduction]\nvariant = \"constraint-preserving\"\nmodes = { count = 12 }\n";

fn setup(dir: &Path, pipeline_body: &str) {
    let base = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/double_pendulum.toml"))
        .unwrap();
    std::fs::write(dir.join("m.toml"), format!("{}{TIP_FORCE}", base.replace("scaled = true", "scaled = \"g\"")))
        .unwrap();
    std::fs::write(
        dir.join("p.toml"),
        format!("model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n{pipeline_body}"),
    )
    .unwrap();
}

fn flexrom(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(args)
        .current_dir(dir)
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap()
}

fn text(o: &Output) -> (String, String) {
    (String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn a_basis_trained_over_a_box_holds_it_and_checks_runs_against_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup(d, &format!("{BOX}{TRAIN}"));
    let out = flexrom(d, &["train", "p.toml", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);

    // the basis holds the box and the training points, as the pipeline draws them
    let p = flexrom::pipeline::Pipeline::load(d.join("p.toml")).unwrap();
    let space = flexrom::io::basis_file::read_basis(&d.join("b.h5")).unwrap().training.space;
    assert_eq!(space, p.space());
    let points = p.training_points();
    assert_eq!(points.len(), 6);
    let f = flexrom::io::h5_open::open(d.join("b.h5")).unwrap();
    for r in &space.ranges {
        let stored = f.dataset(&format!("parameters/{}", r.name)).unwrap().read_raw::<f64>().unwrap();
        let drawn: Vec<f64> = points.iter().map(|mu| mu.get(&r.name).unwrap()).collect();
        assert_eq!(stored, drawn, "{}", r.name);
        assert!(stored.iter().all(|x| !r.excludes(*x)), "{}: a training point left the box", r.name);
    }
    drop(f);

    // validate without a point: held-out points of the box, accurate and not extrapolated
    let out = flexrom(d, &["validate", "p.toml", "--json", "--no-dense"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    let vs: Vec<serde_json::Value> = serde_json::from_str(&stdout).unwrap();
    assert_eq!(vs.len(), 4);
    for v in &vs {
        let params = v["parameters"].as_object().unwrap();
        assert!(params.contains_key("g") && params.contains_key("push"), "{v}");
        assert!(!points.iter().any(|mu| mu.get("g") == params["g"].as_f64()), "a validation point is a training point");
        assert_eq!(v["extrapolated"], false, "{v}");
        assert!(v["rel_error"].as_f64().unwrap() <= 1e-3, "{v}");
    }
    assert!(!stderr.contains("outside what the basis was trained on"), "{stderr}");

    // a point outside the box names the parameter and the range it left
    let out = flexrom(d, &["online", "p.toml", "--param", "push=3", "--param", "g=1.0", "-o", "o.h5", "--json"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("outside what the basis was trained on: push = 3 (trained over [0.2, 2])"), "{stderr}");
    assert!(stdout.contains("\"extrapolated\":true"), "{stdout}");
    // and the result file says so too, as `validate` does
    let f = flexrom::io::h5_open::open(d.join("o.h5")).unwrap();
    assert_eq!(f.attr("extrapolated").unwrap().read_scalar::<u64>().unwrap(), 1);
    assert_eq!(f.attr("parameter:push").unwrap().read_scalar::<f64>().unwrap(), 3.0);
    drop(f);
    let out = flexrom(d, &["validate", "p.toml", "--param", "push=3", "--param", "g=1.0", "--json", "--no-dense"]);
    let v: serde_json::Value = serde_json::from_str(&text(&out).0).unwrap();
    assert_eq!(v["extrapolated"], true, "{v}");

    // `run` over the box: its sweep at 16 random points of the box, validated, and a report
    // that names points, not load scales
    let out = flexrom(d, &["run", "p.toml", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let summary = std::fs::read_to_string(d.join("r/summary.md")).unwrap();
    assert!(summary.contains("Training box g ∈ [0.8, 1.2], push ∈ [0.2, 2] (log)"), "{summary}");
    assert!(summary.contains("16 random points of the box") && summary.contains("| point | rel_error"), "{summary}");
    let f = flexrom::io::h5_open::open(d.join("r/sweep.h5")).unwrap();
    let swept = f.dataset("points").unwrap().read_2d::<f64>().unwrap();
    assert_eq!(swept.nrows(), 16);
    assert!(swept.rows().into_iter().all(|r| (0.8..=1.2).contains(&r[1]) && (0.2..=2.0).contains(&r[2])), "{swept}");
    let errors = f.dataset("rel_error").unwrap().read_raw::<f64>().unwrap();
    assert!(errors.iter().all(|&e| e <= 1e-3), "{errors:?}");
    drop(f);

    // training in separate jobs: two shards of the six points, joined in the pipeline's
    // order, give the single `train`'s basis (the same snapshot matrix: same POD)
    for k in ["1/2", "2/2"] {
        let out = flexrom(d, &["train", "p.toml", "--snapshots-only", "--shard", k, "-o", &format!("s{}.h5", &k[..1])]);
        assert!(out.status.success(), "{}", text(&out).1);
    }
    let out = flexrom(d, &["train", "p.toml", "--basis", "b2.h5", "--from-snapshots", "s2.h5", "s1.h5", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let read = |file: &str, name: &str| {
        flexrom::io::h5_open::open(d.join(file)).unwrap().dataset(name).unwrap().read_raw::<f64>().unwrap()
    };
    assert_eq!(read("b2.h5", "parameters/push"), read("b.h5", "parameters/push"));
    let (sv, sv2) = (read("b.h5", "basis/singular_values"), read("b2.h5", "basis/singular_values"));
    assert!(sv.iter().zip(&sv2).all(|(a, b)| (a - b).abs() <= 1e-10 * sv[0]), "{sv:?} vs {sv2:?}");
    // one of the two files is not enough, and a box's jobs are shards, not load scales
    let out = flexrom(d, &["train", "p.toml", "--basis", "b3.h5", "--from-snapshots", "s1.h5"]);
    assert!(text(&out).1.contains("no file holds the training point(s) 1 (g = "), "{}", text(&out).1);
    let out = flexrom(d, &["train", "p.toml", "--snapshots-only", "--load-scale", "1.0", "-o", "s3.h5"]);
    assert!(text(&out).1.contains("split them with --shard K/N"), "{}", text(&out).1);
    assert!(!d.join("b3.h5").exists() && !d.join("s3.h5").exists());

    // a pipeline whose box differs from the basis's is refused before anything runs
    std::fs::write(
        d.join("p2.toml"),
        format!("model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n{}{TRAIN}", BOX.replace("0.8, 1.2", "0.7, 1.2")),
    )
    .unwrap();
    let out = flexrom(d, &["online", "p2.toml", "--param", "g=1.0", "-o", "o2.h5"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = text(&out).1;
    assert!(stderr.contains("b.h5: parameters: the basis was trained over g [0.8, 1.2] linear"), "{stderr}");
    assert!(stderr.contains("names g [0.7, 1.2] linear"), "{stderr}");
    assert!(!d.join("o2.h5").exists());

    // a basis whose training points are damaged — a NaN, a parameter one run short — is
    // refused naming the file and the dataset, before anything runs
    type Damage = fn(&hdf5::File);
    let damages: [(&str, Damage, &str); 2] = [
        (
            "nan.h5",
            |f| f.dataset("parameters/push").unwrap().write(&[f64::NAN; 6]).unwrap(),
            "parameters/push: holds NaN",
        ),
        (
            "short.h5",
            |f| {
                let g = f.group("parameters").unwrap();
                let d = g.dataset("g").unwrap();
                let (range, scale): (Vec<f64>, String) = (
                    d.attr("range").unwrap().read_raw().unwrap(),
                    flexrom::io::h5::read_attr_str(&d, "scale").unwrap(),
                );
                g.unlink("g").unwrap();
                let d = g.new_dataset_builder().with_data(&[1.0; 5]).create("g").unwrap();
                d.new_attr::<f64>().shape(2).create("range").unwrap().write(&range).unwrap();
                flexrom::io::h5::attr_str(&d, "scale", &scale).unwrap();
            },
            "parameters/push: has shape (6) where (5) is expected",
        ),
    ];
    for (name, damage, needle) in damages {
        std::fs::copy(d.join("b.h5"), d.join(name)).unwrap();
        damage(&hdf5::File::open_rw(d.join(name)).unwrap());
        let out = flexrom(d, &["online", "p.toml", "--basis", name, "--param", "g=1.0", "-o", "o3.h5"]);
        assert_eq!(out.status.code(), Some(1), "{name}");
        assert!(text(&out).1.contains(&format!("{name}: {needle}")), "{name}: {}", text(&out).1);
        assert!(!d.join("o3.h5").exists());
    }
}

/// Greedy training over the box (no range: `[parameters]` is the range): it converges at
/// the tutorial's tolerance 1e-3 (the double pendulum over g × push: 5 full runs at commit
/// of 2026-11-26, benches/greedy_box.py), its first runs are the box's lower and upper
/// corners and its centre, the basis records the candidates and the runs as points of the
/// box, and at the four held-out random points `validate` checks the error is within the
/// tolerance and the estimate covers it (the coverage the estimate promises on a line).
#[test]
fn greedy_training_over_a_box_converges_and_its_estimate_covers_held_out_points() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup(d, &format!("{BOX}[train]\ngreedy = {{ tolerance = 1e-3, max_runs = 8 }}\n[reduction]\nvariant = \"constraint-preserving\"\n"));
    let out = flexrom(d, &["train", "p.toml"]);
    let stderr = text(&out).1;
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("greedy training over the box g ∈ [0.8, 1.2], push ∈ [0.2, 2] (log)"), "{stderr}");
    // the double pendulum's dt = 0.005 s does not resolve its 75 Hz first bending mode: the
    // one warning expected (src/analysis/resolution.rs); no other
    assert!(!stderr.lines().any(|l| l.contains("warning") && !l.contains("does not resolve")), "{stderr}");

    let f = flexrom::io::h5_open::open(d.join("b.h5")).unwrap();
    let t = f.group("training").unwrap();
    assert_eq!(t.attr("converged").unwrap().read_scalar::<u64>().unwrap(), 1);
    assert!(t.dataset("range").is_err() && t.dataset("candidates").is_err(), "a box has no load range");
    let cands = t.dataset("candidate_points").unwrap();
    assert_eq!(flexrom::io::h5::read_attr_str(&cands, "parameters").unwrap(), "g,push");
    let cands = cands.read_2d::<f64>().unwrap();
    // the box's 4 corners and 4 face centres, and 32 drawn candidates per parameter, inside the box
    assert_eq!(cands.dim(), (4 + 4 + 64, 2));
    assert_eq!(cands.row(3).to_vec(), vec![1.2, 2.0]);
    assert!(cands.rows().into_iter().all(|r| (0.8..=1.2).contains(&r[0]) && (0.2..=2.0).contains(&r[1])));
    let runs = t.dataset("points").unwrap().read_2d::<f64>().unwrap();
    // the first runs: lower corner, centre (a log axis's centre: √(0.2 · 2)), upper corner
    let first = [[0.8, 0.2], [1.0, (0.2f64 * 2.0).sqrt()], [1.2, 2.0]];
    for (row, want) in runs.rows().into_iter().zip(first) {
        assert!((row[0] - want[0]).abs() < 1e-12 && (row[1] - want[1]).abs() < 1e-12, "{row} vs {want:?}");
    }
    // `/parameters` holds the same runs
    let g = f.dataset("parameters/g").unwrap().read_raw::<f64>().unwrap();
    assert_eq!(g, runs.column(0).to_vec());
    // the routes were timed at the box's centre, which `/timing` names
    let t = flexrom::io::basis_file::read_basis(&d.join("b.h5")).unwrap().training.timing.unwrap();
    assert_eq!(t.named.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>(), ["g", "push"]);
    assert!((t.named[0].1 - 1.0).abs() < 1e-12 && (t.named[1].1 - (0.2f64 * 2.0).sqrt()).abs() < 1e-12, "{t:?}");
    drop(f);

    // a sharded sweep merged keeps training's sensitivity at the nearest candidates, as
    // the single sweep does
    let grid = ["--param", "g=0.8:1.2:2", "--param", "push=0.2:2:2:log", "-q"];
    for (k, o) in [("1/2", "q1.h5"), ("2/2", "q2.h5")] {
        let out = flexrom(d, &[&["sweep", "p.toml", "-o", o, "--shard", k][..], &grid].concat());
        assert!(out.status.success(), "{}", text(&out).1);
    }
    assert!(flexrom(d, &[&["sweep", "p.toml", "-o", "q.h5"][..], &grid].concat()).status.success());
    assert!(flexrom(d, &["merge", "q1.h5", "q2.h5", "-o", "qm.h5"]).status.success());
    let near = |f: &str| {
        flexrom::io::h5_open::open(d.join(f)).unwrap().dataset("sensitivity_near").unwrap().read_raw::<f64>().unwrap()
    };
    let single = near("q.h5");
    assert!(single.iter().all(|s| s.is_finite()), "{single:?}");
    assert_eq!(near("qm.h5"), single);
    // a part whose own rows are not its points (a named value changed, λ kept) is refused
    std::fs::copy(d.join("q1.h5"), d.join("q1bad.h5")).unwrap();
    {
        let f = flexrom::io::h5_open::open_rw(d.join("q1bad.h5")).unwrap();
        let pts = f.dataset("points").unwrap();
        let mut a = pts.read_2d::<f64>().unwrap();
        a[[0, 2]] *= 1.5;
        pts.write(&a).unwrap();
    }
    let out = flexrom(d, &["merge", "q1bad.h5", "q2.h5", "-o", "qbad.h5"]);
    let err = text(&out).1;
    assert!(!out.status.success() && !d.join("qbad.h5").exists(), "{err}");
    assert!(err.contains("q1bad.h5: points: are not the points of shard 1/2"), "{err}");

    common::held_out_points_within(d, 1e-3);
}

#[test]
fn a_box_that_does_not_fit_the_model_or_the_training_is_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (body, field, problem) in [
        (
            format!("{}{TRAIN}", BOX.replace("push =", "pushh =")),
            "parameters.pushh",
            "the model has no parameter `pushh` (its parameters: g, push)",
        ),
        (
            format!("{}{TRAIN}", BOX.replace("0.2, 2.0", "0.0, 2.0")),
            "parameters.push",
            "with scale = \"log\" must lie above zero",
        ),
        (format!("{}{TRAIN}", BOX.replace("0.8, 1.2", "1.2, 0.8")), "parameters.g", "lower < upper"),
        (
            format!("{BOX}[train]\nload_scales = [1.0]\n[reduction]\nmodes = {{ count = 4 }}\n"),
            "train",
            "sample it with `points = { count = N }`",
        ),
        (TRAIN.to_string(), "train.points", "the pipeline has no [parameters] table"),
        (
            format!("{BOX}{TRAIN}[validate]\nload_scales = [1.0]\n"),
            "validate.load_scales",
            "use random points of the box",
        ),
        (format!("{}{}", BOX, TRAIN.replace("count = 6", "count = 0")), "train.points.count", "is 0"),
        (
            format!("{BOX}[train]\ngreedy = {{ range = [0.5, 1.5], tolerance = 1e-3, max_runs = 4 }}\n"),
            "train.greedy.range",
            "leave `range` out",
        ),
        (
            "[train]\ngreedy = { range = [0.5, 1.5], tolerance = 1e-3, max_runs = 4, seed = 3 }\n".to_string(),
            "train.greedy.seed",
            "the pipeline has no [parameters] box",
        ),
        ("[train]\ngreedy = { tolerance = 1e-3, max_runs = 4 }\n".to_string(), "train.greedy.range", "is missing"),
        // the model's loads are scaled by g and push, none by λ
        (
            "[train]\ngreedy = { range = [0.5, 1.5], tolerance = 1e-3, max_runs = 4 }\n".to_string(),
            "train.greedy.range",
            "no load of the model is `scaled = true`, so it would change nothing; its parameters are g, push",
        ),
        (
            format!("{}{TRAIN}", BOX.replace("\"log\"", "\"logarithmic\"")),
            "parameters.push",
            "unknown variant `logarithmic`, expected `linear` or `log`",
        ),
    ] {
        setup(d, &body);
        let e = flexrom::pipeline::Pipeline::load(d.join("p.toml")).expect_err(&body).to_string();
        // a problem serde finds while reading also names the line
        let named = e.contains(&format!("p.toml: {field}: ")) || e.contains(&format!("p.toml: {field} (line "));
        assert!(named && e.contains(problem), "{body}\n{e}");
    }
    // a box's settings hash counts the candidates it draws (32 per parameter when not
    // given), so that a basis trained with another count is flagged as stale
    let hash = |candidates: &str| {
        setup(d, &format!("{BOX}[train]\ngreedy = {{ tolerance = 1e-3, max_runs = 4{candidates} }}\n"));
        flexrom::pipeline::Pipeline::load(d.join("p.toml")).unwrap().settings_hash()
    };
    assert_eq!(hash(""), hash(", candidates = 64"));
    assert_ne!(hash(""), hash(", candidates = 33"));
}

#[test]
fn a_sweep_over_a_grid_of_points_runs_each_point_as_online_does_and_resumes_by_point() {
    // the grid's point (g = 1.2, push = 2) swept and run alone by `online` give the same
    // probe trajectory to the bit (a sweep without --continuation runs each point exactly as
    // `online`); the file's /points hold the grid, first axis slowest
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup(d, &format!("{BOX}{TRAIN}"));
    assert!(flexrom(d, &["train", "p.toml", "-q"]).status.success());
    let grid = ["--param", "g=0.8:1.2:3", "--param", "push=0.2:2:2:log"];
    let out = flexrom(d, &[&["sweep", "p.toml", "-o", "s.h5", "--csv"][..], &grid].concat());
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.lines().next().unwrap().ends_with(",parameter:g,parameter:push"), "{stdout}");
    let f = flexrom::io::h5_open::open(d.join("s.h5")).unwrap();
    let points = f.dataset("points").unwrap();
    assert_eq!(flexrom::io::h5::read_attr_str(&points, "parameters").unwrap(), "load_scale,g,push");
    let p = points.read_2d::<f64>().unwrap();
    let expected =
        [[1.0, 0.8, 0.2], [1.0, 0.8, 2.0], [1.0, 1.0, 0.2], [1.0, 1.0, 2.0], [1.0, 1.2, 0.2], [1.0, 1.2, 2.0]];
    assert_eq!(p.shape(), [6, 3]);
    for (row, e) in p.rows().into_iter().zip(expected) {
        for (a, b) in row.iter().zip(e) {
            assert!((a - b).abs() <= 1e-12 * b, "{p}");
        }
    }
    let swept = f.dataset("probes/tip").unwrap().read::<f64, ndarray::Ix3>().unwrap();
    drop(f);
    let (g, push) = (p[[5, 1]].to_string(), p[[5, 2]].to_string());
    let out = flexrom(
        d,
        &["online", "p.toml", "--param", &format!("g={g}"), "--param", &format!("push={push}"), "-o", "o.h5"],
    );
    assert!(out.status.success(), "{}", text(&out).1);
    let alone =
        flexrom::io::h5_open::open(d.join("o.h5")).unwrap().dataset("probes/tip").unwrap().read_2d::<f64>().unwrap();
    assert!(swept.index_axis(ndarray::Axis(0), 5) == alone, "the swept point differs from `online` at it");

    // the same grid in two shards, merged: the single sweep's points and probes, to the bit
    for k in ["1/2", "2/2"] {
        let part = format!("part_{}.h5", &k[..1]);
        let out = flexrom(d, &[&["sweep", "p.toml", "-o", &part, "--shard", k, "-q"][..], &grid].concat());
        assert!(out.status.success(), "{}", text(&out).1);
    }
    let out = flexrom(d, &["merge", "part_2.h5", "part_1.h5", "-o", "m.h5"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let m = flexrom::io::h5_open::open(d.join("m.h5")).unwrap();
    assert_eq!(m.dataset("points").unwrap().read_2d::<f64>().unwrap(), p);
    assert!(m.dataset("probes/tip").unwrap().read::<f64, ndarray::Ix3>().unwrap() == swept, "merged ≠ single sweep");
    drop(m);
    // a part of another list of points is refused, naming the hash
    let other = ["--param", "g=0.8:1.2:3", "--param", "push=0.2:2:3:log"];
    let out = flexrom(d, &[&["sweep", "p.toml", "-o", "other_1.h5", "--shard", "1/2", "-q"][..], &other].concat());
    assert!(out.status.success(), "{}", text(&out).1);
    let out = flexrom(d, &["merge", "part_2.h5", "other_1.h5", "-o", "m2.h5"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out).1.contains("shard/load_list_hash"), "{}", text(&out).1);

    // --resume over the same grid takes every point from the file; a grid with a new axis
    // value runs only the new points
    let out = flexrom(d, &[&["sweep", "p.toml", "-o", "s.h5", "--resume", "-v"][..], &grid].concat());
    assert!(text(&out).1.contains("6 of 6 points already finished"), "{}", text(&out).1);
    let more = ["--param", "g=0.8:1.2:3", "--param", "push=0.2:2:3:log"];
    let out = flexrom(d, &[&["sweep", "p.toml", "-o", "s.h5", "--resume", "-v"][..], &more].concat());
    assert!(text(&out).1.contains("6 of 9 points already finished"), "{}", text(&out).1);

    // a point outside the box is flagged, and the warning counts such points
    let out = flexrom(d, &["sweep", "p.toml", "-o", "s2.h5", "--param", "g=1.0", "--param", "push=1:3:3", "--json"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    let rows: Vec<serde_json::Value> = serde_json::from_str(&stdout).unwrap();
    let flags: Vec<bool> = rows.iter().map(|r| r["extrapolated"].as_bool().unwrap()).collect();
    assert_eq!(flags, [false, false, true], "push = 1, 2 inside [0.2, 2], 3 outside");
    assert!(
        stderr.contains("1 of 3 points lie outside what the basis was trained on (the first: push = 3"),
        "{stderr}"
    );

    // a points file, and a box pipeline without points to sweep
    std::fs::write(d.join("pts.csv"), "g,push\n0.9,0.5\n1.1,1.5\n").unwrap();
    let out = flexrom(d, &["sweep", "p.toml", "-o", "s3.h5", "--points", "pts.csv", "--json"]);
    let rows: Vec<serde_json::Value> = serde_json::from_str(&text(&out).0).unwrap();
    assert_eq!(rows.iter().map(|r| r["parameter:push"].as_f64().unwrap()).collect::<Vec<_>>(), [0.5, 1.5]);
    let out = flexrom(d, &["sweep", "p.toml", "-o", "s4.h5"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out).1.contains("sweeps the points of `--param NAME=A:B:N`"));
    assert!(!d.join("s4.h5").exists());
}

/// A parameter the model does not have, or one that means nothing to it: a misspelt CSV
/// column is refused naming the CSV's header; a load scale on a model none of whose loads
/// is `scaled = true` (here: gravity by `g`, the push by `push`) runs, but warns that it
/// changes nothing and names the parameters the model has.
#[test]
fn parameters_the_model_does_not_have_are_refused_or_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup(d, &format!("{BOX}{TRAIN}"));
    std::fs::write(d.join("pts.csv"), "g,puhs\n1.0,0.5\n").unwrap();
    let out = flexrom(d, &["sweep", "p.toml", "--points", "pts.csv", "-o", "s.h5"]);
    let err = text(&out).1;
    assert!(!out.status.success() && !d.join("s.h5").exists(), "{err}");
    assert!(
        err.contains("pts.csv: header: column `puhs`: the model has no parameter `puhs` (its parameters: g, push); did you mean `push`?"),
        "{err}"
    );
    for args in [
        &["simulate", "m.toml", "--load-scale", "1.2", "--t-end", "0.01", "-o", "x.h5"][..],
        &["simulate", "m.toml", "--param", "load_scale=0.8", "--t-end", "0.01", "-o", "y.h5"],
    ] {
        let out = flexrom(d, args);
        let err = text(&out).1;
        assert!(out.status.success(), "{err}");
        assert!(
            err.contains("warning: m.toml: the load scale")
                && err.contains("so it would change nothing; its parameters are g, push"),
            "{err}"
        );
    }
}
