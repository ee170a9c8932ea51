//! `flexrom statics`: the static equilibrium of a model file under its loads, by load
//! stepping, written as a result file (one row per load step, the equilibrium last).

use super::{print_table, FormatArgs};
use flexrom::analysis::statics::StaticOptions;
use flexrom::io::attrs::Kind;
use flexrom::io::output::{check_output, Origin};
use flexrom::io::result_file::{write_statics, ResultFile, RunPlan};
use flexrom::limits::Limits;
use flexrom::model::Model;
use flexrom::output::info;
use flexrom::output::table::Cell;
use std::path::PathBuf;

/// The arguments of `flexrom statics`.
#[derive(clap::Args)]
pub struct Args {
    /// model file (TOML)
    model: PathBuf,
    /// result file (HDF5); may be left out with --csv or --json
    #[arg(short, long, required_unless_present_any = ["csv", "json"])]
    output: Option<PathBuf>,
    #[command(flatten)]
    loads: LoadArgs,
    /// number of equal load steps to the full load (each halved where Newton fails)
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    steps: usize,
    /// linear solver
    #[arg(long, value_enum, default_value_t = super::values::Solver::Banded)]
    solver: super::values::Solver,
    /// also write ParaView's view beside the result: the deformed centre lines at every
    /// instant (4 points an element) with strain, curvature and velocity, in the result
    /// file's /paraview and an XDMF file of the same stem (out.h5 → out.xdmf)
    #[arg(long, requires = "output")]
    paraview: bool,
    #[command(flatten)]
    format: FormatArgs,
}

/// `--load-scale`, `--param` and `--time`: the loads a static analysis takes.
#[derive(clap::Args)]
pub struct LoadArgs {
    /// multiplies every load marked `scaled` in the model file
    #[arg(long, allow_negative_numbers = true)]
    load_scale: Option<f64>,
    #[command(flatten)]
    params: super::ParamArgs,
    /// the time at which the loads are taken, s (within the model's run)
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    time: f64,
}

impl LoadArgs {
    pub fn parameters(&self) -> flexrom::Result<flexrom::solver::parameters::Parameters> {
        self.params.parameters(self.load_scale, 1.0)
    }

    pub fn time(&self) -> f64 {
        self.time
    }
}

impl Args {
    pub fn run(self, limits: &Limits) -> flexrom::Result<()> {
        let Args { model, output, loads, steps, solver, paraview, format } = self;
        if let Some(output) = &output {
            check_output(output, Origin::Flag("-o"), &[(&model, "model file")], &[Kind::Result])?;
            if paraview {
                flexrom::io::paraview::check_xdmf_output(output)?;
            }
        }
        let model = Model::load_with(&model, limits.clone())?;
        let mu = loads.parameters()?;
        super::warn(&model.admit(std::slice::from_ref(&mu), flexrom::model::Runs::Full)?);
        let o = StaticOptions { mu: mu.clone(), t: loads.time, steps, solver: solver.into() };
        let (r, solution) = flexrom::simulate::statics(&model, &o).map_err(|e| e.at_stage("statics", &mu))?;
        if let Some(output) = &output {
            let file =
                ResultFile::begin(output, &model.text, &model.path.display().to_string(), &RunPlan::of_result(&r))?;
            let factors: Vec<f64> = solution.steps.iter().map(|s| s.load_factor).collect();
            let mut layout = None;
            file.finish(&r, |f| {
                if paraview {
                    layout = Some(flexrom::io::paraview::extra(f, output, model.bodies(), &r)?);
                }
                write_statics(f, o.t, steps, &factors).map_err(|err| flexrom::Error::hdf5(output, err))
            })?;
            if let Some(layout) = layout {
                flexrom::io::paraview::write_xdmf(output, &layout)?;
            }
        }
        let written = output.as_ref().map_or("no result file (-o not given)".to_string(), |o| o.display().to_string());
        info(&format!(
            "{}: static equilibrium at t = {} s in {} load step{} ({} Newton iterations, {} step cuts, {:.3} s) -> {}",
            model.path.display(),
            o.t,
            steps,
            if steps == 1 { "" } else { "s" },
            r.stats.newton_iterations,
            r.stats.step_cuts,
            r.wall_seconds,
            written
        ));
        for (name, xy) in &r.probes {
            let k = xy.nrows() - 1;
            info(&format!("  {name}: ({:.6e}, {:.6e}) m", xy[[k, 0]], xy[[k, 1]]));
        }
        // the probe table with the load factor of each row beside its time
        let mut table = flexrom::report::tables::probe_table(&r);
        table.columns.insert(1, "load_factor".into());
        for (row, step) in table.rows.iter_mut().zip(&solution.steps) {
            row.insert(1, Cell::from(step.load_factor));
        }
        if format.format() != flexrom::output::table::Format::Text {
            flexrom::report::tables::add_reactions(&mut table, &model, &r);
        }
        print_table(&table, format.format(), false)
    }
}
