//! The TOML schema of a model file (`data/models/*.toml`). Every table refuses unknown keys.

use crate::physics::time_function::TimeFunction;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// free text shown in reports
    #[serde(default)]
    pub description: String,
    pub time: TimeSettings,
    #[serde(default)]
    pub damping: Option<DampingSpec>,
    pub bodies: Vec<BodySpec>,
    #[serde(default)]
    pub joints: Vec<JointSpec>,
    #[serde(default)]
    pub loads: Vec<LoadSpec>,
    /// point masses at nodes
    #[serde(default)]
    pub masses: Vec<MassSpec>,
    /// spring-dampers between nodes, or a node and the ground (absent: none; left out of
    /// the serialized file then, so that older files keep their fingerprint)
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub springs: Vec<SpringSpec>,
    #[serde(default)]
    pub probes: Vec<ProbeSpec>,
    /// how a dynamic run starts (absent: from the undeformed configuration at rest; left
    /// out of the serialized file then, so that older files keep their fingerprint)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial: Option<InitialSpec>,
}

/// `[initial]`: the state a dynamic run starts from.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// start from the static equilibrium under the loads at t = 0 (at rest)
    #[serde(default)]
    pub r#static: bool,
}

/// A point mass at a node, kg (gravity acts on it).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MassSpec {
    pub body: String,
    pub node: NodeRef,
    /// kg; or `{ value, parameter = "name" }`
    pub mass: PropertySpec,
    /// kg m² about the node, on its slope (absent: none; left out of the serialized file
    /// then, so that older files keep their fingerprint)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotary_inertia: Option<f64>,
}

/// A spring-damper (`[[springs]]`): translational between a node and a node or a ground
/// point, or torsional between two nodes' slopes.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SpringSpec {
    /// shown in messages
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// translational (the default) or torsional
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub r#type: Option<SpringKind>,
    pub a: NodeSpec,
    pub b: SpringEndSpec,
    /// N/m (translational) or N m/rad (torsional); or `{ value, parameter = "name" }`
    pub stiffness: PropertySpec,
    /// N s/m (translational) or N m s/rad (torsional)
    #[serde(default)]
    pub damping: f64,
    /// free length, m (translational; default: the initial distance)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
}

/// The kind of a [`SpringSpec`].
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SpringKind {
    Translational,
    Torsional,
}

/// A spring's second end: `{ body, node }` or `{ point = [x, y] }` (one table, so that a
/// misspelt key is named: the check tells which combination is missing).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SpringEndSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub node: Option<NodeRef>,
    #[serde(default, deserialize_with = "pair::optional", skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 2]>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSettings {
    pub t_end: f64,
    pub dt: f64,
    /// spectral radius of generalized-α at infinite frequency (1 = trapezoidal rule)
    pub rho_inf: f64,
    /// Newton tolerance on ‖Δq‖∞ relative to the longest body
    #[serde(default)]
    pub newton_tolerance: Option<f64>,
    /// Newton increments (relative to the longest body) accepted when Newton has stopped
    /// contracting: the round-off floor (default 1e-6, 0 = never)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub newton_stagnation: Option<f64>,
    #[serde(default)]
    pub max_iterations: Option<i64>,
    #[serde(default)]
    pub max_step_cuts: Option<i64>,
    /// "within-step" (the default: keep a factorized Newton matrix while Newton contracts
    /// fast) or "never" (a fresh matrix at every iteration: full Newton)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jacobian_reuse: Option<String>,
    /// where Newton starts a step: "adaptive" (the default: each step, whichever of the
    /// other three came closest to the last step's solution), "zero-acceleration",
    /// "constant-velocity" (q_n + h q̇_n) or "constant-position" (q_n;
    /// docs/reduced-speed.md)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub predictor: Option<String>,
    /// blow-up check: the largest mean axial strain |ε̄| a run may reach (default 0.5)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_strain: Option<f64>,
    /// blow-up check: step halvings a whole run may take (default 50)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_total_step_cuts: Option<i64>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DampingSpec {
    /// a in C = a M + b K_t
    #[serde(default)]
    pub mass: f64,
    /// b in C = a M + b K_t
    #[serde(default)]
    pub stiffness: f64,
}

