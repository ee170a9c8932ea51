//! A body's Young's modulus or density as a parameter (`youngs_modulus = { value,
//! parameter }`, `density = { … }` in the model file): the full model at a value, the
//! reduced models at it, ECSW's rows per group of elements, greedy training over a box with
//! them, and the model files and runs refused.
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
//! - the same for a density (`rho_coupler = 2000`): the full run follows the model file
//!   with `density = 2000` to 1e-10 relative (the mass is built at that density, as in the
//!   file; the weight is the file's times 2000/1402, one rounding apart per entry, which a
//!   0.3 s run amplifies little), the reduced forces, mass products and Newton steps as for
//!   the modulus;
//! - ECSW's training matrix gives each group of elements that share a parameter rows of its
//!   own, so each group's force is reproduced apart (module documentation of
//!   `reduction::ecsw`);
//! - with Rayleigh damping `a M + b K` (`[damping]`), the full model at a modulus or a
//!   density follows the model file with it written in, as above, and the reduced models'
//!   damping forces `f(q, q̇) − f(q, 0)` equal those of the file's to 1e-9 (their mass part
//!   scaled by `mₑ(μ)`, their stiffness part by `sₑ(μ)`: `reduction::damping`), while at the
//!   file's value they differ by more than 1e-4;
//! - a point mass as a parameter (`[[masses]] mass = { value, parameter }`, a payload): the
//!   full run at 0.5 kg follows the model file with `mass = 0.5` to 1e-10 (its weight the
//!   file's times 0.5/0.2), the reduced models' forces, mass products and Newton steps as for
//!   a density (a mass group with no element: `solver::model::mass_groups`), and greedy
//!   training over gravity × payload converges with its held-out points within the tolerance
//!   and covered; a bad name, a shared name or a non-positive value is refused;
//! - a name shared with a load or with the other property or
//!   given two values, a non-positive modulus or density on the command line or in a box
//!   are refused, naming the file and the field; a value or a box two orders of magnitude
//!   from the file's value is warned about (a factor meant, `model::FACTOR_LIKE`).

mod common;

use flexrom::model::Model;
use flexrom::pipeline::Pipeline;
use flexrom::reduction::ecsw::training_matrix;
use flexrom::reduction::{ecsw, Basis, Hyper, HyperReducedModel, ReducedModel};
use flexrom::simulate::{prepare, Overrides, Settings};
use flexrom::solver::model::{stiffness_groups, ElementModel, IterationCoefficients, ParametricModel};
use flexrom::solver::parameters::Parameters;
use flexrom::training::train::train;
use ndarray::Array2;
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

/// Compares the parametric reduced model `a` at `mu` with `b`, the same reduction of the
/// model file with the parameter's value written in, at its defaults: forces to 1e-9, mass
/// products to 1e-12, Newton steps to 1e-6 (the module documentation); and checks that `a`
/// at the file's value differs (by more than 1e-3 in its force or its mass), so that the
/// comparison can fail.
fn compare<A: ParametricModel, B: ParametricModel>(
    what: &str,
    a: &mut A,
    b: &mut B,
    (mu, default): (&Parameters, &Parameters),
    (q, v, acc): (&[f64], &[f64], &[f64]),
    coef: IterationCoefficients,
) {
    let r = q.len();
    let (mut fa, mut fb, mut ma, mut mb) = (vec![0.0; r], vec![0.0; r], vec![0.0; r], vec![0.0; r]);
    b.bind(default);
    b.force(default, q, v, 0.2, &mut fb);
    b.mass_mul(acc, &mut mb);
    a.bind(default);
    a.force(default, q, v, 0.2, &mut fa);
    a.mass_mul(acc, &mut ma);
    let apart = rel(&fa, &fb).max(rel(&ma, &mb));
    assert!(apart > 1e-3, "{what}: the file's value and the parameter's give models {apart:e} apart");
    a.bind(mu);
    a.force(mu, q, v, 0.2, &mut fa);
    a.mass_mul(acc, &mut ma);
    assert!(rel(&fa, &fb) < 1e-9, "{what}: forces differ by {:e}", rel(&fa, &fb));
    assert!(rel(&ma, &mb) < 1e-12, "{what}: mass products differ by {:e}", rel(&ma, &mb));
    a.factor(mu, q, v, 0.2, coef).unwrap();
    b.factor(default, q, v, 0.2, coef).unwrap();
    let nc = a.n_constraints();
    let rhs: Vec<f64> = (0..r + nc).map(|i| 1.0 + (i as f64).cos()).collect();
    let (mut xa, mut xb) = (rhs.clone(), rhs);
    a.solve(&mut xa).unwrap();
    b.solve(&mut xb).unwrap();
    assert!(rel(&xa, &xb) < 1e-6, "{what}: Newton steps differ by {:e}", rel(&xa, &xb));
}

