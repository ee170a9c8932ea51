//! The parameters `μ` of a run, passed to every solve instead of being stored in a model
//! (as pyMOR passes `mu` to `solve(mu)`): models take them in each evaluation
//! ([`super::model::ParametricModel`]), and the integrator sees a model bound to one run's
//! ([`super::model::Bound`]).
//!
//! A model's loads are affine in the load scale `λ` (SPEC §4):
//!
//! ```text
//!     g(q, q̇, t; μ) = C q̇ + Q_e(q) − Q_fixed(q, t) − λ Q_scaled(q, t)
//! ```
//!
//! so a reduced model projects the fixed and the scaled constant forces once each and
//! combines them at `λ` when it evaluates, `g₀,r(μ) = Vᵀg₀,fixed + λ Vᵀg₀,scaled`: one
//! reduced model serves every load without projecting anything again.

use crate::error::{Error, Result};

/// The parameters of one run. `Default` is the model file's own loads (`λ = 1`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parameters {
    /// `λ`: multiplies every load marked `scaled` in the model file
    pub load_scale: f64,
}

impl Default for Parameters {
    fn default() -> Self {
        Parameters { load_scale: 1.0 }
    }
}

impl Parameters {
    pub fn new(load_scale: f64) -> Self {
        Parameters { load_scale }
    }

    /// Refuses parameters no run can use: a non-finite load scale (NaN or ±∞).
    pub fn validate(&self) -> Result<()> {
        if !self.load_scale.is_finite() {
            return Err(Error::Usage(format!("--load-scale must be finite, got {}", self.load_scale)));
        }
        Ok(())
    }

    /// The factor of a load: `λ` when it is marked `scaled`, else 1.
    #[inline]
    pub fn load_factor(&self, scaled: bool) -> f64 {
        if scaled {
            self.load_scale
        } else {
            1.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_the_model_files_loads_and_non_finite_scales_are_refused() {
        assert_eq!(Parameters::default().load_scale, 1.0);
        assert!(Parameters::new(-2.5).validate().is_ok());
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let e = Parameters::new(bad).validate().expect_err("non-finite load scale accepted").to_string();
            assert!(e.contains("--load-scale must be finite"), "{e}");
        }
    }
}
