//! The zoo drives the release binary as a user does (`train`, `validate --json`,
//! `simulate`), one worker thread per process, and reads what it prints: the JSON of
//! `train --json` and `validate --json` (docs/cli.md) and greedy's lines on stderr
//! (docs/greedy-training.md, "What `train` prints").
//!
//! Every call keeps what the process printed beside the pipeline (`KEY.out`, `KEY.err`,
//! and `KEY.done` last, with the exit code, the wall time and the binary's size and
//! modification time): the raw record of the run, and what `resume` reads back instead of
//! running again when the same binary made it.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// The `flexrom` binary.
pub struct Flexrom {
    pub bin: PathBuf,
    /// read a call's kept output instead of running it again (same binary only)
    pub resume: bool,
}

/// What one process printed.
struct Printed {
    success: bool,
    stdout: Vec<u8>,
    stderr: Vec<u8>,
    wall_seconds: f64,
}

/// What `train` did.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Training {
    pub converged: bool,
    /// why it stopped: greedy's last iteration line, and its warning when it did not converge
    pub reason: String,
    pub full_runs: usize,
    pub pod_modes: usize,
    pub joint_coordinates: usize,
    /// sampled elements of the chosen basis (from its iteration line)
    pub elements: Option<usize>,
    /// the online default estimate the training chose: "defects" or "corrected"
    pub method: String,
    pub wall_seconds: f64,
}

/// One `validate --json` at one load.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Validation {
    pub load_scale: f64,
    pub n_modes: usize,
    pub rel_error: f64,
    pub error_estimate: f64,
    pub rel_error_by_time: [f64; 5],
    pub error_estimate_by_time: [f64; 5],
    pub full_seconds: f64,
    pub rom_seconds: f64,
    pub estimate_seconds: f64,
    pub speedup: f64,
    /// the run warned that the model amplifies changes of the load beyond what the estimate
    /// sees (`amplifying` of `validate --json`; false when absent)
    pub amplifying: bool,
    /// training's sensitivity beside the load (`sensitivity_near`; NaN when absent): what a
    /// sweep reads, where `validate`'s `amplifying` may also read its own full runs
    pub sensitivity_near: f64,
    /// every probe quantity's error and estimate (`probe_quantity_errors`)
    pub quantities: Vec<QuantityError>,
}

/// One probe quantity of a validation (`probe_quantity_errors` of `validate --json`,
/// docs/cli.md): the reduced run's error relative to the full run's range, and its estimate.
#[derive(Clone, Debug, serde::Serialize)]
pub struct QuantityError {
    pub probe: String,
    /// "position", "strain" or "curvature"; a joint reaction's "force" or "moment"
    pub quantity: String,
    /// `relative`: NaN where the JSON has null (no swing to measure against: the full run's
    /// range within the quantity's resolution; ∞ is written as null too, `max_error` and
    /// `range` tell them apart)
    pub relative: f64,
    /// `estimate`; NaN where the JSON has null (no estimate, no swing, or ∞)
    pub estimate: f64,
    pub max_error: f64,
    pub range: f64,
}

/// `probe_quantity_errors` and `reaction_errors` (a reaction point as the probe) of a
/// `validate --json` (none when absent).
fn quantity_errors(v: &Value) -> Vec<QuantityError> {
    let list = |key: &str| v.get(key).and_then(Value::as_array).cloned().unwrap_or_default();
    let text = |q: &Value, k: &str| q.get(k).and_then(Value::as_str).unwrap_or("").to_string();
    let probes = list("probe_quantity_errors").into_iter().map(|q| (text(&q, "probe"), q));
    let reactions = list("reaction_errors").into_iter().map(|q| (text(&q, "reaction"), q));
    probes
        .chain(reactions)
        .map(|(probe, q)| QuantityError {
            probe,
            quantity: text(&q, "quantity"),
            relative: number(&q, "relative"),
            estimate: number(&q, "estimate"),
            max_error: number(&q, "max_error"),
            range: number(&q, "range"),
        })
        .collect()
}

/// The last line of a process's stderr that says something (its error).
fn last_line(stderr: &[u8]) -> String {
    String::from_utf8_lossy(stderr).lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("").trim().to_string()
}

fn number(v: &Value, key: &str) -> f64 {
    v.get(key).and_then(Value::as_f64).unwrap_or(f64::NAN)
}

