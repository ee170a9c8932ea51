//! Maps over a box of parameters: the runs drawn as points at their parameters' values,
//! coloured by a value (rel_error, its estimate, the speedup), the training runs marked
//! with crosses. Two parameters give one map per layer; more give one per pair of
//! parameters (a row each), every point seen along the two axes of the pair. The colour
//! scale is shared by the layers of a figure (so that rel_error and its estimate compare
//! by colour) and drawn as a colour bar, logarithmic for errors:
//!
//! ```text
//!     s(v) = (log v − log v_min) / (log v_max − log v_min)   (log scale; linear: without the logs)
//!     colour(v) = viridis(s(v))                               (s clamped to [0, 1])
//! ```
//!
//! viridis (van der Walt & Smith 2015) runs from dark violet (smallest) to yellow
//! (largest), in even lightness steps and readable with colour-blindness. A run without a
//! value there (NaN, ∞, or ≤ 0 on a log scale) is an open grey circle.

use crate::error::{Error, Result};
use crate::report::plot::{linear_labels, log_labels, not_drawn, register_font, write_png};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// One axis of the box: a parameter and its range.
#[derive(Clone)]
pub struct MapAxis {
    pub name: String,
    pub lower: f64,
    pub upper: f64,
    /// drawn on a logarithmic axis (a `scale = "log"` parameter)
    pub log: bool,
}

/// The points of one map: each run's coordinates (one per axis, in the axes' order) and
/// its value.
pub struct Layer {
    pub title: String,
    pub points: Vec<(Vec<f64>, f64)>,
}

/// A figure of maps: a row per pair of axes, a column per layer, one colour bar.
pub struct Map {
    pub title: String,
    pub axes: Vec<MapAxis>,
    pub layers: Vec<Layer>,
    /// the colour bar's label (the value and its unit)
    pub value_label: String,
    pub log_values: bool,
    /// the training runs' coordinates, marked on every map
    pub training: Vec<Vec<f64>>,
    /// a value marked on the colour bar (the tolerance, a speedup of 1×) and its label
    pub mark: Option<(f64, String)>,
}

const CELL_WIDTH: u32 = 420;
const CELL_HEIGHT: u32 = 380;
const STRIP: u32 = 220;
const TITLE: u32 = 40;
const NO_VALUE: RGBColor = RGBColor(150, 150, 150);

/// viridis at s = 0, 1/8, …, 1 (matplotlib's table, rounded to 8 bits); between them linear.
const VIRIDIS: [(u8, u8, u8); 9] = [
    (68, 1, 84),
    (71, 44, 122),
    (59, 81, 139),
    (44, 113, 142),
    (33, 144, 141),
    (39, 173, 129),
    (92, 200, 99),
    (170, 220, 50),
    (253, 231, 37),
];

