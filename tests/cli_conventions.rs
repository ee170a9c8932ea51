//! The command-line conventions of docs/cli.md, as a user meets them:
//!
//! * `--csv` and `--json` on every command that prints results (`simulate`, `train`,
//!   `online`, `validate`, `sweep`, `merge`, `demo`) give stdout that the `csv` crate and
//!   `serde_json` read back, with the documented columns; the expected values are not
//!   numbers from a reference but the same run's own figures: the rows count the steps
//!   (the pendulum's dt = 0.005 s, so `--t-end 0.02` is 4 steps + t = 0), the load scales
//!   asked for (0.9:1.1:3 → 0.9, 1.0, 1.1), and the JSON and CSV of one command agree.
//! * `-q` leaves stderr empty on success, `-v` adds the Newton statistics line.
//! * `validate --no-dense` leaves `full_dense_seconds` null without a word; the automatic
//!   skip (here forced by a memory bound, 1 MiB, between the banded run's 813.1 KiB and the
//!   dense run's 1.44 MiB: `Model::check_full_run_memory`, q and q̇ kept) prints exactly one line saying
//!   so and how to force it; below both bounds the dense run is timed.
//! * `validate` says whether the full and reduced runs took the same time steps:
//!   `full_step_cuts`, `rom_step_cuts` and `steps_differ_from` (null, an empty CSV cell,
//!   when neither run halved a step, as on this pendulum).
//! * every command's `--help` has examples and the exit-code table.
//! * every command creates the folders of its outputs.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn flexrom(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flexrom")).args(args).env("HDF5_USE_FILE_LOCKING", "FALSE").output().unwrap()
}

