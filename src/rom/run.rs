//! A reduced model's runs: the reduced model of a basis projected once from the model's
//! shared physics, run at any parameters, its trajectory reconstructed where asked.

use crate::error::{Error, Result};
use crate::model::{Model, SharedPhysics};
use crate::physics::system::FlexibleSystem;
use crate::reduction::{Basis, Hyper, HyperReducedModel, Reduced, ReducedModel};
use crate::simulate::{Overrides, Settings, SimulationResult};
use crate::solver::model::{Parameters, ParametricModel};
use ndarray::{Array1, Array2, ArrayView1, ArrayView2};
use std::sync::Arc;

/// A reduced run: the full-coordinate result (same layout as `simulate`) and the reduced
/// trajectory. `result.wall_seconds` is the reduced time loop alone.
#[derive(Clone, Debug)]
pub struct ReducedRun {
    pub result: SimulationResult,
    /// r × n_t
    pub reduced_q: Array2<f64>,
}

/// What the run writes: the full coordinates (`online`, `validate`) or only the reduced
/// ones and the probes (`sweep`: nothing of size n_dof, probes from their own rows of V).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    Full,
    ReducedAndProbes,
}

/// The reduced model of a basis, built once and run at as many load scales as wanted (a
/// sweep keeps one per thread: building it projects every element, ~1 ms on the four-bar).
pub struct ReducedRunner {
    model: Arc<Model>,
    basis: Arc<Basis>,
    rom: Kind,
    /// the initial configuration in reduced coordinates, `Vᵀ(x₀ − x_ref)`: the same for
    /// every run, projected once (O(n_dof r), what a run of a refined mesh would otherwise
    /// spend most of its time on)
    q0: Vec<f64>,
    /// the initial velocities' reduced coordinates
    v0: Vec<f64>,
}

/// The hyper-reduced model when the basis carries a sampled set; without one, every element
/// at weight 1, which is plain Galerkin (to round-off, tests/hyper.rs) through the cheaper
/// per-element Gₑ route; the generic element-by-element projection only for elements that
/// route does not support.
enum Kind {
    Invariant(Box<HyperReducedModel<FlexibleSystem>>),
    Generic(Box<ReducedModel<FlexibleSystem>>),
}

impl ReducedRunner {
    /// Projects the physics of `model` (assembled once per model: [`Model::physics`]) on
    /// `basis`.
    pub fn new(model: &Arc<Model>, basis: &Arc<Basis>) -> Result<Self> {
        Self::with_physics(model, basis, model.physics()?)
    }

    /// Projects the already assembled physics of `model` on `basis`.
    pub fn with_physics(model: &Arc<Model>, basis: &Arc<Basis>, physics: &SharedPhysics) -> Result<Self> {
        let sys = Arc::clone(&physics.sys);
        let q0 = basis.reduce(ArrayView1::from(&physics.x0[..])).to_vec();
        let v0 = basis.reduce_increment(ArrayView1::from(&physics.v0[..])).to_vec();
        let (model, basis) = (Arc::clone(model), Arc::clone(basis));
        let cannot = |e: Error| e.context("cannot build the reduced model");
        let rom = match &basis.hyper {
            Some(h) => Kind::Invariant(Box::new(HyperReducedModel::new(sys, &basis, h).map_err(cannot)?)),
            None if HyperReducedModel::<FlexibleSystem>::supports(&sys) => {
                let all = Hyper::all(sys.n_elements());
                Kind::Invariant(Box::new(HyperReducedModel::new(sys, &basis, &all).map_err(cannot)?))
            }
            None => Kind::Generic(Box::new(ReducedModel::new(sys, &basis).map_err(cannot)?)),
        };
        Ok(ReducedRunner { model, basis, rom, q0, v0 })
    }

