//! A `Result` as bytes for `pickle` (joblib, multiprocessing): everything it holds, the
//! model's text and path among it, in one versioned payload. The payload is
//!
//! ```text
//!     MAGIC | format (u32, little-endian) | version length (u8) | flexrom version
//!           | SHA-256 of the body (32 bytes) | body (bincode of [`Parts`])
//! ```
//!
//! bincode keeps every `f64` bit for bit (NaN and ±∞ too, which JSON has no form for). A
//! payload of another format or flexrom version is refused, as are bytes that do not begin
//! with [`MAGIC`] or whose body does not match its digest: a `ValueError` naming what is
//! wrong, never a panic.
//!
//! The library types outside `rom` and `analysis` (the run, its settings, the integrator's
//! parameters and counters, the parameters μ, the model's limits) are given their serde
//! form here, as serde's "remote" definitions: each names every field of its type, so a
//! field added to one of them fails to compile here until the payload carries it.

use crate::{PyRunResult, ReducedPart, StaticsPart};
use bincode::Options;
use flexrom::analysis::energy::Energies;
use flexrom::limits::Limits;
use flexrom::linalg::kkt_pattern::LinearSolverKind;
use flexrom::model::Model;
use flexrom::rom::estimator::Estimate;
use flexrom::simulate::{Settings, SimulationResult};
use flexrom::solver::generalized_alpha::{LargestStrain, Stats};
use flexrom::solver::integrator_params::{IntegratorParams, JacobianReuse};
use flexrom::solver::predictor::Predictor;
use ndarray::{Array1, Array2};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::PathBuf;
use std::sync::Arc;

/// The first bytes of every payload.
const MAGIC: &[u8] = b"flexrom.Result\0";

/// The layout of the body; raised whenever [`Parts`] or a type it holds changes its form.
const FORMAT: u32 = 1;

/// The flexrom version that wrote a payload: a payload is read by the same version only (the
/// library's types may change between versions without a new [`FORMAT`]).
const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Everything a `Result` holds ([`PyRunResult`]), the model as its file's text, path and the
/// bounds it was read with.
#[derive(Serialize, Deserialize)]
struct Parts {
    model_path: PathBuf,
    model_text: String,
    #[serde(with = "LimitsDef")]
    model_limits: Limits,
    #[serde(with = "RunDef")]
    r: SimulationResult,
    reduced: Option<ReducedPart>,
    fallback: Option<String>,
    fallback_failed: Option<String>,
    exact: Option<(Estimate, bool)>,
    statics: Option<StaticsPart>,
}

/// The body's bincode layout: fixed-width little-endian numbers, no bytes left over.
fn layout() -> impl bincode::Options {
    bincode::DefaultOptions::new().with_fixint_encoding().reject_trailing_bytes()
}

/// The payload of `result` (its `__reduce__`).
pub(crate) fn to_bytes(result: &PyRunResult) -> Result<Vec<u8>, String> {
    // every field named: a field added to the Result fails to compile here
    let PyRunResult { model, r, reduced, fallback, fallback_failed, exact, statics } = result;
    let parts = Parts {
        model_path: model.path.clone(),
        model_text: model.text.clone(),
        model_limits: model.limits.clone(),
        r: r.clone(),
        reduced: reduced.clone(),
        fallback: fallback.clone(),
        fallback_failed: fallback_failed.clone(),
        exact: exact.clone(),
        statics: statics.clone(),
    };
    let body = layout().serialize(&parts).map_err(|e| format!("cannot pickle this Result: {e}"))?;
    let mut out = Vec::with_capacity(MAGIC.len() + 4 + 1 + VERSION.len() + 32 + body.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT.to_le_bytes());
    out.push(VERSION.len() as u8);
    out.extend_from_slice(VERSION.as_bytes());
    out.extend_from_slice(&Sha256::digest(&body));
    out.extend_from_slice(&body);
    Ok(out)
}

/// The `Result` of a payload [`to_bytes`] wrote; what is wrong with it otherwise.
pub(crate) fn from_bytes(bytes: &[u8]) -> Result<PyRunResult, String> {
    let rest = bytes
        .strip_prefix(MAGIC)
        .ok_or("the bytes are not a pickled flexrom.Result (they do not begin with its marker)")?;
    let truncated = || "the pickled flexrom.Result is damaged: it ends inside its header".to_string();
    let (format, rest) = rest.split_first_chunk::<4>().ok_or_else(truncated)?;
    let format = u32::from_le_bytes(*format);
    let (&n, rest) = rest.split_first().ok_or_else(truncated)?;
    let (version, rest) = rest.split_at_checked(n as usize).ok_or_else(truncated)?;
    let version = String::from_utf8_lossy(version);
    if format != FORMAT || version != VERSION {
        return Err(format!(
            "this Result was pickled by flexrom {version} (payload format {format}); this is flexrom {VERSION} \
             (format {FORMAT}), which reads its own pickles only: unpickle it with flexrom {version}, or keep \
             results across versions as result files (Result.to_hdf5)"
        ));
    }
    let (digest, body) = rest.split_first_chunk::<32>().ok_or_else(truncated)?;
    if Sha256::digest(body).as_slice() != digest {
        return Err(format!(
            "the pickled flexrom.Result is damaged: its {} bytes of data do not match their SHA-256 digest \
             (cut short or changed)",
            body.len()
        ));
    }
    // read no further than the body (a length inside it cannot make it allocate more)
    let parts: Parts = layout()
        .with_limit(body.len() as u64)
        .deserialize(body)
        .map_err(|e| format!("the pickled flexrom.Result is damaged: its data do not read ({e})"))?;
    let model = Model::from_text_with(&parts.model_text, &parts.model_path, parts.model_limits)
        .map_err(|e| format!("the pickled flexrom.Result's model file does not read: {e}"))?;
    Ok(PyRunResult {
        model: Arc::new(model),
        r: parts.r,
        reduced: parts.reduced,
        fallback: parts.fallback,
        fallback_failed: parts.fallback_failed,
        exact: parts.exact,
        statics: parts.statics,
    })
}

