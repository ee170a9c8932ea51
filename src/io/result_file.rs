//! The result file of `simulate` and of reduced runs (`online`). Fixed layout (layout
//! [`super::attrs::LAYOUT_VERSION`]: time first), read by scripts outside the project:
//!
//! ```text
//! /t                      (n_t)          time, s
//! /q                      (n_t, n_dof)   row k = all coordinates at t_k (m, slopes 1)
//! /qd                     (n_t, n_dof)   their velocities q̇ (m/s, slopes 1/s; reduced: V ż)
//! /multipliers            (n_t, n_c)     Lagrange multipliers (N; N·m on clamp slope rows)
//! /probes/<name>          (n_t, 2)       x, y of each probe, m
//! /probe_strain/<name>    (n_t)          axial strain at the probes that record it, 1
//! /probe_curvature/<name> (n_t)          curvature at the probes that record it, 1/m
//!                                        (`online`: each of these probe datasets carries the
//!                                        attribute error_estimate, the estimate of its error
//!                                        over its range over the run, crate::rom::quantities)
//! /energy/<name>          (n_t)          energies, J: kinetic, strain, strain_axial,
//!                                        strain_bending, gravity, springs, external_work,
//!                                        drive_work
//!                                        (simulate, statics, online)
//! /reactions/force        (n_t, n_r, 2)  force each joint applies on the body at each of
//!                                        its nodes, x and y, N (models with joints)
//! /reactions/moment       (n_t, n_r)     its moment on the body, N m, counter-clockwise
//! /reduced/q              (n_t, r)       `online` only: the reduced coordinates
//! /labels/...                            names of the coordinates and constraint rows;
//!                                        labels/reaction and labels/reaction_joint name
//!                                        the reactions (crate::analysis::reactions)
//! every dataset: attributes units, dims (src/io/attrs.rs)
//! attributes on /: flexrom_layout, flexrom_file = "result", model (TOML text), model_path,
//!   load_scale, dt, t_end, rho_inf, linear_solver, newton_iterations, factorizations,
//!   step_cuts, steps, max_iterations_in_a_step, steps_at_round_off, wall_seconds,
//!   program_version
//! ```

use super::attrs::{annotate_rest, Kind, Labelled};
use super::h5::{attr_f64, attr_str, attr_u64, shorten, StagedFile};
use crate::analysis::reactions::{ReactionMap, Reactions};
use crate::error::{Error, Result};
use crate::linalg::kkt::LinearSolverKind;
use crate::simulate::{Settings, SimulationResult};
use std::path::Path;

/// What is known of a run before it runs: the sizes of its arrays (`n_t` instants, `n_dof`
/// coordinates, `n_c` multipliers, the probes by name, those recording strain and those
/// recording curvature) and the settings its file records.
#[derive(Clone, Debug, PartialEq)]
pub struct RunPlan {
    pub n_t: usize,
    pub n_dof: usize,
    pub n_c: usize,
    pub probes: Vec<String>,
    pub strains: Vec<String>,
    pub curvatures: Vec<String>,
    /// the run's parameters (the file records `λ` as its `load_scale` attribute)
    pub mu: crate::solver::parameters::Parameters,
    pub dt: f64,
    pub t_end: f64,
    pub rho_inf: f64,
    pub solver: LinearSolverKind,
}

impl RunPlan {
    /// The plan of a run of `model` with the settings `s` (one instant recorded per step
    /// and the start, whatever halving a step takes).
    pub fn of(model: &crate::model::Model, s: &Settings) -> RunPlan {
        let z = model.sizes();
        let series = model.section_names();
        Self::new(s.n_steps + 1, z.n_dof as usize, z.n_constraints as usize, model.probe_names(), series, s)
    }

    /// The plan a finished run `r` followed.
    pub fn of_result(r: &SimulationResult) -> RunPlan {
        let names = |v: &[(String, ndarray::Array1<f64>)]| v.iter().map(|p| p.0.clone()).collect();
        let series = [names(&r.strains), names(&r.curvatures)];
        let probes = r.probes.iter().map(|p| p.0.clone()).collect();
        Self::new(r.t.len(), r.q.nrows(), r.multipliers.nrows(), probes, series, &r.settings)
    }

