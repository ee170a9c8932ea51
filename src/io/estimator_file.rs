//! The error estimator's part of the basis file (see [`crate::reduction::estimator`]), and
//! the training range and tolerance the online tools compare against:
//!
//! ```text
//! /estimator/modes            (n_dof, r⁺)  V⁺: the same POD with k more modes per block
//!                                          (POD columns block by block, then the kept unit columns)
//! /estimator/block_modes      (n_b)        POD modes per block of V⁺
//! /estimator/multiplier_modes (n_c, r⁺)    whole-system only
//! /estimator/hyper/elements, /estimator/hyper/weights   V⁺'s ECSW set (hyper-reduced bases)
//!   attributes on /estimator/hyper: tolerance, training_residual, n_training
//! /estimator/calibration/load_scale, raw_estimate, rel_error   (m) held-out calibration pairs
//! /estimator/defects/load_scale (N), ratio (N, 5), factor (5)   the defects method's
//!                                          calibration (greedy training only; `DefectsCalibration`;
//!                                          load_scale empty: the N candidates were points of a
//!                                          parameter box, `unit_point` (N, d) where they lie in
//!                                          its unit cube, attribute `parameters`);
//! /estimator/defects/quantity_ratio (N, n_q)   each probe quantity's whole-run ratio at the
//!                                          same candidates (attribute `quantities`: the keys
//!                                          `quantity:probe`, one a line)
//!   attribute on /estimator/defects: reliable (1: its leave-one-out check passed); factor and
//!   reliable follow from load_scale and ratio and are recomputed when read
//!   attributes on /estimator: method ("enriched": the estimators compare with an enriched
//!   basis), default_method (the method online estimates use unless the pipeline names one:
//!   "corrected", "defects" or "enriched"; files of an earlier flexrom have none, and
//!   the rule of `Estimator::default_method` decides), extra_modes (k), factor (c),
//!   calibrated (1: c from calibration pairs, 0: the default), n_modes (r⁺)
//! /training/range             (2)          [min, max] training load scale (greedy training;
//!                                          otherwise min/max of /snapshot_load_scale)
//! /training/tolerance or attribute `tolerance` on /training: greedy's tolerance
//!   attribute `measure` on /training: the error that tolerance is on ("relative" or
//!   "displacement"; files of an earlier flexrom have none: relative)
//!   attributes `held_out_note`, `estimate_note` on /training: the converged held-out check's
//!   error above the tolerance, the online default reading above it between the candidates,
//!   in words (each absent when within it)
//! ```

use super::h5::{attr_f64, attr_str, attr_u64, read_attr_f64, read_attr_str};
use crate::error::{Error, Result};
use crate::reduction::estimator::{
    Calibration, CalibrationPoint, DefectsCalibration, ErrorMeasure, EstimateMethod, Estimator, FIFTHS,
};
use crate::reduction::{Basis, Hyper};
use ndarray::Array1;
use std::path::Path;

