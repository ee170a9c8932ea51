//! The `flexrom` command line.

mod cli;

use clap::{Parser, Subcommand};
use flexrom::output::{self, detail, note, verbosity, Verbosity};
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
  flexrom sweep pipelines/double_pendulum.toml --load-scales 0.5:1.5:21 -o out/dp.h5 --csv > sweep.csv

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
    #[arg(long, global = true, value_name = "SIZE", allow_negative_numbers = true)]
    max_memory: Option<String>,
    /// most time steps a run may take (default: env FLEXROM_MAX_STEPS, else 10000000)
    #[arg(long, global = true, value_name = "N", allow_negative_numbers = true)]
    max_steps: Option<String>,
    /// most elements a model may have (default: env FLEXROM_MAX_ELEMENTS, else 200000)
    #[arg(long, global = true, value_name = "N", allow_negative_numbers = true)]
    max_elements: Option<String>,
    /// a run whose strain or step cuts leave plausible bounds warns instead of failing
    #[arg(long, global = true)]
    allow_blowup: bool,
    /// worker threads (default: env RAYON_NUM_THREADS, else SLURM_CPUS_PER_TASK, else one per core)
    #[arg(long, global = true, value_name = "N", allow_negative_numbers = true)]
    threads: Option<usize>,
}

#[derive(Subcommand)]
enum Command {
    /// Run the full-order model and write an HDF5 result file.
    #[command(after_help = concat!(
        "Examples:
  flexrom simulate data/models/pendulum.toml -o out/pendulum.h5
  flexrom simulate data/models/fourbar.toml -o fourbar.h5 --t-end 0.5 --solver sparse
  flexrom simulate data/models/pendulum.toml -o p.h5 --load-scale 1.2 --csv > probes.csv
  flexrom simulate data/models/pendulum.toml --load-scale -1 --csv > reversed.csv   no file

--csv/--json print every probe's position at every step: columns t (s), NAME_x, NAME_y (m),
then NAME_strain (1) and NAME_curvature (1/m) of the probes that record them; with either,
-o may be left out (nothing is written then).

",
        exit_codes!()
    ))]
    Simulate(cli::simulate::Args),
    /// Static equilibrium under the model's loads (load stepping), written as a result file.
    #[command(after_help = concat!(
        "Examples:
  flexrom statics data/models/pendulum.toml -o out/pendulum_static.h5
  flexrom statics cantilever.toml -o s.h5 --steps 10 --load-scale 2
  flexrom statics data/models/fourbar.toml -o s.h5 --time 0.3 --csv

The loads (gravity, forces, moments at --time T, default 0) are applied in --steps equal
steps, each solved by Newton from the last equilibrium and halved where Newton fails. The
result file has one row per load step (the equilibrium last; /load_factor says which), with
the probes, multipliers and energies. A mechanism whose loads drive a free motion has no
equilibrium: the error names the motion. --csv/--json print one row per load step: t (s),
load_factor, the probes' NAME_x, NAME_y (m) (strain, curvature), energy_* (J).

",
        exit_codes!()
    ))]
    Statics(cli::statics::Args),
    /// Natural frequencies and mode shapes, linearized at the initial or static configuration.
    #[command(after_help = concat!(
        "Examples:
  flexrom modes data/models/pendulum.toml --count 6
  flexrom modes cantilever.toml --count 3 --json
  flexrom modes data/models/pendulum.toml --at static --count 4 -o out/modes.h5
  flexrom modes data/models/pendulum_5000.toml --count 10 --csv

