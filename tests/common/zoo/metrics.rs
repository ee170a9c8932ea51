//! How the zoo judges a basis and its error estimate (docs/zoo.md), and the targets it is
//! held to (docs/zoo.md, "Targets"):
//!
//! ```text
//! coverage      estimate ≥ true rel_error, over the whole run (pairs: model, load) and up
//!               to the end of each fifth (triples: model, load, fifth)
//! effectivity   estimate / true rel_error over the whole run (median, 95th percentile, max)
//! cost          estimate seconds / reduced-run seconds (median over a model's loads)
//! ```
//!
//! A validation that failed (no reduced answer) counts as uncovered; its effectivity as ∞.

use super::drive::{Training, Validation};

/// The zoo's targets over all models together.
pub const MIN_CONVERGED: f64 = 0.90;
pub const MIN_PAIR_COVERAGE: f64 = 0.95;
pub const MIN_TRIPLE_COVERAGE: f64 = 0.90;
pub const MAX_MEDIAN_EFFECTIVITY: f64 = 3.0;
pub const MAX_P95_EFFECTIVITY: f64 = 20.0;
pub const MAX_EFFECTIVITY: f64 = 100.0;
pub const MAX_MEDIAN_COST: f64 = 1.0;

/// A model's estimate fails where it reads under the error or over it by more than the
/// 95th-percentile target.
pub fn estimate_fails(s: &ModelStats) -> bool {
    s.under_pairs > 0 || s.under_triples > 0 || !within(s.effectivity_max, MAX_P95_EFFECTIVITY)
}

/// `x ≤ bound`, with NaN outside every bound.
fn within(x: f64, bound: f64) -> bool {
    matches!(x.partial_cmp(&bound), Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal))
}

/// The median (mean of the middle two); NaN for none.
pub fn median(v: &[f64]) -> f64 {
    let mut v: Vec<f64> = v.to_vec();
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// The `p`-th percentile by nearest rank (the smallest value with ≥ p % of them at or below).
pub fn percentile(v: &[f64], p: f64) -> f64 {
    let mut v: Vec<f64> = v.to_vec();
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    let rank = ((p / 100.0) * v.len() as f64).ceil().max(1.0) as usize;
    v[rank.min(v.len()) - 1]
}

/// One model's numbers at one tolerance.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct ModelStats {
    pub loads: usize,
    pub failed_loads: usize,
    pub covered_pairs: usize,
    pub covered_triples: usize,
    pub under_pairs: usize,
    /// under pairs of runs that gave an answer without warning that the model amplifies
    /// changes of the load there: the estimate read low silently
    pub silent_under_pairs: usize,
    pub under_triples: usize,
    /// coverage per fifth (0..1)
    pub coverage_by_fifth: [f64; 5],
    pub effectivities: Vec<f64>,
    pub effectivity_median: f64,
    pub effectivity_max: f64,
    pub effectivity_min: f64,
    /// the smallest estimate / true ratio over every fifth (below 1: an underestimate)
    pub fifth_effectivity_min: f64,
    pub cost_median: f64,
    pub speedup_median: f64,
    pub rel_error_max: f64,
    pub error_estimate_max: f64,
    pub modes: usize,
    /// loads `sweep --fallback full` answers with the full model ([`fallback_stats`])
    pub fallbacks: usize,
}

fn ratio(e: f64, t: f64) -> f64 {
    if e.is_nan() || t.is_nan() {
        f64::INFINITY
    } else {
        e / t
    }
}

