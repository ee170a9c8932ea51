//! The results of the commands as [`Table`]s, for `--csv` and `--json` (one row per load
//! scale, per time step or per run; units in the column names' documentation below and in
//! docs/cli.md).

use crate::output::table::{Cell, Table};
use crate::simulate::SimulationResult;
use crate::workflows::sweep::Sweep;

/// `sweep`, `merge`: one row per load scale, in the order asked for. `status` is 0 (done),
/// 1 (failed, `message` says why) or 2 (not run yet), as `/status` of the sweep file;
/// times in seconds, errors relative (`rel_error`, `error_estimate`; `displacement_error`,
/// `error_estimate_displacement` relative to the motion) or in metres (`max_probe_error`).
/// The validation columns are there only for `--validate` sweeps; a full sweep (`--full`)
/// has `full_seconds` (its time loops) and no estimate columns.
pub fn sweep_table(s: &Sweep) -> Table {
    if s.full {
        return full_sweep_table(s);
    }
    let mut cols = vec![
        "load_scale",
        "status",
        "message",
        "rom_seconds",
        "newton_iterations",
        "step_cuts",
        "error_estimate",
        "estimate_seconds",
        "extrapolated",
    ];
    if s.validated {
        cols.extend(["rel_error", "max_probe_error", "full_seconds", "speedup", "steps_differ_from"]);
    }
    // the columns added with the displacement measure go last: the others keep their places
    cols.push("error_estimate_displacement");
    if s.validated {
        cols.push("displacement_error");
    }
    // `/fallback`: 1 where the full model answered in place of the reduced one (`--fallback
    // full`), 2 where it was tried and failed too, 0 elsewhere
    cols.push("fallback");
    let base = cols.len();
    let named = named_columns(s);
    cols.extend(named.iter().map(|(c, _)| c.as_str()));
    let mut t = Table::new(&cols);
    for x in &s.scales {
        let mut row: Vec<Cell> = vec![x.mu.scale().into(), (x.status() as u64).into(), x.message().into()];
        match x.point() {
            Some(p) => {
                let r = &p.run.result;
                row.extend([
                    r.wall_seconds.into(),
                    r.stats.newton_iterations.into(),
                    r.stats.step_cuts.into(),
                    p.estimate.as_ref().map(|e| e.error_estimate).into(),
                    p.estimate.as_ref().map(|e| e.seconds).into(),
                    p.extrapolated.into(),
                ]);
                if s.validated {
                    let v = p.validation.as_ref();
                    row.extend([
                        v.map(|v| v.rel_error).into(),
                        v.map(|v| v.max_probe_error).into(),
                        v.map(|v| v.full_seconds).into(),
                        v.map(|v| v.speedup).into(),
                        v.and_then(|v| v.steps_differ_from).into(),
                    ]);
                }
                row.push(p.estimate.as_ref().map(|e| e.error_estimate_displacement).into());
                if s.validated {
                    row.push(p.validation.as_ref().map(|v| v.displacement_error).into());
                }
                row.push((p.fallback_code() as u64).into());
            }
            None => row.resize(base, Cell::Null),
        }
        row.extend(named.iter().map(|(_, n)| x.mu.get(n).unwrap_or(1.0).into()));
        t.push(row);
    }
    t
}

/// The columns `parameter:NAME` of the named parameters the sweep's points set (none for a
/// line of load scales), appended after the others so that those keep their places.
fn named_columns(s: &Sweep) -> Vec<(String, String)> {
    let names = crate::workflows::sweep::point_names(s.scales.iter().map(|x| &x.mu));
    names.into_iter().skip(1).map(|n| (format!("parameter:{n}"), n)).collect()
}

/// [`sweep_table`] of a full sweep: `load_scale`, `status`, `message`, `full_seconds`,
/// `newton_iterations`, `step_cuts`.
fn full_sweep_table(s: &Sweep) -> Table {
    let mut cols = vec!["load_scale", "status", "message", "full_seconds", "newton_iterations", "step_cuts"];
    let base = cols.len();
    let named = named_columns(s);
    cols.extend(named.iter().map(|(c, _)| c.as_str()));
    let mut t = Table::new(&cols);
    for x in &s.scales {
        let mut row: Vec<Cell> = vec![x.mu.scale().into(), (x.status() as u64).into(), x.message().into()];
        match x.point() {
            Some(p) => {
                let r = &p.run.result;
                row.extend([r.wall_seconds.into(), r.stats.newton_iterations.into(), r.stats.step_cuts.into()]);
            }
            None => row.resize(base, Cell::Null),
        }
        row.extend(named.iter().map(|(_, n)| x.mu.get(n).unwrap_or(1.0).into()));
        t.push(row);
    }
    t
}

