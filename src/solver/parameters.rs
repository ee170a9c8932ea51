//! The parameters `μ` of a run, passed to every solve instead of being stored in a model
//! (as pyMOR passes `mu` to `solve(mu)`): models take them in each evaluation
//! ([`super::model::ParametricModel`]), and the integrator sees a model bound to one run's
//! ([`super::model::Bound`]).
//!
//! `μ` is a set of named values. The default parameter, [`LOAD_SCALE`] (`λ`), multiplies
//! every load marked `scaled` in the model file; it is `1` (the model file's own loads) when
//! not given. A model's loads are affine in it (SPEC §4):
//!
//! ```text
//!     g(q, q̇, t; μ) = C q̇ + Q_e(q) − Q_fixed(q, t) − λ Q_scaled(q, t)
//! ```
//!
//! so a reduced model projects the fixed and the scaled constant forces once each and
//! combines them at `λ` when it evaluates, `g₀,r(μ) = Vᵀg₀,fixed + λ Vᵀg₀,scaled`: one
//! reduced model serves every load without projecting anything again.

use crate::error::{show_number, Error, Result};
use std::collections::BTreeMap;
use std::fmt;

/// The name of the default parameter: the load scale `λ` of every load marked
/// `scaled = true` (`--load-scale X` on the command line).
pub const LOAD_SCALE: &str = "load_scale";

/// The parameters of one run: named values. `Default` is the model file's own loads
/// (`λ = 1`, no other parameter set).
///
/// The default parameter is kept in a field of its own, so the force evaluations that read
/// it on every Newton iteration do not look a name up.
/// Whether `name` can name a parameter: letters, digits and `_`, starting with a letter
/// (it becomes `--param name=…`, a CSV column and an HDF5 attribute).
pub fn is_parameter_name(name: &str) -> bool {
    name.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

#[derive(Clone, Debug, PartialEq)]
pub struct Parameters {
    load_scale: f64,
    /// every other parameter, by name (empty for a model with the load scale alone)
    named: BTreeMap<String, f64>,
}

impl Default for Parameters {
    fn default() -> Self {
        Parameters::load_scale(1.0)
    }
}

impl Parameters {
    /// The parameters of a run at load scale `λ` (the short form of `--load-scale`).
    pub fn load_scale(load_scale: f64) -> Self {
        Parameters { load_scale, named: BTreeMap::new() }
    }

    /// Sets the value of the parameter `name` ([`LOAD_SCALE`] sets `λ`).
    pub fn with(mut self, name: &str, value: f64) -> Self {
        if name == LOAD_SCALE {
            self.load_scale = value;
        } else {
            self.named.insert(name.to_string(), value);
        }
        self
    }

    /// `λ`, the default parameter.
    #[inline]
    pub fn scale(&self) -> f64 {
        self.load_scale
    }

    /// The value of the parameter `name`, if set (`λ` is always set).
    pub fn get(&self, name: &str) -> Option<f64> {
        if name == LOAD_SCALE {
            Some(self.load_scale)
        } else {
            self.named.get(name).copied()
        }
    }

    /// Every parameter, by name: the default one first, then the others in name order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, f64)> {
        std::iter::once((LOAD_SCALE, self.load_scale)).chain(self.named.iter().map(|(k, &v)| (k.as_str(), v)))
    }

    /// Refuses parameters no run can use: a non-finite value (NaN or ±∞).
    pub fn validate(&self) -> Result<()> {
        for (name, value) in self.iter() {
            if !value.is_finite() {
                let problem = format!("must be finite, got {value}");
                return Err(if name == LOAD_SCALE {
                    Error::option(LOAD_SCALE, None, problem)
                } else {
                    Error::usage(format!("parameter {name} {problem}"))
                });
            }
        }
        Ok(())
    }

    /// The factor of a load ([`Scaling`]): 1 for a fixed load, `λ` for one marked
    /// `scaled = true`, the value of the parameter it names otherwise (1, the model file's own
    /// load, where `μ` does not set it).
    #[inline]
    pub fn factor(&self, scaling: &Scaling) -> f64 {
        match scaling {
            Scaling::Fixed => 1.0,
            Scaling::LoadScale => self.load_scale,
            Scaling::Named(name) => self.named.get(name).copied().unwrap_or(1.0),
            Scaling::Property { name, file } => self.named.get(name).map_or(1.0, |value| value / file),
        }
    }

    /// The parameters other than `λ`, by name.
    pub fn named(&self) -> impl Iterator<Item = (&str, f64)> {
        self.named.iter().map(|(k, &v)| (k.as_str(), v))
    }

    /// The same parameters with `λ` multiplied by `factor` (the neighbouring run of a
    /// sensitivity check).
    pub fn scaled_by(&self, factor: f64) -> Self {
        Parameters { load_scale: factor * self.load_scale, named: self.named.clone() }
    }
}

