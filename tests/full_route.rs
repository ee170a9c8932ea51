//! The exact route where reduction does not pay (docs/basis-and-sweep.md, "Full or
//! reduced"), through the `flexrom` command.
//!
//! Checks, and where each expectation comes from:
//! - `a_full_sweep_is_simulate_at_every_load`: `sweep --full` needs no basis file; its
//!   probes are, bit for bit, those of `flexrom simulate` at each load of the file's
//!   `/load_scales` (the same full model and integrator: module docs of `workflows::sweep`),
//!   and so are the Newton iterations and factorizations; the file says `route = "full"`,
//!   holds no `/reduced_q`, `/rom_seconds` or basis attributes, a positive `/full_seconds`
//!   and NaN estimates (docs/file-formats.md); its CSV has the full sweep's columns (docs/cli.md);
//!   `--full` with `--validate`, `--basis`, `--continuation`, `--no-estimate` or `--strict`
//!   is a usage error (exit 2: nothing to validate, no basis, no estimate);
//! - `train_stores_the_times_of_both_routes`: the basis file's `/timing` holds positive,
//!   finite medians of the full and reduced time loops and of the estimate, in seconds
//!   (`units` "s", scalars), timed at 0.9, the lower middle of the training loads
//!   [0.9, 1.1] (`cost::route::timing_load`), `threads` 1, 1 to 7 rounds (the budget
//!   of `cost::timing`), and `estimate_method` the basis's default;
//! - `the_notice_says_once_when_the_full_model_is_faster`: with `/timing` edited to say the
//!   reduced run takes 10× the full one, `online` and `sweep` print exactly one warning line
//!   naming the basis, both times and `sweep --full`; with the reduced run at 1/10 and its
//!   estimate at 1/10 of the full one, none; with 0.5 and 0.6 (the estimate tips it), only
//!   the runs that make an estimate say it (`sweep --no-estimate` does not); a basis without
//!   `/timing` (files written before it) runs as before without a word, and a damaged one
//!   (a negative time) is refused naming `timing/reduced_seconds`;
//! - `run_states_the_faster_route`: `run`'s summary.md has a "Full or reduced" section whose
//!   times are the medians of its validation.json (`full_seconds`, `rom_seconds`,
//!   `estimate_seconds`), and the one-line notice on stderr exactly when those say the full
//!   model is as fast or faster.
//!
//! Resume, shards and merge of full sweeps: tests/shard.rs.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn flexrom() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_flexrom"));
    // a child must not inherit a lock on a file this test has open
    c.env("HDF5_USE_FILE_LOCKING", "FALSE");
    c
}

fn run(args: &[&str]) -> (Output, String) {
    let o = flexrom().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_ne!(o.status.code(), Some(101), "panic: {err}");
    assert!(o.status.code().is_some(), "killed by a signal: {err}");
    (o, err)
}