    fn new(
        n_t: usize,
        n_dof: usize,
        n_c: usize,
        probes: Vec<String>,
        series: [Vec<String>; 2],
        s: &Settings,
    ) -> RunPlan {
        let [strains, curvatures] = series;
        RunPlan {
            n_t,
            n_dof,
            n_c,
            probes,
            strains,
            curvatures,
            mu: s.mu.clone(),
            dt: s.dt,
            t_end: s.t_end,
            rho_inf: s.rho_inf,
            solver: s.solver,
        }
    }
}

/// A result file in the making: its fixed part, which depends on the model and the
/// [`RunPlan`] alone, is written by [`ResultFile::begin`] (HDF5's start-up, the temporary
/// file, the model's text and the run's settings, the `/labels` of its coordinates and the
/// empty, labelled datasets of the run); [`ResultFile::finish`] fills in the run and moves
/// the file into place. Dropped unfinished, the temporary file is removed.
pub struct ResultFile {
    // the datasets before the file: closed first when dropped
    t: hdf5::Dataset,
    q: hdf5::Dataset,
    qd: hdf5::Dataset,
    multipliers: hdf5::Dataset,
    probes: Vec<hdf5::Dataset>,
    /// the strain series, then the curvature series
    sections: Vec<hdf5::Dataset>,
    /// the joints' reactions (force, moment) and the map from multipliers to them, where the
    /// model has joints
    reactions: Option<(hdf5::Dataset, hdf5::Dataset, ReactionMap)>,
    staged: StagedFile,
    labelled: Labelled,
    model_text: String,
    model_path: String,
    plan: RunPlan,
}

impl ResultFile {
    pub fn begin(path: &Path, model_text: &str, model_path: &str, plan: &RunPlan) -> Result<ResultFile> {
        let staged = StagedFile::create(path)?;
        let mut labelled = Labelled::new(Kind::Result);
        let f = staged.file();
        let e = |err: hdf5::Error| shorten(Error::hdf5(path, err));
        attr_str(f, "model", model_text).map_err(e)?;
        attr_str(f, "model_path", model_path).map_err(e)?;
        attr_str(f, "program_version", env!("CARGO_PKG_VERSION")).map_err(e)?;
        attr_f64(f, "load_scale", plan.mu.scale()).map_err(e)?;
        // the model's named parameters, where the run sets any: `parameter:NAME`
        for (name, value) in plan.mu.named() {
            attr_f64(f, &format!("parameter:{name}"), value).map_err(e)?;
        }
        attr_f64(f, "dt", plan.dt).map_err(e)?;
        attr_f64(f, "t_end", plan.t_end).map_err(e)?;
        attr_f64(f, "rho_inf", plan.rho_inf).map_err(e)?;
        attr_str(f, "linear_solver", &format!("{:?}", plan.solver).to_lowercase()).map_err(e)?;
        // the model parsed once for the labels and the reactions (it parsed when the run
        // started; a text that does not parse writes neither rather than failing the file)
        let model = crate::model::Model::from_text(model_text, model_path).ok();
        if let Some(m) = &model {
            super::labels::Labels::of(m).write_labelled(f, Some(&mut labelled)).map_err(e)?;
        }
        let map = model.as_ref().map(ReactionMap::of).filter(|m| !m.points.is_empty() && m.n_rows() == plan.n_c);
        // the run's datasets, empty and labelled (units, dims), time first
        let mut create = |g: &hdf5::Group, path: &str, name: &str, dims: &[usize]| {
            let d = g.new_dataset::<f64>().shape(dims).create(name)?;
            labelled.label(path, &d)?;
            Ok(d)
        };
        let t = create(f, "t", "t", &[plan.n_t]).map_err(e)?;
        let q = create(f, "q", "q", &[plan.n_t, plan.n_dof]).map_err(e)?;
        let qd = create(f, "qd", "qd", &[plan.n_t, plan.n_dof]).map_err(e)?;
        let multipliers = create(f, "multipliers", "multipliers", &[plan.n_t, plan.n_c]).map_err(e)?;
        let g = f.create_group("probes").map_err(e)?;
        let probes = plan
            .probes
            .iter()
            .map(|name| create(&g, &format!("probes/{name}"), name, &[plan.n_t, 2]))
            .collect::<hdf5::Result<Vec<_>>>()
            .map_err(e)?;
        // a group only where some probe records the quantity
        let mut sections = Vec::new();
        for (group, names) in [("probe_strain", &plan.strains), ("probe_curvature", &plan.curvatures)] {
            if names.is_empty() {
                continue;
            }
            let g = f.create_group(group).map_err(e)?;
            for name in names {
                sections.push(create(&g, &format!("{group}/{name}"), name, &[plan.n_t]).map_err(e)?);
            }
        }
        let reactions = match map {
            Some(map) => {
                let g = f.create_group("reactions").map_err(e)?;
                let force = create(&g, "reactions/force", "force", &[plan.n_t, map.points.len(), 2]).map_err(e)?;
                let moment = create(&g, "reactions/moment", "moment", &[plan.n_t, map.points.len()]).map_err(e)?;
                write_reaction_labels(f, &map, &mut labelled).map_err(e)?;
                Some((force, moment, map))
            }
            None => None,
        };
        Ok(ResultFile {
            t,
            q,
            qd,
            multipliers,
            probes,
            sections,
            reactions,
            staged,
            labelled,
            model_text: model_text.to_string(),
            model_path: model_path.to_string(),
            plan: plan.clone(),
        })
    }

