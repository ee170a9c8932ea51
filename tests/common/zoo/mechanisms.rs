//! The kinds of mechanism in the zoo and how each is drawn from a random stream: what a user
//! would build first (a pendulum, a cantilever, a chain, a driven arm, a clamped boom with
//! links, a four-bar, a frame, a five-bar), and what a user builds with sliders, welds, point
//! masses, drives by angle and initial velocities (a slider-crank, an arm driven by angle, a
//! welded frame, a spinning link), with materials, sections, loads, drives and time settings
//! drawn over the ranges of the zoo's brief (tests/common/zoo/mod.rs).

use super::parts::{
    ahead, beam, describe_extras, material, model_toml, sig, time, unit_function, Beam, Func, Joint, Load, Material,
    Parts, Place, PointMass, Probe, Rng, Spring, Time, G,
};
use super::springs;
use std::f64::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// one beam on a ground pin (at its end or inside), swinging or driven round
    Pendulum,
    /// one clamped beam (sometimes propped by a ground pin at its far end) under a point load
    Cantilever,
    /// 2–4 beams pinned in a chain from a ground pin, falling under gravity
    NPendulum,
    /// 2–3 beams pinned in a chain, driven by a moment at the ground pin (the shoulder)
    DrivenArm,
    /// a clamped beam carrying 1–3 pinned links
    ClampedChain,
    /// crank, coupler, follower: a closed loop of three beams, the crank driven
    FourBar,
    /// a V of two beams pinned at the apex, or a portal of two clamped columns and a pinned beam
    Frame,
    /// a closed loop of four beams between two ground pins (two degrees of freedom)
    FiveBar,
    /// a crank on a ground pin, a flexible rod whose far end slides on the x axis (sometimes
    /// carrying a slider block's point mass); the crank driven by angle from rest to a rate,
    /// or in some draws by a moment
    SliderCrank,
    /// 1–3 beams pinned in a chain, the first driven by angle at its ground pin (the
    /// shoulder): a rest-to-rest move or a swing; sometimes a point mass at the tip
    AngleArm,
    /// an L or a T of beams welded at a corner, clamped at the column's foot or pinned at the
    /// corner, with point masses at the arms' ends, under gravity or a force
    WeldedFrame,
    /// one beam on a ground pin spun up by angle from rest (the spin-up beam), or released
    /// with an initial angular velocity under gravity; sometimes a tip mass
    SpinningLink,
    /// one bar hanging from a ground point by a spring-damper at its top node, released
    /// tilted (an elastic pendulum); sometimes a tip mass
    SpringPendulum,
    /// a clamped flexible boom with a bar hanging from its end by a spring-damper, a load's
    /// point mass at the bar's lower end
    SprungBoom,
    /// 1–2 links on a short clamped bracket, a torsional spring-damper at the shoulder and
    /// the elbow, a tip point mass with rotary inertia, sagging under gravity
    SpringArm,
    /// two pendulums on ground pins side by side, joined by a spring-damper, one released
    /// tilted
    CoupledPendulums,
}

pub const KINDS: [Kind; 8] = [
    Kind::Pendulum,
    Kind::Cantilever,
    Kind::NPendulum,
    Kind::DrivenArm,
    Kind::ClampedChain,
    Kind::FourBar,
    Kind::Frame,
    Kind::FiveBar,
];

/// The kinds of the slots after the first [`OLD_SLOTS`]: slot `i ≥ OLD_SLOTS` draws
/// `NEW_KINDS[(i − OLD_SLOTS) mod 4]`, so that the first slots keep their models.
pub const NEW_KINDS: [Kind; 4] = [Kind::SliderCrank, Kind::AngleArm, Kind::WeldedFrame, Kind::SpinningLink];

/// The kinds with spring-dampers and point masses with rotary inertia: slot `i ≥
/// SPRING_SLOTS` draws `SPRING_KINDS[(i − SPRING_SLOTS) mod 4]`, so that the slots before
/// keep their models.
pub const SPRING_KINDS: [Kind; 4] = [Kind::SpringPendulum, Kind::SprungBoom, Kind::SpringArm, Kind::CoupledPendulums];

/// The slots the zoo had before the kinds of [`NEW_KINDS`]: slot `i` below it draws `KINDS[i mod 8]`.
pub const OLD_SLOTS: usize = 24;

/// The slots the zoo had before the kinds of [`SPRING_KINDS`]: slots `OLD_SLOTS..SPRING_SLOTS`
/// draw [`NEW_KINDS`].
pub const SPRING_SLOTS: usize = 32;

/// The kind of slot `slot`.
pub fn kind_of(slot: usize) -> Kind {
    if slot < OLD_SLOTS {
        KINDS[slot % KINDS.len()]
    } else if slot < SPRING_SLOTS {
        NEW_KINDS[(slot - OLD_SLOTS) % NEW_KINDS.len()]
    } else {
        SPRING_KINDS[(slot - SPRING_SLOTS) % SPRING_KINDS.len()]
    }
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Pendulum => "pendulum",
            Kind::Cantilever => "cantilever",
            Kind::NPendulum => "n-pendulum",
            Kind::DrivenArm => "driven-arm",
            Kind::ClampedChain => "clamped-chain",
            Kind::FourBar => "four-bar",
            Kind::Frame => "frame",
            Kind::FiveBar => "five-bar",
            Kind::SliderCrank => "slider-crank",
            Kind::AngleArm => "angle-arm",
            Kind::WeldedFrame => "welded-frame",
            Kind::SpinningLink => "spinning-link",
            Kind::SpringPendulum => "spring-pendulum",
            Kind::SprungBoom => "sprung-boom",
            Kind::SpringArm => "spring-arm",
            Kind::CoupledPendulums => "coupled-pendulums",
        }
    }
}

/// E over the whole range of the zoo: 1e6 (soft elastomer) to 1e11 Pa (steel-like).
pub(super) const E_ALL: (f64, f64) = (1e6, 1e11);
/// Flexibility caps (`Beam::flexibility`): a body hanging or driven from one end, a
/// cantilever, a body held at both ends.
pub(super) const FLEX_FREE: f64 = 1.0;
pub(super) const FLEX_CLAMPED: f64 = 0.5;
const FLEX_HELD: f64 = 3.0;
/// How far a drive's peak moment may bend the link it acts on (M L / EI, rad).
pub(super) const DRIVE_BEND: f64 = 0.3;

