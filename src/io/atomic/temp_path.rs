//! [`TempPath`]: a temporary file or folder beside its target, registered while it lives,
//! removed when dropped, renamed over the target when committed.

use super::fs::{check_replaceable, create_dirs, follow_symlink, split, sync_file_data, sync_path};
use super::registry::{live, record_commit, unique_sibling, unregister, Live};
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
                // the output named, not the temporary name the user never gave
                Err(e) => {
                    return Err(Error::usage(format!(
                        "{}: cannot write there: creating its temporary sibling {} failed: {e}",
                        target.display(),
                        tmp.display()
                    )))
                }
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

    /// `fdatasync`s the temporary file, renames it over the target and `fsync`s the folder.
    /// For a folder use [`super::swap_in_dir`] (which checks what it replaces).
    ///
    /// Why each step, and why none is skipped (docs/process-speed.md measures them):
    /// 1. `fdatasync(tmp)` before the rename, always, also when no file exists at the target
    ///    yet. Without it the rename can reach the disk before the data: ext4 allocates blocks
    ///    late (and forces them out early only for a rename *over an existing* file), XFS
    ///    likewise, so after a power cut the target can be a zero-length or zero-filled file
    ///    under its final name. The data-integrity sync (not `fsync`) suffices: it covers the
    ///    bytes and the size and block map needed to read them; times may lag.
    /// 2. `rename` is atomic: the name points at the old inode or at the new, complete one.
    /// 3. `fsync(folder)` makes the rename itself durable: without it a crash right after flexrom
    ///    reported success could bring back the previous file (never a broken one). It is the
    ///    cheapest of the three (~0.3 ms), and a night of sweeps must not lose finished runs.
    ///
    /// Nothing is committed once a stop was asked for ([`crate::interrupt`]): some loops read a
    /// run the stop ended as a failed one (an infinite estimate) and go on, and what they
    /// finish is not the file a complete run writes; the previous file stays.
    pub fn commit(mut self) -> Result<()> {
        crate::interrupt::check()?;
        let tmp = self.path().to_path_buf();
        if matches!(self.live, Live::Dir(_)) {
            return Err(Error::usage(format!(
                "internal: {} is a folder; it is swapped in, not committed",
                tmp.display()
            )));
        }
        self.prepare_commit()?;
        // the rename, its record and the temporary's leaving the registry are one step for a
        // signal's clean-up (which takes the lock): it says the output is new exactly when it is
        let mut v = live();
        self.rename_locked(&mut v)?;
        drop(v);
        sync_path(&split(&self.target)?.0)
    }

    /// What comes before a file's rename: its data on disk, the target checked again (it
    /// may have changed meanwhile). For a folder use [`super::swap_in_dir`].
    pub(super) fn prepare_commit(&self) -> Result<()> {
        sync_file_data(self.path())?;
        check_replaceable(&self.target)
    }

    /// Renames the file over its target and takes it off the registry, whose lock `v` is.
    pub(super) fn rename_locked(&mut self, v: &mut std::sync::MutexGuard<'static, Vec<Live>>) -> Result<()> {
        std::fs::rename(self.path(), &self.target).map_err(|e| Error::io(&self.target, e))?;
        record_commit(v, &self.target);
        if let Some(i) = v.iter().position(|x| x == &self.live) {
            v.swap_remove(i);
        }
        self.armed = false;
        Ok(())
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
