//! A body's Young's modulus as a parameter (`youngs_modulus = { value, parameter }` in the
//! model file): the full model at a modulus, the reduced models at it, ECSW's rows per
//! group of elements, and the model files and runs refused.
//!
//! Checks, with where each bound comes from:
//! - the full model at `E_coupler = 7e6` is the model file with `youngs_modulus = 7e6`, to
//!   the bit (the same element prototype is built from the same section);
//! - a hyper-reduced and a Galerkin model of the parametric four-bar at μ equal those of
//!   the model file with the modulus written in, on the same basis and sample: forces to
//!   1e-9 relative (the linear parts summed per group and scaled, instead of built at the
//!   modulus: round-off of sums whose terms cancel, ~1e8 on the crank against a sum of ~1,
//!   see tests/hyper.rs), Newton steps to 1e-6 (Gₑ in single precision, tests/hyper.rs);
//!   evaluated at the file's modulus instead they differ by more than 1e-3 (the check can
//!   fail);
//! - ECSW's training matrix gives each group of elements that share a parameter rows of its
//!   own, so each group's force is reproduced apart (module documentation of
//!   `reduction::ecsw`);
//! - a density parameter, a modulus parameter with damping, a name shared with a load or
//!   given two values, a non-positive modulus on the command line or in a pipeline's box
//!   are refused, naming the file and the field.