    /// Writes the run `r`, then lets `extra` add datasets and attributes (reduced runs add
    /// `/reduced/q` ([`write_reduced`]) and the basis they used), labels the datasets left
    /// ([`super::attrs::annotate_rest`]), and commits the file (`fdatasync`, rename, folder
    /// `fsync`). A run of another model or plan than the file
    /// was begun with (a bug: the plan is made from the same model and settings) is not
    /// lost: the begun file is removed and the file written again from the run.
    pub fn finish(self, r: &SimulationResult, extra: impl FnOnce(&hdf5::File) -> Result<()>) -> Result<()> {
        if r.model_text != self.model_text || r.model_path != self.model_path || RunPlan::of_result(r) != self.plan {
            let path = self.staged.path().to_path_buf();
            drop(self);
            return ResultFile::begin(&path, &r.model_text, &r.model_path, &RunPlan::of_result(r))?.finish(r, extra);
        }
        // on an error `self` is dropped whole: datasets, then the file, then its temporary
        self.write_run(r, extra)?;
        let ResultFile { t, q, qd, multipliers, probes, sections, reactions, staged, .. } = self;
        drop((t, q, qd, multipliers, probes, sections, reactions));
        staged.commit()
    }

    fn write_run(&self, r: &SimulationResult, extra: impl FnOnce(&hdf5::File) -> Result<()>) -> Result<()> {
        let f = self.staged.file();
        let e = |err: hdf5::Error| shorten(Error::hdf5(self.staged.path(), err));
        self.t.write(&r.t).map_err(e)?;
        // time first: the solver's columns (one per instant) become rows
        fill_time_first(&self.q, &r.q).map_err(e)?;
        fill_time_first(&self.qd, &r.qd).map_err(e)?;
        fill_time_first(&self.multipliers, &r.multipliers).map_err(e)?;
        for (d, (_, xy)) in self.probes.iter().zip(&r.probes) {
            d.write(xy).map_err(e)?;
        }
        for (d, (_, v)) in self.sections.iter().zip(r.strains.iter().chain(&r.curvatures)) {
            d.write(v).map_err(e)?;
        }
        if let Some((force, moment, map)) = &self.reactions {
            let Reactions { force: f_values, moment: m_values } =
                map.series((&r.settings.mu, r.t.as_slice().expect("contiguous")), &r.q, &r.multipliers);
            force.write(&f_values).map_err(e)?;
            moment.write(&m_values).map_err(e)?;
        }
        attr_u64(f, "steps", r.stats.steps as u64).map_err(e)?;
        attr_u64(f, "newton_iterations", r.stats.newton_iterations as u64).map_err(e)?;
        attr_u64(f, "factorizations", r.stats.factorizations as u64).map_err(e)?;
        attr_u64(f, "step_cuts", r.stats.step_cuts as u64).map_err(e)?;
        attr_u64(f, "max_iterations_in_a_step", r.stats.max_iterations_in_a_step as u64).map_err(e)?;
        attr_u64(f, "steps_at_round_off", r.stats.steps_at_round_off as u64).map_err(e)?;
        attr_f64(f, "wall_seconds", r.wall_seconds).map_err(e)?;
        if let Some(energy) = &r.energy {
            write_energy(f, energy).map_err(e)?;
        }
        extra(f).map_err(shorten)?;
        annotate_rest(f, &self.labelled).map_err(e)
    }
}

