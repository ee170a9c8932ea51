//! The report's figures (plotters), each written as SVG (for the report and papers) and PNG
//! (for slides and notebooks) from one description: panels stacked over a shared x axis,
//! the legend in a strip to the right of the data (never over it), log axes labelled in
//! powers of ten, and optional vertical markers (the training loads).

use crate::error::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Style {
    Line,
    Dashed,
    /// filled circles, no line (measured points, e.g. validated errors)
    Markers,
}

pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub style: Style,
    /// its colour; `None`: the palette's colour of its place in the panel
    pub color: Option<RGBColor>,
}

impl Series {
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>, style: Style) -> Series {
        Series { name: name.into(), points, style, color: None }
    }

    /// Drawn in the palette's colour `k` (cycling): the series of one run or one quantity
    /// share a colour (a full run solid, its reduced run dashed).
    pub fn colored(self, k: usize) -> Series {
        self.in_color(COLORS[k % COLORS.len()])
    }

    /// Drawn in the colour `c`.
    pub fn in_color(mut self, c: RGBColor) -> Series {
        self.color = Some(c);
        self
    }

    /// A horizontal line at `y` over the x range `x` of the other series (a reference
    /// value, e.g. a speedup of 1×), black: apart from the grey dashed training markers.
    pub fn level(name: impl Into<String>, y: f64, (x0, x1): (f64, f64)) -> Series {
        Series::new(name, vec![(x0, y), (x1, y)], Style::Line).in_color(BLACK)
    }

    /// The colour it is drawn in as the `i`-th series of its panel.
    fn color_at(&self, i: usize) -> RGBColor {
        self.color.unwrap_or(COLORS[i % COLORS.len()])
    }
}

/// One chart of a figure: its y axis and series.
pub struct Panel {
    pub y_label: String,
    pub log_y: bool,
    pub series: Vec<Series>,
}

/// Panels stacked over one x axis; `markers` are vertical lines drawn on every panel
/// (labelled once in the legend as `marker_label`).
pub struct Figure {
    pub title: String,
    pub x_label: String,
    pub panels: Vec<Panel>,
    pub markers: Vec<f64>,
    pub marker_label: String,
}

const WIDTH: u32 = 960;
const LEGEND: u32 = 210;
const PANEL_HEIGHT: u32 = 300;
/// Colour-blind-safe palette (Okabe & Ito 2008), in order of use.
pub const COLORS: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
    RGBColor(230, 159, 0),
    RGBColor(0, 0, 0),
];
const MARKER_COLOR: RGBColor = RGBColor(120, 120, 120);

pub fn register_font() {
    // both backends measure (and the PNG one draws) text with this font, built into the
    // binary: no system fonts needed on a fresh machine
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    });
}

fn usable(log_y: bool) -> impl Fn(&(f64, f64)) -> bool {
    move |&(x, y)| x.is_finite() && y.is_finite() && (!log_y || y > 0.0)
}

/// `1e-4`, `3e-4`: a log axis's labels, short and never garbled.
fn log_label(v: &f64) -> String {
    let s = format!("{v:.0e}");
    s.replace("e0", "").replace("e-0", "e-")
}

/// A log axis over `lo..hi` labels only ticks at whole mantissas (plotters also places ticks
/// such as 9.5e-4, which `log_label` would print as a second "1e-3"), and over more than a
/// factor of 10 only 1, 2 and 5 of each decade, so that the labels of the crowded top of a
/// decade do not run into each other.
pub fn log_labels(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let sparse = hi > 10.0 * lo;
    move |v: &f64| {
        if !(*v > 0.0) {
            return String::new();
        }
        let m = v / 10f64.powf(v.log10().floor());
        let whole = m.round();
        let keep = (m - whole).abs() < 1e-6 * whole && (!sparse || [1.0, 2.0, 5.0, 10.0].contains(&whole));
        if keep {
            log_label(v)
        } else {
            String::new()
        }
    }
}

/// Linear labels with as many digits as the axis span `lo..hi` needs (scientific notation
/// for spans below 1e-3, where fixed decimals would print every tick as 0). A tick within
/// 1e-9 of the span of zero is 0: plotters computes ticks as lo + k·step, so the tick at
/// zero carries the round-off of the span (it printed as -2.7e-20 on a probe-error axis).
pub fn linear_labels(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let span = (hi - lo).abs();
    move |v: &f64| {
        let v = &if v.abs() <= 1e-9 * span { 0.0 } else { *v };
        if span > 0.0 && span < 1e-3 {
            return log_label_precise(*v);
        }
        let digits = if span > 0.0 { (2.0 - (span / 5.0).log10().floor()).clamp(0.0, 6.0) as usize } else { 3 };
        let s = format!("{v:.digits$}");
        let s = if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s };
        if s == "-0" {
            "0".into()
        } else {
            s
        }
    }
}

