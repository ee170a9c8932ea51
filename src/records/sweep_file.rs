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
//! /reaction_error_estimate/<force|moment>/<point> (N)  the estimate of each joint reaction's
//!                                    error over its range (crate::rom::reactions; a reduced
//!                                    sweep of a model with joints)
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

use super::sweep_outcome::{ScaleResult, Sweep, SweepPoint, STATUS_OK, STATUS_PENDING};
use super::validation::{displacement_note, ProbeQuantityError, Validation};
use crate::error::{Error, Result, Text};
use crate::io::attrs::{check_layout, write_atomically_as, Kind};
use crate::io::basis_file::StoredBasis;
use crate::io::h5::{attr_f64, attr_str, attr_u64, bounded_len, dataset_of_shape, read_attr_str, read_strings};
use crate::model::Model;
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
    write_reaction_estimates(f, s)
}

/// `/reaction_error_estimate/<force|moment>/<point>` (load): each joint reaction's estimated
/// error over its range (0 where the full model answered; NaN: no estimate, or a variant
/// without physical multipliers); a reduced sweep of a model with joints.
fn write_reaction_estimates(f: &hdf5::File, s: &Sweep) -> hdf5::Result<()> {
    if s.full || s.reactions.is_empty() {
        return Ok(());
    }
    let top = f.create_group("reaction_error_estimate")?;
    for (name, q) in &s.reactions {
        let estimate = |p: &SweepPoint| {
            let e =
                p.estimate.as_ref().and_then(|e| e.quantities.iter().find(|x| x.quantity == *q && x.probe == *name));
            if p.fallback.is_some() {
                0.0
            } else {
                e.map_or(f64::NAN, |e| e.estimate)
            }
        };
        let g = if top.link_exists(q.name()) { top.group(q.name())? } else { top.create_group(q.name())? };
        let col = Array1::from_iter(s.scales.iter().map(|x| x.point().map_or(f64::NAN, estimate)));
        g.new_dataset_builder().with_data(&col).create(name.as_str())?;
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
    if s.scales.is_empty() {
        return Err(Error::usage("the sweep has no load scales"));
    }
    if s.full != basis.is_none() {
        return Err(Error::usage(format!(
            "{}: a reduced sweep is written with its basis, a full one without",
            path.display()
        )));
    }
    write_atomically_as(path, Kind::Sweep, |f| {
        let e = |err: hdf5::Error| Error::hdf5(path, err);
        write_runs(f, s).map_err(e)?;
        write_estimates(f, s, basis.as_ref().and_then(|b| b.sensitivity)).map_err(e)?;
        if s.validated {
            write_validations(f, s).map_err(e)?;
        }
        if s.full {
            // the full time loops, as a validated sweep's column of the same name
            f.new_dataset_builder()
                .with_data(&column(s, &|p| p.run.result.wall_seconds))
                .create("full_seconds")
                .map_err(e)?;
        }
        write_attributes(f, s, basis).map_err(e)?;
        extra(f)
    })
}

/// One value per point: NaN where it did not run to the end.
fn column(s: &Sweep, g: &dyn Fn(&SweepPoint) -> f64) -> Array1<f64> {
    Array1::from_iter(s.scales.iter().map(|x| x.point().map_or(f64::NAN, g)))
}

/// One count per point: 0 where it did not run to the end.
fn counts(s: &Sweep, g: &dyn Fn(&SweepPoint) -> usize) -> Array1<u64> {
    Array1::from_iter(s.scales.iter().map(|x| x.point().map_or(0, g) as u64))
}

/// The runs: their points, status and messages, the time, the probes (reduced, and the
/// full runs' of a validated sweep), the section probes and probe quantities, a reduced
/// sweep's coordinates, seconds and fallbacks, and the solver's counts.
fn write_runs(f: &hdf5::File, s: &Sweep) -> hdf5::Result<()> {
    let (n, nt, r) = (s.scales.len(), s.t.len(), s.n_reduced);
    f.new_dataset_builder()
        .with_data(&Array1::from_iter(s.scales.iter().map(|x| x.mu.scale())))
        .create("load_scales")?;
    // the points, where the sweep sets a named parameter (a line of load scales has none)
    let names = point_names(s.scales.iter().map(|x| &x.mu));
    if names.len() > 1 {
        let points = Array2::from_shape_fn((n, names.len()), |(k, j)| s.scales[k].mu.get(&names[j]).unwrap_or(1.0));
        let d = f.new_dataset_builder().with_data(&points).create("points")?;
        attr_str(&d, "parameters", &names.join(","))?;
    }
    f.new_dataset_builder().with_data(&Array1::from_iter(s.scales.iter().map(ScaleResult::status))).create("status")?;
    let messages: Vec<VarLenUnicode> =
        s.scales.iter().map(|x| x.message().replace('\0', " ").parse::<VarLenUnicode>().unwrap_or_default()).collect();
    f.new_dataset_builder().with_data(&Array1::from(messages)).create("message")?;
    f.new_dataset_builder().with_data(&s.t).create("t")?;
    // the reduced runs' probes, and beside them with --validate the full runs'
    type ProbesOf = fn(&SweepPoint) -> Option<&[(String, Array2<f64>)]>;
    let groups: &[(&str, ProbesOf)] =
        &[("probes", |p| Some(&p.run.result.probes)), ("full_probes", |p| p.full_probes.as_deref())];
    for (group, probes) in &groups[..if s.validated { 2 } else { 1 }] {
        let g = f.create_group(group)?;
        for (i, name) in s.probe_names.iter().enumerate() {
            let mut a = Array3::from_elem((n, nt, 2), f64::NAN);
            for (k, x) in s.scales.iter().enumerate() {
                if let Some(xy) = x.point().and_then(probes) {
                    a.index_axis_mut(ndarray::Axis(0), k).assign(&xy[i].1);
                }
            }
            g.new_dataset_builder().with_data(&a).create(name.as_str())?;
        }
    }
    write_sections(f, s)?;
    write_quantity_errors(f, s)?;
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
        f.new_dataset_builder().chunk((1, nt.max(1), r.max(1))).with_data(&zq).create("reduced_q")?;
        f.new_dataset_builder().with_data(&column(s, &|p| p.run.result.wall_seconds)).create("rom_seconds")?;
        // 1 where the full model answered in place of the reduced one (`--fallback full`;
        // why: /message; its probes, seconds and iterations are then the full run's), 2
        // where it was tried and failed and the reduced answer stands
        f.new_dataset_builder()
            .with_data(&Array1::from_iter(s.scales.iter().map(|x| x.point().map_or(0, SweepPoint::fallback_code))))
            .create("fallback")?;
    }
    f.new_dataset_builder()
        .with_data(&counts(s, &|p| p.run.result.stats.newton_iterations))
        .create("newton_iterations")?;
    f.new_dataset_builder().with_data(&counts(s, &|p| p.run.result.stats.factorizations)).create("factorizations")?;
    Ok(())
}

