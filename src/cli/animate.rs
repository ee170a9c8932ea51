//! `flexrom animate`: the motion of a result file as an animated GIF.

use flexrom::limits::Limits;
use flexrom::output::info;
use flexrom::report::animate::{animate_picked, check_own_gif, AnimateOptions};
use flexrom::workflows::sweep::SweepPick;
use std::path::PathBuf;

/// The arguments of `flexrom animate`.
#[derive(clap::Args)]
pub struct Args {
    /// result file (HDF5) of `simulate`, `online` or `statics`, or a reduced sweep file of
    /// `sweep` (with --load-scale or --point)
    result: PathBuf,
    /// the animation to write (must end in .gif)
    #[arg(short, long)]
    output: PathBuf,
    /// frames per second of the GIF
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    fps: f64,
    /// image size in pixels: WIDTHxHEIGHT, or a width alone (the height then fits the motion)
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    size: Option<(u32, Option<u32>)>,
    /// most frames drawn: a longer run is shown at this many evenly spaced instants
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u64).range(2..=2000))]
    max_frames: u64,
    /// a second result file drawn over the first, dashed in another colour (full against
    /// reduced, or two loads), at the instants nearest the first's
    #[arg(long, value_name = "OTHER.h5")]
    compare: Option<PathBuf>,
    /// of a sweep file, the run at this load scale (reconstructed on the basis the sweep
    /// file names; a full sweep keeps no coordinates: animate `flexrom simulate MODEL
    /// --load-scale L -o run.h5` instead); applies to --compare too when it is a sweep file
    #[arg(long, value_name = "L", allow_negative_numbers = true, conflicts_with = "point")]
    load_scale: Option<f64>,
    /// of a sweep file over named parameters, its point K, where a load scale names several:
    /// 0-based, row K of its /points and of `flexrom sweep`'s table (the report's plots
    /// number the points from 1)
    #[arg(long, value_name = "K")]
    point: Option<usize>,
}

fn parse_size(s: &str) -> Result<(u32, Option<u32>), String> {
    let bad = || format!("`{s}` is not WIDTHxHEIGHT or a width in pixels (120 to 4000 each)");
    let num = |v: &str| v.trim().parse::<u32>().ok().filter(|n| (120..=4000).contains(n)).ok_or_else(bad);
    match s.split_once(['x', 'X']) {
        Some((w, h)) => Ok((num(w)?, Some(num(h)?))),
        None => Ok((num(s)?, None)),
    }
}

impl Args {
    pub fn run(self, limits: &Limits) -> flexrom::Result<()> {
        let Args { result, output, fps, size, max_frames, compare, load_scale, point } = self;
        let pick = load_scale.map(SweepPick::LoadScale).or(point.map(SweepPick::Point));
        let mut inputs = vec![(result.as_path(), "result file")];
        if let Some(c) = &compare {
            inputs.push((c.as_path(), "compared result file"));
        }
        check_own_gif(&output, "-o", &inputs)?;
        let defaults = AnimateOptions::default();
        let opts = AnimateOptions { fps, size: size.unwrap_or(defaults.size), max_frames: max_frames as usize };
        let start = std::time::Instant::now();
        let a = animate_picked(&result, compare.as_deref(), pick, &output, &opts, limits)?;
        info(&format!(
            "{}: {} frames, {}×{} px, {:.1} KiB in {:.2} s -> {}",
            result.display(),
            a.frames,
            a.width,
            a.height,
            a.bytes as f64 / 1024.0,
            start.elapsed().as_secs_f64(),
            output.display()
        ));
        Ok(())
    }
}
