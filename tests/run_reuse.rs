//! `flexrom run` reuses a current basis: run twice and the second run neither trains nor
//! touches the basis file (same inode, same bytes) and says so in one line; a changed
//! training key, a changed model, a basis that fails its own checks or `--retrain` train
//! again. A comment added to the model file changes no fingerprint: still reused.

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const REUSED: &str = "is current (model and training keys unchanged): reusing it; --retrain to train again";

/// A 10-element pendulum run for 0.1 s: a pipeline small enough to run four times.
const MODEL: &str = r#"
[time]
t_end = 0.1
dt = 0.005
rho_inf = 1.0

[[bodies]]
name = "beam"
start = [0.0, 0.0]
angle = 0.0
length = 1.2
elements = 10
density = 5540.0
area = 1.8e-3
inertia = 1.215e-8
youngs_modulus = 0.7e9

[[joints]]
type = "ground_pin"
body = "beam"
node = "start"

[[loads]]
type = "gravity"
g = [0.0, -9.81]
scaled = true

[[probes]]
name = "tip"
body = "beam"
node = "end"
"#;

fn pipeline(modes: &str) -> String {
    format!(
        "model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n\n[train]\nload_scales = [0.9, 1.1]\nsnapshots = \"reference\"\n\n[reduction]\nvariant = \"galerkin\"\nmodes = {modes}\n\n[online]\nload_scales = [1.0]\n\n[validate]\nload_scales = [1.0]\n"
    )
}

fn run(dir: &Path, extra: &[&str]) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .current_dir(dir)
        .args(["run", "p.toml", "--no-dense"])
        .args(extra)
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The basis file's inode and bytes: a rewrite (temporary file renamed over it) changes the
/// inode, whatever the bytes.
fn basis(dir: &Path) -> (u64, Vec<u8>) {
    let b: PathBuf = dir.join("b.h5");
    (std::fs::metadata(&b).unwrap().ino(), std::fs::read(&b).unwrap())
}

#[test]
fn run_reuses_a_current_basis_and_trains_when_anything_it_was_trained_from_changed() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    std::fs::write(dir.join("m.toml"), MODEL).unwrap();
    std::fs::write(dir.join("p.toml"), pipeline("{ count = 4 }")).unwrap();

    let first = run(dir, &[]);
    assert!(!stderr(&first).contains(REUSED), "nothing to reuse yet: {}", stderr(&first));
    let trained = basis(dir);

    // the same model and training keys: reused, the file untouched, the summary says so
    let second = run(dir, &[]);
    let err = stderr(&second);
    let said: Vec<&str> = err.lines().filter(|l| l.contains(REUSED)).map(str::trim).collect();
    assert_eq!(said, [format!("p.toml: basis b.h5 {REUSED}")], "{}", stderr(&second));
    assert!(!stderr(&second).contains("[1/3] train"), "{}", stderr(&second));
    assert_eq!(basis(dir), trained, "the basis file left as it was");
    let summary = std::fs::read_to_string(dir.join("r/summary.md")).unwrap();
    assert!(summary.contains("(reused: current, trained "), "{summary}");

    // a comment and a key-order change of the model: the same fingerprint, still reused
    std::fs::write(dir.join("m.toml"), format!("# a note\n{MODEL}")).unwrap();
    assert!(stderr(&run(dir, &[])).contains(REUSED));
    assert_eq!(basis(dir), trained);

    // [online] and [validate] are no training keys: still reused
    std::fs::write(
        dir.join("p.toml"),
        pipeline("{ count = 4 }").replace("[online]\nload_scales = [1.0]", "[online]\nload_scales = [0.95, 1.05]"),
    )
    .unwrap();
    assert!(stderr(&run(dir, &[])).contains(REUSED));
    assert_eq!(basis(dir), trained);

    // --retrain: trained again, the file replaced
    let o = run(dir, &["--retrain"]);
    assert!(!stderr(&o).contains(REUSED) && stderr(&o).contains("[1/3] train"), "{}", stderr(&o));
    let retrained = basis(dir);
    assert_ne!(retrained.0, trained.0, "a new file renamed into place");

    // a training key changed ([reduction] modes): trained again
    std::fs::write(dir.join("p.toml"), pipeline("{ count = 3 }")).unwrap();
    let o = run(dir, &["-v"]);
    assert!(!stderr(&o).contains(REUSED), "{}", stderr(&o));
    let fewer = basis(dir);
    assert_ne!(fewer.0, retrained.0);
    // and back: the basis on disk is the 3-mode one, not current for 4 modes
    std::fs::write(dir.join("p.toml"), pipeline("{ count = 4 }")).unwrap();
    assert!(!stderr(&run(dir, &[])).contains(REUSED));

    // the model changed (its density): trained again
    std::fs::write(dir.join("m.toml"), MODEL.replace("density = 5540.0", "density = 5600.0")).unwrap();
    assert!(!stderr(&run(dir, &[])).contains(REUSED));
    let current = basis(dir);
    assert!(stderr(&run(dir, &[])).contains(REUSED), "current again");
    assert_eq!(basis(dir), current);

    // a basis that fails its own checks (one mode entry edited: its content hash differs) is
    // never reused, whatever its fingerprints say: trained again
    {
        let f = flexrom::io::h5_open::open_rw(dir.join("b.h5")).unwrap();
        let d = f.dataset("basis/modes").unwrap();
        let mut v = d.read_2d::<f64>().unwrap();
        v[[4, 0]] += 1e-3;
        d.write(&v).unwrap();
    }
    let o = run(dir, &[]);
    assert!(!stderr(&o).contains(REUSED), "{}", stderr(&o));
    assert_ne!(basis(dir).0, current.0);
}
