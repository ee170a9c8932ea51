//! Small helpers over the `hdf5` crate: atomic file creation and typed attributes.

use crate::error::{Error, Result};
use hdf5::types::VarLenUnicode;
use std::path::{Path, PathBuf};

/// Creates `path` atomically: `fill` writes into a temporary file beside it, which is renamed
/// over `path` only when `fill` succeeds, so a failed run never leaves a half-written file
/// nor destroys a previous good one.
pub fn write_atomically(path: &Path, fill: impl FnOnce(&hdf5::File) -> Result<()>) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(Error::input(path, "output path", format!("directory `{}` does not exist", dir.display())));
    }
    let name = path.file_name().ok_or_else(|| Error::input(path, "output path", "is not a file name"))?;
    // unique per process and call: two writes of one path in one process (threads, or a
    // test that trains twice) never share a temporary file
    static CALLS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = dir.join(format!(".{}.tmp-{}-{call}", name.to_string_lossy(), std::process::id()));
    let result = (|| {
        let file = hdf5::File::create(&tmp).map_err(|e| Error::hdf5(path, format!("cannot create: {e}")))?;
        fill(&file)?;
        file.flush().map_err(|e| Error::hdf5(path, e))?;
        drop(file);
        std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
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
