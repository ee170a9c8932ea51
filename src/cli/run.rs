//! `flexrom run`: the whole pipeline (train, or reuse a current basis; sweep, validate) and
//! its report folder.

use super::{print_table, DenseArgs, EstimateArgs, FormatArgs};
use flexrom::limits::Limits;
use flexrom::output::table::{Format, Table};
use flexrom::output::{self, info};
use flexrom::pipeline::Pipeline;
use std::path::PathBuf;

/// The arguments of `flexrom run`.
#[derive(clap::Args)]
pub struct Args {
    /// pipeline file (TOML)
    pipeline: PathBuf,
    /// exit with code 4 (after writing the output) when an error estimate exceeds the
    /// tolerance ([online] tolerance, default the training tolerance)
    #[arg(long)]
    strict: bool,
    /// train even where the pipeline's basis is current (without it, a basis trained from
    /// this model with these [train]/[reduction]/[parameters] keys, that passes its checks,
    /// is reused and said so)
    #[arg(long)]
    retrain: bool,
    #[command(flatten)]
    dense: DenseArgs,
    #[command(flatten)]
    estimate: EstimateArgs,
    #[command(flatten)]
    format: FormatArgs,
}

impl Args {
    pub fn run(self, limits: &Limits) -> flexrom::Result<()> {
        let Args { pipeline, strict, retrain, dense, estimate, format } = self;
        let p = Pipeline::load_with(&pipeline, limits.clone())?;
        super::warn(&p.property_warnings());
        super::warn(&super::model_resolution(&p.model));
        if p.online_fallback() == Some(flexrom::workflows::sweep::Fallback::Full) {
            info(&format!(
                "{}: [online] fallback = \"full\" applies to `sweep` and `online`; the report's sweep is validated and measures the reduced model at every load",
                p.path.display()
            ));
        }
        let (dir, warnings) =
            flexrom::report::run_with(&p, output::show_progress(), dense.choice(), estimate.method(), retrain)?;
        super::warn(&warnings);
        let read = |name: &str| {
            let f = dir.join(name);
            std::fs::read_to_string(&f).map_err(|e| flexrom::Error::io(&f, e))
        };
        match format.format() {
            Format::Text => output::println(&read("summary.md")?)?,
            f => print_table(&Table::from_json_records(&read("validation.json")?)?, f, false)?,
        }
        info(&format!("report: {}", dir.display()));
        super::warn(&flexrom::report::check_report(&p, &dir, strict, estimate.method())?);
        Ok(())
    }
}
