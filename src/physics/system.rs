//! A planar flexible multibody system: straight ANCF beams meshed into equal elements,
//! linear joints on nodal coordinates (the rows of [`super::joints::lower`]), external
//! loads. Implements [`ParametricModel`]: the load scale is an argument of each evaluation
//! ([`Parameters`]), not part of the system.
//!
//! Coordinates: node `k` (numbered body after body) owns `q[4k..4k+4] = (x, y, x', y')`.

use super::element::{BeamElement, Mat8, Vec8};
use super::joints::{lower, Row};
use super::loads::{assemble_weight, Gravity, Load, NodalLoad, Weight};
use super::masses::{MassEntry, PointMass};
use crate::error::{Error, Result};
use crate::linalg::kkt::{make_solver, KktPattern, KktSolver, LinearSolverKind};
use crate::solver::model::{IterationCoefficients, Parameters, ParametricModel};

pub use super::joints::Joint;
pub use super::parts::{BeamBody, Constraint, NodeId, Probe, Rayleigh};

mod models;

/// The most terms a moving row has (a turning slope row: two).
const MOVING_TERMS: usize = 2;

pub struct FlexibleSystem {
    pub bodies: Vec<BeamBody>,
    /// first node of each body
    first_node: Vec<usize>,
    /// element → (body, dofs)
    elements: Vec<(usize, [usize; 8])>,
    /// one element prototype per body, at the model file's values
    prototypes: Vec<BeamElement>,
    /// one element prototype per body at the parameters of the last evaluation (the
    /// bodies' Young's moduli and densities)
    bound: Vec<BeamElement>,
    /// every constraint row's coefficients and right-hand side at the start (t = 0, where
    /// a prescribed motion has not moved: the model checks its functions start at 0)
    pub constraints: Vec<Constraint>,
    /// the rows that move with time, each with its index in `constraints`
    moving: Vec<(usize, Row)>,
    pub probes: Vec<Probe>,
    damping: Rayleigh,
    /// the weight of the bodies, in parts by what multiplies it ([`super::loads::Gravity`])
    weight: Weight,
    /// the loads on a few coordinates (moments, nodal forces), in file order
    nodal: Vec<Box<dyn NodalLoad>>,
    /// per nodal load with a Jacobian, the iteration block that holds it and that block's
    /// dofs: an element's, or a coupling block's (`coupling`)
    nodal_blocks: Vec<Option<(usize, [usize; 8])>>,
    /// the blocks of the iteration matrix after the elements' (numbered from
    /// `elements.len()`): the coordinates of two nodes no element holds together, which a
    /// spring couples
    coupling: Vec<[usize; 8]>,
    /// whether every nodal load's Jacobian is symmetric to the bit (no damper)
    symmetric_loads: bool,
    /// whether some nodal load depends on the velocities (a damper)
    load_damping: bool,
    /// point masses' mass-matrix entries `(row, column, value)` (the position diagonal and
    /// any rotary inertia's slope block), each with the element whose iteration block holds
    /// the node (its first dof); the values at the parameters last bound
    point_masses: Vec<(MassEntry, (usize, usize))>,
    /// the entries a parameter sets (a point mass's `mass = { value, parameter }`): (entry,
    /// the parameter, the file's kg)
    point_mass_parameters: Vec<(usize, String, f64)>,
    /// the dofs the nodal loads act on, sorted
    load_dofs: Vec<usize>,
    n_dof: usize,
    kkt: Box<dyn KktSolver>,
    blocks: Vec<Mat8>,
    /// per body: the constant part `m M + c C + k K_t` of the iteration blocks for the
    /// coefficients `iteration_coef` (recomputed when the integrator changes them)
    iteration_constant: Vec<Mat8>,
    iteration_coef: Option<IterationCoefficients>,
    length_scale: f64,
}

