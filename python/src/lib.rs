//! The native module of the Python package `flexrom` (`flexrom._flexrom`): thin wrappers
//! over the library's model, run, basis, sweep, training and validation, numpy arrays in
//! and out. Every array is a copy in the files' layout (time first); the Python side
//! (`python/flexrom/__init__.py`) re-exports these names and adds nothing computational.
//!
//! Long work runs on a thread of its own without the GIL while the calling thread waits in
//! slices of [`SIGNAL_POLL`], taking the GIL between them only to let Python run its signal
//! handlers: a Ctrl-C there sets [`flexrom::interrupt`], every run stops at its next time
//! step, the temporary files it had begun are dropped, and `KeyboardInterrupt` is raised.

mod convert;
mod errors;
mod pickle;

use convert::{dict_of_series, parameters, time_first, warn};
use errors::{to_py, FlexromWarning};
use flexrom::io::attrs::Kind;
use flexrom::io::labels::Labels;
use flexrom::io::output::{check_output, Origin};
use flexrom::io::result_file::{ResultFile, RunPlan};
use flexrom::model::{Model, Runs};
use flexrom::pipeline::Pipeline;
use flexrom::rom::estimator::{Estimate, EstimateMethod};
use flexrom::rom::{Rom, Trust};
use flexrom::simulate::{Overrides, SimulationResult};
use flexrom::solver::parameters::Parameters;
use flexrom::workflows::online::{load_rom, pipeline_of_basis};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

/// How often the waiting thread lets Python look at its signals (Ctrl-C is answered within
/// this and one time step).
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Runs `work` on a thread of its own without the GIL, answering Ctrl-C (see the module).
fn interruptible<T: Send>(py: Python<'_>, work: impl FnOnce() -> flexrom::Result<T> + Send) -> PyResult<T> {
    interruptible_with(py, None, work)
}

/// One computing call at a time in the process: the stop request ([`flexrom::interrupt`])
/// and the progress count ([`flexrom::output::ticker::latest`]) are the process's, so two
/// Python threads calling flexrom take turns (each call still uses every core inside).
static BUSY: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// The turn of one call ([`BUSY`] held until dropped).
struct Turn;

thread_local! {
    /// This thread holds the turn (a progress callback calling flexrom again would wait for
    /// itself).
    static HOLDS_TURN: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

impl Turn {
    /// Waits, without the GIL, until no other call computes.
    fn take(py: Python<'_>) -> PyResult<Turn> {
        use std::sync::atomic::Ordering;
        if HOLDS_TURN.get() {
            return Err(pyo3::exceptions::PyRuntimeError::new_err(
                "flexrom cannot be called from inside a progress callback of flexrom",
            ));
        }
        while BUSY.compare_exchange(false, true, Ordering::Acquire, Ordering::Relaxed).is_err() {
            py.detach(|| std::thread::sleep(Duration::from_millis(5)));
        }
        HOLDS_TURN.set(true);
        Ok(Turn)
    }
}

impl Drop for Turn {
    fn drop(&mut self) {
        HOLDS_TURN.set(false);
        BUSY.store(false, std::sync::atomic::Ordering::Release);
    }
}

/// The worker's stack: the command line's main thread has 8 MiB.
const WORKER_STACK: usize = 8 << 20;

/// [`interruptible`], calling `progress(label, done, total)` on the calling thread whenever
/// the library's count of finished items ([`flexrom::output::ticker::latest`]) moved (looked
/// at every [`SIGNAL_POLL`]). An exception in the callback stops the work as Ctrl-C does
/// and is raised.
fn interruptible_with<T: Send>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce() -> flexrom::Result<T> + Send,
) -> PyResult<T> {
    let _turn = Turn::take(py)?;
    flexrom::interrupt::clear();
    flexrom::output::ticker::forget();
    // `logging` configured since the last call applies to this one
    if let Some(h) = LOG_RESET.get() {
        h.reset();
    }
    let mut shown: Option<flexrom::output::ticker::Progress> = None;
    let mut tell = || -> PyResult<()> {
        let Some(cb) = progress else { return Ok(()) };
        let now = flexrom::output::ticker::latest();
        if now != shown {
            if let Some(p) = &now {
                cb.call1((p.label.as_str(), p.done, p.total))?;
            }
            shown = now;
        }
        Ok(())
    };
    let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
    let mut stopped: Option<PyErr> = None;
    let joined = std::thread::scope(|s| {
        let worker = std::thread::Builder::new()
            .name("flexrom-work".into())
            .stack_size(WORKER_STACK)
            .spawn_scoped(s, move || {
                let out = work();
                let _ = done_tx.send(());
                out
            })
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
        let mut done_rx = done_rx;
        loop {
            // the receiver travels into the GIL-free closure and back (it is Send, not Sync)
            let (rx, waited) = py.detach(move || {
                let waited = done_rx.recv_timeout(SIGNAL_POLL);
                (done_rx, waited)
            });
            done_rx = rx;
            // done, or the worker ended without sending (a panic)
            if !matches!(waited, Err(std::sync::mpsc::RecvTimeoutError::Timeout)) {
                break;
            }
            if stopped.is_none() {
                if let Err(e) = py.check_signals().and_then(|_| tell()) {
                    flexrom::interrupt::request();
                    stopped = Some(e);
                }
            }
        }
        PyResult::Ok(worker.join())
    });
    flexrom::interrupt::clear();
    let out = match joined? {
        Ok(out) => out,
        Err(_) => return Err(pyo3::exceptions::PyRuntimeError::new_err("flexrom: the computation panicked")),
    };
    if let Some(e) = stopped {
        return Err(e);
    }
    let out = out.map_err(to_py)?;
    // the last count (the work may end between two looks)
    tell()?;
    Ok(out)
}

/// Resets pyo3-log's cache of Python loggers and levels.
static LOG_RESET: std::sync::OnceLock<pyo3_log::ResetHandle> = std::sync::OnceLock::new();

/// The progress callback a call's `progress` argument asks for: None or False, none; True,
/// a text bar on stderr (`flexrom._support.TextBar`); a callable, itself.
fn progress_callback<'py>(py: Python<'py>, progress: Option<Bound<'py, PyAny>>) -> PyResult<Option<Bound<'py, PyAny>>> {
    let Some(p) = progress else { return Ok(None) };
    if p.is_none() {
        return Ok(None);
    }
    if let Ok(on) = p.extract::<bool>() {
        return if on { Ok(Some(py.import("flexrom._support")?.getattr("TextBar")?.call0()?)) } else { Ok(None) };
    }
    if !p.is_callable() {
        return Err(errors::model_error("progress: give True, False, None or a callable(label, done, total)"));
    }
    Ok(Some(p))
}

/// A model file: the system of bodies, joints and loads, run by [`PyModel::simulate`].
#[pyclass(name = "Model", module = "flexrom._flexrom", frozen)]
struct PyModel {
    model: Arc<Model>,
}

