//! The zoo's kinds with spring-dampers (`[[springs]]`) and point masses with rotary inertia
//! (docs/zoo.md, slots 32 on): an elastic pendulum on a spring to the ground, a load hanging
//! on a spring from a flexible boom, an arm on torsional springs carrying a block, two
//! pendulums coupled by a spring. Every spring is sized as an engineer would size it:
//!
//! * a translational spring carrying a mass `m` bounces with the period `T = 2π √(m/k)`,
//!   drawn between 20 steps of `dt` (so the step resolves the bounce: `simulate`'s Δt
//!   check asks for 10) and half the run (so that it bounces at least twice), within
//!   [0.03, 0.5] s, and it is no stiffer than the axial stiffness `E A / L` of the bodies
//!   it joins (a spring stiffer than the beam it hangs from is a beam, not a spring);
//! * a torsional spring holds the weight outboard of it with a static turn drawn in
//!   [0.05, 0.4] rad at λ = 1 (`k = W / φ`), within the same period bound on the rigid
//!   inertia it carries;
//! * a damper has a damping ratio ζ = c / (2 √(k m)) drawn in [0.005, 0.2], or none.
//!
//! Gravity is scaled in every kind, so λ ∈ [0.5, 1.5] changes the static stretch, the sag
//! and the pendulums' frequencies against the springs'.

use super::mechanisms::{chain, Draft, DRIVE_BEND, E_ALL, FLEX_CLAMPED, FLEX_FREE};
use super::parts::{
    ahead, beam, material, sig, unit_function, Beam, End, Joint, Load, PointMass, Rng, Spring, Time, G,
};
use std::f64::consts::PI;

/// The range of a spring's bounce period, s: a spring a user would notice and a step resolves.
const PERIOD: (f64, f64) = (0.03, 0.5);
/// The range of a torsional spring's static turn under the weight outboard of it, rad.
const SAG: (f64, f64) = (0.05, 0.4);

/// E A / L: the axial stiffness of a beam, N/m.
fn axial(b: &Beam) -> f64 {
    b.youngs_modulus * b.area / b.length()
}

/// The shortest period a step of `t` resolves with 20 steps, and the longest bounce worth a
/// spring in a run of `t`: the bounds of [`PERIOD`] within [20 Δt, t_end / 2].
fn period_range(t: Time) -> (f64, f64) {
    let lo = PERIOD.0.max(20.0 * t.dt);
    (lo, PERIOD.1.min(0.5 * t.t_end).max(lo))
}

/// The stiffness k = m (2π/T)² of a spring on which `mass` (kg; or kg m² for a torsional
/// spring) bounces with a period drawn in [`period_range`], at most `cap`.
fn bounce_stiffness(rng: &mut Rng, t: Time, mass: f64, cap: f64) -> f64 {
    let (lo, hi) = period_range(t);
    let period = rng.log_uniform(lo, hi);
    sig((mass * (2.0 * PI / period).powi(2)).min(cap), 2)
}

/// The stiffness that holds the largest rigid `inertia` (kg m² about the spring's joint) of
/// a step's resolution: k ≤ J (2π / (20 Δt))².
fn resolved_torsion(inertia: f64, t: Time) -> f64 {
    inertia * (2.0 * PI / period_range(t).0).powi(2)
}

/// A damper of damping ratio ζ ∈ [0.005, 0.2] on a spring `k` carrying `mass`, c = 2 ζ √(k m);
/// none in three draws of ten.
fn damper(rng: &mut Rng, k: f64, mass: f64) -> f64 {
    if rng.chance(0.3) {
        0.0
    } else {
        sig(2.0 * rng.log_uniform(0.005, 0.2) * (k * mass).sqrt(), 2)
    }
}

/// A point mass of `ratio` (log-uniform) times `of` kg at the end of `body`.
fn end_mass(rng: &mut Rng, body: &str, of: f64, ratio: (f64, f64)) -> PointMass {
    PointMass::new(body, "end", sig(of * rng.log_uniform(ratio.0, ratio.1), 3))
}

/// Gravity, scaled: λ is the gravity's size.
fn scaled_gravity() -> Load {
    Load::Gravity { g: [0.0, -G], scaled: Some(true) }
}

