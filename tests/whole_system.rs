//! Whole-system reduction (docs/whole-system.md): the plain variant (one POD of `[x; λ/w]`, thesis eqs.
//! 18–19) and the stabilized one (separate PODs, supremizers; src/reduction/whole_system.rs).
//!
//! Checks, with where each expected number comes from:
//! - the plain four-bar basis (pipelines/thesis/fourbar_whole_system.toml) has inf-sup
//!   constant σ_min(V_λᵀ B V) ≈ 0 (below 1e-6: every snapshot satisfies B x = b, so the
//!   coordinate part of every POD mode has B V = 0 up to round-off over σ), and its reduced
//!   run fails with a message naming the stabilized variant (what a user must switch to);
//! - the stabilized basis of the thesis setting (pipelines/thesis/fourbar_whole_system_stabilized.toml,
//!   30 % of the coordinates, λ = 0.935, 4 multiplier modes) has β ≥ INF_SUP_MIN (the basis
//!   check's bound, 1e-6; trained ones are O(0.1–1)), and meets the targets of
//!   docs/whole-system.md:
//!   rel_error ≤ 1e-3 and max_constraint_violation ≤ 1e-6 m, with fewer reduced unknowns
//!   (POD modes + supremizers + reduced multipliers) than constraint-preserving (136 modes
//!   + 12 joint coordinates + 8 multipliers = 156);
//! - the pendulum with the pin reduced (pipelines/thesis/pendulum_whole_system_stabilized.toml,
//!   10 %, ECSW τ = 1e-4): rel_error ≤ 1e-3, no kept coordinates.

use flexrom::io::basis_check::INF_SUP_MIN;
use flexrom::linalg::kkt::LinearSolverKind;
use flexrom::pipeline::Pipeline;
use flexrom::reduction::whole_system::{constraint_matrix, inf_sup};
use flexrom::rom::Rom;
use flexrom::solver::parameters::Parameters;
use flexrom::training::train::train;
use flexrom::workflows::validate::validate;
use ndarray::Array2;
use std::path::Path;

fn pipeline(name: &str) -> Pipeline {
    Pipeline::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("pipelines/thesis").join(name)).unwrap()
}

fn b_of(p: &Pipeline) -> Array2<f64> {
    let sys = p.model.system(LinearSolverKind::Banded);
    let rows: Vec<Vec<(usize, f64)>> = sys.constraints.iter().map(|c| c.terms.clone()).collect();
    constraint_matrix(flexrom::solver::model::ParametricModel::n_dof(&sys), &rows)
}

#[test]
fn plain_whole_system_has_no_inf_sup_and_its_failure_points_to_the_stabilized_variant() {
    let p = pipeline("fourbar_whole_system.toml");
    let (_, summary) = train(&p).unwrap();
    let basis = &summary.trained.basis;
    let vl = basis.multiplier_modes.as_ref().unwrap();
    let beta = inf_sup(&b_of(&p), vl, &basis.modes);
    assert!(beta < 1e-6, "plain whole-system β = {beta:e}");
    let Err(err) = validate(&Rom::of(&p.model, basis).unwrap(), &Parameters::load_scale(0.935), false) else {
        panic!("the plain variant fails")
    };
    let err = err.to_string();
    assert!(err.contains("whole-system-stabilized"), "{err}");
}

#[test]
fn stabilized_four_bar_meets_the_targets_with_fewer_unknowns() {
    let p = pipeline("fourbar_whole_system_stabilized.toml");
    let (_, summary) = train(&p).unwrap();
    let basis = &summary.trained.basis;
    let psi = basis.multiplier_modes.as_ref().unwrap();
    assert!(inf_sup(&b_of(&p), psi, &basis.modes) >= INF_SUP_MIN);
    let unknowns = basis.n_reduced() + psi.ncols();
    assert!(unknowns < 156, "{unknowns} reduced unknowns");
    let (v, _, _) = validate(&Rom::of(&p.model, basis).unwrap(), &Parameters::load_scale(0.935), false).unwrap();
    assert!(v.rel_error <= 1e-3, "rel_error {:e}", v.rel_error);
    assert!(v.max_constraint_violation <= 1e-6, "violation {:e}", v.max_constraint_violation);
}

#[test]
fn stabilized_pendulum_with_the_pin_reduced() {
    let p = pipeline("pendulum_whole_system_stabilized.toml");
    let (_, summary) = train(&p).unwrap();
    let basis = &summary.trained.basis;
    assert!(basis.kept.is_empty() && basis.hyper.is_some());
    let (v, _, _) = validate(&Rom::of(&p.model, basis).unwrap(), &Parameters::default(), false).unwrap();
    assert!(v.rel_error <= 1e-3, "rel_error {:e}", v.rel_error);
}