pub fn model_stats(runs: &[Result<Validation, String>]) -> ModelStats {
    let mut s = ModelStats { loads: runs.len(), ..Default::default() };
    let mut fifth_cover = [0usize; 5];
    let (mut costs, mut speedups) = (Vec::new(), Vec::new());
    s.fifth_effectivity_min = f64::INFINITY;
    s.rel_error_max = 0.0;
    s.error_estimate_max = 0.0;
    for r in runs {
        let Ok(v) = r else {
            s.failed_loads += 1;
            s.under_pairs += 1;
            s.under_triples += 5;
            s.effectivities.push(f64::INFINITY);
            continue;
        };
        s.modes = v.n_modes;
        if v.error_estimate >= v.rel_error {
            s.covered_pairs += 1;
        } else {
            s.under_pairs += 1;
            s.silent_under_pairs += usize::from(!v.amplifying);
        }
        for (i, (e, t)) in v.error_estimate_by_time.iter().zip(&v.rel_error_by_time).enumerate() {
            if e >= t {
                s.covered_triples += 1;
                fifth_cover[i] += 1;
            } else {
                s.under_triples += 1;
            }
            s.fifth_effectivity_min = s.fifth_effectivity_min.min(ratio(*e, *t));
        }
        s.effectivities.push(ratio(v.error_estimate, v.rel_error));
        costs.push(v.estimate_seconds / v.rom_seconds);
        speedups.push(v.speedup);
        s.rel_error_max = s.rel_error_max.max(v.rel_error);
        s.error_estimate_max = s.error_estimate_max.max(v.error_estimate);
    }
    let n = runs.len().max(1) as f64;
    s.coverage_by_fifth = fifth_cover.map(|c| c as f64 / n);
    s.effectivity_median = median(&s.effectivities);
    s.effectivity_max = s.effectivities.iter().copied().fold(f64::NAN, f64::max);
    s.effectivity_min = s.effectivities.iter().copied().fold(f64::NAN, f64::min);
    s.cost_median = median(&costs);
    s.speedup_median = median(&speedups);
    s
}

/// Whether `sweep --fallback full` answers a validation's load with the full model (docs/
/// basis-and-sweep.md), by the rule of `flexrom::pipeline::fallback`: the reduced
/// run failed (the zoo validates only where the full model runs: its models are replaced
/// otherwise), its estimate is above the tolerance `tol` (the zoo's pipelines hold it to the
/// training tolerance, relative measure), or training's sensitivity beside the load
/// amplifies beyond the tolerance and the estimate (`Trust::amplifies`; not `validate`'s
/// `amplifying`, which may also read its own full runs, as a sweep does not).
pub fn falls_back(r: &Result<Validation, String>, tol: f64) -> bool {
    match r {
        Err(_) => true,
        Ok(v) => {
            let trust = flexrom::rom::Trust { tolerance: Some(tol), ..flexrom::rom::Trust::range((0.5, 1.5)) };
            !within(v.error_estimate, tol) || trust.amplifies(v.sensitivity_near, Some(v.error_estimate))
        }
    }
}

/// What a sweep with `--fallback full` gives at the validation loads: the loads that fall
/// back ([`falls_back`]) are the full model's answers, exact (covered over the run and in
/// every fifth, no effectivity), the others the reduced answers as [`model_stats`] counts
/// them.
pub fn fallback_stats(runs: &[Result<Validation, String>], tol: f64) -> ModelStats {
    let kept: Vec<Result<Validation, String>> = runs.iter().filter(|r| !falls_back(r, tol)).cloned().collect();
    let exact = runs.len() - kept.len();
    let mut s = model_stats(&kept);
    let n = runs.len().max(1) as f64;
    s.coverage_by_fifth = s.coverage_by_fifth.map(|c| (c * kept.len() as f64 + exact as f64) / n);
    s.loads = runs.len();
    s.covered_pairs += exact;
    s.covered_triples += 5 * exact;
    s.fallbacks = exact;
    s
}

/// The numbers over all models together.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Aggregate {
    pub models: usize,
    pub converged: usize,
    pub pairs: usize,
    pub covered_pairs: usize,
    /// validations whose estimate read below the error without the amplification warning
    pub silent_under_pairs: usize,
    pub triples: usize,
    pub covered_triples: usize,
    pub effectivity_median: f64,
    pub effectivity_p95: f64,
    pub effectivity_max: f64,
    pub cost_median: f64,
    /// loads answered by the full model (the statistics of [`fallback_stats`])
    pub fallbacks: usize,
}

