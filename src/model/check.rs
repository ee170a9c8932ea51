//! The checks of a model file beyond its syntax: every field in range, names and nodes that
//! exist, joints that close and whose constraint rows are independent, time settings that
//! make a run; the validated bodies, joints, loads and probes are kept on the [`Model`].

mod springs;
mod value_parameters;

use super::schema::*;
use super::toml_errors::entry_line;
use super::Model;
use crate::error::Result;
use crate::physics::element::Section;
use crate::physics::joints::{Clamp, Drive, DrivenAngle, DrivenPoint, GroundPin, Joint, Pin, Slider, Weld};
use crate::physics::loads::{Force, Gravity, Load, Moment};
use crate::physics::masses::PointMass;
use crate::physics::system::{BeamBody, NodeId, Probe};
use crate::physics::time_function::TimeFunction;
use crate::solver::generalized_alpha::{IntegratorParams, JacobianReuse, Predictor};
use crate::solver::parameters::{Scaling, LOAD_SCALE};

/// A body property that may be a parameter.
#[derive(Clone, Copy)]
enum Property {
    YoungsModulus,
    Density,
}

impl Property {
    fn key(self) -> &'static str {
        match self {
            Property::YoungsModulus => "youngs_modulus",
            Property::Density => "density",
        }
    }

    fn other(self) -> Property {
        match self {
            Property::YoungsModulus => Property::Density,
            Property::Density => Property::YoungsModulus,
        }
    }

    fn of(self, body: &BodySpec) -> &PropertySpec {
        match self {
            Property::YoungsModulus => &body.youngs_modulus,
            Property::Density => &body.density,
        }
    }
}

/// Relative tolerance for a joint to count as closed in the initial configuration.
const CLOSURE_TOL: f64 = 1e-6;

/// A node's position in the undeformed configuration.
fn node_position(bodies: &[BeamBody], (b, k): NodeId) -> [f64; 2] {
    let r = bodies[b].undeformed_node(k);
    [r[0], r[1]]
}

impl Model {
    pub(super) fn check(&mut self) -> Result<()> {
        let f = self.file.clone();
        self.check_time(&f)?;
        if f.bodies.is_empty() {
            return Err(self.err("bodies", "a model needs at least one body"));
        }
        for i in 0..f.bodies.len() {
            let body = self.checked_body(&f, i)?;
            self.bodies.push(body);
        }
        let lmax = self.bodies.iter().map(|b| b.length).fold(0.0, f64::max);
        for (i, j) in f.joints.iter().enumerate() {
            let joint = self.checked_joint(i, j, lmax)?;
            self.joints.push(joint);
        }
        self.check_joint_rank()?;
        self.check_initial_velocities()?;
        for (i, l) in f.loads.iter().enumerate() {
            let load = self.checked_load(i, l)?;
            self.loads.push(load);
        }
        for (i, m) in f.masses.iter().enumerate() {
            let mass = self.checked_mass(i, m)?;
            self.masses.push(mass);
        }
        self.check_springs(&f.springs)?;
        for i in 0..f.probes.len() {
            let probe = self.checked_probe(&f, i)?;
            self.probes.push(probe);
        }
        Ok(())
    }

    /// The `[time]` settings (step within the end time, the integrator's parameters) and
    /// the Rayleigh damping's coefficients.
    fn check_time(&self, f: &ModelFile) -> Result<()> {
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
        Ok(())
    }