impl FlexibleSystem {
    /// Builds the system. Indices in joints, loads and probes must be valid (the model-file
    /// layer checks them and reports errors against the file).
    pub fn new(
        bodies: Vec<BeamBody>,
        joints: &[Joint],
        loads: &[Load],
        masses: &[PointMass],
        probes: Vec<Probe>,
        damping: Rayleigh,
        solver: LinearSolverKind,
    ) -> Self {
        let mut first_node = Vec::new();
        let mut elements = Vec::new();
        let mut prototypes = Vec::new();
        let mut node = 0;
        for (b, body) in bodies.iter().enumerate() {
            first_node.push(node);
            prototypes.push(BeamElement::new(body.length / body.n_elements as f64, body.section));
            for k in 0..body.n_elements {
                // 8 consecutive dofs: the residual's loop reads an element's as one slice
                let d0 = 4 * (node + k);
                elements.push((b, std::array::from_fn(|i| d0 + i)));
            }
            node += body.n_elements + 1;
        }
        let n_dof = 4 * node;
        let gnode = |(b, k): NodeId| first_node[b] + k;

        let first = |id: NodeId| 4 * gnode(id);
        let rows: Vec<Row> = lower(joints, &first).into_iter().map(|(_, row)| row).collect();
        let constraints: Vec<Constraint> =
            rows.iter().map(|row| Constraint { terms: row.terms.clone(), rhs: row.rhs }).collect();
        let moving: Vec<(usize, Row)> = rows.into_iter().enumerate().filter(|(_, r)| r.motion.is_some()).collect();
        debug_assert!(moving.iter().all(|(_, r)| r.terms.len() <= MOVING_TERMS));

        let gravities: Vec<&Gravity> =
            loads.iter().filter_map(|l| if let Load::Gravity(g) = l { Some(g) } else { None }).collect();
        let (mut point_masses, mut point_mass_parameters) = (Vec::new(), Vec::new());
        for m in masses {
            let d = first(m.node);
            // a node's four coordinates lie in an element of its
            let e = block_holding(&elements, &[d, d + 3]).expect("a node of the mesh");
            let block = (e, elements[e].1[0]);
            if let Some(name) = &m.parameter {
                // the two position entries come first (PointMass::entries)
                let k = point_masses.len();
                point_mass_parameters.extend([k, k + 1].map(|k| (k, name.clone(), m.mass)));
            }
            point_masses.extend(m.entries(&first, bodies[m.node.0].angle).into_iter().map(|x| (x, block)));
        }
        let lumped: Vec<_> = masses.iter().map(|m| m.lower(&first)).collect();
        let weight = assemble_weight(&gravities, &bodies, &elements, &prototypes, &lumped, n_dof);
        let nodal: Vec<Box<dyn NodalLoad>> = loads.iter().filter_map(|l| l.lower(&first)).collect();
        let mut coupling = Vec::new();
        let nodal_blocks = nodal
            .iter()
            .map(|l| (l.has_stiffness() || l.has_damping()).then(|| load_block(&elements, &mut coupling, l.dofs())))
            .collect();
        let symmetric_loads = nodal.iter().all(|l| l.symmetric());
        let load_damping = nodal.iter().any(|l| l.has_damping());
        let pattern = KktPattern {
            n_dof,
            element_dofs: elements.iter().map(|(_, d)| *d).chain(coupling.iter().copied()).collect(),
            constraint_rows: constraints.iter().map(|c| c.terms.clone()).collect(),
        };
        let length_scale = bodies.iter().map(|b| b.length).fold(0.0, f64::max);
        let n_blocks = elements.len() + coupling.len();
        let mut load_dofs: Vec<usize> = nodal.iter().flat_map(|l| l.dofs().iter().copied()).collect();
        load_dofs.sort_unstable();
        load_dofs.dedup();
        FlexibleSystem {
            bodies,
            first_node,
            elements,
            prototypes: prototypes.clone(),
            constraints,
            moving,
            probes,
            damping,
            weight,
            nodal,
            nodal_blocks,
            coupling,
            symmetric_loads,
            load_damping,
            point_masses,
            point_mass_parameters,
            load_dofs,
            n_dof,
            bound: prototypes.clone(),
            kkt: make_solver(solver, pattern),
            blocks: vec![Mat8::zeros(); n_blocks],
            iteration_constant: Vec::new(),
            iteration_coef: None,
            length_scale,
        }
    }

