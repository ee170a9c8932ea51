//! One run of a reduced sweep file, picked by its load scale or its point, with the model
//! and the basis it ran on: what drawing that run needs. A sweep file keeps each run's
//! reduced coordinates `/reduced_q` (load, time, mode) and names its basis (attributes
//! `basis`, `basis_content_hash`, `model_fingerprint`); the model is the one the basis file
//! stores. The coordinates of an instant are reconstructed as the reduced result files'
//! are, `x = x_ref + V z` ([`crate::reduction::Basis::reconstruct_columns`]).
//!
//! A full sweep (`--full`) stores probes only, a run the full model answered in place of the
//! reduced one (`--fallback full`) no reduced coordinates: both are refused with the command
//! that draws such a run (`flexrom simulate … --load-scale L`, then `flexrom animate`).

use super::sweep_file::points_of;
use super::sweep_outcome::{STATUS_OK, STATUS_PENDING};
use crate::error::{Error, Result, Text};
use crate::io::attrs::{check_layout, Kind, KIND_ATTR};
use crate::io::h5::{bounded_len, dataset_of_shape, read_attr_str, read_strings};
use crate::model::Model;
use crate::reduction::Basis;
use crate::solver::parameters::Parameters;
use ndarray::Array2;
use std::path::{Path, PathBuf};

/// Which run of a sweep file: by its load scale (a sweep over load scales, or a box sweep
/// where one point has it), or by its index in the file (0-based, the row of `/points`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SweepPick {
    LoadScale(f64),
    Point(usize),
}

impl SweepPick {
    /// The command-line option that picks this way.
    pub fn flag(&self) -> &'static str {
        match self {
            SweepPick::LoadScale(_) => "--load-scale",
            SweepPick::Point(_) => "--point",
        }
    }
}

/// One finished reduced run of a sweep file.
pub struct SweepRun {
    /// the model the basis file stores (the sweep file's `model_fingerprint` checked)
    pub model: Model,
    /// `/t`, s
    pub t: Vec<f64>,
    /// the run's parameters
    pub mu: Parameters,
    /// the run's index in the file
    pub index: usize,
    basis: std::sync::Arc<Basis>,
    /// reduced coordinates, one column per instant (r × n_t)
    zq: Array2<f64>,
}

impl SweepRun {
    /// Every coordinate at `t_k`: `x_ref + V z_k`.
    pub fn q_row(&self, k: usize) -> Vec<f64> {
        self.basis.reconstruct_columns(self.zq.slice(ndarray::s![.., k..k + 1])).column(0).to_vec()
    }
}

/// Whether the HDF5 file at `path` says it is a sweep file (`flexrom_file = "sweep"`);
/// false for anything else, unreadable files included (their reader says why).
pub fn is_sweep_file(path: &Path) -> bool {
    crate::io::h5_open::open(path).is_ok_and(|f| read_attr_str(&f, KIND_ATTR).is_ok_and(|k| k == Kind::Sweep.name()))
}