#[pymethods]
impl PyModel {
    /// Reads and checks the model file at `path` (TOML, docs/model-format.md).
    #[staticmethod]
    fn from_file(path: PathBuf) -> PyResult<Self> {
        Ok(PyModel { model: Arc::new(Model::load(&path).map_err(to_py)?) })
    }

    /// A model from the text of a model file; `path` names it in messages and results.
    #[staticmethod]
    #[pyo3(signature = (text, path = None))]
    fn from_toml(text: &str, path: Option<PathBuf>) -> PyResult<Self> {
        let path = path.unwrap_or_else(|| PathBuf::from("<string>"));
        Ok(PyModel { model: Arc::new(Model::from_text(text, &path).map_err(to_py)?) })
    }

    /// A model from a dict of the model file's tables and keys (as `tomllib.load` gives
    /// them); written out as TOML, so messages quote that text's lines.
    #[staticmethod]
    #[pyo3(signature = (model, path = None))]
    fn from_dict(py: Python<'_>, model: &Bound<'_, PyDict>, path: Option<PathBuf>) -> PyResult<Self> {
        // numpy numbers and arrays as plain ones
        let kw = PyDict::new(py);
        kw.set_item("default", py.import("flexrom._support")?.getattr("plain")?)?;
        kw.set_item("allow_nan", false)?;
        let json: String = py
            .import("json")?
            .call_method("dumps", (model,), Some(&kw))
            .map_err(|e| {
                errors::model_error(&format!(
                    "model dict: {e} (a value NaN or infinite has no TOML form a model file accepts)"
                ))
            })?
            .extract()?;
        let value: serde_json::Value =
            serde_json::from_str(&json).map_err(|e| errors::model_error(&format!("model dict: {e}")))?;
        let text = toml::to_string(&value)
            .map_err(|e| errors::model_error(&format!("model dict: cannot be written as TOML: {e}")))?;
        let path = path.unwrap_or_else(|| PathBuf::from("<dict>"));
        // the text is flexrom's own rendering of the dict: its lines mean nothing to the caller
        let model = Model::from_text(&text, &path).map_err(|e| to_py(without_lines(e)))?;
        Ok(PyModel { model: Arc::new(model) })
    }

    #[getter]
    fn path(&self) -> String {
        self.model.path.display().to_string()
    }

    /// The model file's text.
    #[getter]
    fn text(&self) -> String {
        self.model.text.clone()
    }

    /// The named parameters (`scaled = "NAME"` loads, `{ value, parameter }` properties).
    #[getter]
    fn parameter_names(&self) -> Vec<String> {
        self.model.parameter_names().into_iter().map(String::from).collect()
    }

    #[getter]
    fn n_dof(&self) -> usize {
        self.model.sizes().n_dof as usize
    }

    #[getter]
    fn n_constraints(&self) -> usize {
        self.model.sizes().n_constraints as usize
    }

    #[getter]
    fn probe_names(&self) -> Vec<String> {
        self.model.probe_names()
    }

    /// One full run (`flexrom simulate`): the load scale and named parameters, and the time
    /// settings over the model file's.
    #[pyo3(signature = (load_scale = None, *, dt = None, t_end = None, rho_inf = None, **params))]
    fn simulate(
        &self,
        py: Python<'_>,
        load_scale: Option<f64>,
        dt: Option<f64>,
        t_end: Option<f64>,
        rho_inf: Option<f64>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<PyRunResult> {
        let params = convert::named(params)?;
        let model = &self.model;
        // as `simulate --load-scale X`: no parameters at all leaves the model file's
        let mu = match (&params, load_scale) {
            (Some(p), _) if !p.is_empty() => Some(parameters(load_scale, p)?),
            (_, Some(x)) => Some(parameters(Some(x), &HashMap::new())?),
            _ => None,
        };
        let shown = mu.clone().unwrap_or_default();
        warn(py, &model.admit(std::slice::from_ref(&shown), Runs::Full).map_err(to_py)?)?;
        let overrides = Overrides { dt, t_end, rho_inf, mu, ..Default::default() };
        let r = interruptible(py, || {
            // with its energies, as `simulate`'s result file (to_hdf5 writes that layout)
            flexrom::simulate::simulate(model, &overrides)
                .and_then(|r| flexrom::simulate::with_energies(model, r))
                .map_err(|e| e.at_stage("simulate", &shown))
        })?;
        Ok(PyRunResult {
            model: Arc::clone(model),
            r,
            reduced: None,
            fallback: None,
            fallback_failed: None,
            exact: None,
            statics: None,
        })
    }

    /// The static equilibrium under the loads (`flexrom statics`): load stepping in `steps`
    /// equal steps (each halved where Newton fails), the loads at `time`; a Result with one
    /// instant per load step, the equilibrium last (`load_factor` says each row's fraction).
    #[pyo3(signature = (load_scale = None, *, time = 0.0, steps = 1, **params))]
    fn statics(
        &self,
        py: Python<'_>,
        load_scale: Option<f64>,
        time: f64,
        steps: usize,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<PyRunResult> {
        let params = convert::named(params)?.unwrap_or_default();
        let mu = parameters(load_scale, &params)?;
        let model = &self.model;
        warn(py, &model.admit(std::slice::from_ref(&mu), Runs::Full).map_err(to_py)?)?;
        let o = flexrom::analysis::statics::StaticOptions { mu: mu.clone(), t: time, steps, ..Default::default() };
        let (r, solution) =
            interruptible(py, || flexrom::simulate::statics(model, &o).map_err(|e| e.at_stage("statics", &mu)))?;
        let load_factors = solution.steps.iter().map(|s| s.load_factor).collect();
        Ok(PyRunResult {
            model: Arc::clone(model),
            r,
            reduced: None,
            fallback: None,
            fallback_failed: None,
            exact: None,
            statics: Some(StaticsPart { time, steps, load_factors }),
        })
    }

    /// The lowest `count` natural frequencies and mode shapes (`flexrom modes`), linearized
    /// at the initial configuration (`at="initial"`) or the static equilibrium
    /// (`at="static"`, the loads at `time`).
    #[pyo3(signature = (count = 6, *, at = "initial", load_scale = None, time = 0.0, **params))]
    fn modes(
        &self,
        py: Python<'_>,
        count: usize,
        at: &str,
        load_scale: Option<f64>,
        time: f64,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<PyModes> {
        use flexrom::simulate::ModesAt;
        let at = match at {
            "initial" => ModesAt::Initial,
            "static" => ModesAt::Static,
            other => return Err(errors::model_error(&format!("at: give \"initial\" or \"static\", got {other:?}"))),
        };
        let params = convert::named(params)?.unwrap_or_default();
        let mu = parameters(load_scale, &params)?;
        let model = &self.model;
        warn(py, &model.admit(std::slice::from_ref(&mu), Runs::Full).map_err(to_py)?)?;
        let o = flexrom::simulate::ModesOptions { count, at, mu, time, solver: Default::default() };
        let a = interruptible(py, || flexrom::simulate::modes(model, &o))?;
        Ok(PyModes { model: Arc::clone(model), a, at, time })
    }

    fn __repr__(&self) -> String {
        let z = self.model.sizes();
        format!("Model('{}': {} coordinates, {} constraints)", self.model.path.display(), z.n_dof, z.n_constraints)
    }
}

/// What a static equilibrium adds to its result: what `statics` writes beside it.
#[derive(Clone, serde::Serialize, serde::Deserialize)]
struct StaticsPart {
    /// the time of the loads, s
    time: f64,
    /// the load steps asked for
    steps: usize,
    /// the fraction of the loads of each row
    load_factors: Vec<f64>,
}

/// What a reduced run adds to its result: what `online` writes beside the run.
#[derive(Clone, serde::Serialize, serde::Deserialize)]
struct ReducedPart {
    /// r × n_t
    reduced_q: ndarray::Array2<f64>,
    basis_name: String,
    /// the basis file and the pipeline file it was checked against (none: the one the
    /// basis stores), which a result must never be written over
    basis_path: PathBuf,
    pipeline_path: Option<PathBuf>,
    variant: String,
    n_modes: usize,
    estimate: Option<Estimate>,
    method: Option<String>,
    trust: Trust,
    #[serde(with = "pickle::parameters")]
    mu: Parameters,
    extrapolated: bool,
}

/// A run's result, full (`Model.simulate`) or reduced (`Basis.online`), in the layout of a
/// result file: time first.
/// An error about a model given as a dict, with the key path its field names and no
/// `(line N)` of the TOML text flexrom wrote the dict as: `bodies[0].length (line 20)` reads
/// `bodies[0].length`; a bare `line N` reads `(dict)`.
fn without_lines(e: flexrom::Error) -> flexrom::Error {
    match e {
        flexrom::Error::Input { file, field, problem } => {
            let field = match field.rsplit_once(" (line ") {
                Some((key, rest)) if rest.ends_with(')') => key.to_string(),
                _ if field.starts_with("line ") => "(dict)".to_string(),
                _ => field,
            };
            flexrom::Error::Input { file, field, problem }
        }
        flexrom::Error::Hinted { source, hint } => {
            flexrom::Error::Hinted { source: Box::new(without_lines(*source)), hint }
        }
        other => other,
    }
}

#[pyclass(name = "Result", module = "flexrom._flexrom", frozen)]
struct PyRunResult {
    model: Arc<Model>,
    r: SimulationResult,
    reduced: Option<ReducedPart>,
    /// why the full model answered in place of the reduced one (`online(fallback="full")`)
    fallback: Option<String>,
    /// why the full model was tried in place of this reduced answer and how it failed
    fallback_failed: Option<String>,
    /// where the full model answered in place of the reduced one: the estimate of an exact
    /// answer (0) and whether the load lies outside the basis's range
    exact: Option<(Estimate, bool)>,
    /// a static equilibrium's load steps (`Model.statics`)
    statics: Option<StaticsPart>,
}

#[pymethods]
impl PyRunResult {
    /// (n_t) time, s
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.r.t.clone().into_pyarray(py)
    }

    /// (n_t, n_dof) the coordinates at every instant (m, slopes 1)
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        time_first(py, &self.r.q)
    }

    /// (n_t, n_dof) their velocities
    #[getter]
    fn qd<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        time_first(py, &self.r.qd)
    }

