//! Basis files checked against the model (docs/guarantees-robust.md): a tiny hyper-reduced pendulum
//! basis is trained into a temporary folder, then bad copies are crafted with the hdf5 crate
//! and each must be refused by `flexrom online` with a one-line error naming the file and the
//! dataset, a non-zero exit that is not a panic (101), and no output file.
//!
//! Where the expectations come from:
//! - the good basis is accepted (control: the checks do not refuse what `train` writes);
//! - each crafted defect is one a damaged or foreign file can have: a shifted reference (x_ref must be the
//!   model's consistent initial state to 1e-9 relative, src/io/basis_check.rs), integer and
//!   float32 modes, non-orthonormal modes (‖VᵀV − I‖ ≤ 1e-8), NaN, an ECSW weight of 1e-300
//!   (below the 1e-8 floor; trained pendulum weights are 0.93–5.2), an element index out of
//!   range and a repeated one, a content hash copied from another basis of the same model,
//!   a model fingerprint copied from a basis of another model, an external link, a soft link,
//!   a dataset in external storage, a version-1 file, a declared shape of 29 GB (refused
//!   before reading);
//! - a pipeline whose [reduction] changed since training still runs, with one warning line;
//! - whole-system bases (orthonormal only as the stacked [V; V_λ]) pass the library check.

use flexrom::io::basis_check;
use flexrom::pipeline::Pipeline;
use flexrom::training::train::train_and_write;
use ndarray::{Array1, Array2};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The tests of this file run one at a time: a child `flexrom` forked while the other test
/// has an HDF5 file open inherits its descriptor and with it HDF5's file lock, and the
/// other test's next open of that file then fails with "unable to lock file".
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn flexrom() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flexrom"))
}

fn pendulum_text(elements: usize, t_end: f64, density: f64) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/pendulum.toml"))
        .unwrap()
        .replace("elements = 50", &format!("elements = {elements}"))
        .replace("t_end = 1.1", &format!("t_end = {t_end}"))
        .replace("density = 5540.0", &format!("density = {density}"))
}

const PIPE: &str = r#"
[train]
load_scales = [1.0]
[reduction]
variant = "galerkin"
modes = { count = 4 }
hyper = { tolerance = 1e-2 }
"#;

/// Writes a model and a pipeline into `dir` (names prefixed by `tag`), trains; returns the
/// pipeline path (its basis is `<tag>.h5`).
fn trained(dir: &Path, tag: &str, density: f64, pipe: &str) -> PathBuf {
    std::fs::write(dir.join(format!("{tag}_model.toml")), pendulum_text(8, 0.1, density)).unwrap();
    let p = dir.join(format!("{tag}.toml"));
    std::fs::write(
        &p,
        format!("model = \"{tag}_model.toml\"\nbasis = \"{tag}.h5\"\nreport = \"{tag}_report\"\n{pipe}"),
    )
    .unwrap();
    train_and_write(&Pipeline::load(&p).unwrap(), &dir.join(format!("{tag}.h5"))).unwrap();
    p
}

/// A copy of `good` named `name`, edited by `edit` through the hdf5 crate.
fn craft(good: &Path, name: &str, edit: impl FnOnce(&hdf5::File)) -> PathBuf {
    let bad = good.with_file_name(name);
    std::fs::copy(good, &bad).unwrap();
    let f = flexrom::io::h5_open::open_rw(&bad).unwrap();
    edit(&f);
    f.close().unwrap();
    bad
}

/// Replaces dataset `name` (e.g. "basis/modes") with `data`.
fn replace<T: hdf5::H5Type, D: ndarray::Dimension>(f: &hdf5::File, name: &str, data: &ndarray::Array<T, D>) {
    f.unlink(name).unwrap();
    f.new_dataset_builder().with_data(data).create(name).unwrap();
}

fn read2(f: &hdf5::File, name: &str) -> Array2<f64> {
    f.dataset(name).unwrap().read_2d::<f64>().unwrap()
}

fn read1(f: &hdf5::File, name: &str) -> Array1<f64> {
    f.dataset(name).unwrap().read_1d::<f64>().unwrap()
}

