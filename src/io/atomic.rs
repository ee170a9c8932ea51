//! Atomic, durable writes and the registry of live temporary paths.
//!
//! Every file flexrom writes is first written under a temporary name in the target's own
//! folder (`.<name>.flexrom-tmp-<pid>-<n>`), flushed to disk (`fsync` of the file), renamed
//! over the final name and the folder `fsync`ed, so the final path holds either the previous
//! file or the complete new one, also after a power cut. Every temporary path is entered in a
//! process-wide registry while it lives; it leaves the registry when it is renamed into place
//! or removed (on every error path, by `Drop`). On SIGINT or SIGTERM the handler installed by
//! [`install_signal_handler`] removes every registered path, puts back a report folder that
//! was moved aside, and exits with 128 + the signal number (130, 143).

mod registry;

use crate::error::{Error, Result};
pub use registry::{install_signal_handler, live_paths};
use registry::{live, unique_sibling, unregister, Live};
use std::path::{Path, PathBuf};

/// False for a path whose last segment is `.`, `..`, empty or the root (`Path::components`
/// drops a trailing `.`, so the text is split here).
pub fn names_an_entry(p: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let last = p.as_os_str().as_bytes().split(|&b| b == b'/').rfind(|seg| !seg.is_empty());
    !matches!(last, None | Some(b".") | Some(b".."))
}

