//! The basis of training snapshots: the snapshot matrix of full runs, the POD basis of the
//! pipeline's variant and blocks, its hyper-reduction and its error estimator.

use crate::error::{Error, Result};
use crate::io::basis_file::TrainingData;
use crate::physics::element::Vec8;
use crate::physics::system::FlexibleSystem;
use crate::pipeline::config::{Blocks, Pipeline};
use crate::reduction::output_modes::{add_output_modes, Output, Outputs, Stop};
use crate::reduction::{ecsw, train_basis, BasisSpec, ModeRule, Trained};
use crate::rom::estimator::training::{build_estimator, Estimator, Snapshots, DEFAULT_EXTRA_MODES};
use crate::rom::quantities::Quantity;
use crate::simulate::SimulationResult;
use crate::training::training_record::TrainSummary;
use ndarray::{concatenate, Array1, Axis};

pub(super) fn joint_dofs_of(sys: &FlexibleSystem) -> Vec<usize> {
    let mut d: Vec<usize> = sys.constraints.iter().flat_map(|c| c.terms.iter().map(|&(dof, _)| dof)).collect();
    d.sort_unstable();
    d.dedup();
    d
}

/// The joint equations and multiplier mode rule of the whole-system-stabilized variant
/// (`None` for the others).
fn stabilization_for(p: &Pipeline, sys: &FlexibleSystem) -> Option<crate::reduction::Stabilization> {
    use crate::reduction::whole_system::{constraint_matrix, DEFAULT_MULTIPLIER_MODES};
    (p.variant() == crate::reduction::Variant::WholeSystemStabilized).then(|| {
        let rows: Vec<Vec<(usize, f64)>> = sys.constraints.iter().map(|c| c.terms.clone()).collect();
        crate::reduction::Stabilization {
            constraints: constraint_matrix(crate::solver::model::ParametricModel::n_dof(sys), &rows),
            multiplier_modes: p.file.reduction.multiplier_modes.clone().unwrap_or(DEFAULT_MULTIPLIER_MODES),
        }
    })
}

/// The snapshots of full runs, side by side in run order.
pub fn training_data(runs: &[SimulationResult]) -> TrainingData {
    let cat = |f: &dyn Fn(&SimulationResult) -> ndarray::ArrayView2<f64>| {
        concatenate(Axis(1), &runs.iter().map(f).collect::<Vec<_>>()).expect("same row counts")
    };
    TrainingData {
        x: cat(&|r| r.q.view()),
        multipliers: cat(&|r| r.multipliers.view()),
        load_scale: Array1::from_iter(runs.iter().flat_map(|r| std::iter::repeat_n(r.settings.mu.scale(), r.t.len()))),
        t: Array1::from_iter(runs.iter().flat_map(|r| r.t.iter().copied())),
    }
}

