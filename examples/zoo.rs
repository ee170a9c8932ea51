//! The zoo benchmark (docs/zoo.md): greedy training and held-out validation of the error
//! estimate on mechanisms nobody tuned flexrom on, drawn from a seed
//! (tests/common/zoo/). Drives the release binary as a subprocess, as a user would:
//!
//! ```text
//! cargo build --release
//! cargo run --release --example zoo -- [--seed S] [--models N | --slots A..B] [--out DIR]
//!     [--tolerances 5e-3,1e-2] [--subset] [--jobs 2] [--estimate METHOD] [--measure M] [--no-methods] [--draw-only] [--resume]
//!     [--flexrom PATH]
//! ```
//!
//! For every model and tolerance: `train` (greedy over [0.5, 1.5], `max_runs = 10`), then
//! `validate --json` at 8 loads that are neither training nor candidate loads; per model the
//! convergence and its reason, full runs, modes, sampled elements, speedup, the estimate
//! method, coverage over the whole run and per fifth, effectivity and estimator cost; over
//! all models the aggregate targets of docs/zoo.md (tests/common/zoo/metrics.rs), and the
//! same for each probe quantity (the tip's position, the roots' strain and curvature:
//! `probe_quantity_errors`, reported beside the targets, not held to them). `--estimate
//! METHOD` validates with that method (`[online] estimate`) instead of the one training
//! chose; the training is the same (`--resume` in a copy of a finished run's folder reuses
//! it). Where a model's
//! default estimate fails (reads under the error, or over it by more than 20×) it is
//! validated again with each method (`[online] estimate`). Writes DIR/zoo.md (Markdown
//! tables) and DIR/zoo.json (every number), DIR/models/NAME/ the model and pipelines.
//! `--draw-only` writes the models and pipelines and stops; `--resume` reads back what an
//! interrupted run of the same binary kept (every process's output is kept beside its
//! pipeline) instead of running it again. At most `--jobs` (≤ 2) flexrom processes at a time, each with `--threads 1`.

#[path = "../tests/common/zoo/mod.rs"]
mod zoo;

use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;
use zoo::drive::{Flexrom, Training, Validation};
use zoo::metrics::{
    aggregate, estimate_fails, fallback_stats, model_stats, quantity_cases, quantity_stats, Aggregate, ModelStats,
    QuantityCase, QuantityStats,
};
use zoo::{accepted, pipeline_toml, validation_loads, Choices, Replacement, ZooModel};

const METHODS: [&str; 3] = ["corrected", "defects", "enriched"];

struct Args {
    seed: u64,
    models: usize,
    /// `--slots A..B`: these slots only (the new kinds' slots: `--slots 24..32`)
    slots: Option<std::ops::Range<usize>>,
    out: PathBuf,
    tolerances: Vec<f64>,
    subset: bool,
    jobs: usize,
    /// `--estimate METHOD`: validate with this method instead of training's choice
    estimate: Option<String>,
    /// `--measure M`: greedy's `measure` (`"probes"`: held to the root probes too)
    measure: Option<String>,
    methods: bool,
    draw_only: bool,
    resume: bool,
    flexrom: Option<PathBuf>,
}

fn usage(msg: &str) -> ! {
    eprintln!("zoo: {msg}\nusage: zoo [--seed S] [--models N | --slots A..B] [--out DIR] [--tolerances 5e-3,1e-2] [--subset] [--jobs 1|2] [--estimate corrected|defects|enriched] [--measure relative|displacement|probes] [--no-methods] [--draw-only] [--resume] [--flexrom PATH]");
    std::process::exit(2)
}

