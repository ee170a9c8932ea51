//! What every file flexrom writes says about itself: the layout version on `/`
//! ([`LAYOUT_ATTR`] = [`LAYOUT_VERSION`], [`KIND_ATTR`]), and on every dataset its `units`
//! (SI; `1` for dimensionless numbers, counts and indices; `none (text)` for text) and its
//! `dims` (axis names, comma-separated, first axis first; `""` for a scalar).
//!
//! Layout 2 (this one): every time series is time-first, `(n_t, …)` (a sweep's
//! `(n_loads, n_t, …)`); snapshot and mode matrices keep the POD convention, one column per
//! snapshot or mode (`dims = "dof, snapshot"`, `"dof, mode"`). Layout 1 (files without the
//! attribute, flexrom ≤ 0.1) stored `/q`, `/multipliers`, `/reduced/q` as
//! `(n, n_t)` and a sweep's `/reduced_q` as `(n_loads, r, n_t)`; readers convert them
//! ([`layout_version`]). A file of a newer layout is refused ([`check_layout`]).
//!
//! The units of each dataset live in one table per file kind ([`units_of`]); the writers
//! call [`annotate`] (through [`write_atomically_as`]) after filling a file, which labels
//! every dataset it finds from the table (a writer may label some as it creates them,
//! [`Labelled`]: the same attributes, without opening the datasets again). docs/file-formats.md shows the same tables
//! (a test checks every row of them against this one).

use super::h5::{attr_str, attr_u64, write_atomically};
use crate::error::{Error, Result};
use std::path::Path;

/// Root attribute holding the layout version.
pub const LAYOUT_ATTR: &str = "flexrom_layout";
/// The layout this program writes and reads.
pub const LAYOUT_VERSION: u64 = 2;
/// Root attribute naming the kind of file ([`Kind::name`]).
pub const KIND_ATTR: &str = "flexrom_file";

/// Coordinates `q`: node `k` owns `(x, y, x', y')`, positions in m, slopes dimensionless.
pub const COORDINATE_UNITS: &str = "m (positions x, y), 1 (slopes x', y')";
/// Velocities `q̇`: of positions in m/s, of slopes in 1/s.
pub const VELOCITY_UNITS: &str = "m/s (positions x, y), 1/s (slopes x', y')";
/// Lagrange multipliers: forces on position rows, moments (N·m, conjugate to a
/// dimensionless slope) on the slope rows (clamps, welds, driven angles, locked sliders).
pub const MULTIPLIER_UNITS: &str = "N (position rows), N·m (slope rows: clamps, welds, driven angles, locked sliders)";
/// Reduced coordinates `z = Vᵀ(q − x_ref)` with orthonormal, dimensionless modes: each mixes
/// the units of `q` in proportion to the mode's entries.
pub const REDUCED_UNITS: &str = "m (positions) and 1 (slopes), mixed by the modes: z = Vᵀ(q − x_ref)";
/// Singular values of a snapshot matrix with rows in m and in 1.
pub const SINGULAR_VALUE_UNITS: &str = "m (positions) and 1 (slopes), mixed: singular values of /snapshots";
/// Constraint residuals: position rows in m, slope rows dimensionless.
pub const VIOLATION_UNITS: &str = "m (position rows), 1 (slope rows: clamps, welds, driven angles, locked sliders)";
/// Text datasets.
pub const TEXT: &str = "none (text)";

/// The kinds of file flexrom writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `simulate`, `online`
    Result,
    /// `train` (with the estimator and greedy's `/training`)
    Basis,
    /// `sweep`, `run`'s sweep.h5, shard parts, `merge`
    Sweep,
    /// `train --snapshots-only`
    Snapshots,
    /// `modes -o`
    Modes,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Result => "result",
            Kind::Basis => "basis",
            Kind::Sweep => "sweep",
            Kind::Snapshots => "snapshots",
            Kind::Modes => "modes",
        }
    }
}

