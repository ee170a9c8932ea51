//! The pieces every zoo mechanism is made of: a reproducible random stream, materials and
//! cross-sections, time functions, and the TOML text of bodies, joints and loads.

use rand_chacha::rand_core::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;
use std::fmt::Write;

pub const G: f64 = 9.81;

/// The random stream of one model. ChaCha8 because its output for a seed is fixed across
/// versions of `rand_chacha` (the crate documents it as reproducible): a zoo seed names the
/// same models on every machine and every later build.
pub struct Rng(ChaCha8Rng);

impl Rng {
    /// The stream of attempt `attempt` at slot `slot` of the zoo with seed `seed`.
    pub fn new(seed: u64, slot: usize, attempt: usize) -> Self {
        let mut key = [0u8; 32];
        key[..8].copy_from_slice(&seed.to_le_bytes());
        key[8..16].copy_from_slice(&(slot as u64).to_le_bytes());
        key[16..24].copy_from_slice(&(attempt as u64).to_le_bytes());
        Rng(ChaCha8Rng::from_seed(key))
    }

    /// Uniform in [0, 1) from the top 53 bits.
    pub fn unit(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    pub fn uniform(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }

    /// Uniform in log: each decade of [a, b] equally likely.
    pub fn log_uniform(&mut self, a: f64, b: f64) -> f64 {
        (a.ln() + (b.ln() - a.ln()) * self.unit()).exp()
    }

    /// An integer in a..=b.
    pub fn int(&mut self, a: usize, b: usize) -> usize {
        a + ((self.unit() * (b - a + 1) as f64) as usize).min(b - a)
    }

    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    pub fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[self.int(0, items.len() - 1)]
    }
}

/// `x` to `digits` significant digits, as a user writes numbers in a model file.
pub fn sig(x: f64, digits: i32) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let k = 10f64.powi(digits - 1 - x.abs().log10().floor() as i32);
    let r = (x * k).round() / k;
    // print-stable: the shortest decimal of the rounded value
    format!("{r:.12e}").parse().unwrap_or(r)
}

/// A straight beam: geometry and section.
#[derive(Clone, Debug)]
pub struct Beam {
    pub name: String,
    pub start: [f64; 2],
    pub end: [f64; 2],
    pub elements: usize,
    pub density: f64,
    pub area: f64,
    pub inertia: f64,
    pub youngs_modulus: f64,
    /// the initial angular velocity about the start, rad/s (`angular_velocity`; None: at rest)
    pub angular_velocity: Option<f64>,
}

impl Beam {
    pub fn length(&self) -> f64 {
        (self.end[0] - self.start[0]).hypot(self.end[1] - self.start[1])
    }
    pub fn mass(&self) -> f64 {
        self.density * self.area * self.length()
    }
    pub fn centre(&self) -> [f64; 2] {
        [0.5 * (self.start[0] + self.end[0]), 0.5 * (self.start[1] + self.end[1])]
    }
    /// EI
    pub fn bending_stiffness(&self) -> f64 {
        self.youngs_modulus * self.inertia
    }
    /// The moment of inertia about `p` of the beam as a rigid rod.
    pub fn inertia_about(&self, p: [f64; 2]) -> f64 {
        let c = self.centre();
        let d2 = (c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2);
        self.mass() * (self.length().powi(2) / 12.0 + d2)
    }
    /// ‖moment of its weight about `p`‖ when the beam is where it starts.
    pub fn weight_moment_about(&self, p: [f64; 2]) -> f64 {
        self.mass() * G * (self.centre()[0] - p[0]).abs()
    }
    /// Thickens the section (both sides in proportion) until a moment `m` at one end bends
    /// the beam by at most `limit` rad (M L / EI ≤ limit): an engineer sizes a driven link
    /// for its motor's torque.
    pub fn carry_moment(&mut self, m: f64, limit: f64) {
        let bend = m.abs() * self.length() / self.bending_stiffness();
        if bend > limit {
            let s = (bend / limit).powf(0.25);
            self.area = sig(self.area * s * s, 3);
            self.inertia = sig(self.inertia * s.powi(4) * 1.001, 3);
        }
    }