/// A run's serde form ([`SimulationResult`]).
#[derive(Serialize, Deserialize)]
#[serde(remote = "SimulationResult")]
struct RunDef {
    model_text: String,
    model_path: String,
    #[serde(with = "SettingsDef")]
    settings: Settings,
    t: Array1<f64>,
    q: Array2<f64>,
    qd: Array2<f64>,
    multipliers: Array2<f64>,
    probes: Vec<(String, Array2<f64>)>,
    strains: Vec<(String, Array1<f64>)>,
    curvatures: Vec<(String, Array1<f64>)>,
    #[serde(with = "StatsDef")]
    stats: Stats,
    wall_seconds: f64,
    energy: Option<Energies>,
}

#[derive(Serialize, Deserialize)]
#[serde(remote = "Settings")]
struct SettingsDef {
    dt: f64,
    t_end: f64,
    rho_inf: f64,
    #[serde(with = "parameters")]
    mu: flexrom::solver::parameters::Parameters,
    n_steps: usize,
    #[serde(with = "LinearSolverKindDef")]
    solver: LinearSolverKind,
    #[serde(with = "IntegratorParamsDef")]
    params: IntegratorParams,
    allow_blowup: bool,
}

#[derive(Serialize, Deserialize)]
#[serde(remote = "LinearSolverKind")]
enum LinearSolverKindDef {
    Banded,
    Sparse,
    Dense,
}

#[derive(Serialize, Deserialize)]
#[serde(remote = "IntegratorParams")]
struct IntegratorParamsDef {
    rho_inf: f64,
    tolerance: f64,
    stagnation: f64,
    max_iterations: usize,
    max_cuts: u32,
    #[serde(with = "JacobianReuseDef")]
    reuse: JacobianReuse,
    #[serde(with = "PredictorDef")]
    predictor: Predictor,
    max_strain: f64,
    max_total_cuts: usize,
}

#[derive(Serialize, Deserialize)]
#[serde(remote = "JacobianReuse")]
enum JacobianReuseDef {
    Never,
    WithinStep,
    AcrossSteps,
}

#[derive(Serialize, Deserialize)]
#[serde(remote = "Predictor")]
enum PredictorDef {
    ZeroAcceleration,
    ConstantVelocity,
    ConstantPosition,
    Adaptive,
}

#[derive(Serialize, Deserialize)]
#[serde(remote = "Stats")]
struct StatsDef {
    steps: usize,
    newton_iterations: usize,
    factorizations: usize,
    step_cuts: usize,
    max_iterations_in_a_step: usize,
    steps_at_round_off: usize,
    constant_velocity_starts: usize,
    constant_position_starts: usize,
    zero_acceleration_starts: usize,
    step_cut_times: Vec<f64>,
    #[serde(with = "largest_strain")]
    largest_strain: Option<LargestStrain>,
}

#[derive(Serialize, Deserialize)]
#[serde(remote = "LargestStrain")]
struct LargestStrainDef {
    strain: f64,
    element: usize,
    t: f64,
}

#[derive(Serialize, Deserialize)]
#[serde(remote = "Limits")]
struct LimitsDef {
    max_memory: u64,
    memory_source: String,
    max_steps: u64,
    max_elements: u64,
    allow_blowup: bool,
}

/// `Option<LargestStrain>` through [`LargestStrainDef`].
mod largest_strain {
    use super::*;

    #[derive(Serialize, Deserialize)]
    struct Some_(#[serde(with = "LargestStrainDef")] LargestStrain);

    pub fn serialize<S: serde::Serializer>(v: &Option<LargestStrain>, to: S) -> Result<S::Ok, S::Error> {
        v.map(Some_).serialize(to)
    }

    pub fn deserialize<'de, D: serde::Deserializer<'de>>(from: D) -> Result<Option<LargestStrain>, D::Error> {
        Ok(Option::<Some_>::deserialize(from)?.map(|Some_(x)| x))
    }
}

/// Parameters μ as what they are: the load scale λ and the named values (their fields are
/// the solver's own).
pub(crate) mod parameters {
    use flexrom::solver::parameters::Parameters;
    use serde::{Deserialize, Serialize};
    use std::collections::BTreeMap;

    type Plain = (f64, BTreeMap<String, f64>);

    pub fn serialize<S: serde::Serializer>(mu: &Parameters, to: S) -> Result<S::Ok, S::Error> {
        let named: BTreeMap<String, f64> = mu.named().map(|(k, v)| (k.to_string(), v)).collect();
        (mu.scale(), named).serialize(to)
    }

    pub fn deserialize<'de, D: serde::Deserializer<'de>>(from: D) -> Result<Parameters, D::Error> {
        let (scale, named) = Plain::deserialize(from)?;
        Ok(named.into_iter().fold(Parameters::load_scale(scale), |mu, (k, v)| mu.with(&k, v)))
    }
}
