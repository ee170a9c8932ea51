//! The report's figures over a box of two parameters or more ([`crate::report::map`]): where the
//! runs lie in the box and how each fared, in place of the figures against the load scale
//! a line of loads has.
//!
//! - `error_map`: rel_error of every validated run (the sweep's points and `validate`'s)
//!   beside its error_estimate (no full run), on one logarithmic colour scale with the
//!   tolerance marked;
//! - `probe_error_map`: the largest probe error, m (models with probes);
//! - `speedup_map`: the reduced time loop's speedup over the full one, 1× marked.
//!
//! The training runs (the full runs whose snapshots the basis holds) are crosses on each.

use crate::error::Result;
use crate::report::map::{Layer, Map, MapAxis};
use crate::solver::parameter_space::{ParameterSpace, Spacing};
use crate::solver::parameters::Parameters;
use crate::workflows::validate::Validation;
use std::path::Path;

/// One validated run: its point, what it measured, and its estimate (`None`: no estimator).
pub struct MappedRun<'a> {
    pub validation: &'a Validation,
    pub estimate: Option<f64>,
}

/// What the maps show beside the runs.
pub struct MapContext<'a> {
    pub space: &'a ParameterSpace,
    /// the training runs' points
    pub training: &'a [Parameters],
    /// the tolerance the estimate is held to, marked on the error's colour bar
    pub tolerance: Option<f64>,
    /// the model has probes (else no probe-error map)
    pub probes: bool,
}

/// Writes the maps into `out`; returns, for the summary, each figure's file stem and what
/// it shows, in order.
pub fn write_maps(out: &Path, runs: &[MappedRun], cx: &MapContext) -> Result<Vec<(&'static str, &'static str)>> {
    let axes: Vec<MapAxis> = cx
        .space
        .names()
        .filter_map(|n| cx.space.range(n))
        .map(|r| MapAxis { name: r.name.clone(), lower: r.lower, upper: r.upper, log: r.spacing == Spacing::Log })
        .collect();
    let at = |mu: &Parameters| -> Vec<f64> { axes.iter().map(|a| mu.get(&a.name).unwrap_or(1.0)).collect() };
    let layer = |title: &str, f: &dyn Fn(&MappedRun) -> Option<f64>| Layer {
        title: title.into(),
        points: runs.iter().filter_map(|r| Some((at(&r.validation.mu()), f(r)?))).collect(),
    };
    let training: Vec<Vec<f64>> = cx.training.iter().map(at).collect();
    let map = |title: &str, layers: Vec<Layer>, value_label: &str, log_values: bool, mark: Option<(f64, String)>| Map {
        title: title.into(),
        axes: axes.clone(),
        layers,
        value_label: value_label.into(),
        log_values,
        training: training.clone(),
        mark,
    };
    let mut written = Vec::new();
    let mut save = |m: Map, stem: &'static str, what: &'static str| {
        m.save(&out.join(stem))?;
        written.push((stem, what));
        Ok::<(), crate::error::Error>(())
    };
    let mut errors = vec![layer("rel_error (full runs)", &|r| Some(r.validation.rel_error))];
    if runs.iter().any(|r| r.estimate.is_some()) {
        errors.push(layer("error_estimate (no full run)", &|r| r.estimate));
    }
    let tolerance = cx.tolerance.map(|t| (t, "tolerance".to_string()));
    save(
        map("Reduced vs full model over the box", errors, "relative error", true, tolerance),
        "error_map",
        "rel_error and error_estimate over the box",
    )?;
    if cx.probes {
        let probe = vec![layer("largest probe error", &|r| Some(r.validation.max_probe_error))];
        save(
            map("Largest probe error, reduced vs full", probe, "probe error (m)", true, None),
            "probe_error_map",
            "the largest probe error over the box",
        )?;
    }
    let speedup = vec![layer("speedup (banded full solver)", &|r| Some(r.validation.speedup))];
    save(
        map("Speedup of the reduced time loop over the full one", speedup, "speedup", false, Some((1.0, "1×".into()))),
        "speedup_map",
        "the speedup over the box",
    )?;
    Ok(written)
}
