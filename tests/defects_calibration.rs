//! The cheap estimate put on the corrected one's scale by greedy training, so that it can be
//! the default at a fraction of the cost (`DefectsCalibration` in src/reduction/estimator.rs).
//!
//! On the thesis pendulum (data/models/pendulum.toml) coarsened to 20 elements and
//! t_end = 0.4 s, trained greedily over [0.5, 1.5] to 1e-3 as in tests/greedy.rs:
//! - `greedy_calibrates_the_defects_estimate`: the basis file holds `/estimator/defects`
//!   (33 candidate loads, 33 × 5 ratios, 5 factors, `reliable` = 1: the pendulum's ratio
//!   of the two estimates changes smoothly with the load, so its leave-one-out check
//!   passes); the online default method is then `defects`, and an `online` result file
//!   says so (`error_estimate_method`); a basis file whose calibration loads are out of
//!   order is refused with exit code 1 and a message naming `estimator/defects/load_scale`,
//!   no result written. At a candidate load the
//!   calibrated defect estimate equals the corrected estimate fifth by fifth (to 1e-9
//!   relative: the ratio was measured from the same reduced run there, so `ρ · defects_raw`
//!   is the corrected estimate up to round-off). At loads that are neither training loads
//!   nor candidates (0.57, 1.03, 1.41) and outside the range (0.4, 1.6: extrapolated) the
//!   default estimate of `validate` bounds the true rel_error with effectivity ≤ 30 (the
//!   targets the estimate is held to: it covers the error, and overestimates it at most 30×;
//!   docs/error-estimate.md).
//! - `an_unreliable_calibration_uses_its_largest_ratio_and_warns`: with every other
//!   candidate's ratios made 10× larger (the leave-one-out check fails: a neighbours' mean
//!   is then below own / 1.5) and `[online] estimate = "defects"` asked for, `online` warns
//!   once and its whole-run factor is the largest ratio of the last fifth, not an
//!   interpolation.
//! - `pipelines_may_still_choose_the_corrected_estimate`: `[online] estimate = "corrected"`
//!   overrides the default for the same basis file.

use flexrom::pipeline::Pipeline;
use flexrom::rom::estimator::EstimateMethod;
use flexrom::rom::Output;
use flexrom::solver::model::Parameters;
use flexrom::training::train::train_and_write;
use flexrom::workflows::online::load_rom;
use flexrom::workflows::validate::validate;
use std::path::{Path, PathBuf};

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The coarse pendulum and a greedy pipeline in `dir`, `online` appended to `[online]`.
fn setup(dir: &Path, online: &str) -> PathBuf {
    let model = std::fs::read_to_string(repo("data/models/pendulum.toml"))
        .unwrap()
        .replace("elements = 50", "elements = 20")
        .replace("t_end = 1.1", "t_end = 0.4");
    assert!(model.contains("elements = 20") && model.contains("t_end = 0.4"));
    std::fs::write(dir.join("model.toml"), model).unwrap();
    let p = dir.join("pipe.toml");
    std::fs::write(
        &p,
        format!(
            "model = \"model.toml\"\nbasis = \"basis.h5\"\nreport = \"report\"\n[train]\ngreedy = {{ range = [0.5, 1.5], tolerance = 1e-3, max_runs = 8 }}\n[online]\nload_scales = \"0.5:1.5:3\"\n{online}"
        ),
    )
    .unwrap();
    p
}

