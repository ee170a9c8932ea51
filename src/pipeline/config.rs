//! Pipeline files (`pipelines/*.toml`): which model, how to train, which reduction, which
//! load scales to run and validate. Paths inside are relative to the pipeline file.
//!
//! ```toml
//! model = "../data/models/pendulum.toml"
//! basis = "../data/bases/pendulum.h5"       # default: ../data/bases/<pipeline name>.h5
//! report = "../reports/pendulum"            # default: ../reports/<pipeline name>
//! [train]
//! load_scales = [1.0]                       # or, over a load range (docs/greedy-training.md):
//!                                           # greedy = { range = [0.5, 1.5], tolerance = 1e-3,
//!                                           #            max_runs = 8, candidates = 33,
//!                                           #            measure = "relative" }
//! snapshots = "reference"                   # or "raw" (the thesis)
//! [reduction]                               # with greedy: optional, or partial
//! variant = "galerkin"                      # or "constraint-preserving", "whole-system",
//!                                           # "whole-system-stabilized" (docs/whole-system.md)
//! multiplier_modes = { count = 4 }          # whole-system-stabilized only (default energy 1e-12)
//! modes = { ratio = 0.1 }                   # or { count = 20 }, { energy = 1e-6 }
//! blocks = "bodies"                         # one POD per body (modes = { counts = [..] }
//!                                           # gives each its own); default: one POD
//! hyper = { tolerance = 1e-3 }              # ECSW element sampling; omit for plain Galerkin
//! probe_modes = { tolerance = 1e-3 }        # modes until the probes' strains and curvatures
//!                                           # of the snapshots are reproduced (docs/error-estimate.md)
//! [online]
//! load_scales = "0.5:1.5:21"                # or a list
//! tolerance = 1e-3                          # error estimates above it warn (--strict: exit 4);
//!                                           # default: greedy training's tolerance, if any
//! tolerance_measure = "relative"            # or "displacement" (default: greedy's `measure`)
//! [validate]
//! load_scales = [0.8, 1.0, 1.2]
//! ```

mod scales;
mod schema;

use crate::error::{Error, Result, Text};
use crate::io::output::tidy;
use crate::limits::Limits;
use crate::model::Model;
pub use crate::reduction::estimator::{ErrorMeasure, EstimateMethod};
use crate::reduction::{ModeRule, Variant};
use crate::solver::parameter_space::ParameterSpace;
use crate::solver::parameters::Parameters;
use scales::check_scales;
pub use scales::{parse_range, parse_scales, Scales, MAX_LOAD_SCALES};
pub use schema::{
    Blocks, GreedyMeasure, GreedySpec, HyperSpec, OnlineSpec, ParameterSpec, PipelineFile, PointsSpec, ReductionSpec,
    ScalesSpec, TrainSpec, DEFAULT_BOX_CANDIDATES_PER_PARAMETER, DEFAULT_LINE_CANDIDATES,
};
use std::path::{Component, Path, PathBuf};

/// A loaded, checked pipeline with its model.
#[derive(Clone, Debug)]
pub struct Pipeline {
    pub path: PathBuf,
    pub text: String,
    pub file: PipelineFile,
    pub model: std::sync::Arc<Model>,
    pub basis_path: PathBuf,
    pub report_dir: PathBuf,
}

/// A model file given where a pipeline belongs (`flexrom train model.toml`) is named as such,
/// rather than by the first of its keys a pipeline does not know (`unknown field bodies`).
fn refuse_model_file(text: &str, path: &Path) -> Result<()> {
    let is_model = text.parse::<toml::Table>().is_ok_and(|t| t.contains_key("bodies") && !t.contains_key("model"));
    if is_model {
        return Err(Error::input(
            path,
            "bodies",
            "this is a model file; train, online, validate, sweep and run take a pipeline file that names its model (`model = \"path/to/model.toml\"`, docs/model-format.md \"Pipeline files\"); `flexrom simulate` runs a model file itself",
        ));
    }
    Ok(())
}

impl Pipeline {
    /// [`Pipeline::load_with`] the environment's bounds or the defaults.
    pub fn load(path: impl AsRef<Path>) -> Result<Pipeline> {
        Pipeline::load_with(path, Limits::from_env_or_defaults())
    }