/// Which parameter multiplies a load: `scaled` in the model file (`false`, `true`, or the
/// name of a parameter). A load is linear in its factor, so a model stays affine in every
/// parameter that scales loads.
#[derive(Clone, Debug, PartialEq)]
pub enum Scaling {
    /// `scaled = false`: the file's load at every `μ`
    Fixed,
    /// `scaled = true` (or `"load_scale"`): times `λ`
    LoadScale,
    /// `scaled = "drive"`: times the parameter `drive`
    Named(String),
    /// a property the parameter `name` sets, `file` its model file's value (a spring's
    /// `stiffness = { value, parameter }`): times `μ_name / file`, 1 where μ does not set it
    Property { name: String, file: f64 },
}

impl Scaling {
    /// The parameter's name, if the load has one.
    pub fn parameter(&self) -> Option<&str> {
        match self {
            Scaling::Fixed => None,
            Scaling::LoadScale => Some(LOAD_SCALE),
            Scaling::Named(n) | Scaling::Property { name: n, .. } => Some(n),
        }
    }
}

/// `load scale 1.1` (as messages have always named a run), then `, name = value` for every
/// other parameter.
impl fmt::Display for Parameters {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "load scale {}", show_number(self.load_scale))?;
        for (name, value) in &self.named {
            write!(f, ", {name} = {}", show_number(*value))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_the_model_files_loads_and_non_finite_values_are_refused() {
        // the default parameter is λ = 1: the loads as the model file writes them (SPEC §4)
        assert_eq!(Parameters::default().scale(), 1.0);
        assert_eq!(Parameters::default(), Parameters::load_scale(1.0));
        assert!(Parameters::load_scale(-2.5).validate().is_ok());
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            // the library names the option by its key; a front end spells it its own way
            let e = Parameters::load_scale(bad).validate().expect_err("non-finite load scale accepted");
            assert!(e.to_string().starts_with("load_scale must be finite"), "{e}");
            let flag = e.render(&crate::error::cli_flag);
            assert!(flag.starts_with("--load-scale must be finite"), "{flag}");
            let e = Parameters::default().with("E_lower", bad).validate().expect_err("non-finite value accepted");
            assert!(e.to_string().contains("parameter E_lower must be finite"), "{e}");
        }
    }

    #[test]
    fn named_values_are_kept_apart_from_the_load_scale() {
        let mu = Parameters::load_scale(1.1).with("E_lower", 2.5e8).with(LOAD_SCALE, 0.9);
        assert_eq!(mu.scale(), 0.9, "naming the default parameter sets λ");
        assert_eq!(mu.get("E_lower"), Some(2.5e8));
        assert_eq!(mu.get("drive"), None);
        assert_eq!(mu.iter().collect::<Vec<_>>(), [(LOAD_SCALE, 0.9), ("E_lower", 2.5e8)]);
        assert_eq!(mu.factor(&Scaling::LoadScale), 0.9);
        assert_eq!(mu.factor(&Scaling::Fixed), 1.0);
        assert_eq!(mu.factor(&Scaling::Named("E_lower".into())), 2.5e8);
        // a load named after a parameter the run does not set keeps the file's value
        assert_eq!(mu.factor(&Scaling::Named("drive".into())), 1.0);
        // a property's factor is its value over the file's, 1 where the run does not set it
        assert_eq!(mu.factor(&Scaling::Property { name: "E_lower".into(), file: 5e8 }), 0.5);
        assert_eq!(mu.factor(&Scaling::Property { name: "k".into(), file: 400.0 }), 1.0);
        assert_eq!(mu.scaled_by(2.0).get("E_lower"), Some(2.5e8));
        // messages name a run as they always did; other parameters follow
        assert_eq!(Parameters::load_scale(1.1).to_string(), "load scale 1.1");
        assert_eq!(mu.to_string(), "load scale 0.9, E_lower = 2.5e8");
    }
}