/// `online` with `basis`: returns (success, stderr); asserts no panic and no stray output.
fn online(pipe: &Path, basis: &Path) -> (bool, String) {
    let out = basis.with_extension("out.h5");
    let _ = std::fs::remove_file(&out);
    let o = flexrom()
        .args([
            "online",
            pipe.to_str().unwrap(),
            "--load-scale",
            "1",
            "-o",
            out.to_str().unwrap(),
            "--basis",
            basis.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_ne!(o.status.code(), Some(101), "panic: {err}");
    assert!(o.status.code().is_some(), "killed by a signal: {err}");
    assert!(!err.contains("panicked"), "{err}");
    if !o.status.success() {
        assert!(!out.exists(), "no output on error");
    }
    (o.status.success(), err)
}

fn refused(pipe: &Path, basis: &Path, needles: &[&str]) {
    let (ok, err) = online(pipe, basis);
    assert!(!ok, "{} was accepted: {err}", basis.display());
    assert_eq!(err.trim().lines().count(), 1, "one-line error: {err}");
    let name = basis.file_name().unwrap().to_str().unwrap();
    assert!(err.contains(name), "names the file {name}: {err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` in: {err}");
    }
}

/// The warning lines of `err`, but for the one saying which route is faster: that depends
/// on the machine's timing, not on the basis checks (tests/full_route.rs checks it).
fn warnings(err: &str) -> Vec<&str> {
    err.lines().filter(|l| l.starts_with("warning:") && !l.contains("not faster than the full one")).collect()
}

#[test]
fn crafted_basis_files_are_refused_naming_file_and_dataset() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let pipe = trained(d, "a", 5540.0, PIPE);
    let good = d.join("a.h5");
    let (ok, err) = online(&pipe, &good);
    assert!(ok, "the trained basis is accepted: {err}");
    assert!(warnings(&err).is_empty(), "{err}");

    let bad = craft(&good, "shifted.h5", |f| {
        let mut r = read1(f, "basis/reference");
        r[5] += 1e-3;
        replace(f, "basis/reference", &r);
    });
    refused(&pipe, &bad, &["basis/reference", "initial state"]);

    let bad = craft(&good, "intmodes.h5", |f| {
        let m = read2(f, "basis/modes").mapv(|v| (v * 1000.0).round() as i64);
        replace(f, "basis/modes", &m);
    });
    refused(&pipe, &bad, &["basis/modes", "integer", "f64"]);

    let bad = craft(&good, "f32modes.h5", |f| {
        let m = read2(f, "basis/modes").mapv(|v| v as f32);
        replace(f, "basis/modes", &m);
    });
    refused(&pipe, &bad, &["basis/modes", "4-byte float"]);

    let bad = craft(&good, "skewed.h5", |f| {
        let mut m = read2(f, "basis/modes");
        m.column_mut(1).mapv_inplace(|v| v * 1.001);
        replace(f, "basis/modes", &m);
    });
    refused(&pipe, &bad, &["basis/modes", "orthonormal"]);

    // a shape that would need 36 × 10⁸ × 8 bytes = 29 GB to read: refused before reading
    let bad = craft(&good, "huge.h5", |f| {
        let rows = read2(f, "basis/modes").nrows();
        f.unlink("basis/modes").unwrap();
        f.new_dataset::<f64>().chunk((1, 1024)).shape((rows, 100_000_000)).create("basis/modes").unwrap();
    });
    refused(&pipe, &bad, &["basis/modes", "shape"]);

    let bad = craft(&good, "nan.h5", |f| {
        let mut m = read2(f, "basis/modes");
        m[[3, 0]] = f64::NAN;
        replace(f, "basis/modes", &m);
    });
    refused(&pipe, &bad, &["basis/modes", "finite"]);

    let bad = craft(&good, "tiny_weight.h5", |f| {
        let mut w = read1(f, "hyper/weights");
        w[0] = 1e-300;
        replace(f, "hyper/weights", &w);
    });
    refused(&pipe, &bad, &["hyper/weights", "1e-300"]);

    let bad = craft(&good, "huge_weight.h5", |f| {
        let mut w = read1(f, "hyper/weights");
        w[0] = 1e300;
        replace(f, "hyper/weights", &w);
    });
    refused(&pipe, &bad, &["hyper/weights"]);

    let elements =
        flexrom::io::h5_open::open(&good).unwrap().dataset("hyper/elements").unwrap().read_1d::<u64>().unwrap();
    assert!(elements.len() >= 2, "the test needs two sampled elements: {elements}");
    let bad = craft(&good, "far_element.h5", |f| {
        let mut e = elements.clone();
        *e.last_mut().unwrap() = 8;
        replace(f, "hyper/elements", &e);
    });
    refused(&pipe, &bad, &["hyper/elements", "element 8", "8 elements"]);
    let bad = craft(&good, "twice.h5", |f| {
        let mut e = elements.clone();
        e[1] = e[0];
        replace(f, "hyper/elements", &e);
    });
    refused(&pipe, &bad, &["hyper/elements", "each element once"]);

    // another basis of the same model (5 modes): its content hash does not fit this content
    let other = trained(d, "b", 5540.0, &PIPE.replace("count = 4", "count = 5"));
    let other_hash = flexrom::io::h5::read_attr_str(
        &flexrom::io::h5_open::open(other.with_extension("h5")).unwrap(),
        "content_hash",
    )
    .unwrap();
    let bad = craft(&good, "copied_hash.h5", |f| {
        f.delete_attr("content_hash").unwrap();
        flexrom::io::h5::attr_str(f, "content_hash", &other_hash).unwrap();
    });
    refused(&pipe, &bad, &["content_hash", "copied"]);
    // a basis of another model (denser beam, same sizes) given this model's fingerprint
    trained(d, "c", 6000.0, PIPE);
    let mine =
        flexrom::io::h5::read_attr_str(&flexrom::io::h5_open::open(&good).unwrap(), "model_fingerprint").unwrap();
    let bad = craft(&d.join("c.h5"), "copied_fingerprint.h5", |f| {
        f.delete_attr("model_fingerprint").unwrap();
        flexrom::io::h5::attr_str(f, "model_fingerprint", &mine).unwrap();
    });
    // (same geometry, so the same reference state: only the content hash can tell)
    refused(&pipe, &bad, &["copied_fingerprint.h5", "content_hash"]);

    // links: an external link in place of the modes, a soft link in place of the weights
    let outside = d.join("outside.h5");
    std::fs::copy(&good, &outside).unwrap();
    let bad = craft(&good, "external_link.h5", |f| {
        f.unlink("basis/modes").unwrap();
        f.group("basis").unwrap().link_external(outside.to_str().unwrap(), "/basis/modes", "modes").unwrap();
    });
    refused(&pipe, &bad, &["basis/modes", "external"]);
    let bad = craft(&good, "soft_link.h5", |f| {
        f.unlink("hyper/weights").unwrap();
        f.group("hyper").unwrap().link_soft("/snapshot_t", "weights").unwrap();
    });
    refused(&pipe, &bad, &["hyper/weights", "soft link"]);
    let bad =
        craft(&good, "extra_link.h5", |f| f.link_external(outside.to_str().unwrap(), "/snapshots", "notes").unwrap());
    refused(&pipe, &bad, &["notes", "external"]);
    // a dataset whose data lives in an external raw file
    let bad = craft(&good, "external_storage.h5", |f| {
        let r = read1(f, "basis/reference");
        f.unlink("basis/reference").unwrap();
        let raw = d.join("reference.bin");
        let ds = f
            .new_dataset::<f64>()
            .shape(r.len())
            .external(raw.to_str().unwrap(), 0, 8 * r.len())
            .create("basis/reference")
            .unwrap();
        ds.write(&r).unwrap();
    });
    refused(&pipe, &bad, &["basis/reference", "external file"]);

    let bad = craft(&good, "v1.h5", |f| {
        f.delete_attr("schema_version").unwrap();
        flexrom::io::h5::attr_u64(f, "schema_version", 1).unwrap();
    });
    refused(&pipe, &bad, &["schema_version", "train"]);

    // the pipeline's [reduction] changed since training: a warning, and the run goes on
    let text = std::fs::read_to_string(&pipe).unwrap();
    std::fs::write(&pipe, text.replace("tolerance = 1e-2", "tolerance = 5e-3")).unwrap();
    let (ok, err) = online(&pipe, &good);
    assert!(ok, "{err}");
    let w = warnings(&err);
    assert_eq!(w.len(), 1, "{err}");
    assert!(w[0].contains("a.h5") && w[0].contains("settings"), "{err}");
    // comments and number spelling do not count as a change
    std::fs::write(
        &pipe,
        text.replace("tolerance = 1e-2", "tolerance = 0.01").replace("[train]", "# same settings\n[train]"),
    )
    .unwrap();
    let (ok, err) = online(&pipe, &good);
    assert!(ok && warnings(&err).is_empty(), "{err}");
}

