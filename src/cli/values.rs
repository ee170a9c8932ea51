//! The command line's value enums: the library's kinds (a linear solver, an error estimate's
//! method) as the options name them and their `--help` explains them, so that the library
//! below needs no command-line parser.

use flexrom::linalg::kkt::LinearSolverKind;
use flexrom::pipeline::config::EstimateMethod;

/// `--solver`: which linear solver the full-order model uses ([`LinearSolverKind`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Solver {
    /// Symmetric band LDLᵀ after reverse Cuthill–McKee ordering (each constraint row behind
    /// its coordinates), falling back to a band LU with threshold pivoting (LAPACK dgbtf2's
    /// algorithm) when a pivot or the symmetry check fails: linear in the number of elements
    /// for chains and loops, the fastest here.
    Banded,
    /// faer general sparse LU (COLAMD + partial pivoting), symbolic analysis reused: for
    /// topologies whose band after ordering is wide (trees with many branches).
    Sparse,
    /// Dense LU through LAPACK: the O(n³) reference the thesis's timings most likely had.
    Dense,
}

impl From<Solver> for LinearSolverKind {
    fn from(s: Solver) -> Self {
        match s {
            Solver::Banded => LinearSolverKind::Banded,
            Solver::Sparse => LinearSolverKind::Sparse,
            Solver::Dense => LinearSolverKind::Dense,
        }
    }
}

/// `--estimate`: how the error estimate is computed ([`EstimateMethod`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Method {
    #[value(
        help = "one Newton iteration of the enriched model per step along the reduced run (about 1.5× the error; 45–130 % of the reduced run)"
    )]
    Corrected,
    #[value(help = "the enriched model integrated on its own (about 2× the reduced run)")]
    Enriched,
    #[value(
        help = "the enriched model's local defects at every 10th step (7–16 % of the reduced run; calibrated by greedy training)"
    )]
    Defects,
}

impl From<Method> for EstimateMethod {
    fn from(m: Method) -> Self {
        match m {
            Method::Corrected => EstimateMethod::Corrected,
            Method::Enriched => EstimateMethod::Enriched,
            Method::Defects => EstimateMethod::Defects,
        }
    }
}
