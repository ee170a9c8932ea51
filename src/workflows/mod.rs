//! The online workflows on a trained basis: `online` (one reduced run), `sweep` (many points,
//! in parallel), `validate` (reduced against full runs), `points` (the points a command
//! runs), `shard` and `merge` (a sweep split over machines and put back together).

pub mod merge;
pub mod online;
pub mod points;
pub mod shard;
pub mod sweep;
pub mod validate;
