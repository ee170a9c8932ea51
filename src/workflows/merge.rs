//! `merge`: the part files of a sharded sweep ([`crate::workflows::shard`]) joined into the file a
//! single `sweep` over the whole list writes: the same datasets with the same values (the
//! runs' rows are read back and written by the same writer, [`crate::workflows::sweep::write_sweep`]).
//! Only the whole-sweep attributes differ in meaning: `wall_seconds` is the longest part's
//! (the parts ran side by side) and `threads` the sum of the parts' threads.
//!
//! Checks, each failing with one line that names the file: every part is a part file (has
//! `/shard`), all come from the same load list (hash), the same shard count, the same route
//! (all reduced or all `--full`), the same basis content and model, and the same options
//! (`--validate`, `--continuation`). Two parts of
//! the same shard are refused (naming both files and the loads); a missing shard, or loads a
//! part has not run yet (a killed shard), are refused naming the loads, unless `--partial`,
//! which merges what is there and marks the gaps `status` 2 ("not run yet"), so that
//! `sweep --resume` on the merged file runs exactly the gaps.

use crate::error::{show_text, Error, Result, Text};
use crate::io::h5::{bounded_len, dataset_of_shape, read_attr_f64, read_attr_str, read_strings};
use crate::limits::Limits;
use crate::pipeline::config::Pipeline;
use crate::simulate::{Overrides, Settings};
use crate::solver::parameters::{Parameters, LOAD_SCALE};
use crate::workflows::online::load_basis;
use crate::workflows::shard::point_list_hash;
use crate::workflows::sweep::{
    read_sweep, write_sweep, Fallback, Outcome, ScaleResult, Sweep, SweepBasis, STATUS_FAILED, STATUS_OK,
};
use ndarray::Array1;
use std::path::{Path, PathBuf};

/// What a listed point may take in memory while parts are merged: its value, its
/// `Parameters` and its row of the merged sweep before any run is read (a generous figure: a
/// list a file claims longer than the memory bound allows at it is refused unread).
const BYTES_PER_LISTED_POINT: f64 = 256.0;

/// What one part file says about itself.
struct Part {
    path: PathBuf,
    index: usize,
    count: usize,
    list_hash: String,
    /// the whole list of points (of load scales alone, or `/shard/all_points`)
    all: Vec<Parameters>,
    indices: Vec<usize>,
    status: Vec<u8>,
    message: Vec<String>,
    /// a part of a full sweep (`--full`): no basis
    full: bool,
    /// the basis of a reduced sweep's part: its content hash, its path on `/shard` and on `/`
    basis: Option<PartBasis>,
    model_fingerprint: String,
    validated: bool,
    continuation: bool,
    /// `--fallback` (attribute `fallback`; "none" in files written before it)
    fallback: String,
    wall_seconds: f64,
    threads: u64,
    pipeline: PathBuf,
}

struct PartBasis {
    hash: String,
    path: PathBuf,
    attr: String,
}