/// Runs `run` on this thread while [`ResultFile::begin`] writes the result file's fixed
/// part on a second one, so that the run's wall time hides it (HDF5's start-up, the
/// labels and the datasets' creation are about 2 ms of a 12 ms pendulum `simulate`,
/// docs/process-speed.md). Both are waited for; the run's error comes first, and the begun
/// file is then removed. Where no thread can be started, the two run one after the other.
pub fn begin_alongside<T>(
    path: &Path,
    model_text: &str,
    model_path: &str,
    plan: &RunPlan,
    run: impl FnOnce() -> Result<T>,
) -> Result<(ResultFile, T)> {
    std::thread::scope(|s| {
        let begun = std::thread::Builder::new()
            .name("flexrom-result-file".into())
            .spawn_scoped(s, || ResultFile::begin(path, model_text, model_path, plan));
        let out = run();
        let file = begun.ok().map(|h| h.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)));
        let out = out?;
        let file = match file {
            Some(file) => file?,
            None => ResultFile::begin(path, model_text, model_path, plan)?,
        };
        Ok((file, out))
    })
}

/// Rows of the transposed copy written at a time: ≤ 8 MiB of it, whatever the run's size.
const BLOCK_BYTES: usize = 8 << 20;

/// Writes `a` (n × n_t: one column per instant, as the solver keeps it) as the dataset
/// `name` of shape (n_t, n), time first, transposing a block of instants at a time so that
/// a large run is not copied whole.
pub fn write_time_first(g: &hdf5::Group, name: &str, a: &ndarray::Array2<f64>) -> hdf5::Result<hdf5::Dataset> {
    let (n, nt) = a.dim();
    let d = g.new_dataset::<f64>().shape((nt, n)).create(name)?;
    fill_time_first(&d, a)?;
    Ok(d)
}

/// Fills the dataset `d` of shape (n_t, n) with `a` (n × n_t), time first: a column-major
/// `a` as it is, a row-major one transposed a block of instants at a time ([`BLOCK_BYTES`]).
fn fill_time_first(d: &hdf5::Dataset, a: &ndarray::Array2<f64>) -> hdf5::Result<()> {
    fill_in_blocks(d, a, (BLOCK_BYTES / (8 * a.nrows().max(1))).max(1))
}

fn fill_in_blocks(d: &hdf5::Dataset, a: &ndarray::Array2<f64>, rows: usize) -> hdf5::Result<()> {
    let (n, nt) = a.dim();
    if n == 0 || nt == 0 {
        return Ok(());
    }
    if a.t().is_standard_layout() {
        // column-major (as full runs keep it): the rows of the time-first dataset already
        return d.write(&a.t());
    }
    for start in (0..nt).step_by(rows) {
        let end = (start + rows).min(nt);
        let tr = transposed(a, start, end);
        d.write_slice(&tr, ndarray::s![start..end, ..])?;
    }
    Ok(())
}

/// Columns `start..end` of `a` as rows: `out[(k − start, i)] = a[(i, k)]`. Eight rows of `a`
/// at a time, each read in order, so every cache line read is used whole (ndarray's
/// `as_standard_layout` of the transposed view visits one element at a time through its
/// general iterator: half the time of writing `/q`).
fn transposed(a: &ndarray::Array2<f64>, start: usize, end: usize) -> ndarray::Array2<f64> {
    let (n, nt) = a.dim();
    let rows = end - start;
    let mut out = vec![0.0; rows * n];
    match a.as_slice() {
        Some(src) => {
            for i0 in (0..n).step_by(8) {
                let i1 = (i0 + 8).min(n);
                for (k, dst) in (start..end).zip(out.chunks_exact_mut(n)) {
                    for (i, d) in (i0..i1).zip(&mut dst[i0..i1]) {
                        *d = src[i * nt + k];
                    }
                }
            }
        }
        None => {
            for (k, dst) in (start..end).zip(out.chunks_exact_mut(n)) {
                for (i, d) in dst.iter_mut().enumerate() {
                    *d = a[(i, k)];
                }
            }
        }
    }
    ndarray::Array2::from_shape_vec((rows, n), out).expect("rows × n entries")
}