K_T φ = ω² M φ in the null space of the constraints (K_T the tangent stiffness with its
geometric part), the lowest --count modes by shift-invert subspace iteration; rigid-body
modes have frequency 0. --json prints {\"frequencies\": [Hz, ascending], \"omega_squared\",
\"rigid\", \"iterations\", \"seconds\"}; --csv one row per mode: mode, frequency (Hz),
omega_squared (1/s²), rigid (0/1). -o writes the modes file (docs/file-formats.md).

",
        exit_codes!()
    ))]
    Modes(cli::modes::Args),
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
    Train(cli::train::Args),
    /// Run the reduced model at one load scale and write a result file.
    #[command(after_help = concat!(
        "Examples:
  flexrom online pipelines/double_pendulum.toml --load-scale 1.2 -o out/dp_1.2.h5
  flexrom online pipelines/pendulum.toml --load-scale 0.8 -o p.h5 --strict --json

--csv/--json print one record: load scale, modes, steps, time, Newton iterations, error estimate.

",
        exit_codes!()
    ))]
    Online(cli::online::Args),
    /// Run full and reduced models at a load scale (or the pipeline's [validate] loads) and report errors and timings.
    #[command(after_help = concat!(
        "Examples:
  flexrom validate pipelines/pendulum.toml --load-scale 1.0
  flexrom validate pipelines/fourbar.toml --load-scale 0.935 --json
  flexrom validate pipelines/double_pendulum.toml --json      at every [validate] load
  flexrom validate pipelines/pendulum_5000.toml --load-scale 1.0 --no-dense

Without --load-scale every load of the pipeline's [validate] load_scales is validated in
turn (default: the training loads). The full run with a dense LU (the thesis's reference
timing) is skipped, with one line on stderr, when its matrix would exceed 256 MiB, its work
half a minute (steps · n³/3 > 2e11 flops) or the memory bound; --dense forces it. --json prints one object (null where not measured) for
--load-scale, else an array of them, one per load, as the report's validation.json; --csv
one header line and one row per load (arrays as NAME_1, NAME_2, ...).

",
        exit_codes!()
    ))]
    Validate(cli::validate::Args),
    /// Reduced (or, with --full, full) runs at many load scales, in parallel, into one HDF5
    /// file and a table.
    #[command(after_help = concat!(
        "Examples:
  flexrom sweep pipelines/double_pendulum.toml --load-scales 0.5:1.5:21 -o out/dp_sweep.h5
  flexrom sweep pipelines/pendulum.toml -o out/sweep.h5 --validate --csv > sweep.csv
  flexrom sweep pipelines/fourbar.toml --load-scales 0.8:1.0:40 --shard 2/4 -o parts/part_2.h5
  flexrom sweep pipelines/fourbar.toml -o out/sweep.h5 --resume
  flexrom sweep pipelines/fourbar.toml --load-scales 0.8:1.2:100 --full -o out/full.h5

-o is required: the pipeline's report folder holds the sweep.h5 of `flexrom run`, which the
report's summary.md describes, and a plain sweep does not replace it.

--full runs the full model instead (exact: no basis, no estimate, nothing to validate, so
--validate, --continuation, --no-estimate, --strict and --basis are refused with it); on
small meshes it is the faster route, and `online`/`sweep` say so when the basis's timing
shows it. --resume, --shard and merge work alike (a full sweep does not resume from, or
merge with, a reduced one).

--csv/--json print one row per load scale: load_scale, status (0 done, 1 failed, 2 not run),
message, rom_seconds, newton_iterations, step_cuts, error_estimate, estimate_seconds,
extrapolated (and rel_error, max_probe_error (m), full_seconds, speedup with --validate;
--full: load_scale, status, message, full_seconds, newton_iterations, step_cuts).

",
        exit_codes!()
    ))]
    Sweep(cli::sweep::Args),
    /// Join the part files of `sweep --shard` into the file one `sweep` writes.
    #[command(after_help = concat!(
        "Examples:
  flexrom merge parts/part_*.h5 -o out/sweep.h5
  flexrom merge parts/part_1.h5 parts/part_3.h5 -o out/sweep.h5 --partial   then sweep --resume

--csv/--json print the merged sweep's table, one row per load scale (as `sweep`).

