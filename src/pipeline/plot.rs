//! Line plots as SVG (plotters), for the report of `run`.

use plotters::prelude::*;
use std::path::Path;

pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub dashed: bool,
}

/// One chart with any number of line series; `log_y` for decays and errors.
pub fn line_chart(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    log_y: bool,
) -> Result<(), String> {
    let finite = |v: f64| v.is_finite() && (!log_y || v > 0.0);
    let pts: Vec<(f64, f64)> =
        series.iter().flat_map(|s| s.points.iter().copied()).filter(|&(x, y)| x.is_finite() && finite(y)).collect();
    if pts.is_empty() {
        return Err(format!("{}: nothing to plot", path.display()));
    }
    let (mut x0, mut x1) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (mut y0, mut y1) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    if x1 <= x0 {
        (x0, x1) = (x0 - 0.5, x1 + 0.5);
    }
    if log_y {
        (y0, y1) = (y0 / 2.0, y1 * 2.0);
    } else {
        let pad = if y1 > y0 { 0.05 * (y1 - y0) } else { 0.5 * y0.abs().max(1e-12) };
        (y0, y1) = (y0 - pad, y1 + pad);
    }
    let root = SVGBackend::new(path, (900, 520)).into_drawing_area();
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut b = ChartBuilder::on(&root);
    b.caption(title, ("sans-serif", 20)).margin(12).x_label_area_size(42).y_label_area_size(78);
    let colors = [BLUE, RED, GREEN, MAGENTA, CYAN, BLACK];
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart.configure_mesh().x_desc(x_label).y_desc(y_label).draw().map_err(|e| err(&e))?;
            for (i, s) in series.iter().enumerate() {
                let c = colors[i % colors.len()];
                let data: Vec<(f64, f64)> =
                    s.points.iter().copied().filter(|&(x, y)| x.is_finite() && finite(y)).collect();
                let style =
                    ShapeStyle { color: c.to_rgba(), filled: false, stroke_width: if s.dashed { 1 } else { 2 } };
                let anno = if s.dashed {
                    chart.draw_series(DashedLineSeries::new(data, 6, 4, style)).map_err(|e| err(&e))?
                } else {
                    chart.draw_series(LineSeries::new(data, style)).map_err(|e| err(&e))?
                };
                anno.label(s.name.clone()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(|e| err(&e))?;
        }};
    }
    if log_y {
        draw!(b.build_cartesian_2d(x0..x1, (y0..y1).log_scale()).map_err(|e| err(&e))?);
    } else {
        draw!(b.build_cartesian_2d(x0..x1, y0..y1).map_err(|e| err(&e))?);
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// The error estimate against the load scale (a line, log scale), the true errors where
/// validated (circles), and the training loads (vertical grey lines): the report's
/// `estimate_vs_load.svg`.
pub fn estimate_chart(
    path: &Path,
    title: &str,
    estimates: &[(f64, f64)],
    errors: &[(f64, f64)],
    training: &[f64],
) -> Result<(), String> {
    let ok = |&(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && y > 0.0;
    let est: Vec<(f64, f64)> = estimates.iter().copied().filter(ok).collect();
    let err_pts: Vec<(f64, f64)> = errors.iter().copied().filter(ok).collect();
    let all: Vec<(f64, f64)> = est.iter().chain(&err_pts).copied().collect();
    if all.is_empty() {
        return Err(format!("{}: nothing to plot", path.display()));
    }
    let xs = all.iter().map(|p| p.0).chain(training.iter().copied().filter(|x| x.is_finite()));
    let (mut x0, mut x1) = xs.fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
    if x1 <= x0 {
        (x0, x1) = (x0 - 0.5, x1 + 0.5);
    }
    let pad = 0.03 * (x1 - x0);
    (x0, x1) = (x0 - pad, x1 + pad);
    let (y0, y1) = all.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let (y0, y1) = (y0 / 3.0, y1 * 3.0);
    let root = SVGBackend::new(path, (900, 520)).into_drawing_area();
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(78)
        .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
        .map_err(|e| err(&e))?;
    chart.configure_mesh().x_desc("load scale").y_desc("relative error").draw().map_err(|e| err(&e))?;
    let grey = RGBColor(150, 150, 150);
    for (i, &x) in training.iter().filter(|x| x.is_finite()).enumerate() {
        let a = chart
            .draw_series(LineSeries::new(
                vec![(x, y0), (x, y1)],
                ShapeStyle { color: grey.to_rgba(), filled: false, stroke_width: 1 },
            ))
            .map_err(|e| err(&e))?;
        if i == 0 {
            a.label("training load").legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey));
        }
    }
    if !est.is_empty() {
        chart
            .draw_series(LineSeries::new(
                est.clone(),
                ShapeStyle { color: BLUE.to_rgba(), filled: false, stroke_width: 2 },
            ))
            .map_err(|e| err(&e))?
            .label("error_estimate")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
    }
    if !err_pts.is_empty() {
        chart
            .draw_series(err_pts.iter().map(|&p| Circle::new(p, 4, RED.filled())))
            .map_err(|e| err(&e))?
            .label("rel_error (validated)")
            .legend(|(x, y)| Circle::new((x + 10, y), 4, RED.filled()));
    }
    chart.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(BLACK).draw().map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