/// A drawn mechanism: the model file and a one-line account of it.
pub struct Mechanism {
    pub toml: String,
    pub summary: String,
    pub n_bodies: usize,
    pub n_elements: usize,
    /// 4 per node (x, y and the slope's two components)
    pub n_coordinates: usize,
}

pub fn build(kind: Kind, rng: &mut Rng) -> Mechanism {
    let t = time(rng);
    let mut m = match kind {
        Kind::Pendulum => pendulum(rng, t),
        Kind::Cantilever => cantilever(rng, t),
        Kind::NPendulum => n_pendulum(rng, t),
        Kind::DrivenArm => driven_arm(rng, t),
        Kind::ClampedChain => clamped_chain(rng, t),
        Kind::FourBar => four_bar(rng, t),
        Kind::Frame => frame(rng, t),
        Kind::FiveBar => five_bar(rng, t),
        Kind::SliderCrank => slider_crank(rng, t),
        Kind::AngleArm => angle_arm(rng, t),
        Kind::WeldedFrame => welded_frame(rng, t),
        Kind::SpinningLink => spinning_link(rng, t),
        Kind::SpringPendulum => springs::spring_pendulum(rng, t),
        Kind::SprungBoom => springs::sprung_boom(rng, t),
        Kind::SpringArm => springs::spring_arm(rng, t),
        Kind::CoupledPendulums => springs::coupled_pendulums(rng, t),
    };
    // a light Rayleigh damping in one model of five, as some users add
    if rng.chance(0.2) {
        m.damping = Some(if rng.chance(0.5) {
            (sig(rng.log_uniform(0.1, 2.0), 2), 0.0)
        } else {
            (0.0, sig(rng.log_uniform(1e-5, 1e-3), 2))
        });
    }
    // at least one load or drive follows the load scale, or λ would change nothing (drives
    // by angle always do: `Joint::DrivenAngle` is written with `scaled = true`)
    let driven = m.joints.iter().any(|j| matches!(j, Joint::DrivenAngle { .. }));
    if !driven && !m.loads.iter().any(Load::is_scaled) {
        match &mut m.loads[0] {
            Load::Gravity { scaled, .. } | Load::Moment { scaled, .. } | Load::Force { scaled, .. } => {
                *scaled = Some(true)
            }
        }
    }
    m.finish(kind, t)
}

/// A mechanism being drawn.
pub(super) struct Draft {
    bodies: Vec<Beam>,
    joints: Vec<Joint>,
    loads: Vec<Load>,
    damping: Option<(f64, f64)>,
    pub(super) masses: Vec<PointMass>,
    pub(super) springs: Vec<Spring>,
    /// what the drive aims at, for the summary
    motion: String,
}

impl Draft {
    pub(super) fn new(bodies: Vec<Beam>, joints: Vec<Joint>, loads: Vec<Load>, motion: String) -> Self {
        Draft { bodies, joints, loads, damping: None, masses: Vec::new(), springs: Vec::new(), motion }
    }

    /// The nodes held against turning by the ground — clamped, driven by angle, or
    /// ground-pinned and driven by a moment — in the order of the joints, then the loads;
    /// each once. Where a link carries the largest bending moment of its motion.
    fn roots(&self) -> Vec<(String, String)> {
        let pinned = |b: &str, n: &str| {
            self.joints.iter().any(|j| matches!(j, Joint::GroundPin { body, node } if body == b && node == n))
        };
        let mut roots: Vec<(String, String)> = Vec::new();
        let joints = self.joints.iter().filter_map(|j| match j {
            Joint::Clamp { body, node } | Joint::DrivenAngle { body, node, .. } => Some((body, node)),
            _ => None,
        });
        let moments = self.loads.iter().filter_map(|l| match l {
            Load::Moment { body, node, .. } if pinned(body, node) => Some((body, node)),
            _ => None,
        });
        for (body, node) in joints.chain(moments) {
            if !roots.iter().any(|(b, n)| b == body && n == node) {
                roots.push((body.clone(), node.clone()));
            }
        }
        roots
    }

    /// A probe recording strain and curvature (the bending moment E I κ) at every root
    /// ([`Draft::roots`]): "root" at the first, "root_BODY" at the others. Probes record; the
    /// dynamics are those of the model without them.
    fn root_probes(&self) -> Vec<Probe> {
        self.roots()
            .into_iter()
            .enumerate()
            .map(|(i, (body, node))| Probe {
                name: if i == 0 { "root".into() } else { format!("root_{body}") },
                body,
                place: Place::Node(node),
                quantities: vec!["strain", "curvature"],
            })
            .collect()
    }

    fn finish(self, kind: Kind, t: Time) -> Mechanism {
        let last = self.bodies.last().expect("a body");
        let mut probes =
            vec![Probe { name: "tip".into(), body: last.name.clone(), place: Place::At(1.0), quantities: Vec::new() }];
        probes.extend(self.root_probes());
        let bodies: Vec<String> = self
            .bodies
            .iter()
            .map(|b| {
                format!(
                    "{} {} el. E {:.0e} L/r {:.0} flex {:.1e}",
                    b.name,
                    b.elements,
                    b.youngs_modulus,
                    b.slenderness(),
                    b.flexibility()
                )
            })
            .collect();
        let mut loads: Vec<String> = self.loads.iter().map(Load::describe).collect();
        loads.extend(describe_extras(&self.masses, &self.springs));
        if loads.is_empty() {
            loads.push("no loads".into());
        }
        let damping = match self.damping {
            Some((a, 0.0)) => format!("; damping {a} M"),
            Some((_, b)) => format!("; damping {b:e} K"),
            None => String::new(),
        };
        let summary = format!(
            "{}: {}; {}; {}; t_end {} s, dt {} s, rho_inf {}{}",
            kind.name(),
            bodies.join(", "),
            loads.join(", "),
            self.motion,
            t.t_end,
            t.dt,
            t.rho_inf,
            damping
        );
        let parts = Parts {
            bodies: &self.bodies,
            joints: &self.joints,
            loads: &self.loads,
            masses: &self.masses,
            springs: &self.springs,
        };
        let toml = model_toml(&summary, t, self.damping, &parts, &probes);
        let n_elements: usize = self.bodies.iter().map(|b| b.elements).sum();
        Mechanism {
            toml,
            summary,
            n_bodies: self.bodies.len(),
            n_elements,
            n_coordinates: self.bodies.iter().map(|b| 4 * (b.elements + 1)).sum(),
        }
    }
}