fn read_part(path: &Path, limits: &Limits) -> Result<Part> {
    let bad = |field: &str, problem: String| Error::input(path, field, problem);
    let f = crate::io::h5_open::open(path).map_err(|e| bad("(file)", crate::io::h5_open::unreadable(&e)))?;
    let g = f.group("shard").map_err(|_| {
        bad(
            "shard",
            "is missing: not a part file of `flexrom sweep --shard K/N` (a merged or plain sweep file?)".into(),
        )
    })?;
    let u = |name: &str| -> Result<u64> {
        g.attr(name)
            .and_then(|a| a.read_scalar::<u64>())
            .map_err(|e| bad(&format!("shard/{name}"), format!("cannot be read: {e}")))
    };
    let s = |loc: &hdf5::Location, name: &str| {
        read_attr_str(loc, name).map_err(|e| bad(name, format!("cannot be read ({e}): not a flexrom part file?")))
    };
    let (index, count) = (u("index")? as usize, u("count")? as usize);
    if index == 0 || index > count {
        return Err(bad("shard/index", format!("is {index} of {count}: need 1 ≤ index ≤ count")));
    }
    // the lists' lengths are the file's own: bounded before anything is read (each point
    // becomes a `Parameters` and a row of the merged sweep), every other shape checked
    // against them
    let n_all = bounded_len(&g, "all_load_scales", BYTES_PER_LISTED_POINT, limits)
        .map_err(|p| Error::input(path, "shard/all_load_scales", p.problem_text()))?;
    let shaped = |loc: &hdf5::Group, name: &str, want: &[usize]| {
        let field = if loc.name() == "/shard" { format!("shard/{name}") } else { name.to_string() };
        dataset_of_shape(loc, name, want).map_err(|p| bad(&field, p.problem()))
    };
    let scales_all = shaped(&g, "all_load_scales", &[n_all])?
        .read_1d::<f64>()
        .map_err(|e| bad("shard/all_load_scales", format!("cannot be read: {e}")))?
        .to_vec();
    // a sweep over named parameters: the points, as /points holds them
    let (all, names): (Vec<Parameters>, Vec<String>) = match g.dataset("all_points") {
        Ok(d) => {
            let (names, all) = crate::records::sweep_file::read_point_table(&d, scales_all.len())
                .map_err(|problem| bad("shard/all_points", problem))?;
            if names.first().map(String::as_str) != Some(LOAD_SCALE) {
                return Err(bad("shard/all_points", format!("has parameters {names:?}; load_scale comes first")));
            }
            (all, names)
        }
        Err(_) => (scales_all.iter().map(|&x| Parameters::load_scale(x)).collect(), vec![LOAD_SCALE.to_string()]),
    };
    let list_hash = s(&g, "load_list_hash")?;
    if point_list_hash(&all, &names) != list_hash
        || all.iter().zip(&scales_all).any(|(mu, x)| mu.scale().to_bits() != x.to_bits())
    {
        return Err(bad(
            "shard/load_list_hash",
            "does not match shard/all_load_scales and shard/all_points (a damaged file)".into(),
        ));
    }
    let n = bounded_len(&f, "load_scales", BYTES_PER_LISTED_POINT, limits)
        .map_err(|p| Error::input(path, "load_scales", p.problem_text()))?;
    let indices: Vec<usize> = shaped(&g, "indices", &[n])?
        .read_1d::<u64>()
        .map_err(|e| bad("shard/indices", format!("cannot be read: {e}")))?
        .iter()
        .map(|&i| i as usize)
        .collect();
    let scales = shaped(&f, "load_scales", &[n])?
        .read_1d::<f64>()
        .map_err(|e| bad("load_scales", format!("cannot be read: {e}")))?;
    let status = shaped(&f, "status", &[n])?
        .read_1d::<u8>()
        .map_err(|e| bad("status", format!("cannot be read: {e}")))?
        .to_vec();
    let message: Vec<String> =
        read_strings(&shaped(&f, "message", &[n])?).map_err(|e| bad("message", format!("cannot be read: {e}")))?;
    let noun = if names.len() > 1 { "points" } else { "load scales" };
    if indices.len() != n || status.len() != n || message.len() != n {
        return Err(bad(
            "shard/indices",
            format!(
                "has {} entries, /status {}, /message {}, for {n} {noun}",
                indices.len(),
                status.len(),
                message.len()
            ),
        ));
    }
    if indices != (index - 1..all.len()).step_by(count).collect::<Vec<_>>()
        || indices.iter().zip(scales.iter()).any(|(&i, &x)| all[i].scale().to_bits() != x.to_bits())
    {
        return Err(bad(
            "shard/indices",
            format!("are not the {noun} of shard {index}/{count} of shard/all_load_scales (a damaged file)"),
        ));
    }
    // over named parameters every parameter of each row, not λ alone
    if names.len() > 1 {
        let d = f.dataset("points").map_err(|e| bad("points", format!("cannot be read: {e}")))?;
        let (_, rows) =
            crate::records::sweep_file::read_point_table(&d, n).map_err(|problem| bad("points", problem))?;
        let same = |a: &Parameters, b: &Parameters| {
            names.iter().all(|k| a.get(k).map(f64::to_bits) == b.get(k).map(f64::to_bits))
        };
        if indices.iter().zip(&rows).any(|(&i, mu)| !same(&all[i], mu)) {
            return Err(bad(
                "points",
                format!("are not the points of shard {index}/{count} of shard/all_points (a damaged file)"),
            ));
        }
    }
    let flag = |name: &str| -> Result<bool> {
        f.attr(name)
            .and_then(|a| a.read_scalar::<u64>())
            .map(|v| v != 0)
            .map_err(|e| bad(name, format!("cannot be read: {e}")))
    };
    // parts written before the attribute are of reduced sweeps
    let full = f.attr("route").is_ok() && s(&f, "route")? == "full";
    let basis = if full {
        None
    } else {
        Some(PartBasis {
            hash: s(&f, "basis_content_hash")?,
            path: recorded_path(&g, "basis").map_err(|p| bad("shard/basis", p.problem()))?,
            attr: s(&f, "basis")?,
        })
    };
    Ok(Part {
        path: path.to_path_buf(),
        index,
        count,
        list_hash,
        all,
        indices,
        status,
        message,
        full,
        basis,
        model_fingerprint: s(&f, "model_fingerprint")?,
        validated: flag("validated")?,
        continuation: flag("continuation")?,
        fallback: if f.attr("fallback").is_ok() { s(&f, "fallback")? } else { "none".into() },
        wall_seconds: read_attr_f64(&f, "wall_seconds").unwrap_or(f64::NAN),
        threads: f.attr("threads").and_then(|a| a.read_scalar::<u64>()).unwrap_or(1),
        pipeline: recorded_path(&g, "pipeline").map_err(|p| bad("shard/pipeline", p.problem()))?,
    })
}