    /// Slenderness L / r with r = √(I/A) the radius of gyration.
    pub fn slenderness(&self) -> f64 {
        self.length() / (self.inertia / self.area).sqrt()
    }
    /// ρ g L³ / (E r²): the bending a beam's own weight would cause, relative to its length
    /// (a cantilever's tip sags by 1/8 of it; ≪ 1 near-rigid, ≳ 1 very soft).
    pub fn flexibility(&self) -> f64 {
        self.density * G * self.length().powi(3) * self.area / self.bending_stiffness()
    }
}

/// How stiff a body is chosen: E over the brief's range, a density that goes with it, a
/// rectangular section from a slenderness, thickened where the body's own weight would
/// fold it beyond `max_flexibility` (no engineer builds a link that cannot carry itself).
#[derive(Clone, Copy, Debug)]
pub struct Material {
    pub youngs_modulus: f64,
    pub density: f64,
}

pub fn material(rng: &mut Rng, e_range: (f64, f64)) -> Material {
    let e = sig(rng.log_uniform(e_range.0, e_range.1), 2);
    // elastomers, polymers, wood and composites, light and heavy metals
    let density = if e < 1e8 {
        rng.uniform(1000.0, 1500.0)
    } else if e < 1e10 {
        rng.uniform(500.0, 2000.0)
    } else {
        rng.uniform(2700.0, 7850.0)
    };
    Material { youngs_modulus: e, density: sig(density, 2) }
}

/// A beam from `start` to `end` of `material`, slenderness drawn in [20, 400] (thickened to
/// keep the flexibility ≤ `max_flexibility`), rectangular section of aspect 0.5–4.
pub fn beam(rng: &mut Rng, name: &str, start: [f64; 2], end: [f64; 2], m: Material, max_flexibility: f64) -> Beam {
    let length = (end[0] - start[0]).hypot(end[1] - start[1]);
    let slenderness = rng.log_uniform(20.0, 400.0);
    let mut r = length / slenderness;
    let r_min = (m.density * G * length.powi(3) / (m.youngs_modulus * max_flexibility)).sqrt();
    r = r.max(r_min);
    let h = r * 12f64.sqrt();
    let b = h * rng.log_uniform(0.5, 4.0);
    let area = sig(b * h, 3);
    let inertia = sig(area * h * h / 12.0, 3);
    Beam {
        name: name.into(),
        start,
        end,
        elements: rng.int(10, 60),
        density: m.density,
        area,
        inertia,
        youngs_modulus: m.youngs_modulus,
        angular_velocity: None,
    }
}

/// The point at `length` from `p` in direction `angle`.
pub fn ahead(p: [f64; 2], length: f64, angle: f64) -> [f64; 2] {
    [p[0] + length * angle.cos(), p[1] + length * angle.sin()]
}

/// A time function of the model format (docs/model-format.md).
#[derive(Clone, Debug)]
pub enum Func {
    Constant(f64),
    Sine {
        amplitude: f64,
        frequency: f64,
        phase: f64,
    },
    Exponential {
        amplitude: f64,
        rate: f64,
    },
    Ramp {
        amplitude: f64,
        duration: f64,
    },
    Piecewise(Vec<(Option<f64>, Func)>),
    /// c0 + c1 t + c2 t² + …
    Polynomial(Vec<f64>),
    Sum(Vec<Func>),
}

