//! `sweep --shard K/N`: the K-th of N deterministic parts of a sweep's load list, written as
//! a part file that `flexrom merge` ([`crate::workflows::merge`]) joins into the file a single sweep
//! writes.
//!
//! The parts are strided: load index i (0-based, in the order of the list) belongs to shard
//! `(i mod N) + 1`. The cost of a run grows or falls with the load along the list, so
//! striding gives every shard a like share of cheap and dear loads; the assignment depends
//! on the list and N alone, so every job of an array computes the same parts.
//!
//! A part file is a sweep file of its own loads ([`crate::workflows::sweep`]'s layout, rows in list
//! order) plus the group `/shard`:
//!
//! ```text
//! /shard/all_load_scales   (N_all)     the whole list, as the sweep was asked for
//! /shard/all_points        (N_all, d)  a sweep over named parameters: the whole list of
//!                                      points (attribute `parameters`, as `/points`)
//! /shard/indices           (n_part)    u64: row j of the part is load all_load_scales[indices[j]]
//! attributes on /shard: index (K, 1-based), count (N), load_list_hash (SHA-256 hex of the
//!   list: its length, then each value's IEEE-754 bits, little-endian; for points the names
//!   and every point's values too: [`point_list_hash`]), pipeline and, for a reduced sweep,
//!   basis (absolute paths, for `merge`)
//! ```

use crate::error::{show_text, Error, Result};
use crate::io::h5::{attr_str, attr_u64};
use crate::pipeline::config::Pipeline;
use crate::solver::parameters::Parameters;
use crate::workflows::sweep::{sweep_to_file, Route, Sweep, SweepFile, SweepOptions};
use ndarray::Array1;
use sha2::{Digest, Sha256};

/// One part of N (`index` 1-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;

    /// `K/N` with 1 ≤ K ≤ N.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let (k, n) = s.split_once('/').ok_or_else(|| format!("`{s}` is not K/N (e.g. 2/8)"))?;
        let k: usize = k.trim().parse().map_err(|_| format!("`{s}`: K is not a whole number"))?;
        let n: usize = n.trim().parse().map_err(|_| format!("`{s}`: N is not a whole number"))?;
        if n == 0 || k == 0 || k > n {
            return Err(format!("`{s}`: need 1 ≤ K ≤ N (K counts from 1)"));
        }
        Ok(Shard { index: k, count: n })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// The indices into a list of `n` loads that belong to this shard, in order.
    pub fn indices(&self, n: usize) -> Vec<usize> {
        (0..n).filter(|i| i % self.count == self.index - 1).collect()
    }
}