    /// Runs at `load_scale` with the model's time settings. With `previous` runs (a
    /// continuation in the load scale) each step's Newton solve starts from their
    /// increment of that step, extrapolated linearly in the load scale,
    ///
    /// ```text
    ///     Δq_k(λ) ≈ Δq_k(λ₁) + (λ − λ₁)/(λ₁ − λ₂) · (Δq_k(λ₁) − Δq_k(λ₂)),
    /// ```
    ///
    /// and, with the default within-step reuse
    /// ([`JacobianReuse`](crate::solver::generalized_alpha::JacobianReuse)), keeps the
    /// factorized matrix of a good guess. Only the starting point changes: every step
    /// stops on the same tolerance as a run on its own.
    ///
    /// The reduced model is not changed by the parameters (it keeps its projected loads
    /// unscaled), so runs at any sequence of parameters give what fresh models give.
    pub fn solve(&mut self, mu: &Parameters, output: Output, previous: &[&ReducedRun]) -> Result<ReducedRun> {
        let s = settings_at(&self.model, mu)?;
        let previous = &previous[previous.len().saturating_sub(2)..];
        let (model, basis, q0) = (&*self.model, &*self.basis, (&self.q0[..], &self.v0[..]));
        let result = match &mut self.rom {
            Kind::Invariant(rom) => run(rom.as_mut(), model, basis, s, q0, output, previous),
            Kind::Generic(rom) => run(rom.as_mut(), model, basis, s, q0, output, previous),
        };
        result.map_err(|e| crate::reduction::whole_system::explain_failure(e, basis.variant, mu))
    }
}

/// The settings of a reduced run of `model` at the parameters `mu`: the model file's time
/// settings (what `online` plans its result file from, before the run).
pub fn settings_at(model: &Model, mu: &Parameters) -> Result<Settings> {
    Settings::resolve(model, &Overrides::at(mu))
}

/// Refuses `runs` reduced runs of `r` coordinates over `n_steps` whose kept arrays would
/// not fit the memory bound: `8 n_t (4 r + n_c + n_pv + 1)` each (z, ż and z̈ by instant and
/// z by mode, the reduced multipliers, the probes' values, t), plus the full coordinates
/// and velocities and the multipliers `8 n_t (2 n_dof + n_c)` when they are reconstructed
/// ([`crate::limits`]).
pub fn check_reduced_memory(model: &Model, r: usize, n_steps: usize, output: Output, runs: f64) -> Result<()> {
    let z = model.sizes();
    let nt = n_steps as f64 + 1.0;
    let full = if output == Output::Full { 2.0 * z.n_dof + z.n_constraints } else { 0.0 };
    let bytes = runs * 8.0 * nt * (4.0 * r as f64 + z.n_constraints + z.n_probe_values + 1.0 + full);
    let what = if runs > 1.0 {
        format!(
            "{runs} reduced runs of {n_steps} steps × {r} modes{}",
            if full > 0.0 { " with their full coordinates" } else { "" }
        )
    } else {
        format!("a reduced run of {n_steps} steps × {r} modes")
    };
    model.limits.check_memory(&what, bytes)
}

/// The reduced model's own static equilibrium under the run's loads at t = 0 (`[initial]
/// static = true`, as full runs start from the full model's): Newton on the reduced KKT
/// system from the reduced coordinates `z0` (the undeformed state's), the whole load at once
/// (the reduced model has no load ramp of its own; a load the full model needed steps for
/// is refused with the reason). Starting at the reduced model's equilibrium, the run starts
/// at rest without the jolt of the projected full equilibrium's residual. `whose` names the
/// model in the message (the reduced model's, the error estimator's enriched model's).
pub(crate) fn static_start<R: Reduced<FlexibleSystem>>(
    rom: &mut R,
    s: &Settings,
    z0: Vec<f64>,
    whose: &str,
) -> Result<Vec<f64>> {
    use crate::analysis::statics::{MAX_ITERATIONS, TOLERANCE};
    let mut z = z0;
    let mut bound = crate::solver::model::Bound::new(rom, &s.mu);
    crate::solver::statics::solve_static(&mut bound, &mut z, 0.0, TOLERANCE, MAX_ITERATIONS).map_err(|e| {
        if e.is_numerical() {
            Error::usage(format!("[initial] static: {whose} static equilibrium under the run's loads: {e}"))
        } else {
            e
        }
    })?;
    Ok(z)
}

/// The physical multipliers (n_c × n_t, `n_c` the full model's constraints) of a reduced
/// model's own multipliers `own` (columns: instants at `t`) along its trajectory, given by
/// instant (`[q, q̇, q̈]`, n_t × r each), over the first `taken` instants, moved to hold every
/// body's balance of momentum ([`Reduced::balance`]); NaN after them and where the variant
/// has none. Made after a time loop, so that the loop allocates nothing for them.
pub(crate) fn physical_multipliers<F, R: Reduced<F>>(
    rom: &R,
    n_c: usize,
    (mu, t): (&Parameters, &[f64]),
    states: [ArrayView2<f64>; 3],
    own: ArrayView2<f64>,
    taken: usize,
) -> Array2<f64> {
    let mut out = Array2::from_elem((n_c, own.ncols()), f64::NAN);
    let taken = taken.min(own.ncols());
    let along = states.map(|x| x.slice_move(ndarray::s![..taken, ..]));
    if let Some(l) = rom.multipliers_along(along[0], own.slice(ndarray::s![.., ..taken])) {
        let mut kept = out.slice_mut(ndarray::s![.., ..taken]);
        kept.assign(&l);
        rom.balance(mu, &t[..taken], along, kept);
    }
    out
}