fn gravity(rng: &mut Rng, p_scaled: f64) -> Load {
    let scaled = if rng.chance(p_scaled) {
        Some(true)
    } else if rng.chance(0.5) {
        Some(false)
    } else {
        None // the default: unscaled
    };
    Load::Gravity { g: [0.0, -G], scaled }
}

/// A force at the end of the last link, `ratio` (log-uniform in the given range) times the
/// mechanism's weight, in a drawn direction, with a drawn time function.
fn tip_force(rng: &mut Rng, bodies: &[Beam], ratio: (f64, f64), t: Time) -> Load {
    let last = bodies.last().expect("a link");
    let total: f64 = bodies.iter().map(Beam::mass).sum();
    let p = rng.log_uniform(ratio.0, ratio.1) * total * G;
    let dir = rng.uniform(0.0, 2.0 * PI);
    Load::Force {
        body: last.name.clone(),
        node: "end".into(),
        value: [sig(p * dir.cos(), 3), sig(p * dir.sin(), 3)],
        function: Some(unit_function(rng, t.t_end, t.dt)),
        scaled: None,
    }
}

/// A moment history of a drawn shape whose size turns a body of rotational inertia `j`
/// by about `theta` over the run (rigid estimate; gravity and elasticity ignored), at
/// least `hold` at its peak (a moment that can lift the mechanism against its weight).
fn drive(rng: &mut Rng, t: Time, j: f64, theta: f64, hold: f64) -> Func {
    let f = unit_function(rng, t.t_end, t.dt);
    let per_unit = f.max_double_integral(t.t_end) / j;
    let amplitude = (theta / per_unit).max(hold / f.peak(t.t_end).max(1e-12));
    f.scaled(amplitude)
}

/// A moment load on `body` at `node` that turns by about `theta` (`drive`), its link
/// thickened to carry it (`DRIVE_BEND`).
fn driving_moment(rng: &mut Rng, t: Time, body: &mut Beam, node: &str, j: f64, theta: f64, hold: f64) -> Load {
    let f = drive(rng, t, j, theta, hold);
    body.carry_moment(f.peak(t.t_end), DRIVE_BEND);
    Load::Moment { body: body.name.clone(), node: node.into(), function: f, scaled: None }
}

/// A gravity hold for a drive that aims at more than a swing: 1.5× the weight's moment
/// (`weight`), so the drive can lift the mechanism over the top; none for smaller aims.
fn hold_for(theta: f64, weight: f64) -> f64 {
    if theta > 1.0 {
        1.5 * weight
    } else {
        0.0
    }
}

/// A rotation target from small swings (0.05 rad) to several full turns (4π).
fn rotation(rng: &mut Rng) -> f64 {
    rng.log_uniform(0.05, 4.0 * PI)
}

fn describe_rotation(theta: f64) -> String {
    if theta >= 2.0 * PI {
        format!("drive aims at {:.1} turns", theta / (2.0 * PI))
    } else {
        format!("drive aims at {theta:.2} rad")
    }
}

fn pendulum(rng: &mut Rng, t: Time) -> Draft {
    let m = material(rng, E_ALL);
    let length = sig(rng.uniform(0.3, 1.5), 2);
    // released at `swing` from hanging straight down (small swings to horizontal and beyond)
    let swing = rng.log_uniform(0.05, 0.6 * PI) * if rng.chance(0.5) { 1.0 } else { -1.0 };
    let angle = -0.5 * PI + swing;
    // pinned at its end, or at a node a quarter along (a swinging bar pivoted inside)
    let inside = rng.chance(0.25);
    let mut b = beam(rng, "beam", [0.0, 0.0], ahead([0.0, 0.0], length, angle), m, FLEX_FREE);
    let pivot_node = if inside { b.elements / 4 } else { 0 };
    let offset = length * pivot_node as f64 / b.elements as f64;
    b.start = ahead([0.0, 0.0], -offset, angle);
    b.end = ahead(b.start, length, angle);
    let pivot = b.start;
    let node = if inside { pivot_node.to_string() } else { "start".into() };
    let mut loads = vec![gravity(rng, 0.6)];
    let mut motion = format!("released {swing:.2} rad from hanging");
    match rng.int(0, 2) {
        0 => {}
        1 => {
            // driven round at the pivot
            let theta = rotation(rng);
            let (j, w) = (b.inertia_about(pivot), b.weight_moment_about(pivot));
            loads.push(driving_moment(rng, t, &mut b, &node, j, theta, hold_for(theta, w)));
            motion = format!("{motion}, {}", describe_rotation(theta));
        }
        _ => {
            let p = rng.log_uniform(0.1, 2.0) * b.mass() * G;
            let dir = rng.uniform(0.0, 2.0 * PI);
            let f = unit_function(rng, t.t_end, t.dt);
            loads.push(Load::Force {
                body: "beam".into(),
                node: "end".into(),
                value: [sig(p * dir.cos(), 3), sig(p * dir.sin(), 3)],
                function: Some(f),
                scaled: if rng.chance(0.5) { None } else { Some(rng.chance(0.7)) },
            });
        }
    }
    Draft::new(vec![b], vec![Joint::GroundPin { body: "beam".into(), node }], loads, motion)
}