impl Func {
    pub fn eval(&self, t: f64) -> f64 {
        match self {
            Func::Constant(v) => *v,
            Func::Sine { amplitude, frequency, phase } => amplitude * (2.0 * PI * frequency * t + phase).sin(),
            Func::Exponential { amplitude, rate } => amplitude * (rate * t).exp(),
            Func::Ramp { amplitude, duration } => amplitude * (t / duration).min(1.0),
            Func::Piecewise(pieces) => {
                pieces.iter().find(|(u, _)| u.is_none_or(|u| t <= u)).map_or(0.0, |(_, f)| f.eval(t))
            }
            Func::Polynomial(c) => c.iter().rev().fold(0.0, |acc, ci| acc * t + ci),
            Func::Sum(terms) => terms.iter().map(|f| f.eval(t)).sum(),
        }
    }

    /// The function times `k` (every amplitude scaled, rounded to 3 digits).
    pub fn scaled(&self, k: f64) -> Func {
        match self {
            Func::Constant(v) => Func::Constant(sig(v * k, 3)),
            Func::Sine { amplitude, frequency, phase } => {
                Func::Sine { amplitude: sig(amplitude * k, 3), frequency: *frequency, phase: *phase }
            }
            Func::Exponential { amplitude, rate } => {
                Func::Exponential { amplitude: sig(amplitude * k, 3), rate: *rate }
            }
            Func::Ramp { amplitude, duration } => Func::Ramp { amplitude: sig(amplitude * k, 3), duration: *duration },
            Func::Piecewise(p) => Func::Piecewise(p.iter().map(|(u, f)| (*u, f.scaled(k))).collect()),
            // not rounded: a polynomial piece must meet the next piece where it ends
            Func::Polynomial(c) => Func::Polynomial(c.iter().map(|ci| ci * k).collect()),
            Func::Sum(terms) => Func::Sum(terms.iter().map(|f| f.scaled(k)).collect()),
        }
    }

    /// max over [0, t_end] of |∫₀ᵗ∫₀ˢ f|: the rotation a unit moment of inertia makes
    /// under this moment history (trapezoidal sums on 2000 intervals).
    pub fn max_double_integral(&self, t_end: f64) -> f64 {
        let n = 2000;
        let h = t_end / n as f64;
        let (mut v, mut x, mut worst) = (0.0_f64, 0.0_f64, 0.0_f64);
        let mut f0 = self.eval(0.0);
        for i in 1..=n {
            let f1 = self.eval(i as f64 * h);
            let v1 = v + 0.5 * h * (f0 + f1);
            x += 0.5 * h * (v + v1);
            v = v1;
            f0 = f1;
            worst = worst.max(x.abs());
        }
        worst
    }

    /// max over [0, t_end] of |f|.
    pub fn peak(&self, t_end: f64) -> f64 {
        (0..=2000).map(|i| self.eval(t_end * i as f64 / 2000.0).abs()).fold(0.0, f64::max)
    }

    /// The inline TOML table.
    pub fn toml(&self) -> String {
        match self {
            Func::Constant(v) => format!("{{ type = \"constant\", value = {v:?} }}"),
            Func::Sine { amplitude, frequency, phase } if *phase == 0.0 => {
                format!("{{ type = \"sine\", amplitude = {amplitude:?}, frequency = {frequency:?} }}")
            }
            Func::Sine { amplitude, frequency, phase } => format!(
                "{{ type = \"sine\", amplitude = {amplitude:?}, frequency = {frequency:?}, phase = {phase:?} }}"
            ),
            Func::Exponential { amplitude, rate } => {
                format!("{{ type = \"exponential\", amplitude = {amplitude:?}, rate = {rate:?} }}")
            }
            Func::Ramp { amplitude, duration } => {
                format!("{{ type = \"ramp\", amplitude = {amplitude:?}, duration = {duration:?} }}")
            }
            Func::Piecewise(pieces) => {
                let p: Vec<String> = pieces
                    .iter()
                    .map(|(u, f)| match u {
                        Some(u) => format!("{{ until = {u:?}, function = {} }}", f.toml()),
                        None => format!("{{ function = {} }}", f.toml()),
                    })
                    .collect();
                format!("{{ type = \"piecewise\", pieces = [{}] }}", p.join(", "))
            }
            Func::Polynomial(c) => {
                let c: Vec<String> = c.iter().map(|x| format!("{x:?}")).collect();
                format!("{{ type = \"polynomial\", coefficients = [{}] }}", c.join(", "))
            }
            Func::Sum(terms) => {
                let t: Vec<String> = terms.iter().map(Func::toml).collect();
                format!("{{ type = \"sum\", terms = [{}] }}", t.join(", "))
            }
        }
    }

