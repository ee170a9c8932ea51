//! Whether `validate` and `run` time the full model once more with a dense LU of the KKT
//! matrix (the thesis's reference solver, for the "speedup vs dense" column).
//!
//! The dense run stores the n × n iteration matrix (n = coordinates + constraints), 8 n²
//! bytes, and factors it at every Newton matrix update, n³/3 flops each. Both grow so fast
//! with the mesh that the comparison is skipped by default above
//!
//! ```text
//!     8 n² > DENSE_AUTO_MAX_BYTES = 256 MiB      ⇔   n > 5792
//!     N_steps · n³/3 > DENSE_AUTO_MAX_FLOPS = 2·10¹¹
//! ```
//!
//! The second is a lower bound of the run's work (an LU is 2n³/3, and a step takes one to
//! four factorizations): the shipped four-bar's dense run (157 steps, n = 460, bound
//! 5.1·10⁹) took 0.85 s on one core of the 2-core development host (2026-11-28), so the
//! bound stops runs of about half a minute and more. A user's two-link arm of 600 elements
//! (n = 2412, 1000 steps, bound 4.7·10¹²) ran over ten minutes in the dense comparison
//! alone before this bound.
//!
//! At that size one factorization is ≈ 6.5·10¹⁰ flops (seconds on one core, and the run
//! takes one per step or more). The pendulum (n = 206) and the four-bar (n = 460) are timed;
//! the 500-element pendulum (n = 2006, 31 MiB, bound 5.9·10¹¹) and the refined four-bar
//! (n = 4420, 149 MiB, bound 4.5·10¹²) fit the memory but not the time; the 5000-element pendulum
//! (n = 20006) would need 3.0 GiB for the matrix (twice that with the LU's working copy)
//! and hours of factorizations. The comparison is also skipped when the dense run would
//! not fit the memory bound (`--max-memory`), where it would otherwise fail after the
//! banded run. `--dense` forces it (the memory bound still applies), `--no-dense` skips it.

use crate::error::Result;
use crate::model::Model;
use crate::simulate::{Overrides, Settings};

/// Above this size of the dense KKT matrix (8 n² bytes) the dense comparison is skipped
/// unless forced with `--dense`.
pub const DENSE_AUTO_MAX_BYTES: f64 = 256.0 * 1024.0 * 1024.0;

/// Above this lower bound of the dense run's flops, `N_steps · n³/3`, the dense comparison
/// is skipped unless forced with `--dense` (module documentation).
pub const DENSE_AUTO_MAX_FLOPS: f64 = 2e11;

/// `--dense`, `--no-dense` or neither.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DenseChoice {
    /// run it when the matrix is at most [`DENSE_AUTO_MAX_BYTES`], its work at most
    /// [`DENSE_AUTO_MAX_FLOPS`] and the run fits the memory bound
    #[default]
    Auto,
    /// `--dense`
    Always,
    /// `--no-dense`
    Never,
}

impl DenseChoice {
    /// From the `--dense` and `--no-dense` flags (clap keeps them exclusive).
    pub fn from_flags(dense: bool, no_dense: bool) -> DenseChoice {
        match (dense, no_dense) {
            (true, _) => DenseChoice::Always,
            (_, true) => DenseChoice::Never,
            _ => DenseChoice::Auto,
        }
    }
}

/// Why [`DenseChoice::Auto`] skips the dense run of a KKT system of `n_kkt` rows over
/// `n_steps` steps, or `None` when it runs; `fits_memory` is the memory bound's verdict on
/// the dense run.
pub fn auto_skip_reason(n_kkt: f64, n_steps: f64, fits_memory: Result<()>) -> Option<String> {
    let bytes = 8.0 * n_kkt * n_kkt;
    if bytes > DENSE_AUTO_MAX_BYTES {
        return Some(format!(
            "its {n_kkt} × {n_kkt} matrix would take {} (above {})",
            crate::limits::show_bytes(bytes),
            crate::limits::show_bytes(DENSE_AUTO_MAX_BYTES)
        ));
    }
    let flops = n_steps * n_kkt.powi(3) / 3.0;
    if flops > DENSE_AUTO_MAX_FLOPS {
        return Some(format!(
            "its {n_kkt} × {n_kkt} LU at each of {n_steps} steps is at least {flops:.1e} flops (above {DENSE_AUTO_MAX_FLOPS:.0e}, about half a minute on one core)"
        ));
    }
    fits_memory.err().map(|e| format!("the memory bound: {e}"))
}

