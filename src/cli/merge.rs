//! `flexrom merge`: the part files of `sweep --shard` joined into one sweep file.

use super::{print_table, FormatArgs};
use flexrom::io::attrs::Kind;
use flexrom::io::output::{check_output, Origin};
use flexrom::limits::Limits;
use flexrom::output::info;
use std::path::PathBuf;

/// The arguments of `flexrom merge`.
#[derive(clap::Args)]
pub struct Args {
    /// part files (`sweep --shard K/N -o PART.h5`), one per shard, in any order
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// sweep file to write
    #[arg(short, long)]
    output: PathBuf,
    /// merge the parts there are; loads of missing shards or not run are marked
    /// `status` 2 (not run yet), which `sweep --resume` on the merged file runs
    #[arg(long)]
    partial: bool,
    #[command(flatten)]
    format: FormatArgs,
}

impl Args {
    pub fn run(self, limits: &Limits) -> flexrom::Result<()> {
        let Args { parts, output, partial, format } = self;
        let inputs: Vec<(&std::path::Path, &str)> = parts.iter().map(|p| (p.as_path(), "part file")).collect();
        check_output(&output, Origin::Flag("-o"), &inputs, &[Kind::Sweep])?;
        let m = flexrom::workflows::merge::merge(&parts, &output, partial, limits)?;
        print_table(&flexrom::report::tables::sweep_table(&m.sweep), format.format(), false)?;
        info(&format!(
            "{} parts, {} {} ({} not run) -> {}",
            m.parts,
            m.sweep.scales.len(),
            flexrom::workflows::sweep::runs_noun(m.sweep.scales.iter().map(|x| &x.mu)),
            m.gaps,
            output.display()
        ));
        if let Some(s) = m.sweep.failure_summary() {
            return Err(flexrom::Error::PartlyFailed(format!(
                "{s} (the others are in {}; /status and /message say which)",
                output.display()
            )));
        }
        Ok(())
    }
}
