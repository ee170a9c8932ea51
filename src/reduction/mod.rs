//! Model reduction by POD (SPEC §3), knowing nothing of beams: it sees the physics only
//! through [`crate::solver::model::ElementModel`].
//!
//! `pod` (modes and singular values) → `basis` (the reductor: `train_basis`, `reduce`,
//! `reconstruct`) → `reduced_model` (the projected [`crate::solver::model::DynamicModel`]).

pub mod basis;
pub mod pod;
pub(crate) mod projection;
pub mod reduced_model;

pub use basis::{train_basis, Basis, SnapshotKind, Trained, Variant};
pub use pod::{pod, ModeRule, Pod};
pub use reduced_model::ReducedModel;
