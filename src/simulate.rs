//! Full-order simulation of a model file: the first stage of the flow
//! model file → full simulation → snapshots → POD basis → reduced runs → validation.

use crate::analysis::energy::{energies, Energies, States};
use crate::analysis::statics::{StaticOptions, StaticSolution};
use crate::error::{show_number, Error, Result, Text};
use crate::linalg::kkt::LinearSolverKind;
use crate::model::Model;
use crate::physics::joints::RowKind;
use crate::physics::system::{FlexibleSystem, Probe};
use crate::solver::generalized_alpha::{GeneralizedAlpha, IntegratorParams, LargestStrain, State, Stats};
use crate::solver::model::{Bound, DynamicModel, Parameters, ParametricModel};
use ndarray::{Array1, Array2};

/// Run settings; `None` fields take the model file's values.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub dt: Option<f64>,
    pub t_end: Option<f64>,
    pub rho_inf: Option<f64>,
    /// the run's parameters; `None`: the model file's own loads ([`Parameters::default`])
    pub mu: Option<Parameters>,
    pub solver: LinearSolverKind,
}

impl Overrides {
    /// The model file's settings at the parameters `mu`.
    pub fn at(mu: &Parameters) -> Self {
        Overrides { mu: Some(mu.clone()), ..Default::default() }
    }
}

/// The settings a run actually used.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub dt: f64,
    pub t_end: f64,
    pub rho_inf: f64,
    /// the run's parameters `μ`
    pub mu: Parameters,
    pub n_steps: usize,
    pub solver: LinearSolverKind,
    pub params: IntegratorParams,
    /// blow-up checks warn instead of failing (the model's [`crate::limits::Limits`])
    pub allow_blowup: bool,
}

impl Settings {
    pub fn resolve(model: &Model, o: &Overrides) -> Result<Settings> {
        let t = &model.file.time;
        let dt = o.dt.unwrap_or(t.dt);
        let t_end = o.t_end.unwrap_or(t.t_end);
        let rho_inf = o.rho_inf.unwrap_or(t.rho_inf);
        let mu = o.mu.clone().unwrap_or_default();
        let bad = |key: &'static str, v: f64| Error::option(key, None, format!("must be positive and finite, got {v}"));
        if !(dt.is_finite() && dt > 0.0) {
            return Err(bad("dt", dt));
        }
        if !(t_end.is_finite() && t_end > 0.0) {
            return Err(bad("t_end", t_end));
        }
        mu.validate()?;
        model.check_parameters(&mu)?;
        // a body property the run does not set is the file's value: say so in the result
        let mu = model.with_property_values(&mu);
        let params = IntegratorParams { rho_inf, ..model.integrator_params() };
        params.validate().map_err(|e| Error::option("rho_inf", Some(show_number(rho_inf)), e.problem()))?;
        // the number of whole steps that fit (SPEC §4: 1.1 s at 0.007 s is 157 steps),
        // bounded in floating point before the cast (t_end = 1e300 or dt = 1e-300 would
        // saturate it and overflow n_t = n_steps + 1)
        let steps = (t_end / dt + 1e-9).floor();
        model.limits.check_steps(steps, dt, t_end)?;
        let n_steps = steps as usize;
        if n_steps == 0 {
            // name where each value came from: an option, or the model file
            let from = |given: bool, option: &str, key: &str| {
                if given {
                    format!("--{option}")
                } else {
                    format!("{}: time.{key}", model.path.display())
                }
            };
            return Err(Error::usage(format!(
                "the time step ({} = {dt}) is longer than the run ({} = {t_end}): no step fits",
                from(o.dt.is_some(), "dt", "dt"),
                from(o.t_end.is_some(), "t-end", "t_end"),
            )));
        }
        Ok(Settings {
            dt,
            t_end,
            rho_inf,
            mu,
            n_steps,
            solver: o.solver,
            params,
            allow_blowup: model.limits.allow_blowup,
        })
    }

