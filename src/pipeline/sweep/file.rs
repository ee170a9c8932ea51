//! The sweep file, written atomically at every checkpoint and read back by `--resume`
//! (N load scales; rows of scales that failed or did not run yet hold NaN,
//! and 0 in the counters):
//!
//! ```text
//! /load_scales        (N)
//! /points             (N, d)         a sweep over named parameters only: every parameter's
//!                                    value at each point (attribute `parameters`: the d names,
//!                                    comma-separated, load_scale first)
//! /status             (N)            0 = ok, 1 = failed, 2 = not run yet
//! /message            (N)            why it failed; for a finished point, why the full model
//!                                    answered (or was tried) in its place ("" otherwise)
//! /t                  (n_t)
//! /probes/<name>      (N, n_t, 2)    probe positions of each run (reduced; --full: full), m
//! /full_probes/<name> (N, n_t, 2)    with --validate: the full runs' probe positions, m
//! /probe_strain/<name>    (N, n_t)   each run's axial strain at the probes that record it, 1
//! /probe_curvature/<name> (N, n_t)   each run's curvature there, 1/m (bending moment E I κ)
//! /probe_error_estimate/<quantity>/<name> (N)   the estimate of each probe quantity's error
//!                                    (position, strain, curvature) over its range over the
//!                                    run (crate::rom::quantities; 0 where the full model
//!                                    answered); with --validate /probe_error/<quantity>/<name>
//!                                    the error measured against the full run
//! /reduced_q          (N, n_t, r)    reduced coordinates (time first; layout 1: (N, r, n_t));
//!                                    not in a full sweep
//! /rom_seconds        (N)            reduced time loop of each run (not in a full sweep; the
//!                                    full run's where /fallback is 1)
//! /fallback           (N)            reduced sweeps: 0 the reduced answer, 1 the full model's
//!                                    in its place (`--fallback full`), 2 the reduced answer
//!                                    kept where the full model was tried and failed
//! /newton_iterations  (N)
//! /factorizations     (N)            iteration matrices factorized
//! /error_estimate     (N)            the estimate of rel_error of each run (NaN: no estimator)
//! /error_estimate_by_time (N, 5)     the estimate up to the end of each fifth of the run (the
//!                                    last column is /error_estimate; NaN: no estimator)
//! /error_estimate_displacement (N)   the estimate of displacement_error of each run
//! /error_estimate_displacement_by_time (N, 5)   the same up to the end of each fifth
//! /extrapolated       (N)            1 where the load scale is outside the training range
//! /sensitivity_near   (N)            the reduced model's sensitivity at greedy training's
//!                                    candidates beside the load (NaN for other bases)
//! /estimate_seconds   (N)            the estimator's enriched run and norms, s
//! with --validate:    /rel_error, /max_probe_error, /max_constraint_violation,
//!                     /full_seconds, /speedup, /steps_differ_from, /displacement_error  (N each),
//!                     /rel_error_by_time (N, 5): rel_error up to the end of each fifth, beside
//!                     /error_estimate_by_time (files before 2026-11-26 lack it)
//! with --full:        /full_seconds (N), the full time loop of each run; the estimate
//!                     columns NaN (an exact run has none), /extrapolated 0
//! every dataset: units, dims (src/io/attrs.rs)
//! attributes on /: flexrom_layout, flexrom_file = "sweep", route ("reduced" or "full";
//!   files written before 2026-11-26 have none and are reduced), basis,
//!   basis_content_hash, variant, n_modes (reduced sweeps only), model_fingerprint,
//!   validated (0/1), wall_seconds (whole sweep), threads, continuation (1 when the runs
//!   were continued from their neighbours), n_failed, n_pending, program_version
//! ```

use super::outcome::{ScaleResult, Sweep, SweepPoint, STATUS_OK, STATUS_PENDING};
use crate::error::{Error, Result};
use crate::io::attrs::{check_layout, write_atomically_as, Kind};
use crate::io::basis_file::StoredBasis;
use crate::io::h5::{attr_f64, attr_str, attr_u64, bounded_len, dataset_of_shape, read_attr_str, read_strings};
use crate::model::Model;
use crate::pipeline::validate::{displacement_note, ProbeQuantityError, Validation};
use crate::rom::estimator::{Estimate, QuantityEstimate};
use crate::rom::quantities::Quantity;
use crate::rom::trust::LoadSensitivity;
use crate::rom::ReducedRun;
use crate::simulate::{Overrides, Settings, SimulationResult};
use crate::solver::generalized_alpha::Stats;
use crate::solver::parameters::Parameters;
use hdf5::types::VarLenUnicode;
use ndarray::{Array1, Array2, Array3};
use std::path::Path;

/// Named series of every run (name → load × time).
type NamedRuns = Vec<(String, Array2<f64>)>;

/// Extra content written into every version of a sweep file (a shard's `/shard` group).
pub type Extra<'a> = &'a (dyn Fn(&hdf5::File) -> Result<()> + Sync);

