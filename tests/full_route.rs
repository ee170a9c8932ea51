//! The exact route where reduction does not pay (docs/basis-and-sweep.md, "Full or
//! reduced"), through the `flexrom` command.
//!
//! Checks, and where each expectation comes from:
//! - `a_full_sweep_is_simulate_at_every_load`: `sweep --full` needs no basis file; its
//!   probes are, bit for bit, those of `flexrom simulate` at each load of the file's
//!   `/load_scales` (the same full model and integrator: module docs of `pipeline::sweep`),
//!   and so are the Newton iterations and factorizations; the file says `route = "full"`,
//!   holds no `/reduced_q`, `/rom_seconds` or basis attributes, a positive `/full_seconds`
//!   and NaN estimates (docs/file-formats.md); its CSV has the full sweep's columns (docs/cli.md);
//!   `--full` with `--validate`, `--basis`, `--continuation`, `--no-estimate` or `--strict`
//!   is a usage error (exit 2: nothing to validate, no basis, no estimate);
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

    let f = hdf5::File::open(&out).unwrap();
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
        let g = hdf5::File::open(&r).unwrap();
        for name in &names {
            let swept = f.dataset(&format!("probes/{name}")).unwrap().read::<f64, ndarray::Ix3>().unwrap();
            let alone = g.dataset(&format!("probes/{name}")).unwrap().read_2d::<f64>().unwrap();
            let swept = swept.index_axis(ndarray::Axis(0), k).to_owned();
            assert_eq!(bits(swept.as_slice().unwrap()), bits(alone.as_slice().unwrap()), "{name} at {x}");
        }
        let attr = |name: &str| g.attr(name).unwrap().read_scalar::<u64>().unwrap();
        assert_eq!((newton[k], factorizations[k]), (attr("newton_iterations"), attr("factorizations")), "{x}");
    }

    // nothing to validate, no basis, no estimate: refused before any run
    for extra in [&["--validate"][..], &["--basis", "b.h5"], &["--continuation"], &["--no-estimate"], &["--strict"]] {
        let mut args = vec!["sweep", s(&p), "--full", "-o", s(&out)];
        args.extend_from_slice(extra);
        let (o, err) = run(&args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains("--full") && err.contains(extra[0]), "{err}");
    }
}
