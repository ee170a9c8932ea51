//! Runs a numeric kernel compiled for the best instruction set the CPU has, through pulp's
//! run-time dispatch (AVX2+FMA on x86-64 when present, NEON on aarch64, else the baseline).
//!
//! A kernel is a [`Kernel`] whose `run` is `#[inline(always)]` and calls plain Rust loops
//! that are `#[inline(always)]` too: all of it is inlined into pulp's `#[target_feature]`
//! function, where the compiler vectorizes the loops 4 wide instead of SSE2's 2 (a closure
//! would not do: it is a function of its own, compiled for the baseline, unless the
//! optimizer happens to inline it). Rust never contracts `a * b + c` into a fused
//! multiply-add and never reorders floating-point sums, so the vector path computes the same
//! operations in the same order as the scalar one and gives the same bits (tests/simd.rs
//! checks that). The binary stays portable: no `-C target-cpu` is needed.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;

static SCALAR_ONLY: AtomicBool = AtomicBool::new(false);
/// The CPU's instruction set, detected once.
static ARCH: OnceLock<pulp::Arch> = OnceLock::new();

/// A numeric kernel to run through [`dispatch`]; implement `run` with `#[inline(always)]`.
pub trait Kernel {
    type Output;
    fn run(self) -> Self::Output;
}

struct Op<K>(K);

impl<K: Kernel> pulp::WithSimd for Op<K> {
    type Output = K::Output;
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> K::Output {
        self.0.run()
    }
}

/// Makes [`dispatch`] run every kernel on the baseline instruction set (process-wide), for
/// the test that compares both paths and for measuring what the vector path gains.
pub fn set_scalar_only(on: bool) {
    SCALAR_ONLY.store(on, Ordering::Relaxed);
}

/// Runs `kernel` compiled for the CPU's best instruction set (or the baseline one after
/// [`set_scalar_only`]`(true)`). The check is two loads per call.
#[inline(always)]
pub fn dispatch<K: Kernel>(kernel: K) -> K::Output {
    if SCALAR_ONLY.load(Ordering::Relaxed) {
        kernel.run()
    } else {
        ARCH.get_or_init(pulp::Arch::new).dispatch(Op(kernel))
    }
}