/// Writes `/estimator` into an open basis file (inside `write_basis_with`'s closure).
pub fn write_estimator(f: &hdf5::File, est: &Estimator) -> hdf5::Result<()> {
    let g = f.create_group("estimator")?;
    let b = &est.enriched;
    g.new_dataset_builder().with_data(&b.modes.as_standard_layout()).create("modes")?;
    let idx = |v: &[usize]| Array1::from_iter(v.iter().map(|&d| d as u64));
    g.new_dataset_builder().with_data(&idx(&est.block_modes)).create("block_modes")?;
    if let Some(vl) = &b.multiplier_modes {
        g.new_dataset_builder().with_data(&vl.as_standard_layout()).create("multiplier_modes")?;
    }
    if let Some(h) = &b.hyper {
        let hg = g.create_group("hyper")?;
        hg.new_dataset_builder().with_data(&idx(&h.elements)).create("elements")?;
        hg.new_dataset_builder().with_data(&Array1::from(h.weights.clone())).create("weights")?;
        attr_f64(&hg, "tolerance", h.tolerance)?;
        attr_f64(&hg, "training_residual", h.training_residual)?;
        attr_u64(&hg, "n_training", h.n_training as u64)?;
    }
    let c = &est.calibration;
    let cg = g.create_group("calibration")?;
    let col = |f: &dyn Fn(&CalibrationPoint) -> f64| Array1::from_iter(c.points.iter().map(f));
    cg.new_dataset_builder().with_data(&col(&|p| p.load_scale)).create("load_scale")?;
    cg.new_dataset_builder().with_data(&col(&|p| p.raw_estimate)).create("raw_estimate")?;
    cg.new_dataset_builder().with_data(&col(&|p| p.rel_error)).create("rel_error")?;
    if !c.quantities.is_empty() {
        let factors = Array1::from_iter(c.quantities.iter().map(|(_, f)| *f));
        let ds = cg.new_dataset_builder().with_data(&factors).create("quantity_factor")?;
        let keys: Vec<&str> = c.quantities.iter().map(|(k, _)| k.as_str()).collect();
        attr_str(&ds, "quantities", &keys.join("\n"))?;
    }
    if let Some(d) = &est.defects {
        let dg = g.create_group("defects")?;
        dg.new_dataset_builder().with_data(&Array1::from(d.load_scales.clone())).create("load_scale")?;
        let ratios = ndarray::Array2::from_shape_fn((d.ratios.len(), 5), |(j, i)| d.ratios[j][i]);
        dg.new_dataset_builder().with_data(&ratios).create("ratio")?;
        dg.new_dataset_builder().with_data(&Array1::from(d.factors.to_vec())).create("factor")?;
        if let Some(sc) = &d.scattered {
            let dims = sc.space.ranges.len();
            let unit = ndarray::Array2::from_shape_fn((sc.unit.len(), dims), |(j, i)| sc.unit[j][i]);
            let ds = dg.new_dataset_builder().with_data(&unit).create("unit_point")?;
            attr_str(&ds, "parameters", &sc.space.names().collect::<Vec<_>>().join(","))?;
        }
        attr_u64(&dg, "reliable", d.reliable as u64)?;
        if !d.quantities.is_empty() {
            // each quantity's whole-run ratio at the candidates, a column per quantity
            let n = d.ratios.len();
            let all = &d.quantities;
            let q = ndarray::Array2::from_shape_fn((n, all.len()), |(j, k)| {
                all[k].1.ratios.get(j).map_or(f64::NAN, |r| r[FIFTHS - 1])
            });
            let ds = dg.new_dataset_builder().with_data(&q).create("quantity_ratio")?;
            let keys: Vec<&str> = all.iter().map(|(k, _)| k.as_str()).collect();
            attr_str(&ds, "quantities", &keys.join("\n"))?;
        }
    }
    attr_str(&g, "method", "enriched")?;
    attr_str(&g, "default_method", est.default_method().name())?;
    attr_u64(&g, "extra_modes", est.extra_modes as u64)?;
    attr_f64(&g, "factor", c.factor)?;
    attr_u64(&g, "calibrated", c.calibrated as u64)?;
    attr_u64(&g, "n_modes", b.n_reduced() as u64)?;
    Ok(())
}