/// SHA-256 (hex) of a load list: its length, then each value's bits (little-endian), so
/// that two lists hash alike only when they are the same values in the same order.
pub fn load_list_hash(scales: &[f64]) -> String {
    let mut h = Sha256::new();
    h.update((scales.len() as u64).to_le_bytes());
    for x in scales {
        h.update(x.to_bits().to_le_bytes());
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// SHA-256 (hex) of a list of points with the parameters `names` (`load_scale` first, as
/// [`crate::workflows::sweep::point_names`] gives them): [`load_list_hash`] of their load scales when
/// they set nothing else (so a part file of a line of loads keeps its hash), else the
/// count, each name (length, bytes) and each point's values in `names` order (bits,
/// little-endian).
pub fn point_list_hash(all: &[Parameters], names: &[String]) -> String {
    if names.len() <= 1 {
        return load_list_hash(&all.iter().map(Parameters::scale).collect::<Vec<_>>());
    }
    let mut h = Sha256::new();
    h.update((all.len() as u64).to_le_bytes());
    for n in names {
        h.update((n.len() as u64).to_le_bytes());
        h.update(n.as_bytes());
    }
    for mu in all {
        for n in names {
            h.update(mu.get(n).unwrap_or(1.0).to_bits().to_le_bytes());
        }
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// The indices of `shard` in a list of `n` runs (`points`: of named parameters, else of
/// load scales), or a usage error when it holds none.
pub fn shard_indices(n: usize, shard: Shard, points: bool) -> Result<Vec<usize>> {
    let idx = shard.indices(n);
    if idx.is_empty() {
        let (many, one) = if points { ("points", "point") } else { ("load scales", "load") };
        return Err(Error::option(
            "shard",
            Some(shard.to_string()),
            format!("a list of {n} {many} has no {one} for shard {}; use at most {n} shards", shard.index),
        ));
    }
    Ok(idx)
}

/// Runs the loads of `shard` by `route` and writes the part file `out` (checkpointed like
/// a sweep, every version with its `/shard` group, so a killed shard leaves a part that
/// `--resume` finishes and `merge --partial` reads). `f.extra` is replaced by the shard's
/// group.
pub fn sweep_shard(
    p: &Pipeline,
    route: Route,
    all: &[Parameters],
    shard: Shard,
    o: SweepOptions,
    f: SweepFile,
) -> Result<Sweep> {
    let out = f.out;
    let names = crate::workflows::sweep::point_names(all.iter());
    let idx = shard_indices(all.len(), shard, names.len() > 1)?;
    let hash = point_list_hash(all, &names);
    let scales: Vec<f64> = all.iter().map(Parameters::scale).collect();
    let pipeline = crate::io::output::resolve(&p.path).display().to_string();
    let basis = route.basis().map(|b| crate::io::output::resolve(b.path).display().to_string());
    let extra = |f: &hdf5::File| -> Result<()> {
        let e = |err: hdf5::Error| Error::hdf5(out, err);
        let g = f.create_group("shard").map_err(e)?;
        g.new_dataset_builder().with_data(&Array1::from(scales.clone())).create("all_load_scales").map_err(e)?;
        if names.len() > 1 {
            let table =
                ndarray::Array2::from_shape_fn((all.len(), names.len()), |(k, j)| all[k].get(&names[j]).unwrap_or(1.0));
            let d = g.new_dataset_builder().with_data(&table).create("all_points").map_err(e)?;
            attr_str(&d, "parameters", &names.join(",")).map_err(e)?;
        }
        g.new_dataset_builder()
            .with_data(&Array1::from_iter(idx.iter().map(|&i| i as u64)))
            .create("indices")
            .map_err(e)?;
        attr_u64(&g, "index", shard.index as u64).map_err(e)?;
        attr_u64(&g, "count", shard.count as u64).map_err(e)?;
        attr_str(&g, "load_list_hash", &hash).map_err(e)?;
        attr_str(&g, "pipeline", &pipeline).map_err(e)?;
        match &basis {
            Some(b) => attr_str(&g, "basis", b).map_err(e),
            None => Ok(()),
        }
    };
    let points: Vec<Parameters> = idx.iter().map(|&i| all[i].clone()).collect();
    sweep_to_file(route, &points, o, SweepFile { extra: &extra, ..f })
}

/// Most worker threads any setting may ask for: each thread reserves a stack (2 MiB of
/// address space) and starts at once, so `--threads 100000` spent minutes starting threads
/// for a 0.02 s run and, under an address-space limit, panicked inside rayon.
pub const MOST_THREADS: usize = 1024;

/// Sets the size of the worker pool: `--threads` when given, else `RAYON_NUM_THREADS` (0 or
/// empty: one per core, as rayon reads it), else `SLURM_CPUS_PER_TASK` (a Slurm job step gets
/// that many CPUs, however many the node has), else one per core. A count above the cores this
/// process may use is cut to them (the runs compute and never block, so more threads than
/// cores only wait on each other); 0, a count above [`MOST_THREADS`] or one that is not a
/// whole number is a usage error naming the option or variable.
pub fn configure_threads(flag: Option<usize>) -> Result<()> {
    let asked = match flag {
        Some(0) => return Err(Error::option("threads", None, "must be at least 1")),
        Some(n) if n > MOST_THREADS => return Err(Error::option("threads", Some(n.to_string()), too_many_threads())),
        Some(n) => Some(("--threads", n)),
        None if std::env::var_os("RAYON_NUM_THREADS").is_some() => threads_from_env("RAYON_NUM_THREADS", true)?,
        None => threads_from_env("SLURM_CPUS_PER_TASK", false)?,
    };
    // nothing asked: rayon starts its one-per-core pool when first used (not at all for a
    // command that runs nothing in parallel)
    let Some((source, n)) = asked else { return Ok(()) };
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    let n = capped_threads(source, n, cores);
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build_global()
        .map_err(|e| Error::usage(format!("{source}: could not start {n} worker threads: {e}")))
}

/// The count an environment variable asks for; `None` when unset or empty (and for 0 where
/// that means "one per core").
fn threads_from_env(name: &'static str, zero_is_default: bool) -> Result<Option<(&'static str, usize)>> {
    let Some(raw) = std::env::var_os(name) else { return Ok(None) };
    let raw = raw.to_string_lossy();
    let v = raw.trim();
    let shown = format!("environment variable {name}=`{}`", show_text(&raw));
    match v.parse::<u64>() {
        _ if v.is_empty() => Ok(None),
        Ok(0) if zero_is_default => Ok(None),
        Ok(n) if n > 0 && n <= MOST_THREADS as u64 => Ok(Some((name, n as usize))),
        // a row of digits too large for u64 is as absurd as 100000
        Ok(n) if n > 0 => Err(Error::usage(format!("{shown}: {}", too_many_threads()))),
        Err(_) if v.bytes().all(|b| b.is_ascii_digit()) => {
            Err(Error::usage(format!("{shown}: {}", too_many_threads())))
        }
        _ => Err(Error::usage(format!("{shown} is not a positive whole number"))),
    }
}

/// What a thread count above [`MOST_THREADS`] is told, after the option or the variable.
fn too_many_threads() -> String {
    format!("more worker threads than flexrom starts (at most {MOST_THREADS}; the default is one per core)")
}

/// `asked` cut to the cores, with a detail line saying so.
fn capped_threads(source: &str, asked: usize, cores: usize) -> usize {
    if asked <= cores {
        return asked;
    }
    log::debug!("flexrom: {source} asks for {asked} worker threads; using the {cores} cores this process may use");
    cores
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every index in exactly one shard, strided, and K/N parsed with its bounds.
    #[test]
    fn shards_partition_the_list() {
        for (n, count) in [(64, 4), (7, 3), (3, 3), (1, 1), (10, 4)] {
            let mut seen: Vec<usize> = (1..=count).flat_map(|index| Shard { index, count }.indices(n)).collect();
            seen.sort();
            assert_eq!(seen, (0..n).collect::<Vec<_>>(), "{n} {count}");
        }
        assert_eq!(Shard { index: 2, count: 4 }.indices(10), vec![1, 5, 9]);
        assert_eq!("3/8".parse::<Shard>(), Ok(Shard { index: 3, count: 8 }));
        for bad in ["0/4", "5/4", "1/0", "2", "a/4", "1/b"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        assert!(shard_indices(2, Shard { index: 3, count: 3 }, false).is_err());
        assert_ne!(load_list_hash(&[1.0, 2.0]), load_list_hash(&[2.0, 1.0]));
        assert_ne!(load_list_hash(&[1.0]), load_list_hash(&[1.0, 1.0]));
    }

    /// A list of load scales alone hashes as it always has (part files written before
    /// points existed keep merging); points hash their names and values, so a changed
    /// value or name gives another hash.
    #[test]
    fn point_lists_hash_their_names_and_values() {
        let line = [Parameters::load_scale(0.8), Parameters::load_scale(1.2)];
        assert_eq!(point_list_hash(&line, &["load_scale".into()]), load_list_hash(&[0.8, 1.2]));
        let names: Vec<String> = vec!["load_scale".into(), "push".into()];
        let pts = |x: f64| [Parameters::default().with("push", 0.5), Parameters::default().with("push", x)];
        let h = point_list_hash(&pts(2.0), &names);
        assert_eq!(h, point_list_hash(&pts(2.0), &names));
        assert_ne!(h, point_list_hash(&pts(2.5), &names));
        assert_ne!(h, point_list_hash(&pts(2.0), &["load_scale".into(), "pull".into()]));
    }

    /// A thread count above the most is refused before any pool starts, named by the option's
    /// key; on the command line it reads as the message did when it wrote the flag
    /// (`"{what} {value}: more worker threads …"` with `--threads`).
    #[test]
    fn too_many_threads_name_the_option() {
        let e = configure_threads(Some(MOST_THREADS + 1)).unwrap_err();
        let tail = "more worker threads than flexrom starts (at most 1024; the default is one per core)";
        assert_eq!(e.render(&crate::error::cli_flag), format!("--threads 1025: {tail}"));
        assert_eq!(e.to_string(), format!("threads = 1025: {tail}"));
    }
}