    /// `bodies[i]`, checked against the bodies before it (its name unique, the element count
    /// within the limits): the beam body it gives.
    fn checked_body(&self, f: &ModelFile, i: usize) -> Result<BeamBody> {
        let b = &f.bodies[i];
        let p = |k: &str| format!("bodies[{i}].{k}");
        if b.name.trim().is_empty() {
            return Err(self.err(p("name"), "must not be empty"));
        }
        if b.name.chars().any(char::is_control) {
            // the result files' labels store it as HDF5 text, which ends at a NUL
            return Err(self.err(
                p("name"),
                format!("`{}` holds a control character (a NUL, a newline, …): names are written into the result files' labels", crate::error::show_text(&b.name)),
            ));
        }
        if f.bodies[..i].iter().any(|o| o.name == b.name) {
            return Err(self.err(p("name"), format!("body `{}` is defined twice", b.name)));
        }
        self.finite2(&p("start"), b.start)?;
        if b.elements <= 0 {
            return Err(self.err(p("elements"), format!("must be a positive integer, got {}", b.elements)));
        }
        let total: f64 = f.bodies[..=i].iter().map(|b| b.elements.max(0) as f64).sum();
        self.limits.check_elements(total).map_err(|e| self.err(p("elements"), e.problem_text()))?;
        // a property given as `{ value, parameter }` names its `value`
        let property = |k: &str, spec: &PropertySpec| match spec {
            PropertySpec::Value(v) => (k.to_string(), *v),
            PropertySpec::Parameter(x) => (format!("{k}.value"), x.value),
        };
        for (k, v) in [
            property("density", &b.density),
            ("area".into(), b.area),
            ("inertia".into(), b.inertia),
            property("youngs_modulus", &b.youngs_modulus),
        ] {
            self.positive(&p(&k), v)?;
        }
        let youngs_modulus_parameter = self.checked_property_parameter(f, i, Property::YoungsModulus)?;
        let density_parameter = self.checked_property_parameter(f, i, Property::Density)?;
        let (angle, length) = self.body_angle_and_length(b, i)?;
        Ok(BeamBody {
            name: b.name.clone(),
            start: b.start,
            angle,
            length,
            n_elements: b.elements as usize,
            section: Section {
                density: b.density.value(),
                area: b.area,
                inertia: b.inertia,
                youngs_modulus: b.youngs_modulus.value(),
            },
            youngs_modulus_parameter,
            density_parameter,
            velocity: match b.velocity {
                Some(v) => {
                    self.finite2(&p("velocity"), v)?;
                    v
                }
                None => [0.0; 2],
            },
            angular_velocity: match b.angular_velocity {
                Some(w) => {
                    self.finite(&p("angular_velocity"), w)?;
                    w
                }
                None => 0.0,
            },
        })
    }

    /// A body's direction and length, from `angle` and `length` or from `end` (a `length`
    /// given beside `end` must agree with it).
    fn body_angle_and_length(&self, b: &BodySpec, i: usize) -> Result<(f64, f64)> {
        let p = |k: &str| format!("bodies[{i}].{k}");
        match (b.angle, b.end) {
            (Some(_), Some(_)) => Err(self.err(p("end"), "give either `angle` or `end`, not both")),
            (None, None) => Err(self.err(p("angle"), "missing: give `angle` (rad) with `length`, or `end`")),
            (Some(a), None) => {
                self.finite(&p("angle"), a)?;
                let l = b.length.ok_or_else(|| self.err(p("length"), "missing (required with `angle`)"))?;
                self.positive(&p("length"), l)?;
                Ok((a, l))
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
                Ok((dy.atan2(dx), l))
            }
        }
    }

    /// `joints[i]` on the checked bodies: its nodes exist and, for the joints that hold two
    /// points together, start closed (within `CLOSURE_TOL` of the longest body `lmax`).
    fn checked_joint(&self, i: usize, j: &JointSpec, lmax: f64) -> Result<Joint> {
        let p = |k: &str| format!("joints[{i}].{k}");
        let node_pos = |id: NodeId| node_position(&self.bodies, id);
        Ok(match j {
            JointSpec::GroundPin { body, node, point } => {
                let id = self.node_id(&p("body"), &p("node"), body, node)?;
                let at = node_pos(id);
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
                Joint::GroundPin(GroundPin { node: id, point })
            }
            JointSpec::Pin { a, b } => {
                let (ia, ib) = self.closed_node_pair(i, a, b, "pin", lmax)?;
                Joint::Pin(Pin { a: ia, b: ib })
            }
            JointSpec::Clamp { body, node } => {
                let id = self.node_id(&p("body"), &p("node"), body, node)?;
                let bd = &self.bodies[id.0];
                Joint::Clamp(Clamp { node: id, point: node_pos(id), slope: [bd.angle.cos(), bd.angle.sin()] })
            }
            JointSpec::Slider { body, node, direction, lock_rotation } => {
                let id = self.node_id(&p("body"), &p("node"), body, node)?;
                self.finite2(&p("direction"), *direction)?;
                if direction[0].hypot(direction[1]) == 0.0 {
                    return Err(self.err(p("direction"), "has zero length; give the line's direction, e.g. [1.0, 0.0]"));
                }
                let angle = self.bodies[id.0].angle;
                Joint::Slider(Slider {
                    node: id,
                    point: node_pos(id),
                    direction: *direction,
                    locked_slope: lock_rotation.then(|| [angle.cos(), angle.sin()]),
                })
            }
            JointSpec::Weld { a, b } => {
                let (ia, ib) = self.closed_node_pair(i, a, b, "weld", lmax)?;
                Joint::Weld(Weld { a: ia, b: ib, angle: self.bodies[ib.0].angle - self.bodies[ia.0].angle })
            }
            JointSpec::DrivenAngle { body, node, function, scaled } => {
                let id = self.node_id(&p("body"), &p("node"), body, node)?;
                let drive = self.drive(&p("function"), Some(function), &p("scaled"), scaled)?;
                Joint::DrivenAngle(DrivenAngle { node: id, theta0: self.bodies[id.0].angle, drive })
            }
            JointSpec::DrivenPoint { body, node, x, y, scaled } => {
                let id = self.node_id(&p("body"), &p("node"), body, node)?;
                let path = [
                    self.drive(&p("x"), x.as_ref(), &p("scaled"), scaled)?,
                    self.drive(&p("y"), y.as_ref(), &p("scaled"), scaled)?,
                ];
                Joint::DrivenPoint(DrivenPoint { node: id, point: node_pos(id), path })
            }
        })
    }