/// The tutorial's double pendulum (data/models/double_pendulum.toml) with gravity scaled by
/// `g` and the lower link's `property` (written `file_value` in the file) the parameter
/// `name`, trained greedily over g ∈ [0.8, 1.2] × `name` ∈ `range` (log) at the tutorial's
/// tolerance 1e-3 (pipelines/double_pendulum.toml): checks that it converged, and returns
/// `validate --json`'s four held-out points, each checked within the tolerance and covered
/// by the estimate.
fn greedy_over_gravity_and(
    d: &Path,
    property: &str,
    file_value: &str,
    name: &str,
    range: &str,
) -> Vec<serde_json::Value> {
    let base = std::fs::read_to_string(repo("data/models/double_pendulum.toml")).unwrap();
    let lower = base.find("name = \"lower\"").unwrap();
    let (head, tail) = base.split_at(lower);
    let written = format!("{property} = {file_value}");
    let parameter = format!("{property} = {{ value = {file_value}, parameter = \"{name}\" }}");
    let model = format!("{head}{}", tail.replacen(&written, &parameter, 1)).replace("scaled = true", "scaled = \"g\"");
    assert_eq!(model.matches(&parameter).count(), 1);
    std::fs::write(d.join("m.toml"), model).unwrap();
    std::fs::write(
        d.join("p.toml"),
        format!(
            "model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n[parameters]\ng = [0.8, 1.2]\n\
             {name} = {{ range = {range}, scale = \"log\" }}\n[train]\ngreedy = {{ tolerance = 1e-3, max_runs = 8 }}\n\
             [reduction]\nvariant = \"constraint-preserving\"\n"
        ),
    )
    .unwrap();
    let (ok, err) = flexrom(d, &["train", "p.toml"]);
    assert!(ok, "{err}");
    let f = flexrom::io::h5_open::open(d.join("b.h5")).unwrap();
    assert_eq!(f.group("training").unwrap().attr("converged").unwrap().read_scalar::<u64>().unwrap(), 1, "{err}");
    drop(f);
    common::held_out_points_within(d, 1e-3)
}

/// Trains a 20-mode constraint-preserving basis of `model` at two points of `box_line` (the
/// pipeline's `[parameters]`) in `d`, and returns the pipeline, its snapshots and basis, the
/// model file with the parameter's value written in (`fixed`), and each one's settings (the
/// pipeline's at `mu`, `fixed`'s at its defaults).
fn trained_beside_fixed(
    d: &Path,
    model: &str,
    box_line: &str,
    fixed: &str,
    mu: &Parameters,
) -> (Pipeline, Array2<f64>, Basis, Model, Settings, Settings) {
    std::fs::write(d.join("model.toml"), model).unwrap();
    std::fs::write(
        d.join("pipe.toml"),
        format!(
            "model = \"model.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n[parameters]\n{box_line}\n\
             [train]\npoints = {{ count = 2 }}\n[reduction]\nvariant = \"constraint-preserving\"\nmodes = {{ count = 20 }}\n"
        ),
    )
    .unwrap();
    let p = Pipeline::load(d.join("pipe.toml")).unwrap();
    let (data, summary) = train(&p).unwrap();
    let fixed = Model::from_text(fixed, d.join("fixed.toml")).unwrap();
    let s = Settings::resolve(&p.model, &Overrides::at(mu)).unwrap();
    let s_fixed = Settings::resolve(&fixed, &Overrides::at(&Parameters::default())).unwrap();
    (p, data.x, summary.trained.basis, fixed, s, s_fixed)
}

