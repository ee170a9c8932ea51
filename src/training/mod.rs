//! Training, the offline stage: full runs of a pipeline's training points, their snapshots,
//! the POD basis (and ECSW sample, error estimator) built from them, and the greedy loop that
//! chooses the points; `train` writes the basis file.

pub mod basis_build;
pub mod greedy;
pub mod snapshots;
pub mod train;
pub mod training_record;