fn args() -> Args {
    let mut a = Args {
        seed: zoo::DEFAULT_SEED,
        models: zoo::SLOTS,
        slots: None,
        out: PathBuf::from("target/zoo"),
        tolerances: vec![5e-3, 1e-2],
        subset: false,
        jobs: 2,
        estimate: None,
        measure: None,
        methods: true,
        draw_only: false,
        resume: false,
        flexrom: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(k) = it.next() {
        let mut value = || it.next().unwrap_or_else(|| usage(&format!("{k} needs a value")));
        match k.as_str() {
            "--seed" => a.seed = value().parse().unwrap_or_else(|_| usage("--seed: not an integer")),
            "--models" => a.models = value().parse().unwrap_or_else(|_| usage("--models: not an integer")),
            "--slots" => {
                let v = value();
                let r = v
                    .split_once("..")
                    .and_then(|(x, y)| Some(x.trim().parse::<usize>().ok()?..y.trim().parse::<usize>().ok()?))
                    .filter(|r| r.start < r.end)
                    .unwrap_or_else(|| usage("--slots: A..B with A < B (slots A to B − 1)"));
                a.slots = Some(r)
            }
            "--out" => a.out = PathBuf::from(value()),
            "--tolerances" => {
                a.tolerances = value()
                    .split(',')
                    .map(|t| t.trim().parse::<f64>().ok().filter(|t| *t > 0.0 && t.is_finite()))
                    .collect::<Option<_>>()
                    .unwrap_or_else(|| usage("--tolerances: positive numbers separated by commas"))
            }
            "--jobs" => {
                a.jobs = value().parse().ok().filter(|j| (1..=2).contains(j)).unwrap_or_else(|| usage("--jobs: 1 or 2"))
            }
            "--estimate" => {
                let m = value();
                if !METHODS.contains(&m.as_str()) {
                    usage(&format!("--estimate: one of {}", METHODS.join(", ")));
                }
                a.estimate = Some(m)
            }
            "--measure" => {
                let m = value();
                if !["relative", "displacement", "probes"].contains(&m.as_str()) {
                    usage("--measure: relative, displacement or probes");
                }
                a.measure = Some(m)
            }
            "--subset" => a.subset = true,
            "--no-methods" => a.methods = false,
            "--draw-only" => a.draw_only = true,
            "--resume" => a.resume = true,
            "--flexrom" => a.flexrom = Some(PathBuf::from(value())),
            _ => usage(&format!("unknown argument {k}")),
        }
    }
    if a.models == 0 {
        usage("--models: at least 1");
    }
    a
}

/// The release binary beside this example's directory (target/release/flexrom).
fn find_flexrom(given: Option<PathBuf>) -> PathBuf {
    let bin = given.unwrap_or_else(|| {
        let exe = std::env::current_exe().expect("the example's path");
        exe.parent().and_then(Path::parent).map_or_else(|| PathBuf::from("flexrom"), |d| d.join("flexrom"))
    });
    if !bin.is_file() {
        eprintln!("zoo: {} not found; build it first: cargo build --release", bin.display());
        std::process::exit(1);
    }
    bin
}

/// Writes `text` to `path` through a temporary file in the same directory.
fn write_atomic(path: &Path, text: &str) {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, text)
        .and_then(|()| std::fs::rename(&tmp, path))
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
}

/// Writes a model file; where it replaces a different one, the outputs kept from runs of
/// the old model (`*.done`, tests/common/zoo/drive.rs) no longer count.
fn write_model(dir: &Path, text: &str) {
    let path = dir.join("model.toml");
    if std::fs::read_to_string(&path).is_ok_and(|old| old == text) {
        return;
    }
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            if e.path().extension().is_some_and(|x| x == "done") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
    write_atomic(&path, text);
}

/// One model at one tolerance.
#[derive(serde::Serialize)]
struct Entry {
    model: String,
    tolerance: f64,
    training: Result<Training, String>,
    validations: Vec<Result<Validation, String>>,
    /// the method the validations used: `--estimate`'s, else training's choice
    method: String,
    stats: ModelStats,
    /// the other estimate methods, where the default failed
    methods: Vec<MethodRun>,
    /// wall time of the whole entry: training, validations, other methods
    wall_seconds: f64,
}

#[derive(serde::Serialize)]
struct MethodRun {
    method: String,
    validations: Vec<Result<Validation, String>>,
    stats: ModelStats,
}

#[derive(serde::Serialize)]
struct ModelInfo {
    name: String,
    slot: usize,
    attempt: usize,
    kind: &'static str,
    bodies: usize,
    elements: usize,
    coordinates: usize,
    summary: String,
}

fn validate_all(fx: &Flexrom, dir: &Path, pipeline: &str) -> Vec<Result<Validation, String>> {
    validation_loads().into_iter().map(|x| fx.validate(dir, pipeline, x)).collect()
}

fn tol_tag(t: f64) -> String {
    format!("{t:e}")
}

