//! The `flexrom` command line.

use clap::{Parser, Subcommand};
use flexrom::io::result_file::write_result;
use flexrom::model::Model;
use flexrom::simulate::{simulate, Overrides};
use flexrom::solver::kkt::LinearSolverKind;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "flexrom", version, about = "Planar flexible multibody dynamics (ANCF beams) with POD reduced-order models")]
struct Cli {
    #[command(subcommand)]
    command: Command,
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
        Overrides { dt: self.dt, t_end: self.t_end, rho_inf: self.rho_inf, load_scale: self.load_scale, solver: self.solver }
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
    /// Run each model and print its probe positions at a few times.
    Demo {
        /// model files (TOML)
        models: Vec<PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    flexrom::single_threaded_blas();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> flexrom::Result<()> {
    match cli.command {
        Command::Simulate { model, output, run, csv } => {
            let model = Model::load(&model)?;
            check_output_dir(&output)?;
            let r = simulate(&model, &run.overrides())?;
            write_result(&output, &r)?;
            eprintln!(
                "{}: {} steps in {:.3} s ({} Newton iterations, {} factorizations, {} step cuts) -> {}",
                model.path.display(),
                r.stats.steps,
                r.wall_seconds,
                r.stats.newton_iterations,
                r.stats.factorizations,
                r.stats.step_cuts,
                output.display()
            );
            if csv {
                print_csv(&r);
            }
            Ok(())
        }
        Command::Demo { models } => {
            for path in models {
                let model = Model::load(&path)?;
                let r = simulate(&model, &Overrides::default())?;
                println!(
                    "{} ({} coordinates, {} steps of {} s, {:.1} ms, {} Newton iterations)",
                    path.display(),
                    r.q.nrows(),
                    r.stats.steps,
                    r.settings.dt,
                    1e3 * r.wall_seconds,
                    r.stats.newton_iterations
                );
                let nt = r.t.len();
                for k in [0, nt / 4, nt / 2, 3 * nt / 4, nt - 1] {
                    let cells: Vec<String> =
                        r.probes.iter().map(|(n, xy)| format!("{n} = ({:+.5}, {:+.5})", xy[[k, 0]], xy[[k, 1]])).collect();
                    println!("  t = {:.4} s: {}", r.t[k], cells.join("  "));
                }
            }
            Ok(())
        }
    }
}

fn check_output_dir(output: &std::path::Path) -> flexrom::Result<()> {
    if let Some(d) = output.parent() {
        if !d.as_os_str().is_empty() && !d.is_dir() {
            return Err(flexrom::Error::input(output, "-o", format!("directory `{}` does not exist", d.display())));
        }
    }
    Ok(())
}

fn print_csv(r: &flexrom::simulate::SimulationResult) {
    let mut header = vec!["t".to_string()];
    for (n, _) in &r.probes {
        header.push(format!("{n}_x"));
        header.push(format!("{n}_y"));
    }
    println!("{}", header.join(","));
    for k in 0..r.t.len() {
        let mut row = vec![format!("{}", r.t[k])];
        for (_, xy) in &r.probes {
            row.push(format!("{}", xy[[k, 0]]));
            row.push(format!("{}", xy[[k, 1]]));
        }
        println!("{}", row.join(","));
    }
}
