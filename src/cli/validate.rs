//! `flexrom validate`: full and reduced runs at one load scale, compared.

use super::{warn, DenseArgs, EstimateArgs, FormatArgs};
use flexrom::limits::Limits;
use flexrom::output::table::{Format, Table};
use flexrom::output::{self};
use flexrom::pipeline::Pipeline;
use flexrom::rom::warnings::Answered;
use flexrom::solver::parameters::Parameters;
use flexrom::workflows::online::load_rom;
use std::path::PathBuf;

/// The arguments of `flexrom validate`.
#[derive(clap::Args)]
pub struct Args {
    /// pipeline file (TOML)
    pipeline: PathBuf,
    /// multiplies every load marked `scaled` in the model file (negative: the load reversed);
    /// default: every load of the pipeline's `[validate] load_scales`
    #[arg(long, allow_negative_numbers = true)]
    load_scale: Option<f64>,
    #[command(flatten)]
    params: super::ParamArgs,
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
    #[command(flatten)]
    estimate: EstimateArgs,
}

impl Args {
    pub fn run(self, limits: &Limits) -> flexrom::Result<()> {
        let Args { pipeline, load_scale, params, format, basis, dense, strict, estimate } = self;
        let p = Pipeline::load_with(&pipeline, limits.clone())?;
        // --param with the pipeline's loads: the named values at each of them
        let points = p.validation_points_given(load_scale, (params.any(), params.sets_load_scale()), |x| {
            params.parameters(x, 1.0)
        })?;
        warn(&p.model.admit(&points, flexrom::model::Runs::Reduced)?);
        // a body property not given is the file's value (online's reason)
        let points: Vec<Parameters> = points.iter().map(|mu| p.model.with_property_values(mu)).collect();
        let path = basis.unwrap_or_else(|| p.basis_path.clone());
        let (_, rom, warnings) = load_rom(&p, &path, estimate.method(), false)?;
        warn(&warnings);
        let with_dense = flexrom::cost::dense::decide(dense.choice(), &p.model)?;
        let mut vs = Vec::with_capacity(points.len());
        for mu in &points {
            let (v, _, _) = flexrom::workflows::validate::validate(&rom, mu, with_dense)?;
            // text: each load's lines as soon as they are known
            if format.format() == Format::Text {
                output::println(&v.describe())?;
            }
            vs.push(v);
        }
        let json_err = |e: serde_json::Error| flexrom::Error::usage(format!("cannot write the JSON: {e}"));
        match format.format() {
            // the record as serde writes it (arrays stay arrays): the keys scripts read; one
            // object for --load-scale, else an array as the report's validation.json
            Format::Json => {
                let text = match (load_scale.is_some() || params.any(), vs.as_slice()) {
                    (true, [v]) => serde_json::to_string(v),
                    _ => serde_json::to_string(&vs),
                };
                output::println(&text.map_err(json_err)?)?;
            }
            Format::Csv => {
                let text = serde_json::to_string(&vs).map_err(json_err)?;
                output::print(&Table::from_json_records(&text)?.to_csv()?)?
            }
            Format::Text => {}
        }
        let answered: Vec<Answered> = points.iter().zip(&vs).map(|(mu, v)| v.answered(&rom, mu)).collect();
        super::warn_after(rom.warnings_after(&answered, strict), &rom, strict)
    }
}