/// [`compare`] of the hyper-reduced models on `hyper` and the Galerkin models of the
/// pipeline's model at `mu` and of `fixed`, at a state of the training run (t = 0.2 s).
fn compare_reductions(
    p: &Pipeline,
    x: &Array2<f64>,
    basis: &Basis,
    hyper: &Hyper,
    (fixed, s, s_fixed): (&Model, &Settings, &Settings),
    mu: &Parameters,
) {
    let k = 2 * (x.ncols() / 2 - 1) / 3;
    let q = basis.reduce(x.column(k)).to_vec();
    let v: Vec<f64> = (0..q.len()).map(|i| 0.01 * (i as f64).sin()).collect();
    let acc: Vec<f64> = (0..q.len()).map(|i| (i as f64).cos()).collect();
    let coef = IterationCoefficients { mass: 1.0, damping: 30.0, stiffness: 1e-4 };
    let default = Parameters::default();
    let (mut a, mut b) = (
        HyperReducedModel::new(prepare(&p.model, s).unwrap().0, basis, hyper).unwrap(),
        HyperReducedModel::new(prepare(fixed, s_fixed).unwrap().0, basis, hyper).unwrap(),
    );
    compare("hyper-reduced", &mut a, &mut b, (mu, &default), (&q, &v, &acc), coef);
    let (mut a, mut b) = (
        ReducedModel::new(prepare(&p.model, s).unwrap().0, basis).unwrap(),
        ReducedModel::new(prepare(fixed, s_fixed).unwrap().0, basis).unwrap(),
    );
    compare("Galerkin", &mut a, &mut b, (mu, &default), (&q, &v, &acc), coef);
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
    let q = |f: &str| flexrom::io::h5_open::open(d.join(f)).unwrap().dataset("q").unwrap().read_raw::<f64>().unwrap();
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
    let mu = Parameters::default().with("E_coupler", 7e6);
    let fixed = short_fourbar_stiffness()
        .replace("youngs_modulus = { value = 5e6, parameter = \"E_coupler\" }", "youngs_modulus = 7e6");
    let (p, x, basis, fixed, s, s_fixed) =
        trained_beside_fixed(dir.path(), &short_fourbar_stiffness(), "E_coupler = [4e6, 8e6]", &fixed, &mu);
    let (sys, _) = prepare(&p.model, &s).unwrap();

    // ECSW: the coupler's elements (the parameter's group) and the others get rows apart
    let groups = stiffness_groups(&sys);
    assert_eq!(groups.len(), 2, "{groups:?}");
    assert_eq!(groups[0].0, None);
    assert_eq!(groups[1].0.as_deref(), Some("E_coupler"));
    assert_eq!(groups[1].1, (20..70).collect::<Vec<_>>(), "the coupler's 50 elements, after the crank's 20");
    let snaps = x.slice(ndarray::s![.., ..5]).to_owned();
    let c = training_matrix(&sys, &basis, snaps.view());
    let rows = 5 * basis.n_reduced();
    assert_eq!(c.nrows(), 2 * rows);
    for e in 0..sys.n_elements() {
        let group = usize::from(sys.stiffness_parameter(e).is_some());
        let outside = if group == 0 { c.slice(ndarray::s![rows.., e]) } else { c.slice(ndarray::s![..rows, e]) };
        assert!(outside.iter().all(|&x| x == 0.0), "element {e} has terms in another group's rows");
    }
    let hyper = ecsw(&sys, &basis, x.view(), 1e-3).unwrap();
    assert!(
        hyper.elements.iter().any(|&e| (20..70).contains(&e)) && hyper.elements.iter().any(|&e| !(20..70).contains(&e))
    );

    compare_reductions(&p, &x, &basis, &hyper, (&fixed, &s, &s_fixed), &mu);
}