    /// The parameters μ of the run.
    pub fn parameters(&self) -> &Parameters {
        &self.mu
    }
}

/// Named series of one value per instant (a probe's strain or curvature).
pub type Series = Vec<(String, Array1<f64>)>;

/// Everything `simulate` writes.
#[derive(Clone, Debug)]
pub struct SimulationResult {
    pub model_text: String,
    pub model_path: String,
    pub settings: Settings,
    pub t: Array1<f64>,
    /// n_dof × n_t
    pub q: Array2<f64>,
    /// n_dof × n_t: the velocities q̇ (a reduced run's V ż)
    pub qd: Array2<f64>,
    /// n_c × n_t
    pub multipliers: Array2<f64>,
    /// name → (n_t × 2)
    pub probes: Vec<(String, Array2<f64>)>,
    /// name → (n_t): the axial strain of each probe that records it
    pub strains: Series,
    /// name → (n_t): the curvature (1/m) of each probe that records it
    pub curvatures: Series,
    pub stats: Stats,
    /// wall time of the time loop alone
    pub wall_seconds: f64,
    /// the energies at every instant, where they are written ([`with_energies`],
    /// [`with_reduced_energies`]); `None` otherwise
    pub energy: Option<Energies>,
}

/// The one solve of every run, full or reduced (`simulate`, `online`, `sweep`, `validate`,
/// greedy training and the error estimate all come here): integrates `model` at the
/// settings' parameters over its `n_steps` steps of `dt` from `(q0, v0)`, with the
/// optional increment guess of [`integrate_guided`], calling `record` at t₀ and after every
/// step. The model is not changed by the parameters: the same model runs at λ₁, λ₂, λ₁ and
/// gives what three fresh models give (tests/parameters.rs).
pub fn solve<M: ParametricModel + ?Sized>(
    model: &mut M,
    s: &Settings,
    (q0, v0): (Vec<f64>, Vec<f64>),
    guess: impl FnMut(usize, &mut [f64]) -> bool,
    record: impl FnMut(usize, &State),
) -> Result<Stats> {
    let mu = s.parameters();
    mu.validate()?;
    integrate_guided(&mut Bound::new(model, mu), s, (q0, v0), guess, record)
}

/// Integrates any [`DynamicModel`] (a model bound to its parameters) with the settings'
/// integrator over their `n_steps` steps of `dt`, calling `record` at t₀ and after every
/// step. Returns the integrator statistics.
pub fn integrate<M: DynamicModel>(
    model: &mut M,
    s: &Settings,
    q0: Vec<f64>,
    record: impl FnMut(usize, &State),
) -> Result<Stats> {
    let v0 = vec![0.0; q0.len()];
    integrate_guided(model, s, (q0, v0), |_, _| false, record)
}

/// [`integrate`] with a guess of each step's increment: `guess(k, out)` fills `out` with
/// `q_k − q_{k−1}` and returns true, or returns false for the default predictor.
pub fn integrate_guided<M: DynamicModel>(
    model: &mut M,
    s: &Settings,
    (q0, v0): (Vec<f64>, Vec<f64>),
    mut guess: impl FnMut(usize, &mut [f64]) -> bool,
    mut record: impl FnMut(usize, &State),
) -> Result<Stats> {
    let (params, dt, n_steps) = (&s.params, s.dt, s.n_steps);
    let mut integ = GeneralizedAlpha::new(params.clone())?;
    let mut state = integ.initialize(model, q0, v0, 0.0)?;
    let mut increment = vec![0.0; state.q.len()];
    let mut watch = BlowUpWatch::new(params, s.allow_blowup);
    record(0, &state);
    let mut steps = || -> Result<()> {
        for k in 1..=n_steps {
            crate::interrupt::check()?;
            let guessed = guess(k, &mut increment);
            integ.step_guided(model, &mut state, dt, guessed.then_some(increment.as_slice()))?;
            // keep t on the nominal grid despite round-off in sub-steps
            state.t = k as f64 * dt;
            watch.check(model, &state, &mut integ.stats, k == n_steps || k % STRAIN_CHECK_EVERY == 0)?;
            record(k, &state);
        }
        Ok(())
    };
    if let Err(e) = steps() {
        // what `-v` prints of a run that ends, for one that failed (the error says where)
        let st = &integ.stats;
        log::debug!(
            "  Newton until the run failed: {} steps done, {} iterations (at most {} in one attempt), {} \
             factorizations, {} step cuts; started from {}",
            st.steps,
            st.newton_iterations,
            st.max_iterations_in_a_step,
            st.factorizations,
            st.step_cuts,
            st.starts()
        );
        return Err(e);
    }
    Ok(integ.stats)
}