    pub fn n_elements(&self) -> usize {
        self.elements.len()
    }

    /// Global dof indices of element `e`.
    pub fn element_dofs(&self, e: usize) -> &[usize; 8] {
        &self.elements[e].1
    }

    /// The element object (constant matrices, force, tangent) of element `e`, at the
    /// model file's values.
    pub fn element(&self, e: usize) -> &BeamElement {
        &self.prototypes[self.elements[e].0]
    }

    /// Body `b`'s stiffness factor `E(μ)/E_file` at `mu` (1 where no parameter sets its
    /// Young's modulus, or μ does not set the parameter).
    fn body_stiffness_factor(&self, b: usize, mu: &Parameters) -> f64 {
        let body = &self.bodies[b];
        match body.youngs_modulus_parameter.as_deref().and_then(|name| mu.get(name)) {
            Some(e) => e / body.section.youngs_modulus,
            None => 1.0,
        }
    }

    /// Body `b`'s mass factor `ρ(μ)/ρ_file` at `mu`, as [`Self::body_stiffness_factor`].
    fn body_mass_factor(&self, b: usize, mu: &Parameters) -> f64 {
        let body = &self.bodies[b];
        match body.density_parameter.as_deref().and_then(|name| mu.get(name)) {
            Some(rho) => rho / body.section.density,
            None => 1.0,
        }
    }

    /// Makes the element prototypes the evaluations use those at `mu`: a body whose Young's
    /// modulus or density is a parameter gets a prototype at `E = μ[name]`, `ρ = μ[name]`
    /// (its elastic force and stiffness scale by `E(μ)/E_file`, its mass by `ρ(μ)/ρ_file`)
    /// whenever that changes; a point mass a parameter sets is `μ[name]` kg.
    fn bind_parameters(&mut self, mu: &Parameters) {
        for (k, name, file) in &self.point_mass_parameters {
            self.point_masses[*k].0 .2 = mu.get(name).unwrap_or(*file);
        }
        for b in 0..self.bodies.len() {
            let body = &self.bodies[b];
            let mut section = body.section;
            if let Some(e) = body.youngs_modulus_parameter.as_deref().and_then(|name| mu.get(name)) {
                section.youngs_modulus = e;
            }
            if let Some(rho) = body.density_parameter.as_deref().and_then(|name| mu.get(name)) {
                section.density = rho;
            }
            // the values themselves, not their ratios to the file's (two values a ratio
            // cannot tell apart still build two prototypes)
            if section != self.bound[b].section {
                self.bound[b] = BeamElement::new(body.length / body.n_elements as f64, section);
                // the iteration matrix's constant part holds the mass and bending stiffness
                self.iteration_coef = None;
            }
        }
    }

    /// Global node index of node `k` of body `b`.
    pub fn node_index(&self, b: usize, k: usize) -> usize {
        self.first_node[b] + k
    }

    /// The coordinates of body `b` (4 per node, its nodes numbered consecutively).
    pub fn body_dofs(&self, b: usize) -> std::ops::Range<usize> {
        let first = self.first_node[b];
        4 * first..4 * (first + self.bodies[b].n_elements + 1)
    }

    fn gather(&self, e: usize, q: &[f64]) -> Vec8 {
        let d = &self.elements[e].1;
        Vec8::from_fn(|i, _| q[d[i]])
    }