use flexrom::model::Model;
use flexrom::pipeline::train::train;
use flexrom::pipeline::Pipeline;
use flexrom::reduction::ecsw::training_matrix;
use flexrom::reduction::{ecsw, HyperReducedModel, ReducedModel};
use flexrom::simulate::{prepare, Overrides, Settings};
use flexrom::solver::model::{stiffness_groups, ElementModel, IterationCoefficients, ParametricModel};
use flexrom::solver::parameters::Parameters;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The shipped parametric four-bar (the thesis four-bar with the coupler's modulus the
/// parameter `E_coupler`, 5e6 Pa in the file) over its first 0.3 s.
fn short_fourbar_stiffness() -> String {
    std::fs::read_to_string(repo("data/models/fourbar_stiffness.toml")).unwrap().replace("t_end = 1.1", "t_end = 0.3")
}

fn rel(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
    d / b.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn flexrom(dir: &Path, args: &[&str]) -> (bool, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(args)
        .current_dir(dir)
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    (o.status.success(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn the_full_model_at_a_modulus_is_the_model_file_with_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = short_fourbar_stiffness();
    std::fs::write(d.join("param.toml"), &text).unwrap();
    let written = text.replace("youngs_modulus = { value = 5e6, parameter = \"E_coupler\" }", "youngs_modulus = 7e6");
    assert_ne!(written, text);
    std::fs::write(d.join("fixed.toml"), written).unwrap();
    for (model, args) in [("param.toml", &["--param", "E_coupler=7e6"][..]), ("fixed.toml", &[][..])] {
        let out = format!("{model}.h5");
        let (ok, err) = flexrom(d, &[&["simulate", model, "-o", &out, "-q"][..], args].concat());
        assert!(ok, "{err}");
    }
    let q = |f: &str| hdf5::File::open(d.join(f)).unwrap().dataset("q").unwrap().read_raw::<f64>().unwrap();
    let (a, b) = (q("param.toml.h5"), q("fixed.toml.h5"));
    assert_eq!(a, b, "the parameter at 7e6 and the file's 7e6 must give the same run");
    // and the parameter not set is the file's value, 5e6: another run
    let (ok, err) = flexrom(d, &["simulate", "param.toml", "-o", "five.h5", "-q"]);
    assert!(ok, "{err}");
    assert!(rel(&q("five.h5"), &b) > 1e-3, "a 40 % stiffer coupler must change the run");
}

#[test]
fn reduced_models_at_a_modulus_equal_those_of_the_model_file_with_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("model.toml"), short_fourbar_stiffness()).unwrap();
    std::fs::write(
        d.join("pipe.toml"),
        "model = \"model.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n[parameters]\nE_coupler = [4e6, 8e6]\n\
         [train]\npoints = { count = 2 }\n[reduction]\nvariant = \"constraint-preserving\"\nmodes = { count = 20 }\n",
    )
    .unwrap();
    let p = Pipeline::load(d.join("pipe.toml")).unwrap();
    let (data, summary) = train(&p).unwrap();
    let basis = summary.trained.basis;
    let mu = Parameters::default().with("E_coupler", 7e6);
    let fixed_text = short_fourbar_stiffness()
        .replace("youngs_modulus = { value = 5e6, parameter = \"E_coupler\" }", "youngs_modulus = 7e6");
    let fixed = Model::from_text(&fixed_text, d.join("fixed.toml")).unwrap();
    let s = Settings::resolve(&p.model, &Overrides::at(&mu)).unwrap();
    let (sys, _) = prepare(&p.model, &s).unwrap();
    let s_fixed = Settings::resolve(&fixed, &Overrides::at(&Parameters::default())).unwrap();
    let (sys_fixed, _) = prepare(&fixed, &s_fixed).unwrap();

    // ECSW: the coupler's elements (the parameter's group) and the others get rows apart
    let groups = stiffness_groups(&sys);
    assert_eq!(groups.len(), 2, "{groups:?}");
    assert_eq!(groups[0].0, None);
    assert_eq!(groups[1].0.as_deref(), Some("E_coupler"));
    assert_eq!(groups[1].1, (20..70).collect::<Vec<_>>(), "the coupler's 50 elements, after the crank's 20");
    let snaps = data.x.slice(ndarray::s![.., ..5]).to_owned();
    let c = training_matrix(&sys, &basis, snaps.view());
    let rows = 5 * basis.n_reduced();
    assert_eq!(c.nrows(), 2 * rows);
    for e in 0..sys.n_elements() {
        let group = usize::from(sys.stiffness_parameter(e).is_some());
        let outside = if group == 0 { c.slice(ndarray::s![rows.., e]) } else { c.slice(ndarray::s![..rows, e]) };
        assert!(outside.iter().all(|&x| x == 0.0), "element {e} has terms in another group's rows");
    }
    let hyper = ecsw(&sys, &basis, data.x.view(), 1e-3).unwrap();
    assert!(
        hyper.elements.iter().any(|&e| (20..70).contains(&e)) && hyper.elements.iter().any(|&e| !(20..70).contains(&e))
    );

    let k = 2 * (data.x.ncols() / 2 - 1) / 3;
    let q = basis.reduce(data.x.column(k)).to_vec();
    let v: Vec<f64> = (0..q.len()).map(|i| 0.01 * (i as f64).sin()).collect();
    let r = q.len();
    let coef = IterationCoefficients { mass: 1.0, damping: 30.0, stiffness: 1e-4 };
    let default = Parameters::default();

    fn compare<A: ParametricModel, B: ParametricModel>(
        what: &str,
        a: &mut A,
        b: &mut B,
        (mu, default): (&Parameters, &Parameters),
        (q, v): (&[f64], &[f64]),
        coef: IterationCoefficients,
    ) {
        let r = q.len();
        let (mut fa, mut fb) = (vec![0.0; r], vec![0.0; r]);
        b.force(default, q, v, 0.2, &mut fb);
        // at the file's modulus the parametric model is another model: the check can fail
        a.force(default, q, v, 0.2, &mut fa);
        assert!(rel(&fa, &fb) > 1e-3, "{what}: 5e6 and 7e6 give forces {:e} apart", rel(&fa, &fb));
        a.force(mu, q, v, 0.2, &mut fa);
        assert!(rel(&fa, &fb) < 1e-9, "{what}: forces differ by {:e}", rel(&fa, &fb));
        a.factor(mu, q, v, 0.2, coef).unwrap();
        b.factor(default, q, v, 0.2, coef).unwrap();
        let nc = a.n_constraints();
        let rhs: Vec<f64> = (0..r + nc).map(|i| 1.0 + (i as f64).cos()).collect();
        let (mut xa, mut xb) = (rhs.clone(), rhs);
        a.solve(&mut xa).unwrap();
        b.solve(&mut xb).unwrap();
        assert!(rel(&xa, &xb) < 1e-6, "{what}: Newton steps differ by {:e}", rel(&xa, &xb));
    }
    let (mut a, mut b) = (
        HyperReducedModel::new(prepare(&p.model, &s).unwrap().0, &basis, &hyper).unwrap(),
        HyperReducedModel::new(prepare(&fixed, &s_fixed).unwrap().0, &basis, &hyper).unwrap(),
    );
    compare("hyper-reduced", &mut a, &mut b, (&mu, &default), (&q, &v), coef);
    let (mut a, mut b) = (ReducedModel::new(sys, &basis).unwrap(), ReducedModel::new(sys_fixed, &basis).unwrap());
    compare("Galerkin", &mut a, &mut b, (&mu, &default), (&q, &v), coef);
    assert_eq!(r, basis.n_reduced());
}

#[test]
fn a_modulus_parameter_the_model_cannot_take_is_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = short_fourbar_stiffness();
    let param = "youngs_modulus = { value = 5e6, parameter = \"E_coupler\" }";
    let cases: Vec<(String, &str)> = vec![
        (
            base.replace("density = 1402.0", "density = { value = 1402.0, parameter = \"rho\" }"),
            "bodies[1].density: cannot be a parameter yet",
        ),
        (base.clone() + "\n[damping]\nmass = 0.1\n", "bodies[1].youngs_modulus.parameter: a Young's modulus parameter needs a model without [damping]"),
        (base.replace(param, "youngs_modulus = { value = 5e6, parameter = \"load_scale\" }"), "is not a parameter name"),
        (base.replace("youngs_modulus = 5e8", "youngs_modulus = { value = 6e8, parameter = \"E_coupler\" }"), "bodies[2].youngs_modulus.value: is 600000000, but body `coupler` gives the parameter `E_coupler` the value 5000000"),
        (base.replace(param, "youngs_modulus = { value = 5e6, parameter = \"E_coupler\", unit = \"Pa\" }"), "bodies[1].youngs_modulus"),
        (base.replace(param, "youngs_modulus = { value = -5e6, parameter = \"E_coupler\" }"), "bodies[1].youngs_modulus.value: must be positive"),
    ];
    for (text, want) in &cases {
        std::fs::write(d.join("m.toml"), text).unwrap();
        let (ok, err) = flexrom(d, &["simulate", "m.toml", "-o", "x.h5"]);
        assert!(!ok && !d.join("x.h5").exists(), "accepted, wanted {want}");
        assert!(err.contains("m.toml") && err.contains(want), "wanted `{want}`, got: {err}");
    }
    // a load scaled by the modulus's name
    let shared = base.replace("scaled = true", "scaled = \"E_coupler\"");
    assert_ne!(shared, base);
    std::fs::write(d.join("m.toml"), shared).unwrap();
    let (ok, err) = flexrom(d, &["simulate", "m.toml", "-o", "x.h5"]);
    assert!(!ok && err.contains("`E_coupler` also scales loads[1]"), "{err}");

    // a modulus that is not positive, on the command line and in a pipeline's box
    std::fs::write(d.join("m.toml"), &base).unwrap();
    let (ok, err) = flexrom(d, &["simulate", "m.toml", "-o", "x.h5", "--param", "E_coupler=-1e6"]);
    assert!(
        !ok && err.contains("parameter E_coupler is a Young's modulus and must be positive, got -1000000"),
        "{err}"
    );
    std::fs::write(
        d.join("p.toml"),
        "model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n[parameters]\nE_coupler = [-1e6, 8e6]\n[train]\ngreedy = { tolerance = 1e-2, max_runs = 4 }\n",
    )
    .unwrap();
    let (ok, err) = flexrom(d, &["train", "p.toml"]);
    assert!(!ok && !d.join("b.h5").exists(), "{err}");
    assert!(err.contains("parameters.E_coupler: is a Young's modulus (Pa); its range must be positive"), "{err}");
}

/// The tutorial's double pendulum (data/models/double_pendulum.toml) with gravity scaled by
/// `g` and the lower link's modulus the parameter `E_lower` (7e10 Pa in the file), trained
/// greedily over g ∈ [0.8, 1.2] × E_lower ∈ [2e10, 2e11] (log) at the tutorial's tolerance
/// 1e-3 (pipelines/double_pendulum.toml): it converges, and at the four held-out points
/// `validate` draws the estimate covers the error, both within the tolerance (measured
/// 4 full runs, effectivity 4.0–5.6, at commit time); a run at a modulus outside the box
/// is flagged, naming the parameter.
#[test]
fn greedy_training_over_a_load_and_a_modulus_converges_and_covers_held_out_points() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = std::fs::read_to_string(repo("data/models/double_pendulum.toml")).unwrap();
    let lower = base.find("name = \"lower\"").unwrap();
    let (head, tail) = base.split_at(lower);
    let model = format!(
        "{head}{}",
        tail.replacen("youngs_modulus = 7.0e10", "youngs_modulus = { value = 7.0e10, parameter = \"E_lower\" }", 1)
    )
    .replace("scaled = true", "scaled = \"g\"");
    assert_eq!(model.matches("parameter = \"E_lower\"").count(), 1);
    std::fs::write(d.join("m.toml"), model).unwrap();
    std::fs::write(
        d.join("p.toml"),
        "model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n[parameters]\ng = [0.8, 1.2]\n\
         E_lower = { range = [2.0e10, 2.0e11], scale = \"log\" }\n[train]\ngreedy = { tolerance = 1e-3, max_runs = 8 }\n\
         [reduction]\nvariant = \"constraint-preserving\"\n",
    )
    .unwrap();
    let (ok, err) = flexrom(d, &["train", "p.toml"]);
    assert!(ok, "{err}");
    assert!(err.contains("greedy training over the box E_lower ∈ [2e10, 2e11] (log), g ∈ [0.8, 1.2]"), "{err}");
    let f = hdf5::File::open(d.join("b.h5")).unwrap();
    assert_eq!(f.group("training").unwrap().attr("converged").unwrap().read_scalar::<u64>().unwrap(), 1);
    drop(f);

    let out = Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(["validate", "p.toml", "--json", "--no-dense"])
        .current_dir(d)
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let vs: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(vs.len(), 4);
    for v in &vs {
        let (e, est) = (v["rel_error"].as_f64().unwrap(), v["error_estimate"].as_f64().unwrap());
        assert!(e <= 1e-3 && est >= e, "{v}");
        assert_eq!(v["extrapolated"], false, "{v}");
        let modulus = v["parameters"]["E_lower"].as_f64().unwrap();
        assert!((2e10..=2e11).contains(&modulus), "{v}");
    }
    let (ok, err) = flexrom(d, &["online", "p.toml", "--param", "E_lower=3e11", "--param", "g=1", "-o", "o.h5"]);
    assert!(ok, "{err}");
    assert!(err.contains("E_lower = 3e11 (trained over [2e10, 2e11])"), "{err}");
}
