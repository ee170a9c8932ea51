//! flexrom never deletes or overwrites what it did not create, and
//! writes atomically (docs/guarantees.md). Each test runs the release binary as a user would,
//! in a temporary folder, on a tiny copy of data/models/pendulum.toml (t_end shortened) and
//! a pipeline written here; nothing is compared with stored numbers. The expected outcome of
//! every case is the guarantee itself:
//! - refused report folders (`.`, `..`, `/`, `/usr`, the pipeline's folder, a folder holding user files,
//!   unmarked or marked): non-zero exit, an error naming the pipeline key `report`, and
//!   every file of the temporary tree (listing and bytes) exactly as before;
//! - outputs that are an input (the same path, through `..`, a symlink, a hard link) or not a
//!   regular file (fifo, folder, /dev/null): refused, the inputs byte for byte unchanged;
//! - an existing output file that flexrom did not write (a text file, an HDF5 file of
//!   another program), or wrote as another kind (a basis named as a result's `-o`): refused,
//!   every file byte for byte unchanged; flexrom's own file of the same kind is replaced;
//! - missing output folders are created by every writing command;
//! - SIGTERM / SIGINT during `run`: exit 143 / 130, no temporary file or folder left, the
//!   previous basis and report unchanged;
//! - SIGTERM during a long `simulate`: exit 143, the previous result file unchanged;
//! - a `run` whose sweep stage fails (Newton limited to 4 iterations without step cuts, at
//!   load scale 100 after training at 0.1) keeps the previous basis and report, and so does
//!   a `train` that fails.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn flexrom() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flexrom"))
}

fn pendulum_text() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/pendulum.toml")).unwrap()
}

/// The pendulum model with end time `t_end` (and extra `[time]` lines).
fn model_text(t_end: f64, extra_time: &str) -> String {
    let t = pendulum_text();
    assert!(t.contains("t_end = 1.1"));
    t.replace("t_end = 1.1", &format!("t_end = {t_end}\n{extra_time}"))
}

/// `proj/m.toml` and `proj/pipe.toml` in `root`, with the given `report`, online scales and
/// model; returns the pipeline path.
fn project(root: &Path, report: &str, online: &str, model: &str) -> PathBuf {
    let proj = root.join("proj");
    std::fs::create_dir_all(&proj).unwrap();
    std::fs::write(proj.join("m.toml"), model).unwrap();
    let p = proj.join("pipe.toml");
    std::fs::write(
        &p,
        format!(
            "model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"{report}\"\n[train]\nload_scales = [1.0]\n[reduction]\nvariant = \"galerkin\"\nmodes = {{ count = 4 }}\n\
             [online]\nload_scales = {online}\n[validate]\nload_scales = [1.0]\n"
        ),
    )
    .unwrap();
    p
}

fn run(args: &[&Path]) -> Output {
    let mut c = flexrom();
    for a in args {
        c.arg(a);
    }
    c.output().unwrap()
}

/// Every entry below `root`: path → bytes (files), `<dir>` / `<link …>` / `<other>`.
/// An entry that vanishes between its listing and its reading is left out: `kill_run` polls
/// while flexrom renames its temporary paths, and a rename there is not a fault.
fn snapshot(root: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn present<T>(r: std::io::Result<T>) -> Option<T> {
        match r {
            Ok(v) => Some(v),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => panic!("{e}"),
        }
    }
    fn walk(d: &Path, m: &mut BTreeMap<PathBuf, Vec<u8>>) {
        let Some(entries) = present(std::fs::read_dir(d)) else { return };
        for e in entries {
            let Some(e) = present(e) else { continue };
            let p = e.path();
            let Some(t) = present(std::fs::symlink_metadata(&p)).map(|m| m.file_type()) else { continue };
            let bytes = if t.is_symlink() {
                present(std::fs::read_link(&p)).map(|l| format!("<link {}>", l.display()).into_bytes())
            } else if t.is_dir() {
                walk(&p, m);
                Some(b"<dir>".to_vec())
            } else if t.is_file() {
                present(std::fs::read(&p))
            } else {
                Some(b"<other>".to_vec())
            };
            if let Some(b) = bytes {
                m.insert(p, b);
            }
        }
    }
    let mut m = BTreeMap::new();
    walk(root, &mut m);
    m
}

