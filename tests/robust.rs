//! Resource bounds refused before allocating, errors that say
//! where (TOML entry lines, dependent joints, stage and load scale), blow-up detection, and
//! a closed or full standard output.
//!
//! Where the expected figures come from:
//! - memory of a full pendulum run (src/limits.rs): n_t = 221 instants (1.1 s / 0.005 s + 1)
//!   × (2 × 204 coordinates and velocities + 2 multipliers + 2 probe columns + 1 time) × 8 B
//!   = 730 184 B, plus 50 elements × 2048 B = 102 400 B: 832 584 B = 813.1 KiB, so an 800 KiB
//!   bound refuses it and a 900 KiB bound admits it;
//! - steps: 1.1 s / 1e-9 s = 1.1e9 steps > the default 10⁷; 1e12 s / 0.005 s = 2e14;
//! - a 10⁶-element body is over the default 2·10⁵ elements; with the element bound raised
//!   its run needs 221 × (4 000 004 + 2 + 2 + 1) × 8 B ≈ 6.6 GiB, over a 1 GiB bound;
//! - blow-up: the pendulum with E = 1e3 Pa instead of 0.7e9 (EA = 1.8 N for a 12 kg beam)
//!   cannot carry its own weight: it stretches past 50 % within 0.1 s (seen: |ε̄| = 0.52
//!   at t = 0.06 s); at load scale 1e4 (98 100 m/s²) the stiff beam stretches past it too
//!   (seen: 2.25 at 0.06 s), and its Newton solves need step halvings, so a budget of 0
//!   cuts is exceeded (seen: the first halving at t = 0.04 s).
//!   Lines of TOML entries are found by searching the test's own text.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

fn flexrom() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flexrom"))
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

fn pendulum() -> String {
    std::fs::read_to_string(root().join("data/models/pendulum.toml")).unwrap()
}

