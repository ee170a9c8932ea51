//! `flexrom online`: one reduced run at one load scale, written to a result file.

use super::{print_table, run_details, warn, EstimateArgs, FormatArgs};
use flexrom::io::attrs::Kind;
use flexrom::io::output::{check_output, Origin};
use flexrom::limits::Limits;
use flexrom::model::Runs;
use flexrom::output::info;
use flexrom::output::table::{Cell, Format, Table};
use flexrom::pipeline::Pipeline;
use flexrom::workflows::online::{load_rom, online_to_file};
use std::path::PathBuf;

/// The arguments of `flexrom online`.
#[derive(clap::Args)]
pub struct Args {
    /// pipeline file (TOML)
    pipeline: PathBuf,
    /// multiplies every load marked `scaled` in the model file (negative: the load reversed;
    /// default 1, as `simulate` and Python's `Basis.online`)
    #[arg(long, allow_negative_numbers = true)]
    load_scale: Option<f64>,
    #[command(flatten)]
    params: super::ParamArgs,
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
    /// `full`: where the reduced answer cannot be trusted — its run fails, its error
    /// estimate exceeds the tolerance, or the model amplifies load changes beyond it — run
    /// the full model and write its exact result (attribute `fallback`: why); over the
    /// pipeline's [online] fallback, default none
    #[arg(long, value_enum, value_name = "WHAT")]
    fallback: Option<flexrom::workflows::sweep::Fallback>,
    /// also write ParaView's view beside the result: the deformed centre lines at every
    /// instant (4 points an element) with strain, curvature and velocity, in the result
    /// file's /paraview and an XDMF file of the same stem (out.h5 → out.xdmf)
    #[arg(long, requires = "output")]
    paraview: bool,
    #[command(flatten)]
    estimate: EstimateArgs,
    #[command(flatten)]
    format: FormatArgs,
}

impl Args {
    pub fn run(self, limits: &Limits) -> flexrom::Result<()> {
        let Args { pipeline, load_scale, params, output, basis, strict, fallback, paraview, estimate, format } = self;
        let p = Pipeline::load_with(&pipeline, limits.clone())?;
        // λ checked finite with the named values
        let mu = params.parameters(load_scale, 1.0)?;
        warn(&p.model.admit(std::slice::from_ref(&mu), Runs::Reduced)?);
        // a body property not given is the file's value, which the checks against the
        // training box must read too
        let mu = p.model.with_property_values(&mu);
        let load_scale = mu.scale();
        let path = basis.unwrap_or_else(|| p.basis_path.clone());
        check_output(
            &output,
            Origin::Flag("-o"),
            &[(&p.path, "pipeline file"), (&p.model.path, "model file"), (&path, "basis file")],
            &[Kind::Result],
        )?;
        if paraview {
            flexrom::io::paraview::check_xdmf_output(&output)?;
        }
        let (stored, rom, warnings) = load_rom(&p, &path, estimate.method(), false)?;
        warn(&warnings);
        // read before the run (a damaged /timing fails now), said after it
        let notice = flexrom::cost::route::speed_notice_of(&path, &stored, &rom);
        let fallback = fallback.or(p.online_fallback()).unwrap_or_default();
        let done = online_to_file(&p, &rom, &path, &mu, &output, fallback, paraview)?;
        let (run, estimate) = (&done.run, &done.estimate);
        let st = &run.result.stats;
        info(&format!(
            "{}: {} at {mu}: {} steps in {:.4} s ({} Newton iterations, {} step cuts) -> {}",
            p.path.display(),
            match &done.fallback {
                Some(why) => format!("{why}; the full run"),
                None => format!("reduced run ({} modes)", stored.basis.n_reduced()),
            },
            st.steps,
            run.result.wall_seconds,
            st.newton_iterations,
            st.step_cuts,
            output.display()
        ));
        if let (Some(e), Some(method), None) = (estimate, rom.method(), &done.fallback) {
            info(&format!("  {}", flexrom::rom::trust::describe(e, method, run.result.wall_seconds)));
        }
        run_details(&run.result, true);
        let mut cols = vec!["load_scale", "n_modes"];
        cols.extend(flexrom::report::tables::RUN_COLUMNS);
        cols.extend(["error_estimate", "extrapolated", "output", "error_estimate_displacement", "fallback"]);
        // the named parameters last, as a sweep's table has them
        let named: Vec<String> = mu.named().map(|(name, _)| format!("parameter:{name}")).collect();
        cols.extend(named.iter().map(String::as_str));
        let mut t = Table::new(&cols);
        // a full answer has no modes
        let modes = if done.fallback.is_some() { Cell::Null } else { stored.basis.n_reduced().into() };
        let mut row: Vec<Cell> = vec![load_scale.into(), modes];
        row.extend(flexrom::report::tables::run_cells(&run.result));
        row.extend([
            estimate.as_ref().map(|e| e.error_estimate).into(),
            done.extrapolated.into(),
            output.display().to_string().into(),
            estimate.as_ref().map(|e| e.error_estimate_displacement).into(),
            done.fallback.as_deref().map_or(Cell::Null, Cell::from),
        ]);
        row.extend(mu.named().map(|(_, value)| value.into()));
        t.push(row);
        match format.format() {
            // the time series, as `simulate --csv` prints it (the summary is `--json`'s)
            Format::Csv => super::print_series(&p.model, &run.result, Format::Csv)?,
            f => print_table(&t, f, true)?,
        }
        warn(notice.as_slice());
        super::warn_after(done.warnings(&rom, &mu, strict), &rom, strict && done.fallback.is_none())
    }
}
