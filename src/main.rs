//! The `flexrom` command line.

use clap::{Parser, Subcommand};
use flexrom::io::atomic::TempPath;
use flexrom::io::output::{check_output, check_report_dir, claim_in_report, Origin};
use flexrom::io::result_file::{write_result, write_result_with};
use flexrom::linalg::kkt::LinearSolverKind;
use flexrom::model::Model;
use flexrom::output::table::{Cell, Format, Table};
use flexrom::output::{self, detail, info, note, Verbosity};
use flexrom::pipeline::dense::DenseChoice;
use flexrom::pipeline::online::load_basis;
use flexrom::pipeline::Pipeline;
use flexrom::simulate::{simulate, Overrides};
use std::path::PathBuf;
use std::process::ExitCode;

/// The exit codes, as `flexrom --help` and every command's `--help` list them (a macro so
/// that `concat!` can put it into the help texts).
macro_rules! exit_codes {
    () => {
        "Exit codes:
  0        success
  1        an error: one line on stderr naming the file and field, or the stage, load scale and time
  2        the command line could not be parsed (unknown option, missing or malformed argument)
  3        sweep, merge, run: some load scales failed; the others are written (/status says which)
  4        --strict: an error estimate is above the tolerance (the output is written first)
  129/130/143  stopped by SIGHUP/SIGINT/SIGTERM (temporary files removed, earlier outputs kept)"
    };
}

#[derive(Parser)]
#[command(
    name = "flexrom",
    version,
    about = "Planar flexible multibody dynamics (ANCF beams) with POD reduced-order models",
    after_help = concat!(
        "Examples:
  flexrom simulate data/models/pendulum.toml -o out/pendulum.h5
  flexrom run pipelines/pendulum.toml                     train, sweep, validate, report
  flexrom train pipelines/double_pendulum.toml
  flexrom sweep pipelines/double_pendulum.toml --load-scales 0.5:1.5:21 --csv > sweep.csv

Results go to stdout (--csv or --json where a command prints them), messages to stderr
(-q: errors and warnings only; -v: timings and Newton statistics too).

",
        exit_codes!()
    )
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// only errors and warnings on stderr (no progress bars, no info lines)
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    quiet: bool,
    /// more detail on stderr: settings, Newton statistics and timings of each run
    #[arg(short, long, global = true)]
    verbose: bool,
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

/// `--csv` / `--json`: how a command prints its results on stdout.
#[derive(clap::Args, Clone, Copy)]
struct FormatArgs {
    /// print the results as CSV on stdout (one header line)
    #[arg(long, conflicts_with = "json")]
    csv: bool,
    /// print the results as JSON on stdout
    #[arg(long)]
    json: bool,
}

impl FormatArgs {
    fn format(self) -> Format {
        Format::from_flags(self.csv, self.json)
    }
}

/// `--dense` / `--no-dense` of `validate` and `run` ([`flexrom::pipeline::dense`]).
#[derive(clap::Args, Clone, Copy)]
struct DenseArgs {
    /// skip the full run with a dense LU (its time and speedup are then empty)
    #[arg(long, conflicts_with = "dense")]
    no_dense: bool,
    /// run the dense-LU comparison even when its matrix is above 256 MiB (skipped by
    /// default there, with a line saying so)
    #[arg(long)]
    dense: bool,
}