impl Aggregate {
    pub fn share_converged(&self) -> f64 {
        self.converged as f64 / self.models.max(1) as f64
    }
    pub fn pair_coverage(&self) -> f64 {
        self.covered_pairs as f64 / self.pairs.max(1) as f64
    }
    pub fn triple_coverage(&self) -> f64 {
        self.covered_triples as f64 / self.triples.max(1) as f64
    }

    /// The targets missed, one line each (empty: all met).
    pub fn missed(&self) -> Vec<String> {
        let mut out = Vec::new();
        let mut need = |ok: bool, what: String| {
            if !ok {
                out.push(what)
            }
        };
        need(
            self.share_converged() >= MIN_CONVERGED,
            format!("converged {}/{} < {:.0} %", self.converged, self.models, 100.0 * MIN_CONVERGED),
        );
        need(
            self.pair_coverage() >= MIN_PAIR_COVERAGE,
            format!(
                "coverage (model, load) {:.1} % < {:.0} %",
                100.0 * self.pair_coverage(),
                100.0 * MIN_PAIR_COVERAGE
            ),
        );
        need(
            self.triple_coverage() >= MIN_TRIPLE_COVERAGE,
            format!(
                "coverage (model, load, fifth) {:.1} % < {:.0} %",
                100.0 * self.triple_coverage(),
                100.0 * MIN_TRIPLE_COVERAGE
            ),
        );
        need(
            self.effectivity_median <= MAX_MEDIAN_EFFECTIVITY,
            format!("median effectivity {:.3} > {MAX_MEDIAN_EFFECTIVITY}", self.effectivity_median),
        );
        need(
            self.effectivity_p95 <= MAX_P95_EFFECTIVITY,
            format!("95th percentile effectivity {:.3} > {MAX_P95_EFFECTIVITY}", self.effectivity_p95),
        );
        need(
            self.effectivity_max <= MAX_EFFECTIVITY,
            format!("max effectivity {:.3} > {MAX_EFFECTIVITY}", self.effectivity_max),
        );
        need(
            self.cost_median <= MAX_MEDIAN_COST,
            format!("median estimator cost {:.0} % > {:.0} %", 100.0 * self.cost_median, 100.0 * MAX_MEDIAN_COST),
        );
        out
    }
}

/// Over models: each a training (None: it failed) and the statistics of its validations.
pub fn aggregate(models: &[(Option<&Training>, &ModelStats)]) -> Aggregate {
    let mut eff = Vec::new();
    let mut costs = Vec::new();
    let mut a = Aggregate {
        models: models.len(),
        converged: 0,
        pairs: 0,
        covered_pairs: 0,
        silent_under_pairs: 0,
        triples: 0,
        covered_triples: 0,
        effectivity_median: f64::NAN,
        effectivity_p95: f64::NAN,
        effectivity_max: f64::NAN,
        cost_median: f64::NAN,
        fallbacks: 0,
    };
    for (t, s) in models {
        a.converged += usize::from(t.is_some_and(|t| t.converged));
        // a model whose training failed has no validation: all its pairs uncovered
        let loads = if t.is_some() { s.loads } else { super::validation_loads().len() };
        a.pairs += loads;
        a.triples += 5 * loads;
        a.covered_pairs += s.covered_pairs;
        a.silent_under_pairs += s.silent_under_pairs;
        a.covered_triples += s.covered_triples;
        a.fallbacks += s.fallbacks;
        eff.extend(&s.effectivities);
        if t.is_none() {
            eff.extend(std::iter::repeat_n(f64::INFINITY, loads));
        }
        if s.cost_median.is_finite() {
            costs.push(s.cost_median);
        }
    }
    a.effectivity_median = median(&eff);
    a.effectivity_p95 = percentile(&eff, 95.0);
    a.effectivity_max = eff.iter().copied().fold(f64::NAN, f64::max);
    a.cost_median = median(&costs);
    a
}

