//! Sweeps survive a bad load (docs/basis-and-sweep.md), through the `flexrom sweep` command.
//!
//! Checks, and where each expectation comes from:
//! - a load scale that makes Newton fail (1e20 × gravity on a coarse pendulum: measured to
//!   fail at the first step after 8 halvings; 1e12 still runs) does not stop the sweep: the
//!   good scales are written, `/status` is 0 for them and 1 for the failed ones with the
//!   error in `/message`, their rows are NaN, the exit code is 3 and stderr ends with one
//!   line "2 of 5 load scales failed: …" and, once, the way on (the full model is the exact
//!   route where a reduced run fails);
//! - a good scale's probe trajectory in the sweep file is bit-for-bit the one `online`
//!   writes at the same load scale (without --continuation a sweep runs each scale exactly
//!   as `online` does);
//! - `--resume` on a file of 3 finished scales runs only the 2 missing of 5 (stderr says so,
//!   and the 3 reused rows keep their `/rom_seconds` bit for bit: a rerun would measure a
//!   new time), reruns failed scales, and refuses a file of another basis;
//! - a sweep killed (SIGKILL) while it runs leaves a valid file at the final path (statuses
//!   0 and 2 only), from which `--resume` finishes the sweep;
//! - a sweep stopped by SIGINT stops its runs, writes every scale finished by then (not
//!   only those of its last checkpoint), exits 130, says which file keeps how many and that
//!   the same command with `--resume` runs the others, which it then does.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// One test at a time: a `flexrom` child forked while another test has an HDF5 file open
/// inherits that descriptor and HDF5's lock on it, and the file cannot be opened again
/// until the child exits.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn flexrom() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flexrom"))
}

fn pendulum_text(elements: usize, t_end: f64) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/pendulum.toml"))
        .unwrap()
        .replace("elements = 50", &format!("elements = {elements}"))
        .replace("t_end = 1.1", &format!("t_end = {t_end}"))
}

