//! `flexrom animate`: the motion of a result file, or of one run of a reduced sweep file
//! ([`crate::report::motion`]), as an animated GIF (plotters' pure-Rust GIF backend: plays in any
//! browser and in Markdown, no ffmpeg). Each frame draws the mechanism as
//! [`crate::report::drawing`] does (the deformed centre lines from the ANCF interpolation, the
//! joints, springs, point masses and probes) and the time, on equal axes fitted to the
//! whole motion; `--compare` overlays a second run, dashed in another colour, at the
//! nearest instant of its own time grid.
//!
//! A long run is subsampled in time (at most `max_frames` evenly spaced instants, the
//! first and last included) and a big mesh along its bodies ([`MAX_POINTS`] samples a
//! run), so that a 5000-element model's animation stays small and quick.

use crate::error::{Error, Result};
use crate::physics::centre_line::CentreLines;
use crate::report::drawing::{draw_frame, motion_chart, Bounds, Frame, Style, BOTTOM, LEFT, MARGIN, TITLE};
use crate::report::motion::Motion;
use crate::report::plot::{not_drawn, register_font, COLORS};
use crate::workflows::sweep::SweepPick;
use plotters::prelude::*;
use std::path::Path;

/// Sample points a frame draws per run at most: a 640-pixel-wide frame shows no more.
pub const MAX_POINTS: usize = 2000;
/// The comment every GIF flexrom writes carries: how `animate` recognises its own file.
pub const GIF_MARK: &[u8] = b"flexrom animation";

/// How the animation is made.
#[derive(Clone, Debug)]
pub struct AnimateOptions {
    /// frames per second of the GIF
    pub fps: f64,
    /// width and height, pixels; `None` for the height fits it to the motion's aspect
    pub size: (u32, Option<u32>),
    /// most frames drawn
    pub max_frames: usize,
}

impl Default for AnimateOptions {
    fn default() -> Self {
        AnimateOptions { fps: 20.0, size: (640, None), max_frames: 200 }
    }
}

/// What was written.
#[derive(Clone, Debug)]
pub struct Animation {
    pub frames: usize,
    pub bytes: u64,
    pub width: u32,
    pub height: u32,
}

/// A run's motion and its sampling along the bodies.
struct Run {
    motion: Motion,
    lines: CentreLines,
}

impl Run {
    fn new(motion: Motion) -> Run {
        let lines = CentreLines::new(motion.model.bodies(), MAX_POINTS);
        Run { motion, lines }
    }

    fn frame(&self, k: usize) -> Result<Frame> {
        Ok(Frame::at(&self.motion.model, &self.lines, &self.motion.q_row(k)?))
    }

    /// The instant of this run's time grid nearest `t`.
    fn nearest(&self, t: f64) -> usize {
        let ts = self.motion.t();
        let i = ts.partition_point(|&x| x < t).min(ts.len() - 1);
        if i > 0 && (t - ts[i - 1]).abs() <= (ts[i] - t).abs() {
            i - 1
        } else {
            i
        }
    }
}

/// At most `max` instants of `0..n`, evenly spaced, the first and the last included.
pub fn frame_indices(n: usize, max: usize) -> Vec<usize> {
    if n <= max.max(2) {
        return (0..n).collect();
    }
    let m = max.max(2);
    (0..m).map(|i| ((i * (n - 1)) as f64 / (m - 1) as f64).round() as usize).collect()
}

/// Writes the animation of `result` (and `compare` over it) to `out`, atomically: a failed
/// one leaves what was at `out` as it was. The caller checks `out` ([`check_own_gif`]).
pub fn animate(
    result: &Path,
    compare: Option<&Path>,
    out: &Path,
    opts: &AnimateOptions,
    limits: &crate::limits::Limits,
) -> Result<Animation> {
    animate_picked(result, compare, None, out, opts, limits)
}

