//! The record of a training: what `train` returns (`TrainSummary`) and what the greedy loop did
//! (`GreedyRecord`, written under `/training` in the basis file).

use crate::reduction::Trained;
use crate::rom::estimator::{ErrorMeasure, EstimateMethod, Estimator};
use crate::solver::parameters::Parameters;
use crate::training::greedy::CandidateSet;

pub struct TrainSummary {
    pub trained: Trained,
    pub n_snapshots: usize,
    pub full_seconds: f64,
    /// full runs made (greedy: with the last, held-out check run;
    /// [`Self::n_training_runs`] + [`Self::n_held_out`])
    pub n_runs: usize,
    /// what the greedy loop did (`/training` in the basis file); `None` for `load_scales`
    pub greedy: Option<GreedyRecord>,
    /// the error estimator (uncalibrated for `load_scales` training: no held-out runs;
    /// greedy training calibrates it on its held-out full runs)
    pub estimator: Option<Estimator>,
    /// what the user should hear of the training beside its result (a greedy loop that ran
    /// out of full runs), one line each; the caller shows them
    pub warnings: Vec<String>,
}

impl TrainSummary {
    /// The full runs whose snapshots the basis holds.
    pub fn n_training_runs(&self) -> usize {
        self.greedy.as_ref().map_or(self.n_runs, |g| g.runs.len().min(self.n_runs))
    }

    /// The full runs made only to check the basis (greedy's last run when it converged): not
    /// in the basis.
    pub fn n_held_out(&self) -> usize {
        self.n_runs - self.n_training_runs()
    }

    /// The points of the held-out runs.
    pub fn held_out_points(&self) -> Vec<Parameters> {
        let Some(g) = &self.greedy else { return Vec::new() };
        let runs = g.iterations.iter().filter_map(|i| i.run_candidate).map(|c| &g.candidates.points[c]);
        runs.filter(|mu| !g.runs.contains(mu)).cloned().collect()
    }

    /// "3 training runs + 1 held-out check" (a held-out run is not in the basis), or "3
    /// full run(s)" without one.
    pub fn runs_text(&self) -> String {
        match self.n_held_out() {
            0 => format!("{} full run(s)", self.n_runs),
            h => format!(
                "{} training run{} + {h} held-out check{}",
                self.n_training_runs(),
                if self.n_training_runs() == 1 { "" } else { "s" },
                if h == 1 { "" } else { "s" }
            ),
        }
    }
}

/// One pass of the loop: the basis it chose and where its estimate was worst.
#[derive(Clone, Debug)]
pub struct Iteration {
    /// the energy tolerance ε chosen (NaN when `reduction.modes` is given)
    pub energy: f64,
    /// ECSW τ (NaN without hyper-reduction)
    pub hyper_tolerance: f64,
    /// POD modes per block
    pub block_modes: Vec<usize>,
    /// reduced coordinates (POD modes and kept joint coordinates)
    pub n_modes: usize,
    /// sampled elements (all of them without hyper-reduction)
    pub n_elements: usize,
    /// the score at every candidate (`GreedyRecord::candidates` order; module documentation)
    pub estimates: Vec<f64>,
    /// the whole-run error estimate at every candidate
    pub whole_run_estimates: Vec<f64>,
    /// the reduced model's whole-run sensitivity at every candidate
    pub sensitivity: Vec<f64>,
    /// the candidate with the largest score
    pub worst_candidate: usize,
    pub worst_estimate: f64,
    /// where this iteration ran the full model: the worst candidate without a full run yet
    /// (`None` when no run was made)
    pub run_candidate: Option<usize>,
    /// the true rel_error of this iteration's basis at `run_load`, from the full run there
    /// (NaN when no run was made)
    pub true_error: f64,
    /// the true error's score at `run_load` (as the estimates': held to the sensitivity where
    /// the model is sensitive; NaN when no run was made)
    pub true_score: f64,
    /// the estimate at `run_load` over the true error there, the held-out check of the
    /// estimate itself (NaN when no run was made)
    pub held_out_effectivity: f64,
    /// the method the candidates' estimates were made with
    pub method: EstimateMethod,
    /// what the estimate may reach between the candidates (the greedy module
    /// documentation, "Meeting T over the range"), after looking between them
    pub bound: f64,
    /// the points between candidates the bound looked at
    pub between_points: usize,
}

