//! `flexrom train`: full runs at the training load scales (or greedy over a load range) and the
//! POD basis written to HDF5; or, with `--snapshots-only` / `--from-snapshots`, the two halves of
//! that apart.

use super::{print_table, FormatArgs};
use flexrom::io::attrs::Kind;
use flexrom::io::output::{check_output, Origin};
use flexrom::limits::Limits;
use flexrom::output::info;
use flexrom::output::table::Table;
use flexrom::pipeline::Pipeline;
use std::path::PathBuf;

/// The arguments of `flexrom train`.
#[derive(clap::Args)]
pub struct Args {
    /// pipeline file (TOML)
    pipeline: PathBuf,
    /// basis file to write (default: the pipeline's `basis`)
    #[arg(long)]
    basis: Option<PathBuf>,
    /// only run the full model (at --load-scale X, or at the --shard K/N part of
    /// train.load_scales) and write its snapshots to -o; no basis
    #[arg(long, requires = "output", conflicts_with_all = ["from_snapshots", "basis"])]
    snapshots_only: bool,
    /// the load scale of a --snapshots-only run
    #[arg(long, requires = "snapshots_only", conflicts_with = "shard", allow_negative_numbers = true)]
    load_scale: Option<f64>,
    /// `K/N`: the --snapshots-only runs of loads K, K+N, … of train.load_scales
    #[arg(long, value_name = "K/N", requires = "snapshots_only")]
    shard: Option<flexrom::workflows::shard::Shard>,
    /// snapshot file of --snapshots-only
    #[arg(short, long, requires = "snapshots_only")]
    output: Option<PathBuf>,
    /// build the basis from these snapshot files instead of running the full model
    #[arg(long, num_args = 1.., value_name = "SNAPS.h5")]
    from_snapshots: Vec<PathBuf>,
    #[command(flatten)]
    format: FormatArgs,
}

impl Args {
    pub fn run(self, limits: &Limits) -> flexrom::Result<()> {
        let Args { pipeline, basis, snapshots_only, load_scale, shard, output, from_snapshots, format } = self;
        let p = Pipeline::load_with(&pipeline, limits.clone())?;
        super::warn(&p.property_warnings());
        super::warn(&super::model_resolution(&p.model));
        if snapshots_only {
            let out = output.expect("clap: --snapshots-only requires -o");
            check_output(
                &out,
                Origin::Flag("-o"),
                &[(&p.path, "pipeline file"), (&p.model.path, "model file")],
                &[Kind::Snapshots],
            )?;
            let points = flexrom::training::snapshots::job_points(&p, load_scale, shard)?;
            let (n, secs) = flexrom::training::snapshots::write_snapshots(&p, &points, &out)?;
            let scales: Vec<f64> = points.iter().map(|mu| mu.scale()).collect();
            let at = if p.space().is_empty() {
                format!("{scales:?}")
            } else {
                points.iter().map(|mu| format!("({})", p.space().label(mu))).collect::<Vec<_>>().join(", ")
            };
            info(&format!("{}: {n} full run(s) at {at} ({secs:.3} s) -> {}", p.path.display(), out.display()));
            let mut t = Table::new(&["pipeline", "output", "n_runs", "load_scales", "seconds"]);
            let list: Vec<String> = scales.iter().map(|x| x.to_string()).collect();
            t.push(vec![
                p.path.display().to_string().into(),
                out.display().to_string().into(),
                n.into(),
                list.join(" ").into(),
                secs.into(),
            ]);
            return print_table(&t, format.format(), true);
        }
        let origin =
            if basis.is_some() { Origin::Flag("--basis") } else { Origin::Key { pipeline: &p.path, key: "basis" } };
        let out = basis.clone().unwrap_or_else(|| p.basis_path.clone());
        let s = flexrom::training::train::train_to_file(&p, &out, origin, &from_snapshots)?;
        super::warn(&s.warnings);
        let b = &s.trained.basis;
        info(&format!(
            "{}: {} snapshots from {} ({:.3} s); {} basis, {} snapshots, {} POD modes{}{} (captured energy 1 − {:.2e}) -> {}",
            p.path.display(),
            s.n_snapshots,
            s.runs_text(),
            s.full_seconds,
            b.variant.name(),
            b.snapshots.name(),
            b.n_pod_modes - s.trained.output_modes.iter().sum::<usize>(),
            match s.trained.output_modes.iter().sum::<usize>() {
                0 => String::new(),
                k => format!(" + {k} output modes"),
            },
            if b.kept.is_empty() { String::new() } else { format!(" + {} joint coordinates", b.kept.len()) },
            s.trained.uncaptured_energy(),
            out.display()
        ));
        let mut t = Table::new(&[
            "pipeline",
            "basis",
            "n_runs",
            "n_snapshots",
            "full_seconds",
            "variant",
            "snapshots",
            "n_pod_modes",
            "n_joint_coordinates",
            "uncaptured_energy",
            "n_training_runs",
            "n_held_out",
        ]);
        t.push(vec![
            p.path.display().to_string().into(),
            out.display().to_string().into(),
            s.n_runs.into(),
            s.n_snapshots.into(),
            s.full_seconds.into(),
            b.variant.name().into(),
            b.snapshots.name().into(),
            b.n_pod_modes.into(),
            b.kept.len().into(),
            s.trained.uncaptured_energy().into(),
            s.n_training_runs().into(),
            s.n_held_out().into(),
        ]);
        print_table(&t, format.format(), true)
    }
}
