//! The zoo: mechanisms nobody tuned flexrom on, drawn reproducibly from a seed, with the
//! pipeline a new user would write for each (greedy training over the load range with a
//! tolerance, nothing else set) and held-out validation loads. Shared by the benchmark
//! `examples/zoo.rs` and the regression test `tests/zoo.rs` (docs/zoo.md); both drive the
//! release binary as a subprocess (`drive.rs`) and judge the estimate with `metrics.rs`.
//!
//! Slot `i` of a zoo draws its kind (`mechanisms::kind_of`: `KINDS[i mod 8]` for the first
//! 24 slots, the zoo before sliders, welds, point masses and drives by angle; `NEW_KINDS[(i −
//! 24) mod 4]` after them up to slot 32; `SPRING_KINDS[(i − 32) mod 4]`, the kinds with
//! spring-dampers, from there) from its own stream (seed, slot, attempt), so a slot's model does
//! not depend on how many slots are drawn: the subset is the same models as in the whole zoo,
//! and growing the zoo left its first 24 models as they were. A model whose full run fails at either end of the load range,
//! or at a load greedy training or the validation would run it at (`check_loads`), is
//! replaced by the slot's next attempt (the report counts them): such a model says nothing
//! about the reduction, and a full run that fails inside the range would end its training.
#![allow(dead_code)]

pub mod drive;
pub mod mechanisms;
pub mod metrics;
pub mod parts;
pub mod springs;

use mechanisms::{build, kind_of, Kind, Mechanism};
use parts::Rng;
use std::fmt::Write;

/// The zoo of docs/zoo.md.
pub const DEFAULT_SEED: u64 = 2026;
/// The slots of the whole zoo: 24 of the first eight kinds, 8 of the four kinds with
/// sliders, welds, drives by angle and point masses, 8 of the four with spring-dampers.
pub const SLOTS: usize = 40;
/// The load range every pipeline trains over; its ends are where a model must run.
pub const RANGE: (f64, f64) = (0.5, 1.5);
pub const MAX_RUNS: usize = 10;
/// greedy's default number of candidate loads (docs/greedy-training.md): the validation
/// loads lie between them
pub const GREEDY_CANDIDATES: usize = 33;
/// Attempts per slot before the zoo gives up on a slot (a kind that never runs).
pub const MAX_ATTEMPTS: usize = 20;
/// The slots of the subset (`--subset`, tests/zoo.rs): one of each first kind but the frame
/// and the pendulum, the kinds with an estimate that failed on the baseline of docs/zoo.md
/// among them, and the first slider-crank (a slider, a drive by angle and a point mass; about
/// 20 s of runs on two cores, docs/zoo.md).
pub const SUBSET: [usize; 7] = [1, 2, 3, 4, 5, 7, 24];

/// One drawn model.
pub struct ZooModel {
    pub slot: usize,
    /// 0 for the slot's first draw; k after k replacements
    pub attempt: usize,
    pub kind: Kind,
    pub mechanism: Mechanism,
}

impl ZooModel {
    /// `07-five-bar`: the slot and the kind.
    pub fn name(&self) -> String {
        format!("{:02}-{}", self.slot, self.kind.name())
    }
}

/// The model of `slot`, attempt `attempt`, of the zoo with seed `seed`.
pub fn draw(seed: u64, slot: usize, attempt: usize) -> ZooModel {
    let kind = kind_of(slot);
    let mut rng = Rng::new(seed, slot, attempt);
    ZooModel { slot, attempt, kind, mechanism: build(kind, &mut rng) }
}

/// A model that was replaced, and why.
pub struct Replacement {
    pub slot: usize,
    pub attempt: usize,
    pub reason: String,
}

/// The model of `slot`: the first attempt for which `runs` (the full model at every load of
/// [`check_loads`]) succeeds, and the attempts replaced before it. `Err` after [`MAX_ATTEMPTS`].
pub fn accepted(
    seed: u64,
    slot: usize,
    mut runs: impl FnMut(&ZooModel) -> Result<(), String>,
) -> Result<(ZooModel, Vec<Replacement>), String> {
    let mut replaced = Vec::new();
    for attempt in 0..MAX_ATTEMPTS {
        let m = draw(seed, slot, attempt);
        match runs(&m) {
            Ok(()) => return Ok((m, replaced)),
            Err(reason) => replaced.push(Replacement { slot, attempt, reason }),
        }
    }
    Err(format!("slot {slot}: no model of {MAX_ATTEMPTS} attempts ran at both ends of the range"))
}

/// Eight loads that are neither training nor candidate loads: midpoints between greedy's
/// [`GREEDY_CANDIDATES`] evenly spaced candidates (training loads are candidates or the
/// range's ends), eight of the 32 intervals spread evenly from the first to the last.
pub fn validation_loads() -> Vec<f64> {
    let (a, b) = RANGE;
    let intervals = GREEDY_CANDIDATES - 1;
    let h = (b - a) / intervals as f64;
    (0..8)
        .map(|i| {
            let k = (i * (intervals - 1) + 3) / 7; // 0, 4, 9, 13, 18, 22, 27, 31
            a + (k as f64 + 0.5) * h
        })
        .collect()
}

/// Where a model's full run must complete: the range's ends first, then the validation loads,
/// then the other candidate loads (greedy runs the full model at candidates only).
pub fn check_loads() -> Vec<f64> {
    let (a, b) = RANGE;
    let n = GREEDY_CANDIDATES;
    let mut loads = vec![a, b];
    loads.extend(validation_loads());
    loads.extend((1..n - 1).map(|i| a + (b - a) * i as f64 / (n - 1) as f64));
    loads
}

/// What a zoo run sets beyond the defaults: an online estimate method (`[online]
/// estimate`, with the validation loads as its sweep), greedy's `measure`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Choices<'a> {
    pub estimate: Option<&'a str>,
    pub measure: Option<&'a str>,
}

/// The pipeline a user writes for a model: greedy over [`RANGE`] to `tolerance` with at
/// most [`MAX_RUNS`] full runs, nothing else set but `choices`.
pub fn pipeline_toml(model: &str, basis: &str, tolerance: f64, choices: Choices) -> String {
    let Choices { estimate, measure } = choices;
    let measure = measure.map_or(String::new(), |m| format!(", measure = {m:?}"));
    let loads: Vec<String> = validation_loads().iter().map(|x| format!("{x:?}")).collect();
    let mut s = String::new();
    let _ = writeln!(s, "model = {model:?}\nbasis = {basis:?}\nreport = \"report\"\n");
    let _ = writeln!(
        s,
        "[train]\ngreedy = {{ range = [{:?}, {:?}], tolerance = {tolerance:e}, max_runs = {MAX_RUNS}{measure} }}\n",
        RANGE.0, RANGE.1
    );
    if let Some(m) = estimate {
        let _ = writeln!(s, "[online]\nload_scales = [{}]\nestimate = {m:?}\n", loads.join(", "));
    }
    let _ = writeln!(s, "[validate]\nload_scales = [{}]", loads.join(", "));
    s
}