#[test]
fn a_material_parameter_the_model_cannot_take_is_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = short_fourbar_stiffness();
    let param = "youngs_modulus = { value = 5e6, parameter = \"E_coupler\" }";
    let cases: Vec<(String, &str)> = vec![
        (
            base.replace("density = 1402.0", "density = { value = 1402.0, parameter = \"E_coupler\" }"),
            "bodies[1].youngs_modulus.parameter: `E_coupler` is also body `coupler`'s density",
        ),
        (base.replace(param, "youngs_modulus = { value = 5e6, parameter = \"load_scale\" }"), "is not a parameter name"),
        (base.replace("youngs_modulus = 5e8", "youngs_modulus = { value = 6e8, parameter = \"E_coupler\" }"), "bodies[2].youngs_modulus.value: is 600000000, but body `coupler` gives the parameter `E_coupler` the value 5000000"),
        (base.replace(param, "youngs_modulus = { value = 5e6, parameter = \"E_coupler\", unit = \"Pa\" }"), "bodies[1].youngs_modulus"),
        (base.replace(param, "youngs_modulus = { value = -5e6, parameter = \"E_coupler\" }"), "bodies[1].youngs_modulus.value: must be positive"),
    ];
    for (text, want) in &cases {
        std::fs::write(d.join("m.toml"), text).unwrap();
        let (ok, err) = flexrom(d, &["simulate", "m.toml", "-o", "x.h5"]);
        assert!(!ok && !d.join("x.h5").exists(), "accepted, wanted {want}");
        // the field's line is named too (tests/robust.rs); here only the field and the problem
        let plain = without_lines(&err);
        assert!(err.contains("m.toml") && plain.contains(want), "wanted `{want}`, got: {err}");
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
        !ok && err.contains("parameter E_coupler is a Young's modulus (Pa) and must be positive, got -1000000"),
        "{err}"
    );
    std::fs::write(
        d.join("p.toml"),
        "model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n[parameters]\nE_coupler = [-1e6, 8e6]\n[train]\ngreedy = { tolerance = 1e-2, max_runs = 4 }\n",
    )
    .unwrap();
    let (ok, err) = flexrom(d, &["train", "p.toml"]);
    assert!(!ok && !d.join("b.h5").exists(), "{err}");
    // (line 5: the pipeline's `E_coupler = [-1e6, 8e6]`)
    assert!(
        err.contains("parameters.E_coupler (line 5): is a Young's modulus (Pa); its range must be positive"),
        "{err}"
    );

    // a factor meant for a value (two orders of magnitude or more from the file's 5e6) is
    // warned about, on the command line and in a box; a value near the file's is not
    let far = "E_coupler = 0.5 is far from the model file's value 5e6: it sets the Young's modulus (Pa) itself, not a factor of it";
    let (_, err) = flexrom(d, &["simulate", "m.toml", "-o", "far.h5", "--param", "E_coupler=0.5", "--t-end", "0.007"]);
    assert!(err.contains(far), "{err}");
    let (ok, err) =
        flexrom(d, &["simulate", "m.toml", "-o", "near.h5", "--param", "E_coupler=3e6", "--t-end", "0.007"]);
    assert!(ok && !err.contains("is far from"), "{err}");
    std::fs::write(
        d.join("p.toml"),
        "model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n[parameters]\nE_coupler = [0.5, 2.0]\n[train]\ngreedy = { tolerance = 1e-2, max_runs = 4 }\n",
    )
    .unwrap();
    let (_, err) = flexrom(d, &["train", "p.toml"]);
    assert!(
        err.contains("E_coupler = [0.5, 2] is far from the model file's value 5e6")
            && err.contains("(parameters.E_coupler)"),
        "{err}"
    );
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
    for v in greedy_over_gravity_and(d, "youngs_modulus", "7.0e10", "E_lower", "[2.0e10, 2.0e11]") {
        let modulus = v["parameters"]["E_lower"].as_f64().unwrap();
        assert!((2e10..=2e11).contains(&modulus), "{v}");
    }
    let (ok, err) = flexrom(d, &["online", "p.toml", "--param", "E_lower=3e11", "--param", "g=1", "-o", "o.h5"]);
    assert!(ok, "{err}");
    assert!(err.contains("E_lower = 3e11 (trained over [2e10, 2e11])"), "{err}");
    // a modulus not given is the file's 7e10, inside the box: not extrapolated, and the
    // result says the value it ran at; validate's neighbouring run moves 7e10, not 1
    let (ok, err) = flexrom(d, &["online", "p.toml", "--param", "g=1", "-o", "o2.h5"]);
    assert!(ok && !err.contains("trained over"), "{err}");
    let f = flexrom::io::h5_open::open(d.join("o2.h5")).unwrap();
    assert_eq!(f.attr("parameter:E_lower").unwrap().read_scalar::<f64>().unwrap(), 7e10);
    assert_eq!(f.attr("extrapolated").unwrap().read_scalar::<u64>().unwrap(), 0);
    drop(f);
    let (ok, err) = flexrom(d, &["validate", "p.toml", "--param", "g=1", "--no-dense"]);
    assert!(ok && !err.contains("trained over"), "{err}");
}

