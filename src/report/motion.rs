//! A run's motion as drawing reads it, an instant at a time: the coordinates `/q` of a
//! result file (`simulate`, `online`, `statics`: a reduced run's file holds them
//! reconstructed), or one run of a reduced sweep file reconstructed on its basis
//! ([`crate::records::sweep_run`]), with the model it ran and its time grid.

use crate::error::{Error, Result, Text};
use crate::io::result_read::ResultReader;
use crate::model::Model;
use crate::workflows::sweep::{is_sweep_file, open_sweep_run, SweepPick, SweepRun};
use std::path::Path;

/// Where the coordinates come from.
enum Source {
    Result(ResultReader),
    Sweep(Box<SweepRun>),
}

/// One run's motion.
pub struct Motion {
    source: Source,
    /// the model the run used
    pub model: Model,
    /// how a title names the run: the file's name, and for a sweep the run picked
    pub name: String,
}

impl Motion {
    /// Opens the run in the file at `path`: a result file as it is, a sweep file at the run
    /// `pick` names (a sweep file without `pick` is refused, naming the options). Returns
    /// whether the file was a sweep file beside the motion.
    pub fn open(path: &Path, pick: Option<SweepPick>, limits: &crate::limits::Limits) -> Result<(Motion, bool)> {
        let file = path.file_name().map_or(path.display().to_string(), |n| n.to_string_lossy().into_owned());
        if is_sweep_file(path) {
            let Some(pick) = pick else {
                return Err(Error::input(
                    path,
                    "(file)",
                    Text::new("is a sweep file: pick the run to draw with ")
                        .option("load_scale", Some("L"))
                        .then(" (or ")
                        .option("point", Some("K"))
                        .then(" in a sweep over named parameters)"),
                ));
            };
            let run = open_sweep_run(path, pick, limits)?;
            let name = format!("{file}, {} (point {})", run.mu, run.index);
            let model = run.model.clone();
            return Ok((Motion { source: Source::Sweep(Box::new(run)), model, name }, true));
        }
        let reader = ResultReader::open(path, limits)?;
        let model = Model::from_text_with(&reader.model_text, &reader.model_path, limits.clone())
            .map_err(|e| Error::input(path, "model", format!("the model text it stores is not valid: {e}")))?;
        let n_dof = 4 * model.bodies().iter().map(|b| b.n_elements + 1).sum::<usize>();
        if n_dof != reader.n_dof() {
            return Err(Error::input(
                path,
                "q",
                format!("has {} coordinates a row; the model it stores has {n_dof}", reader.n_dof()),
            ));
        }
        Ok((Motion { source: Source::Result(reader), model, name: file }, false))
    }

    /// The run's instants, s.
    pub fn t(&self) -> &[f64] {
        match &self.source {
            Source::Result(r) => &r.t,
            Source::Sweep(s) => &s.t,
        }
    }

    /// Every coordinate at `t_k`.
    pub fn q_row(&self, k: usize) -> Result<Vec<f64>> {
        match &self.source {
            Source::Result(r) => r.q_row(k),
            Source::Sweep(s) => Ok(s.q_row(k)),
        }
    }
}
