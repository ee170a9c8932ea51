//! Measures the error estimator (docs/error-estimate.md): trains a pipeline's basis at the
//! given training loads (in memory, nothing written but the basis under /tmp), then at
//! every test load runs the full model and the reduced model with its estimate, and prints
//! one row per load and a summary: coverage (estimate ≥ rel_error), median and max
//! effectivity (estimate / rel_error) inside and outside the training range, and the
//! estimator's cost relative to the reduced run (time loops only, median).
//!
//! ```text
//! cargo run --release --example estimate_table -- PIPELINE TRAIN_LOADS TEST_LOADS
//! cargo run --release --example estimate_table -- pipelines/thesis/pendulum_hyper.toml 0.5,1.0,1.5 0.4:1.6:15
//! ```
//!
//! The estimator's method is the default; `ESTIMATE_METHOD=corrected|defects|enriched` selects
//! one (docs/error-estimate.md); `ESTIMATE_SAMPLE=s` the defects method's sampling interval.

use flexrom::pipeline::config::parse_range;
use flexrom::pipeline::Pipeline;
use flexrom::rom::estimator::norms::{distance_and_norm, rel_error_by_time};
use flexrom::rom::estimator::{self, defects::Defects, ErrorEstimator, EstimateMethod};
use flexrom::rom::trust::is_extrapolated;
use flexrom::rom::{Output, Rom};
use flexrom::simulate::{simulate, Overrides};
use flexrom::solver::model::Parameters;
use flexrom::training::train::train;
use std::sync::Arc;

fn list(s: &str) -> Vec<f64> {
    if s.contains(':') {
        parse_range(s).expect("A:B:N")
    } else {
        s.split(',').map(|x| x.trim().parse().expect("number")).collect()
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

fn main() -> flexrom::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: estimate_table PIPELINE TRAIN_LOADS(a,b,c) TEST_LOADS(a,b,.. or A:B:N)");
        std::process::exit(2);
    }
    let mut p = Pipeline::load(&args[1])?;
    // the pipeline's reduction with these training loads (a greedy pipeline needs its
    // [reduction] modes given: e.g. pipelines/thesis/pendulum_hyper.toml)
    let train_loads = list(&args[2]);
    p.file.train.load_scales = Some(train_loads.clone());
    p.file.train.greedy = None;
    let tests = list(&args[3]);
    let (data, mut summary) = train(&p)?;
    // experiments (not the default): ESTIMATE_HYPER=none runs the enriched model over every
    // element; ESTIMATE_HYPER=<τ> retrains its ECSW set at τ
    if let Ok(h) = std::env::var("ESTIMATE_HYPER") {
        let est = summary.estimator.as_mut().expect("estimator");
        if h == "none" {
            est.enriched.hyper = None;
        } else {
            let tol: f64 = h.parse().expect("ESTIMATE_HYPER: none or a tolerance");
            let sys = p.model.system(Default::default());
            est.enriched.hyper = Some(flexrom::reduction::ecsw(&sys, &est.enriched, data.x.view(), tol).expect("ECSW"));
        }
        println!("experiment: ESTIMATE_HYPER={h}");
    }
    let method = match std::env::var("ESTIMATE_METHOD") {
        Ok(m) => EstimateMethod::parse(&m).expect("ESTIMATE_METHOD"),
        Err(_) => summary.estimator.as_ref().expect("estimator").default_method(),
    };
    let basis = Arc::new(summary.trained.basis.clone());
    let est = Arc::new(summary.estimator.clone().expect("train builds an estimator"));
    // experiments with the defects method: ESTIMATE_SAMPLE=s (default DEFECT_SAMPLE)
    let estimator: Arc<dyn ErrorEstimator> = match std::env::var("ESTIMATE_SAMPLE") {
        Ok(m) if method == EstimateMethod::Defects => {
            println!("experiment: ESTIMATE_SAMPLE={m}");
            Arc::new(
                Defects::new(&p.model, &basis, &est)?.with_sample(m.parse().expect("ESTIMATE_SAMPLE: a whole number")),
            )
        }
        _ => estimator::build(method, &p.model, &basis, &est)?,
    };
    println!("estimate method: {}", estimator.name());
    let lo = train_loads.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = train_loads.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    println!(
        "{}: training loads {:?}, {} modes (+{} in the estimator's basis, {} elements sampled / {} in the estimator's)",
        p.path.display(),
        train_loads,
        basis.n_reduced(),
        est.enriched.n_reduced() - basis.n_reduced(),
        basis.hyper.as_ref().map_or("all".into(), |h| h.elements.len().to_string()),
        est.enriched.hyper.as_ref().map_or("all".into(), |h| h.elements.len().to_string()),
    );
    println!("| load scale | inside | rel_error | error_estimate | effectivity | reduced (s) | estimator (s) | cost | error to 0.4 T / estimate |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let rom = Rom::new(&p.model, &basis, Some(estimator), None)?;
    let mut rows = Vec::new();
    for &x in &tests {
        let full = simulate(&p.model, &Overrides::at(&Parameters::load_scale(x)))?;
        let (run, e) = rom.solve_and_estimate(&Parameters::load_scale(x), Output::Full, &[])?;
        let e = e.expect("estimator");
        let (distance, norm) = distance_and_norm(&run.result.q, &full.q);
        let err = distance / norm;
        let inside = !is_extrapolated((lo, hi), x);
        let cost = e.seconds / run.result.wall_seconds;
        let by_time = rel_error_by_time(&run.result.q, &full.q);
        println!(
            "| {x:.4} | {} | {err:.3e} | {:.3e} | {:.2} | {:.4} | {:.4} | {:.0} % | {:.2e} / {:.2e} |",
            if inside { "yes" } else { "no" },
            e.error_estimate,
            e.error_estimate / err,
            run.result.wall_seconds,
            e.seconds,
            100.0 * cost,
            by_time[1],
            e.by_time[1]
        );
        rows.push((inside, err, e.error_estimate, cost));
    }
    println!("\n| loads | n | coverage | median effectivity | max effectivity | min effectivity |\n|---|---|---|---|---|---|");
    for (name, pick) in [("inside", Some(true)), ("outside", Some(false)), ("all", None)] {
        let sel: Vec<_> = rows.iter().filter(|r| pick.is_none_or(|i| r.0 == i)).collect();
        if sel.is_empty() {
            continue;
        }
        let covered = sel.iter().filter(|r| r.2 >= r.1).count();
        let mut eff: Vec<f64> = sel.iter().map(|r| r.2 / r.1).collect();
        let max = eff.iter().copied().fold(0.0, f64::max);
        let min = eff.iter().copied().fold(f64::INFINITY, f64::min);
        println!(
            "| {name} | {} | {}/{} | {:.2} | {:.2} | {:.2} |",
            sel.len(),
            covered,
            sel.len(),
            median(&mut eff),
            max,
            min
        );
    }
    let mut costs: Vec<f64> = rows.iter().map(|r| r.3).collect();
    println!("\nestimator cost / reduced run: median {:.0} %", 100.0 * median(&mut costs));
    Ok(())
}