/// Decides whether to run the dense comparison of `model` (at the model file's time
/// grid); when `Auto` skips it, says so in one line on standard error, with how to force it.
pub fn decide(choice: DenseChoice, model: &Model) -> Result<bool> {
    match choice {
        DenseChoice::Always => Ok(true),
        DenseChoice::Never => Ok(false),
        DenseChoice::Auto => {
            let z = model.sizes();
            let n_steps = Settings::resolve(model, &Overrides::default())?.n_steps;
            let n = z.n_dof + z.n_constraints;
            match auto_skip_reason(n, n_steps as f64, model.check_full_run_memory(n_steps, true)) {
                None => Ok(true),
                Some(why) => {
                    log::info!(
                        "skipping the dense-LU comparison (full_dense_seconds and speedup_vs_dense will be empty): {why}; --dense forces it, --no-dense skips it silently"
                    );
                    Ok(false)
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The threshold sits between n = 5792 (8·5792² = 268 378 112 B ≤ 256 MiB = 268 435 456 B < 8·5793²)
    /// and n = 5793 (one step, far from the work bound); the shipped models fall on the
    /// sides the module documentation names.
    #[test]
    fn auto_skips_above_the_matrix_size_or_the_work() {
        assert!(auto_skip_reason(5792.0, 1.0, Ok(())).is_none());
        let why = auto_skip_reason(5793.0, 1.0, Ok(())).expect("skipped above 256 MiB");
        assert!(why.contains("5793 × 5793") && why.contains("256.0 MiB"), "{why}");
        // (n, steps): the pendulum, the four-bar (220 and 157 steps) are timed
        for (n, steps) in [(206.0, 220.0), (460.0, 157.0)] {
            assert!(auto_skip_reason(n, steps, Ok(())).is_none(), "n = {n}");
        }
        // the 500-element pendulum (220 · 2006³/3 = 5.9e11), the ×10 four-bar and a
        // 600-element arm of 1000 steps (4.7e12) are not
        for (n, steps, flops) in [(2006.0, 220.0, "5.9e11"), (4420.0, 157.0, "4.5e12"), (2412.0, 1000.0, "4.7e12")] {
            let why = auto_skip_reason(n, steps, Ok(())).expect("skipped above the work bound");
            assert!(why.contains(&format!("at least {flops} flops")) && why.contains("above 2e11"), "{why}");
        }
        // 2e11 = steps · n³/3 at n = 600, steps = 2777.8: just below and above
        assert!(auto_skip_reason(600.0, 2777.0, Ok(())).is_none());
        assert!(auto_skip_reason(600.0, 2778.0, Ok(())).is_some());
        let why = auto_skip_reason(20006.0, 220.0, Ok(())).unwrap();
        assert!(why.contains("3.0 GiB"), "{why}");
    }

    /// Below the size, a dense run over the memory bound is skipped too, with the bound's
    /// message.
    #[test]
    fn auto_skips_over_the_memory_bound() {
        let why =
            auto_skip_reason(206.0, 220.0, Err(crate::Error::Resource("over the limit of 1.0 MiB".into()))).unwrap();
        assert!(why.contains("over the limit of 1.0 MiB"), "{why}");
    }

    #[test]
    fn flags() {
        assert_eq!(DenseChoice::from_flags(false, false), DenseChoice::Auto);
        assert_eq!(DenseChoice::from_flags(true, false), DenseChoice::Always);
        assert_eq!(DenseChoice::from_flags(false, true), DenseChoice::Never);
    }
}