fn cantilever(rng: &mut Rng, t: Time) -> Draft {
    let m = material(rng, E_ALL);
    let length = sig(rng.uniform(0.3, 1.5), 2);
    let angle = match rng.int(0, 4) {
        0..=2 => 0.0,
        3 => 0.5 * PI,
        _ => sig(rng.uniform(-0.5 * PI, 0.5 * PI), 2),
    };
    let b = beam(rng, "beam", [0.0, 0.0], ahead([0.0, 0.0], length, angle), m, FLEX_CLAMPED);
    let propped = rng.chance(0.25);
    let mut joints = vec![Joint::Clamp { body: "beam".into(), node: "start".into() }];
    if propped {
        joints.push(Joint::GroundPin { body: "beam".into(), node: "end".into() });
    }
    let ei = b.bending_stiffness();
    let f = unit_function(rng, t.t_end, t.dt);
    // loads of the elastica's range: P L²/EI (or M L/EI) from 0.02 to 2
    let kappa = rng.log_uniform(0.02, 2.0);
    let load_node = if propped { (b.elements / 2).to_string() } else { "end".into() };
    let mut loads = Vec::new();
    let motion = if rng.chance(0.7) || propped {
        let p = kappa * ei / (length * length) * if propped { 8.0 } else { 1.0 };
        let dir = angle + if rng.chance(0.7) { -0.5 * PI } else { rng.uniform(0.0, 2.0 * PI) };
        loads.push(Load::Force {
            body: "beam".into(),
            node: load_node,
            value: [sig(p * dir.cos(), 3), sig(p * dir.sin(), 3)],
            function: Some(f),
            scaled: if rng.chance(0.5) { None } else { Some(true) },
        });
        format!("point force P L²/EI up to {kappa:.2}{}", if propped { ", propped end" } else { "" })
    } else {
        let mo = kappa.min(1.0) * ei / length;
        loads.push(Load::Moment { body: "beam".into(), node: "end".into(), function: f.scaled(mo), scaled: None });
        format!("tip moment M L/EI up to {:.2}", kappa.min(1.0))
    };
    if rng.chance(0.5) {
        loads.push(gravity(rng, 0.3));
    }
    Draft::new(vec![b], joints, loads, motion)
}

/// Beams end to end from `origin`, each at its own angle; pins between neighbours.
pub(super) fn chain(rng: &mut Rng, origin: [f64; 2], specs: &[(f64, f64, Material, f64)]) -> (Vec<Beam>, Vec<Joint>) {
    let mut bodies: Vec<Beam> = Vec::new();
    let mut joints = Vec::new();
    let mut p = origin;
    for (i, &(length, angle, m, cap)) in specs.iter().enumerate() {
        let name = format!("link{}", i + 1);
        let b = beam(rng, &name, p, ahead(p, length, angle), m, cap);
        p = b.end;
        if let Some(prev) = bodies.last() {
            joints.push(Joint::Pin { a: (prev.name.clone(), "end".into()), b: (name.clone(), "start".into()) });
        }
        bodies.push(b);
    }
    (bodies, joints)
}

fn n_pendulum(rng: &mut Rng, t: Time) -> Draft {
    let n = rng.int(2, 4);
    let straight = rng.chance(0.5);
    let first = if straight { sig(rng.uniform(-0.5 * PI, 0.0), 2) } else { 0.0 };
    let specs: Vec<_> = (0..n)
        .map(|_| {
            let angle = if straight { first } else { sig(rng.uniform(-PI, 0.0), 2) };
            (sig(rng.uniform(0.2, 0.8), 2), angle, material(rng, E_ALL), FLEX_FREE)
        })
        .collect();
    let (bodies, mut joints) = chain(rng, [0.0, 0.0], &specs);
    joints.insert(0, Joint::GroundPin { body: "link1".into(), node: "start".into() });
    let mut loads = vec![gravity(rng, 0.7)];
    if rng.chance(0.4) {
        loads.push(tip_force(rng, &bodies, (0.05, 1.0), t));
    }
    let motion = if straight { "released straight".to_string() } else { "released bent".to_string() };
    Draft::new(bodies, joints, loads, motion)
}

fn driven_arm(rng: &mut Rng, t: Time) -> Draft {
    let n = rng.int(2, 3);
    // half of them: a stiff crank carrying soft links
    let stiff_crank = rng.chance(0.5);
    let specs: Vec<_> = (0..n)
        .map(|i| {
            let e = if !stiff_crank {
                E_ALL
            } else if i == 0 {
                (1e10, 1e11)
            } else {
                (1e6, 1e8)
            };
            (sig(rng.uniform(0.2, 0.8), 2), sig(rng.uniform(-PI, PI), 2), material(rng, e), FLEX_FREE)
        })
        .collect();
    let (mut bodies, mut joints) = chain(rng, [0.0, 0.0], &specs);
    joints.insert(0, Joint::GroundPin { body: "link1".into(), node: "start".into() });
    let with_gravity = rng.chance(0.5);
    let j: f64 = bodies.iter().map(|b| b.inertia_about([0.0, 0.0])).sum();
    let weight: f64 =
        if with_gravity { bodies.iter().map(|b| b.weight_moment_about([0.0, 0.0])).sum::<f64>() } else { 0.0 };
    let theta = rotation(rng);
    let mut loads = vec![driving_moment(rng, t, &mut bodies[0], "start", j, theta, hold_for(theta, weight))];
    if with_gravity {
        loads.push(gravity(rng, 0.3));
    }
    // an elbow moment on the second link, in one arm of three
    if rng.chance(0.33) {
        let j2: f64 = bodies[1..].iter().map(|b| b.inertia_about(bodies[1].start)).sum();
        let theta2 = rotation(rng);
        let mut elbow = driving_moment(rng, t, &mut bodies[1], "start", j2, theta2, 0.0);
        if let Load::Moment { scaled, .. } = &mut elbow {
            *scaled = if rng.chance(0.5) { None } else { Some(false) };
        }
        loads.push(elbow);
    }
    let motion = format!("{}{}", if stiff_crank { "stiff crank, soft links; " } else { "" }, describe_rotation(theta));
    Draft::new(bodies, joints, loads, motion)
}

fn clamped_chain(rng: &mut Rng, t: Time) -> Draft {
    let n = rng.int(2, 4);
    let base_angle = if rng.chance(0.5) { 0.5 * PI } else { 0.0 };
    let specs: Vec<_> = (0..n)
        .map(|i| {
            let angle = if i == 0 { base_angle } else { sig(rng.uniform(-PI, PI), 2) };
            let cap = if i == 0 { FLEX_CLAMPED } else { FLEX_FREE };
            (sig(rng.uniform(0.2, 0.9), 2), angle, material(rng, E_ALL), cap)
        })
        .collect();
    let (mut bodies, mut joints) = chain(rng, [0.0, 0.0], &specs);
    joints.insert(0, Joint::Clamp { body: "link1".into(), node: "start".into() });
    let mut loads = vec![gravity(rng, 0.5)];
    let motion = if rng.chance(0.5) {
        // a moment on the first pinned link, at its pin
        let j: f64 = bodies[1..].iter().map(|b| b.inertia_about(bodies[1].start)).sum();
        let theta = rotation(rng);
        loads.push(driving_moment(rng, t, &mut bodies[1], "start", j, theta, 0.0));
        describe_rotation(theta)
    } else {
        loads.push(tip_force(rng, &bodies, (0.1, 2.0), t));
        "tip force".into()
    };
    Draft::new(bodies, joints, loads, motion)
}