    /// The straight, undeformed configuration of every body (SPEC §1).
    pub fn initial_state(&self) -> Vec<f64> {
        let mut q = vec![0.0; self.n_dof];
        for (b, body) in self.bodies.iter().enumerate() {
            for k in 0..=body.n_elements {
                let n = self.first_node[b] + k;
                q[4 * n..4 * n + 4].copy_from_slice(&body.undeformed_node(k));
            }
        }
        q
    }

    /// The bodies' initial rigid-body velocities ([`BeamBody::rigid_velocity`]) at the
    /// nodes of `q` (the consistent initial state): zero for bodies that start at rest.
    pub fn initial_velocity(&self, q: &[f64]) -> Vec<f64> {
        let mut v = vec![0.0; self.n_dof];
        // a body at rest keeps exact zeros (no signed zeros from ω × r)
        let moving =
            self.bodies.iter().enumerate().filter(|(_, b)| b.velocity != [0.0; 2] || b.angular_velocity != 0.0);
        for (b, body) in moving {
            for k in 0..=body.n_elements {
                let d = 4 * (self.first_node[b] + k);
                let node = [q[d], q[d + 1], q[d + 2], q[d + 3]];
                v[d..d + 4].copy_from_slice(&body.rigid_velocity(node));
            }
        }
        v
    }

    /// Closes the joints of `q` (given to finitely many digits in a model file): first by
    /// the smallest rigid motion of each body (translation `t` and rotation `θ` about its
    /// start), which strains no element; then whatever is left (round-off, or a gap no rigid
    /// motion closes) by the smallest change of the joint coordinates. Moving the joint
    /// nodes alone would bend the end elements: a gap `g` costs ~12 EI g / l³, 10 N for
    /// g = 2e-10 m on the four-bar refined 10×. Returns the largest change of a coordinate.
    pub fn make_consistent(&mut self, q: &mut [f64]) -> Result<f64> {
        use nalgebra::{DMatrix, DVector};
        let (n, nb, nc) = (self.n_dof, self.bodies.len(), self.constraints.len());
        let mut res = vec![0.0; nc];
        self.initial_constraint_residual(q, &mut res);
        let mut change = 0.0_f64;
        if res.iter().any(|r| *r != 0.0) {
            // ∂q_d/∂(t_x, t_y, θ̂) with θ = θ̂/L: all three in metres
            let body_of =
                |node: usize| (0..nb).rev().find(|&b| self.first_node[b] <= node).expect("node 0 is in body 0");
            let motion = |d: usize, q: &[f64]| -> (usize, [f64; 3]) {
                let node = d / 4;
                let b = body_of(node);
                let (rot, st) = (1.0 / self.bodies[b].length, self.bodies[b].start);
                let t = match d % 4 {
                    0 => [1.0, 0.0, -(q[4 * node + 1] - st[1]) * rot],
                    1 => [0.0, 1.0, (q[4 * node] - st[0]) * rot],
                    2 => [0.0, 0.0, -q[4 * node + 3] * rot],
                    _ => [0.0, 0.0, q[4 * node + 2] * rot],
                };
                (b, t)
            };
            let mut a = DMatrix::<f64>::zeros(nc, 3 * nb);
            for (c, con) in self.constraints.iter().enumerate() {
                for &(d, k) in &con.terms {
                    let (b, t) = motion(d, q);
                    for (j, tj) in t.iter().enumerate() {
                        a[(c, 3 * b + j)] += k * tj;
                    }
                }
            }
            let rhs = DVector::from_iterator(nc, res.iter().map(|r| -r));
            // least-squares solution of least norm (a body may be held by several joints)
            let p = a
                .svd(true, true)
                .solve(&rhs, 1e-12)
                .map_err(|e| Error::linear_solve(format!("rigid joint closure: {e}")))?;
            let old = q.to_vec();
            for d in 0..n {
                let (b, t) = motion(d, &old);
                let dq: f64 = (0..3).map(|j| t[j] * p[3 * b + j]).sum();
                q[d] += dq;
                change = change.max(dq.abs());
            }
        }
        let n_el = self.elements.len();
        self.blocks[..n_el].iter_mut().for_each(|b| *b = Mat8::identity());
        self.blocks[n_el..].iter_mut().for_each(|b| *b = Mat8::zeros());
        // the rows at the start (a run leaves the moving ones at its last time)
        for (c, _) in &self.moving {
            let coefs: Vec<f64> = self.constraints[*c].terms.iter().map(|t| t.1).collect();
            self.kkt.set_constraint_row(*c, &coefs);
        }
        self.kkt.factor(&self.blocks, 1.0)?;
        let mut rhs = vec![0.0; n + nc];
        self.initial_constraint_residual(q, &mut rhs[n..]);
        rhs[n..].iter_mut().for_each(|r| *r = -*r);
        self.kkt.solve(&mut rhs)?;
        for i in 0..n {
            q[i] += rhs[i];
            change = change.max(rhs[i].abs());
        }
        Ok(change)
    }

