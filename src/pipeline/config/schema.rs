//! The tables of a pipeline file as they are parsed (`serde`, unknown keys refused): what
//! [`super::Pipeline::load`] reads before it checks them against each other and the model.

use super::scales::Scales;
use crate::reduction::estimator::{ErrorMeasure, EstimateMethod};
use crate::reduction::{ModeRule, SnapshotKind, Variant};
use crate::solver::parameter_space::{ParameterRange, Sampling, Spacing};
use serde::Deserialize;
use std::path::PathBuf;

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
    /// the box of parameters training samples (`[parameters]`, by name); empty: the load
    /// scale alone, as `[train]` gives it
    #[serde(default)]
    pub parameters: std::collections::BTreeMap<String, ParameterSpec>,
}

/// A parameter's range in `[parameters]`: `drive = [0.5, 1.5]`, or `E = { range = [1e8,
/// 4e8], scale = "log" }`.
#[derive(Clone, Debug, serde::Serialize, PartialEq)]
#[serde(untagged)]
pub enum ParameterSpec {
    Range([f64; 2]),
    Table(ParameterTable),
}

// by hand rather than `untagged`, whose only message is "data did not match any variant":
// a table's own problem (`scale = "logarithmic"`) is worth naming
impl<'de> Deserialize<'de> for ParameterSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        use serde::de::Error as _;
        let v = toml::Value::deserialize(d)?;
        match v {
            toml::Value::Array(_) => v.try_into().map(ParameterSpec::Range).map_err(|_| {
                D::Error::custom("a range is two numbers [A, B] (or { range = [A, B], scale = \"log\" })")
            }),
            toml::Value::Table(_) => v.try_into().map(ParameterSpec::Table).map_err(|e| D::Error::custom(e.message())),
            _ => Err(D::Error::custom(format!(
                "is a {}; expected [A, B] or {{ range = [A, B], scale = \"linear\" | \"log\" }}",
                v.type_str()
            ))),
        }
    }
}

#[derive(Clone, Debug, Deserialize, serde::Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ParameterTable {
    #[serde(deserialize_with = "crate::model::schema::pair::exactly")]
    pub range: [f64; 2],
    #[serde(default)]
    pub scale: Spacing,
}

impl ParameterSpec {
    pub fn range(&self, name: &str) -> ParameterRange {
        let (r, spacing) = match self {
            ParameterSpec::Range(r) => (r, Spacing::Linear),
            ParameterSpec::Table(t) => (&t.range, t.scale),
        };
        ParameterRange { name: name.to_string(), lower: r[0], upper: r[1], spacing }
    }
}

/// `[train] points = { count = N, sampling = "sobol", seed = 1 }`: full runs at N points of
/// the `[parameters]` box (sobol, lhs or random; the same points for the same seed).
#[derive(Clone, Debug, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct PointsSpec {
    pub count: usize,
    #[serde(default)]
    pub sampling: Sampling,
    #[serde(default = "default_seed")]
    pub seed: u64,
}

fn default_seed() -> u64 {
    1
}

#[derive(Clone, Debug, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct TrainSpec {
    /// the training loads; exactly one of `load_scales` and `greedy`
    #[serde(default)]
    pub load_scales: Option<Vec<f64>>,
    /// greedy training over a load range (src/training/greedy.rs)
    #[serde(default)]
    pub greedy: Option<GreedySpec>,
    /// training points sampled from the `[parameters]` box
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<PointsSpec>,
    #[serde(default = "default_snapshots")]
    pub snapshots: SnapshotKind,
}

fn default_snapshots() -> SnapshotKind {
    SnapshotKind::Reference
}