    /// The nodes `a` and `b` of the pin or weld `joints[i]` (`kind`): on two different bodies,
    /// and starting at one point.
    fn closed_node_pair(
        &self,
        i: usize,
        a: &NodeSpec,
        b: &NodeSpec,
        kind: &str,
        lmax: f64,
    ) -> Result<(NodeId, NodeId)> {
        let p = |k: &str| format!("joints[{i}].{k}");
        let ia = self.node_id(&p("a.body"), &p("a.node"), &a.body, &a.node)?;
        let ib = self.node_id(&p("b.body"), &p("b.node"), &b.body, &b.node)?;
        if ia.0 == ib.0 {
            return Err(self.err(p("b.body"), format!("a {kind} joins two different bodies")));
        }
        let (pa, pb) = (node_position(&self.bodies, ia), node_position(&self.bodies, ib));
        let gap = (pa[0] - pb[0]).hypot(pa[1] - pb[1]);
        if gap > CLOSURE_TOL * lmax {
            return Err(self.err(p("b"), format!("the two nodes start {gap:.3e} m apart ({pa:?} and {pb:?}); the initial configuration must satisfy every joint")));
        }
        Ok((ia, ib))
    }

    /// `loads[i]` on the checked bodies.
    fn checked_load(&self, i: usize, l: &LoadSpec) -> Result<Load> {
        let p = |k: &str| format!("loads[{i}].{k}");
        Ok(match l {
            LoadSpec::Gravity { g, scaled } => {
                self.finite2(&p("g"), *g)?;
                Load::Gravity(Gravity { g: *g, scaled: self.scaling(&p("scaled"), scaled)? })
            }
            LoadSpec::Moment { body, node, function, scaled } => {
                let id = self.node_id(&p("body"), &p("node"), body, node)?;
                function.check().map_err(|e| self.err(p("function"), e.problem()))?;
                Load::Moment(Moment {
                    node: id,
                    function: function.clone(),
                    scaled: self.scaling(&p("scaled"), scaled)?,
                })
            }
            LoadSpec::Force { body, node, value, function, scaled } => {
                let id = self.node_id(&p("body"), &p("node"), body, node)?;
                self.finite2(&p("value"), *value)?;
                if let Some(func) = function {
                    func.check().map_err(|e| self.err(p("function"), e.problem()))?;
                }
                let scaled = self.scaling(&p("scaled"), scaled)?;
                Load::Force(Force { node: id, value: *value, function: function.clone(), scaled })
            }
        })
    }

    /// `masses[i]`: a point mass on a node, its mass (maybe a parameter) positive, its rotary
    /// inertia finite and non-negative.
    fn checked_mass(&self, i: usize, m: &MassSpec) -> Result<PointMass> {
        let p = |k: &str| format!("masses[{i}].{k}");
        let node = self.node_id(&p("body"), &p("node"), &m.body, &m.node)?;
        self.positive(&p("mass"), m.mass.value())?;
        let parameter = self.value_parameter(&p("mass"), &m.mass, value_parameters::ValueKind::PointMass)?;
        let rotary_inertia = m.rotary_inertia.unwrap_or(0.0);
        if !(rotary_inertia.is_finite() && rotary_inertia >= 0.0) {
            let msg = format!("must be finite and ≥ 0 (kg m²), got {rotary_inertia}");
            return Err(self.err(p("rotary_inertia"), msg));
        }
        Ok(PointMass { node, mass: m.mass.value(), rotary_inertia, parameter: parameter.map(|p| p.0) })
    }

