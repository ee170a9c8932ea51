//! The verbosity chosen on the command line, one process-wide setting read by every
//! printing site: `-q` keeps errors and warnings only, `-v` adds timings and solver
//! statistics.

use std::io::Write;
use std::sync::atomic::{AtomicU8, Ordering};

/// How much flexrom says on standard error (results on standard output are not affected).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Verbosity {
    /// `-q`: errors and warnings only; no progress bars, no info lines
    Quiet = 0,
    /// the default: errors, warnings, progress and one line per finished stage
    Normal = 1,
    /// `-v`: also timings and Newton statistics per stage
    Verbose = 2,
}

static LEVEL: AtomicU8 = AtomicU8::new(Verbosity::Normal as u8);

/// Sets the process-wide verbosity (once, from the command line).
pub fn set_verbosity(v: Verbosity) {
    LEVEL.store(v as u8, Ordering::Relaxed);
}

pub fn verbosity() -> Verbosity {
    match LEVEL.load(Ordering::Relaxed) {
        0 => Verbosity::Quiet,
        1 => Verbosity::Normal,
        _ => Verbosity::Verbose,
    }
}

/// Progress bars and progress lines are drawn (they are also hidden by `indicatif` when
/// standard error is not a terminal).
pub fn show_progress() -> bool {
    verbosity() >= Verbosity::Normal
}

/// A progress or info line on standard error, left out under `-q`.
pub fn info(text: &str) {
    if verbosity() >= Verbosity::Normal {
        note(text);
    }
}

/// A detail line (timings, solver statistics) on standard error, shown only under `-v`.
pub fn detail(text: &str) {
    if verbosity() >= Verbosity::Verbose {
        note(text);
    }
}

/// A line on standard error that every verbosity shows (errors, warnings); a closed or full
/// stderr is ignored (messages are a courtesy, never a reason to fail or panic).
pub fn note(text: &str) {
    let mut err = std::io::stderr().lock();
    let _ = writeln!(err, "{text}");
}