impl DenseArgs {
    fn choice(self) -> DenseChoice {
        DenseChoice::from_flags(self.dense, self.no_dense)
    }
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
    #[command(after_help = concat!(
        "Examples:
  flexrom simulate data/models/pendulum.toml -o out/pendulum.h5
  flexrom simulate data/models/fourbar.toml -o fourbar.h5 --t-end 0.5 --solver sparse
  flexrom simulate data/models/pendulum.toml -o p.h5 --load-scale 1.2 --csv > probes.csv

--csv/--json print every probe's position at every step: columns t (s), NAME_x, NAME_y (m).

",
        exit_codes!()
    ))]
    Simulate {
        /// model file (TOML)
        model: PathBuf,
        /// result file (HDF5)
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        run: RunArgs,
        #[command(flatten)]
        format: FormatArgs,
    },
    /// Run the full model at the pipeline's training load scales and write the POD basis (HDF5).
    #[command(after_help = concat!(
        "Examples:
  flexrom train pipelines/double_pendulum.toml                  greedy over its load range
  flexrom train pipelines/pendulum_500.toml --basis bases/p500.h5 --json
  flexrom train pipelines/pendulum_500.toml --snapshots-only --shard 1/2 -o snaps/s1.h5
  flexrom train pipelines/pendulum_500.toml --from-snapshots snaps/s1.h5 snaps/s2.h5

--csv/--json print one record: the basis (or snapshot file), its runs, snapshots, modes and times.

",
        exit_codes!()
    ))]
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
        #[command(flatten)]
        format: FormatArgs,
    },
    /// Run the reduced model at one load scale and write a result file.
    #[command(after_help = concat!(
        "Examples:
  flexrom online pipelines/double_pendulum.toml --load-scale 1.2 -o out/dp_1.2.h5
  flexrom online pipelines/pendulum.toml --load-scale 0.8 -o p.h5 --strict --json

--csv/--json print one record: load scale, modes, steps, time, Newton iterations, error estimate.

",
        exit_codes!()
    ))]
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
        #[command(flatten)]
        format: FormatArgs,
    },
    /// Run full and reduced models at one load scale and report errors and timings.
    #[command(after_help = concat!(
        "Examples:
  flexrom validate pipelines/pendulum.toml --load-scale 1.0
  flexrom validate pipelines/fourbar.toml --load-scale 0.935 --json
  flexrom validate pipelines/pendulum_5000.toml --load-scale 1.0 --no-dense

The full run with a dense LU (the thesis's reference timing) is skipped, with one line on
stderr, when its matrix would exceed 256 MiB or the memory bound; --dense forces it.
--json prints one object (null where not measured), --csv one header line and one row
(arrays as NAME_1, NAME_2, ...).

",
        exit_codes!()
    ))]
    Validate {
        /// pipeline file (TOML)
        pipeline: PathBuf,
        /// multiplies every load marked `scaled` in the model file
        #[arg(long)]
        load_scale: f64,
        #[command(flatten)]
        format: FormatArgs,
        /// basis file (default: the pipeline's `basis`)
        #[arg(long)]
        basis: Option<PathBuf>,
        #[command(flatten)]
        dense: DenseArgs,
        /// exit with code 4 (after writing the output) when an error estimate exceeds the
        /// tolerance ([online] tolerance, default the training tolerance)
        #[arg(long)]
        strict: bool,
    },
    /// Reduced runs at many load scales, in parallel, into one HDF5 file and a table.
    #[command(after_help = concat!(
        "Examples:
  flexrom sweep pipelines/double_pendulum.toml --load-scales 0.5:1.5:21
  flexrom sweep pipelines/pendulum.toml -o out/sweep.h5 --validate --csv > sweep.csv
  flexrom sweep pipelines/fourbar.toml --load-scales 0.8:1.0:40 --shard 2/4 -o parts/part_2.h5
  flexrom sweep pipelines/fourbar.toml -o out/sweep.h5 --resume

--csv/--json print one row per load scale: load_scale, status (0 done, 1 failed, 2 not run),
message, rom_seconds, newton_iterations, step_cuts, error_estimate, estimate_seconds,
extrapolated (and rel_error, max_probe_error (m), full_seconds, speedup with --validate).

",
        exit_codes!()
    ))]
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
        #[command(flatten)]
        format: FormatArgs,
    },
    /// Join the part files of `sweep --shard` into the file one `sweep` writes.
    #[command(after_help = concat!(
        "Examples:
  flexrom merge parts/part_*.h5 -o out/sweep.h5
  flexrom merge parts/part_1.h5 parts/part_3.h5 -o out/sweep.h5 --partial   then sweep --resume

