//! Proper orthogonal decomposition of a snapshot matrix (SPEC §3, thesis eqs. 8–10).
//!
//! ```text
//!     Ψ = [x(t₁) … x(t_m)] = U Σ Vᵀ,    Φ = U[:, :r],
//!     energy(r) = Σ_{i≤r} σᵢ² / Σ_i σᵢ²
//! ```

use crate::error::{Error, Result};
use crate::linalg::lapack::{JobSvd, SVDDC};
use ndarray::{s, Array1, Array2, ArrayView2};

/// How many POD modes to keep.
#[derive(Clone, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ModeRule {
    /// exactly this many (per block, when the basis has blocks)
    Count(usize),
    /// this many in each block of a block basis, in block order
    Counts(Vec<usize>),
    /// this fraction of the full model's coordinate count, rounded (the thesis's
    /// "reduction ratio": 0.1 for the pendulum, 0.3 for the four-bar)
    Ratio(f64),
    /// the fewest modes whose captured energy is at least `1 − tol`
    Energy(f64),
}

impl ModeRule {
    pub fn validate(&self) -> Result<()> {
        match *self {
            ModeRule::Count(0) => Err(Error::usage("count must be at least 1")),
            ModeRule::Counts(ref c) if c.is_empty() || c.contains(&0) => {
                Err(Error::usage(format!("counts must be at least 1 each, got {c:?}")))
            }
            ModeRule::Ratio(x) if !(x.is_finite() && x > 0.0 && x <= 1.0) => {
                Err(Error::usage(format!("ratio must lie in (0, 1], got {x}")))
            }
            ModeRule::Energy(t) if !(t.is_finite() && t > 0.0 && t < 1.0) => {
                Err(Error::usage(format!("energy tolerance must lie in (0, 1), got {t}")))
            }
            _ => Ok(()),
        }
    }

    /// The number of modes this rule keeps, given the full model's dof count and the
    /// captured-energy curve; an error when it asks for more modes than the snapshots hold.
    pub fn count(&self, n_dof: usize, energy: &[f64]) -> Result<usize> {
        self.count_in_block(0, n_dof, energy)
    }

    /// [`Self::count`] for block `b` of a block basis whose block has `n_dof` coordinates
    /// (`counts` gives each block its own number).
    pub fn count_in_block(&self, b: usize, n_dof: usize, energy: &[f64]) -> Result<usize> {
        self.validate()?;
        let available = energy.len();
        let r = match *self {
            ModeRule::Count(n) => n,
            ModeRule::Counts(ref c) => {
                *c.get(b).ok_or_else(|| Error::usage(format!("{self} has no count for block {}", b + 1)))?
            }
            ModeRule::Ratio(x) => ((x * n_dof as f64).round() as usize).max(1),
            ModeRule::Energy(tol) => energy.iter().position(|&e| e >= 1.0 - tol).map_or(available, |i| i + 1),
        };
        if r > available {
            return Err(Error::usage(format!("{self} asks for {r} modes but the snapshots span at most {available}")));
        }
        Ok(r)
    }
}

impl std::fmt::Display for ModeRule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ModeRule::Count(n) => write!(f, "count = {n}"),
            ModeRule::Counts(c) => write!(f, "counts = {c:?}"),
            ModeRule::Ratio(x) => write!(f, "ratio = {x}"),
            ModeRule::Energy(t) => write!(f, "energy = {t:e}"),
        }
    }
}

/// Left singular vectors and singular values of a snapshot matrix.
#[derive(Clone, Debug)]
pub struct Pod {
    /// n × k, orthonormal columns, k = min(n, m) (thin SVD)
    pub modes: Array2<f64>,
    /// non-increasing, k of them
    pub singular_values: Array1<f64>,
    /// cumulative captured energy fraction, k of them, ending at 1
    pub energy: Array1<f64>,
}

impl Pod {
    /// The first `r` modes.
    pub fn leading(&self, r: usize) -> Array2<f64> {
        self.modes.slice(s![.., ..r]).to_owned()
    }
}

/// Thin SVD of `snapshots` (n × m) by LAPACK's divide-and-conquer `gesdd`.
pub fn pod(snapshots: ArrayView2<f64>) -> Result<Pod> {
    let (n, m) = snapshots.dim();
    if n == 0 || m == 0 {
        return Err(Error::numerical("POD", format!("the snapshot matrix is empty ({n} × {m})")));
    }
    if snapshots.iter().any(|x| !x.is_finite()) {
        return Err(Error::numerical("POD", "the snapshot matrix holds non-finite values"));
    }
    let (u, sigma, _) =
        snapshots.svddc(JobSvd::Some).map_err(|e| Error::numerical("POD", format!("SVD failed: {e}")))?;
    // LAPACK hands back column-major storage; keep everything downstream row-major
    let u = u
        .ok_or_else(|| Error::numerical("POD", "SVD returned no left singular vectors"))?
        .as_standard_layout()
        .into_owned();
    let total: f64 = sigma.iter().map(|s| s * s).sum();
    let mut acc = 0.0;
    let energy = sigma
        .iter()
        .map(|s| {
            acc += s * s;
            if total > 0.0 {
                acc / total
            } else {
                1.0
            }
        })
        .collect();
    Ok(Pod { modes: u, singular_values: sigma, energy })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::array;

    /// A rank-2 matrix built from known orthonormal vectors and singular values 3 and 1:
    /// the POD must return exactly those (up to sign), and energy 9/10 then 1.
    #[test]
    fn recovers_known_decomposition() {
        let s2 = 0.5_f64.sqrt();
        let u1 = array![s2, s2, 0.0];
        let u2 = array![0.0, 0.0, 1.0];
        let v1 = array![1.0, 0.0, 0.0, 0.0];
        let v2 = array![0.0, 0.6, 0.8, 0.0];
        let a = 3.0 * outer(&u1, &v1) + 1.0 * outer(&u2, &v2);
        let p = pod(a.view()).unwrap();
        assert!((p.singular_values[0] - 3.0).abs() < 1e-12);
        assert!((p.singular_values[1] - 1.0).abs() < 1e-12);
        assert!(p.singular_values[2].abs() < 1e-12);
        assert!((p.energy[0] - 0.9).abs() < 1e-12);
        assert!((p.modes.column(0).dot(&u1).abs() - 1.0).abs() < 1e-12);
        assert!((p.modes.column(1).dot(&u2).abs() - 1.0).abs() < 1e-12);
        assert_eq!(ModeRule::Energy(0.15).count(3, p.energy.as_slice().unwrap()).ok(), Some(1));
        assert_eq!(ModeRule::Energy(0.05).count(3, p.energy.as_slice().unwrap()).ok(), Some(2));
        assert_eq!(ModeRule::Ratio(0.5).count(3, p.energy.as_slice().unwrap()).ok(), Some(2));
        assert!(ModeRule::Count(4).count(3, p.energy.as_slice().unwrap()).is_err());
        assert!(ModeRule::Count(0).validate().is_err());
    }

    fn outer(a: &Array1<f64>, b: &Array1<f64>) -> Array2<f64> {
        Array2::from_shape_fn((a.len(), b.len()), |(i, j)| a[i] * b[j])
    }
}