/// The colour of `s` ∈ [0, 1] (clamped).
pub fn viridis(s: f64) -> RGBColor {
    let x = if s.is_nan() { 0.0 } else { s.clamp(0.0, 1.0) } * (VIRIDIS.len() - 1) as f64;
    let k = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - k as f64;
    let mix = |a: u8, b: u8| (a as f64 + f * (b as f64 - a as f64)).round() as u8;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Every pair `(i, j)`, `i < j`, of `n` axes, in order: (0, 1), (0, 2), (1, 2), …
fn pairs(n: usize) -> Vec<(usize, usize)> {
    (0..n).flat_map(|i| (i + 1..n).map(move |j| (i, j))).collect()
}

impl Map {
    /// Whether `v` has a place on the colour scale.
    fn has_value(&self, v: f64) -> bool {
        v.is_finite() && (!self.log_values || v > 0.0)
    }

    /// The colour scale's ends: the values of every layer and the marked value, so that the
    /// mark (the tolerance, 1×) is always on the bar (a decade, or ±0.5, around a single
    /// value; 1e-16..1 without any).
    fn value_range(&self) -> (f64, f64) {
        let marked = self.mark.iter().map(|m| m.0);
        let vs =
            self.layers.iter().flat_map(|l| l.points.iter().map(|p| p.1)).chain(marked).filter(|v| self.has_value(*v));
        let (lo, hi) = vs.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
        match (lo <= hi, self.log_values) {
            (false, true) => (1e-16, 1.0),
            (false, false) => (0.0, 1.0),
            (true, true) if lo == hi => (lo / 10f64.sqrt(), hi * 10f64.sqrt()),
            (true, false) if lo == hi => (lo - 0.5, hi + 0.5),
            _ => (lo, hi),
        }
    }

    /// `s(v)` of the module documentation over the scale `(lo, hi)`.
    fn position(&self, v: f64, (lo, hi): (f64, f64)) -> f64 {
        if self.log_values {
            (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
        } else {
            (v - lo) / (hi - lo)
        }
    }

    /// The colour bar's ticks over `(lo, hi)` and their labels: on a log scale 1, 2 and 5 of
    /// each decade (every whole mantissa over less than a decade); on a linear one at most
    /// eight steps of 1, 2 or 5 times a power of ten.
    fn ticks(&self, (lo, hi): (f64, f64)) -> Vec<(f64, String)> {
        let inside = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
        if self.log_values {
            let label = log_labels(lo, hi);
            let decades = (lo.log10().floor() as i32)..=(hi.log10().ceil() as i32);
            let mut ticks: Vec<(f64, String)> = decades
                .flat_map(|d| (1..10).map(move |m| m as f64 * 10f64.powi(d)))
                .filter(inside)
                .map(|v| (v, label(&v)))
                .filter(|(_, l)| !l.is_empty())
                .collect();
            if ticks.len() < 2 {
                // a narrow range: its ends
                ticks = vec![(lo, format!("{lo:.2e}")), (hi, format!("{hi:.2e}"))];
            }
            ticks
        } else {
            let raw = (hi - lo) / 8.0;
            let p = 10f64.powf(raw.log10().floor());
            let step = [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * p).find(|s| *s >= raw).unwrap_or(10.0 * p);
            let label = linear_labels(lo, hi);
            let first = (lo / step).ceil() as i64;
            (first..).map(|k| k as f64 * step).take_while(|v| *v <= hi).map(|v| (v, label(&v))).collect()
        }
    }

    /// The figure's size: a cell per pair of axes and layer, the strip of the colour bar.
    pub fn size(&self) -> (u32, u32) {
        let rows = pairs(self.axes.len()).len().max(1) as u32;
        let cols = self.layers.len().max(1) as u32;
        (CELL_WIDTH * cols + STRIP, TITLE + CELL_HEIGHT * rows)
    }

    /// Writes `<stem>.svg` and `<stem>.png`; returns their paths.
    pub fn save(&self, stem: &Path) -> Result<Vec<PathBuf>> {
        if self.axes.len() < 2 {
            return Err(Error::usage("a map needs two parameters or more"));
        }
        let (svg, png) = (stem.with_extension("svg"), stem.with_extension("png"));
        let (w, h) = self.size();
        register_font();
        {
            let root = SVGBackend::new(&svg, (w, h)).into_drawing_area();
            self.draw(&root, &svg)?;
            root.present().map_err(|e| not_drawn(&svg, e))?;
        }
        let mut buf = vec![0u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            self.draw(&root, &png)?;
            root.present().map_err(|e| not_drawn(&png, e))?;
        }
        write_png(&png, &buf, w, h)?;
        Ok(vec![svg, png])
    }

    /// Draws the map on `root`; a failure is one to write `file`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, file: &Path) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let e = |x: &dyn std::fmt::Display| not_drawn(file, x);
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let area = root.titled(&self.title, ("sans-serif", 22)).map_err(|x| e(&x))?;
        let (w, _) = self.size();
        let (cells, strip) = area.split_horizontally(w - STRIP);
        let pairs = pairs(self.axes.len());
        let cols = self.layers.len().max(1);
        let grid = cells.split_evenly((pairs.len(), cols));
        let scale = self.value_range();
        for (r, &(i, j)) in pairs.iter().enumerate() {
            for (c, layer) in self.layers.iter().enumerate() {
                self.draw_cell(&grid[r * cols + c], layer, (i, j), scale, file)?;
            }
        }
        self.draw_strip(&strip, scale, file)
    }

    /// The map of `layer` over the axes `i` (x) and `j` (y).
    fn draw_cell<DB: DrawingBackend>(
        &self,
        cell: &DrawingArea<DB, Shift>,
        layer: &Layer,
        (i, j): (usize, usize),
        scale: (f64, f64),
        file: &Path,
    ) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let e = |x: &dyn std::fmt::Display| not_drawn(file, x);
        let (ax, ay) = (&self.axes[i], &self.axes[j]);
        // a margin of 4 % of each axis (in its own scale) so that points at the box's edge show
        let pad = |a: &MapAxis| {
            if a.log {
                let f = (a.upper / a.lower).powf(0.04);
                (a.lower / f, a.upper * f)
            } else {
                let d = 0.04 * (a.upper - a.lower);
                (a.lower - d, a.upper + d)
            }
        };
        let ((x0, x1), (y0, y1)) = (pad(ax), pad(ay));
        let label = |a: &MapAxis, lo: f64, hi: f64| -> Box<dyn Fn(&f64) -> String> {
            if a.log {
                Box::new(log_labels(lo, hi))
            } else {
                Box::new(linear_labels(lo, hi))
            }
        };
        let (x_fmt, y_fmt) = (label(ax, x0, x1), label(ay, y0, y1));
        let mut b = ChartBuilder::on(cell);
        b.caption(&layer.title, ("sans-serif", 16)).margin(10).x_label_area_size(44).y_label_area_size(64);
        let points: Vec<((f64, f64), Option<RGBColor>)> = layer
            .points
            .iter()
            .map(|(at, v)| ((at[i], at[j]), self.has_value(*v).then(|| viridis(self.position(*v, scale)))))
            .collect();
        let training: Vec<(f64, f64)> = self.training.iter().map(|at| (at[i], at[j])).collect();
        macro_rules! finish {
            ($chart:expr) => {{
                let mut chart = $chart.map_err(|x| e(&x))?;
                chart
                    .configure_mesh()
                    .x_desc(ax.name.as_str())
                    .y_desc(ay.name.as_str())
                    .x_label_formatter(&x_fmt)
                    .y_label_formatter(&y_fmt)
                    .label_style(("sans-serif", 14))
                    .axis_desc_style(("sans-serif", 15))
                    .light_line_style(WHITE.mix(0.0))
                    .bold_line_style(BLACK.mix(0.1))
                    .draw()
                    .map_err(|x| e(&x))?;
                for (p, c) in &points {
                    match c {
                        Some(c) => chart.draw_series(std::iter::once(Circle::new(*p, 6, c.filled()))),
                        None => chart.draw_series(std::iter::once(Circle::new(*p, 6, NO_VALUE.stroke_width(2)))),
                    }
                    .map_err(|x| e(&x))?;
                }
                chart
                    .draw_series(training.iter().map(|p| Cross::new(*p, 6, BLACK.stroke_width(2))))
                    .map_err(|x| e(&x))?;
            }};
        }
        match (ax.log, ay.log) {
            (false, false) => finish!(b.build_cartesian_2d(x0..x1, y0..y1)),
            (true, false) => finish!(b.build_cartesian_2d((x0..x1).log_scale(), y0..y1)),
            (false, true) => finish!(b.build_cartesian_2d(x0..x1, (y0..y1).log_scale())),
            (true, true) => finish!(b.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())),
        }
        Ok(())
    }

    /// The strip right of the maps: the key of the markers, then the colour bar.
    fn draw_strip<DB: DrawingBackend>(
        &self,
        strip: &DrawingArea<DB, Shift>,
        (lo, hi): (f64, f64),
        file: &Path,
    ) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let e = |x: &dyn std::fmt::Display| not_drawn(file, x);
        let font = ("sans-serif", 15).into_font();
        let (key, bar) = strip.split_vertically(110);
        let mid = viridis(0.5);
        key.draw(&Circle::new((18, 24), 6, mid.filled())).map_err(|x| e(&x))?;
        key.draw(&Text::new("run (colour: value)", (34, 16), font.clone())).map_err(|x| e(&x))?;
        key.draw(&Cross::new((18, 50), 6, BLACK.stroke_width(2))).map_err(|x| e(&x))?;
        key.draw(&Text::new("training run", (34, 42), font.clone())).map_err(|x| e(&x))?;
        let missing = self.layers.iter().flat_map(|l| &l.points).any(|p| !self.has_value(p.1));
        if missing {
            key.draw(&Circle::new((18, 76), 6, NO_VALUE.stroke_width(2))).map_err(|x| e(&x))?;
            key.draw(&Text::new("no value", (34, 68), font.clone())).map_err(|x| e(&x))?;
        }
        let mut b = ChartBuilder::on(&bar);
        b.margin_top(10).margin_bottom(50).margin_left(8).margin_right(100).y_label_area_size(80);
        // the bar in the scale's own coordinate, s(v) of the module documentation (0..1
        // bottom to top), its bands the colours of s and its ticks placed by s
        let mut chart = b.build_cartesian_2d(0.0..1.0, 0.0..1.0).map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_labels(0)
            .y_labels(0)
            .y_desc(self.value_label.as_str())
            .axis_desc_style(("sans-serif", 15))
            .draw()
            .map_err(|x| e(&x))?;
        const BANDS: usize = 120;
        let band = |k: usize| k as f64 / BANDS as f64;
        let bands = (0..BANDS).map(|k| Rectangle::new([(0.0, band(k)), (1.0, band(k + 1))], viridis(band(k)).filled()));
        chart.draw_series(bands).map_err(|x| e(&x))?;
        let right: TextStyle = ("sans-serif", 14).into_font().into();
        let right = right.pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Right,
            plotters::style::text_anchor::VPos::Center,
        ));
        for (v, label) in self.ticks((lo, hi)) {
            let s = self.position(v, (lo, hi));
            let tick = EmptyElement::at((0.0, s))
                + PathElement::new(vec![(-6, 0), (0, 0)], BLACK.stroke_width(1))
                + Text::new(label, (-9, 0), right.clone());
            chart.plotting_area().draw(&tick).map_err(|x| e(&x))?;
        }
        if let Some((v, name)) = self.mark.as_ref().filter(|(v, _)| *v >= lo && *v <= hi) {
            let s = self.position(*v, (lo, hi));
            let mark = EmptyElement::at((1.0, s))
                + PathElement::new(vec![(-40, 0), (6, 0)], BLACK.stroke_width(2))
                + Text::new(name.clone(), (12, -8), font.clone());
            chart.plotting_area().draw(&mark).map_err(|x| e(&x))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// viridis's ends and middle are matplotlib's table (van der Walt & Smith 2015), and its
    /// lightness (the sum of the channels, a proxy) grows along the scale.
    #[test]
    fn viridis_runs_dark_to_light() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(0.5), RGBColor(33, 144, 141));
        assert_eq!((viridis(-1.0), viridis(2.0)), (viridis(0.0), viridis(1.0)));
        let light = |c: RGBColor| c.0 as u32 + c.1 as u32 + c.2 as u32;
        assert!((1..=20).all(|k| light(viridis(k as f64 / 20.0)) >= light(viridis((k - 1) as f64 / 20.0))));
    }

    fn map(axes: usize) -> Map {
        let axis = |k: usize| MapAxis { name: format!("p{k}"), lower: 0.5, upper: 1.5, log: k == 1 };
        let at = |u: f64| (0..axes).map(|_| 0.5 + u).collect::<Vec<f64>>();
        Map {
            title: "t".into(),
            axes: (0..axes).map(axis).collect(),
            layers: vec![
                Layer {
                    title: "rel_error".into(),
                    points: vec![(at(0.1), 1e-4), (at(0.9), 3e-3), (at(0.5), f64::NAN)],
                },
                Layer { title: "error_estimate".into(), points: vec![(at(0.1), 2e-4), (at(0.9), 5e-3)] },
            ],
            value_label: "relative error".into(),
            log_values: true,
            training: vec![at(0.0), at(1.0)],
            mark: Some((1e-3, "tolerance".into())),
        }
    }

    /// The log colour scale spans the layers' values (1e-4 .. 5e-3, NaN left out), a value
    /// at its geometric middle sits at s = ½, and the figure has a row per pair of axes and
    /// a column per layer: two parameters one row, three parameters three rows (the PNG's
    /// size read back).
    #[test]
    fn maps_of_two_and_three_parameters() {
        let m = map(2);
        let scale = m.value_range();
        assert_eq!(scale, (1e-4, 5e-3));
        assert!((m.position((1e-4f64 * 5e-3).sqrt(), scale) - 0.5).abs() < 1e-12);
        assert_eq!(pairs(3), vec![(0, 1), (0, 2), (1, 2)]);
        // over 1e-4 .. 5e-3: 1, 2, 5 of each decade inside it
        let ticks: Vec<String> = m.ticks(scale).into_iter().map(|t| t.1).collect();
        assert_eq!(ticks, ["1e-4", "2e-4", "5e-4", "1e-3", "2e-3", "5e-3"]);
        let speed = Map { log_values: false, ..map(2) };
        let ticks: Vec<f64> = speed.ticks((0.2, 6.5)).into_iter().map(|t| t.0).collect();
        assert_eq!(ticks, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let dir = tempfile::tempdir().unwrap();
        for (axes, rows) in [(2, 1), (3, 3)] {
            let files = map(axes).save(&dir.path().join(format!("m{axes}"))).unwrap();
            let svg = std::fs::read_to_string(&files[0]).unwrap();
            assert!(svg.contains("training run") && svg.contains("tolerance") && svg.contains("p1"), "{axes}");
            let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&files[1]).unwrap()));
            let reader = dec.read_info().unwrap();
            let size = (reader.info().width, reader.info().height);
            assert_eq!(size, (2 * CELL_WIDTH + STRIP, TITLE + rows * CELL_HEIGHT), "{axes} parameters");
        }
        assert!(map(1).save(&dir.path().join("m1")).is_err());
    }
}