/// `[train] greedy = { range = [A, B], tolerance = T, max_runs = K, candidates = N,
/// measure = "relative" }`: full runs where the error estimate over N evenly spaced loads
/// of [A, B] is worst, until every estimate is ≤ T or K full runs were made. With a
/// `[parameters]` box the range is the box's (no `range`), and the candidates are N points
/// drawn from the box by `sampling` from `seed` (default N: 32 per parameter).
#[derive(Clone, Debug, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct GreedySpec {
    /// `[A, B]` of the load scale; empty with a `[parameters]` box
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub range: Vec<f64>,
    pub tolerance: f64,
    pub max_runs: usize,
    /// the candidates' count; `None`: 33 on a line (hashed as 33, as before the key was
    /// optional), 32 per parameter in a box
    #[serde(default, serialize_with = "candidates_as_hashed")]
    pub candidates: Option<usize>,
    /// the error `tolerance` is on: "relative" (rel_error, the default), "displacement"
    /// (displacement_error) or "probes" (rel_error and every probe quantity over its range);
    /// left out of the settings hash when relative, so that a basis trained before the key
    /// existed is not stale
    #[serde(default, skip_serializing_if = "GreedyMeasure::is_relative")]
    pub measure: GreedyMeasure,
    /// how a box's candidates are drawn (a box only)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampling: Option<Sampling>,
    /// the seed of a box's candidates (a box only; default 1)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

/// The candidates on a line of loads when `candidates` is not given.
pub const DEFAULT_LINE_CANDIDATES: usize = 33;
/// What greedy training holds to its tolerance (`[train] greedy.measure`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum GreedyMeasure {
    /// rel_error (the default)
    #[default]
    Relative,
    /// displacement_error
    Displacement,
    /// rel_error and every quantity the probes record — position, strain, curvature — each
    /// over its range (`crate::rom::quantities`); every basis of the loop then carries
    /// output modes for the strains and curvatures at the same tolerance
    Probes,
}

impl GreedyMeasure {
    pub fn is_relative(&self) -> bool {
        *self == GreedyMeasure::Relative
    }

    /// The measure of the coordinates' error (the probes' measure holds rel_error).
    pub fn coordinates(self) -> ErrorMeasure {
        match self {
            GreedyMeasure::Displacement => ErrorMeasure::Displacement,
            GreedyMeasure::Relative | GreedyMeasure::Probes => ErrorMeasure::Relative,
        }
    }

    /// Whether the probe quantities are held to the tolerance too.
    pub fn probes(self) -> bool {
        self == GreedyMeasure::Probes
    }

    /// The name of the error held to the tolerance, as messages print it.
    pub fn error_name(self) -> &'static str {
        match self {
            GreedyMeasure::Probes => "error (rel_error and the probe quantities over their ranges)",
            m => m.coordinates().error_name(),
        }
    }
}

/// A box's candidates per parameter when `candidates` is not given.
pub const DEFAULT_BOX_CANDIDATES_PER_PARAMETER: usize = 32;

fn candidates_as_hashed<S: serde::Serializer>(c: &Option<usize>, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_u64(c.unwrap_or(DEFAULT_LINE_CANDIDATES) as u64)
}

