//! The offline/online workflow on top of the full solver and the reduction:
//! pipeline file → `train` (full runs, snapshots, POD basis in HDF5) → `online` (reduced
//! runs) → `validate` (error norms, timings) → `sweep` (many load scales) → `run` (all of
//! it, with a report).

pub mod animate;
pub mod basis_build;
pub mod config;
pub mod dense;
pub mod drawing;
pub mod greedy;
pub mod map;
pub mod merge;
pub mod model_figure;
pub mod motion;
pub mod online;
pub mod plot;
pub mod points;
pub mod report;
pub mod report_maps;
pub mod route;
pub mod shard;
pub mod snapshots;
pub mod sweep;
pub mod tables;
pub mod timing;
pub mod train;
pub mod training_record;
pub mod validate;

pub use config::Pipeline;
