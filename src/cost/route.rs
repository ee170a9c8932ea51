//! Which route is faster at a model's size: the reduced model (with its error estimate, as
//! runs make it) or the full one, exact, on our banded solver. The full solve's cost grows
//! with the mesh and the reduced one's does not, so reduction pays on refined meshes and
//! not on the small ones people start with; nothing else tells a user which side of that
//! line their model is on.
//!
//! `train` times both time loops at a training load and stores the medians in the basis
//! file ([`time_routes`], [`crate::io::timing_file`]); `online` and `sweep` read them and
//! say in one line when the reduced model is not faster ([`speed_notice`]); `run` compares
//! the medians its validation measured and states the faster route in its report
//! ([`Comparison`]).

use crate::cost::timing::{median, repeat_timing};
use crate::error::Result;
use crate::io::basis_file::StoredBasis;
use crate::io::timing_file::RouteTiming;
use crate::linalg::kkt::LinearSolverKind;
use crate::rom::{Output, Rom};
use crate::simulate::{FullModel, Overrides};
use crate::solver::model::Parameters;
use std::path::Path;

/// Times the full time loop (banded solver) and the reduced one with its estimate at
/// the parameters `mu`, interleaved, one run at a time, within the budget of `validate`'s
/// timing ([`crate::cost::timing`]), and returns their medians.
pub fn time_routes(rom: &Rom, mu: &Parameters) -> Result<RouteTiming> {
    let model = &**rom.model();
    let o = Overrides::at(mu);
    let stage = |what: &'static str| move |e: crate::Error| e.at_stage(what, mu);
    let mut full = FullModel::new(model, LinearSolverKind::Banded).map_err(stage("train (timing the full run)"))?;
    let (mut full_times, mut rom_times, mut estimate_times) = (Vec::new(), Vec::new(), Vec::new());
    loop {
        full_times.push(full.simulate(&o).map_err(stage("train (timing the full run)"))?.wall_seconds);
        let (run, estimate) = rom
            .solve_and_estimate(mu, Output::ReducedAndProbes, &[])
            .map_err(stage("train (timing the reduced run)"))?;
        rom_times.push(run.result.wall_seconds);
        if let Some(e) = estimate {
            estimate_times.push(e.seconds);
        }
        let kinds: [&[f64]; 3] = [&full_times, &rom_times, &estimate_times];
        if !repeat_timing(if estimate_times.is_empty() { &kinds[..2] } else { &kinds }) {
            break;
        }
    }
    Ok(RouteTiming {
        load_scale: mu.scale(),
        named: mu.named().map(|(n, x)| (n.to_string(), x)).collect(),
        full_seconds: median(&mut full_times),
        reduced_seconds: median(&mut rom_times),
        estimate_seconds: if estimate_times.is_empty() { f64::NAN } else { median(&mut estimate_times) },
        estimate_method: rom.method().map(str::to_string),
        runs: full_times.len(),
        threads: 1,
    })
}

/// The training load that `train` times: the middle one of the basis's training loads
/// (the lower of the two middle ones of an even count).
pub fn timing_load(training_loads: &[f64]) -> Option<f64> {
    training_loads.get(training_loads.len().checked_sub(1)? / 2).copied()
}

/// Times both routes at the middle training load of the basis file at `path` (just
/// written, read back as `stored` and `rom`, its handle closed) and adds `/timing` to it. A
/// run that fails here leaves the basis without `/timing` and returns the warning that
/// says so.
pub fn time_and_store(stored: &StoredBasis, rom: &Rom, path: &Path) -> Result<Option<String>> {
    let Some(x) = timing_load(&stored.training.loads) else { return Ok(None) };
    // a basis of a [parameters] box: its centre (in the unit cube), inside the box
    let mu = match rom.trust().map(|t| &t.space).filter(|s| !s.is_empty()) {
        Some(space) => space.at(&vec![0.5; space.ranges.len()]),
        None => Parameters::load_scale(x),
    };
    match time_routes(rom, &mu) {
        Ok(t) => {
            crate::io::timing_file::append_timing(path, &t)?;
            Ok(None)
        }
        Err(e) => Ok(Some(format!(
            "the full and the reduced time loop could not be timed ({e}); the basis holds no /timing, and \
             `online` and `sweep` cannot say which route is faster"
        ))),
    }
}

/// Time per run of each route (s): the full time loop, the reduced one and its estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    pub full: f64,
    pub reduced: f64,
    /// `None`: the runs come without an estimate (no estimator, or `--no-estimate`)
    pub estimate: Option<f64>,
}

impl Comparison {
    /// The times stored by `train`, for runs made `with_estimate` (when the basis has one).
    pub fn stored(t: &RouteTiming, with_estimate: bool) -> Self {
        let estimate = if with_estimate && t.estimate_seconds.is_finite() { Some(t.estimate_seconds) } else { None };
        Comparison { full: t.full_seconds, reduced: t.reduced_seconds, estimate }
    }

    /// A reduced run as the user makes it: its time loop and its estimate.
    pub fn reduced_total(&self) -> f64 {
        self.reduced + self.estimate.unwrap_or(0.0)
    }

    /// Whether the reduced route is slower than the full one or as fast.
    pub fn full_is_faster(&self) -> bool {
        !(self.reduced_total() < self.full)
    }

    /// "17.5 ms reduced + 8.1 ms estimate against 10.9 ms full".
    pub fn figures(&self) -> String {
        let ms = |s: f64| format!("{:.3} ms", 1e3 * s);
        let estimate = self.estimate.map_or(String::new(), |e| format!(" + {} estimate", ms(e)));
        format!("{} reduced{estimate} against {} full", ms(self.reduced), ms(self.full))
    }