/// Opens the run of the sweep file at `path` that `pick` names, with its basis and model;
/// every refusal names the file (the sweep's, or the basis's) and what to do instead.
pub fn open_sweep_run(path: &Path, pick: SweepPick, limits: &crate::limits::Limits) -> Result<SweepRun> {
    let bad = |field: &str, problem: String| Error::input(path, field, problem);
    let f = crate::io::h5_open::open(path).map_err(|e| bad("(file)", crate::io::h5_open::unreadable(&e)))?;
    let layout = check_layout(&f, path, "flexrom sweep")?;
    let text = |name: &str| read_attr_str(&f, name).map_err(|e| bad(name, format!("cannot be read: {e}")));
    // files written before the attribute are reduced sweeps
    if f.attr("route").is_ok() && text("route")? == "full" {
        return Err(bad(
            "route",
            "is \"full\": a sweep of the full model stores its probes only, no coordinates to draw; \
             run `flexrom simulate MODEL --load-scale L -o run.h5` and animate run.h5"
                .into(),
        ));
    }
    let basis_path = PathBuf::from(text("basis")?);
    let (model, basis) = sweep_basis(path, &basis_path, &text("basis_content_hash")?, limits)?;
    if text("model_fingerprint")? != model.fingerprint() {
        return Err(bad(
            "model_fingerprint",
            format!("is not that of the model the basis {} stores: the sweep ran another model", basis_path.display()),
        ));
    }
    // the file alone sizes /t: bounded before it is read (8 bytes an instant), and a run's
    // coordinates and columns bound how many runs the file may hold
    bounded_len(&f, "t", 8.0, limits).map_err(|p| Error::input(path, "t", p.problem_text()))?;
    let t: Vec<f64> =
        f.dataset("t").and_then(|d| d.read_raw()).map_err(|e| bad("t", format!("cannot be read: {e}")))?;
    let (nt, r) = (t.len(), basis.n_reduced());
    let n = bounded_len(&f, "load_scales", 8.0 * (nt * r + 32) as f64, limits)
        .map_err(|p| Error::input(path, "load_scales", p.problem_text()))?;
    let shaped = |name: &str, want: &[usize]| dataset_of_shape(&f, name, want).map_err(|p| bad(name, p.problem()));
    let scales = shaped("load_scales", &[n])?.read_raw::<f64>().map_err(|e| bad("load_scales", e.to_string()))?;
    let points = points_of(&f, &scales).map_err(|(field, p)| bad(field, p))?;
    let index = pick_index(path, &points, pick)?;
    let mu = points[index].clone();
    let status = shaped("status", &[n])?.read_raw::<u8>().map_err(|e| bad("status", e.to_string()))?;
    if status[index] != STATUS_OK {
        let messages = read_strings(&shaped("message", &[n])?).map_err(|e| bad("message", e.to_string()))?;
        let why = messages.get(index).filter(|m| !m.is_empty()).map_or(String::new(), |m| format!(": {m}"));
        let what = if status[index] == STATUS_PENDING { "did not run yet" } else { "failed" };
        return Err(bad("status", format!("the run at {mu} (point {index}) {what}{why}; it has no motion to draw")));
    }
    let fallback = if f.link_exists("fallback") {
        shaped("fallback", &[n])?.read_raw::<u8>().map_err(|e| bad("fallback", e.to_string()))?[index]
    } else {
        0
    };
    if fallback == 1 {
        return Err(bad(
            "fallback",
            format!(
                "is 1 at {mu} (point {index}): the full model answered there and the sweep keeps no coordinates of it; \
                 run `flexrom simulate MODEL --load-scale {} -o run.h5` and animate run.h5",
                mu.scale()
            ),
        ));
    }
    // layout 1 stored (load, mode, time), later ones (load, time, mode)
    let want = if layout == 1 { [n, r, nt] } else { [n, nt, r] };
    let zq = shaped("reduced_q", &want)?
        .read_slice_2d::<f64, _>(ndarray::s![index, .., ..])
        .map_err(|e| bad("reduced_q", format!("cannot be read: {e}")))?;
    let zq = if layout == 1 { zq } else { zq.reversed_axes().as_standard_layout().to_owned() };
    if zq.iter().any(|x| !x.is_finite()) {
        return Err(bad("reduced_q", format!("holds non-finite values at {mu} (point {index})")));
    }
    Ok(SweepRun { model, t, mu, index, basis, zq })
}

/// The model and basis of the basis file a sweep names, read and checked as every command
/// checks a basis ([`crate::io::basis_check::check`]) and held to the sweep's content hash.
fn sweep_basis(
    sweep: &Path,
    path: &Path,
    content_hash: &str,
    limits: &crate::limits::Limits,
) -> Result<(Model, std::sync::Arc<Basis>)> {
    if !path.is_file() {
        return Err(Error::input(
            sweep,
            "basis",
            format!(
                "names the basis file {}, which does not exist: the sweep's coordinates are reconstructed on it",
                path.display()
            ),
        ));
    }
    // opened once: its model's texts, then the basis checked against that model
    let f = crate::io::h5_open::open_to_read(path)?;
    let text = |name: &str| {
        read_attr_str(&f, name).map_err(|e| {
            Error::input(
                path,
                name,
                format!("cannot be read ({e}); is this the basis file the sweep {} ran?", sweep.display()),
            )
        })
    };
    let (model_text, model_path) = (text("model")?, text("model_path")?);
    let model = Model::from_text_with(&model_text, &model_path, limits.clone())
        .map_err(|e| Error::input(path, "model", format!("the model text it stores is not valid: {e}")))?;
    let stored = crate::io::basis_check::check_open(&f, path, &model, None)?;
    if stored.content_hash != content_hash {
        return Err(Error::input(
            sweep,
            "basis_content_hash",
            format!("is not that of {}: the basis was retrained or replaced since the sweep ran", path.display()),
        ));
    }
    Ok((model, stored.basis))
}

