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

/// A pipeline in `dir` on the shipped pendulum, trained at the one load 1.0 with raw
/// snapshots (one full run, seconds), its basis `b.h5` inside `dir`.
fn pipeline(dir: &Path) -> String {
    let p = dir.join("p.toml");
    let text = format!(
        "model = \"{}\"\nbasis = \"{}\"\nreport = \"{}\"\n\n[train]\nload_scales = [1.0]\nsnapshots = \"raw\"\n\n[reduction]\nvariant = \"galerkin\"\nmodes = {{ ratio = 0.1 }}\n",
        model("pendulum.toml"),
        dir.join("b.h5").display(),
        dir.join("report").display()
    );
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// A reduced sweep animated at one of its loads is `online`'s run at that load: the same
/// instants and, reconstructed on the basis the sweep names, the same coordinates (the
/// same reduced run, `x = x_ref + V z` both ways: equal to round-off, 1e-12 m on a 1.2 m
/// pendulum), so the GIFs have the same frames and size; `--point` picks the same run as
/// its load scale, `--compare` overlays a result file. Refused, naming the file and what to
/// do: a load not in the file (the nearest named), a sweep file without a load, a load with
/// no sweep file, a full sweep (probes only: `simulate … --load-scale` instead), an absent
/// basis and a damaged one.
#[test]
fn a_reduced_sweep_is_animated_at_one_of_its_loads() {
    use flexrom::report::motion::Motion;
    use flexrom::workflows::sweep::SweepPick;
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).display().to_string();
    let pipe = pipeline(dir.path());
    ok(&["train", &pipe, "-q"]);
    ok(&["online", &pipe, "--load-scale", "1.0", "-o", &p("on.h5"), "-q"]);
    ok(&["sweep", &pipe, "--load-scales", "0.9:1.1:3", "-o", &p("sw.h5"), "--no-estimate", "-q"]);
    let limits = flexrom::limits::Limits::from_env_or_defaults();
    let (on, _) = Motion::open(Path::new(&p("on.h5")), None, &limits).unwrap();
    let (sw, is_sweep) = Motion::open(Path::new(&p("sw.h5")), Some(SweepPick::LoadScale(1.0)), &limits).unwrap();
    assert!(is_sweep);
    assert_eq!(on.t(), sw.t(), "the same time grid");
    for k in [0, on.t().len() / 2, on.t().len() - 1] {
        let (a, b) = (on.q_row(k).unwrap(), sw.q_row(k).unwrap());
        let diff = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        assert!(diff <= 1e-12, "instant {k}: the sweep's coordinates differ from online's by {diff}");
    }
    ok(&["animate", &p("on.h5"), "-o", &p("on.gif"), "--size", "400"]);
    ok(&["animate", &p("sw.h5"), "--load-scale", "1.0", "-o", &p("sw.gif"), "--size", "400"]);
    assert_eq!(gif_info(Path::new(&p("sw.gif"))), gif_info(Path::new(&p("on.gif"))), "frames and extent");
    ok(&["animate", &p("sw.h5"), "--point", "1", "-o", &p("pt.gif"), "--size", "400"]);
    assert_eq!(std::fs::read(p("pt.gif")).unwrap(), std::fs::read(p("sw.gif")).unwrap(), "point 1 is load 1.0");
    ok(&["animate", &p("sw.h5"), "--load-scale", "1.1", "--compare", &p("on.h5"), "-o", &p("c.gif")]);

    let refused = |args: &[&str], words: &[&str]| {
        let o = flexrom(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        for w in words {
            assert!(err.contains(w), "{args:?}: `{w}` not in {err}");
        }
    };
    refused(&["animate", &p("sw.h5"), "--load-scale", "1.05", "-o", &p("x.gif")], &["sw.h5", "nearest", "1 and 1.1"]);
    refused(&["animate", &p("sw.h5"), "-o", &p("x.gif")], &["sw.h5", "sweep file", "--load-scale"]);
    refused(&["animate", &p("on.h5"), "--load-scale", "1.0", "-o", &p("x.gif")], &["on.h5", "--load-scale"]);
    refused(&["animate", &p("sw.h5"), "--point", "3", "-o", &p("x.gif")], &["sw.h5", "--point", "it has 3"]);
    ok(&["sweep", &pipe, "--full", "--load-scales", "1.0:1.1:2", "-o", &p("full.h5"), "-q"]);
    refused(
        &["animate", &p("full.h5"), "--load-scale", "1.0", "-o", &p("x.gif")],
        &["full.h5", "route", "flexrom simulate", "--load-scale"],
    );
    std::fs::rename(p("b.h5"), p("moved.h5")).unwrap();
    refused(&["animate", &p("sw.h5"), "--load-scale", "1.0", "-o", &p("x.gif")], &["sw.h5", "b.h5", "does not exist"]);
    std::fs::write(p("b.h5"), b"not a basis").unwrap();
    refused(&["animate", &p("sw.h5"), "--load-scale", "1.0", "-o", &p("x.gif")], &["b.h5", "not a readable HDF5 file"]);
    assert!(!Path::new(&p("x.gif")).exists());
}
