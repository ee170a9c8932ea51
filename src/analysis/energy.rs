//! The energies of a state (SPEC §6), at the parameters `μ`:
//!
//! ```text
//! kinetic          T = ½ q̇ᵀ M q̇
//! strain           U = Σ_e (½ eᵀ K_t e + ½ EA l ε̄²)   (bending, then axial; E = E(μ))
//! gravity          V = −g₀(μ)ᵀ q                       (−Σ ∫ ρA g · r ds)
//! springs          V_s = Σ ½ k (L − L₀)² + Σ ½ k φ²   (translational, torsional)
//! external work    W(t) = ∫₀ᵗ (Q_ext − Q_s)ᵀ q̇ dt     (forces, moments and the springs'
//!                                                       dampers, not gravity)
//! drive work       W_d(t) = −∫₀ᵗ λᵀ (ḃ − Ḃ q) dt      (prescribed motions)
//! ```
//!
//! A prescribed motion's rows `B(t) q = b(t)` hold the system with the force `−Bᵀλ`, whose
//! power `−λᵀ B q̇ = −λᵀ (ḃ − Ḃ q)` is not zero where the rows move: the work a motor does
//! to keep the hub on its prescribed angle. Constant joints do no work (`ḃ − Ḃ q = 0`).
//!
//! with `Q_s` the springs' elastic forces (`−Q_sᵀ q̇ = V̇_s`): the spring-dampers' dampers
//! enter `W` as the negative work `−∫ c L̇² dt` (`−∫ c φ̇² dt`) they dissipate, so that
//! `T + U + V + V_s − W − W_d` stays constant with them too. `W` and `W_d` are integrated by
//! the trapezoidal rule over the recorded instants (second order, as the integrator at
//! `ρ∞ = 1`). Without Rayleigh damping `T + U + V + V_s − W − W_d` stays constant to the
//! integrator's order; Rayleigh damping makes it decrease (the dissipated energy).

use crate::physics::element::Vec8;
use crate::physics::system::FlexibleSystem;
use crate::solver::model::{ElementModel, Parameters, ParametricModel};
use ndarray::Array1;

/// One series per energy, one value per instant, J.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Energies {
    pub kinetic: Array1<f64>,
    pub strain: Array1<f64>,
    pub strain_axial: Array1<f64>,
    pub strain_bending: Array1<f64>,
    pub gravity: Array1<f64>,
    pub springs: Array1<f64>,
    pub external_work: Array1<f64>,
    pub drive_work: Array1<f64>,
}

