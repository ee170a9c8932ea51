//! The native module links what the command line links (the root build.rs: static OpenBLAS
//! with its LAPACK, libgfortran), except HDF5: Debian's static libhdf5.a is not
//! position-independent, which a shared object needs, so the module takes Debian's shared
//! libhdf5_serial. Named here, it comes on the link line before the `-lhdf5` of
//! hdf5-metno-sys, which then finds every symbol defined and takes nothing from the archive.
//! h5py's own HDF5 (a wheel's private copy) never meets it: Python loads extension modules
//! with RTLD_LOCAL, so each module resolves HDF5 from its own dependencies.

#[path = "../build.rs"]
#[allow(dead_code)]
mod cli;

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-changed=../build.rs");
    cli::link_native_libraries();
    if std::env::var("TARGET").unwrap_or_default() == "x86_64-unknown-linux-gnu" {
        println!("cargo::rustc-link-lib=dylib=hdf5_serial");
    }
}
