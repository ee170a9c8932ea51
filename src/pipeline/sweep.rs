//! `sweep`: reduced runs at many load scales, in parallel across cores (rayon; BLAS stays
//! on one thread inside each run), optionally validated against full runs.
//!
//! The sweep file:
//!
//! ```text
//! /load_scales        (N)
//! /t                  (n_t)
//! /probes/<name>      (N, n_t, 2)    reduced-model probe positions, m
//! /reduced_q          (N, r, n_t)    reduced coordinates
//! /rom_seconds        (N)            reduced time loop of each run
//! /newton_iterations  (N)
//! /factorizations     (N)            iteration matrices factorized
//! /error_estimate     (N)            the estimate of rel_error of each run (NaN: no estimator)
//! /extrapolated       (N)            1 where the load scale is outside the training range
//! /estimate_seconds   (N)            the estimator's enriched run and norms, s
//! with --validate:    /rel_error, /max_probe_error, /max_constraint_violation,
//!                     /full_seconds, /speedup  (N each)
//! attributes on /: basis, variant, n_modes, wall_seconds (whole sweep), threads,
//!   continuation (1 when the runs were continued from their neighbours), program_version
//! ```

use super::estimate::{is_extrapolated, Estimate, EstimatingRunner, TrustInfo};
use super::online::{Output, ReducedRun};
use super::validate::{compare, Validation};
use crate::error::{Error, Result};
use crate::io::h5::{attr_f64, attr_str, attr_u64, write_atomically};
use crate::model::Model;
use crate::reduction::Basis;
use crate::simulate::{simulate, Overrides};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use ndarray::{Array1, Array3};
use rayon::prelude::*;
use std::path::Path;

pub struct SweepPoint {
    pub rom: ReducedRun,
    pub validation: Option<Validation>,
    /// the run's error estimate (None: no estimator)
    pub estimate: Option<Estimate>,
    /// outside the training range
    pub extrapolated: bool,
}

pub struct Sweep {
    pub points: Vec<SweepPoint>,
    pub wall_seconds: f64,
    pub threads: usize,
    pub continuation: bool,
}

/// How a sweep runs (default: independent runs, no validation, no progress bar).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SweepOptions {
    /// also run the full model at every load scale and compare
    pub validate: bool,
    /// continuation in the load scale: each thread takes two contiguous parts of the list
    /// (one from each end) and starts every Newton solve from the previous points'
    /// increments
    /// ([`super::online::ReducedRunner::run`]); off (the default): every load scale on its own, exactly as
    /// `online` runs it
    pub continuation: bool,
    /// a progress bar on stderr
    pub progress: bool,
}

/// The chains of a continuation sweep over `n` scales, by thread: the list cut into `2 T`
/// contiguous blocks, thread t taking block t and block 2T − 1 − t (one from each end).
/// The cost of a run usually grows or falls along the list with the load, so each thread
/// gets a cheap and a dear block (four-bar, 100 scales: the threads' time loops 0.75 and
/// 1.09 s with one block each, balanced with two). Fixed by n and T alone, so a sweep
/// repeats exactly on the same machine.
fn continuation_lanes(n: usize, threads: usize) -> Vec<Vec<std::ops::Range<usize>>> {
    let part = n.div_ceil(2 * threads.max(1)).max(1);
    let blocks: Vec<std::ops::Range<usize>> = (0..n).step_by(part).map(|a| a..(a + part).min(n)).collect();
    let nb = blocks.len();
    (0..nb.div_ceil(2)).map(|t| if t == nb - 1 - t { vec![blocks[t].clone()] } else { vec![blocks[t].clone(), blocks[nb - 1 - t].clone()] }).collect()
}

/// Runs the reduced model at every scale, in parallel; with `validate`, also the full one.
pub fn sweep(model: &Model, basis: &Basis, scales: &[f64], o: SweepOptions) -> Result<Sweep> {
    sweep_with(model, basis, None, scales, o)
}

