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
//! - [`Predictor::ZeroAcceleration`] (`"zero-acceleration"`): `q̈_{n+1} = 0` (the classic
//!   choice, Géradin & Cardona, *Flexible Multibody Dynamics*, §10.5). Its error is exactly
//!   `h² β c |q̈_{n+1}|`; with ρ∞ = 1 that is `h²/4 |q̈_{n+1}|`, where the constant-velocity
//!   start misses by `h²/4 |q̈_n + q̈_{n+1}|`. Where the accelerations are smooth
//!   (`q̈_{n+1} ≈ q̈_n`) zero acceleration misses by half as much; where undamped
//!   vibrations of stiff elements make `q̈` alternate from step to step (`q̈_{n+1} ≈ −q̈_n`)
//!   at amplitudes the positions never reach, it misses by all of `h²/4 |q̈|` and constant
//!   velocity by little (a first increment of 10³ on a one-metre four-bar, 25 iterations a
//!   step, step halvings).
//! - [`Predictor::ConstantVelocity`] (`"constant-velocity"`): `q_{n+1} = q_n + h q̇_n`, i.e.
//!   the guess `d = h q̇_n`, treated like any other guess of the step: Newton starts there,
//!   and the first iteration's matrix is kept when its correction is small next to the
//!   guessed step (`JacobianReuse::WithinStep`). Its error is `h² |½ q̈|` averaged over the
//!   step, with no `q̈_{n+1}` in it, and it needs no history (halved steps use it too). On
//!   the shipped pendulum its kept first matrix costs twice the iterations (660 → 1240).
//! - [`Predictor::ConstantPosition`] (`"constant-position"`): `q_{n+1} = q_n`, the guess
//!   `d = 0`: Newton's first step is the linearized step from where the step starts. It
//!   misses by the step's whole motion `|q_{n+1} − q_n|`, so it needs more iterations where
//!   the motion is resolved (the shipped pendulum 5.45 a step against 3.0), but it carries
//!   neither the velocities nor the accelerations of vibrations the step does not resolve,
//!   whose positions stay small: on a stiff arm driven from rest by a moment the velocity
//!   guess of its second step lands in the cubic range of the axial force (residual 2.6e7,
//!   Newton crawling at θ = ⅔), the position guess at a residual of 1.4e2.
//! - [`Predictor::Adaptive`] (`"adaptive"`, the default): once a step's
//!   solution is known, it judges which of the three starts came closest to it (‖·‖∞,
//!   Newton's own measure; ties to zero acceleration, then constant velocity); the next
//!   step starts there. A run's first step, with no step before it to judge by, starts from
//!   constant velocity (at rest: where the run starts): the consistent initial
//!   accelerations of a load applied at t₀ are largest in the stiffest parts, which the
//!   step resolves least. A step that fails from the chosen start is retried once, with
//!   full Newton as before, from constant position, and its halves start there too. No first matrix
//!   is kept (the pendulum's two extra iterations). With ρ∞ = 1 most steps start from
//!   constant velocity (the shipped pendulum 220 of 220), with ρ∞ = 0.7–0.9 mostly from
//!   zero acceleration (90–95 % on the zoo's pendulums), stiff vibrating models from
//!   constant position, and some mix. No fixed start is right for every model, and the
//!   choice costs one pass over the coordinates a step; on the zoo's first draws
//!   (tests/adaptive_start.rs) it completes every run any fixed start completes (67 of 72,
//!   against 62 for zero acceleration) at 0.98× the best one's iterations, and halves no
//!   step where all four complete (zero acceleration 41, constant velocity 11).
//!
//! Only the starting point changes: every step still stops on the same Newton tolerance
//! (tests/predictor.rs checks it step by step). Measured (docs/reduced-speed.md): the full
//! 5000-element pendulum 2.35× faster than with the zero-acceleration start, the ×10
//! four-bar 1.24×, the zoo's models where zero acceleration is the wrong start 1.4–4.9×, the
//! shipped pendulum 6 % slower.

/// Newton's starting point for a step without a guess.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Predictor {
    /// `q̈_{n+1} = 0`
    ZeroAcceleration,
    /// `q_{n+1} = q_n + h q̇_n`, handled as a guessed increment
    ConstantVelocity,
    /// `q_{n+1} = q_n`, handled as a guessed increment of zero
    ConstantPosition,
    /// each step, whichever of the three starts above came closest to the last step's
    /// solution (a run's first step from constant velocity, a failed step's retry and
    /// halves from constant position)
    #[default]
    Adaptive,
}

impl Predictor {
    /// Every start, the default first (the order the model file's error lists them in).
    pub const ALL: [Predictor; 4] =
        [Predictor::Adaptive, Predictor::ZeroAcceleration, Predictor::ConstantVelocity, Predictor::ConstantPosition];

    /// The start the model file's spelling names ([`Self::name`]).
    pub fn from_name(name: &str) -> Option<Predictor> {
        Predictor::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The model file's spelling (`[time] predictor`).
    pub fn name(self) -> &'static str {
        match self {
            Predictor::ZeroAcceleration => "zero-acceleration",
            Predictor::ConstantVelocity => "constant-velocity",
            Predictor::ConstantPosition => "constant-position",
            Predictor::Adaptive => "adaptive",
        }
    }

    /// The guessed increment `q_{n+1} − q_n` of coordinate `i` (velocity `v`), or `None`
    /// for the zero-acceleration start.
    #[inline]
    pub fn increment(self, h: f64, v: f64) -> Option<f64> {
        match self {
            Predictor::ZeroAcceleration | Predictor::Adaptive => None,
            Predictor::ConstantVelocity => Some(h * v),
            Predictor::ConstantPosition => Some(0.0),
        }
    }

    /// `‖d‖∞` of the guessed increment over all coordinates (`None`: no guess), for the
    /// rule that keeps the first iteration's matrix when the guess was good.
    pub fn increment_size(self, h: f64, v: &[f64]) -> Option<f64> {
        match self {
            Predictor::ZeroAcceleration | Predictor::Adaptive => None,
            Predictor::ConstantVelocity => Some(h * crate::linalg::vec_ops::max_abs(v)),
            Predictor::ConstantPosition => Some(0.0),
        }
    }
}