/// `[x, y]` read as exactly two numbers: serde's fixed-size arrays take the first two of a
/// longer list and drop the rest (`start = [0, 0, 5]`, a 3-D habit, would lose its `5`
/// silently).
pub mod pair {
    use serde::de::{Deserialize, Deserializer, Error};

    pub fn exactly<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
        let v: Vec<f64> = Vec::deserialize(d)?;
        <[f64; 2]>::try_from(v.as_slice()).map_err(|_| D::Error::invalid_length(v.len(), &"two numbers, [x, y]"))
    }

    pub fn optional<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
        exactly(d).map(Some)
    }
}

/// A straight beam: `start` and either `angle` (rad) with `length`, or `end` (then
/// `length`, if given, must agree with it and is used as the exact length).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    pub name: String,
    #[serde(deserialize_with = "pair::exactly")]
    pub start: [f64; 2],
    #[serde(default)]
    pub angle: Option<f64>,
    #[serde(default, deserialize_with = "pair::optional")]
    pub end: Option<[f64; 2]>,
    #[serde(default)]
    pub length: Option<f64>,
    pub elements: i64,
    pub density: PropertySpec,
    pub area: f64,
    pub inertia: f64,
    pub youngs_modulus: PropertySpec,
    /// initial velocity of the body's start, m/s
    #[serde(default, deserialize_with = "pair::optional")]
    pub velocity: Option<[f64; 2]>,
    /// initial angular velocity about the body's start, rad/s, counter-clockwise
    #[serde(default)]
    pub angular_velocity: Option<f64>,
}

/// A material property: a number, or `{ value = …, parameter = "name" }`, which makes the
/// property the parameter `name` (`value` where a run does not set it).
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(untagged)]
pub enum PropertySpec {
    Value(f64),
    Parameter(ParameterProperty),
}

/// `{ value = …, parameter = "name" }` of a [`PropertySpec`].
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ParameterProperty {
    pub value: f64,
    pub parameter: String,
}

/// A number, or a table whose own errors name its key (`missing field `parameter``,
/// `unknown field `paramter``), which an untagged enum would swallow.
impl<'de> Deserialize<'de> for PropertySpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        use serde::de::Error as _;
        let v = toml::Value::deserialize(d)?;
        match v {
            toml::Value::Float(x) => Ok(PropertySpec::Value(x)),
            toml::Value::Integer(i) => Ok(PropertySpec::Value(i as f64)),
            toml::Value::Table(_) => {
                v.try_into().map(PropertySpec::Parameter).map_err(|e| D::Error::custom(e.message()))
            }
            _ => Err(D::Error::custom(format!(
                "is a {}; expected a number, or {{ value = NUMBER, parameter = \"NAME\" }}",
                v.type_str()
            ))),
        }
    }
}

impl PropertySpec {
    /// The value the model file gives (used where the parameter is not set).
    pub fn value(&self) -> f64 {
        match self {
            PropertySpec::Value(v) => *v,
            PropertySpec::Parameter(p) => p.value,
        }
    }

    /// The parameter's name, when the property is one.
    pub fn parameter(&self) -> Option<&str> {
        match self {
            PropertySpec::Value(_) => None,
            PropertySpec::Parameter(p) => Some(&p.parameter),
        }
    }
}