--csv/--json print the merged sweep's table, one row per load scale (as `sweep`).

",
        exit_codes!()
    ))]
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
        #[command(flatten)]
        format: FormatArgs,
    },
    /// Train, sweep, validate and write a report folder (Markdown and SVG plots).
    #[command(after_help = concat!(
        "Examples:
  flexrom run pipelines/pendulum.toml                 report in reports/pendulum
  flexrom run pipelines/pendulum_5000.toml -q         the dense comparison is skipped (n > 5792)
  flexrom run pipelines/fourbar.toml --no-dense --json > validation.json

The summary (summary.md) is printed on stdout; --csv/--json print the validation rows
instead (as the report's validation.json). The dense-LU timing is skipped, with one line on
stderr, when its matrix would exceed 256 MiB or the memory bound; --dense forces it.

",
        exit_codes!()
    ))]
    Run {
        /// pipeline file (TOML)
        pipeline: PathBuf,
        /// exit with code 4 (after writing the output) when an error estimate exceeds the
        /// tolerance ([online] tolerance, default the training tolerance)
        #[arg(long)]
        strict: bool,
        #[command(flatten)]
        dense: DenseArgs,
        #[command(flatten)]
        format: FormatArgs,
    },
    /// Run each model and print its probe positions at a few times.
    #[command(after_help = concat!(
        "Examples:
  flexrom demo data/models/pendulum.toml data/models/fourbar.toml
  flexrom demo data/models/double_pendulum.toml --csv

--csv/--json print one row per model, time and probe: model, t (s), probe, x, y (m).

