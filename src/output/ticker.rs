//! Progress for logs: where a progress bar is hidden because stderr is not a terminal (a
//! batch job, `make thesis`, a pipe), a long stage still says how far it is, in a line at
//! most every [`TICK_SECONDS`].

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::Instant;

/// How far the latest counted stage of the process is: its label, items done, items in all.
/// A host that shows progress its own way (Python's callbacks) reads it with [`latest`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Progress {
    pub label: String,
    pub done: u64,
    pub total: u64,
}

static LATEST: Mutex<Option<Progress>> = Mutex::new(None);

/// The progress of the stage counted last ([`Ticker`]), if any since [`forget`].
pub fn latest() -> Option<Progress> {
    LATEST.lock().ok().and_then(|p| p.clone())
}

/// Forgets the recorded progress (before a host's next call).
pub fn forget() {
    if let Ok(mut p) = LATEST.lock() {
        *p = None;
    }
}

fn record(label: &str, done: u64, total: u64) {
    record_in(&LATEST, label, done, total)
}

/// Counts `done` of `total` for the stage `label` in `slot` (a new stage replaces the old).
fn record_in(slot: &Mutex<Option<Progress>>, label: &str, done: u64, total: u64) {
    if let Ok(mut p) = slot.lock() {
        match p.as_mut() {
            Some(x) if x.label == label && x.total == total => x.done = done,
            _ => *p = Some(Progress { label: label.to_string(), done, total }),
        }
    }
}

/// Least time between two progress lines.
pub const TICK_SECONDS: f64 = 30.0;

/// Counts finished items of `total` and prints `label: done/total (elapsed)` now and then,
/// only when progress is shown (not `-q`) and stderr is not a terminal (there the bar
/// shows it); records the count for [`latest`] always. Safe to share between worker threads.
pub struct Ticker {
    label: String,
    total: u64,
    active: bool,
    start: Instant,
    state: Mutex<(u64, f64)>,
}

impl Ticker {
    pub fn new(label: &str, total: u64, progress: bool) -> Ticker {
        record(label, 0, total);
        Ticker {
            label: label.to_string(),
            total,
            active: progress && super::verbosity::progress_wanted() && !std::io::stderr().is_terminal(),
            start: Instant::now(),
            state: Mutex::new((0, 0.0)),
        }
    }

    /// One more item finished.
    pub fn tick(&self) {
        let Ok(mut s) = self.state.lock() else { return };
        s.0 += 1;
        record(&self.label, s.0, self.total);
        let t = self.start.elapsed().as_secs_f64();
        if self.active && t - s.1 >= TICK_SECONDS && s.0 < self.total {
            s.1 = t;
            log::info!("{}: {}/{} done ({t:.0} s)", self.label, s.0, self.total);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The slot follows the counted stage item by item, from any thread; a new stage
    /// replaces the old one. (A slot of its own: the process's records the sweeps of other
    /// unit tests running alongside.)
    #[test]
    fn the_slot_follows_the_counted_stage() {
        let slot = Mutex::new(None);
        let read = || slot.lock().unwrap().clone();
        record_in(&slot, "sweep", 0, 3);
        assert_eq!(read(), Some(Progress { label: "sweep".into(), done: 0, total: 3 }));
        std::thread::scope(|s| {
            s.spawn(|| record_in(&slot, "sweep", 1, 3));
            s.spawn(|| record_in(&slot, "sweep", 2, 3));
        });
        assert_eq!(read().map(|p| (p.label, p.total)), Some(("sweep".into(), 3)));
        record_in(&slot, "iteration 2", 0, 21);
        assert_eq!(read(), Some(Progress { label: "iteration 2".into(), done: 0, total: 21 }));
    }
}