/// What the greedy loop did: written under `/training` in the basis file.
#[derive(Clone, Debug)]
pub struct GreedyRecord {
    /// the load range; `None` for a box (the candidates' space)
    pub range: Option<(f64, f64)>,
    pub tolerance: f64,
    pub max_runs: usize,
    pub candidates: CandidateSet,
    /// the points whose snapshots the basis holds, in run order
    pub runs: Vec<Parameters>,
    pub iterations: Vec<Iteration>,
    /// every candidate's estimate ≤ T and the held-out check run within T
    pub converged: bool,
    /// full runs made, the held-out check included
    pub full_runs: usize,
    /// the estimate training ended with (`corrected`, or `enriched` when a held-out check
    /// found the correction off)
    pub method: EstimateMethod,
    /// the error `tolerance`, the scores and the true errors are in
    pub measure: ErrorMeasure,
    /// the converged held-out check's error above the tolerance, in words (within the
    /// model's own sensitivity there; `/training` attribute `held_out_note`); `None` when it
    /// was within the tolerance or no check ran
    pub held_out_note: Option<String>,
    /// the online default (`defects`) may read above the tolerance between the candidates
    /// where training's own estimate met it, in words (`/training` attribute
    /// `estimate_note`); `None` where it stays within
    pub estimate_note: Option<String>,
}

impl GreedyRecord {
    /// The load scales of the runs whose snapshots the basis holds (`/training/load_scales`).
    pub fn load_scales(&self) -> Vec<f64> {
        self.runs.iter().map(Parameters::scale).collect()
    }

    /// The candidates' load scales (`/training/candidates` on a line).
    pub fn candidate_loads(&self) -> Vec<f64> {
        self.candidates.loads()
    }

    /// The `mode_rule` attribute of the basis file.
    pub fn mode_rule(&self) -> String {
        match self.iterations.last() {
            Some(it) if it.energy.is_finite() => {
                format!(
                    "greedy: energy = {:e} per block ({}), hyper tolerance {:e}",
                    it.energy,
                    modes_text(&it.block_modes),
                    it.hyper_tolerance
                )
            }
            Some(it) => format!("greedy: {}", modes_text(&it.block_modes)),
            None => "greedy".into(),
        }
    }
}

pub(super) fn modes_text(block_modes: &[usize]) -> String {
    let v: Vec<String> = block_modes.iter().map(|m| m.to_string()).collect();
    format!("{} modes", v.join(" + "))
}

