//! [`FlexibleSystem`] as the models the solver and the reduction see: [`ElementModel`],
//! [`InvariantElementModel`], [`ParametricModel`] and, at the file's own loads,
//! [`crate::solver::model::DynamicModel`].

use super::*;
use crate::solver::model::{ConstantForces, ElementModel, InvariantElementModel};

impl ElementModel for FlexibleSystem {
    fn n_elements(&self) -> usize {
        self.elements.len()
    }

    fn element_dofs(&self, e: usize) -> &[usize] {
        &self.elements[e].1
    }

    fn element_force(&self, e: usize, qe: &[f64], ve: &[f64], out: &mut [f64]) {
        let f = self.element_force_vec(self.element(e), &Vec8::from_column_slice(qe), &Vec8::from_column_slice(ve));
        out.copy_from_slice(f.as_slice());
    }

    fn element_matrix(&self, e: usize, qe: &[f64], coef: IterationCoefficients, out: &mut [f64]) {
        out.copy_from_slice(self.element_matrix_mat(e, &Vec8::from_column_slice(qe), coef).as_slice());
    }

    fn load_dofs(&self) -> Vec<usize> {
        self.load_dofs.clone()
    }

    fn load_force(&self, mu: &Parameters, ql: &[f64], vl: &[f64], t: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        let at = |d| self.local_load_index(d);
        self.add_nodal_loads(mu, t, |d| ql[at(d)], |d| vl[at(d)], |d, v| out[at(d)] += v);
    }

    fn load_jacobian(&self, mu: &Parameters, ql: &[f64], vl: &[f64], t: f64, out: &mut [f64]) {
        let nl = self.load_dofs.len();
        out.iter_mut().for_each(|x| *x = 0.0);
        let at = |d| self.local_load_index(d);
        let (q, v) = (|d: usize| ql[at(d)], |d: usize| vl[at(d)]);
        for load in &self.nodal {
            load.add_stiffness(mu.factor(load.scaling()), t, &q, &v, &mut |r, c, x| out[at(c) * nl + at(r)] += x);
        }
    }

    fn load_has_damping(&self) -> bool {
        self.load_damping
    }

    fn load_damping_jacobian(&self, mu: &Parameters, ql: &[f64], vl: &[f64], t: f64, out: &mut [f64]) {
        let nl = self.load_dofs.len();
        out.iter_mut().for_each(|x| *x = 0.0);
        let at = |d| self.local_load_index(d);
        let (q, v) = (|d: usize| ql[at(d)], |d: usize| vl[at(d)]);
        for load in self.nodal.iter().filter(|l| l.has_damping()) {
            load.add_damping(mu.factor(load.scaling()), t, &q, &v, &mut |r, c, x| out[at(c) * nl + at(r)] += x);
        }
    }

    fn stiffness_parameter(&self, e: usize) -> Option<&str> {
        self.bodies[self.elements[e].0].youngs_modulus_parameter.as_deref()
    }

    fn stiffness_factor(&self, e: usize, mu: &Parameters) -> f64 {
        self.body_stiffness_factor(self.elements[e].0, mu)
    }

    fn mass_parameter(&self, e: usize) -> Option<&str> {
        self.bodies[self.elements[e].0].density_parameter.as_deref()
    }

    fn mass_factor(&self, e: usize, mu: &Parameters) -> f64 {
        self.body_mass_factor(self.elements[e].0, mu)
    }

    /// Rayleigh `a Mₑ` and `b K_bending,ₑ` at the file's values.
    fn element_damping_parts(&self, e: usize, by_mass: &mut [f64], by_stiffness: &mut [f64]) {
        let el = self.element(e);
        by_mass.copy_from_slice((el.mass() * self.damping.mass).as_slice());
        by_stiffness.copy_from_slice((el.bending_stiffness() * self.damping.stiffness).as_slice());
    }

