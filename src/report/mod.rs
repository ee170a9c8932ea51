//! `run`: train → online sweep (validated) → validation with timings at chosen points →
//! a report folder: `summary.md`, `validation.json`, `sweep.h5` and plots (SVG and PNG; the
//! model's figure first, [`crate::report::model_figure`]). Over a line of load scales the plots run
//! along λ, over a box of one parameter along it; over a box of two parameters or more they
//! are maps over the box ([`crate::report::report_maps`]).
//! The folder is built beside the target and renamed into place at the end, the basis
//! written under a temporary name and renamed into place only when every stage succeeded.
//! A current basis (trained from this model with these training keys, passing its checks:
//! `current_basis`) is reused as it is: neither trained nor rewritten.

pub mod animate;
pub mod drawing;
pub mod map;
pub mod model_figure;
pub mod motion;
pub mod plot;
pub mod report_maps;
pub mod tables;

use crate::error::{Error, Result};
use crate::io::atomic::TempPath;
use crate::io::output::{check_output, check_report_dir, mark_new_report, swap_in_report, Origin};
use crate::limits::Limits;
use crate::pipeline::config::{EstimateMethod, Pipeline};
use crate::report::plot::{Figure, Panel, Series, Style};
use crate::rom::quantities::Quantity;
use crate::rom::Rom;
use crate::simulate::SimulationResult;
use crate::solver::parameters::Parameters;
use crate::training::train::train_and_write;
use crate::workflows::online::load_rom;
use crate::workflows::sweep::{sweep, table, write_sweep, SweepBasis, SweepOptions};
use crate::workflows::validate::{validate, Validation};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The files `run` reads, for the checks of its outputs.
fn inputs(p: &Pipeline) -> [(&Path, &'static str); 2] {
    [(p.path.as_path(), "pipeline file"), (p.model.path.as_path(), "model file")]
}

/// Checks, before any work, that `run` may write the pipeline's basis and replace its
/// report folder (see [`crate::io::output`]).
pub fn check_outputs(p: &Pipeline) -> Result<()> {
    let [a, b] = inputs(p);
    check_output(
        &p.basis_path,
        Origin::Key { pipeline: &p.path, key: "basis" },
        &[a, b],
        &[crate::io::attrs::Kind::Basis],
    )?;
    check_report_dir(&p.report_dir, &p.path, &[a, b, (p.basis_path.as_path(), "basis file")])
}

/// Trains, sweeps and validates, building the report in a temporary folder beside the
/// target and the basis under a temporary name beside the pipeline's `basis`. Only when
/// every stage succeeded is the basis renamed into place and the report folder swapped in
/// (the previous one, flexrom's own, removed after); on any failure both are left as they
/// were and the temporary ones removed. Returns the report folder and the training's
/// warnings.
pub fn run(p: &Pipeline, progress: bool) -> Result<(PathBuf, Vec<String>)> {
    run_with(p, progress, crate::cost::dense::DenseChoice::Auto, None, true)
}

/// [`run`] with the choice of the dense-LU comparison ([`crate::cost::dense`]), decided before
/// any work, the error estimate's method (`--estimate`; `None`: the pipeline's
/// `[online] estimate`, else the basis's default) and whether to train even where the
/// pipeline's basis is current (`retrain`; else a current basis, trained from this model with
/// these training keys and passing its checks, is reused).
pub fn run_with(
    p: &Pipeline,
    progress: bool,
    dense: crate::cost::dense::DenseChoice,
    method: Option<EstimateMethod>,
    retrain: bool,
) -> Result<(PathBuf, Vec<String>)> {
    check_outputs(p)?;
    let dense = crate::cost::dense::decide(dense, &p.model)?;
    let dir = p.report_dir.clone();
    let report = TempPath::dir_for(&dir)?;
    let reused = if retrain { None } else { current_basis(p, method) };
    let (warnings, basis) = match reused {
        Some(current) => {
            log::info!(
                "{}: basis {} is current (model and training keys unchanged): reusing it; --retrain to train again",
                p.path.display(),
                p.basis_path.display()
            );
            (build(p, report.path(), &p.basis_path, progress, (dense, method), Some(current))?, None)
        }
        None => {
            let basis = TempPath::file_for(&p.basis_path)?;
            (build(p, report.path(), basis.path(), progress, (dense, method), None)?, Some(basis))
        }
    };
    mark_new_report(report.path())?;
    // checked again: the folder or the basis path may have changed during a long run
    check_outputs(p)?;
    // the basis and the report together: a signal leaves both old or both new
    swap_in_report(report, basis.into_iter().collect(), &p.path)?;
    Ok((dir, warnings))
}

/// The pipeline's basis read and checked as every reader of a basis does
/// ([`load_rom`]: the model's fingerprint, the content hash, the file's schema version),
/// when it is current: trained from this model (its fingerprint: the parsed file, not its
/// comments) with this pipeline's training keys (`[train]`, `[reduction]`, `[parameters]`:
/// [`Pipeline::settings_hash`]). `None` (train again) where it is missing, fails a check,
/// or was trained from anything else; the training a current basis would repeat is
/// deterministic (seeded sampling, the same full runs), so reusing it gives the same basis.
fn current_basis(p: &Pipeline, method: Option<EstimateMethod>) -> Option<Reused> {
    if !p.basis_path.is_file() {
        return None;
    }
    let (stored, rom, _) = load_rom(p, &p.basis_path, method, false).ok()?;
    if stored.settings_hash != p.settings_hash() || stored.model_fingerprint != p.model.fingerprint() {
        return None;
    }
    let n_snapshots = stored.training.snapshot_count?;
    let runs = stored_runs(p, &stored);
    Some(Reused { stored, rom, n_snapshots, runs })
}

/// A current basis `run` uses as it is ([`current_basis`]), with what the summary says of
/// its training.
struct Reused {
    stored: crate::io::basis_file::StoredBasis,
    rom: Rom,
    /// columns of its `/snapshots`
    n_snapshots: usize,
    /// the points of the full runs whose snapshots it holds
    runs: Vec<Parameters>,
}

/// The points of the full runs a basis holds the snapshots of: in a box, `/parameters`
/// (their values in run order); on a line, its training loads. Both as the one read of the
/// basis file gave them ([`crate::io::basis_training`]).
fn stored_runs(p: &Pipeline, stored: &crate::io::basis_file::StoredBasis) -> Vec<Parameters> {
    if p.space().is_empty() {
        return stored.training.loads.iter().map(|&l| Parameters::load_scale(l)).collect();
    }
    stored.training.points.clone()
}

/// Every stage, writing the basis to `basis_path` (a temporary name) and the report files
/// into `out` (a temporary folder); the files are `fsync`ed when the folder is swapped in.
fn build(
    p: &Pipeline,
    out: &Path,
    basis_path: &Path,
    progress: bool,
    (dense, method): (bool, Option<EstimateMethod>),
    reused: Option<Reused>,
) -> Result<Vec<String>> {
    // the model as the user wrote it, at its initial state: it needs none of the runs
    crate::report::model_figure::save_model_figure(&p.model, &out.join("model"))?;
    let space = p.space();
    let st = Stage { p, out, in_box: !space.is_empty(), space };
    let (stored, rom, trained) = train_or_reuse(&st, basis_path, method, reused)?;
    let sw = sweep_stage(&st, &rom, &stored, progress)?;
    let (validations, animated) = validation_stage(&st, &rom, dense)?;
    // the figures summary.md shows after the runs' own, in order: (file stem, what it shows)
    let mut shown: Vec<(&str, &str)> = vec![("singular_values", "singular values")];
    st.single(
        "POD singular values",
        "index",
        vec![Panel { y_label: "σ".into(), log_y: true, series: singular_value_series(p, &stored) }],
        vec![],
        "singular_values",
    )?;
    shown.extend(parameter_figures(&st, &stored, &rom, &sw, &validations)?);
    st.single(
        "rel_error (solid) and error_estimate (dashed) up to a fraction of the run",
        "fraction of the run",
        vec![Panel { y_label: "relative error".into(), log_y: true, series: error_by_time_series(&st, &validations) }],
        vec![],
        "error_by_time",
    )?;
    shown.push(("error_by_time", "error by time"));
    let json = serde_json::to_string_pretty(&validations).expect("serializable");
    std::fs::write(out.join("validation.json"), json)
        .map_err(|e| Error::io(p.report_dir.join("validation.json"), e))?;
    let run = Done { stored: &stored, rom: &rom, sw: &sw, validations: &validations };
    write_summary(&st, &run, trained, animated.as_deref(), &shown)
}

/// What every stage of [`build`] reads: the pipeline, the temporary folder it writes into,
/// and whether its runs are points of a box (else load scales on a line).
struct Stage<'a> {
    p: &'a Pipeline,
    out: &'a Path,
    space: crate::solver::parameter_space::ParameterSpace,
    in_box: bool,
}