    /// `out = B(0) q − b(0)`, the rows where every prescribed motion starts.
    fn initial_constraint_residual(&self, q: &[f64], out: &mut [f64]) {
        for (o, c) in out.iter_mut().zip(&self.constraints) {
            *o = c.terms.iter().map(|&(d, k)| k * q[d]).sum::<f64>() - c.rhs;
        }
    }

    /// Moving row `k`'s `order`-th time derivative at μ and `t` ([`row_at`]).
    fn moving_row(&self, mu: &Parameters, k: usize, t: f64, order: u32) -> ([f64; MOVING_TERMS], f64) {
        row_at(&self.moving[k].1, mu, t, order)
    }

    /// Sets the moving rows of a KKT solver built on this system's pattern to their
    /// coefficients at μ and `t` (the others never change).
    pub fn set_moving_rows(&self, mu: &Parameters, t: f64, kkt: &mut dyn KktSolver) {
        for (c, row) in &self.moving {
            let (b, _) = row_at(row, mu, t, 0);
            kkt.set_constraint_row(*c, &b[..row.terms.len()]);
        }
    }

    /// Whether any constraint row moves with time.
    pub fn has_moving_constraints(&self) -> bool {
        !self.moving.is_empty()
    }

    /// Position of a probe.
    pub fn probe_position(&self, probe: &Probe, q: &[f64]) -> [f64; 2] {
        self.element(probe.element).position(&self.gather(probe.element, q), probe.xi)
    }

    /// Axial strain and curvature (1/m) at a probe ([`super::section`]).
    pub fn probe_section(&self, probe: &Probe, q: &[f64]) -> (f64, f64) {
        let (el, e) = (self.element(probe.element), self.gather(probe.element, q));
        (el.axial_strain(&e, probe.xi), el.curvature(&e, probe.xi))
    }

    /// Kinetic energy `½ q̇ᵀ M q̇`.
    pub fn kinetic_energy(&self, v: &[f64]) -> f64 {
        let mut mv = vec![0.0; self.n_dof];
        self.mass_mul(v, &mut mv);
        0.5 * v.iter().zip(&mv).map(|(a, b)| a * b).sum::<f64>()
    }

    /// The gradient of gravity's potential at `mu`, `−g₀(μ)` (the weight, point masses'
    /// included, with a minus sign): gravity's potential energy at `q` is its dot with `q`.
    pub fn gravity_potential_gradient(&self, mu: &Parameters) -> Vec<f64> {
        let mut g = vec![0.0; self.n_dof];
        self.gravity_into(mu, &mut g);
        g
    }

    /// Potential energy at the parameters `mu`: strain energy plus that of the (constant)
    /// gravity loads.
    pub fn potential_energy(&self, mu: &Parameters, q: &[f64]) -> f64 {
        // the strain energy is linear in Young's modulus
        let strain: f64 = (0..self.elements.len())
            .map(|e| {
                let b = self.elements[e].0;
                self.body_stiffness_factor(b, mu) * self.element(e).strain_energy(&self.gather(e, q))
            })
            .sum();
        let mut g = vec![0.0; self.n_dof];
        self.gravity_into(mu, &mut g);
        let grav: f64 = g.iter().zip(q).map(|(g, q)| -g * q).sum();
        strain - grav
    }

