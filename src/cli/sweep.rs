//! `flexrom sweep`: reduced runs (or, with `--full`, full ones) at many load scales into one
//! sweep file and a table (optionally one shard of the list, resumed, or validated).

use super::{print_table, warn, EstimateArgs, FormatArgs};
use flexrom::io::attrs::Kind;
use flexrom::io::output::{check_output, Origin};
use flexrom::limits::Limits;
use flexrom::output::table::Format;
use flexrom::output::{self, info};
use flexrom::pipeline::Pipeline;
use flexrom::solver::parameters::{Parameters, LOAD_SCALE};
use flexrom::workflows::online::load_rom;
use flexrom::workflows::sweep::{Fallback, Route, SweepBasis, SweepFile, SweepOptions};
use std::path::PathBuf;

/// The arguments of `flexrom sweep`.
#[derive(clap::Args)]
pub struct Args {
    /// pipeline file (TOML)
    pipeline: PathBuf,
    /// `A:B:N`: N load scales from A to B, or a list `X,Y,Z` (default: the pipeline's
    /// [online] load_scales, else its training loads); A may be negative (`-1:1:21`)
    #[arg(long, allow_hyphen_values = true, value_name = "A:B:N", value_parser = scale_list)]
    load_scales: Option<ScaleList>,
    /// an axis of a grid of named parameters: `NAME=A:B:N`, `NAME=A:B:N:log` or `NAME=X`;
    /// repeat it for several (with --load-scales, or the pipeline's loads, as the first
    /// axis); the grid runs every combination, the first axis slowest
    #[arg(long = "param", value_name = "NAME=A:B:N", allow_hyphen_values = true)]
    params: Vec<String>,
    /// a CSV file of points: a header of parameter names (`load_scale` for the load
    /// scale), one point per row
    #[arg(long, value_name = "FILE", conflicts_with_all = ["load_scales", "params"])]
    points: Option<PathBuf>,
    /// also run the full model at each load scale and report errors
    #[arg(long)]
    validate: bool,
    /// run the full model at every load instead of the reduced one: exact (no estimate,
    /// nothing to validate), no basis needed, into the same sweep file layout; faster than
    /// the reduced model on small meshes (`train` measures both and `online`/`sweep` say
    /// which is faster)
    #[arg(long, conflicts_with_all = ["validate", "continuation", "no_estimate", "basis", "strict"])]
    full: bool,
    /// continuation in the load scale: each thread takes two contiguous parts of the list
    /// (one from each end) and every run starts its Newton solves from its neighbours'
    /// steps (about 2× fewer iterations on the pendulum). Same step equations and tolerance, but where the
    /// dynamics are sensitive (the four-bar after t ≈ 0.6 s) Newton may settle on
    /// another nearby solution than `online` does; without it every load scale runs on
    /// its own, exactly as `online`
    #[arg(long)]
    continuation: bool,
    /// where the reduced answer cannot be trusted — its run fails, its error estimate
    /// exceeds the tolerance ([online] tolerance, else the training tolerance), or the model
    /// amplifies load changes beyond it — `full` runs the full model there and keeps its
    /// exact answer (`/fallback` 1, why in `/message`); over the pipeline's [online]
    /// fallback, default none
    #[arg(long, value_enum, value_name = "WHAT", conflicts_with_all = ["validate", "full"])]
    fallback: Option<flexrom::workflows::sweep::Fallback>,
    /// skip the error estimate (about 2× faster; `/error_estimate` is then NaN)
    #[arg(long, conflicts_with = "estimate")]
    no_estimate: bool,
    /// sweep file to write (HDF5); no default: the pipeline's report folder holds the
    /// sweep.h5 of `flexrom run`, which the report's summary.md describes
    #[arg(short, long)]
    output: PathBuf,
    /// basis file (default: the pipeline's `basis`)
    #[arg(long)]
    basis: Option<PathBuf>,
    /// take the load scales that the sweep file already holds as finished (same basis
    /// and model) from it and run only the others; failed ones run again
    #[arg(long)]
    resume: bool,
    /// exit with code 4 (after writing the output) when an error estimate exceeds the
    /// tolerance ([online] tolerance, default the training tolerance)
    #[arg(long)]
    strict: bool,
    /// `K/N`: run only the K-th (1-based) of N parts of the load list (loads K, K+N,
    /// K+2N, …) into the part file given by -o; join the parts with `flexrom merge`
    #[arg(long, value_name = "K/N")]
    shard: Option<flexrom::workflows::shard::Shard>,
    #[command(flatten)]
    estimate: EstimateArgs,
    #[command(flatten)]
    format: FormatArgs,
}