/// The basis of the pipeline's variant and blocks from `data` with `modes` (and output modes
/// at `probe_tolerance` when given), hyper-reduced by ECSW at `hyper_tolerance` when given,
/// and its error estimator (uncalibrated: the same
/// POD with [`DEFAULT_EXTRA_MODES`] more modes per block); `Err((pipeline field, problem))`.
pub fn build_basis(
    p: &Pipeline,
    data: &TrainingData,
    modes: ModeRule,
    (hyper_tolerance, probe_tolerance): (Option<f64>, Option<f64>),
) -> std::result::Result<(Trained, Estimator), (&'static str, String)> {
    // the physics, assembled once for the blocks, the joint rows, ECSW and the estimator
    let physics = p.model.physics().map_err(|e| ("model", e.to_string()))?;
    let sys = &*physics.sys;
    // every run starts from the same consistent, undeformed state; with `[initial] static`
    // from the equilibrium of its own loads, and the basis is centred on the undeformed
    // state all the same (what reduced runs and the basis checks take as x₀)
    let starts_static = p.model.starts_static();
    let x_ref = if starts_static { Array1::from(physics.x0.to_vec()) } else { data.x.column(0).to_owned() };
    // whole-system: scale the multipliers so both blocks weigh alike in the POD
    let dx = (&data.x - &x_ref.view().insert_axis(Axis(1))).mapv(|v| v * v).sum().sqrt();
    let dl = data.multipliers.mapv(|v| v * v).sum().sqrt();
    let w = if dx > 0.0 && dl > 0.0 { dl / dx } else { 1.0 };
    let blocks = match p.blocks() {
        Some(Blocks::Bodies) => (0..sys.bodies.len()).map(|b| sys.body_dofs(b).collect()).collect(),
        None => Vec::new(),
    };
    let stabilization = stabilization_for(p, sys);
    let spec = BasisSpec {
        variant: p.variant(),
        snapshots: p.file.train.snapshots,
        modes,
        multiplier_scale: w,
        blocks,
        stabilization,
    };
    let joints = joint_dofs_of(sys);
    let mut trained = train_basis(data.x.view(), data.multipliers.view(), &joints, x_ref.view(), &spec)
        .map_err(|e| ("reduction.modes", e.problem()))?;
    let eval = |o: usize, v: &[f64]| probe_output(sys, o, v);
    let outputs =
        probe_tolerance.map(|_| Outputs { outputs: probe_outputs(p, sys, physics.length_scale()), eval: &eval });
    let rows = block_rows(&spec, &trained);
    if let (Some(tol), Some(outputs)) = (probe_tolerance, &outputs) {
        add_output_modes(&mut trained, &rows, data.x.view(), outputs, &[], Stop::Tolerance(tol))
            .map_err(|e| ("reduction.probe_modes", e.problem()))?;
    }
    if let Some(tol) = hyper_tolerance {
        let hyper = ecsw(sys, &trained.basis, data.x.view(), tol)
            .map_err(|e| ("reduction.hyper", format!("ECSW training failed: {e}")))?;
        within_weight_bound(&hyper, sys.n_elements())?;
        trained.basis.hyper = Some(hyper);
    }
    let snapshots = Snapshots {
        x: data.x.view(),
        multipliers: data.multipliers.view(),
        joint_dofs: &joints,
        x_ref: x_ref.view(),
        outputs: outputs.as_ref().map(|o| (o, rows.as_slice())),
    };
    let estimator = build_estimator(sys, &trained, &spec, &snapshots, hyper_tolerance, DEFAULT_EXTRA_MODES)
        .map_err(|e| ("reduction", format!("cannot build the error estimator: {e}")))?;
    Ok((trained, estimator))
}

/// The rows each block's modes live on: the block's coordinates without the kept ones
/// (one block of every reduced coordinate without blocks).
fn block_rows(spec: &BasisSpec, trained: &Trained) -> Vec<Vec<usize>> {
    if spec.blocks.is_empty() {
        return vec![trained.reduced_dofs.clone()];
    }
    let kept = &trained.basis.kept;
    spec.blocks.iter().map(|b| b.iter().copied().filter(|d| !kept.contains(d)).collect()).collect()
}

/// The outputs of `[reduction] probe_modes`: every strain and curvature a probe records,
/// each reading its element's 8 coordinates, with the resolution of the quantity at the
/// model's Newton tolerance ([`Quantity::resolution`]) as its floor. Output `2 i` is probe
/// `i`'s strain, `2 i + 1` its curvature (a probe that records one of them only has the
/// other left out).
fn probe_outputs(p: &Pipeline, sys: &FlexibleSystem, length: f64) -> Vec<Output> {
    let tol = p.model.integrator_params().tolerance;
    let mut out = Vec::new();
    for (i, probe) in sys.probes.iter().enumerate() {
        let dofs = sys.element_dofs(probe.element).to_vec();
        for (k, (wanted, q)) in
            [(probe.strain, Quantity::Strain), (probe.curvature, Quantity::Curvature)].into_iter().enumerate()
        {
            if wanted {
                out.push(Output { dofs: dofs.clone(), floor: q.resolution(tol, length), id: 2 * i + k });
            }
        }
    }
    out
}