impl Stage<'_> {
    /// How the report names a run: its load scale, or its point of the box.
    fn name(&self, mu: &Parameters) -> String {
        if self.in_box {
            self.space.label(mu)
        } else {
            mu.scale().to_string()
        }
    }

    /// A validation's row label in the summary's tables.
    fn at(&self, v: &Validation) -> String {
        if self.in_box {
            self.name(&v.mu())
        } else {
            v.load_scale.to_string()
        }
    }

    /// The head of the tables' first column.
    fn head(&self) -> &'static str {
        if self.in_box {
            "point"
        } else {
            "load scale"
        }
    }

    /// A figure that could not be written, named by the report's own path: the temporary
    /// folder is gone by the time the user reads it.
    fn plot_err(&self, e: Error) -> Error {
        match e {
            Error::Io { file, source } => {
                let name = Path::new(&file).file_name().unwrap_or_default();
                Error::io(self.p.report_dir.join(name), source)
            }
            other => other,
        }
    }

    /// Writes one figure of `panels` as `stem`.svg and .png, the training runs marked at `markers`.
    fn single(&self, title: &str, x_label: &str, panels: Vec<Panel>, markers: Vec<f64>, stem: &str) -> Result<()> {
        // in a box the training runs are points of it: marked by name, not as loads
        let marker_label = if self.in_box { "training run" } else { "training load" };
        Figure { title: title.into(), x_label: x_label.into(), panels, markers, marker_label: marker_label.into() }
            .save(&self.out.join(stem))
            .map(|_| ())
            .map_err(|e| self.plot_err(e))
    }
}

/// What the runs gave, for the summary.
struct Done<'a> {
    stored: &'a crate::io::basis_file::StoredBasis,
    rom: &'a Rom,
    sw: &'a crate::workflows::sweep::Sweep,
    validations: &'a [Validation],
}

/// Stage 1: the reused basis, or one trained now (written to `basis_path`, with the routes'
/// timing), read back as every reader of a basis reads it.
fn train_or_reuse(
    st: &Stage,
    basis_path: &Path,
    method: Option<EstimateMethod>,
    reused: Option<Reused>,
) -> Result<(crate::io::basis_file::StoredBasis, Rom, Training)> {
    let p = st.p;
    let name = |mu: &Parameters| st.name(mu);
    if let Some(r) = reused {
        let trained = Training::reused(&r, &name);
        return Ok((r.stored, r.rom, trained));
    }
    match &p.file.train.greedy {
        Some(_) if st.in_box => log::info!("[1/3] train: greedy over the box {}", st.space.describe()),
        Some(g) => log::info!("[1/3] train: greedy over [{}, {}]", g.range().0, g.range().1),
        None if st.in_box => log::info!("[1/3] train: {} full run(s)", p.training_points().len()),
        None => log::info!("[1/3] train: {} full run(s)", p.training_scales().len()),
    }
    let summary = train_and_write(p, basis_path)?;
    // the warnings of loading it come with `check_report`'s, once
    let (stored, rom, _) = load_rom(p, basis_path, method, false)?;
    let mut trained = Training::trained(p, summary, &name);
    trained.warnings.extend(crate::cost::route::time_and_store(&stored, &rom, basis_path)?);
    Ok((stored, rom, trained))
}