/// The strain check runs every this many steps (and at the last): a full model pays one
/// pass over its elements for it (~a quarter of a force evaluation), and a blow-up that
/// grows for four steps is still caught long before the end of a run.
pub const STRAIN_CHECK_EVERY: usize = 4;

/// Blow-up detection: a run whose largest mean axial strain |ε̄| exceeds `max_strain` or
/// whose step halvings exceed `max_total_cuts` stops with [`Error::BlowUp`], naming what,
/// when, and the key that relaxes it; with `--allow-blowup` each check warns once instead.
struct BlowUpWatch {
    max_strain: f64,
    max_cuts: usize,
    warn_only: bool,
    warned_strain: bool,
    warned_cuts: bool,
}

impl BlowUpWatch {
    fn new(p: &IntegratorParams, warn_only: bool) -> Self {
        BlowUpWatch {
            max_strain: p.max_strain,
            max_cuts: p.max_total_cuts,
            warn_only,
            warned_strain: false,
            warned_cuts: false,
        }
    }

    fn check<M: DynamicModel>(&mut self, model: &M, st: &State, stats: &mut Stats, strain_now: bool) -> Result<()> {
        if stats.step_cuts > self.max_cuts && !self.warned_cuts {
            let problem = format!(
                "{} step halvings so far, over the budget of {} per run (`[time] max_total_step_cuts` in the model file raises it",
                stats.step_cuts, self.max_cuts
            );
            self.report(st.t, problem, true)?;
        }
        // the largest strain is kept after a warned blow-up too (`-v` reports it)
        if strain_now {
            if let Some((eps, e)) = model.max_strain(&st.q) {
                if stats.largest_strain.is_none_or(|l| !(eps <= l.strain)) {
                    stats.largest_strain = Some(LargestStrain { strain: eps, element: e, t: st.t });
                }
                if !(eps <= self.max_strain) && !self.warned_strain {
                    let problem = format!(
                        "mean axial strain |ε̄| = {eps:.3e} in element {e}, over the plausible bound {} (`[time] max_strain` in the model file raises it",
                        self.max_strain
                    );
                    self.report(st.t, problem, false)?;
                }
            }
        }
        Ok(())
    }

    /// `problem` (what and the key that relaxes it, up to its closing parenthesis) as an
    /// error that names the option warning instead, or, where that option is on, as a warning.
    fn report(&mut self, t: f64, problem: String, cuts: bool) -> Result<()> {
        if !self.warn_only {
            let problem = Text::new(problem).clause("; ", "allow_blowup", None, " only warns").then(")");
            return Err(Error::BlowUp { t, problem });
        }
        log::warn!("warning: blow-up at t = {t:.6} s: {problem})");
        if cuts {
            self.warned_cuts = true
        } else {
            self.warned_strain = true
        }
        Ok(())
    }
}

/// Builds the model's system with the linear solver `s.solver` and its consistent initial
/// state (neither depends on the load scale).
pub fn prepare(model: &Model, s: &Settings) -> Result<(FlexibleSystem, Vec<f64>)> {
    let mut sys = model.system(s.solver);
    let mut q0 = sys.initial_state();
    sys.make_consistent(&mut q0).map_err(|e| e.at_time_in(0.0, "initial joint projection"))?;
    Ok((sys, q0))
}

