//! The basis file's `/timing`: the full and the reduced time loop measured by `train` at
//! one of its training loads, so that the commands that run the basis can say which route
//! is faster at the model's size without timing anything themselves.
//!
//! ```text
//! /timing/full_seconds      ()   the full time loop (banded solver), median, s
//! /timing/reduced_seconds   ()   the reduced time loop, median, s
//! /timing/estimate_seconds  ()   the error estimate of the reduced run, median, s (NaN:
//!                                the basis has no estimator)
//! attributes on /timing: load_scale (the training load timed), parameter:NAME (the other
//!   parameters of the point timed, over a box: its centre), threads (1: one run at a
//!   time on the calling thread), runs (timed rounds, each a full run, a reduced run and
//!   its estimate, interleaved), estimate_method ("none" without an estimator)
//! ```
//!
//! Basis files of an earlier flexrom have no `/timing`: nothing is known, nothing said.
//! The content hash does not cover it: it is a measurement of a machine, not the basis.

use super::attrs::{units_of, write_units, Kind};
use super::h5::{attr_f64, attr_str, attr_u64, read_attr_f64, read_attr_str};
use crate::error::{Error, Result};
use std::path::Path;

/// The medians `train` measured at one training load, one run at a time.
#[derive(Clone, Debug, PartialEq)]
pub struct RouteTiming {
    pub load_scale: f64,
    /// the named parameters of the point timed (a box's centre), in name order
    pub named: Vec<(String, f64)>,
    pub full_seconds: f64,
    pub reduced_seconds: f64,
    /// NaN without an estimator
    pub estimate_seconds: f64,
    /// the estimate's method (`None`: no estimator)
    pub estimate_method: Option<String>,
    /// timed rounds
    pub runs: usize,
    /// runs at a time (1)
    pub threads: usize,
}

const SECONDS: [&str; 3] = ["full_seconds", "reduced_seconds", "estimate_seconds"];

/// Adds `/timing` to the basis file at `path` (a staged file, not yet renamed into place).
pub fn append_timing(path: &Path, t: &RouteTiming) -> Result<()> {
    let e = |err: hdf5::Error| Error::hdf5(path, err);
    let f = crate::io::h5_open::open_rw(path).map_err(e)?;
    let g = f.create_group("timing").map_err(e)?;
    for (name, value) in SECONDS.iter().zip([t.full_seconds, t.reduced_seconds, t.estimate_seconds]) {
        let d = g.new_dataset_builder().with_data(&ndarray::arr0(value)).create(*name).map_err(e)?;
        let (units, dims) = units_of(Kind::Basis, &format!("timing/{name}")).expect("in the basis table");
        write_units(&d, units, dims).map_err(e)?;
    }
    attr_f64(&g, "load_scale", t.load_scale).map_err(e)?;
    for (name, value) in &t.named {
        attr_f64(&g, &format!("parameter:{name}"), *value).map_err(e)?;
    }
    attr_u64(&g, "threads", t.threads as u64).map_err(e)?;
    attr_u64(&g, "runs", t.runs as u64).map_err(e)?;
    attr_str(&g, "estimate_method", t.estimate_method.as_deref().unwrap_or("none")).map_err(e)?;
    f.flush().map_err(e)
}

/// `/timing` of the open basis file `f` at `path`; `None` for a file written before it. A timing
/// that is there but unreadable, or not positive where it must be, is an error naming it.
pub fn read_timing(f: &hdf5::File, path: &Path) -> Result<Option<RouteTiming>> {
    let Ok(g) = f.group("timing") else { return Ok(None) };
    let bad = |field: &str, problem: String| Error::input(path, format!("timing/{field}"), problem);
    let mut seconds = [f64::NAN; 3];
    for (s, name) in seconds.iter_mut().zip(SECONDS) {
        *s = g
            .dataset(name)
            .and_then(|d| d.read_scalar::<f64>())
            .map_err(|e| bad(name, format!("cannot be read: {e}")))?;
        // only the estimate may be NaN (no estimator)
        let no_estimator = name == "estimate_seconds" && s.is_nan();
        if !(no_estimator || *s > 0.0 && s.is_finite()) {
            return Err(bad(name, format!("is {s}; a time loop takes a positive, finite time")));
        }
    }
    let u = |name: &str| {
        g.attr(name).and_then(|a| a.read_scalar::<u64>()).map_err(|e| bad(name, format!("cannot be read: {e}")))
    };
    let method =
        read_attr_str(&g, "estimate_method").map_err(|e| bad("estimate_method", format!("cannot be read: {e}")))?;
    let mut named = Vec::new();
    for a in g.attr_names().map_err(|e| bad("(attributes)", format!("cannot be listed: {e}")))? {
        if let Some(name) = a.strip_prefix("parameter:") {
            named.push((name.to_string(), read_attr_f64(&g, &a).map_err(|e| bad(&a, format!("cannot be read: {e}")))?));
        }
    }
    named.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(Some(RouteTiming {
        load_scale: read_attr_f64(&g, "load_scale").map_err(|e| bad("load_scale", format!("cannot be read: {e}")))?,
        named,
        full_seconds: seconds[0],
        reduced_seconds: seconds[1],
        estimate_seconds: seconds[2],
        estimate_method: (method != "none").then_some(method),
        runs: u("runs")? as usize,
        threads: u("threads")? as usize,
    }))
}