/// Stage 2: the validated sweep over the online points, written as `sweep.h5`; an error
/// where any point failed (the plots and tables need every one).
fn sweep_stage(
    st: &Stage,
    rom: &Rom,
    stored: &crate::io::basis_file::StoredBasis,
    progress: bool,
) -> Result<crate::workflows::sweep::Sweep> {
    let points = st.p.online_points();
    log::info!("[2/3] sweep: {} reduced and full runs", points.len());
    let sw = sweep(rom, &points, SweepOptions { validate: true, progress, ..Default::default() })?;
    write_sweep(
        &st.out.join("sweep.h5"),
        &sw,
        Some(SweepBasis {
            stored,
            path: &st.p.basis_path,
            sensitivity: rom.trust().and_then(|t| t.sensitivity.as_ref()),
        }),
    )?;
    // the plots and tables below need every load scale
    if let Some(s) = sw.failure_summary() {
        return Err(Error::PartlyFailed(format!("sweep: {s}; no report written (the basis is)")));
    }
    Ok(sw)
}

/// Stage 3: the validations with timings at the validation points, each with its energy
/// and probe figures, and the one with the largest rel_error animated (its name; `None`
/// where the animation could not be written, with a warning).
fn validation_stage(st: &Stage, rom: &Rom, dense: bool) -> Result<(Vec<Validation>, Option<String>)> {
    let (p, out, in_box) = (st.p, st.out, st.in_box);
    let vpoints = p.validation_points();
    let with = if dense { ", with the dense full solve" } else { "" };
    log::info!("[3/3] validate at {} {}{with}", vpoints.len(), if in_box { "point(s)" } else { "load scale(s)" });
    let mut validations: Vec<Validation> = Vec::new();
    // the validation with the largest rel_error, animated full against reduced
    let mut worst: Option<(f64, String, SimulationResult, SimulationResult)> = None;
    for (i, mu) in vpoints.iter().enumerate() {
        let (v, full, reduced) = validate(rom, mu, dense)?;
        energy_figure(
            rom,
            (&full, &reduced.result),
            &format!("Energies, full and reduced, {}{}", if in_box { "" } else { "load scale " }, st.name(mu)),
        )?
        .save(&out.join(format!("energy_{i}")))
        .map_err(|e| st.plot_err(e))?;
        // a model without probes has nothing to draw here
        if !full.probes.is_empty() {
            let title = format!("Probes, full and reduced, {}{}", if in_box { "" } else { "load scale " }, st.name(mu));
            probes_figure(&full, &reduced.result, title)
                .save(&out.join(format!("probes_{i}")))
                .map_err(|e| st.plot_err(e))?;
        }
        if worst.as_ref().is_none_or(|w| v.rel_error > w.0) {
            worst = Some((v.rel_error, st.name(mu), full, reduced.result));
        }
        validations.push(v);
    }
    let animated = match &worst {
        Some((_, at, full, reduced)) => animate_worst(out, full, reduced, &p.model.limits)
            .map(|_| at.clone())
            .map_err(|e| log::warn!("the report's animation was not written: {e}"))
            .ok(),
        None => None,
    };
    Ok((validations, animated))
}

/// The POD singular values, one curve per block of a block basis (one POD per body: named
/// by the body), each indexed from 1.
fn singular_value_series(p: &Pipeline, stored: &crate::io::basis_file::StoredBasis) -> Vec<Series> {
    let bodies = p.model.bodies();
    let block_name = |b: usize| match bodies.get(b) {
        Some(body) if stored.block_values.len() == bodies.len() => format!("σᵢ, {}", body.name),
        _ => format!("σᵢ, block {}", b + 1),
    };
    let mut sv = stored.singular_values.iter();
    stored
        .block_values
        .iter()
        .enumerate()
        .map(|(b, &k)| {
            let name = if stored.block_values.len() == 1 { "σᵢ".into() } else { block_name(b) };
            Series::new(name, sv.by_ref().take(k).enumerate().map(|(i, s)| ((i + 1) as f64, *s)).collect(), Style::Line)
        })
        .collect()
}

/// The figures over the parameters: along the axis the runs lie on (λ on a line, the
/// parameter of a one-parameter box), or maps over a box of two parameters or more; the
/// (file stem, what it shows) of each, in the order summary.md shows them.
fn parameter_figures(
    st: &Stage,
    stored: &crate::io::basis_file::StoredBasis,
    rom: &Rom,
    sw: &crate::workflows::sweep::Sweep,
    validations: &[Validation],
) -> Result<Vec<(&'static str, &'static str)>> {
    let p = st.p;
    let names: Vec<&str> = st.space.names().collect();
    let axis = match names.as_slice() {
        [] => Some(crate::solver::parameters::LOAD_SCALE),
        [one] => Some(*one),
        _ => None,
    };
    let Some(axis) = axis else {
        // every validated run, the sweep's and the validation's, at its point
        let runs: Vec<crate::report::report_maps::MappedRun> = (sw.scales.iter())
            .filter_map(|x| x.point())
            .filter_map(|q| {
                let estimate = q.estimate.as_ref().map(|e| e.error_estimate);
                Some(crate::report::report_maps::MappedRun { validation: q.validation.as_ref()?, estimate })
            })
            .chain(
                validations
                    .iter()
                    .map(|v| crate::report::report_maps::MappedRun { validation: v, estimate: v.error_estimate }),
            )
            .collect();
        let training = stored_runs(p, stored);
        let cx = crate::report::report_maps::MapContext {
            space: &st.space,
            training: &training,
            tolerance: rom.trust().and_then(|t| t.tolerance),
            probes: !p.model.probe_names().is_empty(),
        };
        return crate::report::report_maps::write_maps(st.out, &runs, &cx).map_err(|e| st.plot_err(e));
    };
    axis_figures(st, axis, stored, sw, validations)
}

