//! Loads scaled by named parameters (`scaled = "name"` in the model file, `--param
//! name=value` on the command line): each parameter reaches exactly its own loads, and a
//! parameter does what the load scale does to the same loads.
//!
//! No expected number is hard-coded. The reference is the same model with the loads marked
//! `scaled = true` (or `false`) run at the load scale: a load's factor is one multiplication
//! whichever parameter supplies it, and a named gravity is added to a zero fixed part, so
//! the runs must agree bit for bit. Runs at different values must also differ (by more than
//! 1e-6 of the trajectory), so that a parameter that never reached the model could not pass.
//! Model: the tutorial's double pendulum (`data/models/double_pendulum.toml`) with a
//! horizontal tip force added.

use flexrom::model::Model;
use flexrom::pipeline::Pipeline;
use flexrom::rom::{Output, ReducedRunner};
use flexrom::simulate::{simulate, Overrides};
use flexrom::solver::model::Parameters;
use flexrom::training::train::train;
use ndarray::Array2;
use std::path::Path;
use std::process::Command;
use std::sync::Arc;

const TIP_FORCE: &str = "\n[[loads]]\ntype = \"force\"\nbody = \"lower\"\nnode = \"end\"\nvalue = [0.5, 0.0]\n";

/// The double pendulum with gravity marked `gravity` and a tip force marked `force`
/// (`scaled = ` followed by each).
fn model_text(gravity: &str, force: &str) -> String {
    let base = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/double_pendulum.toml"))
        .unwrap();
    assert!(base.contains("scaled = true"), "the tutorial model's gravity is scaled");
    format!("{}{TIP_FORCE}scaled = {force}\n", base.replace("scaled = true", &format!("scaled = {gravity}")))
}

fn model(gravity: &str, force: &str) -> Model {
    Model::from_text(&model_text(gravity, force), "double_pendulum_named.toml").unwrap()
}

fn q_at(m: &Model, mu: Parameters) -> Array2<f64> {
    simulate(m, &Overrides::at(&mu)).unwrap().q
}

fn differ(a: &Array2<f64>, b: &Array2<f64>) -> f64 {
    (a - b).mapv(|v| v * v).sum().sqrt() / b.mapv(|v| v * v).sum().sqrt()
}

#[test]
fn each_named_parameter_scales_its_own_loads_as_the_load_scale_would() {
    let named = model("\"g\"", "\"push\"");
    assert_eq!(named.parameter_names(), ["g", "push"]);
    let both = Parameters::default().with("g", 1.3).with("push", 1.3);
    // both loads at 1.3 through their names = both marked `true` at λ = 1.3
    let reference = q_at(&model("true", "true"), Parameters::load_scale(1.3));
    assert!(q_at(&named, both) == reference, "g = push = 1.3 differs from λ = 1.3 on the same loads");
    // one name set, the other left at the file's load = that load fixed
    let reference = q_at(&model("true", "false"), Parameters::load_scale(1.3));
    assert!(q_at(&named, Parameters::default().with("g", 1.3)) == reference, "g = 1.3 alone differs");
    let reference = q_at(&model("false", "true"), Parameters::load_scale(0.4));
    assert!(q_at(&named, Parameters::default().with("push", 0.4)) == reference, "push = 0.4 alone differs");
    // and the parameters are independent: changing one changes the run
    let a = q_at(&named, Parameters::default().with("g", 1.3).with("push", 0.4));
    let b = q_at(&named, Parameters::default().with("g", 1.3).with("push", 1.6));
    assert!(differ(&a, &b) > 1e-6, "push = 0.4 and 1.6 gave the same trajectory");
    // λ itself reaches no load of this model: the run at λ = 2 is the file's
    assert!(q_at(&named, Parameters::load_scale(2.0)) == q_at(&named, Parameters::default()));
}

#[test]
fn a_parameter_the_model_does_not_have_is_refused_naming_the_file_and_its_parameters() {
    let named = model("\"g\"", "false");
    let e = simulate(&named, &Overrides::at(&Parameters::default().with("gg", 1.1))).expect_err("`gg` accepted");
    let text = e.to_string();
    assert!(text.contains("double_pendulum_named.toml") && text.contains("no parameter `gg`"), "{text}");
    assert!(text.contains("its parameters: g") && text.contains("did you mean `g`?"), "{text}");
    let bad = model_text("\"2g\"", "false");
    let e = Model::from_text(&bad, "bad.toml").expect_err("`2g` accepted as a name").to_string();
    assert!(
        e.contains("bad.toml") && e.contains("loads[0].scaled") && e.contains("`2g` is not a parameter name"),
        "{e}"
    );
    // a quoted flag is not taken for a parameter named "true"
    let e = Model::from_text(&model_text("\"true\"", "false"), "bad.toml").expect_err("\"true\" accepted").to_string();
    assert!(e.contains("loads[0].scaled") && e.contains("write true without quotes"), "{e}");
}

