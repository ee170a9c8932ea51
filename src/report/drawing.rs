//! The mechanism drawn at one state `q`: the centre lines from the ANCF interpolation
//! ([`crate::physics::centre_line`]), the joints (each kind its mark, a slider with its
//! rail), point masses, springs (translational: a zig-zag; torsional: a spiral at the
//! node), probes and body names. One drawing for every use: the frames of `flexrom animate`
//! ([`crate::report::animate`]) and the report's figure of the model ([`crate::report::model_figure`]),
//! on any plotters backend (GIF, PNG, SVG).

use crate::model::Model;
use crate::physics::centre_line::CentreLines;
use crate::physics::joints::Joint;
use crate::physics::loads::{Load, SpringEnd};
use crate::report::plot::{linear_labels, not_drawn, COLORS};
use plotters::coord::types::RangedCoordf64;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters::style::TextStyle;
use plotters_backend::{BackendCoord, DrawingErrorKind};

/// How a part is marked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mark {
    /// a node pinned to the ground (`ground_pin`): a filled triangle
    GroundPin,
    /// two bodies pinned together (`pin`): a ring
    Pin,
    /// a node clamped to the ground (`clamp`): a filled square
    Clamp,
    /// a node on a ground rail (`slider`): a hollow square, the rail drawn through its point
    Slider,
    /// two bodies welded at an angle (`weld`): a filled diamond
    Weld,
    /// a prescribed motion (`driven_angle`, `driven_point`): two rings
    Drive,
    /// a point mass: a disc
    Mass,
    /// a probe: a cross
    Probe,
    /// a translational spring: a zig-zag between its ends
    Spring,
    /// a torsional spring: a spiral about its node
    TorsionalSpring,
}

impl Mark {
    /// The legend's words for the mark.
    pub fn name(self) -> &'static str {
        match self {
            Mark::GroundPin => "ground pin",
            Mark::Pin => "pin",
            Mark::Clamp => "clamp",
            Mark::Slider => "slider (rail)",
            Mark::Weld => "weld",
            Mark::Drive => "drive",
            Mark::Mass => "point mass",
            Mark::Probe => "probe",
            Mark::Spring => "spring",
            Mark::TorsionalSpring => "torsional spring",
        }
    }
}

type Point = (f64, f64);

/// A slider's rail: its point and unit direction.
#[derive(Clone, Copy, Debug)]
pub struct Rail {
    pub point: Point,
    pub direction: Point,
}

/// The mechanism at one state.
#[derive(Clone, Debug)]
pub struct Frame {
    /// each body's centre line
    pub lines: Vec<Vec<Point>>,
    /// each body's name and the middle sample of its centre line
    pub names: Vec<(String, Point)>,
    /// joints, masses and torsional springs: where and how each is marked
    pub marks: Vec<(Point, Mark)>,
    pub rails: Vec<Rail>,
    /// translational springs' ends, and whether the second is a ground point
    pub springs: Vec<(Point, Point, bool)>,
    /// probes: name, position
    pub probes: Vec<(String, Point)>,
}

fn xy(p: [f64; 2]) -> Point {
    (p[0], p[1])
}

impl Frame {
    /// `model` at the coordinates `q`, its centre lines sampled at `lines`' points.
    pub fn at(model: &Model, lines: &CentreLines, q: &[f64]) -> Frame {
        let r = lines.interpolate(q);
        let curves: Vec<Vec<Point>> = lines.bodies().map(|range| r[range].iter().map(|&p| xy(p)).collect()).collect();
        let names = model
            .bodies()
            .iter()
            .zip(&curves)
            .filter_map(|(b, c)| Some((b.name.clone(), *c.get(c.len() / 2)?)))
            .collect();
        let node = |n| xy(lines.node_position(q, n));
        let mut marks = Vec::new();
        let mut rails = Vec::new();
        for j in model.joints() {
            let kind = j.kind();
            let at = node(kind.nodes()[0]);
            let mark = match j {
                Joint::GroundPin(_) => Mark::GroundPin,
                Joint::Pin(_) => Mark::Pin,
                Joint::Clamp(_) => Mark::Clamp,
                Joint::Slider(s) => {
                    rails.push(Rail { point: xy(s.point), direction: xy(s.direction) });
                    Mark::Slider
                }
                Joint::Weld(_) => Mark::Weld,
                Joint::DrivenAngle(_) | Joint::DrivenPoint(_) => Mark::Drive,
            };
            marks.push((at, mark));
        }
        marks.extend(model.masses().iter().map(|m| (node(m.node), Mark::Mass)));
        let mut springs = Vec::new();
        for load in model.loads() {
            match load {
                Load::Spring(s) => springs.push(match s.b {
                    SpringEnd::Node(b) => (node(s.a), node(b), false),
                    SpringEnd::Point(p) => (node(s.a), xy(p), true),
                }),
                Load::TorsionalSpring(s) => marks.push((node(s.a), Mark::TorsionalSpring)),
                _ => {}
            }
        }
        let probes =
            model.probes().iter().map(|p| (p.name.clone(), xy(lines.point_position(q, p.element, p.xi)))).collect();
        Frame { lines: curves, names, marks, rails, springs, probes }
    }

