//! Reaction forces and moments by joint: what each joint applies on the bodies it holds,
//! from the multipliers of its rows. With the equations of motion (SPEC §2)
//!
//! ```text
//! M q̈ + Q_e(q) + Bᵀλ = Q_ext,   so the joints' generalized force on the bodies is  −Bᵀλ
//! ```
//!
//! For each joint and each node it acts on, the generalized force over the node's four
//! coordinates `f = −Σ_rows B_row,d λ_row` gives
//!
//! ```text
//! force  F = (f_x, f_y)                               N, on the body, at the node
//! moment M = x' f_y' − y' f_x'   (= r' × f_slope)     N m, counter-clockwise
//! ```
//!
//! `M` is the moment of the slope part under a rigid rotation δθ (δr' = ẑ × r' δθ, the
//! virtual work `f_slope · δr' = (r' × f_slope) δθ`), the conjugate of a nodal moment's
//! `Q = M/|r'|² (−y', x')` (loads/moment.rs). A ground pin, a pin and a slider without locked
//! rotation have no slope rows: their moment is 0. For a clamp it is the clamping moment;
//! for a slope row that holds a driven angle (SPEC §6, its multiplier times |r'| the drive
//! torque) it is that torque on the body, `−λ |r'|`. The slope part along `r'` (a stretch of
//! the slope, not a moment) is not reported. A joint between two bodies acts on both: its
//! entries on the second node are the opposite of the first's (pins and welds: action and
//! reaction), reported for each node all the same.

use crate::model::Model;
use crate::physics::joints::{lower, Row};
use crate::physics::system::NodeId;
use crate::solver::parameters::Parameters;
use ndarray::{Array2, Array3};

/// What one joint applies on one node: its name and where its coordinates are.
#[derive(Clone, Debug, PartialEq)]
pub struct ReactionPoint {
    /// the joint's index in the model file's `[[joints]]`
    pub joint: usize,
    /// "joint 0 (ground_pin crank node 0) on crank node 0"
    pub name: String,
    /// the node's first global coordinate (x; then y, x', y')
    first: usize,
}

/// The joints' reaction points and, per constraint row, the points and coordinates its
/// multiplier acts on: built once per model, applied to every instant.
#[derive(Clone, Debug, PartialEq)]
pub struct ReactionMap {
    pub points: Vec<ReactionPoint>,
    /// per constraint row (in the system's order): (term of the row, point, coordinate
    /// 0..4, coefficient at the start)
    rows: Vec<Vec<(usize, usize, usize, f64)>>,
    /// the rows that move with time (prescribed motions), by index: their coefficients are
    /// taken at each instant
    moving: Vec<(usize, Row)>,
}

/// Reactions at every instant: `force` (n_t, n_points, 2) in N, `moment` (n_t, n_points) in N m.
#[derive(Clone, Debug, PartialEq)]
pub struct Reactions {
    pub force: Array3<f64>,
    pub moment: Array2<f64>,
}

/// The force and moment the Newton tolerance `tol` resolves in `model`: slopes resolve to
/// `tol`, so a body's curvature to `tol / l` over an element of length `l`, which its bending
/// stiffness `E I` holds with a moment `E I tol / l` and a shear force `E I tol / l²`; the
/// most flexible body's, `[N, N m]`. A reaction's resolution is never below these (a model
/// at rest has reactions of round-off, whose range means nothing).
pub fn resolution_floors(model: &Model, tol: f64) -> [f64; 2] {
    let (force, moment) = model
        .bodies()
        .iter()
        .map(|b| {
            let l = b.length / b.n_elements as f64;
            let m = b.section.youngs_modulus * b.section.inertia / l;
            (m / l, m)
        })
        .fold((f64::INFINITY, f64::INFINITY), |(f, m), (bf, bm)| (f.min(bf), m.min(bm)));
    [tol * force, tol * moment].map(|x| if x.is_finite() { x } else { 0.0 })
}

impl ReactionMap {
    /// The reaction points of `model`'s joints, in file order, each joint's nodes in the
    /// order its description names them.
    pub fn of(model: &Model) -> ReactionMap {
        let bodies = model.bodies();
        let first_node = model.first_nodes();
        let first = |(b, k): NodeId| 4 * (first_node[b] + k);
        let node_name = |(b, k): NodeId| format!("{} node {k}", bodies[b].name);
        let joints = model.joints();
        let mut points = Vec::new();
        for (j, joint) in joints.iter().enumerate() {
            let what = joint.describe(&node_name);
            for node in joint.kind().nodes() {
                let name = format!("joint {j} ({what}) on {}", node_name(node));
                points.push(ReactionPoint { joint: j, name, first: first(node) });
            }
        }
        let lowered = lower(joints, &first);
        let rows = lowered
            .iter()
            .map(|(j, row)| {
                row.terms
                    .iter()
                    .enumerate()
                    .filter_map(|(i, &(dof, coef))| {
                        let p = points.iter().position(|p| p.joint == *j && (p.first..p.first + 4).contains(&dof))?;
                        Some((i, p, dof - points[p].first, coef))
                    })
                    .collect()
            })
            .collect();
        let moving = lowered
            .into_iter()
            .enumerate()
            .filter(|(_, (_, r))| r.motion.is_some())
            .map(|(c, (_, r))| (c, r))
            .collect();
        ReactionMap { points, rows, moving }
    }

    /// The number of constraint rows the map reads multipliers of.
    pub fn n_rows(&self) -> usize {
        self.rows.len()
    }