    fn group_mass_mul(&self, group: Option<&str>, a: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        for (e, (b, dofs)) in self.elements.iter().enumerate() {
            if self.bodies[*b].density_parameter.as_deref() == group {
                let f = self.element(e).mass_product(&self.gather(e, a));
                for (i, &d) in dofs.iter().enumerate() {
                    out[d] += f[i];
                }
            }
        }
        // the point masses of the group: those its parameter sets, or those none sets
        self.add_point_mass_group_product(group, a, out);
    }

    /// Each beam: its nodes' positions and slopes (the Berzeri–Shabana element is objective:
    /// its strain invariant and bending curvature do not change in a rigid motion).
    fn rigid_bodies(&self) -> Vec<crate::solver::model::RigidBody> {
        let pairs =
            |b: usize, offset: usize| self.body_dofs(b).step_by(4).map(|d| [d + offset, d + offset + 1]).collect();
        (0..self.bodies.len())
            .map(|b| crate::solver::model::RigidBody {
                positions: pairs(b, 0),
                slopes: pairs(b, 2),
                length: self.bodies[b].length,
            })
            .collect()
    }

    fn moving_rows(&self) -> Vec<(usize, Vec<usize>)> {
        self.moving.iter().map(|(c, row)| (*c, row.terms.iter().map(|t| t.0).collect())).collect()
    }

    fn moving_row_at(&self, mu: &Parameters, k: usize, t: f64, order: u32, coefs: &mut [f64]) -> f64 {
        let (b, rhs) = self.moving_row(mu, k, t, order);
        coefs.copy_from_slice(&b[..coefs.len()]);
        rhs
    }

    fn has_lumped_mass(&self) -> bool {
        self.has_point_masses()
    }

    fn lumped_mass_parameters(&self) -> Vec<String> {
        let mut names: Vec<String> = Vec::new();
        for (_, name, _) in &self.point_mass_parameters {
            if !names.contains(name) {
                names.push(name.clone());
            }
        }
        names
    }

    fn lumped_mass_factor(&self, name: &str, mu: &Parameters) -> f64 {
        match (mu.get(name), self.point_mass_parameters.iter().find(|p| p.1 == name)) {
            (Some(m), Some((_, _, file))) => m / file,
            _ => 1.0,
        }
    }

    fn group_constant_forces(&self, group: Option<&str>) -> ConstantForces {
        let negated = |g: &[f64]| g.iter().map(|x| -x).collect::<Vec<f64>>();
        let named = |n: &[(String, Vec<f64>)]| n.iter().map(|(name, g)| (name.clone(), negated(g))).collect();
        match group.and_then(|name| self.weight.by_density.iter().find(|d| d.parameter == name)) {
            Some(d) => ConstantForces {
                fixed: negated(&d.parts.fixed),
                scaled: negated(&d.parts.scaled),
                named: named(&d.parts.named),
            },
            None if group.is_some() => {
                let zero = vec![0.0; self.n_dof];
                ConstantForces { fixed: zero.clone(), scaled: zero, named: Vec::new() }
            }
            None => ConstantForces {
                fixed: negated(&self.weight.plain.fixed),
                scaled: negated(&self.weight.plain.scaled),
                named: named(&self.weight.plain.named),
            },
        }
    }
}

/// Berzeri–Shabana in invariant form (SPEC §1): `L = K_t`, `C = a M + b K_t`, one invariant
/// `s = eᵀS_l e` with `Û = ½ EA l ε̄²`, `ε̄ = s/(2l) − ½`, so `ψ = EA ε̄/2`, `ψ' = EA/(4l)`.
impl InvariantElementModel for FlexibleSystem {
    fn n_invariants(&self) -> usize {
        1
    }

    fn element_linear(&self, e: usize, stiffness: &mut [f64], damping: &mut [f64]) {
        let el = self.element(e);
        stiffness.copy_from_slice(el.bending_stiffness().as_slice());
        let c = el.mass() * self.damping.mass + el.bending_stiffness() * self.damping.stiffness;
        damping.copy_from_slice(c.as_slice());
    }

    fn element_invariant_matrix(&self, e: usize, _j: usize, out: &mut [f64]) {
        out.copy_from_slice(self.element(e).axial_matrix().as_slice());
    }