    /// Every point the frame draws (rails are infinite: their points only).
    fn points(&self) -> impl Iterator<Item = &Point> {
        let springs = self.springs.iter().flat_map(|(a, b, _)| [a, b]);
        self.lines
            .iter()
            .flatten()
            .chain(self.marks.iter().map(|m| &m.0))
            .chain(springs)
            .chain(self.probes.iter().map(|p| &p.1))
            .chain(self.rails.iter().map(|r| &r.point))
    }

    /// The kinds of mark the frame holds, in [`Mark`]'s order: what a legend lists.
    pub fn kinds(&self) -> Vec<Mark> {
        let mut k: Vec<Mark> = self.marks.iter().map(|m| m.1).collect();
        k.extend(self.springs.first().map(|_| Mark::Spring));
        k.extend(self.probes.first().map(|_| Mark::Probe));
        let order = |m: &Mark| ALL.iter().position(|a| a == m);
        k.sort_by_key(order);
        k.dedup();
        k
    }
}

const ALL: [Mark; 10] = [
    Mark::GroundPin,
    Mark::Pin,
    Mark::Clamp,
    Mark::Slider,
    Mark::Weld,
    Mark::Drive,
    Mark::Spring,
    Mark::TorsionalSpring,
    Mark::Mass,
    Mark::Probe,
];

/// Room around a drawing of the motion, px: its title, the y axis's labels, the x axis's
/// labels, the margin.
pub const TITLE: u32 = 34;
pub const LEFT: u32 = 64;
pub const BOTTOM: u32 = 36;
pub const MARGIN: u32 = 10;

/// The chart a drawing of the motion is made on (an animation's frame, the report's model):
/// `b` on `area`, x and y in metres, a faint grid; a failure is one to write `file`.
pub fn motion_chart<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, plotters::coord::Shift>,
    b: &Bounds,
    file: &std::path::Path,
) -> crate::error::Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| not_drawn(file, x);
    let (x_fmt, y_fmt) = (linear_labels(b.x.0, b.x.1), linear_labels(b.y.0, b.y.1));
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .x_label_area_size(BOTTOM)
        .y_label_area_size(LEFT)
        .build_cartesian_2d(b.x.0..b.x.1, b.y.0..b.y.1)
        .map_err(e)?;
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
        .map_err(e)?;
    Ok(chart)
}

/// The data's bounding box over frames, with a margin.
#[derive(Clone, Copy, Debug)]
pub struct Bounds {
    pub x: (f64, f64),
    pub y: (f64, f64),
}

