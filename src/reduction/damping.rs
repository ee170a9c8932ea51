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
        let parts: Vec<_> = damping_parts(full)
            .into_iter()
            .map(|part| {
                let mut c = Array2::zeros((v.ncols(), v.ncols()));
                part.each_element(full, |dofs, ce| {
                    let ve = v.select(Axis(0), dofs);
                    c += &ve.t().dot(&ce.t().dot(&ve));
                });
                (part.member, part.follows_mass, c)
            })
            .collect();
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
        let factor = |&(member, follows_mass, _): &(Option<usize>, bool, Array2<f64>)| {
            part_factor(full, (member, follows_mass), mu)
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

/// A part of a model's damping: Rayleigh's mass or stiffness part over a group of elements
/// one parameter scales (every element where none does).
pub(crate) struct DampingPart {
    /// an element of the group, where its factor is read
    pub member: Option<usize>,
    /// whether the part follows the mass (else the stiffness)
    pub follows_mass: bool,
    pub members: Vec<usize>,
}

impl DampingPart {
    /// Calls `each(dofs, Cₑ)` with each element's global dofs and its part of `Cₑ` at the
    /// model file's values (symmetric).
    pub(crate) fn each_element<M: ElementModel + ?Sized>(
        &self,
        full: &M,
        mut each: impl FnMut(&[usize], ArrayView2<f64>),
    ) {
        let ne = full.element_dofs(0).len();
        let (mut cm, mut cs) = (vec![0.0; ne * ne], vec![0.0; ne * ne]);
        for &e in &self.members {
            full.element_damping_parts(e, &mut cm, &mut cs);
            // column-major Cₑ read row-major is Cₑᵀ = Cₑ
            let ce = ArrayView2::from_shape((ne, ne), if self.follows_mass { &cm } else { &cs }).expect("ne × ne");
            each(full.element_dofs(e), ce);
        }
    }
}

/// `m_g(μ)` or `s_h(μ)` of a damping part (its element `member`, whether it follows the
/// mass); 1 for a part no parameter scales.
pub(crate) fn part_factor<M: ElementModel + ?Sized>(
    full: &M,
    (member, follows_mass): (Option<usize>, bool),
    mu: &Parameters,
) -> f64 {
    match member {
        Some(e) if follows_mass => full.mass_factor(e, mu),
        Some(e) => full.stiffness_factor(e, mu),
        None => 1.0,
    }
}

/// The parts of `full`'s damping: by mass group, then by stiffness group ([`mass_groups`],
/// [`stiffness_groups`]; all elements in one group where no parameter scales them); none for
/// a model without elements.
pub(crate) fn damping_parts<M: ElementModel + ?Sized>(full: &M) -> Vec<DampingPart> {
    let n = full.n_elements();
    if n == 0 {
        return Vec::new();
    }
    let whole = |groups: Vec<(Option<String>, Vec<usize>)>| {
        if groups.is_empty() {
            vec![(None, (0..n).collect())]
        } else {
            groups
        }
    };
    let by = [(true, whole(mass_groups(full))), (false, whole(stiffness_groups(full)))];
    by.into_iter()
        .flat_map(|(follows_mass, groups)| {
            groups.into_iter().map(move |(_, members)| DampingPart {
                member: members.first().copied(),
                follows_mass,
                members,
            })
        })
        .collect()
}
