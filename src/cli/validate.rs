//! `flexrom validate`: full and reduced runs at one load scale, compared.

use super::{check_scale, DenseArgs, FormatArgs};
use flexrom::output::table::{Format, Table};
use flexrom::output::{self};
use flexrom::pipeline::online::load_basis;
use flexrom::pipeline::Pipeline;
use std::path::PathBuf;

/// The arguments of `flexrom validate`.
#[derive(clap::Args)]
pub struct Args {
    /// pipeline file (TOML)
    pipeline: PathBuf,
    /// multiplies every load marked `scaled` in the model file (negative: the load reversed)
    #[arg(long, allow_negative_numbers = true)]
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
}

impl Args {
    pub fn run(self) -> flexrom::Result<()> {
        let Args { pipeline, load_scale, format, basis, dense, strict } = self;
        let p = Pipeline::load(&pipeline)?;
        check_scale(load_scale)?;
        let path = basis.unwrap_or_else(|| p.basis_path.clone());
        let stored = load_basis(&p, &path)?;
        let trust = flexrom::pipeline::estimate::load_trust(&p, &path, &stored)?;
        let with_dense = flexrom::pipeline::dense::decide(dense.choice(), &p.model)?;
        let (v, _, _) =
            flexrom::pipeline::validate::validate_with(&p.model, &stored.basis, Some(&trust), load_scale, with_dense)?;
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
}