/// The figures along `axis`: the error and the speedup over the sweep, and the estimate
/// (no full run) against the true errors (full runs) where the sweep has estimates.
fn axis_figures(
    st: &Stage,
    axis: &str,
    stored: &crate::io::basis_file::StoredBasis,
    sw: &crate::workflows::sweep::Sweep,
    validations: &[Validation],
) -> Result<Vec<(&'static str, &'static str)>> {
    let p = st.p;
    // the estimate over the sweep (no full run), by the sweep's points
    let estimates: Vec<(Parameters, f64)> = (sw.scales.iter())
        .filter_map(|x| x.point())
        .filter_map(|q| q.estimate.as_ref().map(|e| (q.run.result.settings.mu.clone(), e.error_estimate)))
        .collect();
    let x_of = |mu: &Parameters| mu.get(axis).unwrap_or(1.0);
    let x_label = if st.in_box { axis } else { "load scale" };
    // the sweep's validated runs along the axis, in its order (a box's points are drawn at random)
    let pts = |f: &dyn Fn(&Validation) -> f64| -> Vec<(f64, f64)> {
        let mut v: Vec<(f64, f64)> =
            (sw.scales.iter()).filter_map(|x| x.point()?.validation.as_ref()).map(|v| (x_of(&v.mu()), f(v))).collect();
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        v
    };
    // the full runs the basis was trained on, marked on the plots along the axis
    let training: Vec<f64> =
        if st.in_box { stored_runs(p, stored).iter().map(x_of).collect() } else { stored.training.loads.clone() };
    // rel_error and the probe error (m) on axes of their own: two units, two axes
    let mut panels = vec![Panel {
        y_label: "rel_error".into(),
        log_y: true,
        series: vec![Series::new("rel_error", pts(&|v| v.rel_error), Style::Line)],
    }];
    if !p.model.probe_names().is_empty() {
        panels.push(Panel {
            y_label: "probe error (m)".into(),
            log_y: true,
            series: vec![Series::new("max probe error", pts(&|v| v.max_probe_error), Style::Line).colored(1)],
        });
    }
    st.single("Reduced vs full model", x_label, panels, training.clone(), "error_vs_load")?;
    let speedups = pts(&|v| v.speedup);
    let span = speedups.iter().fold((f64::MAX, f64::MIN), |(a, b), q| (a.min(q.0), b.max(q.0)));
    let mut series = vec![Series::new("speedup (banded full solver)", speedups, Style::Line)];
    if span.0 <= span.1 {
        series.push(Series::level("1× (as fast as the full run)", 1.0, span));
    }
    st.single(
        "Speedup of the reduced time loop over the full one",
        x_label,
        vec![Panel { y_label: "speedup".into(), log_y: false, series }],
        training.clone(),
        "speedup_vs_load",
    )?;
    let mut shown = vec![("error_vs_load", "error"), ("speedup_vs_load", "speedup")];
    // the validation's own runs lie on the same axis
    let mut errors = pts(&|v| v.rel_error);
    errors.extend(validations.iter().map(|v| (x_of(&v.mu()), v.rel_error)));
    if !estimates.is_empty() {
        let mut along: Vec<(f64, f64)> = estimates.iter().map(|(mu, e)| (x_of(mu), *e)).collect();
        along.sort_by(|a, b| a.0.total_cmp(&b.0));
        st.single(
            "Error estimate (no full run) and true error (full runs)",
            x_label,
            vec![Panel {
                y_label: "relative error".into(),
                log_y: true,
                series: vec![
                    Series::new("error_estimate", along, Style::Line),
                    Series::new("rel_error (validated)", errors, Style::Markers),
                ],
            }],
            training,
            "estimate_vs_load",
        )?;
        shown.push(("estimate_vs_load", "error estimate"));
    }
    Ok(shown)
}

/// The true error (solid) and its estimate (dashed) up to each fifth of the run, one
/// colour a validated run.
fn error_by_time_series(st: &Stage, validations: &[Validation]) -> Vec<Series> {
    let fifths = |v: &[f64]| v.iter().enumerate().map(|(i, e)| ((i + 1) as f64 / 5.0, *e)).collect::<Vec<_>>();
    validations
        .iter()
        .enumerate()
        .flat_map(|(k, v)| {
            // one legend entry a run (the two series share its name)
            let at = if st.in_box { st.name(&v.mu()) } else { format!("load scale {}", v.load_scale) };
            let truth = Series::new(at.clone(), fifths(&v.rel_error_by_time), Style::Line).colored(k);
            let est = v.error_estimate_by_time.as_ref().map(|e| Series::new(at, fifths(e), Style::Dashed).colored(k));
            std::iter::once(truth).chain(est)
        })
        .collect()
}

/// Writes summary.md: what was trained and run, the validations, the route verdict, the
/// estimate's section, the sweep's table, its warnings and the plots; returns the
/// training's and the route's warnings for the caller to print.
fn write_summary(
    st: &Stage,
    run: &Done,
    trained: Training,
    animated: Option<&str>,
    shown: &[(&str, &str)],
) -> Result<Vec<String>> {
    let (p, validations) = (st.p, run.validations);
    let mut md = String::new();
    summary_head(&mut md, st, run, &trained);
    validation_table(&mut md, st, validations);
    let mut warnings = trained.warnings;
    if let Some(speed) = route_comparison(validations) {
        let _ = writeln!(md, "\n## Full or reduced\n");
        let _ = writeln!(
            md,
            "{} Time loops on one thread: the median over the validated loads of the medians above{}.",
            speed.verdict(),
            if speed.estimate.is_some() { " (the estimate: one run at each load)" } else { "" }
        );
        let measured = format!("medians of `run`'s validation at {} load(s)", validations.len());
        warnings.extend(speed.notice(&p.path, &measured));
    }
    let trust = run.rom.trust().expect("read from its basis file");
    estimate_table(&mut md, st, run.rom, validations);
    let labels: Vec<String> = validations.iter().map(|v| st.at(v)).collect();
    motion_section(&mut md, validations, &labels, st.head(), trust);
    sweep_section(&mut md, st, run)?;
    plots_section(&mut md, st, &labels, animated, shown);
    std::fs::write(st.out.join("summary.md"), md).map_err(|e| Error::io(p.report_dir.join("summary.md"), e))?;
    Ok(warnings)
}