/// (path, units, dims) of one dataset; `*` stands for one name (a probe's).
pub type Entry = (&'static str, &'static str, &'static str);

/// `/labels/*`, in result, basis and snapshot files (src/io/labels.rs).
pub const LABELS: [Entry; 7] = [
    ("labels/body", TEXT, "body"),
    ("labels/dof", TEXT, "dof"),
    ("labels/dof_body", "1", "dof"),
    ("labels/dof_node", "1", "dof"),
    ("labels/dof_coordinate", "1", "dof"),
    ("labels/multiplier", TEXT, "constraint"),
    ("labels/multiplier_joint", "1", "constraint"),
];

/// Mode shapes normalized to unit modal mass, `φᵀMφ = 1 kg·(m or 1)²`.
pub const MODE_SHAPE_UNITS: &str = "m/√kg (positions x, y), 1/√kg (slopes x', y')";

const MODES: [Entry; 8] = [
    ("frequencies", "Hz", "mode"),
    ("omega_squared", "1/s²", "mode"),
    ("rigid", "1", "mode"),
    ("shapes", MODE_SHAPE_UNITS, "mode, dof"),
    ("q", COORDINATE_UNITS, "dof"),
    ("paraview/lines", "1", "segment, end"),
    ("paraview/points", "m", "point, xyz"),
    ("paraview/shapes/*", "m/√kg", "point, xyz"),
];

const RESULT: [Entry; 19] = [
    ("t", "s", "time"),
    ("q", COORDINATE_UNITS, "time, dof"),
    ("qd", VELOCITY_UNITS, "time, dof"),
    ("multipliers", MULTIPLIER_UNITS, "time, constraint"),
    ("probes/*", "m", "time, xy"),
    ("probe_strain/*", "1", "time"),
    ("probe_curvature/*", "1/m", "time"),
    ("energy/*", "J", "time"),
    ("load_factor", "1", "time"),
    ("reduced/q", REDUCED_UNITS, "time, mode"),
    ("paraview/lines", "1", "segment, end"),
    ("paraview/points/*", "m", "point, xyz"),
    ("paraview/velocity/*", "m/s", "point, xyz"),
    ("paraview/strain/*", "1", "point"),
    ("paraview/curvature/*", "1/m", "point"),
    ("reactions/force", "N", "time, reaction, xy"),
    ("reactions/moment", "N·m", "time, reaction"),
    ("labels/reaction", TEXT, "reaction"),
    ("labels/reaction_joint", "1", "reaction"),
];

const BASIS: [Entry; 57] = [
    ("snapshots", COORDINATE_UNITS, "dof, snapshot"),
    ("snapshot_multipliers", MULTIPLIER_UNITS, "constraint, snapshot"),
    ("snapshot_load_scale", "1", "snapshot"),
    ("snapshot_t", "s", "snapshot"),
    ("basis/modes", "1", "dof, mode"),
    ("basis/singular_values", SINGULAR_VALUE_UNITS, "singular value"),
    ("basis/energy", "1", "singular value"),
    ("basis/block_modes", "1", "block"),
    ("basis/output_modes", "1", "block"),
    ("basis/block_values", "1", "block"),
    ("basis/reference", COORDINATE_UNITS, "dof"),
    ("basis/reduced_dofs", "1", "entry"),
    ("basis/kept_dofs", "1", "entry"),
    ("basis/multiplier_modes", "1", "constraint, mode"),
    ("hyper/elements", "1", "sample"),
    ("hyper/weights", "1", "sample"),
    ("estimator/modes", "1", "dof, mode"),
    ("estimator/block_modes", "1", "block"),
    ("estimator/multiplier_modes", "1", "constraint, mode"),
    ("estimator/hyper/elements", "1", "sample"),
    ("estimator/hyper/weights", "1", "sample"),
    ("estimator/calibration/load_scale", "1", "pair"),
    ("estimator/calibration/raw_estimate", "1", "pair"),
    ("estimator/calibration/rel_error", "1", "pair"),
    ("estimator/calibration/quantity_factor", "1", "quantity"),
    ("estimator/defects/load_scale", "1", "load"),
    ("estimator/defects/ratio", "1", "load, fifth"),
    ("estimator/defects/factor", "1", "fifth"),
    ("estimator/defects/unit_point", "1", "candidate, parameter"),
    ("estimator/defects/quantity_ratio", "1", "load, quantity"),
    ("parameters/*", "1", "run"),
    ("training/range", "1", "bound"),
    ("training/tolerance", "1", ""),
    ("training/load_scales", "1", "run"),
    ("training/candidates", "1", "candidate"),
    ("training/candidate_points", "1", "candidate, parameter"),
    ("training/points", "1", "run, parameter"),
    ("training/worst_point", "1", "iteration, parameter"),
    ("training/run_point", "1", "iteration, parameter"),
    ("training/worst_estimate", "1", "iteration"),
    ("training/worst_load", "1", "iteration"),
    ("training/run_load", "1", "iteration"),
    ("training/true_error", "1", "iteration"),
    ("training/energy_tolerance", "1", "iteration"),
    ("training/hyper_tolerance", "1", "iteration"),
    ("training/n_modes", "1", "iteration"),
    ("training/n_elements", "1", "iteration"),
    ("training/estimates", "1", "iteration, candidate"),
    ("training/whole_run_estimates", "1", "iteration, candidate"),
    ("training/sensitivity", "1", "iteration, candidate"),
    ("training/true_score", "1", "iteration"),
    ("training/bound", "1", "iteration"),
    ("training/between_points", "1", "iteration"),
    ("training/held_out_effectivity", "1", "iteration"),
    ("timing/full_seconds", "s", ""),
    ("timing/reduced_seconds", "s", ""),
    ("timing/estimate_seconds", "s", ""),
];

const SWEEP: [Entry; 40] = [
    ("load_scales", "1", "load"),
    ("points", "1", "load, parameter"),
    ("status", "1", "load"),
    ("message", TEXT, "load"),
    ("t", "s", "time"),
    ("probes/*", "m", "load, time, xy"),
    ("full_probes/*", "m", "load, time, xy"),
    ("probe_strain/*", "1", "load, time"),
    ("probe_curvature/*", "1/m", "load, time"),
    // each probe quantity's error over its range: estimated, and measured with --validate
    ("probe_error_estimate/position/*", "1", "load"),
    ("probe_error_estimate/strain/*", "1", "load"),
    ("probe_error_estimate/curvature/*", "1", "load"),
    ("reaction_error_estimate/force/*", "1", "load"),
    ("reaction_error_estimate/moment/*", "1", "load"),
    ("probe_error/position/*", "1", "load"),
    ("probe_error/strain/*", "1", "load"),
    ("probe_error/curvature/*", "1", "load"),
    ("reduced_q", REDUCED_UNITS, "load, time, mode"),
    ("rom_seconds", "s", "load"),
    ("newton_iterations", "1", "load"),
    ("factorizations", "1", "load"),
    ("error_estimate", "1", "load"),
    // the estimate per fifth of the run
    ("error_estimate_by_time", "1", "load, fifth"),
    ("error_estimate_displacement", "1", "load"),
    ("error_estimate_displacement_by_time", "1", "load, fifth"),
    ("estimate_seconds", "s", "load"),
    ("extrapolated", "1", "load"),
    // 1 where the full model answered in place of the reduced one
    ("fallback", "1", "load"),
    ("sensitivity_near", "1", "load"),
    ("rel_error", "1", "load"),
    ("max_probe_error", "m", "load"),
    ("max_constraint_violation", VIOLATION_UNITS, "load"),
    ("full_seconds", "s", "load"),
    ("speedup", "1", "load"),
    ("steps_differ_from", "s", "load"),
    ("displacement_error", "1", "load"),
    ("rel_error_by_time", "1", "load, fifth"),
    ("shard/all_load_scales", "1", "all loads"),
    ("shard/all_points", "1", "all loads, parameter"),
    ("shard/indices", "1", "load"),
];

const SNAPSHOTS: [Entry; 6] = [
    ("x", COORDINATE_UNITS, "dof, snapshot"),
    ("multipliers", MULTIPLIER_UNITS, "constraint, snapshot"),
    ("load_scale", "1", "snapshot"),
    ("t", "s", "snapshot"),
    ("point_index", "1", "run"),
    ("points", "1", "run, parameter"),
];

/// The table of a file kind (without `/labels`).
pub fn table(kind: Kind) -> &'static [Entry] {
    match kind {
        Kind::Result => &RESULT,
        Kind::Basis => &BASIS,
        Kind::Sweep => &SWEEP,
        Kind::Snapshots => &SNAPSHOTS,
        Kind::Modes => &MODES,
    }
}

