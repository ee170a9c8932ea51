//! `flexrom::simulate::statics` (load stepping with Newton and cut-back,
//! src/analysis/statics.rs) against closed forms, with mesh convergence, and its refusals.
//!
//! * Cantilever under a tip force P: `δ = P L³/(3EI)` (Timoshenko & Gere, *Mechanics of
//!   Materials*); cubic Hermite elements are nodally exact for it, so every mesh is within
//!   1e-6 (the load is small, δ/L = 1e-4: the geometric effect is ~1e-8).
//! * The elastica under a tip moment `M = π EI/L`: the bending moment is M everywhere, so
//!   the beam closes into a half circle of radius L/π, its tip at (0, 2L/π) (Euler; e.g.
//!   Bisshopp & Drucker, Q. Appl. Math. 3 (1945)). The elements interpolate the arc with
//!   an error falling as h² (φ²/12 in curvature for the element angle φ = π/n,
//!   src/physics/section.rs), so the tip's distance from (0, 2L/π) must drop at least
//!   threefold per doubling of the mesh and be below 1e-6 L at 32 elements (measured:
//!   1.3e-4, 7.5e-6, 6.9e-8 m at 8, 16, 32). The section is thin (I/A = 2.1e-8 m²) so that
//!   the model's axial–bending coupling, 3κ²I/A ≈ 6e-7, stays under the mesh error.
//! * A mechanism whose loads drive a free motion has no equilibrium: the error names it; a
//!   free motion without load makes the tangent singular: the error says so.

use flexrom::analysis::statics::StaticOptions;
use flexrom::model::Model;
use flexrom::simulate::statics;
use std::f64::consts::PI;

const L: f64 = 1.0;
const E: f64 = 2.1e11;

fn beam(elements: usize, area: f64, inertia: f64, joint: &str, load: &str) -> Model {
    let text = format!(
        r#"
        [time]
        t_end = 1.0
        dt = 0.01
        rho_inf = 1.0
        [[bodies]]
        name = "beam"
        start = [0.0, 0.0]
        angle = 0.0
        length = {L}
        elements = {elements}
        density = 7800.0
        area = {area}
        inertia = {inertia}
        youngs_modulus = {E}
        {joint}
        {load}
        [[probes]]
        name = "tip"
        body = "beam"
        node = "end"
        quantities = ["position", "curvature"]
        "#
    );
    Model::from_text(&text, "beam.toml").unwrap()
}

const CLAMP: &str = "[[joints]]\ntype = \"clamp\"\nbody = \"beam\"\nnode = \"start\"";

fn tip(model: &Model, steps: usize) -> [f64; 2] {
    let o = StaticOptions { steps, ..Default::default() };
    let (r, solution) = statics(model, &o).expect("an equilibrium");
    assert_eq!(r.t.len(), steps, "one row per load step");
    assert_eq!(solution.equilibrium().load_factor, 1.0, "the full load last");
    let xy = &r.probes[0].1;
    [xy[[steps - 1, 0]], xy[[steps - 1, 1]]]
}

#[test]
fn tip_force_deflects_a_cantilever_by_pl3_over_3ei() {
    let (a, i) = (1e-4, 1e-8 / 12.0);
    let p = 1e-4 * 3.0 * E * i / L.powi(3);
    let exact = p * L.powi(3) / (3.0 * E * i);
    for elements in [1, 2, 4, 8] {
        let load = format!("[[loads]]\ntype = \"force\"\nbody = \"beam\"\nnode = \"end\"\nvalue = [0.0, {}]", -p);
        let y = tip(&beam(elements, a, i, CLAMP, &load), 1)[1];
        let rel = (-y / exact - 1.0).abs();
        assert!(rel < 1e-6, "{elements} elements: δ = {} vs PL³/3EI = {exact} (rel {rel:.2e})", -y);
    }
}

#[test]
fn tip_moment_closes_the_elastica_into_a_half_circle() {
    // 100 mm × 0.5 mm: I = b h³/12, I/A = h²/12
    let (a, i) = (0.1 * 0.5e-3, 0.1 * 0.5e-3_f64.powi(3) / 12.0);
    let m = PI * E * i / L;
    let load =
        format!("[[loads]]\ntype = \"moment\"\nbody = \"beam\"\nnode = \"end\"\nfunction = {{ type = \"constant\", value = {m} }}");
    let exact = [0.0, 2.0 * L / PI];
    let mut last = f64::INFINITY;
    for elements in [8, 16, 32] {
        let t = tip(&beam(elements, a, i, CLAMP, &load), 4);
        let err = (t[0] - exact[0]).hypot(t[1] - exact[1]);
        assert!(err <= last / 3.0, "{elements} elements: tip {t:?}, {err:.2e} from (0, 2L/π); {last:.2e} at half");
        last = err;
    }
    assert!(last < 1e-6 * L, "32 elements: {last:.2e} m from (0, 2L/π)");
}

