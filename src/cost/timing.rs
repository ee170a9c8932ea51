//! Time loops timed honestly on a shared machine: the full and the reduced loop repeated,
//! interleaved (a busy spell falls on both), within a budget, and compared by their medians
//! (`validate`'s speedup, `train`'s stored timing of both routes).

/// Time loops of a few milliseconds move by ±30 % from one run to the next on a shared
/// machine (other processes, page faults of a first run), so the loops are timed
/// repeatedly, interleaved, and compared by medians: while all kinds together have taken
/// less than this, s…
pub const TIMING_BUDGET: f64 = 0.25;
/// …and each kind has fewer runs than this (odd: the median is a run). A full run that
/// alone exceeds the budget is timed once.
pub const TIMING_RUNS: usize = 7;

/// Whether to time one more round of runs ([`TIMING_BUDGET`], [`TIMING_RUNS`]): `kinds`
/// holds each kind's times so far (full, reduced, …), one per round.
pub fn repeat_timing(kinds: &[&[f64]]) -> bool {
    let spent: f64 = kinds.iter().flat_map(|k| k.iter()).sum();
    let next: f64 = kinds.iter().map(|k| k.last().copied().unwrap_or(0.0)).sum();
    kinds.iter().all(|k| k.len() < TIMING_RUNS) && spent + next <= TIMING_BUDGET
}

/// The median (the middle of an odd count, the mean of the middle two of an even one).
pub fn median(x: &mut [f64]) -> f64 {
    x.sort_by(f64::total_cmp);
    let n = x.len();
    if n % 2 == 1 {
        x[n / 2]
    } else {
        0.5 * (x[n / 2 - 1] + x[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::{median, repeat_timing, TIMING_BUDGET, TIMING_RUNS};

    /// Medians of odd and even counts, in any order; the timing repeats while another round
    /// fits the budget and stops at the run count, and a single run over the budget is
    /// timed once.
    #[test]
    fn timing_medians_and_their_budget() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(repeat_timing(&[&[5e-3], &[1e-3]]));
        assert!(!repeat_timing(&[&[5e-3; TIMING_RUNS], &[1e-3; TIMING_RUNS]]));
        assert!(!repeat_timing(&[&[TIMING_BUDGET], &[1e-3]]));
        // 0.1 + 0.05 spent, a next pair of 0.15 would exceed 0.25
        assert!(!repeat_timing(&[&[0.1], &[0.05]]));
        // a third kind (the estimate) counts too: 0.07 + 0.03 + 0.03 twice is 0.26
        assert!(!repeat_timing(&[&[0.07], &[0.03], &[0.03]]));
        assert!(repeat_timing(&[&[0.07], &[0.03]]));
    }
}
