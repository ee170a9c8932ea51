//! Model files: parse, validate (errors name the file, the field and the problem) and build
//! the physical system.

pub mod schema;

use crate::error::{Error, Result};
use crate::physics::element::Section;
use crate::physics::system::{BeamBody, FlexibleSystem, Joint, Load, NodeId, Probe, Rayleigh};
use crate::solver::generalized_alpha::{IntegratorParams, JacobianReuse};
use crate::solver::kkt::LinearSolverKind;
use schema::*;
use std::path::{Path, PathBuf};

/// Sizes of a model's system (see [`Model::sizes`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sizes {
    pub n_dof: f64,
    pub n_constraints: f64,
    pub n_elements: f64,
    pub n_probes: f64,
}

/// A validated model file.
#[derive(Clone, Debug)]
pub struct Model {
    pub path: PathBuf,
    /// the file's text, stored with every result
    pub text: String,
    pub file: ModelFile,
    bodies: Vec<BeamBody>,
    joints: Vec<Joint>,
    loads: Vec<Load>,
    probes: Vec<Probe>,
}

/// Relative tolerance for a joint to count as closed in the initial configuration.
const CLOSURE_TOL: f64 = 1e-6;

impl Model {
    pub fn load(path: impl AsRef<Path>) -> Result<Model> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Model::from_text(&text, path)
    }

    pub fn from_text(text: &str, path: impl AsRef<Path>) -> Result<Model> {
        let path = path.as_ref();
        let file: ModelFile = parse_toml(text, path).map_err(|e| entry_error(text, path).unwrap_or(e))?;
        let mut model = Model {
            path: path.to_path_buf(),
            text: text.to_string(),
            file,
            bodies: vec![],
            joints: vec![],
            loads: vec![],
            probes: vec![],
        };
        model.check()?;
        Ok(model)
    }

    fn err(&self, field: impl Into<String>, problem: impl Into<String>) -> Error {
        Error::input(&self.path, field, problem)
    }

    fn check(&mut self) -> Result<()> {
        let f = self.file.clone();
        let t = &f.time;
        self.positive("time.t_end", t.t_end)?;
        self.positive("time.dt", t.dt)?;
        if t.dt > t.t_end {
            return Err(self.err("time.dt", format!("step {} is longer than t_end {}", t.dt, t.t_end)));
        }
        self.params_from(t)?;
        if let Some(d) = &f.damping {
            for (name, v) in [("damping.mass", d.mass), ("damping.stiffness", d.stiffness)] {
                if !v.is_finite() || v < 0.0 {
                    return Err(self.err(name, format!("must be finite and non-negative, got {v}")));
                }
            }
        }
        if f.bodies.is_empty() {
            return Err(self.err("bodies", "a model needs at least one body"));
        }
        for (i, b) in f.bodies.iter().enumerate() {
            let p = |k: &str| format!("bodies[{i}].{k}");
            if b.name.trim().is_empty() {
                return Err(self.err(p("name"), "must not be empty"));
            }
            if f.bodies[..i].iter().any(|o| o.name == b.name) {
                return Err(self.err(p("name"), format!("body `{}` is defined twice", b.name)));
            }
            self.finite2(&p("start"), b.start)?;
            if b.elements <= 0 {
                return Err(self.err(p("elements"), format!("must be a positive integer, got {}", b.elements)));
            }
            let total: f64 = f.bodies[..=i].iter().map(|b| b.elements.max(0) as f64).sum();
            crate::limits::check_elements(total).map_err(|e| self.err(p("elements"), e))?;
            for (k, v) in
                [("density", b.density), ("area", b.area), ("inertia", b.inertia), ("youngs_modulus", b.youngs_modulus)]
            {
                self.positive(&p(k), v)?;
            }
            let (angle, length) = match (b.angle, b.end) {
                (Some(_), Some(_)) => return Err(self.err(p("end"), "give either `angle` or `end`, not both")),
                (None, None) => return Err(self.err(p("angle"), "missing: give `angle` (rad) with `length`, or `end`")),
                (Some(a), None) => {
                    self.finite(&p("angle"), a)?;
                    let l = b.length.ok_or_else(|| self.err(p("length"), "missing (required with `angle`)"))?;
                    self.positive(&p("length"), l)?;
                    (a, l)
                }
                (None, Some(end)) => {
                    self.finite2(&p("end"), end)?;
                    let (dx, dy) = (end[0] - b.start[0], end[1] - b.start[1]);
                    let dist = dx.hypot(dy);
                    if dist <= 0.0 {
                        return Err(self.err(p("end"), "coincides with `start`: the body has zero length"));
                    }
                    let l = match b.length {
                        Some(l) => {
                            self.positive(&p("length"), l)?;
                            if (l - dist).abs() > CLOSURE_TOL * l {
                                return Err(self.err(p("length"), format!("{l} disagrees with |end − start| = {dist}")));
                            }
                            l
                        }
                        None => dist,
                    };
                    (dy.atan2(dx), l)
                }
            };
            self.bodies.push(BeamBody {
                name: b.name.clone(),
                start: b.start,
                angle,
                length,
                n_elements: b.elements as usize,
                section: Section {
                    density: b.density,
                    area: b.area,
                    inertia: b.inertia,
                    youngs_modulus: b.youngs_modulus,
                },
            });
        }
        let lmax = self.bodies.iter().map(|b| b.length).fold(0.0, f64::max);
        let node_pos = |(b, k): NodeId, bodies: &[BeamBody]| -> [f64; 2] {
            let r = bodies[b].undeformed_node(k);
            [r[0], r[1]]
        };
        for (i, j) in f.joints.iter().enumerate() {
            let p = |k: &str| format!("joints[{i}].{k}");
            let joint = match j {
                JointSpec::GroundPin { body, node, point } => {
                    let id = self.node_id(&p("body"), &p("node"), body, node)?;
                    let at = node_pos(id, &self.bodies);
                    let point = match point {
                        Some(pt) => {
                            self.finite2(&p("point"), *pt)?;
                            let gap = (pt[0] - at[0]).hypot(pt[1] - at[1]);
                            if gap > CLOSURE_TOL * lmax {
                                return Err(self.err(p("point"), format!("{pt:?} is {gap:.3e} m from the node's initial position {at:?}; the initial configuration must satisfy every joint")));
                            }
                            *pt
                        }
                        None => at,
                    };
                    Joint::GroundPin { node: id, point }
                }
                JointSpec::Pin { a, b } => {
                    let ia = self.node_id(&p("a.body"), &p("a.node"), &a.body, &a.node)?;
                    let ib = self.node_id(&p("b.body"), &p("b.node"), &b.body, &b.node)?;
                    if ia.0 == ib.0 {
                        return Err(self.err(p("b.body"), "a pin joins two different bodies"));
                    }
                    let (pa, pb) = (node_pos(ia, &self.bodies), node_pos(ib, &self.bodies));
                    let gap = (pa[0] - pb[0]).hypot(pa[1] - pb[1]);
                    if gap > CLOSURE_TOL * lmax {
                        return Err(self.err(p("b"), format!("the two nodes start {gap:.3e} m apart ({pa:?} and {pb:?}); the initial configuration must satisfy every joint")));
                    }
                    Joint::Pin { a: ia, b: ib }
                }
                JointSpec::Clamp { body, node } => {
                    let id = self.node_id(&p("body"), &p("node"), body, node)?;
                    let bd = &self.bodies[id.0];
                    Joint::Clamp {
                        node: id,
                        point: node_pos(id, &self.bodies),
                        slope: [bd.angle.cos(), bd.angle.sin()],
                    }
                }
            };
            self.joints.push(joint);
        }
        self.check_joint_rank()?;
        for (i, l) in f.loads.iter().enumerate() {
            let p = |k: &str| format!("loads[{i}].{k}");
            let load = match l {
                LoadSpec::Gravity { g, scaled } => {
                    self.finite2(&p("g"), *g)?;
                    Load::Gravity { g: *g, scaled: *scaled }
                }
                LoadSpec::Moment { body, node, function, scaled } => {
                    let id = self.node_id(&p("body"), &p("node"), body, node)?;
                    function.check().map_err(|e| self.err(p("function"), e))?;
                    Load::Moment { node: id, function: function.clone(), scaled: *scaled }
                }
                LoadSpec::Force { body, node, value, function, scaled } => {
                    let id = self.node_id(&p("body"), &p("node"), body, node)?;
                    self.finite2(&p("value"), *value)?;
                    if let Some(func) = function {
                        func.check().map_err(|e| self.err(p("function"), e))?;
                    }
                    Load::Force { node: id, value: *value, function: function.clone(), scaled: *scaled }
                }
            };
            self.loads.push(load);
        }
        for (i, pr) in f.probes.iter().enumerate() {
            let p = |k: &str| format!("probes[{i}].{k}");
            if f.probes[..i].iter().any(|o| o.name == pr.name) {
                return Err(self.err(p("name"), format!("probe `{}` is defined twice", pr.name)));
            }
            if pr.name.is_empty() || pr.name.contains('/') {
                return Err(self.err(p("name"), "must be non-empty and contain no `/` (it names an HDF5 dataset)"));
            }
            let b = self.body_index(&p("body"), &pr.body)?;
            let n_el = self.bodies[b].n_elements;
            let first_el: usize = self.bodies[..b].iter().map(|x| x.n_elements).sum();
            let (element, xi) = match (&pr.node, pr.at) {
                (Some(_), Some(_)) => return Err(self.err(p("at"), "give either `node` or `at`, not both")),
                (None, None) => return Err(self.err(p("node"), "missing: give `node` or `at`")),
                (Some(node), None) => {
                    let (_, k) = self.node_id(&p("body"), &p("node"), &pr.body, node)?;
                    if k < n_el {
                        (first_el + k, 0.0)
                    } else {
                        (first_el + n_el - 1, 1.0)
                    }
                }
                (None, Some(at)) => {
                    if !(at.is_finite() && (0.0..=1.0).contains(&at)) {
                        return Err(self.err(p("at"), format!("{at} lies outside the body (must be in [0, 1])")));
                    }
                    let s = at * n_el as f64;
                    let k = (s.floor() as usize).min(n_el - 1);
                    (first_el + k, s - k as f64)
                }
            };
            self.probes.push(Probe { name: pr.name.clone(), element, xi });
        }
        Ok(())
    }

    /// Refuses joints whose constraint rows `B` are linearly dependent (a node pinned twice,
    /// a clamp plus a pin on its node, a loop of pins closing on one point): the KKT matrix
    /// is then singular. Elimination row by row in joint order (B has entries ±1, so it is
    /// exact); each row keeps the set of joints it was combined from, so a row that
    /// reduces to zero names exactly the joints whose constraints it repeats.
    fn check_joint_rank(&self) -> Result<()> {
        use std::collections::{BTreeMap, BTreeSet, HashMap};
        let mut first = Vec::with_capacity(self.bodies.len());
        let mut n = 0;
        for b in &self.bodies {
            first.push(n);
            n += b.n_elements + 1;
        }
        let g = |(b, k): NodeId| first[b] + k;
        // reduced rows with their pivot column and the joints they combine
        let mut basis: Vec<(BTreeMap<usize, f64>, BTreeSet<usize>)> = Vec::new();
        let mut pivot_of: HashMap<usize, usize> = HashMap::new();
        for (j, joint) in self.joints.iter().enumerate() {
            let rows: Vec<Vec<(usize, f64)>> = match *joint {
                Joint::GroundPin { node, .. } => (0..2).map(|c| vec![(4 * g(node) + c, 1.0)]).collect(),
                Joint::Clamp { node, .. } => (0..4).map(|c| vec![(4 * g(node) + c, 1.0)]).collect(),
                Joint::Pin { a, b } => (0..2).map(|c| vec![(4 * g(a) + c, 1.0), (4 * g(b) + c, -1.0)]).collect(),
            };
            for row in rows {
                let mut r: BTreeMap<usize, f64> = row.into_iter().collect();
                let mut used = BTreeSet::from([j]);
                // eliminate the earliest basis row first: a basis row holds only pivot
                // columns of later rows, so this ends
                while let Some((c, bi)) =
                    r.keys().filter_map(|c| pivot_of.get(c).map(|&bi| (*c, bi))).min_by_key(|x| x.1)
                {
                    let (brow, bj) = &basis[bi];
                    let f = r[&c] / brow[&c];
                    for (&cc, &bv) in brow {
                        *r.entry(cc).or_insert(0.0) -= f * bv;
                    }
                    r.remove(&c);
                    r.retain(|_, v| v.abs() > 1e-9);
                    used.extend(bj.iter().copied());
                }
                match r.keys().next() {
                    Some(&c) => {
                        pivot_of.insert(c, basis.len());
                        basis.push((r, used));
                    }
                    None => {
                        let others: Vec<String> = used
                            .iter()
                            .filter(|&&i| i != j)
                            .map(|&i| format!("joints[{i}] ({})", self.describe_joint(i)))
                            .collect();
                        let field = match entry_line(&self.text, "joints", j) {
                            Some(l) => format!("joints[{j}] (line {l})"),
                            None => format!("joints[{j}]"),
                        };
                        return Err(self.err(
                            field,
                            format!(
                                "{} constrains what {} already fix{}: the joint equations are dependent (over-constrained, singular); remove or change one of them",
                                self.describe_joint(j),
                                others.join(" and "),
                                if others.len() == 1 { "es" } else { "" }
                            ),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    fn describe_joint(&self, i: usize) -> String {
        let node = |n: &NodeRef| match n {
            NodeRef::Index(k) => format!("node {k}"),
            NodeRef::Name(s) => format!("node \"{s}\""),
        };
        match &self.file.joints[i] {
            JointSpec::GroundPin { body, node: n, .. } => format!("ground_pin on `{body}` {}", node(n)),
            JointSpec::Clamp { body, node: n } => format!("clamp on `{body}` {}", node(n)),
            JointSpec::Pin { a, b } => format!("pin `{}` {} – `{}` {}", a.body, node(&a.node), b.body, node(&b.node)),
        }
    }

    fn params_from(&self, t: &TimeSettings) -> Result<IntegratorParams> {
        let mut p = IntegratorParams { rho_inf: t.rho_inf, ..IntegratorParams::default() };
        if !(t.rho_inf.is_finite() && (0.0..=1.0).contains(&t.rho_inf)) {
            return Err(self.err("time.rho_inf", format!("must lie in [0, 1], got {}", t.rho_inf)));
        }
        if let Some(tol) = t.newton_tolerance {
            self.positive("time.newton_tolerance", tol)?;
            p.tolerance = tol;
        }
        if let Some(x) = t.newton_stagnation {
            if !(x.is_finite() && x >= 0.0) {
                return Err(self.err("time.newton_stagnation", format!("must be zero or positive, got {x}")));
            }
            p.stagnation = x;
        }
        if let Some(m) = t.max_iterations {
            if m <= 0 {
                return Err(self.err("time.max_iterations", format!("must be a positive integer, got {m}")));
            }
            p.max_iterations = m as usize;
        }
        if let Some(m) = t.max_step_cuts {
            if !(0..=30).contains(&m) {
                return Err(self.err("time.max_step_cuts", format!("must be in 0..=30, got {m}")));
            }
            p.max_cuts = m as u32;
        }
        if let Some(x) = t.max_strain {
            self.positive("time.max_strain", x)?;
            p.max_strain = x;
        }
        if let Some(m) = t.max_total_step_cuts {
            if m < 0 {
                return Err(
                    self.err("time.max_total_step_cuts", format!("must be zero or a positive integer, got {m}"))
                );
            }
            p.max_total_cuts = usize::try_from(m).unwrap_or(usize::MAX);
        }
        if let Some(r) = &t.jacobian_reuse {
            p.reuse = match r.as_str() {
                "within-step" => JacobianReuse::WithinStep,
                "never" => JacobianReuse::Never,
                "across-steps" => JacobianReuse::AcrossSteps,
                _ => {
                    return Err(
                        self.err("time.jacobian_reuse", format!("must be \"within-step\", \"across-steps\" or \"never\", got \"{r}\""))
                    )
                }
            };
        }
        Ok(p)
    }

    /// Integrator parameters from the `[time]` table.
    /// SHA-256 of the model's canonical form: the parsed file as JSON, without the free
    /// `description`. Comments, layout, key order and number spelling do not change it;
    /// any change of geometry, material, mesh, joints, loads, probes or time settings does.
    pub fn fingerprint(&self) -> String {
        use sha2::{Digest, Sha256};
        let mut canonical = self.file.clone();
        canonical.description.clear();
        let json = serde_json::to_string(&canonical).expect("the schema serializes");
        Sha256::digest(json.as_bytes()).iter().map(|b| format!("{b:02x}")).collect()
    }

    pub fn integrator_params(&self) -> IntegratorParams {
        self.params_from(&self.file.time).expect("validated at load")
    }

    /// Builds the physical system with the given linear solver.
    pub fn system(&self, solver: LinearSolverKind) -> FlexibleSystem {
        let damping = self
            .file
            .damping
            .as_ref()
            .map_or(Rayleigh::default(), |d| Rayleigh { mass: d.mass, stiffness: d.stiffness });
        FlexibleSystem::new(self.bodies.clone(), &self.joints, &self.loads, self.probes.clone(), damping, solver)
    }

    /// The sizes of the system this model builds, from the file alone (nothing is
    /// assembled), as floats so that estimates from them cannot overflow.
    pub fn sizes(&self) -> Sizes {
        let n_elements: f64 = self.bodies.iter().map(|b| b.n_elements as f64).sum();
        let n_dof = 4.0 * self.bodies.iter().map(|b| b.n_elements as f64 + 1.0).sum::<f64>();
        let n_constraints = self.joints.iter().map(|j| if matches!(j, Joint::Clamp { .. }) { 4.0 } else { 2.0 }).sum();
        Sizes { n_dof, n_constraints, n_elements, n_probes: self.probes.len() as f64 }
    }

    /// Refuses a full run of `n_steps` whose arrays (plus, with `dense`, the dense LU of
    /// the KKT matrix) would not fit the memory bound ([`crate::limits`]).
    pub fn check_full_run_memory(&self, n_steps: usize, dense: bool) -> Result<()> {
        let z = self.sizes();
        let nt = n_steps as f64 + 1.0;
        let arrays = 8.0 * nt * (z.n_dof + z.n_constraints + 2.0 * z.n_probes + 1.0);
        let system = z.n_elements * crate::limits::BYTES_PER_ELEMENT;
        let n_kkt = z.n_dof + z.n_constraints;
        let lu = if dense { 2.0 * 8.0 * n_kkt * n_kkt } else { 0.0 };
        let what = format!(
            "a full run of {} steps × {} coordinates{}",
            n_steps,
            z.n_dof,
            if dense { format!(" with a dense {n_kkt} × {n_kkt} LU") } else { String::new() }
        );
        crate::limits::check_memory(&what, arrays + system + lu)
    }

    pub fn probe_names(&self) -> Vec<String> {
        self.probes.iter().map(|p| p.name.clone()).collect()
    }

    fn positive(&self, field: &str, v: f64) -> Result<()> {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(self.err(field, format!("must be positive and finite, got {v}")))
        }
    }

    fn finite(&self, field: &str, v: f64) -> Result<()> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(self.err(field, format!("must be finite, got {v}")))
        }
    }

    fn finite2(&self, field: &str, v: [f64; 2]) -> Result<()> {
        if v.iter().all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(self.err(field, format!("must be finite, got {v:?}")))
        }
    }

    fn body_index(&self, field: &str, name: &str) -> Result<usize> {
        self.bodies.iter().position(|b| b.name == name).ok_or_else(|| {
            let names: Vec<_> = self.bodies.iter().map(|b| b.name.as_str()).collect();
            self.err(field, format!("no body named `{name}` (bodies: {})", names.join(", ")))
        })
    }

    fn node_id(&self, body_field: &str, node_field: &str, body: &str, node: &NodeRef) -> Result<NodeId> {
        let b = self.body_index(body_field, body)?;
        let n = self.bodies[b].n_elements;
        let k = match node {
            NodeRef::Index(k) if (0..=n as i64).contains(k) => *k as usize,
            NodeRef::Index(k) => {
                return Err(self.err(node_field, format!("node {k} is outside body `{body}` (nodes 0..={n})")))
            }
            NodeRef::Name(s) if s == "start" => 0,
            NodeRef::Name(s) if s == "end" => n,
            NodeRef::Name(s) => {
                return Err(
                    self.err(node_field, format!("`{s}` is not a node: use an index 0..={n}, \"start\" or \"end\""))
                )
            }
        };
        Ok((b, k))
    }
}

/// The entry of an array of tables (`[[bodies]]`, `[[joints]]`, `[[loads]]`, `[[probes]]`)
/// that fails to parse, with the key at fault and its line: serde reports errors inside
/// internally tagged or untagged entries against the whole entry, so each entry is parsed
/// on its own, and the key at fault is the one whose removal changes the error (the
/// `type` tag last: removing it always does). `None` when every entry parses by itself.
fn entry_error(text: &str, path: &Path) -> Option<Error> {
    fn first_error<T: serde::de::DeserializeOwned>(v: &toml::Value) -> Option<String> {
        v.clone().try_into::<T>().err().map(|e| e.message().to_string())
    }
    let doc: toml::Table = toml::from_str(text).ok()?;
    type FirstError = fn(&toml::Value) -> Option<String>;
    let kinds: [(&str, FirstError); 4] = [
        ("bodies", first_error::<BodySpec>),
        ("joints", first_error::<JointSpec>),
        ("loads", first_error::<LoadSpec>),
        ("probes", first_error::<ProbeSpec>),
    ];
    for (name, parse) in kinds {
        let Some(toml::Value::Array(items)) = doc.get(name) else { continue };
        for (i, item) in items.iter().enumerate() {
            let Some(message) = parse(item) else { continue };
            let key = item.as_table().and_then(|t| {
                let changes = |k: &String| {
                    let mut rest = t.clone();
                    rest.remove(k);
                    parse(&toml::Value::Table(rest)).as_deref() != Some(message.as_str())
                };
                t.keys()
                    .filter(|k| k.as_str() != "type")
                    .find(|k| changes(k))
                    .or_else(|| t.keys().find(|k| changes(k)))
                    .cloned()
            });
            let line =
                entry_line(text, name, i).map(|l| key.as_deref().and_then(|k| key_line(text, l, k)).unwrap_or(l));
            let field = match (&key, line) {
                (Some(k), Some(l)) => format!("{name}[{i}].{k} (line {l})"),
                (Some(k), None) => format!("{name}[{i}].{k}"),
                (None, Some(l)) => format!("{name}[{i}] (line {l})"),
                (None, None) => format!("{name}[{i}]"),
            };
            return Some(Error::input(path, field, message));
        }
    }
    None
}

/// The line (1-based) of the `[[name]]` header of entry `i`, if written that way.
fn entry_line(text: &str, name: &str, i: usize) -> Option<usize> {
    let is_header =
        |l: &str| l.trim().strip_prefix("[[").and_then(|r| r.split("]]").next()).is_some_and(|n| n.trim() == name);
    text.lines().enumerate().filter(|(_, l)| is_header(l)).nth(i).map(|(k, _)| k + 1)
}

/// The line of `key = …` in the table whose header is on line `header`.
fn key_line(text: &str, header: usize, key: &str) -> Option<usize> {
    for (k, l) in text.lines().enumerate().skip(header) {
        let l = l.trim();
        if l.starts_with('[') {
            return None;
        }
        let lhs = l.split('=').next().unwrap_or("").trim().trim_matches('"');
        if l.contains('=') && (lhs == key || lhs.starts_with(&format!("{key}."))) {
            return Some(k + 1);
        }
    }
    None
}

/// The dotted key path (or line) at byte `pos` of a TOML text, for error messages.
/// Parses a TOML file into its schema; an error names the file, the field path (with its
/// line) and the problem. Shared by model and pipeline files.
pub(crate) fn parse_toml<T: serde::de::DeserializeOwned>(text: &str, path: &Path) -> Result<T> {
    toml::from_str(text).map_err(|e| {
        let field = e.span().map(|s| locate(text, s.start)).unwrap_or_else(|| "(file)".into());
        Error::input(path, field, e.message().to_string())
    })
}

fn locate(text: &str, pos: usize) -> String {
    // counted on bytes: a span that is not on a char boundary must not panic
    let line = text.as_bytes()[..pos.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1;
    let mut table = String::new();
    let mut counts: std::collections::HashMap<String, usize> = Default::default();
    for l in text.lines().take(line) {
        let l = l.trim();
        if let Some(name) = l.strip_prefix("[[").and_then(|r| r.strip_suffix("]]")) {
            let c = counts.entry(name.to_string()).or_insert(0);
            table = format!("{name}[{}]", *c);
            *c += 1;
        } else if let Some(name) = l.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
            table = name.to_string();
        }
    }
    let this = text.lines().nth(line - 1).unwrap_or("");
    let key = this.split('=').next().unwrap_or("").trim();
    let key = if this.contains('=') && !key.is_empty() { key } else { "" };
    match (table.is_empty(), key.is_empty()) {
        (true, true) => format!("line {line}"),
        (true, false) => format!("{key} (line {line})"),
        (false, true) => format!("{table} (line {line})"),
        (false, false) => format!("{table}.{key} (line {line})"),
    }
}