    fn invariant_derivatives(&self, e: usize, s: &[f64], d1: &mut [f64], d2: &mut [f64]) {
        let el = self.element(e);
        let (ea, l) = (el.section.ea(), el.length);
        d1[0] = 0.5 * ea * (s[0] / (2.0 * l) - 0.5);
        d2[0] = ea / (4.0 * l);
    }

    /// ε̄ = s/(2l) − ½ with s = eᵀS_l e (SPEC §1)
    fn invariant_strain(&self, e: usize, s: &[f64]) -> Option<f64> {
        Some(s[0] / (2.0 * self.element(e).length) - 0.5)
    }
}

impl ParametricModel for FlexibleSystem {
    fn n_dof(&self) -> usize {
        self.n_dof
    }

    fn n_constraints(&self) -> usize {
        self.constraints.len()
    }

    fn bind(&mut self, mu: &Parameters) {
        self.bind_parameters(mu);
    }

    /// At the parameters of the last [`ParametricModel::bind`] or evaluation.
    fn mass_mul(&self, a: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        for e in 0..self.elements.len() {
            let f = self.bound[self.elements[e].0].mass_product(&self.gather(e, a));
            for (i, &d) in self.elements[e].1.iter().enumerate() {
                out[d] += f[i];
            }
        }
        self.add_point_mass_product(a, out);
    }

    fn force(&mut self, mu: &Parameters, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        self.bind_parameters(mu);
        self.gravity_into(mu, out);
        for e in 0..self.elements.len() {
            let el = &self.bound[self.elements[e].0];
            let f = self.element_force_vec(el, &self.gather(e, q), &self.gather(e, v));
            for (i, &d) in self.elements[e].1.iter().enumerate() {
                out[d] += f[i];
            }
        }
        self.add_nodal_loads(mu, t, |d| q[d], |d| v[d], |d, value| out[d] += value);
    }

    /// [`Self::force`] and [`Self::mass_mul`] in one pass over the elements, each element's
    /// coordinates read once (its 8 dofs are consecutive, [`FlexibleSystem::new`]); the same
    /// sums in the same order, so the same bits.
    fn force_and_inertia(
        &mut self,
        mu: &Parameters,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        t: f64,
        out: (&mut [f64], &mut [f64]),
    ) {
        let (force, inertia) = out;
        self.bind_parameters(mu);
        self.gravity_into(mu, force);
        inertia.iter_mut().for_each(|x| *x = 0.0);
        let damped = self.damping != Rayleigh::default();
        for (e, (b, dofs)) in self.elements.iter().enumerate() {
            let d0 = dofs[0];
            let el = &self.bound[*b];
            let qe: &[f64; 8] = q[d0..d0 + 8].try_into().expect("8 consecutive dofs");
            let ae: &[f64; 8] = a[d0..d0 + 8].try_into().expect("8 consecutive dofs");
            let (mut f, m) = el.force_and_inertia(qe, ae);
            if damped {
                // as element_force_vec: the elastic force, then the damping force added
                f = (Vec8::from(f) + self.damping_force(el, &self.gather(e, v))).into();
            }
            for (o, fi) in force[d0..d0 + 8].iter_mut().zip(f) {
                *o += fi;
            }
            for (o, mi) in inertia[d0..d0 + 8].iter_mut().zip(m) {
                *o += mi;
            }
        }
        self.add_point_mass_product(a, inertia);
        self.add_nodal_loads(mu, t, |d| q[d], |d| v[d], |d, value| force[d] += value);
    }

    /// The constant rows as built; the moving ones ([`crate::physics::joints::Motion`]) at
    /// `t` and the drive's factor at μ.
    fn constraint_residual(&self, mu: &Parameters, q: &[f64], t: f64, out: &mut [f64]) {
        self.initial_constraint_residual(q, out);
        for (k, (c, row)) in self.moving.iter().enumerate() {
            let (b, rhs) = self.moving_row(mu, k, t, 0);
            out[*c] = row.terms.iter().zip(&b).map(|(&(d, _), k)| k * q[d]).sum::<f64>() - rhs;
        }
    }