/// `(units, dims)` of the dataset at `path` (no leading `/`) in a file of `kind`.
pub fn units_of(kind: Kind, path: &str) -> Option<(&'static str, &'static str)> {
    let labels: &[Entry] = if kind == Kind::Sweep { &[] } else { &LABELS };
    let matches = |pattern: &str| match pattern.strip_suffix('*') {
        Some(prefix) => path.strip_prefix(prefix).is_some_and(|rest| !rest.is_empty() && !rest.contains('/')),
        None => pattern == path,
    };
    table(kind).iter().chain(labels).find(|e| matches(e.0)).map(|e| (e.1, e.2))
}

/// Writes `units` (and `dims`) on a dataset, replacing neither: a writer that set its own
/// keeps them.
pub fn write_units(d: &hdf5::Dataset, units: &str, dims: &str) -> hdf5::Result<()> {
    if !d.attr_names()?.iter().any(|a| a == "units") {
        attr_str(d, "units", units)?;
    }
    if !d.attr_names()?.iter().any(|a| a == "dims") {
        attr_str(d, "dims", dims)?;
    }
    Ok(())
}

/// The datasets a writer labelled itself as it created them ([`Labelled::label`]), which
/// [`annotate`] then passes by without opening them: opening every dataset of a result
/// file again, to find the same attributes missing, was a fifth of the time of writing it
/// (docs/process-speed.md).
#[derive(Debug)]
pub struct Labelled {
    kind: Kind,
    /// paths (no leading `/`) of the datasets labelled so far
    done: Vec<String>,
}

