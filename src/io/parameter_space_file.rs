//! The box of parameters a basis was trained over, in its file:
//!
//! ```text
//! /parameters/<name>   (n_runs)   the parameter's value at each training run, in run order
//!   attributes: range ([lower, upper]), scale ("linear" or "log")
//! ```
//!
//! Written by `train` for a pipeline with a `[parameters]` table; a basis without the group
//! was trained over the load scale alone (every named parameter at 1).

use super::h5::{attr_str, bounded_len, dataset_of_shape, read_attr_str};
use crate::error::{Error, Result};
use crate::solver::parameter_space::{ParameterRange, ParameterSpace, Spacing};
use crate::solver::parameters::Parameters;
use std::path::Path;

/// Writes `/parameters` into an open basis file: the box and the training `points`.
pub fn write_parameter_space(f: &hdf5::File, space: &ParameterSpace, points: &[Parameters]) -> hdf5::Result<()> {
    let g = f.create_group("parameters")?;
    for r in &space.ranges {
        let values: Vec<f64> = points.iter().map(|mu| mu.get(&r.name).unwrap_or(1.0)).collect();
        let d = g.new_dataset_builder().with_data(&values).create(r.name.as_str())?;
        d.new_attr::<f64>().shape(2).create("range")?.write(&[r.lower, r.upper])?;
        attr_str(&d, "scale", r.spacing.name())?;
    }
    Ok(())
}

/// The points of the training runs in the box `space` of the open basis file `f` at `path`:
/// each parameter's `/parameters/<name>` values, in run order (empty for a basis trained over
/// the load scale alone).
pub fn training_points(f: &hdf5::File, path: &Path, space: &ParameterSpace) -> Result<Vec<Parameters>> {
    let names: Vec<&str> = space.names().collect();
    let Some(first) = names.first() else { return Ok(Vec::new()) };
    let g = f.group("parameters").map_err(|e| Error::input(path, "parameters", format!("cannot be read: {e}")))?;
    let refused = |name: &str, e: Error| Error::input(path, format!("parameters/{name}"), e.problem_text());
    // the file's header sizes the runs: bounded before anything is read (a point holds a
    // value per name), then every name's dataset must have that length
    let limits = crate::limits::Limits::from_env_or_defaults();
    let n = bounded_len(&g, first, 64.0 * names.len() as f64, &limits).map_err(|e| refused(first, e))?;
    let mut runs = vec![Parameters::default(); n];
    for name in names {
        let values = dataset_of_shape(&g, name, &[n])
            .and_then(|d| d.read_1d::<f64>().map_err(|e| Error::hdf5(path, format!("cannot be read: {e}"))))
            .map_err(|e| refused(name, e))?;
        if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            return Err(Error::input(
                path,
                format!("parameters/{name}"),
                format!("holds {v} where a training run's value belongs"),
            ));
        }
        for (mu, v) in runs.iter_mut().zip(values.iter()) {
            *mu = std::mem::take(mu).with(name, *v);
        }
    }
    Ok(runs)
}

/// The box of `/parameters` of the open basis file `f` at `path` (`None`: the basis was
/// trained over the load scale alone).
/// A range that is not `[lower, upper]` with lower < upper, or an unknown scale, is an
/// error naming the dataset.
pub fn parameter_space(f: &hdf5::File, path: &Path) -> Result<Option<ParameterSpace>> {
    let Ok(g) = f.group("parameters") else { return Ok(None) };
    let mut names = g.member_names().map_err(|e| Error::hdf5(path, e))?;
    names.sort();
    let mut ranges = Vec::with_capacity(names.len());
    for name in names {
        let field = format!("parameters/{name}");
        let bad = |problem: String| Error::input(path, &field, problem);
        let d = g.dataset(&name).map_err(|e| bad(format!("cannot be read: {e}")))?;
        let r = d
            .attr("range")
            .and_then(|a| a.read_raw::<f64>())
            .map_err(|e| bad(format!("has no readable attribute `range`: {e}")))?;
        let scale = read_attr_str(&d, "scale").map_err(|e| bad(format!("has no readable attribute `scale`: {e}")))?;
        let spacing = match scale.as_str() {
            "linear" => Spacing::Linear,
            "log" => Spacing::Log,
            other => return Err(bad(format!("has scale \"{other}\"; expected \"linear\" or \"log\""))),
        };
        let [lower, upper] = r[..] else { return Err(bad(format!("has a range of {} values; expected 2", r.len()))) };
        let range = ParameterRange { name, lower, upper, spacing };
        range.validate().map_err(|e| bad(e.problem()))?;
        ranges.push(range);
    }
    Ok(Some(ParameterSpace { ranges }))
}
