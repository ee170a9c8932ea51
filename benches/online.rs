//! Online benchmark: full (banded, our default) against reduced runs of the
//! shipped pipelines, at the thesis meshes and refined, in one process: each pipeline is
//! trained in memory, then full and reduced runs alternate, `runs` times each; the table
//! gives medians of the time loops (release build, one core, BLAS single-threaded) and the
//! error of the reduced model against the full one at the same Δt. Then the 100-scale sweep
//! of the thesis four-bar is timed as a whole process (`flexrom sweep`, both cores).
//!
//!     cargo bench --bench online            # everything (about two minutes)
//!     cargo bench --bench online -- quick   # the thesis meshes only

use flexrom::pipeline::Pipeline;
use flexrom::rom::Rom;
use flexrom::simulate::{simulate, Overrides};
use flexrom::solver::model::Parameters;
use flexrom::training::train::{train, train_and_write};
use flexrom::workflows::validate::compare;
use std::process::Command;
use std::sync::Arc;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() {
    // joins the OpenBLAS workers this binary's constructor started before any timing (the
    // library would at its first LAPACK call)
    flexrom::single_threaded_blas();
    let quick = std::env::args().any(|a| a == "quick");
    let root = env!("CARGO_MANIFEST_DIR");
    let cases: &[(&str, usize)] = if quick {
        &[("pendulum", 9), ("fourbar", 5)]
    } else {
        &[("pendulum", 9), ("fourbar", 5), ("pendulum_500", 5), ("pendulum_5000", 3), ("fourbar_x10", 3)]
    };
    println!("| pipeline | coordinates | elements | reduced coordinates | sampled elements | full (ms) | reduced (ms) | speedup | rel_error | max probe error (m) | Newton it. full / reduced |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for &(name, runs) in cases {
        let p = Pipeline::load(format!("{root}/pipelines/{name}.toml")).expect("shipped pipeline");
        let (_, summary) = train(&p).expect("training");
        let basis = Arc::new(summary.trained.basis);
        let reduced = Rom::new(&p.model, &basis, None, None).expect("reduced model");
        // the thesis load: the (first) training load scale of each shipped pipeline; for a
        // greedy pipeline the middle of its range
        let x = match &p.file.train.load_scales {
            Some(s) => s[0],
            None => p.training_scales()[1],
        };
        let (mut tf, mut tr) = (Vec::new(), Vec::new());
        let mut last = None;
        for _ in 0..runs {
            let full = simulate(&p.model, &Overrides::at(&Parameters::load_scale(x))).expect("full run");
            let rom = reduced.solve(&Parameters::load_scale(x)).expect("reduced run");
            tf.push(full.wall_seconds);
            tr.push(rom.result.wall_seconds);
            last = Some((full, rom));
        }
        let (full, rom) = last.expect("at least one run");
        let v = compare(&p.model, &full, &rom, None, basis.n_reduced(), basis.variant.name());
        let sys = p.model.system(Default::default());
        let sampled = basis.hyper.as_ref().map_or_else(|| "all".to_string(), |h| h.elements.len().to_string());
        let (f, r) = (median(tf), median(tr));
        println!(
            "| {name} | {} | {} | {} | {sampled} | {:.2} | {:.3} | {:.1} | {:.2e} | {:.2e} | {} / {} |",
            full.q.nrows(),
            sys.n_elements(),
            basis.n_reduced(),
            1e3 * f,
            1e3 * r,
            f / r,
            v.rel_error,
            v.max_probe_error,
            full.stats.newton_iterations,
            rom.result.stats.newton_iterations
        );
    }

    // the sweep users came for: 100 load scales of the thesis four-bar, whole process
    let p = Pipeline::load(format!("{root}/pipelines/fourbar.toml")).expect("shipped pipeline");
    let dir = std::env::temp_dir().join(format!("flexrom-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let basis = dir.join("fourbar.h5");
    train_and_write(&p, &basis).expect("training");
    let exe = format!("{root}/target/release/flexrom");
    println!();
    for extra in [None, Some("--continuation")] {
        let mut times = Vec::new();
        for _ in 0..3 {
            let start = std::time::Instant::now();
            let out = Command::new(&exe)
                .args(["sweep", &format!("{root}/pipelines/fourbar.toml"), "--load-scales", "0.85:1.0:100", "--basis"])
                .arg(&basis)
                .arg("-o")
                .arg(dir.join("sweep.h5"))
                .args(extra)
                .output()
                .expect("flexrom sweep (build it first: cargo build --release)");
            assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
            times.push(start.elapsed().as_secs_f64());
        }
        println!(
            "`flexrom sweep pipelines/fourbar.toml --load-scales 0.85:1.0:100{}`, whole process, median of 3: {:.2} s",
            extra.map_or(String::new(), |e| format!(" {e}")),
            median(times)
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