    /// Its kind, for the zoo's description.
    pub fn kind(&self) -> &'static str {
        match self {
            Func::Constant(_) => "constant",
            Func::Sine { .. } => "sine",
            Func::Exponential { .. } => "exponential",
            Func::Ramp { .. } => "ramp",
            Func::Piecewise(_) => "piecewise",
            Func::Polynomial(_) => "polynomial",
            Func::Sum(_) => "sum",
        }
    }
}

/// A time function of unit size (peak ≈ 1 over the run) of a kind drawn at random, with
/// frequencies a step of `dt` resolves by ≥ 20 steps a period.
pub fn unit_function(rng: &mut Rng, t_end: f64, dt: f64) -> Func {
    let f_max = (1.0 / (20.0 * dt)).min(4.0 / t_end);
    let sine = |rng: &mut Rng| Func::Sine {
        amplitude: 1.0,
        frequency: sig(rng.uniform(0.5 / t_end, f_max), 2),
        phase: if rng.chance(0.5) { 0.0 } else { sig(rng.uniform(0.0, PI), 2) },
    };
    match rng.int(0, 4) {
        0 => sine(rng),
        1 => Func::Ramp { amplitude: 1.0, duration: sig(rng.uniform(0.1, 0.8) * t_end, 2) },
        2 => {
            if rng.chance(0.7) {
                Func::Exponential { amplitude: 1.0, rate: -sig(rng.uniform(1.0, 10.0) / t_end, 2) }
            } else {
                // growing: starts at e^{-r t_end} so that it ends at 1
                let rate = sig(rng.uniform(0.5, 2.0) / t_end, 2);
                Func::Exponential { amplitude: sig((-rate * t_end).exp(), 3), rate }
            }
        }
        3 => Func::Constant(1.0),
        _ => {
            let until = sig(rng.uniform(0.2, 0.6) * t_end, 2);
            let first = match rng.int(0, 2) {
                0 => sine(rng),
                1 => Func::Ramp { amplitude: 1.0, duration: until },
                _ => Func::Constant(1.0),
            };
            // then a decay from about where the first piece ended, a hold, or release
            let rate = -sig(rng.uniform(2.0, 15.0) / t_end, 2);
            let then = match rng.int(0, 2) {
                0 => Func::Exponential { amplitude: sig((-rate * until).exp(), 3), rate },
                1 => Func::Constant(1.0),
                _ => Func::Constant(0.0),
            };
            Func::Piecewise(vec![(Some(until), first), (None, then)])
        }
    }
}

/// A load of the model file.
#[derive(Clone, Debug)]
pub enum Load {
    /// `scaled`: None leaves the key out (the default, false for gravity)
    Gravity {
        g: [f64; 2],
        scaled: Option<bool>,
    },
    Moment {
        body: String,
        node: String,
        function: Func,
        scaled: Option<bool>,
    },
    Force {
        body: String,
        node: String,
        value: [f64; 2],
        function: Option<Func>,
        scaled: Option<bool>,
    },
}

impl Load {
    /// Whether `--load-scale` multiplies it (the format's defaults applied).
    pub fn is_scaled(&self) -> bool {
        match self {
            Load::Gravity { scaled, .. } => scaled.unwrap_or(false),
            Load::Moment { scaled, .. } | Load::Force { scaled, .. } => scaled.unwrap_or(true),
        }
    }