#[test]
fn greedy_calibrates_the_defects_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let p = Pipeline::load(setup(dir.path(), "")).unwrap();
    let summary = train_and_write(&p, &p.basis_path).unwrap();
    let candidates = summary.greedy.as_ref().expect("greedy record").candidate_loads();
    assert_eq!(candidates.len(), 33);

    // the file layout
    let f = flexrom::io::h5_open::open(&p.basis_path).unwrap();
    let g = f.group("estimator/defects").expect("/estimator/defects");
    assert_eq!(g.dataset("load_scale").unwrap().read_1d::<f64>().unwrap().to_vec(), candidates);
    assert_eq!(g.dataset("ratio").unwrap().shape(), vec![33, 5]);
    let factors = g.dataset("factor").unwrap().read_1d::<f64>().unwrap();
    assert!(factors.len() == 5 && factors.iter().all(|x| x.is_finite() && *x > 0.0), "{factors:?}");
    assert_eq!(g.attr("reliable").unwrap().read_scalar::<u64>().unwrap(), 1);
    drop(f);

    let (_, rom, warnings) = load_rom(&p, &p.basis_path, None, false).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(rom.method(), Some("defects"), "the calibrated cheap method is the default");
    let default_method: hdf5::types::VarLenUnicode = flexrom::io::h5_open::open(&p.basis_path)
        .unwrap()
        .group("estimator")
        .unwrap()
        .attr("default_method")
        .unwrap()
        .read_scalar()
        .unwrap();
    assert_eq!(default_method.as_str(), "defects", "the basis file names it");

    // at a candidate: the corrected estimate, to round-off
    let x = candidates[7];
    let (_, corrected, _) = load_rom(&p, &p.basis_path, Some(EstimateMethod::Corrected), false).unwrap();
    assert_eq!(corrected.method(), Some("corrected"));
    let mu = Parameters::load_scale(x);
    let (_, d) = rom.solve_and_estimate(&mu, Output::Full, &[]).unwrap();
    let (_, c) = corrected.solve_and_estimate(&mu, Output::Full, &[]).unwrap();
    let (d, c) = (d.unwrap(), c.unwrap());
    for i in 0..5 {
        let rel = (d.by_time[i] - c.by_time[i]).abs() / c.by_time[i];
        assert!(rel < 1e-9, "λ = {x}, fifth {i}: defects {:e}, corrected {:e}", d.by_time[i], c.by_time[i]);
    }

    // what a user's result file says of it
    let out = dir.path().join("run.h5");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(["online", p.path.to_str().unwrap(), "--load-scale", "1.03", "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "online: {}", String::from_utf8_lossy(&o.stderr));
    let method: hdf5::types::VarLenUnicode =
        flexrom::io::h5_open::open(&out).unwrap().attr("error_estimate_method").unwrap().read_scalar().unwrap();
    assert_eq!(method.as_str(), "defects");

    // a calibration whose loads are out of order is refused, naming the field
    let bad = dir.path().join("bad.h5");
    std::fs::copy(&p.basis_path, &bad).unwrap();
    {
        let f = flexrom::io::h5_open::open_rw(&bad).unwrap();
        let g = f.group("estimator/defects").unwrap();
        let mut loads = candidates.clone();
        loads.swap(3, 4);
        g.unlink("load_scale").unwrap();
        g.new_dataset_builder().with_data(&loads).create("load_scale").unwrap();
    }
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(["online", p.path.to_str().unwrap(), "--basis", bad.to_str().unwrap(), "--load-scale", "1.0"])
        .args(["-o", dir.path().join("bad_run.h5").to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("estimator/defects/load_scale") && err.contains("increasing"), "{err}");
    assert!(!dir.path().join("bad_run.h5").exists());

    // held out and outside the range: a bound, not a loose one
    for x in [0.57, 1.03, 1.41, 0.4, 1.6] {
        assert!(candidates.iter().all(|&l| (l - x).abs() > 1e-3));
        let (v, _, _) = validate(&rom, &Parameters::load_scale(x), false).unwrap();
        let e = v.error_estimate.expect("estimate");
        assert!(e >= v.rel_error, "λ = {x}: estimate {e:e} below rel_error {:e}", v.rel_error);
        assert!(e / v.rel_error <= 30.0, "λ = {x}: effectivity {}", e / v.rel_error);
        assert_eq!(v.extrapolated, !(0.5..=1.5).contains(&x), "λ = {x}");
    }
}

/// A pipeline that asks for `defects` on a basis whose calibration fails its check gets
/// the largest ratio measured and one warning line saying so.
#[test]
fn an_unreliable_calibration_uses_its_largest_ratio_and_warns() {
    let dir = tempfile::tempdir().unwrap();
    let p = Pipeline::load(setup(dir.path(), "estimate = \"defects\"\n")).unwrap();
    train_and_write(&p, &p.basis_path).unwrap();
    // ratios that jump by 10× from one candidate to the next fail the leave-one-out check
    let largest = {
        let f = flexrom::io::h5_open::open_rw(&p.basis_path).unwrap();
        let g = f.group("estimator/defects").unwrap();
        let mut ratio = g.dataset("ratio").unwrap().read_2d::<f64>().unwrap();
        for (j, mut row) in ratio.rows_mut().into_iter().enumerate() {
            if j % 2 == 1 {
                row.mapv_inplace(|x| 10.0 * x);
            }
        }
        g.unlink("ratio").unwrap();
        g.new_dataset_builder().with_data(&ratio).create("ratio").unwrap();
        ratio.column(4).iter().copied().fold(f64::NAN, f64::max)
    };
    let out = dir.path().join("run.h5");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(["online", p.path.to_str().unwrap(), "--load-scale", "1.03", "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert_eq!(err.matches("defects calibration failed its check").count(), 1, "{err}");
    let factor: f64 =
        flexrom::io::h5_open::open(&out).unwrap().attr("error_estimate_factor").unwrap().read_scalar().unwrap();
    assert_eq!(factor, largest);
}

#[test]
fn pipelines_may_still_choose_the_corrected_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let p = Pipeline::load(setup(dir.path(), "estimate = \"corrected\"\n")).unwrap();
    train_and_write(&p, &p.basis_path).unwrap();
    let (_, rom, _) = load_rom(&p, &p.basis_path, None, false).unwrap();
    let est = rom.estimator().expect("estimator");
    assert!(est.data().defects.as_ref().is_some_and(|d| d.reliable));
    assert_eq!(est.name(), "corrected");
}
