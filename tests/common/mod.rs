//! Code shared by the integration tests.
#![allow(dead_code)]

use flexrom::model::Model;

/// A model from TOML text (the path is only used in messages).
pub fn model(text: &str) -> Model {
    Model::from_text(text, "test.toml").expect("valid test model")
}

/// A straight horizontal steel-density cantilever along +x, clamped at the origin, with a
/// tip force `(0, −P)` (scaled by the load scale) and no gravity.
pub fn cantilever(elements: usize, length: f64, e: f64, area: f64, inertia: f64, p: f64) -> Model {
    cantilever_with_density(elements, length, e, area, inertia, 7800.0, p)
}

pub fn cantilever_with_density(
    elements: usize,
    length: f64,
    e: f64,
    area: f64,
    inertia: f64,
    density: f64,
    p: f64,
) -> Model {
    model(&format!(
        r#"
        [time]
        t_end = 1.0
        dt = 0.01
        rho_inf = 1.0
        [[bodies]]
        name = "beam"
        start = [0.0, 0.0]
        angle = 0.0
        length = {length}
        elements = {elements}
        density = {density}
        area = {area}
        inertia = {inertia}
        youngs_modulus = {e}
        [[joints]]
        type = "clamp"
        body = "beam"
        node = "start"
        [[loads]]
        type = "force"
        body = "beam"
        node = "end"
        value = [0.0, {minus_p}]
        [[probes]]
        name = "tip"
        body = "beam"
        node = "end"
        "#,
        minus_p = -p
    ))
}

/// `flexrom validate p.toml --json --no-dense` in `dir` (a pipeline over a box: the box's
/// four random held-out points), each point checked within `tolerance`, covered by its error
/// estimate and inside the box; returns the points' JSON objects.
pub fn held_out_points_within(dir: &std::path::Path, tolerance: f64) -> Vec<serde_json::Value> {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(["validate", "p.toml", "--json", "--no-dense"])
        .current_dir(dir)
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let vs: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(vs.len(), 4);
    for v in &vs {
        let (e, est) = (v["rel_error"].as_f64().unwrap(), v["error_estimate"].as_f64().unwrap());
        assert!(e <= tolerance && est >= e, "{v}");
        assert_eq!(v["extrapolated"], false, "{v}");
    }
    vs
}

/// A two-link aluminium arm (links of 0.5 m pinned together, the upper on a ground pin)
/// swung by a shoulder moment `2.5 sin(4π t)` N·m scaled by the load scale, under gravity,
/// with a tip force `(0, −2)` N scaled by the parameter `payload` and a probe `tip`;
/// `elements` a link, time step `dt`, 1 s.
pub fn two_link_arm(elements: usize, dt: f64) -> String {
    let link = |name: &str, x0: f64| {
        format!("[[bodies]]\nname = \"{name}\"\nstart = [{x0:?}, 0.0]\nangle = 0.0\nlength = 0.5\nelements = {elements}\ndensity = 2700.0\narea = 1.0e-4\ninertia = 8.3e-10\nyoungs_modulus = 7.0e10\n")
    };
    TWO_LINK_ARM.replace("LINKS", &(link("upper", 0.0) + &link("lower", 0.5))).replace("DT", &dt.to_string())
}

const TWO_LINK_ARM: &str = r#"
description = "Two aluminium links pinned together, swung by a shoulder moment, a payload at the tip"
[time]
t_end = 1.0
dt = DT
rho_inf = 0.9
LINKS[[joints]]
type = "ground_pin"
body = "upper"
node = "start"
[[joints]]
type = "pin"
a = { body = "upper", node = "end" }
b = { body = "lower", node = "start" }
[[loads]]
type = "gravity"
g = [0.0, -9.81]
scaled = false
[[loads]]
type = "moment"
body = "upper"
node = "start"
function = { type = "sine", amplitude = 2.5, frequency = 2.0 }
scaled = true
[[loads]]
type = "force"
body = "lower"
node = "end"
value = [0.0, -2.0]
scaled = "payload"
[[probes]]
name = "tip"
body = "lower"
node = "end"
"#;

/// Writes `text` to `dir/name` and returns the path.
pub fn write(dir: &std::path::Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// `flexrom modes` of a model text: its lowest frequency, Hz.
pub fn lowest_frequency(text: &str) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "m.toml", text);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(["modes", path.to_str().unwrap(), "--count", "1", "--json", "-q"])
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    v["frequencies"][0].as_f64().expect("a frequency")
}
