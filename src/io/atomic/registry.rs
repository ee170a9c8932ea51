//! The process-wide registry of live temporary paths and the signal handler that removes
//! them: every temporary path [`super::TempPath`] makes is registered while it lives, and
//! on SIGINT, SIGTERM or SIGHUP the handler removes them all (putting back a report folder
//! moved aside) before the process exits with 128 + the signal number.

use crate::error::{Error, Result};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicI32, AtomicU64, AtomicU8, Ordering};
use std::sync::{Mutex, MutexGuard};

/// What the signal handler does with a registered path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) enum Live {
    /// a temporary file: removed
    File(PathBuf),
    /// a temporary folder flexrom made itself: removed with its contents
    Dir(PathBuf),
    /// a previous report folder moved aside while a new one is renamed in: renamed back to
    /// `target` when the new one is not there yet, removed otherwise
    Aside { aside: PathBuf, target: PathBuf },
}

static LIVE: Mutex<Vec<Live>> = Mutex::new(Vec::new());
/// The outputs renamed into place so far (each path once), so that a stop says which outputs
/// are new rather than "left as they were". Taken only under [`LIVE`]'s lock: a rename and
/// its record are one step for the signal's clean-up.
static COMMITTED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// What a stopped process should say about the work it kept ([`set_stop_note`]).
static STOP_NOTE: Mutex<Option<String>> = Mutex::new(None);

/// The line the signal handler prints after its own when the process is stopped (a sweep:
/// which file keeps the finished runs, and how to go on); `None` withdraws it.
pub fn set_stop_note(note: Option<String>) {
    *STOP_NOTE.lock().unwrap_or_else(|e| e.into_inner()) = note;
}

/// The line [`set_stop_note`] set, if any.
pub fn stop_note() -> Option<String> {
    STOP_NOTE.lock().unwrap_or_else(|e| e.into_inner()).clone()
}
pub(super) static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Where a graceful stop stands ([`GracefulStop`]): [`OFF`], [`ON`] (a first signal stops
/// the runs), [`STOPPING`] (one did). One atomic, so that the handler's claim and the
/// guard's release cannot both succeed.
static GRACEFUL: AtomicU8 = AtomicU8::new(OFF);
const OFF: u8 = 0;
const ON: u8 = 1;
const STOPPING: u8 = 2;
/// The signal that asked a graceful stop (0: none).
static STOPPED_BY: AtomicI32 = AtomicI32::new(0);

/// While it lives, the first SIGINT/SIGTERM/SIGHUP asks every run to stop at its next time
/// step ([`crate::interrupt`]) instead of ending the process, so that the work finished so
/// far can be written (a sweep's final file, with every point finished by then); the same
/// or another signal again ends the process at once, as without it. Held by a sweep while
/// its runs go on; [`GracefulStop::release`] ends it before the final write and says
/// whether a stop came.
pub struct GracefulStop(());

impl GracefulStop {
    pub fn on() -> Self {
        STOPPED_BY.store(0, Ordering::SeqCst);
        GRACEFUL.store(ON, Ordering::SeqCst);
        GracefulStop(())
    }

    /// Ends the graceful reach (a later signal ends the process at once) and says whether a
    /// signal asked a stop while it lasted. When it did, the stop request was set before
    /// the claim ([`install_signal_handler`]), so it is there to be withdrawn.
    pub fn release(self) -> bool {
        GRACEFUL.swap(OFF, Ordering::SeqCst) == STOPPING
    }
}

impl Drop for GracefulStop {
    fn drop(&mut self) {
        GRACEFUL.store(OFF, Ordering::SeqCst);
    }
}

/// The signal that asked a graceful stop, by number and name, when one did.
pub fn stopped_by() -> Option<(i32, &'static str)> {
    match STOPPED_BY.load(Ordering::SeqCst) {
        0 => None,
        sig => Some((sig, signal_name(sig))),
    }
}

fn signal_name(sig: i32) -> &'static str {
    use signal_hook::consts::{SIGHUP, SIGINT};
    match sig {
        SIGINT => "SIGINT",
        SIGHUP => "SIGHUP",
        _ => "SIGTERM",
    }
}

/// The registry, also after a thread panicked while holding it (the list stays valid).
pub(super) fn live() -> MutexGuard<'static, Vec<Live>> {
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

pub(super) fn unregister(l: &Live) {
    let mut v = live();
    if let Some(i) = v.iter().position(|x| x == l) {
        v.swap_remove(i);
    }
}

/// Records that `target` was renamed into place; called with the registry lock held
/// (`_held`), in the same step as the rename.
pub(super) fn record_commit(_held: &MutexGuard<'static, Vec<Live>>, target: &Path) {
    let mut c = COMMITTED.lock().unwrap_or_else(|e| e.into_inner());
    if !c.iter().any(|p| p == target) {
        c.push(target.to_path_buf());
    }
}