/// The parametric four-bar with the coupler's density a parameter too (`rho_coupler`,
/// 1402 kg/m³ in the file), and the model file with `density = 2000` written in.
fn fourbar_with_density() -> (String, String) {
    let param = short_fourbar_stiffness()
        .replace("density = 1402.0", "density = { value = 1402.0, parameter = \"rho_coupler\" }");
    let fixed = short_fourbar_stiffness().replace("density = 1402.0", "density = 2000.0");
    assert!(param.contains("rho_coupler") && fixed.contains("density = 2000.0"));
    (param, fixed)
}

#[test]
fn the_full_model_at_a_density_follows_the_model_file_with_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (param, fixed) = fourbar_with_density();
    std::fs::write(d.join("param.toml"), param).unwrap();
    std::fs::write(d.join("fixed.toml"), fixed).unwrap();
    for (model, args) in
        [("param.toml", &["--param", "rho_coupler=2000"][..]), ("fixed.toml", &[][..]), ("param.toml", &[][..])]
    {
        let out = format!("{model}{}.h5", args.len());
        let (ok, err) = flexrom(d, &[&["simulate", model, "-o", &out, "-q"][..], args].concat());
        assert!(ok, "{err}");
    }
    let q = |f: &str| flexrom::io::h5_open::open(d.join(f)).unwrap().dataset("q").unwrap().read_raw::<f64>().unwrap();
    let (a, b) = (q("param.toml2.h5"), q("fixed.toml0.h5"));
    assert!(rel(&a, &b) < 1e-10, "density parameter at 2000 vs the file's 2000: {:e}", rel(&a, &b));
    assert!(rel(&q("param.toml0.h5"), &b) > 1e-3, "a 43 % heavier coupler must change the run");
}

#[test]
fn reduced_models_at_a_density_equal_those_of_the_model_file_with_it() {
    let dir = tempfile::tempdir().unwrap();
    let (param, fixed) = fourbar_with_density();
    let mu = Parameters::default().with("rho_coupler", 2000.0);
    let (p, x, basis, fixed, s, s_fixed) =
        trained_beside_fixed(dir.path(), &param, "rho_coupler = [1200, 2400]", &fixed, &mu);
    let hyper = ecsw(&prepare(&p.model, &s).unwrap().0, &basis, x.view(), 1e-3).unwrap();
    compare_reductions(&p, &x, &basis, &hyper, (&fixed, &s, &s_fixed), &mu);
}

/// The tutorial's double pendulum with gravity scaled by `g` and the lower link's density
/// the parameter `rho_lower` (2700 kg/m³ in the file), trained greedily over g ∈ [0.8, 1.2]
/// × rho_lower ∈ [1350, 5400] (log, half to twice aluminium) at the tutorial's tolerance
/// 1e-3: it converges, and the estimate covers the error at `validate`'s four held-out
/// points, within the tolerance.
#[test]
fn greedy_training_over_a_load_and_a_density_converges_and_covers_held_out_points() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    greedy_over_gravity_and(d, "density", "2700.0", "rho_lower", "[1350, 5400]");
    let (ok, err) = flexrom(d, &["online", "p.toml", "--param", "rho_lower=0", "-o", "o.h5"]);
    assert!(!ok && err.contains("parameter rho_lower is a density (kg/m³) and must be positive, got 0"), "{err}");
}

/// A basis trained over the load scale alone, on a model whose coupler modulus is a
/// parameter: training ran at the file's modulus, so a run that leaves it (or sets it to
/// that value) is not extrapolated, in the command's output and in the result file alike,
/// and one at another modulus is, named against the file's value.
#[test]
fn a_property_training_did_not_vary_counts_as_trained_at_the_file_value() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("m.toml"), short_fourbar_stiffness()).unwrap();
    std::fs::write(
        d.join("p.toml"),
        "model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n[train]\nload_scales = [0.9, 1.0]\n\
         [reduction]\nvariant = \"constraint-preserving\"\nmodes = { count = 20 }\n",
    )
    .unwrap();
    let (ok, err) = flexrom(d, &["train", "p.toml", "-q"]);
    assert!(ok, "{err}");
    let extrapolated = |f: &str| {
        flexrom::io::h5_open::open(d.join(f)).unwrap().attr("extrapolated").unwrap().read_scalar::<u64>().unwrap()
    };
    for (out, args) in [("o1.h5", &[][..]), ("o2.h5", &["--param", "E_coupler=5e6"][..])] {
        let (ok, err) = flexrom(d, &[&["online", "p.toml", "--load-scale", "0.95", "-o", out][..], args].concat());
        assert!(ok && !err.contains("trained at"), "{err}");
        assert_eq!(extrapolated(out), 0, "{out}");
    }
    let (ok, err) =
        flexrom(d, &["online", "p.toml", "--load-scale", "0.95", "--param", "E_coupler=7e6", "-o", "o3.h5"]);
    assert!(ok && err.contains("E_coupler = 7e6 (trained at 5e6, the model file's value)"), "{err}");
    assert_eq!(extrapolated("o3.h5"), 1);
}

