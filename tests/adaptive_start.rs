//! The adaptive start (`Predictor::Adaptive`, the default; src/solver/predictor.rs) on
//! models nobody tuned it on: the first draw of every slot of the zoo (tests/common/zoo,
//! seed 2026), each run in full at the load range's ends and at λ = 1, once with each
//! fixed start and once with the adaptive one.
//!
//! What must hold:
//! * every run that any fixed start completes, the adaptive start completes too (a default
//!   that loses a model a fixed start runs is no default);
//! * it completes more of them than the zero-acceleration start, the default before
//!   2026-11-27 (measured: 67 of 72 against 62; constant velocity and constant position 67:
//!   the zero-acceleration start's failures are step halvings past the run's budget and
//!   strain blow-ups, mostly on stiff bodies without numerical damping, `rho_inf` = 1);
//! * over the runs all four complete, its Newton iterations are within 5 % of the best
//!   fixed start's, run by run, summed (measured: 0.98×; the wrong fixed start takes up to
//!   3.8× them, zero acceleration on a frame, and 2.3×, constant position on the shipped
//!   double pendulum), and no run takes more than 1.3× them (measured: at most 1.06×);
//! * on those runs it halves no more steps than the best fixed start (measured: none;
//!   zero acceleration 41, constant velocity 11, constant position none, the adaptive start
//!   of 2026-11-27, which chose between the first two only and started a run at zero
//!   acceleration, 8). A halved step is where a full run and its reduced run part: they
//!   then solve different discretizations (src/workflows/validate.rs).

#[path = "common/zoo/mod.rs"]
mod zoo;

use flexrom::model::Model;
use flexrom::simulate::{integrate, prepare, Overrides, Settings};
use flexrom::solver::generalized_alpha::Predictor;
use flexrom::solver::model::{Bound, Parameters};

/// Newton iterations and halved steps of the full run of `model` at `scale` with
/// `predictor`, or why it failed.
fn iterations(model: &Model, scale: f64, predictor: Predictor) -> Result<(usize, usize), String> {
    let mut s = Settings::resolve(model, &Overrides::at(&Parameters::load_scale(scale))).map_err(|e| e.to_string())?;
    s.params.predictor = predictor;
    let (mut sys, q0) = prepare(model, &s).map_err(|e| e.to_string())?;
    let mu = s.mu.clone();
    let stats = integrate(&mut Bound::new(&mut sys, &mu), &s, q0, |_, _| {}).map_err(|e| e.to_string())?;
    Ok((stats.newton_iterations, stats.step_cuts))
}

#[test]
fn the_adaptive_start_runs_what_any_fixed_start_runs_at_the_best_ones_cost() {
    let starts =
        [Predictor::ZeroAcceleration, Predictor::ConstantVelocity, Predictor::ConstantPosition, Predictor::Adaptive];
    let (mut completed, mut runs) = ([0usize; 4], 0);
    let (mut sum_best, mut sum_adaptive, mut worst_ratio) = (0usize, 0usize, 0.0_f64);
    let mut cuts = [0usize; 4];
    for slot in 0..24 {
        let m = zoo::draw(zoo::DEFAULT_SEED, slot, 0);
        let model = Model::from_text(&m.mechanism.toml, format!("{}.toml", m.name())).unwrap();
        for scale in [zoo::RANGE.0, 1.0, zoo::RANGE.1] {
            runs += 1;
            let r: Vec<Result<(usize, usize), String>> = starts.iter().map(|&p| iterations(&model, scale, p)).collect();
            for (c, x) in completed.iter_mut().zip(&r) {
                *c += x.is_ok() as usize;
            }
            eprintln!("{} λ = {scale}: {:?}", m.name(), r.iter().map(|x| x.as_ref().ok()).collect::<Vec<_>>());
            if r[..3].iter().any(|x| x.is_ok()) {
                assert!(
                    r[3].is_ok(),
                    "{} at λ = {scale}: a fixed start ran, the adaptive one failed: {:?}",
                    m.name(),
                    r[3]
                );
            }
            if let [Ok(za), Ok(cv), Ok(cp), Ok(ad)] = &r[..] {
                let best = za.0.min(cv.0).min(cp.0);
                sum_best += best;
                sum_adaptive += ad.0;
                worst_ratio = worst_ratio.max(ad.0 as f64 / best as f64);
                for (c, x) in cuts.iter_mut().zip([za, cv, cp, ad]) {
                    *c += x.1;
                }
            }
        }
    }
    let total = sum_adaptive as f64 / sum_best as f64;
    eprintln!(
        "completed of {runs} (zero acceleration, constant velocity, constant position, adaptive): {completed:?}; \
         adaptive iterations {total:.3}× the best fixed start's in sum, at most {worst_ratio:.3}× in one run; \
         halved steps where all complete: {cuts:?}"
    );
    assert!(completed[3] > completed[0], "completed {completed:?} of {runs}");
    assert!(total <= 1.05, "adaptive {total:.3}× the best fixed start's iterations");
    assert!(worst_ratio <= 1.3, "one run took {worst_ratio:.3}× the best fixed start's iterations");
    assert!(cuts[3] <= *cuts[..3].iter().min().unwrap(), "halved steps {cuts:?}");
}

/// A moment applied at t₀ to a slender arm of stiff links (the zoo's `11-driven-arm`: glass
/// fibre and aluminium, Δt = 0.01 s, far beyond the links' axial periods): the consistent
/// initial accelerations are set by what the step resolves least, and the zero-acceleration
/// guess they enter lies 10² m off on a one-metre arm (first residual 4e11 against 2e2 at
/// rest); its first step is halved. The adaptive start begins a run from constant velocity
/// (here: at rest) and halves no step at any of the three loads (measured: none; 2, 3 and 3
/// halved steps with the adaptive start of 2026-11-27), so a reduced run, which halves
/// none either, solves the same discretization as the full one.
#[test]
fn a_load_applied_at_the_start_halves_no_step_of_the_adaptive_start() {
    let m = zoo::draw(zoo::DEFAULT_SEED, 11, 0);
    assert_eq!(m.name(), "11-driven-arm");
    let model = Model::from_text(&m.mechanism.toml, format!("{}.toml", m.name())).unwrap();
    let cut_times = |scale: f64, predictor| {
        let mut s = Settings::resolve(&model, &Overrides::at(&Parameters::load_scale(scale))).unwrap();
        s.params.predictor = predictor;
        let (mut sys, q0) = prepare(&model, &s).unwrap();
        let mu = s.mu.clone();
        integrate(&mut Bound::new(&mut sys, &mu), &s, q0, |_, _| {}).unwrap().step_cut_times
    };
    for scale in [zoo::RANGE.0, 1.0, zoo::RANGE.1] {
        assert_eq!(cut_times(scale, Predictor::Adaptive), Vec::<f64>::new(), "λ = {scale}");
    }
    // what the first step avoids: from zero acceleration it is halved
    assert_eq!(cut_times(zoo::RANGE.0, Predictor::ZeroAcceleration).first(), Some(&0.0));
}