    /// `probes[i]`: a unique name fit for an HDF5 dataset, and the element and local
    /// coordinate ξ of its point (a node, or a fraction `at` of its body's length).
    fn checked_probe(&self, f: &ModelFile, i: usize) -> Result<Probe> {
        let pr = &f.probes[i];
        let p = |k: &str| format!("probes[{i}].{k}");
        if f.probes[..i].iter().any(|o| o.name == pr.name) {
            return Err(self.err(p("name"), format!("probe `{}` is defined twice", pr.name)));
        }
        if pr.name.is_empty() || pr.name.contains('/') || pr.name.chars().any(char::is_control) {
            return Err(self.err(
                p("name"),
                "must be non-empty and contain no `/` and no control character (a NUL, a newline, …): it names an HDF5 dataset",
            ));
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
        let asks = |q: ProbeQuantity| pr.quantities.as_ref().is_some_and(|l| l.contains(&q));
        Ok(Probe {
            name: pr.name.clone(),
            element,
            xi,
            strain: asks(ProbeQuantity::Strain),
            curvature: asks(ProbeQuantity::Curvature),
        })
    }

    /// Refuses joints whose constraint rows `B` (as each joint kind builds them) are
    /// linearly dependent (a node pinned twice, a clamp plus a pin on its node, a loop of
    /// pins closing on one point): the KKT matrix is then singular. Elimination row by row in
    /// joint order (entries of B are ±1 or direction cosines: a row that reduces below 1e-9 is
    /// dependent); each row keeps the set of joints it was combined from, so a row that
    /// reduces to zero names exactly the joints whose constraints it repeats.
    fn check_joint_rank(&self) -> Result<()> {
        use std::collections::{BTreeMap, BTreeSet, HashMap};
        let mut first = Vec::with_capacity(self.bodies.len());
        let mut n = 0;
        for b in &self.bodies {
            first.push(n);
            n += b.n_elements + 1;
        }
        let g = |(b, k): NodeId| 4 * (first[b] + k);
        // reduced rows with their pivot column and the joints they combine
        let mut basis: Vec<(BTreeMap<usize, f64>, BTreeSet<usize>)> = Vec::new();
        let mut pivot_of: HashMap<usize, usize> = HashMap::new();
        for (j, joint) in self.joints.iter().enumerate() {
            for row in joint.kind().rows(&g) {
                let mut r: BTreeMap<usize, f64> = row.terms.into_iter().collect();
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

    /// Refuses initial velocities that move a joint: every row must hold at the velocity
    /// level, `B q̇₀ = ḃ` (0 for today's joints), at the undeformed configuration. The bound
    /// is relative to the fastest point of the bodies (round-off of `ω × r`).
    fn check_initial_velocities(&self) -> Result<()> {
        let mut first = Vec::with_capacity(self.bodies.len());
        let mut v0 = Vec::new();
        for b in &self.bodies {
            first.push(v0.len());
            for k in 0..=b.n_elements {
                v0.extend(b.rigid_velocity(b.undeformed_node(k)));
            }
        }
        let speed = v0.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if speed == 0.0 {
            return Ok(());
        }
        let g = |(b, k): NodeId| first[b] + 4 * k;
        for (j, joint) in self.joints.iter().enumerate() {
            // a prescribed motion sets its own rate (its factor is a run's: checked when it starts)
            for row in joint.kind().rows(&g).into_iter().filter(|r| r.motion.is_none()) {
                let rate: f64 = row.terms.iter().map(|&(d, c)| c * v0[d]).sum();
                if rate.abs() > 1e-9 * speed {
                    let field = match entry_line(&self.text, "joints", j) {
                        Some(l) => format!("joints[{j}] (line {l})"),
                        None => format!("joints[{j}]"),
                    };
                    let unit = if row.kind == crate::physics::joints::RowKind::Position { "m/s" } else { "1/s" };
                    return Err(self.err(
                        field,
                        format!(
                            "the bodies' initial velocities move {} ({} changes at {rate:.3e} {unit}); give `velocity` and `angular_velocity` the joints allow",
                            self.describe_joint(j),
                            row.component
                        ),
                    ));
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
            JointSpec::Slider { body, node: n, .. } => format!("slider on `{body}` {}", node(n)),
            JointSpec::Weld { a, b } => format!("weld `{}` {} – `{}` {}", a.body, node(&a.node), b.body, node(&b.node)),
            JointSpec::DrivenAngle { body, node: n, .. } => format!("driven_angle on `{body}` {}", node(n)),
            JointSpec::DrivenPoint { body, node: n, .. } => format!("driven_point on `{body}` {}", node(n)),
        }
    }

    pub(super) fn params_from(&self, t: &TimeSettings) -> Result<IntegratorParams> {
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
                    return Err(self.err(
                        "time.jacobian_reuse",
                        format!("must be \"within-step\", \"across-steps\" or \"never\", got \"{r}\""),
                    ))
                }
            };
        }
        if let Some(r) = &t.predictor {
            p.predictor = Predictor::from_name(r).ok_or_else(|| {
                let names: Vec<String> = Predictor::ALL.iter().map(|p| format!("\"{}\"", p.name())).collect();
                let (last, rest) = names.split_last().expect("four starts");
                self.err("time.predictor", format!("must be {} or {last}, got \"{r}\"", rest.join(", ")))
            })?;
        }
        Ok(p)
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

    /// The parameter that body `i`'s `youngs_modulus` or `density = { value, parameter }`
    /// names, if any: a parameter name that no load scales (a load's parameter is a factor,
    /// a property's its value) and no other kind of property takes, the same value wherever
    /// bodies share it (Rayleigh damping `a M(ρ) + b K(E)` follows both properties).
    fn checked_property_parameter(&self, f: &ModelFile, i: usize, which: Property) -> Result<Option<String>> {
        let key = which.key();
        let field = format!("bodies[{i}].{key}.parameter");
        let Some(name) = which.of(&f.bodies[i]).parameter() else { return Ok(None) };
        self.value_parameter_name(&field, name)?;
        let value = which.of(&f.bodies[i]).value();
        if let Some(other) = f.bodies[..i].iter().find(|o| which.of(o).parameter() == Some(name)) {
            if which.of(other).value() != value {
                return Err(self.err(
                    format!("bodies[{i}].{key}.value"),
                    format!(
                        "is {value}, but body `{}` gives the parameter `{name}` the value {}: a parameter has one value",
                        other.name,
                        which.of(other).value()
                    ),
                ));
            }
        }
        let other_kind = which.other();
        if let Some(other) = f.bodies.iter().find(|o| other_kind.of(o).parameter() == Some(name)) {
            return Err(self.err(
                field,
                format!(
                    "`{name}` is also body `{}`'s {}: give the two properties different names",
                    other.name,
                    other_kind.key()
                ),
            ));
        }
        if let Some((k, _)) = f.loads.iter().enumerate().find(|(_, l)| l.scaled_parameter() == Some(name)) {
            return Err(self.err(
                field,
                format!("`{name}` also scales loads[{k}]: a load's parameter multiplies it, a {key} parameter is its value; give them different names"),
            ));
        }
        Ok(Some(name.to_string()))
    }

    /// `scaled = true | false | "name"`; a name is a parameter's: letters, digits and `_`,
    /// not starting with a digit (it becomes `--param name=…` and an HDF5 attribute).
    /// A prescribed motion's function (none: 0) checked, and starting at 0: the model's
    /// initial configuration is where every drive starts.
    fn drive(
        &self,
        field: &str,
        function: Option<&TimeFunction>,
        scaled_field: &str,
        scaled: &ScaledSpec,
    ) -> Result<Drive> {
        let function = function.cloned().unwrap_or(TimeFunction::Constant { value: 0.0 });
        function.check().map_err(|e| self.err(field, e.problem()))?;
        let start = function.eval(0.0);
        if start != 0.0 {
            return Err(self.err(
                field,
                format!(
                    "is {start} at t = 0; a prescribed motion starts where the model places the node (shift the function so that it starts at 0)"
                ),
            ));
        }
        Ok(Drive { function, scaled: self.scaling(scaled_field, scaled)? })
    }

    fn scaling(&self, field: &str, spec: &ScaledSpec) -> Result<Scaling> {
        match spec {
            ScaledSpec::Flag(false) => Ok(Scaling::Fixed),
            ScaledSpec::Flag(true) => Ok(Scaling::LoadScale),
            ScaledSpec::Parameter(name) if name == LOAD_SCALE => Ok(Scaling::LoadScale),
            // a quoted flag would silently become a parameter named "true"
            ScaledSpec::Parameter(name) if matches!(name.to_ascii_lowercase().as_str(), "true" | "false") => Err(self
                .err(
                    field,
                    format!(
                        "is the string \"{name}\"; write {} without quotes (or a parameter's name)",
                        name.to_ascii_lowercase()
                    ),
                )),
            ScaledSpec::Parameter(name) => {
                if self.is_body_property(name) {
                    Err(self.err(
                        field,
                        format!("`{name}` is a body's Young's modulus or density: a parameter here multiplies, a property's is its value; give them different names"),
                    ))
                } else if crate::solver::parameters::is_parameter_name(name) {
                    Ok(Scaling::Named(name.clone()))
                } else {
                    Err(self.err(
                        field,
                        format!("`{name}` is not a parameter name: use letters, digits and `_`, starting with a letter (or true / false)"),
                    ))
                }
            }
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