impl Bounds {
    /// The box of every finite point of `frames`, grown by 5 % of its larger extent.
    pub fn of<'a>(frames: impl Iterator<Item = &'a Frame>) -> Bounds {
        let mut b = Bounds { x: (f64::MAX, f64::MIN), y: (f64::MAX, f64::MIN) };
        for f in frames {
            for &(x, y) in f.points().filter(|p| p.0.is_finite() && p.1.is_finite()) {
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
    pub fn equal(&self, w: f64, h: f64) -> Bounds {
        let (dx, dy) = (self.x.1 - self.x.0, self.y.1 - self.y.0);
        let per_pixel = (dx / w).max(dy / h);
        let grow = |(a, b): (f64, f64), span: f64| {
            let c = 0.5 * (a + b);
            (c - 0.5 * span, c + 0.5 * span)
        };
        Bounds { x: grow(self.x, per_pixel * w), y: grow(self.y, per_pixel * h) }
    }

    /// The part of the line `p + s d` inside the box (Liang–Barsky), if any.
    fn clip(&self, p: Point, d: Point) -> Option<(Point, Point)> {
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for (p, d, (a, b)) in [(p.0, d.0, self.x), (p.1, d.1, self.y)] {
            if d == 0.0 {
                if p < a || p > b {
                    return None;
                }
                continue;
            }
            let (s0, s1) = ((a - p) / d, (b - p) / d);
            lo = lo.max(s0.min(s1));
            hi = hi.min(s0.max(s1));
        }
        (lo < hi && lo.is_finite()).then_some(((p.0 + lo * d.0, p.1 + lo * d.1), (p.0 + hi * d.0, p.1 + hi * d.1)))
    }
}

/// How a frame is drawn: its colour, dashed (a compared run) or solid, with the bodies'
/// and probes' names or without.
#[derive(Clone, Copy, Debug)]
pub struct Style {
    pub colour: RGBColor,
    pub dashed: bool,
    pub names: bool,
}

/// A chart on equal axes in metres.
pub type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

const SPRING_INK: RGBColor = RGBColor(90, 90, 90);
const RAIL_INK: RGBColor = RGBColor(150, 150, 150);

/// The mark `m` at `at` (any coordinate: data on a chart, pixels in a legend), in `ink`;
/// drawn in pixels about the point, so its size does not change with the axes.
pub struct MarkElement<C> {
    pub at: C,
    pub mark: Mark,
    pub ink: RGBColor,
}

impl<'a, C> PointCollection<'a, C> for &'a MarkElement<C> {
    type Point = &'a C;
    type IntoIter = std::iter::Once<&'a C>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.at)
    }
}

impl<C, DB: DrawingBackend> Drawable<DB> for MarkElement<C> {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        mut points: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        let Some((x, y)) = points.next() else { return Ok(()) };
        let at = |v: &[(i32, i32)]| v.iter().map(|&(a, b)| (x + a, y + b)).collect::<Vec<_>>();
        let (line, fill) = (self.ink.stroke_width(2), self.ink.filled());
        match self.mark {
            Mark::GroundPin => backend.fill_polygon(at(&[(0, -3), (-7, 8), (7, 8)]), &fill),
            Mark::Pin => backend.draw_circle((x, y), 5, &line, false),
            Mark::Clamp => backend.draw_rect((x - 6, y - 6), (x + 6, y + 6), &fill, true),
            Mark::Slider => backend.draw_rect((x - 7, y - 5), (x + 7, y + 5), &line, false),
            Mark::Weld => backend.fill_polygon(at(&[(0, -7), (7, 0), (0, 7), (-7, 0)]), &fill),
            Mark::Drive => {
                backend.draw_circle((x, y), 4, &line, false)?;
                backend.draw_circle((x, y), 9, &line, false)
            }
            Mark::Mass => backend.draw_circle((x, y), 6, &COLORS[2].filled(), true),
            Mark::Probe => {
                let pen = COLORS[3].stroke_width(2);
                backend.draw_line((x - 5, y - 5), (x + 5, y + 5), &pen)?;
                backend.draw_line((x - 5, y + 5), (x + 5, y - 5), &pen)
            }
            Mark::TorsionalSpring => backend.draw_path(at(&spiral()), &SPRING_INK.stroke_width(2)),
            Mark::Spring => {
                let zig: Vec<(i32, i32)> = (0..=6).map(|i| (-12 + 4 * i, [0, 5, 0, -5][i as usize % 4])).collect();
                backend.draw_path(at(&zig), &SPRING_INK.stroke_width(2))
            }
        }
    }
}

/// A name written beside a point, offset in pixels.
pub struct Label<C> {
    pub at: C,
    pub text: String,
    pub offset: (i32, i32),
    pub style: TextStyle<'static>,
}

impl<'a, C> PointCollection<'a, C> for &'a Label<C> {
    type Point = &'a C;
    type IntoIter = std::iter::Once<&'a C>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.at)
    }
}

impl<C, DB: DrawingBackend> Drawable<DB> for Label<C> {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        mut points: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        match points.next() {
            Some((x, y)) => backend.draw_text(&self.text, &self.style, (x + self.offset.0, y + self.offset.1)),
            None => Ok(()),
        }
    }
}

