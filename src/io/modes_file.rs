//! The modes file of `flexrom modes -o`: the lowest modes of a model linearized at a
//! configuration ([`crate::analysis::modes`]), written atomically.
//!
//! ```text
//! /frequencies    (N)          Hz, ascending (0 for rigid-body modes)
//! /omega_squared  (N)          ω², 1/s² (the eigenvalues of K_T φ = ω² M φ, B φ = 0)
//! /rigid          (N)          1 where the mode is a rigid-body motion, else 0
//! /shapes         (N, n_dof)   row i = mode i laid out like q, φᵀMφ = 1
//! /q              (n_dof)      the configuration the model was linearized at
//! /labels/...                  names of the coordinates and constraint rows
//! /paraview/...                `--paraview` only: the shapes as ParaView's displacement
//!                              fields ([`crate::io::paraview`])
//! attributes on /: flexrom_layout, flexrom_file = "modes", model, model_path, at
//!   ("initial" or "static"), load_scale, parameter:NAME, time, iterations, program_version
//! ```

use super::attrs::{write_atomically_labelled, Kind};
use super::h5::{attr_f64, attr_str, attr_u64};
use crate::analysis::modes::Modes;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::solver::parameters::Parameters;
use std::path::Path;

/// Where and how the modes were computed, as the file records it.
pub struct ModesRecord<'a> {
    pub model: &'a Model,
    pub modes: &'a Modes,
    /// the configuration `q*`
    pub q: &'a [f64],
    /// "initial" or "static"
    pub at: &'a str,
    pub mu: &'a Parameters,
    /// the time of the loads, s
    pub time: f64,
}

/// Writes `r` to `path` atomically (a temporary file renamed into place).
pub fn write(path: &Path, r: &ModesRecord) -> Result<()> {
    write_with_paraview(path, r, false).map(|_| ())
}

/// [`write()`], with ParaView's datasets where `paraview` (their layout returned, for the
/// XDMF file: [`crate::io::paraview::write_modes_xdmf`]).
pub fn write_with_paraview(
    path: &Path,
    r: &ModesRecord,
    paraview: bool,
) -> Result<Option<crate::io::paraview::ModesLayout>> {
    let mut layout = None;
    write_atomically_labelled(path, Kind::Modes, |f, labelled| {
        let e = |err: hdf5::Error| Error::hdf5(path, err);
        let model_path = r.model.path.display().to_string();
        attr_str(f, "model", &r.model.text).map_err(e)?;
        attr_str(f, "model_path", &model_path).map_err(e)?;
        attr_str(f, "program_version", env!("CARGO_PKG_VERSION")).map_err(e)?;
        attr_str(f, "at", r.at).map_err(e)?;
        attr_f64(f, "load_scale", r.mu.scale()).map_err(e)?;
        for (name, value) in r.mu.named() {
            attr_f64(f, &format!("parameter:{name}"), value).map_err(e)?;
        }
        attr_f64(f, "time", r.time).map_err(e)?;
        attr_u64(f, "iterations", r.modes.iterations as u64).map_err(e)?;
        super::labels::write_labels_of_text_labelled(f, &r.model.text, &model_path, Some(labelled)).map_err(e)?;
        let rigid: Vec<f64> = r.modes.rigid.iter().map(|&b| if b { 1.0 } else { 0.0 }).collect();
        let write = |name: &str, data: ndarray::ArrayViewD<f64>| -> hdf5::Result<()> {
            f.new_dataset_builder().with_data(&data).create(name).map(|_| ())
        };
        write("frequencies", ndarray::ArrayView1::from(&r.modes.frequencies).into_dyn()).map_err(e)?;
        write("omega_squared", ndarray::ArrayView1::from(&r.modes.omega_squared).into_dyn()).map_err(e)?;
        write("rigid", ndarray::ArrayView1::from(&rigid).into_dyn()).map_err(e)?;
        write("shapes", r.modes.shapes.view().into_dyn()).map_err(e)?;
        write("q", ndarray::ArrayView1::from(r.q).into_dyn()).map_err(e)?;
        if paraview {
            let (bodies, shapes) = (r.model.bodies(), r.modes.shapes.view());
            let written = crate::io::paraview::write_mode_datasets(f, bodies, r.q, shapes, &r.modes.frequencies);
            layout = Some(written.map_err(e)?);
        }
        Ok(())
    })?;
    Ok(layout)
}
