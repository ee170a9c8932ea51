//! The error measures a tolerance can be on, what `train -v` shows of greedy's search, and
//! `--estimate METHOD` (docs/error-estimate.md, "Two measures of the error";
//! docs/greedy-training.md; docs/cli.md).
//!
//! Checks, with where each expected value comes from:
//! - `greedy_on_the_displacement_measure`: the thesis pendulum coarsened to 20 elements and
//!   t_end = 0.4 s (as tests/greedy.rs, so the loop runs in seconds) trained greedily with
//!   `measure = "displacement"`: the basis file's `/training` attribute `measure` says
//!   "displacement" and reads back as such; the held-out check's true error, recorded in the
//!   training's measure, is ≤ T (the loop's stopping rule); `train -v` prints one line per
//!   rung of the mode search with its modes, elements and worst score, and the rung kept;
//!   without -v none of them (the rungs are detail); the summary line and the train table
//!   count the runs in the basis and the held-out check apart, and they add up to the full
//!   runs of `/training`. Then `online`, `validate`, `sweep --validate` and `run` with
//!   `--estimate enriched` report that method (result file attribute, JSON, summary.md);
//!   `validate` reports displacement_error > rel_error (‖X_full‖ holds the undeformed
//!   geometry, which ‖X_full − X₀‖ does not: the same distance over a smaller norm) and the
//!   tip's error over its travel; the sweep file holds `/displacement_error` and
//!   `/error_estimate_displacement`; summary.md has the section on the errors against the
//!   motion and names the held-out run.
//! - `a_tolerance_below_the_loads_own_change_is_held`: the shipped clamped beam made ten
//!   times stiffer (E = 70 GPa: its tip deflects by about 3 % of its length, a response
//!   proportional to the load) trained greedily over [0.5, 2] with the displacement measure
//!   at T = 1e-4. A 0.1 % change of the load moves such a response by δ = 1e-3 in this
//!   measure (`/training/sensitivity` reads it), ten times T and no amplification: the loop
//!   must hold the estimate to T itself (`rom::trust::amplifying`), and the energy ladder
//!   must go far enough to meet it (the beam needs ε ≈ 1e-12, 20 modes). It converges, and
//!   `validate` at three loads that are neither training nor candidate loads finds
//!   displacement errors ≤ T with the estimate above each. (With the sensitivity relaxing
//!   every score above T, it "converged" at 13 modes with a held-out error of 3.0e-4; with
//!   the ladder ending at 1e-10 it spent its 8 runs at 15 modes and 2e-4.)
//! - `a_range_from_rest_trains_on_the_displacement_measure`: the same coarse pendulum
//!   trained over [0, 1] (at λ = 0 it does not move) with the displacement measure at
//!   T = 3e-3 converges (measured: 3 training runs and the held-out check); at λ = 0 the
//!   displacement estimate is undefined like the error it estimates — NaN in the result file,
//!   "displacement none" on the terminal, no "above the tolerance" warning and `--strict`
//!   passing — not a ratio of two runs' rounding (before
//!   2026-11-27 it read 2.1 there, so greedy spent its 6 runs and stopped above T at λ = 0).
//! - `displacement_error_at_rest_is_none_in_words`: at λ = 0 the pendulum does not move, so
//!   displacement_error is 0/0: "none" with its reason on `validate`'s text line, and in
//!   JSON null with `displacement_error_note` (null where the error is a number).
//! - `bad_measures_and_methods_are_refused`: a greedy `measure` that is not one of the two
//!   fails `train` naming the pipeline file and `train.greedy.measure`; `[online]
//!   tolerance_measure` without `[online] tolerance` and with a bad value name
//!   `online.tolerance_measure`; `--estimate bogus` on each of the four commands exits 2 with
//!   clap's message listing the three values, and `sweep --estimate X --no-estimate` is a
//!   usage error.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn flexrom(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flexrom")).args(args).env("HDF5_USE_FILE_LOCKING", "FALSE").output().unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn pendulum(elements: usize, t_end: f64) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/pendulum.toml"))
        .unwrap()
        .replace("elements = 50", &format!("elements = {elements}"))
        .replace("t_end = 1.1", &format!("t_end = {t_end}"))
}