    /// (n_t, n_c) the Lagrange multipliers (N; N·m on clamp slope rows)
    #[getter]
    fn multipliers<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        time_first(py, &self.r.multipliers)
    }

    /// probe name → (n_t, 2) its x, y, m
    #[getter]
    fn probes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (name, xy) in &self.r.probes {
            d.set_item(name, xy.clone().into_pyarray(py))?;
        }
        Ok(d)
    }

    /// probe name → (n_t) axial strain, for the probes that record it
    #[getter]
    fn strains<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        dict_of_series(py, &self.r.strains)
    }

    /// probe name → (n_t) curvature, 1/m, for the probes that record it
    #[getter]
    fn curvatures<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        dict_of_series(py, &self.r.curvatures)
    }

    /// name → (n_t) energy, J, as a result file's `/energy/<name>`: `kinetic`, `strain`
    /// (`strain_axial` + `strain_bending`), `gravity`, `springs`, `external_work`,
    /// `drive_work`, and `total` = kinetic + strain + gravity + springs − external_work −
    /// drive_work (constant without damping; its drift measures the integrator's); None for a
    /// run without them (a reduced run's are over its sampled elements)
    #[getter]
    fn energies<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(e) = &self.r.energy else { return Ok(None) };
        let d = PyDict::new(py);
        for (name, series) in e.named() {
            d.set_item(name, series.clone().into_pyarray(py))?;
        }
        d.set_item("total", e.total().into_pyarray(py))?;
        Ok(Some(d))
    }

    /// names of the coordinates (`dof`), constraint rows (`multiplier`) and bodies, as a
    /// result file's `/labels`
    #[getter]
    fn labels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let l = Labels::of(&self.model);
        let d = PyDict::new(py);
        d.set_item("dof", l.dof_names())?;
        d.set_item("multiplier", l.multipliers.iter().map(|(_, s)| s.clone()).collect::<Vec<_>>())?;
        d.set_item("body", l.bodies.clone())?;
        let reactions = flexrom::analysis::reactions::ReactionMap::of(&self.model);
        d.set_item("reaction", reactions.names())?;
        Ok(d)
    }

    /// reaction name (as `labels["reaction"]`) → (n_t, 3): the force the joint applies on
    /// the body at the node, Fx and Fy (N), and its moment M (N·m, counter-clockwise), as
    /// the result file's `/reactions`
    #[getter]
    fn reactions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let map = flexrom::analysis::reactions::ReactionMap::of(&self.model);
        let d = PyDict::new(py);
        if map.n_rows() != self.r.multipliers.nrows() {
            return Ok(d);
        }
        let v =
            map.series((&self.r.settings.mu, self.r.t.as_slice().expect("contiguous")), &self.r.q, &self.r.multipliers);
        for (p, name) in map.names().into_iter().enumerate() {
            let mut a = ndarray::Array2::zeros((self.r.t.len(), 3));
            a.column_mut(0).assign(&v.force.slice(ndarray::s![.., p, 0]));
            a.column_mut(1).assign(&v.force.slice(ndarray::s![.., p, 1]));
            a.column_mut(2).assign(&v.moment.column(p));
            d.set_item(name, a.into_pyarray(py))?;
        }
        Ok(d)
    }

    /// (n_t) the fraction of the loads of each row of a static equilibrium (`Model.statics`;
    /// None for a run)
    #[getter]
    fn load_factor<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.statics.as_ref().map(|s| s.load_factors.clone().into_pyarray(py))
    }

    /// body name → (n_t, n_nodes, 2): each node's x, y, m, time first (the deformed shape:
    /// `plt.plot(*nodes["crank"][k].T)` draws the crank at instant k)
    #[getter]
    fn nodes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let n_t = self.r.t.len();
        let mut row = 0;
        for body in self.model.bodies() {
            let n_nodes = body.n_elements + 1;
            let mut xy = ndarray::Array3::zeros((n_t, n_nodes, 2));
            for k in 0..n_nodes {
                for c in 0..2 {
                    xy.slice_mut(ndarray::s![.., k, c]).assign(&self.r.q.row(row + 4 * k + c));
                }
            }
            row += 4 * n_nodes;
            d.set_item(&body.name, xy.into_pyarray(py))?;
        }
        Ok(d)
    }

    /// dataset → unit, as the result file's `units` attributes
    #[getter]
    fn units<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        use flexrom::io::attrs::{units_of, Kind};
        let d = PyDict::new(py);
        for name in [
            "t",
            "q",
            "qd",
            "multipliers",
            "probes/*",
            "probe_strain/*",
            "probe_curvature/*",
            "reduced/q",
            "reactions/force",
            "reactions/moment",
            "load_factor",
        ] {
            let probe = name.replace('*', "p");
            if let Some((units, _)) = units_of(Kind::Result, &probe) {
                d.set_item(name.trim_end_matches("/*"), units)?;
            }
        }
        Ok(d)
    }

    /// the model file the run is of (as the result file's `model_path`)
    #[getter]
    fn model_path(&self) -> String {
        self.r.model_path.clone()
    }

    /// the basis file of a reduced run (None for a full run)
    #[getter]
    fn basis_path(&self) -> Option<String> {
        self.reduced.as_ref().map(|x| x.basis_name.clone())
    }

    /// the load scale λ of the run
    #[getter]
    fn load_scale(&self) -> f64 {
        self.r.settings.parameters().scale()
    }

    /// the named parameters the run set
    #[getter]
    fn parameters(&self) -> HashMap<String, f64> {
        self.r.settings.parameters().named().map(|(k, v)| (k.to_string(), v)).collect()
    }

    /// the integrator's statistics and the time loop's wall time
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.r.stats;
        let d = PyDict::new(py);
        d.set_item("steps", s.steps)?;
        d.set_item("newton_iterations", s.newton_iterations)?;
        d.set_item("factorizations", s.factorizations)?;
        d.set_item("step_cuts", s.step_cuts)?;
        d.set_item("wall_seconds", self.r.wall_seconds)?;
        Ok(d)
    }

    /// whether this is a reduced run
    #[getter]
    fn reduced(&self) -> bool {
        self.reduced.is_some()
    }

    /// why the full model answered in place of the reduced one (`Basis.online(…,
    /// fallback="full")`), else None
    #[getter]
    fn fallback(&self) -> Option<String> {
        self.fallback.clone()
    }

    /// why the full model was tried in place of this reduced answer and how it failed,
    /// else None
    #[getter]
    fn fallback_failed(&self) -> Option<String> {
        self.fallback_failed.clone()
    }

    /// (n_t, r) the reduced coordinates (reduced runs; None for a full run)
    #[getter]
    fn reduced_q<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f64>>> {
        self.reduced.as_ref().map(|x| time_first(py, &x.reduced_q))
    }

    /// the estimate of the run's relative error against the full model (None: a full run,
    /// or no estimator; 0 where the full model answered in place of the reduced one)
    #[getter]
    fn error_estimate(&self) -> Option<f64> {
        self.estimate().map(|e| e.error_estimate)
    }

    /// (5) the estimate over the instants up to the end of each fifth of the run
    #[getter]
    fn error_estimate_by_time<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.estimate().map(|e| e.by_time.to_vec().into_pyarray(py))
    }

    /// the estimate of the error relative to the displacement X − X₀
    #[getter]
    fn error_estimate_displacement(&self) -> Option<f64> {
        self.estimate().map(|e| e.error_estimate_displacement)
    }

    /// probe name → {quantity → the estimate of its error over its range over the run}
    /// (quantities `position`, `strain`, `curvature`; docs/error-estimate.md); None: a
    /// full run, or no estimator
    #[getter]
    fn quantity_error_estimates<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(e) = self.estimate() else { return Ok(None) };
        let d = PyDict::new(py);
        for q in e.quantities.iter().filter(|q| !q.quantity.is_reaction()) {
            convert::inner_dict(&d, &q.probe)?.set_item(q.quantity.name(), q.estimate)?;
        }
        Ok(Some(d))
    }

    /// reaction point (as `reactions()` names them) → {`force`, `moment` → the estimate of
    /// its error over its range over the run} (docs/error-estimate.md); None: a full run, or
    /// no estimator; empty where the reduced run has no physical multipliers
    #[getter]
    fn reaction_error_estimates<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(e) = self.estimate() else { return Ok(None) };
        let d = PyDict::new(py);
        for q in e.quantities.iter().filter(|q| q.quantity.is_reaction()) {
            convert::inner_dict(&d, &q.probe)?.set_item(q.quantity.name(), q.estimate)?;
        }
        Ok(Some(d))
    }

    /// why the estimator's own run failed, when it did (`error_estimate` is then inf)
    #[getter]
    fn estimate_failure(&self) -> Option<String> {
        self.estimate().and_then(|e| e.failure.clone())
    }

    /// the estimate's method (`corrected`, `enriched`, `defects`, …)
    #[getter]
    fn estimate_method(&self) -> Option<String> {
        self.reduced.as_ref().and_then(|x| x.method.clone())
    }

    /// whether the run's parameters left those the basis was trained over (False for a
    /// full run of `Model.simulate`)
    #[getter]
    fn extrapolated(&self) -> bool {
        self.reduced.as_ref().is_some_and(|x| x.extrapolated) || self.exact.as_ref().is_some_and(|(_, x)| *x)
    }

    /// the reduced coordinates r (None for a full run)
    #[getter]
    fn n_modes(&self) -> Option<usize> {
        self.reduced.as_ref().map(|x| x.n_modes)
    }

    /// Writes the result file `flexrom simulate -o` (full) or `flexrom online -o` (reduced)
    /// writes, to a temporary file renamed into place; refuses a path that is an input of
    /// the run, not a regular file, or an existing file that is not a result flexrom wrote.
    fn to_hdf5(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let mut inputs: Vec<(&Path, &str)> = vec![(&self.model.path, "model file")];
        if let Some(x) = &self.reduced {
            inputs.push((&x.basis_path, "basis file"));
            if let Some(p) = &x.pipeline_path {
                inputs.push((p, "pipeline file"));
            }
        }
        check_output(&path, Origin::Flag("path"), &inputs, &[Kind::Result]).map_err(to_py)?;
        py.detach(|| self.write(&path)).map_err(to_py)
    }

    /// Draws the run's motion as an animated GIF at `path` (as `flexrom animate` does:
    /// docs/cli.md): the result is written to a temporary file beside `path`, animated, and
    /// removed. `path` must end in .gif; an existing file is replaced only when flexrom
    /// wrote it.
    #[pyo3(signature = (path, fps = 20.0, size = None, max_frames = 200))]
    fn animate(
        &self,
        py: Python<'_>,
        path: PathBuf,
        fps: f64,
        size: Option<(u32, u32)>,
        max_frames: usize,
    ) -> PyResult<()> {
        use flexrom::report::animate::{animate, check_own_gif, AnimateOptions};
        check_own_gif(&path, "path", &[(&self.model.path, "model file")]).map_err(to_py)?;
        let defaults = AnimateOptions::default();
        let size = size.map_or(defaults.size, |(w, h)| (w, Some(h)));
        let opts = AnimateOptions { fps, size, max_frames: max_frames.max(2) };
        py.detach(|| {
            let tmp = flexrom::io::atomic::TempPath::file_for(&path.with_extension("h5"))?;
            self.write(tmp.path())?;
            animate(tmp.path(), None, &path, &opts, &self.model.limits).map(|_| ())
        })
        .map_err(to_py)
    }

    /// Pickled as one versioned payload of everything it holds (python/src/pickle.rs):
    /// unpickling gives a Result equal in every array bit and attribute, in any process of
    /// the same flexrom version (joblib, multiprocessing), without the files it came from.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let bytes = pickle::to_bytes(self).map_err(pyo3::exceptions::PyValueError::new_err)?;
        let unpickle = py.import("flexrom._flexrom")?.getattr("_result_from_pickle")?;
        Ok((unpickle, (PyBytes::new(py, &bytes),)))
    }

    fn __repr__(&self) -> String {
        if self.statics.is_some() {
            return format!(
                "Result(static equilibrium at {}: {} load steps, {} coordinates)",
                self.r.settings.parameters(),
                self.r.t.len(),
                self.r.q.nrows()
            );
        }
        let kind = if self.reduced.is_some() { "reduced" } else { "full" };
        format!(
            "Result({kind} run at {}: {} instants, {} coordinates)",
            self.r.settings.parameters(),
            self.r.t.len(),
            self.r.q.nrows()
        )
    }
}