/// [`animate`] where `result` or `compare` may be a reduced sweep file: `pick` names the
/// run drawn of each sweep file given ([`Motion::open`]); a `pick` with no sweep file
/// given is refused.
pub fn animate_picked(
    result: &Path,
    compare: Option<&Path>,
    pick: Option<SweepPick>,
    out: &Path,
    opts: &AnimateOptions,
    limits: &crate::limits::Limits,
) -> Result<Animation> {
    if !(opts.fps.is_finite() && opts.fps > 0.0 && opts.fps <= 100.0) {
        return Err(Error::option("fps", None, format!("{} is not in (0, 100] frames per second", opts.fps)));
    }
    let (main, main_sweep) = Motion::open(result, pick, limits)?;
    let other = compare.map(|p| Motion::open(p, pick, limits)).transpose()?;
    if let Some(pick) = pick.filter(|_| !main_sweep && !other.as_ref().is_some_and(|o| o.1)) {
        return Err(Error::input(
            result,
            pick.flag(),
            "picks a run of a sweep file, and no file given is one: a result file holds one run, animated as it is",
        ));
    }
    let (main, other) = (Run::new(main), other.map(|o| Run::new(o.0)));
    let ts = main.motion.t();
    if ts.is_empty() {
        return Err(Error::input(result, "t", "is empty: the run recorded no instant"));
    }
    let indices = frame_indices(ts.len(), opts.max_frames);
    let mut frames = Vec::with_capacity(indices.len());
    for &k in &indices {
        let t = ts[k];
        let second = match &other {
            Some(o) if !o.motion.t().is_empty() => Some(o.frame(o.nearest(t))?),
            _ => None,
        };
        frames.push((t, main.frame(k)?, second));
    }
    let bounds = Bounds::of(frames.iter().flat_map(|(_, a, b)| std::iter::once(a).chain(b)));
    let width = opts.size.0.clamp(120, 4000);
    let height = opts.size.1.unwrap_or_else(|| fitted_height(width, &bounds)).clamp(120, 4000);
    let title = match &other {
        Some(o) => format!("{} (solid) vs {} (dashed)", main.motion.name, o.motion.name),
        None => main.motion.name.clone(),
    };
    let delay_ms = (1000.0 / opts.fps).round().max(10.0) as u32;
    crate::io::atomic::write_file_atomically(out, |tmp| {
        draw((tmp, out), (width, height), delay_ms, &title, &bounds, &frames)?;
        mark_gif(tmp)
    })?;
    let bytes = std::fs::metadata(out).map_err(|e| Error::io(out, e))?.len();
    Ok(Animation { frames: frames.len(), bytes, width, height })
}

/// The height at which the motion's box fills the plot's width with equal axes, kept
/// between 40 % and 100 % of the width.
fn fitted_height(width: u32, b: &Bounds) -> u32 {
    let plot_w = width.saturating_sub(LEFT + 2 * MARGIN).max(1) as f64;
    let plot_h = plot_w * (b.y.1 - b.y.0) / (b.x.1 - b.x.0);
    let h = plot_h.clamp(0.4 * width as f64, width as f64) as u32;
    h + TITLE + BOTTOM + 2 * MARGIN
}

/// Draws `frames` as a GIF at `path`; a failure is one to write `out`, the file the user named.
fn draw(
    (path, out): (&Path, &Path),
    size: (u32, u32),
    delay_ms: u32,
    title: &str,
    bounds: &Bounds,
    frames: &[(f64, Frame, Option<Frame>)],
) -> Result<()> {
    let e = |x: &dyn std::fmt::Display| not_drawn(out, x);
    register_font();
    let root = BitMapBackend::gif(path, size, delay_ms).map_err(|x| e(&x))?.into_drawing_area();
    let plot_w = size.0.saturating_sub(LEFT + 2 * MARGIN).max(1) as f64;
    let plot_h = size.1.saturating_sub(TITLE + BOTTOM + 2 * MARGIN).max(1) as f64;
    let b = bounds.equal(plot_w, plot_h);
    for (t, main, second) in frames {
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let area = root.titled(&format!("{title}    t = {t:.4} s"), ("sans-serif", 16)).map_err(|x| e(&x))?;
        let mut chart = motion_chart(&area, &b, out)?;
        if let Some(s) = second {
            draw_frame(&mut chart, s, &b, Style { colour: COLORS[1], dashed: true, names: false }, out)?;
        }
        draw_frame(&mut chart, main, &b, Style { colour: COLORS[0], dashed: false, names: false }, out)?;
        root.present().map_err(|x| e(&x))?;
    }
    Ok(())
}