/// Trains the model at `tolerance` and validates it with `estimate` (None: training's choice),
/// through a pipeline of its own with the same basis (the one `run_methods` writes).
fn run_entry(fx: &Flexrom, dir: &Path, name: &str, tolerance: f64, choices: Choices) -> Entry {
    let (estimate, measure) = (choices.estimate, choices.measure);
    let tag = tol_tag(tolerance);
    let (pipeline, basis) = (format!("pipeline_{tag}.toml"), format!("basis_{tag}.h5"));
    write_atomic(
        &dir.join(&pipeline),
        &pipeline_toml("model.toml", &basis, tolerance, Choices { estimate: None, measure }),
    );
    let training = fx.train(dir, &pipeline);
    let checked = match estimate {
        Some(m) => {
            let p = format!("pipeline_{tag}_{m}.toml");
            write_atomic(&dir.join(&p), &pipeline_toml("model.toml", &basis, tolerance, choices));
            p
        }
        None => pipeline,
    };
    let validations = if training.is_ok() { validate_all(fx, dir, &checked) } else { Vec::new() };
    let stats = model_stats(&validations);
    let method = estimate.map(str::to_string).or_else(|| training.as_ref().ok().map(|t| t.method.clone()));
    Entry {
        model: name.into(),
        tolerance,
        training,
        validations,
        method: method.unwrap_or_else(|| "–".into()),
        stats,
        methods: Vec::new(),
        wall_seconds: 0.0,
    }
}

fn run_methods(fx: &Flexrom, dir: &Path, e: &mut Entry, measure: Option<&str>) {
    let tag = tol_tag(e.tolerance);
    for m in METHODS {
        let pipeline = format!("pipeline_{tag}_{m}.toml");
        write_atomic(
            &dir.join(&pipeline),
            &pipeline_toml(
                "model.toml",
                &format!("basis_{tag}.h5"),
                e.tolerance,
                Choices { estimate: Some(m), measure },
            ),
        );
        let validations = validate_all(fx, dir, &pipeline);
        let stats = model_stats(&validations);
        e.methods.push(MethodRun { method: m.into(), validations, stats });
    }
}

fn pct(x: f64) -> String {
    format!("{:.0} %", 100.0 * x)
}

fn g3(x: f64) -> String {
    if x.is_nan() {
        "–".into()
    } else if x.is_infinite() {
        "∞".into()
    } else if (0.01..1000.0).contains(&x.abs()) {
        format!("{x:.3}").trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{x:.2e}")
    }
}

fn aggregate_row(a: &Aggregate) -> String {
    format!(
        "| {}/{} ({}) | {}/{} ({:.1} %) | {} | {}/{} ({:.1} %) | {} | {} | {} | {} |",
        a.converged,
        a.models,
        pct(a.share_converged()),
        a.covered_pairs,
        a.pairs,
        100.0 * a.pair_coverage(),
        a.silent_under_pairs,
        a.covered_triples,
        a.triples,
        100.0 * a.triple_coverage(),
        g3(a.effectivity_median),
        g3(a.effectivity_p95),
        g3(a.effectivity_max),
        pct(a.cost_median)
    )
}

const AGG_HEAD: &str = "| converged | coverage (model, load) | under without a warning | coverage (model, load, fifth) | effectivity median | 95th pct | max | estimator cost median |\n|---|---|---|---|---|---|---|---|";

fn short_reason(t: &Training) -> String {
    if t.converged {
        return "yes".into();
    }
    // "iteration n: no full run left (max_runs = 10), worst estimate X > T at λ = …"
    let r = &t.reason;
    let worst = r.split("worst estimate ").nth(1).and_then(|s| s.split_whitespace().next()).unwrap_or("?");
    if r.contains("no full run left") {
        format!("no: max_runs spent, worst score {worst}")
    } else if r.contains("every candidate has a full run") {
        format!("no: every candidate run, worst score {worst}")
    } else {
        "no".into()
    }
}

fn fifths(c: &[f64; 5]) -> String {
    c.iter().map(|x| format!("{:.0}", 100.0 * x)).collect::<Vec<_>>().join("/")
}

