//! A request, from the host program, that the computation under way stop.
//!
//! The command line ends on SIGINT through its own handler (`io::atomic`), which removes the
//! temporary files and exits. A host that keeps running after an interruption (Python, where
//! Ctrl-C raises `KeyboardInterrupt`) sets this flag instead: every time step of every run
//! (full, reduced, estimate, training) reads it, and a run that sees it returns
//! [`Error::Interrupted`], so the error travels up like any other, dropping the temporary
//! files it had begun. One relaxed load per step: nothing against a step's cost.

use crate::error::{Error, Result};
use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Asks every run in the process to stop at its next time step.
pub fn request() {
    REQUESTED.store(true, Ordering::Relaxed);
}

/// Withdraws the request (before the next computation starts).
pub fn clear() {
    REQUESTED.store(false, Ordering::Relaxed);
}

/// Whether a stop was asked for.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// [`Error::Interrupted`] when a stop was asked for. Runs check it at every time step;
/// the loops that swallow a failed run (greedy training's candidates and mode search,
/// where a run that fails reads as an infinite estimate) check it themselves.
pub fn check() -> Result<()> {
    check_flag(&REQUESTED)
}

fn check_flag(flag: &AtomicBool) -> Result<()> {
    if flag.load(Ordering::Relaxed) {
        Err(Error::Interrupted)
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A raised flag is an `Interrupted` error, a lowered one none. (A flag of its own: the
    /// process's would stop the runs of other unit tests running alongside.)
    #[test]
    fn a_raised_flag_is_an_interruption() {
        let flag = AtomicBool::new(false);
        assert!(check_flag(&flag).is_ok());
        flag.store(true, Ordering::Relaxed);
        assert!(matches!(check_flag(&flag), Err(Error::Interrupted)));
        flag.store(false, Ordering::Relaxed);
        assert!(check_flag(&flag).is_ok());
    }
}