/// A force on `body`'s end of `ratio` (log-uniform) times `weight`, in a drawn direction,
/// with a drawn time function (scaled: the format's default).
fn end_force(rng: &mut Rng, body: &str, weight: f64, ratio: (f64, f64), t: Time) -> Load {
    let p = rng.log_uniform(ratio.0, ratio.1) * weight;
    let dir = rng.uniform(0.0, 2.0 * PI);
    Load::Force {
        body: body.into(),
        node: "end".into(),
        value: [sig(p * dir.cos(), 3), sig(p * dir.sin(), 3)],
        function: Some(unit_function(rng, t.t_end, t.dt)),
        scaled: None,
    }
}

/// The free length of a spring that starts `gap` long and carries `weight` N on `k`: the
/// static stretch taken off, so that the mass starts at rest where it hangs at λ = 1; None
/// (relaxed at the start: it drops and bounces) in half the draws, or where the stretch
/// would take more than 80 % of the gap.
fn free_length(rng: &mut Rng, gap: f64, weight: f64, k: f64) -> Option<f64> {
    let stretch = weight / k;
    (rng.chance(0.5) && stretch < 0.8 * gap).then(|| sig(gap - stretch, 3))
}

/// A bar hanging from a ground point by a spring-damper at its top node, released tilted:
/// it swings and bounces (an elastic pendulum, data/models/spring_pendulum.toml's kind).
pub(super) fn spring_pendulum(rng: &mut Rng, t: Time) -> Draft {
    let m = material(rng, E_ALL);
    let length = sig(rng.uniform(0.3, 1.5), 2);
    let tilt = sig(rng.log_uniform(0.05, 1.0), 2) * if rng.chance(0.5) { 1.0 } else { -1.0 };
    let bar = beam(rng, "bar", [0.0, 0.0], ahead([0.0, 0.0], length, -0.5 * PI + tilt), m, FLEX_FREE);
    let mut masses = Vec::new();
    if rng.chance(0.5) {
        masses.push(end_mass(rng, "bar", bar.mass(), (0.2, 2.0)));
    }
    let carried = bar.mass() + masses.iter().map(|p| p.mass).sum::<f64>();
    let gap = sig(rng.uniform(0.1, 0.3) * length, 2);
    let k = bounce_stiffness(rng, t, carried, axial(&bar));
    let spring = Spring {
        name: "suspension".into(),
        torsional: false,
        a: ("bar".into(), "start".into()),
        b: End::Point([0.0, gap]),
        stiffness: k,
        damping: damper(rng, k, carried),
        length: free_length(rng, gap, carried * G, k),
    };
    let mut loads = vec![scaled_gravity()];
    if rng.chance(0.3) {
        loads.push(end_force(rng, "bar", carried * G, (0.05, 0.5), t));
    }
    let motion = format!("hanging {gap} m below its spring's ground point, released {tilt} rad from hanging");
    let mut d = Draft::new(vec![bar], Vec::new(), loads, motion);
    d.masses = masses;
    d.springs.push(spring);
    d
}

/// A clamped flexible boom with a bar hanging from its end by a spring-damper, a load's
/// point mass at the bar's lower end: the boom's bending and the load's bounce and swing.
pub(super) fn sprung_boom(rng: &mut Rng, t: Time) -> Draft {
    let reach = sig(rng.uniform(0.4, 1.5), 2);
    let incline = sig(rng.uniform(-0.3, 0.5), 2);
    let mb = material(rng, E_ALL);
    let mut boom = beam(rng, "boom", [0.0, 0.0], ahead([0.0, 0.0], reach, incline), mb, FLEX_CLAMPED);
    let gap = sig(rng.uniform(0.05, 0.2), 2);
    let top = [boom.end[0], sig(boom.end[1] - gap, 6)];
    let swing = sig(rng.uniform(-0.4, 0.4), 2);
    let hl = sig(rng.uniform(0.2, 0.6), 2);
    let mh = material(rng, E_ALL);
    let hanger = beam(rng, "hanger", top, ahead(top, hl, -0.5 * PI + swing), mh, FLEX_FREE);
    let load = end_mass(rng, "hanger", boom.mass() + hanger.mass(), (0.2, 2.0));
    let carried = hanger.mass() + load.mass;
    // the boom sized for the load at its end at λ = 1.5 (M L / EI ≤ 0.3), its own weight too
    boom.carry_moment(1.5 * G * (carried + 0.5 * boom.mass()) * reach, DRIVE_BEND);
    let k = bounce_stiffness(rng, t, carried, axial(&boom).min(axial(&hanger)));
    let spring = Spring {
        name: "hook".into(),
        torsional: false,
        a: ("boom".into(), "end".into()),
        b: End::Node("hanger".into(), "start".into()),
        stiffness: k,
        damping: damper(rng, k, carried),
        length: free_length(rng, gap, carried * G, k),
    };
    let mut loads = vec![scaled_gravity()];
    if rng.chance(0.3) {
        loads.push(end_force(rng, "hanger", carried * G, (0.05, 0.5), t));
    }
    let motion = format!("the load hanging {gap} m below the boom's end, released {swing} rad from hanging");
    let mut d =
        Draft::new(vec![boom, hanger], vec![Joint::Clamp { body: "boom".into(), node: "start".into() }], loads, motion);
    d.masses.push(load);
    d.springs.push(spring);
    d
}