/// A path a part records for `merge` (attribute `name` on `/shard`; `sweep --shard` writes
/// it absolute). `Err(problem)`.
fn recorded_path(g: &hdf5::Group, name: &str) -> Result<PathBuf> {
    let v = read_attr_str(g, name)
        .map_err(|e| Error::hdf5(g.filename(), format!("cannot be read ({e}): not a flexrom part file?")))?;
    if v.trim().is_empty() {
        let problem = format!("is `{}`, not a path (`sweep --shard` records one): a damaged part file", show_text(&v));
        return Err(Error::hdf5(g.filename(), problem));
    }
    Ok(PathBuf::from(v))
}

/// A failure to read a file at the path a part records (`key`): says where the path came
/// from, since the user gave only the part files.
fn recorded_in(e: Error, part: &Part, key: &str) -> Error {
    Error::Hinted {
        source: Box::new(e),
        hint: format!(
            "that path is the one {} records in `{key}` (moved since the sweep? put it back there, or sweep again)",
            part.path.display()
        )
        .into(),
    }
}

/// A few runs for a message: "load scales 0.5, 0.53, 0.56 and 13 more", or for named
/// parameters "points (load scale 1, push = 0.5); … and 13 more".
fn some(xs: &[Parameters]) -> String {
    let head = crate::workflows::sweep::runs_noun(xs);
    let named = head == "points";
    let shown: Vec<String> =
        xs.iter().take(4).map(|mu| if named { format!("({mu})") } else { mu.scale().to_string() }).collect();
    let sep = if named { "; " } else { ", " };
    format!("{head} {}", some_of(&shown, xs.len(), sep))
}

fn some_of(shown: &[String], n: usize, sep: &str) -> String {
    if n > 4 {
        format!("{} and {} more", shown.join(sep), n - 4)
    } else {
        shown.join(sep)
    }
}

pub struct Merged {
    pub sweep: Sweep,
    /// loads no part has run (`--partial` only)
    pub gaps: usize,
    pub parts: usize,
}