    /// `[F_x, F_y, M]` of every point at one instant `t` of a run at `mu`, from the
    /// coordinates `q` and the multipliers `lambda` (in the system's row order).
    pub fn at(
        &self,
        (mu, t): (&Parameters, f64),
        q: impl Fn(usize) -> f64,
        lambda: impl Fn(usize) -> f64,
    ) -> Vec<[f64; 3]> {
        // a moving row's coefficients at t
        let mut now: Vec<Option<Vec<f64>>> = vec![None; self.rows.len()];
        for (c, row) in &self.moving {
            let s = row.scaling().map_or(1.0, |sc| mu.factor(sc));
            let mut b = vec![0.0; row.terms.len()];
            row.at(s, t, 0, &mut b);
            now[*c] = Some(b);
        }
        // f: the generalized force −B(t)ᵀλ on each point's four coordinates
        let mut f = vec![[0.0; 4]; self.points.len()];
        for (c, terms) in self.rows.iter().enumerate() {
            let l = lambda(c);
            for &(i, p, d, coef) in terms {
                f[p][d] -= now[c].as_ref().map_or(coef, |b| b[i]) * l;
            }
        }
        self.points.iter().zip(&f).map(|(p, f)| [f[0], f[1], q(p.first + 2) * f[3] - q(p.first + 3) * f[2]]).collect()
    }

    /// The reactions of a run at `mu`: at the instants `t`, `q` (n_dof × n_t) and
    /// `multipliers` (n_c × n_t), one column per instant as the solvers keep them.
    pub fn series(&self, (mu, t): (&Parameters, &[f64]), q: &Array2<f64>, multipliers: &Array2<f64>) -> Reactions {
        self.series_by((mu, t), |i, k| q[(i, k)], |c, k| multipliers[(c, k)])
    }

    /// [`Self::series`] with the coordinates and multipliers read by `(index, instant)`: a
    /// reduced trajectory gives the few coordinates the moments read (the slopes at the
    /// joints' nodes) without forming every coordinate.
    pub fn series_by(
        &self,
        (mu, t): (&Parameters, &[f64]),
        q: impl Fn(usize, usize) -> f64,
        lambda: impl Fn(usize, usize) -> f64,
    ) -> Reactions {
        let (nt, np) = (t.len(), self.points.len());
        let mut force = Array3::zeros((nt, np, 2));
        let mut moment = Array2::zeros((nt, np));
        for k in 0..nt {
            for (p, r) in self.at((mu, t[k]), |i| q(i, k), |c| lambda(c, k)).into_iter().enumerate() {
                force[(k, p, 0)] = r[0];
                force[(k, p, 1)] = r[1];
                moment[(k, p)] = r[2];
            }
        }
        Reactions { force, moment }
    }

    /// The coordinates the reactions read: the slopes of the joints' nodes (the moments'
    /// lever), in point order.
    pub fn read_coordinates(&self) -> Vec<usize> {
        self.points.iter().flat_map(|p| [p.first + 2, p.first + 3]).collect()
    }

    /// The points' names, in order.
    pub fn names(&self) -> Vec<&str> {
        self.points.iter().map(|p| p.name.as_str()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A clamp at the start of "beam", a pin from its end to "link", a ground pin at the end
    /// of "link": the points in file order, each row's multiplier on its own coordinate.
    #[test]
    fn each_row_acts_on_its_joints_nodes_with_the_opposite_sign() {
        let body = |name: &str, x: f64, n: usize| {
            format!(
                "[[bodies]]\nname = \"{name}\"\nstart = [{x}, 0.0]\nangle = 0.0\nlength = 1.0\nelements = {n}\n\
                 density = 7800.0\narea = 1e-4\ninertia = 1e-9\nyoungs_modulus = 2e11\n"
            )
        };
        let text = format!(
            "[time]\nt_end = 0.1\ndt = 0.01\nrho_inf = 0.8\n{}{}\
             [[joints]]\ntype = \"clamp\"\nbody = \"beam\"\nnode = \"start\"\n\
             [[joints]]\ntype = \"pin\"\na = {{ body = \"beam\", node = \"end\" }}\nb = {{ body = \"link\", node = 0 }}\n\
             [[joints]]\ntype = \"ground_pin\"\nbody = \"link\"\nnode = \"end\"\n",
            body("beam", 0.0, 2),
            body("link", 1.0, 3)
        );
        let model = Model::from_text(&text, "m.toml").unwrap();
        let map = ReactionMap::of(&model);
        assert_eq!(
            map.names(),
            [
                "joint 0 (clamp beam node 0) on beam node 0",
                "joint 1 (pin beam node 2 – link node 0) on beam node 2",
                "joint 1 (pin beam node 2 – link node 0) on link node 0",
                "joint 2 (ground_pin link node 3) on link node 3",
            ]
        );
        let sys = model.system(crate::linalg::kkt::LinearSolverKind::Banded);
        assert_eq!(map.n_rows(), sys.constraints.len());
        // multipliers 1, 2, 3, …; slopes of every node (1, 0) (the bodies lie along x)
        let q = sys.initial_state();
        let r = map.at((&Parameters::load_scale(1.0), 0.0), |i| q[i], |c| (c + 1) as f64);
        // rows: clamp x y x' y' (1..4), ground pin x y (5, 6), pin x y (7, 8)
        // clamp: F = −(1, 2), M = x'·f_y' − y'·f_x' = 1·(−4) − 0 = −4
        assert_eq!(r[0], [-1.0, -2.0, -4.0]);
        // pin: +1 on beam's node, −1 on link's: equal and opposite
        assert_eq!(r[1], [-7.0, -8.0, 0.0]);
        assert_eq!(r[2], [7.0, 8.0, 0.0]);
        assert_eq!(r[3], [-5.0, -6.0, 0.0]);
    }
}
