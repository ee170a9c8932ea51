//! Reading a result file back ([`super::result_file`]'s layout) a few instants at a time:
//! what drawing the motion needs (the model's text, `/t`, rows of `/q`), without reading
//! the whole run. A reduced run's file holds the reconstructed coordinates `V z` in `/q`
//! (`online` writes them), so full and reduced results are read alike.

use super::attrs::{check_layout, Kind, KIND_ATTR};
use super::h5::{read_attr_f64, read_attr_str};
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// An open result file.
pub struct ResultReader {
    q: hdf5::Dataset,
    path: PathBuf,
    /// the model file's text the run used, and the path it was read from
    pub model_text: String,
    pub model_path: String,
    /// `/t`, s
    pub t: Vec<f64>,
    /// the run's load scale (attribute `load_scale`; 1 where absent)
    pub load_scale: f64,
    n_dof: usize,
}

impl ResultReader {
    /// Opens the result file at `path`, refusing a file that is not HDF5, another kind of
    /// flexrom file (a basis, a sweep: named), a newer layout, or a result whose `/t` and
    /// `/q` disagree; every message names the file and what is wrong.
    pub fn open(path: &Path, limits: &crate::limits::Limits) -> Result<ResultReader> {
        let f = crate::io::h5_open::open(path).map_err(|e| {
            if super::h5_open::is_locked(&e) {
                Error::hdf5(path, super::h5_open::unreadable(&e))
            } else if std::fs::metadata(path).is_err() {
                Error::hdf5(path, "no such file")
            } else {
                Error::hdf5(path, "is not an HDF5 file (a result file of `flexrom simulate`, `online` or `statics`)")
            }
        })?;
        match read_attr_str(&f, KIND_ATTR) {
            Ok(kind) if kind == Kind::Result.name() => {}
            Ok(kind) => {
                return Err(Error::input(
                    path,
                    KIND_ATTR,
                    format!(
                        "is `{kind}`: a {kind} file, not a result file (of `flexrom simulate`, `online` or `statics`)"
                    ),
                ))
            }
            Err(_) => {
                return Err(Error::input(
                    path,
                    KIND_ATTR,
                    "is missing: not a result file flexrom wrote (of `flexrom simulate`, `online` or `statics`)",
                ))
            }
        }
        check_layout(&f, path, "flexrom simulate")?;
        let text =
            |name: &str| read_attr_str(&f, name).map_err(|e| Error::input(path, name, format!("cannot be read: {e}")));
        let (model_text, model_path) = (text("model")?, text("model_path")?);
        // the file alone sizes /t: bounded before it is read (8 bytes an instant)
        super::h5::bounded_len(&f, "t", 8.0, limits).map_err(|e| Error::input(path, "t", e.problem_text()))?;
        let t: Vec<f64> = f
            .dataset("t")
            .and_then(|d| d.read_raw::<f64>())
            .map_err(|e| Error::input(path, "t", format!("cannot be read: {e}")))?;
        let q = f.dataset("q").map_err(|e| Error::input(path, "q", format!("cannot be read: {e}")))?;
        let shape = q.shape();
        if shape.len() != 2 || shape[0] != t.len() {
            return Err(Error::input(
                path,
                "q",
                format!("has shape {shape:?}; a result's /q is (n_t, n_dof) with n_t = {} instants of /t", t.len()),
            ));
        }
        let load_scale = read_attr_f64(&f, "load_scale").unwrap_or(1.0);
        Ok(ResultReader { n_dof: shape[1], q, path: path.to_path_buf(), model_text, model_path, t, load_scale })
    }

    /// The number of coordinates of a row of `/q`.
    pub fn n_dof(&self) -> usize {
        self.n_dof
    }

    /// Row `k` of `/q`: every coordinate at `t_k`.
    pub fn q_row(&self, k: usize) -> Result<Vec<f64>> {
        self.q
            .read_slice_1d::<f64, _>(ndarray::s![k, ..])
            .map(|a| a.to_vec())
            .map_err(|e| Error::input(&self.path, "q", format!("row {k} cannot be read: {e}")))
    }
}