/// The warnings of a time step `s.dt` that does not resolve `model`'s lowest elastic
/// natural period or its loads' sines ([`crate::analysis::resolution`]), one line each;
/// none where that check is not cheap or the model cannot be prepared (the run says why).
pub fn resolution_warnings(model: &Model, s: &Settings) -> Vec<String> {
    // sized from the file before anything is assembled: a model too large for the check (or
    // for the memory bound, which its run then names) costs nothing here
    if model.sizes().n_dof > crate::analysis::resolution::MAX_DOF as f64 {
        return Vec::new();
    }
    let Ok((sys, q0)) = prepare(model, s) else { return Vec::new() };
    let mu = model.with_property_values(&s.mu);
    crate::analysis::resolution::time_step_warnings(model, &sys, &mu, &q0, s.dt)
}

/// The full model of a model file, assembled once and run at as many parameters as wanted
/// (training, validation): the system and its consistent initial state.
pub struct FullModel<'a> {
    model: &'a Model,
    solver: LinearSolverKind,
    sys: FlexibleSystem,
    q0: Vec<f64>,
}

impl<'a> FullModel<'a> {
    /// Assembles the system of `model` with the linear solver `solver`.
    pub fn new(model: &'a Model, solver: LinearSolverKind) -> Result<Self> {
        let s = Settings::resolve(model, &Overrides { solver, ..Default::default() })?;
        let (sys, q0) = prepare(model, &s)?;
        Ok(FullModel { model, solver, sys, q0 })
    }

    pub fn system(&self) -> &FlexibleSystem {
        &self.sys
    }

    /// The full run with `overrides` (their `solver` is this model's): [`simulate`] without
    /// assembling the system again.
    pub fn simulate(&mut self, overrides: &Overrides) -> Result<SimulationResult> {
        let s = Settings::resolve(self.model, &Overrides { solver: self.solver, ..overrides.clone() })?;
        run_full(self.model, &mut self.sys, self.q0.clone(), s)
    }
}

/// The full run of `model` with `overrides`: assembles the system and runs it once
/// ([`FullModel`] keeps the system for more runs).
pub fn simulate(model: &Model, overrides: &Overrides) -> Result<SimulationResult> {
    let s = Settings::resolve(model, overrides)?;
    model.check_full_run_memory(s.n_steps, s.solver == LinearSolverKind::Dense)?;
    let (mut sys, q0) = prepare(model, &s)?;
    run_full(model, &mut sys, q0, s)
}

/// Warns about each prescribed motion whose rate at t = 0 the bodies' initial velocities do
/// not have (`B q̇₀ ≠ ḃ − Ḃ q₀`, a drive started at speed from rest): the first step
/// absorbs the jump, with a spike in the accelerations and the joint forces.
///
/// A jump counts when it exceeds 1e-9 of the run's own rates (the bodies' and the drives'
/// initial ones) or of the rate that moves the model's length (a slope: one radian) over the
/// run, so that round-off of a drive starting at rest is not one.
fn warn_on_drive_jumps(model: &Model, sys: &FlexibleSystem, s: &Settings, q0: &[f64], v0: &[f64]) {
    if !sys.has_moving_constraints() {
        return;
    }
    let mu = &s.mu;
    let nc = ParametricModel::n_constraints(sys);
    let (mut want, mut bv, mut b0) = (vec![0.0; nc], vec![0.0; nc], vec![0.0; nc]);
    sys.constraint_velocity_rhs(mu, q0, 0.0, &mut want);
    // B v₀ as the residual at v₀ less the residual at 0
    sys.constraint_residual(mu, v0, 0.0, &mut bv);
    sys.constraint_residual(mu, &vec![0.0; q0.len()], 0.0, &mut b0);
    let first = |(b, k): crate::physics::system::NodeId| 4 * sys.node_index(b, k);
    let rows = crate::physics::joints::lower(model.joints(), &first);
    let speed = v0.iter().chain(&want).fold(0.0_f64, |m, v| m.max(v.abs()));
    for (c, (j, row)) in rows.iter().enumerate() {
        let jump = want[c] - (bv[c] - b0[c]);
        let reach = if row.kind == RowKind::Position { sys.length_scale() } else { 1.0 } / s.t_end;
        if row.motion.is_some() && jump.abs() > 1e-9 * speed.max(reach) {
            let joint = model.joints()[*j].describe(&|(b, k)| format!("{} node {k}", model.file.bodies[b].name));
            log::warn!(
                "joints[{j}] ({joint}) starts at a rate the bodies do not have at t = 0 ({} off by {jump:.3e} {}/s): \
                 the first step absorbs the jump, with a spike in the accelerations and the joint forces; start the \
                 drive at rest (a smooth profile such as the spin-up's) or give the bodies its initial velocity",
                row.component,
                row.kind.residual_unit()
            );
        }
    }
}