/// Adds a GIF comment extension holding [`GIF_MARK`] before the file's trailer (`0x3B`):
/// viewers ignore it, and [`check_own_gif`] reads it.
fn mark_gif(path: &Path) -> Result<()> {
    let mut bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    if bytes.last() != Some(&0x3B) {
        return Err(Error::io(path, std::io::Error::other("the GIF encoder left no trailer")));
    }
    bytes.pop();
    bytes.extend_from_slice(&[0x21, 0xFE, GIF_MARK.len() as u8]);
    bytes.extend_from_slice(GIF_MARK);
    bytes.extend_from_slice(&[0x00, 0x3B]);
    std::fs::write(path, &bytes).map_err(|e| Error::io(path, e))
}

/// Whether the file at `path` is a GIF flexrom wrote: it starts `GIF8` and ends with
/// [`GIF_MARK`]'s comment and the trailer.
pub fn is_own_gif(path: &Path) -> bool {
    use std::io::{Read, Seek, SeekFrom};
    let Ok(mut f) = std::fs::File::open(path) else { return false };
    let tail = GIF_MARK.len() as i64 + 5;
    let (mut head, mut end) = ([0u8; 4], vec![0u8; tail as usize]);
    f.read_exact(&mut head).is_ok()
        && &head == b"GIF8"
        && f.seek(SeekFrom::End(-tail)).is_ok()
        && f.read_exact(&mut end).is_ok()
        && end[..3] == [0x21, 0xFE, GIF_MARK.len() as u8]
        && &end[3..3 + GIF_MARK.len()] == GIF_MARK
        && end[3 + GIF_MARK.len()..] == [0x00, 0x3B]
}

/// Refuses an animation's output (given as `flag`: `-o`, or Python's `path`): one not
/// ending in `.gif`, and an existing file that is not a GIF flexrom wrote ([`is_own_gif`]);
/// the other checks of every output ([`crate::io::output::check_output_with`]: not an
/// input, a creatable regular file).
pub fn check_own_gif(out: &Path, flag: &str, inputs: &[(&Path, &str)]) -> Result<()> {
    use crate::io::output::{check_output_with, Origin};
    let gif = out.extension().is_some_and(|x| x.eq_ignore_ascii_case("gif"));
    if !gif {
        return Err(Error::input(out, flag, "does not end in `.gif`: `flexrom animate` writes an animated GIF"));
    }
    check_output_with(out, Origin::Flag(flag), inputs, |p| {
        if is_own_gif(p) {
            Ok(())
        } else {
            Err(Error::input(
                p,
                flag,
                "exists and is not an animation flexrom wrote; flexrom replaces only its own: remove it or choose another path",
            ))
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 7 instants fit 200 frames whole; 1001 become 200, evenly, ends included.
    #[test]
    fn frames_are_spread_over_the_run() {
        assert_eq!(frame_indices(7, 200), (0..7).collect::<Vec<_>>());
        let f = frame_indices(1001, 200);
        assert_eq!((f.len(), f[0], f[199]), (200, 0, 1000));
        assert!(f.windows(2).all(|w| (5..=6).contains(&(w[1] - w[0]))), "1000/199 ≈ 5.03 apart");
    }
}