/// [`sweep`] with the basis's estimator and training range: every point gets its error
/// estimate and extrapolation flag.
pub fn sweep_with(model: &Model, basis: &Basis, trust: Option<&TrustInfo>, scales: &[f64], o: SweepOptions) -> Result<Sweep> {
    let est = trust.and_then(|t| t.estimator.as_ref());
    let bar = ProgressBar::with_draw_target(Some(scales.len() as u64), if o.progress { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() });
    bar.set_style(ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} load scales, {elapsed} elapsed, ETA {eta}").expect("valid template").progress_chars("=> "));
    bar.set_prefix(if o.validate { "sweep + validate" } else { "sweep" });
    let start = std::time::Instant::now();
    let threads = rayon::current_num_threads().max(1);
    // continuation: a few chains of neighbouring scales per thread; otherwise one point per task
    let lanes = if o.continuation { continuation_lanes(scales.len(), threads) } else { (0..scales.len()).map(|i| std::iter::once(i..i + 1).collect()).collect() };
    let parts: Result<Vec<Vec<(usize, SweepPoint)>>> = lanes
        .par_iter()
        // one reduced model per worker, built at its first lane, its loads changed per scale
        .map_init(|| None, |slot: &mut Option<EstimatingRunner>, chains| {
            let runner = match slot {
                Some(r) => r,
                None => slot.insert(EstimatingRunner::new(model, basis, est)?),
            };
            let mut done: Vec<(usize, SweepPoint)> = Vec::new();
            for chain in chains {
                let first = done.len();
                for i in chain.clone() {
                    let x = scales[i];
                    // the last two runs of this chain
                    let previous: Vec<&ReducedRun> = done[first.max(done.len().saturating_sub(2))..].iter().map(|p| &p.1.rom).collect();
                    // without validation nothing of full size is reconstructed
                    let output = if o.validate { Output::Full } else { Output::ReducedAndProbes };
                    let (rom, estimate) = runner.run_with(x, output, &previous)?;
                    let validation = if o.validate {
                        let full = simulate(model, &Overrides { load_scale: Some(x), ..Default::default() })?;
                        Some(compare(model, &full, &rom, None, basis.n_reduced(), basis.variant.name()).with_trust(estimate.as_ref(), trust))
                    } else {
                        None
                    };
                    let extrapolated = trust.is_some_and(|t| is_extrapolated(t.range, x));
                    bar.inc(1);
                    done.push((i, SweepPoint { rom, validation, estimate, extrapolated }));
                }
            }
            Ok(done)
        })
        .collect();
    bar.finish_and_clear();
    let mut points: Vec<(usize, SweepPoint)> = parts?.into_iter().flatten().collect();
    points.sort_by_key(|p| p.0);
    let points = points.into_iter().map(|p| p.1).collect();
    Ok(Sweep { points, wall_seconds: start.elapsed().as_secs_f64(), threads, continuation: o.continuation })
}

