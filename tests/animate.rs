//! `flexrom animate`: a GIF of a result's motion, read back with the gif crate (frames,
//! size, the comment that marks it flexrom's), `--compare`, and the refusals: an `-o` not
//! ending in .gif, a file there flexrom did not write, an input that is not a result file.

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

fn model(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data/models").join(name).display().to_string()
}

/// (frames, width, height) of a GIF.
fn gif_info(path: &Path) -> (usize, u16, u16) {
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut d = opts.read_info(std::fs::File::open(path).unwrap()).unwrap();
    let mut frames = 0;
    while d.read_next_frame().unwrap().is_some() {
        frames += 1;
    }
    (frames, d.width(), d.height())
}

/// The pendulum over 0.05 s (dt 0.005: 11 instants) gives 11 frames of the asked size;
/// `--max-frames 4` 4; a reduced-looking second run overlays; the comment marks the file.
#[test]
fn a_result_becomes_a_gif() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).display().to_string();
    ok(&["simulate", &model("pendulum.toml"), "-o", &p("a.h5"), "--t-end", "0.05", "-q"]);
    ok(&["simulate", &model("pendulum.toml"), "-o", &p("b.h5"), "--t-end", "0.08", "--load-scale", "1.2", "-q"]);
    ok(&["animate", &p("a.h5"), "-o", &p("a.gif"), "--size", "400x300"]);
    assert_eq!(gif_info(Path::new(&p("a.gif"))), (11, 400, 300));
    let bytes = std::fs::read(p("a.gif")).unwrap();
    assert!(bytes.ends_with(b"flexrom animation\x00\x3b"), "the comment before the trailer");
    // replaced: flexrom's own
    ok(&["animate", &p("a.h5"), "-o", &p("a.gif"), "--max-frames", "4", "--compare", &p("b.h5"), "--size", "300"]);
    let (frames, w, _) = gif_info(Path::new(&p("a.gif")));
    assert_eq!((frames, w), (4, 300));
}

/// The refusals, each naming the file and what is wrong, exit code 1, nothing written.
#[test]
fn bad_outputs_and_inputs_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).display().to_string();
    ok(&["simulate", &model("pendulum.toml"), "-o", &p("a.h5"), "--t-end", "0.01", "-q"]);
    let refused = |args: &[&str], words: &[&str]| {
        let o = flexrom(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        for w in words {
            assert!(err.contains(w), "{args:?}: `{w}` not in {err}");
        }
    };
    refused(&["animate", &p("a.h5"), "-o", &p("a.png")], &["a.png", "-o", ".gif"]);
    std::fs::write(p("mine.gif"), b"GIF89a the user's own").unwrap();
    refused(&["animate", &p("a.h5"), "-o", &p("mine.gif")], &["mine.gif", "not an animation flexrom wrote"]);
    assert_eq!(std::fs::read(p("mine.gif")).unwrap(), b"GIF89a the user's own");
    refused(&["animate", &model("pendulum.toml"), "-o", &p("m.gif")], &["pendulum.toml", "not an HDF5 file"]);
    refused(&["animate", &p("none.h5"), "-o", &p("m.gif")], &["none.h5", "no such file"]);
    ok(&["modes", &model("pendulum.toml"), "--count", "2", "-o", &p("modes.h5"), "-q"]);
    refused(&["animate", &p("modes.h5"), "-o", &p("m.gif")], &["modes.h5", "flexrom_file", "not a result file"]);
    refused(&["animate", &p("a.h5"), "-o", &p("a.h5.gif"), "--fps", "0"], &["--fps"]);
    assert!(!Path::new(&p("m.gif")).exists() && !Path::new(&p("a.h5.gif")).exists());
}