/// The estimates a point (NaN where it has none), whether it extrapolated, and training's
/// sensitivity beside it (NaN: a full sweep, or a basis without it).
fn write_estimates(f: &hdf5::File, s: &Sweep, sensitivity: Option<&LoadSensitivity>) -> hdf5::Result<()> {
    let n = s.scales.len();
    f.new_dataset_builder()
        .with_data(&column(s, &|p| p.estimate.as_ref().map_or(f64::NAN, |e| e.error_estimate)))
        .create("error_estimate")?;
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
    f.new_dataset_builder().with_data(&by_fifth(&|e| e.by_time)).create("error_estimate_by_time")?;
    f.new_dataset_builder()
        .with_data(&column(s, &|p| p.estimate.as_ref().map_or(f64::NAN, |e| e.error_estimate_displacement)))
        .create("error_estimate_displacement")?;
    f.new_dataset_builder()
        .with_data(&by_fifth(&|e| e.displacement_by_time))
        .create("error_estimate_displacement_by_time")?;
    f.new_dataset_builder()
        .with_data(&column(s, &|p| p.estimate.as_ref().map_or(f64::NAN, |e| e.seconds)))
        .create("estimate_seconds")?;
    f.new_dataset_builder()
        .with_data(&Array1::from_iter(s.scales.iter().map(|x| x.point().is_some_and(|p| p.extrapolated) as u8)))
        .create("extrapolated")?;
    f.new_dataset_builder()
        .with_data(&Array1::from_iter(
            s.scales.iter().map(|x| sensitivity.as_ref().and_then(|t| t.near(&x.mu)).unwrap_or(f64::NAN)),
        ))
        .create("sensitivity_near")?;
    Ok(())
}