fn run<R: Reduced<FlexibleSystem>>(
    rom: &mut R,
    model: &Model,
    basis: &Basis,
    s: Settings,
    (q0, v0): (&[f64], &[f64]),
    output: Output,
    previous: &[&ReducedRun],
) -> Result<ReducedRun> {
    let (r, nt) = (rom.n_dof(), s.n_steps + 1);
    check_reduced_memory(model, r, s.n_steps, output, 1.0)?;
    let q0 =
        if model.starts_static() { static_start(rom, &s, q0.to_vec(), "the reduced model's")? } else { q0.to_vec() };
    let v0 = v0.to_vec();
    // the state by instant (z, ż, z̈: n_t × r), rows written whole: the multipliers'
    // balance reads it so, and `z` is laid out by mode after the loop
    let mut by_instant = [Array2::zeros((nt, r)), Array2::zeros((nt, r)), Array2::zeros((nt, r))];
    let mut lam = Array2::<f64>::zeros((rom.n_constraints(), nt));
    let mut t = Array1::zeros(nt);
    // (λᵢ, trajectory) of the earlier runs that fit this one, nearest last
    let known: Vec<(f64, &Array2<f64>)> = previous
        .iter()
        .filter(|p| p.reduced_q.dim() == (r, nt))
        .map(|p| (p.result.settings.mu.scale(), &p.reduced_q))
        .collect();
    let x = s.mu.scale();
    let guess = |k: usize, out: &mut [f64]| match known.as_slice() {
        [] => false,
        [.., (l2, z2), (l1, z1)] if l1 != l2 => {
            let f = (x - l1) / (l1 - l2);
            for (i, o) in out.iter_mut().enumerate() {
                let (d1, d2) = (z1[[i, k]] - z1[[i, k - 1]], z2[[i, k]] - z2[[i, k - 1]]);
                *o = d1 + f * (d1 - d2);
            }
            true
        }
        [.., (_, z1)] => {
            for (i, o) in out.iter_mut().enumerate() {
                *o = z1[[i, k]] - z1[[i, k - 1]];
            }
            true
        }
    };
    let start = std::time::Instant::now();
    let stats = crate::simulate::solve(rom, &s, (q0, v0), guess, |k, st| {
        t[k] = st.t;
        for (to, from) in by_instant.iter_mut().zip([&st.q, &st.v, &st.qdd]) {
            to.row_mut(k).assign(&ArrayView1::from(from));
        }
        lam.column_mut(k).assign(&ArrayView1::from(&st.lambda));
    })?;
    let wall_seconds = start.elapsed().as_secs_f64();
    // reconstruct only what is written out
    let full = rom.full();
    let n_c = full.n_constraints();
    // the physical multipliers in either output: the reactions and their estimates read them
    let multipliers = physical_multipliers(
        rom,
        n_c,
        (&s.mu, t.as_slice().expect("contiguous")),
        by_instant.each_ref().map(|x| x.view()),
        lam.view(),
        nt,
    );
    let zq = by_instant[0].t().as_standard_layout().into_owned();
    let (q, qd) = match output {
        // q̇ = V ż: the reference is constant
        Output::Full => (basis.reconstruct_columns(zq.view()), basis.modes.dot(&by_instant[1].t())),
        Output::ReducedAndProbes => (Array2::zeros((0, nt)), Array2::zeros((0, nt))),
    };
    let values = super::probes::probe_values(full, basis, zq.view());
    Ok(ReducedRun {
        result: SimulationResult {
            model_text: model.text.clone(),
            model_path: model.path.display().to_string(),
            settings: s,
            t,
            q,
            qd,
            multipliers,
            probes: values.positions,
            strains: values.strains,
            curvatures: values.curvatures,
            stats,
            wall_seconds,
            // computed where written (workflows::online::answer), not in every reduced run
            energy: None,
        },
        reduced_q: zq,
    })
}
