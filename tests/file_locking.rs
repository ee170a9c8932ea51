//! HDF5's file locking (on by default) and child processes: a file written while a child
//! process starts can be read back as soon as it is written (src/io/h5_open.rs).
//!
//! libhdf5 `flock`s every file it opens (exclusive to write). Opened without close-on-exec,
//! a child started while the file is open inherits the lock and keeps it after the parent
//! closed the file: a read-back then failed with "unable to lock file" while the child ran
//! (tests beside each other in one harness, a Python host calling `subprocess`). flexrom's
//! programs link libhdf5 statically with its `open` calls wrapped to add `O_CLOEXEC`
//! (build.rs, src/io/open_cloexec.c), so that even libhdf5's own open, called directly, leaves
//! no descriptor to a child; flexrom's opens also mark the descriptor (the Python module's
//! shared libhdf5 has only that). The check runs in a child test process with
//! `HDF5_USE_FILE_LOCKING` removed (the test environment may turn locking off).
//!
//! A second test keeps it so: no HDF5 file is opened or created in src/ but through
//! `io::h5_open`.

use std::path::Path;
use std::process::{Child, Command};

/// A child process that outlives the writes (killed by the test).
fn sleeper() -> Child {
    Command::new("sleep").arg("30").spawn().expect("`sleep` starts")
}

fn stop(mut c: Child) {
    c.kill().ok();
    c.wait().ok();
}

#[test]
#[ignore = "run by `a_file_written_while_a_child_starts_reads_back` with HDF5's locking on"]
fn written_while_a_child_starts_with_locking_on() {
    let d = tempfile::tempdir().unwrap();
    // libhdf5's own create, its `open` wrapped: the child inherits no descriptor, and the
    // file is read back while it runs (without the wrap: "unable to lock file")
    let plain = d.path().join("plain.h5");
    let f = hdf5::File::create(&plain).unwrap();
    let child = sleeper();
    drop(f);
    let read = hdf5::File::open(&plain);
    stop(child);
    read.expect("libhdf5's own descriptor is not inherited");

    // flexrom's atomic write, a child started inside it, then its reader
    let ours = d.path().join("ours.h5");
    let mut child = None;
    flexrom::io::h5::write_atomically(&ours, |f| {
        flexrom::io::h5::attr_str(f, "x", "y").map_err(|e| flexrom::Error::hdf5(&ours, e))?;
        child = Some(sleeper());
        Ok(())
    })
    .unwrap();
    let read = flexrom::io::h5_open::open_to_read(&ours);
    stop(child.expect("started"));
    let f = read.unwrap();
    assert_eq!(flexrom::io::h5::read_attr_str(&f, "x").unwrap(), "y");
}

#[test]
fn a_file_written_while_a_child_starts_reads_back() {
    let out = Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "written_while_a_child_starts_with_locking_on", "--ignored", "--nocapture"])
        .env_remove("HDF5_USE_FILE_LOCKING")
        .output()
        .unwrap();
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success() && text.contains("1 passed"), "{text}");
}

/// Each way of opening gives a close-on-exec descriptor, libhdf5's own open too (its
/// `open(2)` wrapped, build.rs).
#[test]
fn descriptors_are_close_on_exec() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("a.h5");
    let close_on_exec = |f: &hdf5::File| {
        let mut handle: *mut std::ffi::c_void = std::ptr::null_mut();
        // SAFETY: under hdf5-metno's library lock; the sec2 driver's handle of a file open
        // here points at its descriptor
        let fd = hdf5::sync::sync(|| unsafe {
            assert!(hdf5_sys::h5f::H5Fget_vfd_handle(f.id(), hdf5_sys::h5p::H5P_DEFAULT, &mut handle) >= 0);
            *handle.cast::<std::ffi::c_int>()
        });
        // SAFETY: reading the flags of an open descriptor
        unsafe { libc::fcntl(fd, libc::F_GETFD) & libc::FD_CLOEXEC != 0 }
    };
    let plain = hdf5::File::create(&p).unwrap();
    assert!(close_on_exec(&plain), "libhdf5's own create");
    drop(plain);
    // one at a time: a second open of a file still open shares its descriptor
    let f = flexrom::io::h5_open::create(&p).unwrap();
    assert!(close_on_exec(&f), "create");
    drop(f);
    let f = flexrom::io::h5_open::open_rw(&p).unwrap();
    assert!(close_on_exec(&f), "open_rw");
    drop(f);
    let f = flexrom::io::h5_open::open(&p).unwrap();
    assert!(close_on_exec(&f), "open");
}

/// The code of a source file before its test module (`#[cfg(test)]`, last by the
/// project's convention).
fn code_of(text: &str) -> &str {
    text.split("#[cfg(test)]").next().unwrap_or(text)
}

fn sources(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            sources(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn hdf5_files_are_opened_through_h5_open() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    assert!(files.len() > 50, "the source tree is read");
    let mut found = Vec::new();
    for p in files.iter().filter(|p| !p.ends_with("io/h5_open.rs")) {
        let text = std::fs::read_to_string(p).unwrap();
        for call in ["hdf5::File::open", "hdf5::File::create", "hdf5::File::append", "hdf5::File::with_options"] {
            if code_of(&text).contains(call) {
                found.push(format!("{}: {call}", p.display()));
            }
        }
    }
    assert!(found.is_empty(), "open HDF5 files with flexrom::io::h5_open: {found:?}");
    // the check sees a call where there is one
    assert!(code_of(&std::fs::read_to_string(src.join("io/h5_open.rs")).unwrap()).contains("hdf5::File::open("));
}
