//! What a signal's clean-up (`io::atomic::clean_up_for_stop`, the body of the SIGINT,
//! SIGTERM and SIGHUP handler before it ends the process) leaves and says, at the moments a
//! mutation campaign's signals hit:
//! - during `run`'s commit of its basis and report folder (`swap_in_dir_with`, as
//!   `report::run_with` calls it), before the renames: the previous basis and
//!   report stay byte for byte, no temporary path is left, and the message says the previous
//!   outputs were left (7 of 40 SIGINTs during `flexrom run` had left a new basis beside the
//!   old report, saying the same);
//! - after that commit: both are new, and the message names both as complete;
//! - right after a single file's commit (`online`, `simulate`, `train`): the message names
//!   the file as complete and in place instead of "previous outputs left as they were".
//!
//! The clean-up is called where the signal would arrive; the process is not ended. A test
//! binary of its own: the record of committed outputs is process-wide.

use flexrom::io::atomic::{clean_up_for_stop, live_paths, swap_in_dir_with, write_bytes_atomically, TempPath};
use std::path::Path;
use std::sync::Mutex;

fn read_dir_sorted(d: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

/// A new report folder (one file, `text`) and basis (`text`) ready to be committed.
fn staged(report: &Path, basis: &Path, text: &[u8]) -> (TempPath, TempPath) {
    let r = TempPath::dir_for(report).unwrap();
    std::fs::write(r.path().join("summary.md"), text).unwrap();
    let b = TempPath::file_for(basis).unwrap();
    std::fs::write(b.path(), text).unwrap();
    (r, b)
}

#[test]
fn a_stop_during_or_after_a_commit_leaves_and_says_what_is_in_place() {
    let d = tempfile::tempdir().unwrap();
    let (report, basis) = (d.path().join("report"), d.path().join("basis.h5"));
    std::fs::create_dir(&report).unwrap();
    std::fs::write(report.join("summary.md"), b"old").unwrap();
    std::fs::write(&basis, b"old").unwrap();

    // the signal after every stage, as the outputs are about to be renamed into place
    let (r, b) = staged(&report, &basis, b"new");
    let said = Mutex::new(String::new());
    let _ = swap_in_dir_with(r, vec![b], |_| {
        *said.lock().unwrap() = clean_up_for_stop("SIGINT");
        Ok(())
    });
    let said = said.into_inner().unwrap();
    assert_eq!(std::fs::read(&basis).unwrap(), b"old", "{said}");
    assert_eq!(std::fs::read(report.join("summary.md")).unwrap(), b"old", "{said}");
    assert_eq!(read_dir_sorted(d.path()), ["basis.h5", "report"]);
    assert!(live_paths().is_empty(), "{:?}", live_paths());
    assert!(said.ends_with("2 temporary path(s) removed, previous outputs left as they were"), "{said}");

    // the signal just after the commit
    let (r, b) = staged(&report, &basis, b"new");
    swap_in_dir_with(r, vec![b], |_| Ok(())).unwrap();
    let said = clean_up_for_stop("SIGTERM");
    assert_eq!(std::fs::read(&basis).unwrap(), b"new");
    assert_eq!(std::fs::read(report.join("summary.md")).unwrap(), b"new");
    assert_eq!(read_dir_sorted(d.path()), ["basis.h5", "report"]);
    let named = |p: &Path| said.contains(&p.display().to_string());
    assert!(said.starts_with("stopped by SIGTERM after ") && named(&basis) && named(&report), "{said}");
    assert!(said.contains("complete and in place") && !said.contains("previous outputs left"), "{said}");

    // a single file (a result of `online` or `simulate`, a basis of `train`)
    let out = d.path().join("out.h5");
    write_bytes_atomically(&out, b"result").unwrap();
    let said = clean_up_for_stop("SIGHUP");
    assert!(said.contains(&out.display().to_string()) && said.contains("complete and in place"), "{said}");
    assert!(said.ends_with("0 temporary path(s) removed, other outputs left as they were"), "{said}");
}