/// Writes `/labels/reaction` (each reaction's name) and `/labels/reaction_joint` (the
/// model file's `joints[j]` it belongs to).
fn write_reaction_labels(f: &hdf5::File, map: &ReactionMap, labelled: &mut Labelled) -> hdf5::Result<()> {
    let g = f.group("labels")?;
    let names = map
        .names()
        .into_iter()
        .map(|s| s.parse::<hdf5::types::VarLenUnicode>().map_err(|e| hdf5::Error::from(format!("label `{s}`: {e:?}"))))
        .collect::<hdf5::Result<Vec<_>>>()?;
    labelled.label("labels/reaction", &super::h5_text::write_strings(&g, "reaction", &names)?)?;
    let joints = ndarray::Array1::from_iter(map.points.iter().map(|p| p.joint as u64));
    labelled.label("labels/reaction_joint", &g.new_dataset_builder().with_data(&joints).create("reaction_joint")?)
}

/// Writes `/energy/<name>` (J, one value per instant) of a run's energies.
fn write_energy(f: &hdf5::File, energy: &crate::analysis::energy::Energies) -> hdf5::Result<()> {
    let g = f.create_group("energy")?;
    for (name, values) in energy.named() {
        g.new_dataset_builder().with_data(values).create(name)?;
    }
    Ok(())
}

/// Writes what a `statics` result file adds to a run's: the attributes `analysis =
/// "statics"`, `time` (of the loads, s) and `load_steps`, and `/load_factor` (the fraction
/// of the loads of each row).
pub fn write_statics(f: &hdf5::File, time: f64, load_steps: usize, load_factors: &[f64]) -> hdf5::Result<()> {
    attr_str(f, "analysis", "statics")?;
    attr_f64(f, "time", time)?;
    attr_u64(f, "load_steps", load_steps as u64)?;
    f.new_dataset_builder().with_data(load_factors).create("load_factor").map(|_| ())
}

/// Writes `/reduced/q`, time first, from the reduced coordinates `zq` (r × n_t, one column
/// per instant as the solver keeps them).
pub fn write_reduced(f: &hdf5::File, zq: &ndarray::Array2<f64>) -> hdf5::Result<()> {
    write_time_first(&f.create_group("reduced")?, "q", zq).map(|_| ())
}

#[cfg(test)]
mod tests {
    use crate::error::Error;

    fn entries(d: &std::path::Path) -> Vec<String> {
        let mut v: Vec<String> =
            std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    }

    /// The file begun beside a run that fails is removed, and the previous file is kept;
    /// beside a run that succeeds it holds the run once finished; finished with another
    /// model's run, or a run of another plan (sizes, settings), it is written again from
    /// the run, with no temporary file left.
    #[test]
    fn a_file_begun_beside_a_run_goes_with_a_failed_run() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("r.h5");
        std::fs::write(&out, b"previous").unwrap();
        let r = crate::simulate::SimulationResult {
            model_text: "other = 2".into(),
            model_path: "m.toml".into(),
            settings: crate::simulate::Settings::resolve(
                &crate::model::Model::from_text(
                    "[time]\nt_end = 0.1\ndt = 0.1\nrho_inf = 1.0\n[[bodies]]\nname = \"b\"\nstart = [0.0, 0.0]\nangle = 0.0\nlength = 1.0\nelements = 1\ndensity = 1.0\narea = 1.0\ninertia = 1.0\nyoungs_modulus = 1.0\n",
                    "m.toml",
                )
                .unwrap(),
                &Default::default(),
            )
            .unwrap(),
            t: ndarray::Array1::zeros(1),
            q: ndarray::Array2::from_shape_fn((8, 1), |(i, _)| i as f64),
            qd: ndarray::Array2::from_shape_fn((8, 1), |(i, _)| -(i as f64)),
            multipliers: ndarray::Array2::zeros((0, 1)),
            probes: vec![],
            strains: vec![],
            curvatures: vec![],
            stats: Default::default(),
            wall_seconds: 0.0,
            energy: None,
        };
        let plan = super::RunPlan::of_result(&r);
        assert_eq!((plan.n_t, plan.n_dof, plan.n_c, plan.dt), (1, 8, 0, 0.1));
        let failed = super::begin_alongside(&out, "text = 1", "m.toml", &plan, || -> crate::Result<()> {
            Err(Error::usage("the run failed"))
        });
        assert!(matches!(failed, Err(Error::Usage(m)) if m.to_string() == "the run failed"));
        assert_eq!(entries(dir.path()), ["r.h5"]);
        assert_eq!(std::fs::read(&out).unwrap(), b"previous");