/// Reads `/estimator` of the open basis file `f` (at `path`, for messages), completing it
/// from `basis` (variant, reference, kept coordinates are the basis's). `None` when the file
/// has none (trained before the estimator existed).
pub fn read_estimator(f: &hdf5::File, path: &Path, basis: &Basis) -> Result<Option<Estimator>> {
    let Ok(g) = f.group("estimator") else { return Ok(None) };
    let field = |name: &str, problem: String| Error::input(path, format!("estimator/{name}"), problem);
    let modes = g
        .dataset("modes")
        .and_then(|d| d.read_2d::<f64>())
        .map_err(|e| field("modes", format!("cannot be read: {e}")))?;
    let idx = |g: &hdf5::Group, name: &str, prefix: &str| -> Result<Vec<usize>> {
        Ok(g.dataset(name)
            .and_then(|d| d.read_1d::<u64>())
            .map_err(|e| field(&format!("{prefix}{name}"), format!("cannot be read: {e}")))?
            .iter()
            .map(|&v| v as usize)
            .collect())
    };
    let vec = |g: &hdf5::Group, name: &str| -> Result<Vec<f64>> {
        Ok(g.dataset(name)
            .and_then(|d| d.read_1d::<f64>())
            .map_err(|e| field(&format!("calibration/{name}"), format!("cannot be read: {e}")))?
            .to_vec())
    };
    let block_modes = idx(&g, "block_modes", "")?;
    let num = |name: &str| read_attr_f64(&g, name).map_err(|e| field(name, format!("cannot be read: {e}")));
    let count = |name: &str| {
        g.attr(name).and_then(|a| a.read_scalar::<u64>()).map_err(|e| field(name, format!("cannot be read: {e}")))
    };
    let method = read_attr_str(&g, "method").map_err(|e| field("method", format!("cannot be read: {e}")))?;
    if method != "enriched" {
        return Err(field("method", format!("is `{method}`; this program knows `enriched`")));
    }
    let chosen = match g.attr("default_method") {
        Ok(_) => {
            let m = read_attr_str(&g, "default_method")
                .map_err(|e| field("default_method", format!("cannot be read: {e}")))?;
            Some(EstimateMethod::parse(&m).map_err(|p| field("default_method", p.problem()))?)
        }
        Err(_) => None,
    };
    let multiplier_modes = match g.dataset("multiplier_modes") {
        Ok(d) => Some(d.read_2d::<f64>().map_err(|e| field("multiplier_modes", format!("cannot be read: {e}")))?),
        Err(_) => None,
    };
    let hyper = match g.group("hyper") {
        Ok(hg) => {
            let hnum = |name: &str| {
                read_attr_f64(&hg, name).map_err(|e| field(&format!("hyper/{name}"), format!("cannot be read: {e}")))
            };
            let weights = hg
                .dataset("weights")
                .and_then(|d| d.read_1d::<f64>())
                .map_err(|e| field("hyper/weights", format!("cannot be read: {e}")))?
                .to_vec();
            let n_training =
                hg.attr("n_training")
                    .and_then(|a| a.read_scalar::<u64>())
                    .map_err(|e| field("hyper/n_training", format!("cannot be read: {e}")))? as usize;
            let h = Hyper {
                elements: idx(&hg, "elements", "hyper/")?,
                weights,
                tolerance: hnum("tolerance")?,
                training_residual: hnum("training_residual")?,
                n_training,
            };
            h.validate(usize::MAX).map_err(|(f, p)| field(&f, p))?;
            Some(h)
        }
        Err(_) => None,
    };
    let cg = g.group("calibration").map_err(|e| field("calibration", format!("cannot be read: {e}")))?;
    let (ls, raw, err) = (vec(&cg, "load_scale")?, vec(&cg, "raw_estimate")?, vec(&cg, "rel_error")?);
    if raw.len() != ls.len() || err.len() != ls.len() {
        return Err(field(
            "calibration",
            format!("load_scale, raw_estimate, rel_error have {}, {}, {} entries", ls.len(), raw.len(), err.len()),
        ));
    }
    let points = (0..ls.len())
        .map(|i| CalibrationPoint { load_scale: ls[i], raw_estimate: raw[i], rel_error: err[i] })
        .collect();
    let factor = num("factor")?;
    if !(factor.is_finite() && factor > 0.0) {
        return Err(field("factor", format!("is {factor}; it must be positive and finite")));
    }
    let kept = basis.kept.clone();
    let n_pod_modes = block_modes.iter().sum();
    let enriched = Basis {
        variant: basis.variant,
        snapshots: basis.snapshots,
        reference: basis.reference.clone(),
        modes,
        kept,
        multiplier_modes,
        multiplier_scale: basis.multiplier_scale,
        n_pod_modes,
        hyper,
    };
    // whole-system-stabilized: k supremizer columns follow the POD modes
    let supremizers = match (&enriched.multiplier_modes, enriched.variant) {
        (Some(psi), crate::reduction::Variant::WholeSystemStabilized) => psi.ncols(),
        _ => 0,
    };
    if enriched.modes.nrows() != basis.n_dof()
        || n_pod_modes + supremizers + enriched.kept.len() != enriched.modes.ncols()
    {
        return Err(field(
            "modes",
            format!(
                "is {:?}; expected {} rows and {} POD + {supremizers} supremizer + {} kept columns (block_modes)",
                enriched.modes.dim(),
                basis.n_dof(),
                n_pod_modes,
                enriched.kept.len()
            ),
        ));
    }
    let defects = match g.group("defects") {
        Ok(dg) => Some(read_defects(f, path, &dg, &field)?),
        Err(_) => None,
    };
    Ok(Some(Estimator {
        enriched,
        block_modes,
        extra_modes: count("extra_modes")? as usize,
        calibration: Calibration {
            factor,
            calibrated: count("calibrated")? != 0,
            points,
            quantities: read_quantity_factors(&cg, &field)?,
        },
        defects,
        method: chosen,
    }))
}