fn model_row(info: &ModelInfo, e: &Entry) -> String {
    let s = &e.stats;
    match &e.training {
        Err(msg) => format!(
            "| {} | {}/{}/{} | training failed: {} | | | | | | | | | | |",
            info.name,
            info.bodies,
            info.elements,
            info.coordinates,
            msg.replace('|', "/")
        ),
        Ok(t) => format!(
            "| {} | {}/{}/{} | {} | {} | {} | {} | {} | {} | {}/{} | {} | {} | {} | {} |",
            info.name,
            info.bodies,
            info.elements,
            info.coordinates,
            short_reason(t),
            t.full_runs,
            if t.joint_coordinates > 0 {
                format!("{}+{}", t.pod_modes, t.joint_coordinates)
            } else {
                t.pod_modes.to_string()
            },
            t.elements.map_or("–".into(), |n| n.to_string()),
            g3(s.speedup_median),
            e.method,
            s.covered_pairs,
            s.loads,
            fifths(&s.coverage_by_fifth),
            g3(s.effectivity_median),
            g3(s.effectivity_max),
            pct(s.cost_median)
        ),
    }
}

const MODEL_HEAD: &str = "| model | bodies/elements/coordinates | converged | full runs | modes | sampled elements | speedup | method | covered loads | coverage by fifth (%) | effectivity median | max | estimator cost |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|";

fn method_row(name: &str, tol: f64, m: &MethodRun) -> String {
    let s = &m.stats;
    format!(
        "| {name} | {} | {} | {}/{} | {} | {} | {} | {} | {} | {} |",
        tol_tag(tol),
        m.method,
        s.covered_pairs,
        s.loads,
        fifths(&s.coverage_by_fifth),
        g3(s.effectivity_min),
        g3(s.effectivity_median),
        g3(s.effectivity_max),
        g3(s.fifth_effectivity_min),
        pct(s.cost_median)
    )
}

/// CPU seconds (user + system) of the finished child processes (Linux: /proc/self/stat's
/// cutime and cstime, in clock ticks of `getconf CLK_TCK`); None elsewhere. On a shared
/// machine this is the figure to compare: the wall time depends on the other users.
fn children_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // the fields after the command name in parentheses; cutime and cstime are the 16th and 17th
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(13)?.parse::<f64>().ok()? + f.get(14)?.parse::<f64>().ok()?;
    let o = std::process::Command::new("getconf").arg("CLK_TCK").output().ok()?;
    let hz: f64 = String::from_utf8_lossy(&o.stdout).trim().parse().ok()?;
    Some(ticks / hz)
}

fn replaced_json(r: &[Replacement]) -> serde_json::Value {
    r.iter().map(|r| serde_json::json!({"slot": r.slot, "attempt": r.attempt, "reason": r.reason})).collect()
}

const FAIL_HEAD: &str = "| model | tolerance | default | loads under (whole run) | triples under | worst under: true / estimate (whole, by fifth) | max effectivity | methods that hold |\n|---|---|---|---|---|---|---|---|";

/// How a model's default estimate failed, and which methods hold there (every load and
/// fifth covered, effectivity ≤ 20: `metrics::estimate_fails` false).
fn failure_row(name: &str, e: &Entry) -> String {
    let s = &e.stats;
    let method = &e.method;
    let holds: Vec<&str> = e.methods.iter().filter(|m| !estimate_fails(&m.stats)).map(|m| m.method.as_str()).collect();
    format!(
        "| {name} | {} | {method} | {}/{} | {}/{} | {}, {} | {} | {} |",
        tol_tag(e.tolerance),
        s.under_pairs,
        s.loads,
        s.under_triples,
        5 * s.loads,
        g3(1.0 / s.effectivity_min),
        g3(1.0 / s.fifth_effectivity_min),
        g3(s.effectivity_max),
        if holds.is_empty() { "none".to_string() } else { holds.join(", ") }
    )
}

const QUANTITY_HEAD: &str = "| quantity | (model, load, probe) | no swing | covered | effectivity median | 95th pct | max |\n|---|---|---|---|---|---|---|";

fn quantity_row(q: &QuantityStats) -> String {
    format!(
        "| {} | {} | {} | {}/{} ({:.1} %) | {} | {} | {} |",
        q.quantity,
        q.cases,
        q.no_swing,
        q.covered,
        q.cases,
        100.0 * q.coverage(),
        g3(q.effectivity_median),
        g3(q.effectivity_p95),
        g3(q.effectivity_max)
    )
}

