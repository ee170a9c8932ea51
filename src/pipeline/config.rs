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
//!                                           #            max_runs = 8, candidates = 33 }
//! snapshots = "reference"                   # or "raw" (the thesis)
//! [reduction]                               # with greedy: optional, or partial
//! variant = "galerkin"                      # or "constraint-preserving", "whole-system",
//!                                           # "whole-system-stabilized" (docs/whole-system.md)
//! multiplier_modes = { count = 4 }          # whole-system-stabilized only (default energy 1e-12)
//! modes = { ratio = 0.1 }                   # or { count = 20 }, { energy = 1e-6 }
//! blocks = "bodies"                         # one POD per body (modes = { counts = [..] }
//!                                           # gives each its own); default: one POD
//! hyper = { tolerance = 1e-3 }              # ECSW element sampling; omit for plain Galerkin
//! [online]
//! load_scales = "0.5:1.5:21"                # or a list
//! tolerance = 1e-3                          # error estimates above it warn (--strict: exit 4);
//!                                           # default: greedy training's tolerance, if any
//! [validate]
//! load_scales = [0.8, 1.0, 1.2]
//! ```

use crate::error::{Error, Result};
use crate::model::Model;
pub use crate::reduction::estimator::EstimateMethod;
use crate::reduction::{ModeRule, SnapshotKind, Variant};
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PipelineFile {
    #[serde(default)]
    pub description: String,
    pub model: PathBuf,
    #[serde(default)]
    pub basis: Option<PathBuf>,
    #[serde(default)]
    pub report: Option<PathBuf>,
    pub train: TrainSpec,
    /// may be omitted or partial with `train.greedy` (the rest is chosen by the greedy loop)
    #[serde(default)]
    pub reduction: ReductionSpec,
    #[serde(default)]
    pub online: Option<OnlineSpec>,
    #[serde(default)]
    pub validate: Option<ScalesSpec>,
}

#[derive(Clone, Debug, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct TrainSpec {
    /// the training loads; exactly one of `load_scales` and `greedy`
    #[serde(default)]
    pub load_scales: Option<Vec<f64>>,
    /// greedy training over a load range (src/pipeline/greedy.rs)
    #[serde(default)]
    pub greedy: Option<GreedySpec>,
    #[serde(default = "default_snapshots")]
    pub snapshots: SnapshotKind,
}

fn default_snapshots() -> SnapshotKind {
    SnapshotKind::Reference
}

/// `[train] greedy = { range = [A, B], tolerance = T, max_runs = K, candidates = N }`:
/// full runs where the error estimate over N evenly spaced loads of [A, B] is worst, until
/// every estimate is ≤ T or K full runs were made.
#[derive(Clone, Debug, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct GreedySpec {
    pub range: Vec<f64>,
    pub tolerance: f64,
    pub max_runs: usize,
    #[serde(default = "default_candidates")]
    pub candidates: usize,
}

fn default_candidates() -> usize {
    33
}

impl GreedySpec {
    /// `Err((field, problem))` with the field under `train.greedy`.
    pub fn validate(&self) -> std::result::Result<(), (String, String)> {
        let bad = |f: &str, p: String| Err((format!("train.greedy.{f}"), p));
        match self.range[..] {
            [a, b] if !(a.is_finite() && b.is_finite()) => {
                return bad("range", format!("[{a}, {b}] must be two finite numbers"))
            }
            [a, b] if a >= b => return bad("range", format!("[{a}, {b}]: the first end must be less than the second")),
            [_, _] => {}
            _ => return bad("range", format!("has {} entries; it must be [A, B] with A < B", self.range.len())),
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return bad(
                "tolerance",
                format!("is {}; it must be positive and finite (a relative error, e.g. 1e-3)", self.tolerance),
            );
        }
        if self.max_runs == 0 {
            return bad("max_runs", "is 0; at least one full run is needed".into());
        }
        if self.candidates < 2 {
            return bad("candidates", format!("is {}; at least 2 (the range ends) are needed", self.candidates));
        }
        Ok(())
    }

    /// `(A, B)`; call after [`Self::validate`].
    pub fn range(&self) -> (f64, f64) {
        (self.range[0], self.range[1])
    }

    /// The N evenly spaced candidate loads `A + (B − A) i/(N − 1)`.
    pub fn candidate_loads(&self) -> Vec<f64> {
        let (a, b) = self.range();
        let n = self.candidates;
        // rounded to 12 significant digits: 0.7 + 0.5 · 19/20 prints as 1.175, not 1.1749999999999998
        let round = |x: f64| {
            if x == 0.0 {
                x
            } else {
                let k = 10f64.powi(11 - x.abs().log10().floor() as i32);
                (x * k).round() / k
            }
        };
        (0..n).map(|i| if i + 1 == n { b } else { round(a + (b - a) * i as f64 / (n - 1) as f64) }).collect()
    }
}