#[test]
fn a_reduced_model_applies_named_parameters_as_the_load_scale() {
    // one basis (trained at the file's loads), two models that differ only in how the
    // loads are marked: the reduced runs at g = push = 0.7 and at λ = 0.7 agree bit for bit
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| {
        std::fs::write(dir.path().join(format!("{name}.toml")), text).unwrap();
        let p = dir.path().join(format!("{name}_pipe.toml"));
        let body =
            "[train]\nload_scales = [1.0]\n[reduction]\nvariant = \"constraint-preserving\"\nmodes = { count = 12 }\n";
        std::fs::write(&p, format!("model = \"{name}.toml\"\nbasis = \"{name}.h5\"\nreport = \"r\"\n{body}")).unwrap();
        Pipeline::load(&p).unwrap()
    };
    let named = write("named", &model_text("\"g\"", "\"push\""));
    let scaled = write("scaled", &model_text("true", "true"));
    let basis = Arc::new(train(&named).unwrap().1.trained.basis);
    let run = |p: &Pipeline, mu: Parameters| {
        ReducedRunner::new(&p.model, &basis).unwrap().solve(&mu, Output::ReducedAndProbes, &[]).unwrap().reduced_q
    };
    let a = run(&named, Parameters::default().with("g", 0.7).with("push", 0.7));
    assert!(a == run(&scaled, Parameters::load_scale(0.7)), "named parameters differ from λ in the reduced model");
    let b = run(&named, Parameters::default().with("g", 0.7).with("push", 1.2));
    assert!(differ(&a, &b) > 1e-6, "push reached no load of the reduced model");
}

#[test]
fn online_at_a_named_parameter_says_the_basis_was_not_trained_over_it() {
    // training varies λ alone: a named parameter away from 1 is extrapolation, said in a
    // warning and in the `extrapolated` column; at 1 it is not
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.toml"), model_text("true", "\"push\"")).unwrap();
    let body =
        "[train]\nload_scales = [0.8, 1.2]\n[reduction]\nvariant = \"constraint-preserving\"\nmodes = { count = 12 }\n";
    let p = dir.path().join("p.toml");
    std::fs::write(&p, format!("model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n{body}")).unwrap();
    let flexrom = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_flexrom"))
            .args(args)
            .current_dir(dir.path())
            .env("HDF5_USE_FILE_LOCKING", "FALSE")
            .output()
            .unwrap()
    };
    assert!(flexrom(&["train", "p.toml", "-q"]).status.success());
    let out = flexrom(&["online", "p.toml", "--param", "push=1.5", "--load-scale", "1.0", "-o", "a.h5", "--json"]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("outside what the basis was trained on: push = 1.5 (trained at 1"), "{stderr}");
    assert!(stdout.contains("\"extrapolated\":true"), "{stdout}");
    // the record names the run's parameters, last, as a sweep's table does
    assert!(stdout.contains("\"parameter:push\":1.5}"), "{stdout}");
    let out = flexrom(&["online", "p.toml", "--param", "push=1", "--load-scale", "1.1", "-o", "a2.h5", "--json"]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success() && !stderr.contains("outside"), "{stderr}");
    assert!(stdout.contains("\"extrapolated\":false"), "{stdout}");
    // validate --json names every parameter of the run
    let out = flexrom(&["validate", "p.toml", "--param", "push=0.5", "--load-scale", "1.1", "--json", "--no-dense"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("\"parameters\":{\"load_scale\":1.1,\"push\":0.5}"), "{stdout}");
    // `--param load_scale=X` is `--load-scale X`: one point, not the [validate] loads
    let out = flexrom(&["validate", "p.toml", "--param", "load_scale=1.1", "--json", "--no-dense"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.starts_with('{') && stdout.contains("\"parameters\":{\"load_scale\":1.1}"), "{stdout}");
    // a misspelt name is refused before anything runs
    let out = flexrom(&["online", "p.toml", "--param", "pus=1.5", "-o", "c.h5"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no parameter `pus` (its parameters: load_scale, push)"));
    assert!(!dir.path().join("c.h5").exists());
}