/// A pendulum pipeline in `dir` with `modes` POD modes and the given [online] list; trained.
fn setup(dir: &Path, elements: usize, t_end: f64, modes: usize, online: &str) -> PathBuf {
    std::fs::write(dir.join("model.toml"), pendulum_text(elements, t_end)).unwrap();
    let p = dir.join("pipe.toml");
    std::fs::write(
        &p,
        format!(
            "model = \"model.toml\"\nbasis = \"basis.h5\"\nreport = \"report\"\n[train]\nload_scales = [1.0]\n[reduction]\nvariant = \"galerkin\"\nmodes = {{ count = {modes} }}\n[online]\nload_scales = {online}\n"
        ),
    )
    .unwrap();
    let o = flexrom().args(["train", p.to_str().unwrap()]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    p
}

fn run(args: &[&str]) -> (Output, String) {
    let o = flexrom().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_ne!(o.status.code(), Some(101), "panic: {err}");
    assert!(o.status.code().is_some(), "killed by a signal: {err}");
    (o, err)
}

fn status(f: &Path) -> Vec<u8> {
    flexrom::io::h5_open::open(f).unwrap().dataset("status").unwrap().read_raw::<u8>().unwrap()
}

fn column(f: &Path, name: &str) -> Vec<f64> {
    flexrom::io::h5_open::open(f).unwrap().dataset(name).unwrap().read_raw::<f64>().unwrap()
}

#[test]
fn a_failing_load_scale_is_recorded_and_the_others_written() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let p = setup(d, 8, 0.1, 4, "[0.9, 1e20, 1.0, 1.1, 5e19]");
    let out = d.join("s.h5");
    let (o, err) = run(&["sweep", p.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(3), "{err}");
    let last = err.lines().find(|l| l.starts_with("error: ")).unwrap_or_else(|| panic!("{err}"));
    assert!(
        last.starts_with("error: 2 of 5 load scales failed: sweep (reduced run) at load scale 1e20: Newton failed"),
        "{err}"
    );
    assert!(last.contains("s.h5"), "{err}");
    assert_eq!(status(&out), vec![0, 1, 0, 0, 1]);
    // the answers kept are warned about too (0.9 and 1.1 outside the range [1, 1])
    assert!(err.contains("outside the basis's training range [1, 1]"), "{err}");
    let f = flexrom::io::h5_open::open(&out).unwrap();
    let messages: Vec<String> = f
        .dataset("message")
        .unwrap()
        .read_raw::<hdf5::types::VarLenUnicode>()
        .unwrap()
        .iter()
        .map(|m| m.to_string())
        .collect();
    assert_eq!(messages[0], "");
    assert!(messages[1].starts_with("sweep (reduced run) at load scale 1e20: Newton failed at t = "), "{messages:?}");
    assert!(messages[4].starts_with("sweep (reduced run) at load scale 5e19: Newton failed"), "{messages:?}");
    // and the way on, once after the failures: the full model is the exact route there
    assert_eq!(err.matches("`flexrom simulate` runs the full model at this load").count(), 1, "{err}");
    assert!(err.trim().ends_with(flexrom::error::REDUCED_RUN_FAILED), "{err}");
    assert_eq!(f.attr("n_failed").unwrap().read_scalar::<u64>().unwrap(), 2);
    let tip = f.dataset("probes/tip").unwrap().read::<f64, ndarray::Ix3>().unwrap();
    let rom_seconds = column(&out, "rom_seconds");
    for (k, ok) in [true, false, true, true, false].into_iter().enumerate() {
        let row = tip.index_axis(ndarray::Axis(0), k);
        assert_eq!(row.iter().all(|v| v.is_finite()), ok, "row {k}");
        assert_eq!(row.iter().all(|v| v.is_nan()), !ok, "row {k}");
        assert_eq!(rom_seconds[k].is_finite(), ok);
    }
    // the stdout table names the failures too
    let table = String::from_utf8_lossy(&o.stdout).to_string();
    assert_eq!(table.lines().filter(|l| l.contains("failed: sweep (reduced run) at load scale")).count(), 2, "{table}");
    // a good row is exactly what `online` computes at that load scale
    let single = d.join("online.h5");
    let (o, err) = run(&["online", p.to_str().unwrap(), "--load-scale", "1.0", "-o", single.to_str().unwrap()]);
    assert!(o.status.success(), "{err}");
    let alone = flexrom::io::h5_open::open(&single).unwrap().dataset("probes/tip").unwrap().read_2d::<f64>().unwrap();
    assert_eq!(tip.index_axis(ndarray::Axis(0), 2), alone);

    // --resume reruns the failed scales only (they fail again: exit 3 again)
    let before = column(&out, "rom_seconds");
    let (o, err) = run(&["sweep", p.to_str().unwrap(), "-o", out.to_str().unwrap(), "--resume"]);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(err.contains("3 of 5 load scales already finished, running 2"), "{err}");
    let after = column(&out, "rom_seconds");
    for k in [0, 2, 3] {
        assert_eq!(before[k].to_bits(), after[k].to_bits(), "row {k} was not rerun");
    }
    assert_eq!(status(&out), vec![0, 1, 0, 0, 1]);
}

#[test]
fn resume_runs_only_the_missing_scales_of_the_same_basis() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let p = setup(d, 8, 0.1, 4, "\"0.8:1.2:5\"");
    let (ps, out) = (p.to_str().unwrap(), d.join("s.h5"));
    let os = out.to_str().unwrap();
    let (o, err) = run(&["sweep", ps, "-o", os, "--load-scales", "0.8:1.2:3"]);
    assert!(o.status.success(), "{err}");
    let first = column(&out, "rom_seconds");
    assert_eq!(column(&out, "load_scales"), vec![0.8, 1.0, 1.2]);
    // the pipeline's list of 5 holds the 3 finished ones
    let (o, err) = run(&["sweep", ps, "-o", os, "--resume"]);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("resuming") && err.contains("3 of 5 load scales already finished, running 2"), "{err}");
    assert_eq!(column(&out, "load_scales"), vec![0.8, 0.9, 1.0, 1.1, 1.2]);
    assert_eq!(status(&out), vec![0; 5]);
    let merged = column(&out, "rom_seconds");
    for (k, j) in [(0, 0), (1, 2), (2, 4)] {
        assert_eq!(first[k].to_bits(), merged[j].to_bits(), "scale {k} was taken from the file");
    }
    assert!(merged.iter().all(|v| v.is_finite()));
    // everything finished: nothing runs
    let (o, err) = run(&["sweep", ps, "-o", os, "--resume"]);
    assert!(o.status.success() && err.contains("5 of 5 load scales already finished, running 0"), "{err}");
    // a file of another basis is refused, and left as it was
    let bytes = std::fs::read(&out).unwrap();
    let other = d.join("other.h5");
    let text = std::fs::read_to_string(&p).unwrap().replace("count = 4", "count = 3").replace("basis.h5", "other.h5");
    let p2 = d.join("pipe2.toml");
    std::fs::write(&p2, text).unwrap();
    assert!(run(&["train", p2.to_str().unwrap()]).0.status.success());
    let (o, err) = run(&["sweep", ps, "-o", os, "--resume", "--basis", other.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{err}");
    // (the other basis was trained with other settings than pipe.toml has: one warning line first)
    let errors: Vec<&str> = err.lines().filter(|l| !l.starts_with("warning:")).collect();
    assert_eq!(errors.len(), 1, "{err}");
    assert!(err.contains("s.h5") && err.contains("basis_content_hash") && err.contains("another basis"), "{err}");
    assert_eq!(std::fs::read(&out).unwrap(), bytes);
}

/// A sweep of 300 load scales in `d` (~10 ms per reduced run: seconds, long enough to be
/// stopped midway) whose file has just been written for the first time: its pipeline, the
/// sweep file and the running process (stderr to `stderr`).
fn sweep_under_way(d: &Path, stderr: std::process::Stdio) -> (PathBuf, PathBuf, std::process::Child) {
    let p = setup(d, 50, 1.1, 14, "\"0.5:1.5:300\"");
    let out = d.join("s.h5");
    let child = flexrom()
        .args(["sweep", p.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .stdout(std::process::Stdio::null())
        .stderr(stderr)
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while !out.exists() && start.elapsed().as_secs() < 120 {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    (p, out, child)
}

#[test]
fn a_killed_sweep_leaves_a_valid_file_to_resume_from() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let (p, out, mut child) = sweep_under_way(d, std::process::Stdio::null());
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(out.exists(), "the first finished scale is written at once");
    let st = status(&out);
    assert_eq!(st.len(), 300);
    assert!(st.iter().all(|&s| s == 0 || s == 2), "{st:?}");
    let finished = st.iter().filter(|&&s| s == 0).count();
    assert!((1..300).contains(&finished), "killed midway: {finished} finished");
    let (o, err) = run(&["sweep", p.to_str().unwrap(), "-o", out.to_str().unwrap(), "--resume"]);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains(&format!("{finished} of 300 load scales already finished, running {}", 300 - finished)),
        "{err}"
    );
    assert_eq!(status(&out), vec![0; 300]);
    assert!(column(&out, "rom_seconds").iter().all(|v| v.is_finite()));
}

#[test]
fn an_interrupted_sweep_names_the_file_it_keeps_and_how_to_go_on() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let (p, out, child) = sweep_under_way(d, std::process::Stdio::piped());
    // past the first checkpoint's rename, after which the note is set
    std::thread::sleep(std::time::Duration::from_millis(300));
    let kill = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(kill.success());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(err.contains("flexrom: SIGINT: stopping the runs under way to write the finished ones"), "{err}");
    assert!(err.contains("flexrom: stopped by SIGINT\n"), "{err}");
    // the file holds every scale finished before the stop, and says how many
    let st = status(&out);
    let finished = st.iter().filter(|&&s| s == 0).count();
    assert!(st.iter().all(|&s| s == 0 || s == 2), "{st:?}");
    assert!((1..300).contains(&finished), "stopped midway: {finished}");
    assert!(
        err.contains(&format!(
            "{} keeps the {finished} load scales finished; the same command with --resume runs the other {}",
            out.display(),
            300 - finished
        )),
        "{err}"
    );
    let (o, err) = run(&["sweep", p.to_str().unwrap(), "-o", out.to_str().unwrap(), "--resume"]);
    assert!(o.status.success(), "{err}");
    assert!(err.contains(&format!("{finished} of 300 load scales already finished")), "{err}");
    assert_eq!(status(&out), vec![0; 300]);
}

fn messages(f: &Path) -> Vec<String> {
    let f = flexrom::io::h5_open::open(f).unwrap();
    let m = f.dataset("message").unwrap().read_raw::<hdf5::types::VarLenUnicode>().unwrap();
    m.iter().map(|m| m.to_string()).collect()
}

fn tip(f: &Path) -> ndarray::Array3<f64> {
    flexrom::io::h5_open::open(f).unwrap().dataset("probes/tip").unwrap().read::<f64, ndarray::Ix3>().unwrap()
}

/// `--fallback full` where every estimate is above the tolerance (an `[online] tolerance`
/// of 1e-12 against estimates of about 1e-3 for 4 POD modes on the coarse pendulum): every
/// point is the full model's answer — its tip trajectory bit for bit that of `sweep
/// --full` (the same full model, one per worker) —, `/fallback` 1, `/error_estimate` 0,
/// `/reduced_q` NaN, why in `/message`, one summary line, exit 0 and no warning about the
/// tolerance (the answers are exact). `online --fallback full` writes the full run's
/// result file (q bit for bit `simulate`'s) with the reason and no reduced coordinates.
/// `--resume` keeps those points as they are; the pipeline's `[online] fallback = "full"`
/// does the same without the flag (for `online` too), and `--fallback none` overrides it:
/// the reduced answers with the warning, `/fallback` 0.
#[test]
fn a_fallback_answers_with_the_full_model_where_the_estimate_exceeds_the_tolerance() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let p = setup(d, 8, 0.1, 4, "[0.9, 1.0, 1.1]\ntolerance = 1e-12");
    let ps = p.to_str().unwrap();
    let (fb, full, plain) = (d.join("fb.h5"), d.join("full.h5"), d.join("plain.h5"));
    let (o, err) = run(&["sweep", ps, "--fallback", "full", "-o", fb.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains("the full model answered 3 of 3 load scales in place of the reduced one (3: error estimate above the tolerance;"),
        "{err}"
    );
    assert!(!err.contains("warning: error estimate above"), "{err}");
    let (o, err) = run(&["sweep", ps, "--full", "-o", full.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert_eq!(tip(&fb), tip(&full), "the fallback's answers are the full model's");
    let f = flexrom::io::h5_open::open(&fb).unwrap();
    assert_eq!(f.dataset("fallback").unwrap().read_raw::<u8>().unwrap(), vec![1, 1, 1]);
    assert!(f.dataset("reduced_q").unwrap().read_raw::<f64>().unwrap().iter().all(|x| x.is_nan()));
    drop(f);
    assert_eq!(column(&fb, "error_estimate"), vec![0.0; 3]);
    for m in messages(&fb) {
        assert!(m.starts_with("full model in place of the reduced one: error estimate "), "{m}");
        assert!(m.ends_with(" above the tolerance 1e-12"), "{m}");
    }
    // `online` takes the same way: the result file is the full run's (q bit for bit that of
    // `simulate`), with the reason and without reduced coordinates
    let (one, sim) = (d.join("one.h5"), d.join("sim.h5"));
    let (o, err) =
        run(&["online", ps, "--load-scale", "1.1", "--fallback", "full", "-o", one.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(String::from_utf8_lossy(&o.stdout).contains("\"n_modes\":null"), "{}", String::from_utf8_lossy(&o.stdout));
    let model = d.join("model.toml");
    let (o, err) = run(&["simulate", model.to_str().unwrap(), "--load-scale", "1.1", "-o", sim.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{err}");
    let q = |f: &Path| flexrom::io::h5_open::open(f).unwrap().dataset("q").unwrap().read_raw::<f64>().unwrap();
    assert_eq!(q(&one), q(&sim));
    let f = flexrom::io::h5_open::open(&one).unwrap();
    let why = f.attr("fallback").unwrap().read_scalar::<hdf5::types::VarLenUnicode>().unwrap().to_string();
    assert!(why.starts_with("full model in place of the reduced one: error estimate "), "{why}");
    assert_eq!(f.attr("error_estimate").unwrap().read_scalar::<f64>().unwrap(), 0.0);
    assert!(!f.link_exists("reduced"));
    drop(f);
    // resumed: nothing runs again, and the points stay the full model's
    let before = column(&fb, "rom_seconds");
    let (o, err) = run(&["sweep", ps, "--fallback", "full", "--resume", "-o", fb.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("3 of 3 load scales already finished, running 0"), "{err}");
    assert_eq!(column(&fb, "rom_seconds"), before);
    assert!(messages(&fb).iter().all(|m| m.starts_with("full model in place")));
    // the pipeline's key, and the flag over it
    let text = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, text.replace("tolerance = 1e-12", "tolerance = 1e-12\nfallback = \"full\"")).unwrap();
    let keyed = d.join("keyed.h5");
    let (o, err) = run(&["sweep", ps, "-o", keyed.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert_eq!(tip(&keyed), tip(&full));
    let (o, err) = run(&["online", ps, "--load-scale", "1.1", "-o", one.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("full model in place of the reduced one"), "the key holds for online too: {err}");
    let (o, err) = run(&["sweep", ps, "--fallback", "none", "-o", plain.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("warning: error estimate above the tolerance 1e-12"), "{err}");
    let f = flexrom::io::h5_open::open(&plain).unwrap();
    assert_eq!(f.dataset("fallback").unwrap().read_raw::<u8>().unwrap(), vec![0, 0, 0]);
    drop(f);
    assert!(column(&plain, "error_estimate").iter().all(|&e| e > 1e-12));
    assert_ne!(tip(&plain), tip(&full), "4 modes are not the full model");
    assert_eq!(messages(&plain), vec![""; 3]);
}

/// `--fallback full` where the reduced runs fail and the full ones do not: the ×10 four-bar
/// (data/models/fourbar_x10.toml, shortened to t_end = 0.4 s) on a basis too poor for it
/// (2 + 10 + 2 POD modes, ECSW at τ = 0.1, trained at 0.7 and 1.2; measured 2026-11-28:
/// every reduced run blows up at t = 0.168 s, a mean axial strain of 0.51–0.59 in the
/// coupler, while the full runs finish). Every point is the full model's answer (its probes
/// bit for bit those of `sweep --full`), `/status` 0, `/fallback` 1, `/error_estimate` 0,
/// the reduced run's failure named in `/message`, exit 0; without the fallback the same
/// sweep fails at every point (exit 3) and says that the full model is the way on.
#[test]
fn a_fallback_answers_with_the_full_model_where_the_reduced_run_fails() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let model = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/fourbar_x10.toml"))
        .unwrap()
        .replace("t_end = 1.1", "t_end = 0.4");
    assert!(model.contains("t_end = 0.4"));
    std::fs::write(d.join("model.toml"), model).unwrap();
    let p = d.join("pipe.toml");
    std::fs::write(
        &p,
        "model = \"model.toml\"\nbasis = \"basis.h5\"\n[train]\nload_scales = [0.7, 1.2]\n[reduction]\nvariant = \"constraint-preserving\"\nblocks = \"bodies\"\nmodes = { counts = [2, 10, 2] }\nhyper = { tolerance = 0.1 }\n",
    )
    .unwrap();
    let ps = p.to_str().unwrap();
    let (o, err) = run(&["train", ps]);
    assert_eq!(o.status.code(), Some(0), "{err}");
    let (fb, full, plain) = (d.join("fb.h5"), d.join("full.h5"), d.join("plain.h5"));
    let loads = ["--load-scales", "0.8:1.0:3"];
    // first that the setup still does what the test is about: without the fallback every
    // reduced run fails, and the way on is named
    let (o, err) = run(&[&["sweep", ps, "-o", plain.to_str().unwrap()][..], &loads].concat());
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert_eq!(status(&plain), vec![1, 1, 1]);
    assert!(err.contains("3 of 3 load scales failed"), "{err}");
    assert!(err.contains("`flexrom sweep --full` at many"), "{err}");
    let (o, err) = run(&[&["sweep", ps, "--fallback", "full", "-o", fb.to_str().unwrap()][..], &loads].concat());
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains("the full model answered 3 of 3 load scales in place of the reduced one (3: reduced run failed;"),
        "{err}"
    );
    let (o, err) = run(&[&["sweep", ps, "--full", "-o", full.to_str().unwrap()][..], &loads].concat());
    assert_eq!(o.status.code(), Some(0), "{err}");
    let probes = |f: &Path| {
        let f = flexrom::io::h5_open::open(f).unwrap();
        let g = f.group("probes").unwrap();
        let mut names = g.member_names().unwrap();
        names.sort();
        names.into_iter().map(|n| (g.dataset(&n).unwrap().read_raw::<f64>().unwrap(), n)).collect::<Vec<_>>()
    };
    let answers = probes(&fb);
    assert_eq!(answers.len(), 3, "the model's three probes");
    assert_eq!(answers, probes(&full), "the fallback's answers are the full model's");
    assert_eq!(status(&fb), vec![0, 0, 0]);
    let f = flexrom::io::h5_open::open(&fb).unwrap();
    assert_eq!(f.dataset("fallback").unwrap().read_raw::<u8>().unwrap(), vec![1, 1, 1]);
    drop(f);
    assert_eq!(column(&fb, "error_estimate"), vec![0.0; 3]);
    for m in messages(&fb) {
        assert!(
            m.starts_with(
                "full model in place of the reduced one: the reduced run failed: sweep (reduced run) at load scale "
            ),
            "{m}"
        );
        assert!(m.contains("blow-up at t = "), "{m}");
    }
}

/// Where the full model fails too (1e20 × gravity: Newton fails in both after 8 halvings,
/// see the first test), the point is failed and its message holds both failures; the
/// others are the reduced answers (the tolerance of the pipeline is the training one:
/// none for a fixed-load basis, so nothing else falls back).
#[test]
fn a_fallback_whose_full_run_fails_too_says_both() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let p = setup(d, 8, 0.1, 4, "[1.0, 1e20]");
    let out = d.join("s.h5");
    let (o, err) = run(&["sweep", p.to_str().unwrap(), "--fallback", "full", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert_eq!(status(&out), vec![0, 1]);
    let m = messages(&out);
    assert_eq!(m[0], "");
    assert!(m[1].starts_with("sweep (full run) at load scale 1e20: Newton failed"), "{m:?}");
    assert!(
        m[1].contains("; the full model ran in place of the reduced one, which had failed: sweep (reduced run) at load scale 1e20: Newton failed"),
        "{m:?}"
    );
    let f = flexrom::io::h5_open::open(&out).unwrap();
    assert_eq!(f.dataset("fallback").unwrap().read_raw::<u8>().unwrap(), vec![0, 0]);
}

/// Where the full model fails too at a point the fallback would take, the reduced answer
/// stands as it would without the fallback, with a note in `/message`, `/fallback` 2 and
/// a summary line that says so. The shipped four-bar (its pipeline trained here) at
/// λ = 1.34, outside its basis's range [0.7, 1.2] (measured 2026-11-27): the reduced run
/// finishes, its estimator's richer run fails (estimate ∞, above the tolerance 1e-2), and
/// the full run blows up at t = 1.064 s (strain 0.87 in the coupler).
#[test]
fn where_the_full_model_fails_too_the_reduced_answer_stands_with_a_note() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("s.h5");
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("pipelines/fourbar.toml");
    // the shipped pipeline's basis, trained here (a clean clone has no data/bases)
    let basis = tmp.path().join("fourbar.h5");
    let (o, err) = run(&["-q", "train", p.to_str().unwrap(), "--basis", basis.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{err}");
    let (o, err) = run(&[
        "sweep",
        p.to_str().unwrap(),
        "--basis",
        basis.to_str().unwrap(),
        "--load-scales",
        "1.34:1.34:1",
        "--fallback",
        "full",
        "-o",
        out.to_str().unwrap(),
        "--csv",
    ]);
    assert_eq!(o.status.code(), Some(0), "{err}");
    let csv = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(csv.lines().next().unwrap().ends_with(",fallback") && csv.lines().nth(1).unwrap().ends_with(",2"), "{csv}");
    assert!(err.contains("warning: error estimate above the tolerance 1e-2 at load scale 1.34"), "{err}");
    assert!(
        err.contains(
            "at 1 load scale the full model was tried in place of the reduced answer and failed too (1: no estimate;"
        ),
        "{err}"
    );
    assert_eq!(status(&out), vec![0]);
    let f = flexrom::io::h5_open::open(&out).unwrap();
    assert_eq!(f.dataset("fallback").unwrap().read_raw::<u8>().unwrap(), vec![2]);
    assert!(f.dataset("reduced_q").unwrap().read_raw::<f64>().unwrap().iter().all(|x| x.is_finite()));
    drop(f);
    let m = &messages(&out)[0];
    assert!(m.starts_with(flexrom::pipeline::fallback::FULL_TRIED), "{m}");
    assert!(m.contains("failed: sweep (full run) at load scale 1.34: blow-up"), "{m}");
}

/// What a fallback sweep keeps and refuses, on the coarse pendulum of the first fallback
/// test (every estimate above an `[online] tolerance` of 1e-12):
/// - `--resume --fallback full` on a file of a sweep without the fallback runs again the
///   points it would not keep (all 3 here), and answers them with the full model; the
///   file is not resumed without the fallback (refused, left as it is);
/// - `merge` refuses parts of sweeps with different `--fallback`, naming the attribute;
/// - `--fallback full --no-estimate` is refused (exit 1, as `--strict --no-estimate`):
///   nothing could judge the answers;
/// - the pipeline's `[online] fallback = "full"` does not apply to `--validate`, which
///   says so and measures the reduced model at every point (`/fallback` 0).
#[test]
fn a_fallback_sweep_resumes_merges_and_refuses_what_it_cannot_judge() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let p = setup(d, 8, 0.1, 4, "[0.9, 1.0, 1.1]\ntolerance = 1e-12");
    let ps = p.to_str().unwrap();
    let out = d.join("s.h5");
    let o = out.to_str().unwrap();
    let (r, err) = run(&["sweep", ps, "-o", o]);
    assert_eq!(r.status.code(), Some(0), "{err}");
    let (r, err) = run(&["sweep", ps, "--fallback", "full", "--resume", "-o", o]);
    assert_eq!(r.status.code(), Some(0), "{err}");
    assert!(err.contains("0 of 3 load scales already finished, running 3"), "{err}");
    let fb = |f: &Path| flexrom::io::h5_open::open(f).unwrap().dataset("fallback").unwrap().read_raw::<u8>().unwrap();
    assert_eq!(fb(&out), vec![1, 1, 1]);
    // and not resumed without it: its full answers would stand in a file that says none
    let (r, err) = run(&["sweep", ps, "--resume", "-o", o]);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(err.contains("fallback: is \"full\": the sweep was written with --fallback full"), "{err}");
    assert_eq!(fb(&out), vec![1, 1, 1]);
    // parts of different fallbacks
    let (a, b, m) = (d.join("a.h5"), d.join("b.h5"), d.join("m.h5"));
    let (r, err) = run(&["sweep", ps, "--shard", "1/2", "--fallback", "full", "-o", a.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(0), "{err}");
    let (r, err) = run(&["sweep", ps, "--shard", "2/2", "-o", b.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(0), "{err}");
    let (r, err) = run(&["merge", a.to_str().unwrap(), b.to_str().unwrap(), "-o", m.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(err.contains("fallback") && err.contains("another --fallback"), "{err}");
    assert!(!m.exists());
    let (r, err) = run(&["sweep", ps, "--shard", "2/2", "--fallback", "full", "-o", b.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(0), "{err}");
    let (r, err) = run(&["merge", a.to_str().unwrap(), b.to_str().unwrap(), "-o", m.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(0), "{err}");
    assert_eq!(fb(&m), vec![1, 1, 1]);
    // nothing to judge with, and a validated sweep
    let (r, err) = run(&["sweep", ps, "--fallback", "full", "--no-estimate", "-o", d.join("n.h5").to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(err.contains("--fallback full needs the error estimate"), "{err}");
    let text = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, text.replace("tolerance = 1e-12", "tolerance = 1e-12\nfallback = \"full\"")).unwrap();
    let v = d.join("v.h5");
    let (r, err) = run(&["sweep", ps, "--validate", "-o", v.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(0), "{err}");
    assert!(err.contains("[online] fallback = \"full\" does not apply to a validated sweep"), "{err}");
    assert_eq!(fb(&v), vec![0, 0, 0]);
}
