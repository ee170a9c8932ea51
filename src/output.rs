//! Writing results to standard output without panicking: `println!` panics when the
//! reader has gone (`flexrom ... | head -1`) or the disk is full. A closed pipe becomes
//! [`Error::StdoutClosed`] (the program then ends quietly), any other write error an
//! ordinary error with its message.

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

/// A line on standard error; a closed or full stderr is ignored (messages are a courtesy,
/// never a reason to fail or panic).
pub fn note(text: &str) {
    let mut err = std::io::stderr().lock();
    let _ = writeln!(err, "{text}");
}