    /// `ḃ − Ḃ q`, nonzero on the moving rows only.
    fn constraint_velocity_rhs(&self, mu: &Parameters, q: &[f64], t: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        for (k, (c, row)) in self.moving.iter().enumerate() {
            let (b1, rhs1) = self.moving_row(mu, k, t, 1);
            out[*c] = rhs1 - row.terms.iter().zip(&b1).map(|(&(d, _), k)| k * q[d]).sum::<f64>();
        }
    }

    /// `b̈ − 2 Ḃ q̇ − B̈ q`, nonzero on the moving rows only.
    fn constraint_acceleration_rhs(&self, mu: &Parameters, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        for (k, (c, row)) in self.moving.iter().enumerate() {
            let (b1, _) = self.moving_row(mu, k, t, 1);
            let (b2, rhs2) = self.moving_row(mu, k, t, 2);
            let terms = row.terms.iter().zip(b1.iter().zip(&b2));
            out[*c] = rhs2 - terms.map(|(&(d, _), (k1, k2))| 2.0 * k1 * v[d] + k2 * q[d]).sum::<f64>();
        }
    }

    fn add_constraint_force(&self, mu: &Parameters, lambda: &[f64], t: f64, out: &mut [f64]) {
        // the moving rows (sorted by row) at t, the others as built
        let mut moving = self.moving.iter().enumerate().peekable();
        for (c, (l, con)) in lambda.iter().zip(&self.constraints).enumerate() {
            if let Some((k, _)) = moving.next_if(|(_, (mc, _))| *mc == c) {
                let (b, _) = self.moving_row(mu, k, t, 0);
                con.terms.iter().zip(&b).for_each(|(&(d, _), k)| out[d] += k * l);
                continue;
            }
            for &(d, k) in &con.terms {
                out[d] += k * l;
            }
        }
    }

    fn factor(&mut self, mu: &Parameters, q: &[f64], v: &[f64], t: f64, coef: IterationCoefficients) -> Result<f64> {
        self.bind_parameters(mu);
        if self.iteration_coef != Some(coef) {
            let damped = coef.damping != 0.0 && self.damping != Rayleigh::default();
            self.iteration_constant = self
                .bound
                .iter()
                .map(|el| {
                    let mut c = el.mass() * coef.mass + el.bending_stiffness() * coef.stiffness;
                    if damped {
                        c += (el.mass() * self.damping.mass + el.bending_stiffness() * self.damping.stiffness)
                            * coef.damping;
                    }
                    c
                })
                .collect();
            self.iteration_coef = Some(coef);
        }
        let diag_max = crate::linalg::simd::dispatch(IterationBlocks {
            elements: &self.elements,
            prototypes: &self.bound,
            constants: &self.iteration_constant,
            stiffness: coef.stiffness,
            q,
            blocks: &mut self.blocks[..self.elements.len()],
        });
        if coef.mass != 0.0 {
            self.add_point_mass_blocks(coef.mass);
        }
        let n_el = self.elements.len();
        self.blocks[n_el..].iter_mut().for_each(|b| *b = Mat8::zeros());
        let damping = if self.load_damping { coef.damping } else { 0.0 };
        if coef.stiffness != 0.0 || damping != 0.0 {
            self.add_nodal_jacobians(mu, t, (q, v), coef.stiffness, damping);
        }
        for (c, row) in &self.moving {
            let (b, _) = row_at(row, mu, t, 0);
            self.kkt.set_constraint_row(*c, &b[..row.terms.len()]);
        }
        let scale = if diag_max > 0.0 { diag_max } else { 1.0 };
        // sums of symmetric element matrices, each entry and its mirror computed alike
        // (BeamElement::iteration_block_from), plus the moments' Jacobians, whose two
        // off-diagonal entries are one value (loads::moment_jacobian), and undamped
        // springs' (each entry and its mirror from the same products): symmetric to the bit
        // (a test checks), so the solver need not check; a damper's Jacobian is not
        if self.symmetric_loads {
            self.kkt.factor_symmetric(&self.blocks, scale)?;
        } else {
            self.kkt.factor(&self.blocks, scale)?;
        }
        Ok(scale)
    }

    fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
        self.kkt.solve(rhs)
    }

    fn length_scale(&self) -> f64 {
        self.length_scale
    }

    fn max_strain(&self, q: &[f64]) -> Option<(f64, usize)> {
        let mut worst = (0.0_f64, 0);
        for e in 0..self.elements.len() {
            let eps = self.element(e).mean_axial_strain(&self.gather(e, q)).abs();
            // NaN counts as the worst
            if !(eps <= worst.0) {
                worst = (eps, e);
            }
        }
        Some(worst)
    }
}

/// The element blocks of the iteration matrix (`BeamElement::iteration_block`, written
/// into the system's blocks: no 512-byte copy per element and factorization) at
/// `q`, and the largest diagonal entry, as a kernel for [`crate::linalg::simd::dispatch`]:
/// the same operations in the same order on every instruction set.
struct IterationBlocks<'a> {
    elements: &'a [(usize, [usize; 8])],
    prototypes: &'a [BeamElement],
    constants: &'a [Mat8],
    stiffness: f64,
    q: &'a [f64],
    blocks: &'a mut [Mat8],
}

impl crate::linalg::simd::Kernel for IterationBlocks<'_> {
    type Output = f64;
    #[inline(always)]
    fn run(self) -> f64 {
        // the largest |diagonal entry| per position: eight independent chains of `max`
        // (exact, so in any order the same value as one chain)
        let mut diag_max = [0.0_f64; 8];
        const CHUNK: usize = 8;
        for (els, blks) in self.elements.chunks(CHUNK).zip(self.blocks.chunks_mut(CHUNK)) {
            // first the chains (S_l e, ε̄, a) of a few elements, which overlap, then their blocks
            let mut scalars = [(Vec8::zeros(), 0.0, 0.0); CHUNK];
            for ((b, dofs), sc) in els.iter().zip(scalars.iter_mut()) {
                let d0 = dofs[0];
                let qe: &[f64; 8] = self.q[d0..d0 + 8].try_into().expect("8 consecutive dofs");
                *sc = self.prototypes[*b].iteration_scalars(self.stiffness, &Vec8::from(*qe));
            }
            for (((b, _), blk), (sle, a, bb)) in els.iter().zip(blks.iter_mut()).zip(&scalars) {
                self.prototypes[*b].iteration_block_from(&self.constants[*b], sle, *a, *bb, blk);
                for (i, m) in diag_max.iter_mut().enumerate() {
                    *m = m.max(blk[(i, i)].abs());
                }
            }
        }
        diag_max.iter().fold(0.0_f64, |m, x| m.max(*x))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::element::Section;
    use crate::physics::loads::{Force, Gravity, Moment, Spring, SpringEnd, TorsionalSpring};
    use crate::physics::time_function::TimeFunction;
    use crate::solver::parameters::Scaling;

    /// A 1 m aluminium beam of `n` elements, at 0.3 rad: the test systems' body.
    fn aluminium_body(name: &str, n: usize) -> BeamBody {
        BeamBody {
            name: name.into(),
            start: [0.0, 0.0],
            angle: 0.3,
            length: 1.0,
            n_elements: n,
            section: Section { density: 2700.0, area: 1e-3, inertia: 1e-7, youngs_modulus: 7e9 },
            youngs_modulus_parameter: None,
            density_parameter: None,
            velocity: [0.0; 2],
            angular_velocity: 0.0,
        }
    }

    /// The iteration blocks are symmetric to the bit, as `factor_symmetric` takes them to
    /// be (the band LDLᵀ then skips its check): with and without Rayleigh damping, with a
    /// moment load (its Jacobian enters two blocks' slope entries), at a strained state,
    /// for mass-only and full coefficients.
    #[test]
    fn iteration_blocks_are_symmetric_to_the_bit() {
        let body = aluminium_body("b", 5);
        let gravity = [
            Load::Gravity(Gravity { g: [0.0, -9.81], scaled: Scaling::LoadScale }),
            Load::Moment(Moment {
                node: (0, 2),
                function: TimeFunction::Constant { value: 3.0 },
                scaled: Scaling::LoadScale,
            }),
            Load::Moment(Moment {
                node: (0, 5),
                function: TimeFunction::Constant { value: -1.5 },
                scaled: Scaling::Fixed,
            }),
        ];
        for damping in [Rayleigh::default(), Rayleigh { mass: 0.3, stiffness: 2e-3 }] {
            let mut sys =
                FlexibleSystem::new(vec![body.clone()], &[], &gravity, &[], vec![], damping, LinearSolverKind::Banded);
            let n = ParametricModel::n_dof(&sys);
            let q: Vec<f64> =
                sys.initial_state().iter().enumerate().map(|(i, x)| x + 0.03 * (i as f64 * 0.7).sin()).collect();
            for coef in [
                IterationCoefficients { mass: 1.0, damping: 0.0, stiffness: 0.0 },
                IterationCoefficients { mass: 1.0, damping: 37.0, stiffness: 1.3e-5 },
            ] {
                ParametricModel::factor(&mut sys, &Parameters::load_scale(1.0), &q, &vec![0.1; n], 0.0, coef).unwrap();
                for (e, b) in sys.blocks.iter().enumerate() {
                    assert!(b.iter().any(|x| *x != 0.0));
                    for i in 0..8 {
                        for j in 0..8 {
                            assert_eq!(
                                b[(i, j)].to_bits(),
                                b[(j, i)].to_bits(),
                                "element {e} ({i}, {j}), {damping:?}, {coef:?}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// The residual's one pass (`force_and_inertia`) gives `force` and `mass_mul` to the
    /// bit, with and without Rayleigh damping, with gravity (fixed and scaled), a moment and
    /// a nodal force, on two bodies (their elements' dofs consecutive in each).
    #[test]
    fn one_pass_residual_equals_force_and_mass_product_to_the_bit() {
        let body = aluminium_body;
        let loads = [
            Load::Gravity(Gravity { g: [0.5, -9.81], scaled: Scaling::LoadScale }),
            Load::Gravity(Gravity { g: [0.0, -1.0], scaled: Scaling::Fixed }),
            Load::Moment(Moment {
                node: (1, 2),
                function: TimeFunction::Constant { value: 3.0 },
                scaled: Scaling::LoadScale,
            }),
            Load::Force(Force { node: (0, 1), value: [1.0, 2.0], function: None, scaled: Scaling::Fixed }),
            Load::Gravity(Gravity { g: [0.2, 0.0], scaled: Scaling::Named("wind".into()) }),
            Load::Force(Force {
                node: (1, 1),
                value: [0.5, -1.0],
                function: None,
                scaled: Scaling::Named("push".into()),
            }),
        ];
        for damping in [Rayleigh::default(), Rayleigh { mass: 0.3, stiffness: 2e-3 }] {
            let mut sys = FlexibleSystem::new(
                vec![body("a", 3), body("b", 2)],
                &[],
                &loads,
                &[],
                vec![],
                damping,
                LinearSolverKind::Banded,
            );
            let n = ParametricModel::n_dof(&sys);
            let q: Vec<f64> =
                sys.initial_state().iter().enumerate().map(|(i, x)| x + 0.01 * (i as f64 * 0.7).sin()).collect();
            let v: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).cos()).collect();
            let a: Vec<f64> = (0..n).map(|i| (i as f64 * 1.1).sin() * 5.0).collect();
            let mu = Parameters::load_scale(1.3).with("wind", 0.7).with("push", -2.0);
            let (mut f_ref, mut m_ref, mut f, mut m) = (vec![0.0; n], vec![0.0; n], vec![1.0; n], vec![1.0; n]);
            ParametricModel::force(&mut sys, &mu, &q, &v, 0.2, &mut f_ref);
            ParametricModel::mass_mul(&sys, &a, &mut m_ref);
            sys.force_and_inertia(&mu, &q, &v, &a, 0.2, (&mut f, &mut m));
            let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&f), bits(&f_ref), "force, {damping:?}");
            assert_eq!(bits(&m), bits(&m_ref), "inertia, {damping:?}");
            assert!(f.iter().any(|x| *x != 0.0) && m.iter().any(|x| *x != 0.0));
        }
    }

    /// The invariant form (`InvariantElementModel`) must rebuild the element force and
    /// tangent of `ElementModel` exactly: both implement SPEC §1, one directly, one as
    /// `L e + C ė + 2ψ S_l e` and `L + 2ψ S_l + 4ψ' (S_l e)(S_l e)ᵀ`.
    #[test]
    fn invariant_form_rebuilds_element_force_and_tangent() {
        let body = aluminium_body("b", 2);
        let sys = FlexibleSystem::new(
            vec![body],
            &[],
            &[],
            &[],
            vec![],
            Rayleigh { mass: 0.3, stiffness: 2e-3 },
            LinearSolverKind::Banded,
        );
        // a stretched and bent element with an arbitrary velocity
        let qe: Vec<f64> = (0..8).map(|i| [0.1, -0.05, 0.95, 0.31, 0.62, 0.2, 1.02, 0.4][i]).collect();
        let ve: Vec<f64> = (0..8).map(|i| 0.1 * i as f64 - 0.3).collect();
        let (mut l, mut c, mut s) = ([0.0; 64], [0.0; 64], [0.0; 64]);
        sys.element_linear(1, &mut l, &mut c);
        sys.element_invariant_matrix(1, 0, &mut s);
        let (l, c, s) = (Mat8::from_column_slice(&l), Mat8::from_column_slice(&c), Mat8::from_column_slice(&s));
        let (e, v) = (Vec8::from_column_slice(&qe), Vec8::from_column_slice(&ve));
        let se = s * e;
        let (mut d1, mut d2) = ([0.0], [0.0]);
        sys.invariant_derivatives(1, &[e.dot(&se)], &mut d1, &mut d2);
        let f = l * e + c * v + se * (2.0 * d1[0]);
        let k = l + s * (2.0 * d1[0]) + se * se.transpose() * (4.0 * d2[0]);
        let mut f_ref = [0.0; 8];
        sys.element_force(1, &qe, &ve, &mut f_ref);
        let mut k_ref = [0.0; 64];
        sys.element_matrix(1, &qe, IterationCoefficients { mass: 0.0, damping: 0.0, stiffness: 1.0 }, &mut k_ref);
        let scale_f = f.amax();
        for i in 0..8 {
            assert!((f[i] - f_ref[i]).abs() <= 1e-13 * scale_f, "force {i}: {} vs {}", f[i], f_ref[i]);
        }
        let scale_k = k.amax();
        for (a, b) in k.as_slice().iter().zip(&k_ref) {
            assert!((a - b).abs() <= 1e-13 * scale_k, "tangent {a} vs {b}");
        }
    }

    /// The springs' part of the iteration matrix (the blocks scattered through their dofs,
    /// the elements' and the coupling blocks, less those of the system without springs) is
    /// `c ∂g_s/∂q̇ + k ∂g_s/∂q` of their force by central differences, with springs between
    /// two bodies (a coupling block), to the ground and within one element, a torsional
    /// one, dampers on all; and the blocks are symmetric to the bit without dampers.
    #[test]
    fn springs_enter_the_iteration_matrix_as_the_force_s_jacobians() {
        let springs = |c: f64| {
            vec![
                Load::Spring(Spring {
                    a: (0, 3),
                    b: SpringEnd::Node((1, 0)),
                    stiffness: 400.0,
                    damping: c,
                    length: 0.4,
                    scaled: Scaling::Fixed,
                }),
                Load::Spring(Spring {
                    a: (1, 2),
                    b: SpringEnd::Point([0.5, -0.3]),
                    stiffness: 90.0,
                    damping: c,
                    length: 0.1,
                    scaled: Scaling::Fixed,
                }),
                Load::Spring(Spring {
                    a: (0, 1),
                    b: SpringEnd::Node((0, 2)),
                    stiffness: 50.0,
                    damping: c,
                    length: 0.2,
                    scaled: Scaling::Fixed,
                }),
                Load::TorsionalSpring(TorsionalSpring {
                    a: (0, 3),
                    b: (1, 0),
                    stiffness: 7.0,
                    damping: c,
                    angle: 0.2,
                    scaled: Scaling::Fixed,
                }),
            ]
        };
        let mut b = aluminium_body("b", 2);
        b.start = [0.6, 0.1];
        let system = |loads: &[Load]| {
            FlexibleSystem::new(
                vec![aluminium_body("a", 3), b.clone()],
                &[],
                loads,
                &[],
                vec![],
                Rayleigh::default(),
                LinearSolverKind::Banded,
            )
        };
        let mu = Parameters::load_scale(1.0);
        let coef = IterationCoefficients { mass: 0.0, damping: 0.7, stiffness: 1.3 };
        // the dense iteration matrix and the force of a system
        let matrix = |sys: &mut FlexibleSystem, q: &[f64], v: &[f64]| {
            let n = q.len();
            ParametricModel::factor(sys, &mu, q, v, 0.0, coef).unwrap();
            let mut s = vec![0.0; n * n];
            for k in 0..sys.n_blocks() {
                let d = *sys.block_dofs(k);
                for i in 0..8 {
                    for j in 0..8 {
                        s[d[i] * n + d[j]] += sys.blocks[k][(i, j)];
                    }
                }
            }
            s
        };
        let force = |sys: &mut FlexibleSystem, q: &[f64], v: &[f64]| {
            let mut g = vec![0.0; q.len()];
            ParametricModel::force(sys, &mu, q, v, 0.0, &mut g);
            g
        };
        let mut bare = system(&[]);
        for c in [0.0, 0.3] {
            let mut sys = system(&springs(c));
            // one coupling block: a's end and b's start are in no element together
            assert_eq!(sys.n_blocks(), sys.n_elements() + 1);
            let n = ParametricModel::n_dof(&sys);
            let q: Vec<f64> =
                sys.initial_state().iter().enumerate().map(|(i, x)| x + 0.02 * (i as f64 * 0.9).sin()).collect();
            let v: Vec<f64> = (0..n).map(|i| 0.5 * (i as f64 * 0.4).cos()).collect();
            let (with, without) = (matrix(&mut sys, &q, &v), matrix(&mut bare, &q, &v));
            let s: Vec<f64> = with.iter().zip(&without).map(|(a, b)| a - b).collect();
            let mut spring_force = |q: &[f64], v: &[f64]| -> Vec<f64> {
                force(&mut sys, q, v).iter().zip(force(&mut bare, q, v)).map(|(a, b)| a - b).collect()
            };
            // the elements' forces (~1e5 N at this strain) leave a round-off of ~1e-11 N in
            // the difference: h = 1e-5 keeps it at 1e-6 N/m, its truncation (h/L)² ~ 1e-9
            let h = 1e-5;
            let scale = s.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            assert!(scale > 100.0, "the springs' part is there: {scale}");
            for col in 0..n {
                let mut fd = vec![0.0; n];
                for (wrt, f) in [(0, coef.stiffness), (1, coef.damping)] {
                    let (mut plus, mut minus) = ([q.clone(), v.clone()], [q.clone(), v.clone()]);
                    plus[wrt][col] += h;
                    minus[wrt][col] -= h;
                    let (gp, gm) = (spring_force(&plus[0], &plus[1]), spring_force(&minus[0], &minus[1]));
                    for r in 0..n {
                        fd[r] += f * (gp[r] - gm[r]) / (2.0 * h);
                    }
                }
                for r in 0..n {
                    // 1e-6 of the largest entry: above the differences' truncation and round-off
                    let want = s[r * n + col];
                    assert!((fd[r] - want).abs() <= 1e-6 * scale, "c = {c}: ({r}, {col}) {} vs {want}", fd[r]);
                }
            }
            if c == 0.0 {
                for (k, blk) in sys.blocks.iter().enumerate() {
                    for i in 0..8 {
                        for j in 0..8 {
                            assert_eq!(blk[(i, j)].to_bits(), blk[(j, i)].to_bits(), "block {k} ({i}, {j})");
                        }
                    }
                }
            }
        }
    }
}