/// `text` without the ` (line N)` an error puts after its field.
fn without_lines(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(i) = rest.find(" (line ") {
        out.push_str(&rest[..i]);
        let after = &rest[i + " (line ".len()..];
        let digits = after.bytes().take_while(u8::is_ascii_digit).count();
        if digits > 0 && after[digits..].starts_with(')') {
            rest = &after[digits + 1..];
        } else {
            out.push_str(" (line ");
            rest = after;
        }
    }
    out + rest
}

/// Rayleigh damping for the four-bar, `a = 2 s⁻¹` on the mass and `b` on the bending
/// stiffness: at the test's velocities (every reduced coordinate at 0.3) the stiff crank's
/// and follower's bending dominates unless `b` is small, so each case picks `b` for its
/// parameter's part to show: 2e-4 s for a modulus, 1e-8 s for a density.
fn fourbar_damping(stiffness: f64) -> String {
    format!("\n[damping]\nmass = 2.0\nstiffness = {stiffness:e}\n")
}

/// The damping forces `f(q, q̇) − f(q, 0)` of `a` at `mu` and of `b` at its defaults agree to
/// 1e-9, and `a`'s at its own defaults differ from `b`'s by more than 1e-4, five orders above
/// (the check can fail: the mass part at `ρ_file` or the stiffness part at `E_file`; the
/// mass part dominates these forces, so a 40 % stiffer coupler moves them by ~7e-4).
fn compare_damping<A: ParametricModel, B: ParametricModel>(
    what: &str,
    a: &mut A,
    b: &mut B,
    mu: &Parameters,
    q: &[f64],
) {
    let r = q.len();
    let v: Vec<f64> = (0..r).map(|i| 0.3 * (i as f64 + 1.0).sin()).collect();
    let damping = |m: &mut dyn FnMut(&[f64], &mut [f64])| {
        let (mut with, mut without) = (vec![0.0; r], vec![0.0; r]);
        m(&v, &mut with);
        m(&vec![0.0; r], &mut without);
        with.iter().zip(&without).map(|(x, y)| x - y).collect::<Vec<f64>>()
    };
    let default = Parameters::default();
    let fb = damping(&mut |v, out| {
        b.bind(&default);
        b.force(&default, q, v, 0.2, out)
    });
    assert!(fb.iter().any(|&x| x != 0.0), "{what}: the model is damped");
    let at_file = damping(&mut |v, out| {
        a.bind(&default);
        a.force(&default, q, v, 0.2, out)
    });
    assert!(rel(&at_file, &fb) > 1e-4, "{what}: the file's value gives damping {:e} apart", rel(&at_file, &fb));
    let fa = damping(&mut |v, out| {
        a.bind(mu);
        a.force(mu, q, v, 0.2, out)
    });
    assert!(rel(&fa, &fb) < 1e-9, "{what}: damping forces differ by {:e}", rel(&fa, &fb));
}

