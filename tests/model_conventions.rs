//! The units and sign conventions of docs/model-format.md's key table hold in the program.
//! tests/docs.rs checks that every schema key has a row; this file checks that every row
//! names a unit (or "–" for a pure number) and that the conventions users trip over are what
//! the code does:
//!
//! * `frequency` is in Hz and `phase` in rad: sin(2π f t + φ) with f = 1 Hz is 1 at
//!   t = 0.25 s, and with φ = π/2 it is 1 at t = 0 (exact values of the sine);
//! * a negative `rate` decays: exp(−16.32 · 0.1) = 0.1955… < 1;
//! * `angle` is counter-clockwise from +x in rad: a beam of length 1 at angle π/2 has its
//!   end at (0, 1) at t = 0;
//! * `g = [0, -9.81]` pulls down (y up): a pinned horizontal beam's tip moves to y < 0;
//! * a positive moment turns counter-clockwise: a cantilever along +x, clamped at its
//!   start, with a positive constant moment at its end, bends its tip to y > 0 (and a
//!   negative one to y < 0).
//!
//! Each check first finds the convention's words in the key's row, so the document and the
//! program are tied together.

use std::path::Path;
use std::process::Command;

fn table() -> String {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/model-format.md")).unwrap();
    text[text.find("## Every key").expect("no '## Every key' section")..].to_string()
}

/// The cells of the key table's row for `key` (several rows may share a key, e.g. `value`;
/// the one whose `where` cell contains `place`).
fn row(key: &str, place: &str) -> Vec<String> {
    table()
        .lines()
        .filter(|l| l.starts_with(&format!("| `{key}` |")))
        .map(|l| l.trim_matches('|').split(" | ").map(|c| c.trim().to_string()).collect::<Vec<_>>())
        .find(|cells| cells[1].contains(place))
        .unwrap_or_else(|| panic!("docs/model-format.md: no row for `{key}` in {place}"))
}

#[test]
fn every_row_names_a_unit_or_none() {
    let t = table();
    let rows: Vec<&str> = t.lines().filter(|l| l.starts_with("| `")).collect();
    assert!(rows.len() >= 30, "only {} key rows", rows.len());
    for l in rows {
        let cells: Vec<&str> = l.trim_matches('|').split(" | ").map(str::trim).collect();
        assert!(cells.len() >= 4, "row without unit and meaning: {l}");
        assert!(!cells[2].is_empty(), "row without a unit (write – for a pure number): {l}");
        assert!(!cells[3].is_empty(), "row without a meaning: {l}");
    }
}

fn eval(f: &str, t: f64) -> f64 {
    let f: flexrom::physics::time_function::TimeFunction = toml::from_str(f).unwrap();
    f.eval(t)
}

#[test]
fn time_function_units_and_signs() {
    assert_eq!(row("frequency", "sine")[2], "Hz");
    assert_eq!(row("phase", "sine")[2], "rad");
    assert!((eval("type = \"sine\"\namplitude = 1.0\nfrequency = 1.0", 0.25) - 1.0).abs() < 1e-12);
    let half_pi = std::f64::consts::FRAC_PI_2;
    assert!(
        (eval(&format!("type = \"sine\"\namplitude = 1.0\nfrequency = 1.0\nphase = {half_pi}"), 0.0) - 1.0).abs()
            < 1e-12
    );

    let rate = row("rate", "exponential");
    assert_eq!(rate[2], "1/s");
    assert!(rate[3].contains("negative decays"), "{rate:?}");
    let decayed = eval("type = \"exponential\"\namplitude = 1.0\nrate = -16.32", 0.1);
    assert!((decayed - (-1.632_f64).exp()).abs() < 1e-15 && decayed < 1.0);
}

/// A one-body model: `extra` holds its joints, loads and time settings.
fn run_tip(dir: &Path, name: &str, body: &str, extra: &str) -> (f64, f64, f64, f64) {
    let model = dir.join(format!("{name}.toml"));
    std::fs::write(
        &model,
        format!(
            "[time]\nt_end = 0.02\ndt = 0.001\nrho_inf = 0.8\n\n[[bodies]]\nname = \"beam\"\nstart = [0.0, 0.0]\n{body}\nelements = 4\ndensity = 7800.0\narea = 1e-4\ninertia = 1e-9\nyoungs_modulus = 2e11\n\n{extra}\n[[probes]]\nname = \"tip\"\nbody = \"beam\"\nnode = \"end\"\n"
        ),
    )
    .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args([
            "-q",
            "simulate",
            model.to_str().unwrap(),
            "-o",
            dir.join(format!("{name}.h5")).to_str().unwrap(),
            "--json",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{name}: {}", String::from_utf8_lossy(&o.stderr));
    let rows: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    let (first, last) = (&rows[0], &rows[rows.len() - 1]);
    let f = |r: &serde_json::Value, k: &str| r[k].as_f64().unwrap();
    (f(first, "tip_x"), f(first, "tip_y"), f(last, "tip_x"), f(last, "tip_y"))
}

#[test]
fn geometry_gravity_and_moment_signs() {
    let d = tempfile::tempdir().unwrap();
    let angle = row("angle", "bodies");
    assert_eq!(angle[2], "rad");
    assert!(angle[3].contains("counter-clockwise from +x"), "{angle:?}");
    let (x0, y0, _, _) = run_tip(
        d.path(),
        "up",
        &format!("angle = {}\nlength = 1.0", std::f64::consts::FRAC_PI_2),
        "[[joints]]\ntype = \"clamp\"\nbody = \"beam\"\nnode = \"start\"\n",
    );
    assert!(x0.abs() < 1e-12 && (y0 - 1.0).abs() < 1e-12, "end at ({x0}, {y0})");

    let g = row("g", "gravity");
    assert_eq!(g[2], "m/s²");
    assert!(g[3].contains("y up"), "{g:?}");
    let (_, y0, _, y1) = run_tip(
        d.path(),
        "fall",
        "angle = 0.0\nlength = 1.0",
        "[[joints]]\ntype = \"ground_pin\"\nbody = \"beam\"\nnode = \"start\"\n\n[[loads]]\ntype = \"gravity\"\ng = [0.0, -9.81]\n",
    );
    assert!(y0 == 0.0 && y1 < -1e-4, "gravity [0, -9.81]: tip y {y0} → {y1}");

    let amp = row("amplitude", "functions");
    assert!(amp[2].contains("N·m"), "{amp:?}");
    assert!(amp[3].contains("positive = counter-clockwise"), "{amp:?}");
    for (sign, name) in [(1.0, "ccw"), (-1.0, "cw")] {
        let (_, _, _, y1) = run_tip(
            d.path(),
            name,
            "angle = 0.0\nlength = 1.0",
            &format!("[[joints]]\ntype = \"clamp\"\nbody = \"beam\"\nnode = \"start\"\n\n[[loads]]\ntype = \"moment\"\nbody = \"beam\"\nnode = \"end\"\nfunction = {{ type = \"constant\", value = {} }}\n", sign * 50.0),
        );
        assert!(sign * y1 > 1e-6, "moment {}: tip y {y1}", sign * 50.0);
    }
}
