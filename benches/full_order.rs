//! Full-order benchmark: wall time of the time loop for the pendulum at growing
//! meshes (dt = 0.005, 220 steps) and for the four-bar, median of several runs, release
//! build, one core. Prints a Markdown table for the README.
//!
//!     cargo bench --bench full_order            # all sizes
//!     cargo bench --bench full_order -- quick   # 50 elements and the four-bar only

use flexrom::linalg::kkt::LinearSolverKind;
use flexrom::model::Model;
use flexrom::simulate::{simulate, Overrides};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn bench(model: &Model, solver: LinearSolverKind, runs: usize) -> (f64, usize, usize, usize) {
    let o = Overrides { solver, ..Default::default() };
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..runs {
        let r = simulate(model, &o).expect("benchmark run");
        times.push(r.wall_seconds);
        last = Some(r);
    }
    let r = last.unwrap();
    (median(times), r.stats.steps, r.stats.newton_iterations, r.stats.factorizations)
}

fn main() {
    // joins the OpenBLAS workers this binary's constructor started before any timing (the
    // library would at its first LAPACK call)
    flexrom::single_threaded_blas();
    // `cargo bench` passes `--bench`; anything else named `quick` shortens the run
    let quick = std::env::args().any(|a| a == "quick");
    let root = env!("CARGO_MANIFEST_DIR");
    let pendulum = std::fs::read_to_string(format!("{root}/data/models/pendulum.toml")).unwrap();
    let sizes: &[usize] = if quick { &[50] } else { &[50, 100, 200, 400, 800, 1600] };
    println!("| model | elements | coordinates | solver | steps | Newton it. | factorizations | median time (ms) | per step (µs) | per step per element (µs) |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for &n in sizes {
        let text = pendulum.replace("elements = 50", &format!("elements = {n}"));
        let m = Model::from_text(&text, format!("pendulum-{n}.toml")).unwrap();
        let runs = if n <= 200 { 9 } else { 5 };
        let (t, steps, it, fac) = bench(&m, LinearSolverKind::Banded, runs);
        println!(
            "| pendulum | {n} | {} | banded | {steps} | {it} | {fac} | {:.2} | {:.1} | {:.3} |",
            4 * (n + 1),
            1e3 * t,
            1e6 * t / steps as f64,
            1e6 * t / steps as f64 / n as f64
        );
    }
    let fourbar = Model::load(format!("{root}/data/models/fourbar.toml")).unwrap();
    for solver in [LinearSolverKind::Banded, LinearSolverKind::Sparse, LinearSolverKind::Dense] {
        let runs = if solver == LinearSolverKind::Dense { 3 } else { 9 };
        let (t, steps, it, fac) = bench(&fourbar, solver, runs);
        println!(
            "| four-bar | 110 | 452 | {} | {steps} | {it} | {fac} | {:.2} | {:.1} | {:.3} |",
            format!("{solver:?}").to_lowercase(),
            1e3 * t,
            1e6 * t / steps as f64,
            1e6 * t / steps as f64 / 110.0
        );
    }
}
