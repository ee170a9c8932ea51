//! `flexrom animate`: the motion of a result file as an animated GIF (plotters' pure-Rust
//! GIF backend: plays in any browser and in Markdown, no ffmpeg). Each frame draws the
//! deformed centre lines from the ANCF interpolation ([`crate::physics::centre_line`]),
//! the joints, point masses and probes, and the time, on equal axes fitted to the whole
//! motion; `--compare` overlays a second run, dashed in another colour, at the nearest
//! instant of its own time grid.
//!
//! A long run is subsampled in time (at most `max_frames` evenly spaced instants, the
//! first and last included) and a big mesh along its bodies ([`MAX_POINTS`] samples a
//! run), so that a 5000-element model's animation stays small and quick.

use super::plot::{linear_labels, register_font, COLORS};
use crate::error::{Error, Result};
use crate::io::result_read::ResultReader;
use crate::model::Model;
use crate::physics::centre_line::CentreLines;
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

/// One run's drawing at one instant.
struct Frame {
    lines: Vec<Vec<(f64, f64)>>,
    /// joints: position, whether it holds a node to the ground
    joints: Vec<((f64, f64), bool)>,
    masses: Vec<(f64, f64)>,
    probes: Vec<(f64, f64)>,
}

/// A result file's model and sampling.
struct Run {
    reader: ResultReader,
    model: Model,
    lines: CentreLines,
    name: String,
}

impl Run {
    fn open(path: &Path, limits: &crate::limits::Limits) -> Result<Run> {
        let reader = ResultReader::open(path, limits)?;
        let model = Model::from_text_with(&reader.model_text, &reader.model_path, limits.clone())
            .map_err(|e| Error::input(path, "model", format!("the model text it stores is not valid: {e}")))?;
        let n_dof = 4 * model.bodies().iter().map(|b| b.n_elements + 1).sum::<usize>();
        if n_dof != reader.n_dof() {
            return Err(Error::input(
                path,
                "q",
                format!("has {} coordinates a row; the model it stores has {n_dof}", reader.n_dof()),
            ));
        }
        let lines = CentreLines::new(model.bodies(), MAX_POINTS);
        let name = path.file_name().map_or(path.display().to_string(), |n| n.to_string_lossy().into_owned());
        Ok(Run { reader, model, lines, name })
    }

    fn frame(&self, k: usize) -> Result<Frame> {
        let q = self.reader.q_row(k)?;
        let xy = |p: [f64; 2]| (p[0], p[1]);
        let r = self.lines.interpolate(&q);
        let lines = self.lines.bodies().map(|range| r[range].iter().map(|&p| xy(p)).collect()).collect();
        let joints = self
            .model
            .joints()
            .iter()
            .map(|j| {
                let kind = j.kind();
                let node = kind.nodes()[0];
                (xy(self.lines.node_position(&q, node)), !kind.couples_bodies())
            })
            .collect();
        let masses = self.model.masses().iter().map(|m| xy(self.lines.node_position(&q, m.node))).collect();
        let probes = self.model.probes().iter().map(|p| xy(self.lines.point_position(&q, p.element, p.xi))).collect();
        Ok(Frame { lines, joints, masses, probes })
    }

    /// The instant of this run's time grid nearest `t`.
    fn nearest(&self, t: f64) -> usize {
        let ts = &self.reader.t;
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
    if !(opts.fps.is_finite() && opts.fps > 0.0 && opts.fps <= 100.0) {
        return Err(Error::Usage(format!("--fps {} is not in (0, 100] frames per second", opts.fps)));
    }
    let main = Run::open(result, limits)?;
    let other = compare.map(|p| Run::open(p, limits)).transpose()?;
    if main.reader.t.is_empty() {
        return Err(Error::input(result, "t", "is empty: the run recorded no instant"));
    }
    let indices = frame_indices(main.reader.t.len(), opts.max_frames);
    let mut frames = Vec::with_capacity(indices.len());
    for &k in &indices {
        let t = main.reader.t[k];
        let second = match &other {
            Some(o) if !o.reader.t.is_empty() => Some(o.frame(o.nearest(t))?),
            _ => None,
        };
        frames.push((t, main.frame(k)?, second));
    }
    let bounds = Bounds::of(frames.iter().flat_map(|(_, a, b)| std::iter::once(a).chain(b)));
    let width = opts.size.0.clamp(120, 4000);
    let height = opts.size.1.unwrap_or_else(|| fitted_height(width, &bounds)).clamp(120, 4000);
    let title = match &other {
        Some(o) => format!("{} (solid) vs {} (dashed)", main.name, o.name),
        None => main.name.clone(),
    };
    let delay_ms = (1000.0 / opts.fps).round().max(10.0) as u32;
    crate::io::atomic::write_file_atomically(out, |tmp| {
        draw(tmp, (width, height), delay_ms, &title, &bounds, &frames)
            .map_err(|e| Error::io(out, std::io::Error::other(e)))?;
        mark_gif(tmp)
    })?;
    let bytes = std::fs::metadata(out).map_err(|e| Error::io(out, e))?.len();
    Ok(Animation { frames: frames.len(), bytes, width, height })
}

/// The data's bounding box over every frame of both runs.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    x: (f64, f64),
    y: (f64, f64),
}

