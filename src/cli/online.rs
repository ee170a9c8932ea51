//! `flexrom online`: one reduced run at one load scale, written to a result file.

use super::{check_scale, print_table, run_details, FormatArgs};
use flexrom::io::output::{check_output, Origin};
use flexrom::io::result_file::{begin_alongside, RunPlan};
use flexrom::output::info;
use flexrom::output::table::{Cell, Table};
use flexrom::pipeline::online::load_basis;
use flexrom::pipeline::Pipeline;
use std::path::PathBuf;

/// The arguments of `flexrom online`.
#[derive(clap::Args)]
pub struct Args {
    /// pipeline file (TOML)
    pipeline: PathBuf,
    /// multiplies every load marked `scaled` in the model file (negative: the load reversed)
    #[arg(long, allow_negative_numbers = true)]
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
}

impl Args {
    pub fn run(self) -> flexrom::Result<()> {
        let Args { pipeline, load_scale, output, basis, strict, format } = self;
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
        // the result file's fixed part is written on a second thread while the run computes;
        // a run too large for the memory bound is refused before the file is begun
        let settings = flexrom::pipeline::online::settings_at(&p.model, load_scale)?;
        let full = flexrom::pipeline::online::Output::Full;
        flexrom::pipeline::online::check_reduced_memory(
            &p.model,
            stored.basis.n_reduced(),
            settings.n_steps,
            full,
            1.0,
        )?;
        let plan = RunPlan::of(&p.model, &settings);
        let model_path = p.model.path.display().to_string();
        let (file, (run, estimate)) = begin_alongside(&output, &p.model.text, &model_path, &plan, || {
            runner
                .run(load_scale, flexrom::pipeline::online::Output::Full)
                .map_err(|e| e.at_stage("online", load_scale))
        })?;
        let extrapolated = flexrom::pipeline::estimate::is_extrapolated(trust.range, load_scale);
        // absolute, so that the file names its basis wherever it is read from
        let basis_name = flexrom::io::output::resolve(&path).display().to_string();
        file.finish(&run.result, |f| {
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
            let method = trust.estimator.as_ref().map_or("corrected", |m| m.method.name());
            info(&format!("  {}", flexrom::pipeline::estimate::describe(e, method, run.result.wall_seconds)));
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
}
