//! `flexrom simulate`: one full-order run of a model file, written to an HDF5 result file.

use super::{run_details, FormatArgs};
use flexrom::io::attrs::Kind;
use flexrom::io::output::{check_output, Origin};
use flexrom::io::result_file::{begin_alongside, RunPlan};
use flexrom::limits::Limits;
use flexrom::linalg::kkt::LinearSolverKind;
use flexrom::model::Model;
use flexrom::output::info;
use flexrom::simulate::{simulate, with_energies, Overrides, Settings};
use flexrom::solver::parameters::Parameters;
use std::path::PathBuf;

/// The arguments of `flexrom simulate`.
#[derive(clap::Args)]
pub struct Args {
    /// model file (TOML)
    model: PathBuf,
    /// result file (HDF5); may be left out with --csv or --json, which then print the
    /// probes on stdout and write no file
    #[arg(short, long, required_unless_present_any = ["csv", "json"])]
    output: Option<PathBuf>,
    /// also write ParaView's view beside the result: the deformed centre lines at every
    /// instant (4 points an element) with strain, curvature and velocity, in the result
    /// file's /paraview and an XDMF file of the same stem (out.h5 → out.xdmf)
    #[arg(long, requires = "output")]
    paraview: bool,
    #[command(flatten)]
    run: RunArgs,
    #[command(flatten)]
    format: FormatArgs,
}

impl Args {
    pub fn run(self, limits: &Limits) -> flexrom::Result<()> {
        let Args { model, output, paraview, run, format } = self;
        if let Some(output) = &output {
            check_output(output, Origin::Flag("-o"), &[(&model, "model file")], &[Kind::Result])?;
            if paraview {
                flexrom::io::paraview::check_xdmf_output(output)?;
            }
        }
        let model = Model::load_with(&model, limits.clone())?;
        let overrides = run.overrides()?;
        let mu = overrides.mu.clone().unwrap_or_default();
        super::warn(&model.admit(std::slice::from_ref(&mu), flexrom::model::Runs::Full)?);
        // whether dt resolves the model, looked at on a second thread while the run computes
        // (a modes analysis: the run's own time is not to grow by it), said after the run
        let (r, resolution) = std::thread::scope(|s| {
            let check = s.spawn(|| {
                Settings::resolve(&model, &overrides)
                    .map_or_else(|_| Vec::new(), |settings| flexrom::simulate::resolution_warnings(&model, &settings))
            });
            let r = run_and_write(&model, &overrides, output.as_deref(), paraview);
            (r, check.join().unwrap_or_default())
        });
        super::warn(&resolution);
        let r = r?;
        let written = output.as_ref().map_or("no result file (-o not given)".to_string(), |o| o.display().to_string());
        info(&format!(
            "{}: {} steps in {:.3} s ({} Newton iterations, {} factorizations, {} step cuts) -> {}",
            model.path.display(),
            r.stats.steps,
            r.wall_seconds,
            r.stats.newton_iterations,
            r.stats.factorizations,
            r.stats.step_cuts,
            written
        ));
        run_details(&r, false);
        super::print_series(&model, &r, format.format())
    }
}

/// The run, written to `output` (with ParaView's view where asked) or, without it, only
/// returned (`--csv`/`--json` print it).
fn run_and_write(
    model: &Model,
    overrides: &Overrides,
    output: Option<&std::path::Path>,
    paraview: bool,
) -> flexrom::Result<flexrom::simulate::SimulationResult> {
    let mu = overrides.mu.clone().unwrap_or_default();
    let compute =
        || simulate(model, overrides).and_then(|r| with_energies(model, r)).map_err(|e| e.at_stage("simulate", &mu));
    Ok(match output {
        // the result file's fixed part is written on a second thread while the run computes
        Some(output) => {
            let settings = Settings::resolve(model, overrides)?;
            // a run too large for the memory bound is refused before the file is begun
            // (its labels alone are a string per coordinate)
            model.check_full_run_memory(settings.n_steps, settings.solver == LinearSolverKind::Dense)?;
            let plan = RunPlan::of(model, &settings);
            let (file, r) = begin_alongside(output, &model.text, &model.path.display().to_string(), &plan, compute)?;
            let mut layout = None;
            file.finish(&r, |f| {
                if paraview {
                    layout = Some(flexrom::io::paraview::extra(f, output, model.bodies(), &r)?);
                }
                Ok(())
            })?;
            if let Some(layout) = layout {
                flexrom::io::paraview::write_xdmf(output, &layout)?;
            }
            r
        }
        // --csv or --json alone: the probes on stdout, no file
        None => compute()?,
    })
}

#[derive(clap::Args)]
struct RunArgs {
    /// time step, s (default: the model file's)
    #[arg(long, allow_negative_numbers = true)]
    dt: Option<f64>,
    /// end time, s (default: the model file's)
    #[arg(long, allow_negative_numbers = true)]
    t_end: Option<f64>,
    /// generalized-α spectral radius ρ∞ in [0, 1] (default: the model file's)
    #[arg(long, allow_negative_numbers = true)]
    rho_inf: Option<f64>,
    /// multiplies every load marked `scaled` in the model file (negative: the load reversed)
    #[arg(long, allow_negative_numbers = true)]
    load_scale: Option<f64>,
    #[command(flatten)]
    params: super::ParamArgs,
    /// linear solver of the full model
    #[arg(long, value_enum, default_value_t = super::values::Solver::Banded)]
    solver: super::values::Solver,
}

impl RunArgs {
    fn overrides(&self) -> flexrom::Result<Overrides> {
        let mu = if self.params.any() {
            Some(self.params.parameters(self.load_scale, 1.0)?)
        } else {
            self.load_scale.map(Parameters::load_scale)
        };
        Ok(Overrides { dt: self.dt, t_end: self.t_end, rho_inf: self.rho_inf, mu, solver: self.solver.into() })
    }
}