fn case_line(c: &QuantityCase) -> String {
    format!(
        "{} λ = {} {} {}: error {}, estimate {}, effectivity {}",
        c.model,
        c.load_scale,
        c.probe,
        c.quantity,
        g3(c.relative),
        g3(c.estimate),
        g3(c.effectivity)
    )
}

/// The probe quantities' table, the targets they miss (reported, not held) and each
/// quantity's extreme cases.
fn quantity_section(qs: &[QuantityStats]) -> String {
    let mut md =
        format!("Probe quantities (error over the full run's range, `probe_quantity_errors`):\n\n{QUANTITY_HEAD}\n");
    for q in qs {
        let _ = writeln!(md, "{}", quantity_row(q));
    }
    let missed: Vec<String> = qs.iter().flat_map(QuantityStats::missed).collect();
    let _ = writeln!(
        md,
        "\nTargets (coverage ≥ 95 %, median effectivity ≤ 3; reported, not held): {}.\n",
        if missed.is_empty() { "met".to_string() } else { format!("missed: {}", missed.join("; ")) }
    );
    for q in qs.iter().filter(|q| q.cases > 0) {
        let lowest: Vec<String> = q.lowest.iter().map(case_line).collect();
        let highest: Vec<String> = q.highest.iter().map(case_line).collect();
        let _ = writeln!(md, "- {} lowest: {}", q.quantity, lowest.join("; "));
        let _ = writeln!(md, "- {} highest: {}", q.quantity, highest.join("; "));
    }
    md.push('\n');
    md
}

fn commit() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "--short", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map_or("unknown".into(), |o| String::from_utf8_lossy(&o.stdout).trim().to_string())
}