fn run_full(model: &Model, sys: &mut FlexibleSystem, q0: Vec<f64>, s: Settings) -> Result<SimulationResult> {
    model.check_full_run_memory(s.n_steps, s.solver == LinearSolverKind::Dense)?;
    let q0 = if model.starts_static() { static_start(sys, q0, &s)? } else { q0 };
    let (n, nc, nt) = (ParametricModel::n_dof(sys), ParametricModel::n_constraints(sys), s.n_steps + 1);
    // column-major: each instant's column is contiguous, so recording a step is one copy
    // and the result file's time-first rows are the memory as it is (no transposition)
    let mut q = Array2::zeros(ndarray::ShapeBuilder::f((n, nt)));
    let mut qd = Array2::zeros(ndarray::ShapeBuilder::f((n, nt)));
    let mut mult = Array2::zeros(ndarray::ShapeBuilder::f((nc, nt)));
    let mut t = Array1::zeros(nt);
    let mut probes: Vec<(String, Array2<f64>)> =
        sys.probes.iter().map(|p| (p.name.clone(), Array2::zeros((nt, 2)))).collect();
    let probe_defs = sys.probes.clone();
    let start = std::time::Instant::now();
    let v0 = sys.initial_velocity(&q0);
    warn_on_drive_jumps(model, sys, &s, &q0, &v0);
    // the probes are evaluated after the loop, from the stored coordinates
    let stats = solve(
        sys,
        &s,
        (q0, v0),
        |_, _| false,
        |k, st| {
            t[k] = st.t;
            q.column_mut(k).assign(&ndarray::ArrayView1::from(&st.q));
            qd.column_mut(k).assign(&ndarray::ArrayView1::from(&st.v));
            mult.column_mut(k).assign(&ndarray::ArrayView1::from(&st.lambda));
        },
    )?;
    let wall_seconds = start.elapsed().as_secs_f64();
    for (p, (_, xy)) in probe_defs.iter().zip(probes.iter_mut()) {
        for k in 0..nt {
            let r = sys.probe_position(p, &q.column(k).to_vec());
            xy[[k, 0]] = r[0];
            xy[[k, 1]] = r[1];
        }
    }
    let (strains, curvatures) =
        probe_sections(&probe_defs, |p| (0..nt).map(|k| sys.probe_section(p, &q.column(k).to_vec())).collect());
    Ok(SimulationResult {
        model_text: model.text.clone(),
        model_path: model.path.display().to_string(),
        settings: s,
        t,
        q,
        qd,
        multipliers: mult,
        probes,
        strains,
        curvatures,
        stats,
        wall_seconds,
        // computed where they are written ([`with_energies`]): training and validation runs
        // do not pay a pass over the elements per instant for them
        energy: None,
    })
}