/// Where the circles |P − a| = ra and |P − b| = rb meet, on the left of a → b.
fn circles(a: [f64; 2], ra: f64, b: [f64; 2], rb: f64) -> Option<[f64; 2]> {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let d = dx.hypot(dy);
    if d >= ra + rb || d <= (ra - rb).abs() {
        return None;
    }
    let x = (d * d + ra * ra - rb * rb) / (2.0 * d);
    let h = (ra * ra - x * x).sqrt();
    Some([a[0] + (x * dx - h * dy) / d, a[1] + (x * dy + h * dx) / d])
}

fn four_bar(rng: &mut Rng, t: Time) -> Draft {
    // a Grashof crank-rocker (crank the shortest link, s + l ≤ p + q with 10 % to spare) so
    // that the crank may turn fully without the loop locking
    let (o, gp, a, p) = loop {
        let g = sig(rng.uniform(0.4, 0.9), 2);
        let a = sig(rng.uniform(0.1, 0.25), 2);
        let b = sig(rng.uniform(0.4, 1.0), 2);
        let c = sig(rng.uniform(0.3, 0.9), 2);
        let l = g.max(b).max(c);
        if !(a < g.min(b).min(c) && 1.1 * (a + l) <= g + b + c - l) {
            continue;
        }
        let (ground, crank, coupler, follower) = (g, a, b, c);
        let theta0 = sig(rng.uniform(0.3 * PI, 0.7 * PI), 2);
        let o = [0.0, 0.0];
        let gp = [ground, 0.0];
        let a = ahead(o, crank, theta0);
        // the coupler's far end, above the line from the crank pin to the follower's ground pin
        // (a Grashof crank-rocker closes at every crank angle, so the draw is not repeated)
        let Some(p) = circles(a, coupler, gp, follower) else { continue };
        break (o, gp, a, p);
    };
    let mats: Vec<Material> = (0..3).map(|_| material(rng, E_ALL)).collect();
    let mut bodies = vec![
        beam(rng, "crank", o, a, mats[0], FLEX_HELD),
        beam(rng, "coupler", a, p, mats[1], FLEX_HELD),
        beam(rng, "follower", gp, p, mats[2], FLEX_HELD),
    ];
    let joints = vec![
        Joint::GroundPin { body: "crank".into(), node: "start".into() },
        Joint::Pin { a: ("crank".into(), "end".into()), b: ("coupler".into(), "start".into()) },
        Joint::Pin { a: ("coupler".into(), "end".into()), b: ("follower".into(), "end".into()) },
        Joint::GroundPin { body: "follower".into(), node: "start".into() },
    ];
    let with_gravity = rng.chance(0.7);
    // the loop's inertia and weight seen from the crank, roughly (virtual work with the
    // crank pin moving at speed a·ω): the coupler moves with the crank pin, the follower
    // turns at about a/c of the crank's rate
    let r = bodies[0].length();
    let (mc, mf) = (bodies[1].mass(), bodies[2].mass());
    let j = bodies[0].inertia_about(o) + (mc + mf / 3.0) * r * r;
    let weight = if with_gravity { bodies[0].weight_moment_about(o) + (mc + 0.5 * mf) * G * r } else { 0.0 };
    let theta = rotation(rng);
    let mut loads = vec![driving_moment(rng, t, &mut bodies[0], "start", j, theta, hold_for(theta, weight))];
    if with_gravity {
        loads.push(gravity(rng, 0.2));
    }
    Draft::new(bodies, joints, loads, describe_rotation(theta))
}

fn frame(rng: &mut Rng, t: Time) -> Draft {
    let f = unit_function(rng, t.t_end, t.dt);
    let mut loads = Vec::new();
    let (bodies, joints, motion);
    if rng.chance(0.5) {
        // a V: two struts from the ground to a pinned apex, a point load at the apex
        let w = sig(rng.uniform(0.4, 1.2), 2);
        let h = sig(rng.uniform(0.3, 1.0), 2);
        let apex = [sig(w * rng.uniform(0.2, 0.8), 3), h];
        let ma = material(rng, E_ALL);
        let mb = if rng.chance(0.5) { ma } else { material(rng, E_ALL) };
        bodies =
            vec![beam(rng, "left", [0.0, 0.0], apex, ma, FLEX_HELD), beam(rng, "right", [w, 0.0], apex, mb, FLEX_HELD)];
        joints = vec![
            Joint::GroundPin { body: "left".into(), node: "start".into() },
            Joint::GroundPin { body: "right".into(), node: "start".into() },
            Joint::Pin { a: ("left".into(), "end".into()), b: ("right".into(), "end".into()) },
        ];
        // up to 60 % of the weaker strut's Euler load
        let euler =
            bodies.iter().map(|b| PI * PI * b.bending_stiffness() / b.length().powi(2)).fold(f64::INFINITY, f64::min);
        let kappa = rng.log_uniform(0.05, 0.6);
        let dir = rng.uniform(-PI, 0.0);
        loads.push(Load::Force {
            body: "left".into(),
            node: "end".into(),
            value: [sig(kappa * euler * dir.cos(), 3), sig(kappa * euler * dir.sin(), 3)],
            function: Some(f),
            scaled: None,
        });
        motion = format!("V, apex load up to {kappa:.2} of the Euler load");
    } else {
        // a portal: two clamped columns, a beam pinned across their tops, a side load
        let w = sig(rng.uniform(0.4, 1.2), 2);
        let h = sig(rng.uniform(0.3, 1.0), 2);
        let mc = material(rng, E_ALL);
        let mbeam = material(rng, E_ALL);
        let left = beam(rng, "left", [0.0, 0.0], [0.0, h], mc, FLEX_CLAMPED);
        let mut right = left.clone();
        right.name = "right".into();
        right.start = [w, 0.0];
        right.end = [w, h];
        right.elements = rng.int(10, 60);
        let top = beam(rng, "top", [0.0, h], [w, h], mbeam, FLEX_HELD);
        // side sway δ/h from 0.5 % to 20 % (two columns of stiffness 3EI/h³ each)
        let sway = rng.log_uniform(0.005, 0.2);
        let p = sway * h * 6.0 * left.bending_stiffness() / h.powi(3);
        loads.push(Load::Force {
            body: "top".into(),
            node: "start".into(),
            value: [sig(p, 3), 0.0],
            function: Some(f),
            scaled: None,
        });
        bodies = vec![left, right, top];
        joints = vec![
            Joint::Clamp { body: "left".into(), node: "start".into() },
            Joint::Clamp { body: "right".into(), node: "start".into() },
            Joint::Pin { a: ("left".into(), "end".into()), b: ("top".into(), "start".into()) },
            Joint::Pin { a: ("right".into(), "end".into()), b: ("top".into(), "end".into()) },
        ];
        motion = format!("portal, side sway up to {:.1} % of the height", 100.0 * sway);
    }
    if rng.chance(0.5) {
        loads.push(gravity(rng, 0.3));
    }
    Draft::new(bodies, joints, loads, motion)
}