#[derive(Clone, Debug, Default, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ReductionSpec {
    /// default: constraint-preserving when the model has joints that the basis cannot
    /// hold by itself, galerkin otherwise (see `Pipeline::variant`)
    #[serde(default)]
    pub variant: Option<Variant>,
    /// required with `train.load_scales`; with `train.greedy`, absent: chosen by the loop
    #[serde(default)]
    pub modes: Option<ModeRule>,
    /// `"bodies"`: a block basis, one POD per body (`modes` applies to each body, or
    /// `counts` gives each its own); absent: one POD of all coordinates (with
    /// `train.greedy`, absent: "bodies" when the model has more than one body)
    #[serde(default)]
    pub blocks: Option<Blocks>,
    /// hyper-reduction by ECSW; absent: every element is evaluated (plain Galerkin)
    #[serde(default)]
    pub hyper: Option<HyperSpec>,
    /// whole-system-stabilized only: how many multiplier modes (a ratio is of the joint
    /// equations' count); absent: `whole_system::DEFAULT_MULTIPLIER_MODES`
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub multiplier_modes: Option<ModeRule>,
}

/// How the coordinates are split into blocks with a POD each.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Blocks {
    /// one block per body: each mode moves one body only
    Bodies,
}

/// `[reduction.hyper]`: ECSW element sampling trained to a relative tolerance τ on the
/// training snapshots (‖C w − b‖ ≤ τ ‖b‖; smaller τ: more elements, closer to Galerkin).
#[derive(Clone, Debug, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct HyperSpec {
    pub tolerance: f64,
}

/// `[online]`: the load scales of `sweep` and `run`, and the tolerance every reduced run's
/// error estimate is held to (a warning, or exit code 4 with `--strict`, above it).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OnlineSpec {
    pub load_scales: Scales,
    #[serde(default)]
    pub tolerance: Option<f64>,
    /// how every reduced run computes its error estimate: "corrected" (default) or
    /// "enriched" (docs/error-estimate.md)
    #[serde(default)]
    pub estimate: Option<EstimateMethod>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScalesSpec {
    pub load_scales: Scales,
}

/// A list of load scales, or `"A:B:N"`: N evenly spaced values from A to B.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum Scales {
    List(Vec<f64>),
    Range(String),
}

impl Scales {
    pub fn values(&self) -> std::result::Result<Vec<f64>, String> {
        let v = match self {
            Scales::List(v) => v.clone(),
            Scales::Range(s) => parse_range(s)?,
        };
        check_scales(&v)?;
        Ok(v)
    }
}

/// The most load scales one range may list (each is a reduced run whose trajectory is kept
/// until the sweep file is written; the memory check in `sweep` bounds them further).
pub const MAX_LOAD_SCALES: usize = 1_000_000;

/// `"A:B:N"` → N evenly spaced values from A to B (N ≥ 1; N = 1 gives A).
pub fn parse_range(s: &str) -> std::result::Result<Vec<f64>, String> {
    let parts: Vec<&str> = s.split(':').collect();
    if parts.len() != 3 {
        return Err(format!("`{s}` is not of the form A:B:N"));
    }
    let num = |p: &str| p.trim().parse::<f64>().map_err(|_| format!("`{p}` in `{s}` is not a number"));
    let (a, b) = (num(parts[0])?, num(parts[1])?);
    let n: usize = parts[2].trim().parse().map_err(|_| format!("`{}` in `{s}` is not a whole number", parts[2]))?;
    if n == 0 {
        return Err(format!("`{s}` asks for no load scales (N = 0)"));
    }
    if n > MAX_LOAD_SCALES {
        return Err(format!("`{s}` asks for {n} load scales, more than the {MAX_LOAD_SCALES} one sweep takes; split the range into several sweeps"));
    }
    let v = if n == 1 { vec![a] } else { (0..n).map(|i| a + (b - a) * i as f64 / (n - 1) as f64).collect() };
    check_scales(&v)?;
    Ok(v)
}

fn check_scales(v: &[f64]) -> std::result::Result<(), String> {
    if v.is_empty() {
        return Err("the list of load scales is empty".into());
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(format!("load scale {x} is not finite"));
    }
    Ok(())
}

