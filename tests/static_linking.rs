//! The executable's start-up as docs/startup.md describes it: HDF5 and
//! OpenBLAS linked statically, so the dynamic loader maps none of libhdf5, libopenblas or the
//! network and security libraries the shared Debian libhdf5 drags in (libcurl, OpenSSL,
//! GnuTLS, Kerberos, LDAP), and OpenBLAS starts no worker thread.
//!
//! Expected values: the list of forbidden names is the one `ldd` printed for the dynamically
//! linked build (docs/startup.md); the thread count 1 is the main thread alone, which is what
//! flexrom's constructor (`OPENBLAS_NUM_THREADS=1` before OpenBLAS's) gives.

use std::process::Command;

const EXE: &str = env!("CARGO_BIN_EXE_flexrom");

#[test]
fn no_shared_hdf5_blas_or_network_libraries() {
    let out = Command::new("ldd").arg(EXE).output().expect("ldd runs (Debian's libc-bin)");
    assert!(out.status.success(), "ldd {EXE} failed: {}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    // the listing is real: glibc is there
    assert!(text.contains("libc.so.6"), "ldd output without libc:\n{text}");
    for name in [
        "libhdf5",
        "libopenblas",
        "libcurl",
        "libssl",
        "libcrypto",
        "libgnutls",
        "libkrb5",
        "libgssapi",
        "libldap",
        "libsz",
        "libaec",
        "libz.so",
    ] {
        assert!(!text.contains(name), "{EXE} still loads {name}:\n{text}");
    }
}

/// OpenBLAS's constructor would start one worker per extra core (the dynamically linked build
/// had 2 threads here on 2 cores: its worker sleeps after its time-out but stays); with
/// flexrom's constructor it starts none. The thread count is read from `/proc/PID/status`
/// while a long run (the 5000-element pendulum) is under way, then the run is killed.
#[test]
fn openblas_starts_no_worker_thread() {
    use std::time::Duration;
    // the 5000-element pendulum runs long enough (seconds) to be caught running
    let model = concat!(env!("CARGO_MANIFEST_DIR"), "/data/models/pendulum_5000.toml");
    let dir = tempfile::tempdir().unwrap();
    let mut child = Command::new(EXE)
        .args(["simulate", model, "-o"])
        .arg(dir.path().join("p.h5"))
        .env_remove("OPENBLAS_NUM_THREADS")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    // every thread's name; the ones flexrom starts on purpose are named `flexrom-…`: the
    // SIGINT/SIGTERM/SIGHUP clean-up (`flexrom-signals`, src/io/atomic.rs) and, while the
    // run starts, the result file's writer (`flexrom-result-file`, src/io/result_file.rs;
    // the kernel keeps 15 bytes of a name)
    let names: Option<Vec<String>> = std::fs::read_dir(format!("/proc/{}/task", child.id())).ok().map(|d| {
        d.filter_map(|e| e.ok())
            .filter_map(|e| std::fs::read_to_string(e.path().join("comm")).ok())
            .map(|c| c.trim().to_string())
            .collect()
    });
    child.kill().ok();
    child.wait().ok();
    let names = names.expect("flexrom still running after 0.3 s");
    assert!(names.iter().any(|n| n == "flexrom-signals"), "{names:?}");
    let others: Vec<&String> =
        names.iter().filter(|n| !["flexrom-signals", "flexrom-result-"].contains(&n.as_str())).collect();
    assert_eq!(others.len(), 1, "flexrom runs these threads besides its own: {others:?}");
}
