//! Between the library's values and Python's: parameters from keywords, arrays time first,
//! warnings through Python's `warnings`, a sweep as a dict of arrays.

use crate::errors::{model_error, FlexromWarning};
use flexrom::solver::parameters::Parameters;
use flexrom::workflows::sweep::{Outcome, Sweep};
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::collections::HashMap;

/// The run's parameters: the load scale (default 1) and the named ones, checked finite.
/// `load_scale` may also come as a named parameter, not both.
pub fn parameters(load_scale: Option<f64>, named: &HashMap<String, f64>) -> PyResult<Parameters> {
    use flexrom::solver::parameters::LOAD_SCALE;
    if load_scale.is_some() && named.contains_key(LOAD_SCALE) {
        return Err(model_error("load_scale given twice (as load_scale and in params)"));
    }
    // sorted: a dict's order must not change which parameter a message names first
    let mut names: Vec<&String> = named.keys().collect();
    names.sort();
    let mut mu = Parameters::load_scale(load_scale.unwrap_or(1.0));
    for name in names {
        mu = mu.with(name, named[name]);
    }
    mu.validate().map_err(crate::errors::to_py)?;
    Ok(mu)
}

/// The named parameters of a call's keywords (`drive=1.1, E_lower=2.5e8`), each a number.
pub fn named(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Option<HashMap<String, f64>>> {
    let Some(kwargs) = kwargs else { return Ok(None) };
    let mut out = HashMap::new();
    for (k, v) in kwargs.iter() {
        let name: String = k.extract()?;
        let value: f64 = v.extract().map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(format!(
                "`{name}={v}`: keywords beyond the call's own are the model's named parameters, and a parameter is a number"
            ))
        })?;
        out.insert(name, value);
    }
    Ok(Some(out))
}

/// `a` (n × n_t: a column per instant, as the solver keeps it) as an (n_t, n) array.
pub fn time_first<'py>(py: Python<'py>, a: &ndarray::Array2<f64>) -> Bound<'py, PyArray2<f64>> {
    a.t().as_standard_layout().into_owned().into_pyarray(py)
}

/// name → (n_t) array.
pub fn dict_of_series<'py>(py: Python<'py>, s: &flexrom::simulate::Series) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, v) in s {
        d.set_item(name, v.clone().into_pyarray(py))?;
    }
    Ok(d)
}

/// Each line through `warnings.warn` as a `FlexromWarning` (shown once per place by
/// Python's default filter; an error under `-W error`).
pub fn warn<W: flexrom::error::Said>(py: Python<'_>, lines: &[W]) -> PyResult<()> {
    for line in lines {
        let msg = std::ffi::CString::new(crate::errors::said(line).replace('\0', " ")).expect("NULs replaced");
        PyErr::warn(py, &py.get_type::<FlexromWarning>(), &msg, 1)?;
    }
    Ok(())
}

/// `d[key]`, a dict, made empty where `d` has no such key (probe name → quantity → …).
pub fn inner_dict<'py>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<Bound<'py, PyDict>> {
    if let Some(x) = d.get_item(key)? {
        return Ok(x.cast_into::<PyDict>()?);
    }
    let x = PyDict::new(d.py());
    d.set_item(key, &x)?;
    Ok(x)
}

/// A sweep's strains and curvatures (`strains`, `curvatures`: probe name → (n, n_t)) and
/// each probe quantity's error estimate (`quantity_error_estimates`: probe name → quantity →
/// (n)), NaN where a point did not run to the end or has no estimate (0 where the full
/// model answered).
fn sweep_sections<'py>(py: Python<'py>, d: &Bound<'py, PyDict>, s: &Sweep) -> PyResult<()> {
    let (n, n_t) = (s.scales.len(), s.t.len());
    for (key, i) in [("strains", 0), ("curvatures", 1)] {
        let out = PyDict::new(py);
        for (j, name) in s.section_names[i].iter().enumerate() {
            let mut a = ndarray::Array2::from_elem((n, n_t), f64::NAN);
            for (k, sr) in s.scales.iter().enumerate() {
                let Outcome::Done(p) = &sr.outcome else { continue };
                let series = if i == 0 { &p.run.result.strains } else { &p.run.result.curvatures };
                if let Some((_, v)) = series.get(j).filter(|(_, v)| v.len() == n_t) {
                    a.row_mut(k).assign(v);
                }
            }
            out.set_item(name, a.into_pyarray(py))?;
        }
        d.set_item(key, out)?;
    }
    for (key, reactions) in [("quantity_error_estimates", false), ("reaction_error_estimates", true)] {
        d.set_item(key, estimate_columns(py, s, reactions)?)?;
    }
    Ok(())
}

