//! The free motions of a mechanism at a configuration: its modes of zero frequency
//! ([`super::modes`], the rigid motions the joints leave), each told as what every body
//! does. Per body the motion `δr` of its nodes is fitted, in least squares, by a rigid one
//! `δr = t + θ ẑ × (r − c)` about the nodes' centroid `c` (`t` the mean of `δr`,
//! `θ = Σ (ẑ × (r − c)) · δr / Σ |r − c|²`): a rotation about the point where `δr = 0`,
//! `c + (−t_y, t_x)/θ`, or, when `|θ| ℓ` is below a thousandth of `|t|` (ℓ the body's
//! length), a translation along `t`. The loads start the free motion
//! `a = Σ φ_i (φ_iᵀ Q_ext)` (the `φ_i` `M`-orthonormal: the rigid acceleration they cause);
//! where `Q_extᵀa > 10⁻⁶ |Q_ext| |a|` they do work on it, and no static equilibrium exists
//! near the configuration.

use super::modes;
use super::ramp::Ramped;
use crate::error::{Error, Result};
use crate::physics::system::FlexibleSystem;

/// One free motion: what it does, in words, and the loads' share of work on it (the one
/// the loads drive, when they drive one; else every free motion, unloaded).
#[derive(Clone, Debug)]
pub struct FreeMotion {
    pub description: String,
    /// `Q_extᵀa / (|Q_ext| |a|)` of the driven motion `a` (0 for an unloaded one)
    pub work: f64,
}

impl FreeMotion {
    /// The loads drive the motion.
    pub fn loaded(&self) -> bool {
        self.work.abs() > 1e-6
    }
}

/// The free motions of `model`'s system at `q` (the loads at `t`, at the full load).
pub fn free_motions(model: &mut Ramped, q: &[f64], t: f64) -> Result<Vec<FreeMotion>> {
    let sys = model.system();
    let n_free = modes::unconstrained(sys);
    let count = (3 * sys.bodies.len()).min(n_free);
    if count == 0 {
        return Ok(Vec::new());
    }
    let found = modes::compute(sys, model.parameters(), q, t, count, model.solver_kind())?;
    let shapes: Vec<Vec<f64>> = (0..found.len()).filter(|&i| found.rigid[i]).map(|i| found.shape(i)).collect();
    if shapes.is_empty() {
        // none at this configuration (the loads' geometric stiffness can lift a pendulum's
        // swing off zero): nothing to name
        return Ok(Vec::new());
    }
    let load = model.external_force(q, t);
    let load_norm = norm(&load);
    let sys = model.system();
    // the motion the loads start: Σ φ_i (φ_iᵀ Q_ext) over the M-orthonormal free motions
    let pushes: Vec<f64> = shapes.iter().map(|phi| phi.iter().zip(&load).map(|(a, b)| a * b).sum()).collect();
    let mut driven = vec![0.0; q.len()];
    for (phi, c) in shapes.iter().zip(&pushes) {
        driven.iter_mut().zip(phi).for_each(|(d, p)| *d += c * p);
    }
    let push: f64 = pushes.iter().map(|c| c * c).sum();
    let work = if load_norm > 0.0 && push > 0.0 { push / (load_norm * norm(&driven)) } else { 0.0 };
    if work > 1e-6 {
        return Ok(vec![FreeMotion { description: describe(sys, q, &driven), work }]);
    }
    if shapes.len() == 1 {
        return Ok(vec![FreeMotion { description: describe(sys, q, &shapes[0]), work: 0.0 }]);
    }
    // several: any mix of them is one too, so say how many ways each body moves
    Ok(vec![FreeMotion { description: describe_several(sys, q, &shapes), work: 0.0 }])
}

/// Per body, its rigid motion `(t_x, t_y, θ ℓ)` in each of the free motions `shapes`, and the
/// rank of these (SVD, 10⁻⁶ of the largest): "translates and rotates freely" (3),
/// "translates freely in the plane" (2 without rotation), else the count.
fn describe_several(sys: &FlexibleSystem, q: &[f64], shapes: &[Vec<f64>]) -> String {
    let mut parts = Vec::new();
    for (b, body) in sys.bodies.iter().enumerate() {
        let fits: Vec<[f64; 3]> = shapes.iter().filter_map(|phi| rigid_fit(sys, b, q, phi)).collect();
        if fits.is_empty() {
            continue;
        }
        let a = nalgebra::DMatrix::from_fn(fits.len(), 3, |i, j| fits[i][j]);
        let sv = a.singular_values();
        let top = sv.max();
        let rank = sv.iter().filter(|&&v| v > 1e-6 * top).count();
        let turns = fits.iter().any(|f| f[2].abs() > 1e-3 * f[0].hypot(f[1]).max(f[2].abs()) && f[2] != 0.0);
        let what = match (rank, turns) {
            (3, _) => "translates and rotates freely".to_string(),
            (2, false) => "translates freely in the plane".to_string(),
            (1, _) => describe(sys, q, &shapes[0]),
            (r, _) => format!("moves in {r} independent ways"),
        };
        parts.push(if rank == 1 { what } else { format!("body '{}' {what}", body.name) });
    }
    format!("{} free motions: {}", shapes.len(), parts.join(", "))
}

