//! Training that says what it checked (docs/greedy-training.md, "What the basis file
//! records"): where greedy's converged held-out check measured an error above the
//! tolerance (within the model's own sensitivity there, so its score met T), the basis file
//! records that check in words (`/training` attribute `held_out_note`) and `online` and
//! `validate` repeat it once, not once per load.
//!
//! Checks, with where each expected value comes from:
//! - `the_note_is_recorded_only_when_the_check_was_above_t_and_repeated_once`: the thesis
//!   pendulum coarsened to 20 elements and t_end = 0.4 s (as tests/measures.rs, so the loop
//!   runs in seconds) trained greedily to 3e-3: its held-out error is within T (the stop rule
//!   of a calm model), so no `held_out_note` is written and `validate` says nothing of a
//!   held-out error; a basis file without `/training` notes (as written before them) reads
//!   none. With the attribute set
//!   as `train` writes it where the error was above T (a sentence of the form
//!   `greedy::above_tolerance_note` builds), `validate` at the pipeline's two loads and
//!   `online` at one print it exactly once each, naming the basis file.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn flexrom(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flexrom")).args(args).env("HDF5_USE_FILE_LOCKING", "FALSE").output().unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn setup(dir: &Path) -> PathBuf {
    let model = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/pendulum.toml"))
        .unwrap()
        .replace("elements = 50", "elements = 20")
        .replace("t_end = 1.1", "t_end = 0.4");
    std::fs::write(dir.join("model.toml"), model).unwrap();
    let p = dir.join("pipe.toml");
    let body = "model = \"model.toml\"\nbasis = \"basis.h5\"\nreport = \"report\"\n[train]\ngreedy = { range = [0.5, 1.5], tolerance = 3e-3, max_runs = 8 }\n[validate]\nload_scales = [0.8, 1.2]\n";
    std::fs::write(&p, body).unwrap();
    p
}

#[test]
fn the_note_is_recorded_only_when_the_check_was_above_t_and_repeated_once() {
    let dir = tempfile::tempdir().unwrap();
    let pipe = setup(dir.path());
    let p = pipe.to_str().unwrap();
    let basis = dir.path().join("basis.h5");
    let o = flexrom(&["train", p]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(!text(&o.stderr).contains("is above the tolerance"), "{}", text(&o.stderr));
    let notes = |path: &Path| -> Vec<String> {
        flexrom::io::estimator_file::read_training_notes(path).unwrap().into_iter().map(|n| n.1).collect()
    };
    assert!(flexrom::io::h5_open::open(&basis).unwrap().group("training").unwrap().attr("held_out_note").is_err());
    let o = flexrom(&["validate", p, "--no-dense"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(!text(&o.stderr).contains("greedy training: held-out"), "{}", text(&o.stderr));
    // a basis file with neither attribute (as files written before them)
    let old = dir.path().join("old.h5");
    std::fs::copy(&basis, &old).unwrap();
    {
        let f = flexrom::io::h5_open::open_rw(&old).unwrap();
        let g = f.group("training").unwrap();
        for name in ["held_out_note", "estimate_note"] {
            if g.attr(name).is_ok() {
                g.delete_attr(name).unwrap();
            }
        }
    }
    assert!(notes(&old).is_empty());

    // the attribute as `train` writes it where the held-out error was above T
    let note = "held-out rel_error 2.93e-3 at λ = 1.3 is above the tolerance 3e-3; the model's own sensitivity there is 1.9e-2";
    {
        let f = flexrom::io::h5_open::open_rw(&basis).unwrap();
        let g = f.group("training").unwrap();
        let v: hdf5::types::VarLenUnicode = note.parse().unwrap();
        g.new_attr::<hdf5::types::VarLenUnicode>().create("held_out_note").unwrap().write_scalar(&v).unwrap();
    }
    assert_eq!(notes(&basis).first().map(String::as_str), Some(note));
    let o = flexrom(&["validate", p, "--no-dense"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert_eq!(err.matches(note).count(), 1, "once, not per load: {err}");
    assert!(err.contains("basis.h5: greedy training: held-out rel_error"), "{err}");
    let out = dir.path().join("r.h5");
    let o = flexrom(&["online", p, "--load-scale", "0.9", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(text(&o.stderr).matches(note).count(), 1, "{}", text(&o.stderr));
}