fn five_bar(rng: &mut Rng, t: Time) -> Draft {
    let (o, a, p, b, gp) = loop {
        let d = sig(rng.uniform(0.3, 0.6), 2);
        let (a1, a2) = (sig(rng.uniform(0.1, 0.25), 2), sig(rng.uniform(0.1, 0.25), 2));
        let (b1, b2) = (sig(rng.uniform(0.4, 0.8), 2), sig(rng.uniform(0.4, 0.8), 2));
        let o = [0.0, 0.0];
        let gp = [d, 0.0];
        let a = ahead(o, a1, sig(rng.uniform(0.4 * PI, 0.8 * PI), 2));
        let b = ahead(gp, a2, sig(rng.uniform(0.2 * PI, 0.6 * PI), 2));
        // the two links meet above, not near a straight (locking) angle
        if let Some(p) = circles(a, b1, b, b2) {
            let ang = |u: [f64; 2], v: [f64; 2]| (v[1] - u[1]).atan2(v[0] - u[0]);
            let bend = (ang(a, p) - ang(b, p)).rem_euclid(2.0 * PI);
            if p[1] > a[1].max(b[1]) && (0.3 * PI..1.7 * PI).contains(&bend) {
                break (o, a, p, b, gp);
            }
        }
    };
    let mats: Vec<Material> = (0..4).map(|_| material(rng, E_ALL)).collect();
    let mut bodies = vec![
        beam(rng, "crank1", o, a, mats[0], FLEX_HELD),
        beam(rng, "link1", a, p, mats[1], FLEX_HELD),
        beam(rng, "link2", b, p, mats[2], FLEX_HELD),
        beam(rng, "crank2", gp, b, mats[3], FLEX_HELD),
    ];
    let joints = vec![
        Joint::GroundPin { body: "crank1".into(), node: "start".into() },
        Joint::Pin { a: ("crank1".into(), "end".into()), b: ("link1".into(), "start".into()) },
        Joint::Pin { a: ("link1".into(), "end".into()), b: ("link2".into(), "end".into()) },
        Joint::Pin { a: ("link2".into(), "start".into()), b: ("crank2".into(), "end".into()) },
        Joint::GroundPin { body: "crank2".into(), node: "start".into() },
    ];
    // each crank with the link it carries, the link moving with the crank pin
    let j1 = bodies[0].inertia_about(o) + bodies[1].mass() * bodies[0].length().powi(2);
    let j2 = bodies[3].inertia_about(gp) + bodies[2].mass() * bodies[3].length().powi(2);
    let theta = rng.log_uniform(0.05, 1.0);
    let mut loads = vec![driving_moment(rng, t, &mut bodies[0], "start", j1, theta, 0.0)];
    if rng.chance(0.5) {
        let theta2 = rng.log_uniform(0.05, 1.0);
        let mut second = driving_moment(rng, t, &mut bodies[3], "start", j2, theta2, 0.0);
        if let Load::Moment { scaled, .. } = &mut second {
            *scaled = if rng.chance(0.5) { None } else { Some(false) };
        }
        loads.push(second);
    }
    if rng.chance(0.6) {
        loads.push(gravity(rng, 0.3));
    }
    Draft::new(bodies, joints, loads, describe_rotation(theta))
}

/// The most a drive may turn at the top of the load range (λ = 1.5) in one step: 0.05 rad,
/// 125 steps a turn, what a user resolving a driven motion picks `dt` for.
fn rate_cap(t: Time) -> f64 {
    0.05 / (1.5 * t.dt)
}

/// The rate at which a spinning body stretches by 1 % at the top of the load range
/// (centrifugal strain ρ ω² L² / (2E) ≤ 0.01 at 1.5 ω): softer links spin slower.
fn stretch_cap(b: &Beam) -> f64 {
    (0.02 * b.youngs_modulus / b.density).sqrt() / b.length() / 1.5
}

/// A drive from rest to the rate `omega` (rad/s) reached at `ramp` s, then held: Simo and
/// Vu-Quoc's spin-up θ = (ω/T)(t²/2 + (T/2π)²(cos 2πt/T − 1)) (peak θ̈ = 2ω/T), or the
/// smooth-step polynomial θ = ω(t³/T² − t⁴/(2T³)) (peak θ̈ = 1.5 ω/T at T/2); both
/// θ(T) = ωT/2, then ω(t − T/2). The function and its peak angular acceleration.
fn spin_up(rng: &mut Rng, omega: f64, ramp: f64) -> (Func, f64) {
    let tail = Func::Polynomial(vec![-0.5 * omega * ramp, omega]);
    if rng.chance(0.5) {
        let a = omega / ramp * (ramp / (2.0 * PI)).powi(2);
        let start = Func::Sum(vec![
            Func::Polynomial(vec![0.0, 0.0, 0.5 * omega / ramp]),
            Func::Sine { amplitude: a, frequency: 1.0 / ramp, phase: 0.5 * PI },
            Func::Constant(-a),
        ]);
        (Func::Piecewise(vec![(Some(ramp), start), (None, tail)]), 2.0 * omega / ramp)
    } else {
        let start = Func::Polynomial(vec![0.0, 0.0, 0.0, omega / ramp.powi(2), -0.5 * omega / ramp.powi(3)]);
        (Func::Piecewise(vec![(Some(ramp), start), (None, tail)]), 1.5 * omega / ramp)
    }
}