fn ok(args: &[&str]) -> (Output, String) {
    let (o, err) = run(args);
    assert!(o.status.success(), "{args:?}: {err}");
    (o, err)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The warning lines of a command's stderr.
fn warnings(err: &str) -> Vec<&str> {
    err.lines().filter(|l| l.starts_with("warning:")).collect()
}

/// The one line about the faster route (docs/basis-and-sweep.md).
fn notices(err: &str) -> Vec<&str> {
    warnings(err).into_iter().filter(|l| l.contains("not faster than the full one")).collect()
}

/// A coarse pendulum (8 elements, 0.1 s) and a pipeline trained at [0.9, 1.1] with 4 modes
/// (an estimator comes with every fixed-load basis), trained when `train`.
fn pendulum(dir: &Path, train: bool) -> PathBuf {
    let model = std::fs::read_to_string(repo("data/models/pendulum.toml"))
        .unwrap()
        .replace("elements = 50", "elements = 8")
        .replace("t_end = 1.1", "t_end = 0.1");
    assert!(model.contains("elements = 8") && model.contains("t_end = 0.1"));
    std::fs::write(dir.join("model.toml"), model).unwrap();
    let p = dir.join("pipe.toml");
    std::fs::write(
        &p,
        "model = \"model.toml\"\nbasis = \"basis.h5\"\nreport = \"report\"\n[train]\nload_scales = [0.9, 1.1]\n[reduction]\nvariant = \"galerkin\"\nmodes = { count = 4 }\n[online]\nload_scales = \"0.9:1.1:3\"\n[validate]\nload_scales = [0.95, 1.05]\n",
    )
    .unwrap();
    if train {
        ok(&["train", s(&p)]);
    }
    p
}

fn bits(a: &[f64]) -> Vec<u64> {
    a.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn a_full_sweep_is_simulate_at_every_load() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();
    // the four-bar (three bodies, pins, three probes, the constant-velocity predictor) to 0.3 s
    let model =
        std::fs::read_to_string(repo("data/models/fourbar.toml")).unwrap().replace("t_end = 1.1", "t_end = 0.3");
    assert!(model.contains("t_end = 0.3"));
    let m = d.join("fourbar.toml");
    std::fs::write(&m, model).unwrap();
    let p = d.join("pipe.toml");
    std::fs::write(&p, "model = \"fourbar.toml\"\nbasis = \"never_trained.h5\"\n[train]\nload_scales = [1.0]\n[reduction]\nmodes = { count = 10 }\n")
        .unwrap();
    let out = d.join("full.h5");
    let (o, _) = ok(&["sweep", s(&p), "--full", "--load-scales", "0.8:1.2:3", "-o", s(&out), "--csv"]);
    assert!(!d.join("never_trained.h5").exists());
    let csv = String::from_utf8(o.stdout).unwrap();
    assert_eq!(csv.lines().next(), Some("load_scale,status,message,full_seconds,newton_iterations,step_cuts"));
    assert_eq!(csv.lines().count(), 4, "{csv}");

    let f = flexrom::io::h5_open::open(&out).unwrap();
    let route = f.attr("route").unwrap().read_scalar::<hdf5::types::VarLenUnicode>().unwrap();
    assert_eq!(route.as_str(), "full");
    for absent in ["reduced_q", "rom_seconds"] {
        assert!(!f.link_exists(absent), "/{absent} in a full sweep");
    }
    for absent in ["basis", "basis_content_hash", "variant", "n_modes"] {
        assert!(f.attr(absent).is_err(), "attribute {absent} in a full sweep");
    }
    let read = |name: &str| f.dataset(name).unwrap().read_raw::<f64>().unwrap();
    assert!(read("error_estimate").iter().all(|e| e.is_nan()), "an exact run has no estimate");
    assert!(read("full_seconds").iter().all(|t| *t > 0.0 && t.is_finite()));
    assert_eq!(f.dataset("status").unwrap().read_raw::<u8>().unwrap(), vec![0, 0, 0]);
    let loads = read("load_scales");
    let newton = f.dataset("newton_iterations").unwrap().read_raw::<u64>().unwrap();
    let factorizations = f.dataset("factorizations").unwrap().read_raw::<u64>().unwrap();
    let names = f.group("probes").unwrap().member_names().unwrap();
    assert_eq!(names.len(), 3, "{names:?}");
    for (k, x) in loads.iter().enumerate() {
        // `{x}` is the shortest text that reads back as the same f64
        let r = d.join(format!("sim{k}.h5"));
        ok(&["simulate", s(&m), "--load-scale", &format!("{x}"), "-o", s(&r)]);
        let g = flexrom::io::h5_open::open(&r).unwrap();
        for name in &names {
            let swept = f.dataset(&format!("probes/{name}")).unwrap().read::<f64, ndarray::Ix3>().unwrap();
            let alone = g.dataset(&format!("probes/{name}")).unwrap().read_2d::<f64>().unwrap();
            let swept = swept.index_axis(ndarray::Axis(0), k).to_owned();
            assert_eq!(bits(swept.as_slice().unwrap()), bits(alone.as_slice().unwrap()), "{name} at {x}");
        }
        let attr = |name: &str| g.attr(name).unwrap().read_scalar::<u64>().unwrap();
        assert_eq!((newton[k], factorizations[k]), (attr("newton_iterations"), attr("factorizations")), "{x}");
    }

    // the same loads given as a list, in another order: the same runs, in the list's order
    let listed = d.join("listed.h5");
    ok(&["sweep", s(&p), "--full", "--load-scales", &format!("{},{}", loads[2], loads[0]), "-o", s(&listed)]);
    let g = flexrom::io::h5_open::open(&listed).unwrap();
    assert_eq!(bits(&g.dataset("load_scales").unwrap().read_raw::<f64>().unwrap()), bits(&[loads[2], loads[0]]));
    let probe = |file: &hdf5::File, k: usize| {
        let p = file.dataset(&format!("probes/{}", names[0])).unwrap().read::<f64, ndarray::Ix3>().unwrap();
        bits(p.index_axis(ndarray::Axis(0), k).to_owned().as_slice().unwrap())
    };
    assert_eq!((probe(&g, 0), probe(&g, 1)), (probe(&f, 2), probe(&f, 0)));

    // nothing to validate, no basis, no estimate: refused before any run
    for extra in [&["--validate"][..], &["--basis", "b.h5"], &["--continuation"], &["--no-estimate"], &["--strict"]] {
        let mut args = vec!["sweep", s(&p), "--full", "-o", s(&out)];
        args.extend_from_slice(extra);
        let (o, err) = run(&args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains("--full") && err.contains(extra[0]), "{err}");
    }
}

/// The `/timing` group of a basis file: (full, reduced, estimate) seconds.
fn timing(basis: &Path) -> [f64; 3] {
    let f = flexrom::io::h5_open::open(basis).unwrap();
    ["full_seconds", "reduced_seconds", "estimate_seconds"]
        .map(|n| f.dataset(&format!("timing/{n}")).unwrap().read_scalar::<f64>().unwrap())
}

/// Overwrites the basis file's stored times (what `train` measured on some machine).
fn set_timing(basis: &Path, [full, reduced, estimate]: [f64; 3]) {
    let f = flexrom::io::h5_open::open_rw(basis).unwrap();
    for (n, v) in [("full_seconds", full), ("reduced_seconds", reduced), ("estimate_seconds", estimate)] {
        f.dataset(&format!("timing/{n}")).unwrap().write_scalar(&v).unwrap();
    }
}

#[test]
fn train_stores_the_times_of_both_routes() {
    let d = tempfile::tempdir().unwrap();
    pendulum(d.path(), true);
    let basis = d.path().join("basis.h5");
    let times = timing(&basis);
    assert!(times.iter().all(|t| *t > 0.0 && t.is_finite()), "{times:?}");
    let f = flexrom::io::h5_open::open(&basis).unwrap();
    let g = f.group("timing").unwrap();
    assert_eq!(g.attr("load_scale").unwrap().read_scalar::<f64>().unwrap(), 0.9);
    assert_eq!(g.attr("threads").unwrap().read_scalar::<u64>().unwrap(), 1);
    let runs = g.attr("runs").unwrap().read_scalar::<u64>().unwrap();
    assert!((1..=7).contains(&runs), "{runs}");
    let text = |loc: &hdf5::Location, n: &str| {
        loc.attr(n).unwrap().read_scalar::<hdf5::types::VarLenUnicode>().unwrap().as_str().to_string()
    };
    let method = text(&g, "estimate_method");
    let default = text(&f.group("estimator").unwrap(), "default_method");
    assert_eq!(method, default);
    for n in ["full_seconds", "reduced_seconds", "estimate_seconds"] {
        let ds = g.dataset(n).unwrap();
        assert_eq!((text(&ds, "units").as_str(), ds.ndim()), ("s", 0), "{n}");
    }
}

#[test]
fn the_notice_says_once_when_the_full_model_is_faster() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();
    let p = pendulum(d, true);
    let basis = d.join("basis.h5");
    let (on, sw) = (d.join("on.h5"), d.join("sw.h5"));
    let online = |extra: &[&str]| {
        let mut args = vec!["online", s(&p), "--load-scale", "1.0", "-o", s(&on)];
        args.extend_from_slice(extra);
        ok(&args).1
    };
    let sweep = |extra: &[&str]| {
        let mut args = vec!["sweep", s(&p), "-o", s(&sw)];
        args.extend_from_slice(extra);
        ok(&args).1
    };

    set_timing(&basis, [1e-3, 1e-2, 1e-3]);
    for err in [online(&[]), sweep(&[]), sweep(&["--no-estimate"])] {
        let n = notices(&err);
        assert_eq!(n.len(), 1, "{err}");
        assert_eq!(warnings(&err).len(), 1, "the notice is the only warning: {err}");
        for want in [s(&basis), "10.000 ms reduced", "1.000 ms full", "sweep --full", "load scale 0.9"] {
            assert!(n[0].contains(want), "{want:?} not in {}", n[0]);
        }
    }
    assert!(notices(&online(&[]))[0].contains("+ 1.000 ms estimate"));

    set_timing(&basis, [1e-2, 1e-3, 1e-3]);
    for err in [online(&[]), sweep(&[]), sweep(&["--no-estimate"])] {
        assert!(notices(&err).is_empty(), "{err}");
    }

    // 5 ms + 6 ms with the estimate is not faster than 10 ms; 5 ms without it is
    set_timing(&basis, [1e-2, 5e-3, 6e-3]);
    assert_eq!(notices(&online(&[])).len(), 1);
    assert_eq!(notices(&sweep(&[])).len(), 1);
    assert!(notices(&sweep(&["--no-estimate"])).is_empty());

    // a damaged timing is refused, naming it
    set_timing(&basis, [1e-2, -1.0, 6e-3]);
    let (o, err) = run(&["online", s(&p), "--load-scale", "1.0", "-o", s(&d.join("on2.h5"))]);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("timing/reduced_seconds") && err.contains(s(&basis)), "{err}");

    // a basis file from before /timing: runs as before, without a word
    flexrom::io::h5_open::open_rw(&basis).unwrap().unlink("timing").unwrap();
    for err in [online(&[]), sweep(&[])] {
        assert!(warnings(&err).is_empty(), "{err}");
    }
}

