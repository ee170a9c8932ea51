//! Links OpenBLAS (with its LAPACK) and the libraries under Debian's static HDF5 statically,
//! so that start-up loads no shared library beyond glibc, libgcc and libgfortran
//! (docs/startup.md: a dynamic libhdf5 drags in libcurl, OpenSSL, Kerberos and LDAP, ~7 ms).
//!
//! HDF5 itself is found by hdf5-metno-sys through `HDF5_DIR` (.cargo/config.toml), a folder
//! whose `lib/` holds only `libhdf5.a`, so its `-lhdf5` resolves to the archive. That archive
//! references zlib and libsz/libaec (the szip filter) and, in its ROS3 driver, libcurl and
//! libcrypto; nothing in flexrom or hdf5-metno calls the ROS3 driver, so the linker never takes
//! those objects from the archive and curl/OpenSSL are not needed.
//!
//! The libraries are given as link arguments, not `rustc-link-lib`: those land on the linker's
//! command line after every crate's libraries, i.e. after `-lhdf5`, which a static archive
//! needs (the linker resolves an archive's symbols only from archives that follow it).

use std::path::Path;
use std::process::Command;

/// Debian's multiarch library folder and the pthread flavour of OpenBLAS inside it
/// (libopenblas-dev installs it; libopenblas.a holds BLAS and LAPACK).
const LIB_DIR: &str = "/usr/lib/x86_64-linux-gnu";
const OPENBLAS_DIR: &str = "/usr/lib/x86_64-linux-gnu/openblas-pthread";

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    link_native_libraries();
}

/// Emits the link arguments above (also called by the Python module's build script,
/// python/build.rs, which links HDF5 itself).
///
/// With them goes `--wrap=open`: the `open(2)` calls of the objects linked statically —
/// libhdf5's file drivers among them — go to `__wrap_open` (src/io/open_cloexec.c, compiled
/// here and linked into every program), which adds `O_CLOEXEC`, so that no child process
/// started at any moment inherits a descriptor of an HDF5 file with its lock.
pub fn link_native_libraries() {
    let target = std::env::var("TARGET").unwrap_or_default();
    if target != "x86_64-unknown-linux-gnu" {
        // other systems: leave it to the user's link flags (docs/startup.md)
        println!("cargo::warning=flexrom's build.rs knows only Debian's x86_64 library layout; BLAS/LAPACK and HDF5 dependencies are not linked");
        return;
    }
    for (dir, file) in
        [(OPENBLAS_DIR, "libopenblas.a"), (LIB_DIR, "libz.a"), (LIB_DIR, "libsz.a"), (LIB_DIR, "libaec.a")]
    {
        let path = Path::new(dir).join(file);
        if !path.exists() {
            panic!(
                "{} not found: install the Debian packages libopenblas-dev (with its default libopenblas-pthread-dev) and libhdf5-dev (`make deps` does)",
                path.display()
            );
        }
    }

    let mut args = vec![format!("-L{OPENBLAS_DIR}"), "-Wl,-Bstatic".to_string()];
    // OpenBLAS: BLAS + LAPACK; HDF5's compression filters: szip (libsz over libaec) and zlib
    args.extend(["-lopenblas", "-lsz", "-laec", "-lz"].map(String::from));
    // LAPACK is compiled Fortran: a few objects (dgesvd, dormqr, …) call libgfortran's
    // string helpers. Its static archive comes with libgfortran-12-dev; without it the
    // shared libgfortran.so.5 (a dependency of libopenblas0) is linked instead.
    let static_gfortran = gcc_file("libgfortran.a");
    if let Some(path) = &static_gfortran {
        println!("cargo::rerun-if-changed={path}");
        args.push("-lgfortran".into());
        args.push("-lquadmath".into());
    }
    args.push("-Wl,-Bdynamic".into());
    if static_gfortran.is_none() {
        args.push("-l:libgfortran.so.5".into());
    }
    args.extend(["-lm", "-lpthread", "-ldl"].map(String::from));
    args.push(open_cloexec());
    args.push("-Wl,--wrap=open".into());
    for arg in args {
        println!("cargo::rustc-link-arg={arg}");
    }
}

/// src/io/open_cloexec.c compiled into `OUT_DIR`: the object file's path (the package's
/// own source, or the root package's for the Python module in python/).
fn open_cloexec() -> String {
    let dir = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let source = ["src/io/open_cloexec.c", "../src/io/open_cloexec.c"]
        .map(|p| Path::new(&dir).join(p))
        .into_iter()
        .find(|p| p.exists())
        .expect("src/io/open_cloexec.c is in the source tree");
    let object = Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("open_cloexec.o");
    println!("cargo::rerun-if-changed={}", source.display());
    match Command::new("cc").args(["-c", "-O2", "-fPIC", "-o"]).arg(&object).arg(&source).status() {
        Ok(s) if s.success() => object.display().to_string(),
        other => panic!("cannot compile {} with `cc` (gcc): {other:?}", source.display()),
    }
}

/// The path of a file in the C compiler's library search path, if it is there
/// (`cc -print-file-name` echoes the bare name when it is not).
fn gcc_file(name: &str) -> Option<String> {
    let out = Command::new("cc").arg(format!("-print-file-name={name}")).output().ok()?;
    let path = String::from_utf8(out.stdout).ok()?.trim().to_string();
    (Path::new(&path).is_absolute() && Path::new(&path).exists()).then_some(path)
}
