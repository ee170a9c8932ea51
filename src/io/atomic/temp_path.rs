//! [`TempPath`]: a temporary file or folder beside its target, registered while it lives,
//! removed when dropped, renamed over the target when committed.

use super::fs::{check_replaceable, create_dirs, follow_symlink, split, sync_path};
use super::registry::{live, unique_sibling, unregister, Live};
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// A temporary file or folder beside a target path, registered while it lives. Dropped
/// without [`TempPath::commit`] it is removed (error paths, panics); committed it is
/// `fsync`ed and renamed over the target.
#[derive(Debug)]
pub struct TempPath {
    pub(super) live: Live,
    pub(super) target: PathBuf,
    pub(super) armed: bool,
}

impl TempPath {
    /// Creates an empty temporary file beside `target`, exclusively, so that what is removed
    /// on failure is always flexrom's own file (the writer truncates it). The target's folder
    /// is created when missing. A symlink at `target` is followed: the file it points to is
    /// the one replaced, the link stays.
    pub fn file_for(target: &Path) -> Result<TempPath> {
        let target = follow_symlink(target)?;
        check_replaceable(&target)?;
        let (dir, name) = split(&target)?;
        Self::create(&dir, &name, target.clone(), |p| {
            std::fs::OpenOptions::new().write(true).create_new(true).open(p).map(|_| Live::File(p.to_path_buf()))
        })
    }

    /// Creates a temporary folder beside `target` (whose parent is created when missing).
    pub fn dir_for(target: &Path) -> Result<TempPath> {
        let (dir, name) = split(target)?;
        Self::create(&dir, &name, target.to_path_buf(), |p| std::fs::create_dir(p).map(|_| Live::Dir(p.to_path_buf())))
    }

    /// Makes a fresh sibling with `make` (which must fail if the path exists) and registers
    /// it, both under the registry lock: a signal's clean-up (which takes the lock) sees it
    /// registered only once it is flexrom's own, and after that clean-up (which keeps the
    /// lock until the exit) nothing is made again. A name that turns out to be taken is not
    /// touched; the next one is tried.
    fn create(
        dir: &Path,
        name: &str,
        target: PathBuf,
        make: impl Fn(&Path) -> std::io::Result<Live>,
    ) -> Result<TempPath> {
        let mut v = live();
        create_dirs(dir)?;
        loop {
            let tmp = unique_sibling(dir, name, "flexrom-tmp");
            match make(&tmp) {
                Ok(l) => {
                    v.push(l.clone());
                    return Ok(TempPath { live: l, target, armed: true });
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(Error::io(&tmp, e)),
            }
        }
    }

    /// The temporary path to write.
    pub fn path(&self) -> &Path {
        match &self.live {
            Live::File(p) | Live::Dir(p) => p,
            Live::Aside { aside, .. } => aside,
        }
    }

    /// The final path this temporary replaces on commit.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// `fsync`s the temporary file, renames it over the target and `fsync`s the folder.
    /// For a folder use [`super::swap_in_dir`] (which checks what it replaces).
    pub fn commit(mut self) -> Result<()> {
        let tmp = self.path().to_path_buf();
        if matches!(self.live, Live::Dir(_)) {
            return Err(Error::Usage(format!(
                "internal: {} is a folder; it is swapped in, not committed",
                tmp.display()
            )));
        }
        sync_path(&tmp)?;
        // checked again right before the rename: something may have appeared meanwhile
        check_replaceable(&self.target)?;
        std::fs::rename(&tmp, &self.target).map_err(|e| Error::io(&self.target, e))?;
        self.disarm();
        sync_path(&split(&self.target)?.0)
    }

    fn disarm(&mut self) {
        if self.armed {
            unregister(&self.live);
            self.armed = false;
        }
    }
}

impl Drop for TempPath {
    fn drop(&mut self) {
        if self.armed {
            match &self.live {
                Live::File(p) => {
                    let _ = std::fs::remove_file(p);
                }
                Live::Dir(p) => {
                    let _ = std::fs::remove_dir_all(p);
                }
                Live::Aside { .. } => {}
            }
            unregister(&self.live);
        }
    }
}
