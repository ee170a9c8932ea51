//! Greedy training over a load range (src/training/greedy.rs).
//!
//! Checks, with where each expected number comes from:
//! - `greedy_pendulum_meets_its_tolerance`: the thesis pendulum (data/models/pendulum.toml),
//!   coarsened to 20 elements and t_end = 0.4 s so the test runs in seconds, trained greedily
//!   over [0.5, 1.5] to T = 1e-3 (the shipped pendulum's tolerance) with max_runs = 8 and no
//!   `[reduction]` at all: the loop must converge in ≤ 4 full runs (as the shipped one does,
//!   the held-out check run included); every candidate's final estimate ≤ T (the loop's
//!   stopping rule); the TRUE rel_error of the written basis, from `validate` at three loads
//!   that are neither training loads nor candidates (0.57, 1.03, 1.41), ≤ T (what the
//!   tolerance promises a user); the held-out check run's true error, recorded per
//!   iteration, ≤ T.
//! - the same run writes `/training` (range, tolerance, chosen loads, worst estimate per
//!   iteration, candidates, estimates, attributes) with the values the loop reported, read
//!   back through the hdf5 crate, and by h5py when python3 has it.
//! - `bad_greedy_tables_are_refused`: each malformed `[train]` (both or neither of
//!   load_scales/greedy, A ≥ B, a range of one value, T ≤ 0 or NaN, K = 0, N = 1, an unknown
//!   key, load_scales without reduction.modes) fails `flexrom train` with a non-zero exit, no
//!   panic, and a message naming the pipeline file and the field (`train.greedy.range`, …).
//! - `a_basis_no_held_out_run_checked_says_so`: the same pendulum with max_runs = 3 (the
//!   three first runs) converges on its estimates alone, and training warns that no held-out
//!   full run checked the basis.
//! - `greedy_defaults_follow_the_model`: without `[reduction]`, the four-bar (pins between
//!   bodies, three bodies) gets the constraint-preserving variant and one POD per body, the
//!   one-body pendulum (a ground pin only) galerkin and one POD (SPEC §3).

use flexrom::pipeline::Pipeline;
use flexrom::reduction::Variant;
use flexrom::rom::Rom;
use flexrom::solver::parameters::Parameters;
use flexrom::training::train::train_and_write;
use flexrom::workflows::validate::validate;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

fn flexrom() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flexrom"))
}

fn pendulum_text(elements: usize, t_end: f64) -> String {
    std::fs::read_to_string(repo("data/models/pendulum.toml"))
        .unwrap()
        .replace("elements = 50", &format!("elements = {elements}"))
        .replace("t_end = 1.1", &format!("t_end = {t_end}"))
}

fn setup(dir: &Path, model: &str, body: &str) -> PathBuf {
    std::fs::write(dir.join("model.toml"), model).unwrap();
    let p = dir.join("pipe.toml");
    std::fs::write(&p, format!("model = \"model.toml\"\nbasis = \"basis.h5\"\nreport = \"report\"\n{body}")).unwrap();
    p
}

const GREEDY_PENDULUM: &str = r#"
[train]
greedy = { range = [0.5, 1.5], tolerance = 1e-3, max_runs = 8 }
"#;

#[test]
fn greedy_pendulum_meets_its_tolerance() {
    let dir = tempfile::tempdir().unwrap();
    let p = Pipeline::load(setup(dir.path(), &pendulum_text(20, 0.4), GREEDY_PENDULUM)).unwrap();
    let s = train_and_write(&p, &p.basis_path).unwrap();
    let g = s.greedy.as_ref().expect("greedy record");
    let t = 1e-3;
    assert!(g.converged, "not converged: {g:?}");
    assert!(g.full_runs <= 4, "{} full runs", g.full_runs);
    let last = g.iterations.last().unwrap();
    assert!(last.estimates.iter().all(|&e| e <= t), "final estimates {:?}", last.estimates);
    assert!(last.true_error <= t, "held-out check {}", last.true_error);
    assert_eq!(g.candidates.len(), 33);
    // the basis as written, at loads that are neither training loads nor candidates
    let stored = flexrom::workflows::online::load_basis(&p, &p.basis_path).unwrap();
    for x in [0.57, 1.03, 1.41] {
        assert!(g.load_scales().iter().chain(&g.candidate_loads()).all(|&l| (l - x).abs() > 1e-3));
        let (v, _, _) =
            validate(&Rom::of(&p.model, &stored.basis).unwrap(), &Parameters::load_scale(x), false).unwrap();
        assert!(v.rel_error <= t, "λ = {x}: rel_error {:.3e} > {t}", v.rel_error);
    }

    // /training as the loop reported it
    let f = flexrom::io::h5_open::open(&p.basis_path).unwrap();
    let tr = f.group("training").unwrap();
    let v1 = |n: &str| tr.dataset(n).unwrap().read_raw::<f64>().unwrap();
    assert_eq!(v1("range"), vec![0.5, 1.5]);
    assert_eq!(v1("tolerance"), vec![t]);
    assert_eq!(v1("load_scales"), g.load_scales());
    assert_eq!(v1("load_scales").len() + 1, g.full_runs, "the held-out check run is not a training load");
    assert_eq!(v1("candidates"), g.candidate_loads());
    assert_eq!(v1("worst_estimate"), g.iterations.iter().map(|i| i.worst_estimate).collect::<Vec<_>>());
    assert_eq!(tr.dataset("estimates").unwrap().shape(), vec![g.iterations.len(), 33]);
    assert_eq!(tr.attr("iterations").unwrap().read_scalar::<u64>().unwrap() as usize, g.iterations.len());
    assert_eq!(tr.attr("converged").unwrap().read_scalar::<u64>().unwrap(), 1);
    // the snapshots are those of the chosen loads only
    let sl = f.dataset("snapshot_load_scale").unwrap().read_raw::<f64>().unwrap();
    assert!(sl.iter().all(|x| g.load_scales().contains(x)));

    let has_h5py =
        Command::new("python3").args(["-c", "import h5py, numpy"]).status().map(|s| s.success()).unwrap_or(false);
    if has_h5py {
        let script = r#"
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1], "r")
t = f["training"]
assert list(t["range"][:]) == [0.5, 1.5]
assert float(t["tolerance"][()]) == 1e-3
assert len(t["worst_estimate"][:]) == int(t.attrs["iterations"])
assert t["estimates"].shape == (int(t.attrs["iterations"]), 33)
print("ok")
"#;
        let o = Command::new("python3").args(["-c", script, p.basis_path.to_str().unwrap()]).output().unwrap();
        assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    } else {
        eprintln!("h5py check skipped: python3 with h5py and numpy is not installed");
    }
}