/// Writes `/training` (the basis file's layout: src/io/basis_file.rs): on a line the load
/// range, candidates and runs as load scales; in a box as points (`candidate_points`,
/// `points`, `worst_point`, `run_point`: one column per parameter, named by the attribute
/// `parameters`).
pub fn write_training(f: &hdf5::File, r: &GreedyRecord) -> hdf5::Result<()> {
    use crate::io::h5::{attr_str, attr_u64};
    use ndarray::{arr0, Array1, Array2};
    let g = f.create_group("training")?;
    let col = |get: &dyn Fn(&Iteration) -> f64| Array1::from_iter(r.iterations.iter().map(get));
    let c = &r.candidates;
    let candidate = |i: Option<usize>| i.map(|i| &c.points[i]);
    if let Some(range) = r.range {
        let load = |mu: Option<&Parameters>| mu.map_or(f64::NAN, Parameters::scale);
        g.new_dataset_builder().with_data(&Array1::from(vec![range.0, range.1])).create("range")?;
        g.new_dataset_builder()
            .with_data(&Array1::from_iter(r.runs.iter().map(Parameters::scale)))
            .create("load_scales")?;
        g.new_dataset_builder().with_data(&Array1::from(c.loads())).create("candidates")?;
        g.new_dataset_builder().with_data(&col(&|i| load(candidate(Some(i.worst_candidate))))).create("worst_load")?;
        g.new_dataset_builder().with_data(&col(&|i| load(candidate(i.run_candidate)))).create("run_load")?;
    } else {
        let names: Vec<&str> = c.space.names().collect();
        let table = |rows: Vec<Option<&Parameters>>| {
            Array2::from_shape_fn((rows.len(), names.len()), |(i, j)| {
                rows[i].map_or(f64::NAN, |mu| mu.get(names[j]).unwrap_or(1.0))
            })
        };
        let its = &r.iterations;
        for (name, rows) in [
            ("candidate_points", c.points.iter().map(Some).collect::<Vec<_>>()),
            ("points", r.runs.iter().map(Some).collect()),
            ("worst_point", its.iter().map(|i| candidate(Some(i.worst_candidate))).collect()),
            ("run_point", its.iter().map(|i| candidate(i.run_candidate)).collect()),
        ] {
            let d = g.new_dataset_builder().with_data(&table(rows)).create(name)?;
            attr_str(&d, "parameters", &names.join(","))?;
        }
    }
    g.new_dataset_builder().with_data(&arr0(r.tolerance)).create("tolerance")?;
    g.new_dataset_builder().with_data(&col(&|i| i.worst_estimate)).create("worst_estimate")?;
    g.new_dataset_builder().with_data(&col(&|i| i.true_error)).create("true_error")?;
    g.new_dataset_builder().with_data(&col(&|i| i.energy)).create("energy_tolerance")?;
    g.new_dataset_builder().with_data(&col(&|i| i.hyper_tolerance)).create("hyper_tolerance")?;
    g.new_dataset_builder()
        .with_data(&Array1::from_iter(r.iterations.iter().map(|i| i.n_modes as u64)))
        .create("n_modes")?;
    g.new_dataset_builder()
        .with_data(&Array1::from_iter(r.iterations.iter().map(|i| i.n_elements as u64)))
        .create("n_elements")?;
    let (ni, nc) = (r.iterations.len(), c.len());
    let table = |get: &dyn Fn(&Iteration) -> &Vec<f64>| {
        Array2::from_shape_fn((ni, nc), |(i, j)| get(&r.iterations[i]).get(j).copied().unwrap_or(f64::NAN))
    };
    g.new_dataset_builder().with_data(&table(&|i| &i.estimates)).create("estimates")?;
    g.new_dataset_builder().with_data(&table(&|i| &i.whole_run_estimates)).create("whole_run_estimates")?;
    g.new_dataset_builder().with_data(&table(&|i| &i.sensitivity)).create("sensitivity")?;
    g.new_dataset_builder().with_data(&col(&|i| i.true_score)).create("true_score")?;
    g.new_dataset_builder().with_data(&col(&|i| i.bound)).create("bound")?;
    g.new_dataset_builder()
        .with_data(&Array1::from_iter(r.iterations.iter().map(|i| i.between_points as u64)))
        .create("between_points")?;
    g.new_dataset_builder().with_data(&col(&|i| i.held_out_effectivity)).create("held_out_effectivity")?;
    attr_str(&g, "estimate_method", r.method.name())?;
    attr_str(&g, "measure", r.measure.name())?;
    for (name, note) in [("held_out_note", &r.held_out_note), ("estimate_note", &r.estimate_note)] {
        if let Some(note) = note {
            attr_str(&g, name, note)?;
        }
    }
    attr_str(&g, "method", "greedy")?;
    attr_u64(&g, "iterations", ni as u64)?;
    attr_u64(&g, "max_runs", r.max_runs as u64)?;
    attr_u64(&g, "full_runs", r.full_runs as u64)?;
    attr_u64(&g, "converged", r.converged as u64)
}