/// A spiral of 1½ turns about the origin, radius 3 to 10 pixels.
fn spiral() -> Vec<(i32, i32)> {
    (0..=36)
        .map(|i| {
            let a = i as f64 / 36.0 * 3.0 * std::f64::consts::PI;
            let r = 3.0 + 7.0 * i as f64 / 36.0;
            ((r * a.cos()).round() as i32, (-r * a.sin()).round() as i32)
        })
        .collect()
}

/// A spring's zig-zag from `a` to `b`: straight for the first and last fifth, six
/// half-coils between, of amplitude a tenth of the length.
fn zigzag(a: Point, b: Point) -> Vec<Point> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (n, amp) = (6, 0.1);
    let mut out = vec![a];
    for i in 0..=n {
        let s = 0.2 + 0.6 * i as f64 / n as f64;
        let side = if i == 0 || i == n {
            0.0
        } else if i % 2 == 1 {
            amp
        } else {
            -amp
        };
        out.push((a.0 + s * dx - side * dy, a.1 + s * dy + side * dx));
    }
    out.push(b);
    out
}

/// Draws `f` on `chart` (clipped rails first, then springs, centre lines, marks, probes,
/// names); a failure is one to write `file`.
pub fn draw_frame<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    f: &Frame,
    bounds: &Bounds,
    style: Style,
    file: &std::path::Path,
) -> crate::error::Result<()>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| not_drawn(file, x);
    let colour = style.colour;
    for r in &f.rails {
        if let Some((p, q)) = bounds.clip(r.point, r.direction) {
            chart.draw_series(LineSeries::new([p, q], RAIL_INK.stroke_width(1))).map_err(e)?;
        }
    }
    let spring_ink = if style.dashed { colour } else { SPRING_INK };
    for &(a, b, ground) in &f.springs {
        chart.draw_series(LineSeries::new(zigzag(a, b), spring_ink.stroke_width(1))).map_err(e)?;
        if ground {
            chart.draw_series([MarkElement { at: b, mark: Mark::GroundPin, ink: RAIL_INK }]).map_err(e)?;
        }
    }
    for line in &f.lines {
        if style.dashed {
            chart.draw_series(DashedLineSeries::new(line.iter().copied(), 6, 4, colour.stroke_width(2))).map_err(e)?;
        } else {
            chart.draw_series(LineSeries::new(line.iter().copied(), colour.stroke_width(2))).map_err(e)?;
        }
    }
    let ink = if style.dashed { colour } else { BLACK };
    chart.draw_series(f.marks.iter().map(|&(at, mark)| MarkElement { at, mark, ink })).map_err(e)?;
    chart.draw_series(f.probes.iter().map(|(_, p)| MarkElement { at: *p, mark: Mark::Probe, ink })).map_err(e)?;
    if style.names {
        let label = |(text, at): &(String, Point), offset, size, colour: &RGBColor| Label {
            at: *at,
            text: text.clone(),
            offset,
            style: ("sans-serif", size).into_font().color(colour),
        };
        chart.draw_series(f.names.iter().map(|n| label(n, (6, -20), 14, &BLACK))).map_err(e)?;
        chart.draw_series(f.probes.iter().map(|n| label(n, (7, 3), 11, &COLORS[3]))).map_err(e)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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

    /// A horizontal rail through (0.5, 0.2) crosses the unit box from x = 0 to 1; a
    /// diagonal one through the centre from corner to corner; one above the box not at all.
    #[test]
    fn rails_are_clipped_to_the_box() {
        let b = Bounds { x: (0.0, 1.0), y: (0.0, 1.0) };
        assert_eq!(b.clip((0.5, 0.2), (1.0, 0.0)), Some(((0.0, 0.2), (1.0, 0.2))));
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let ((x0, y0), (x1, y1)) = b.clip((0.5, 0.5), (s, s)).unwrap();
        assert!([x0, y0].iter().all(|v| v.abs() < 1e-12) && [x1, y1].iter().all(|v| (v - 1.0).abs() < 1e-12));
        assert_eq!(b.clip((0.5, 2.0), (1.0, 0.0)), None);
    }

    /// The zig-zag starts and ends at the spring's ends and swings a tenth of its length
    /// to either side of the line between them.
    #[test]
    fn a_zigzag_runs_between_the_ends() {
        let z = zigzag((0.0, 0.0), (2.0, 0.0));
        assert_eq!((z[0], *z.last().unwrap()), ((0.0, 0.0), (2.0, 0.0)));
        let swing = z.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
        assert!((swing - 0.2).abs() < 1e-12, "0.1 × length 2");
    }
}