/// Entries below `root` whose name says they are flexrom's temporary or moved-aside paths.
fn leftovers(root: &Path) -> Vec<PathBuf> {
    snapshot(root)
        .into_keys()
        .filter(|p| p.file_name().unwrap().to_string_lossy().contains(".flexrom-"))
        .filter(|p| !p.ends_with(".flexrom-report"))
        .collect()
}

fn fails_with(o: &Output, words: &[&str]) -> String {
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(!o.status.success(), "expected a failure, got success: {err}");
    // 1: an error; 3: some load scales of a sweep failed (here the sweep stage of `run`)
    assert!(matches!(o.status.code(), Some(1) | Some(3)), "exit code: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for w in words {
        assert!(err.contains(w), "`{w}` missing from: {err}");
    }
    err
}

#[test]
fn report_folders_that_are_not_flexroms_own_are_refused_and_nothing_is_deleted() {
    let d = tempfile::tempdir().unwrap();
    let root = d.path();
    let model = model_text(0.05, "");
    // the user's files: a data folder, a marked report folder the user added a note to
    std::fs::create_dir_all(root.join("data/sub")).unwrap();
    std::fs::write(root.join("data/results.csv"), b"1,2,3\n").unwrap();
    std::fs::write(root.join("data/sub/notes.txt"), b"keep me").unwrap();
    std::fs::create_dir_all(root.join("marked")).unwrap();
    std::fs::write(
        root.join("marked/.flexrom-report"),
        "flexrom report folder: made by flexrom and replaced as a whole by `flexrom run`; files:\nsummary.md\n",
    )
    .unwrap();
    std::fs::write(root.join("marked/summary.md"), b"old").unwrap();
    std::fs::write(root.join("marked/mine.txt"), b"the user's").unwrap();
    std::fs::write(root.join("file.txt"), b"a file").unwrap();
    // a symlink to the user's data folder
    std::os::unix::fs::symlink(root.join("data"), root.join("link")).unwrap();
    for (report, why) in [
        (".", "names `.`"),
        ("..", "names `.`"),
        ("", "pipeline's own folder"),
        ("../proj", "pipeline's own folder"),
        ("../data", "without flexrom's mark"),
        ("../data/sub", "without flexrom's mark"),
        ("../marked", "mine.txt"),
        ("../link", "symbolic link"),
        ("../file.txt", "not a folder"),
        ("../file.txt/sub", "cannot be created"),
        ("/", "`/`"),
        ("/usr", "top-level"),
        ("../proj/..", "names `.`"),
    ] {
        let p = project(root, report, "[1.0]", &model);
        let before = snapshot(root);
        let o = run(&[Path::new("run"), &p]);
        let err = fails_with(&o, &["pipe.toml", "report", why]);
        assert!(err.lines().count() <= 2, "{report}: {err}");
        assert_eq!(snapshot(root), before, "report = {report:?}: files changed");
    }
}