/// Whole-system (orthonormal as the stacked [V; V_λ]) and raw-snapshot (zero reference)
/// bases pass the library check; the good basis read back carries both hashes.
#[test]
fn whole_system_and_raw_bases_pass_the_check() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    for (tag, pipe) in [
        (
            "ws",
            PIPE.replace("variant = \"galerkin\"", "variant = \"whole-system\"")
                .replace("hyper = { tolerance = 1e-2 }", ""),
        ),
        ("raw", PIPE.replace("[reduction]", "snapshots = \"raw\"\n[reduction]")),
    ] {
        let p = Pipeline::load(trained(d, tag, 5540.0, &pipe)).unwrap();
        let s = basis_check::check(&d.join(format!("{tag}.h5")), &p.model, Some(&p.settings_hash())).unwrap();
        assert_eq!(s.content_hash.len(), 64);
        assert_eq!(s.settings_hash, p.settings_hash());
        if tag == "ws" {
            // V alone is not orthonormal: the check must use the stacked matrix
            let g = s.basis.modes.t().dot(&s.basis.modes);
            assert!(
                (&g - &Array2::<f64>::eye(g.nrows())).iter().any(|v| v.abs() > 1e-8),
                "V alone should not be orthonormal here"
            );
        } else {
            assert!(s.basis.reference.iter().all(|v| *v == 0.0));
        }
    }
}