impl Bounds {
    fn of<'a>(frames: impl Iterator<Item = &'a Frame>) -> Bounds {
        let mut b = Bounds { x: (f64::MAX, f64::MIN), y: (f64::MAX, f64::MIN) };
        for f in frames {
            let points =
                f.lines.iter().flatten().chain(f.joints.iter().map(|j| &j.0)).chain(&f.masses).chain(&f.probes);
            for &(x, y) in points.filter(|p| p.0.is_finite() && p.1.is_finite()) {
                b.x = (b.x.0.min(x), b.x.1.max(x));
                b.y = (b.y.0.min(y), b.y.1.max(y));
            }
        }
        if b.x.0 > b.x.1 {
            return Bounds { x: (-1.0, 1.0), y: (-1.0, 1.0) };
        }
        // a margin of 5 % of the larger extent (never zero: a motion along a line)
        let pad = 0.05 * (b.x.1 - b.x.0).max(b.y.1 - b.y.0).max(1e-9);
        Bounds { x: (b.x.0 - pad, b.x.1 + pad), y: (b.y.0 - pad, b.y.1 + pad) }
    }

    /// The ranges grown (about their centres) to `w : h` pixels, so a metre is as long
    /// across as up (equal axes).
    fn equal(&self, w: f64, h: f64) -> Bounds {
        let (dx, dy) = (self.x.1 - self.x.0, self.y.1 - self.y.0);
        let per_pixel = (dx / w).max(dy / h);
        let grow = |(a, b): (f64, f64), span: f64| {
            let c = 0.5 * (a + b);
            (c - 0.5 * span, c + 0.5 * span)
        };
        Bounds { x: grow(self.x, per_pixel * w), y: grow(self.y, per_pixel * h) }
    }
}

/// Margins around the plot: title strip, axis labels.
const TITLE: u32 = 34;
const LEFT: u32 = 64;
const BOTTOM: u32 = 36;
const MARGIN: u32 = 10;

/// The height at which the motion's box fills the plot's width with equal axes, kept
/// between 40 % and 100 % of the width.
fn fitted_height(width: u32, b: &Bounds) -> u32 {
    let plot_w = width.saturating_sub(LEFT + 2 * MARGIN).max(1) as f64;
    let plot_h = plot_w * (b.y.1 - b.y.0) / (b.x.1 - b.x.0);
    let h = plot_h.clamp(0.4 * width as f64, width as f64) as u32;
    h + TITLE + BOTTOM + 2 * MARGIN
}

fn draw(
    path: &Path,
    size: (u32, u32),
    delay_ms: u32,
    title: &str,
    bounds: &Bounds,
    frames: &[(f64, Frame, Option<Frame>)],
) -> std::result::Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    register_font();
    let root = BitMapBackend::gif(path, size, delay_ms).map_err(|x| e(&x))?.into_drawing_area();
    let plot_w = size.0.saturating_sub(LEFT + 2 * MARGIN).max(1) as f64;
    let plot_h = size.1.saturating_sub(TITLE + BOTTOM + 2 * MARGIN).max(1) as f64;
    let b = bounds.equal(plot_w, plot_h);
    let (x_fmt, y_fmt) = (linear_labels(b.x.0, b.x.1), linear_labels(b.y.0, b.y.1));
    for (t, main, second) in frames {
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let area = root.titled(&format!("{title}    t = {t:.4} s"), ("sans-serif", 16)).map_err(|x| e(&x))?;
        let mut chart = ChartBuilder::on(&area)
            .margin(MARGIN)
            .x_label_area_size(BOTTOM)
            .y_label_area_size(LEFT)
            .build_cartesian_2d(b.x.0..b.x.1, b.y.0..b.y.1)
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc("x, m")
            .y_desc("y, m")
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .label_style(("sans-serif", 12))
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.08))
            .draw()
            .map_err(|x| e(&x))?;
        if let Some(s) = second {
            draw_frame(&mut chart, s, COLORS[1], true)?;
        }
        draw_frame(&mut chart, main, COLORS[0], false)?;
        root.present().map_err(|x| e(&x))?;
    }
    Ok(())
}

type Chart<'a, 'b> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// The centre lines (solid or dashed), then the marks: ground joints as triangles,
/// joints between bodies as rings, point masses as discs, probes as crosses.
fn draw_frame(chart: &mut Chart<'_, '_>, f: &Frame, colour: RGBColor, dashed: bool) -> std::result::Result<(), String> {
    let e = |x: DrawingAreaErrorKind<_>| x.to_string();
    for line in &f.lines {
        if dashed {
            chart.draw_series(DashedLineSeries::new(line.iter().copied(), 6, 4, colour.stroke_width(2))).map_err(e)?;
        } else {
            chart.draw_series(LineSeries::new(line.iter().copied(), colour.stroke_width(2))).map_err(e)?;
        }
    }
    let ink = if dashed { colour } else { BLACK };
    for &(p, ground) in &f.joints {
        if ground {
            chart.draw_series(std::iter::once(TriangleMarker::new(p, 7, ink.filled()))).map_err(e)?;
        } else {
            chart.draw_series(std::iter::once(Circle::new(p, 5, ink.stroke_width(2)))).map_err(e)?;
        }
    }
    chart.draw_series(f.masses.iter().map(|&p| Circle::new(p, 6, COLORS[2].filled()))).map_err(e)?;
    chart.draw_series(f.probes.iter().map(|&p| Cross::new(p, 5, COLORS[3].stroke_width(2)))).map_err(e)?;
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

    /// Equal axes: the grown box has the pixels' aspect and still holds the data.
    #[test]
    fn equal_axes_keep_the_data_and_the_aspect() {
        let b = Bounds { x: (0.0, 2.0), y: (-0.5, 0.5) };
        let e = b.equal(400.0, 400.0);
        assert!(((e.x.1 - e.x.0) - (e.y.1 - e.y.0)).abs() < 1e-12);
        assert!(e.y.0 <= -0.5 && e.y.1 >= 0.5 && e.x == (0.0, 2.0));
        let e = b.equal(800.0, 100.0);
        assert!(((e.x.1 - e.x.0) / 800.0 - (e.y.1 - e.y.0) / 100.0).abs() < 1e-12 && e.y == (-0.5, 0.5));
    }
}