    pub fn describe(&self) -> String {
        let s = if self.is_scaled() { "scaled" } else { "unscaled" };
        match self {
            Load::Gravity { .. } => format!("gravity ({s})"),
            Load::Moment { body, function, .. } => format!("{} moment on {body} ({s})", function.kind()),
            Load::Force { body, function, .. } => {
                format!("{} force on {body} ({s})", function.as_ref().map_or("constant", Func::kind))
            }
        }
    }
}

/// A joint of the model file.
#[derive(Clone, Debug)]
pub enum Joint {
    GroundPin {
        body: String,
        node: String,
    },
    Clamp {
        body: String,
        node: String,
    },
    Pin {
        a: (String, String),
        b: (String, String),
    },
    /// the node on the ground line through where it starts along `direction`
    Slider {
        body: String,
        node: String,
        direction: [f64; 2],
    },
    Weld {
        a: (String, String),
        b: (String, String),
    },
    /// the node's slope turned by `function` (rad), multiplied by the load scale
    DrivenAngle {
        body: String,
        node: String,
        function: Func,
    },
}

/// The time settings a user would write.
#[derive(Clone, Copy, Debug)]
pub struct Time {
    pub t_end: f64,
    pub dt: f64,
    pub rho_inf: f64,
}

/// t_end of 0.5–2 s, 100–400 steps, ρ∞ as in the shipped files or a little lower.
pub fn time(rng: &mut Rng) -> Time {
    let t_end = rng.pick(&[0.5, 0.8, 1.0, 1.0, 1.2, 1.5, 2.0]);
    let steps = rng.pick(&[100.0, 150.0, 200.0, 250.0, 300.0, 400.0]);
    // a round step: the largest of 1, 2, 2.5, 4, 5 × 10^k not above t_end / steps
    let raw: f64 = t_end / steps;
    let decade = 10f64.powf(raw.log10().floor());
    let mantissa = [5.0, 4.0, 2.5, 2.0, 1.0].into_iter().find(|m| m * decade <= raw * (1.0 + 1e-9)).unwrap_or(1.0);
    let dt = sig(mantissa * decade, 2);
    let rho_inf = rng.pick(&[1.0, 1.0, 0.9, 0.8, 0.8, 0.7]);
    Time { t_end, dt, rho_inf }
}

fn node_toml(n: &str) -> String {
    if n.parse::<usize>().is_ok() {
        n.to_string()
    } else {
        format!("\"{n}\"")
    }
}

/// A point mass of the model file (`[[masses]]`) at a node of a body.
#[derive(Clone, Debug)]
pub struct PointMass {
    pub body: String,
    pub node: String,
    /// kg
    pub mass: f64,
    /// kg m² about the node (`rotary_inertia`; None leaves the key out, the format's 0)
    pub rotary_inertia: Option<f64>,
}

impl PointMass {
    pub fn new(body: &str, node: &str, mass: f64) -> Self {
        PointMass { body: body.into(), node: node.into(), mass, rotary_inertia: None }
    }

    fn describe(&self) -> String {
        let j = self.rotary_inertia.map_or(String::new(), |j| format!(" (J {} kg m²)", sig(j, 2)));
        format!("mass {} kg{j} at {} {}", sig(self.mass, 2), self.body, self.node)
    }
}

/// A spring's second end: a node of a body, or a ground point.
#[derive(Clone, Debug)]
pub enum End {
    Node(String, String),
    Point([f64; 2]),
}

/// A spring-damper of the model file (`[[springs]]`): translational between node `a` and
/// `b`, or torsional between two nodes' slopes.
#[derive(Clone, Debug)]
pub struct Spring {
    pub name: String,
    pub torsional: bool,
    pub a: (String, String),
    pub b: End,
    /// N/m, or N m/rad (torsional)
    pub stiffness: f64,
    /// N s/m, or N m s/rad (torsional); 0 leaves the key out
    pub damping: f64,
    /// the free length, m (None: the initial distance)
    pub length: Option<f64>,
}