/// `/estimator/defects`: the loads (finite, increasing) and their ratios (N × 5); the
/// factors and the check's outcome are derived from them, as training derived them.
fn read_defects(
    f: &hdf5::File,
    path: &Path,
    dg: &hdf5::Group,
    field: &dyn Fn(&str, String) -> Error,
) -> Result<DefectsCalibration> {
    let load_scales = dg
        .dataset("load_scale")
        .and_then(|d| d.read_1d::<f64>())
        .map_err(|e| field("defects/load_scale", format!("cannot be read: {e}")))?
        .to_vec();
    if load_scales.iter().any(|x| !x.is_finite()) || load_scales.windows(2).any(|w| !(w[0] < w[1])) {
        return Err(field(
            "defects/load_scale",
            "must hold finite load scales in increasing order (the candidate loads of greedy training)".into(),
        ));
    }
    let ratio = dg
        .dataset("ratio")
        .and_then(|d| d.read_2d::<f64>())
        .map_err(|e| field("defects/ratio", format!("cannot be read: {e}")))?;
    // no loads: the candidates were points of a parameter box (one row each)
    let scattered = load_scales.is_empty();
    if ratio.ncols() != 5 || !(scattered || ratio.nrows() == load_scales.len()) {
        return Err(field(
            "defects/ratio",
            format!("is {:?}; expected ({}, 5), a row per load of defects/load_scale", ratio.dim(), load_scales.len()),
        ));
    }
    let ratios = ratio.rows().into_iter().map(|r| [r[0], r[1], r[2], r[3], r[4]]).collect();
    // `factor` and `reliable` follow from the ratios; the file carries them for its readers
    let c = if scattered {
        // where the candidates lie: their unit-cube coordinates in the basis's box
        let space = crate::io::parameter_space_file::parameter_space(f, path)?.unwrap_or_default();
        let unit = dg
            .dataset("unit_point")
            .and_then(|d| d.read_2d::<f64>())
            .map_err(|e| field("defects/unit_point", format!("cannot be read (the candidates of a box): {e}")))?;
        if unit.dim() != (ratio.nrows(), space.ranges.len()) || unit.iter().any(|x| !x.is_finite()) {
            return Err(field(
                "defects/unit_point",
                format!(
                    "is {:?}; expected ({}, {}) finite values, a row per row of defects/ratio and a column per parameter of /parameters",
                    unit.dim(),
                    ratio.nrows(),
                    space.ranges.len()
                ),
            ));
        }
        let unit = unit.rows().into_iter().map(|r| r.to_vec()).collect();
        DefectsCalibration::scattered(space, unit, ratios)
    } else {
        DefectsCalibration::new(load_scales, ratios)
    };
    let c =
        c.ok_or_else(|| field("defects/ratio", "has a fifth of the run without one positive, finite ratio".into()))?;
    read_quantity_ratios(dg, c, field)
}