/// The basis file a reduced sweep ran: as read and checked (`stored`) and where (`path`).
#[derive(Clone, Copy)]
pub struct SweepBasis<'a> {
    pub stored: &'a StoredBasis,
    pub path: &'a Path,
    /// greedy training's sensitivity along the range (`/sensitivity_near`), when it has one
    pub sensitivity: Option<&'a LoadSensitivity>,
}

/// The value of the `route` attribute: what the sweep ran.
fn route_name(full: bool) -> &'static str {
    if full {
        "full"
    } else {
        "reduced"
    }
}

/// The probe quantities of a model with these probes and section probes (strain,
/// curvature), in [`crate::rom::quantities::readings`]' order: every probe's position, then
/// the strains, then the curvatures.
fn quantity_keys<'a>(
    probe_names: &'a [String],
    [strains, curvatures]: &'a [Vec<String>; 2],
) -> Vec<(Quantity, &'a str)> {
    let named = |q: Quantity, names: &'a [String]| names.iter().map(move |n| (q, n.as_str()));
    named(Quantity::Position, probe_names)
        .chain(named(Quantity::Strain, strains))
        .chain(named(Quantity::Curvature, curvatures))
        .collect()
}

/// `/probe_strain/<name>` and `/probe_curvature/<name>` (load, time): each run's strain and
/// curvature at the probes that record them; NaN where a load did not run to the end.
fn write_sections(f: &hdf5::File, s: &Sweep) -> hdf5::Result<()> {
    let (n, nt) = (s.scales.len(), s.t.len());
    for (group, i) in [("probe_strain", 0), ("probe_curvature", 1)] {
        if s.section_names[i].is_empty() {
            continue;
        }
        let g = f.create_group(group)?;
        for (j, name) in s.section_names[i].iter().enumerate() {
            let mut a = Array2::from_elem((n, nt), f64::NAN);
            for (k, x) in s.scales.iter().enumerate() {
                let series = x.point().map(|p| if i == 0 { &p.run.result.strains } else { &p.run.result.curvatures });
                if let Some((_, v)) = series.and_then(|v| v.get(j)).filter(|(_, v)| v.len() == nt) {
                    a.row_mut(k).assign(v);
                }
            }
            g.new_dataset_builder().with_data(&a).create(name.as_str())?;
        }
    }
    Ok(())
}

/// `/probe_error_estimate/<quantity>/<name>` (load): each probe quantity's estimated error
/// over its range (0 where the full model answered; NaN: no estimate), and with
/// `--validate` `/probe_error/<quantity>/<name>`, the error measured against the full run.
fn write_quantity_errors(f: &hdf5::File, s: &Sweep) -> hdf5::Result<()> {
    let estimate = |p: &SweepPoint, q: Quantity, name: &str| {
        if p.fallback.is_some() {
            return 0.0;
        }
        let e = p.estimate.as_ref().and_then(|e| e.quantities.iter().find(|x| x.quantity == q && x.probe == name));
        e.map_or(f64::NAN, |e| e.estimate)
    };
    let error = |p: &SweepPoint, q: Quantity, name: &str| {
        let v = p.validation.as_ref().and_then(|v| {
            v.probe_quantity_errors.iter().find(|x| x.quantity == q && x.probe == name).and_then(|x| x.relative)
        });
        v.unwrap_or(f64::NAN)
    };
    type Column = fn(&SweepPoint, Quantity, &str) -> f64;
    let groups: [(&str, Column); 2] = [("probe_error_estimate", estimate), ("probe_error", error)];
    for (group, value) in &groups[..if s.validated { 2 } else { 1 }] {
        let top = f.create_group(group)?;
        for (q, name) in quantity_keys(&s.probe_names, &s.section_names) {
            let g = if top.link_exists(q.name()) { top.group(q.name())? } else { top.create_group(q.name())? };
            let col = Array1::from_iter(s.scales.iter().map(|x| x.point().map_or(f64::NAN, |p| value(p, q, name))));
            g.new_dataset_builder().with_data(&col).create(name)?;
        }
    }
    Ok(())
}

/// Writes the sweep file (atomically: a temporary file renamed over `path`); `basis` is
/// the basis of a reduced sweep, `None` for a full one.
pub fn write_sweep(path: &Path, s: &Sweep, basis: Option<SweepBasis>) -> Result<()> {
    write_sweep_with(path, s, basis, &|_| Ok(()))
}