/// `-1.5e-5`: two significant digits in scientific notation; 0 as `0`.
fn log_label_precise(v: f64) -> String {
    if v == 0.0 || v.abs() < 1e-300 {
        return "0".into();
    }
    format!("{v:.1e}").replace(".0e", "e")
}

impl Figure {
    fn x_range(&self) -> Option<(f64, f64)> {
        let xs = self
            .panels
            .iter()
            .flat_map(|p| {
                p.series.iter().flat_map(move |s| s.points.iter().copied().filter(usable(p.log_y)).map(|q| q.0))
            })
            .chain(self.markers.iter().copied().filter(|x| x.is_finite()));
        let (a, b) = xs.fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
        if a > b {
            return None;
        }
        Some(if b > a { (a, b) } else { (a - 0.5, b + 0.5) })
    }

    /// Writes `<stem>.svg` and `<stem>.png`; returns their paths.
    pub fn save(&self, stem: &Path) -> Result<Vec<PathBuf>> {
        let svg = stem.with_extension("svg");
        let png = stem.with_extension("png");
        let height = 70 + PANEL_HEIGHT * self.panels.len().max(1) as u32;
        register_font();
        {
            let root = SVGBackend::new(&svg, (WIDTH, height)).into_drawing_area();
            self.draw(&root, &svg)?;
            root.present().map_err(|e| not_drawn(&svg, e))?;
        }
        let mut buf = vec![0u8; (WIDTH * height * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (WIDTH, height)).into_drawing_area();
            self.draw(&root, &png)?;
            root.present().map_err(|e| not_drawn(&png, e))?;
        }
        write_png(&png, &buf, WIDTH, height)?;
        Ok(vec![svg, png])
    }