    /// Dense global mass matrix and tangent stiffness at `q` (row-major n×n) at the model
    /// file's values, for modal analysis and tests.
    pub fn dense_mass_and_stiffness(&self, q: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let n = self.n_dof;
        let (mut m, mut k) = (vec![0.0; n * n], vec![0.0; n * n]);
        for e in 0..self.elements.len() {
            let el = self.element(e);
            let kt = el.tangent(&self.gather(e, q));
            let d = &self.elements[e].1;
            for i in 0..8 {
                for j in 0..8 {
                    m[d[i] * n + d[j]] += el.mass()[(i, j)];
                    k[d[i] * n + d[j]] += kt[(i, j)];
                }
            }
        }
        for (entry, &((i, j, mass), _)) in self.point_masses.iter().enumerate() {
            m[i * n + j] += self.point_mass_file_value(entry).unwrap_or(mass);
        }
        (m, k)
    }

    /// `fₑ = Cₑ q̇ₑ + Qₑ(qₑ)` with Rayleigh `Cₑ = a Mₑ + b K_bending,ₑ`, `Qₑ` from the
    /// element prototype `el` (the file's or the bound one).
    fn element_force_vec(&self, el: &BeamElement, qe: &Vec8, ve: &Vec8) -> Vec8 {
        let mut f = el.elastic_force(qe);
        if self.damping != Rayleigh::default() {
            f += self.damping_force(el, ve);
        }
        f
    }

    /// The Rayleigh damping force `Cₑ q̇ₑ = (a Mₑ + b K_bending,ₑ) q̇ₑ` of an element whose
    /// prototype is `el`: at a bound density and modulus, `a Mₑ(ρ) + b K_bending,ₑ(E)`.
    fn damping_force(&self, el: &BeamElement, ve: &Vec8) -> Vec8 {
        (el.mass() * self.damping.mass + el.bending_stiffness() * self.damping.stiffness) * ve
    }

    /// `out = −g₀(μ)`: gravity, the fixed part, the scaled part times the load scale, and
    /// each named part times its parameter; the bodies whose density is a parameter, each
    /// part times `ρ(μ)/ρ_file` as well.
    fn gravity_into(&self, mu: &Parameters, out: &mut [f64]) {
        let plain = &self.weight.plain;
        for (o, (gf, gs)) in out.iter_mut().zip(plain.fixed.iter().zip(&plain.scaled)) {
            *o = -(gf + mu.scale() * gs);
        }
        for (name, g) in &plain.named {
            // a parameter the run does not set keeps the file's load
            let x = mu.get(name).unwrap_or(1.0);
            out.iter_mut().zip(g).for_each(|(o, g)| *o -= x * g);
        }
        for d in &self.weight.by_density {
            let m = mu.get(&d.parameter).map_or(1.0, |rho| rho / d.density);
            for (o, (gf, gs)) in out.iter_mut().zip(d.parts.fixed.iter().zip(&d.parts.scaled)) {
                *o -= m * (gf + mu.scale() * gs);
            }
            for (name, g) in &d.parts.named {
                let x = m * mu.get(name).unwrap_or(1.0);
                out.iter_mut().zip(g).for_each(|(o, g)| *o -= x * g);
            }
        }
    }

    /// `c Cₑ + k Kₑ(qₑ)`.
    fn element_matrix_mat(&self, e: usize, qe: &Vec8, coef: IterationCoefficients) -> Mat8 {
        let el = self.element(e);
        let mut blk = Mat8::zeros();
        if coef.stiffness != 0.0 {
            blk += el.tangent(qe) * coef.stiffness;
        }
        if coef.damping != 0.0 && self.damping != Rayleigh::default() {
            blk += (el.mass() * self.damping.mass + el.bending_stiffness() * self.damping.stiffness) * coef.damping;
        }
        blk
    }

