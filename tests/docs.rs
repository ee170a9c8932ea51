//! The documentation tells the truth about the repository.
//!
//! Checks, with where each expected value comes from:
//! - `relative_links_resolve`: every relative Markdown link `[..](path)` in README.md and
//!   docs/*.md names a file or folder that exists in the repository (links to web
//!   addresses and in-page anchors are left alone).
//! - `every_model_key_has_a_unit`: every key of the model-file schema (the field names in
//!   src/model/schema.rs and src/physics/time_function.rs, read from the source so a new
//!   key cannot be forgotten) has a row `| \`key\` |` in the key table of
//!   docs/model-format.md.
//! - `readme_pipeline_snippet_is_the_shipped_file`: each key line of the README's pipeline
//!   snippet is a line of pipelines/double_pendulum.toml, so the tutorial shows what runs.
//! - `readme_tutorial_runs_as_written`: the commands between `<!-- tutorial:begin -->` and
//!   `<!-- tutorial:end -->` run, as written (`target/release/flexrom`, which `make run`
//!   builds: the tutorial must not assume `flexrom` on PATH; here the built binary), in a
//!   copy of the tutorial's model and pipeline files; then the README's Python block runs
//!   there and writes its figure when python3 has h5py, numpy and matplotlib (otherwise it
//!   says it skipped). Every command must exit 0 and the files the README names must exist.
//! - `slider_crank_tutorial_runs_as_written`: the same for docs/tutorial-slider-crank.md's
//!   blocks (the slider-crank model and its tutorial pipeline); its Python block must print
//!   the full run's peak midpoint deflection, 3.88 mm (docs/slider-crank.md's converged value).
//! - `readme_is_at_most_300_lines`: the README stays a page a new user reads whole.
//! - `the_files_speak_of_the_project_not_of_its_making`: no development bookkeeping (the
//!   numbered steps and tickets of the work, its sittings, whose measurement it was) in the
//!   README, CHANGELOG.md, docs/, pipelines/, src/, scripts/, benches/, examples/ or tests/:
//!   history is in git and CHANGELOG.md, by commit and date.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn markdown_files() -> Vec<PathBuf> {
    let mut files = vec![root().join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    files
}

/// The targets of inline Markdown links `](target)` in `text`, outside code blocks.
fn link_targets(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_code = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code {
            continue;
        }
        let mut rest = line;
        while let Some(i) = rest.find("](") {
            let after = &rest[i + 2..];
            let Some(j) = after.find(')') else { break };
            out.push(after[..j].to_string());
            rest = &after[j..];
        }
    }
    out
}

#[test]
fn relative_links_resolve() {
    let mut broken = Vec::new();
    let mut checked = 0;
    for file in markdown_files() {
        let text = std::fs::read_to_string(&file).unwrap();
        for target in link_targets(&text) {
            let target = target.split_whitespace().next().unwrap_or("").to_string();
            if target.is_empty() || target.starts_with('#') || target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let path = target.split('#').next().unwrap();
            checked += 1;
            if !file.parent().unwrap().join(path).exists() {
                broken.push(format!("{}: {target}", file.strip_prefix(root()).unwrap().display()));
            }
        }
    }
    assert!(checked > 20, "only {checked} relative links found: is the link parser broken?");
    assert!(broken.is_empty(), "broken relative links:\n{}", broken.join("\n"));
}

/// Field names of the serde structs and enum variants in a Rust source file: lines of the
/// form `name: Type,` or `pub name: Type,` inside a struct or a variant's braces.
fn schema_keys(source: &str) -> Vec<String> {
    let mut keys = Vec::new();
    for line in source.lines() {
        let l = line.trim();
        if l.starts_with("//") || l.starts_with('#') || l.contains("fn ") || l.contains("let ") || l.contains("=>") {
            continue;
        }
        // one-line variants such as `Exponential { amplitude: f64, rate: f64 },` hold several
        for part in l.split(['{', ',']) {
            let part = part.trim();
            let part = part.strip_prefix("pub ").unwrap_or(part);
            let Some((name, _ty)) = part.split_once(": ") else { continue };
            if !name.is_empty() && name.chars().all(|c| c.is_ascii_lowercase() || c == '_') {
                keys.push(name.to_string());
            }
        }
    }
    keys.sort();
    keys.dedup();
    keys
}