impl Spring {
    pub fn describe(&self) -> String {
        let (what, unit) = if self.torsional { ("torsional spring", "N m/rad") } else { ("spring", "N/m") };
        let damper = if self.damping > 0.0 { "-damper" } else { "" };
        format!("{what}{damper} {} {:e} {unit}", self.name, self.stiffness)
    }

    /// The `[[springs]]` table.
    fn toml(&self) -> String {
        let mut s = format!("\n[[springs]]\nname = {:?}\n", self.name);
        if self.torsional {
            s.push_str("type = \"torsional\"\n");
        }
        let _ = writeln!(s, "a = {{ body = {:?}, node = {} }}", self.a.0, node_toml(&self.a.1));
        match &self.b {
            End::Node(body, node) => {
                let _ = writeln!(s, "b = {{ body = {body:?}, node = {} }}", node_toml(node));
            }
            End::Point(p) => {
                let _ = writeln!(s, "b = {{ point = [{:?}, {:?}] }}", p[0], p[1]);
            }
        }
        let _ = writeln!(s, "stiffness = {:?}", self.stiffness);
        if self.damping > 0.0 {
            let _ = writeln!(s, "damping = {:?}", self.damping);
        }
        if let Some(l) = self.length {
            let _ = writeln!(s, "length = {l:?}");
        }
        s
    }
}

/// What a mechanism is made of: its bodies, joints, loads, point masses and spring-dampers.
pub struct Parts<'a> {
    pub bodies: &'a [Beam],
    pub joints: &'a [Joint],
    pub loads: &'a [Load],
    pub masses: &'a [PointMass],
    pub springs: &'a [Spring],
}

/// What the summary line says of a mechanism's point masses and springs, after its loads.
pub fn describe_extras(masses: &[PointMass], springs: &[Spring]) -> Vec<String> {
    masses.iter().map(PointMass::describe).chain(springs.iter().map(Spring::describe)).collect()
}

/// Where on its body a probe sits.
#[derive(Clone, Debug, PartialEq)]
pub enum Place {
    /// a fraction of the body's length (`at`)
    At(f64),
    /// a node (`node`: an index, `"start"` or `"end"`)
    Node(String),
}

/// A probe of the model file: a point of a body and what it records besides its position
/// (`quantities`: `"strain"`, `"curvature"`; empty leaves the key out, the format's default).
#[derive(Clone, Debug)]
pub struct Probe {
    pub name: String,
    pub body: String,
    pub place: Place,
    pub quantities: Vec<&'static str>,
}

impl Probe {
    /// The `[[probes]]` table.
    fn toml(&self) -> String {
        let place = match &self.place {
            Place::At(at) => format!("at = {at:?}"),
            Place::Node(n) => format!("node = {}", node_toml(n)),
        };
        let mut s = format!("\n[[probes]]\nname = {:?}\nbody = {:?}\n{place}\n", self.name, self.body);
        if !self.quantities.is_empty() {
            let q: Vec<String> = self.quantities.iter().map(|q| format!("{q:?}")).collect();
            let _ = writeln!(s, "quantities = [{}]", q.join(", "));
        }
        s
    }
}