impl Energies {
    /// The series by name, as the result file's `/energy/<name>` and the CSV columns
    /// `energy_<name>`.
    pub fn named(&self) -> [(&'static str, &Array1<f64>); 8] {
        [
            ("kinetic", &self.kinetic),
            ("strain", &self.strain),
            ("strain_axial", &self.strain_axial),
            ("strain_bending", &self.strain_bending),
            ("gravity", &self.gravity),
            ("springs", &self.springs),
            ("external_work", &self.external_work),
            ("drive_work", &self.drive_work),
        ]
    }

    /// `T + U + V + springs − W − W_d` at each instant: constant without damping.
    pub fn total(&self) -> Array1<f64> {
        &self.kinetic + &self.strain + &self.gravity + &self.springs - &self.external_work - &self.drive_work
    }
}

/// The elements whose strain energy a model sums: every element at weight 1 (`None`, the
/// full model and a reduced one without hyper-reduction), or a hyper-reduced model's
/// sampled elements with their ECSW weights, `U ≈ Σ_{e∈S} w_e U_e`: the energy the reduced
/// model itself conserves.
pub type ElementWeights<'a> = Option<(&'a [usize], &'a [f64])>;

/// `(bending, axial)` strain energy of the whole system at `q`.
pub fn strain_parts(sys: &FlexibleSystem, mu: &Parameters, q: &[f64]) -> (f64, f64) {
    let (mut bending, mut axial) = (0.0, 0.0);
    for e in 0..sys.n_elements() {
        let (b, a) = element_strain(sys, mu, q, e);
        bending += b;
        axial += a;
    }
    (bending, axial)
}

/// [`strain_parts`] over the elements `weights` names (all of them for `None`).
pub fn strain_parts_over(sys: &FlexibleSystem, mu: &Parameters, q: &[f64], weights: ElementWeights) -> (f64, f64) {
    let Some((elements, w)) = weights else { return strain_parts(sys, mu, q) };
    let (mut bending, mut axial) = (0.0, 0.0);
    for (&e, &we) in elements.iter().zip(w) {
        let (b, a) = element_strain(sys, mu, q, e);
        bending += we * b;
        axial += we * a;
    }
    (bending, axial)
}

/// Element `e`'s `(bending, axial)` strain energy at `q`, at `E(μ)`.
fn element_strain(sys: &FlexibleSystem, mu: &Parameters, q: &[f64], e: usize) -> (f64, f64) {
    let d = sys.element_dofs(e);
    let qe = Vec8::from_fn(|i, _| q[d[i]]);
    let k = sys.stiffness_factor(e, mu);
    let (b, a) = sys.element(e).strain_energy_parts(&qe);
    (k * b, k * a)
}

/// `(Q_ext − Q_s)ᵀ q̇` of the forces, moments and springs' dampers (not gravity), with
/// `V̇_s` of the springs given as `spring_rate`.
fn load_power(sys: &FlexibleSystem, mu: &Parameters, (q, v): (&[f64], &[f64]), t: f64, spring_rate: f64) -> f64 {
    let dofs = sys.load_dofs();
    if dofs.is_empty() {
        return 0.0;
    }
    let (ql, vl): (Vec<f64>, Vec<f64>) = dofs.iter().map(|&d| (q[d], v[d])).unzip();
    let mut g = vec![0.0; dofs.len()];
    // g = −Q_ext on the load dofs (the springs' forces in it)
    sys.load_force(mu, &ql, &vl, t, &mut g);
    let power = -dofs.iter().zip(&g).map(|(&d, g)| g * v[d]).sum::<f64>();
    // the springs' elastic power −V̇_s is stored, not external, work
    if spring_rate != 0.0 {
        power + spring_rate
    } else {
        power
    }
}

/// The power of the prescribed motions at `(q, t)` with the multipliers `lambda`,
/// `−λᵀ (ḃ − Ḃ q)` over the rows that move (`work`: n_c scratch): exactly 0 without any,
/// whatever `lambda` holds (a reduced run without physical multipliers keeps NaN).
fn drive_power(sys: &FlexibleSystem, mu: &Parameters, (q, lambda): (&[f64], &[f64]), t: f64, work: &mut [f64]) -> f64 {
    ParametricModel::constraint_velocity_rhs(sys, mu, q, t, work);
    -lambda.iter().zip(work.iter()).filter(|(_, &w)| w != 0.0).map(|(l, w)| l * w).sum::<f64>()
}

/// A run's states: `(q_k, q̇_k, λ_k)` at instant `k` (λ: the physical multipliers, NaN
/// where a run kept none).
pub struct States<Q, V, L> {
    pub q: Q,
    pub v: V,
    pub lambda: L,
}

/// The energies of the states `(t_k, q_k, q̇_k, λ_k)` of a run at `μ`.
pub fn energies<Q, V, L>(sys: &mut FlexibleSystem, mu: &Parameters, t: &[f64], states: States<Q, V, L>) -> Energies
where
    Q: Fn(usize) -> Vec<f64>,
    V: Fn(usize) -> Vec<f64>,
    L: Fn(usize) -> Vec<f64>,
{
    energies_over(sys, mu, t, states, None)
}

/// [`energies`] with the strain summed over the elements `weights` names: a reduced run's
/// energies from its reconstructed states `x_ref + V z`, `V ż` (the kinetic energy
/// `½ żᵀ VᵀMV ż`, the gravity's `−g₀ᵀ(x_ref + V z)`, the strain of its own sampled elements).
pub fn energies_over<Q, V, L>(
    sys: &mut FlexibleSystem,
    mu: &Parameters,
    t: &[f64],
    States { q, v, lambda }: States<Q, V, L>,
    weights: ElementWeights,
) -> Energies
where
    Q: Fn(usize) -> Vec<f64>,
    V: Fn(usize) -> Vec<f64>,
    L: Fn(usize) -> Vec<f64>,
{
    let nt = t.len();
    sys.bind(mu);
    let mut out = Energies {
        kinetic: Array1::zeros(nt),
        strain: Array1::zeros(nt),
        strain_axial: Array1::zeros(nt),
        strain_bending: Array1::zeros(nt),
        gravity: Array1::zeros(nt),
        springs: Array1::zeros(nt),
        external_work: Array1::zeros(nt),
        drive_work: Array1::zeros(nt),
    };
    let (mut last_power, mut last_drive) = (0.0, 0.0);
    let mut rows = vec![0.0; ParametricModel::n_constraints(sys)];
    // gravity's potential −g₀(μ)ᵀ q: its gradient is constant, taken once
    let weight = sys.gravity_potential_gradient(mu);
    let mut mv = vec![0.0; weight.len()];
    for k in 0..nt {
        let (qk, vk) = (q(k), v(k));
        sys.mass_mul(&vk, &mut mv);
        out.kinetic[k] = 0.5 * vk.iter().zip(&mv).map(|(a, b)| a * b).sum::<f64>();
        let (b, a) = strain_parts_over(sys, mu, &qk, weights);
        out.strain_bending[k] = b;
        out.strain_axial[k] = a;
        out.strain[k] = a + b;
        out.gravity[k] = weight.iter().zip(&qk).map(|(g, q)| g * q).sum();
        let (stored, rate) = sys.spring_energy(mu, &qk, &vk);
        out.springs[k] = stored;
        let power = load_power(sys, mu, (&qk, &vk), t[k], rate);
        let drive = drive_power(sys, mu, (&qk, &lambda(k)), t[k], &mut rows);
        if k > 0 {
            let h = 0.5 * (t[k] - t[k - 1]);
            out.external_work[k] = out.external_work[k - 1] + h * (power + last_power);
            out.drive_work[k] = out.drive_work[k - 1] + h * (drive + last_drive);
        }
        (last_power, last_drive) = (power, drive);
    }
    out
}