/// A loaded, checked pipeline with its model.
#[derive(Clone, Debug)]
pub struct Pipeline {
    pub path: PathBuf,
    pub text: String,
    pub file: PipelineFile,
    pub model: Model,
    pub basis_path: PathBuf,
    pub report_dir: PathBuf,
}

impl Pipeline {
    pub fn load(path: impl AsRef<Path>) -> Result<Pipeline> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let file: PipelineFile = crate::model::parse_toml(&text, path)?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let stem = path.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_else(|| "pipeline".into());
        let model = Model::load(dir.join(&file.model)).map_err(|e| match e {
            Error::Io { .. } => Error::input(path, "model", format!("cannot read `{}`: {e}", file.model.display())),
            other => other,
        })?;
        let basis_path =
            dir.join(file.basis.clone().unwrap_or_else(|| PathBuf::from(format!("../data/bases/{stem}.h5"))));
        let report_dir = dir.join(file.report.clone().unwrap_or_else(|| PathBuf::from(format!("../reports/{stem}"))));
        let p = Pipeline { path: path.to_path_buf(), text, file, model, basis_path, report_dir };
        p.check()?;
        Ok(p)
    }

    fn check(&self) -> Result<()> {
        let bad = |field: &str, problem: String| Err(Error::input(&self.path, field, problem));
        let red = &self.file.reduction;
        match (&self.file.train.load_scales, &self.file.train.greedy) {
            (Some(_), Some(_)) => return bad("train", "has both load_scales and greedy; give exactly one".into()),
            (None, None) => {
                return bad(
                    "train",
                    "needs load_scales = [..] or greedy = { range = [A, B], tolerance = T, max_runs = K }".into(),
                )
            }
            (Some(s), None) => {
                if let Err(e) = check_scales(s) {
                    return bad("train.load_scales", e);
                }
                if red.modes.is_none() {
                    return bad("reduction.modes", "is missing: with train.load_scales the mode count must be given (or train greedily, which chooses it)".into());
                }
            }
            (None, Some(g)) => {
                if let Err((f, p)) = g.validate() {
                    return bad(&f, p);
                }
            }
        }
        if let Err(e) = red.modes.as_ref().map_or(Ok(()), |m| m.validate()) {
            return bad("reduction.modes", e);
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
                Err("gives counts per block; use count, ratio or energy".to_string())
            } else {
                Ok(())
            }) {
                return bad("reduction.multiplier_modes", e);
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
        for (name, scales) in [
            ("online", self.file.online.as_ref().map(|o| &o.load_scales)),
            ("validate", self.file.validate.as_ref().map(|v| &v.load_scales)),
        ] {
            if let Some(s) = scales {
                if let Err(e) = s.values() {
                    return bad(&format!("{name}.load_scales"), e);
                }
            }
        }
        if let Some(t) = self.online_tolerance() {
            if !(t.is_finite() && t > 0.0) {
                return bad("online.tolerance", format!("is {t}; it must be positive and finite"));
            }
        }
        Ok(())
    }

    /// The reduction variant: the file's, or constraint-preserving when the model has
    /// joints between bodies, galerkin when it has none or only ground joints.
    pub fn variant(&self) -> Variant {
        self.file.reduction.variant.unwrap_or(
            if self.model.file.joints.iter().any(|j| matches!(j, crate::model::schema::JointSpec::Pin { .. })) {
                Variant::ConstraintPreserving
            } else {
                Variant::Galerkin
            },
        )
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
            (None, Some(g)) => {
                let (a, b) = g.range();
                vec![a, 0.5 * (a + b), b]
            }
            (None, None) => Vec::new(),
        }
    }

    pub fn online_scales(&self) -> Vec<f64> {
        self.file.online.as_ref().map_or_else(|| self.training_scales(), |s| s.load_scales.values().expect("checked"))
    }

    /// `[online] tolerance`, when given.
    pub fn online_tolerance(&self) -> Option<f64> {
        self.file.online.as_ref().and_then(|o| o.tolerance)
    }

    pub fn validate_scales(&self) -> Vec<f64> {
        self.file.validate.as_ref().map_or_else(|| self.training_scales(), |s| s.load_scales.values().expect("checked"))
    }

    /// The hash of the `[train]` and `[reduction]` settings a basis file records
    /// ([`crate::io::basis_hash::settings_hash`]): a basis trained with other settings is
    /// flagged as stale.
    pub fn settings_hash(&self) -> String {
        crate::io::basis_hash::settings_hash(&self.file.train, &self.file.reduction)
    }
}