/// Output `o` of [`probe_outputs`] at its element's coordinates `v`.
fn probe_output(sys: &FlexibleSystem, o: usize, v: &[f64]) -> f64 {
    let probe = &sys.probes[o / 2];
    let e = Vec8::from_iterator(v.iter().copied());
    let el = sys.element(probe.element);
    if o % 2 == 0 {
        el.axial_strain(&e, probe.xi)
    } else {
        el.curvature(&e, probe.xi)
    }
}

/// Refuses an ECSW set the basis check would refuse on reading it back (a weight above
/// [`crate::io::basis_check::MAX_WEIGHT_PER_ELEMENT`] per element): said here, as the
/// pipeline's setting, rather than as a defect of the file just written.
fn within_weight_bound(
    h: &crate::reduction::Hyper,
    n_elements: usize,
) -> std::result::Result<(), (&'static str, String)> {
    let max = crate::io::basis_check::MAX_WEIGHT_PER_ELEMENT * n_elements as f64;
    match h.weights.iter().zip(&h.elements).find(|(w, _)| !(**w <= max)) {
        None => Ok(()),
        Some((w, e)) => Err((
            "reduction.hyper",
            format!(
                "ECSW gave element {e} the weight {w:.3e}, above the {max:.0e} ({:.0e} per element) a basis may hold: the training runs barely load that element, so its force would stand in for many; train with more modes or load scales, a smaller hyper tolerance, or without hyper-reduction",
                crate::io::basis_check::MAX_WEIGHT_PER_ELEMENT
            ),
        )),
    }
}

/// The basis and estimator of fixed-load training (`train.load_scales`, the pipeline's
/// `[reduction]` rule) from the snapshots of `n_runs` full runs, on one machine or gathered
/// from sharded jobs ([`crate::training::snapshots`]).
pub(crate) fn basis_from_snapshots(
    p: &Pipeline,
    data: TrainingData,
    full_seconds: f64,
    n_runs: usize,
) -> Result<(TrainingData, TrainSummary)> {
    let modes = p.file.reduction.modes.clone().ok_or_else(|| Error::input(&p.path, "reduction.modes", "is missing"))?;
    let tol = p.file.reduction.hyper.as_ref().map(|h| h.tolerance);
    let (trained, estimator) = build_basis(p, &data, modes, (tol, p.probe_mode_tolerance(None)))
        .map_err(|(f, e)| Error::input(&p.path, f, e))?;
    let n_snapshots = data.x.ncols();
    let summary = TrainSummary {
        trained,
        n_snapshots,
        full_seconds,
        n_runs,
        greedy: None,
        estimator: Some(estimator),
        warnings: Vec::new(),
    };
    Ok((data, summary))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bound training holds its ECSW set to is the one the basis check reads it back
    /// with (1e4 per element): a weight of 3.8e8 on a 50-element model, as a campaign's
    /// training wrote and then refused on reading it back, is refused as the pipeline's
    /// `reduction.hyper`; the largest weight the check takes passes.
    #[test]
    fn ecsw_weights_beyond_the_basis_check_are_refused_at_training() {
        let set = |w: f64| crate::reduction::Hyper {
            elements: vec![0, 7],
            weights: vec![w, 1.0],
            tolerance: 1e-3,
            training_residual: 0.0,
            n_training: 10,
        };
        let max = crate::io::basis_check::MAX_WEIGHT_PER_ELEMENT * 50.0;
        assert!(within_weight_bound(&set(max), 50).is_ok());
        for w in [3.8e8, f64::INFINITY, f64::NAN] {
            let (field, problem) = within_weight_bound(&set(w), 50).unwrap_err();
            assert_eq!(field, "reduction.hyper");
            assert!(problem.contains("element 0") && problem.contains("5e5"), "{problem}");
        }
    }
}
