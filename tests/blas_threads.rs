//! LAPACK called from many threads at once, without `OPENBLAS_NUM_THREADS`: the library keeps
//! its statically linked OpenBLAS on one thread by itself (src/linalg/lapack.rs), so the
//! caller need not set the variable.
//!
//! Through ndarray-linalg directly, the same loop crashed OpenBLAS 0.3.21 on 2 cores with the
//! variable unset (SIGSEGV in `dgetrf_parallel`, or non-finite solutions), in 3 runs of 3;
//! with `OPENBLAS_NUM_THREADS=1` it passed.
//!
//! The check runs in a child process started without the variable (OpenBLAS reads it once,
//! in its constructor before `main`), whatever the environment of `cargo test`.
//! Expected values: each solution `x` of `A x = b` has a residual `‖A x − b‖∞` within
//! `1e-10·‖b‖∞`, far above what LU with partial pivoting leaves on these diagonally
//! dominant matrices (about n·ε·‖A‖·‖x‖ ≈ 1e-13) and far below what a corrupted
//! factorization gives.

use flexrom::linalg::lapack::{FactorizeInto, Solve};
use ndarray::{Array1, Array2};
use std::process::Command;

#[test]
fn lapack_from_many_threads_needs_no_openblas_variable() {
    let out = Command::new(std::env::current_exe().unwrap())
        .args(["--ignored", "--exact", "many_threads_factor_and_solve", "--test-threads", "1"])
        .env_remove("OPENBLAS_NUM_THREADS")
        .output()
        .unwrap();
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "the child failed ({:?}):\n{text}", out.status);
    assert!(text.contains("1 passed"), "the child ran no test:\n{text}");
}

/// Eight threads, each factoring and solving 40 dense systems of 150 to 260 unknowns (above
/// the size where OpenBLAS's LU goes parallel).
#[test]
#[ignore = "run by lapack_from_many_threads_needs_no_openblas_variable in a child without OPENBLAS_NUM_THREADS"]
fn many_threads_factor_and_solve() {
    let handles: Vec<_> = (0..8)
        .map(|k| {
            std::thread::spawn(move || {
                for r in 0..40 {
                    let n = 150 + 10 * k + r;
                    // off-diagonal entries in [-1, 1], diagonal n: strictly diagonally dominant
                    let a = Array2::from_shape_fn((n, n), |(i, j)| {
                        ((i * 7 + j * 3 + r) as f64 * 0.37).sin() + if i == j { n as f64 } else { 0.0 }
                    });
                    let b = Array1::from_shape_fn(n, |i| 1.0 + (i as f64 * 0.1).cos());
                    let x = a.clone().factorize_into().unwrap().solve(&b).unwrap();
                    let residual = (&a.dot(&x) - &b).iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    assert!(residual <= 1e-10 * 2.0, "thread {k}, system {r}: residual {residual}");
                }
            })
        })
        .collect();
    for h in handles {
        h.join().unwrap();
    }
}