#[test]
fn every_model_key_has_a_unit() {
    let table = std::fs::read_to_string(root().join("docs/model-format.md")).unwrap();
    let table = &table[table.find("## Every key").expect("docs/model-format.md: no '## Every key' table")..];
    let mut keys = schema_keys(&std::fs::read_to_string(root().join("src/model/schema.rs")).unwrap());
    // TimeFunction's fields, up to its `impl` (the rest is code, not schema)
    let tf = std::fs::read_to_string(root().join("src/physics/time_function.rs")).unwrap();
    keys.extend(schema_keys(&tf[..tf.find("impl TimeFunction").unwrap()]));
    // the schema's own top-level structure: tables, not keys with a unit
    let tables = ["time", "damping", "bodies", "joints", "loads", "probes"];
    keys.retain(|k| !tables.contains(&k.as_str()));
    assert!(keys.len() >= 30, "only {} keys read from the schema: {keys:?}", keys.len());
    for must in ["youngs_modulus", "rate", "phase", "frequency", "g", "scaled", "until"] {
        assert!(keys.iter().any(|k| k == must), "the schema reader missed `{must}`: {keys:?}");
    }
    let missing: Vec<&String> = keys.iter().filter(|k| !table.contains(&format!("| `{k}` |"))).collect();
    assert!(missing.is_empty(), "model keys without a row in docs/model-format.md's key table: {missing:?}");
}

/// The fenced block that follows the marker `marker` in the Markdown file `page`.
fn page_block(page: &str, marker: &str) -> String {
    let text = std::fs::read_to_string(root().join(page)).unwrap();
    let at = text.find(marker).unwrap_or_else(|| panic!("{page} has no {marker}"));
    let rest = &text[at..];
    let open = rest.find("```").unwrap();
    let body = &rest[open..];
    let body = &body[body.find('\n').unwrap() + 1..];
    body[..body.find("```").unwrap()].to_string()
}

#[test]
fn readme_pipeline_snippet_is_the_shipped_file() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let at = readme.find("**2. A pipeline**").expect("README.md: no tutorial step 2");
    let rest = &readme[at..];
    let body = &rest[rest.find("```toml").unwrap() + 7..];
    let body = &body[..body.find("```").unwrap()];
    let shipped = std::fs::read_to_string(root().join("pipelines/double_pendulum.toml")).unwrap();
    let mut n = 0;
    for line in body.lines().map(str::trim).filter(|l| !l.is_empty()) {
        n += 1;
        assert!(shipped.lines().any(|s| s.trim() == line), "README pipeline line not in the shipped file: {line}");
    }
    assert!(n >= 5, "the README's pipeline snippet has only {n} lines");
}

fn copy_tutorial(dir: &Path, files: &[&str]) {
    for f in files {
        std::fs::create_dir_all(dir.join(f).parent().unwrap()).unwrap();
        std::fs::copy(root().join(f), dir.join(f)).unwrap();
    }
}

/// Runs the shell block after `<!-- tutorial:begin -->` of `page` in `dir` (each line starts
/// with the built binary, and must exit 0); the number of commands.
fn run_tutorial_commands(page: &str, dir: &Path) -> usize {
    let commands = page_block(page, "<!-- tutorial:begin -->");
    let mut n = 0;
    for line in commands.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
        let words: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(words[0], "target/release/flexrom", "tutorial line does not start with the built binary: {line}");
        let out = Command::new(env!("CARGO_BIN_EXE_flexrom"))
            .args(&words[1..])
            .current_dir(dir)
            .env("HDF5_USE_FILE_LOCKING", "FALSE")
            .output()
            .unwrap();
        assert!(out.status.success(), "`{line}` failed ({}):\n{}", out.status, String::from_utf8_lossy(&out.stderr));
        n += 1;
    }
    n
}

/// Runs the Python block after `<!-- tutorial:python -->` of `page` in `dir`: `Some(stdout)`,
/// or `None` (said) where python3 lacks h5py, numpy or matplotlib.
fn run_tutorial_python(page: &str, dir: &Path) -> Option<String> {
    let python = page_block(page, "<!-- tutorial:python -->");
    let has = Command::new("python3")
        .args(["-c", "import h5py, numpy, matplotlib"])
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    if !has {
        eprintln!("skipped: the Python block of {page} (python3 with h5py, numpy and matplotlib not found)");
        return None;
    }
    let out = Command::new("python3")
        .args(["-c", &python])
        .current_dir(dir)
        .env("MPLBACKEND", "Agg")
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    assert!(out.status.success(), "the Python block of {page} failed:\n{}", String::from_utf8_lossy(&out.stderr));
    Some(String::from_utf8_lossy(&out.stdout).into_owned())
}

#[test]
fn readme_tutorial_runs_as_written() {
    let dir = tempfile::tempdir().unwrap();
    copy_tutorial(dir.path(), &["data/models/double_pendulum.toml", "pipelines/double_pendulum.toml"]);
    let n = run_tutorial_commands("README.md", dir.path());
    assert!(n >= 4, "the tutorial has only {n} commands");
    for f in ["data/bases/double_pendulum.h5", "out/dp_1.3.h5", "out/dp_sweep.h5"] {
        assert!(dir.path().join(f).is_file(), "the tutorial did not write {f}");
    }
    if run_tutorial_python("README.md", dir.path()).is_some() {
        assert!(dir.path().join("out/dp.png").is_file(), "the README's Python block wrote no figure");
    }
}