impl PyRunResult {
    /// The run's estimate: a reduced run's, or the exact one (0) of the full model's answer
    /// in place of the reduced one.
    fn estimate(&self) -> Option<&Estimate> {
        self.reduced.as_ref().and_then(|x| x.estimate.as_ref()).or(self.exact.as_ref().map(|(e, _)| e))
    }

    fn write(&self, path: &Path) -> flexrom::Result<()> {
        let r = &self.r;
        let file = ResultFile::begin(path, &r.model_text, &r.model_path, &RunPlan::of_result(r))?;
        file.finish(r, |f| {
            let e = |err: hdf5_error::Error| flexrom::Error::hdf5(path, err);
            if let Some(why) = &self.fallback {
                flexrom::io::h5::attr_str(f, "fallback", why).map_err(e)?;
            }
            if let Some((exact, extrapolated)) = &self.exact {
                flexrom::io::h5::attr_f64(f, "error_estimate", exact.error_estimate).map_err(e)?;
                flexrom::io::h5::attr_u64(f, "extrapolated", *extrapolated as u64).map_err(e)?;
            }
            if let Some(note) = &self.fallback_failed {
                flexrom::io::h5::attr_str(f, "fallback_failed", note).map_err(e)?;
            }
            if let Some(st) = &self.statics {
                flexrom::io::result_file::write_statics(f, st.time, st.steps, &st.load_factors).map_err(e)?;
            }
            let Some(x) = &self.reduced else { return Ok(()) };
            flexrom::io::result_file::write_reduced(f, &x.reduced_q).map_err(e)?;
            flexrom::io::h5::attr_str(f, "basis", &x.basis_name).map_err(e)?;
            flexrom::io::h5::attr_str(f, "variant", &x.variant).map_err(e)?;
            flexrom::io::h5::attr_u64(f, "n_modes", x.n_modes as u64).map_err(e)?;
            flexrom::rom::trust::write_run_attributes(
                f,
                x.estimate.as_ref(),
                x.method.as_deref(),
                &x.trust,
                &x.mu,
                x.extrapolated,
            )
            .map_err(e)
        })
    }
}

