//! The SIMD path against the scalar one. The kernels that run through
//! `flexrom::linalg::simd::dispatch` — the bordered block Cholesky of `DenseLu` and the
//! hyper-reduced model's per-element update and tangent — are run once compiled for the CPU's
//! best instruction set (pulp's dispatch: AVX2+FMA on x86-64) and once on the baseline one
//! (`set_scalar_only(true)`), on the same inputs:
//!
//! * a bordered block-diagonal system (blocks of 9, 7, 8 and 8, a border of 2 rows: the
//!   matrix of `dense_lu`'s unit test `bordered_block_systems_by_blocks_or_the_lu_fallback`,
//!   which checks that it takes the bordered path), factored and solved;
//! * a whole reduced run of `pipelines/thesis/fourbar_blocks.toml` (one POD per body, so its
//!   Newton matrix is bordered block-diagonal, hyper-reduced by ECSW), trained in memory;
//! * full runs of the pendulum and the four-bar (the full system's iteration blocks,
//!   `IterationBlocks` in src/physics/system/models.rs), 0.2 s of each.
//!
//! Expected: the same bits, a tolerance of 0 ulp. Why: the vector code performs the same
//! IEEE-754 operations in the same order as the scalar code — Rust never contracts `a * b + c`
//! into a fused multiply-add (even with FMA enabled) and never reassociates floating-point
//! sums, so vectorizing only runs independent lanes side by side. A difference of even one
//! ulp therefore means a kernel is not what the scalar code says (a `mul_add`, a reordered
//! sum), which is the thing this test is for. Both paths run in one `#[test]`: the switch is
//! process-wide.

use flexrom::linalg::dense_lu::DenseLu;
use flexrom::linalg::simd::set_scalar_only;
use flexrom::model::Model;
use flexrom::pipeline::Pipeline;
use flexrom::rom::Rom;
use flexrom::simulate::{simulate, Overrides};
use flexrom::solver::model::Parameters;
use flexrom::training::train::train;

/// Factors and solves the bordered block system; returns the solution.
fn bordered_solve() -> Vec<f64> {
    let blocks = [0usize, 9, 16, 24, 32];
    let n = 34;
    let block = |i: usize| blocks.iter().rposition(|&b| i >= b).expect("in a block");
    let a = |i: usize, j: usize| -> f64 {
        let coupled = block(i) == block(j) || i >= 32 || j >= 32;
        match (i == j, coupled) {
            (true, _) => 20.0 + i as f64,
            (false, true) => ((i * j + 3 * (i + j)) % 7) as f64 / 7.0 - 0.4 + 1e-3 * (i + j) as f64,
            (false, false) => 0.0,
        }
    };
    let mut lu = DenseLu::new(n);
    let m = lu.matrix_mut();
    for j in 0..n {
        for i in 0..n {
            m[i + n * j] = a(i, j);
        }
    }
    lu.factor_symmetric().expect("positive definite: diagonally dominant");
    let mut b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin() + 0.3).collect();
    lu.solve(&mut b).expect("solve");
    b
}

/// The bits of every number, for an exact comparison that also tells where it differs.
fn first_difference(a: &[f64], b: &[f64]) -> Option<(usize, f64, f64)> {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).enumerate().find(|(_, (x, y))| x.to_bits() != y.to_bits()).map(|(i, (x, y))| (i, *x, *y))
}

#[test]
fn scalar_and_simd_paths_give_the_same_bits() {
    #[cfg(target_arch = "x86_64")]
    if !std::arch::is_x86_feature_detected!("avx2") {
        eprintln!("note: this CPU has no AVX2, both runs take the baseline path");
    }
    let root = env!("CARGO_MANIFEST_DIR");
    let p = Pipeline::load(format!("{root}/pipelines/thesis/fourbar_blocks.toml")).expect("shipped pipeline");
    let (_, summary) = train(&p).expect("training");
    let basis = summary.trained.basis;
    assert!(basis.hyper.is_some(), "the pipeline is hyper-reduced, so the hyper kernels run");

    let full_models: Vec<Model> = ["pendulum", "fourbar"]
        .iter()
        .map(|m| Model::load(format!("{root}/data/models/{m}.toml")).expect("shipped model"))
        .collect();
    let short = Overrides { t_end: Some(0.2), ..Default::default() };
    let mut runs = Vec::new();
    let mut full = Vec::new();
    for scalar in [false, true] {
        set_scalar_only(scalar);
        let x = bordered_solve();
        let rom = Rom::of(&p.model, &basis).and_then(|r| r.solve(&Parameters::load_scale(0.935))).expect("reduced run");
        runs.push((x, rom));
        full.push(full_models.iter().map(|m| simulate(m, &short).expect("full run")).collect::<Vec<_>>());
    }
    set_scalar_only(false);
    let ((x_simd, r_simd), (x_scalar, r_scalar)) = (&runs[0], &runs[1]);
    for (s, c) in full[0].iter().zip(&full[1]) {
        assert!(s.stats.factorizations > 0, "{}: the full run factored", s.model_path);
        let (qs, qc) = (s.q.as_standard_layout(), c.q.as_standard_layout());
        assert_eq!(
            first_difference(qs.as_slice().unwrap(), qc.as_slice().unwrap()),
            None,
            "{}: full coordinates, (flat index, simd, scalar)",
            s.model_path
        );
    }

    assert_eq!(first_difference(x_simd, x_scalar), None, "bordered Cholesky solve, (index, simd, scalar)");
    assert!(r_simd.result.stats.newton_iterations > 0, "the reduced run iterated");
    assert_eq!(r_simd.result.stats.newton_iterations, r_scalar.result.stats.newton_iterations, "Newton iterations");
    let (qs, qc) = (r_simd.reduced_q.as_standard_layout(), r_scalar.reduced_q.as_standard_layout());
    assert_eq!(qs.dim(), qc.dim());
    assert_eq!(
        first_difference(qs.as_slice().unwrap(), qc.as_slice().unwrap()),
        None,
        "reduced coordinates of the four-bar run, (flat index, simd, scalar)"
    );
}