/// A validated sweep's columns: each point's errors, full seconds and speedup, where its
/// steps first differed, and its rel_error by fifth of the run (NaN where it has none).
fn write_validations(f: &hdf5::File, s: &Sweep) -> hdf5::Result<()> {
    let v = |g: &dyn Fn(&Validation) -> f64| column(s, &|p: &SweepPoint| p.validation.as_ref().map_or(f64::NAN, g));
    f.new_dataset_builder().with_data(&v(&|x| x.rel_error)).create("rel_error")?;
    f.new_dataset_builder().with_data(&v(&|x| x.max_probe_error)).create("max_probe_error")?;
    f.new_dataset_builder().with_data(&v(&|x| x.max_constraint_violation)).create("max_constraint_violation")?;
    f.new_dataset_builder().with_data(&v(&|x| x.full_seconds)).create("full_seconds")?;
    f.new_dataset_builder().with_data(&v(&|x| x.speedup)).create("speedup")?;
    f.new_dataset_builder().with_data(&v(&|x| x.steps_differ_from.unwrap_or(f64::NAN))).create("steps_differ_from")?;
    f.new_dataset_builder().with_data(&v(&|x| x.displacement_error)).create("displacement_error")?;
    let mut by_time = Array2::from_elem((s.scales.len(), 5), f64::NAN);
    for (k, x) in s.scales.iter().enumerate() {
        let r = x.point().and_then(|p| p.validation.as_ref()).map(|v| &v.rel_error_by_time);
        if let Some(r) = r.filter(|r| r.len() == 5) {
            by_time.row_mut(k).assign(&ndarray::ArrayView1::from(&r[..]));
        }
    }
    f.new_dataset_builder().with_data(&by_time).create("rel_error_by_time")?;
    Ok(())
}