/// A rest-to-rest move by `theta` rad in `duration` s, θ = Θ(10s³ − 15s⁴ + 6s⁵), s = t/T,
/// then held (peak rate 1.875 Θ/T, peak θ̈ = 10/√3 Θ/T²); or a swing θ = (Θ/2)(1 − cos 2πft)
/// with f = 1/duration (peak rate πfΘ, peak θ̈ = 2π²f²Θ). Both start at rest. The function,
/// its peak rate and its peak angular acceleration per unit Θ.
fn move_by(rng: &mut Rng, duration: f64) -> (Func, f64, f64) {
    let d = duration;
    if rng.chance(0.6) {
        let c = vec![0.0, 0.0, 0.0, 10.0 / d.powi(3), -15.0 / d.powi(4), 6.0 / d.powi(5)];
        (Func::Piecewise(vec![(Some(d), Func::Polynomial(c)), (None, Func::Constant(1.0))]), 1.875 / d, 5.78 / (d * d))
    } else {
        let f = 1.0 / d;
        let swing = Func::Sum(vec![Func::Constant(0.5), Func::Sine { amplitude: 0.5, frequency: f, phase: -0.5 * PI }]);
        (swing, PI * f, 2.0 * PI * PI * f * f)
    }
}

fn slider_crank(rng: &mut Rng, t: Time) -> Draft {
    let a = sig(rng.uniform(0.1, 0.3), 2);
    let b = sig(a * rng.uniform(2.0, 4.0), 2);
    let theta0 = sig(rng.uniform(0.0, 2.0 * PI), 2);
    let o = [0.0, 0.0];
    let p = ahead(o, a, theta0);
    // the rod's far end on the x axis, ahead of the crank
    let end = [p[0] + (b * b - p[1] * p[1]).sqrt(), 0.0];
    let stiff_crank = rng.chance(0.5);
    let mc = material(rng, if stiff_crank { (1e10, 1e11) } else { E_ALL });
    let mut crank = beam(rng, "crank", o, p, mc, FLEX_FREE);
    let mr = material(rng, E_ALL);
    let rod = beam(rng, "rod", p, end, mr, FLEX_HELD);
    let mut joints = vec![
        Joint::GroundPin { body: "crank".into(), node: "start".into() },
        Joint::Pin { a: ("crank".into(), "end".into()), b: ("rod".into(), "start".into()) },
        Joint::Slider { body: "rod".into(), node: "end".into(), direction: [1.0, 0.0] },
    ];
    let block = if rng.chance(0.7) { sig(rod.mass() * rng.log_uniform(0.2, 2.0), 3) } else { 0.0 };
    // the crank's inertia with the rod and block moving at about the crank pin's speed
    let j = crank.inertia_about(o) + (rod.mass() + block) * a * a;
    let mut loads = Vec::new();
    let motion = if rng.chance(0.3) {
        let theta = rotation(rng);
        loads.push(driving_moment(rng, t, &mut crank, "start", j, theta, 0.0));
        format!("by a moment, {}", describe_rotation(theta))
    } else {
        let cap = rate_cap(t);
        let omega = sig(rng.log_uniform(0.2 * cap, cap), 2);
        let ramp = sig(rng.uniform(0.2, 0.8) * t.t_end, 2);
        let (f, alpha) = spin_up(rng, omega, ramp);
        crank.carry_moment(1.5 * j * alpha, DRIVE_BEND);
        joints.push(Joint::DrivenAngle { body: "crank".into(), node: "start".into(), function: f });
        format!("by angle from rest to {omega} rad/s in {ramp} s")
    };
    if rng.chance(0.5) {
        loads.push(gravity(rng, 0.0));
    }
    let mut d = Draft::new(vec![crank, rod], joints, loads, motion);
    if block > 0.0 {
        d.masses.push(PointMass::new("rod", "end", block));
    }
    d
}

fn angle_arm(rng: &mut Rng, t: Time) -> Draft {
    let n = rng.int(1, 3);
    let specs: Vec<_> = (0..n)
        .map(|_| (sig(rng.uniform(0.2, 0.8), 2), sig(rng.uniform(-PI, PI), 2), material(rng, E_ALL), FLEX_FREE))
        .collect();
    let (mut bodies, mut joints) = chain(rng, [0.0, 0.0], &specs);
    joints.insert(0, Joint::GroundPin { body: "link1".into(), node: "start".into() });
    let total: f64 = bodies.iter().map(Beam::mass).sum();
    let tip = if rng.chance(0.5) { sig(total * rng.log_uniform(0.1, 1.0), 3) } else { 0.0 };
    let last = bodies.last().expect("a link").end;
    let j = bodies.iter().map(|b| b.inertia_about([0.0, 0.0])).sum::<f64>() + tip * last[0].hypot(last[1]).powi(2);
    let with_gravity = rng.chance(0.5);
    let duration = sig(rng.uniform(0.3, 0.8) * t.t_end, 2);
    let (unit, rate, accel) = move_by(rng, duration);
    // the move: from a tenth of a radian to a turn, no faster than a step resolves
    let sign = if rng.chance(0.5) { 1.0 } else { -1.0 };
    let theta = rng.log_uniform(0.1, 2.0 * PI).min(rate_cap(t) / rate);
    let theta = sig(sign * theta, 2);
    let weight = if with_gravity {
        bodies.iter().map(|b| b.mass() * G * b.centre()[0].hypot(b.centre()[1])).sum::<f64>()
            + tip * G * last[0].hypot(last[1])
    } else {
        0.0
    };
    bodies[0].carry_moment(1.5 * (j * accel * theta.abs() + weight), DRIVE_BEND);
    joints.push(Joint::DrivenAngle { body: "link1".into(), node: "start".into(), function: unit.scaled(theta) });
    let mut loads = Vec::new();
    if with_gravity {
        loads.push(gravity(rng, 0.0));
    }
    let what = if matches!(unit, Func::Sum(_)) { "swings" } else { "moves" };
    let mut d = Draft::new(bodies, joints, loads, format!("shoulder {what} by {theta} rad in {duration} s"));
    if tip > 0.0 {
        d.masses.push(PointMass::new(&format!("link{n}"), "end", tip));
    }
    d
}