/// `r` with its energies ([`crate::analysis::energy`]), from its recorded states: what the
/// result files and tables of `simulate` show.
pub fn with_energies(model: &Model, mut r: SimulationResult) -> Result<SimulationResult> {
    let mut sys = model.system(LinearSolverKind::Banded);
    let (q, v, lambda) = (&r.q, &r.qd, &r.multipliers);
    let t = r.t.to_vec();
    let states =
        States { q: |k| q.column(k).to_vec(), v: |k| v.column(k).to_vec(), lambda: |k| lambda.column(k).to_vec() };
    r.energy = Some(energies(&mut sys, &r.settings.mu, &t, states));
    Ok(r)
}

/// A reduced run's `r` with its energies from its reconstructed states
/// ([`crate::analysis::energy::energies_over`]): the strain over the hyper-reduced model's
/// sampled elements at their weights (`hyper`), else over every element.
pub fn with_reduced_energies(
    model: &Model,
    mut r: SimulationResult,
    hyper: Option<&crate::reduction::Hyper>,
) -> Result<SimulationResult> {
    let mut sys = model.system(LinearSolverKind::Banded);
    let (q, v, lambda) = (&r.q, &r.qd, &r.multipliers);
    let t = r.t.to_vec();
    let weights = hyper.map(|h| (&h.elements[..], &h.weights[..]));
    let states =
        States { q: |k| q.column(k).to_vec(), v: |k| v.column(k).to_vec(), lambda: |k| lambda.column(k).to_vec() };
    r.energy = Some(crate::analysis::energy::energies_over(&mut sys, &r.settings.mu, &t, states, weights));
    Ok(r)
}

/// The static equilibrium under the run's loads at t = 0 (`[initial] static = true`), from
/// the consistent undeformed state `q0`: where a dynamic run starts, at rest.
fn static_start(sys: &mut FlexibleSystem, q0: Vec<f64>, s: &Settings) -> Result<Vec<f64>> {
    let o = StaticOptions { mu: s.mu.clone(), t: 0.0, steps: 1, solver: s.solver };
    let solution = crate::analysis::statics::solve(sys, q0, &o)?;
    log::debug!(
        "  initial static equilibrium: {} Newton iterations, {} load-step cuts",
        solution.newton_iterations,
        solution.step_cuts
    );
    Ok(solution.equilibrium().q.clone())
}

