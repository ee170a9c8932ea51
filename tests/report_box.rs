//! `run`'s report over a box of parameters: maps over the box in place of the figures
//! against the load scale (docs/cli.md, "The report"; src/report/report_maps.rs).
//!
//! Model: the two-link arm of tests/common (4 elements a link, Δt 5 ms, 1 s: a run in
//! milliseconds), its shoulder moment scaled by the load scale, its tip force by `payload`
//! and, for the three-parameter box, its gravity by `g`; six Sobol training points and 12
//! modes (no greedy loop: the report, not the basis, is under test).
//!
//! Checks (structural: which files a report has and what its summary and figures name):
//! - two parameters: `error_map`, `probe_error_map` and `speedup_map` (SVG and PNG) are
//!   written and summary.md shows each; none of the `*_vs_load` figures is (they plotted
//!   against a point's number); `error_map` has the rel_error and the error_estimate
//!   maps, the training runs' key, both parameters' names as axes; `speedup_map` marks 1×;
//! - three parameters: one row of maps per pair of parameters (3 rows: the PNG's height is
//!   three rows of maps, `map.rs`'s CELL_HEIGHT = 380 px under a 40 px title);
//! - one parameter: the figures against the load scale, now along that parameter (the SVG's
//!   x axis is named `payload`), under their `*_vs_load` names, and no map.

mod common;

use std::path::Path;
use std::process::Command;

const PIPELINE: &str = "model = \"arm.toml\"\nbasis = \"b.h5\"\nreport = \"r\"\n[train]\npoints = { count = 6 }\n[reduction]\nvariant = \"constraint-preserving\"\nmodes = { count = 12 }\n";

/// Writes the arm (gravity scaled by `g` when `scaled_gravity`) and the pipeline over
/// `parameters` into `dir`, runs `flexrom run` and returns the report folder.
fn report(dir: &Path, parameters: &str, scaled_gravity: bool) -> std::path::PathBuf {
    let mut arm = common::two_link_arm(4, 0.005);
    if scaled_gravity {
        arm = arm.replace("g = [0.0, -9.81]\nscaled = false", "g = [0.0, -9.81]\nscaled = \"g\"");
        assert!(arm.contains("scaled = \"g\""));
    }
    common::write(dir, "arm.toml", &arm);
    common::write(dir, "p.toml", &format!("{PIPELINE}[parameters]\n{parameters}"));
    let o = Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(["run", "-q", "p.toml"])
        .current_dir(dir)
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    dir.join("r")
}

fn png_size(path: &Path) -> (u32, u32) {
    let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let reader = dec.read_info().unwrap();
    (reader.info().width, reader.info().height)
}

#[test]
fn a_box_of_two_parameters_is_mapped() {
    let dir = tempfile::tempdir().unwrap();
    let r = report(dir.path(), "load_scale = [0.5, 1.5]\npayload = [0.5, 1.5]\n", false);
    let summary = std::fs::read_to_string(r.join("summary.md")).unwrap();
    for stem in ["error_map", "probe_error_map", "speedup_map", "singular_values", "error_by_time"] {
        assert!(r.join(format!("{stem}.svg")).is_file() && r.join(format!("{stem}.png")).is_file(), "{stem}");
        assert!(summary.contains(&format!("]({stem}.svg)")), "summary.md does not show {stem}: {summary}");
    }
    for stem in ["error_vs_load", "speedup_vs_load", "estimate_vs_load"] {
        assert!(!r.join(format!("{stem}.svg")).exists(), "{stem} written for a box");
        assert!(!summary.contains(stem), "{stem} named in summary.md");
    }
    let errors = std::fs::read_to_string(r.join("error_map.svg")).unwrap();
    for word in ["rel_error (full runs)", "error_estimate (no full run)", "training run", "load_scale", "payload"] {
        assert!(errors.contains(word), "error_map.svg lacks {word}");
    }
    assert!(std::fs::read_to_string(r.join("speedup_map.svg")).unwrap().contains("1×"));
    assert_eq!(png_size(&r.join("error_map.png")).1, 40 + 380, "one row of maps");
}

#[test]
fn a_box_of_three_parameters_maps_every_pair() {
    let dir = tempfile::tempdir().unwrap();
    let r = report(dir.path(), "load_scale = [0.5, 1.0]\npayload = [0.5, 1.5]\ng = [0.9, 1.1]\n", true);
    // (load_scale, payload), (load_scale, g), (payload, g)
    assert_eq!(png_size(&r.join("error_map.png")).1, 40 + 3 * 380, "three rows of maps");
    assert_eq!(png_size(&r.join("speedup_map.png")).1, 40 + 3 * 380);
    let svg = std::fs::read_to_string(r.join("error_map.svg")).unwrap();
    assert!(svg.matches("\ng\n").count() >= 2, "g names two axes");
}

#[test]
fn a_box_of_one_parameter_plots_along_it() {
    let dir = tempfile::tempdir().unwrap();
    let r = report(dir.path(), "payload = [0.5, 1.5]\n", false);
    for stem in ["error_vs_load", "speedup_vs_load", "estimate_vs_load"] {
        let svg = std::fs::read_to_string(r.join(format!("{stem}.svg"))).unwrap();
        assert!(svg.contains("\npayload\n") && svg.contains("training run"), "{stem}");
    }
    assert!(!r.join("error_map.svg").exists());
}