/// A node of a body: its index (0 = start) or `"start"` / `"end"`.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum NodeRef {
    Index(i64),
    Name(String),
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct NodeSpec {
    pub body: String,
    pub node: NodeRef,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum JointSpec {
    /// the node's position is fixed at `point` (default: where it starts)
    GroundPin {
        body: String,
        node: NodeRef,
        #[serde(default, deserialize_with = "pair::optional")]
        point: Option<[f64; 2]>,
    },
    /// two bodies' nodes share their position
    Pin { a: NodeSpec, b: NodeSpec },
    /// position and slope of the node fixed at their initial values
    Clamp { body: String, node: NodeRef },
    /// the node stays on the ground line through its initial position along `direction`;
    /// with `lock_rotation` its slope keeps its direction too (a prismatic joint)
    Slider {
        body: String,
        node: NodeRef,
        #[serde(deserialize_with = "pair::exactly")]
        direction: [f64; 2],
        #[serde(default)]
        lock_rotation: bool,
    },
    /// two bodies' nodes rigidly joined: the same position, slopes at their initial angle
    Weld { a: NodeSpec, b: NodeSpec },
    /// the node's slope turns by `function(t)` rad from its initial direction (a motor by
    /// angle with a ground pin at the node); `scaled` as for loads
    DrivenAngle {
        body: String,
        node: NodeRef,
        function: TimeFunction,
        #[serde(default = "yes")]
        scaled: ScaledSpec,
    },
    /// the node's position is its initial position plus `(x(t), y(t))`, m; a missing
    /// component stays 0; `scaled` as for loads
    DrivenPoint {
        body: String,
        node: NodeRef,
        #[serde(default)]
        x: Option<TimeFunction>,
        #[serde(default)]
        y: Option<TimeFunction>,
        #[serde(default = "yes")]
        scaled: ScaledSpec,
    },
}

/// `scaled` of a load: `true` (times the load scale), `false` (fixed), or the name of the
/// parameter that multiplies it (`scaled = "drive"`).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(untagged, expecting = "true, false or the name of a parameter (\"drive\")")]
pub enum ScaledSpec {
    Flag(bool),
    Parameter(String),
}

fn yes() -> ScaledSpec {
    ScaledSpec::Flag(true)
}

fn no() -> ScaledSpec {
    ScaledSpec::Flag(false)
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum LoadSpec {
    /// gravity acceleration vector, m/s²; `scaled` = multiplied by the load scale (or by
    /// the parameter it names)
    Gravity {
        g: [f64; 2],
        #[serde(default = "no")]
        scaled: ScaledSpec,
    },
    /// moment (N·m) at a node, `function` of time
    Moment {
        body: String,
        node: NodeRef,
        function: TimeFunction,
        #[serde(default = "yes")]
        scaled: ScaledSpec,
    },
    /// force (N) at a node, times `function` of time if given
    Force {
        body: String,
        node: NodeRef,
        value: [f64; 2],
        #[serde(default)]
        function: Option<TimeFunction>,
        #[serde(default = "yes")]
        scaled: ScaledSpec,
    },
}

impl LoadSpec {
    /// The name `scaled = "name"` gives, if any.
    pub fn scaled_parameter(&self) -> Option<&str> {
        match self {
            LoadSpec::Gravity { scaled, .. } | LoadSpec::Moment { scaled, .. } | LoadSpec::Force { scaled, .. } => {
                match scaled {
                    ScaledSpec::Parameter(name) => Some(name),
                    ScaledSpec::Flag(_) => None,
                }
            }
        }
    }
}

/// A recorded point: a `node` of a body, or the point at fraction `at` ∈ [0, 1] of its length.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    pub name: String,
    pub body: String,
    #[serde(default)]
    pub node: Option<NodeRef>,
    #[serde(default)]
    pub at: Option<f64>,
    /// what the probe records: its position always, and the axial strain and curvature
    /// there when listed (default `["position"]`); left out of the fingerprint when absent,
    /// so that models without it keep theirs
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quantities: Option<Vec<ProbeQuantity>>,
}

/// A quantity a probe records ([`ProbeSpec::quantities`]).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ProbeQuantity {
    /// x, y of the point, m (always recorded)
    Position,
    /// axial Green strain ½(r'·r' − 1) at the point, 1
    Strain,
    /// signed curvature (r' × r'')_z / |r'|³ of the centre line at the point, 1/m
    Curvature,
}