/// [`write_sweep`] with `extra` written into the file before it is renamed into place.
pub fn write_sweep_with(path: &Path, s: &Sweep, basis: Option<SweepBasis>, extra: Extra) -> Result<()> {
    let (n, nt, r) = (s.scales.len(), s.t.len(), s.n_reduced);
    if n == 0 {
        return Err(Error::Usage("the sweep has no load scales".into()));
    }
    if s.full != basis.is_none() {
        return Err(Error::Usage(format!(
            "{}: a reduced sweep is written with its basis, a full one without",
            path.display()
        )));
    }
    write_atomically_as(path, Kind::Sweep, |f| {
        let e = |err: hdf5::Error| Error::hdf5(path, err);
        // one value per load scale: NaN where it did not run to the end
        let col =
            |g: &dyn Fn(&SweepPoint) -> f64| Array1::from_iter(s.scales.iter().map(|x| x.point().map_or(f64::NAN, g)));
        let count = |g: &dyn Fn(&SweepPoint) -> usize| {
            Array1::from_iter(s.scales.iter().map(|x| x.point().map_or(0, g) as u64))
        };
        f.new_dataset_builder()
            .with_data(&Array1::from_iter(s.scales.iter().map(|x| x.mu.scale())))
            .create("load_scales")
            .map_err(e)?;
        // the points, where the sweep sets a named parameter (a line of load scales has none)
        let names = point_names(s.scales.iter().map(|x| &x.mu));
        if names.len() > 1 {
            let points = Array2::from_shape_fn((n, names.len()), |(k, j)| s.scales[k].mu.get(&names[j]).unwrap_or(1.0));
            let d = f.new_dataset_builder().with_data(&points).create("points").map_err(e)?;
            attr_str(&d, "parameters", &names.join(",")).map_err(e)?;
        }
        f.new_dataset_builder()
            .with_data(&Array1::from_iter(s.scales.iter().map(ScaleResult::status)))
            .create("status")
            .map_err(e)?;
        let messages: Vec<VarLenUnicode> = s
            .scales
            .iter()
            .map(|x| x.message().replace('\0', " ").parse::<VarLenUnicode>().unwrap_or_default())
            .collect();
        f.new_dataset_builder().with_data(&Array1::from(messages)).create("message").map_err(e)?;
        f.new_dataset_builder().with_data(&s.t).create("t").map_err(e)?;
        // the reduced runs' probes, and beside them with --validate the full runs'
        type ProbesOf = fn(&SweepPoint) -> Option<&[(String, Array2<f64>)]>;
        let groups: &[(&str, ProbesOf)] =
            &[("probes", |p| Some(&p.run.result.probes)), ("full_probes", |p| p.full_probes.as_deref())];
        for (group, probes) in &groups[..if s.validated { 2 } else { 1 }] {
            let g = f.create_group(group).map_err(e)?;
            for (i, name) in s.probe_names.iter().enumerate() {
                let mut a = Array3::from_elem((n, nt, 2), f64::NAN);
                for (k, x) in s.scales.iter().enumerate() {
                    if let Some(xy) = x.point().and_then(probes) {
                        a.index_axis_mut(ndarray::Axis(0), k).assign(&xy[i].1);
                    }
                }
                g.new_dataset_builder().with_data(&a).create(name.as_str()).map_err(e)?;
            }
        }
        write_sections(f, s).map_err(e)?;
        write_quantity_errors(f, s).map_err(e)?;
        if !s.full {
            // time first: (load, time, mode); the runs keep r × n_t
            let mut zq = Array3::from_elem((n, nt, r), f64::NAN);
            // NaN where the full model answered in place of the reduced one (no reduced q)
            for (k, x) in s.scales.iter().enumerate() {
                if let Some(p) = x.point().filter(|p| p.fallback.is_none()) {
                    zq.index_axis_mut(ndarray::Axis(0), k).assign(&p.run.reduced_q.t());
                }
            }
            // one chunk per run, not compressed: deflate took 15 % off the size of these
            // trajectories for 0.15 s of a 1.5 s four-bar sweep
            f.new_dataset_builder().chunk((1, nt.max(1), r.max(1))).with_data(&zq).create("reduced_q").map_err(e)?;
            f.new_dataset_builder().with_data(&col(&|p| p.run.result.wall_seconds)).create("rom_seconds").map_err(e)?;
            // 1 where the full model answered in place of the reduced one (`--fallback full`;
            // why: /message; its probes, seconds and iterations are then the full run's), 2
            // where it was tried and failed and the reduced answer stands
            f.new_dataset_builder()
                .with_data(&Array1::from_iter(s.scales.iter().map(|x| x.point().map_or(0, SweepPoint::fallback_code))))
                .create("fallback")
                .map_err(e)?;
        }
        f.new_dataset_builder()
            .with_data(&count(&|p| p.run.result.stats.newton_iterations))
            .create("newton_iterations")
            .map_err(e)?;
        f.new_dataset_builder()
            .with_data(&count(&|p| p.run.result.stats.factorizations))
            .create("factorizations")
            .map_err(e)?;
        f.new_dataset_builder()
            .with_data(&col(&|p| p.estimate.as_ref().map_or(f64::NAN, |e| e.error_estimate)))
            .create("error_estimate")
            .map_err(e)?;
        // (load, fifth) of an estimate's by-fifth figures; NaN where a load has none
        let by_fifth = |get: &dyn Fn(&crate::rom::estimator::Estimate) -> crate::rom::estimator::ByFifth| {
            let mut a = Array2::from_elem((n, 5), f64::NAN);
            for (k, x) in s.scales.iter().enumerate() {
                if let Some(est) = x.point().and_then(|p| p.estimate.as_ref()) {
                    a.row_mut(k).assign(&ndarray::ArrayView1::from(&get(est)));
                }
            }
            a
        };
        f.new_dataset_builder().with_data(&by_fifth(&|e| e.by_time)).create("error_estimate_by_time").map_err(e)?;
        f.new_dataset_builder()
            .with_data(&col(&|p| p.estimate.as_ref().map_or(f64::NAN, |e| e.error_estimate_displacement)))
            .create("error_estimate_displacement")
            .map_err(e)?;
        f.new_dataset_builder()
            .with_data(&by_fifth(&|e| e.displacement_by_time))
            .create("error_estimate_displacement_by_time")
            .map_err(e)?;
        f.new_dataset_builder()
            .with_data(&col(&|p| p.estimate.as_ref().map_or(f64::NAN, |e| e.seconds)))
            .create("estimate_seconds")
            .map_err(e)?;
        f.new_dataset_builder()
            .with_data(&Array1::from_iter(s.scales.iter().map(|x| x.point().is_some_and(|p| p.extrapolated) as u8)))
            .create("extrapolated")
            .map_err(e)?;
        // training's sensitivity beside each load (NaN: a full sweep, or a basis without it)
        let sensitivity = basis.as_ref().and_then(|b| b.sensitivity);
        f.new_dataset_builder()
            .with_data(&Array1::from_iter(
                s.scales.iter().map(|x| sensitivity.as_ref().and_then(|t| t.near(&x.mu)).unwrap_or(f64::NAN)),
            ))
            .create("sensitivity_near")
            .map_err(e)?;
        if s.validated {
            let v = |g: &dyn Fn(&Validation) -> f64| col(&|p: &SweepPoint| p.validation.as_ref().map_or(f64::NAN, g));
            f.new_dataset_builder().with_data(&v(&|x| x.rel_error)).create("rel_error").map_err(e)?;
            f.new_dataset_builder().with_data(&v(&|x| x.max_probe_error)).create("max_probe_error").map_err(e)?;
            f.new_dataset_builder()
                .with_data(&v(&|x| x.max_constraint_violation))
                .create("max_constraint_violation")
                .map_err(e)?;
            f.new_dataset_builder().with_data(&v(&|x| x.full_seconds)).create("full_seconds").map_err(e)?;
            f.new_dataset_builder().with_data(&v(&|x| x.speedup)).create("speedup").map_err(e)?;
            f.new_dataset_builder()
                .with_data(&v(&|x| x.steps_differ_from.unwrap_or(f64::NAN)))
                .create("steps_differ_from")
                .map_err(e)?;
            f.new_dataset_builder().with_data(&v(&|x| x.displacement_error)).create("displacement_error").map_err(e)?;
            let mut by_time = Array2::from_elem((n, 5), f64::NAN);
            for (k, x) in s.scales.iter().enumerate() {
                let r = x.point().and_then(|p| p.validation.as_ref()).map(|v| &v.rel_error_by_time);
                if let Some(r) = r.filter(|r| r.len() == 5) {
                    by_time.row_mut(k).assign(&ndarray::ArrayView1::from(&r[..]));
                }
            }
            f.new_dataset_builder().with_data(&by_time).create("rel_error_by_time").map_err(e)?;
        }
        if s.full {
            // the full time loops, as a validated sweep's column of the same name
            f.new_dataset_builder()
                .with_data(&col(&|p| p.run.result.wall_seconds))
                .create("full_seconds")
                .map_err(e)?;
        }
        attr_str(f, "route", route_name(s.full)).map_err(e)?;
        if let Some(SweepBasis { stored, path: basis_path, .. }) = basis {
            // absolute, so that the file names its basis wherever it is read from
            attr_str(f, "basis", &crate::io::output::resolve(basis_path).display().to_string()).map_err(e)?;
            attr_str(f, "basis_content_hash", &stored.content_hash).map_err(e)?;
            attr_str(f, "model_fingerprint", &stored.model_fingerprint).map_err(e)?;
            attr_str(f, "variant", stored.basis.variant.name()).map_err(e)?;
            attr_u64(f, "n_modes", stored.basis.n_reduced() as u64).map_err(e)?;
        } else {
            attr_str(f, "model_fingerprint", &s.model_fingerprint).map_err(e)?;
        }
        attr_u64(f, "validated", s.validated as u64).map_err(e)?;
        attr_str(f, "fallback", s.fallback.name()).map_err(e)?;
        attr_f64(f, "wall_seconds", s.wall_seconds).map_err(e)?;
        attr_u64(f, "threads", s.threads as u64).map_err(e)?;
        attr_u64(f, "continuation", s.continuation as u64).map_err(e)?;
        attr_u64(f, "n_failed", s.n_failed() as u64).map_err(e)?;
        attr_u64(f, "n_pending", s.scales.iter().filter(|x| x.status() == STATUS_PENDING).count() as u64).map_err(e)?;
        attr_str(f, "program_version", env!("CARGO_PKG_VERSION")).map_err(e)?;
        extra(f)
    })
}

