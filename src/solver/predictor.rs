//! Where Newton starts a generalized-α step ([`super::generalized_alpha`]) when no guess of
//! the step is given.
//!
//! The step's unknown is `q̈_{n+1}`; with `a₀ = (α_f q̈_n − α_m a_n)/(1 − α_m)` and
//! `c = (1 − α_f)/(1 − α_m)` the scheme puts
//!
//! ```text
//!     q_{n+1} = q_n + h q̇_n + h²(½ − β) a_n + h² β (a₀ + c q̈_{n+1})
//! ```
//!
//! so any predicted `q̈_{n+1}` is a predicted position, and a predicted position `q_n + d`
//! is the `q̈_{n+1} = (d − Δq₀)/(h² β c)` with `Δq₀` the position change at `q̈_{n+1} = 0`.
//!
//! - [`Predictor::ZeroAcceleration`] (the default): `q̈_{n+1} = 0` (the classic choice, Géradin & Cardona,
//!   *Flexible Multibody Dynamics*, §10.5). Its error is `h² β c |q̈_{n+1}|`: large where the
//!   accelerations are (a fast crank, a soft body's vibrations).
//! - [`Predictor::ConstantVelocity`] (`[time] predictor = "constant-velocity"`): `q_{n+1} = q_n + h q̇_n`, i.e. the guess
//!   `d = h q̇_n`, treated like any other guess of the step: Newton starts there, and the
//!   first iteration's matrix is kept when its correction is small next to the guessed step
//!   (`JacobianReuse::WithinStep`). Its error is `h² |½ q̈|` averaged over the step, with no
//!   `q̈_{n+1}` in it, and it needs no history (halved steps use it too).
//!
//! Only the starting point changes: every step still stops on the same Newton tolerance
//! (tests/predictor.rs checks it step by step). Measured (docs/reduced-speed.md) on the
//! four-bar, full and reduced: 10–25 % fewer factorizations than `ZeroAcceleration`; on the
//! pendulum fewer factorizations (441 → 317) but twice the iterations (660 → 1240) and
//! 10–55 % more CPU for the whole `simulate`. Not the default for that reason: the
//! four-bar's gain is the same for the full and the reduced model, so it does not move
//! the reduced model's speedup either.

/// Newton's starting point for a step without a guess.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Predictor {
    /// `q̈_{n+1} = 0`
    #[default]
    ZeroAcceleration,
    /// `q_{n+1} = q_n + h q̇_n`, handled as a guessed increment
    ConstantVelocity,
}

impl Predictor {
    /// The guessed increment `q_{n+1} − q_n` of coordinate `i` (velocity `v`), or `None`
    /// for the zero-acceleration start.
    #[inline]
    pub fn increment(self, h: f64, v: f64) -> Option<f64> {
        match self {
            Predictor::ZeroAcceleration => None,
            Predictor::ConstantVelocity => Some(h * v),
        }
    }

    /// `‖d‖∞` of the guessed increment over all coordinates (`None`: no guess), for the
    /// rule that keeps the first iteration's matrix when the guess was good.
    pub fn increment_size(self, h: f64, v: &[f64]) -> Option<f64> {
        match self {
            Predictor::ZeroAcceleration => None,
            Predictor::ConstantVelocity => Some(h * crate::linalg::vec_ops::max_abs(v)),
        }
    }
}
