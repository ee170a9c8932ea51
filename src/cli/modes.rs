//! `flexrom modes`: the lowest natural frequencies and mode shapes of a model, linearized at
//! its initial configuration or at its static equilibrium.

use super::statics::LoadArgs;
use super::FormatArgs;
use flexrom::analysis::modes::{compute, unconstrained};
use flexrom::analysis::statics::StaticOptions;
use flexrom::io::attrs::Kind;
use flexrom::io::modes_file::{write, ModesRecord};
use flexrom::io::output::{check_output, Origin};
use flexrom::limits::Limits;
use flexrom::linalg::kkt::LinearSolverKind;
use flexrom::model::Model;
use flexrom::output::info;
use flexrom::output::table::{Cell, Format, Table};
use flexrom::simulate::{prepare, Overrides, Settings};
use std::path::PathBuf;

/// The configuration the model is linearized at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum At {
    /// the model's initial (undeformed) configuration
    Initial,
    /// the static equilibrium under the loads (`flexrom statics`, one load step)
    Static,
}

/// The arguments of `flexrom modes`.
#[derive(clap::Args)]
pub struct Args {
    /// model file (TOML)
    model: PathBuf,
    /// how many of the lowest modes (at most the unconstrained coordinates)
    #[arg(long, default_value_t = 6, allow_negative_numbers = true)]
    count: usize,
    /// linearize at the initial configuration or at the static equilibrium
    #[arg(long, value_enum, default_value_t = At::Initial)]
    at: At,
    #[command(flatten)]
    loads: LoadArgs,
    /// modes file (HDF5): frequencies and mode shapes laid out like q, with labels
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// linear solver of the shift-invert factorization
    #[arg(long, value_enum, default_value_t = LinearSolverKind::Banded)]
    solver: LinearSolverKind,
    #[command(flatten)]
    format: FormatArgs,
}

impl Args {
    pub fn run(self, limits: &Limits) -> flexrom::Result<()> {
        let Args { model, count, at, loads, output, solver, format } = self;
        if let Some(output) = &output {
            check_output(output, Origin::Flag("-o"), &[(&model, "model file")], &[Kind::Modes])?;
        }
        let model = Model::load_with(&model, limits.clone())?;
        let mu = model.with_property_values(&loads.parameters()?);
        model.check_parameters(&mu)?;
        let settings = Settings::resolve(&model, &Overrides { mu: Some(mu.clone()), solver, ..Default::default() })?;
        let (sys, q0) = prepare(&model, &settings)?;
        let n_free = unconstrained(&sys);
        if count == 0 || count > n_free {
            return Err(flexrom::Error::Usage(format!(
                "--count {count}: {} has {n_free} unconstrained coordinates ({} coordinates less {} constraint rows); ask for 1 to {n_free}",
                model.path.display(),
                q0.len(),
                q0.len() - n_free
            )));
        }
        let start = std::time::Instant::now();
        let q = match at {
            At::Initial => q0,
            At::Static => {
                let o = StaticOptions { mu: mu.clone(), t: loads.time(), steps: 1, solver };
                let (r, _) = flexrom::simulate::statics(&model, &o).map_err(|e| e.at_stage("statics", &mu))?;
                r.q.column(r.q.ncols() - 1).to_vec()
            }
        };
        let modes = compute(&sys, &mu, &q, loads.time(), count, solver).map_err(|e| e.at_stage("modes", &mu))?;
        let seconds = start.elapsed().as_secs_f64();
        info(&format!(
            "{}: {count} modes at the {} configuration in {seconds:.3} s ({} subspace iterations, {} coordinates)",
            model.path.display(),
            if at == At::Initial { "initial" } else { "static" },
            modes.iterations,
            q.len()
        ));
        flexrom::output::detail(&format!(
            "  round-off of every ω²: about {:.2e} 1/s² (ε times the mesh's largest ω²)",
            modes.roundoff
        ));
        for (i, f) in modes.frequencies.iter().enumerate() {
            let kind = if modes.rigid[i] { " (rigid-body motion)" } else { "" };
            info(&format!("  mode {}: {f:.6} Hz{kind}", i + 1));
        }
        if let Some(output) = &output {
            let at = if at == At::Initial { "initial" } else { "static" };
            write(output, &ModesRecord { model: &model, modes: &modes, q: &q, at, mu: &mu, time: loads.time() })?;
        }
        match format.format() {
            Format::Json => flexrom::output::println(
                &serde_json::json!({
                    "frequencies": modes.frequencies,
                    "omega_squared": modes.omega_squared,
                    "rigid": modes.rigid,
                    "iterations": modes.iterations,
                    "seconds": seconds,
                })
                .to_string(),
            ),
            Format::Csv => {
                let mut t = Table::new(&["mode", "frequency", "omega_squared", "rigid"]);
                for i in 0..modes.len() {
                    t.push(vec![
                        Cell::from(i + 1),
                        Cell::from(modes.frequencies[i]),
                        Cell::from(modes.omega_squared[i]),
                        Cell::from(usize::from(modes.rigid[i])),
                    ]);
                }
                flexrom::output::print(&t.to_csv()?)
            }
            Format::Text => Ok(()),
        }
    }
}