fn ok(args: &[&str]) -> Output {
    let o = flexrom(args);
    assert!(o.status.success(), "flexrom {args:?}: {}", String::from_utf8_lossy(&o.stderr));
    o
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A pipeline in `dir` on the shipped pendulum, trained at the one load 1.0 with raw
/// snapshots (one full run, seconds), its basis and report inside `dir`.
fn pipeline(dir: &Path) -> String {
    let p = dir.join("p.toml");
    std::fs::write(
        &p,
        format!(
            "model = \"{}\"\nbasis = \"{}\"\nreport = \"{}\"\n\n[train]\nload_scales = [1.0]\nsnapshots = \"raw\"\n\n[reduction]\nvariant = \"galerkin\"\nmodes = {{ ratio = 0.1 }}\n",
            root().join("data/models/pendulum.toml").display(),
            dir.join("bases/deep/b.h5").display(),
            dir.join("reports/r").display()
        ),
    )
    .unwrap();
    p.to_str().unwrap().to_string()
}

fn csv_rows(o: &Output) -> (Vec<String>, Vec<csv::StringRecord>) {
    let mut r = csv::Reader::from_reader(o.stdout.as_slice());
    let head = r.headers().unwrap().iter().map(String::from).collect();
    (head, r.records().map(|x| x.unwrap()).collect())
}

fn json(o: &Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&o.stdout)))
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn every_result_prints_as_csv_and_json() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let p = pipeline(dir);
    let model = root().join("data/models/pendulum.toml");

    // simulate: one row per instant
    let out = dir.join("sim/deep/p.h5");
    let o = ok(&["simulate", s(&model), "-o", s(&out), "--t-end", "0.02", "--csv"]);
    let (head, rows) = csv_rows(&o);
    let energy =
        ["kinetic", "strain", "strain_axial", "strain_bending", "gravity", "springs", "external_work", "drive_work"];
    let expected: Vec<String> = ["t", "tip_x", "tip_y"]
        .iter()
        .map(|s| s.to_string())
        .chain(energy.iter().map(|e| format!("energy_{e}")))
        .chain(["Fx", "Fy", "M"].iter().map(|c| format!("joint 0 (ground_pin beam node 0) on beam node 0: {c}")))
        .collect();
    assert_eq!(head, expected);
    assert_eq!(rows.len(), 5, "t = 0 and 4 steps of 0.005 s");
    let o = ok(&["simulate", s(&model), "-o", s(&out), "--t-end", "0.02", "--json"]);
    let j = json(&o);
    assert_eq!(j.as_array().unwrap().len(), 5);
    assert_eq!(j[4]["t"].as_f64().unwrap(), rows[4][0].parse::<f64>().unwrap());
    assert_eq!(j[4]["tip_y"].as_f64().unwrap(), rows[4][2].parse::<f64>().unwrap(), "JSON and CSV agree");
    assert!(out.exists(), "simulate created sim/deep/");

    // train: one record; the basis's folder bases/deep/ does not exist yet
    let j = json(&ok(&["train", &p, "--json"]));
    assert_eq!(j["n_runs"], 1);
    assert!(j["n_pod_modes"].as_u64().unwrap() > 0);
    assert!(dir.join("bases/deep/b.h5").exists());
    let (head, rows) = csv_rows(&ok(&["train", &p, "--csv"]));
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0][head.iter().position(|h| h == "n_pod_modes").unwrap()], j["n_pod_modes"].to_string());

    // online: one record, at λ = 1 where no load is given (as `simulate`)
    let on = dir.join("online/deep/o.h5");
    let j = json(&ok(&["online", &p, "-o", s(&on), "--json"]));
    assert_eq!(j["load_scale"].as_f64(), Some(1.0));
    assert_eq!(j["steps"].as_u64(), Some(220), "t_end 1.1 s / dt 0.005 s");
    assert!(j["error_estimate"].as_f64().unwrap() > 0.0);
    // online --csv: the time series, as simulate --csv prints it (one shared writer): every
    // column of the reduced run is one of the full run's, under the same name, at the same
    // instants
    let (head, rows) = csv_rows(&ok(&["online", &p, "--load-scale", "1.0", "-o", s(&on), "--csv"]));
    assert_eq!(head[..3], ["t", "tip_x", "tip_y"]);
    assert_eq!(rows.len(), 221, "t = 0 and 220 steps of 0.005 s");
    let (full_head, full_rows) = csv_rows(&ok(&["simulate", s(&model), "--load-scale", "1.0", "--csv"]));
    for h in &head {
        assert!(full_head.contains(h), "online's column {h} is none of simulate's: {full_head:?}");
    }
    assert_eq!(rows[220][0], full_rows[220][0], "the same last instant");
    let (tip, full_tip): (f64, f64) = (rows[220][2].parse().unwrap(), full_rows[220][2].parse().unwrap());
    // the reduced tip within the basis's tolerance of the full one (1e-2 of the 1.2 m length
    // is far above the pendulum pipeline's rel_error; a different series would miss it)
    assert!((tip - full_tip).abs() < 1.2e-2, "reduced tip_y {tip} vs full {full_tip}");

    // validate: JSON object (arrays kept), CSV with one row and the arrays spread out
    let j = json(&ok(&["validate", &p, "--load-scale", "1.0", "--json", "--no-dense"]));
    assert_eq!(j["rel_error_by_time"].as_array().unwrap().len(), 5);
    let (head, rows) = csv_rows(&ok(&["validate", &p, "--load-scale", "1.0", "--csv", "--no-dense"]));
    assert_eq!(rows.len(), 1);
    let col = |n: &str| head.iter().position(|h| h == n).unwrap_or_else(|| panic!("no column {n}: {head:?}"));
    assert_eq!(rows[0][col("n_modes")], j["n_modes"].to_string());
    assert_eq!(&rows[0][col("full_dense_seconds")], "", "not measured: empty cell");
    let rel: f64 = rows[0][col("rel_error")].parse().unwrap();
    assert!((rel - j["rel_error"].as_f64().unwrap()).abs() <= 1e-12, "the same deterministic run");
    let _ = col("rel_error_by_time_5");
    // the pendulum's steps converge without halving in both runs (its Newton needs at most
    // 3 iterations a step, docs/benchmarks.md): the same time grid, no differing step
    assert_eq!((j["full_step_cuts"].as_u64(), j["rom_step_cuts"].as_u64()), (Some(0), Some(0)));
    assert!(j["steps_differ_from"].is_null(), "{}", j["steps_differ_from"]);
    assert_eq!(&rows[0][col("steps_differ_from")], "", "null: an empty cell");

    // sweep and merge: one row per load scale
    let sw = dir.join("sweep/deep/s.h5");
    let j = json(&ok(&["sweep", &p, "--load-scales", "0.9:1.1:3", "-o", s(&sw), "--json", "--no-estimate"]));
    let scales: Vec<f64> = j.as_array().unwrap().iter().map(|r| r["load_scale"].as_f64().unwrap()).collect();
    assert_eq!(scales, [0.9, 1.0, 1.1]);
    assert!(j.as_array().unwrap().iter().all(|r| r["status"] == 0 && r["error_estimate"].is_null()));
    let part = dir.join("parts/deep/p1.h5");
    let (head, rows) = csv_rows(&ok(&[
        "sweep",
        &p,
        "--load-scales",
        "0.9:1.1:3",
        "--shard",
        "1/1",
        "-o",
        s(&part),
        "--csv",
        "--no-estimate",
    ]));
    assert_eq!(head[0], "load_scale");
    assert_eq!(rows.len(), 3);
    let merged = dir.join("merged/deep/m.h5");
    let (_, rows) = csv_rows(&ok(&["merge", s(&part), "-o", s(&merged), "--csv"]));
    assert_eq!(rows.iter().map(|r| r[0].parse::<f64>().unwrap()).collect::<Vec<_>>(), [0.9, 1.0, 1.1]);
    assert!(merged.exists());

    // demo: model, t, probe, x, y at five times
    let (head, rows) = csv_rows(&ok(&["demo", s(&model), "--csv"]));
    assert_eq!(head, ["model", "t", "probe", "x", "y"]);
    assert_eq!(rows.len(), 5);
    assert_eq!(json(&ok(&["demo", s(&model), "--json"])).as_array().unwrap().len(), 5);

    // --csv and --json together are a usage error (exit 2)
    assert_eq!(flexrom(&["demo", s(&model), "--csv", "--json"]).status.code(), Some(2));

    // negative load scales are values, not flags: a sweep over reversed loads
    let neg = dir.join("sweep/neg.h5");
    let j = json(&ok(&["sweep", &p, "--load-scales", "-1.1:-0.9:3", "-o", s(&neg), "--json", "--no-estimate"]));
    let scales: Vec<f64> = j.as_array().unwrap().iter().map(|r| r["load_scale"].as_f64().unwrap()).collect();
    assert_eq!(scales, [-1.1, -1.0, -0.9]);
}