/// `/estimator/calibration/quantity_factor` (n_q) and its attribute `quantities` (the keys
/// `quantity:probe`, one a line): each probe quantity's and reaction's `c_q`, positive and
/// finite; files written before it have none (every quantity reads `c`).
fn read_quantity_factors(cg: &hdf5::Group, field: &dyn Fn(&str, String) -> Error) -> Result<Vec<(String, f64)>> {
    let Ok(ds) = cg.dataset("quantity_factor") else { return Ok(Vec::new()) };
    let name = "calibration/quantity_factor";
    let keys = quantity_keys(&ds, name, field)?;
    if ds.shape() != [keys.len()] {
        return Err(field(name, format!("is {:?}; expected ({}), one factor per quantity", ds.shape(), keys.len())));
    }
    let f = ds.read_1d::<f64>().map_err(|e| field(name, format!("cannot be read: {e}")))?;
    if let Some(bad) = f.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
        return Err(field(name, format!("holds {bad}; every factor must be positive and finite")));
    }
    Ok(keys.into_iter().zip(f.iter().copied()).collect())
}

/// The attribute `quantities` of the dataset `name`: the keys `quantity:probe` of its
/// columns, one a line.
fn quantity_keys(ds: &hdf5::Dataset, name: &str, field: &dyn Fn(&str, String) -> Error) -> Result<Vec<String>> {
    let keys = crate::io::h5::read_attr_str(ds, "quantities")
        .map_err(|e| field(name, format!("has no readable attribute quantities ({e})")))?;
    Ok(keys.lines().map(str::to_string).collect())
}

/// `/estimator/defects/quantity_ratio` (N, n_q) and its attribute `quantities` (the keys
/// `quantity:probe`, one a line): each probe quantity's calibration; files written before
/// it have none.
fn read_quantity_ratios(
    dg: &hdf5::Group,
    c: DefectsCalibration,
    field: &dyn Fn(&str, String) -> Error,
) -> Result<DefectsCalibration> {
    let Ok(ds) = dg.dataset("quantity_ratio") else { return Ok(c) };
    let name = "defects/quantity_ratio";
    let keys = quantity_keys(&ds, name, field)?;
    let want = (c.ratios.len(), keys.len());
    let shape = ds.shape();
    if shape != [want.0, want.1] {
        return Err(field(
            name,
            format!("is {shape:?}; expected {want:?}, a row per candidate and a column per quantity"),
        ));
    }
    let q = ds.read_2d::<f64>().map_err(|e| field(name, format!("cannot be read: {e}")))?;
    let rows: Vec<Vec<f64>> = q.rows().into_iter().map(|r| r.to_vec()).collect();
    Ok(c.with_quantities(&keys, &rows))
}

/// `[min, max]` of the training load scales: `/training/range` when present (greedy
/// training), else the extremes of `/snapshot_load_scale`.
pub fn training_range(f: &hdf5::File, path: &Path) -> Result<(f64, f64)> {
    if let Ok(d) = f.dataset("training/range") {
        let r = d.read_1d::<f64>().map_err(|e| Error::input(path, "training/range", format!("cannot be read: {e}")))?;
        if r.len() != 2 || !(r[0].is_finite() && r[1].is_finite() && r[0] <= r[1]) {
            return Err(Error::input(path, "training/range", format!("is {r}; expected [A, B] with A ≤ B finite")));
        }
        return Ok((r[0], r[1]));
    }
    let s = f
        .dataset("snapshot_load_scale")
        .and_then(|d| d.read_1d::<f64>())
        .map_err(|e| Error::input(path, "snapshot_load_scale", format!("cannot be read: {e}")))?;
    let lo = s.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = s.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(Error::input(path, "snapshot_load_scale", "is empty or not finite"));
    }
    Ok((lo, hi))
}