/// Joins `parts` into `out` (atomically; the caller has checked that `out` may be written).
pub fn merge(parts: &[PathBuf], out: &Path, partial: bool, limits: &Limits) -> Result<Merged> {
    if parts.is_empty() {
        return Err(Error::usage("merge: no part files given"));
    }
    let parts: Vec<Part> = parts.iter().map(|p| read_part(p, limits)).collect::<Result<_>>()?;
    let first = &parts[0];
    for p in &parts[1..] {
        same_sweep(first, p)?;
    }
    check_coverage(&parts, partial)?;
    let (pipeline, stored) = recorded_basis(first, limits)?;
    let model = &pipeline.model;
    let s = Settings::resolve(model, &Overrides::default())?;
    let mut sweep = Sweep {
        scales: first.all.iter().map(|mu| ScaleResult { mu: mu.clone(), outcome: Outcome::Pending }).collect(),
        t: Array1::from_iter((0..=s.n_steps).map(|k| k as f64 * s.dt)),
        probe_names: model.probe_names(),
        section_names: model.section_names(),
        reactions: crate::rom::reactions::ReactionReader::new(model).points(),
        n_reduced: stored.as_ref().map_or(0, |b| b.basis.n_reduced()),
        full: first.full,
        model_fingerprint: model.fingerprint(),
        validated: first.validated,
        fallback: if first.fallback == "full" { Fallback::Full } else { Fallback::None },
        wall_seconds: parts.iter().map(|p| p.wall_seconds).fold(0.0, f64::max),
        threads: parts.iter().map(|p| p.threads as usize).sum(),
        continuation: first.continuation,
        resumed: 0,
    };
    for p in &parts {
        let rows = read_sweep(&p.path, model, stored.as_ref(), p.validated)?;
        for (j, (_, point)) in rows.into_iter().enumerate() {
            let i = p.indices[j];
            sweep.scales[i].outcome = match (p.status[j], point) {
                (STATUS_OK, Some(pt)) => Outcome::Done(pt),
                (STATUS_FAILED, _) => Outcome::Failed(p.message[j].clone()),
                _ => Outcome::Pending,
            };
        }
    }
    let gaps = sweep.scales.iter().filter(|x| matches!(x.outcome, Outcome::Pending)).count();
    // the basis file is where the parts say (checked against their hash above)
    let sensitivity = stored.as_ref().and_then(|s| {
        let t = &s.training;
        t.sensitivity.as_ref().map(|x| crate::rom::trust::LoadSensitivity::of_stored(x, &t.space))
    });
    let basis = stored.as_ref().zip(first.basis.as_ref()).map(|(stored, b)| SweepBasis {
        stored,
        path: Path::new(&b.attr),
        sensitivity: sensitivity.as_ref(),
    });
    write_sweep(out, &sweep, basis)?;
    Ok(Merged { sweep, gaps, parts: parts.len() })
}

/// Refuses a part `p` of another sweep than `first`'s: another route, basis, model, point
/// list, split, `--validate`, `--continuation` or `--fallback`.
fn same_sweep(first: &Part, p: &Part) -> Result<()> {
    let differ = |field: &str, what: &str| {
        Error::input(
            &p.path,
            field,
            format!("{what} than {}; parts of different sweeps cannot be merged", first.path.display()),
        )
    };
    if p.full != first.full {
        let kind = |full: bool| if full { "the full model (`sweep --full`)" } else { "a reduced model" };
        return Err(Error::input(
            &p.path,
            "route",
            format!(
                "is a sweep of {} and {} one of {}; parts of different sweeps cannot be merged",
                kind(p.full),
                first.path.display(),
                kind(first.full)
            ),
        ));
    }
    if p.basis.as_ref().map(|b| &b.hash) != first.basis.as_ref().map(|b| &b.hash) {
        return Err(differ("basis_content_hash", "comes from another basis"));
    }
    if p.model_fingerprint != first.model_fingerprint {
        return Err(differ("model_fingerprint", "comes from another model"));
    }
    if p.list_hash != first.list_hash {
        let list = if crate::workflows::sweep::runs_noun(&first.all) == "points" { "point list" } else { "load list" };
        return Err(differ("shard/load_list_hash", &format!("comes from another {list}")));
    }
    if p.count != first.count {
        return Err(differ(
            "shard/count",
            &format!("is one of {} shards, not of {}, (another split)", p.count, first.count),
        ));
    }
    if p.validated != first.validated {
        return Err(differ("validated", "was run with another --validate"));
    }
    if p.continuation != first.continuation {
        return Err(differ("continuation", "was run with another --continuation"));
    }
    if p.fallback != first.fallback {
        return Err(differ(
            "fallback",
            &format!("is \"{}\", not \"{}\" (another --fallback)", p.fallback, first.fallback),
        ));
    }
    Ok(())
}