fn fifths(v: &Value, key: &str) -> [f64; 5] {
    let mut out = [f64::NAN; 5];
    if let Some(a) = v.get(key).and_then(Value::as_array) {
        for (o, x) in out.iter_mut().zip(a) {
            *o = x.as_f64().unwrap_or(f64::NAN);
        }
    }
    out
}

/// The number before " elements" in greedy's iteration line (`…, 12 elements`).
fn elements_of(line: &str) -> Option<usize> {
    let head = &line[..line.rfind(" elements")?];
    head.rsplit(|c: char| !c.is_ascii_digit()).next()?.parse().ok()
}

impl Flexrom {
    /// The binary's size and modification time: which build made a kept output.
    fn stamp(&self) -> String {
        std::fs::metadata(&self.bin)
            .map(|m| {
                let t = m.modified().ok().and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok());
                format!("{}:{}", m.len(), t.map_or(0, |d| d.as_nanos()))
            })
            .unwrap_or_default()
    }

    /// Runs `flexrom ARGS` in `dir` (or reads its kept output under `key`, see the module
    /// documentation).
    fn run(&self, dir: &Path, key: &str, args: &[&str]) -> Result<Printed, String> {
        let (out, err, done) =
            (dir.join(format!("{key}.out")), dir.join(format!("{key}.err")), dir.join(format!("{key}.done")));
        let stamp = self.stamp();
        if self.resume {
            if let Ok(d) = std::fs::read_to_string(&done) {
                let field = |k: &str| d.split_whitespace().find_map(|w| w.strip_prefix(k)).map(str::to_string);
                if field("bin=").as_deref() == Some(stamp.as_str()) {
                    if let (Ok(stdout), Ok(stderr), Some(exit), Some(wall)) =
                        (std::fs::read(&out), std::fs::read(&err), field("exit="), field("wall="))
                    {
                        return Ok(Printed {
                            success: exit == "0",
                            stdout,
                            stderr,
                            wall_seconds: wall.parse().unwrap_or(f64::NAN),
                        });
                    }
                }
            }
        }
        let _ = std::fs::remove_file(&done);
        let start = Instant::now();
        let o = Command::new(&self.bin)
            .current_dir(dir)
            .env_remove("RAYON_NUM_THREADS")
            .args(args)
            .output()
            .map_err(|e| format!("{}: {e}", self.bin.display()))?;
        let wall_seconds = start.elapsed().as_secs_f64();
        let exit = o.status.code().map_or("signal".to_string(), |c| c.to_string());
        let kept = std::fs::write(&out, &o.stdout).and_then(|()| std::fs::write(&err, &o.stderr));
        if kept.is_ok() {
            let _ = std::fs::write(&done, format!("exit={exit} wall={wall_seconds} bin={stamp}\n"));
        }
        Ok(Printed { success: o.status.success(), stdout: o.stdout, stderr: o.stderr, wall_seconds })
    }

    /// The full model at `load`: Ok when the run completes (the binary's blow-up checks
    /// included), else its error line. The result file is removed.
    pub fn full_run(&self, dir: &Path, model: &str, load: f64) -> Result<(), String> {
        let out = format!("full_{load}.h5");
        let key = format!("full_{load}");
        let o = self.run(
            dir,
            &key,
            &["simulate", "-q", "--threads", "1", "--load-scale", &load.to_string(), "-o", &out, model],
        )?;
        let _ = std::fs::remove_file(dir.join(&out));
        if o.success {
            Ok(())
        } else {
            Err(format!("λ = {load}: {}", last_line(&o.stderr)))
        }
    }

    /// The full model at every load of [`super::check_loads`], stopping at the first that fails.
    pub fn full_runs_complete(&self, dir: &Path, model: &str) -> Result<(), String> {
        super::check_loads().into_iter().try_for_each(|x| self.full_run(dir, model, x))
    }

    /// `train --json` of `pipeline` (a file in `dir`).
    pub fn train(&self, dir: &Path, pipeline: &str) -> Result<Training, String> {
        let key = format!("{}.train", pipeline.trim_end_matches(".toml"));
        let o = self.run(dir, &key, &["train", "--json", "--threads", "1", pipeline])?;
        let wall_seconds = o.wall_seconds;
        if !o.success {
            return Err(last_line(&o.stderr));
        }
        let v: Value = serde_json::from_slice(&o.stdout).map_err(|e| format!("train --json: {e}"))?;
        let err = String::from_utf8_lossy(&o.stderr);
        let last = err.lines().rfind(|l| l.starts_with("iteration ")).unwrap_or("").to_string();
        let warning = err.lines().find(|l| l.starts_with("warning: greedy training stopped"));
        let method = if err.lines().any(|l| l.starts_with("error estimate:") && l.ends_with("the online default")) {
            "defects"
        } else {
            "corrected"
        };
        let count = |k: &str| v.get(k).and_then(Value::as_u64).unwrap_or(0) as usize;
        Ok(Training {
            converged: warning.is_none(),
            reason: match warning {
                Some(w) => format!("{last} | {w}"),
                None => last.clone(),
            },
            full_runs: count("n_runs"),
            pod_modes: count("n_pod_modes"),
            joint_coordinates: count("n_joint_coordinates"),
            elements: elements_of(&last),
            method: method.into(),
            wall_seconds,
        })
    }

    /// `validate --json --no-dense` of `pipeline` at `load`.
    pub fn validate(&self, dir: &Path, pipeline: &str, load: f64) -> Result<Validation, String> {
        let key = format!("{}.validate_{load}", pipeline.trim_end_matches(".toml"));
        let x = load.to_string();
        let o = self.run(
            dir,
            &key,
            &["validate", "--json", "--no-dense", "-q", "--threads", "1", "--load-scale", &x, pipeline],
        )?;
        if !o.success {
            return Err(format!("λ = {load}: {}", last_line(&o.stderr)));
        }
        let v: Value = serde_json::from_slice(&o.stdout).map_err(|e| format!("validate --json: {e}"))?;
        Ok(Validation {
            load_scale: load,
            n_modes: v.get("n_modes").and_then(Value::as_u64).unwrap_or(0) as usize,
            rel_error: number(&v, "rel_error"),
            error_estimate: number(&v, "error_estimate"),
            rel_error_by_time: fifths(&v, "rel_error_by_time"),
            error_estimate_by_time: fifths(&v, "error_estimate_by_time"),
            full_seconds: number(&v, "full_seconds"),
            rom_seconds: number(&v, "rom_seconds"),
            estimate_seconds: number(&v, "estimate_seconds"),
            speedup: number(&v, "speedup"),
            amplifying: v.get("amplifying").and_then(Value::as_bool).unwrap_or(false),
            sensitivity_near: number(&v, "sensitivity_near"),
            quantities: quantity_errors(&v),
        })
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn elements_are_read_from_the_iteration_line() {
        let l = "iteration 1: worst score 8.04e-4 ≤ 1e-3; held-out check at λ = 1.4375 (score 7.74e-4): rel_error 1.06e-4 (score 9.79e-5, sensitivity 1.2e-3); 4 + 5 modes + 6 joint coordinates, 8 elements";
        assert_eq!(super::elements_of(l), Some(8));
        assert_eq!(super::elements_of("no count"), None);
    }

    /// A probe quantity's null `relative` (no swing) and null estimate read as NaN; an
    /// output without the key has none.
    #[test]
    fn quantity_errors_are_read_from_validate_json() {
        let v: serde_json::Value = serde_json::from_str(
            r#"{"probe_quantity_errors": [
                {"probe": "root", "quantity": "curvature", "max_error": 0.02, "range": 0.5, "largest": 0.3,
                 "relative": 0.04, "estimate": 0.06, "effectivity": 1.5},
                {"probe": "root", "quantity": "position", "max_error": 0.0, "range": 0.0, "largest": 1.0,
                 "relative": null, "estimate": null, "effectivity": null}]}"#,
        )
        .expect("JSON");
        let q = super::quantity_errors(&v);
        assert_eq!(
            (q[0].probe.as_str(), q[0].quantity.as_str(), q[0].relative, q[0].estimate),
            ("root", "curvature", 0.04, 0.06)
        );
        assert!(q[1].relative.is_nan() && q[1].estimate.is_nan() && q[1].range == 0.0);
        assert!(super::quantity_errors(&serde_json::json!({})).is_empty());
    }
}