/// A command line clap cannot parse gets clap's whole message on stderr, exit 2: the
/// missing arguments named, the usage line, a "did you mean" tip for a misspelt flag.
#[test]
fn parse_errors_show_the_whole_clap_message() {
    let model = root().join("data/models/pendulum.toml");
    let pipeline = root().join("pipelines/pendulum.toml");
    let cases: [(&[&str], &[&str]); 5] = [
        (
            &["simulate", s(&model)],
            &["required arguments were not provided", "--output <OUTPUT>", "Usage: flexrom simulate"],
        ),
        (
            &["online", s(&pipeline)],
            &["required arguments were not provided", "--output <OUTPUT>", "Usage: flexrom online"],
        ),
        (
            &["sweep", s(&pipeline), "--loadscales", "1:2:3"],
            &["'--loadscales'", "tip: a similar argument exists: '--load-scales'", "Usage: flexrom sweep"],
        ),
        (&["simulate", s(&model), "-o", "x.h5", "--threads", "-1"], &["invalid value '-1' for '--threads <N>'"]),
        // a malformed list of load scales is a malformed argument too (a list `X,Y,Z` is one)
        (
            &["sweep", s(&pipeline), "--load-scales", "0.5:1.0", "-o", "x.h5"],
            &["invalid value '0.5:1.0' for '--load-scales <A:B:N>'", "is not of the form A:B:N"],
        ),
    ];
    for (args, needles) in cases {
        let o = flexrom(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.starts_with("error: ") && err.contains("For more information, try '--help'."), "{args:?}: {err}");
        for n in needles {
            assert!(err.contains(n), "{args:?}: `{n}` not in:\n{err}");
        }
    }
}