/// The lowest natural frequencies and mode shapes of a model (`Model.modes`), as the modes
/// file of `flexrom modes -o`.
#[pyclass(name = "Modes", module = "flexrom._flexrom", frozen)]
struct PyModes {
    model: Arc<Model>,
    a: flexrom::simulate::ModesAnalysis,
    at: flexrom::simulate::ModesAt,
    time: f64,
}

#[pymethods]
impl PyModes {
    /// (N) the frequencies, Hz, ascending (0 for a rigid-body mode)
    #[getter]
    fn frequencies<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.a.modes.frequencies.clone().into_pyarray(py)
    }

    /// (N) ω², 1/s²: the eigenvalues of K_T φ = ω² M φ with B φ = 0
    #[getter]
    fn omega_squared<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.a.modes.omega_squared.clone().into_pyarray(py)
    }

    /// (N) whether each mode is a rigid-body motion
    #[getter]
    fn rigid(&self) -> Vec<bool> {
        self.a.modes.rigid.clone()
    }

    /// (N, n_dof) row i = mode i laid out like q, φᵀMφ = 1
    #[getter]
    fn shapes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.a.modes.shapes.clone().into_pyarray(py)
    }

    /// (n_dof) the configuration the model was linearized at
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.a.q.clone().into_pyarray(py)
    }

    /// "initial" or "static"
    #[getter]
    fn at(&self) -> &'static str {
        self.at.name()
    }

    /// names of the coordinates (`dof`, the columns of `shapes`) and bodies
    #[getter]
    fn labels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let l = Labels::of(&self.model);
        let d = PyDict::new(py);
        d.set_item("dof", l.dof_names())?;
        d.set_item("body", l.bodies.clone())?;
        Ok(d)
    }

    /// subspace iterations taken
    #[getter]
    fn iterations(&self) -> usize {
        self.a.modes.iterations
    }

    /// Writes the modes file `flexrom modes -o` writes (atomically); refuses the model file's
    /// path and an existing file that is not a modes file flexrom wrote.
    fn to_hdf5(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        check_output(&path, Origin::Flag("path"), &[(&self.model.path, "model file")], &[Kind::Modes])
            .map_err(to_py)?;
        let record = flexrom::io::modes_file::ModesRecord {
            model: &self.model,
            modes: &self.a.modes,
            q: &self.a.q,
            at: self.at.name(),
            mu: &self.a.mu,
            time: self.time,
        };
        py.detach(|| flexrom::io::modes_file::write(&path, &record)).map_err(to_py)
    }

    fn __len__(&self) -> usize {
        self.a.modes.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Modes({} modes at the {} configuration: {:?} Hz)",
            self.a.modes.len(),
            self.at.name(),
            self.a.modes.frequencies
        )
    }
}

