//! Every HDF5 file flexrom opens or creates, opened here so that its descriptor is not
//! inherited by child processes.
//!
//! libhdf5 opens a file with a plain `open(2)` (no `O_CLOEXEC`) and, with its file locking
//! on (the default: `HDF5_USE_FILE_LOCKING` unset), `flock`s it: shared to read, exclusive
//! to write. An `flock` belongs to the open file description, which a child process shares
//! through an inherited descriptor, and keeps after the parent closed the file. A program
//! that starts a process while one of its threads has a file open (a test harness running
//! tests beside each other, a Python host calling `subprocess`) thus left the file locked
//! for as long as the child ran: a basis read right after it was written failed with
//! "unable to lock file", the writer's exclusive lock still held by an unrelated child.
//! Marking the descriptor close-on-exec as soon as the file is open closes it in every
//! program a child `exec`s. A child started in the microseconds between libhdf5's `open`
//! and the mark would still inherit it (a test harness met it): where libhdf5 is linked
//! statically (flexrom's programs and tests, build.rs), the linker sends its `open` calls to
//! `__wrap_open` (src/io/open_cloexec.c), which opens with `O_CLOEXEC`, and no such moment is
//! left. The Python
//! module links the shared libhdf5, whose descriptors only the mark closes.

use crate::error::{Error, Result};
use std::path::Path;

/// Opens the HDF5 file at `path` read-only, its descriptor not inherited.
pub fn open(path: impl AsRef<Path>) -> hdf5::Result<hdf5::File> {
    not_inherited(hdf5::File::open(path)?)
}

/// Opens the HDF5 file at `path` to read and write, its descriptor not inherited.
pub fn open_rw(path: impl AsRef<Path>) -> hdf5::Result<hdf5::File> {
    not_inherited(hdf5::File::open_rw(path)?)
}

/// Creates (truncates) the HDF5 file at `path`, its descriptor not inherited.
pub fn create(path: impl AsRef<Path>) -> hdf5::Result<hdf5::File> {
    not_inherited(hdf5::File::create(path)?)
}

/// [`open`] with the error a message shows: the file named and why it cannot be read
/// ([`unreadable`]: a lock held by another handle, or not HDF5).
pub fn open_to_read(path: &Path) -> Result<hdf5::File> {
    open(path).map_err(|e| Error::input(path, "(file)", unreadable(&e)))
}

/// Marks the descriptor of `f` close-on-exec (POSIX files of libhdf5's default `sec2`
/// driver; other drivers, and other systems, keep what they have).
fn not_inherited(f: hdf5::File) -> hdf5::Result<hdf5::File> {
    #[cfg(unix)]
    if matches!(f.access_plist()?.get_driver()?, hdf5::file::FileDriver::Sec2) {
        let mut handle: *mut std::ffi::c_void = std::ptr::null_mut();
        hdf5::sync::sync(|| {
            // SAFETY: `H5Fget_vfd_handle` on an open file id, under hdf5-metno's library
            // lock, writes the driver's handle into `handle`; for the sec2 driver it points at
            // the driver's `int` descriptor, which lives while the file is open (it is, `f`).
            hdf5::h5check(unsafe { hdf5_sys::h5f::H5Fget_vfd_handle(f.id(), hdf5_sys::h5p::H5P_DEFAULT, &mut handle) })
        })?;
        if handle.is_null() {
            return Err(hdf5::Error::from("libhdf5 gave no file descriptor"));
        }
        // SAFETY: `handle` points at the sec2 driver's open descriptor (above).
        let fd = unsafe { *handle.cast::<std::ffi::c_int>() };
        // SAFETY: `fcntl` on a descriptor this process has open, reading then setting its
        // flags; no memory is passed.
        let ok = unsafe {
            let flags = libc::fcntl(fd, libc::F_GETFD);
            flags >= 0 && libc::fcntl(fd, libc::F_SETFD, flags | libc::FD_CLOEXEC) == 0
        };
        if !ok {
            return Err(hdf5::Error::from(format!(
                "cannot mark its descriptor close-on-exec: {}",
                std::io::Error::last_os_error()
            )));
        }
    }
    Ok(f)
}

/// Whether an HDF5 open failed on a lock another handle holds (HDF5's file locking).
pub fn is_locked(e: &hdf5::Error) -> bool {
    e.to_string().contains("unable to lock file")
}

/// Why an HDF5 file could not be opened, for a message that follows the file's name: a lock
/// held by another open handle (an h5py `File` in the same Python process, another program
/// writing it) said as such, anything else as a file that is not readable HDF5.
pub fn unreadable(e: &hdf5::Error) -> String {
    let text = e.to_string();
    if is_locked(e) {
        format!("is locked by another open handle (an h5py File still open, or a program writing it): close it first, or set HDF5_USE_FILE_LOCKING=FALSE to share it read-only ({text})")
    } else {
        format!("is not a readable HDF5 file (truncated or of another format?): {text}")
    }
}
