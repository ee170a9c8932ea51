//! Newton reaches its tolerance on refined meshes instead of stalling at the residual's
//! rounding (docs/reduced-speed.md, "The round-off floor"): at most 5 % of the steps may end
//! at the round-off floor (`Stats::steps_at_round_off`, the steps the stagnation test
//! ended; measured: none, but where exactly the rounding falls depends on the machine's
//! LAPACK and instruction set).
//!
//! - The shipped ×10 four-bar's reduced model (pipelines/fourbar_x10.toml: trained here in
//!   memory at its one training load λ = 0.935, 7 + 35 + 14 modes + 12 joint coordinates on
//!   ECSW's elements, ~4 s) at λ = 0.935 and 0.9, and at most 25 % more Newton iterations
//!   than the full run at the same load. Measured before 2026-11-27 (`L_r q` formed
//!   directly): over 100 of 157 steps at the floor (104 and 112 with `flexrom online`),
//!   8.45 and 8.52 iterations a step against the full run's 5.97 (41 % more); since: none,
//!   6.63 and 6.31 (11 % more at 0.935).
//! - The full 5000-element pendulum (data/models/pendulum_5000.toml, ~1 s) at λ = 1. Before
//!   (the elastic terms over absolute coordinates): 123 of 220 steps at the floor.

use flexrom::pipeline::Pipeline;
use flexrom::rom::Rom;
use flexrom::simulate::{simulate, Overrides};
use flexrom::solver::model::Parameters;
use flexrom::training::train::train;
use std::path::Path;
use std::sync::Arc;

fn repo(rel: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

#[test]
fn the_refined_four_bars_reduced_runs_reach_the_tolerance() {
    let p = Pipeline::load(repo("pipelines/fourbar_x10.toml")).expect("shipped pipeline");
    let (_, summary) = train(&p).expect("training");
    let basis = Arc::new(summary.trained.basis);
    let rom = Rom::new(&p.model, &basis, None, None).expect("reduced model");
    for x in [0.935, 0.9] {
        let mu = Parameters::load_scale(x);
        let full = simulate(&p.model, &Overrides::at(&mu)).expect("full run").stats;
        let reduced = rom.solve(&mu).expect("reduced run").result.stats;
        assert!(reduced.steps_at_round_off * 20 <= reduced.steps, "λ = {x}: {reduced:?}");
        let ratio = reduced.newton_iterations as f64 / full.newton_iterations as f64;
        assert!(ratio <= 1.25, "λ = {x}: {ratio:.2} times the full run's iterations ({reduced:?} against {full:?})");
    }
}

#[test]
fn the_5000_element_pendulums_full_run_reaches_the_tolerance() {
    let p = Pipeline::load(repo("pipelines/pendulum_5000.toml")).expect("shipped pipeline");
    let full = simulate(&p.model, &Overrides::at(&Parameters::load_scale(1.0))).expect("full run").stats;
    assert!(full.steps_at_round_off * 20 <= full.steps, "{full:?}");
}