/// docs/tutorial-slider-crank.md's commands run as written, and its Python block prints
/// the two runs' peak torque and midpoint deflection: the full run's peak deflection is the
/// benchmark's 3.88 mm (docs/slider-crank.md, converged in Δt and mesh to 3.88 ± 0.01 mm).
#[test]
fn slider_crank_tutorial_runs_as_written() {
    let page = "docs/tutorial-slider-crank.md";
    let dir = tempfile::tempdir().unwrap();
    copy_tutorial(dir.path(), &["data/models/slider_crank.toml", "pipelines/tutorial_slider_crank.toml"]);
    let n = run_tutorial_commands(page, dir.path());
    assert!(n >= 4, "the slider-crank tutorial has only {n} commands");
    for f in ["data/bases/tutorial_slider_crank.h5", "out/sc_full.h5", "out/sc_1.3.h5"] {
        assert!(dir.path().join(f).is_file(), "the slider-crank tutorial did not write {f}");
    }
    if let Some(out) = run_tutorial_python(page, dir.path()) {
        assert_eq!(out.lines().count(), 2, "{out}");
        assert!(out.contains("peak midpoint deflection 3.88 mm"), "{out}");
    }
}

#[test]
fn readme_is_at_most_300_lines() {
    let n = std::fs::read_to_string(root().join("README.md")).unwrap().lines().count();
    assert!(n <= 300, "README.md has {n} lines");
}

/// Every text file under `dir` (recursively) with one of `exts`.
fn text_files(dir: &Path, exts: &[&str], out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            text_files(&p, exts, out);
        } else if p.extension().is_some_and(|x| exts.iter().any(|e| x == *e)) {
            out.push(p);
        }
    }
}

/// Where `text` speaks of how the project was made: a numbered step or ticket of the work,
/// the sitting it happened in, what came after it, whose measurement it was (a small
/// function that serves others is code, and fine). The words are put together from pieces
/// so that this file does not show up in a plain `grep` for them.
fn bookkeeping(text: &str) -> Vec<String> {
    let lower = text.to_lowercase();
    let mut found = Vec::new();
    for word in [concat!("st", "op "), concat!("iss", "ue ")] {
        for (i, _) in lower.match_indices(word) {
            let before = lower[..i].chars().next_back();
            let after = lower[i + word.len()..].chars().next();
            if !before.is_some_and(|c| c.is_alphanumeric()) && after.is_some_and(|c| c.is_ascii_digit()) {
                found.push(lower[i..(i + word.len() + 3).min(lower.len())].to_string());
            }
        }
    }
    let phrases = [
        concat!("this ", "session"),
        concat!("follow", "-up"),
        concat!("help", "er's"),
        concat!("help", "ers'"),
        concat!("the ", "issue's"),
    ];
    for phrase in phrases {
        if lower.contains(phrase) {
            found.push(phrase.to_string());
        }
    }
    found
}

#[test]
fn the_files_speak_of_the_project_not_of_its_making() {
    // the check itself, on text that must and must not match
    assert_eq!(bookkeeping(concat!("measured in St", "op 27, after iss", "ue 15")).len(), 2);
    assert!(bookkeeping(concat!("a nonst", "op 3-ticket run; a small function; commit 84270d5")).is_empty());
    let mut files = vec![root().join("README.md"), root().join("CHANGELOG.md")];
    for (dir, exts) in [
        ("docs", &["md"][..]),
        ("pipelines", &["md", "toml", "sh"][..]),
        ("data", &["toml", "md"][..]),
        ("src", &["rs"][..]),
        ("scripts", &["py", "sh", "sbatch"][..]),
        ("benches", &["rs", "py"][..]),
        ("examples", &["rs", "py"][..]),
        ("python", &["rs", "py", "pyi", "md", "toml"][..]),
        ("tests", &["rs"][..]),
    ] {
        text_files(&root().join(dir), exts, &mut files);
    }
    assert!(files.len() > 100, "only {} files found", files.len());
    let this = root().join("tests/docs.rs");
    let mut hits = Vec::new();
    for f in files.iter().filter(|f| **f != this) {
        let text = std::fs::read_to_string(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        for line in text.lines() {
            for what in bookkeeping(line) {
                hits.push(format!("{}: `{what}` in: {}", f.strip_prefix(root()).unwrap().display(), line.trim()));
            }
        }
    }
    assert!(hits.is_empty(), "development bookkeeping in the project's files:\n{}", hits.join("\n"));
}