    /// One sentence for a report: which route is faster at this size and by how much.
    pub fn verdict(&self) -> String {
        let (r, f) = (self.reduced_total(), self.full);
        let reduced = if self.estimate.is_some() { "the reduced model with its estimate" } else { "the reduced model" };
        if self.full_is_faster() {
            format!(
                "At this size the full model is {:.2}× as fast as {reduced} ({} per run); it is exact, and \
                 `flexrom sweep --full` runs it at every load.",
                r / f,
                self.figures()
            )
        } else {
            format!("At this size {reduced} is {:.2}× as fast as the full model ({} per run).", f / r, self.figures())
        }
    }
}

impl Comparison {
    /// The one line saying that the reduced route is not faster than the full one, naming
    /// `what` (the basis file, the pipeline) and how the times were `measured`; `None` when
    /// the reduced route is faster.
    pub fn notice(&self, what: &Path, measured: &str) -> Option<String> {
        self.full_is_faster().then(|| {
            format!(
                "{}: the reduced model is not faster than the full one at this size ({} per run, {measured}); \
                 the full model is exact: `flexrom sweep --full` runs it at every load, `flexrom simulate` at one",
                what.display(),
                self.figures(),
            )
        })
    }
}

/// The one line `online` and `sweep` print when the basis file's timing (`timing`, made by
/// `train`) says that the reduced model, with its estimate when runs make one
/// (`with_estimate`), is not faster than the full one; `None` when it is faster.
pub fn speed_notice(basis: &Path, timing: &RouteTiming, with_estimate: bool) -> Option<String> {
    let at = std::iter::once(format!("load scale {}", timing.load_scale))
        .chain(timing.named.iter().map(|(n, x)| format!("{n} = {}", crate::solver::parameter_space::short_number(*x))))
        .collect::<Vec<_>>()
        .join(", ");
    let measured = format!("timed by `train` at {at}, one run at a time");
    Comparison::stored(timing, with_estimate).notice(basis, &measured)
}

/// [`speed_notice`] for the basis file at `path`, read as `stored` and run by `rom` (with
/// its estimate when it has an estimator); `None` also for a basis without `/timing`.
pub fn speed_notice_of(path: &Path, stored: &StoredBasis, rom: &Rom) -> Option<String> {
    let timing = stored.training.timing.as_ref()?;
    speed_notice(path, timing, rom.estimator().is_some())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(full: f64, reduced: f64, estimate: f64) -> RouteTiming {
        RouteTiming {
            load_scale: 0.935,
            named: Vec::new(),
            full_seconds: full,
            reduced_seconds: reduced,
            estimate_seconds: estimate,
            estimate_method: Some("corrected".into()),
            runs: 7,
            threads: 1,
        }
    }

    /// The notice counts the estimate only when runs make one, and says nothing when the
    /// reduced route is faster; the four-bar's figures of docs/benchmarks.md (full 10.9 ms,
    /// reduced 17.4 ms) read as slower with or without the estimate, the pendulum's (3.3 ms
    /// against 1.2 ms + 1.2 ms estimate) as faster only without it.
    #[test]
    fn the_notice_compares_the_route_as_it_runs() {
        let path = Path::new("b.h5");
        let fourbar = timing(10.9e-3, 17.4e-3, 8.1e-3);
        let line = speed_notice(path, &fourbar, true).expect("the reduced four-bar is slower");
        assert!(line.contains("17.400 ms reduced + 8.100 ms estimate against 10.900 ms full"), "{line}");
        assert!(line.contains("sweep --full") && line.contains("0.935") && !line.contains('\n'), "{line}");
        assert!(speed_notice(path, &fourbar, false).is_some());
        let pendulum = timing(3.3e-3, 1.2e-3, 2.4e-3);
        assert!(speed_notice(path, &pendulum, false).is_none());
        assert!(speed_notice(path, &pendulum, true).is_some(), "1.2 + 2.4 ms is not faster than 3.3 ms");
        // no estimator: the stored NaN does not count
        assert!(speed_notice(path, &timing(3.3e-3, 1.2e-3, f64::NAN), true).is_none());
        // as fast is not faster
        assert!(speed_notice(path, &timing(2e-3, 1e-3, 1e-3), true).is_some());
    }

    /// The verdict names the faster route and the ratio of the two times.
    #[test]
    fn the_verdict_names_the_faster_route() {
        let c = Comparison { full: 10e-3, reduced: 15e-3, estimate: Some(5e-3) };
        assert!(c.verdict().starts_with("At this size the full model is 2.00× as fast"), "{}", c.verdict());
        let c = Comparison { full: 9e-3, reduced: 2e-3, estimate: Some(1e-3) };
        assert!(c.verdict().starts_with("At this size the reduced model with its estimate is 3.00× as fast"));
        let c = Comparison { full: 9e-3, reduced: 3e-3, estimate: None };
        assert!(c.verdict().starts_with("At this size the reduced model is 3.00× as fast"), "{}", c.verdict());
    }

    /// The middle training load, the lower middle of an even count, none of none.
    #[test]
    fn the_timed_load_is_the_middle_training_load() {
        assert_eq!(timing_load(&[0.7, 0.95, 1.2]), Some(0.95));
        assert_eq!(timing_load(&[0.9, 1.1]), Some(0.9));
        assert_eq!(timing_load(&[1.0]), Some(1.0));
        assert_eq!(timing_load(&[]), None);
    }
}