/// The median of `x` (the mean of the middle two of an even count), as `run` takes it.
fn median(mut x: Vec<f64>) -> f64 {
    x.sort_by(f64::total_cmp);
    let n = x.len();
    if n % 2 == 1 {
        x[n / 2]
    } else {
        0.5 * (x[n / 2 - 1] + x[n / 2])
    }
}

#[test]
fn run_states_the_faster_route() {
    let d = tempfile::tempdir().unwrap();
    let p = pendulum(d.path(), false);
    let (_, err) = ok(&["run", s(&p), "--no-dense"]);
    let report = d.path().join("report");
    let summary = std::fs::read_to_string(report.join("summary.md")).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("validation.json")).unwrap()).unwrap();
    let rows = json.as_array().unwrap();
    assert_eq!(rows.len(), 2, "[validate] load_scales = [0.95, 1.05]");
    let mid = |key: &str| median(rows.iter().map(|r| r[key].as_f64().unwrap()).collect());
    let (full, reduced, estimate) = (mid("full_seconds"), mid("rom_seconds"), mid("estimate_seconds"));
    let figures = format!(
        "{:.3} ms reduced + {:.3} ms estimate against {:.3} ms full",
        1e3 * reduced,
        1e3 * estimate,
        1e3 * full
    );
    let at = summary.find("## Full or reduced").expect("a Full or reduced section");
    let section = &summary[at..summary[at + 3..].find("\n## ").map_or(summary.len(), |e| at + 3 + e)];
    assert!(section.contains(&figures), "{figures:?} not in {section}");
    let full_faster = reduced + estimate >= full;
    let verdict = if full_faster { "the full model is" } else { "the reduced model with its estimate is" };
    assert!(section.contains(&format!("At this size {verdict}")), "{section}");
    assert_eq!(notices(&err).len(), full_faster as usize, "{err}");
    // the basis `run` trained holds the timing too
    assert!(timing(&d.path().join("basis.h5")).iter().all(|t| *t > 0.0));
}