/// With `--validate`: the median of the points' speedups, and what they are (one run of each
/// model, timed while the other threads ran theirs: one point's figure is noisy).
fn speedup_summary(sw: &flexrom::workflows::sweep::Sweep) -> Option<String> {
    let mut v: Vec<f64> = sw
        .scales
        .iter()
        .filter_map(|x| x.point().and_then(|p| p.validation.as_ref()).map(|v| v.speedup))
        .filter(|x| x.is_finite())
        .collect();
    if v.is_empty() {
        return None;
    }
    let median = flexrom::cost::timing::median(&mut v);
    Some(format!(
        "speedup (reduced run without its estimate): median {median:.2}× over {} points, each from one run of either model{}; `validate` times medians of interleaved runs",
        v.len(),
        if sw.threads > 1 { format!(", timed beside the sweep's other runs on {} threads", sw.threads) } else { String::new() }
    ))
}

/// The values of `--load-scales` (a type of its own: clap would read a `Vec` as a repeated
/// option); parsed by clap, so a malformed one exits with code 2 as other bad arguments do.
#[derive(Clone, Debug)]
pub struct ScaleList(Vec<f64>);

fn scale_list(s: &str) -> std::result::Result<ScaleList, String> {
    flexrom::pipeline::config::parse_scales(s).map(ScaleList)
}

impl Args {
    pub fn run(self, limits: &Limits) -> flexrom::Result<()> {
        let Args {
            pipeline,
            load_scales,
            params,
            points,
            validate,
            full,
            continuation,
            fallback,
            no_estimate,
            output,
            basis,
            resume,
            strict,
            shard,
            estimate,
            format,
        } = self;
        let p = Pipeline::load_with(&pipeline, limits.clone())?;
        let points = sweep_points(&p, load_scales.map(|l| l.0), &params, points.as_deref())?;
        let named = points.iter().any(|mu| mu.named().next().is_some());
        let path = basis.unwrap_or_else(|| p.basis_path.clone());
        let mut inputs = vec![(p.path.as_path(), "pipeline file"), (p.model.path.as_path(), "model file")];
        if !full {
            inputs.push((path.as_path(), "basis file"));
        }
        let out = output;
        check_output(&out, Origin::Flag("-o"), &inputs, &[Kind::Sweep])?;
        if no_estimate && strict {
            return Err(flexrom::Error::usage("--strict needs the error estimate; drop --no-estimate"));
        }
        let options = sweep_options(&p, fallback, validate, continuation, full, no_estimate)?;
        let fallback = options.fallback;
        let loaded = if full { None } else { Some(load_rom(&p, &path, estimate.method(), no_estimate)?) };
        if let Some((_, _, warnings)) = &loaded {
            warn(warnings);
        }
        // read before the runs (a damaged /timing fails now), said after them, failed runs or not
        let notice = match &loaded {
            Some((stored, rom, _)) => flexrom::cost::route::speed_notice_of(&path, stored, rom),
            None => None,
        };
        let route = match &loaded {
            Some((stored, rom, _)) => Route::Reduced {
                rom,
                basis: SweepBasis {
                    stored,
                    path: &path,
                    sensitivity: rom.trust().and_then(|t| t.sensitivity.as_ref()),
                },
            },
            None => Route::Full(&p.model),
        };
        if let (Fallback::Full, Some((_, rom, _))) = (fallback, &loaded) {
            warn_what_the_fallback_lacks(rom);
        }
        let file = SweepFile { out: &out, resume, extra: &|_| Ok(()) };
        let sw = match shard {
            Some(k) => flexrom::workflows::shard::sweep_shard(&p, route, &points, k, options, file)?,
            None => flexrom::workflows::sweep::sweep_to_file(route, &points, options, file)?,
        };
        show_sweep(&sw, format.format(), shard, full, named, &out)?;
        warn(notice.as_slice());
        if let Some(line) = fallback_summary(&sw) {
            info(&line);
        }
        // the answers kept are warned about also when some points failed (exit 3 below)
        let failure = sw.failure_summary();
        let checked = match &loaded {
            Some((_, rom, _)) => {
                let strict = strict && failure.is_none();
                super::warn_after(rom.warnings_after(&sw.answered(rom), strict), rom, strict)
            }
            None => Ok(()),
        };
        // the good runs are written; the exit code (3) says that some failed
        if let Some(s) = failure {
            return Err(partly_failed(&s, loaded.is_some() && fallback == Fallback::None, &out));
        }
        checked
    }
}