/// The hdf5 crate's error type, as the library's result files use it.
mod hdf5_error {
    pub use hdf5::Error;
}

/// A trained basis and its reduced model, ready to run at new loads.
#[pyclass(name = "Basis", module = "flexrom._flexrom", frozen)]
struct PyBasis {
    pipeline: Pipeline,
    /// the pipeline file given to `load` (none: the pipeline the basis file stores)
    pipeline_file: Option<PathBuf>,
    path: PathBuf,
    stored: flexrom::io::basis_file::StoredBasis,
    rom: Arc<Rom>,
    training_loads: Vec<f64>,
    /// what greedy training said beside meeting its tolerance, one sentence each
    training_notes: Vec<String>,
    /// `load`'s `estimate` and `no_estimate`, for pickling (`__reduce__`)
    estimate: Option<String>,
    no_estimate: bool,
}

#[pymethods]
impl PyBasis {
    /// Reads and checks the basis file at `path` and builds its reduced model. `pipeline`:
    /// the pipeline file it is checked against (default: the pipeline and model the basis
    /// file stores); `estimate`: the error estimate's method over the pipeline's; with
    /// `no_estimate`, none.
    #[staticmethod]
    #[pyo3(signature = (path, pipeline = None, estimate = None, no_estimate = false))]
    fn load(
        py: Python<'_>,
        path: PathBuf,
        pipeline: Option<PathBuf>,
        estimate: Option<&str>,
        no_estimate: bool,
    ) -> PyResult<Self> {
        let method = estimate.map(parse_method).transpose()?;
        // a pipeline file that is wrong is the pipeline's error, not the basis's
        let p = match &pipeline {
            Some(file) => Some(py.detach(|| Pipeline::load(file)).map_err(to_py)?),
            None => None,
        };
        let b = py.detach(|| Self::open(&path, p, pipeline.clone(), method, no_estimate));
        let (mut b, warnings) = b.map_err(errors::basis_error)?;
        warn(py, &warnings)?;
        b.estimate = estimate.map(str::to_string);
        Ok(b)
    }

    /// `Basis(path, …)` is `Basis.load(path, …)`: what unpickling calls.
    #[new]
    #[pyo3(signature = (path, pipeline = None, estimate = None, no_estimate = false))]
    fn new(
        py: Python<'_>,
        path: PathBuf,
        pipeline: Option<PathBuf>,
        estimate: Option<&str>,
        no_estimate: bool,
    ) -> PyResult<Self> {
        Self::load(py, path, pipeline, estimate, no_estimate)
    }

