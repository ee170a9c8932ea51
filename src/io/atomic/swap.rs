//! A finished report folder swapped in for the old one, with the old one put back when a
//! signal arrives between the two renames, and with it the files that belong to it (`run`'s
//! basis): for a signal, the folder and the files are renamed into place in one step.

use super::fs::{split, sync_path, sync_tree};
use super::registry::{live, record_commit, unique_sibling, unregister, Live};
use super::temp_path::TempPath;
use crate::error::{Error, Result};
use std::path::Path;

/// Puts the folder `tmp` (a [`TempPath::dir_for`] of `target`) in place of `target`:
/// everything below `tmp` is `fsync`ed; an existing `target` (which the caller has checked
/// is flexrom's own, see [`crate::io::output::check_report_dir`]) is first renamed aside,
/// then `tmp` renamed to `target`, then the old folder removed. A signal between the two
/// renames puts the old folder back.
pub fn swap_in_dir(tmp: TempPath, may_replace: impl Fn(&Path) -> Result<()>) -> Result<()> {
    swap_in_dir_with(tmp, Vec::new(), may_replace)
}

/// [`swap_in_dir`], then every file of `files` (each a [`TempPath::file_for`]) renamed over
/// its target, all under the registry lock: a signal's clean-up sees either none of them in
/// place (and puts back what was there) or all of them, and says which. A file's rename
/// that fails puts the previous folder back (the files renamed before it stay new: a rename
/// in the same folder fails only when the folder itself changed). The files' data is on disk
/// before the first rename.
pub fn swap_in_dir_with(
    mut tmp: TempPath,
    mut files: Vec<TempPath>,
    may_replace: impl Fn(&Path) -> Result<()>,
) -> Result<()> {
    let (src, target) = match &tmp.live {
        Live::Dir(p) => (p.clone(), tmp.target.clone()),
        _ => return Err(Error::usage("internal: swap_in_dir needs a temporary folder")),
    };
    let (parent, name) = split(&target)?;
    // a stop asked for: the folder's contents may come from runs the stop cut short
    // ([`TempPath::commit`])
    crate::interrupt::check()?;
    sync_tree(&src)?;
    for f in &files {
        f.prepare_commit()?;
    }
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
    for f in &mut files {
        if let Err(e) = f.rename_locked(&mut v) {
            // the new folder out, the previous one back
            let _ = std::fs::rename(&target, &src);
            if let Some(a) = &aside {
                let _ = std::fs::rename(a, &target);
            }
            let _ = std::fs::remove_dir_all(&src);
            return Err(e);
        }
    }
    record_commit(&v, &target);
    let old = aside.map(|a| Live::Aside { aside: a, target: target.clone() });
    if let Some(l) = &old {
        v.push(l.clone());
    }
    drop(v);
    let synced = files.iter().try_for_each(|f| sync_path(&split(f.target())?.0)).and(sync_path(&parent));
    if let Some(l @ Live::Aside { aside, .. }) = &old {
        let r = std::fs::remove_dir_all(aside).map_err(|e| Error::io(aside, e));
        unregister(l);
        r?;
    }
    synced
}