/// The static equilibrium of `model` under `o`'s loads ([`crate::analysis::statics`]) as a
/// result: one instant per load step (all at the time `o.t` of the loads), the
/// equilibrium last, its probes, multipliers and energies; the velocities are zero.
/// `--time` outside `[0, t_end]` of the model's run is refused.
pub fn statics(model: &Model, o: &StaticOptions) -> Result<(SimulationResult, StaticSolution)> {
    let t_end = model.file.time.t_end;
    if !(o.t >= 0.0 && o.t <= t_end) {
        return Err(Error::option(
            "time",
            Some(show_number(o.t)),
            format!("outside the model's run, [0, {}] s ({}: time.t_end)", show_number(t_end), model.path.display()),
        ));
    }
    if o.steps == 0 || o.steps as u64 > model.limits.max_steps {
        return Err(Error::option(
            "steps",
            Some(o.steps.to_string()),
            format!("give 1 to {} load steps", model.limits.max_steps),
        ));
    }
    o.mu.validate()?;
    model.check_parameters(&o.mu)?;
    let mu = model.with_property_values(&o.mu);
    let o = StaticOptions { mu, ..o.clone() };
    let settings =
        Settings::resolve(model, &Overrides { mu: Some(o.mu.clone()), solver: o.solver, ..Default::default() })?;
    let (mut sys, q0) = prepare(model, &settings)?;
    let start = std::time::Instant::now();
    let solution = crate::analysis::statics::solve(&mut sys, q0, &o)?;
    let wall_seconds = start.elapsed().as_secs_f64();
    let rows = &solution.steps;
    let (n, nc, nt) = (ParametricModel::n_dof(&sys), ParametricModel::n_constraints(&sys), rows.len());
    let q = Array2::from_shape_fn(ndarray::ShapeBuilder::f((n, nt)), |(i, k)| rows[k].q[i]);
    let qd = Array2::zeros(ndarray::ShapeBuilder::f((n, nt)));
    let multipliers = Array2::from_shape_fn(ndarray::ShapeBuilder::f((nc, nt)), |(i, k)| rows[k].lambda[i]);
    let t = Array1::from_elem(nt, o.t);
    let probe_defs = sys.probes.clone();
    let probes = probe_defs
        .iter()
        .map(|p| {
            let xy = Array2::from_shape_fn((nt, 2), |(k, c)| sys.probe_position(p, &rows[k].q)[c]);
            (p.name.clone(), xy)
        })
        .collect();
    let (strains, curvatures) =
        probe_sections(&probe_defs, |p| rows.iter().map(|r| sys.probe_section(p, &r.q)).collect());
    // a static state's energies: no motion, no work along a path of equilibria counted
    let states =
        States { q: |k: usize| rows[k].q.clone(), v: |_| vec![0.0; n], lambda: |k: usize| rows[k].lambda.clone() };
    let energy = energies(&mut sys, &o.mu, t.as_slice().expect("contiguous"), states);
    let stats = Stats {
        steps: nt,
        newton_iterations: solution.newton_iterations,
        factorizations: solution.factorizations,
        step_cuts: solution.step_cuts,
        ..Default::default()
    };
    let result = SimulationResult {
        model_text: model.text.clone(),
        model_path: model.path.display().to_string(),
        settings: Settings { n_steps: nt.saturating_sub(1), ..settings },
        t,
        q,
        qd,
        multipliers,
        probes,
        strains,
        curvatures,
        stats,
        wall_seconds,
        energy: Some(energy),
    };
    Ok((result, solution))
}

/// Where [`modes`] linearizes a model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModesAt {
    /// the initial (undeformed, consistent) configuration
    Initial,
    /// the static equilibrium under the loads ([`statics`], one load step)
    Static,
}

impl ModesAt {
    /// `initial` or `static`, as `--at` and the modes file's `at` attribute spell it.
    pub fn name(self) -> &'static str {
        match self {
            ModesAt::Initial => "initial",
            ModesAt::Static => "static",
        }
    }
}

/// What [`modes`] is asked for (`flexrom modes`' options).
#[derive(Clone, Debug)]
pub struct ModesOptions {
    /// how many of the lowest modes
    pub count: usize,
    pub at: ModesAt,
    /// the loads' parameters (before the model's property values)
    pub mu: Parameters,
    /// the time of the loads, s
    pub time: f64,
    pub solver: LinearSolverKind,
}

/// The modes of a model and where they were computed.
#[derive(Clone, Debug)]
pub struct ModesAnalysis {
    pub modes: crate::analysis::modes::Modes,
    /// the configuration `q*` the model was linearized at
    pub q: Vec<f64>,
    /// the parameters with the model's property values
    pub mu: Parameters,
    /// wall time of the static solve (if any) and the eigensolver, s
    pub seconds: f64,
}