/// The quantities a zoo probe records — the tip's position, the roots' position, strain and
/// curvature (tests/common/zoo/mechanisms.rs) — and the joints' reaction forces and moments.
pub const QUANTITIES: [&str; 5] = ["position", "strain", "curvature", "force", "moment"];

/// One probe quantity of one validation, with where it comes from.
#[derive(Clone, Debug, serde::Serialize)]
pub struct QuantityCase {
    pub model: String,
    pub load_scale: f64,
    pub probe: String,
    pub quantity: String,
    /// the error relative to the full run's range (∞: the validation failed)
    pub relative: f64,
    /// its estimate (NaN: none)
    pub estimate: f64,
    /// estimate / relative; ∞ where the validation failed or gave no estimate (as for
    /// `rel_error`, [`model_stats`])
    pub effectivity: f64,
}

impl QuantityCase {
    pub fn covered(&self) -> bool {
        self.estimate >= self.relative
    }
}

/// How the estimates of one probe quantity fare over (model, load, probe) triples:
/// coverage (estimate ≥ error) and effectivity (estimate / error). Entries whose full run
/// has no swing of the quantity (`relative` null: a clamped root's position) have no ratio
/// and are counted apart.
#[derive(Clone, Debug, serde::Serialize)]
pub struct QuantityStats {
    pub quantity: String,
    /// (model, load, probe) triples with an error to measure
    pub cases: usize,
    pub covered: usize,
    /// triples with no swing of the quantity in the full run (not in `cases`)
    pub no_swing: usize,
    pub effectivity_median: f64,
    pub effectivity_p95: f64,
    pub effectivity_max: f64,
    /// the three cases of smallest effectivity (the worst under, when any is)
    pub lowest: Vec<QuantityCase>,
    /// the three of largest effectivity
    pub highest: Vec<QuantityCase>,
}

impl QuantityStats {
    pub fn coverage(&self) -> f64 {
        self.covered as f64 / self.cases.max(1) as f64
    }

    /// The targets of a probe quantity's estimate missed (docs/zoo.md: coverage ≥
    /// [`MIN_PAIR_COVERAGE`], median effectivity ≤ [`MAX_MEDIAN_EFFECTIVITY`], the targets of
    /// `rel_error`'s estimate); empty: met.
    pub fn missed(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.cases == 0 {
            return out;
        }
        if self.coverage() < MIN_PAIR_COVERAGE {
            out.push(format!(
                "{} coverage {:.1} % < {:.0} %",
                self.quantity,
                100.0 * self.coverage(),
                100.0 * MIN_PAIR_COVERAGE
            ));
        }
        if !within(self.effectivity_median, MAX_MEDIAN_EFFECTIVITY) {
            out.push(format!(
                "{} median effectivity {:.3} > {MAX_MEDIAN_EFFECTIVITY}",
                self.quantity, self.effectivity_median
            ));
        }
        out
    }
}

/// Every probe quantity of the validations of `models` (each a model's name and its
/// validations). A failed validation counts as uncovered, effectivity ∞, for every probe
/// quantity the model's first answered validation measured (one with a swing).
pub fn quantity_cases(models: &[(&str, &[Result<Validation, String>])]) -> Vec<QuantityCase> {
    let mut out = Vec::new();
    for (model, runs) in models {
        let recorded: Vec<(String, String)> = runs
            .iter()
            .flatten()
            .next()
            .map(|v| {
                v.quantities
                    .iter()
                    .filter(|q| !q.relative.is_nan())
                    .map(|q| (q.probe.clone(), q.quantity.clone()))
                    .collect()
            })
            .unwrap_or_default();
        for (r, load) in runs.iter().zip(super::validation_loads()) {
            let case = |probe: &str, quantity: &str, relative: f64, estimate: f64| QuantityCase {
                model: model.to_string(),
                load_scale: load,
                probe: probe.into(),
                quantity: quantity.into(),
                relative,
                estimate,
                effectivity: if relative.is_infinite() { f64::INFINITY } else { ratio(estimate, relative) },
            };
            match r {
                Ok(v) => out.extend(v.quantities.iter().map(|q| case(&q.probe, &q.quantity, q.relative, q.estimate))),
                Err(_) => out.extend(recorded.iter().map(|(p, q)| case(p, q, f64::INFINITY, f64::NAN))),
            }
        }
    }
    out
}