#[test]
fn a_marked_report_is_replaced_and_a_failed_later_stage_keeps_the_previous_basis_and_report() {
    let d = tempfile::tempdir().unwrap();
    let root = d.path();
    let p = project(root, "rep", "[0.9, 1.0]", &model_text(0.05, ""));
    let o = run(&[Path::new("run"), &p]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rep = root.join("proj/rep");
    let mark = std::fs::read_to_string(rep.join(".flexrom-report")).unwrap();
    for f in ["summary.md", "sweep.h5", "validation.json", "singular_values.svg"] {
        assert!(rep.join(f).is_file() && mark.lines().any(|l| l == f), "{f}: {mark}");
    }
    // a second run replaces flexrom's own folder; files of a removed kind go with it
    std::fs::write(rep.join("probes_7.svg"), b"stale").unwrap();
    std::fs::write(rep.join(".flexrom-report"), format!("{mark}probes_7.svg\n")).unwrap();
    let o = run(&[Path::new("run"), &p]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!rep.join("probes_7.svg").exists() && rep.join("summary.md").is_file());
    assert!(leftovers(root).is_empty(), "{:?}", leftovers(root));

    // now a pipeline whose training passes (load 0.1) but whose sweep must fail: Newton gets
    // 4 iterations and no step cut, not enough at load scale 100
    let before = snapshot(root);
    let model = model_text(0.05, "max_iterations = 4\nmax_step_cuts = 0");
    std::fs::write(root.join("proj/m.toml"), &model).unwrap();
    let text = std::fs::read_to_string(&p)
        .unwrap()
        .replace("load_scales = [1.0]\n[reduction]", "load_scales = [0.1]\n[reduction]")
        .replace("[0.9, 1.0]", "[0.1, 100.0]");
    std::fs::write(&p, &text).unwrap();
    let mut expected = before.clone();
    expected.insert(root.join("proj/m.toml"), model.into_bytes());
    expected.insert(p.clone(), text.into_bytes());
    let o = run(&[Path::new("run"), &p]);
    let err = fails_with(&o, &["Newton failed"]);
    assert!(err.contains("[2/3]"), "the training stage passed: {err}");
    assert_eq!(snapshot(root), expected, "basis or report changed by a failed run");
    // `train` whose training run fails (load scale 100) keeps the previous basis too
    let text = std::fs::read_to_string(&p)
        .unwrap()
        .replace("load_scales = [0.1]\n[reduction]", "load_scales = [100.0]\n[reduction]");
    std::fs::write(&p, &text).unwrap();
    expected.insert(p.clone(), text.into_bytes());
    fails_with(&run(&[Path::new("train"), &p]), &["Newton failed"]);
    assert_eq!(snapshot(root), expected, "basis changed by a failed train");
}

/// [`project`] (report `rep`, online at 1.0, 0.05 s of the pendulum) trained: the pipeline,
/// model and basis paths.
fn trained_project(root: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let p = project(root, "rep", "[1.0]", &model_text(0.05, ""));
    let proj = root.join("proj");
    let o = run(&[Path::new("train"), &p]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (p, proj.join("m.toml"), proj.join("b.h5"))
}

/// Every case failed with its words, in an error of at most two lines.
fn refused_in_at_most_two_lines(cases: &[(Output, &[&str])]) {
    for (i, (o, words)) in cases.iter().enumerate() {
        let err = fails_with(o, words);
        assert!(err.lines().count() <= 2, "case {i}: {err}");
    }
}

#[test]
fn outputs_that_are_inputs_or_not_regular_files_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let root = d.path();
    let (p, model, basis) = trained_project(root);
    std::os::unix::fs::symlink(&model, root.join("to_model.h5")).unwrap();
    std::os::unix::fs::symlink("proj/b.h5", root.join("to_basis.h5")).unwrap();
    std::os::unix::fs::symlink(root.join("data"), root.join("to_dir.h5")).unwrap();
    std::os::unix::fs::symlink(root.join("nothing"), root.join("dangling.h5")).unwrap();
    std::fs::hard_link(&model, root.join("hard.h5")).unwrap();
    std::fs::create_dir(root.join("data")).unwrap();
    assert!(Command::new("mkfifo").arg(root.join("fifo")).status().unwrap().success());
    let before = snapshot(root);
    let sim = |out: &Path| run(&[Path::new("simulate"), &model, Path::new("-o"), out]);
    let online =
        |out: &Path| run(&[Path::new("online"), &p, Path::new("--load-scale"), Path::new("1"), Path::new("-o"), out]);
    let cases: Vec<(Output, &[&str])> = vec![
        (sim(&model), &["-o", "model file"]),
        (sim(&root.join("proj/../proj/./m.toml")), &["model file"]),
        (sim(&root.join("to_model.h5")), &["model file"]),
        (sim(&root.join("hard.h5")), &["model file"]),
        (sim(&root.join("fifo")), &["a fifo"]),
        (sim(&root.join("data")), &["a directory"]),
        (sim(&root.join("to_dir.h5")), &["symbolic link to a directory"]),
        (sim(&root.join("dangling.h5")), &["dangling"]),
        (sim(Path::new("/dev/null")), &["character device"]),
        (sim(&root.join("newdir/")), &["names a folder"]),
        (sim(&root.join("hard.h5/x.h5")), &["not a folder"]),
        (online(&basis), &["basis file"]),
        (online(&root.join("to_basis.h5")), &["basis file"]),
        (online(&p), &["pipeline file"]),
        (online(&model), &["model file"]),
        (run(&[Path::new("sweep"), &p, Path::new("-o"), &root.join("to_basis.h5")]), &["basis file"]),
        (run(&[Path::new("train"), &p, Path::new("--basis"), &model]), &["--basis", "model file"]),
        (run(&[Path::new("train"), &p, Path::new("--basis"), &root.join("fifo")]), &["a fifo"]),
    ];
    refused_in_at_most_two_lines(&cases);
    assert_eq!(snapshot(root), before, "an input or another file changed");
    // a basis path in the pipeline that is the model file
    std::fs::write(&p, std::fs::read_to_string(&p).unwrap().replace("basis = \"b.h5\"", "basis = \"m.toml\"")).unwrap();
    let before = snapshot(root);
    for cmd in ["train", "run"] {
        fails_with(&run(&[Path::new(cmd), &p]), &["pipe.toml", "basis", "model file"]);
        assert_eq!(snapshot(root), before);
    }
}

#[test]
fn existing_files_flexrom_did_not_write_or_wrote_as_another_kind_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let root = d.path();
    let (p, model, basis) = trained_project(root);
    let result = root.join("result.h5");
    assert!(run(&[Path::new("simulate"), &model, Path::new("-o"), &result]).status.success());
    let sweep = root.join("sweep.h5");
    assert!(run(&[Path::new("sweep"), &p, Path::new("-o"), &sweep]).status.success());
    let notes = root.join("notes.txt");
    std::fs::write(&notes, "the user's notes").unwrap();
    let empty = root.join("empty.h5");
    std::fs::write(&empty, "").unwrap();
    // an HDF5 file of another program: no `flexrom_file`, no `program_version` on its root
    let foreign = root.join("theirs.h5");
    let f = flexrom::io::h5_open::create(&foreign).unwrap();
    f.new_dataset::<f64>().shape(3).create("data").unwrap().write(&[1.0, 2.0, 3.0]).unwrap();
    drop(f);
    let before = snapshot(root);
    let sim = |out: &Path| run(&[Path::new("simulate"), &model, Path::new("-o"), out]);
    let online =
        |out: &Path| run(&[Path::new("online"), &p, Path::new("--load-scale"), Path::new("1"), Path::new("-o"), out]);
    let cases: Vec<(Output, &[&str])> = vec![
        (sim(&notes), &["-o", "not an HDF5 file flexrom wrote", "result files"]),
        (sim(&empty), &["not an HDF5 file flexrom wrote"]),
        (sim(&foreign), &["flexrom did not write"]),
        (sim(&basis), &["is a basis file", "only its own result files"]),
        (online(&sweep), &["is a sweep file", "result files"]),
        (run(&[Path::new("sweep"), &p, Path::new("-o"), &result]), &["is a result file", "sweep files"]),
        (run(&[Path::new("sweep"), &p, Path::new("-o"), &notes]), &["not an HDF5 file flexrom wrote"]),
        (run(&[Path::new("merge"), &sweep, Path::new("-o"), &foreign]), &["flexrom did not write"]),
        (
            run(&[Path::new("train"), &p, Path::new("--basis"), &result]),
            &["--basis", "is a result file", "basis files"],
        ),
        (run(&[Path::new("train"), &p, Path::new("--basis"), &notes]), &["--basis", "not an HDF5 file"]),
    ];
    refused_in_at_most_two_lines(&cases);
    assert_eq!(snapshot(root), before, "a file flexrom was told to replace changed");
    // a pipeline whose `basis` names the user's file: `train` and `run` refuse it
    std::fs::write(&p, std::fs::read_to_string(&p).unwrap().replace("basis = \"b.h5\"", "basis = \"../notes.txt\""))
        .unwrap();
    let before = snapshot(root);
    for cmd in ["train", "run"] {
        fails_with(&run(&[Path::new(cmd), &p]), &["pipe.toml", "basis", "not an HDF5 file flexrom wrote"]);
        assert_eq!(snapshot(root), before);
    }
    // flexrom's own files of the kind a command writes are replaced, as every rerun needs
    assert!(sim(&result).status.success());
    assert!(run(&[Path::new("sweep"), &p, Path::new("--basis"), &basis, Path::new("-o"), &sweep]).status.success());
    assert!(run(&[Path::new("train"), &p, Path::new("--basis"), &basis]).status.success());
    assert!(leftovers(root).is_empty(), "{:?}", leftovers(root));
}