/// A damped four-bar whose coupler modulus (`E_coupler`, 7e6 written in the fixed file) or
/// density (`rho_coupler`, 2000): the full runs follow the file with the value written in,
/// and both reduced models' damping forces and Newton steps too (module documentation).
#[test]
fn damped_models_with_a_modulus_or_density_parameter_follow_the_model_file_with_it() {
    let (rho_param, rho_fixed) = fourbar_with_density();
    let e_fixed = short_fourbar_stiffness()
        .replace("youngs_modulus = { value = 5e6, parameter = \"E_coupler\" }", "youngs_modulus = 7e6");
    let cases = [
        ("E_coupler", 7e6, short_fourbar_stiffness(), e_fixed, "E_coupler = [4e6, 8e6]", 2e-4),
        ("rho_coupler", 2000.0, rho_param, rho_fixed, "rho_coupler = [1200, 2400]", 1e-8),
    ];
    for (name, value, param, fixed, box_line, b) in cases {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let (param, fixed) = (param + &fourbar_damping(b), fixed + &fourbar_damping(b));
        std::fs::write(d.join("param.toml"), &param).unwrap();
        std::fs::write(d.join("fixed.toml"), &fixed).unwrap();
        let setting = format!("{name}={value}");
        for (model, args) in [("param.toml", &["--param", &setting][..]), ("fixed.toml", &[][..])] {
            let (ok, err) = flexrom(d, &[&["simulate", model, "-o", &format!("{model}.h5"), "-q"][..], args].concat());
            assert!(ok, "{err}");
        }
        let q =
            |f: &str| flexrom::io::h5_open::open(d.join(f)).unwrap().dataset("q").unwrap().read_raw::<f64>().unwrap();
        let (a, b) = (q("param.toml.h5"), q("fixed.toml.h5"));
        assert!(rel(&a, &b) < 1e-10, "{name}: the damped full runs differ by {:e}", rel(&a, &b));

        let mu = Parameters::default().with(name, value);
        let (p, x, basis, fixed, s, s_fixed) = trained_beside_fixed(d, &param, box_line, &fixed, &mu);
        let hyper = ecsw(&prepare(&p.model, &s).unwrap().0, &basis, x.view(), 1e-3).unwrap();
        compare_reductions(&p, &x, &basis, &hyper, (&fixed, &s, &s_fixed), &mu);
        let k = 2 * (x.ncols() / 2 - 1) / 3;
        let qr = basis.reduce(x.column(k)).to_vec();
        let (mut ha, mut hb) = (
            HyperReducedModel::new(prepare(&p.model, &s).unwrap().0, &basis, &hyper).unwrap(),
            HyperReducedModel::new(prepare(&fixed, &s_fixed).unwrap().0, &basis, &hyper).unwrap(),
        );
        compare_damping(&format!("{name}, hyper-reduced"), &mut ha, &mut hb, &mu, &qr);
        let (mut ga, mut gb) = (
            ReducedModel::new(prepare(&p.model, &s).unwrap().0, &basis).unwrap(),
            ReducedModel::new(prepare(&fixed, &s_fixed).unwrap().0, &basis).unwrap(),
        );
        compare_damping(&format!("{name}, Galerkin"), &mut ga, &mut gb, &mu, &qr);
    }
}

/// The tutorial's double pendulum carrying a payload at the lower link's end: a point mass
/// the parameter `payload` sets (0.2 kg in the file), and the file with `mass = 0.5`.
fn double_pendulum_with_payload() -> (String, String) {
    let base = std::fs::read_to_string(repo("data/models/double_pendulum.toml")).unwrap();
    let mass = |m: &str| format!("\n[[masses]]\nbody = \"lower\"\nnode = \"end\"\nmass = {m}\n");
    (base.clone() + &mass("{ value = 0.2, parameter = \"payload\" }"), base + &mass("0.5"))
}

#[test]
fn a_point_mass_parameter_follows_the_model_file_with_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (param, fixed) = double_pendulum_with_payload();
    std::fs::write(d.join("param.toml"), &param).unwrap();
    std::fs::write(d.join("fixed.toml"), &fixed).unwrap();
    for (model, args) in
        [("param.toml", &["--param", "payload=0.5"][..]), ("fixed.toml", &[][..]), ("param.toml", &[][..])]
    {
        let out = format!("{model}{}.h5", args.len());
        let (ok, err) = flexrom(d, &[&["simulate", model, "-o", &out, "-q"][..], args].concat());
        assert!(ok, "{err}");
    }
    let q = |f: &str| flexrom::io::h5_open::open(d.join(f)).unwrap().dataset("q").unwrap().read_raw::<f64>().unwrap();
    let (a, b) = (q("param.toml2.h5"), q("fixed.toml0.h5"));
    assert!(rel(&a, &b) < 1e-10, "payload 0.5 kg by the parameter and in the file: {:e}", rel(&a, &b));
    assert!(rel(&q("param.toml0.h5"), &b) > 1e-3, "2.5 times the payload must change the run");

    let mu = Parameters::default().with("payload", 0.5);
    let (p, x, basis, fixed, s, s_fixed) = trained_beside_fixed(d, &param, "payload = [0.1, 0.6]", &fixed, &mu);
    let hyper = ecsw(&prepare(&p.model, &s).unwrap().0, &basis, x.view(), 1e-3).unwrap();
    compare_reductions(&p, &x, &basis, &hyper, (&fixed, &s, &s_fixed), &mu);
}