/// The index of the run `pick` names among `points`; a load scale not in the file is
/// refused naming the nearest ones, one shared by several points naming them.
fn pick_index(path: &Path, points: &[Parameters], pick: SweepPick) -> Result<usize> {
    let n = points.len();
    match pick {
        SweepPick::Point(k) if k < n => Ok(k),
        SweepPick::Point(k) => Err(Error::input(
            path,
            "--point",
            format!("{k} is not a point of the sweep: it has {n} (0 to {})", n.saturating_sub(1)),
        )),
        SweepPick::LoadScale(x) => {
            // written from the same decimal as typed, or within round-off of it (0.1 · 3)
            let near = |s: f64| (s - x).abs() <= 1e-9 * x.abs().max(1.0);
            let at: Vec<usize> = (0..n).filter(|&k| near(points[k].scale())).collect();
            match at.as_slice() {
                [k] => Ok(*k),
                [] => Err(Error::input(
                    path,
                    "load_scales",
                    format!("has no run at load scale {x}; {}", nearest(points, x)),
                )),
                many => Err(Error::input(
                    path,
                    "--load-scale",
                    Text::new(format!(
                        "{x} is the load scale of {} points of the sweep ({}): pick one with ",
                        many.len(),
                        many.iter().map(|&k| format!("{k}: {}", points[k])).collect::<Vec<_>>().join("; ")
                    ))
                    .option("point", Some("K")),
                )),
            }
        }
    }
}

/// `the nearest in the file are 1 and 1.1`: the file's loads next below and above `x`.
fn nearest(points: &[Parameters], x: f64) -> String {
    let scales = points.iter().map(Parameters::scale).filter(|s| s.is_finite());
    let below = scales.clone().filter(|&s| s < x).reduce(f64::max);
    let above = scales.filter(|&s| s > x).reduce(f64::min);
    match (below, above) {
        (Some(a), Some(b)) => format!("the nearest in the file are {a} and {b}"),
        (Some(a), None) | (None, Some(a)) => format!("the nearest in the file is {a}"),
        (None, None) => "the file has no load scale".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1.05 lies between 1.0 and 1.1; 0.1 · 3 is 0.3 within round-off; 2 is past the end.
    #[test]
    fn loads_are_found_or_their_neighbours_named() {
        let points: Vec<Parameters> = [0.9, 1.0, 1.1, 0.1 * 3.0].iter().map(|&x| Parameters::load_scale(x)).collect();
        let p = Path::new("s.h5");
        assert_eq!(pick_index(p, &points, SweepPick::LoadScale(1.0)).unwrap(), 1);
        assert_eq!(pick_index(p, &points, SweepPick::LoadScale(0.3)).unwrap(), 3);
        assert_eq!(pick_index(p, &points, SweepPick::Point(2)).unwrap(), 2);
        let e = pick_index(p, &points, SweepPick::LoadScale(1.05)).unwrap_err().to_string();
        assert!(e.contains("nearest in the file are 1 and 1.1"), "{e}");
        let e = pick_index(p, &points, SweepPick::LoadScale(2.0)).unwrap_err().to_string();
        assert!(e.contains("nearest in the file is 1.1"), "{e}");
        let e = pick_index(p, &points, SweepPick::Point(4)).unwrap_err().to_string();
        assert!(e.contains("it has 4 (0 to 3)"), "{e}");
    }

    /// Two points of a box at load scale 1: the load alone is ambiguous.
    #[test]
    fn a_load_shared_by_points_asks_for_the_point() {
        let points = vec![Parameters::load_scale(1.0).with("e", 1.0), Parameters::load_scale(1.0).with("e", 2.0)];
        let e = pick_index(Path::new("s.h5"), &points, SweepPick::LoadScale(1.0)).unwrap_err();
        let e = e.render(&crate::error::cli_flag);
        assert!(e.contains("pick one with --point K") && e.contains("0: load scale 1, e = 1"), "{e}");
    }
}