    /// Calls `add(dof, value)` with the contributions `−Q_ext` of the nodal loads, in file
    /// order; `q(dof)` and `v(dof)` read the coordinates and velocities they depend on.
    fn add_nodal_loads(
        &self,
        mu: &Parameters,
        t: f64,
        q: impl Fn(usize) -> f64,
        v: impl Fn(usize) -> f64,
        mut add: impl FnMut(usize, f64),
    ) {
        for load in &self.nodal {
            load.add_force(mu.factor(load.scaling()), t, &q, &v, &mut add);
        }
    }

    /// The springs' stored energy `Σ ½ k (L − L₀)² + Σ ½ k φ²` at `q` and its rate at `q̇`,
    /// their stiffnesses at `mu` (`loads::NodalLoad::stored_energy`); zeros without springs.
    pub fn spring_energy(&self, mu: &Parameters, q: &[f64], v: &[f64]) -> (f64, f64) {
        self.nodal
            .iter()
            .filter_map(|l| l.stored_energy(mu.factor(l.scaling()), &|d| q[d], &|d| v[d]))
            .fold((0.0, 0.0), |(e, r), (le, lr)| (e + le, r + lr))
    }

    /// The number of blocks of the iteration matrix: the elements', then the coupling
    /// blocks of springs between nodes no element holds together.
    pub fn n_blocks(&self) -> usize {
        self.elements.len() + self.coupling.len()
    }

    /// The global dofs of iteration block `k` ([`Self::n_blocks`]).
    pub fn block_dofs(&self, k: usize) -> &[usize; 8] {
        match self.elements.get(k) {
            Some((_, d)) => d,
            None => &self.coupling[k - self.elements.len()],
        }
    }

    /// `out += M_p a`, the point masses' part of the mass matrix.
    fn add_point_mass_product(&self, a: &[f64], out: &mut [f64]) {
        for &((i, j, mass), _) in &self.point_masses {
            out[i] += mass * a[j];
        }
    }

    /// The point masses as entries of element blocks: `(element, local row, local column,
    /// value)` for each entry of their mass matrix (the block that holds the node, as the
    /// iteration matrix's), for callers that assemble their own block matrices.
    pub fn point_mass_entries(&self) -> impl Iterator<Item = (usize, usize, usize, f64)> + '_ {
        self.point_masses.iter().map(|&((i, j, mass), (e, d0))| (e, i - d0, j - d0, mass))
    }

    /// The model file's kg of point-mass entry `entry` when a parameter sets it.
    fn point_mass_file_value(&self, entry: usize) -> Option<f64> {
        self.point_mass_parameters.iter().find(|p| p.0 == entry).map(|p| p.2)
    }

    /// The parameter that sets point-mass entry `entry`, if any.
    fn point_mass_parameter(&self, entry: usize) -> Option<&str> {
        self.point_mass_parameters.iter().find(|p| p.0 == entry).map(|p| p.1.as_str())
    }

    /// `out += M_p,g a` at the model file's values, `M_p,g` the point masses the parameter
    /// `group` sets (`None`: those no parameter sets).
    fn add_point_mass_group_product(&self, group: Option<&str>, a: &[f64], out: &mut [f64]) {
        for (entry, &((i, j, mass), _)) in self.point_masses.iter().enumerate() {
            if self.point_mass_parameter(entry) == group {
                out[i] += self.point_mass_file_value(entry).unwrap_or(mass) * a[j];
            }
        }
    }

    /// Whether the model has point masses (mass outside its elements).
    pub fn has_point_masses(&self) -> bool {
        !self.point_masses.is_empty()
    }

    /// Adds `m_c M_p` to the element blocks that hold the point masses.
    fn add_point_mass_blocks(&mut self, coef_mass: f64) {
        for &((i, j, mass), (e, d0)) in &self.point_masses {
            self.blocks[e][(i - d0, j - d0)] += coef_mass * mass;
        }
    }

    /// Adds `k ∂(−Q_ext)/∂q + c ∂(−Q_ext)/∂q̇` of the nodal loads to the blocks that hold
    /// them (`c` only for the loads that depend on velocities).
    fn add_nodal_jacobians(&mut self, mu: &Parameters, t: f64, (q, v): (&[f64], &[f64]), k: f64, c: f64) {
        for (load, slot) in self.nodal.iter().zip(&self.nodal_blocks) {
            if let Some((e, dofs)) = slot {
                let block = &mut self.blocks[*e];
                let at = |d: usize| dofs.iter().position(|&x| x == d).expect("the block holds the load's dofs");
                let (factor, q, v) = (mu.factor(load.scaling()), &|d| q[d], &|d| v[d]);
                if k != 0.0 && load.has_stiffness() {
                    load.add_stiffness(factor, t, q, v, &mut |r, col, x| block[(at(r), at(col))] += k * x);
                }
                if c != 0.0 && load.has_damping() {
                    load.add_damping(factor, t, q, v, &mut |r, col, x| block[(at(r), at(col))] += c * x);
                }
            }
        }
    }

    fn local_load_index(&self, dof: usize) -> usize {
        self.load_dofs.binary_search(&dof).expect("load dof listed")
    }
}

