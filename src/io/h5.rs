//! Small helpers over the `hdf5` crate: atomic file creation and typed attributes.

use crate::error::{Error, Result};
use hdf5::types::VarLenUnicode;
use std::path::Path;

/// Creates `path` atomically and durably: `fill` writes into a temporary file beside it
/// (unique name, created exclusively by flexrom, registered for removal on SIGINT/SIGTERM), which is
/// closed, `fdatasync`ed and renamed over `path` only when `fill` succeeds, then the folder is
/// `fsync`ed ([`super::atomic`]). A failed run never leaves a half-written file nor destroys a
/// previous good one; a missing folder is created.
pub fn write_atomically(path: &Path, fill: impl FnOnce(&hdf5::File) -> Result<()>) -> Result<()> {
    super::atomic::write_file_atomically(path, |tmp| {
        // the empty temporary file is flexrom's own (created exclusively): truncated here
        let file = hdf5::File::create(tmp).map_err(|e| Error::hdf5(path, format!("cannot create: {e}")))?;
        fill(&file)?;
        file.flush().map_err(|e| Error::hdf5(path, e))?;
        // closed before the fdatasync and the rename (the last handle closes the file)
        drop(file);
        Ok(())
    })
    .map_err(|e| match e {
        Error::Hdf5 { file, problem } => Error::Hdf5 { file, problem: short_write_error(&problem) },
        other => other,
    })
}

/// HDF5's write errors span lines (time, temporary file name, buffer address, …); the
/// system's message is what the user can act on: "cannot write: No space left on device
/// (errno 28)".
fn short_write_error(problem: &str) -> String {
    let field = |key: &str| {
        problem
            .split(key)
            .nth(1)
            .and_then(|r| r.split(['\'', ',']).find(|s| !s.trim().is_empty()))
            .map(|s| s.trim().to_string())
    };
    match (field("error message = '"), field("errno = ")) {
        (Some(msg), Some(errno)) => format!("cannot write: {msg} (errno {errno})"),
        (Some(msg), None) => format!("cannot write: {msg}"),
        _ => problem.split_whitespace().collect::<Vec<_>>().join(" "),
    }
}

pub fn attr_str(loc: &hdf5::Location, name: &str, value: &str) -> hdf5::Result<()> {
    let v: VarLenUnicode = value.parse().map_err(|e| hdf5::Error::from(format!("{e:?}")))?;
    loc.new_attr::<VarLenUnicode>().create(name)?.write_scalar(&v)
}

pub fn attr_f64(loc: &hdf5::Location, name: &str, value: f64) -> hdf5::Result<()> {
    loc.new_attr::<f64>().create(name)?.write_scalar(&value)
}

pub fn attr_u64(loc: &hdf5::Location, name: &str, value: u64) -> hdf5::Result<()> {
    loc.new_attr::<u64>().create(name)?.write_scalar(&value)
}

pub fn read_attr_str(loc: &hdf5::Location, name: &str) -> hdf5::Result<String> {
    Ok(loc.attr(name)?.read_scalar::<VarLenUnicode>()?.as_str().to_string())
}

pub fn read_attr_f64(loc: &hdf5::Location, name: &str) -> hdf5::Result<f64> {
    loc.attr(name)?.read_scalar::<f64>()
}

#[cfg(test)]
mod tests {
    #[test]
    fn hdf5_write_errors_are_one_line_with_the_system_message() {
        let p = "H5Dwrite(): can't write data: file write failed: time = Wed Nov 25 02:33:25 2026\n, filename = '/tmp/x/.out.h5.flexrom-tmp-1-0', file descriptor = 5, errno = 28, error message = 'No space left on device', buf = 0x55, total write size = 32424";
        assert_eq!(super::short_write_error(p), "cannot write: No space left on device (errno 28)");
        assert_eq!(super::short_write_error("a\n b"), "a b");
    }
}