/// The model file's text.
pub fn model_toml(
    description: &str,
    time: Time,
    damping: Option<(f64, f64)>,
    parts: &Parts,
    probes: &[Probe],
) -> String {
    let Parts { bodies, joints, loads, masses, springs } = *parts;
    let mut s = String::new();
    let _ = writeln!(s, "description = {description:?}\n");
    let _ = writeln!(s, "[time]\nt_end = {:?}\ndt = {:?}\nrho_inf = {:?}", time.t_end, time.dt, time.rho_inf);
    if let Some((a, b)) = damping {
        let _ = writeln!(s, "\n[damping]\nmass = {a:?}\nstiffness = {b:?}");
    }
    for b in bodies {
        let _ = writeln!(
            s,
            "\n[[bodies]]\nname = {:?}\nstart = [{:?}, {:?}]\nend = [{:?}, {:?}]\nelements = {}\ndensity = {:?}\narea = {:?}\ninertia = {:?}\nyoungs_modulus = {:?}",
            b.name, b.start[0], b.start[1], b.end[0], b.end[1], b.elements, b.density, b.area, b.inertia, b.youngs_modulus
        );
        if let Some(w) = b.angular_velocity {
            let _ = writeln!(s, "angular_velocity = {w:?}");
        }
    }
    for j in joints {
        match j {
            Joint::GroundPin { body, node } => {
                let _ = writeln!(s, "\n[[joints]]\ntype = \"ground_pin\"\nbody = {body:?}\nnode = {}", node_toml(node));
            }
            Joint::Clamp { body, node } => {
                let _ = writeln!(s, "\n[[joints]]\ntype = \"clamp\"\nbody = {body:?}\nnode = {}", node_toml(node));
            }
            Joint::Pin { a, b } | Joint::Weld { a, b } => {
                let _ = writeln!(
                    s,
                    "\n[[joints]]\ntype = \"{}\"\na = {{ body = {:?}, node = {} }}\nb = {{ body = {:?}, node = {} }}",
                    if matches!(j, Joint::Pin { .. }) { "pin" } else { "weld" },
                    a.0,
                    node_toml(&a.1),
                    b.0,
                    node_toml(&b.1)
                );
            }
            Joint::Slider { body, node, direction } => {
                let _ = writeln!(
                    s,
                    "\n[[joints]]\ntype = \"slider\"\nbody = {body:?}\nnode = {}\ndirection = [{:?}, {:?}]",
                    node_toml(node),
                    direction[0],
                    direction[1]
                );
            }
            Joint::DrivenAngle { body, node, function } => {
                let _ = writeln!(
                    s,
                    "\n[[joints]]\ntype = \"driven_angle\"\nbody = {body:?}\nnode = {}\nscaled = true\nfunction = {}",
                    node_toml(node),
                    function.toml()
                );
            }
        }
    }
    let scaled = |s: &Option<bool>| s.map_or(String::new(), |v| format!("\nscaled = {v}"));
    for l in loads {
        match l {
            Load::Gravity { g, scaled: sc } => {
                let _ = writeln!(s, "\n[[loads]]\ntype = \"gravity\"\ng = [{:?}, {:?}]{}", g[0], g[1], scaled(sc));
            }
            Load::Moment { body, node, function, scaled: sc } => {
                let _ = writeln!(
                    s,
                    "\n[[loads]]\ntype = \"moment\"\nbody = {body:?}\nnode = {}{}\nfunction = {}",
                    node_toml(node),
                    scaled(sc),
                    function.toml()
                );
            }
            Load::Force { body, node, value, function, scaled: sc } => {
                let _ = writeln!(
                    s,
                    "\n[[loads]]\ntype = \"force\"\nbody = {body:?}\nnode = {}\nvalue = [{:?}, {:?}]{}{}",
                    node_toml(node),
                    value[0],
                    value[1],
                    scaled(sc),
                    function.as_ref().map_or(String::new(), |f| format!("\nfunction = {}", f.toml()))
                );
            }
        }
    }
    for m in masses {
        let _ = writeln!(s, "\n[[masses]]\nbody = {:?}\nnode = {}\nmass = {:?}", m.body, node_toml(&m.node), m.mass);
        if let Some(j) = m.rotary_inertia {
            let _ = writeln!(s, "rotary_inertia = {j:?}");
        }
    }
    for sp in springs {
        s.push_str(&sp.toml());
    }
    for p in probes {
        s.push_str(&p.toml());
    }
    s
}