    /// Draws the figure on `root`; a failure is one to write `file`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, file: &Path) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let e = |x: &dyn std::fmt::Display| not_drawn(file, x);
        let (x0, x1) = self.x_range().ok_or_else(|| not_drawn(file, "nothing to plot"))?;
        let pad = 0.02 * (x1 - x0);
        let (x0, x1) = (x0 - pad, x1 + pad);
        let x_fmt = linear_labels(x0, x1);
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let area = root.titled(&self.title, ("sans-serif", 22)).map_err(|x| e(&x))?;
        let (plots, legend) = area.split_horizontally(WIDTH - LEGEND);
        let n = self.panels.len().max(1);
        let rows = plots.split_evenly((n, 1));
        for (k, (panel, row)) in self.panels.iter().zip(&rows).enumerate() {
            let last = k + 1 == n;
            let pts: Vec<(f64, f64)> =
                panel.series.iter().flat_map(|s| s.points.iter().copied()).filter(usable(panel.log_y)).collect();
            let (mut y0, mut y1) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
            if pts.is_empty() {
                (y0, y1) = if panel.log_y { (1e-16, 1.0) } else { (0.0, 1.0) };
            }
            let mut b = ChartBuilder::on(row);
            b.margin_left(8).margin_right(12).margin_top(8).margin_bottom(if last { 4 } else { 8 });
            b.x_label_area_size(if last { 48 } else { 22 }).y_label_area_size(84);
            macro_rules! finish {
                ($chart:expr, $ylo:expr, $yhi:expr, $fmt:expr) => {{
                    let mut chart = $chart;
                    let mut mesh = chart.configure_mesh();
                    mesh.y_desc(panel.y_label.as_str())
                        .y_label_formatter(&$fmt)
                        .x_label_formatter(&x_fmt)
                        .label_style(("sans-serif", 15))
                        .axis_desc_style(("sans-serif", 16))
                        .light_line_style(WHITE.mix(0.0))
                        .bold_line_style(BLACK.mix(0.12));
                    if last {
                        mesh.x_desc(self.x_label.as_str());
                    }
                    mesh.draw().map_err(|x| e(&x))?;
                    for &m in self.markers.iter().filter(|m| m.is_finite()) {
                        chart
                            .draw_series(DashedLineSeries::new(
                                vec![(m, $ylo), (m, $yhi)],
                                5,
                                4,
                                MARKER_COLOR.stroke_width(2),
                            ))
                            .map_err(|x| e(&x))?;
                    }
                    for (i, s) in panel.series.iter().enumerate() {
                        let c = s.color_at(i);
                        let data: Vec<(f64, f64)> = s.points.iter().copied().filter(usable(panel.log_y)).collect();
                        match s.style {
                            Style::Line => chart.draw_series(LineSeries::new(data, c.stroke_width(2))).map(|_| ()),
                            Style::Dashed => {
                                chart.draw_series(DashedLineSeries::new(data, 7, 4, c.stroke_width(2))).map(|_| ())
                            }
                            Style::Markers => {
                                chart.draw_series(data.into_iter().map(|p| Circle::new(p, 4, c.filled()))).map(|_| ())
                            }
                        }
                        .map_err(|x| e(&x))?;
                    }
                }};
            }
            if panel.log_y {
                let (y0, y1) = (y0 / 2.0, y1 * 2.0);
                let chart = b.build_cartesian_2d(x0..x1, (y0..y1).log_scale()).map_err(|x| e(&x))?;
                let y_fmt = log_labels(y0, y1);
                finish!(chart, y0, y1, y_fmt);
            } else {
                let p = if y1 > y0 { 0.06 * (y1 - y0) } else { 0.5 * y0.abs().max(1e-12) };
                let (y0, y1) = (y0 - p, y1 + p);
                let chart = b.build_cartesian_2d(x0..x1, y0..y1).map_err(|x| e(&x))?;
                let y_fmt = linear_labels(y0, y1);
                finish!(chart, y0, y1, y_fmt);
            }
        }
        self.draw_legend(&legend, file)
    }

    /// The legend, in its own strip right of the panels: one entry per series name (the
    /// colour of its first use), then the markers.
    fn draw_legend<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, file: &Path) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let e = |x: &dyn std::fmt::Display| not_drawn(file, x);
        let mut entries: Vec<(String, Style, RGBColor)> = Vec::new();
        for p in &self.panels {
            for (i, s) in p.series.iter().enumerate() {
                if !entries.iter().any(|(n, ..)| *n == s.name) {
                    entries.push((s.name.clone(), s.style, s.color_at(i)));
                }
            }
        }
        if !self.markers.is_empty() {
            entries.push((self.marker_label.clone(), Style::Dashed, MARKER_COLOR));
        }
        let font = ("sans-serif", 15).into_font();
        let mut y = 30;
        for (name, style, c) in &entries {
            match style {
                Style::Markers => area.draw(&Circle::new((18, y), 4, c.filled())),
                Style::Line => area.draw(&PathElement::new(vec![(6, y), (32, y)], c.stroke_width(2))),
                Style::Dashed => {
                    area.draw(&PathElement::new(vec![(6, y), (14, y)], c.stroke_width(2))).map_err(|x| e(&x))?;
                    area.draw(&PathElement::new(vec![(20, y), (32, y)], c.stroke_width(2)))
                }
            }
            .map_err(|x| e(&x))?;
            // a long name on as many lines as the strip needs, never cut off at its edge
            let style: TextStyle = font.clone().into();
            for line in wrap(name, LEGEND - 48, &|s| area.estimate_text_size(s, &style).map_or(0, |(w, _)| w)) {
                area.draw(&Text::new(line, (40, y - 8), font.clone())).map_err(|x| e(&x))?;
                y += 18;
            }
            y += 6;
        }
        Ok(())
    }
}

/// `text` broken into lines no wider than `width` (as `measure` gives a line's width), at
/// ", " or else at spaces; a single word wider than `width` keeps a line of its own.
pub fn wrap(text: &str, width: u32, measure: &dyn Fn(&str) -> u32) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    // pieces that end with their separator: "drive = 1.305, " "payload = 0.8"
    let pieces = text.split_inclusive(", ").flat_map(|p| {
        if measure(p.trim_end()) <= width {
            vec![p.to_string()]
        } else {
            p.split_inclusive(' ').map(str::to_string).collect()
        }
    });
    for piece in pieces {
        let joined = format!("{line}{piece}");
        if !line.is_empty() && measure(joined.trim_end()) > width {
            lines.push(line.trim_end().to_string());
            line = piece;
        } else {
            line = joined;
        }
    }
    if !line.trim_end().is_empty() || lines.is_empty() {
        lines.push(line.trim_end().to_string());
    }
    lines
}

/// Writes 8-bit RGB pixels `rgb` (row by row) as a PNG file.
pub fn write_png(path: &Path, rgb: &[u8], width: u32, height: u32) -> Result<()> {
    let file = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut w = enc.write_header().map_err(|e| not_drawn(path, e))?;
    w.write_image_data(rgb).map_err(|e| not_drawn(path, e))?;
    w.finish().map_err(|e| not_drawn(path, e))
}

