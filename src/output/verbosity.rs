//! The verbosity chosen on the command line: `-q` keeps errors and warnings only, `-v` adds
//! timings and solver statistics.
//!
//! The library itself never reads it: its info, detail and warning lines go through the
//! `log` facade (`log::info!`, `log::debug!`, `log::warn!`) and its progress bars show only
//! when the caller's logger takes info lines, so whoever calls the library owns what is
//! said. [`set_verbosity`] is the command line's choice: it installs [`StderrLog`], which
//! writes each line as it is, at the matching level. A caller that installs no logger
//! hears nothing.

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

/// Sets the command line's verbosity and routes the library's `log` lines to standard
/// error at that level ([`StderrLog`]; the first logger installed in a process stays).
pub fn set_verbosity(v: Verbosity) {
    LEVEL.store(v as u8, Ordering::Relaxed);
    let _ = log::set_logger(&StderrLog);
    log::set_max_level(match v {
        Verbosity::Quiet => log::LevelFilter::Warn,
        Verbosity::Normal => log::LevelFilter::Info,
        Verbosity::Verbose => log::LevelFilter::Debug,
    });
}

/// The command line's logger: each line of the library, as written, on standard error
/// ([`note`]); the level filter is `log`'s maximum level, which [`set_verbosity`] sets.
pub struct StderrLog;

impl log::Log for StderrLog {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() <= log::max_level()
    }
    fn log(&self, record: &log::Record) {
        if self.enabled(record.metadata()) {
            note(&record.args().to_string());
        }
    }
    fn flush(&self) {}
}

/// Whether a library run draws progress (bars and lines): when the caller's logger takes
/// info lines.
pub fn progress_wanted() -> bool {
    log::log_enabled!(log::Level::Info)
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