/// What a signal's clean-up does before the process ends, as the handler does it: under the
/// registry lock (no new temporary path is made, and no rename is half recorded), removes
/// every live temporary path (putting back a report folder moved aside) and says what it did
/// and which outputs were already complete and in place.
pub fn clean_up_for_stop(signal: &str) -> String {
    stop_locked(&mut live(), signal)
}

fn stop_locked(v: &mut Vec<Live>, signal: &str) -> String {
    let n = v.len();
    clean_up(v);
    let done = COMMITTED.lock().unwrap_or_else(|e| e.into_inner()).clone();
    stop_message(signal, n, &done)
}

fn stop_message(signal: &str, removed: usize, done: &[PathBuf]) -> String {
    if done.is_empty() {
        return format!("stopped by {signal}; {removed} temporary path(s) removed, previous outputs left as they were");
    }
    let names: Vec<String> = done.iter().map(|p| crate::error::show_text(&p.display().to_string())).collect();
    format!(
        "stopped by {signal} after {} had been written in full (complete and in place, replacing what was there); {removed} temporary path(s) removed, other outputs left as they were",
        names.join(", ")
    )
}

/// Removes (or puts back) every registered path; used by the signal handler.
pub(super) fn clean_up(v: &mut Vec<Live>) {
    for l in v.drain(..) {
        match l {
            Live::File(p) => {
                let _ = std::fs::remove_file(p);
            }
            Live::Dir(p) => {
                // the interrupted thread may still be creating a file in it (ENOTEMPTY)
                for _ in 0..50 {
                    if std::fs::remove_dir_all(&p).is_ok() || std::fs::symlink_metadata(&p).is_err() {
                        break;
                    }
                    std::thread::sleep(std::time::Duration::from_millis(2));
                }
            }
            Live::Aside { aside, target } => {
                if std::fs::symlink_metadata(&target).is_err() {
                    let _ = std::fs::rename(&aside, &target);
                } else {
                    let _ = std::fs::remove_dir_all(&aside);
                }
            }
        }
    }
}

/// The temporary paths alive right now (for tests and diagnostics).
pub fn live_paths() -> Vec<PathBuf> {
    live()
        .iter()
        .map(|l| match l {
            Live::File(p) | Live::Dir(p) => p.clone(),
            Live::Aside { aside, .. } => aside.clone(),
        })
        .collect()
}

/// Installs the SIGINT/SIGTERM (and SIGHUP: a closed terminal) handler: a thread (signal-hook) that, on the first signal,
/// takes the registry lock (so no new temporary path can be registered), removes every live
/// temporary path and ends the process with `_exit(128 + signal)`. `_exit` skips the HDF5
/// library's exit handlers, which could wait for a lock held by the interrupted writer.
pub fn install_signal_handler() -> Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])
        .map_err(|e| Error::usage(format!("cannot install the SIGINT/SIGTERM/SIGHUP handler: {e}")))?;
    std::thread::Builder::new()
        .name("flexrom-signals".into())
        .spawn(move || {
            for sig in signals.forever() {
                let name = signal_name(sig);
                // the first signal during a graceful stop's reach: stop the runs, not the process.
                // The request goes first, so that a claimed stop always has it; where the
                // claim fails (the reach just ended) the process ends below anyway
                if GRACEFUL.load(Ordering::SeqCst) == ON {
                    crate::interrupt::request();
                    if GRACEFUL.compare_exchange(ON, STOPPING, Ordering::SeqCst, Ordering::SeqCst).is_ok() {
                        STOPPED_BY.store(sig, Ordering::SeqCst);
                        let _ = writeln!(
                            std::io::stderr(),
                            "flexrom: {name}: stopping the runs under way to write the finished ones (send it again to stop at once)"
                        );
                        continue;
                    }
                }
                // the lock is kept until the exit: nothing is made or renamed after the clean-up
                let mut v = live();
                let said = stop_locked(&mut v, name);
                // an unwritable stderr (a hung-up terminal) must not end this thread
                let mut err = std::io::stderr();
                let _ = writeln!(err, "flexrom: {said}");
                if let Some(note) = STOP_NOTE.lock().unwrap_or_else(|e| e.into_inner()).as_ref() {
                    let _ = writeln!(err, "flexrom: {note}");
                }
                signal_hook::low_level::exit(128 + sig);
            }
        })
        .map_err(|e| Error::usage(format!("cannot start the signal thread: {e}")))?;
    Ok(())
}

/// A unique, not yet existing name `.<name>.<tag>-<pid>-<n>` in `dir`.
pub(super) fn unique_sibling(dir: &Path, name: &str, tag: &str) -> PathBuf {
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let p = dir.join(format!(".{name}.{tag}-{}-{n}", std::process::id()));
        if std::fs::symlink_metadata(&p).is_err() {
            return p;
        }
    }
}
