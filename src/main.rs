//! The `flexrom` command line.

use clap::{Parser, Subcommand};
use flexrom::io::atomic::TempPath;
use flexrom::io::output::{check_output, check_report_dir, claim_in_report, Origin};
use flexrom::io::result_file::{write_result, write_result_with};
use flexrom::linalg::kkt::LinearSolverKind;
use flexrom::model::Model;
use flexrom::output::{self, note};
use flexrom::pipeline::online::load_basis;
use flexrom::pipeline::Pipeline;
use flexrom::simulate::{simulate, Overrides};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "flexrom",
    version,
    about = "Planar flexible multibody dynamics (ANCF beams) with POD reduced-order models"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// memory bound for a stage's big arrays, e.g. 8G, 512M (default: env
    /// FLEXROM_MAX_MEMORY, else half of the machine's memory)
    #[arg(long, global = true, value_name = "SIZE")]
    max_memory: Option<String>,
    /// most time steps a run may take (default: env FLEXROM_MAX_STEPS, else 10000000)
    #[arg(long, global = true, value_name = "N")]
    max_steps: Option<String>,
    /// most elements a model may have (default: env FLEXROM_MAX_ELEMENTS, else 200000)
    #[arg(long, global = true, value_name = "N")]
    max_elements: Option<String>,
    /// a run whose strain or step cuts leave plausible bounds warns instead of failing
    #[arg(long, global = true)]
    allow_blowup: bool,
    /// worker threads (default: env RAYON_NUM_THREADS, else SLURM_CPUS_PER_TASK, else one per core)
    #[arg(long, global = true, value_name = "N")]
    threads: Option<usize>,
}

#[derive(clap::Args)]
struct RunArgs {
    /// time step, s (default: the model file's)
    #[arg(long)]
    dt: Option<f64>,
    /// end time, s (default: the model file's)
    #[arg(long)]
    t_end: Option<f64>,
    /// generalized-α spectral radius ρ∞ in [0, 1] (default: the model file's)
    #[arg(long)]
    rho_inf: Option<f64>,
    /// multiplies every load marked `scaled` in the model file
    #[arg(long)]
    load_scale: Option<f64>,
    /// linear solver of the full model
    #[arg(long, value_enum, default_value_t = LinearSolverKind::Banded)]
    solver: LinearSolverKind,
}

impl RunArgs {
    fn overrides(&self) -> Overrides {
        Overrides {
            dt: self.dt,
            t_end: self.t_end,
            rho_inf: self.rho_inf,
            load_scale: self.load_scale,
            solver: self.solver,
        }
    }
}