",
        exit_codes!()
    ))]
    Demo {
        /// model files (TOML)
        models: Vec<PathBuf>,
        #[command(flatten)]
        format: FormatArgs,
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
    output::set_verbosity(match (cli.quiet, cli.verbose) {
        (true, _) => Verbosity::Quiet,
        (_, true) => Verbosity::Verbose,
        _ => Verbosity::Normal,
    });
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
    let start = std::time::Instant::now();
    let outcome = limits.and_then(|l| {
        flexrom::limits::set(l);
        run(cli)
    });
    detail(&format!(
        "flexrom: {:.3} s wall time on {} thread(s)",
        start.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    ));
    match outcome {
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
        Command::Simulate { model, output, run, format } => {
            check_output(&output, Origin::Flag("-o"), &[(&model, "model file")])?;
            let model = Model::load(&model)?;
            let r = simulate(&model, &run.overrides())
                .map_err(|e| e.at_stage("simulate", run.load_scale.unwrap_or(1.0)))?;
            write_result(&output, &r)?;
            info(&format!(
                "{}: {} steps in {:.3} s ({} Newton iterations, {} factorizations, {} step cuts) -> {}",
                model.path.display(),
                r.stats.steps,
                r.wall_seconds,
                r.stats.newton_iterations,
                r.stats.factorizations,
                r.stats.step_cuts,
                output.display()
            ));
            run_details(&r);
            print_table(&flexrom::pipeline::tables::probe_table(&r), format.format(), false)
        }
        Command::Train { pipeline, basis, snapshots_only, load_scale, shard, output, from_snapshots, format } => {
            let p = Pipeline::load(&pipeline)?;
            if snapshots_only {
                let out = output.expect("clap: --snapshots-only requires -o");
                check_output(&out, Origin::Flag("-o"), &[(&p.path, "pipeline file"), (&p.model.path, "model file")])?;
                let scales = flexrom::pipeline::snapshots::job_scales(&p, load_scale, shard)?;
                let (n, secs) = flexrom::pipeline::snapshots::write_snapshots(&p, &scales, &out)?;
                info(&format!(
                    "{}: {n} full run(s) at {scales:?} ({secs:.3} s) -> {}",
                    p.path.display(),
                    out.display()
                ));
                let mut t = Table::new(&["pipeline", "output", "n_runs", "load_scales", "seconds"]);
                let list: Vec<String> = scales.iter().map(|x| x.to_string()).collect();
                t.push(vec![
                    p.path.display().to_string().into(),
                    out.display().to_string().into(),
                    n.into(),
                    list.join(" ").into(),
                    secs.into(),
                ]);
                return print_table(&t, format.format(), true);
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
            info(&format!(
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
            let mut t = Table::new(&[
                "pipeline",
                "basis",
                "n_runs",
                "n_snapshots",
                "full_seconds",
                "variant",
                "snapshots",
                "n_pod_modes",
                "n_joint_coordinates",
                "uncaptured_energy",
            ]);
            t.push(vec![
                p.path.display().to_string().into(),
                out.display().to_string().into(),
                s.n_runs.into(),
                s.n_snapshots.into(),
                s.full_seconds.into(),
                b.variant.name().into(),
                b.snapshots.name().into(),
                b.n_pod_modes.into(),
                b.kept.len().into(),
                s.trained.uncaptured_energy().into(),
            ]);
            print_table(&t, format.format(), true)
        }
        Command::Online { pipeline, load_scale, output, basis, strict, format } => {
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
            info(&format!(
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
                info(&format!("  {}", flexrom::pipeline::estimate::describe(e, run.result.wall_seconds)));
            }
            run_details(&run.result);
            let mut cols = vec!["load_scale", "n_modes"];
            cols.extend(flexrom::pipeline::tables::RUN_COLUMNS);
            cols.extend(["error_estimate", "extrapolated", "output"]);
            let mut t = Table::new(&cols);
            let mut row: Vec<Cell> = vec![load_scale.into(), stored.basis.n_reduced().into()];
            row.extend(flexrom::pipeline::tables::run_cells(&run.result));
            row.extend([
                estimate.as_ref().map(|e| e.error_estimate).into(),
                extrapolated.into(),
                output.display().to_string().into(),
            ]);
            t.push(row);
            print_table(&t, format.format(), true)?;
            flexrom::pipeline::estimate::check_runs(&trust, &[(load_scale, estimate.map(|e| e.error_estimate))], strict)
        }
        Command::Validate { pipeline, load_scale, format, basis, dense, strict } => {
            let p = Pipeline::load(&pipeline)?;
            check_scale(load_scale)?;
            let path = basis.unwrap_or_else(|| p.basis_path.clone());
            let stored = load_basis(&p, &path)?;
            let trust = flexrom::pipeline::estimate::load_trust(&p, &path, &stored)?;
            let with_dense = flexrom::pipeline::dense::decide(dense.choice(), &p.model)?;
            let (v, _, _) = flexrom::pipeline::validate::validate_with(
                &p.model,
                &stored.basis,
                Some(&trust),
                load_scale,
                with_dense,
            )?;
            match format.format() {
                // the record as serde writes it (arrays stay arrays): the keys scripts read
                Format::Json => {
                    let text = serde_json::to_string(&v)
                        .map_err(|e| flexrom::Error::Usage(format!("cannot write the JSON: {e}")))?;
                    output::println(&text)?;
                }
                Format::Csv => output::print(&Table::from_record(&v)?.to_csv()?)?,
                Format::Text => output::println(&v.describe())?,
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
            format,
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
            let options =
                flexrom::pipeline::sweep::SweepOptions { validate, continuation, progress: output::show_progress() };
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
            match format.format() {
                Format::Text => output::print(&flexrom::pipeline::sweep::table(&sw))?,
                f => print_table(&flexrom::pipeline::tables::sweep_table(&sw), f, false)?,
            }
            info(&format!(
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
        Command::Merge { parts, output, partial, format } => {
            let inputs: Vec<(&std::path::Path, &str)> = parts.iter().map(|p| (p.as_path(), "part file")).collect();
            check_output(&output, Origin::Flag("-o"), &inputs)?;
            let m = flexrom::pipeline::merge::merge(&parts, &output, partial)?;
            print_table(&flexrom::pipeline::tables::sweep_table(&m.sweep), format.format(), false)?;
            info(&format!(
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
        Command::Run { pipeline, strict, dense, format } => {
            let p = Pipeline::load(&pipeline)?;
            let dir = flexrom::pipeline::report::run_with(&p, output::show_progress(), dense.choice())?;
            let read = |name: &str| {
                let f = dir.join(name);
                std::fs::read_to_string(&f).map_err(|e| flexrom::Error::io(&f, e))
            };
            match format.format() {
                Format::Text => output::println(&read("summary.md")?)?,
                f => print_table(&Table::from_json_records(&read("validation.json")?)?, f, false)?,
            }
            info(&format!("report: {}", dir.display()));
            flexrom::pipeline::report::check_report(&p, &dir, strict)
        }
        Command::Demo { models, format } => {
            let mut table = Table::new(&["model", "t", "probe", "x", "y"]);
            for path in models {
                let model = Model::load(&path)?;
                let r = simulate(&model, &Overrides::default()).map_err(|e| e.at_stage("demo", 1.0))?;
                run_details(&r);
                let nt = r.t.len();
                if format.format() != Format::Text {
                    for k in [0, nt / 4, nt / 2, 3 * nt / 4, nt - 1] {
                        for (n, xy) in &r.probes {
                            let name = path.display().to_string();
                            table.push(vec![
                                name.into(),
                                r.t[k].into(),
                                n.as_str().into(),
                                xy[[k, 0]].into(),
                                xy[[k, 1]].into(),
                            ]);
                        }
                    }
                    continue;
                }
                output::println(&format!(
                    "{} ({} coordinates, {} steps of {} s, {:.1} ms, {} Newton iterations)",
                    path.display(),
                    r.q.nrows(),
                    r.stats.steps,
                    r.settings.dt,
                    1e3 * r.wall_seconds,
                    r.stats.newton_iterations
                ))?;
                for k in [0, nt / 4, nt / 2, 3 * nt / 4, nt - 1] {
                    let cells: Vec<String> = r
                        .probes
                        .iter()
                        .map(|(n, xy)| format!("{n} = ({:+.5}, {:+.5})", xy[[k, 0]], xy[[k, 1]]))
                        .collect();
                    output::println(&format!("  t = {:.4} s: {}", r.t[k], cells.join("  ")))?;
                }
            }
            print_table(&table, format.format(), false)
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

/// Prints `t` on stdout as CSV or JSON; nothing in text mode (the command's own lines, on
/// stderr or stdout, are its text form). `single`: the command's result is one record,
/// printed in JSON as one object rather than an array of one.
fn print_table(t: &Table, format: Format, single: bool) -> flexrom::Result<()> {
    match format {
        Format::Text => Ok(()),
        Format::Csv => output::print(&t.to_csv()?),
        Format::Json if single => output::println(&t.to_json_object()),
        Format::Json => output::println(&t.to_json()),
    }
}

/// `-v`: the settings and Newton statistics of one run.
fn run_details(r: &flexrom::simulate::SimulationResult) {
    let (s, st) = (&r.settings, &r.stats);
    detail(&format!(
        "  settings: dt {} s, t_end {} s, rho_inf {}, load scale {}, solver {:?}, {} coordinates",
        s.dt,
        s.t_end,
        s.rho_inf,
        s.load_scale,
        s.solver,
        r.q.nrows()
    ));
    detail(&format!(
        "  Newton: {:.2} iterations per step (at most {} in one step), {} factorizations, {} step cuts, {} steps at the round-off floor; {:.3} ms per step",
        st.newton_iterations as f64 / st.steps.max(1) as f64,
        st.max_iterations_in_a_step,
        st.factorizations,
        st.step_cuts,
        st.steps_at_round_off,
        1e3 * r.wall_seconds / st.steps.max(1) as f64
    ));
}
