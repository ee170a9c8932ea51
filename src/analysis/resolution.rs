//! Whether a run's time step `Δt` resolves the model: its lowest elastic natural period
//! `T₁` (the [`super::modes`] analysis at the initial configuration) and the periods `1/f`
//! of the sines in its loads' and drives' time functions. A step above a tenth of either
//! gets a one-line warning naming the model file and `dt`.
//!
//! Why a tenth: generalized-α is second-order accurate for every ρ∞ (Chung & Hulbert,
//! J. Appl. Mech. 60 (1993) 371–375), and at ρ∞ = 1 it is the trapezoidal rule, whose
//! relative period error on `ẍ + ω²x = 0` is `Ω²/12` with `Ω = ωΔt = 2πΔt/T` (its phase per
//! step is `2 arctan(Ω/2) ≈ Ω − Ω³/12`; Hughes, *The Finite Element Method*, §9.3). At
//! `Δt = T/10`, `Ω = 0.63` and the period is 3.3 % long — a phase error of 0.2 rad every
//! period — and falls as `Δt²` below it; ρ∞ < 1 damps such a mode besides. Above it the
//! lowest mode (or the load) is drawn with errors no reduced basis can fix.
//!
//! Only where cheap: the modes analysis factors the banded `(n + n_c)`-square KKT matrix
//! once and iterates a subspace of `max(2N, N + 8)` vectors for `N` modes; above
//! [`MAX_DOF`] coordinates it is skipped (no warning).

use super::modes;
use crate::linalg::kkt::LinearSolverKind;
use crate::model::Model;
use crate::physics::system::FlexibleSystem;
use crate::solver::model::Parameters;

/// Steps a period must have at least: see the module documentation (3.3 % period error).
pub const STEPS_PER_PERIOD: f64 = 10.0;

/// Largest model (coordinates) whose modes are looked at. Measured (`flexrom modes --count
/// 4`, release, this machine): 1 ms on the 50-element pendulum (204 coordinates, its run
/// 220 steps in about 10 ms), 12 ms on the four-bar (452), 39 ms on the 500-element
/// pendulum (2004 coordinates, its run about 0.17 s): about a tenth to a fifth of a short
/// full run, taken off the run's thread by `simulate`. Above 2000 coordinates the share
/// would be paid by every `train` and `run` of a large model for a check its user can make
/// with `flexrom modes`: left out.
pub const MAX_DOF: usize = 2000;

/// The warning of `dt` on `model` (its system `sys` at `mu`, initial configuration `q0`),
/// one line naming what it does not resolve: the lowest elastic mode, the fastest sine of
/// its loads and drives, or both. Nothing where the modes are not cheap ([`MAX_DOF`]), the
/// analysis fails, or every mode it finds is rigid (a mechanism without elastic bodies).
pub fn time_step_warnings(model: &Model, sys: &FlexibleSystem, mu: &Parameters, q0: &[f64], dt: f64) -> Vec<String> {
    let mut missed = Vec::new();
    if let Some(t1) = lowest_elastic_period(model, sys, mu, q0).filter(|t1| dt > t1 / STEPS_PER_PERIOD) {
        missed.push(format!("the model's lowest elastic natural period T₁ = {t1:.3e} s"));
    }
    let f = loads_highest_frequency(model);
    if f > 0.0 && dt > 1.0 / (STEPS_PER_PERIOD * f) {
        missed.push(format!("a load's or drive's sine of {f} Hz (period {:.3e} s)", 1.0 / f));
    }
    if missed.is_empty() {
        return Vec::new();
    }
    vec![format!(
        "{}: dt = {dt} s does not resolve {} (fewer than {STEPS_PER_PERIOD} steps a period: the integrator's period error exceeds 3 %, and rho_inf = {} damps what it does not resolve); where that motion matters, a smaller [time] dt or --dt",
        model.path.display(),
        missed.join(" nor "),
        model.file.time.rho_inf
    )]
}

/// `T₁ = 1/f₁` of the lowest elastic mode at `q0`; `None` above [`MAX_DOF`], where the
/// analysis fails, or where every mode found is rigid. A mechanism moves with one or two
/// rigid modes (the shipped pendulums and four-bars: one), so the lowest 2 modes are asked
/// for first and twice as many while all are rigid, up to `3 · bodies + 1`: at most 3 rigid
/// motions a body in the plane, so those hold an elastic mode unless none exists.
fn lowest_elastic_period(model: &Model, sys: &FlexibleSystem, mu: &Parameters, q0: &[f64]) -> Option<f64> {
    if q0.len() > MAX_DOF {
        return None;
    }
    let most = (3 * model.bodies().len() + 1).min(modes::unconstrained(sys));
    let mut count = most.min(2);
    while count > 0 {
        let m = modes::compute(sys, mu, q0, 0.0, count, LinearSolverKind::Banded).ok()?;
        if let Some(f1) = m.frequencies.iter().zip(&m.rigid).find(|(f, rigid)| !**rigid && **f > 0.0).map(|(f, _)| *f) {
            return Some(1.0 / f1);
        }
        // every mode rigid (or past buckling): more, unless all were asked for
        if count == most || m.frequencies.iter().any(|f| *f < 0.0) {
            return None;
        }
        count = (2 * count).min(most);
    }
    None
}

/// The highest sine frequency (Hz) of the model's loads and driven joints; 0 without one.
fn loads_highest_frequency(model: &Model) -> f64 {
    use crate::model::schema::{JointSpec, LoadSpec};
    let loads = model.file.loads.iter().map(|l| match l {
        LoadSpec::Moment { function, .. } | LoadSpec::Force { function: Some(function), .. } => {
            function.highest_frequency()
        }
        _ => 0.0,
    });
    let drives = model.file.joints.iter().map(|j| match j {
        JointSpec::DrivenAngle { function, .. } => function.highest_frequency(),
        JointSpec::DrivenPoint { x, y, .. } => x.iter().chain(y).map(|f| f.highest_frequency()).fold(0.0, f64::max),
        _ => 0.0,
    });
    loads.chain(drives).fold(0.0, f64::max)
}