/// The parameters of `points`: `load_scale` first, then every named one any point sets, in
/// name order (the columns of `/points`).
pub fn point_names<'a>(points: impl Iterator<Item = &'a Parameters>) -> Vec<String> {
    let mut named = std::collections::BTreeSet::new();
    for mu in points {
        named.extend(mu.named().map(|(n, _)| n.to_string()));
    }
    std::iter::once(crate::solver::parameters::LOAD_SCALE.to_string()).chain(named).collect()
}

/// The parameters of every run of an open sweep file: `/points` when it has them, else the
/// load scales `scales` (`/load_scales`). `Err((field, problem))`.
pub fn points_of(f: &hdf5::File, scales: &[f64]) -> std::result::Result<Vec<Parameters>, (&'static str, String)> {
    if !f.link_exists("points") {
        return Ok(scales.iter().map(|&x| Parameters::load_scale(x)).collect());
    }
    let d = f.dataset("points").map_err(|e| ("points", format!("cannot be read: {e}")))?;
    read_point_table(&d, scales.len()).map(|(_, points)| points).map_err(|e| ("points", e))
}

/// A (point, parameter) table as `/points` stores it (the names in its attribute
/// `parameters`): the names and one `Parameters` per row; `Err(problem)` when it cannot be
/// read or has not `rows` rows and a column per name.
pub fn read_point_table(d: &hdf5::Dataset, rows: usize) -> std::result::Result<(Vec<String>, Vec<Parameters>), String> {
    let names = read_attr_str(d, "parameters").map_err(|e| format!("has no readable attribute `parameters`: {e}"))?;
    let names: Vec<String> = names.split(',').map(str::to_string).collect();
    // the shape before the values: a damaged one must not size the allocation
    if d.shape() != [rows, names.len()] {
        return Err(format!("is {:?}, expected ({rows}, {}) for its parameters {names:?}", d.shape(), names.len()));
    }
    let a = d.read::<f64, ndarray::Ix2>().map_err(|e| format!("cannot be read: {e}"))?;
    let points =
        a.rows().into_iter().map(|row| names.iter().zip(row).fold(Parameters::default(), |mu, (n, &v)| mu.with(n, v)));
    Ok((names.clone(), points.collect()))
}