    /// Pickled as the file it was read from (absolute paths, so that another process or
    /// folder finds it) with the arguments of `load`: unpickling reads and checks the basis
    /// file again, which must still be there (joblib, multiprocessing).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let py = slf.py();
        let b = slf.get();
        let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        let args = (absolute(&b.path), b.pipeline_file.as_deref().map(absolute), b.estimate.clone(), b.no_estimate);
        Ok((slf.get_type().into_any(), args.into_pyobject(py)?.into_any()))
    }

    #[getter]
    fn path(&self) -> String {
        self.path.display().to_string()
    }

    /// (n_dof, r) V: the modes, one column each (as the basis file's `/basis/modes`)
    #[getter]
    fn modes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.stored.basis.modes.clone().into_pyarray(py)
    }

    /// (n_dof) x_ref: the configuration the modes are taken from (`/basis/reference`)
    #[getter]
    fn reference<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.stored.basis.reference.clone().into_pyarray(py)
    }

    /// Full coordinates from reduced ones, `x = x_ref + V z`: `z` of shape (r) gives (n_dof),
    /// (n_t, r) gives (n_t, n_dof) (a reduced run's `reduced_q`, time first).
    fn reconstruct<'py>(&self, py: Python<'py>, z: PyReadonlyArrayDyn<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        let b = &self.stored.basis;
        let z = z.as_array();
        let r = b.n_reduced();
        match z.ndim() {
            1 if z.len() == r => {
                Ok(b.reconstruct(z.into_dimensionality::<ndarray::Ix1>().expect("1-D")).into_pyarray(py).into_any())
            }
            2 if z.shape()[1] == r => {
                // time first: the columns of Zᵀ are the instants
                let z = z.into_dimensionality::<ndarray::Ix2>().expect("2-D");
                let x = b.reconstruct_columns(z.t()).reversed_axes().as_standard_layout().into_owned();
                Ok(x.into_pyarray(py).into_any())
            }
            _ => Err(errors::model_error(&format!(
                "reconstruct: z has shape {:?}; it must be ({r},) or (n_t, {r})",
                z.shape()
            ))),
        }
    }

    /// Reduced coordinates of full ones, `z = Vᵀ(x − x_ref)` (least squares where V is not
    /// orthonormal): `x` of shape (n_dof) or (n_t, n_dof).
    fn reduce<'py>(&self, py: Python<'py>, x: PyReadonlyArrayDyn<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        let b = &self.stored.basis;
        let x = x.as_array();
        let n = b.modes.nrows();
        match x.ndim() {
            1 if x.len() == n => {
                Ok(b.reduce(x.into_dimensionality::<ndarray::Ix1>().expect("1-D")).into_pyarray(py).into_any())
            }
            2 if x.shape()[1] == n => {
                let x = x.into_dimensionality::<ndarray::Ix2>().expect("2-D");
                let mut z = ndarray::Array2::zeros((x.nrows(), b.n_reduced()));
                for (mut out, row) in z.rows_mut().into_iter().zip(x.rows()) {
                    out.assign(&b.reduce(row));
                }
                Ok(z.into_pyarray(py).into_any())
            }
            _ => Err(errors::model_error(&format!(
                "reduce: x has shape {:?}; it must be ({n},) or (n_t, {n})",
                x.shape()
            ))),
        }
    }

    /// every singular value of the POD, non-increasing
    #[getter]
    fn singular_values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.stored.singular_values.clone().into_pyarray(py)
    }

    /// the load scales of the full runs the snapshots come from, sorted, each once
    #[getter]
    fn training_loads<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.training_loads.clone().into_pyarray(py)
    }

    /// what greedy training said beside meeting its tolerance, one sentence each: its
    /// converged held-out check's error above the tolerance (within the model's own
    /// sensitivity there), the online default estimate reading above it between the
    /// candidates; empty when neither, or for a basis not trained greedily
    #[getter]
    fn training_notes(&self) -> Vec<String> {
        self.training_notes.clone()
    }

    /// the reduced coordinates r (modes and kept joint coordinates)
    #[getter]
    fn n_modes(&self) -> usize {
        self.stored.basis.n_reduced()
    }

    /// the reduction variant (`per-body`, `whole-system`, …)
    #[getter]
    fn variant(&self) -> &'static str {
        self.stored.basis.variant.name()
    }

    /// the sampled elements of the hyper-reduction (None: every element)
    #[getter]
    fn sampled_elements(&self) -> Option<Vec<usize>> {
        self.stored.basis.hyper.as_ref().map(|h| h.elements.clone())
    }

    /// the error estimate's method (None: no estimate)
    #[getter]
    fn estimate_method(&self) -> Option<&'static str> {
        self.rom.method()
    }

    /// the tolerance runs are held to (None: no tolerance)
    #[getter]
    fn tolerance(&self) -> Option<f64> {
        self.rom.trust().and_then(|t| t.tolerance)
    }

    /// the model the basis reduces
    #[getter]
    fn model(&self) -> PyModel {
        PyModel { model: Arc::clone(self.rom.model()) }
    }

    /// One reduced run (`flexrom online`) with its error estimate; warns when the load
    /// leaves the training range or the estimate exceeds the tolerance.
    /// `fallback="full"` (`online --fallback full`): where the reduced answer cannot be
    /// trusted the full model's run is returned in its place (`reduced` False, `fallback` the
    /// reason); default the pipeline's `[online] fallback`.
    #[pyo3(signature = (load_scale = None, *, fallback = None, **params))]
    fn online(
        &self,
        py: Python<'_>,
        load_scale: Option<f64>,
        fallback: Option<String>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<PyRunResult> {
        let fallback = self.fallback_choice(fallback, "online")?;
        let params = convert::named(params)?;
        let mu = self.point(py, load_scale, params.as_ref())?;
        let rom = &self.rom;
        let done = interruptible(py, || flexrom::workflows::online::answer(rom, &mu, fallback))?;
        if done.fallback.is_some() {
            // the full model's answer: exact, nothing to warn about
            let r = done.run.result;
            return Ok(PyRunResult {
                statics: None,
                model: Arc::clone(rom.model()),
                r,
                reduced: None,
                fallback: done.fallback,
                fallback_failed: None,
                exact: done.estimate.map(|e| (e, done.extrapolated)),
            });
        }
        warn(py, &done.warnings(rom, &mu, false).map_err(to_py)?)?;
        let (run, estimate) = (done.run, done.estimate);
        let extrapolated = rom.is_extrapolated(&mu);
        let basis = rom.basis();
        let reduced = ReducedPart {
            reduced_q: run.reduced_q,
            basis_name: flexrom::io::output::resolve(&self.path).display().to_string(),
            basis_path: self.path.clone(),
            pipeline_path: self.pipeline_file.clone(),
            variant: basis.variant.name().to_string(),
            n_modes: basis.n_reduced(),
            estimate,
            method: rom.method().map(str::to_string),
            trust: rom.trust().cloned().unwrap_or_else(|| Trust::range((f64::NAN, f64::NAN))),
            mu,
            extrapolated,
        };
        Ok(PyRunResult {
            model: Arc::clone(rom.model()),
            r: run.result,
            reduced: Some(reduced),
            fallback: None,
            fallback_failed: done.note,
            exact: None,
            statics: None,
        })
    }

    /// Reduced runs at many loads in parallel (`flexrom sweep`): a dict of arrays with the
    /// load axis first (`load_scale`, `t`, `probes` name → (n, n_t, 2), `error_estimate`,
    /// `error_estimate_by_time` (n, 5), `extrapolated`, `failed`: each point's error
    /// message or None, `fallback`: why the full model answered a point in place of the
    /// reduced one, or None, `fallback_failed`: why it was tried there and how it failed,
    /// the reduced answer kept, or None). `points`: a list of dicts of named parameters instead.
    /// `fallback`: "full" runs the full model where the reduced answer cannot be trusted
    /// (`sweep --fallback full`), "none" keeps it; default the pipeline's `[online] fallback`.
    #[pyo3(signature = (load_scales = None, points = None, continuation = false, progress = None, fallback = None))]
    fn sweep<'py>(
        &self,
        py: Python<'py>,
        load_scales: Option<Vec<f64>>,
        points: Option<Vec<HashMap<String, f64>>>,
        continuation: bool,
        progress: Option<Bound<'py, PyAny>>,
        fallback: Option<String>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let fallback = self.fallback_choice(fallback, "sweep")?;
        let progress = progress_callback(py, progress)?;
        let mus: Vec<Parameters> = match (load_scales, points) {
            (Some(s), None) => s.into_iter().map(|x| self.point(py, Some(x), None)).collect::<PyResult<_>>()?,
            (None, Some(p)) => p.iter().map(|p| self.point(py, None, Some(p))).collect::<PyResult<_>>()?,
            _ => return Err(errors::model_error("sweep: give exactly one of load_scales and points")),
        };
        let o = flexrom::workflows::sweep::SweepOptions { continuation, fallback, ..Default::default() };
        let rom = &self.rom;
        let s = interruptible_with(py, progress.as_ref(), || flexrom::workflows::sweep::sweep(rom, &mus, o))?;
        let warnings = rom.warnings_after(&s.answered(rom), false).map_err(to_py)?;
        warn(py, &warnings)?;
        convert::sweep_dict(py, &s, &mus)
    }

    fn __repr__(&self) -> String {
        format!("Basis('{}': {} {} modes)", self.path.display(), self.n_modes(), self.variant())
    }
}

impl PyBasis {
    /// The `fallback` argument of `online` and `sweep` (`what` names the method in
    /// errors): "none" or "full", default the pipeline's `[online] fallback`; "full" needs
    /// the error estimate to judge each reduced answer.
    fn fallback_choice(&self, given: Option<String>, what: &str) -> PyResult<flexrom::workflows::sweep::Fallback> {
        use flexrom::workflows::sweep::Fallback;
        let fallback = match given.as_deref() {
            None => self.pipeline.online_fallback().unwrap_or_default(),
            Some("none") => Fallback::None,
            Some("full") => Fallback::Full,
            Some(other) => {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
                    "{what}: fallback is \"{other}\"; expected \"none\" or \"full\""
                )))
            }
        };
        if fallback == Fallback::Full && self.rom.trust().is_some_and(|t| t.skipped) {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "{what}: fallback \"full\" needs the error estimate to judge each reduced answer; this basis was loaded with no_estimate=True"
            )));
        }
        Ok(fallback)
    }

    /// The basis at `path` checked against the pipeline `p` (loaded from `pipeline_file`),
    /// or, without one, against the pipeline and model the basis file stores.
    fn open(
        path: &Path,
        p: Option<Pipeline>,
        pipeline_file: Option<PathBuf>,
        method: Option<EstimateMethod>,
        no_estimate: bool,
    ) -> flexrom::Result<(Self, Vec<String>)> {
        let p = match p {
            Some(p) => p,
            None => pipeline_of_basis(path, flexrom::limits::Limits::from_env_or_defaults())?,
        };
        let (stored, rom, warnings) = load_rom(&p, path, method, no_estimate)?;
        // what the one read of the file found of its training
        let training_loads = stored.training.loads.clone();
        let training_notes = stored.training.notes.iter().map(|(_, note)| note.clone()).collect();
        let rom = Arc::new(rom);
        let b = PyBasis {
            pipeline: p,
            pipeline_file,
            path: path.to_path_buf(),
            stored,
            rom,
            training_loads,
            training_notes,
            estimate: None,
            no_estimate,
        };
        Ok((b, warnings))
    }

    /// The checked parameters of a run, with the file's value for a property not given
    /// (as `online` reads them); warns of a value far from a property's.
    fn point(
        &self,
        py: Python<'_>,
        load_scale: Option<f64>,
        params: Option<&HashMap<String, f64>>,
    ) -> PyResult<Parameters> {
        let model = &self.pipeline.model;
        let mu = parameters(load_scale, params.unwrap_or(&HashMap::new()))?;
        warn(py, &model.admit(std::slice::from_ref(&mu), Runs::Reduced).map_err(to_py)?)?;
        Ok(model.with_property_values(&mu))
    }
}