/// The loads of the full runs whose snapshots the basis holds, sorted, each once:
/// `/training/load_scales` (greedy training), else the values of `/snapshot_load_scale`.
pub fn training_loads(f: &hdf5::File, path: &Path) -> Result<Vec<f64>> {
    let mut l: Vec<f64> = match f.dataset("training/load_scales") {
        Ok(d) => d.read_1d::<f64>().map_err(|e| Error::input(path, "training/load_scales", e.to_string()))?.to_vec(),
        Err(_) => f
            .dataset("snapshot_load_scale")
            .and_then(|d| d.read_1d::<f64>())
            .map_err(|e| Error::input(path, "snapshot_load_scale", e.to_string()))?
            .to_vec(),
    };
    l.sort_by(f64::total_cmp);
    l.dedup();
    Ok(l)
}

/// Greedy training's candidates and the reduced model's whole-run sensitivity at each, as
/// its last iteration measured them (`/training/candidates`, the last row of
/// `/training/sensitivity`); `None` without greedy training or in files written before the
/// sensitivity was recorded.
pub fn training_sensitivity(f: &hdf5::File, path: &Path) -> Result<Option<(Vec<f64>, Vec<f64>)>> {
    let Ok(g) = f.group("training") else { return Ok(None) };
    let (Ok(c), Ok(s)) = (g.dataset("candidates"), g.dataset("sensitivity")) else { return Ok(None) };
    let c =
        c.read_1d::<f64>().map_err(|e| Error::input(path, "training/candidates", format!("cannot be read: {e}")))?;
    let s =
        s.read_2d::<f64>().map_err(|e| Error::input(path, "training/sensitivity", format!("cannot be read: {e}")))?;
    if !c.iter().all(|x| x.is_finite()) || c.windows(2).into_iter().any(|w| !(w[0] < w[1])) {
        return Err(Error::input(path, "training/candidates", "must be finite and increasing"));
    }
    if s.nrows() == 0 {
        return Ok(None);
    }
    if s.ncols() != c.len() {
        return Err(Error::input(
            path,
            "training/sensitivity",
            format!("has {} columns for {} candidates (training/candidates)", s.ncols(), c.len()),
        ));
    }
    let last = s.row(s.nrows() - 1).to_vec();
    if last.iter().any(|x| *x < 0.0) {
        return Err(Error::input(path, "training/sensitivity", "has a negative entry: a sensitivity is a norm ratio"));
    }
    Ok(Some((c.to_vec(), last)))
}

/// A box's candidates in its unit cube, and the sensitivity at each.
pub type BoxSensitivity = (Vec<Vec<f64>>, Vec<f64>);