/// The sweep's options: the fallback it runs with (none for a full or a validated sweep,
/// which measures the reduced model at every point; else `--fallback`, else the pipeline's
/// [online] fallback), refusing a full fallback without the estimate that judges each answer.
fn sweep_options(
    p: &Pipeline,
    fallback: Option<Fallback>,
    validate: bool,
    continuation: bool,
    full: bool,
    no_estimate: bool,
) -> flexrom::Result<SweepOptions> {
    let keyed = fallback.is_none() && p.online_fallback() == Some(Fallback::Full);
    let options = SweepOptions {
        validate,
        continuation,
        progress: output::show_progress(),
        fallback: fallback.or(p.online_fallback()).unwrap_or_default(),
    }
    .settled(full);
    if keyed && validate {
        info(&format!(
            "{}: [online] fallback = \"full\" does not apply to a validated sweep, which measures the reduced model at every point",
            p.path.display()
        ));
    }
    if options.fallback == Fallback::Full && no_estimate {
        let given = if keyed {
            format!("{}'s [online] fallback = \"full\"", p.path.display())
        } else {
            "--fallback full".into()
        };
        return Err(flexrom::Error::usage(format!(
            "{given} needs the error estimate to judge each reduced answer; drop --no-estimate (or pass --fallback none)"
        )));
    }
    Ok(options)
}

/// The error of a sweep some of whose points failed (exit 3), the good ones written to `out`;
/// `reduced_failed` (reduced runs without a fallback) adds the way on, once for all of them
/// (with the fallback a failed point is one where the full model failed too).
fn partly_failed(summary: &str, reduced_failed: bool, out: &std::path::Path) -> flexrom::Error {
    let hint = if reduced_failed { format!("\n{}", flexrom::error::REDUCED_RUN_FAILED) } else { String::new() };
    flexrom::Error::PartlyFailed(format!(
        "{summary} (the others are in {}; /status and /message say which){hint}",
        out.display()
    ))
}

/// Where `--fallback full` can act less than asked: a basis without an error estimator, or no
/// tolerance to hold the estimates to.
fn warn_what_the_fallback_lacks(rom: &flexrom::rom::Rom) {
    if rom.estimator().is_none() {
        warn(&["the basis has no error estimator: --fallback full acts only where a reduced run fails or the model amplifies load changes (train again for an estimator)".to_string()]);
    } else if rom.trust().and_then(|t| t.tolerance).is_none() {
        warn(&["no tolerance to hold the estimates to (a basis trained at fixed loads, and no [online] tolerance in the pipeline): --fallback full acts only where a reduced run fails".to_string()]);
    }
}

/// The sweep's table on stdout, then its summary line and the speed-up line on stderr.
fn show_sweep(
    sw: &flexrom::workflows::sweep::Sweep,
    format: Format,
    shard: Option<flexrom::workflows::shard::Shard>,
    full: bool,
    named: bool,
    out: &std::path::Path,
) -> flexrom::Result<()> {
    match format {
        Format::Text => output::print(&flexrom::workflows::sweep::table(sw))?,
        f => print_table(&flexrom::report::tables::sweep_table(sw), f, false)?,
    }
    info(&format!(
        "{}{}{} {} ({} resumed) on {} threads in {:.3} s -> {}",
        shard.map(|k| format!("shard {k}: ")).unwrap_or_default(),
        if full { "full model, " } else { "" },
        sw.scales.len(),
        if named { "points" } else { "load scales" },
        sw.resumed,
        sw.threads,
        sw.wall_seconds,
        out.display()
    ));
    if let Some(line) = speedup_summary(sw) {
        info(&line);
    }
    Ok(())
}

