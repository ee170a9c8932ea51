//! What every joint kind builds and answers: its rows ([`Row`], [`RowKind`]) and the
//! [`JointKind`] trait; the kinds' files import it, [`super`] re-exports it.

use crate::physics::parts::NodeId;
use crate::physics::time_function::TimeFunction;
pub use crate::solver::parameters::Scaling;

/// What a constraint row holds fixed, which sets the units of its residual and multiplier.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowKind {
    /// a position coordinate: residual in m, multiplier a force in N
    Position,
    /// a slope coordinate (dimensionless): multiplier a moment-like force in N m
    Slope,
}

impl RowKind {
    /// Unit of the row's residual.
    pub fn residual_unit(self) -> &'static str {
        match self {
            RowKind::Position => "m",
            RowKind::Slope => "1",
        }
    }

    /// Unit of the row's Lagrange multiplier (the generalized force the joint transmits).
    pub fn multiplier_unit(self) -> &'static str {
        match self {
            RowKind::Position => "N",
            RowKind::Slope => "N m",
        }
    }
}

/// One scalar constraint `Σ coef · q[dof] = rhs` as a joint builds it.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub terms: Vec<(usize, f64)>,
    pub rhs: f64,
    /// what the row holds: a coordinate (`x`, `y`, `x'`, `y'`), or `normal` and `angle`
    /// (a slider's distance from its line and its slope's turn)
    pub component: &'static str,
    pub kind: RowKind,
    /// how the row moves with time; `None`: constant
    pub motion: Option<Motion>,
}

/// A prescribed motion's time function and what multiplies it: `s(μ) · f(t)`, `s` the
/// load scale, a named parameter or 1 ([`Scaling`], as for loads).
#[derive(Clone, Debug, PartialEq)]
pub struct Drive {
    pub function: TimeFunction,
    pub scaled: Scaling,
}

impl Drive {
    /// `s · f⁽ᵏ⁾(t)`, the `order`-th time derivative of the drive at factor `s`.
    pub fn at(&self, s: f64, t: f64, order: u32) -> f64 {
        s * self.function.derivative(t, order)
    }
}

/// How a row moves with time (a rheonomic constraint `B(t) q = b(t)`); rows of the
/// other kinds are constant (`Row::motion` is `None`).
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// `b(t) = rhs + s f(t)`, the coefficients constant: a prescribed coordinate
    Shift(Drive),
    /// the row's two terms are `(−sin θ, cos θ)` with `θ(t) = θ₀ + s f(t)`: a slope held
    /// along a turning direction
    Turn { theta0: f64, drive: Drive },
}

impl Row {
    /// What multiplies the row's drive, if it moves.
    pub fn scaling(&self) -> Option<&Scaling> {
        match &self.motion {
            None => None,
            Some(Motion::Shift(d)) | Some(Motion::Turn { drive: d, .. }) => Some(&d.scaled),
        }
    }

    /// The `order`-th time derivative (0, 1 or 2) of the row at time `t` and drive factor
    /// `s`: its coefficients, in the order of [`Row::terms`], into `coefs`; returns that of
    /// its right-hand side. For a turning row, with `c = cos θ`, `σ = sin θ`:
    ///
    /// ```text
    ///     B = (−σ, c),   Ḃ = θ̇ (−c, −σ),   B̈ = θ̇² (σ, −c) + θ̈ (−c, −σ)
    /// ```
    pub fn at(&self, s: f64, t: f64, order: u32, coefs: &mut [f64]) -> f64 {
        let constant = |coefs: &mut [f64]| {
            for (o, &(_, k)) in coefs.iter_mut().zip(&self.terms) {
                *o = if order == 0 { k } else { 0.0 };
            }
        };
        match &self.motion {
            None => {
                constant(coefs);
                if order == 0 {
                    self.rhs
                } else {
                    0.0
                }
            }
            Some(Motion::Shift(drive)) => {
                constant(coefs);
                drive.at(s, t, order) + if order == 0 { self.rhs } else { 0.0 }
            }
            Some(Motion::Turn { theta0, drive }) => {
                let th = theta0 + drive.at(s, t, 0);
                let (sn, c) = th.sin_cos();
                let (w, alpha) = (drive.at(s, t, 1), drive.at(s, t, 2));
                let b = match order {
                    0 => [-sn, c],
                    1 => [-c * w, -sn * w],
                    _ => [sn * w * w - c * alpha, -c * w * w - sn * alpha],
                };
                coefs[..2].copy_from_slice(&b);
                0.0
            }
        }
    }
}

/// The global coordinate index of a node's first coordinate: `4 · node` (SPEC §1 numbering).
pub type NodeIndex<'a> = &'a dyn Fn(NodeId) -> usize;

/// Names of the four coordinates of a node, in their order.
pub const COORDINATES: [&str; 4] = ["x", "y", "x'", "y'"];

/// Row `c` (0..4) of a node held at `value`: one unit coefficient on the coordinate.
pub(super) fn fixed_coordinate(first: usize, c: usize, value: f64) -> Row {
    let kind = if c < 2 { RowKind::Position } else { RowKind::Slope };
    Row { terms: vec![(first + c, 1.0)], rhs: value, component: COORDINATES[c], kind, motion: None }
}

/// A kind of joint: its rows and what the rest of the program asks of it.
pub trait JointKind {
    /// The model file's `type` of this kind (`ground_pin`).
    fn type_name(&self) -> &'static str;
    /// The nodes it acts on, in the order its description names them.
    fn nodes(&self) -> Vec<NodeId>;
    /// Its constraint rows; `first` gives a node's first global coordinate.
    fn rows(&self, first: NodeIndex) -> Vec<Row>;
    /// Whether it joins two bodies (a reduction then keeps multipliers of its own).
    fn couples_bodies(&self) -> bool;
    /// What multiplies its prescribed motion, if it drives one (a run's parameter).
    fn drive_scaling(&self) -> Option<&Scaling> {
        None
    }
}
