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
//! Only where cheap: the modes analysis factors the `(n + n_c)`-square KKT matrix once and
//! iterates a subspace of `max(2N, N + 8)` vectors; above [`MAX_DOF`] coordinates it is
//! skipped (no warning).

use super::modes;
use crate::linalg::kkt::LinearSolverKind;
use crate::model::Model;
use crate::physics::system::FlexibleSystem;
use crate::solver::model::Parameters;

/// Steps a period must have at least: see the module documentation (3.3 % period error).
pub const STEPS_PER_PERIOD: f64 = 10.0;

/// Largest model (coordinates) whose modes are looked at: the analysis of the shipped
/// 50-element pendulum (204 coordinates) takes well under a millisecond, and its cost grows
/// about linearly with the banded factorization; at 2000 coordinates it stays a few
/// milliseconds, below a single time step of a full run that size. Larger models are left
/// out rather than made slower.
pub const MAX_DOF: usize = 2000;

/// The warnings of `dt` on `model` (its system `sys` at `mu`, initial configuration `q0`):
/// one for the lowest elastic mode, one for the fastest sine of its loads and drives.
/// Nothing where the modes are not cheap ([`MAX_DOF`]), the analysis fails, or every mode
/// it finds is rigid (a mechanism without elastic bodies).
pub fn time_step_warnings(model: &Model, sys: &FlexibleSystem, mu: &Parameters, q0: &[f64], dt: f64) -> Vec<String> {
    let mut warnings = Vec::new();
    let file = model.path.display();
    if let Some(t1) = lowest_elastic_period(model, sys, mu, q0) {
        if dt > t1 / STEPS_PER_PERIOD {
            warnings.push(format!(
                "{file}: dt = {dt} s does not resolve the model's lowest elastic natural period T₁ = {t1:.3e} s (dt > T₁/{STEPS_PER_PERIOD}: the integrator's period error exceeds 3 %); a smaller [time] dt or --dt"
            ));
        }
    }
    let f = loads_highest_frequency(model);
    if f > 0.0 && dt > 1.0 / (STEPS_PER_PERIOD * f) {
        warnings.push(format!(
            "{file}: dt = {dt} s does not resolve a load's or drive's sine of {f} Hz (dt > 1/({STEPS_PER_PERIOD} f) = {:.3e} s); a smaller [time] dt or --dt",
            1.0 / (STEPS_PER_PERIOD * f)
        ));
    }
    warnings
}

/// `T₁ = 1/f₁` of the lowest elastic mode at `q0`; `None` above [`MAX_DOF`], where the
/// analysis fails, or where every mode found is rigid. At most 3 rigid motions a body in
/// the plane, so the lowest `3 · bodies + 1` modes hold an elastic one unless none exists.
fn lowest_elastic_period(model: &Model, sys: &FlexibleSystem, mu: &Parameters, q0: &[f64]) -> Option<f64> {
    if q0.len() > MAX_DOF {
        return None;
    }
    let n_free = modes::unconstrained(sys);
    let count = (3 * model.bodies().len() + 1).min(n_free);
    if count == 0 {
        return None;
    }
    let m = modes::compute(sys, mu, q0, 0.0, count, LinearSolverKind::Banded).ok()?;
    let f1 = m.frequencies.iter().zip(&m.rigid).find(|(f, rigid)| !**rigid && **f > 0.0).map(|(f, _)| *f)?;
    Some(1.0 / f1)
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
