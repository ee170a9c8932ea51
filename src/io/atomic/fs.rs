//! File-system functions of the atomic writes: path checks (a final path must name an entry
//! and be replaceable), symlinks followed, and `fsync` of files, folders and trees.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// False for a path whose last segment is `.`, `..`, empty or the root (`Path::components`
/// drops a trailing `.`, so the text is split here).
pub fn names_an_entry(p: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let last = p.as_os_str().as_bytes().split(|&b| b == b'/').rfind(|seg| !seg.is_empty());
    !matches!(last, None | Some(b".") | Some(b".."))
}

/// The folder and file name of a target path (`""` parent → `.`).
pub(super) fn split(target: &Path) -> Result<(PathBuf, String)> {
    let name = match target.file_name() {
        Some(n) if names_an_entry(target) => n,
        _ => return Err(Error::input(target, "output path", "does not end in a file name")),
    };
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok((dir, name.to_string_lossy().into_owned()))
}

/// Creates `dir` and its missing ancestors, `fsync`ing the parent of each one made so the
/// new entries survive a power cut.
pub fn create_dirs(dir: &Path) -> Result<()> {
    if dir.is_dir() {
        return Ok(());
    }
    let mut missing = Vec::new();
    let mut a = Some(dir);
    while let Some(d) = a.filter(|d| !d.as_os_str().is_empty() && std::fs::symlink_metadata(d).is_err()) {
        missing.push(d.to_path_buf());
        a = d.parent();
    }
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    for d in missing.iter().rev() {
        let parent = match d.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        sync_path(parent)?;
    }
    Ok(())
}

/// `fsync` of a file or folder: its data and metadata are on disk when this returns.
pub fn sync_path(p: &Path) -> Result<()> {
    std::fs::File::open(p).and_then(|f| f.sync_all()).map_err(|e| Error::io(p, e))
}

/// `fdatasync` of a regular file: its bytes, and the metadata needed to read them back (size,
/// block map), are on disk when this returns (POSIX `fdatasync`, "synchronized I/O data
/// integrity completion"); only times (mtime, atime) may still be in memory. That is all a
/// temporary file needs before it is renamed over its target: after a crash the target holds
/// the old file or the complete new one. It is never slower than `fsync`, and skips an inode
/// write when only times changed.
pub fn sync_file_data(p: &Path) -> Result<()> {
    std::fs::File::open(p).and_then(|f| f.sync_data()).map_err(|e| Error::io(p, e))
}

/// Refuses a final path that exists and is not a regular file (nor a symlink to one): a
/// rename would replace a device node, a fifo or a socket by a regular file, or fail on a
/// folder.
pub fn check_replaceable(target: &Path) -> Result<()> {
    match std::fs::metadata(target) {
        Ok(m) if !m.is_file() => Err(Error::input(
            target,
            "output path",
            format!("exists and is {}, not a regular file; flexrom only replaces regular files", kind_of(&m)),
        )),
        _ => Ok(()),
    }
}

/// "a directory", "a fifo", … for messages.
pub fn kind_of(m: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = m.file_type();
    if t.is_dir() {
        "a directory"
    } else if t.is_symlink() {
        "a symbolic link"
    } else if t.is_fifo() {
        "a fifo"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else {
        "a regular file"
    }
}

/// A symlink at `target` resolved to the path it points to (relative links against the
/// link's folder); a dangling link is refused, other paths are returned as they are.
pub(super) fn follow_symlink(target: &Path) -> Result<PathBuf> {
    match std::fs::symlink_metadata(target) {
        Ok(m) if m.file_type().is_symlink() => match std::fs::canonicalize(target) {
            Ok(p) => Ok(p),
            Err(_) => Err(Error::input(
                target,
                "output path",
                "is a symbolic link to nothing (dangling); flexrom does not create files through it",
            )),
        },
        _ => Ok(target.to_path_buf()),
    }
}

/// `fdatasync` of every file below `dir` and `fsync` of every folder, deepest first, then `dir`.
pub fn sync_tree(dir: &Path) -> Result<()> {
    for e in std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))? {
        let e = e.map_err(|e| Error::io(dir, e))?;
        let t = e.file_type().map_err(|err| Error::io(e.path(), err))?;
        if t.is_dir() {
            sync_tree(&e.path())?;
        } else if t.is_file() {
            sync_file_data(&e.path())?;
        }
    }
    sync_path(dir)
}
