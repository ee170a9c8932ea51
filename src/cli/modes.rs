//! `flexrom modes`: the lowest natural frequencies and mode shapes of a model, linearized at
//! its initial configuration or at its static equilibrium.

use super::statics::LoadArgs;
use super::FormatArgs;
use flexrom::io::attrs::Kind;
use flexrom::io::modes_file::{write_with_paraview, ModesRecord};
use flexrom::io::output::{check_output, Origin};
use flexrom::limits::Limits;
use flexrom::model::Model;
use flexrom::output::info;
use flexrom::output::table::{Cell, Format, Table};
use flexrom::simulate::{ModesAnalysis, ModesAt, ModesOptions};
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
    /// also write ParaView's view beside the modes file: each mode shape as a displacement
    /// field on the centre lines of the configuration linearized at (4 points an element),
    /// in the file's /paraview and an XDMF file of the same stem (out.h5 → out.xdmf); Warp
    /// By Vector draws a mode
    #[arg(long, requires = "output")]
    paraview: bool,
    /// a basis file (`flexrom train`): also the frequencies of its reduced model (the
    /// stiffness and mass projected on its modes, the constraints held), beside the full
    /// ones, to see which modes the POD kept
    #[arg(long)]
    basis: Option<PathBuf>,
    /// linear solver of the shift-invert factorization
    #[arg(long, value_enum, default_value_t = super::values::Solver::Banded)]
    solver: super::values::Solver,
    #[command(flatten)]
    format: FormatArgs,
}

impl Args {
    pub fn run(self, limits: &Limits) -> flexrom::Result<()> {
        let Args { model, count, at, loads, output, paraview, basis, solver, format } = self;
        if let Some(output) = &output {
            check_output(output, Origin::Flag("-o"), &[(&model, "model file")], &[Kind::Modes])?;
            if paraview {
                flexrom::io::paraview::check_xdmf_output(output)?;
            }
        }
        let model = Model::load_with(&model, limits.clone())?;
        let at = match at {
            At::Initial => ModesAt::Initial,
            At::Static => ModesAt::Static,
        };
        let o = ModesOptions { count, at, mu: loads.parameters()?, time: loads.time(), solver: solver.into() };
        let analysis = flexrom::simulate::modes(&model, &o)?;
        let reduced = match &basis {
            Some(path) => Some(reduced_frequencies(&model, path, &analysis, &o)?),
            None => None,
        };
        let ModesAnalysis { modes, q, mu, seconds } = analysis;
        info(&format!(
            "{}: {count} modes at the {} configuration in {seconds:.3} s ({} subspace iterations, {} coordinates)",
            model.path.display(),
            at.name(),
            modes.iterations,
            q.len()
        ));
        flexrom::output::detail(&format!(
            "  round-off of every ω²: about {:.2e} 1/s² (ε times the mesh's largest ω²)",
            modes.roundoff
        ));
        for (i, f) in modes.frequencies.iter().enumerate() {
            let kind = if modes.rigid[i] { " (rigid-body motion)" } else { "" };
            let kept = match reduced.as_ref().map(|r| r.frequencies.get(i)) {
                Some(Some(fr)) if *f != 0.0 => format!("; reduced {fr:.6} Hz ({:+.2e} relative)", (fr - f) / f),
                Some(Some(fr)) => format!("; reduced {fr:.6} Hz"),
                Some(None) => "; not in the reduced model".to_string(),
                None => String::new(),
            };
            info(&format!("  mode {}: {f:.6} Hz{kind}{kept}", i + 1));
        }
        if let Some(r) = &reduced {
            info(&format!("  the basis leaves {} coordinates once its constraint rows hold", r.dimension));
        }
        if let Some(output) = &output {
            let record = ModesRecord { model: &model, modes: &modes, q: &q, at: at.name(), mu: &mu, time: o.time };
            if let Some(layout) = write_with_paraview(output, &record, paraview)? {
                flexrom::io::paraview::write_modes_xdmf(output, &layout)?;
            }
        }
        match format.format() {
            Format::Json => {
                let mut v = serde_json::json!({
                    "frequencies": modes.frequencies,
                    "omega_squared": modes.omega_squared,
                    "rigid": modes.rigid,
                    "iterations": modes.iterations,
                    "seconds": seconds,
                });
                if let Some(r) = &reduced {
                    v["reduced_frequencies"] = serde_json::json!(r.frequencies);
                    v["reduced_omega_squared"] = serde_json::json!(r.omega_squared);
                    v["reduced_dimension"] = serde_json::json!(r.dimension);
                }
                flexrom::output::println(&v.to_string())
            }
            Format::Csv => {
                let mut cols = vec!["mode", "frequency", "omega_squared", "rigid"];
                if reduced.is_some() {
                    cols.push("reduced_frequency");
                }
                let mut t = Table::new(&cols);
                for i in 0..modes.len() {
                    let mut row = vec![
                        Cell::from(i + 1),
                        Cell::from(modes.frequencies[i]),
                        Cell::from(modes.omega_squared[i]),
                        Cell::from(usize::from(modes.rigid[i])),
                    ];
                    if let Some(r) = &reduced {
                        row.push(r.frequencies.get(i).map_or(Cell::Null, |&f| Cell::from(f)));
                    }
                    t.push(row);
                }
                flexrom::output::print(&t.to_csv()?)
            }
            Format::Text => Ok(()),
        }
    }
}

/// The reduced model's frequencies of the basis file at `path` beside the full model's
/// `analysis`: a basis of another model (another number of coordinates) is refused, one
/// trained on another version of this model file is used with a warning.
fn reduced_frequencies(
    model: &Model,
    path: &std::path::Path,
    analysis: &ModesAnalysis,
    o: &ModesOptions,
) -> flexrom::Result<flexrom::analysis::reduced_modes::ReducedModes> {
    let stored = flexrom::io::basis_file::read_basis(path)?;
    let n = stored.basis.n_dof();
    if n != analysis.q.len() {
        return Err(flexrom::Error::input(
            path,
            "basis/modes",
            format!("has {n} coordinates; {} has {}: a basis of another model", model.path.display(), analysis.q.len()),
        ));
    }
    if stored.model_fingerprint != model.fingerprint() {
        super::warn(&[format!(
            "{}: trained on another version of {} (its model_fingerprint differs); its modes are projected all the same",
            path.display(),
            model.path.display()
        )]);
    }
    flexrom::simulate::reduced_modes(model, analysis, stored.basis.modes.view(), o)
}