/// Greedy training's candidates over a box (`/training/candidate_points`, the columns named
/// by its attribute `parameters`) in the unit cube of `space`, and the reduced model's
/// whole-run sensitivity at each (the last row of `/training/sensitivity`); `None` without
/// them.
pub fn training_box_sensitivity(
    f: &hdf5::File,
    path: &Path,
    space: &crate::solver::parameter_space::ParameterSpace,
) -> Result<Option<BoxSensitivity>> {
    let Ok(g) = f.group("training") else { return Ok(None) };
    let (Ok(c), Ok(s)) = (g.dataset("candidate_points"), g.dataset("sensitivity")) else { return Ok(None) };
    let bad = |field: &str, problem: String| Error::input(path, field, problem);
    let names = read_attr_str(&c, "parameters")
        .map_err(|e| bad("training/candidate_points", format!("has no readable attribute `parameters`: {e}")))?;
    let names: Vec<&str> = names.split(',').collect();
    let c = c.read_2d::<f64>().map_err(|e| bad("training/candidate_points", format!("cannot be read: {e}")))?;
    let s = s.read_2d::<f64>().map_err(|e| bad("training/sensitivity", format!("cannot be read: {e}")))?;
    if c.ncols() != names.len() || names.iter().any(|n| space.range(n).is_none()) {
        return Err(bad(
            "training/candidate_points",
            format!("has columns {names:?}; expected the parameters of /parameters, one column each"),
        ));
    }
    if s.nrows() == 0 {
        return Ok(None);
    }
    if s.ncols() != c.nrows() {
        return Err(bad(
            "training/sensitivity",
            format!("has {} columns for {} candidates (training/candidate_points)", s.ncols(), c.nrows()),
        ));
    }
    let unit = c
        .rows()
        .into_iter()
        .map(|row| {
            let mu =
                names.iter().zip(row).fold(crate::solver::parameters::Parameters::default(), |m, (n, &x)| m.with(n, x));
            space.unit_of(&mu)
        })
        .collect();
    Ok(Some((unit, s.row(s.nrows() - 1).to_vec())))
}

/// Greedy training's tolerance: the dataset `/training/tolerance` or the attribute
/// `tolerance` on `/training`; `None` without greedy training.
pub fn training_tolerance(f: &hdf5::File, path: &Path) -> Result<Option<f64>> {
    let Ok(g) = f.group("training") else { return Ok(None) };
    let t = if let Ok(d) = g.dataset("tolerance") {
        d.read_scalar::<f64>().or_else(|_| d.read_1d::<f64>().map(|a| a.first().copied().unwrap_or(f64::NAN)))
    } else if g.attr("tolerance").is_ok() {
        read_attr_f64(&g, "tolerance")
    } else {
        return Ok(None);
    };
    let t = t.map_err(|e| Error::input(path, "training/tolerance", format!("cannot be read: {e}")))?;
    if !(t.is_finite() && t > 0.0) {
        return Err(Error::input(path, "training/tolerance", format!("is {t}; it must be positive and finite")));
    }
    Ok(Some(t))
}

/// What greedy training said beside meeting its tolerance, in words, one sentence each with
/// the attribute's name: `held_out_note` (its converged held-out check's error above the
/// tolerance) and `estimate_note` (the online default, `defects`, reading above it between
/// the candidates) on `/training`, those present; empty without them (within the
/// tolerance, other training, files written before the attributes).
pub fn training_notes(f: &hdf5::File, path: &Path) -> Result<Vec<(&'static str, String)>> {
    let Ok(g) = f.group("training") else { return Ok(Vec::new()) };
    let mut notes = Vec::new();
    for name in ["held_out_note", "estimate_note"] {
        if g.attr(name).is_err() {
            continue;
        }
        let note = read_attr_str(&g, name)
            .map_err(|e| Error::input(path, format!("training/{name}"), format!("cannot be read: {e}")))?;
        notes.push((name, note));
    }
    Ok(notes)
}

/// The error greedy training's tolerance is on: the attribute `measure` on `/training`;
/// relative without one (files written before the attribute, bases of fixed loads).
pub fn training_measure(f: &hdf5::File, path: &Path) -> Result<ErrorMeasure> {
    let Ok(g) = f.group("training") else { return Ok(ErrorMeasure::Relative) };
    if g.attr("measure").is_err() {
        return Ok(ErrorMeasure::Relative);
    }
    let m = read_attr_str(&g, "measure")
        .map_err(|e| Error::input(path, "training/measure", format!("cannot be read: {e}")))?;
    ErrorMeasure::parse(&m).map_err(|p| Error::input(path, "training/measure", p.problem()))
}

/// [`training_notes`] of the basis file at `path`, opened for it.
pub fn read_training_notes(path: &Path) -> Result<Vec<(&'static str, String)>> {
    training_notes(&crate::io::h5_open::open_to_read(path)?, path)
}