/// The `Result` of a pickled payload (`Result.__reduce__`); a `ValueError` naming what is
/// wrong with bytes that are not one, are damaged, or come from another flexrom version.
#[pyfunction]
fn _result_from_pickle(payload: &[u8]) -> PyResult<PyRunResult> {
    pickle::from_bytes(payload).map_err(pyo3::exceptions::PyValueError::new_err)
}

fn parse_method(name: &str) -> PyResult<EstimateMethod> {
    EstimateMethod::ALL.into_iter().find(|m| m.name().eq_ignore_ascii_case(name)).ok_or_else(|| {
        let names: Vec<&str> = EstimateMethod::ALL.iter().map(|m| m.name()).collect();
        errors::model_error(&format!("estimate: `{name}` is not a method; one of {}", names.join(", ")))
    })
}

/// Trains the pipeline's basis (`flexrom train`) and writes it to `output` (default: the
/// pipeline's `basis`); returns the basis, loaded.
#[pyfunction]
#[pyo3(signature = (pipeline, output = None, progress = None))]
fn train<'py>(
    py: Python<'py>,
    pipeline: PathBuf,
    output: Option<PathBuf>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<PyBasis> {
    let progress = progress_callback(py, progress)?;
    let p = Pipeline::load(&pipeline).map_err(to_py)?;
    warn(py, &p.property_warnings())?;
    let out = output.clone().unwrap_or_else(|| p.basis_path.clone());
    let summary = interruptible_with(py, progress.as_ref(), || {
        let origin = match &output {
            Some(_) => Origin::Flag("output"),
            None => Origin::Key { pipeline: &p.path, key: "basis" },
        };
        flexrom::training::train::train_to_file(&p, &out, origin, &[])
    })?;
    warn(py, &summary.warnings)?;
    let (b, warnings) =
        py.detach(|| PyBasis::open(&out, Some(p), Some(pipeline), None, false)).map_err(errors::basis_error)?;
    warn(py, &warnings)?;
    Ok(b)
}

/// Full and reduced runs compared (`flexrom validate --json`): what the command prints, as
/// Python's `json.loads` reads it (a dict, or a list of dicts), its points chosen as the command chooses them (one record where a load scale or
/// a named parameter is given and names one point, else a list: the pipeline's validation
/// points, or the named values at each of its `[validate]` loads). `dense`: None as the
/// command's default (skipped above 256 MiB or half a minute of work), True `--dense`, False `--no-dense`.
#[pyfunction]
#[pyo3(signature = (pipeline, load_scale = None, basis = None, estimate = None, dense = None, **params))]
fn validate<'py>(
    py: Python<'py>,
    pipeline: PathBuf,
    load_scale: Option<f64>,
    basis: Option<PathBuf>,
    estimate: Option<&str>,
    dense: Option<bool>,
    params: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    use flexrom::cost::dense::DenseChoice;
    let params = convert::named(params)?;
    let method = estimate.map(parse_method).transpose()?;
    let p = py.detach(|| Pipeline::load(&pipeline)).map_err(to_py)?;
    let params = params.unwrap_or_default();
    let named = !params.is_empty();
    let sets_load_scale = params.contains_key(flexrom::solver::parameters::LOAD_SCALE);
    let points = p.validation_points_given(load_scale, (named, sets_load_scale), |x| parameters(x, &params))?;
    warn(py, &p.model.admit(&points, Runs::Reduced).map_err(to_py)?)?;
    let points: Vec<Parameters> = points.iter().map(|mu| p.model.with_property_values(mu)).collect();
    let path = basis.unwrap_or_else(|| p.basis_path.clone());
    let (_, rom, warnings) = py.detach(|| load_rom(&p, &path, method, false)).map_err(errors::basis_error)?;
    warn(py, &warnings)?;
    let choice = match dense {
        None => DenseChoice::Auto,
        Some(true) => DenseChoice::Always,
        Some(false) => DenseChoice::Never,
    };
    let with_dense = flexrom::cost::dense::decide(choice, &p.model).map_err(to_py)?;
    let vs = interruptible(py, || {
        points
            .iter()
            .map(|mu| flexrom::workflows::validate::validate(&rom, mu, with_dense).map(|v| v.0))
            .collect::<flexrom::Result<Vec<_>>>()
    })?;
    // the command's warnings after its runs: estimates over the tolerance, extrapolation,
    // parameters the basis was not trained over
    let answered: Vec<_> = points.iter().zip(&vs).map(|(mu, v)| v.answered(&rom, mu)).collect();
    warn(py, &rom.warnings_after(&answered, false).map_err(to_py)?)?;
    let text = match vs.as_slice() {
        [v] if load_scale.is_some() || named => serde_json::to_string(v),
        _ => serde_json::to_string(&vs),
    };
    let text = text.map_err(|e| errors::model_error(&format!("cannot write the JSON: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

#[pymodule]
fn _flexrom(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // the library's progress and warning lines through Python's `logging` (logger
    // "flexrom"); a failure here (a logger already set) leaves them off
    if let Ok(h) = pyo3_log::try_init() {
        let _ = LOG_RESET.set(h);
    }
    // one OpenBLAS thread, as in the command line (the library sets it at its first LAPACK
    // call anyway): joins now the workers OpenBLAS's constructor started when the module loaded
    flexrom::single_threaded_blas();
    m.add_class::<PyModel>()?;
    m.add_class::<PyRunResult>()?;
    m.add_class::<PyModes>()?;
    m.add_class::<PyBasis>()?;
    m.add_function(wrap_pyfunction!(train, m)?)?;
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add_function(wrap_pyfunction!(_result_from_pickle, m)?)?;
    errors::add(m)?;
    m.add("FlexromWarning", m.py().get_type::<FlexromWarning>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