#[derive(Subcommand)]
enum Command {
    /// Run the full-order model and write an HDF5 result file.
    Simulate {
        /// model file (TOML)
        model: PathBuf,
        /// result file (HDF5)
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        run: RunArgs,
        /// also print the probe positions as CSV on stdout
        #[arg(long)]
        csv: bool,
    },
    /// Run the full model at the pipeline's training load scales and write the POD basis (HDF5).
    Train {
        /// pipeline file (TOML)
        pipeline: PathBuf,
        /// basis file to write (default: the pipeline's `basis`)
        #[arg(long)]
        basis: Option<PathBuf>,
        /// only run the full model (at --load-scale X, or at the --shard K/N part of
        /// train.load_scales) and write its snapshots to -o; no basis
        #[arg(long, requires = "output", conflicts_with_all = ["from_snapshots", "basis"])]
        snapshots_only: bool,
        /// the load scale of a --snapshots-only run
        #[arg(long, requires = "snapshots_only", conflicts_with = "shard")]
        load_scale: Option<f64>,
        /// `K/N`: the --snapshots-only runs of loads K, K+N, … of train.load_scales
        #[arg(long, value_name = "K/N", requires = "snapshots_only")]
        shard: Option<flexrom::pipeline::shard::Shard>,
        /// snapshot file of --snapshots-only
        #[arg(short, long, requires = "snapshots_only")]
        output: Option<PathBuf>,
        /// build the basis from these snapshot files instead of running the full model
        #[arg(long, num_args = 1.., value_name = "SNAPS.h5")]
        from_snapshots: Vec<PathBuf>,
    },
    /// Run the reduced model at one load scale and write a result file.
    Online {
        /// pipeline file (TOML)
        pipeline: PathBuf,
        /// multiplies every load marked `scaled` in the model file
        #[arg(long)]
        load_scale: f64,
        /// result file (HDF5)
        #[arg(short, long)]
        output: PathBuf,
        /// basis file (default: the pipeline's `basis`)
        #[arg(long)]
        basis: Option<PathBuf>,
        /// exit with code 4 (after writing the output) when an error estimate exceeds the
        /// tolerance ([online] tolerance, default the training tolerance)
        #[arg(long)]
        strict: bool,
    },
    /// Run full and reduced models at one load scale and report errors and timings.
    Validate {
        /// pipeline file (TOML)
        pipeline: PathBuf,
        /// multiplies every load marked `scaled` in the model file
        #[arg(long)]
        load_scale: f64,
        /// print one JSON object on stdout
        #[arg(long)]
        json: bool,
        /// basis file (default: the pipeline's `basis`)
        #[arg(long)]
        basis: Option<PathBuf>,
        /// skip the dense-LU full run (its time and speedup are then null)
        #[arg(long)]
        no_dense: bool,
        /// exit with code 4 (after writing the output) when an error estimate exceeds the
        /// tolerance ([online] tolerance, default the training tolerance)
        #[arg(long)]
        strict: bool,
    },
    /// Reduced runs at many load scales, in parallel, into one HDF5 file and a table.
    Sweep {
        /// pipeline file (TOML)
        pipeline: PathBuf,
        /// `A:B:N`: N load scales from A to B (default: the pipeline's [online] list)
        #[arg(long)]
        load_scales: Option<String>,
        /// also run the full model at each load scale and report errors
        #[arg(long)]
        validate: bool,
        /// continuation in the load scale: each thread takes two contiguous parts of the list
        /// (one from each end) and every run starts its Newton solves from its neighbours'
        /// steps (about 2× fewer iterations on the pendulum). Same step equations and tolerance, but where the
        /// dynamics are sensitive (the four-bar after t ≈ 0.6 s) Newton may settle on
        /// another nearby solution than `online` does; without it every load scale runs on
        /// its own, exactly as `online`
        #[arg(long)]
        continuation: bool,
        /// skip the error estimate (about 2× faster; `/error_estimate` is then NaN)
        #[arg(long)]
        no_estimate: bool,
        /// sweep file (default: sweep.h5 in the pipeline's report folder)
        #[arg(short, long)]
        output: Option<PathBuf>,
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
        shard: Option<flexrom::pipeline::shard::Shard>,
    },
    /// Join the part files of `sweep --shard` into the file one `sweep` writes.
    Merge {
        /// part files (`sweep --shard K/N -o PART.h5`), one per shard, in any order
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// sweep file to write
        #[arg(short, long)]
        output: PathBuf,
        /// merge the parts there are; loads of missing shards or not run are marked
        /// `status` 2 (not run yet), which `sweep --resume` on the merged file runs
        #[arg(long)]
        partial: bool,
    },
    /// Train, sweep, validate and write a report folder (Markdown and SVG plots).
    Run {
        /// pipeline file (TOML)
        pipeline: PathBuf,
        /// exit with code 4 (after writing the output) when an error estimate exceeds the
        /// tolerance ([online] tolerance, default the training tolerance)
        #[arg(long)]
        strict: bool,
    },
    /// Run each model and print its probe positions at a few times.
    Demo {
        /// model files (TOML)
        models: Vec<PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // --help, --version: clap's text on stdout (a closed pipe there is not worth a word)
        Err(e) if !e.use_stderr() => {
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        // a usage error in two lines: clap's first (what is wrong), and where to look
        Err(e) => {
            let text = e.render().to_string();
            note(text.lines().find(|l| !l.trim().is_empty()).unwrap_or("error: bad arguments"));
            note("run `flexrom --help` (or `flexrom <command> --help`) for usage");
            return ExitCode::from(2);
        }
    };
    // from here on SIGINT/SIGTERM/SIGHUP remove flexrom's temporary files and exit with 130/143/129
    if let Err(e) = flexrom::io::atomic::install_signal_handler() {
        note(&format!("error: {e}"));
        return ExitCode::FAILURE;
    }
    flexrom::single_threaded_blas();
    if let Err(e) = flexrom::pipeline::shard::configure_threads(cli.threads) {
        note(&format!("error: {e}"));
        return ExitCode::from(e.exit_code());
    }
    let limits = flexrom::limits::from_env(
        cli.max_memory.as_deref(),
        cli.max_steps.as_deref(),
        cli.max_elements.as_deref(),
        cli.allow_blowup,
    );
    match limits.and_then(|l| {
        flexrom::limits::set(l);
        run(cli)
    }) {
        Ok(()) => ExitCode::SUCCESS,
        // the reader of stdout went away (`| head`): nothing to say, and no one to say it to
        Err(flexrom::Error::StdoutClosed) => ExitCode::SUCCESS,
        Err(e) => {
            note(&format!("error: {e}"));
            ExitCode::from(e.exit_code())
        }
    }
}

fn run(cli: Cli) -> flexrom::Result<()> {
    match cli.command {
        Command::Simulate { model, output, run, csv } => {
            check_output(&output, Origin::Flag("-o"), &[(&model, "model file")])?;
            let model = Model::load(&model)?;
            let r = simulate(&model, &run.overrides())
                .map_err(|e| e.at_stage("simulate", run.load_scale.unwrap_or(1.0)))?;
            write_result(&output, &r)?;
            note(&format!(
                "{}: {} steps in {:.3} s ({} Newton iterations, {} factorizations, {} step cuts) -> {}",
                model.path.display(),
                r.stats.steps,
                r.wall_seconds,
                r.stats.newton_iterations,
                r.stats.factorizations,
                r.stats.step_cuts,
                output.display()
            ));
            if csv {
                print_csv(&r)?;
            }
            Ok(())
        }
        Command::Train { pipeline, basis, snapshots_only, load_scale, shard, output, from_snapshots } => {
            let p = Pipeline::load(&pipeline)?;
            if snapshots_only {
                let out = output.expect("clap: --snapshots-only requires -o");
                check_output(&out, Origin::Flag("-o"), &[(&p.path, "pipeline file"), (&p.model.path, "model file")])?;
                let scales = flexrom::pipeline::snapshots::job_scales(&p, load_scale, shard)?;
                let (n, secs) = flexrom::pipeline::snapshots::write_snapshots(&p, &scales, &out)?;
                note(&format!(
                    "{}: {n} full run(s) at {scales:?} ({secs:.3} s) -> {}",
                    p.path.display(),
                    out.display()
                ));
                return Ok(());
            }
            let origin =
                if basis.is_some() { Origin::Flag("--basis") } else { Origin::Key { pipeline: &p.path, key: "basis" } };
            let out = basis.clone().unwrap_or_else(|| p.basis_path.clone());
            check_output(&out, origin, &[(&p.path, "pipeline file"), (&p.model.path, "model file")])?;
            // trained into a temporary file, read back and checked, and only then renamed over
            // the previous basis
            let staged = TempPath::file_for(&out)?;
            let s = if from_snapshots.is_empty() {
                flexrom::pipeline::train::train_and_write(&p, staged.path())?
            } else {
                for f in &from_snapshots {
                    if flexrom::io::output::resolve(f) == flexrom::io::output::resolve(&out) {
                        return Err(flexrom::Error::input(&out, "--basis", "is one of the --from-snapshots files"));
                    }
                }
                let (data, s) = flexrom::pipeline::snapshots::train_from_snapshots(&p, &from_snapshots)?;
                flexrom::pipeline::train::write_trained(&p, staged.path(), &data, &s)?;
                s
            };
            load_basis(&p, staged.path())?;
            staged.commit()?;
            let b = &s.trained.basis;
            note(&format!(
                "{}: {} snapshots from {} full run(s) ({:.3} s); {} basis, {} snapshots, {} POD modes{} (captured energy 1 − {:.2e}) -> {}",
                p.path.display(),
                s.n_snapshots,
                s.n_runs,
                s.full_seconds,
                b.variant.name(),
                b.snapshots.name(),
                b.n_pod_modes,
                if b.kept.is_empty() { String::new() } else { format!(" + {} joint coordinates", b.kept.len()) },
                s.trained.uncaptured_energy(),
                out.display()
            ));
            Ok(())
        }
        Command::Online { pipeline, load_scale, output, basis, strict } => {
            let p = Pipeline::load(&pipeline)?;
            check_scale(load_scale)?;
            let path = basis.unwrap_or_else(|| p.basis_path.clone());
            check_output(
                &output,
                Origin::Flag("-o"),
                &[(&p.path, "pipeline file"), (&p.model.path, "model file"), (&path, "basis file")],
            )?;
            let stored = load_basis(&p, &path)?;
            let trust = flexrom::pipeline::estimate::load_trust(&p, &path, &stored)?;
            let mut runner =
                flexrom::pipeline::estimate::EstimatingRunner::new(&p.model, &stored.basis, trust.estimator.as_ref())?;
            let (run, estimate) = runner
                .run(load_scale, flexrom::pipeline::online::Output::Full)
                .map_err(|e| e.at_stage("online", load_scale))?;
            let extrapolated = flexrom::pipeline::estimate::is_extrapolated(trust.range, load_scale);
            let basis_name = path.display().to_string();
            write_result_with(&output, &run.result, |f| {
                let e = |err: hdf5::Error| flexrom::Error::hdf5(&output, err);
                flexrom::io::result_file::write_reduced(f, &run.reduced_q).map_err(e)?;
                flexrom::io::h5::attr_str(f, "basis", &basis_name).map_err(e)?;
                flexrom::io::h5::attr_str(f, "variant", stored.basis.variant.name()).map_err(e)?;
                flexrom::io::h5::attr_u64(f, "n_modes", stored.basis.n_reduced() as u64).map_err(e)?;
                flexrom::pipeline::estimate::write_run_attributes(f, estimate.as_ref(), &trust, extrapolated).map_err(e)
            })?;
            let st = &run.result.stats;
            note(&format!(
                "{}: reduced run ({} modes) at load scale {load_scale}: {} steps in {:.4} s ({} Newton iterations, {} step cuts) -> {}",
                p.path.display(),
                stored.basis.n_reduced(),
                st.steps,
                run.result.wall_seconds,
                st.newton_iterations,
                st.step_cuts,
                output.display()
            ));
            if let Some(e) = &estimate {
                note(&format!("  {}", flexrom::pipeline::estimate::describe(e, run.result.wall_seconds)));
            }
            flexrom::pipeline::estimate::check_runs(&trust, &[(load_scale, estimate.map(|e| e.error_estimate))], strict)
        }
        Command::Validate { pipeline, load_scale, json, basis, no_dense, strict } => {
            let p = Pipeline::load(&pipeline)?;
            check_scale(load_scale)?;
            let path = basis.unwrap_or_else(|| p.basis_path.clone());
            let stored = load_basis(&p, &path)?;
            let trust = flexrom::pipeline::estimate::load_trust(&p, &path, &stored)?;
            let (v, _, _) = flexrom::pipeline::validate::validate_with(
                &p.model,
                &stored.basis,
                Some(&trust),
                load_scale,
                !no_dense,
            )?;
            if json {
                let text = serde_json::to_string(&v)
                    .map_err(|e| flexrom::Error::Usage(format!("cannot write the JSON: {e}")))?;
                output::println(&text)?;
            } else {
                output::println(&v.describe())?;
            }
            flexrom::pipeline::estimate::check_runs(&trust, &[(load_scale, v.error_estimate)], strict)
        }
        Command::Sweep {
            pipeline,
            load_scales,
            validate,
            continuation,
            no_estimate,
            output,
            basis,
            resume,
            strict,
            shard,
        } => {
            let p = Pipeline::load(&pipeline)?;
            if shard.is_some() && output.is_none() {
                return Err(flexrom::Error::Usage(
                    "--shard needs -o PART.h5: every shard writes its own part file".into(),
                ));
            }
            let scales = match load_scales {
                Some(s) => flexrom::pipeline::config::parse_range(&s)
                    .map_err(|e| flexrom::Error::Usage(format!("--load-scales: {e}")))?,
                None => p.online_scales(),
            };
            let path = basis.unwrap_or_else(|| p.basis_path.clone());
            let inputs = [
                (p.path.as_path(), "pipeline file"),
                (p.model.path.as_path(), "model file"),
                (path.as_path(), "basis file"),
            ];
            // the default goes into the pipeline's report folder, which must then be flexrom's
            let in_report = output.is_none();
            let out = output.unwrap_or_else(|| p.report_dir.join("sweep.h5"));
            if in_report {
                check_report_dir(&p.report_dir, &p.path, &inputs)?;
                check_output(&out, Origin::Key { pipeline: &p.path, key: "report" }, &inputs)?;
            } else {
                check_output(&out, Origin::Flag("-o"), &inputs)?;
            }
            let stored = load_basis(&p, &path)?;
            let options = flexrom::pipeline::sweep::SweepOptions { validate, continuation, progress: true };
            let mut trust = flexrom::pipeline::estimate::load_trust(&p, &path, &stored)?;
            if no_estimate {
                if strict {
                    return Err(flexrom::Error::Usage("--strict needs the error estimate; drop --no-estimate".into()));
                }
                trust.estimator = None;
                trust.skipped = true;
            }
            if in_report {
                claim_in_report(&p.report_dir, &p.path, "sweep.h5")?;
            }
            let sw = match shard {
                Some(k) => flexrom::pipeline::shard::sweep_shard(
                    &p,
                    &stored,
                    Some(&trust),
                    &path,
                    &scales,
                    k,
                    options,
                    &out,
                    resume,
                )?,
                None => flexrom::pipeline::sweep::sweep_to_file(
                    &p.model,
                    &stored,
                    Some(&trust),
                    &path,
                    &scales,
                    options,
                    &out,
                    resume,
                )?,
            };
            output::print(&flexrom::pipeline::sweep::table(&sw))?;
            note(&format!(
                "{}{} load scales ({} resumed) on {} threads in {:.3} s -> {}",
                shard.map(|k| format!("shard {k}: ")).unwrap_or_default(),
                sw.scales.len(),
                sw.resumed,
                sw.threads,
                sw.wall_seconds,
                out.display()
            ));
            // the good runs are written; the exit code (3) says that some failed
            if let Some(s) = sw.failure_summary() {
                return Err(flexrom::Error::PartlyFailed(format!(
                    "{s} (the others are in {}; /status and /message say which)",
                    out.display()
                )));
            }
            let runs: Vec<(f64, Option<f64>)> = sw
                .scales
                .iter()
                .filter_map(|x| x.point())
                .map(|q| (q.rom.result.settings.load_scale, q.estimate.map(|e| e.error_estimate)))
                .collect();
            flexrom::pipeline::estimate::check_runs(&trust, &runs, strict)
        }
        Command::Merge { parts, output, partial } => {
            let inputs: Vec<(&std::path::Path, &str)> = parts.iter().map(|p| (p.as_path(), "part file")).collect();
            check_output(&output, Origin::Flag("-o"), &inputs)?;
            let m = flexrom::pipeline::merge::merge(&parts, &output, partial)?;
            note(&format!(
                "{} parts, {} load scales ({} not run) -> {}",
                m.parts,
                m.sweep.scales.len(),
                m.gaps,
                output.display()
            ));
            if let Some(s) = m.sweep.failure_summary() {
                return Err(flexrom::Error::PartlyFailed(format!(
                    "{s} (the others are in {}; /status and /message say which)",
                    output.display()
                )));
            }
            Ok(())
        }
        Command::Run { pipeline, strict } => {
            let p = Pipeline::load(&pipeline)?;
            let dir = flexrom::pipeline::report::run(&p, true)?;
            output::println(
                &std::fs::read_to_string(dir.join("summary.md")).map_err(|e| flexrom::Error::io(&dir, e))?,
            )?;
            note(&format!("report: {}", dir.display()));
            flexrom::pipeline::report::check_report(&p, &dir, strict)
        }
        Command::Demo { models } => {
            for path in models {
                let model = Model::load(&path)?;
                let r = simulate(&model, &Overrides::default()).map_err(|e| e.at_stage("demo", 1.0))?;
                output::println(&format!(
                    "{} ({} coordinates, {} steps of {} s, {:.1} ms, {} Newton iterations)",
                    path.display(),
                    r.q.nrows(),
                    r.stats.steps,
                    r.settings.dt,
                    1e3 * r.wall_seconds,
                    r.stats.newton_iterations
                ))?;
                let nt = r.t.len();
                for k in [0, nt / 4, nt / 2, 3 * nt / 4, nt - 1] {
                    let cells: Vec<String> = r
                        .probes
                        .iter()
                        .map(|(n, xy)| format!("{n} = ({:+.5}, {:+.5})", xy[[k, 0]], xy[[k, 1]]))
                        .collect();
                    output::println(&format!("  t = {:.4} s: {}", r.t[k], cells.join("  ")))?;
                }
            }
            Ok(())
        }
    }
}

fn check_scale(x: f64) -> flexrom::Result<()> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(flexrom::Error::Usage(format!("--load-scale must be finite, got {x}")))
    }
}

/// The probe positions as CSV on stdout, buffered; a closed pipe or a full disk is an
/// error value (see `flexrom::output`), never a panic.
fn print_csv(r: &flexrom::simulate::SimulationResult) -> flexrom::Result<()> {
    use std::io::Write;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let mut header = vec!["t".to_string()];
    for (n, _) in &r.probes {
        header.push(format!("{n}_x"));
        header.push(format!("{n}_y"));
    }
    writeln!(out, "{}", header.join(",")).map_err(output::stdout_error)?;
    for k in 0..r.t.len() {
        let mut row = vec![format!("{}", r.t[k])];
        for (_, xy) in &r.probes {
            row.push(format!("{}", xy[[k, 0]]));
            row.push(format!("{}", xy[[k, 1]]));
        }
        writeln!(out, "{}", row.join(",")).map_err(output::stdout_error)?;
    }
    out.flush().map_err(output::stdout_error)
}