/// The file's attributes: the route, the basis (or the model) it ran, and the sweep's own.
fn write_attributes(f: &hdf5::File, s: &Sweep, basis: Option<SweepBasis>) -> hdf5::Result<()> {
    attr_str(f, "route", route_name(s.full))?;
    if let Some(SweepBasis { stored, path: basis_path, .. }) = basis {
        // absolute, so that the file names its basis wherever it is read from
        attr_str(f, "basis", &crate::io::output::resolve(basis_path).display().to_string())?;
        attr_str(f, "basis_content_hash", &stored.content_hash)?;
        attr_str(f, "model_fingerprint", &stored.model_fingerprint)?;
        attr_str(f, "variant", stored.basis.variant.name())?;
        attr_u64(f, "n_modes", stored.basis.n_reduced() as u64)?;
    } else {
        attr_str(f, "model_fingerprint", &s.model_fingerprint)?;
    }
    attr_u64(f, "validated", s.validated as u64)?;
    attr_str(f, "fallback", s.fallback.name())?;
    attr_f64(f, "wall_seconds", s.wall_seconds)?;
    attr_u64(f, "threads", s.threads as u64)?;
    attr_u64(f, "continuation", s.continuation as u64)?;
    attr_u64(f, "n_failed", s.n_failed() as u64)?;
    attr_u64(f, "n_pending", s.scales.iter().filter(|x| x.status() == STATUS_PENDING).count() as u64)?;
    attr_str(f, "program_version", env!("CARGO_PKG_VERSION"))
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
pub fn fallback_of(path: &Path) -> Result<crate::pipeline::fallback::Fallback> {
    let f =
        crate::io::h5_open::open(path).map_err(|e| Error::input(path, "(file)", crate::io::h5_open::unreadable(&e)))?;
    if f.attr("fallback").is_err() {
        return Ok(crate::pipeline::fallback::Fallback::None);
    }
    match read_attr_str(&f, "fallback").map_err(|e| Error::input(path, "fallback", format!("cannot be read: {e}")))? {
        s if s == "full" => Ok(crate::pipeline::fallback::Fallback::Full),
        s if s == "none" => Ok(crate::pipeline::fallback::Fallback::None),
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
    let (f, layout, file_full) = open_to_resume(path, model, stored)?;
    let s = Settings::resolve(model, &Overrides::default())?;
    let (nt, r) = (s.n_steps + 1, stored.map_or(0, |b| b.basis.n_reduced()));
    // the number of runs is the file's own: bounded by what holding them takes (coordinates,
    // reduced and full probes, the per-run columns) before anything is read, and every
    // dataset's shape checked against it before that dataset is read
    let sections: usize = model.section_names().iter().map(Vec::len).sum();
    let per_run = 8.0 * (nt as f64 * (r + 4 * model.probe_names().len() + sections) as f64 + 32.0);
    let n = bounded_len(&f, "load_scales", per_run, &model.limits)
        .map_err(|p| cannot_resume(path, "load_scales", p.problem_text()))?;
    let file = Resumed { f, path, n, nt };
    let (probe_names, section_names) = (model.probe_names(), model.section_names());
    let keys = quantity_keys(&probe_names, &section_names);
    let reactions = crate::rom::reactions::ReactionReader::new(model).points();
    let reaction_keys: Vec<(Quantity, &str)> = reactions.iter().map(|(n, q)| (*q, n.as_str())).collect();
    let mut runs = file.runs(model, &keys, (layout, r), file_full, validate)?;
    // files written before the reactions' estimates have none: their points read back without
    runs.reaction_estimates = file.quantities("reaction_error_estimate", &reaction_keys)?;
    let columns = file.columns(file_full, validate, runs.full_probes.is_some(), runs.rom_seconds.len())?;
    let read = ReadBack { model, stored, r, nt, keys: &keys, reaction_keys: &reaction_keys, runs, columns, validate };
    (0..n).map(|k| read.point(k)).collect()
}

/// The error for a sweep file `--resume` cannot take: the file, the field and the problem.
fn cannot_resume(path: &Path, field: &str, problem: impl Into<Text>) -> Error {
    let problem = problem.into().then("; cannot resume from it (remove it, or run without ");
    Error::input(path, field, problem.option("resume", None).then(")"))
}

/// Opens an earlier sweep file for `--resume` and checks that it is one of this sweep: its
/// route (reduced with `stored`, else full), basis and model. Returns the file, its layout
/// version and whether it is a full sweep.
fn open_to_resume(path: &Path, model: &Model, stored: Option<&StoredBasis>) -> Result<(hdf5::File, u64, bool)> {
    let cannot = |field: &str, problem: String| cannot_resume(path, field, problem);
    let f = crate::io::h5_open::open(path).map_err(|e| cannot("(file)", crate::io::h5_open::unreadable(&e)))?;
    // layout 1 stored /reduced_q as (N, r, n_t): converted on reading; newer layouts are refused
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
    Ok((f, layout, file_full))
}

/// An earlier sweep file opened for `--resume`: its datasets, each read with its shape
/// checked against the file's number of runs `n` and the model's instants `nt`.
struct Resumed<'a> {
    f: hdf5::File,
    path: &'a Path,
    n: usize,
    nt: usize,
}

/// What a sweep file holds of its runs (index 0 of each array: the run).
struct StoredRuns {
    points: Vec<Parameters>,
    status: Array1<u8>,
    t: Array1<f64>,
    /// reduced coordinates, run × r × n_t (none for a full sweep)
    zq: Array3<f64>,
    probes: Vec<(String, Array3<f64>)>,
    /// strains and curvatures at the section probes
    sections: [Option<NamedRuns>; 2],
    quantity_estimates: Option<Vec<Array1<f64>>>,
    quantity_errors: Option<Vec<Array1<f64>>>,
    /// the joint reactions' estimates, in the model's reaction order
    reaction_estimates: Option<Vec<Array1<f64>>>,
    full_probes: Option<Vec<(String, Array3<f64>)>>,
    /// the time loops' seconds: the reduced runs', or a full sweep's full runs'
    rom_seconds: Array1<f64>,
}

/// A sweep file's per-run columns beside the runs: estimates, fallbacks, solver counts and
/// validations (each `None` where the file has none).
struct StoredColumns {
    estimates: Option<Array1<f64>>,
    estimate_seconds: Option<Array1<f64>>,
    extrapolated: Option<Array1<u8>>,
    /// (code, message) a run
    fallback: Vec<(u8, String)>,
    by_time: Option<Array2<f64>>,
    estimates_displacement: Option<Array1<f64>>,
    displacement_by_time: Option<Array2<f64>>,
    displacement: Option<Array1<f64>>,
    rel_by_time: Option<Array2<f64>>,
    newton: Array1<u64>,
    factorizations: Array1<u64>,
    differ: Option<Array1<f64>>,
    /// rel_error, max_probe_error, max_constraint_violation, full_seconds, speedup
    validation: Option<[Array1<f64>; 5]>,
}

impl Resumed<'_> {
    fn cannot(&self, field: &str, problem: String) -> Error {
        cannot_resume(self.path, field, problem)
    }

    fn shaped(&self, name: &str, want: &[usize]) -> Result<hdf5::Dataset> {
        dataset_of_shape(&self.f, name, want).map_err(|p| self.cannot(name, p.problem()))
    }

    fn read_err(&self, name: &str, e: hdf5::Error) -> Error {
        self.cannot(name, format!("cannot be read: {e}"))
    }

    /// A per-run column of numbers.
    fn vec(&self, name: &str) -> Result<Array1<f64>> {
        self.shaped(name, &[self.n])?.read_1d::<f64>().map_err(|e| self.read_err(name, e))
    }

    /// A per-run column of counts.
    fn ints(&self, name: &str) -> Result<Array1<u64>> {
        self.shaped(name, &[self.n])?.read_1d::<u64>().map_err(|e| self.read_err(name, e))
    }

    /// A per-run column of flags.
    fn flags(&self, name: &str) -> Result<Array1<u8>> {
        self.shaped(name, &[self.n])?.read_1d::<u8>().map_err(|e| self.read_err(name, e))
    }

    /// A per-run column files written before it lack (none then).
    fn optional(&self, name: &str) -> Result<Option<Array1<f64>>> {
        if self.f.link_exists(name) {
            self.vec(name).map(Some)
        } else {
            Ok(None)
        }
    }

    /// A per-run value by fifth of the run (run × 5), none where the file lacks it.
    fn by_fifth(&self, name: &str) -> Result<Option<Array2<f64>>> {
        if !self.f.link_exists(name) {
            return Ok(None);
        }
        self.shaped(name, &[self.n, 5])?.read::<f64, ndarray::Ix2>().map(Some).map_err(|e| self.read_err(name, e))
    }

    /// `group/<probe>` for every probe of the model: run × time × (x, y).
    fn probes(&self, model: &Model, group: &str) -> Result<Vec<(String, Array3<f64>)>> {
        let mut probes = Vec::new();
        for name in model.probe_names() {
            let path = format!("{group}/{name}");
            let a = self
                .shaped(&path, &[self.n, self.nt, 2])?
                .read::<f64, ndarray::Ix3>()
                .map_err(|e| self.read_err(&path, e))?;
            probes.push((name, a));
        }
        Ok(probes)
    }

    /// `group/<name>` for each of `names`: run × time; none where the file has no such group.
    fn series(&self, group: &str, names: &[String]) -> Result<Option<NamedRuns>> {
        if names.is_empty() || !self.f.link_exists(group) {
            return Ok(None);
        }
        let series = names.iter().map(|name| {
            let path = format!("{group}/{name}");
            let a = self
                .shaped(&path, &[self.n, self.nt])?
                .read::<f64, ndarray::Ix2>()
                .map_err(|e| self.read_err(&path, e))?;
            Ok((name.clone(), a))
        });
        series.collect::<Result<Vec<_>>>().map(Some)
    }

    /// `group/<quantity>/<probe>` for every probe quantity, none where the file has no such group.
    fn quantities(&self, group: &str, keys: &[(Quantity, &str)]) -> Result<Option<Vec<Array1<f64>>>> {
        if !self.f.link_exists(group) {
            return Ok(None);
        }
        keys.iter()
            .map(|(q, name)| self.vec(&format!("{group}/{}/{name}", q.name())))
            .collect::<Result<Vec<_>>>()
            .map(Some)
    }

    /// The runs: points, status, time, reduced coordinates (`layout` 1 stored them as
    /// (N, r, n_t), newer ones as (N, n_t, r)), probes, section probes, the probe quantities'
    /// estimates and (validated) errors, the full runs' probes and the time loops' seconds.
    fn runs(
        &self,
        model: &Model,
        keys: &[(Quantity, &str)],
        (layout, r): (u64, usize),
        file_full: bool,
        validate: bool,
    ) -> Result<StoredRuns> {
        let (n, nt) = (self.n, self.nt);
        let scales = self.vec("load_scales")?;
        let points = points_of(&self.f, &scales.to_vec()).map_err(|(field, problem)| self.cannot(field, problem))?;
        let status = self.flags("status")?;
        let t = self.shaped("t", &[nt])?.read_1d::<f64>().map_err(|e| self.read_err("t", e))?;
        let zq = if file_full {
            // a full sweep keeps no coordinates
            Array3::zeros((n, 0, nt))
        } else {
            let want = if layout == 1 { [n, r, nt] } else { [n, nt, r] };
            self.shaped("reduced_q", &want)?.read::<f64, ndarray::Ix3>().map_err(|e| self.read_err("reduced_q", e))?
        };
        let zq = if file_full || layout == 1 {
            zq
        } else {
            // back to the runs' r × n_t
            zq.permuted_axes([0, 2, 1]).as_standard_layout().to_owned()
        };
        let probes = self.probes(model, "probes")?;
        // each run's strains and curvatures, the probe quantities' estimates and (validated)
        // errors; files written before them have none, and their points read back without
        let section_names = model.section_names();
        let sections =
            [self.series("probe_strain", &section_names[0])?, self.series("probe_curvature", &section_names[1])?];
        let quantity_estimates = self.quantities("probe_error_estimate", keys)?;
        let quantity_errors = if validate { self.quantities("probe_error", keys)? } else { None };
        // files written before /full_probes hold validations without them: run again
        let full_probes =
            if validate && self.f.link_exists("full_probes") { Some(self.probes(model, "full_probes")?) } else { None };
        // each run's time loop: the reduced one, or a full sweep's full one
        let seconds_name = if file_full { "full_seconds" } else { "rom_seconds" };
        let rom_seconds = self.vec(seconds_name)?;
        Ok(StoredRuns {
            points,
            status,
            t,
            zq,
            probes,
            sections,
            quantity_estimates,
            quantity_errors,
            reaction_estimates: None,
            full_probes,
            rom_seconds,
        })
    }

    /// The per-run columns beside the runs; `validated`: the file has the full runs' probes a
    /// validation needs. Every column is checked to have a value a run, as the time loops'
    /// `n_seconds` values are.
    fn columns(&self, file_full: bool, validate: bool, validated: bool, n_seconds: usize) -> Result<StoredColumns> {
        let n = self.n;
        // the estimate columns of the file (absent in files written before them: no estimate)
        let (estimates, estimate_seconds, extrapolated) = (
            self.optional("error_estimate")?,
            self.optional("estimate_seconds")?,
            if self.f.link_exists("extrapolated") { Some(self.flags("extrapolated")?) } else { None },
        );
        let fallback = self.fallback()?;
        let by_time = self.by_fifth("error_estimate_by_time")?;
        // files written before the displacement measure have neither: NaN
        let (estimates_displacement, displacement_by_time) =
            (self.optional("error_estimate_displacement")?, self.by_fifth("error_estimate_displacement_by_time")?);
        let displacement = if validate { self.optional("displacement_error")? } else { None };
        let rel_by_time = if validate { self.by_fifth("rel_error_by_time")? } else { None };
        let (newton, factorizations) = (self.ints("newton_iterations")?, self.ints("factorizations")?);
        // files written before it have no /steps_differ_from: unknown, as no halved step
        let differ = if validate && self.f.link_exists("steps_differ_from") {
            Some(self.vec("steps_differ_from")?)
        } else {
            None
        };
        if differ.as_ref().is_some_and(|a| a.len() != n) {
            return Err(self
                .cannot("steps_differ_from", format!("has {} entries, expected {n}", differ.map_or(0, |a| a.len()))));
        }
        let validation = if validate && self.f.link_exists("rel_error") && validated {
            Some([
                self.vec("rel_error")?,
                self.vec("max_probe_error")?,
                self.vec("max_constraint_violation")?,
                self.vec("full_seconds")?,
                self.vec("speedup")?,
            ])
        } else {
            None
        };
        let seconds_name = if file_full { "full_seconds" } else { "rom_seconds" };
        let lens = std::iter::once(n_seconds).chain(
            (validation.iter().flatten())
                .chain(estimates.iter())
                .chain(estimate_seconds.iter())
                .chain(estimates_displacement.iter())
                .chain(displacement.iter())
                .map(|a| a.len()),
        );
        for len in lens {
            if len != n {
                return Err(
                    self.cannot(seconds_name, format!("a per-scale dataset has {len} entries for {n} load scales"))
                );
            }
        }
        Ok(StoredColumns {
            estimates,
            estimate_seconds,
            extrapolated,
            fallback,
            by_time,
            estimates_displacement,
            displacement_by_time,
            displacement,
            rel_by_time,
            newton,
            factorizations,
            differ,
            validation,
        })
    }

    /// `/fallback` and its reasons (`/message`) a run; files written before /fallback hold
    /// reduced answers only.
    fn fallback(&self) -> Result<Vec<(u8, String)>> {
        let n = self.n;
        if !self.f.link_exists("fallback") {
            return Ok(vec![(0, String::new()); n]);
        }
        let flags = self.flags("fallback")?;
        let messages = read_strings(&self.shaped("message", &[n])?).map_err(|e| self.read_err("message", e))?;
        if flags.len() != n || messages.len() != n {
            return Err(self.cannot(
                "fallback",
                format!("has {} entries (/message {}) for {n} load scales", flags.len(), messages.len()),
            ));
        }
        Ok(flags.iter().zip(messages).map(|(&x, m)| (x, m)).collect())
    }
}