/// The weight moment about `p` of `bodies` and a point mass `tip` at `at`, taken at full
/// reach (each mass at its distance from `p`, as if level): the largest gravity holds.
fn reach_moment(bodies: &[Beam], tip: f64, at: [f64; 2], p: [f64; 2]) -> f64 {
    let dist = |q: [f64; 2]| (q[0] - p[0]).hypot(q[1] - p[1]);
    G * (bodies.iter().map(|b| b.mass() * dist(b.centre())).sum::<f64>() + tip * dist(at))
}

/// 1–2 links on a short clamped bracket, pinned at the shoulder (the bracket's end) and the
/// elbow, each pin with a torsional spring-damper; a block at the tip (a point mass with
/// rotary inertia, J = m r² of a block of r 2–8 cm). The bracket runs along the first link
/// and each link within 0.5 rad of the one before, so that the springs' relative angles stay
/// well inside (−π, π] where `atan2` does not wrap; the arm sags against the springs under
/// gravity, and in four draws of ten a moment at the shoulder turns it.
pub(super) fn spring_arm(rng: &mut Rng, t: Time) -> Draft {
    let n = rng.int(1, 2);
    let first = sig(rng.uniform(-0.6, 0.6), 2);
    let bracket = sig(rng.uniform(0.05, 0.2), 2);
    let mp = material(rng, (1e10, 1e11));
    let mut post = beam(rng, "bracket", ahead([0.0, 0.0], -bracket, first), [0.0, 0.0], mp, FLEX_CLAMPED);
    post.elements = 10; // a short stiff bracket: the coarsest mesh of the zoo's range
    let mut angle = first;
    let specs: Vec<_> = (0..n)
        .map(|i| {
            if i > 0 {
                angle = sig(angle + rng.uniform(-0.5, 0.5), 2);
            }
            (sig(rng.uniform(0.2, 0.8), 2), angle, material(rng, E_ALL), FLEX_FREE)
        })
        .collect();
    let (mut links, pins) = chain(rng, [0.0, 0.0], &specs);
    let total: f64 = links.iter().map(Beam::mass).sum();
    let mut block = end_mass(rng, &format!("link{n}"), total, (0.2, 2.0));
    let r = rng.uniform(0.02, 0.08);
    block.rotary_inertia = Some(sig(block.mass * r * r, 2));
    let tip = links.last().expect("a link").end;
    let mut springs = Vec::new();
    let mut moments = Vec::new();
    for i in 0..n {
        let joint = links[i].start;
        let w = reach_moment(&links[i..], block.mass, tip, joint);
        let inertia = links[i..].iter().map(|b| b.inertia_about(joint)).sum::<f64>()
            + block.mass * (tip[0] - joint[0]).hypot(tip[1] - joint[1]).powi(2);
        let k = sig((w / rng.log_uniform(SAG.0, SAG.1)).min(resolved_torsion(inertia, t)), 2);
        let (a, name) = if i == 0 { ("bracket".to_string(), "shoulder") } else { (format!("link{i}"), "elbow") };
        springs.push(Spring {
            name: name.into(),
            torsional: true,
            a: (a, "end".into()),
            b: End::Node(links[i].name.clone(), "start".into()),
            stiffness: k,
            damping: damper(rng, k, inertia),
            length: None,
        });
        moments.push(w);
    }
    let mut loads = vec![scaled_gravity()];
    if rng.chance(0.4) {
        let f = unit_function(rng, t.t_end, t.dt).scaled(moments[0] * rng.uniform(0.2, 1.0));
        loads.push(Load::Moment { body: "link1".into(), node: "start".into(), function: f, scaled: None });
    }
    // each link and the bracket sized for the moment its spring holds at λ = 1.5, twice the
    // static one for the swing a release from the unsagged shape gives
    for (link, w) in links.iter_mut().zip(&moments) {
        link.carry_moment(3.0 * w, DRIVE_BEND);
    }
    post.carry_moment(3.0 * moments[0], DRIVE_BEND);
    let mut joints = vec![
        Joint::Clamp { body: "bracket".into(), node: "start".into() },
        Joint::Pin { a: ("bracket".into(), "end".into()), b: ("link1".into(), "start".into()) },
    ];
    joints.extend(pins);
    let mut bodies = vec![post];
    bodies.append(&mut links);
    let motion = format!("{n} link(s) on torsional springs, released unsagged");
    let mut d = Draft::new(bodies, joints, loads, motion);
    d.masses.push(block);
    d.springs = springs;
    d
}