/// Greedy training of the payload pendulum over gravity × payload, g ∈ [0.8, 1.2],
/// payload ∈ [0.05, 0.5] kg, at the tutorial's tolerance 1e-3: it converges and its four
/// held-out points are within the tolerance and covered.
#[test]
fn greedy_training_over_a_load_and_a_payload_converges_and_covers_held_out_points() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("m.toml"), double_pendulum_with_payload().0).unwrap();
    std::fs::write(
        d.join("p.toml"),
        "model = \"m.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n[parameters]\nload_scale = [0.8, 1.2]\npayload = [0.05, 0.5]\n\
         [train]\ngreedy = { tolerance = 1e-3, max_runs = 8 }\n",
    )
    .unwrap();
    let (ok, err) = flexrom(d, &["train", "p.toml"]);
    assert!(ok && !err.contains("stopped after"), "{err}");
    common::held_out_points_within(d, 1e-3);
    let (ok, err) = flexrom(d, &["online", "p.toml", "--param", "payload=0", "-o", "o.h5"]);
    assert!(!ok && err.contains("parameter payload is a point mass (kg) and must be positive, got 0"), "{err}");
    // refused with its error alone: no warning that 0 is far from the file's value first
    let (ok, err) = flexrom(d, &["simulate", "m.toml", "--param", "payload=0", "--csv"]);
    assert!(!ok && err.contains("must be positive") && !err.contains("far from"), "{err}");
}

#[test]
fn a_point_mass_parameter_the_model_cannot_take_is_refused_naming_the_field() {
    let (base, _) = double_pendulum_with_payload();
    let second = "\n[[masses]]\nbody = \"upper\"\nnode = \"end\"\nmass = { value = 0.3, parameter = \"payload\" }\n";
    let cases = [
        (base.replace("parameter = \"payload\"", "parameter = \"pay load\""), "masses[0].mass.parameter", "is not a parameter name"),
        (base.replace("value = 0.2, parameter", "value = -0.2, parameter"), "masses[0].mass", "must be positive"),
        (base.replace("density = 2700.0", "density = { value = 2700.0, parameter = \"payload\" }"), "masses[0].mass.parameter", "is also a body's"),
        (base.replace("scaled = true", "scaled = \"payload\""), "masses[0].mass.parameter", "also scales loads[0]"),
        (base.clone() + second, "masses[1].mass.value", "a parameter has one value"),
        (
            base.clone() + "\n[[springs]]\na = { body = \"lower\", node = \"end\" }\nb = { point = [2.0, 0.0] }\nstiffness = { value = 5.0, parameter = \"payload\" }\n",
            "springs[0].stiffness.parameter",
            "is also a point mass",
        ),
        // a drive scaled by the payload's name, and one by a body property's
        (base.clone() + DRIVE_BY_PAYLOAD, "masses[0].mass.parameter", "also scales joints[2]'s motion"),
        (
            (base.clone() + DRIVE_BY_PAYLOAD).replace("scaled = \"payload\"", "scaled = \"rho\"").replace("density = 2700.0", "density = { value = 2700.0, parameter = \"rho\" }"),
            "joints[2].scaled",
            "is a body's Young's modulus or density",
        ),
    ];
    for (text, field, problem) in cases {
        let e = Model::from_text(&text, "bad.toml").unwrap_err().to_string();
        assert!(
            e.contains("bad.toml") && e.contains(field) && e.contains(problem),
            "wanted {field}: {problem}, got {e}"
        );
    }
}

/// A motor by angle at the upper link's pin, its rate scaled by the parameter `payload`.
const DRIVE_BY_PAYLOAD: &str = "\n[[joints]]\ntype = \"driven_angle\"\nbody = \"upper\"\nnode = \"start\"\nscaled = \"payload\"\nfunction = { type = \"polynomial\", coefficients = [0.0, 1.0] }\n";