/// Body `b`'s least-squares rigid motion in `phi`: `(t_x, t_y, θ ℓ)` about its nodes'
/// centroid, `None` where the body stays still.
fn rigid_fit(sys: &FlexibleSystem, b: usize, q: &[f64], phi: &[f64]) -> Option<[f64; 3]> {
    let nodes: Vec<usize> = sys.body_dofs(b).step_by(4).collect();
    let m = nodes.len() as f64;
    let largest = (0..phi.len() / 4).map(|k| phi[4 * k].hypot(phi[4 * k + 1])).fold(0.0, f64::max);
    let moved = nodes.iter().map(|&d| phi[d].hypot(phi[d + 1])).fold(0.0, f64::max);
    if moved <= 1e-6 * largest {
        return None;
    }
    let c = [nodes.iter().map(|&d| q[d]).sum::<f64>() / m, nodes.iter().map(|&d| q[d + 1]).sum::<f64>() / m];
    let t = [nodes.iter().map(|&d| phi[d]).sum::<f64>() / m, nodes.iter().map(|&d| phi[d + 1]).sum::<f64>() / m];
    let (mut num, mut den) = (0.0, 0.0);
    for &d in &nodes {
        let (rx, ry) = (q[d] - c[0], q[d + 1] - c[1]);
        num += -ry * phi[d] + rx * phi[d + 1];
        den += rx * rx + ry * ry;
    }
    let theta = if den > 0.0 { num / den } else { 0.0 };
    Some([t[0], t[1], theta * sys.bodies[b].length])
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The motion `phi` at `q`, body by body ("body 'arm' rotates about (0, 0)"), the bodies
/// that stay still left out.
pub fn describe(sys: &FlexibleSystem, q: &[f64], phi: &[f64]) -> String {
    let mut parts = Vec::new();
    for (b, body) in sys.bodies.iter().enumerate() {
        let Some([tx, ty, turn]) = rigid_fit(sys, b, q, phi) else { continue };
        let tn = tx.hypot(ty);
        let text = if turn.abs() < 1e-3 * tn {
            format!("body '{}' translates along ({}, {})", body.name, unit(tx / tn), unit(ty / tn))
        } else {
            // the point that stays: c + (−t_y, t_x)/θ, from the centroid c
            let nodes: Vec<usize> = sys.body_dofs(b).step_by(4).collect();
            let m = nodes.len() as f64;
            let c = [nodes.iter().map(|&d| q[d]).sum::<f64>() / m, nodes.iter().map(|&d| q[d + 1]).sum::<f64>() / m];
            let theta = turn / body.length;
            let p = [c[0] - ty / theta, c[1] + tx / theta];
            format!("body '{}' rotates about ({}, {}) m", body.name, short(p[0]), short(p[1]))
        };
        parts.push(text);
    }
    if parts.is_empty() {
        "a motion of the slopes alone".to_string()
    } else {
        parts.join(", ")
    }
}

/// A direction's component to three decimals, without a sign on zero.
fn unit(v: f64) -> String {
    // adding 0.0 turns −0.0 into 0.0
    format!("{:.3}", (v * 1000.0).round() / 1000.0 + 0.0)
}

/// A coordinate to six significant digits, round-off near zero shown as 0.
fn short(x: f64) -> String {
    if x.abs() < 1e-9 {
        "0".into()
    } else {
        // six significant digits: a pin's place, not its round-off
        crate::error::show_number(format!("{x:.5e}").parse().unwrap_or(x))
    }
}

/// The error of a load stepping that could not step from the load factor `reached` to
/// `next` (after `e` and `cuts` halvings): no equilibrium where the loads drive a free motion,
/// a singular tangent where a free motion has no load on it, else Newton's failure.
pub fn describe_failure(reached: f64, next: f64, cuts: u32, motions: &[FreeMotion], e: Error) -> Error {
    let told = |m: &[&FreeMotion]| m.iter().map(|m| m.description.as_str()).collect::<Vec<_>>().join("; ");
    let loaded: Vec<&FreeMotion> = motions.iter().filter(|m| m.loaded()).collect();
    let free: Vec<&FreeMotion> = motions.iter().collect();
    if !loaded.is_empty() {
        return Error::usage(format!(
            "statics: no static equilibrium: the loads drive a free motion of the mechanism ({}); \
             add a joint that holds it, or run `simulate`",
            told(&loaded)
        ));
    }
    if !free.is_empty() {
        return Error::usage(format!(
            "statics: the tangent stiffness is singular at {} of the load: free motion ({}) that no joint holds",
            crate::error::show_number(reached),
            told(&free)
        ));
    }
    Error::usage(format!(
        "statics: no equilibrium found past {} of the load (the step to {} failed after {} halvings): {e}",
        crate::error::show_number(reached),
        crate::error::show_number(next),
        cuts
    ))
}