impl Labelled {
    pub fn new(kind: Kind) -> Labelled {
        Labelled { kind, done: Vec::new() }
    }

    /// Writes `units` and `dims` from the table of the file's kind on the dataset `d` just
    /// created at `path` (no leading `/`), as [`annotate`] would, and records it as done.
    /// A path missing from the table gets nothing, and is not recorded (annotate passes it
    /// by all the same).
    pub fn label(&mut self, path: &str, d: &hdf5::Dataset) -> hdf5::Result<()> {
        if let Some((units, dims)) = units_of(self.kind, path) {
            attr_str(d, "units", units)?;
            attr_str(d, "dims", dims)?;
            self.done.push(path.to_string());
        }
        Ok(())
    }
}

/// Labels a freshly written file: [`LAYOUT_ATTR`] and [`KIND_ATTR`] on `/`, `units` and
/// `dims` on every dataset found in the table of `kind`. A dataset missing from the table
/// keeps no `units` (tests/file_layout.rs fails on it: add it to the table and the docs).
pub fn annotate(f: &hdf5::File, kind: Kind) -> hdf5::Result<()> {
    annotate_rest(f, &Labelled::new(kind))
}

/// [`annotate`], passing by the datasets in `labelled` (their writer labelled them).
pub fn annotate_rest(f: &hdf5::File, labelled: &Labelled) -> hdf5::Result<()> {
    fn walk(g: &hdf5::Group, prefix: &str, labelled: &Labelled) -> hdf5::Result<()> {
        for name in g.member_names()? {
            let full = if prefix.is_empty() { name.clone() } else { format!("{prefix}/{name}") };
            if labelled.done.contains(&full) {
                continue;
            }
            // asked, not tried: a failed `group()` on a dataset builds a whole HDF5 error stack
            match g.loc_type_by_name(&name) {
                Ok(hdf5::LocationType::Group) => walk(&g.group(&name)?, &full, labelled)?,
                Ok(hdf5::LocationType::Dataset) => {
                    if let Some((units, dims)) = units_of(labelled.kind, &full) {
                        write_units(&g.dataset(&name)?, units, dims)?;
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }
    walk(f, "", labelled)?;
    if !f.attr_names()?.iter().any(|a| a == LAYOUT_ATTR) {
        attr_u64(f, LAYOUT_ATTR, LAYOUT_VERSION)?;
        attr_str(f, KIND_ATTR, labelled.kind.name())?;
    }
    Ok(())
}

/// [`write_atomically`], then [`annotate`] as `kind`, in the same atomic write.
pub fn write_atomically_as(path: &Path, kind: Kind, fill: impl FnOnce(&hdf5::File) -> Result<()>) -> Result<()> {
    write_atomically_labelled(path, kind, |f, _| fill(f))
}

/// [`write_atomically_as`] for a writer that labels datasets as it creates them
/// ([`Labelled::label`]); [`annotate_rest`] labels the others.
pub fn write_atomically_labelled(
    path: &Path,
    kind: Kind,
    fill: impl FnOnce(&hdf5::File, &mut Labelled) -> Result<()>,
) -> Result<()> {
    write_atomically(path, |f| {
        let mut labelled = Labelled::new(kind);
        fill(f, &mut labelled)?;
        annotate_rest(f, &labelled).map_err(|e| Error::hdf5(path, e))
    })
}

/// The layout version of an open file: [`LAYOUT_ATTR`], or 1 when the file has none (files
/// written before layouts had a version).
pub fn layout_version(f: &hdf5::File) -> Result<u64> {
    match f.attr(LAYOUT_ATTR) {
        Err(_) => Ok(1),
        Ok(a) => a
            .read_scalar::<u64>()
            .map_err(|e| Error::hdf5(f.filename(), format!("cannot be read as a whole number: {e}"))),
    }
}

/// The layout version of the file at `path`, refused when it is newer than this program's
/// (or unreadable) with a message naming the file, both versions and what to do; `stage` is
/// the command that writes such a file (`flexrom train`, …).
pub fn check_layout(f: &hdf5::File, path: &Path, stage: &str) -> Result<u64> {
    let v = layout_version(f).map_err(|p| Error::input(path, LAYOUT_ATTR, p.problem()))?;
    if v > LAYOUT_VERSION {
        return Err(Error::input(
            path,
            LAYOUT_ATTR,
            format!(
                "is {v}, a newer file layout than this flexrom ({}) reads (layout {LAYOUT_VERSION} and older): \
                 use the newer flexrom that wrote it, or re-run `{stage}` with this one",
                env!("CARGO_PKG_VERSION")
            ),
        ));
    }
    if v == 0 {
        return Err(Error::input(
            path,
            LAYOUT_ATTR,
            format!("is 0, not a layout version (1 to {LAYOUT_VERSION}); re-run `{stage}`"),
        ));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probe_patterns_match_one_name_only() {
        assert_eq!(units_of(Kind::Result, "probes/tip").map(|u| u.0), Some("m"));
        assert_eq!(units_of(Kind::Result, "probes/"), None);
        assert_eq!(units_of(Kind::Result, "probes/a/b"), None);
        assert_eq!(units_of(Kind::Sweep, "probes/tip").map(|u| u.1), Some("load, time, xy"));
        assert_eq!(units_of(Kind::Sweep, "labels/dof"), None);
        assert_eq!(units_of(Kind::Basis, "labels/dof").map(|u| u.0), Some(TEXT));
    }
}