/// The lowest `o.count` natural frequencies and mode shapes of `model`
/// ([`crate::analysis::modes::compute`]) at `o.at`: `--count` above the unconstrained
/// coordinates is refused naming the model file.
pub fn modes(model: &Model, o: &ModesOptions) -> Result<ModesAnalysis> {
    let mu = model.with_property_values(&o.mu);
    model.check_parameters(&mu)?;
    let settings =
        Settings::resolve(model, &Overrides { mu: Some(mu.clone()), solver: o.solver, ..Default::default() })?;
    let (sys, q0) = prepare(model, &settings)?;
    let n_free = crate::analysis::modes::unconstrained(&sys);
    if o.count == 0 || o.count > n_free {
        return Err(Error::option(
            "count",
            Some(o.count.to_string()),
            format!(
            "{} has {n_free} unconstrained coordinates ({} coordinates less {} constraint rows); ask for 1 to {n_free}",
            model.path.display(),
            q0.len(),
            q0.len() - n_free
        ),
        ));
    }
    let start = std::time::Instant::now();
    let q = match o.at {
        ModesAt::Initial => q0,
        ModesAt::Static => {
            let so = StaticOptions { mu: mu.clone(), t: o.time, steps: 1, solver: o.solver };
            let (r, _) = statics(model, &so).map_err(|e| e.at_stage("statics", &mu))?;
            r.q.column(r.q.ncols() - 1).to_vec()
        }
    };
    let modes = crate::analysis::modes::compute(&sys, &mu, &q, o.time, o.count, o.solver)
        .map_err(|e| e.at_stage("modes", &mu))?;
    Ok(ModesAnalysis { modes, q, mu, seconds: start.elapsed().as_secs_f64() })
}

/// The frequencies the basis `v` (n_dof × r, one column per mode) keeps of `model` at the
/// configuration and parameters of `a` ([`crate::analysis::reduced_modes`]): the lowest
/// `o.count` of the problem projected on it.
pub fn reduced_modes(
    model: &Model,
    a: &ModesAnalysis,
    v: ndarray::ArrayView2<f64>,
    o: &ModesOptions,
) -> Result<crate::analysis::reduced_modes::ReducedModes> {
    let sys = model.system(o.solver);
    crate::analysis::reduced_modes::compute(&sys, &a.mu, &a.q, o.time, v, o.count)
        .map_err(|e| e.at_stage("modes --basis", &a.mu))
}

/// The strain and the curvature series (each `(name, values at every instant)`) of the
/// probes that record them, in probe order; `series(p)` is the probe's (strain, curvature)
/// at every instant.
pub fn probe_sections(probes: &[Probe], series: impl Fn(&Probe) -> Vec<(f64, f64)>) -> (Series, Series) {
    let (mut strains, mut curvatures) = (Vec::new(), Vec::new());
    for p in probes.iter().filter(|p| p.strain || p.curvature) {
        let values = series(p);
        if p.strain {
            strains.push((p.name.clone(), values.iter().map(|v| v.0).collect()));
        }
        if p.curvature {
            curvatures.push((p.name.clone(), values.iter().map(|v| v.1).collect()));
        }
    }
    (strains, curvatures)
}

#[cfg(test)]
mod limits_tests {
    use super::*;
    use crate::limits::Limits;

    /// Two models with different bounds in one process: each stage keeps to its own
    /// model's (no process-wide setting, so a library caller's choice cannot leak into
    /// another's). The pendulum (data/models/pendulum.toml: 1.1 s at dt 0.005 s) is 220
    /// steps and 50 elements.
    #[test]
    fn each_model_keeps_to_its_own_limits() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/models/pendulum.toml");
        let tight = Limits { max_steps: 100, ..Limits::from_env_or_defaults() };
        let few = Limits { max_elements: 10, ..Limits::from_env_or_defaults() };
        let e = Model::load_with(path, few).expect_err("50 elements over a bound of 10").to_string();
        assert!(e.contains("over the limit of 10"), "{e}");
        let bounded = Model::load_with(path, tight).unwrap();
        let free = Model::load(path).unwrap();
        let e = Settings::resolve(&bounded, &Overrides::default()).expect_err("220 steps over 100").to_string();
        assert!(e.contains("over the limit of 100 steps"), "{e}");
        assert_eq!(Settings::resolve(&free, &Overrides::default()).unwrap().n_steps, 220);
        // the blow-up switch travels with the model into its runs' settings
        let lenient = Model::load_with(path, Limits { allow_blowup: true, ..Limits::from_env_or_defaults() }).unwrap();
        assert!(Settings::resolve(&lenient, &Overrides::default()).unwrap().allow_blowup);
        assert!(!Settings::resolve(&free, &Overrides::default()).unwrap().allow_blowup);
    }
}