#[test]
fn a_free_motion_under_load_has_no_equilibrium_and_is_named() {
    let (a, i) = (1e-4, 1e-8 / 12.0);
    let pin = "[[joints]]\ntype = \"ground_pin\"\nbody = \"beam\"\nnode = \"start\"";
    let gravity = "[[loads]]\ntype = \"gravity\"\ng = [0.0, -9.81]";
    // a horizontal pendulum: gravity turns it about its pin
    let e = statics(&beam(4, a, i, pin, gravity), &StaticOptions::default()).unwrap_err().to_string();
    assert!(e.contains("no static equilibrium") && e.contains("body 'beam' rotates about (0, 0)"), "{e}");
    // a free beam under gravity: it falls
    let e = statics(&beam(4, a, i, "", gravity), &StaticOptions::default()).unwrap_err().to_string();
    assert!(e.contains("no static equilibrium") && e.contains("translates along (0.000, -1.000)"), "{e}");
    // a free beam pulled at both ends: in equilibrium with any rigid motion, its tangent
    // singular (a pinned beam pulled along its axis is not: the tension stiffens its turn)
    let pull = "[[loads]]\ntype = \"force\"\nbody = \"beam\"\nnode = \"end\"\nvalue = [100.0, 0.0]\n\
                [[loads]]\ntype = \"force\"\nbody = \"beam\"\nnode = \"start\"\nvalue = [-100.0, 0.0]";
    let e = statics(&beam(4, a, i, "", pull), &StaticOptions::default()).unwrap_err().to_string();
    assert!(e.contains("singular") && e.contains("body 'beam' translates and rotates freely"), "{e}");
}

/// A stiff clamped link carrying a soft one on a pin, at an angle under gravity and a
/// moment on the pinned link's slope (a model of the test zoo, `04-clamped-chain`): the
/// moment's Jacobian lifts the pinned link's swing off zero, so no mode is rigid to name; the error is Newton's failure, not an empty
/// list of free motions ("0 free motions: ").
#[test]
fn a_failure_without_a_rigid_mode_names_none() {
    let text = r#"
        [time]
        t_end = 0.5
        dt = 0.001
        rho_inf = 0.8
        [[bodies]]
        name = "link1"
        start = [0.0, 0.0]
        end = [0.21, 0.0]
        elements = 13
        density = 5300.0
        area = 3.43e-5
        inertia = 6.65e-11
        youngs_modulus = 7.3e10
        [[bodies]]
        name = "link2"
        start = [0.21, 0.0]
        end = [0.555, -0.134]
        elements = 13
        density = 1200.0
        area = 2.32e-4
        inertia = 3.52e-9
        youngs_modulus = 9.3e8
        [[joints]]
        type = "clamp"
        body = "link1"
        node = "start"
        [[joints]]
        type = "pin"
        a = { body = "link1", node = "end" }
        b = { body = "link2", node = "start" }
        [[loads]]
        type = "gravity"
        g = [0.0, -9.81]
        [[loads]]
        type = "moment"
        body = "link2"
        node = "start"
        function = { type = "exponential", amplitude = 0.0446, rate = 2.3 }
        "#;
    let model = Model::from_text(text, "chain.toml").unwrap();
    let e = statics(&model, &StaticOptions::default()).unwrap_err().to_string();
    assert!(!e.contains("0 free motions") && !e.contains("()"), "{e}");
    assert!(e.contains("no equilibrium found") || e.contains("link2"), "{e}");
}

#[test]
fn time_and_steps_outside_their_range_are_refused() {
    let (a, i) = (1e-4, 1e-8 / 12.0);
    let model = beam(2, a, i, CLAMP, "");
    // the library names the option by its key; the command line writes it as its flag
    let flag =
        |k: &str, v: Option<&str>| format!("--{}{}", k.replace('_', "-"), v.map_or(String::new(), |v| format!(" {v}")));
    let e = statics(&model, &StaticOptions { t: 1.5, ..Default::default() }).unwrap_err();
    assert!(e.to_string().starts_with("time = 1.5: outside"), "{e}");
    let e = e.render(&flag);
    assert!(e.contains("--time 1.5") && e.contains("[0, 1] s") && e.contains("beam.toml: time.t_end"), "{e}");
    let e = statics(&model, &StaticOptions { steps: 0, ..Default::default() }).unwrap_err().render(&flag);
    assert!(e.contains("--steps 0"), "{e}");
}