#[test]
fn every_command_creates_missing_output_folders_and_follows_a_symlink_to_a_regular_file() {
    let d = tempfile::tempdir().unwrap();
    let root = d.path();
    let p = project(root, "../reports/r", "[1.0]", &model_text(0.05, ""));
    let model = root.join("proj/m.toml");
    let new = |s: &str| root.join("new").join(s).join("out.h5");
    let b = new("basis");
    assert!(run(&[Path::new("train"), &p, Path::new("--basis"), &b]).status.success());
    assert!(run(&[Path::new("simulate"), &model, Path::new("-o"), &new("sim")]).status.success());
    assert!(run(&[
        Path::new("online"),
        &p,
        Path::new("--basis"),
        &b,
        Path::new("--load-scale"),
        Path::new("1"),
        Path::new("-o"),
        &new("online")
    ])
    .status
    .success());
    assert!(run(&[Path::new("sweep"), &p, Path::new("--basis"), &b, Path::new("-o"), &new("sweep")]).status.success());
    for k in ["basis", "sim", "online", "sweep"] {
        assert!(flexrom::io::h5_open::open(new(k)).is_ok(), "{k}");
    }
    // `run` writes its report; a `sweep` without -o is refused (exit 2, naming -o) and leaves
    // the report's sweep.h5, which its summary.md describes, as it was
    let o = run(&[Path::new("run"), &p]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report_sweep = std::fs::read(root.join("reports/r/sweep.h5")).unwrap();
    let o = run(&[Path::new("sweep"), &p, Path::new("--basis"), &b]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--output <OUTPUT>"), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read(root.join("reports/r/sweep.h5")).unwrap(), report_sweep, "the report's sweep is kept");
    // a symlink to a regular file: the file it points to is replaced, the link stays
    let link = root.join("link.h5");
    std::os::unix::fs::symlink(new("sim"), &link).unwrap();
    assert!(run(&[Path::new("simulate"), &model, Path::new("-o"), &link, Path::new("--t-end"), Path::new("0.02")])
        .status
        .success());
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    let t = flexrom::io::h5_open::open(new("sim")).unwrap().dataset("t").unwrap().read_1d::<f64>().unwrap();
    assert_eq!(t.len(), 5, "0.02 s in steps of 0.005 s: the new result is behind the link");
    assert!(leftovers(root).is_empty(), "{:?}", leftovers(root));
}

/// Starts `flexrom run` on `p`, waits until stderr shows `stage` and the temporary paths
/// `wanted` (name fragments) exist below `root`, sends `signal` and returns the exit status
/// and stderr.
fn kill_run(root: &Path, p: &Path, stage: &str, wanted: &[&str], signal: &str) -> (Option<i32>, String) {
    let mut child = flexrom().arg("run").arg(p).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let start = Instant::now();
    let mut err = String::new();
    loop {
        while let Ok(l) = rx.try_recv() {
            err.push_str(&l);
            err.push('\n');
        }
        let names: Vec<String> =
            leftovers(root).iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
        if err.contains(stage) && wanted.iter().all(|w| names.iter().any(|n| n.contains(w))) {
            break;
        }
        assert!(child.try_wait().unwrap().is_none(), "the run ended before it could be stopped: {err}");
        assert!(start.elapsed() < Duration::from_secs(120), "no temporary files seen: {err}");
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(Command::new("kill").arg(format!("-{signal}")).arg(child.id().to_string()).status().unwrap().success());
    let status = child.wait().unwrap();
    std::thread::sleep(Duration::from_millis(100));
    while let Ok(l) = rx.try_recv() {
        err.push_str(&l);
        err.push('\n');
    }
    (status.code(), err)
}

#[test]
fn a_killed_run_leaves_no_temporary_files_and_the_previous_outputs_unchanged() {
    let d = tempfile::tempdir().unwrap();
    let root = d.path();
    let p = project(root, "rep", "[1.0]", &model_text(0.05, ""));
    let o = run(&[Path::new("run"), &p]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // a long run: 1000 validated sweep points of 0.2 s (each a full and a reduced run)
    let p = project(root, "rep", "\"0.5:1.5:1000\"", &model_text(0.2, ""));
    let before = snapshot(root);
    // SIGTERM in the sweep: the temporary report folder and the new basis (renamed into its
    // temporary name) both exist
    let (code, err) = kill_run(root, &p, "[2/3]", &[".rep.flexrom-tmp-", ".b.h5.flexrom-tmp-"], "TERM");
    assert_eq!(code, Some(143), "{err}");
    assert!(err.contains("SIGTERM") && !err.contains("panicked"), "{err}");
    assert!(leftovers(root).is_empty(), "{:?}", leftovers(root));
    assert_eq!(snapshot(root), before, "the previous basis and report are unchanged");
    // SIGINT during training: only the temporary report folder exists yet
    let p = project(root, "rep", "[1.0]", &model_text(20.0, ""));
    let before = snapshot(root);
    let (code, err) = kill_run(root, &p, "[1/3]", &[".rep.flexrom-tmp-"], "INT");
    assert_eq!(code, Some(130), "{err}");
    assert!(leftovers(root).is_empty(), "{:?}", leftovers(root));
    assert_eq!(snapshot(root), before);
}

#[test]
fn a_killed_simulate_keeps_the_previous_result() {
    let d = tempfile::tempdir().unwrap();
    let root = d.path();
    let model = root.join("m.toml");
    // 1200 steps of a 1600-element pendulum: about a second of work (1.0 s measured with
    // the adaptive Newton start, 2026-11-27; 400 elements took 0.27 s with it), stopped after
    // 300 ms (a longer run is no good: the pendulum stops itself by t ≈ 7–10 s, its step
    // halvings over budget)
    let text = model_text(6.0, "");
    assert!(text.contains("elements = 50\n"), "the shipped pendulum's mesh");
    std::fs::write(&model, text.replace("elements = 50\n", "elements = 1600\n")).unwrap();
    let out = root.join("out.h5");
    // the previous result: flexrom's own (it replaces no other file), 0.01 s of the same model
    let short = flexrom().arg("simulate").arg(&model).arg("-o").arg(&out).args(["--t-end", "0.01"]).output().unwrap();
    assert!(short.status.success(), "{}", String::from_utf8_lossy(&short.stderr));
    let before = snapshot(root);
    let mut child = flexrom().arg("simulate").arg(&model).arg("-o").arg(&out).stderr(Stdio::piped()).spawn().unwrap();
    std::thread::sleep(Duration::from_millis(300));
    assert!(child.try_wait().unwrap().is_none(), "simulate ended before it could be stopped");
    assert!(Command::new("kill").arg("-TERM").arg(child.id().to_string()).status().unwrap().success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(143), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(snapshot(root), before);
}

/// An output named for another format is refused before anything runs (it would be HDF5
/// whatever its name says), naming the option, the extension and, for `.csv`, `--csv`; no
/// file appears. A name without an extension is the user's choice and is written.
#[test]
fn outputs_named_for_another_format_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("m.toml");
    std::fs::write(&model, model_text(0.01, "")).unwrap();
    for (name, words) in [("arm.csv", &["-o", ".csv", "HDF5", "--csv"][..]), ("arm.vtu", &["-o", ".vtu", "HDF5"][..])] {
        let out = dir.path().join(name);
        let o = flexrom().args(["simulate", "-q"]).arg(&model).arg("-o").arg(&out).output().unwrap();
        fails_with(&o, words);
        assert!(!out.exists(), "{name} was written");
    }
    let plain = dir.path().join("run1");
    let o = flexrom().args(["simulate", "-q"]).arg(&model).arg("-o").arg(&plain).output().unwrap();
    assert!(o.status.success() && plain.exists(), "{}", String::from_utf8_lossy(&o.stderr));
}
