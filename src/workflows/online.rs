//! `online`: load a basis, check it against the pipeline, and build its reduced model.

use crate::error::{Error, Result};
use crate::io::basis_file::StoredBasis;
use crate::io::h5::{attr_str, attr_u64, read_attr_str};
use crate::io::result_file::{begin_alongside, RunPlan};
use crate::pipeline::config::Pipeline;
use crate::pipeline::fallback::{settle, Fallback};
use crate::rom::estimator::{Estimate, EstimateMethod};
use crate::rom::trust::write_run_attributes;
use crate::rom::warnings::Answered;
use crate::rom::{check_reduced_memory, settings_at, LoadOptions, Output, ReducedRun, Rom, Trust};
use crate::solver::model::Parameters;
use std::path::Path;

/// Reads the pipeline's basis (or `path`) and checks it against the pipeline's model and
/// settings ([`crate::io::basis_check::check`]).
pub fn load_basis(p: &Pipeline, path: &Path) -> Result<StoredBasis> {
    crate::io::basis_check::check(path, &p.model, Some(&p.settings_hash()))
}

/// The pipeline a basis file was trained with, rebuilt from the pipeline and model texts
/// the file stores ([`Pipeline::from_texts`]; messages about it name the basis file).
pub fn pipeline_of_basis(path: &Path, limits: crate::limits::Limits) -> Result<Pipeline> {
    if !path.is_file() {
        return Err(Error::input(path, "(file)", "does not exist; run `flexrom train` first"));
    }
    let file =
        crate::io::h5_open::open(path).map_err(|e| Error::input(path, "(file)", crate::io::h5_open::unreadable(&e)))?;
    let text = |name: &str| {
        read_attr_str(&file, name).map_err(|e| {
            Error::input(path, name, format!("cannot be read ({e}); is this a basis file of `flexrom train`?"))
        })
    };
    let (pipeline, model, model_path) = (text("pipeline")?, text("model")?, text("model_path")?);
    drop(file);
    Pipeline::from_texts(path, &pipeline, &model, Path::new(&model_path), limits)
}