/// The folder and file name of a target path (`""` parent → `.`).
fn split(target: &Path) -> Result<(PathBuf, String)> {
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

/// A temporary file or folder beside a target path, registered while it lives. Dropped
/// without [`TempPath::commit`] it is removed (error paths, panics); committed it is
/// `fsync`ed and renamed over the target.
#[derive(Debug)]
pub struct TempPath {
    live: Live,
    target: PathBuf,
    armed: bool,
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
    /// For a folder use [`swap_in_dir`] (which checks what it replaces).
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

/// A symlink at `target` resolved to the path it points to (relative links against the
/// link's folder); a dangling link is refused, other paths are returned as they are.
fn follow_symlink(target: &Path) -> Result<PathBuf> {
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

/// Writes `target` atomically: `fill` writes the temporary path it is given; on success
/// the file is `fsync`ed and renamed into place, on any error it is removed and the
/// previous file at `target` stays as it was.
pub fn write_file_atomically(target: &Path, fill: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let tmp = TempPath::file_for(target)?;
    fill(tmp.path())?;
    tmp.commit()
}

/// Writes `bytes` to `target` atomically and durably.
pub fn write_bytes_atomically(target: &Path, bytes: &[u8]) -> Result<()> {
    // the temporary file exists (flexrom's own, empty): opened without create_new
    write_file_atomically(target, |tmp| write_with(std::fs::OpenOptions::new().write(true).truncate(true), tmp, bytes))
}

/// Creates `path` (which must not exist) with `bytes` and `fsync`s it.
pub fn write_new(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(std::fs::OpenOptions::new().write(true).create_new(true), path, bytes)
}

fn write_with(o: &std::fs::OpenOptions, path: &Path, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let mut f = o.open(path).map_err(|e| Error::io(path, e))?;
    f.write_all(bytes).and_then(|_| f.sync_all()).map_err(|e| Error::io(path, e))
}

/// `fsync` of every file below `dir` and of every folder, deepest first, then `dir`.
pub fn sync_tree(dir: &Path) -> Result<()> {
    for e in std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))? {
        let e = e.map_err(|e| Error::io(dir, e))?;
        let t = e.file_type().map_err(|err| Error::io(e.path(), err))?;
        if t.is_dir() {
            sync_tree(&e.path())?;
        } else if t.is_file() {
            sync_path(&e.path())?;
        }
    }
    sync_path(dir)
}

/// Puts the folder `tmp` (a [`TempPath::dir_for`] of `target`) in place of `target`:
/// everything below `tmp` is `fsync`ed; an existing `target` (which the caller has checked
/// is flexrom's own, see [`crate::io::output::check_report_dir`]) is first renamed aside,
/// then `tmp` renamed to `target`, then the old folder removed. A signal between the two
/// renames puts the old folder back.
pub fn swap_in_dir(mut tmp: TempPath, may_replace: impl Fn(&Path) -> Result<()>) -> Result<()> {
    let (src, target) = match &tmp.live {
        Live::Dir(p) => (p.clone(), tmp.target.clone()),
        _ => return Err(Error::Usage("internal: swap_in_dir needs a temporary folder".into())),
    };
    let (parent, name) = split(&target)?;
    sync_tree(&src)?;
    if std::fs::symlink_metadata(&target).is_ok() {
        // checked again now, right before it is moved: it may have changed during the run
        may_replace(&target)?;
    }
    // the renames happen under the registry lock, so a signal's clean-up sees either the old
    // folder in place or the new one with the old one registered as moved aside
    let mut v = live();
    let aside = match std::fs::symlink_metadata(&target) {
        Ok(_) => {
            let aside = unique_sibling(&parent, &name, "flexrom-old");
            std::fs::rename(&target, &aside).map_err(|e| Error::io(&target, e))?;
            Some(aside)
        }
        Err(_) => None,
    };
    if let Err(e) = std::fs::rename(&src, &target) {
        // put the old one back; the new one is removed by tmp's Drop
        if let Some(a) = &aside {
            let _ = std::fs::rename(a, &target);
        }
        drop(v);
        return Err(Error::io(&target, e));
    }
    if let Some(i) = v.iter().position(|x| x == &tmp.live) {
        v.swap_remove(i);
    }
    tmp.armed = false;
    let old = aside.map(|a| Live::Aside { aside: a, target: target.clone() });
    if let Some(l) = &old {
        v.push(l.clone());
    }
    drop(v);
    let synced = sync_path(&parent);
    if let Some(l @ Live::Aside { aside, .. }) = &old {
        let r = std::fs::remove_dir_all(aside).map_err(|e| Error::io(aside, e));
        unregister(l);
        r?;
    }
    synced
}

#[cfg(test)]
mod tests {
    use super::registry::{clean_up, COUNTER};
    use super::*;
    use std::sync::atomic::Ordering;

    /// Entries that already sit at the temporary names flexrom would pick next (same pid,
    /// next counters) are skipped and survive the temporaries' removal.
    #[test]
    fn a_foreign_entry_at_a_temporary_name_is_never_removed() {
        let d = tempfile::tempdir().unwrap();
        let next = COUNTER.load(Ordering::Relaxed);
        let foreign: Vec<PathBuf> =
            (next..next + 8).map(|n| d.path().join(format!(".out.flexrom-tmp-{}-{n}", std::process::id()))).collect();
        for (i, p) in foreign.iter().enumerate() {
            if i % 2 == 0 {
                std::fs::write(p, b"user data").unwrap();
            } else {
                std::fs::create_dir(p).unwrap();
                std::fs::write(p.join("inside"), b"user data").unwrap();
            }
        }
        for _ in 0..3 {
            drop(TempPath::file_for(&d.path().join("out")).unwrap());
            drop(TempPath::dir_for(&d.path().join("out")).unwrap());
        }
        for (i, p) in foreign.iter().enumerate() {
            let kept = if i % 2 == 0 { std::fs::read(p) } else { std::fs::read(p.join("inside")) };
            assert_eq!(kept.unwrap(), b"user data", "{}", p.display());
        }
    }

    #[test]
    fn a_dropped_temp_file_is_removed_and_a_committed_one_replaces_the_target() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("sub/out.txt");
        {
            let t = TempPath::file_for(&target).unwrap();
            std::fs::write(t.path(), b"half").unwrap();
            assert!(live_paths().contains(&t.path().to_path_buf()));
        }
        // the parent folder was made; nothing else is left in it
        assert_eq!(std::fs::read_dir(d.path().join("sub")).unwrap().count(), 0);
        write_bytes_atomically(&target, b"one").unwrap();
        write_bytes_atomically(&target, b"two").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"two");
        assert_eq!(std::fs::read_dir(d.path().join("sub")).unwrap().count(), 1);
        let r = write_file_atomically(&target, |tmp| {
            std::fs::write(tmp, b"three").map_err(|e| Error::io(tmp, e))?;
            Err(Error::Usage("later stage failed".into()))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read(&target).unwrap(), b"two");
        assert_eq!(std::fs::read_dir(d.path().join("sub")).unwrap().count(), 1);
    }

    #[test]
    fn a_folder_is_swapped_in_and_the_old_one_removed() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("rep");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("old.md"), b"old").unwrap();
        let t = TempPath::dir_for(&target).unwrap();
        std::fs::write(t.path().join("new.md"), b"new").unwrap();
        swap_in_dir(t, |_| Ok(())).unwrap();
        assert!(target.join("new.md").is_file() && !target.join("old.md").exists());
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 1, "no temporary or old folder left");
        // refused replacement: the old folder stays, the new one is removed
        let t = TempPath::dir_for(&target).unwrap();
        std::fs::write(t.path().join("newer.md"), b"x").unwrap();
        assert!(swap_in_dir(t, |p| Err(Error::input(p, "report", "not mine"))).is_err());
        assert!(target.join("new.md").is_file());
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 1);
    }

    /// What the signal handler does: temporary paths removed, a report folder moved aside put
    /// back when the new one is not in place yet, removed when it is.
    #[test]
    fn the_clean_up_removes_temporaries_and_puts_back_a_folder_moved_aside() {
        let d = tempfile::tempdir().unwrap();
        let p = |n: &str| d.path().join(n);
        std::fs::create_dir(p("tmpdir")).unwrap();
        std::fs::write(p("tmpdir/f"), b"x").unwrap();
        std::fs::write(p("tmpfile"), b"x").unwrap();
        for n in ["old1", "old2", "rep2"] {
            std::fs::create_dir(p(n)).unwrap();
            std::fs::write(p(n).join("summary.md"), n).unwrap();
        }
        let mut v = vec![
            Live::Dir(p("tmpdir")),
            Live::File(p("tmpfile")),
            Live::Aside { aside: p("old1"), target: p("rep1") },
            Live::Aside { aside: p("old2"), target: p("rep2") },
        ];
        clean_up(&mut v);
        assert!(v.is_empty());
        let mut left: Vec<String> = std::fs::read_dir(d.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, ["rep1", "rep2"]);
        assert_eq!(std::fs::read(p("rep1/summary.md")).unwrap(), b"old1", "put back");
        assert_eq!(std::fs::read(p("rep2/summary.md")).unwrap(), b"rep2", "the new one kept");
    }

    #[test]
    fn non_regular_targets_are_refused() {
        let d = tempfile::tempdir().unwrap();
        let e = write_bytes_atomically(d.path(), b"x").unwrap_err().to_string();
        assert!(e.contains("directory") || e.contains("file name"), "{e}");
        let sub = d.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        let e = write_bytes_atomically(&sub, b"x").unwrap_err().to_string();
        assert!(e.contains("a directory"), "{e}");
        let e = write_bytes_atomically(Path::new("/dev/null"), b"x").unwrap_err().to_string();
        assert!(e.contains("character device"), "{e}");
    }
}
