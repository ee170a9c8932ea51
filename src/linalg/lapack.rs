//! The one door to LAPACK (and the BLAS under it): every factorization, SVD, eigenproblem
//! and QR of the crate goes through the traits here, which share ndarray-linalg's names and
//! signatures and first pass through [`single_threaded_blas`].
//!
//! Why a door: OpenBLAS is linked statically (build.rs), so the copy in a process running
//! flexrom is flexrom's own. Its constructor starts one worker per extra core unless
//! `OPENBLAS_NUM_THREADS` says otherwise, and OpenBLAS 0.3.21's threaded LU
//! (`dgetrf_parallel`) called from several threads at once, each handing work to that one
//! pool, crashes (SIGSEGV) or returns non-finite solutions: tests/blas_threads.rs shows
//! it with the variable unset. Parallel sweeps and the test harness call LAPACK from many
//! threads, so the library sets its copy to one thread itself, before its first call,
//! whatever the caller did. A call after the first costs one atomic load (`Once`'s
//! completed check). tests/layers.rs checks that no other file names `ndarray_linalg`.

use std::sync::Once;

use ndarray::{ArrayBase, ArrayRef, DataMut, Ix1};
use ndarray_linalg::error::Result;
use ndarray_linalg::Scalar;

pub use ndarray_linalg::{JobSvd, LUFactorized, UPLO};

extern "C" {
    fn openblas_set_num_threads(n: std::os::raw::c_int);
    fn blas_thread_shutdown_() -> std::os::raw::c_int;
}

static ONE_BLAS_THREAD: Once = Once::new();

/// Keeps OpenBLAS on one thread, once per process: the dense reference solver then measures
/// one core, like everything else, parallel sweeps do not oversubscribe the machine, and
/// concurrent callers never share OpenBLAS's worker pool (see the module's comment).
///
/// Every trait of this module calls it before LAPACK, so no caller has to; the command line
/// calls it at start as well, to join the workers a user's `OPENBLAS_NUM_THREADS=N` started
/// in a command that never reaches LAPACK.
///
/// In the `flexrom` binary OpenBLAS has usually started no worker at all (its
/// `BLAS_ONE_THREAD_AT_START` sets `OPENBLAS_NUM_THREADS=1` before OpenBLAS's constructor
/// runs). When the user's `OPENBLAS_NUM_THREADS` asked for more, or in another program
/// linking this library, the constructor has started them before `main`;
/// setting the count to 1 only stops handing them work, and each keeps polling its queue with
/// `sched_yield` (about a third of a pendulum run's CPU time). `blas_thread_shutdown_` joins
/// them; with one thread no call starts them again (OpenBLAS's `exec_blas` is reached only
/// for more than one thread).
pub fn single_threaded_blas() {
    // SAFETY: plain calls into OpenBLAS's thread server, which is idle here: every LAPACK
    // call of the crate waits on this `Once` first, so none is under way while it runs,
    // and with one thread nothing hands work to a worker afterwards.
    ONE_BLAS_THREAD.call_once(|| unsafe {
        openblas_set_num_threads(1);
        blas_thread_shutdown_();
    });
}

/// ndarray-linalg's `SVD` (LAPACK `gesvd`) through the door.
pub trait SVD: ndarray_linalg::SVD {
    #[allow(clippy::type_complexity)]
    fn svd(&self, calc_u: bool, calc_vt: bool) -> Result<(Option<Self::U>, Self::Sigma, Option<Self::VT>)>;
}

impl<T: ndarray_linalg::SVD + ?Sized> SVD for T {
    fn svd(&self, calc_u: bool, calc_vt: bool) -> Result<(Option<Self::U>, Self::Sigma, Option<Self::VT>)> {
        single_threaded_blas();
        ndarray_linalg::SVD::svd(self, calc_u, calc_vt)
    }
}

/// ndarray-linalg's `SVDDC` (LAPACK `gesdd`) through the door.
pub trait SVDDC: ndarray_linalg::SVDDC {
    #[allow(clippy::type_complexity)]
    fn svddc(&self, uvt_flag: JobSvd) -> Result<(Option<Self::U>, Self::Sigma, Option<Self::VT>)>;
}

impl<T: ndarray_linalg::SVDDC + ?Sized> SVDDC for T {
    fn svddc(&self, uvt_flag: JobSvd) -> Result<(Option<Self::U>, Self::Sigma, Option<Self::VT>)> {
        single_threaded_blas();
        ndarray_linalg::SVDDC::svddc(self, uvt_flag)
    }
}

/// ndarray-linalg's `Eigh` (LAPACK `syevd`, and `sygvd` for a pair `(K, M)`) through the door.
pub trait Eigh: ndarray_linalg::Eigh {
    fn eigh(&self, uplo: UPLO) -> Result<(Self::EigVal, Self::EigVec)>;
}

impl<T: ndarray_linalg::Eigh + ?Sized> Eigh for T {
    fn eigh(&self, uplo: UPLO) -> Result<(Self::EigVal, Self::EigVec)> {
        single_threaded_blas();
        ndarray_linalg::Eigh::eigh(self, uplo)
    }
}

/// ndarray-linalg's `QR` (LAPACK `geqrf`/`orgqr`) through the door.
pub trait QR: ndarray_linalg::QR {
    fn qr(&self) -> Result<(Self::Q, Self::R)>;
}

impl<T: ndarray_linalg::QR + ?Sized> QR for T {
    fn qr(&self) -> Result<(Self::Q, Self::R)> {
        single_threaded_blas();
        ndarray_linalg::QR::qr(self)
    }
}

/// ndarray-linalg's `FactorizeInto` (LAPACK `getrf`) through the door.
pub trait FactorizeInto<S: ndarray::Data + ndarray::RawDataClone>: ndarray_linalg::FactorizeInto<S> {
    fn factorize_into(self) -> Result<LUFactorized<S>>;
}

impl<S: ndarray::Data + ndarray::RawDataClone, T: ndarray_linalg::FactorizeInto<S>> FactorizeInto<S> for T {
    fn factorize_into(self) -> Result<LUFactorized<S>> {
        single_threaded_blas();
        ndarray_linalg::FactorizeInto::factorize_into(self)
    }
}

/// ndarray-linalg's `Solve` (LAPACK `getrf`/`getrs`, or `getrs` alone on an
/// [`LUFactorized`]) through the door: the two methods the crate uses.
pub trait Solve<A: Scalar>: ndarray_linalg::Solve<A> {
    fn solve(&self, b: &ArrayRef<A, Ix1>) -> Result<ndarray::Array1<A>>;
    fn solve_into<S: DataMut<Elem = A>>(&self, b: ArrayBase<S, Ix1>) -> Result<ArrayBase<S, Ix1>>;
}

impl<A: Scalar, T: ndarray_linalg::Solve<A> + ?Sized> Solve<A> for T {
    fn solve(&self, b: &ArrayRef<A, Ix1>) -> Result<ndarray::Array1<A>> {
        single_threaded_blas();
        ndarray_linalg::Solve::solve(self, b)
    }

    fn solve_into<S: DataMut<Elem = A>>(&self, b: ArrayBase<S, Ix1>) -> Result<ArrayBase<S, Ix1>> {
        single_threaded_blas();
        ndarray_linalg::Solve::solve_into(self, b)
    }
}
