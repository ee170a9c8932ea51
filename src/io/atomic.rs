//! Atomic, durable writes and the registry of live temporary paths.
//!
//! Every file flexrom writes is first written under a temporary name in the target's own
//! folder (`.<name>.flexrom-tmp-<pid>-<n>`), flushed to disk (`fdatasync` of the file: its
//! bytes and size), renamed over the final name and the folder `fsync`ed, so the final path
//! holds either the previous file or the complete new one, also after a power cut, and a
//! reported success survives one ([`TempPath::commit`] gives the argument step by step). Every temporary path is entered in a
//! process-wide registry while it lives; it leaves the registry when it is renamed into place
//! or removed (on every error path, by `Drop`). On SIGINT or SIGTERM the handler installed by
//! [`install_signal_handler`] removes every registered path, puts back a report folder that
//! was moved aside, and exits with 128 + the signal number (130, 143).

mod fs;
mod registry;
mod swap;
mod temp_path;

use crate::error::{Error, Result};
pub use fs::{check_replaceable, create_dirs, kind_of, names_an_entry, sync_file_data, sync_path, sync_tree};
pub use registry::{
    clean_up_for_stop, install_signal_handler, live_paths, set_stop_note, stop_note, stopped_by, GracefulStop,
};
use std::path::Path;
pub use swap::{swap_in_dir, swap_in_dir_with};
pub use temp_path::TempPath;

/// Writes `target` atomically: `fill` writes the temporary path it is given; on success
/// the file is `fdatasync`ed and renamed into place, on any error it is removed and the
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

/// Creates `path` (which must not exist) with `bytes` and `fdatasync`s it (its bytes and size).
pub fn write_new(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(std::fs::OpenOptions::new().write(true).create_new(true), path, bytes)
}

fn write_with(o: &std::fs::OpenOptions, path: &Path, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let mut f = o.open(path).map_err(|e| Error::io(path, e))?;
    f.write_all(bytes).and_then(|_| f.sync_data()).map_err(|e| Error::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::registry::{clean_up, Live, COUNTER};
    use super::*;
    use std::path::PathBuf;
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
            Err(Error::usage("later stage failed"))
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
