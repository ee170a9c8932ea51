//! The projected damping of a model whose mass or stiffness is a parameter. Each element's
//! damping splits into a part that follows its mass and one that follows its stiffness
//! ([`ElementModel::element_damping_parts`], Rayleigh `a Mₑ + b Kₑ`), so that
//!
//! ```text
//!     C_r(μ) = Σ_g m_g(μ) C_r,g^m + Σ_h s_h(μ) C_r,h^s,
//!     C_r,g^m = Σ_{e ∈ g} Vₑᵀ Cₑ,m Vₑ,   C_r,h^s = Σ_{e ∈ h} Vₑᵀ Cₑ,s Vₑ,
//! ```
//!
//! over the groups `g` of elements one mass parameter scales and `h` one stiffness parameter
//! scales ([`mass_groups`], [`stiffness_groups`]). Every element's damping is summed, exact:
//! it is linear, so the sample of a hyper-reduced model need not carry it. A reduced model
//! keeps `C_r(μ)` and evaluates its elements without velocities.

use crate::solver::model::{mass_groups, stiffness_groups, ElementModel, Parameters};
use ndarray::{Array2, ArrayView2, Axis};

/// A projected damping matrix per group, and the sum at the factors last bound.
pub(crate) struct DampingSplit {
    /// per group: an element of it (`None`: no parameter scales it), whether it follows
    /// the mass (else the stiffness), and its projected part
    parts: Vec<(Option<usize>, bool, Array2<f64>)>,
    factors: Vec<f64>,
    /// `C_r(μ)` at `factors`
    current: Array2<f64>,
}

impl DampingSplit {
    /// The split of `full`'s damping on the modes `v` (n × r), or `None` when it needs
    /// none: an undamped model, or one without mass or stiffness parameters (its damping is
    /// then constant, and the element forces carry it).
    pub(crate) fn new<M: ElementModel + ?Sized>(full: &M, v: ArrayView2<f64>) -> Option<Self> {
        let (by_mass, by_stiffness) = (mass_groups(full), stiffness_groups(full));
        if (by_mass.is_empty() && by_stiffness.is_empty()) || full.n_elements() == 0 {
            return None;
        }
        let whole = |groups: Vec<(Option<String>, Vec<usize>)>| {
            if groups.is_empty() {
                vec![(None, (0..full.n_elements()).collect())]
            } else {
                groups
            }
        };
        let ne = full.element_dofs(0).len();
        let (mut cm, mut cs) = (vec![0.0; ne * ne], vec![0.0; ne * ne]);
        let mut parts = Vec::new();
        for (follows_mass, groups) in [(true, whole(by_mass)), (false, whole(by_stiffness))] {
            for (_, members) in groups {
                let mut c = Array2::zeros((v.ncols(), v.ncols()));
                for &e in &members {
                    full.element_damping_parts(e, &mut cm, &mut cs);
                    let ce = if follows_mass { &cm } else { &cs };
                    let ve = v.select(Axis(0), full.element_dofs(e));
                    // column-major Cₑ: its transpose read row-major, and Cₑ is symmetric
                    let ce = ArrayView2::from_shape((ne, ne), ce).expect("ne × ne");
                    c += &ve.t().dot(&ce.t().dot(&ve));
                }
                parts.push((members.first().copied(), follows_mass, c));
            }
        }
        if parts.iter().all(|(.., c)| c.iter().all(|&x| x == 0.0)) {
            return None;
        }
        let factors = vec![1.0; parts.len()];
        let current = parts.iter().fold(Array2::zeros((v.ncols(), v.ncols())), |acc, (.., c)| acc + c);
        Some(DampingSplit { parts, factors, current })
    }

    /// `C_r(μ)`, summed again when a factor changed at `mu`: `Some` then, `None` when it is
    /// the one of the last call.
    pub(crate) fn bind<M: ElementModel + ?Sized>(&mut self, full: &M, mu: &Parameters) -> Option<&Array2<f64>> {
        let factor = |&(e, follows_mass, _): &(Option<usize>, bool, Array2<f64>)| match e {
            Some(e) if follows_mass => full.mass_factor(e, mu),
            Some(e) => full.stiffness_factor(e, mu),
            None => 1.0,
        };
        // the same factors (every evaluation of a run): nothing to do, nothing allocated
        if self.parts.iter().zip(&self.factors).all(|(p, &f)| factor(p) == f) {
            return None;
        }
        let factors: Vec<f64> = self.parts.iter().map(factor).collect();
        self.current.fill(0.0);
        for ((.., c), &f) in self.parts.iter().zip(&factors) {
            self.current.scaled_add(f, c);
        }
        self.factors = factors;
        Some(&self.current)
    }

    /// `C_r(μ)` at the factors last bound (the file's values before any).
    pub(crate) fn matrix(&self) -> &Array2<f64> {
        &self.current
    }
}
