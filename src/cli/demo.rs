//! `flexrom demo`: each model run once and its probe positions printed at a few times.

use super::{print_table, run_details, FormatArgs};
use flexrom::limits::Limits;
use flexrom::model::Model;
use flexrom::output::table::{Format, Table};
use flexrom::output::{self};
use flexrom::simulate::{simulate, Overrides};
use flexrom::solver::parameters::Parameters;
use std::path::PathBuf;

/// The arguments of `flexrom demo`.
#[derive(clap::Args)]
pub struct Args {
    /// model files (TOML)
    models: Vec<PathBuf>,
    #[command(flatten)]
    format: FormatArgs,
}

impl Args {
    pub fn run(self, limits: &Limits) -> flexrom::Result<()> {
        let Args { models, format } = self;
        let mut table = Table::new(&["model", "t", "probe", "x", "y"]);
        for path in models {
            let model = Model::load_with(&path, limits.clone())?;
            let r = simulate(&model, &Overrides::default()).map_err(|e| e.at_stage("demo", &Parameters::default()))?;
            run_details(&r, false);
            let nt = r.t.len();
            if format.format() != Format::Text {
                for k in [0, nt / 4, nt / 2, 3 * nt / 4, nt - 1] {
                    for (n, xy) in &r.probes {
                        let name = path.display().to_string();
                        table.push(vec![
                            name.into(),
                            r.t[k].into(),
                            n.as_str().into(),
                            xy[[k, 0]].into(),
                            xy[[k, 1]].into(),
                        ]);
                    }
                }
                continue;
            }
            output::println(&format!(
                "{} ({} coordinates, {} steps of {} s, {:.1} ms, {} Newton iterations)",
                path.display(),
                r.q.nrows(),
                r.stats.steps,
                r.settings.dt,
                1e3 * r.wall_seconds,
                r.stats.newton_iterations
            ))?;
            for k in [0, nt / 4, nt / 2, 3 * nt / 4, nt - 1] {
                let cells: Vec<String> =
                    r.probes.iter().map(|(n, xy)| format!("{n} = ({:+.5}, {:+.5})", xy[[k, 0]], xy[[k, 1]])).collect();
                output::println(&format!("  t = {:.4} s: {}", r.t[k], cells.join("  ")))?;
            }
        }
        print_table(&table, format.format(), false)
    }
}
