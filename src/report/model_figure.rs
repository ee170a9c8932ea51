//! The report's figure of the model (`model.svg`, `model.png`): its initial configuration
//! `x₀` (the consistent state every run starts from) drawn as `flexrom animate` draws a
//! frame ([`crate::report::drawing`]), with the bodies' and probes' names, on equal axes with a
//! margin, and a legend of the marks it holds in a strip to the right; so that a user sees
//! at once that the model is the one they meant.

use crate::error::Result;
use crate::model::Model;
use crate::physics::centre_line::CentreLines;
use crate::report::drawing::{
    draw_frame, motion_chart, Bounds, Frame, Mark, MarkElement, Style, BOTTOM, LEFT, MARGIN, TITLE,
};
use crate::report::plot::{not_drawn, register_font, write_png, COLORS};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

const WIDTH: u32 = 960;
const LEGEND: u32 = 170;

/// The model at its initial state, and the figure's height fitted to it.
fn model_frame(model: &Model) -> Result<(Frame, Bounds, u32)> {
    let x0 = &model.physics()?.x0;
    let lines = CentreLines::new(model.bodies(), crate::report::animate::MAX_POINTS);
    let frame = Frame::at(model, &lines, x0);
    let bounds = Bounds::of(std::iter::once(&frame));
    // the plot's height at which the model fills its width on equal axes, between 35 % and
    // 100 % of the width (a long thin model gets room for its names)
    let plot_w = (WIDTH - LEGEND - LEFT - 2 * MARGIN) as f64;
    let plot_h = (plot_w * (bounds.y.1 - bounds.y.0) / (bounds.x.1 - bounds.x.0)).clamp(0.35 * plot_w, plot_w);
    Ok((frame, bounds, plot_h as u32 + TITLE + BOTTOM + 2 * MARGIN))
}

/// Writes `<stem>.svg` and `<stem>.png`, the figure of `model`; returns their paths.
pub fn save_model_figure(model: &Model, stem: &Path) -> Result<Vec<PathBuf>> {
    let (frame, bounds, height) = model_frame(model)?;
    let file = model.path.file_name().map_or(model.path.display().to_string(), |n| n.to_string_lossy().into_owned());
    let title = format!("The model: {file}, initial configuration");
    let (svg, png) = (stem.with_extension("svg"), stem.with_extension("png"));
    register_font();
    {
        let root = SVGBackend::new(&svg, (WIDTH, height)).into_drawing_area();
        draw(&root, &frame, &bounds, &title, &svg)?;
        root.present().map_err(|e| not_drawn(&svg, e))?;
    }
    let mut buf = vec![0u8; (WIDTH * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (WIDTH, height)).into_drawing_area();
        draw(&root, &frame, &bounds, &title, &png)?;
        root.present().map_err(|e| not_drawn(&png, e))?;
    }
    write_png(&png, &buf, WIDTH, height)?;
    Ok(vec![svg, png])
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    frame: &Frame,
    bounds: &Bounds,
    title: &str,
    file: &Path,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = |x: &dyn std::fmt::Display| not_drawn(file, x);
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let area = root.titled(title, ("sans-serif", 18)).map_err(|x| e(&x))?;
    let (w, h) = area.dim_in_pixel();
    let (plot, legend) = area.split_horizontally(w.saturating_sub(LEGEND));
    let plot_w = (w.saturating_sub(LEGEND + LEFT + 2 * MARGIN)).max(1) as f64;
    let plot_h = h.saturating_sub(BOTTOM + 2 * MARGIN).max(1) as f64;
    let b = bounds.equal(plot_w, plot_h);
    let mut chart = motion_chart(&plot, &b, file)?;
    draw_frame(&mut chart, frame, &b, Style { colour: COLORS[0], dashed: false, names: true }, file)?;
    draw_legend(&legend, frame.kinds(), file)
}

/// One line per kind of mark: the mark, and its name.
fn draw_legend<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, kinds: Vec<Mark>, file: &Path) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| not_drawn(file, x);
    let font = ("sans-serif", 13).into_font().color(&BLACK);
    let body = PathElement::new(vec![(8, 24), (32, 24)], COLORS[0].stroke_width(2));
    area.draw(&body).map_err(e)?;
    area.draw(&Text::new("body (centre line)", (40, 17), font.clone())).map_err(e)?;
    for (i, m) in kinds.into_iter().enumerate() {
        let y = 24 + 24 * (i as i32 + 1);
        area.draw(&MarkElement { at: (20, y), mark: m, ink: BLACK }).map_err(e)?;
        area.draw(&Text::new(m.name(), (40, y - 7), font.clone())).map_err(e)?;
    }
    Ok(())
}