/// The summary's title and its lines on the model, the basis (with its training runs) and
/// the sweep, and the model's figure.
fn summary_head(md: &mut String, st: &Stage, run: &Done, trained: &Training) {
    let (p, in_box, stored, sw) = (st.p, st.in_box, run.stored, run.sw);
    let b = &*stored.basis;
    let _ = writeln!(md, "# flexrom report: {}\n", p.path.display());
    if !p.file.description.is_empty() {
        let _ = writeln!(md, "{}\n", p.file.description);
    }
    let _ = writeln!(
        md,
        "- model: `{}` ({} coordinates), fingerprint `{}`",
        p.model.path.display(),
        b.n_dof(),
        &p.model.fingerprint()[..12]
    );
    // a held-out check run is named as such: its load is not among the basis's
    let held_out = match trained.held_out.as_slice() {
        [] => String::new(),
        loads => format!(
            " ({}) + {} held-out check{} at {}{} (not in the basis)",
            if trained.n_training_runs == 1 {
                "1 training run".to_string()
            } else {
                format!("{} training runs", trained.n_training_runs)
            },
            loads.len(),
            if loads.len() == 1 { "" } else { "s" },
            if in_box { "" } else { "λ = " },
            loads.join("; ")
        ),
    };
    let runs = &trained.runs;
    let reused = trained.reused.as_ref().map_or(String::new(), |when| {
        format!(" (reused: current, trained {when} from this model and these training keys)")
    });
    let _ = writeln!(
        md,
        "- basis: `{}`{reused}: {} reduction, {} snapshots, rule `{}` → {} POD modes{}, {} snapshots from {} [{}]{held_out}",
        p.basis_path.display(),
        b.variant.name(),
        b.snapshots.name(),
        stored.mode_rule,
        b.n_pod_modes,
        if b.kept.is_empty() { String::new() } else { format!(" + {} joint coordinates", b.kept.len()) },
        trained.n_snapshots,
        if in_box { "points" } else { "load scales" },
        runs.join(if in_box { "; " } else { ", " })
    );
    let _ = writeln!(
        md,
        "- sweep: {} {} on {} thread{} in {:.3} s (whole sweep, reduced and full runs)\n",
        sw.scales.len(),
        if in_box { "random points of the box" } else { "load scales" },
        sw.threads,
        if sw.threads == 1 { "" } else { "s" },
        sw.wall_seconds
    );
    let _ = writeln!(
        md,
        "The model at its initial configuration (bodies named; joints, springs, point masses and probes marked):\n\n![the model](model.svg)\n"
    );
}

/// The summary's validation table: errors and the time loops' seconds and speedups.
fn validation_table(md: &mut String, st: &Stage, validations: &[Validation]) {
    let _ = writeln!(md, "## Validation (time loops only; full and reduced: medians of up to 7 interleaved runs each; full dense: one run)\n");
    let head = st.head();
    let _ = writeln!(md, "| {head} | rel_error | max probe error (m) | at | max constraint violation | full (s) | full dense (s) | reduced (s) | speedup | vs dense |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    for v in validations {
        let _ = writeln!(
            md,
            "| {} | {:.3e} | {:.3e} | {} t = {:.3} s | {:.2e} | {:.4} | {:.4} | {:.4} | {:.2} | {:.2} |",
            st.at(v),
            v.rel_error,
            v.max_probe_error,
            v.max_probe_error_probe,
            v.max_probe_error_t,
            v.max_constraint_violation,
            v.full_seconds,
            v.full_dense_seconds.unwrap_or(f64::NAN),
            v.rom_seconds,
            v.speedup,
            v.speedup_vs_dense.unwrap_or(f64::NAN)
        );
    }
}

/// The summary's section on the error estimate, extrapolation and sensitivity: the
/// training range or box, the tolerance, and a row per validation.
fn estimate_table(md: &mut String, st: &Stage, rom: &Rom, validations: &[Validation]) {
    let in_box = st.in_box;
    let _ = writeln!(md, "\n## Error estimate, extrapolation, sensitivity\n");
    let trust = rom.trust().expect("read from its basis file");
    let trained_over = if in_box {
        format!("Training box {}", st.space.describe())
    } else {
        format!("Training range [{}, {}]", trust.range.0, trust.range.1)
    };
    let _ = writeln!(
        md,
        "{trained_over}; tolerance {}. The estimate predicts rel_error without a full run ({} method, docs/error-estimate.md); effectivity = estimate / rel_error (≥ 1: bounded). Sensitivity: the full model's own change for a 0.1 % change of the load{}.\n",
        trust.tolerance.map_or("none".to_string(), |t| format!("{t:e}")),
        rom.method().unwrap_or("no"),
        if in_box { " (every parameter of the box)" } else { "" }
    );
    let head = st.head();
    let _ = writeln!(md, "| {head} | rel_error | error_estimate | effectivity | calibrated | extrapolated | sensitivity | rel_error by fifth of the run | error_estimate by fifth of the run |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|");
    for v in validations {
        let by: Vec<String> = v.rel_error_by_time.iter().map(|e| format!("{e:.2e}")).collect();
        let est_by = v
            .error_estimate_by_time
            .as_ref()
            .map_or("–".to_string(), |e| e.iter().map(|e| format!("{e:.2e}")).collect::<Vec<_>>().join(", "));
        let o = |x: Option<f64>, f: &dyn Fn(f64) -> String| x.map_or("–".to_string(), f);
        let _ = writeln!(
            md,
            "| {} | {:.3e} | {} | {} | {} | {} | {} | {} | {} |",
            st.at(v),
            v.rel_error,
            o(v.error_estimate, &|x| format!("{x:.3e}")),
            o(v.effectivity, &|x| format!("{x:.2}")),
            v.estimate_calibrated.map_or("–", |c| if c { "yes" } else { "no" }),
            if v.extrapolated { "yes" } else { "no" },
            o(v.sensitivity, &|x| format!("{x:.2e}")),
            by.join(", "),
            est_by
        );
    }
}