",
        exit_codes!()
    ))]
    Merge(cli::merge::Args),
    /// Train (or reuse a current basis), sweep, validate and write a report folder (Markdown,
    /// SVG and PNG plots).
    #[command(after_help = concat!(
        "Examples:
  flexrom run pipelines/pendulum.toml                 report in reports/pendulum
  flexrom run pipelines/pendulum_5000.toml -q         the dense comparison is skipped (n > 5792)
  flexrom run pipelines/fourbar.toml --no-dense --json > validation.json

A basis trained from this model with the pipeline's [train]/[reduction]/[parameters] keys,
that passes its checks, is reused (one line says so); --retrain trains again.
The summary (summary.md) is printed on stdout; --csv/--json print the validation rows
instead (as the report's validation.json). The dense-LU timing is skipped, with one line on
stderr, when its matrix would exceed 256 MiB, its work half a minute (steps · n³/3 > 2e11
flops) or the memory bound; --dense forces it.

",
        exit_codes!()
    ))]
    Run(cli::run::Args),
    /// Draw a result file's motion (or a sweep file's run) as an animated GIF (deformed centre lines, joints, probes).
    #[command(after_help = concat!(
        "Examples:
  flexrom animate out/pendulum.h5 -o out/pendulum.gif
  flexrom animate full.h5 --compare reduced.h5 -o compare.gif --fps 25 --size 800x500
  flexrom animate out/p5000.h5 -o p5000.gif --max-frames 100 --size 480
  flexrom animate out/sweep.h5 --load-scale 1.2 -o at_1.2.gif
  flexrom animate out/box_sweep.h5 --point 7 -o point_7.gif --compare full_7.h5

The centre lines are drawn from the elements' cubic interpolation (4 points an element; a
big mesh evenly subsampled along its bodies), ground pins as triangles, pins as rings,
clamps as squares, sliders as hollow squares on their rails, welds as diamonds, drives as
double rings, springs as zig-zags (torsional: spirals), point masses as discs, probes as
crosses, on equal axes fitted to the whole motion. A long run is shown at --max-frames
evenly spaced instants. A reduced result (`online`) holds its reconstructed coordinates and
is drawn alike; a reduced sweep file is drawn at one of its runs (--load-scale L, or --point K
where several points share a load scale), reconstructed on the basis it names. A full sweep
keeps probes only: animate `flexrom simulate MODEL --load-scale L -o run.h5` instead. -o
must end in .gif; an existing file there is replaced only when it is an animation flexrom
wrote.

",
        exit_codes!()
    ))]
    Animate(cli::animate::Args),
    /// Run each model and print its probe positions at a few times.
    #[command(after_help = concat!(
        "Examples:
  flexrom demo data/models/pendulum.toml data/models/fourbar.toml
  flexrom demo data/models/double_pendulum.toml --csv

--csv/--json print one row per model, time and probe: model, t (s), probe, x, y (m).