/// Refuses a shard given twice; without `partial`, a shard missing or one whose part did
/// not finish.
fn check_coverage(parts: &[Part], partial: bool) -> Result<()> {
    let first = &parts[0];
    // who holds each shard
    let mut holder: Vec<Option<usize>> = vec![None; first.count];
    for (j, p) in parts.iter().enumerate() {
        if let Some(other) = holder[p.index - 1] {
            let loads: Vec<Parameters> = p.indices.iter().map(|&i| p.all[i].clone()).collect();
            return Err(Error::input(
                &p.path,
                "shard/index",
                format!(
                    "is shard {}/{} again, as is {} (duplicate {}); give each shard once",
                    p.index,
                    p.count,
                    parts[other].path.display(),
                    some(&loads)
                ),
            ));
        }
        holder[p.index - 1] = Some(j);
    }
    if partial {
        return Ok(());
    }
    let all = &first.all;
    let missing: Vec<usize> = (0..first.count).filter(|&k| holder[k].is_none()).collect();
    if !missing.is_empty() {
        let loads: Vec<Parameters> =
            (0..all.len()).filter(|i| missing.contains(&(i % first.count))).map(|i| all[i].clone()).collect();
        let names: Vec<String> = missing.iter().map(|k| format!("{}/{}", k + 1, first.count)).collect();
        return Err(Error::usage(format!(
            "merge: shard(s) {} missing: {} not in any part; give their parts, or --partial to merge the rest with these marked not run",
            names.join(", "),
            some(&loads)
        )));
    }
    for p in parts {
        let not_run: Vec<Parameters> = (0..p.status.len())
            .filter(|&j| p.status[j] != STATUS_OK && p.status[j] != STATUS_FAILED)
            .map(|j| p.all[p.indices[j]].clone())
            .collect();
        if !not_run.is_empty() {
            return Err(Error::input(
                &p.path,
                "status",
                Text::new(format!("{} were not run (the shard did not finish); rerun it with ", some(&not_run)))
                    .option("resume", None)
                    .then(", or merge ")
                    .option("partial", None),
            ));
        }
    }
    Ok(())
}

/// The pipeline the parts were run with and, for a reduced sweep, its basis, checked
/// against the parts' basis hash.
fn recorded_basis(first: &Part, limits: &Limits) -> Result<(Pipeline, Option<crate::io::basis_file::StoredBasis>)> {
    let pipeline =
        Pipeline::load_with(&first.pipeline, limits.clone()).map_err(|e| recorded_in(e, first, "shard/pipeline"))?;
    let Some(b) = &first.basis else { return Ok((pipeline, None)) };
    let stored = load_basis(&pipeline, &b.path).map_err(|e| recorded_in(e, first, "shard/basis"))?;
    if stored.content_hash != b.hash {
        return Err(Error::input(
            &b.path,
            "basis_content_hash",
            format!(
                "differs from the one the parts were swept with ({}): the basis changed since; rerun the sweep",
                first.path.display()
            ),
        ));
    }
    Ok((pipeline, Some(stored)))
}