#[test]
fn bad_greedy_tables_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = pendulum_text(6, 0.1);
    let cases: Vec<(&str, Vec<&str>)> = vec![
        ("[train]\nload_scales = [1.0]\ngreedy = { range = [0.5, 1.5], tolerance = 1e-3, max_runs = 4 }\n[reduction]\nmodes = { count = 4 }", vec!["train", "both", "exactly one"]),
        ("[train]\nsnapshots = \"reference\"", vec!["train", "load_scales", "greedy"]),
        ("[train]\ngreedy = { range = [1.5, 0.5], tolerance = 1e-3, max_runs = 4 }", vec!["train.greedy.range", "less than"]),
        ("[train]\ngreedy = { range = [1.0, 1.0], tolerance = 1e-3, max_runs = 4 }", vec!["train.greedy.range", "less than"]),
        ("[train]\ngreedy = { range = [1.0], tolerance = 1e-3, max_runs = 4 }", vec!["train.greedy.range", "1 entries"]),
        ("[train]\ngreedy = { range = [0.5, 1.5], tolerance = 0.0, max_runs = 4 }", vec!["train.greedy.tolerance", "positive"]),
        ("[train]\ngreedy = { range = [0.5, 1.5], tolerance = nan, max_runs = 4 }", vec!["train.greedy.tolerance", "positive"]),
        ("[train]\ngreedy = { range = [0.5, 1.5], tolerance = 1e-3, max_runs = 0 }", vec!["train.greedy.max_runs", "at least one"]),
        ("[train]\ngreedy = { range = [0.5, 1.5], tolerance = 1e-3, max_runs = 4, candidates = 1 }", vec!["train.greedy.candidates", "at least 2"]),
        ("[train]\ngreedy = { range = [0.5, 1.5], tolerance = 1e-3, max_runs = 4, tol = 1 }", vec!["pipe.toml", "tol"]),
        ("[train]\ngreedy = { range = [0.5, 1.5], tolerance = 1e-3 }", vec!["pipe.toml", "max_runs"]),
        ("[train]\nload_scales = [1.0]", vec!["reduction.modes", "missing"]),
    ];
    for (body, needles) in cases {
        let pipe = setup(d, &model, body);
        let o = flexrom().args(["train", pipe.to_str().unwrap()]).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{body}: should fail");
        assert!(!err.contains("panicked"), "{err}");
        for n in needles {
            assert!(err.contains(n), "{body}: `{n}` not in: {err}");
        }
        assert!(!d.join("basis.h5").exists(), "nothing written");
    }
}
/// With no full run left to hold out (max_runs = 3, the three first runs), a basis that meets
/// T by its estimates is kept, and training says that no held-out run checked it. The
/// pendulum of `greedy_pendulum_meets_its_tolerance` converges at its first iteration with
/// those three runs (there the held-out run then confirms it).
#[test]
fn a_basis_no_held_out_run_checked_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let body = "[train]\ngreedy = { range = [0.5, 1.5], tolerance = 1e-3, max_runs = 3 }\n";
    let p = Pipeline::load(setup(dir.path(), &pendulum_text(20, 0.4), body)).unwrap();
    let s = train_and_write(&p, &p.basis_path).unwrap();
    let g = s.greedy.as_ref().expect("greedy record");
    assert!(g.converged && g.full_runs == 3, "{g:?}");
    assert!(g.iterations.iter().all(|i| i.run_candidate.is_none()), "no held-out run: {g:?}");
    let w: Vec<&String> = s.warnings.iter().filter(|w| w.contains("no held-out full run checked")).collect();
    assert_eq!(w.len(), 1, "{:?}", s.warnings);
    assert!(w[0].contains("max_runs = 3") && w[0].contains("validate"), "{}", w[0]);
}

#[test]
fn greedy_defaults_follow_the_model() {
    let dir = tempfile::tempdir().unwrap();
    let body = "[train]\ngreedy = { range = [0.7, 1.2], tolerance = 1e-3, max_runs = 4 }\n";
    let fourbar =
        Pipeline::load(setup(dir.path(), &std::fs::read_to_string(repo("data/models/fourbar.toml")).unwrap(), body))
            .unwrap();
    assert_eq!(fourbar.variant(), Variant::ConstraintPreserving);
    assert_eq!(fourbar.blocks(), Some(flexrom::pipeline::config::Blocks::Bodies));
    let pendulum = Pipeline::load(setup(dir.path(), &pendulum_text(6, 0.1), body)).unwrap();
    assert_eq!(pendulum.variant(), Variant::Galerkin);
    assert_eq!(pendulum.blocks(), None);
}