/// The `fallback` a sweep file was written with (files before the attribute: `none`).
pub fn fallback_of(path: &Path) -> Result<super::Fallback> {
    let f =
        crate::io::h5_open::open(path).map_err(|e| Error::input(path, "(file)", crate::io::h5_open::unreadable(&e)))?;
    if f.attr("fallback").is_err() {
        return Ok(super::Fallback::None);
    }
    match read_attr_str(&f, "fallback").map_err(|e| Error::input(path, "fallback", format!("cannot be read: {e}")))? {
        s if s == "full" => Ok(super::Fallback::Full),
        s if s == "none" => Ok(super::Fallback::None),
        s => Err(Error::input(path, "fallback", format!("is \"{s}\", expected \"none\" or \"full\""))),
    }
}

/// Reads an earlier sweep file for `--resume`: (parameters, the finished run) for every
/// point it holds, `None` for those that failed or did not run. `stored` is the basis of a
/// reduced sweep, `None` for a full one. Refuses a file of another route, basis or model,
/// and one without the validation a `--validate` sweep needs.
pub fn read_sweep(
    path: &Path,
    model: &Model,
    stored: Option<&StoredBasis>,
    validate: bool,
) -> Result<Vec<(Parameters, Option<SweepPoint>)>> {
    let cannot = |field: &str, problem: String| {
        Error::input(path, field, format!("{problem}; cannot resume from it (remove it, or run without --resume)"))
    };
    let f = crate::io::h5_open::open(path).map_err(|e| cannot("(file)", crate::io::h5_open::unreadable(&e)))?;
    // layout 1 stored /reduced_q as (N, r, n_t): converted below; newer layouts are refused
    let layout = check_layout(&f, path, "flexrom sweep")?;
    let text = |name: &str| {
        read_attr_str(&f, name).map_err(|e| cannot(name, format!("cannot be read ({e}): not a flexrom sweep file?")))
    };
    // files written before the attribute are reduced sweeps
    let file_full = f.attr("route").is_ok() && text("route")? == route_name(true);
    match (stored, file_full) {
        (Some(_), true) => {
            return Err(cannot("route", "is \"full\": a sweep of the full model (`--full`), not of a basis".into()))
        }
        (None, false) => {
            return Err(cannot(
                "route",
                "is not \"full\": a sweep of a reduced model, which a full sweep (`--full`) does not take runs from"
                    .into(),
            ))
        }
        (Some(stored), false) if text("basis_content_hash")? != stored.content_hash => {
            return Err(cannot("basis_content_hash", "comes from another basis than the one given".into()));
        }
        _ => {}
    }
    if text("model_fingerprint")? != model.fingerprint() {
        return Err(cannot("model_fingerprint", "comes from another model than the pipeline's".into()));
    }
    let s = Settings::resolve(model, &Overrides::default())?;
    let (nt, r) = (s.n_steps + 1, stored.map_or(0, |b| b.basis.n_reduced()));
    // the number of runs is the file's own: bounded by what holding them takes (coordinates,
    // reduced and full probes, the per-run columns) before anything is read, and every
    // dataset's shape checked against it before that dataset is read
    let sections: usize = model.section_names().iter().map(Vec::len).sum();
    let per_run = 8.0 * (nt as f64 * (r + 4 * model.probe_names().len() + sections) as f64 + 32.0);
    let n = bounded_len(&f, "load_scales", per_run, &model.limits).map_err(|p| cannot("load_scales", p))?;
    let shaped = |name: &str, want: &[usize]| dataset_of_shape(&f, name, want).map_err(|p| cannot(name, p));
    let read = |name: &str, e: hdf5::Error| cannot(name, format!("cannot be read: {e}"));
    let vec = |name: &str| shaped(name, &[n])?.read_1d::<f64>().map_err(|e| read(name, e));
    let ints = |name: &str| shaped(name, &[n])?.read_1d::<u64>().map_err(|e| read(name, e));
    let flags = |name: &str| shaped(name, &[n])?.read_1d::<u8>().map_err(|e| read(name, e));
    let scales = vec("load_scales")?;
    let points = points_of(&f, &scales.to_vec()).map_err(|(field, problem)| cannot(field, problem))?;
    let status = flags("status")?;
    let t = shaped("t", &[nt])?.read_1d::<f64>().map_err(|e| read("t", e))?;
    let zq = if file_full {
        // a full sweep keeps no coordinates
        Array3::zeros((n, 0, nt))
    } else {
        let want = if layout == 1 { [n, r, nt] } else { [n, nt, r] };
        shaped("reduced_q", &want)?.read::<f64, ndarray::Ix3>().map_err(|e| read("reduced_q", e))?
    };
    let zq = if file_full || layout == 1 {
        zq
    } else {
        // back to the runs' r × n_t
        zq.permuted_axes([0, 2, 1]).as_standard_layout().to_owned()
    };
    let read_probes = |group: &str| -> Result<Vec<(String, Array3<f64>)>> {
        let mut probes = Vec::new();
        for name in model.probe_names() {
            let path = format!("{group}/{name}");
            let a = shaped(&path, &[n, nt, 2])?.read::<f64, ndarray::Ix3>().map_err(|e| read(&path, e))?;
            probes.push((name, a));
        }
        Ok(probes)
    };
    let probes = read_probes("probes")?;
    // each run's strains and curvatures, the probe quantities' estimates and (validated)
    // errors; files written before them have none, and their points read back without
    let read_series = |group: &str, names: &[String]| -> Result<Option<NamedRuns>> {
        if names.is_empty() || !f.link_exists(group) {
            return Ok(None);
        }
        let series = names.iter().map(|name| {
            let path = format!("{group}/{name}");
            let a = shaped(&path, &[n, nt])?.read::<f64, ndarray::Ix2>().map_err(|e| read(&path, e))?;
            Ok((name.clone(), a))
        });
        series.collect::<Result<Vec<_>>>().map(Some)
    };
    let (probe_names, section_names) = (model.probe_names(), model.section_names());
    let sections =
        [read_series("probe_strain", &section_names[0])?, read_series("probe_curvature", &section_names[1])?];
    let keys = quantity_keys(&probe_names, &section_names);
    let read_quantities = |group: &str| -> Result<Option<Vec<Array1<f64>>>> {
        if !f.link_exists(group) {
            return Ok(None);
        }
        keys.iter().map(|(q, name)| vec(&format!("{group}/{}/{name}", q.name()))).collect::<Result<Vec<_>>>().map(Some)
    };
    let quantity_estimates = read_quantities("probe_error_estimate")?;
    let quantity_errors = if validate { read_quantities("probe_error")? } else { None };
    let section_at = |i: usize, k: usize| -> crate::simulate::Series {
        sections[i]
            .as_ref()
            .map_or_else(Vec::new, |v| v.iter().map(|(n, a)| (n.clone(), a.row(k).to_owned())).collect())
    };
    // files written before /full_probes hold validations without them: run again
    let full_probes = if validate && f.link_exists("full_probes") { Some(read_probes("full_probes")?) } else { None };
    let at = |probes: &[(String, Array3<f64>)], k: usize| -> Vec<(String, Array2<f64>)> {
        probes.iter().map(|(name, a)| (name.clone(), a.index_axis(ndarray::Axis(0), k).to_owned())).collect()
    };
    // each run's time loop: the reduced one, or a full sweep's full one
    let seconds_name = if file_full { "full_seconds" } else { "rom_seconds" };
    let rom_seconds = vec(seconds_name)?;
    // the estimate columns of the file (absent in files written before them: no estimate)
    let optional = |name: &str| if f.link_exists(name) { vec(name).map(Some) } else { Ok(None) };
    let (estimates, estimate_seconds, extrapolated) = (
        optional("error_estimate")?,
        optional("estimate_seconds")?,
        if f.link_exists("extrapolated") { Some(flags("extrapolated")?) } else { None },
    );
    // files written before /fallback hold reduced answers only; a fallback's reason is its
    // /message
    let fallback = if f.link_exists("fallback") {
        let flags = flags("fallback")?;
        let messages = read_strings(&shaped("message", &[n])?).map_err(|e| read("message", e))?;
        if flags.len() != n || messages.len() != n {
            return Err(cannot(
                "fallback",
                format!("has {} entries (/message {}) for {n} load scales", flags.len(), messages.len()),
            ));
        }
        flags.iter().zip(messages).map(|(&x, m)| (x, m)).collect()
    } else {
        vec![(0, String::new()); n]
    };
    let by_fifth = |name: &str| -> Result<Option<Array2<f64>>> {
        if !f.link_exists(name) {
            return Ok(None);
        }
        shaped(name, &[n, 5])?.read::<f64, ndarray::Ix2>().map(Some).map_err(|e| read(name, e))
    };
    let by_time = by_fifth("error_estimate_by_time")?;
    // files written before the displacement measure have neither: NaN
    let (estimates_displacement, displacement_by_time) =
        (optional("error_estimate_displacement")?, by_fifth("error_estimate_displacement_by_time")?);
    let displacement = if validate { optional("displacement_error")? } else { None };
    let rel_by_time = if validate { by_fifth("rel_error_by_time")? } else { None };
    let (newton, factorizations) = (ints("newton_iterations")?, ints("factorizations")?);
    // files written before it have no /steps_differ_from: unknown, as no halved step
    let differ = if validate && f.link_exists("steps_differ_from") { Some(vec("steps_differ_from")?) } else { None };
    if differ.as_ref().is_some_and(|a| a.len() != n) {
        return Err(cannot(
            "steps_differ_from",
            format!("has {} entries, expected {n}", differ.map_or(0, |a| a.len())),
        ));
    }
    let validation = if validate && f.link_exists("rel_error") && full_probes.is_some() {
        Some([
            vec("rel_error")?,
            vec("max_probe_error")?,
            vec("max_constraint_violation")?,
            vec("full_seconds")?,
            vec("speedup")?,
        ])
    } else {
        None
    };
    for a in [&rom_seconds]
        .into_iter()
        .chain(validation.iter().flatten())
        .chain(estimates.iter())
        .chain(estimate_seconds.iter())
        .chain(estimates_displacement.iter())
        .chain(displacement.iter())
    {
        if a.len() != n {
            return Err(cannot(
                seconds_name,
                format!("a per-scale dataset has {} entries for {n} load scales", a.len()),
            ));
        }
    }
    let mut out = Vec::new();
    for k in 0..n {
        let mu = points[k].clone();
        // a finished run counts only when it has what this sweep writes
        if status[k] != STATUS_OK || (validate && validation.is_none()) {
            out.push((mu, None));
            continue;
        }
        let settings = Settings::resolve(model, &Overrides::at(&mu))?;
        let stats = Stats {
            steps: settings.n_steps,
            newton_iterations: newton[k] as usize,
            factorizations: factorizations[k] as usize,
            ..Default::default()
        };
        let result = SimulationResult {
            model_text: model.text.clone(),
            model_path: model.path.display().to_string(),
            settings,
            t: t.clone(),
            q: Array2::zeros((0, nt)),
            qd: Array2::zeros((0, nt)),
            multipliers: Array2::zeros((0, nt)),
            probes: at(&probes, k),
            strains: section_at(0, k),
            curvatures: section_at(1, k),
            stats,
            wall_seconds: rom_seconds[k],
            energy: None,
        };
        let v = validation.as_ref().zip(stored).map(|(c, stored)| Validation {
            load_scale: mu.scale(),
            parameters: mu.iter().map(|(n, v)| (n.to_string(), v)).collect(),
            variant: stored.basis.variant.name().to_string(),
            n_dof: stored.basis.n_dof(),
            n_modes: r,
            rel_error: c[0][k],
            max_probe_error: c[1][k],
            max_probe_error_probe: String::new(),
            max_probe_error_t: f64::NAN,
            max_constraint_violation: c[2][k],
            full_seconds: c[3][k],
            full_dense_seconds: None,
            rom_seconds: rom_seconds[k],
            speedup: c[4][k],
            speedup_vs_dense: None,
            speedup_with_estimate: None,
            full_newton_iterations: 0,
            rom_newton_iterations: newton[k] as usize,
            rom_step_cuts: 0,
            full_step_cuts: 0,
            steps_differ_from: differ.as_ref().map(|a| a[k]).filter(|t| !t.is_nan()),
            full_step_cut_times: Vec::new(),
            rom_step_cut_times: Vec::new(),
            // the estimate and the flags are set below from the file's columns
            error_estimate: None,
            effectivity: None,
            estimate_calibrated: None,
            estimate_seconds: None,
            extrapolated: false,
            training_range: None,
            sensitivity: None,
            training_box: None,
            sensitivity_near: None,
            amplifying: false,
            rel_error_by_time: rel_by_time.as_ref().map_or_else(Vec::new, |a| a.row(k).to_vec()),
            error_estimate_by_time: None,
            displacement_error: displacement.as_ref().map_or(f64::NAN, |a| a[k]),
            // the words for a stored NaN or ∞ (a sweep before the column has none to explain)
            displacement_error_note: displacement.as_ref().and_then(|a| displacement_note(a[k])).map(str::to_string),
            displacement_error_by_time: Vec::new(),
            error_estimate_displacement: None,
            effectivity_displacement: None,
            error_estimate_displacement_by_time: None,
            max_error_over_travel: None,
            max_error_over_travel_probe: String::new(),
            probe_errors_over_travel: Vec::new(),
            probe_quantity_errors: quantity_errors.as_ref().map_or_else(Vec::new, |cols| {
                keys.iter().zip(cols).map(|((q, name), c)| ProbeQuantityError::stored(name, *q, c[k])).collect()
            }),
            reaction_errors: Vec::new(),
            error_estimate_method: None,
            estimate_failure: None,
        });
        // the stored estimate: its value and cost (the factor it was made with is the basis's)
        let estimate = estimates.as_ref().map(|a| a[k]).filter(|e| !e.is_nan()).map(|error_estimate| Estimate {
            error_estimate,
            raw: f64::NAN,
            factor: f64::NAN,
            calibrated: false,
            seconds: estimate_seconds.as_ref().map_or(f64::NAN, |a| a[k]),
            by_time: by_time.as_ref().map_or([f64::NAN; 5], |a| std::array::from_fn(|i| a[[k, i]])),
            error_estimate_displacement: estimates_displacement.as_ref().map_or(f64::NAN, |a| a[k]),
            displacement_by_time: displacement_by_time
                .as_ref()
                .map_or([f64::NAN; 5], |a| std::array::from_fn(|i| a[[k, i]])),
            failure: None,
            quantities: quantity_estimates.as_ref().map_or_else(Vec::new, |cols| {
                let each = keys.iter().zip(cols);
                each.map(|((q, name), c)| QuantityEstimate {
                    probe: name.to_string(),
                    quantity: *q,
                    estimate: c[k],
                    raw: f64::NAN,
                })
                .collect()
            }),
        });
        let extrapolated = extrapolated.as_ref().is_some_and(|a| a.get(k).is_some_and(|&v| v != 0));
        let v = v.map(|mut v| {
            if let Some(e) = &estimate {
                v.error_estimate = Some(e.error_estimate);
                v.effectivity = Some(e.error_estimate / v.rel_error);
                v.estimate_seconds = Some(e.seconds);
                v.error_estimate_by_time = Some(e.by_time.to_vec());
                v.error_estimate_displacement = Some(e.error_estimate_displacement);
                v.effectivity_displacement = Some(e.error_estimate_displacement / v.displacement_error);
                v.error_estimate_displacement_by_time = Some(e.displacement_by_time.to_vec());
                v = v.with_quantity_estimates(e);
            }
            v.extrapolated = extrapolated;
            v
        });
        // a fallback's full run has no reduced coordinates (NaN in the file)
        let (code, message) = &fallback[k];
        let reduced_q = if *code == 1 { Array2::zeros((0, nt)) } else { zq.index_axis(ndarray::Axis(0), k).to_owned() };
        let run = ReducedRun { result, reduced_q };
        let full_probes = full_probes.as_deref().map(|p| at(p, k));
        // a finished point's message: why the full model answered (1), or why it was tried
        // in place of the reduced answer kept and how it failed (2)
        let (fallback, note) = match code {
            1 => (Some(message.clone()), None),
            2 => (None, Some(message.clone())),
            _ => (None, None),
        };
        out.push((mu, Some(SweepPoint { run, validation: v, full_probes, estimate, extrapolated, fallback, note })));
    }
    Ok(out)
}
