//! The free motions of a mechanism at a configuration: its modes of zero frequency
//! ([`super::modes`], the rigid motions the joints leave), each told as what every body
//! does. Per body the motion `δr` of its nodes is fitted, in least squares, by a rigid one
//! `δr = t + θ ẑ × (r − c)` about the nodes' centroid `c` (`t` the mean of `δr`,
//! `θ = Σ (ẑ × (r − c)) · δr / Σ |r − c|²`): a rotation about the point where `δr = 0`,
//! `c + (−t_y, t_x)/θ`, or, when `|θ| ℓ` is below a thousandth of `|t|` (ℓ the body's
//! length), a translation along `t`. The loads do work on the motion `φ` when
//! `|Q_extᵀφ| > 10⁻⁶ |Q_ext| |φ|`: then no static equilibrium exists near the configuration.

use super::modes;
use super::ramp::Ramped;
use crate::error::{Error, Result};
use crate::physics::system::FlexibleSystem;

/// One free motion: what it does, in words, and the loads' share of work on it.
#[derive(Clone, Debug)]
pub struct FreeMotion {
    pub description: String,
    /// `Q_extᵀφ / (|Q_ext| |φ|)` (0 without loads)
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
    let load = model.external_force(q, t);
    let load_norm = norm(&load);
    let sys = model.system();
    Ok(shapes
        .iter()
        .map(|phi| {
            let w = load.iter().zip(phi).map(|(a, b)| a * b).sum::<f64>();
            let work = if load_norm > 0.0 { w / (load_norm * norm(phi)) } else { 0.0 };
            FreeMotion { description: describe(sys, q, phi), work }
        })
        .collect())
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The motion `phi` at `q`, body by body ("body 'arm' rotates about (0, 0)"), the bodies
/// that stay still left out.
pub fn describe(sys: &FlexibleSystem, q: &[f64], phi: &[f64]) -> String {
    let largest = (0..phi.len() / 4).map(|k| phi[4 * k].hypot(phi[4 * k + 1])).fold(0.0, f64::max);
    let mut parts = Vec::new();
    for (b, body) in sys.bodies.iter().enumerate() {
        let nodes: Vec<usize> = sys.body_dofs(b).step_by(4).collect();
        let m = nodes.len() as f64;
        let moved = nodes.iter().map(|&d| phi[d].hypot(phi[d + 1])).fold(0.0, f64::max);
        if moved <= 1e-6 * largest {
            continue;
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
        let tn = t[0].hypot(t[1]);
        let text = if theta.abs() * body.length < 1e-3 * tn {
            format!("body '{}' translates along ({:.3}, {:.3})", body.name, t[0] / tn, t[1] / tn)
        } else {
            let p = [c[0] - t[1] / theta, c[1] + t[0] / theta];
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

/// A coordinate to four significant digits, round-off near zero shown as 0.
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
        return Error::Usage(format!(
            "statics: no static equilibrium: the loads drive a free motion of the mechanism ({}); \
             add a joint that holds it, or run `simulate`",
            told(&loaded)
        ));
    }
    if !free.is_empty() {
        return Error::Usage(format!(
            "statics: the tangent stiffness is singular at {} of the load: free motion ({}) that no joint holds",
            crate::error::show_number(reached),
            told(&free)
        ));
    }
    Error::Usage(format!(
        "statics: no equilibrium found past {} of the load (the step to {} failed after {} halvings): {e}",
        crate::error::show_number(reached),
        crate::error::show_number(next),
        cuts
    ))
}