impl GreedySpec {
    /// `Err((field, problem))` with the field under `train.greedy`; `in_box`: the pipeline
    /// has a `[parameters]` box (which gives the range).
    pub fn validate(&self, in_box: bool) -> std::result::Result<(), (String, String)> {
        let bad = |f: &str, p: String| Err((format!("train.greedy.{f}"), p));
        match (in_box, &self.range[..]) {
            (true, []) => {}
            (true, _) => return bad("range", "is given, but the pipeline has a [parameters] box, which is the range of greedy training: leave `range` out (a box holding the load scale says so with `load_scale = [A, B]`)".into()),
            (false, [a, b]) if !(a.is_finite() && b.is_finite()) => {
                return bad("range", format!("[{a}, {b}] must be two finite numbers"))
            }
            (false, [a, b]) if a >= b => return bad("range", format!("[{a}, {b}]: the first end must be less than the second")),
            (false, [_, _]) => {}
            (false, []) => return bad("range", "is missing: give `range = [A, B]` (the load scales to train over), or a [parameters] box".into()),
            (false, _) => return bad("range", format!("has {} entries; it must be [A, B] with A < B", self.range.len())),
        }
        if !in_box && (self.sampling.is_some() || self.seed.is_some()) {
            return bad(
                if self.sampling.is_some() { "sampling" } else { "seed" },
                "draws a box's candidates, but the pipeline has no [parameters] box (on a line the candidates are evenly spaced)".into(),
            );
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
        match self.candidates {
            Some(n) if n < 2 => {
                let why = if in_box { "at least 2 points of the box" } else { "at least 2 (the range ends)" };
                return bad("candidates", format!("is {n}; {why} are needed"));
            }
            Some(n) if in_box && n > crate::solver::parameter_space::MAX_SOBOL_POINTS => {
                return bad(
                    "candidates",
                    format!("is {n}; a box draws at most {}", crate::solver::parameter_space::MAX_SOBOL_POINTS),
                )
            }
            _ => {}
        }
        if self.sampling.unwrap_or_default() == Sampling::Sobol && self.seed.is_some_and(|s| s > u64::from(u32::MAX)) {
            return bad("seed", format!("is {}; a Sobol seed lies in 0..={}", self.seed.unwrap_or(0), u32::MAX));
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
        let n = self.candidates.unwrap_or(DEFAULT_LINE_CANDIDATES);
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
    /// output modes: each block's POD enriched until the strains and curvatures the probes
    /// record are reproduced on the training snapshots within `tolerance` of their range
    /// (`crate::reduction::output_modes`); absent: none
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe_modes: Option<HyperSpec>,
}

/// How the coordinates are split into blocks with a POD each.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Blocks {
    /// one block per body: each mode moves one body only
    Bodies,
}

/// `[reduction.hyper]`: ECSW element sampling trained to a relative tolerance τ on the
/// training snapshots (‖C w − b‖ ≤ τ ‖b‖; smaller τ: more elements, closer to Galerkin);
/// `[reduction.probe_modes]`: the output modes' tolerance.
#[derive(Clone, Debug, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct HyperSpec {
    pub tolerance: f64,
}

/// `[online]`: the load scales of `sweep` and `run`, and the tolerance every reduced run's
/// error estimate is held to (a warning, or exit code 4 with `--strict`, above it). Every
/// key is optional: `estimate` or `tolerance` may be set without a load list.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OnlineSpec {
    /// default: the training loads (greedy: the ends and the middle of its range)
    #[serde(default)]
    pub load_scales: Option<Scales>,
    #[serde(default)]
    pub tolerance: Option<f64>,
    /// the error `tolerance` is on: "relative" or "displacement"; default: the measure of
    /// the basis's training tolerance (greedy's `measure`; "relative" for other bases)
    #[serde(default)]
    pub tolerance_measure: Option<ErrorMeasure>,
    /// how every reduced run computes its error estimate: "defects" (cheap; the default where
    /// greedy training calibrated it reliably), "corrected" (the default otherwise) or
    /// "enriched" (docs/error-estimate.md)
    #[serde(default)]
    pub estimate: Option<EstimateMethod>,
    /// what `sweep` does where it cannot stand behind a reduced answer: "none" (keep it with
    /// its warning, or the failure; the default) or "full" (run the full model there and
    /// keep its exact answer; docs/basis-and-sweep.md)
    #[serde(default)]
    pub fallback: Option<crate::pipeline::fallback::Fallback>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScalesSpec {
    pub load_scales: Scales,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Sobol sampler's limit (2¹⁶ points, `MAX_SOBOL_POINTS`) bounds a box's candidates;
    /// a line's evenly spaced loads have no such limit.
    #[test]
    fn only_a_box_caps_the_candidates() {
        let g = |range: Vec<f64>| GreedySpec {
            range,
            tolerance: 1e-3,
            max_runs: 4,
            candidates: Some(70_000),
            measure: Default::default(),
            sampling: None,
            seed: None,
        };
        assert!(g(vec![0.5, 1.5]).validate(false).is_ok());
        let (field, problem) = g(vec![]).validate(true).unwrap_err();
        assert_eq!(field, "train.greedy.candidates");
        assert!(problem.contains("a box draws at most 65536"), "{problem}");
    }
}