/// `simulate --csv/--json`: one row per instant, `t` (s) and every probe's `NAME_x`,
/// `NAME_y` (m), then `NAME_strain` (1) and `NAME_curvature` (1/m) of the probes that
/// record them, then a full run's energies `energy_kinetic`, `energy_strain`,
/// `energy_strain_axial`, `energy_strain_bending`, `energy_gravity`, `energy_springs`,
/// `energy_external_work`, `energy_drive_work` (J).
pub fn probe_table(r: &SimulationResult) -> Table {
    let mut cols = vec!["t".to_string()];
    for (n, _) in &r.probes {
        cols.push(format!("{n}_x"));
        cols.push(format!("{n}_y"));
    }
    cols.extend(r.strains.iter().map(|(n, _)| format!("{n}_strain")));
    cols.extend(r.curvatures.iter().map(|(n, _)| format!("{n}_curvature")));
    // the energies of a full run (J), as its result file's /energy/<name>
    let energy: Vec<(&str, &ndarray::Array1<f64>)> = r.energy.as_ref().map_or(Vec::new(), |e| e.named().to_vec());
    cols.extend(energy.iter().map(|(n, _)| format!("energy_{n}")));
    let mut t = Table { columns: cols, rows: Vec::new() };
    for k in 0..r.t.len() {
        let mut row = vec![Cell::from(r.t[k])];
        for (_, xy) in &r.probes {
            row.push(xy[[k, 0]].into());
            row.push(xy[[k, 1]].into());
        }
        row.extend(r.strains.iter().chain(&r.curvatures).map(|(_, v)| Cell::from(v[k])));
        row.extend(energy.iter().map(|(_, v)| Cell::from(v[k])));
        t.push(row);
    }
    t
}

/// The time series of a run, one row per instant: [`probe_table`] with the joints'
/// reactions ([`add_reactions`]) where the run has them. What `simulate --csv/--json` and
/// `online --csv` print, so that a full and a reduced run read alike (a reduced run has no
/// energy columns: they are a full run's).
pub fn series_table(model: &crate::model::Model, r: &SimulationResult) -> Table {
    let mut table = probe_table(r);
    add_reactions(&mut table, model, r);
    table
}

/// Appends to a run's `table` ([`probe_table`], one row per instant) the reactions of
/// `model`'s joints ([`crate::analysis::reactions`]): for each joint and node it acts on,
/// `<name>: Fx` and `<name>: Fy` (N, the force on the body) and `<name>: M` (N m,
/// counter-clockwise), `<name>` as `/labels/reaction` of the result file.
pub fn add_reactions(table: &mut Table, model: &crate::model::Model, r: &SimulationResult) {
    let map = crate::analysis::reactions::ReactionMap::of(model);
    if map.n_rows() != r.multipliers.nrows() {
        return;
    }
    let v = map.series((&r.settings.mu, r.t.as_slice().expect("contiguous")), &r.q, &r.multipliers);
    for name in map.names() {
        table.columns.extend(["Fx", "Fy", "M"].map(|c| format!("{name}: {c}")));
    }
    for (k, row) in table.rows.iter_mut().enumerate() {
        for p in 0..map.points.len() {
            row.extend([v.force[(k, p, 0)], v.force[(k, p, 1)], v.moment[(k, p)]].map(Cell::from));
        }
    }
}

/// One run's statistics as cells: `steps`, `seconds` (time loop), `newton_iterations`,
/// `factorizations`, `step_cuts`, with the names [`RUN_COLUMNS`].
pub fn run_cells(r: &SimulationResult) -> Vec<Cell> {
    vec![
        r.stats.steps.into(),
        r.wall_seconds.into(),
        r.stats.newton_iterations.into(),
        r.stats.factorizations.into(),
        r.stats.step_cuts.into(),
    ]
}

/// The column names of [`run_cells`].
pub const RUN_COLUMNS: [&str; 5] = ["steps", "seconds", "newton_iterations", "factorizations", "step_cuts"];
