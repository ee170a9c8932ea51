//! Progress for logs: where a progress bar is hidden because stderr is not a terminal (a
//! batch job, `make thesis`, a pipe), a long stage still says how far it is, in a line at
//! most every [`TICK_SECONDS`].

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::Instant;

/// Least time between two progress lines.
pub const TICK_SECONDS: f64 = 30.0;

/// Counts finished items of `total` and prints `label: done/total (elapsed)` now and then,
/// only when progress is shown (not `-q`) and stderr is not a terminal (there the bar
/// shows it). Safe to share between worker threads.
pub struct Ticker {
    label: String,
    total: u64,
    active: bool,
    start: Instant,
    state: Mutex<(u64, f64)>,
}

impl Ticker {
    pub fn new(label: &str, total: u64, progress: bool) -> Ticker {
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
        let t = self.start.elapsed().as_secs_f64();
        if self.active && t - s.1 >= TICK_SECONDS && s.0 < self.total {
            s.1 = t;
            log::info!("{}: {}/{} done ({t:.0} s)", self.label, s.0, self.total);
        }
    }
}