    /// Reads and checks the pipeline file at `path` and its model, which every stage runs
    /// within `limits`.
    pub fn load_with(path: impl AsRef<Path>, limits: Limits) -> Result<Pipeline> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        refuse_model_file(&text, path)?;
        let file: PipelineFile = crate::model::parse_toml(&text, path)?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let model = Model::load_with(tidy(&dir.join(&file.model)), limits).map_err(|e| match e {
            Error::Io { .. } => Error::input(path, "model", format!("cannot read `{}`: {e}", file.model.display())),
            other => other,
        })?;
        Pipeline::of_parts(path, text, file, model)
    }

    /// The pipeline a basis file was trained with, from the pipeline and model texts the
    /// file stores (`pipeline`, `model`, `model_path` attributes): a basis file is enough to
    /// run its reduced model wherever it was moved. Paths the pipeline names (its `basis`,
    /// `report`) are read relative to `path`, the pipeline file's path at training.
    pub fn from_texts(
        path: &Path,
        text: &str,
        model_text: &str,
        model_path: &Path,
        limits: Limits,
    ) -> Result<Pipeline> {
        let file: PipelineFile = crate::model::parse_toml(text, path)?;
        let model = Model::from_text_with(model_text, model_path, limits)?;
        Pipeline::of_parts(path, text.to_string(), file, model)
    }

    fn of_parts(path: &Path, text: String, file: PipelineFile, model: Model) -> Result<Pipeline> {
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let stem = path.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_else(|| "pipeline".into());
        // `pipelines/../data/bases/x.h5` printed as `data/bases/x.h5` (the same file)
        let basis_path =
            tidy(&dir.join(file.basis.clone().unwrap_or_else(|| PathBuf::from(format!("../data/bases/{stem}.h5")))));
        let report = file.report.clone().unwrap_or_else(|| PathBuf::from(format!("../reports/{stem}")));
        // a report of `.` or `..` stays as written: its refusal names it
        let ends_in_dots = matches!(report.components().next_back(), Some(Component::CurDir | Component::ParentDir));
        let report_dir = if ends_in_dots { dir.join(&report) } else { tidy(&dir.join(&report)) };
        let p = Pipeline {
            path: path.to_path_buf(),
            text,
            file,
            model: std::sync::Arc::new(model),
            basis_path,
            report_dir,
        };
        // the checks name fields; the text knows their lines
        p.check().map_err(|e| crate::model::with_field_line(e, &p.path, &p.text))?;
        Ok(p)
    }

    /// The tolerance of the output modes of a basis of this pipeline: `[reduction]
    /// probe_modes`; else, when greedy training holds the probes to its tolerance and a probe
    /// records a strain or a curvature, `√ε` of the rung's POD energy tolerance `ε`
    /// (`rung_energy`), as its ECSW tolerance is: the energy criterion bounds a squared
    /// relative error, the output modes a relative one, and the ladder tightens both until
    /// the scores meet the tolerance (with modes given, no ladder: the greedy tolerance).
    pub fn probe_mode_tolerance(&self, rung_energy: Option<f64>) -> Option<f64> {
        if let Some(m) = &self.file.reduction.probe_modes {
            return Some(m.tolerance);
        }
        let greedy = self.file.train.greedy.as_ref().filter(|g| g.measure.probes())?;
        // the whole-system variants pair each mode with multiplier modes: no output modes there
        let quantities = self.model.probes().iter().any(|p| p.strain || p.curvature)
            && !matches!(self.variant(), Variant::WholeSystem | Variant::WholeSystemStabilized);
        rung_energy.filter(|_| quantities).map(|e| if e.is_finite() { e.sqrt() } else { greedy.tolerance })
    }

    /// `[reduction] probe_modes`: a tolerance in (0, 1), a variant that has blocks of modes,
    /// and a probe that records what the modes are for.
    fn check_probe_modes(&self, tolerance: f64) -> Result<()> {
        if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1.0) {
            return Err(Error::usage(format!("has tolerance {tolerance}; it must lie strictly between 0 and 1")));
        }
        if matches!(self.variant(), Variant::WholeSystem | Variant::WholeSystemStabilized) {
            return Err(Error::usage(format!(
                "needs the galerkin or the constraint-preserving variant, not {}",
                self.variant().name()
            )));
        }
        if !self.model.probes().iter().any(|p| p.strain || p.curvature) {
            return Err(Error::usage("is set, but no probe of the model records a strain or a curvature (`quantities = [\"strain\", \"curvature\"]` in a [[probes]] entry)"));
        }
        Ok(())
    }

    fn check(&self) -> Result<()> {
        let bad = |field: &str, problem: String| Err(Error::input(&self.path, field, problem));
        let red = &self.file.reduction;
        self.check_parameters()?;
        match (&self.file.train.load_scales, &self.file.train.greedy) {
            // checked with [parameters]
            _ if self.file.train.points.is_some() => {}
            (Some(_), Some(_)) => return bad("train", "has both load_scales and greedy; give exactly one".into()),
            (None, None) => {
                return bad(
                    "train",
                    "needs load_scales = [..], greedy = { range = [A, B], tolerance = T, max_runs = K }, or points = { count = N } with [parameters]".into(),
                )
            }
            (Some(s), None) => {
                if let Err(e) = check_scales(s) {
                    return bad("train.load_scales", e.problem());
                }
                if red.modes.is_none() {
                    return bad("reduction.modes", "is missing: with train.load_scales the mode count must be given (or train greedily, which chooses it)".into());
                }
            }
            (None, Some(g)) => {
                if let Err((f, p)) = g.validate(!self.file.parameters.is_empty()) {
                    return bad(&f, p);
                }
            }
        }
        let t = &self.file.train;
        if self.file.parameters.is_empty() {
            // a line of load scales trains over λ, which must move some load
            let varies = t.greedy.is_some() || t.load_scales.as_ref().is_some_and(|s| s.iter().any(|&x| x != 1.0));
            if let Some(why) = self.model.unscaled_load_scale().filter(|_| varies) {
                let field = if t.greedy.is_some() { "train.greedy.range" } else { "train.load_scales" };
                let problem = Text::new("trains over load scales, but ")
                    .append(why)
                    .then("; a [parameters] box trains over named parameters");
                return Err(Error::input(&self.path, field, problem));
            }
        }
        if let Err(e) = red.modes.as_ref().map_or(Ok(()), |m| m.validate()) {
            return bad("reduction.modes", e.problem());
        }
        match (&red.modes, self.blocks()) {
            (Some(ModeRule::Counts(_)), None) => {
                return bad(
                    "reduction.modes",
                    "gives one count per block, but there are no blocks (set reduction.blocks = \"bodies\")".into(),
                )
            }
            (Some(ModeRule::Counts(c)), Some(Blocks::Bodies)) if c.len() != self.model.file.bodies.len() => {
                return bad(
                    "reduction.modes",
                    format!("gives {} counts, the model has {} bodies", c.len(), self.model.file.bodies.len()),
                )
            }
            _ => {}
        }
        if self.has_drives() && self.variant() != Variant::ConstraintPreserving {
            return bad(
                "reduction.variant",
                format!(
                    "is {}, but the model prescribes motions (driven_angle or driven_point joints), whose rows move \
                     with time: only the constraint-preserving variant keeps them exact",
                    self.variant().name()
                ),
            );
        }
        if self.blocks().is_some() && matches!(self.variant(), Variant::WholeSystem | Variant::WholeSystemStabilized) {
            return bad(
                "reduction.blocks",
                format!("needs the galerkin or the constraint-preserving variant, not {}", self.variant().name()),
            );
        }
        if let Some(m) = &self.file.reduction.multiplier_modes {
            if self.variant() != Variant::WholeSystemStabilized {
                return bad(
                    "reduction.multiplier_modes",
                    format!("applies to the whole-system-stabilized variant only, not {}", self.variant().name()),
                );
            }
            if let Err(e) = m.validate().and(if matches!(m, ModeRule::Counts(_)) {
                Err(Error::usage("gives counts per block; use count, ratio or energy"))
            } else {
                Ok(())
            }) {
                return bad("reduction.multiplier_modes", e.problem());
            }
        }
        if let Some(h) = &self.file.reduction.hyper {
            if !(h.tolerance.is_finite() && h.tolerance > 0.0 && h.tolerance < 1.0) {
                return bad(
                    "reduction.hyper.tolerance",
                    format!("is {}; it must lie strictly between 0 and 1", h.tolerance),
                );
            }
        }
        if self.file.train.greedy.as_ref().is_some_and(|g| g.measure.probes()) && self.model.probes().is_empty() {
            return bad(
                "train.greedy.measure",
                "is \"probes\", but the model has no [[probes]] entry to hold to the tolerance".into(),
            );
        }
        if let Some(m) = &self.file.reduction.probe_modes {
            self.check_probe_modes(m.tolerance)
                .map_err(|e| Error::input(&self.path, "reduction.probe_modes", e.problem()))?;
        }
        for (name, scales) in [
            ("online", self.file.online.as_ref().and_then(|o| o.load_scales.as_ref())),
            ("validate", self.file.validate.as_ref().map(|v| &v.load_scales)),
        ] {
            if let Some(s) = scales {
                if let Err(e) = s.values() {
                    return bad(&format!("{name}.load_scales"), e);
                }
                if !self.file.parameters.is_empty() {
                    // a box's runs are points of it: a list of λ would be silently left out
                    return bad(
                        &format!("{name}.load_scales"),
                        "lists load scales, but the pipeline has a [parameters] box: `run` and `validate` use random points of the box; sweep chosen points with `flexrom sweep --param NAME=A:B:N` or `--points FILE.csv`, validate one with `flexrom validate --param NAME=X`".into(),
                    );
                }
            }
        }
        if let Some(t) = self.online_tolerance() {
            if !(t.is_finite() && t > 0.0) {
                return bad("online.tolerance", format!("is {t}; it must be positive and finite"));
            }
        }
        if let Some(m) = self.file.online.as_ref().filter(|o| o.tolerance.is_none()).and_then(|o| o.tolerance_measure) {
            return bad(
                "online.tolerance_measure",
                format!(
                    "is \"{}\" but there is no online.tolerance for it to apply to (the training tolerance keeps the measure training used)",
                    m.name()
                ),
            );
        }
        Ok(())
    }

    /// Warnings for a `[parameters]` range of a body's property that lies, both ends on one
    /// side, farther than [`crate::model::FACTOR_LIKE`] from the model file's value: most
    /// often factors meant (`E = [0.5, 2.0]`) for a parameter that is the value itself.
    pub fn property_warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (name, spec) in &self.file.parameters {
            let Some(file) = self.model.property_value(name) else { continue };
            let r = spec.range(name);
            let (lo, hi) = (r.lower / file, r.upper / file);
            if crate::model::far_from(lo) && crate::model::far_from(hi) && (hi < 1.0) == (lo < 1.0) {
                let given = format!("[{}, {}]", crate::error::show_number(r.lower), crate::error::show_number(r.upper));
                out.push(format!("{} (parameters.{name})", self.model.factor_like(name, &given, file)));
            }
        }
        out
    }

    /// `[parameters]` against the model and `[train]`: every name one of the model's
    /// parameters, every range one a sample can be drawn from, and training that samples the
    /// box (`points`) exactly when there is one.
    fn check_parameters(&self) -> Result<()> {
        let bad = |field: &str, problem: String| Err(Error::input(&self.path, field, problem));
        for (name, spec) in &self.file.parameters {
            let field = format!("parameters.{name}");
            if let Some(problem) = self.model.unknown_parameter(name) {
                return bad(&field, problem);
            }
            let range = spec.range(name);
            if let Err(e) = range.validate() {
                return bad(&field, e.problem());
            }
            if let Some(what) = self.model.property_parameter(name).filter(|_| !(range.lower > 0.0)) {
                return bad(
                    &field,
                    format!("is a {what}; its range must be positive, got {} … {}", range.lower, range.upper),
                );
            }
        }
        let t = &self.file.train;
        match (&t.points, self.file.parameters.is_empty()) {
            (Some(_), true) => bad("train.points", "samples the [parameters] box, but the pipeline has no [parameters] table (add e.g. `[parameters]` with `drive = [0.5, 1.5]`)".into()),
            (Some(pts), false) => {
                if t.load_scales.is_some() || t.greedy.is_some() {
                    return bad("train", "has points and load_scales or greedy; give exactly one".into());
                }
                if pts.count == 0 || pts.count > MAX_LOAD_SCALES {
                    return bad("train.points.count", format!("is {}; it must lie in 1..={MAX_LOAD_SCALES}", pts.count));
                }
                let sobol = pts.sampling == crate::solver::parameter_space::Sampling::Sobol;
                if sobol && pts.count > crate::solver::parameter_space::MAX_SOBOL_POINTS {
                    return bad(
                        "train.points.count",
                        format!("is {}; Sobol points go up to {} (use sampling = \"lhs\" for more)", pts.count, crate::solver::parameter_space::MAX_SOBOL_POINTS),
                    );
                }
                if sobol && pts.seed > u64::from(u32::MAX) {
                    return bad("train.points.seed", format!("is {}; a Sobol seed lies in 0..={}", pts.seed, u32::MAX));
                }
                if self.file.reduction.modes.is_none() {
                    return bad("reduction.modes", "is missing: with train.points the mode count must be given".into());
                }
                Ok(())
            }
            (None, false) if t.greedy.is_some() => Ok(()),
            (None, false) => bad(
                "train",
                "trains over the load scale alone, but the pipeline has a [parameters] box: train greedily over it with `greedy = { tolerance = T, max_runs = K }`, or sample it with `points = { count = N }`".into(),
            ),
            (None, true) => Ok(()),
        }
    }

    /// Where `validate` and a report check a basis when no load is given: `[validate]
    /// load_scales`, or for a `[parameters]` box four points drawn at random from it (seed:
    /// the training points' plus one), which are not training points.
    pub fn validation_points(&self) -> Vec<Parameters> {
        if self.file.parameters.is_empty() {
            return self.validate_scales().into_iter().map(Parameters::load_scale).collect();
        }
        self.space().sample(4, crate::solver::parameter_space::Sampling::Random, self.box_seed().wrapping_add(1))
    }

    /// The points `validate` runs at, given a load scale (`load_scale`) and whether named
    /// parameters were given (`named`, `sets_load_scale`: one of them is `load_scale`):
    /// the one point `at(load_scale)` where a load scale is given, or named values in a box
    /// or with their own load scale; the named values at each `[validate]` load scale on a
    /// line (`at(Some(x))`); nothing given, [`Self::validation_points`]. `at` builds a
    /// point from a load scale and the caller's named values (the command line's
    /// `--param`, Python's keywords).
    pub fn validation_points_given<E>(
        &self,
        load_scale: Option<f64>,
        (named, sets_load_scale): (bool, bool),
        at: impl Fn(Option<f64>) -> std::result::Result<Parameters, E>,
    ) -> std::result::Result<Vec<Parameters>, E> {
        match (load_scale, named) {
            (Some(_), _) => Ok(vec![at(load_scale)?]),
            (None, false) => Ok(self.validation_points()),
            (None, true) if !self.space().is_empty() || sets_load_scale => Ok(vec![at(None)?]),
            (None, true) => self.validate_scales().into_iter().map(|x| at(Some(x))).collect(),
        }
    }

    /// Where `run` sweeps: `[online] load_scales` (or the training scales), or for a
    /// `[parameters]` box sixteen points drawn at random from it (seed: the training
    /// points' plus two), neither training nor `validate`'s points.
    pub fn online_points(&self) -> Vec<Parameters> {
        if self.file.parameters.is_empty() {
            return self.online_scales().into_iter().map(Parameters::load_scale).collect();
        }
        self.space().sample(16, crate::solver::parameter_space::Sampling::Random, self.box_seed().wrapping_add(2))
    }

    /// The seed a box's points are drawn with: `train.points`' or greedy's (default 1).
    fn box_seed(&self) -> u64 {
        let t = &self.file.train;
        t.points.as_ref().map(|p| p.seed).or(t.greedy.as_ref().and_then(|g| g.seed)).unwrap_or(1)
    }

    /// The box of `[parameters]`, in name order (empty without the table).
    pub fn space(&self) -> ParameterSpace {
        ParameterSpace { ranges: self.file.parameters.iter().map(|(n, s)| s.range(n)).collect() }
    }

    /// The training points of `train.points`, drawn from the box (empty without them).
    pub fn training_points(&self) -> Vec<Parameters> {
        self.file.train.points.as_ref().map_or_else(Vec::new, |p| self.space().sample(p.count, p.sampling, p.seed))
    }

    /// The reduction variant: the file's, or constraint-preserving when the model has
    /// joints between bodies or prescribed motions, galerkin when it has none or only
    /// ground joints.
    pub fn variant(&self) -> Variant {
        let joints = self.model.joints();
        let keeps_joints = joints.iter().any(|j| j.kind().couples_bodies() || j.kind().drive_scaling().is_some());
        self.file.reduction.variant.unwrap_or(if keeps_joints {
            Variant::ConstraintPreserving
        } else {
            Variant::Galerkin
        })
    }

    /// Whether the model prescribes a motion (a driven joint).
    fn has_drives(&self) -> bool {
        self.model.joints().iter().any(|j| j.kind().drive_scaling().is_some())
    }

    /// The block split: the file's; with `train.greedy` and none given, one block per body
    /// when the model has several bodies (each body's modes then move that body only).
    pub fn blocks(&self) -> Option<Blocks> {
        let multi_body = self.model.file.bodies.len() > 1
            && !matches!(self.variant(), Variant::WholeSystem | Variant::WholeSystemStabilized);
        self.file.reduction.blocks.or(if self.file.train.greedy.is_some() && multi_body {
            Some(Blocks::Bodies)
        } else {
            None
        })
    }

    /// The given training loads, or for greedy training the ends and middle of its range
    /// (what `online` and `validate` default to without their own lists).
    pub fn training_scales(&self) -> Vec<f64> {
        match (&self.file.train.load_scales, &self.file.train.greedy) {
            (Some(s), _) => s.clone(),
            (None, Some(g)) if g.range.len() == 2 => {
                let (a, b) = g.range();
                vec![a, 0.5 * (a + b), b]
            }
            // a box: λ is what the model file gives unless the box holds it
            (None, Some(_)) => vec![1.0],
            (None, None) => Vec::new(),
        }
    }

    /// `[online] load_scales`, or the training scales without them.
    pub fn online_scales(&self) -> Vec<f64> {
        let given = self.file.online.as_ref().and_then(|o| o.load_scales.as_ref());
        given.map_or_else(|| self.training_scales(), |s| s.values().expect("checked"))
    }

    /// `[online] tolerance`, when given.
    pub fn online_tolerance(&self) -> Option<f64> {
        self.file.online.as_ref().and_then(|o| o.tolerance)
    }

    /// `[online] fallback`, when given.
    pub fn online_fallback(&self) -> Option<crate::pipeline::fallback::Fallback> {
        self.file.online.as_ref().and_then(|o| o.fallback)
    }

    /// `[online] tolerance_measure`, when given (only with `[online] tolerance`).
    pub fn online_tolerance_measure(&self) -> Option<ErrorMeasure> {
        self.file.online.as_ref().and_then(|o| o.tolerance_measure)
    }

    /// `[validate] load_scales` (`run`'s validation, and `validate` without `--load-scale`),
    /// or the training scales without them.
    pub fn validate_scales(&self) -> Vec<f64> {
        self.file.validate.as_ref().map_or_else(|| self.training_scales(), |s| s.load_scales.values().expect("checked"))
    }

    /// The hash of the `[train]` and `[reduction]` settings a basis file records
    /// ([`crate::io::basis_hash::settings_hash`]): a basis trained with other settings is
    /// flagged as stale.
    pub fn settings_hash(&self) -> String {
        let mut train = self.file.train.clone();
        // a box's default candidate count is its own (32 per parameter), not the line's 33
        // that an absent `candidates` hashes as
        if let Some(g) = train.greedy.as_mut().filter(|_| !self.file.parameters.is_empty()) {
            g.candidates.get_or_insert(DEFAULT_BOX_CANDIDATES_PER_PARAMETER * self.file.parameters.len());
        }
        crate::io::basis_hash::settings_hash(&train, &self.file.reduction, &self.file.parameters)
    }
}
