//! Writing to standard output and standard error without panicking, at the verbosity the
//! user chose (`-q`, `-v`), and results as text, CSV or JSON ([`table`]).
//!
//! `println!` panics when the reader has gone (`flexrom ... | head -1`) or the disk is full.
//! A closed pipe becomes [`Error::StdoutClosed`] (the program then ends quietly), any other
//! write error an ordinary error with its message.
//!
//! Standard error carries three kinds of lines: [`note`] (errors and warnings: always),
//! [`info`] (progress and what a command did: not under `-q`) and [`detail`] (timings and
//! solver statistics: only under `-v`). Results go to standard output.

pub mod table;
pub mod ticker;
mod verbosity;

pub use verbosity::{
    detail, info, note, progress_wanted, set_verbosity, show_progress, verbosity, StderrLog, Verbosity,
};

use crate::error::{Error, Result};
use std::io::Write;

/// Writes `text` to standard output and flushes it.
pub fn print(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes()).and_then(|_| out.flush()).map_err(stdout_error)
}

/// [`print()`] with a newline.
pub fn println(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes()).and_then(|_| out.write_all(b"\n")).and_then(|_| out.flush()).map_err(stdout_error)
}

/// The error for a failed write to standard output.
pub fn stdout_error(e: std::io::Error) -> Error {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        Error::StdoutClosed
    } else {
        Error::io("standard output", e)
    }
}