/// The summary's sweep table, and what `run` says in one line each at its end, whole.
fn sweep_section(md: &mut String, st: &Stage, run: &Done) -> Result<()> {
    let mut swept = table(run.sw);
    if st.in_box {
        // a box's points have no order of their own: numbered, so that a row can be named
        swept = swept
            .lines()
            .enumerate()
            .map(|(i, l)| format!("{:>5}{l}\n", if i == 0 { "#".to_string() } else { i.to_string() }))
            .collect();
    }
    let _ = writeln!(md, "\n## Sweep\n\n```text\n{swept}```\n");
    let said = sweep_warnings(run.rom, &st.out.join("sweep.h5"), false)?;
    if !said.is_empty() {
        let _ = writeln!(md, "## Warnings\n");
        for w in &said {
            let _ = writeln!(md, "- {w}");
        }
        let _ = writeln!(md);
    }
    Ok(())
}

/// The summary's plots: the animation, the validations' probe and energy figures (named by
/// `labels`) and the figures `shown`.
fn plots_section(md: &mut String, st: &Stage, labels: &[String], animated: Option<&str>, shown: &[(&str, &str)]) {
    let _ = writeln!(md, "## Plots\n");
    if let Some(at) = animated {
        let at = if st.in_box { at.to_string() } else { format!("load scale {at}") };
        let _ = writeln!(md, "The motion at {at}, the validation with the largest rel_error: full (solid) against reduced (dashed).\n\n![full against reduced at {at}](animation.gif)\n");
    }
    // a model without probes has no probe figures
    for (i, x) in labels.iter().enumerate().filter(|_| !st.p.model.probe_names().is_empty()) {
        let _ = writeln!(md, "![probes at {x}](probes_{i}.svg)");
    }
    for (i, x) in labels.iter().enumerate() {
        let _ = writeln!(md, "![energies at {x}](energy_{i}.svg)");
    }
    for (stem, what) in shown {
        let _ = writeln!(md, "![{what}]({stem}.svg)");
    }
}

/// The probes' x and y, full (line) and reduced (dashed), and their difference.
fn probes_figure(full: &SimulationResult, reduced: &SimulationResult, title: String) -> Figure {
    // x and y of every probe, full (line) and reduced (dashed), and their difference
    let t = &full.t;
    let mut panels: Vec<Panel> = ["x (m)", "y (m)"]
        .iter()
        .enumerate()
        .map(|(c, label)| Panel {
            y_label: label.to_string(),
            log_y: false,
            series: full
                .probes
                .iter()
                .zip(&reduced.probes)
                .enumerate()
                .flat_map(|(k, ((name, a), (_, b)))| {
                    // a probe's full and reduced lines in one colour, solid and dashed
                    let line = |run: &str, v: &ndarray::Array2<f64>, style| {
                        Series::new(
                            format!("{name}, {run}"),
                            t.iter().copied().zip(v.column(c).iter().copied()).collect(),
                            style,
                        )
                    };
                    [line("full", a, Style::Line), line("reduced", b, Style::Dashed)].map(|l| l.colored(k))
                })
                .collect(),
        })
        .collect();
    panels.push(Panel {
        y_label: "reduced − full (m)".into(),
        log_y: false,
        series: full
            .probes
            .iter()
            .zip(&reduced.probes)
            .flat_map(|((name, a), (_, b))| {
                (0..2).map(move |c| {
                    let d = t.iter().zip(a.column(c)).zip(b.column(c)).map(|((t, f), r)| (*t, r - f)).collect();
                    Series::new(format!("{name} {}, error", ["x", "y"][c]), d, Style::Line)
                })
            })
            .collect(),
    });
    Figure { title, x_label: "t (s)".into(), panels, markers: vec![], marker_label: String::new() }
}

/// `animation.gif` in the report folder `out`: the full run (solid) against the reduced one
/// (dashed), drawn by `flexrom animate` from result files written beside it for the
/// purpose and removed after (they are this function's own).
fn animate_worst(out: &Path, full: &SimulationResult, reduced: &SimulationResult, limits: &Limits) -> Result<()> {
    // named as the animation's title names the runs
    let dir = out.join(".animation");
    std::fs::create_dir(&dir).map_err(|e| Error::io(&dir, e))?;
    let (f, r) = (dir.join("full.h5"), dir.join("reduced.h5"));
    let write = |path: &Path, run: &SimulationResult| {
        let plan = crate::io::result_file::RunPlan::of_result(run);
        crate::io::result_file::ResultFile::begin(path, &run.model_text, &run.model_path, &plan)?
            .finish(run, |_| Ok(()))
    };
    let made = write(&f, full).and_then(|_| write(&r, reduced)).and_then(|_| {
        let opts = crate::report::animate::AnimateOptions::default();
        crate::report::animate::animate(&f, Some(&r), &out.join("animation.gif"), &opts, limits).map(|_| ())
    });
    for path in [&f, &r] {
        let _ = std::fs::remove_file(path);
    }
    let _ = std::fs::remove_dir(&dir);
    made
}

