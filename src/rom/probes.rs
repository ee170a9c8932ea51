//! The probes of a reduced trajectory, evaluated from the rows of the basis on each probe's
//! element alone: `x_e(t_k) = x_ref,e + V_e z_k` (8 rows of `V`), so that nothing of size
//! `n_dof` is formed. Shared by the reduced runs and the error estimators, which read the
//! enriched model's probes the same way.

use crate::physics::element::Vec8;
use crate::physics::system::{FlexibleSystem, Probe};
use crate::reduction::Basis;
use crate::simulate::Series;
use ndarray::{Array2, ArrayView2, Axis};

/// Every probe's position (name → n_t × 2) and the strains and curvatures of the probes
/// that record them, in the layout of [`crate::simulate::SimulationResult`].
#[derive(Clone, Debug, Default)]
pub struct ProbeValues {
    pub positions: Vec<(String, Array2<f64>)>,
    pub strains: Series,
    pub curvatures: Series,
}

/// The probes of `sys` along the reduced trajectory `z` (r × n_t) of `basis`.
pub fn probe_values(sys: &FlexibleSystem, basis: &Basis, z: ArrayView2<f64>) -> ProbeValues {
    let nt = z.ncols();
    let element_coordinates = |p: &Probe| {
        let dofs = sys.element_dofs(p.element);
        let ve = basis.modes.select(Axis(0), dofs);
        let xe_ref = basis.reference.select(Axis(0), dofs);
        ve.dot(&z) + &xe_ref.insert_axis(Axis(1))
    };
    let column = |xe: &Array2<f64>, k: usize| Vec8::from_iterator(xe.column(k).iter().copied());
    let positions = sys
        .probes
        .iter()
        .map(|p| {
            let (xe, el) = (element_coordinates(p), sys.element(p.element));
            let mut xy = Array2::zeros((nt, 2));
            for k in 0..nt {
                let r = el.position(&column(&xe, k), p.xi);
                xy[[k, 0]] = r[0];
                xy[[k, 1]] = r[1];
            }
            (p.name.clone(), xy)
        })
        .collect();
    let (strains, curvatures) = crate::simulate::probe_sections(&sys.probes, |p| {
        let (xe, el) = (element_coordinates(p), sys.element(p.element));
        (0..nt)
            .map(|k| {
                let e = column(&xe, k);
                (el.axial_strain(&e, p.xi), el.curvature(&e, p.xi))
            })
            .collect()
    });
    ProbeValues { positions, strains, curvatures }
}