fn welded_frame(rng: &mut Rng, t: Time) -> Draft {
    let h = sig(rng.uniform(0.3, 1.0), 2);
    let tee = rng.chance(0.5);
    let clamped = rng.chance(0.5);
    // the column from its foot to the corner: standing on a clamped foot, or hanging from a
    // pinned corner, released tilted
    let (foot, corner, up) = if clamped {
        ([0.0, 0.0], [0.0, h], 0.5 * PI)
    } else {
        let tilt = sig(rng.uniform(-0.6, 0.6), 2);
        (ahead([0.0, 0.0], h, -0.5 * PI + tilt), [0.0, 0.0], 0.5 * PI + tilt)
    };
    let mc = material(rng, E_ALL);
    let mut column = beam(rng, "column", foot, corner, mc, if clamped { FLEX_CLAMPED } else { FLEX_FREE });
    let arms: Vec<(String, f64)> = if tee {
        vec![("left".into(), up + 0.5 * PI), ("right".into(), up - 0.5 * PI)]
    } else {
        vec![("arm".into(), up + if rng.chance(0.5) { 0.5 * PI } else { -0.5 * PI })]
    };
    let mut bodies = Vec::new();
    let mut joints = vec![if clamped {
        Joint::Clamp { body: "column".into(), node: "start".into() }
    } else {
        Joint::GroundPin { body: "column".into(), node: "end".into() }
    }];
    let mut masses = Vec::new();
    let frame_mass = column.mass();
    for (name, angle) in &arms {
        let w = sig(rng.uniform(0.3, 1.0), 2);
        let ma = if rng.chance(0.5) { mc } else { material(rng, E_ALL) };
        let arm = beam(rng, name, corner, ahead(corner, w, *angle), ma, FLEX_CLAMPED);
        joints.push(Joint::Weld { a: ("column".into(), "end".into()), b: (name.clone(), "start".into()) });
        if rng.chance(0.7) {
            masses.push(PointMass::new(name, "end", sig((frame_mass + arm.mass()) * rng.log_uniform(0.1, 1.0), 3)));
        }
        bodies.push(arm);
    }
    let mut loads = Vec::new();
    let by_force = clamped && rng.chance(0.5);
    let motion = if by_force {
        // a force at the first arm's end, P w²/EI from 0.02 to 0.5
        let arm = &bodies[0];
        let kappa = rng.log_uniform(0.02, 0.5);
        let p = kappa * arm.bending_stiffness() / arm.length().powi(2);
        let dir = rng.uniform(0.0, 2.0 * PI);
        loads.push(Load::Force {
            body: arm.name.clone(),
            node: "end".into(),
            value: [sig(p * dir.cos(), 3), sig(p * dir.sin(), 3)],
            function: Some(unit_function(rng, t.t_end, t.dt)),
            scaled: None,
        });
        if rng.chance(0.5) {
            loads.push(gravity(rng, 0.0));
        }
        format!("{}, clamped, arm-end force P L²/EI up to {kappa:.2}", if tee { "T" } else { "L" })
    } else {
        loads.push(Load::Gravity { g: [0.0, -G], scaled: Some(true) });
        format!(
            "{}, {} under gravity",
            if tee { "T" } else { "L" },
            if clamped { "clamped" } else { "pinned at the corner" }
        )
    };
    // each arm sized for its end's load, the column for the arms' moments (M L/EI ≤ 0.3 at λ = 1.5)
    let end_load = |name: &str| -> f64 {
        let m: f64 = masses.iter().filter(|p: &&PointMass| p.body == name).map(|p| p.mass * G).sum();
        let f: f64 = loads
            .iter()
            .filter_map(|l| match l {
                Load::Force { body, value, .. } if body == name => Some(value[0].hypot(value[1])),
                _ => None,
            })
            .sum();
        m + f
    };
    let mut corner_moment = 0.0;
    for arm in &mut bodies {
        let m = 1.5 * end_load(&arm.name) * arm.length();
        arm.carry_moment(m, DRIVE_BEND);
        corner_moment += m;
    }
    if clamped {
        column.carry_moment(corner_moment, DRIVE_BEND);
    }
    bodies.insert(0, column);
    let mut d = Draft::new(bodies, joints, loads, motion);
    d.masses = masses;
    d
}

fn spinning_link(rng: &mut Rng, t: Time) -> Draft {
    let length = sig(rng.uniform(0.3, 1.5), 2);
    let angle = sig(rng.uniform(-PI, PI), 2);
    let m = material(rng, E_ALL);
    let mut b = beam(rng, "beam", [0.0, 0.0], ahead([0.0, 0.0], length, angle), m, FLEX_FREE);
    let tip = if rng.chance(0.4) { sig(b.mass() * rng.log_uniform(0.1, 1.0), 3) } else { 0.0 };
    let j = b.inertia_about([0.0, 0.0]) + tip * length * length;
    let joints_pin = Joint::GroundPin { body: "beam".into(), node: "start".into() };
    let cap = rate_cap(t).min(stretch_cap(&b));
    let mut loads = Vec::new();
    let (joints, motion) = if rng.chance(0.3) {
        // released spinning under gravity: over the top at every load when ½ J ω² exceeds
        // 1.5 × the largest rise of its weight (centre by L, tip by 2L), or swinging back
        let rise = G * length * (b.mass() + 2.0 * tip);
        let over = (3.0 * rise / j).sqrt();
        let omega = sig((over * rng.uniform(0.3, 2.0)).min(cap), 2);
        b.angular_velocity = Some(omega);
        loads.push(Load::Gravity { g: [0.0, -G], scaled: Some(true) });
        (vec![joints_pin], format!("released at {omega} rad/s under gravity"))
    } else {
        let omega = sig(rng.log_uniform(0.2 * cap, cap), 2);
        let ramp = sig(rng.uniform(0.3, 0.9) * t.t_end, 2);
        let (f, alpha) = spin_up(rng, omega, ramp);
        b.carry_moment(1.5 * j * alpha, DRIVE_BEND);
        if rng.chance(0.5) {
            loads.push(gravity(rng, 0.0));
        }
        let drive = Joint::DrivenAngle { body: "beam".into(), node: "start".into(), function: f };
        (vec![joints_pin, drive], format!("spun up by angle from rest to {omega} rad/s in {ramp} s"))
    };
    let mut d = Draft::new(vec![b], joints, loads, motion);
    if tip > 0.0 {
        d.masses.push(PointMass::new("beam", "end", tip));
    }
    d
}