/// name → {quantity → (n)}: each point's estimate of each probe quantity (`reactions`
/// false) or joint reaction (true) over its range; 0 where the full model answered, NaN
/// where a point has none.
fn estimate_columns<'py>(py: Python<'py>, s: &Sweep, reactions: bool) -> PyResult<Bound<'py, PyDict>> {
    let n = s.scales.len();
    let est = PyDict::new(py);
    let mut columns: Vec<((String, &'static str), Vec<f64>)> = Vec::new();
    for (k, sr) in s.scales.iter().enumerate() {
        let Outcome::Done(p) = &sr.outcome else { continue };
        for q in p.estimate.iter().flat_map(|e| &e.quantities).filter(|q| q.quantity.is_reaction() == reactions) {
            let key = (q.probe.clone(), q.quantity.name());
            let i = match columns.iter().position(|(c, _)| *c == key) {
                Some(i) => i,
                None => {
                    columns.push((key, vec![f64::NAN; n]));
                    columns.len() - 1
                }
            };
            columns[i].1[k] = if p.fallback.is_some() { 0.0 } else { q.estimate };
        }
    }
    for ((name, quantity), v) in columns {
        inner_dict(&est, &name)?.set_item(quantity, v.into_pyarray(py))?;
    }
    Ok(est)
}

/// A sweep as arrays with the load axis first; a failed point's entries are NaN and its
/// message is in `failed`.
pub fn sweep_dict<'py>(py: Python<'py>, s: &Sweep, points: &[Parameters]) -> PyResult<Bound<'py, PyDict>> {
    let (n, n_t) = (s.scales.len(), s.t.len());
    let d = PyDict::new(py);
    d.set_item("load_scales", points.iter().map(|mu| mu.scale()).collect::<Vec<_>>().into_pyarray(py))?;
    let named = PyDict::new(py);
    for name in
        points.iter().flat_map(|mu| mu.named().map(|(k, _)| k.to_string())).collect::<std::collections::BTreeSet<_>>()
    {
        let v: Vec<f64> = points.iter().map(|mu| mu.get(&name).unwrap_or(f64::NAN)).collect();
        named.set_item(name, v.into_pyarray(py))?;
    }
    d.set_item("parameters", named)?;
    d.set_item("t", s.t.clone().into_pyarray(py))?;
    let mut estimate = vec![f64::NAN; n];
    let mut by_time = ndarray::Array2::from_elem((n, 5), f64::NAN);
    let mut extrapolated = vec![false; n];
    let mut failed: Vec<Option<String>> = vec![None; n];
    let mut fallback: Vec<Option<String>> = vec![None; n];
    let mut fallback_failed: Vec<Option<String>> = vec![None; n];
    let mut probes: Vec<ndarray::Array3<f64>> =
        vec![ndarray::Array3::from_elem((n, n_t, 2), f64::NAN); s.probe_names.len()];
    for (i, sr) in s.scales.iter().enumerate() {
        match &sr.outcome {
            Outcome::Done(p) => {
                if let Some(e) = &p.estimate {
                    estimate[i] = e.error_estimate;
                    by_time.row_mut(i).assign(&ndarray::ArrayView1::from(&e.by_time[..]));
                }
                extrapolated[i] = p.extrapolated;
                fallback[i] = p.fallback.clone();
                fallback_failed[i] = p.note.clone();
                for (k, (_, xy)) in p.run.result.probes.iter().enumerate() {
                    probes[k].index_axis_mut(ndarray::Axis(0), i).assign(xy);
                }
            }
            Outcome::Failed(msg) => failed[i] = Some(msg.clone()),
            Outcome::Pending => failed[i] = Some("not run".into()),
        }
    }
    let pd = PyDict::new(py);
    for (name, a) in s.probe_names.iter().zip(probes) {
        pd.set_item(name, a.into_pyarray(py))?;
    }
    d.set_item("probes", pd)?;
    sweep_sections(py, &d, s)?;
    d.set_item("error_estimate", estimate.into_pyarray(py))?;
    d.set_item("error_estimate_by_time", by_time.into_pyarray(py))?;
    d.set_item("extrapolated", extrapolated.into_pyarray(py))?;
    d.set_item("failed", failed)?;
    d.set_item("fallback", fallback)?;
    d.set_item("fallback_failed", fallback_failed)?;
    d.set_item("wall_seconds", s.wall_seconds)?;
    Ok(d)
}