/// A figure that could not be drawn or encoded as the failure to write its `file` (plotters
/// and the PNG encoder report their backends' and fonts' errors as text).
pub fn not_drawn(file: &Path, e: impl std::fmt::Display) -> Error {
    Error::io(file, std::io::Error::other(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Log-axis labels are powers of ten in short form (the old default printed
    /// "0.00000000000003" for 3e-4).
    #[test]
    fn log_labels_are_short() {
        assert_eq!(log_label(&3e-4), "3e-4");
        assert_eq!(log_label(&1e-10), "1e-10");
        assert_eq!(log_label(&1.0), "1");
        assert_eq!(log_label(&20.0), "2e1");
        // over several decades only 1, 2 and 5 are labelled; 9.5e-4 never prints a second 1e-3
        let f = log_labels(1e-5, 1e-3);
        assert_eq!((f(&2e-4), f(&5e-4), f(&1e-3)), ("2e-4".into(), "5e-4".into(), "1e-3".into()));
        assert_eq!((f(&3e-4), f(&9e-4), f(&9.5e-4)), (String::new(), String::new(), String::new()));
        // within a factor of ten every whole mantissa is labelled
        let f = log_labels(2e-4, 1e-3);
        assert_eq!((f(&3e-4), f(&9e-4), f(&9.5e-4)), ("3e-4".into(), "9e-4".into(), String::new()));
        let f = linear_labels(-1.2, 1.2);
        assert_eq!((f(&-0.0), f(&0.25), f(&-1.2)), ("0".into(), "0.25".into(), "-1.2".into()));
        // a span of 2e-4 m: the old fixed 4 decimals printed 0 for every tick
        let f = linear_labels(-1e-4, 1e-4);
        assert_eq!((f(&2e-5), f(&-1.5e-5), f(&0.0)), ("2e-5".into(), "-1.5e-5".into(), "0".into()));
        // zero to round-off of the span is 0, on any span; a tick 1e-9 of the span off is not
        assert_eq!((f(&-2.7e-20), f(&2.7e-20)), ("0".into(), "0".into()));
        assert_eq!(linear_labels(-1e-12, 1e-12)(&3e-29), "0");
        assert_eq!(linear_labels(-1.2, 1.2)(&-2.7e-17), "0");
        assert_eq!(linear_labels(0.0, 1e-4)(&5e-12), "5e-12");
    }

    /// A legend name wider than its strip wraps at ", " (then at spaces), each line within
    /// the width (here one unit per character), nothing dropped.
    #[test]
    fn long_names_wrap() {
        let chars = |s: &str| s.chars().count() as u32;
        let name = "error_estimate, drive = 1.305, payload = 0.8";
        let lines = wrap(name, 20, &chars);
        assert_eq!(lines, vec!["error_estimate,", "drive = 1.305,", "payload = 0.8"]);
        assert_eq!(wrap("rel_error", 20, &chars), vec!["rel_error"]);
        // a piece wider than the strip breaks at its spaces
        assert_eq!(wrap("max probe error (m)", 10, &chars), vec!["max probe", "error (m)"]);
        assert!(lines.iter().all(|l| chars(l) <= 20) && lines.join(" ") == name);
    }

    /// A figure writes a valid SVG and a PNG of the stated size (the PNG header's width and
    /// height, read back by the png crate), for linear and log panels with markers.
    #[test]
    fn figure_writes_svg_and_png() {
        let dir = tempfile::tempdir().unwrap();
        let fig = Figure {
            title: "t".into(),
            x_label: "load scale".into(),
            panels: vec![
                Panel {
                    y_label: "error".into(),
                    log_y: true,
                    series: vec![
                        Series::new("estimate", vec![(0.5, 1e-4), (1.0, 2e-4), (1.5, 3e-4)], Style::Line),
                        Series::new("true", vec![(0.5, 8e-5), (1.5, 2e-4)], Style::Markers),
                    ],
                },
                Panel {
                    y_label: "y".into(),
                    log_y: false,
                    series: vec![Series::new("a", vec![(0.5, -1.0), (1.5, 1.0)], Style::Dashed)],
                },
            ],
            markers: vec![0.5, 1.0],
            marker_label: "training load".into(),
        };
        let files = fig.save(&dir.path().join("fig")).unwrap();
        let svg = std::fs::read_to_string(&files[0]).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.contains("training load") && svg.contains("2e-4") && svg.contains("5e-4")
        );
        let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&files[1]).unwrap()));
        let reader = dec.read_info().unwrap();
        assert_eq!((reader.info().width, reader.info().height), (WIDTH, 70 + 2 * PANEL_HEIGHT));
    }
}
