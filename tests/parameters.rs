//! The load scale is a parameter of a run, not state of a model: one
//! model run at λ₁, λ₂, λ₁ must give, bit for bit, what a freshly built model gives at each
//! load, for the full model (`FullModel`) and for the reduced ones (`ReducedRunner`, which
//! keeps the projected constant force unscaled and applies λ in each evaluation).
//!
//! No expected number is hard-coded: the reference is the same computation on models built
//! anew (a fresh `Model`, so even the shared physics is assembled again). The runs at λ₁
//! and λ₂ must also differ (by more than 1e-6 of the trajectory), so that a parameter that
//! never reached the model could not pass. Models: the pendulum (gravity is the scaled load,
//! a constant force, hyper-reduced basis) and the four-bar over 0.2 s (the crank moment is
//! the scaled load, a state- and time-dependent nodal load; every element at weight 1).

use flexrom::linalg::kkt::LinearSolverKind;
use flexrom::model::Model;
use flexrom::pipeline::Pipeline;
use flexrom::rom::{Output, ReducedRunner};
use flexrom::simulate::{simulate, FullModel, Overrides};
use flexrom::solver::model::Parameters;
use flexrom::training::train::train;
use ndarray::Array2;
use std::path::Path;
use std::sync::Arc;

fn repo(rel: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap()
}

fn pipeline(dir: &Path, model: &str, body: &str) -> Pipeline {
    std::fs::write(dir.join("model.toml"), model).unwrap();
    let p = dir.join("pipe.toml");
    std::fs::write(&p, format!("model = \"model.toml\"\nbasis = \"basis.h5\"\nreport = \"report\"\n{body}")).unwrap();
    Pipeline::load(&p).unwrap()
}

fn fresh(model: &Model) -> Model {
    Model::from_text(&model.text, &model.path).unwrap()
}

fn differ(a: &Array2<f64>, b: &Array2<f64>) -> f64 {
    let d = (a - b).mapv(|v| v * v).sum().sqrt();
    d / b.mapv(|v| v * v).sum().sqrt()
}

fn check(p: &Pipeline, l1: f64, l2: f64) {
    let (_, summary) = train(p).unwrap();
    let basis = Arc::new(summary.trained.basis);
    let model = &p.model;

    // reduced: one runner at λ₁, λ₂, λ₁ against a fresh model and runner at each
    let mut one = ReducedRunner::new(model, &basis).unwrap();
    let runs: Vec<Array2<f64>> = [l1, l2, l1]
        .iter()
        .map(|&x| one.solve(&Parameters::load_scale(x), Output::ReducedAndProbes, &[]).unwrap().reduced_q)
        .collect();
    for (run, &x) in runs.iter().zip(&[l1, l2, l1]) {
        let m = Arc::new(fresh(model));
        let mut new = ReducedRunner::new(&m, &basis).unwrap();
        let reference = new.solve(&Parameters::load_scale(x), Output::ReducedAndProbes, &[]).unwrap().reduced_q;
        assert!(*run == reference, "reduced run at λ = {x} on a reused model differs from a fresh model's");
    }
    assert!(differ(&runs[0], &runs[1]) > 1e-6, "λ = {l1} and {l2} gave the same reduced trajectory");

    // full: one FullModel at λ₁, λ₂, λ₁ against `simulate` (which assembles anew) at each
    let mut full = FullModel::new(model, LinearSolverKind::Banded).unwrap();
    let mut qs = Vec::new();
    for x in [l1, l2, l1] {
        let o = Overrides::at(&Parameters::load_scale(x));
        let q = full.simulate(&o).unwrap().q;
        let reference = simulate(&fresh(model), &o).unwrap().q;
        assert!(q == reference, "full run at λ = {x} on a reused model differs from a fresh model's");
        qs.push(q);
    }
    assert!(differ(&qs[0], &qs[1]) > 1e-6, "λ = {l1} and {l2} gave the same full trajectory");
}

#[test]
fn pendulum_runs_at_any_sequence_of_load_scales_as_fresh_models_do() {
    let dir = tempfile::tempdir().unwrap();
    let body = "[train]\nload_scales = [1.0]\n[reduction]\nvariant = \"galerkin\"\nmodes = { count = 12 }\nhyper = { tolerance = 1e-2 }\n";
    check(&pipeline(dir.path(), &repo("data/models/pendulum.toml"), body), 0.6, 1.4);
}

#[test]
fn fourbar_runs_at_any_sequence_of_load_scales_as_fresh_models_do() {
    let dir = tempfile::tempdir().unwrap();
    let model = repo("data/models/fourbar.toml").replace("t_end = 1.1", "t_end = 0.2");
    let body =
        "[train]\nload_scales = [0.935]\n[reduction]\nvariant = \"constraint-preserving\"\nmodes = { count = 20 }\n";
    check(&pipeline(dir.path(), &model, body), 0.8, 1.1);
}
