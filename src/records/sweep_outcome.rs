//! What a sweep produced: the outcome of every load scale (done, failed, not run yet), the
//! status codes of the sweep file's `/status`, and the one-line summary of the failures.

use super::validation::Validation;
use crate::rom::estimator::Estimate;
use crate::rom::warnings::Answered;
use crate::rom::{ReducedRun, Rom};
use crate::solver::parameters::Parameters;
use ndarray::{Array1, Array2};

/// Status codes of `/status`.
pub const STATUS_OK: u8 = 0;
pub const STATUS_FAILED: u8 = 1;
pub const STATUS_PENDING: u8 = 2;

pub struct SweepPoint {
    /// the run: the reduced one with its reduced coordinates, or in a full sweep the full
    /// one (its probes and statistics; no coordinates are kept, `reduced_q` has no rows)
    pub run: ReducedRun,
    pub validation: Option<Validation>,
    /// the full run's probe positions (name, n_t × 2), with the validation
    pub full_probes: Option<Vec<(String, Array2<f64>)>>,
    /// the run's error estimate (None: no estimator)
    pub estimate: Option<Estimate>,
    /// outside the training range
    pub extrapolated: bool,
    /// `Some(why)`: the full model answered this point in place of the reduced one
    /// ([`crate::pipeline::fallback::Fallback::Full`]): `run` is the full run (its probes; no reduced
    /// coordinates), `estimate` [`Estimate::exact`]
    pub fallback: Option<String>,
    /// a reduced answer's note: the full model was run in its place and failed
    /// ([`crate::pipeline::fallback::FULL_TRIED`])
    pub note: Option<String>,
}

/// What became of one load scale.
// one per load scale, built once and moved into place: the size difference costs nothing
#[allow(clippy::large_enum_variant)]
pub enum Outcome {
    Done(SweepPoint),
    /// the error message of its run
    Failed(String),
    /// not run (yet)
    Pending,
}

pub struct ScaleResult {
    /// the point's parameters
    pub mu: Parameters,
    pub outcome: Outcome,
}

impl SweepPoint {
    /// The value of `/fallback`: 0 the reduced answer, 1 the full model's in its place, 2
    /// the reduced answer kept where the full model was tried and failed.
    pub fn fallback_code(&self) -> u8 {
        match (&self.fallback, &self.note) {
            (Some(_), _) => 1,
            (None, Some(_)) => 2,
            (None, None) => 0,
        }
    }
}

impl ScaleResult {
    pub fn point(&self) -> Option<&SweepPoint> {
        match &self.outcome {
            Outcome::Done(p) => Some(p),
            _ => None,
        }
    }

    pub fn status(&self) -> u8 {
        match self.outcome {
            Outcome::Done(_) => STATUS_OK,
            Outcome::Failed(_) => STATUS_FAILED,
            Outcome::Pending => STATUS_PENDING,
        }
    }

    pub fn message(&self) -> &str {
        match &self.outcome {
            Outcome::Done(p) => p.fallback.as_deref().or(p.note.as_deref()).unwrap_or(""),
            Outcome::Failed(m) => m,
            Outcome::Pending => "not run yet",
        }
    }
}

pub struct Sweep {
    /// every requested load scale, in the order asked for
    pub scales: Vec<ScaleResult>,
    /// the time grid and probe names every run shares (from the model)
    pub t: Array1<f64>,
    pub probe_names: Vec<String>,
    /// the probes that record strain, and those that record curvature (from the model)
    pub section_names: [Vec<String>; 2],
    /// the joints' reaction points, each one's force then each one's moment (from the model)
    pub reactions: Vec<(String, crate::rom::quantities::Quantity)>,
    /// reduced coordinates r (0 in a full sweep)
    pub n_reduced: usize,
    /// the full model at every load (`sweep --full`): exact, no estimate, no validation
    pub full: bool,
    /// the model's fingerprint ([`crate::model::Model::fingerprint`])
    pub model_fingerprint: String,
    pub validated: bool,
    /// what the sweep did where it could not stand behind a reduced answer (attribute
    /// `fallback`; always `None` for full and validated sweeps)
    pub fallback: crate::pipeline::fallback::Fallback,
    pub wall_seconds: f64,
    pub threads: usize,
    pub continuation: bool,
    /// scales taken from an earlier sweep file (`--resume`)
    pub resumed: usize,
}

impl Sweep {
    /// The reduced answers the sweep kept — not the failed points, nor those the full model
    /// answered, which are exact — as the warnings after a sweep read them
    /// ([`Rom::warnings_after`]).
    pub fn answered<'a>(&'a self, rom: &Rom) -> Vec<Answered<'a>> {
        let kept = self.scales.iter().filter_map(|x| Some((&x.mu, x.point()?)));
        kept.filter(|(_, p)| p.fallback.is_none()).map(|(mu, p)| Answered::new(rom, mu, p.estimate.as_ref())).collect()
    }
}

impl Sweep {
    /// The load scales that ran to the end, in order.
    pub fn done(&self) -> impl Iterator<Item = &SweepPoint> {
        self.scales.iter().filter_map(ScaleResult::point)
    }

    /// The load scales not finished yet (failed or not run), which a sweep runs.
    pub fn n_todo(&self) -> usize {
        self.scales.iter().filter(|s| s.status() != STATUS_OK).count()
    }

    pub fn n_failed(&self) -> usize {
        self.scales.iter().filter(|s| s.status() == STATUS_FAILED).count()
    }

    /// The finished points the full model answered in place of the reduced one.
    pub fn n_fallback(&self) -> usize {
        self.done().filter(|p| p.fallback.is_some()).count()
    }

    /// The finished points where the full model was tried in place of the reduced answer
    /// and failed (the reduced answer kept, with its note).
    pub fn n_fallback_failed(&self) -> usize {
        self.done().filter(|p| p.note.is_some()).count()
    }

    /// One line when some load scale failed, naming the first few and their errors:
    /// "2 of 100 load scales failed: load scale 1e20: Newton failed at …; …".
    pub fn failure_summary(&self) -> Option<String> {
        let failed: Vec<&ScaleResult> = self.scales.iter().filter(|s| s.status() == STATUS_FAILED).collect();
        if failed.is_empty() {
            return None;
        }
        // each message names its stage and load scale already (`Error::at_stage`)
        let shown: Vec<String> = failed.iter().take(3).map(|s| s.message().to_string()).collect();
        let more = if failed.len() > 3 { format!("; and {} more", failed.len() - 3) } else { String::new() };
        Some(format!("{} of {} load scales failed: {}{more}", failed.len(), self.scales.len(), shown.join("; ")))
    }
}

/// A copy of a finished point (the resumed ones are taken from the file read back).
pub(crate) fn clone_point(p: &SweepPoint) -> SweepPoint {
    SweepPoint {
        run: p.run.clone(),
        validation: p.validation.clone(),
        full_probes: p.full_probes.clone(),
        estimate: p.estimate.clone(),
        extrapolated: p.extrapolated,
        fallback: p.fallback.clone(),
        note: p.note.clone(),
    }
}