/// Runs `flexrom args…`; returns (exit code, stderr).
fn run(args: &[&str]) -> (i32, String) {
    let o = flexrom().args(args).output().unwrap();
    (o.status.code().expect("exited, no signal"), String::from_utf8_lossy(&o.stderr).into_owned())
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn runs_that_would_not_fit_are_refused_quickly_with_the_figure_and_the_option() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.h5");
    let (o, m) = (out.to_str().unwrap(), root().join("data/models/pendulum.toml"));
    let m = m.to_str().unwrap();
    for (flag, value, figure) in [("--dt", "1e-9", "1.100e9 steps"), ("--t-end", "1e12", "2.000e14 steps")] {
        let start = Instant::now();
        let (code, err) = run(&["simulate", m, "-o", o, flag, value]);
        assert_eq!(code, 1, "{flag} {value}: {err}");
        assert!(err.contains(figure) && err.contains("--max-steps"), "{flag} {value}: {err}");
        assert!(start.elapsed().as_secs_f64() < 5.0, "{flag} {value} took {:?}", start.elapsed());
        assert!(!out.exists());
    }
    // the memory estimate: 813.1 KiB (header)
    let (code, err) = run(&["simulate", m, "-o", o, "--max-memory", "800K"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("813.1 KiB") && err.contains("--max-memory") && err.contains("FLEXROM_MAX_MEMORY"), "{err}");
    assert!(!out.exists());
    let (code, err) = run(&["simulate", m, "-o", o, "--max-memory", "900K"]);
    assert_eq!(code, 0, "{err}");
    // the same bound through the environment
    let e = flexrom().args(["simulate", m, "-o", o]).env("FLEXROM_MAX_MEMORY", "800K").output().unwrap();
    assert_eq!(e.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&e.stderr).contains("FLEXROM_MAX_MEMORY"));

    // 10⁶ elements: refused by the element bound, then (bound raised) by the memory one
    let huge = write(dir.path(), "huge.toml", &pendulum().replace("elements = 50", "elements = 1000000"));
    let start = Instant::now();
    let (code, err) = run(&["simulate", &huge, "-o", o]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("bodies[0].elements") && err.contains("--max-elements"), "{err}");
    let (code, err) = run(&["simulate", &huge, "-o", o, "--max-elements", "2000000", "--max-memory", "1G"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("4000004 coordinates") && err.contains("--max-memory"), "{err}");
    assert!(start.elapsed().as_secs_f64() < 5.0, "took {:?}", start.elapsed());
}

#[test]
fn errors_inside_array_of_tables_entries_name_the_key_and_its_line() {
    let text = pendulum() + "\n[[loads]]\ntype = \"force\"\nbody = \"beam\"\nnode = \"end\"\nvalue = \"up\"\n";
    let err = flexrom::model::Model::from_text(&text, "m.toml").unwrap_err().to_string();
    let line = text.lines().position(|l| l.starts_with("value = \"up\"")).unwrap() + 1;
    assert!(err.contains(&format!("loads[1].value (line {line})")), "{err}");
    // an untagged node reference of the wrong kind, in the first joint
    let text = pendulum().replace("node = \"start\"", "node = 1.5");
    let err = flexrom::model::Model::from_text(&text, "m.toml").unwrap_err().to_string();
    let line = text.lines().position(|l| l.starts_with("node = 1.5")).unwrap() + 1;
    assert!(err.contains(&format!("joints[0].node (line {line})")), "{err}");
    // an unknown key, and an unknown type tag
    let text = pendulum().replace("scaled = true", "scaled = true\nscale = 2");
    let err = flexrom::model::Model::from_text(&text, "m.toml").unwrap_err().to_string();
    let line = text.lines().position(|l| l.starts_with("scale = 2")).unwrap() + 1;
    assert!(err.contains(&format!("loads[0].scale (line {line})")), "{err}");
    let text = pendulum().replace("type = \"gravity\"", "type = \"gravitation\"");
    let err = flexrom::model::Model::from_text(&text, "m.toml").unwrap_err().to_string();
    let line = text.lines().position(|l| l.contains("\"gravitation\"")).unwrap() + 1;
    assert!(err.contains(&format!("loads[0].type (line {line})")), "{err}");
    // a missing key: named as its entry's key, on the line where the entry opens (not as a
    // key beside it, whose removal changes the message too)
    let text = pendulum() + "\n[[loads]]\ntype = \"moment\"\nbody = \"beam\"\nnode = \"start\"\n";
    let err = flexrom::model::Model::from_text(&text, "m.toml").unwrap_err().to_string();
    let line = text.lines().enumerate().filter(|(_, l)| l.starts_with("[[loads]]")).nth(1).unwrap().0 + 1;
    assert!(err.contains(&format!("loads[1].function (line {line}): missing field `function`")), "{err}");
}

/// Errors of the model's own checks (values the parser accepts: an unknown predictor, a
/// zero element count, a key that is missing, a body named twice) name their field with the
/// line it is written on, as parse errors do; a missing key takes its entry's line.
#[test]
fn check_errors_name_the_line_of_their_field() {
    let line_of = |text: &str, start: &str| text.lines().position(|l| l.starts_with(start)).unwrap() + 1;
    let check = |text: &str| flexrom::model::Model::from_text(text, "m.toml").unwrap_err().to_string();
    let text = pendulum().replace("rho_inf = 1.0", "rho_inf = 1.0\npredictor = \"constant-acceleration\"");
    let err = check(&text);
    assert!(err.contains(&format!("time.predictor (line {}): must be", line_of(&text, "predictor ="))), "{err}");
    let text = pendulum().replace("elements = 50", "elements = 0");
    let err = check(&text);
    assert!(err.contains(&format!("bodies[0].elements (line {}): must be", line_of(&text, "elements ="))), "{err}");
    // `angle` removed: the body's `[[bodies]]` header
    let text = pendulum().replace("angle = 0.0\n", "");
    let err = check(&text);
    assert!(err.contains(&format!("bodies[0].angle (line {}): missing", line_of(&text, "[[bodies]]"))), "{err}");
    // the second of two bodies of one name
    let second = "\n[[bodies]]\nname = \"beam\"\nstart = [0.0, 0.0]\nangle = 1.0\nlength = 1.0\nelements = 2\n\
                  density = 1.0\narea = 1.0\ninertia = 1.0\nyoungs_modulus = 1.0\n";
    let text = pendulum() + second;
    let err = check(&text);
    let line = text.lines().enumerate().filter(|(_, l)| l.starts_with("name = \"beam\"")).nth(1).unwrap().0 + 1;
    assert!(err.contains(&format!("bodies[1].name (line {line}): body `beam` is defined twice")), "{err}");
}

/// An error inside a nested table of an entry (the four-bar's piecewise crank moment, a pin's
/// `a`) names the whole path and the offending key's own line, not the line where the entry
/// or its table opens.
#[test]
fn errors_in_nested_tables_point_at_the_key() {
    let fourbar = std::fs::read_to_string(root().join("data/models/fourbar.toml")).unwrap();
    let line_of = |text: &str, needle: &str| text.lines().position(|l| l.contains(needle)).unwrap() + 1;
    let err = |text: &str| flexrom::model::Model::from_text(text, "m.toml").unwrap_err().to_string();
    // the second piece's function as a table of its own, its amplitude a word
    let text = fourbar.replace(
        "[[loads.function.pieces]]\nfunction = { type = \"exponential\", amplitude = 465.9, rate = -16.32 }",
        "[[loads.function.pieces]]\n[loads.function.pieces.function]\ntype = \"exponential\"\nrate = -16.32\namplitude = \"ten\"",
    );
    assert_ne!(text, fourbar);
    let e = err(&text);
    let want =
        format!("loads[1].function.pieces[1].function.amplitude (line {})", line_of(&text, "amplitude = \"ten\""));
    assert!(e.contains(&want) && e.contains("expected f64"), "want `{want}` in: {e}");
    // the first piece's inline function
    let text = fourbar.replace("amplitude = 10.0, frequency", "amplitude = \"ten\", frequency");
    let e = err(&text);
    let want = format!("loads[1].function.pieces[0].function.amplitude (line {})", line_of(&text, "\"ten\""));
    assert!(e.contains(&want), "want `{want}` in: {e}");
    // an unknown key in the table `[loads.function]` opens
    let text = fourbar.replace("type = \"piecewise\"", "type = \"piecewise\"\nsteps = 3");
    let e = err(&text);
    let want = format!("loads[1].function.steps (line {})", line_of(&text, "steps = 3"));
    assert!(e.contains(&want) && e.contains("unknown field"), "want `{want}` in: {e}");
    // a pin's inline node reference
    let text = fourbar.replace("a = { body = \"coupler\", node = \"end\" }", "a = { body = \"coupler\", node = 1.5 }");
    let e = err(&text);
    let want = format!("joints[2].a.node (line {})", line_of(&text, "node = 1.5"));
    assert!(e.contains(&want), "want `{want}` in: {e}");
}

/// Three beams from one point, with a joint list to append.
fn star(joints: &str) -> String {
    let mut t = String::from("[time]\nt_end = 0.1\ndt = 0.01\nrho_inf = 0.9\n");
    for (name, angle) in [("a", 0.0), ("b", 2.0), ("c", 4.0)] {
        t += &format!(
            "[[bodies]]\nname = \"{name}\"\nstart = [0.0, 0.0]\nangle = {angle}\nlength = 1.0\nelements = 2\ndensity = 7800.0\narea = 1e-4\ninertia = 1e-9\nyoungs_modulus = 2e11\n"
        );
    }
    t + joints
}

fn pin(a: &str, b: &str) -> String {
    format!("[[joints]]\ntype = \"pin\"\na = {{ body = \"{a}\", node = 0 }}\nb = {{ body = \"{b}\", node = 0 }}\n")
}

fn ground(kind: &str, body: &str) -> String {
    format!("[[joints]]\ntype = \"{kind}\"\nbody = \"{body}\"\nnode = 0\n")
}

#[test]
fn dependent_joints_are_refused_naming_them() {
    let load = |j: &str| flexrom::model::Model::from_text(&star(j), "m.toml").map(|_| ()).map_err(|e| e.to_string());
    // independent sets load
    load(&(ground("ground_pin", "a") + &pin("a", "b") + &pin("b", "c"))).unwrap();
    load(&(ground("clamp", "a") + &pin("a", "b"))).unwrap();
    // a node pinned to ground twice
    let e = load(&(ground("ground_pin", "a") + &ground("ground_pin", "a"))).unwrap_err();
    assert!(
        e.contains("joints[1]") && e.contains("joints[0] (ground_pin on `a` node 0)") && e.contains("dependent"),
        "{e}"
    );
    // a clamp and a ground pin on the same node
    let e = load(&(ground("clamp", "a") + &ground("ground_pin", "a"))).unwrap_err();
    assert!(e.contains("joints[1]") && e.contains("joints[0] (clamp on `a` node 0)"), "{e}");
    // a loop of pins closing on one point: the third repeats the first two
    let e = load(&(pin("a", "b") + &pin("b", "c") + &pin("c", "a"))).unwrap_err();
    assert!(e.contains("joints[2]") && e.contains("joints[0]") && e.contains("joints[1]"), "{e}");
    // two ground pins on bodies already pinned together: the second names the chain
    let e = load(&(ground("ground_pin", "a") + &pin("a", "b") + &ground("ground_pin", "b"))).unwrap_err();
    assert!(e.contains("joints[2]") && e.contains("joints[0]") && e.contains("joints[1]"), "{e}");
    // the line of the offending entry
    let text = star(&(ground("ground_pin", "a") + &ground("ground_pin", "a")));
    let line = text.lines().enumerate().filter(|(_, l)| *l == "[[joints]]").nth(1).unwrap().0 + 1;
    assert!(load(&(ground("ground_pin", "a") + &ground("ground_pin", "a")))
        .unwrap_err()
        .contains(&format!("joints[1] (line {line})")));
}

#[test]
fn blow_ups_stop_the_run_unless_allowed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.h5");
    let o = out.to_str().unwrap();
    let soft = write(dir.path(), "soft.toml", &pendulum().replace("youngs_modulus = 0.7e9", "youngs_modulus = 1e3"));
    let (code, err) = run(&["simulate", &soft, "-o", o, "--t-end", "0.1"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("simulate at load scale 1") && err.contains("max_strain") && err.contains("--allow-blowup"),
        "{err}"
    );
    assert!(!out.exists(), "a blown-up run writes nothing");
    let (code, err) = run(&["simulate", &soft, "-o", o, "--t-end", "0.1", "--allow-blowup"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("warning: blow-up") && err.contains("max_strain"), "{err}");
    assert!(out.exists());
    // raising the key instead
    let relaxed = write(
        dir.path(),
        "relaxed.toml",
        &pendulum()
            .replace("youngs_modulus = 0.7e9", "youngs_modulus = 1e3")
            .replace("rho_inf = 1.0", "rho_inf = 1.0\nmax_strain = 1e6"),
    );
    let (code, err) = run(&["simulate", &relaxed, "-o", o, "--t-end", "0.1"]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("blow-up"), "{err}");

    // the load scale 1e4: the strain bound fires (naming the scale); with it relaxed and no
    // step cuts allowed, the cut budget does
    let (code, err) = run(&[
        "simulate",
        &root().join("data/models/pendulum.toml").display().to_string(),
        "-o",
        o,
        "--load-scale",
        "1e4",
        "--t-end",
        "0.3",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("load scale 10000") && err.contains("max_strain"), "{err}");
    let cuts = write(
        dir.path(),
        "cuts.toml",
        &pendulum().replace("rho_inf = 1.0", "rho_inf = 1.0\nmax_strain = 1e9\nmax_total_step_cuts = 0"),
    );
    let (code, err) = run(&["simulate", &cuts, "-o", o, "--load-scale", "1e4", "--t-end", "0.3"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("step halvings") && err.contains("max_total_step_cuts"), "{err}");
    // a bad key value is an input error
    let bad = write(dir.path(), "bad.toml", &pendulum().replace("rho_inf = 1.0", "rho_inf = 1.0\nmax_strain = -1"));
    let (code, err) = run(&["simulate", &bad, "-o", o]);
    assert_eq!(code, 1);
    assert!(err.contains("time.max_strain"), "{err}");
}

/// Runs `args` with stdout a pipe whose reading end is closed at once.
fn into_closed_pipe(args: &[&str]) -> (Option<i32>, String) {
    let mut child = flexrom().args(args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn a_closed_or_full_stdout_is_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.h5");
    let (o, m) = (out.to_str().unwrap(), root().join("data/models/pendulum.toml"));
    let m = m.to_str().unwrap();
    let (code, err) = into_closed_pipe(&["simulate", m, "-o", o, "--t-end", "0.05", "--csv"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("panicked") && !err.contains("error"), "{err}");
    // a full disk is an ordinary error with its message
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let r = flexrom().args(["simulate", m, "-o", o, "--t-end", "0.05", "--csv"]).stdout(full).output().unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(err.contains("standard output") && err.contains("No space left"), "{err}");

    // validate --json and sweep into a closed pipe, with a basis trained here
    let basis = dir.path().join("b.h5");
    let b = basis.to_str().unwrap();
    let p = root().join("pipelines/pendulum.toml");
    let p = p.to_str().unwrap();
    let (code, err) = run(&["train", p, "--basis", b]);
    assert_eq!(code, 0, "{err}");
    let (code, err) = into_closed_pipe(&["validate", p, "--load-scale", "1.0", "--json", "--no-dense", "--basis", b]);
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let sw = dir.path().join("s.h5");
    let (code, err) =
        into_closed_pipe(&["sweep", p, "--load-scales", "0.9:1.1:3", "--basis", b, "-o", sw.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// A point is two numbers: a third (`start = [0, 0, 5]`, a 3-D habit) is refused with the
/// key and its line, not dropped (serde's fixed-size arrays would take the first two).
#[test]
fn a_point_with_three_coordinates_is_refused() {
    let text = pendulum();
    let start = text.lines().find(|l| l.starts_with("start = ")).expect("the pendulum has a start").to_string();
    let three = start.replace(']', ", 5.0]");
    let bad = text.replace(&start, &three);
    let err = flexrom::model::Model::from_text(&bad, "m.toml").unwrap_err().to_string();
    let line = bad.lines().position(|l| l == three).unwrap() + 1;
    assert!(err.contains(&format!("bodies[0].start (line {line})")) && err.contains("invalid length 3"), "{err}");
    // the two-number form still reads
    flexrom::model::Model::from_text(&text, "m.toml").unwrap();
}

/// A model file given where a pipeline belongs (`flexrom train model.toml`, a new user's first
/// slip) is named as a model file, with what to give instead, not by the first key a
/// pipeline does not know; a pipeline still loads.
#[test]
fn a_model_file_given_as_a_pipeline_is_named() {
    let err = flexrom::pipeline::Pipeline::load(root().join("data/models/pendulum.toml")).unwrap_err().to_string();
    assert!(err.contains("pendulum.toml: bodies: this is a model file") && err.contains("model = "), "{err}");
    flexrom::pipeline::Pipeline::load(root().join("pipelines/pendulum.toml")).unwrap();
}

/// `-v` on a run that fails still shows its Newton statistics up to the failure (a run that
/// ends prints its Newton line; the failed one printed nothing): the shipped pendulum at
/// 10⁴ times its gravity, which stretches the beam past the strain bound within 0.06 s.
#[test]
fn a_failed_run_under_verbose_shows_newton_until_the_failure() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.h5");
    let m = root().join("data/models/pendulum.toml");
    let (code, err) =
        run(&["-v", "simulate", m.to_str().unwrap(), "--load-scale", "10000", "-o", out.to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("blow-up"), "{err}");
    let line = err.lines().find(|l| l.contains("Newton until the run failed")).unwrap_or_else(|| panic!("{err}"));
    assert!(line.contains("steps done") && line.contains("step cuts"), "{line}");
    assert!(!out.exists());
    // without -v, the error alone
    let (_, err) = run(&["simulate", m.to_str().unwrap(), "--load-scale", "10000", "-o", out.to_str().unwrap()]);
    assert!(!err.contains("Newton until"), "{err}");
}

/// A pipeline file's checks name the line of their field too (the shipped pendulum's
/// pipeline with a negative greedy tolerance; `modes` missing names its table's line), and
/// so does a check a stage makes after loading it (`train --snapshots-only --shard` of a
/// greedy pipeline).
#[test]
fn pipeline_check_errors_name_the_line_of_their_field() {
    let dir = tempfile::tempdir().unwrap();
    let model = root().join("data/models/pendulum.toml");
    let text = std::fs::read_to_string(root().join("pipelines/pendulum.toml"))
        .unwrap()
        .replace("model = \"../data/models/pendulum.toml\"", &format!("model = {:?}", model.display().to_string()));
    let line_of = |text: &str, start: &str| text.lines().position(|l| l.starts_with(start)).unwrap() + 1;
    let bad = text.replace("tolerance = 1e-3, max_runs", "tolerance = -1e-3, max_runs");
    assert_ne!(bad, text, "the shipped pipeline's greedy line moved: update the test");
    let p = write(dir.path(), "p.toml", &bad);
    let err = flexrom::pipeline::Pipeline::load(&p).unwrap_err().to_string();
    assert!(err.contains(&format!("train.greedy.tolerance (line {}): is -0.001", line_of(&bad, "greedy ="))), "{err}");
    let bad = text
        .lines()
        .map(|l| if l.starts_with("greedy =") { "load_scales = [1.0]" } else { l })
        .collect::<Vec<_>>()
        .join("\n");
    let p = write(dir.path(), "p.toml", &bad);
    let err = flexrom::pipeline::Pipeline::load(&p).unwrap_err().to_string();
    assert!(err.contains(&format!("reduction.modes (line {}): is missing", line_of(&bad, "[reduction]"))), "{err}");
    // a check a stage makes while it runs (sharding a greedy pipeline's training runs),
    // after the file loaded: the command's error names the line too, exit 1
    let p = write(dir.path(), "greedy.toml", &text);
    let out = dir.path().join("snaps.h5");
    let (code, err) = run(&["train", &p, "--snapshots-only", "--shard", "1/2", "-o", out.to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!("train.greedy (line {}): greedy training is sequential", line_of(&text, "greedy ="))),
        "{err}"
    );
    assert!(!out.exists());
}

/// `-v` says how far a run strained its beams: a steel bar clamped at one end and pulled
/// along its axis by F at the other settles at the static strain F/(EA) (here 2100 N /
/// (2.1e11 Pa · 1e-4 m²) = 1.00e-4 in every element; ρ∞ = 0 and steps far longer than the
/// bar's axial period, 4L/c = 0.77 ms, damp the wave of the suddenly applied load at once).
/// The pendulum under 10⁴ g above stops at the blow-up bound; this line shows a user how far
/// below it a run stayed.
#[test]
fn verbose_runs_say_their_largest_axial_strain() {
    let dir = tempfile::tempdir().unwrap();
    let bar = "[time]\nt_end = 0.04\ndt = 1e-3\nrho_inf = 0.0\n\n[[bodies]]\nname = \"bar\"\nstart = [0.0, 0.0]\n\
               angle = 0.0\nlength = 1.0\nelements = 10\ndensity = 7850.0\narea = 1e-4\ninertia = 1e-9\n\
               youngs_modulus = 2.1e11\n\n[[joints]]\ntype = \"clamp\"\nbody = \"bar\"\nnode = \"start\"\n\n\
               [[loads]]\ntype = \"force\"\nbody = \"bar\"\nnode = \"end\"\nvalue = [2100.0, 0.0]\n";
    let m = write(dir.path(), "bar.toml", bar);
    let out = dir.path().join("bar.h5");
    let (code, err) = run(&["-v", "simulate", &m, "-o", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let line = err.lines().find(|l| l.contains("largest mean axial strain")).unwrap_or_else(|| panic!("{err}"));
    assert!(line.contains("|ε̄| = 1.00e-4") && line.contains("blow-up bound 0.5"), "{line}");
}

/// Worker counts: an absurd one (from the option or either variable) is refused naming where
/// it came from, before any run, and leaves no file; one above the cores is cut to them. The
/// cores are what `std::thread::available_parallelism` says here, the figure the program
/// reads too; 1024 is `workflows::shard::MOST_THREADS`.
#[test]
fn absurd_thread_counts_are_refused_and_large_ones_cut_to_the_cores() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.h5");
    let (o, m) = (out.to_str().unwrap(), root().join("data/models/pendulum.toml"));
    let m = m.to_str().unwrap();
    let clean = |c: &mut Command| {
        c.env_remove("RAYON_NUM_THREADS").env_remove("SLURM_CPUS_PER_TASK");
    };
    // (flags, environment, what the message names)
    let cases = [
        ("--threads 100000", None, "--threads 100000"),
        ("--threads 4294967297", None, "--threads 4294967297"),
        ("--threads 1025", None, "--threads 1025"),
        ("", Some(("RAYON_NUM_THREADS", "100000")), "RAYON_NUM_THREADS=`100000`"),
        ("", Some(("SLURM_CPUS_PER_TASK", "100000")), "SLURM_CPUS_PER_TASK=`100000`"),
        ("", Some(("RAYON_NUM_THREADS", "99999999999999999999999")), "RAYON_NUM_THREADS=`99999999999999999999999`"),
    ];
    for (flags, env, named) in cases {
        let mut c = flexrom();
        clean(&mut c);
        c.args(["simulate", m, "-o", o]).args(flags.split_whitespace());
        if let Some((k, v)) = env {
            c.env(k, v);
        }
        let r = c.output().unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(1), "{named}: {err}");
        assert!(err.contains(named) && err.contains("at most 1024"), "{named}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!out.exists(), "{named}");
    }
    let bad = flexrom().args(["simulate", m, "-o", o]).env("RAYON_NUM_THREADS", "four\nthreads").output().unwrap();
    let err = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(bad.status.code(), Some(1), "{err}");
    assert!(err.contains("RAYON_NUM_THREADS=`four\\nthreads` is not a positive whole number"), "{err}");

    let cores = std::thread::available_parallelism().unwrap().get();
    let wide = (cores + 62).to_string();
    for (flags, env) in
        [(vec!["--threads", wide.as_str()], None), (vec![], Some(("SLURM_CPUS_PER_TASK", wide.as_str())))]
    {
        let mut c = flexrom();
        clean(&mut c);
        c.args(["simulate", m, "-o", o, "-v"]).args(&flags);
        if let Some((k, v)) = env {
            c.env(k, v);
        }
        let r = c.output().unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(0), "{err}");
        assert!(err.contains(&format!("on {cores} thread(s)")), "{flags:?} {env:?}: {err}");
    }
}

/// A body or probe name with a control character is refused when the model is loaded,
/// naming the entry's key (a NUL passed the checks and failed at the end of the run, as
/// `InternalNull` from the labels' writer, naming no key).
#[test]
fn names_with_control_characters_are_refused_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.h5");
    for (text, key) in [
        (pendulum().replace("\"beam\"", "\"be\\u0000am\""), "bodies[0].name"),
        (pendulum().replace("\"beam\"", "\"be\\nam\""), "bodies[0].name"),
        (pendulum().replace("name = \"tip\"", "name = \"t\\u0000ip\""), "probes[0].name"),
    ] {
        let m = write(dir.path(), "m.toml", &text);
        let (code, err) = run(&["simulate", &m, "-o", out.to_str().unwrap()]);
        assert_eq!(code, 1, "{key}: {err}");
        assert!(err.contains(key) && err.contains("control character"), "{key}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(!out.exists());
    }
}