/// One line when the full model answered some points in place of the reduced one, or was
/// tried and failed: how many, why (by kind), the first few, and that the warnings after it
/// are about the reduced answers kept.
fn fallback_summary(sw: &flexrom::workflows::sweep::Sweep) -> Option<String> {
    use flexrom::pipeline::fallback::kind;
    use flexrom::workflows::sweep::{runs_noun, ScaleResult};
    let (answered, tried) = (sw.n_fallback(), sw.n_fallback_failed());
    if answered + tried == 0 {
        return None;
    }
    let of = |pick: &dyn Fn(&ScaleResult) -> bool| -> (String, String) {
        let them: Vec<&ScaleResult> = sw.scales.iter().filter(|x| pick(x)).collect();
        let mut kinds: Vec<(&str, usize)> = Vec::new();
        for k in them.iter().filter_map(|x| kind(x.message())) {
            match kinds.iter_mut().find(|(name, _)| *name == k) {
                Some((_, c)) => *c += 1,
                None => kinds.push((k, 1)),
            }
        }
        let kinds = kinds.iter().map(|(name, c)| format!("{c}: {name}")).collect::<Vec<_>>().join(", ");
        let first = them
            .iter()
            .take(3)
            .map(|x| match x.mu.named().next() {
                None => flexrom::rom::trust::short(x.mu.scale()),
                Some(_) => x.mu.to_string(),
            })
            .collect::<Vec<_>>()
            .join(", ");
        (kinds, first)
    };
    let noun = runs_noun(sw.scales.iter().map(|x| &x.mu));
    let one = if noun == "points" { "point" } else { "load scale" };
    let count = |k: usize| format!("{k} {}", if k == 1 { one } else { noun });
    let kept = sw.done().filter(|p| p.fallback.is_none()).count();
    let mut line = String::new();
    if answered > 0 {
        let (kinds, first) = of(&|x| x.point().is_some_and(|p| p.fallback.is_some()));
        line += &format!(
            "the full model answered {answered} of {} in place of the reduced one ({kinds}; first at {first}): exact there, error estimate 0, `/fallback` 1 and why in `/message`",
            count(sw.scales.len())
        );
    }
    if tried > 0 {
        let (kinds, first) = of(&|x| x.point().is_some_and(|p| p.note.is_some()));
        line += &format!(
            "{}at {} the full model was tried in place of the reduced answer and failed too ({kinds}; first at {first}): the reduced answer stands there, `/fallback` 2 and both reasons in `/message`",
            if line.is_empty() { "" } else { "; " },
            count(tried)
        );
    }
    line += &format!("; the warnings below are about the {kept} reduced answers kept");
    // where most points need the full model, running it everywhere is cheaper
    if 2 * answered > sw.scales.len() {
        line += "; most points fell back: `sweep --full` runs the full model at every point without the reduced runs and estimates first";
    }
    Some(line)
}

/// The points of the sweep: `--points FILE`; or the grid of `--param` axes after the load
/// scales (`--load-scales`, else the pipeline's, which a `[parameters]` box pipeline does
/// not have: it needs `--param` or `--points`); or the line of load scales alone.
fn sweep_points(
    p: &Pipeline,
    load_scales: Option<Vec<f64>>,
    params: &[String],
    file: Option<&std::path::Path>,
) -> flexrom::Result<Vec<Parameters>> {
    use flexrom::workflows::points::{grid, parse_axis, read_points_csv};
    let points = if let Some(f) = file {
        let points = read_points_csv(f)?;
        // a misspelt column is the CSV's problem: name its header
        let unknown =
            points[0].named().find_map(|(n, _)| p.model.unknown_parameter(n).map(|why| format!("column `{n}`: {why}")));
        if let Some(problem) = unknown {
            return Err(flexrom::Error::input(f, "header", problem));
        }
        points
    } else if params.is_empty() && p.space().is_empty() {
        let scales = match load_scales {
            Some(v) => v,
            None => p.online_scales(),
        };
        scales.into_iter().map(Parameters::load_scale).collect()
    } else {
        let named = params
            .iter()
            .map(|spec| parse_axis(spec).map_err(|e| flexrom::Error::usage(format!("--param: {e}"))))
            .collect::<flexrom::Result<Vec<_>>>()?;
        let first = match load_scales {
            Some(v) => Some(v),
            // the pipeline's loads, unless --param gives the load scale
            None if p.space().is_empty() && !named.iter().any(|(n, _)| n == LOAD_SCALE) => Some(p.online_scales()),
            None => None,
        };
        let axes: Vec<(String, Vec<f64>)> =
            first.map(|v| (LOAD_SCALE.to_string(), v)).into_iter().chain(named).collect();
        if axes.is_empty() {
            return Err(flexrom::Error::usage(format!(
                "{}: a pipeline with a [parameters] box sweeps the points of `--param NAME=A:B:N` (one per parameter) or `--points FILE`",
                p.path.display()
            )));
        }
        grid(&axes)?
    };
    for mu in &points {
        mu.validate()?;
    }
    super::warn(&p.model.admit(&points, flexrom::model::Runs::Reduced)?);
    // a body property not given is the file's value (online's reason)
    Ok(points.iter().map(|mu| p.model.with_property_values(mu)).collect())
}
