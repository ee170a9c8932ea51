//! The hyper-reduced model's per-iteration kernels: the invariants and their derivatives
//! at `q` (`update`), the sampled elements' force and their tangent, each compiled for the
//! CPU's best instruction set through [`crate::linalg::simd`] (the sums themselves are the
//! block kernels of [`super::sampled`]).

use super::HyperReducedModel;
use crate::linalg::simd::{dispatch, Kernel};
use crate::solver::model::InvariantElementModel;

impl<M: InvariantElementModel> HyperReducedModel<M> {
    /// s_j = xₑᵀSⱼxₑ, ψⱼ, ψⱼₖ and uⱼ = Vₑᵀ Sⱼ xₑ of every sampled element at `q`, with
    /// xₑ = x_ref,ₑ + Vₑ q (once per q: the integrator asks for the force and then the
    /// matrix at the same q).
    pub(super) fn update(&mut self, q: &[f64]) {
        if self.valid && self.at == q {
            return;
        }
        // the kernel, inlined whole into the dispatched function (see crate::linalg::simd)
        struct Update<'a, T: InvariantElementModel, const N: usize>(&'a mut HyperReducedModel<T>, &'a [f64]);
        impl<T: InvariantElementModel, const N: usize> Kernel for Update<'_, T, N> {
            type Output = ();
            #[inline(always)]
            fn run(self) {
                let (full, elements) = (&*self.0.full, &self.0.elements);
                self.0.sampled.update::<N>(self.1, |k, s, d1, d2| full.invariant_derivatives(elements[k], s, d1, d2))
            }
        }
        match self.ne {
            4 => dispatch(Update::<M, 4>(self, q)),
            6 => dispatch(Update::<M, 6>(self, q)),
            8 => dispatch(Update::<M, 8>(self, q)),
            12 => dispatch(Update::<M, 12>(self, q)),
            _ => unreachable!("element size checked in new()"),
        }
        self.at.copy_from_slice(q);
        self.valid = true;
    }

    /// `out += Σ_E wₑ Σⱼ 2ψⱼ uⱼ` at the cached point.
    pub(super) fn add_force(&mut self, out: &mut [f64]) {
        struct Force<'a, T: InvariantElementModel>(&'a mut HyperReducedModel<T>, &'a mut [f64]);
        impl<T: InvariantElementModel> Kernel for Force<'_, T> {
            type Output = ();
            #[inline(always)]
            fn run(self) {
                self.0.sampled.add_force(self.1)
            }
        }
        dispatch(Force(self, out))
    }

    /// `acc` = the upper triangle of Σ_E wₑ [Σⱼ 2ψⱼ Gₑⱼ + Σⱼₖ 4ψⱼₖ uⱼ uₖᵀ] at the cached point
    /// (both terms are symmetric), on the runs that elements reach (the rest stays zero),
    /// compiled for the CPU's best instruction set ([`crate::linalg::simd`]).
    pub(super) fn tangent(&mut self) {
        struct Tangent<'a, T: InvariantElementModel>(&'a mut HyperReducedModel<T>);
        impl<T: InvariantElementModel> Kernel for Tangent<'_, T> {
            type Output = ();
            #[inline(always)]
            fn run(self) {
                let m = self.0;
                let r = m.p.r;
                for &(i, j0, j1) in &m.runs {
                    m.acc[i * r + j0..i * r + j1].fill(0.0);
                }
                m.sampled.add_tangent(&mut m.acc)
            }
        }
        dispatch(Tangent(self))
    }
}
