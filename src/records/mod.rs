//! What the workflows record, and the HDF5 files that keep it: a sweep's outcome
//! (`sweep_outcome`: one point's status, runs and validation), its file (`sweep_file`:
//! layout, writing, reading for `--resume`, `merge` and the report) and one run read back out
//! of it with its basis (`sweep_run`); what a validation found (`validation`), which a
//! validated sweep keeps point by point.

pub mod sweep_file;
pub mod sweep_outcome;
pub mod sweep_run;
pub mod validation;
