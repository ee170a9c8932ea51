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
    if requested() {
        Err(Error::Interrupted)
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A request is seen by `check` and withdrawn by `clear`: the flag's whole contract.
    #[test]
    fn request_is_seen_and_cleared() {
        clear();
        assert!(check().is_ok());
        request();
        assert!(matches!(check(), Err(Error::Interrupted)));
        clear();
        assert!(check().is_ok());
    }
}