/// Reads and checks the basis file at `path` and builds its reduced model with the error
/// estimator by `method` (else the pipeline's `[online] estimate`, else the one the basis
/// file names; none with `no_estimate`), held to the pipeline's `[online] tolerance` (else
/// the training tolerance) in its measure. Returns the warnings a user should see.
pub fn load_rom(
    p: &Pipeline,
    path: &Path,
    method: Option<EstimateMethod>,
    no_estimate: bool,
) -> Result<(StoredBasis, Rom, Vec<String>)> {
    let stored = load_basis(p, path)?;
    let o = LoadOptions {
        method: method.or_else(|| p.file.online.as_ref().and_then(|o| o.estimate)),
        tolerance: p.online_tolerance(),
        tolerance_measure: p.online_tolerance_measure(),
        no_estimate,
    };
    let (rom, more) = Rom::load(&p.model, path, &stored, o)?;
    let trained = rom.trust().map(|t| t.space.clone()).unwrap_or_default();
    if trained != p.space() {
        let show = |s: &crate::solver::parameter_space::ParameterSpace| {
            if s.is_empty() {
                "the load scale alone".to_string()
            } else {
                s.ranges
                    .iter()
                    .map(|r| format!("{} [{}, {}] {}", r.name, r.lower, r.upper, r.spacing.name()))
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        };
        return Err(Error::input(
            path,
            "parameters",
            format!(
                "the basis was trained over {}, the pipeline {} names {}; run `flexrom train` for this pipeline",
                show(&trained),
                p.path.display(),
                show(&p.space())
            ),
        ));
    }
    let mut warnings = stored.warnings.clone();
    warnings.extend(more);
    // what training said beside meeting its tolerance, once per command (of the online
    // default's readings only where the runs read it)
    for (name, note) in &stored.training.notes {
        if *name != "estimate_note" || rom.method() == Some(EstimateMethod::Defects.name()) {
            warnings.push(format!("{}: greedy training: {note}", path.display()));
        }
    }
    Ok((stored, rom, warnings))
}

/// What `online` produced: the run, its estimate and whether it left the training range.
pub struct OnlineRun {
    /// the reduced run, or with `fallback` the full one (no reduced coordinates)
    pub run: ReducedRun,
    pub estimate: Option<Estimate>,
    pub extrapolated: bool,
    /// `Some(why)`: the full model answered in place of the reduced one (`--fallback full`)
    pub fallback: Option<String>,
    /// the full model was run in place of this reduced answer and failed
    pub note: Option<String>,
}

impl OnlineRun {
    /// The warnings after this answer at `mu`, as the command line and Python say them:
    /// [`Rom::warnings_after`], then the note of a full run tried in its place that failed.
    /// The full model's answer is exact: nothing to warn about. With `strict`, an estimate
    /// above the tolerance is the [`crate::Error::Strict`] carrying the others.
    pub fn warnings(&self, rom: &Rom, mu: &Parameters, strict: bool) -> Result<Vec<String>> {
        if self.fallback.is_some() {
            return Ok(Vec::new());
        }
        let note = self.note.iter().cloned();
        match rom.warnings_after(&[Answered::new(rom, mu, self.estimate.as_ref())], strict) {
            Ok(w) => Ok(w.into_iter().chain(note).collect()),
            Err(Error::Strict { message, warnings }) => {
                Err(Error::Strict { message, warnings: warnings.into_iter().chain(note).collect() })
            }
            Err(e) => Err(e),
        }
    }
}

/// The answer of `online` at `mu`: the reduced run with its estimate, or with
/// [`Fallback::Full`], where the reduced answer cannot be trusted
/// ([`crate::pipeline::fallback::settle`]), the full model's run in its place (no
/// reduced coordinates, the estimate of an exact answer); where the full run fails too, the
/// reduced answer with a note, or both failures when the reduced run had failed.
pub fn answer(rom: &Rom, mu: &Parameters, fallback: Fallback) -> Result<OnlineRun> {
    let reduced = rom.solve_and_estimate(mu, Output::Full, &[]);
    // the way on after a failed reduced run is said unless the fallback takes it
    let reduced = reduced.map_err(|e| match fallback {
        Fallback::None => e.at_reduced_stage("online", mu, false),
        Fallback::Full => e.at_stage("online (reduced run)", mu),
    });
    // the full run as `simulate` makes it: the result file holds its coordinates
    let full = || {
        let r = crate::simulate::simulate(rom.model(), &crate::simulate::Overrides::at(mu))
            .map_err(|e| e.at_stage("online (full run)", mu))?;
        let nt = r.t.len();
        Ok(ReducedRun { result: r, reduced_q: ndarray::Array2::zeros((0, nt)) })
    };
    let s = settle(reduced, fallback, rom.trust(), mu, full)?;
    // the energies of the answer, after its run (its wall time without them): the full
    // model's as `simulate` computes them, a reduced run's over its own sampled elements
    let ReducedRun { result, reduced_q } = s.run;
    let result = match s.fallback {
        Some(_) => crate::simulate::with_energies(rom.model(), result)?,
        None => crate::simulate::with_reduced_energies(rom.model(), result, rom.basis().hyper.as_ref())?,
    };
    let run = ReducedRun { result, reduced_q };
    // where the load lies against the basis's range, whichever model answered
    let extrapolated = rom.is_extrapolated(mu);
    Ok(OnlineRun { run, estimate: s.estimate, extrapolated, fallback: s.fallback, note: s.note })
}

/// Runs `rom` at `mu` and writes the result file `out` ([`crate::io::result_file`]: its
/// fixed part on a second thread while the run computes, the file renamed into place only
/// when complete) with the reduced coordinates, the basis it came from (`basis_path`) and
/// the estimate's attributes ([`crate::rom::trust::write_run_attributes`]). With
/// [`Fallback::Full`], where the reduced answer cannot be trusted
/// ([`crate::pipeline::fallback::settle`]) the full
/// model runs and the file is its result (as `simulate` writes it) with the attribute
/// `fallback` (why), the basis, and the estimate's attributes of an exact answer (0);
/// where the full run fails too, a reduced answer stands with the attribute
/// `fallback_failed`. With `paraview`, the file also holds ParaView's datasets and an
/// XDMF file is written beside it ([`crate::io::paraview`]).
pub fn online_to_file(
    p: &Pipeline,
    rom: &Rom,
    basis_path: &Path,
    mu: &Parameters,
    out: &Path,
    fallback: Fallback,
    paraview: bool,
) -> Result<OnlineRun> {
    // a run too large for the memory bound is refused before the file is begun
    let settings = settings_at(&p.model, mu)?;
    check_reduced_memory(&p.model, rom.basis().n_reduced(), settings.n_steps, Output::Full, 1.0)?;
    if fallback == Fallback::Full {
        p.model.check_full_run_memory(settings.n_steps, false)?;
    }
    let plan = RunPlan::of(&p.model, &settings);
    let model_path = p.model.path.display().to_string();
    let (file, done) = begin_alongside(out, &p.model.text, &model_path, &plan, || answer(rom, mu, fallback))?;
    let basis = rom.basis();
    // absolute, so that the file names its basis wherever it is read from
    let basis_name = crate::io::output::resolve(basis_path).display().to_string();
    let trust = rom.trust().cloned().unwrap_or_else(|| Trust::range((f64::NAN, f64::NAN)));
    let (run, estimate) = (&done.run, done.estimate.as_ref());
    let mut layout = None;
    file.finish(&run.result, |f| {
        let e = |err: hdf5::Error| Error::hdf5(out, err);
        if paraview {
            layout = Some(crate::io::paraview::extra(f, out, p.model.bodies(), &run.result)?);
        }
        attr_str(f, "basis", &basis_name).map_err(e)?;
        if let Some(why) = &done.fallback {
            attr_str(f, "fallback", why).map_err(e)?;
        } else {
            crate::io::result_file::write_reduced(f, &run.reduced_q).map_err(e)?;
            attr_str(f, "variant", basis.variant.name()).map_err(e)?;
            attr_u64(f, "n_modes", basis.n_reduced() as u64).map_err(e)?;
        }
        if let Some(note) = &done.note {
            attr_str(f, "fallback_failed", note).map_err(e)?;
        }
        // the full model's answer has no estimate method: it is exact
        let method = if done.fallback.is_some() { None } else { rom.method() };
        write_run_attributes(f, estimate, method, &trust, mu, done.extrapolated).map_err(e)
    })?;
    if let Some(layout) = layout {
        crate::io::paraview::write_xdmf(out, &layout)?;
    }
    Ok(done)
}