fn setup(dir: &Path, body: &str) -> PathBuf {
    std::fs::write(dir.join("model.toml"), pendulum(20, 0.4)).unwrap();
    let p = dir.join("pipe.toml");
    std::fs::write(&p, format!("model = \"model.toml\"\nbasis = \"basis.h5\"\nreport = \"report\"\n{body}")).unwrap();
    p
}

const DISPLACEMENT: &str = r#"
[train]
greedy = { range = [0.5, 1.5], tolerance = 3e-3, max_runs = 8, measure = "displacement" }
[online]
load_scales = [0.8, 1.2]
[validate]
load_scales = [0.9]
"#;

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", text(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(&o.stdout)))
}

#[test]
fn greedy_on_the_displacement_measure() {
    let dir = tempfile::tempdir().unwrap();
    let pipe = setup(dir.path(), DISPLACEMENT);
    let p = pipe.to_str().unwrap();
    let basis = dir.path().join("basis.h5");

    let o = flexrom(&["-v", "train", p, "--json"]);
    let err = text(&o.stderr);
    let row = json(&o);
    let row = row.as_array().map_or(&row, |a| &a[0]);
    let f = flexrom::io::h5_open::open(&basis).unwrap();
    let g = f.group("training").unwrap();
    let measure: hdf5::types::VarLenUnicode = g.attr("measure").unwrap().read_scalar().unwrap();
    assert_eq!(measure.as_str(), "displacement");
    assert_eq!(
        flexrom::io::estimator_file::training_measure(&f, &basis).unwrap(),
        flexrom::pipeline::config::ErrorMeasure::Displacement
    );
    let full_runs: u64 = g.attr("full_runs").unwrap().read_scalar().unwrap();
    let true_error = g.dataset("true_error").unwrap().read_1d::<f64>().unwrap();
    let converged: u64 = g.attr("converged").unwrap().read_scalar().unwrap();
    assert_eq!(converged, 1, "{err}");
    assert!(*true_error.last().unwrap() <= 3e-3, "held-out displacement error {true_error:?}");
    let in_basis = g.dataset("load_scales").unwrap().read_1d::<f64>().unwrap().len() as u64;
    // converged: the last full run was the held-out check, not in the basis
    assert_eq!(row["n_training_runs"].as_u64(), Some(in_basis), "{row}");
    assert_eq!(row["n_held_out"].as_u64(), Some(1), "{row}");
    assert_eq!(in_basis + 1, full_runs);
    assert!(err.contains(&format!("from {in_basis} training runs + 1 held-out check")), "{err}");
    // -v: every rung, with what it chose and why it was kept or not
    let rungs: Vec<&str> = err.lines().filter(|l| l.contains(", rung ε = ")).collect();
    assert!(rungs.len() >= 2, "{err}");
    for r in &rungs {
        assert!(r.contains(" modes, ") && r.contains("elements") && r.contains("worst score "), "{r}");
        assert!(r.contains("within the tolerance 3e-3") || r.contains("above the tolerance 3e-3"), "{r}");
    }
    assert!(err.lines().any(|l| l.contains("iteration 1 keeps rung ε = ")), "{err}");
    assert!(!err.contains("FLEXROM_GREEDY_DEBUG"));
    // without -v the rungs are not shown
    let quiet = flexrom(&["train", p]);
    assert!(quiet.status.success(), "{}", text(&quiet.stderr));
    assert!(!text(&quiet.stderr).contains(", rung ε = "), "{}", text(&quiet.stderr));

    // online with another method than the default
    let out = dir.path().join("r.h5");
    let o = flexrom(&["online", p, "--load-scale", "1.1", "-o", out.to_str().unwrap(), "--estimate", "enriched"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r = flexrom::io::h5_open::open(&out).unwrap();
    let attr = |name: &str| -> String {
        let s: hdf5::types::VarLenUnicode = r.attr(name).unwrap().read_scalar().unwrap();
        s.as_str().to_string()
    };
    assert_eq!(attr("error_estimate_method"), "enriched");
    assert_eq!(attr("tolerance_measure"), "displacement");
    let est: f64 = r.attr("error_estimate_displacement").unwrap().read_scalar().unwrap();
    assert!(est.is_finite() && est > 0.0, "{est}");

    // validate: both measures, the tip over its travel, the method asked for
    let v = json(&flexrom(&["validate", p, "--load-scale", "1.1", "--json", "--no-dense", "--estimate", "corrected"]));
    let num = |k: &str| v[k].as_f64().unwrap_or_else(|| panic!("{k}: {v}"));
    assert_eq!(v["error_estimate_method"].as_str(), Some("corrected"), "{v}");
    assert!(num("displacement_error") > num("rel_error"), "{v}");
    assert!(num("error_estimate_displacement") > num("error_estimate"), "{v}");
    let tip = &v["probe_errors_over_travel"][0];
    assert_eq!(tip["probe"].as_str(), Some("tip"));
    let (e, t) = (tip["max_error"].as_f64().unwrap(), tip["travel"].as_f64().unwrap());
    assert!(t > 0.1, "the pendulum's tip falls: {tip}");
    assert!((tip["error_over_travel"].as_f64().unwrap() - e / t).abs() <= 1e-15, "{tip}");

    // sweep --validate: the dataset and the estimate
    let sw = dir.path().join("s.h5");
    let o = flexrom(&[
        "sweep",
        p,
        "--validate",
        "--load-scales",
        "0.8:1.2:2",
        "-o",
        sw.to_str().unwrap(),
        "--estimate",
        "defects",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let s = flexrom::io::h5_open::open(&sw).unwrap();
    for name in ["displacement_error", "error_estimate_displacement"] {
        let d = s.dataset(name).unwrap().read_1d::<f64>().unwrap();
        assert!(d.len() == 2 && d.iter().all(|x| x.is_finite() && *x > 0.0), "{name}: {d:?}");
    }
    let rel = s.dataset("rel_error").unwrap().read_1d::<f64>().unwrap();
    let disp = s.dataset("displacement_error").unwrap().read_1d::<f64>().unwrap();
    assert!(disp.iter().zip(&rel).all(|(d, r)| d > r), "{disp:?} vs {rel:?}");
    // rel_error by fifth beside the estimate's (each over the run up to the fifth's end):
    // measured everywhere, the last column rel_error itself (to round-off: summed apart)
    let by = s.dataset("rel_error_by_time").unwrap().read_2d::<f64>().unwrap();
    assert_eq!(by.dim(), (2, 5));
    for (row, r) in by.rows().into_iter().zip(&rel) {
        assert!(row.iter().all(|x| x.is_finite() && *x > 0.0) && (row[4] - r).abs() <= 1e-12 * r, "{row} vs {r}");
    }

    // run (training again: the basis above is current and would be reused, and a reused
    // basis's summary names no held-out run): the method, the motion section, the held-out
    // run named
    let o = flexrom(&["run", p, "--no-dense", "--estimate", "enriched", "--retrain"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let md = std::fs::read_to_string(dir.path().join("report/summary.md")).unwrap();
    assert!(md.contains("(enriched method"), "{md}");
    assert!(
        md.contains("## Errors against the motion") && md.contains("The tolerance is on displacement_error"),
        "{md}"
    );
    assert!(md.contains(&format!("({in_basis} training runs) + 1 held-out check at λ = ")), "{md}");
}

#[test]
fn a_range_from_rest_trains_on_the_displacement_measure() {
    let dir = tempfile::tempdir().unwrap();
    let pipe = setup(
        dir.path(),
        "[train]\ngreedy = { range = [0.0, 1.0], tolerance = 3e-3, max_runs = 6, measure = \"displacement\" }\n",
    );
    let p = pipe.to_str().unwrap();
    let o = flexrom(&["train", p]);
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    let f = flexrom::io::h5_open::open(dir.path().join("basis.h5")).unwrap();
    let converged: u64 = f.group("training").unwrap().attr("converged").unwrap().read_scalar().unwrap();
    assert_eq!(converged, 1, "{err}");

    let out = dir.path().join("rest.h5");
    let o = flexrom(&["-v", "online", p, "--load-scale", "0", "-o", out.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("displacement none ("), "{err}");
    // nothing to hold to the tolerance there: no warning, and --strict passes
    assert!(!err.contains("above the tolerance"), "{err}");
    let o = flexrom(&["online", p, "--load-scale", "0", "-o", out.to_str().unwrap(), "--strict"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r = flexrom::io::h5_open::open(&out).unwrap();
    let est: f64 = r.attr("error_estimate_displacement").unwrap().read_scalar().unwrap();
    let rel: f64 = r.attr("error_estimate").unwrap().read_scalar().unwrap();
    assert!(est.is_nan(), "{est}");
    assert!(rel.is_finite() && rel < 1e-9, "the relative estimate at rest is rounding: {rel}");
}

/// At λ = 0 the pendulum (its one load, gravity, scaled by λ) does not move: displacement_error
/// is ‖X_rom − X_full‖ / ‖X_full − X₀‖ = 0/0 to the Newton tolerance. `validate` says so in
/// words — "none (the full run does not move …)" on its text line, null in JSON with
/// `displacement_error_note` giving the words (null where the error is a number, at λ = 1)
/// — and never a ratio of two runs' rounding.
#[test]
fn displacement_error_at_rest_is_none_in_words() {
    let dir = tempfile::tempdir().unwrap();
    let pipe = setup(
        dir.path(),
        "[train]\nload_scales = [0.5, 1.0, 1.5]\nsnapshots = \"reference\"\n[reduction]\nvariant = \"constraint-preserving\"\nmodes = { count = 8 }\n",
    );
    let p = pipe.to_str().unwrap();
    let o = flexrom(&["train", "-q", p]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let o = flexrom(&["validate", p, "--load-scale", "0", "--no-dense"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let line = "displacement_error: none (the full run does not move beyond the Newton tolerance";
    assert!(text(&o.stdout).contains(line), "{}", text(&o.stdout));
    let at_rest = json(&flexrom(&["validate", p, "--load-scale", "0", "--no-dense", "--json"]));
    assert!(at_rest["displacement_error"].is_null(), "{at_rest}");
    let note = at_rest["displacement_error_note"].as_str().unwrap_or_default();
    assert!(note.starts_with("none (the full run does not move"), "{at_rest}");
    // the rel_error there is the runs' rounding over the undeformed geometry: a number
    assert!(at_rest["rel_error"].as_f64().is_some_and(|e| e < 1e-9), "{at_rest}");
    let moving = json(&flexrom(&["validate", p, "--load-scale", "1", "--no-dense", "--json"]));
    assert!(moving["displacement_error"].as_f64().is_some_and(|e| e > 0.0), "{moving}");
    assert!(moving["displacement_error_note"].is_null(), "{moving}");
    // the joint's reactions at rest are round-off: no error relative to their range (it
    // read 0.58–0.83 "of its range" over ~1e-9 N); swinging, the pin's force has one
    let reactions = |v: &serde_json::Value, quantity: &str| -> Vec<serde_json::Value> {
        let all = v["reaction_errors"].as_array().cloned().unwrap_or_default();
        all.into_iter().filter(|r| r["quantity"] == quantity).map(|r| r["relative"].clone()).collect()
    };
    let (rest, swing) = (reactions(&at_rest, "force"), reactions(&moving, "force"));
    assert!(!rest.is_empty() && rest.iter().all(|r| r.is_null()), "{at_rest}");
    assert!(!swing.is_empty() && swing.iter().all(|r| r.as_f64().is_some()), "{moving}");
}

#[test]
fn a_tolerance_below_the_loads_own_change_is_held() {
    let dir = tempfile::tempdir().unwrap();
    let beam = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/clamped_beam.toml"))
        .unwrap()
        .replace("youngs_modulus = 7.0e9", "youngs_modulus = 7.0e10");
    assert!(beam.contains("7.0e10"));
    std::fs::write(dir.path().join("model.toml"), beam).unwrap();
    let pipe = dir.path().join("pipe.toml");
    std::fs::write(
        &pipe,
        r#"model = "model.toml"
basis = "basis.h5"
report = "report"
[train]
greedy = { range = [0.5, 2.0], tolerance = 1e-4, max_runs = 8, measure = "displacement" }
[validate]
load_scales = [0.6, 1.3, 1.9]
"#,
    )
    .unwrap();
    let p = pipe.to_str().unwrap();
    let o = flexrom(&["train", p]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let f = flexrom::io::h5_open::open(dir.path().join("basis.h5")).unwrap();
    let g = f.group("training").unwrap();
    let converged: u64 = g.attr("converged").unwrap().read_scalar().unwrap();
    assert_eq!(converged, 1, "{}", text(&o.stderr));
    // the sensitivity of a response proportional to the load, in the displacement measure: δ
    let s = g.dataset("sensitivity").unwrap().read_2d::<f64>().unwrap();
    let last = s.row(s.nrows() - 1);
    assert!(last.iter().all(|&x| (0.9e-3..1.1e-3).contains(&x)), "{last}");
    let v = json(&flexrom(&["validate", p, "--json", "--no-dense"]));
    let points = v.as_array().expect("three loads");
    assert_eq!(points.len(), 3);
    for x in points {
        let (e, est) = (x["displacement_error"].as_f64().unwrap(), x["error_estimate_displacement"].as_f64().unwrap());
        assert!(e <= 1e-4, "displacement error above T: {x}");
        assert!(est >= e, "estimate below the error: {x}");
    }
}

#[test]
fn bad_measures_and_methods_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let refused = |body: &str, field: &str| {
        let pipe = setup(dir.path(), body);
        let o = flexrom(&["train", pipe.to_str().unwrap()]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{body}: {err}");
        assert!(err.contains("pipe.toml") && err.contains(field) && !err.contains("panicked"), "{body}: {err}");
        err
    };
    let err = refused(
        "[train]\ngreedy = { range = [0.5, 1.5], tolerance = 1e-3, max_runs = 4, measure = \"absolute\" }\n",
        "train.greedy.measure",
    );
    assert!(err.contains("relative") && err.contains("displacement"), "the values it may take: {err}");
    let fixed = "[train]\nload_scales = [1.0]\n[reduction]\nmodes = { count = 4 }\n";
    refused(&format!("{fixed}[online]\ntolerance_measure = \"displacement\"\n"), "online.tolerance_measure");
    refused(&format!("{fixed}[online]\ntolerance = 1e-3\ntolerance_measure = \"tip\"\n"), "online.tolerance_measure");

    // --estimate: clap's message with the values, exit 2, before any work
    let pipe = setup(dir.path(), fixed);
    let p = pipe.to_str().unwrap();
    for args in [
        vec!["online", p, "--load-scale", "1", "-o", "x.h5", "--estimate", "bogus"],
        vec!["validate", p, "--estimate", "bogus"],
        vec!["sweep", p, "-o", "x.h5", "--estimate", "bogus"],
        vec!["run", p, "--estimate", "bogus"],
    ] {
        let o = flexrom(&args);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(["corrected", "enriched", "defects"].iter().all(|m| err.contains(m)), "{args:?}: {err}");
    }
    let o = flexrom(&["sweep", p, "-o", "x.h5", "--estimate", "defects", "--no-estimate"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(!dir.path().join("x.h5").exists());
}
