//! Nothing is committed once a stop was asked for (`TempPath::commit` in
//! src/io/atomic/temp_path.rs, `swap_in_dir` in src/io/atomic/swap.rs): with the process's
//! stop flag raised, which is what Python's Ctrl-C does (`flexrom::interrupt`), an atomic
//! write of bytes, of an HDF5 file and of a folder ends with `Error::Interrupted`, the
//! previous file or folder stays byte for byte and no temporary path is left; with the flag
//! lowered the same writes replace them. Why it matters: greedy training reads a reduced run
//! the stop ended as an infinite estimate and goes on, so without this a stopped training
//! could still write a basis made from cut-short runs. A test binary of its own, as the flag
//! is process-wide.

use flexrom::io::atomic::{swap_in_dir, write_bytes_atomically, TempPath};

#[test]
fn a_stop_asked_for_commits_nothing_and_keeps_the_previous_outputs() {
    let d = tempfile::tempdir().unwrap();
    let (file, h5, dir) = (d.path().join("out.bin"), d.path().join("out.h5"), d.path().join("report"));
    std::fs::write(&file, b"previous").unwrap();
    let h5_with = |x: f64| {
        flexrom::io::h5::write_atomically(&h5, |f| {
            flexrom::io::h5::attr_f64(f, "x", x).map_err(|e| flexrom::Error::hdf5(&h5, e))
        })
    };
    h5_with(1.0).unwrap();
    let previous_h5 = std::fs::read(&h5).unwrap();
    std::fs::create_dir(&dir).unwrap();
    std::fs::write(dir.join("a.txt"), b"previous report").unwrap();
    let write_dir = || -> flexrom::Result<()> {
        let tmp = TempPath::dir_for(&dir)?;
        std::fs::write(tmp.path().join("a.txt"), b"new report").unwrap();
        swap_in_dir(tmp, |_| Ok(()))
    };
    let write_h5 = || h5_with(2.0);

    flexrom::interrupt::request();
    let stopped = [write_bytes_atomically(&file, b"new"), write_h5(), write_dir()];
    flexrom::interrupt::clear();
    for (i, r) in stopped.iter().enumerate() {
        assert!(matches!(r, Err(flexrom::Error::Interrupted)), "write {i}: {r:?}");
    }
    assert_eq!(std::fs::read(&file).unwrap(), b"previous");
    assert_eq!(std::fs::read(&h5).unwrap(), previous_h5);
    assert_eq!(std::fs::read(dir.join("a.txt")).unwrap(), b"previous report");
    assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 3, "no temporary path left");

    write_bytes_atomically(&file, b"new").unwrap();
    write_h5().unwrap();
    write_dir().unwrap();
    assert_eq!(std::fs::read(&file).unwrap(), b"new");
    assert_ne!(std::fs::read(&h5).unwrap(), previous_h5);
    assert_eq!(std::fs::read(dir.join("a.txt")).unwrap(), b"new report");
    assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 3);
}