/// What the summary says of the training: the training `run` just made, or the one a
/// reused basis records.
struct Training {
    /// the full runs whose snapshots the basis holds
    n_training_runs: usize,
    /// the held-out check runs (not in the basis), named as the report names a run
    held_out: Vec<String>,
    /// the training runs, named as the report names a run
    runs: Vec<String>,
    /// columns of the snapshot matrix
    n_snapshots: usize,
    /// the reused basis's creation time (`None`: trained now)
    reused: Option<String>,
    warnings: Vec<String>,
}

impl Training {
    fn trained(
        p: &Pipeline,
        t: crate::training::train::TrainSummary,
        name: &dyn Fn(&Parameters) -> String,
    ) -> Training {
        let runs: Vec<String> = match &t.greedy {
            Some(g) => g.runs.iter().map(name).collect(),
            None if !p.space().is_empty() => p.training_points().iter().map(name).collect(),
            None => p.training_scales().iter().map(|x| x.to_string()).collect(),
        };
        // a held-out check whose load greedy later added to the basis is a training run
        // (its snapshots are in the basis), not a check the basis never saw
        let held_out = t.held_out_points().iter().map(name).filter(|h| !runs.contains(h)).collect();
        Training {
            n_training_runs: t.n_training_runs(),
            held_out,
            runs,
            n_snapshots: t.n_snapshots,
            reused: None,
            warnings: t.warnings,
        }
    }

    fn reused(r: &Reused, name: &dyn Fn(&Parameters) -> String) -> Training {
        Training {
            n_training_runs: r.runs.len(),
            held_out: Vec::new(),
            runs: r.runs.iter().map(name).collect(),
            n_snapshots: r.n_snapshots,
            reused: Some(r.stored.creation_time.clone()),
            warnings: Vec::new(),
        }
    }
}

/// The summary's section on the errors against the motion: displacement_error and its
/// estimate, each probe's error over its travel (a row per validation, named by `labels`
/// under the column `head`).
/// The energies of a validated load, full (lines) and reduced (dashed, from its own reduced
/// quantities: [`crate::simulate::with_reduced_energies`]): kinetic, strain, gravity and
/// springs, and the balance `T + U + V + V_s − W − W_d` (constant without damping at ρ∞ = 1, else
/// falling by what the damping and the numerical damping take).
fn energy_figure(rom: &Rom, (full, reduced): (&SimulationResult, &SimulationResult), title: &str) -> Result<Figure> {
    let full = crate::simulate::with_energies(rom.model(), full.clone())?;
    let reduced = crate::simulate::with_reduced_energies(rom.model(), reduced.clone(), rom.basis().hyper.as_ref())?;
    let (Some(ef), Some(er)) = (&full.energy, &reduced.energy) else { unreachable!("with_energies sets them") };
    let curve = |t: &ndarray::Array1<f64>, v: &ndarray::Array1<f64>| t.iter().zip(v).map(|(t, v)| (*t, *v)).collect();
    let mut series = Vec::new();
    // an energy's full and reduced lines in one colour, solid and dashed
    for (k, (name, a, b)) in [
        ("kinetic", &ef.kinetic, &er.kinetic),
        ("strain", &ef.strain, &er.strain),
        ("gravity", &ef.gravity, &er.gravity),
        ("springs", &ef.springs, &er.springs),
    ]
    .into_iter()
    .enumerate()
    {
        if a.iter().chain(b.iter()).any(|x| *x != 0.0) {
            series.push(Series::new(format!("{name}, full"), curve(&full.t, a), Style::Line).colored(k));
            series.push(Series::new(format!("{name}, reduced"), curve(&reduced.t, b), Style::Dashed).colored(k));
        }
    }
    let balance = vec![
        Series::new("balance, full", curve(&full.t, &ef.total()), Style::Line).colored(6),
        Series::new("balance, reduced", curve(&reduced.t, &er.total()), Style::Dashed).colored(6),
    ];
    Ok(Figure {
        title: title.to_string(),
        x_label: "t (s)".into(),
        panels: vec![
            Panel { y_label: "energy (J)".into(), log_y: false, series },
            Panel { y_label: "T + U + V − W − W_d (J)".into(), log_y: false, series: balance },
        ],
        markers: vec![],
        marker_label: String::new(),
    })
}

fn motion_section(
    md: &mut String,
    validations: &[Validation],
    labels: &[String],
    head: &str,
    trust: &crate::rom::Trust,
) {
    let _ = writeln!(md, "\n## Errors against the motion\n");
    let _ = writeln!(
        md,
        "rel_error divides by ‖X_full‖, which holds the undeformed geometry and the unit slopes; displacement_error = ‖X_rom − X_full‖ / ‖X_full − X₀‖ measures the error against the motion from the initial configuration X₀, and a probe's error over its travel is max_t |r_rom − r_full| / max_t |r_full(t) − r_full(0)| (docs/error-estimate.md). The tolerance is on {}.\n",
        trust.measure.error_name()
    );
    let _ = writeln!(md, "| {head} | rel_error | displacement_error | error_estimate_displacement | effectivity | displacement_error by fifth of the run | probe error over its travel |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|");
    for (v, label) in validations.iter().zip(labels) {
        // none: the full run has not moved beyond the Newton tolerance yet
        let fmt = |e: f64| if e.is_nan() { "none".to_string() } else { format!("{e:.2e}") };
        let by: Vec<String> = v.displacement_error_by_time.iter().map(|&e| fmt(e)).collect();
        let probes: Vec<String> = v
            .probe_errors_over_travel
            .iter()
            .map(|p| match p.error_over_travel {
                Some(e) => format!("{} {e:.2e} ({:.2e} m of {:.3} m)", p.probe, p.max_error, p.travel),
                None => format!("{} (does not move beyond the Newton tolerance)", p.probe),
            })
            .collect();
        let o = |x: Option<f64>, f: &dyn Fn(f64) -> String| x.map_or("–".to_string(), f);
        let _ = writeln!(
            md,
            "| {} | {:.3e} | {} | {} | {} | {} | {} |",
            label,
            v.rel_error,
            fmt(v.displacement_error),
            o(v.error_estimate_displacement, &|x| fmt(x)),
            o(v.effectivity_displacement.filter(|_| v.displacement_error.is_finite()), &|x| format!("{x:.2}")),
            by.join(", "),
            probes.join("; ")
        );
    }
    let rows: Vec<(&str, Vec<QuantityRow>)> =
        validations.iter().zip(labels).map(|(v, label)| (label.as_str(), quantity_rows(v))).collect();
    if rows.iter().all(|(_, r)| r.is_empty()) {
        return;
    }
    let _ = writeln!(
        md,
        "\nWhat engineers read — at the probes position, and strain and curvature where a probe records them (a bending moment is E I κ: its error is the curvature's); at the joints each reaction force and moment that moves — each against the full run, relative to the full run's range over the run, beside its own estimate (docs/error-estimate.md).\n"
    );
    let _ = writeln!(
        md,
        "| {head} | probe or joint | quantity | max error | range (full run) | error over the range | estimate |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|");
    for (label, rows) in &rows {
        for q in rows {
            let unit = q.quantity.unit();
            let rel = q.relative.map_or("none".to_string(), |e| format!("{e:.2e}"));
            let est = q.estimate.map_or("—".to_string(), |e| format!("{e:.2e}"));
            let (name, quantity, error, range) = (q.name, q.quantity.name(), q.max_error, q.range);
            let _ = writeln!(
                md,
                "| {label} | {name} | {quantity} | {error:.2e}{unit} | {range:.2e}{unit} | {rel} | {est} |"
            );
        }
    }
}