/// A moving row's `order`-th time derivative at μ and `t` ([`Row::at`] with its drive's
/// factor at μ): its coefficients (the first `terms.len()` entries) and right-hand side.
fn row_at(row: &Row, mu: &Parameters, t: f64, order: u32) -> ([f64; MOVING_TERMS], f64) {
    let s = row.scaling().map_or(1.0, |sc| mu.factor(sc));
    let mut b = [0.0; MOVING_TERMS];
    let rhs = row.at(s, t, order, &mut b[..row.terms.len()]);
    (b, rhs)
}

/// The iteration block a nodal load's Jacobian is added to and its dofs: the element that
/// holds all its coordinates ([`block_holding`]), or else a coupling block over its two
/// nodes' coordinates (numbered after the elements; one per pair of nodes, shared).
fn load_block(elements: &[(usize, [usize; 8])], coupling: &mut Vec<[usize; 8]>, dofs: &[usize]) -> (usize, [usize; 8]) {
    if let Some(e) = block_holding(elements, dofs) {
        return (e, elements[e].1);
    }
    let mut nodes: Vec<usize> = dofs.iter().map(|d| d / 4).collect();
    nodes.sort_unstable();
    nodes.dedup();
    let [a, b] = nodes[..] else { panic!("a load no element holds couples two nodes, not {}", nodes.len()) };
    let block: [usize; 8] = std::array::from_fn(|i| 4 * if i < 4 { a } else { b } + i % 4);
    let k = coupling.iter().position(|c| *c == block).unwrap_or_else(|| {
        coupling.push(block);
        coupling.len() - 1
    });
    (elements.len() + k, block)
}

/// The element whose 8 consecutive dofs hold every one of `dofs`: the one that starts at
/// the lowest node, or the last of its body. A load whose coordinates span two elements
/// has none.
fn block_holding(elements: &[(usize, [usize; 8])], dofs: &[usize]) -> Option<usize> {
    let (lo, hi) = (dofs.iter().min().copied().unwrap_or(0), dofs.iter().max().copied().unwrap_or(0));
    let node_start = 4 * (lo / 4);
    let e = match elements.iter().position(|(_, d)| d[0] == node_start) {
        Some(e) => e,
        // the last node of a body: the element that ends there
        None => elements.iter().position(|(_, d)| d[4] == node_start).expect("a node of the mesh"),
    };
    (hi < elements[e].1[0] + 8).then_some(e)
}