",
        exit_codes!()
    ))]
    Demo(cli::demo::Args),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // --help, --version: clap's text on stdout (a closed pipe there is not worth a word)
        Err(e) if !e.use_stderr() => {
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        // a usage error as clap words it: what is wrong (the argument named, a "did you
        // mean" tip for a misspelt one), the usage line and where to read more; even under -q
        Err(e) => {
            let _ = e.print();
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
    // the library sets OpenBLAS to one thread at its first LAPACK call; called here too, it
    // joins at once the workers a user's OPENBLAS_NUM_THREADS=N started, in commands that
    // never reach LAPACK as well
    flexrom::single_threaded_blas();
    if let Err(e) = flexrom::workflows::shard::configure_threads(cli.threads) {
        note(&format!("error: {}", cli::message(&e)));
        return ExitCode::from(e.exit_code());
    }
    let limits = flexrom::limits::from_env(
        cli.max_memory.as_deref(),
        cli.max_steps.as_deref(),
        cli.max_elements.as_deref(),
        cli.allow_blowup,
    );
    let start = std::time::Instant::now();
    let outcome = limits.and_then(|l| run(cli, &l));
    // built only when shown: asking rayon for its thread count starts its global pool
    // (cgroup reads, two threads) at the end of every command otherwise
    if verbosity() >= Verbosity::Verbose {
        detail(&format!(
            "flexrom: {:.3} s wall time on {} thread(s)",
            start.elapsed().as_secs_f64(),
            rayon::current_num_threads()
        ));
    }
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        // the reader of stdout went away (`| head`): nothing to say, and no one to say it to
        Err(flexrom::Error::StdoutClosed) => ExitCode::SUCCESS,
        // a first signal stopped a sweep's runs; the note says what its file keeps
        Err(flexrom::Error::Interrupted) if flexrom::io::atomic::stopped_by().is_some() => {
            let (sig, name) = flexrom::io::atomic::stopped_by().expect("checked");
            note(&format!("flexrom: stopped by {name}"));
            if let Some(line) = flexrom::io::atomic::stop_note() {
                note(&format!("flexrom: {line}"));
            }
            ExitCode::from((128 + sig) as u8)
        }
        Err(e) => {
            // strict checking: what would have been warned of is said before the error
            if let flexrom::Error::Strict { warnings, .. } = &e {
                cli::warn(warnings);
            }
            // a check made while a stage ran names its field without the line load-time
            // checks give: the line from the file
            let e = flexrom::model::with_field_line_from_file(e);
            // one line whatever a file's text put into it (an attribute's newline, an
            // escape sequence)
            note(&format!("error: {}", flexrom::error::show_text(&cli::message(&e))));
            ExitCode::from(e.exit_code())
        }
    }
}

fn run(cli: Cli, limits: &flexrom::limits::Limits) -> flexrom::Result<()> {
    match cli.command {
        Command::Simulate(a) => a.run(limits),
        Command::Statics(a) => a.run(limits),
        Command::Modes(a) => a.run(limits),
        Command::Train(a) => a.run(limits),
        Command::Online(a) => a.run(limits),
        Command::Validate(a) => a.run(limits),
        Command::Sweep(a) => a.run(limits),
        Command::Merge(a) => a.run(limits),
        Command::Run(a) => a.run(limits),
        Command::Demo(a) => a.run(limits),
        Command::Animate(a) => a.run(limits),
    }
}

/// Sets `OPENBLAS_NUM_THREADS=1` unless the user set it, before OpenBLAS's constructor runs.
///
/// OpenBLAS is linked statically (build.rs), so its constructor `gotoblas_init` runs before
/// `main`, reads this variable, and without it starts one worker thread per extra core, which
/// costs ~0.5 ms of a 2 ms start on a busy machine (thread start, and a join at exit).
/// `gotoblas_init` sits in the plain `.init_array`; GNU ld places the prioritized
/// `.init_array.NNNNN` sections before it (sorted by priority; 101 is the first one not
/// reserved for the C runtime), and libc is initialized before any of them, so the variable
/// set here stays set (in `.preinit_array` it would not: libc resets `environ` after it).
/// It lives in the binary, not the library: a process that loads the library for other
/// reasons (a Python interpreter with numpy's own OpenBLAS, say) has threads of its own,
/// and setting the environment there is not sound; such a process calls
/// [`flexrom::single_threaded_blas`] instead.
#[used]
#[link_section = ".init_array.00101"]
static BLAS_ONE_THREAD_AT_START: extern "C" fn() = blas_one_thread_at_start;

extern "C" fn blas_one_thread_at_start() {
    if std::env::var_os("OPENBLAS_NUM_THREADS").is_none() {
        // the process is still single-threaded here, which set_var requires
        std::env::set_var("OPENBLAS_NUM_THREADS", "1");
    }
}