/// One row of the report's table of what engineers read.
struct QuantityRow<'a> {
    name: &'a str,
    quantity: Quantity,
    max_error: f64,
    range: f64,
    relative: Option<f64>,
    estimate: Option<f64>,
}

/// Every probe quantity of a validation, then every joint reaction that moves beyond its
/// resolution (a pin's moment is zero: no row).
fn quantity_rows(v: &Validation) -> Vec<QuantityRow<'_>> {
    let probes = v.probe_quantity_errors.iter().map(|q| QuantityRow {
        name: &q.probe,
        quantity: q.quantity,
        max_error: q.max_error,
        range: q.range,
        relative: q.relative,
        estimate: q.estimate,
    });
    let reactions = v.reaction_errors.iter().filter(|q| q.relative.is_some()).map(|q| QuantityRow {
        name: &q.reaction,
        quantity: q.quantity,
        max_error: q.max_error,
        range: q.range,
        relative: q.relative,
        estimate: q.estimate,
    });
    probes.chain(reactions).collect()
}

/// After `run`: the warnings of the report's basis and sweep (read back from its
/// `sweep.h5`: extrapolation, estimates above the tolerance), and `--strict`'s error when an
/// estimate exceeds the tolerance (`method`: the estimate's, as `run_with` was given it).
pub fn check_report(p: &Pipeline, dir: &Path, strict: bool, method: Option<EstimateMethod>) -> Result<Vec<String>> {
    let (_, rom, mut warnings) = load_rom(p, &p.basis_path, method, false)?;
    // one line each: the summary's Warnings section has them whole
    let summary = dir.join("summary.md");
    warnings.extend(
        sweep_warnings(&rom, &dir.join("sweep.h5"), strict)?
            .iter()
            .map(|w| format!("{}; the detail in {}, Warnings", headline(w), summary.display())),
    );
    Ok(warnings)
}

/// A warning's first clause, up to its first `": "` (the whole of it without one): "the
/// model amplifies changes of the load at 17 of 21 load scales".
fn headline(w: &str) -> &str {
    w.split_once(": ").map_or(w, |(head, _)| head)
}

/// The warnings about the runs of the sweep file at `path` (a report's `sweep.h5`) that
/// `online` and `sweep` give ([`Rom::warnings_after`]: extrapolation, a model that
/// amplifies changes of the load, estimates above the tolerance; with `strict`, the last is
/// the error).
fn sweep_warnings(rom: &Rom, path: &Path, strict: bool) -> Result<Vec<String>> {
    let f = crate::io::h5_open::open(path).map_err(|e| Error::hdf5(path, e))?;
    let read = |name: &str| {
        f.dataset(name)
            .and_then(|d| d.read_1d::<f64>())
            .map_err(|e| Error::input(path, name, format!("cannot be read: {e}")))
    };
    let trust = rom.trust().expect("read from its basis file");
    let estimates = match trust.measure {
        crate::rom::estimator::ErrorMeasure::Relative => "error_estimate",
        crate::rom::estimator::ErrorMeasure::Displacement => "error_estimate_displacement",
    };
    let (scales, est) = (read("load_scales")?, read(estimates)?);
    let points = crate::records::sweep_file::points_of(&f, &scales.to_vec())
        .map_err(|(field, problem)| Error::input(path, field, problem))?;
    let answered: Vec<_> = (points.iter().zip(&est))
        .map(|(mu, &e)| crate::rom::warnings::Answered {
            mu,
            estimate: Some(e).filter(|e| !e.is_nan()),
            failure: None,
            quantities: Vec::new(),
        })
        .collect();
    rom.warnings_after(&answered, strict)
}

/// The two routes' times per run from the validation's medians (the median over the
/// validated loads of each; the estimate counts when every validated run has one); `None`
/// without validated loads.
fn route_comparison(validations: &[Validation]) -> Option<crate::cost::route::Comparison> {
    let mid = |f: &dyn Fn(&Validation) -> Option<f64>| -> Option<f64> {
        let mut x: Vec<f64> = validations.iter().map(f).collect::<Option<_>>()?;
        (!x.is_empty()).then(|| crate::cost::timing::median(&mut x))
    };
    Some(crate::cost::route::Comparison {
        full: mid(&|v| Some(v.full_seconds))?,
        reduced: mid(&|v| Some(v.rom_seconds))?,
        estimate: mid(&|v| v.estimate_seconds),
    })
}