/// Negative numbers are values wherever a number is expected. The shipped pendulum starts on
/// the x axis under gravity alone (its only scaled load), so λ = −1 (gravity up) is the
/// mirror image of λ = 1 about that axis: the same tip x, the opposite tip y (to round-off;
/// mirroring flips the sign of every y term). A negative time step reaches the model's own
/// check (exit 1, naming the option), not the parser.
#[test]
fn negative_numbers_are_values() {
    let model = root().join("data/models/pendulum.toml");
    let run = |x: &str| {
        let (_, rows) = csv_rows(&ok(&["simulate", s(&model), "--t-end", "0.05", "--load-scale", x, "--csv"]));
        let last = rows.last().unwrap().iter().map(|c| c.parse::<f64>().unwrap()).collect::<Vec<_>>();
        (last[1], last[2])
    };
    let ((x1, y1), (xm, ym)) = (run("1"), run("-1"));
    assert!(y1 < -1e-3, "the tip falls at λ = 1: {y1}");
    assert!((xm - x1).abs() <= 1e-12 && (ym + y1).abs() <= 1e-12, "({x1}, {y1}) against ({xm}, {ym})");
    let o = flexrom(&["simulate", s(&model), "--dt", "-0.005", "--csv"]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("dt"), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `simulate --csv` (or `--json`) without `-o` prints the probes on stdout and writes no file;
/// the CSV is the one a run with `-o` prints.
#[test]
fn simulate_prints_without_a_result_file() {
    let d = tempfile::tempdir().unwrap();
    let model = root().join("data/models/pendulum.toml");
    let run = |extra: &[&str]| {
        let mut args = vec!["simulate", s(&model), "--t-end", "0.02"];
        args.extend(extra);
        let o = Command::new(env!("CARGO_BIN_EXE_flexrom")).args(&args).current_dir(d.path()).output().unwrap();
        assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
        o.stdout
    };
    let csv = run(&["--csv"]);
    let json = run(&["--json"]);
    assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0, "no file written");
    assert_eq!(csv, run(&["--csv", "-o", "r.h5"]), "the same rows as with a result file");
    assert_eq!(serde_json::from_slice::<serde_json::Value>(&json).unwrap().as_array().unwrap().len(), 5);
}

/// `validate` without `--load-scale` validates at the pipeline's `[validate] load_scales`:
/// one record per load, in the list's order, each the record `validate --load-scale X` gives
/// (the runs are deterministic: the same rel_error and estimate to the bit); `--json` prints
/// them as one array, as the report's validation.json, `--csv` one row each. The pipeline's
/// `[online]` sets `estimate` alone, without `load_scales`.
#[test]
fn validate_defaults_to_the_pipelines_validate_loads() {
    let d = tempfile::tempdir().unwrap();
    let p = pipeline(d.path());
    let text = std::fs::read_to_string(&p).unwrap()
        + "\n[online]\nestimate = \"corrected\"\n\n[validate]\nload_scales = [1.1, 0.9]\n";
    std::fs::write(&p, text).unwrap();
    ok(&["-q", "train", &p]);
    let all = json(&ok(&["validate", &p, "--json", "--no-dense"]));
    let all = all.as_array().expect("an array, one object per load");
    assert_eq!(all.iter().map(|v| v["load_scale"].as_f64().unwrap()).collect::<Vec<_>>(), [1.1, 0.9]);
    for v in all {
        let x = v["load_scale"].to_string();
        let one = json(&ok(&["validate", &p, "--load-scale", &x, "--json", "--no-dense"]));
        assert!(one.is_object(), "--load-scale: one object");
        for key in ["rel_error", "error_estimate", "max_probe_error", "n_modes"] {
            assert_eq!(v[key], one[key], "{key} at {x}");
        }
    }
    let (head, rows) = csv_rows(&ok(&["validate", &p, "--csv", "--no-dense"]));
    assert_eq!(head[0], "load_scale");
    assert_eq!(rows.iter().map(|r| r[0].to_string()).collect::<Vec<_>>(), ["1.1", "0.9"]);
    // the text form: one block per load
    let text = String::from_utf8(ok(&["validate", &p, "--no-dense"]).stdout).unwrap();
    assert!(text.contains("load scale 1.1:") && text.contains("load scale 0.9:"), "{text}");
}

#[test]
fn train_snapshots_only_creates_its_folder() {
    let d = tempfile::tempdir().unwrap();
    let p = pipeline(d.path());
    let out = d.path().join("snaps/a/b/s.h5");
    ok(&["train", &p, "--snapshots-only", "--load-scale", "1.0", "-o", s(&out)]);
    assert!(out.exists());
}

#[test]
fn quiet_and_verbose() {
    let d = tempfile::tempdir().unwrap();
    let model = root().join("data/models/pendulum.toml");
    let out = d.path().join("p.h5");
    let args = ["simulate", s(&model), "-o", s(&out), "--t-end", "0.02"];
    let normal = String::from_utf8(ok(&args).stderr).unwrap();
    assert!(normal.contains("4 steps"), "{normal}");
    assert!(!normal.contains("Newton:"), "{normal}");
    let quiet = ok(&[&["-q"], &args[..]].concat());
    assert!(quiet.stderr.is_empty(), "-q: {}", String::from_utf8_lossy(&quiet.stderr));
    let verbose = String::from_utf8(ok(&[&args[..], &["-v"]].concat()).stderr).unwrap();
    assert!(verbose.contains("4 steps") && verbose.contains("Newton: 3.00 iterations per step"), "{verbose}");
    assert!(verbose.contains("wall time"), "{verbose}");
    // errors still reach stderr under -q
    let bad = flexrom(&["-q", "simulate", s(&d.path().join("missing.toml")), "-o", s(&out)]);
    assert_eq!(bad.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("missing.toml"));
    assert_eq!(flexrom(&["-q", "-v", "demo"]).status.code(), Some(2), "-q and -v exclude each other");
}

#[test]
fn dense_comparison_flags_and_auto_skip() {
    let d = tempfile::tempdir().unwrap();
    let p = pipeline(d.path());
    ok(&["-q", "train", &p]);
    let skip_lines =
        |o: &Output| String::from_utf8_lossy(&o.stderr).lines().filter(|l| l.contains("skipping the dense-LU")).count();

    let o = ok(&["validate", &p, "--load-scale", "1.0", "--json", "--no-dense"]);
    assert!(json(&o)["full_dense_seconds"].is_null());
    assert_eq!(skip_lines(&o), 0, "--no-dense skips silently");

    let o = ok(&["validate", &p, "--load-scale", "1.0", "--json", "--max-memory", "1M"]);
    assert!(json(&o)["full_dense_seconds"].is_null());
    assert!(json(&o)["speedup_vs_dense"].is_null());
    assert_eq!(skip_lines(&o), 1, "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--dense forces it"));

    // forced over the memory bound: the bound's error, exit 1
    let o = flexrom(&["validate", &p, "--load-scale", "1.0", "--dense", "--max-memory", "1M"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("dense 206 × 206 LU"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );

    let o = ok(&["validate", &p, "--load-scale", "1.0", "--json"]);
    assert!(json(&o)["full_dense_seconds"].as_f64().unwrap() > 0.0, "small model: timed by default");
    assert_eq!(skip_lines(&o), 0);
}

#[test]
fn every_help_has_examples_and_exit_codes() {
    let top = String::from_utf8(ok(&["--help"]).stdout).unwrap();
    assert!(top.contains("Exit codes:") && top.contains("Examples:"), "{top}");
    for cmd in ["simulate", "statics", "modes", "train", "online", "validate", "sweep", "merge", "run", "demo"] {
        let h = String::from_utf8(ok(&[cmd, "--help"]).stdout).unwrap();
        assert!(h.contains("Examples:\n  flexrom ") && h.contains(&format!("flexrom {cmd} ")), "{cmd}: {h}");
        for code in ["  0 ", "  1 ", "  2 ", "  3 ", "  4 ", "129/130/143"] {
            assert!(h.contains(code), "{cmd} --help lacks exit code {code}");
        }
        assert!(h.contains("--quiet") && h.contains("--verbose") && h.contains("--threads"), "{cmd}");
    }
}