/// Run `k` of every probe's series (run × time × (x, y)).
fn run_row(probes: &[(String, Array3<f64>)], k: usize) -> Vec<(String, Array2<f64>)> {
    probes.iter().map(|(name, a)| (name.clone(), a.index_axis(ndarray::Axis(0), k).to_owned())).collect()
}

/// A sweep file read back: what turns each of its runs into a finished point.
struct ReadBack<'a> {
    model: &'a Model,
    stored: Option<&'a StoredBasis>,
    r: usize,
    nt: usize,
    keys: &'a [(Quantity, &'a str)],
    reaction_keys: &'a [(Quantity, &'a str)],
    runs: StoredRuns,
    columns: StoredColumns,
    validate: bool,
}

impl ReadBack<'_> {
    /// Run `k`: its parameters and, where it finished with what this sweep writes, the point.
    fn point(&self, k: usize) -> Result<(Parameters, Option<SweepPoint>)> {
        let (model, nt, runs, c) = (self.model, self.nt, &self.runs, &self.columns);
        let mu = runs.points[k].clone();
        // a finished run counts only when it has what this sweep writes
        if runs.status[k] != STATUS_OK || (self.validate && c.validation.is_none()) {
            return Ok((mu, None));
        }
        let settings = Settings::resolve(model, &Overrides::at(&mu))?;
        let stats = Stats {
            steps: settings.n_steps,
            newton_iterations: c.newton[k] as usize,
            factorizations: c.factorizations[k] as usize,
            ..Default::default()
        };
        let section_at = |i: usize| -> crate::simulate::Series {
            runs.sections[i]
                .as_ref()
                .map_or_else(Vec::new, |v| v.iter().map(|(n, a)| (n.clone(), a.row(k).to_owned())).collect())
        };
        let result = SimulationResult {
            model_text: model.text.clone(),
            model_path: model.path.display().to_string(),
            settings,
            t: runs.t.clone(),
            q: Array2::zeros((0, nt)),
            qd: Array2::zeros((0, nt)),
            multipliers: Array2::zeros((0, nt)),
            probes: run_row(&runs.probes, k),
            strains: section_at(0),
            curvatures: section_at(1),
            stats,
            wall_seconds: runs.rom_seconds[k],
            energy: None,
        };
        let estimate = self.estimate(k);
        let extrapolated = c.extrapolated.as_ref().is_some_and(|a| a.get(k).is_some_and(|&v| v != 0));
        let v = self.validation(k, &mu).map(|mut v| {
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
        let (code, message) = &c.fallback[k];
        let reduced_q =
            if *code == 1 { Array2::zeros((0, nt)) } else { runs.zq.index_axis(ndarray::Axis(0), k).to_owned() };
        let run = ReducedRun { result, reduced_q };
        let full_probes = runs.full_probes.as_deref().map(|p| run_row(p, k));
        // a finished point's message: why the full model answered (1), or why it was tried
        // in place of the reduced answer kept and how it failed (2)
        let (fallback, note) = match code {
            1 => (Some(message.clone()), None),
            2 => (None, Some(message.clone())),
            _ => (None, None),
        };
        Ok((mu, Some(SweepPoint { run, validation: v, full_probes, estimate, extrapolated, fallback, note })))
    }

    /// Run `k`'s stored estimate: its value and cost (the factor it was made with is the
    /// basis's); `None` where the file has none for it.
    fn estimate(&self, k: usize) -> Option<Estimate> {
        let c = &self.columns;
        let fifths = |a: &Option<Array2<f64>>| a.as_ref().map_or([f64::NAN; 5], |a| std::array::from_fn(|i| a[[k, i]]));
        c.estimates.as_ref().map(|a| a[k]).filter(|e| !e.is_nan()).map(|error_estimate| Estimate {
            error_estimate,
            raw: f64::NAN,
            factor: f64::NAN,
            calibrated: false,
            seconds: c.estimate_seconds.as_ref().map_or(f64::NAN, |a| a[k]),
            by_time: fifths(&c.by_time),
            error_estimate_displacement: c.estimates_displacement.as_ref().map_or(f64::NAN, |a| a[k]),
            displacement_by_time: fifths(&c.displacement_by_time),
            failure: None,
            quantities: [
                (self.keys, &self.runs.quantity_estimates),
                (self.reaction_keys, &self.runs.reaction_estimates),
            ]
            .into_iter()
            .filter_map(|(keys, cols)| Some(keys.iter().zip(cols.as_ref()?)))
            .flatten()
            .map(|((q, name), c)| QuantityEstimate {
                probe: name.to_string(),
                quantity: *q,
                estimate: c[k],
                raw: f64::NAN,
            })
            .collect(),
        })
    }

    /// Run `k`'s stored validation (a validated reduced sweep's), without its estimate.
    fn validation(&self, k: usize, mu: &Parameters) -> Option<Validation> {
        let c = &self.columns;
        c.validation.as_ref().zip(self.stored).map(|(v, stored)| Validation {
            load_scale: mu.scale(),
            parameters: mu.iter().map(|(n, v)| (n.to_string(), v)).collect(),
            variant: stored.basis.variant.name().to_string(),
            n_dof: stored.basis.n_dof(),
            n_modes: self.r,
            rel_error: v[0][k],
            max_probe_error: v[1][k],
            max_probe_error_probe: String::new(),
            max_probe_error_t: f64::NAN,
            max_constraint_violation: v[2][k],
            full_seconds: v[3][k],
            full_dense_seconds: None,
            rom_seconds: self.runs.rom_seconds[k],
            speedup: v[4][k],
            speedup_vs_dense: None,
            speedup_with_estimate: None,
            full_newton_iterations: 0,
            rom_newton_iterations: c.newton[k] as usize,
            rom_step_cuts: 0,
            full_step_cuts: 0,
            steps_differ_from: c.differ.as_ref().map(|a| a[k]).filter(|t| !t.is_nan()),
            full_step_cut_times: Vec::new(),
            rom_step_cut_times: Vec::new(),
            // the estimate and the flags are set by the caller from the file's columns
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
            rel_error_by_time: c.rel_by_time.as_ref().map_or_else(Vec::new, |a| a.row(k).to_vec()),
            error_estimate_by_time: None,
            displacement_error: c.displacement.as_ref().map_or(f64::NAN, |a| a[k]),
            // the words for a stored NaN or ∞ (a sweep before the column has none to explain)
            displacement_error_note: c.displacement.as_ref().and_then(|a| displacement_note(a[k])).map(str::to_string),
            displacement_error_by_time: Vec::new(),
            error_estimate_displacement: None,
            effectivity_displacement: None,
            error_estimate_displacement_by_time: None,
            max_error_over_travel: None,
            max_error_over_travel_probe: String::new(),
            probe_errors_over_travel: Vec::new(),
            probe_quantity_errors: self.runs.quantity_errors.as_ref().map_or_else(Vec::new, |cols| {
                self.keys.iter().zip(cols).map(|((q, name), c)| ProbeQuantityError::stored(name, *q, c[k])).collect()
            }),
            reaction_errors: Vec::new(),
            error_estimate_method: None,
            estimate_failure: None,
        })
    }
}