pub fn write_sweep(path: &Path, s: &Sweep, basis: &Basis, basis_path: &Path) -> Result<()> {
    let first = &s.points.first().ok_or_else(|| Error::Usage("the sweep has no load scales".into()))?.rom;
    let (n, nt, r) = (s.points.len(), first.result.t.len(), first.reduced_q.nrows());
    write_atomically(path, |f| {
        let e = |err: hdf5::Error| Error::hdf5(path, err);
        let col = |g: &dyn Fn(&SweepPoint) -> f64| Array1::from_iter(s.points.iter().map(g));
        f.new_dataset_builder().with_data(&col(&|p| p.rom.result.settings.load_scale)).create("load_scales").map_err(e)?;
        f.new_dataset_builder().with_data(&first.result.t).create("t").map_err(e)?;
        let g = f.create_group("probes").map_err(e)?;
        for (i, (name, _)) in first.result.probes.iter().enumerate() {
            let a = Array3::from_shape_fn((n, nt, 2), |(k, j, c)| s.points[k].rom.result.probes[i].1[[j, c]]);
            g.new_dataset_builder().with_data(&a).create(name.as_str()).map_err(e)?;
        }
        let zq = Array3::from_shape_fn((n, r, nt), |(k, i, j)| s.points[k].rom.reduced_q[[i, j]]);
        // one chunk per run, not compressed: deflate took 15 % off the size of these
        // trajectories for 0.15 s of a 1.5 s four-bar sweep
        f.new_dataset_builder().chunk((1, r.max(1), nt.max(1))).with_data(&zq).create("reduced_q").map_err(e)?;
        f.new_dataset_builder().with_data(&col(&|p| p.rom.result.wall_seconds)).create("rom_seconds").map_err(e)?;
        f.new_dataset_builder()
            .with_data(&Array1::from_iter(s.points.iter().map(|p| p.rom.result.stats.newton_iterations as u64)))
            .create("newton_iterations")
            .map_err(e)?;
        f.new_dataset_builder()
            .with_data(&Array1::from_iter(s.points.iter().map(|p| p.rom.result.stats.factorizations as u64)))
            .create("factorizations")
            .map_err(e)?;
        f.new_dataset_builder().with_data(&col(&|p| p.estimate.map_or(f64::NAN, |e| e.error_estimate))).create("error_estimate").map_err(e)?;
        f.new_dataset_builder().with_data(&col(&|p| p.estimate.map_or(f64::NAN, |e| e.seconds))).create("estimate_seconds").map_err(e)?;
        f.new_dataset_builder().with_data(&Array1::from_iter(s.points.iter().map(|p| p.extrapolated as u8))).create("extrapolated").map_err(e)?;
        if s.points.iter().all(|p| p.validation.is_some()) {
            let v = |g: &dyn Fn(&Validation) -> f64| col(&|p: &SweepPoint| g(p.validation.as_ref().expect("checked")));
            f.new_dataset_builder().with_data(&v(&|x| x.rel_error)).create("rel_error").map_err(e)?;
            f.new_dataset_builder().with_data(&v(&|x| x.max_probe_error)).create("max_probe_error").map_err(e)?;
            f.new_dataset_builder().with_data(&v(&|x| x.max_constraint_violation)).create("max_constraint_violation").map_err(e)?;
            f.new_dataset_builder().with_data(&v(&|x| x.full_seconds)).create("full_seconds").map_err(e)?;
            f.new_dataset_builder().with_data(&v(&|x| x.speedup)).create("speedup").map_err(e)?;
        }
        attr_str(f, "basis", &basis_path.display().to_string()).map_err(e)?;
        attr_str(f, "variant", basis.variant.name()).map_err(e)?;
        attr_u64(f, "n_modes", basis.n_reduced() as u64).map_err(e)?;
        attr_f64(f, "wall_seconds", s.wall_seconds).map_err(e)?;
        attr_u64(f, "threads", s.threads as u64).map_err(e)?;
        attr_u64(f, "continuation", s.continuation as u64).map_err(e)?;
        attr_str(f, "program_version", env!("CARGO_PKG_VERSION")).map_err(e)
    })
}

/// The table printed on stdout.
pub fn table(s: &Sweep) -> String {
    let mut out = String::new();
    let validated = s.points.iter().all(|p| p.validation.is_some());
    out.push_str("load_scale  rom_ms  newton  error_estimate  est_ms  extrap");
    if validated {
        out.push_str("   rel_error  probe_err_m  full_ms  speedup");
    }
    out.push('\n');
    for p in &s.points {
        let r = &p.rom.result;
        out.push_str(&format!("{:>10.4}  {:>6.2}  {:>6}", r.settings.load_scale, 1e3 * r.wall_seconds, r.stats.newton_iterations));
        match &p.estimate {
            Some(e) => out.push_str(&format!("  {:>14.3e}  {:>6.2}", e.error_estimate, 1e3 * e.seconds)),
            None => out.push_str(&format!("  {:>14}  {:>6}", "-", "-")),
        }
        out.push_str(if p.extrapolated { "     yes" } else { "      no" });
        if let Some(v) = &p.validation {
            out.push_str(&format!("  {:>10.3e}  {:>11.3e}  {:>7.2}  {:>7.2}", v.rel_error, v.max_probe_error, 1e3 * v.full_seconds, v.speedup));
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::continuation_lanes;

    /// Every scale once, in chains of neighbours, at most two chains per thread and no
    /// more lanes than threads; with two threads and 100 scales the blocks pair as 0–24 with
    /// 75–99 and 25–49 with 50–74 (one from each end).
    #[test]
    fn continuation_lanes_cover_the_list_from_both_ends() {
        for (n, threads) in [(100, 2), (7, 2), (3, 4), (1, 2), (10, 3), (0, 2)] {
            let lanes = continuation_lanes(n, threads);
            assert!(lanes.len() <= threads.max(1), "{n} {threads}: {lanes:?}");
            let mut seen: Vec<usize> = lanes.iter().flatten().flat_map(|c| c.clone()).collect();
            seen.sort();
            assert_eq!(seen, (0..n).collect::<Vec<_>>(), "{n} {threads}: {lanes:?}");
            assert!(lanes.iter().all(|l| l.len() <= 2 && l.iter().all(|c| !c.is_empty())));
        }
        assert_eq!(continuation_lanes(100, 2), vec![vec![0..25, 75..100], vec![25..50, 50..75]]);
    }
}
