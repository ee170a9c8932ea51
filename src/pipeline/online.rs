//! `online`: load a basis, run the reduced model at a load scale, reconstruct.

use super::config::Pipeline;
use crate::error::{Error, Result};
use crate::io::basis_file::{read_basis, StoredBasis};
use crate::model::Model;
use crate::reduction::{Basis, ReducedModel};
use crate::simulate::{integrate, prepare, Overrides, Settings, SimulationResult};
use crate::solver::model::DynamicModel;
use ndarray::{Array1, Array2, ArrayView1};
use std::path::Path;

/// A reduced run: the full-coordinate result (same layout as `simulate`) and the reduced
/// trajectory. `result.wall_seconds` is the reduced time loop alone.
#[derive(Clone, Debug)]
pub struct ReducedRun {
    pub result: SimulationResult,
    /// r × n_t
    pub reduced_q: Array2<f64>,
}

/// Reads the pipeline's basis (or `path`) and refuses one trained on another model.
pub fn load_basis(p: &Pipeline, path: &Path) -> Result<StoredBasis> {
    let stored = read_basis(path)?;
    let mine = p.model.fingerprint();
    if stored.model_fingerprint != mine {
        return Err(Error::input(
            path,
            "model_fingerprint",
            format!(
                "the basis was trained on a different model than `{}` (fingerprint {} ≠ {}); run `flexrom train {}` again",
                p.model.path.display(),
                short(&stored.model_fingerprint),
                short(&mine),
                p.path.display()
            ),
        ));
    }
    let sys = p.model.system(Default::default());
    stored.basis.validate(sys.n_dof(), sys.n_constraints()).map_err(|(field, problem)| Error::input(path, field, problem))?;
    Ok(stored)
}

fn short(h: &str) -> &str {
    &h[..h.len().min(12)]
}

/// Runs the reduced model of `basis` at `load_scale` with the model's time settings.
pub fn run_reduced(model: &Model, basis: &Basis, load_scale: f64) -> Result<ReducedRun> {
    let s = Settings::resolve(model, &Overrides { load_scale: Some(load_scale), ..Default::default() })?;
    let (sys, x0) = prepare(model, &s)?;
    let probes = sys.probes.clone();
    let n_c = sys.n_constraints();
    let mut rom = ReducedModel::new(sys, basis).map_err(|e| Error::Usage(format!("cannot build the reduced model: {e}")))?;
    let q0 = basis.reduce(ArrayView1::from(&x0)).to_vec();
    let (r, nt) = (rom.n_dof(), s.n_steps + 1);
    let mut zq = Array2::zeros((r, nt));
    let mut lam = Array2::<f64>::zeros((rom.n_constraints(), nt));
    let mut t = Array1::zeros(nt);
    let start = std::time::Instant::now();
    let stats = integrate(&mut rom, &s.params, q0, s.dt, s.n_steps, |k, st| {
        t[k] = st.t;
        zq.column_mut(k).assign(&ArrayView1::from(&st.q));
        lam.column_mut(k).assign(&ArrayView1::from(&st.lambda));
    })?;
    let wall_seconds = start.elapsed().as_secs_f64();
    // reconstruct only what is written out
    let q = basis.reference.view().insert_axis(ndarray::Axis(1)).to_owned() + basis.modes.dot(&zq);
    let mut multipliers = Array2::from_elem((n_c, nt), f64::NAN);
    for k in 0..nt {
        if let Some(l) = rom.multipliers(&zq.column(k).to_vec(), &lam.column(k).to_vec()) {
            multipliers.column_mut(k).assign(&l);
        }
    }
    let full = rom.full();
    let probes = probes
        .iter()
        .map(|p| {
            let mut xy = Array2::zeros((nt, 2));
            for k in 0..nt {
                let r = full.probe_position(p, &q.column(k).to_vec());
                xy[[k, 0]] = r[0];
                xy[[k, 1]] = r[1];
            }
            (p.name.clone(), xy)
        })
        .collect();
    Ok(ReducedRun {
        result: SimulationResult {
            model_text: model.text.clone(),
            model_path: model.path.display().to_string(),
            settings: s,
            t,
            q,
            multipliers,
            probes,
            stats,
            wall_seconds,
        },
        reduced_q: zq,
    })
}
