//! What a basis file says of the training that made it, beside the basis: the training
//! range and loads, greedy's tolerance and its measure, its notes, the sensitivity it
//! measured, the box of parameters and its training points, the snapshot count, and `train`'s
//! timing of both routes. Read from the
//! open file with the basis itself ([`super::basis_file::read_basis`]), so that a command
//! opens its basis file once.

use super::estimator_file::{
    training_box_sensitivity, training_loads, training_measure, training_notes, training_range, training_sensitivity,
    training_tolerance, BoxSensitivity,
};
use super::timing_file::{read_timing, RouteTiming};
use crate::error::Result;
use crate::reduction::estimator::ErrorMeasure;
use crate::solver::parameter_space::ParameterSpace;
use crate::solver::parameters::{Parameters, LOAD_SCALE};
use std::path::Path;

/// Greedy training's whole-run sensitivity at its candidates, as the file stores it.
#[derive(Clone, Debug, PartialEq)]
pub enum StoredSensitivity {
    /// candidate load scales (increasing), one sensitivity each (`/training/candidates`)
    Loads { candidates: Vec<f64>, whole_run: Vec<f64> },
    /// candidate points of the box in its unit cube, one sensitivity each
    /// (`/training/candidate_points`)
    Box { unit: Vec<Vec<f64>>, whole_run: Vec<f64> },
}

/// The training record of a basis file, as the commands that run the basis read it
/// (`Default`: not read yet).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BasisTraining {
    /// `[min, max]` of the training load scales: the box's load-scale range when it has
    /// one, else `/training/range`, else the extremes of `/snapshot_load_scale`
    pub range: (f64, f64),
    /// the loads of the full runs whose snapshots the basis holds, sorted, each once
    pub loads: Vec<f64>,
    /// greedy training's tolerance; `None` for other training
    pub tolerance: Option<f64>,
    /// the error that tolerance is on (relative for other training)
    pub measure: ErrorMeasure,
    /// what greedy training said beside meeting its tolerance: (attribute, sentence)
    pub notes: Vec<(&'static str, String)>,
    /// the box of parameters the basis was trained over; empty: the load scale alone
    pub space: ParameterSpace,
    /// the points of the full runs in that box, in run order (`/parameters/<name>`); empty
    /// for a basis trained over the load scale alone
    pub points: Vec<Parameters>,
    /// columns of `/snapshots` (`None`: the file has none)
    pub snapshot_count: Option<usize>,
    /// greedy training's sensitivity at its candidates; `None` for other bases
    pub sensitivity: Option<StoredSensitivity>,
    /// `train`'s timing of the full and the reduced route; `None` for a file without it
    pub timing: Option<RouteTiming>,
}

/// Reads the training record of the open basis file `f` (at `path`, for messages); every
/// part that is there but malformed is an error naming its dataset or attribute.
pub fn read_training(f: &hdf5::File, path: &Path) -> Result<BasisTraining> {
    let space = super::parameter_space_file::parameter_space(f, path)?.unwrap_or_default();
    // a box that holds λ gives its range; else the training loads' [min, max]
    let range = match space.range(LOAD_SCALE) {
        Some(r) => (r.lower, r.upper),
        None => training_range(f, path)?,
    };
    let sensitivity = match training_sensitivity(f, path)? {
        Some((candidates, whole_run)) => Some(StoredSensitivity::Loads { candidates, whole_run }),
        None => training_box_sensitivity(f, path, &space)?
            .map(|(unit, whole_run): BoxSensitivity| StoredSensitivity::Box { unit, whole_run }),
    };
    Ok(BasisTraining {
        range,
        loads: training_loads(f, path)?,
        tolerance: training_tolerance(f, path)?,
        measure: training_measure(f, path)?,
        notes: training_notes(f, path)?,
        points: super::parameter_space_file::training_points(f, path, &space)?,
        space,
        snapshot_count: f.dataset("snapshots").ok().and_then(|d| d.shape().get(1).copied()),
        sensitivity,
        timing: read_timing(f, path)?,
    })
}