fn main() {
    let a = args();
    let fx = Flexrom { bin: find_flexrom(a.flexrom.clone()), resume: a.resume };
    let start = Instant::now();
    // never write into a directory of something else
    if a.out.is_dir()
        && std::fs::read_dir(&a.out).is_ok_and(|mut d| d.next().is_some())
        && !a.out.join("zoo.json").is_file()
    {
        eprintln!("zoo: {} exists and holds no earlier zoo run (zoo.json); choose another --out", a.out.display());
        std::process::exit(1);
    }
    let slots: Vec<usize> = match (&a.slots, a.subset) {
        (_, true) => zoo::SUBSET.to_vec(),
        (Some(r), false) => r.clone().collect(),
        (None, false) => (0..a.models).collect(),
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(a.jobs).build().expect("a thread pool");
    let models_dir = a.out.join("models");

    // 1. the models: each slot's first draw whose full runs at both ends of the range complete
    let drawn: Vec<Result<(ZooModel, Vec<Replacement>), String>> = pool.install(|| {
        slots
            .par_iter()
            .map(|&slot| {
                accepted(a.seed, slot, |m| {
                    let dir = models_dir.join(m.name());
                    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
                    write_model(&dir, &m.mechanism.toml);
                    fx.full_runs_complete(&dir, "model.toml")
                })
            })
            .collect()
    });
    let mut models = Vec::new();
    let mut replaced = Vec::new();
    for d in drawn {
        match d {
            Ok((m, r)) => {
                models.push(m);
                replaced.extend(r);
            }
            Err(e) => {
                eprintln!("zoo: {e}");
                std::process::exit(1);
            }
        }
    }
    let infos: Vec<ModelInfo> = models
        .iter()
        .map(|m| ModelInfo {
            name: m.name(),
            slot: m.slot,
            attempt: m.attempt,
            kind: m.kind.name(),
            bodies: m.mechanism.n_bodies,
            elements: m.mechanism.n_elements,
            coordinates: m.mechanism.n_coordinates,
            summary: m.mechanism.summary.clone(),
        })
        .collect();
    eprintln!(
        "zoo: {} models (seed {}), {} replaced, drawn in {:.0} s",
        models.len(),
        a.seed,
        replaced.len(),
        start.elapsed().as_secs_f64()
    );

    if a.draw_only {
        for (m, i) in models.iter().zip(&infos) {
            let dir = models_dir.join(&i.name);
            for &t in &a.tolerances {
                let tag = tol_tag(t);
                let choices = Choices { estimate: None, measure: a.measure.as_deref() };
                let text = pipeline_toml("model.toml", &format!("basis_{tag}.h5"), t, choices);
                write_atomic(&dir.join(format!("pipeline_{tag}.toml")), &text);
            }
            println!(
                "{}{}: {}",
                i.name,
                if m.attempt > 0 { format!(" (attempt {})", m.attempt) } else { String::new() },
                i.summary
            );
        }
        for r in &replaced {
            println!("replaced: slot {} attempt {}: {}", r.slot, r.attempt, r.reason);
        }
        let json = serde_json::json!({ "seed": a.seed, "models": infos, "replaced": replaced_json(&replaced) });
        write_atomic(&a.out.join("zoo.json"), &serde_json::to_string_pretty(&json).expect("JSON"));
        return;
    }

    // 2. train and validate every model at every tolerance, the largest first: each of the
    // `--jobs` workers takes the next job of the list (longest first, so the long ones do
    // not start last and leave one worker idle at the end)
    let mut jobs: Vec<(usize, f64)> =
        (0..models.len()).flat_map(|i| a.tolerances.iter().map(move |&t| (i, t))).collect();
    jobs.sort_by_key(|&(i, _)| std::cmp::Reverse(models[i].mechanism.n_coordinates));
    let run_job = |(i, t): (usize, f64)| -> (usize, Entry) {
        let name = infos[i].name.clone();
        let t0 = Instant::now();
        let choices = Choices { estimate: a.estimate.as_deref(), measure: a.measure.as_deref() };
        let mut e = run_entry(&fx, &models_dir.join(&name), &name, t, choices);
        if a.methods && e.training.is_ok() && estimate_fails(&e.stats) {
            run_methods(&fx, &models_dir.join(&name), &mut e, a.measure.as_deref());
        }
        e.wall_seconds = t0.elapsed().as_secs_f64();
        eprintln!(
            "zoo: {name} at {}: {} ({:.0} s)",
            tol_tag(t),
            match &e.training {
                Ok(tr) => format!(
                    "{}, covered {}/{}, effectivity ≤ {}",
                    short_reason(tr),
                    e.stats.covered_pairs,
                    e.stats.loads,
                    g3(e.stats.effectivity_max)
                ),
                Err(m) => format!("training failed: {m}"),
            },
            t0.elapsed().as_secs_f64()
        );
        (i, e)
    };
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut entries: Vec<(usize, Entry)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..a.jobs)
            .map(|_| {
                scope.spawn(|| {
                    let mut mine = Vec::new();
                    while let Some(&job) = jobs.get(next.fetch_add(1, std::sync::atomic::Ordering::SeqCst)) {
                        mine.push(run_job(job));
                    }
                    mine
                })
            })
            .collect();
        workers.into_iter().flat_map(|w| w.join().expect("a zoo worker")).collect()
    });
    entries.sort_by(|x, y| x.0.cmp(&y.0).then(x.1.tolerance.total_cmp(&y.1.tolerance)));
    let wall = start.elapsed().as_secs_f64();
    let cpu = children_cpu_seconds();

    // 3. the report
    let mut md = String::new();
    let _ = writeln!(
        md,
        "Zoo seed {}, {} models ({} replaced), tolerances {}, estimate {}, commit {}; {:.0} s wall with {} jobs, {} CPU seconds in flexrom.\n",
        a.seed,
        models.len(),
        replaced.len(),
        a.tolerances.iter().map(|t| tol_tag(*t)).collect::<Vec<_>>().join(", "),
        a.estimate.as_deref().map_or("training's choice".to_string(), |m| format!("`{m}` (`--estimate`)")),
        commit(),
        wall,
        a.jobs,
        cpu.map_or("?".into(), |c| format!("{c:.0}"))
    );
    let mut aggregates = Vec::new();
    for &t in &a.tolerances {
        let at: Vec<&(usize, Entry)> = entries.iter().filter(|(_, e)| e.tolerance == t).collect();
        let agg = aggregate(&at.iter().map(|(_, e)| (e.training.as_ref().ok(), &e.stats)).collect::<Vec<_>>());
        let _ = writeln!(md, "### Tolerance {}\n\n{AGG_HEAD}\n{}\n", tol_tag(t), aggregate_row(&agg));
        let missed = agg.missed();
        if missed.is_empty() {
            let _ = writeln!(md, "Every target met.\n");
        } else {
            let _ = writeln!(md, "Targets missed: {}.\n", missed.join("; "));
        }
        // what a sweep with `--fallback full` gives at the same loads (docs/basis-and-sweep.md)
        let fb: Vec<ModelStats> = at.iter().map(|(_, e)| fallback_stats(&e.validations, t)).collect();
        let fagg = aggregate(&at.iter().zip(&fb).map(|((_, e), s)| (e.training.as_ref().ok(), s)).collect::<Vec<_>>());
        let _ = writeln!(
            md,
            "With `sweep --fallback full`: the full model's exact answer at {} of {} loads, in {} models; the others as above.\n\n{AGG_HEAD}\n{}\n",
            fagg.fallbacks,
            fagg.pairs,
            fb.iter().filter(|s| s.fallbacks > 0).count(),
            aggregate_row(&fagg)
        );
        let _ = writeln!(md, "{MODEL_HEAD}");
        for (i, e) in &at {
            let _ = writeln!(md, "{}", model_row(&infos[*i], e));
        }
        let _ = writeln!(md);
        let runs: Vec<(&str, &[Result<Validation, String>])> =
            at.iter().map(|(_, e)| (e.model.as_str(), e.validations.as_slice())).collect();
        let quantities = quantity_stats(&quantity_cases(&runs));
        md.push_str(&quantity_section(&quantities));
        aggregates.push((t, agg, fagg, quantities));
    }
    let failing: Vec<&(usize, Entry)> = entries.iter().filter(|(_, e)| !e.methods.is_empty()).collect();
    if !failing.is_empty() {
        let _ = writeln!(
            md,
            "### Where the default estimate failed

{FAIL_HEAD}"
        );
        for (i, e) in &failing {
            let _ = writeln!(md, "{}", failure_row(&infos[*i].name, e));
        }
        let _ = writeln!(md);
        let _ = writeln!(
            md,
            "### Every estimate method where the default failed\n\n| model | tolerance | method | covered loads | coverage by fifth (%) | effectivity min | median | max | min by fifth | cost |\n|---|---|---|---|---|---|---|---|---|---|"
        );
        for (i, e) in failing {
            for m in &e.methods {
                let _ = writeln!(md, "{}", method_row(&infos[*i].name, e.tolerance, m));
            }
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(md, "### The models\n");
    for i in &infos {
        let _ = writeln!(
            md,
            "- `{}`{}: {}",
            i.name,
            if i.attempt > 0 { format!(" (attempt {})", i.attempt) } else { String::new() },
            i.summary
        );
    }
    if !replaced.is_empty() {
        let _ = writeln!(md, "\nReplaced (the full run failed at an end of the range):\n");
        for r in &replaced {
            let _ = writeln!(md, "- slot {} attempt {}: {}", r.slot, r.attempt, r.reason);
        }
    }
    std::fs::create_dir_all(&a.out).expect("the output folder");
    write_atomic(&a.out.join("zoo.md"), &md);
    let json = serde_json::json!({
        "seed": a.seed,
        "commit": commit(),
        "tolerances": a.tolerances,
        "validation_loads": validation_loads(),
        "wall_seconds": wall,
        "flexrom_cpu_seconds": cpu,
        "jobs": a.jobs,
        "models": infos,
        "replaced": replaced_json(&replaced),
        "estimate": a.estimate,
        "aggregates": aggregates.iter().map(|(t, g, f, q)| serde_json::json!({"tolerance": t, "aggregate": g, "missed": g.missed(), "with_fallback": f, "with_fallback_missed": f.missed(), "quantities": q, "quantities_missed": q.iter().flat_map(QuantityStats::missed).collect::<Vec<_>>()})).collect::<Vec<_>>(),
        "entries": entries.iter().map(|(_, e)| e).collect::<Vec<_>>(),
    });
    write_atomic(&a.out.join("zoo.json"), &serde_json::to_string_pretty(&json).expect("JSON"));
    print!("{md}");
    eprintln!(
        "zoo: {:.0} s wall, {} CPU seconds in flexrom; {} and {}",
        wall,
        cpu.map_or("?".into(), |c| format!("{c:.0}")),
        a.out.join("zoo.md").display(),
        a.out.join("zoo.json").display()
    );
}