/// [`QuantityStats`] of each of [`QUANTITIES`] over `cases`.
pub fn quantity_stats(cases: &[QuantityCase]) -> Vec<QuantityStats> {
    QUANTITIES
        .iter()
        .map(|&quantity| {
            let of: Vec<&QuantityCase> = cases.iter().filter(|c| c.quantity == quantity).collect();
            let mut measured: Vec<QuantityCase> =
                of.iter().filter(|c| !c.relative.is_nan()).map(|&c| c.clone()).collect();
            measured.sort_by(|a, b| a.effectivity.total_cmp(&b.effectivity));
            let eff: Vec<f64> = measured.iter().map(|c| c.effectivity).collect();
            QuantityStats {
                quantity: quantity.into(),
                cases: measured.len(),
                covered: measured.iter().filter(|c| c.covered()).count(),
                no_swing: of.len() - measured.len(),
                effectivity_median: median(&eff),
                effectivity_p95: percentile(&eff, 95.0),
                effectivity_max: eff.last().copied().unwrap_or(f64::NAN),
                lowest: measured.iter().take(3).cloned().collect(),
                highest: measured.iter().rev().take(3).cloned().collect(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(e: f64, t: f64) -> Validation {
        Validation {
            load_scale: 1.0,
            n_modes: 3,
            rel_error: t,
            error_estimate: e,
            rel_error_by_time: [t; 5],
            error_estimate_by_time: [e, e, e, e, 0.5 * t],
            full_seconds: 1.0,
            rom_seconds: 0.5,
            estimate_seconds: 0.25,
            speedup: 2.0,
            amplifying: false,
            sensitivity_near: f64::NAN,
            quantities: Vec::new(),
        }
    }

    fn q(quantity: &str, relative: f64, estimate: f64) -> super::super::drive::QuantityError {
        super::super::drive::QuantityError {
            probe: "root".into(),
            quantity: quantity.into(),
            relative,
            estimate,
            max_error: relative,
            range: 1.0,
        }
    }

    /// Hand-counted: curvature at three loads, effectivities 2 and 0.5 and a failed run
    /// (∞, uncovered): coverage 1/3, median 2, max ∞; the position of no swing (null) is
    /// counted apart; strain at two loads, 4 and 1 (covered: estimate = error).
    #[test]
    fn probe_quantities_are_counted_per_quantity() {
        let with = |qs: Vec<super::super::drive::QuantityError>| Validation { quantities: qs, ..v(1.0, 1.0) };
        let runs = [
            Ok(with(vec![q("curvature", 0.1, 0.2), q("position", f64::NAN, f64::NAN), q("strain", 0.01, 0.04)])),
            Ok(with(vec![q("curvature", 0.2, 0.1), q("strain", 0.02, 0.02)])),
            Err("failed".into()),
        ];
        let cases = quantity_cases(&[("m", &runs)]);
        assert_eq!(cases[0].load_scale, super::super::validation_loads()[0]);
        let s = quantity_stats(&cases);
        let (pos, strain, curv) = (&s[0], &s[1], &s[2]);
        assert_eq!((pos.cases, pos.no_swing), (0, 1), "a failed run adds no quantity without a swing");
        assert!(pos.missed().is_empty(), "nothing to measure, nothing missed");
        assert_eq!((curv.cases, curv.covered, curv.no_swing), (3, 1, 0));
        assert_eq!((curv.effectivity_median, curv.effectivity_max), (2.0, f64::INFINITY));
        assert_eq!(curv.lowest[0].effectivity, 0.5);
        assert_eq!(curv.missed().len(), 1, "coverage 33 % < 95 %; median 2 ≤ 3");
        assert_eq!((strain.cases, strain.covered), (3, 2));
        assert_eq!(strain.effectivity_median, 4.0, "1, 4, ∞");
    }

    /// Hand-counted: two loads, one covered with effectivity 2, one under (0.5); the last
    /// fifth of both is under by construction.
    #[test]
    fn coverage_and_effectivity_are_counted() {
        let s = model_stats(&[Ok(v(2e-3, 1e-3)), Ok(v(1e-3, 2e-3)), Err("failed".into())]);
        assert_eq!((s.covered_pairs, s.under_pairs, s.failed_loads), (1, 2, 1));
        assert_eq!(s.silent_under_pairs, 1, "the under one gave no warning; a failed run is no silent answer");
        let warned = Validation { amplifying: true, ..v(1e-3, 2e-3) };
        assert_eq!(model_stats(&[Ok(warned)]).silent_under_pairs, 0);
        assert_eq!((s.covered_triples, s.under_triples), (4, 11));
        assert_eq!(s.effectivity_median, 2.0);
        assert_eq!(s.effectivity_max, f64::INFINITY);
        assert_eq!(s.cost_median, 0.5);
        assert!(estimate_fails(&s));
        assert_eq!(percentile(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0], 95.0), 10.0);
        assert_eq!(percentile(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0], 50.0), 5.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
    }

    /// Hand-counted: at tolerance 1e-2 the failed run, the one reading 2e-2 and the one whose
    /// training sensitivity (3e-2) exceeds the tolerance, `AMPLIFYING · δ` = 1e-2 and its
    /// estimate fall back and count as exact (covered in every fifth, no effectivity); the
    /// one reading 2e-3 against 1e-3 stays, covered over the run and in four fifths. A
    /// sensitivity of 9.9e-3 (below 1e-2) or one the estimate reaches does not fall back,
    /// whatever `validate`'s own `amplifying` says.
    #[test]
    fn a_fallback_answers_exactly_where_it_falls_back() {
        let amplifying = Validation { sensitivity_near: 3e-2, ..v(1e-3, 2e-3) };
        let runs = [Ok(v(2e-3, 1e-3)), Ok(v(2e-2, 1e-3)), Ok(amplifying), Err("failed".into())];
        assert_eq!(runs.iter().map(|r| falls_back(r, 1e-2)).collect::<Vec<_>>(), [false, true, true, true]);
        let below = Validation { sensitivity_near: 9.9e-3, amplifying: true, ..v(1e-3, 2e-3) };
        let reached = Validation { sensitivity_near: 3e-2, ..v(5e-2, 2e-3) };
        assert!(!falls_back(&Ok(below), 1e-2));
        assert!(!falls_back(&Ok(reached), 1.0), "an estimate of 5e-2 ≥ the sensitivity 3e-2, below the tolerance 1");
        let s = fallback_stats(&runs, 1e-2);
        assert_eq!((s.loads, s.fallbacks, s.covered_pairs, s.under_pairs, s.failed_loads), (4, 3, 4, 0, 0));
        assert_eq!((s.covered_triples, s.under_triples), (19, 1));
        assert_eq!(s.coverage_by_fifth, [1.0, 1.0, 1.0, 1.0, 0.75]);
        assert_eq!(s.effectivities, vec![2.0]);
        let a = aggregate(&[(None, &s)]);
        assert_eq!((a.fallbacks, a.covered_pairs), (3, 4));
    }
}