/// Two pendulums on ground pins `d` apart, hanging, joined by a spring-damper between nodes
/// at the same fraction of their lengths (their ends in half the draws), its free length the
/// nodes' distance when both hang straight; the left one released tilted away from the
/// right by at most what keeps its swing within half the gap (the spring never folds).
/// The coupling k a² against the left pendulum's gravity stiffness W ℓ is drawn in [0.05, 2].
pub(super) fn coupled_pendulums(rng: &mut Rng, t: Time) -> Draft {
    let d = sig(rng.uniform(0.2, 0.6), 2);
    let l1 = sig(rng.uniform(0.3, 1.2), 2);
    let l2 = if rng.chance(0.5) { l1 } else { sig(rng.uniform(0.3, 1.2), 2) };
    let tilt = sig(rng.log_uniform(0.05, 0.6).min((0.5 * d / l1).asin()), 2);
    let down = -0.5 * PI;
    let (m1, m2) = (material(rng, E_ALL), material(rng, E_ALL));
    let left = beam(rng, "left", [0.0, 0.0], ahead([0.0, 0.0], l1, down - tilt), m1, FLEX_FREE);
    let right = beam(rng, "right", [d, 0.0], ahead([d, 0.0], l2, down), m2, FLEX_FREE);
    let frac = if rng.chance(0.5) { 1.0 } else { rng.uniform(0.3, 1.0) };
    let node = |b: &Beam| ((frac * b.elements as f64).round() as usize).clamp(1, b.elements);
    let (n1, n2) = (node(&left), node(&right));
    let name = |b: &Beam, k: usize| if k == b.elements { "end".to_string() } else { k.to_string() };
    let depth = |b: &Beam, k: usize| b.length() * k as f64 / b.elements as f64;
    let (a1, a2) = (depth(&left, n1), depth(&right, n2));
    let mut masses = Vec::new();
    for b in [&left, &right] {
        if rng.chance(0.4) {
            masses.push(end_mass(rng, &b.name, b.mass(), (0.2, 2.0)));
        }
    }
    let tip = |b: &Beam| masses.iter().filter(|p: &&PointMass| p.body == b.name).map(|p| p.mass).sum::<f64>();
    // the left pendulum's gravity stiffness at the spring's node, W ℓ / a² (N/m), and its
    // inertia there, J / a² (kg)
    let gravity_stiffness = G * (0.5 * left.mass() * l1 + tip(&left) * l1) / (a1 * a1);
    let mass_there = (left.inertia_about([0.0, 0.0]) + tip(&left) * l1 * l1) / (a1 * a1);
    let cap = (mass_there * (2.0 * PI / period_range(t).0).powi(2)).min(axial(&left)).min(axial(&right));
    let k = sig((gravity_stiffness * rng.log_uniform(0.05, 2.0)).min(cap), 2);
    let spring = Spring {
        name: "coupler".into(),
        torsional: false,
        a: ("left".into(), name(&left, n1)),
        b: End::Node("right".into(), name(&right, n2)),
        stiffness: k,
        damping: damper(rng, k, mass_there),
        length: Some(sig(d.hypot(a1 - a2), 6)),
    };
    let joints = vec![
        Joint::GroundPin { body: "left".into(), node: "start".into() },
        Joint::GroundPin { body: "right".into(), node: "start".into() },
    ];
    let motion = format!("{d} m apart, coupled at {:.2} of their lengths, the left released {tilt} rad out", frac);
    let mut dr = Draft::new(vec![left, right], joints, vec![scaled_gravity()], motion);
    dr.masses = masses;
    dr.springs.push(spring);
    dr
}