        let (file, v) = super::begin_alongside(&out, "text = 1", "m.toml", &plan, || Ok(7)).unwrap();
        assert_eq!(v, 7);
        // a temporary file beside the target until finished
        assert_eq!(entries(dir.path()).len(), 2);
        let written = |file: super::ResultFile| {
            std::fs::write(&out, b"previous").unwrap();
            file.finish(&r, |_| Ok(())).unwrap();
            assert_eq!(entries(dir.path()), ["r.h5"]);
            let f = hdf5::File::open(&out).unwrap();
            assert_eq!(crate::io::h5::read_attr_str(&f, "model").unwrap(), "other = 2");
            assert_eq!(crate::io::h5::read_attr_f64(&f, "dt").unwrap(), 0.1);
            assert_eq!(f.dataset("q").unwrap().read_2d::<f64>().unwrap(), r.q.t());
            assert_eq!(f.dataset("qd").unwrap().read_2d::<f64>().unwrap(), r.qd.t());
        };
        // begun for another model: written again from the run
        written(file);
        // the right model, the wrong sizes or settings: the same
        for wrong in [super::RunPlan { n_t: 2, ..plan.clone() }, super::RunPlan { dt: 0.2, ..plan.clone() }] {
            let (file, ()) = super::begin_alongside(&out, "other = 2", "m.toml", &wrong, || Ok(())).unwrap();
            written(file);
        }
        let (file, ()) = super::begin_alongside(&out, "other = 2", "m.toml", &plan, || Ok(())).unwrap();
        written(file);
    }

    /// The plan made before a run, from the model file and the settings alone, is the plan
    /// of the run (else `finish` writes the file twice): every shipped model, and one with a
    /// clamp (4 rows), a pin and a ground pin and a probe, over three steps, also with its
    /// probe recording strain and curvature.
    #[test]
    fn the_plan_of_a_model_is_that_of_its_run() {
        let clamped = crate::io::labels::tests::CLAMPED;
        let sectioned = clamped.replace("node = 1\n", "node = 1\nquantities = [\"strain\", \"curvature\"]\n");
        assert_ne!(sectioned, clamped);
        let mut models = vec![
            crate::model::Model::from_text(clamped, "clamped.toml").unwrap(),
            crate::model::Model::from_text(&sectioned, "sectioned.toml").unwrap(),
        ];
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models");
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|x| x == "toml") && !path.to_string_lossy().contains("5000") {
                models.push(crate::model::Model::load(&path).unwrap());
            }
        }
        assert!(models.len() >= 5, "the shipped models were found");
        for model in &models {
            let overrides = crate::simulate::Overrides {
                t_end: Some(3.0 * model.file.time.dt),
                mu: Some(crate::solver::parameters::Parameters::load_scale(1.1)),
                ..Default::default()
            };
            let s = crate::simulate::Settings::resolve(model, &overrides).unwrap();
            let r = crate::simulate::simulate(model, &overrides).unwrap();
            assert_eq!(super::RunPlan::of(model, &s), super::RunPlan::of_result(&r), "{}", model.path.display());
        }
    }

    /// Blocks of 3 instants (the last one short) and one block give the transpose, from a
    /// row-major matrix and from a column-major one.
    #[test]
    fn time_first_blocks_give_the_transpose() {
        let dir = tempfile::tempdir().unwrap();
        let f = hdf5::File::create(dir.path().join("t.h5")).unwrap();
        let a = ndarray::Array2::from_shape_fn((4, 10), |(i, k)| (10 * i + k) as f64);
        let blocks = |name: &str, a: &ndarray::Array2<f64>| {
            let d = f.new_dataset::<f64>().shape((a.ncols(), a.nrows())).create(name).unwrap();
            super::fill_in_blocks(&d, a, 3).unwrap();
        };
        blocks("blocks", &a);
        super::write_time_first(&f, "whole", &a).unwrap();
        // a matrix in column-major order takes the other branch of the transposition
        let fortran = a.t().as_standard_layout().into_owned().reversed_axes();
        assert_eq!(fortran, a);
        assert!(fortran.as_slice().is_none());
        blocks("fortran", &fortran);
        for name in ["blocks", "whole", "fortran"] {
            assert_eq!(f.dataset(name).unwrap().read_2d::<f64>().unwrap(), a.t(), "{name}");
        }
    }
}
