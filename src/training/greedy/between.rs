//! Looking between the candidates where the bound alone rejects a basis: every candidate's
//! score is within the tolerance, but two neighbours differ so much that the bound between
//! them ([`pair_bound`]) is not. The bound's rule extrapolates the
//! step from one neighbour to the other; a ratio of 12 between neighbours 3 % of the range
//! apart is as consistent with an error that falls smoothly over that step (the rule then
//! holds the gap to 12× the larger score) as with a peak between them. Which one it is,
//! a reduced run at the midpoint says: the pair is bisected, up to [`MAX_BISECTIONS`]
//! times, where a sub-interval's bound by the same rule is still above the tolerance, and
//! the pair's bound becomes the rule's over the points it then has. A smooth fall comes
//! out as a few small steps (the zoo's `05-four-bar` at 5e-3: scores 8.3e-4 and 6.9e-5 at
//! neighbouring candidates, 8.1e-4, 3.2e-4 and 1.3e-4 between them, every step ≤ 2.6×); a
//! peak comes out as a score above the tolerance, which rejects the basis as before.
//! Only where the model is calm at both ends: where it amplifies changes of the load
//! (`rom::trust::amplifying`) the scores jump with the dynamics, not along a curve a finer
//! spacing would resolve, and the pair keeps the rule's bound (on the shipped four-bar,
//! looking between such pairs let the search keep a looser rung whose error at λ = 1.175
//! was 1.0e-1, within that load's sensitivity of 1.8e-1 but 50× the basis kept without it).
//! Nothing here is fitted: the rule, the tolerance and the midpoints are the loop's own.

/// The bound of an estimate between two neighbouring candidates from its values `a`, `b`
/// there (`both_sensitive`, `settled`: below). Between
/// neighbours `i`, `j` (the `pairs`: `i`, `i + 1` on a line of evenly spaced loads, each
/// point and its d + 1 nearest in a box, [`super::candidate_set::CandidateSet`]) the estimate is taken to rise above the
/// larger of the two by as much as it changes from one to the other,
///
/// ```text
///     max_(i,j)  max(eᵢ, eⱼ)² / min(eᵢ, eⱼ)
/// ```
///
/// so a smooth estimate is held to its largest value times the local step ratio (a few per
/// cent with the default 33 candidates), a jumpy one to much more. Nothing in it is fitted:
/// a spike narrower than the spacing is what more candidates would find. Between two
/// candidates that are both `sensitive` (the model's answer moves by more than the
/// tolerance for a 0.1 % change of the load, so their scores are already held to that
/// sensitivity, the greedy module documentation) the pair counts with its larger value
/// only: there the scores jump because the dynamics do, not along a trend a ratio could
/// extrapolate, and no number of candidates would resolve them. A non-finite or
/// non-positive estimate (a failed run, a basis with no extra modes to estimate from) gives
/// ∞. A pair with a `settled` candidate — one whose full
/// run is in the snapshots, so that its estimate measures only what the basis truncates
/// there, not a trend — counts with its larger value too: between a point the basis holds
/// and its neighbour the error rises from about nothing towards the neighbour's, and a
/// ratio against that nothing says nothing. (Held only in a box, on a line the zoo's
/// `18-n-pendulum` stayed unconverged at scores within T because a training load's 2.3e-6
/// stood beside a neighbour's 7.8e-3.)
pub(crate) fn pair_bound(a: f64, b: f64, both_sensitive: bool, settled: bool) -> f64 {
    if !(a.is_finite() && a > 0.0 && b.is_finite() && b > 0.0) {
        return f64::INFINITY;
    }
    let (hi, lo) = (a.max(b), a.min(b));
    if both_sensitive || settled {
        hi
    } else {
        hi * (hi / lo)
    }
}

/// The bound over every pair, from the candidates' `scores` and the pairs' bounds: the
/// largest pair's; ∞ where a score is not a positive finite number or there is none, a
/// single candidate's own score.
pub(crate) fn largest(scores: &[f64], pair_bounds: &[f64]) -> f64 {
    if scores.is_empty() || scores.iter().any(|&x| !(x.is_finite() && x > 0.0)) {
        return f64::INFINITY;
    }
    if scores.len() == 1 {
        return scores[0];
    }
    pair_bounds.iter().fold(0.0, |m, &x| m.max(x))
}

/// [`largest`] of the rule's bounds without looking between candidates (the tests' form).
#[cfg(test)]
pub(crate) fn between_candidates(e: &[f64], sensitive: &[bool], settled: &[bool], pairs: &[(usize, usize)]) -> f64 {
    let flag = |v: &[bool], i: usize| v.get(i).copied().unwrap_or(false);
    let b: Vec<f64> = pairs
        .iter()
        .map(|&(i, j)| {
            pair_bound(e[i], e[j], flag(sensitive, i) && flag(sensitive, j), flag(settled, i) || flag(settled, j))
        })
        .collect();
    largest(e, &b)
}

/// The neighbours of a line of `n` candidates: `(i, i + 1)`.
#[cfg(test)]
pub(crate) fn line_pairs(n: usize) -> Vec<(usize, usize)> {
    (1..n).map(|i| (i - 1, i)).collect()
}

/// What looking at a batch of points (unit coordinates) gives at each: the score, and
/// whether the model is sensitive there.
pub(crate) type Look<'a> = dyn FnMut(&[Vec<f64>]) -> Vec<(f64, bool)> + 'a;

/// Bisections of one pair at most: a gap of 1/32 of the range (the default 33 candidates)
/// looked at down to 1/256.
pub const MAX_BISECTIONS: usize = 3;

/// One pair's segment as far as it was looked at: positions `t` ∈ [0, 1] from the pair's
/// first candidate to its second, with the score and the sensitivity flag at each.
struct Segment {
    pair: usize,
    t: Vec<f64>,
    score: Vec<f64>,
    sensitive: Vec<bool>,
}

impl Segment {
    /// The rule's bound over the segment's neighbouring points.
    fn bound(&self) -> f64 {
        (1..self.t.len()).map(|k| self.step(k)).fold(0.0, f64::max)
    }

    /// Neither point `k − 1` nor `k` is where the model amplifies changes of the load.
    fn calm(&self, k: usize) -> bool {
        !self.sensitive[k - 1] && !self.sensitive[k]
    }

    /// The rule's bound between points `k − 1` and `k`.
    fn step(&self, k: usize) -> f64 {
        pair_bound(self.score[k - 1], self.score[k], self.sensitive[k - 1] && self.sensitive[k], false)
    }
}

/// The bound of every pair of candidates (`pairs`, with the candidates' `scores`, whether
/// each is `sensitive` and `settled`, and their `unit` coordinates), pairs whose bound alone
/// is above `tolerance` looked at between their candidates by bisection: `look` gives the
/// score and the sensitivity flag at each of a batch of points in unit coordinates (reduced
/// runs, in parallel). At most `budget` points in all, the pairs with the largest bounds
/// first. Returns the bound of each pair (in `pairs` order) and the number of points looked
/// at. Nothing is looked at unless every score is finite and within the tolerance: a basis
/// above it at a candidate is rejected whatever lies between.
pub(crate) fn resolve(
    (scores, sensitive, settled): (&[f64], &[bool], &[bool]),
    pairs: &[(usize, usize)],
    unit: &[Vec<f64>],
    tolerance: f64,
    budget: usize,
    look: &mut Look,
) -> (Vec<f64>, usize) {
    let flag = |v: &[bool], i: usize| v.get(i).copied().unwrap_or(false);
    let mut bounds: Vec<f64> = pairs
        .iter()
        .map(|&(i, j)| {
            pair_bound(
                scores[i],
                scores[j],
                flag(sensitive, i) && flag(sensitive, j),
                flag(settled, i) || flag(settled, j),
            )
        })
        .collect();
    if !scores.iter().all(|&s| s.is_finite() && s > 0.0 && s <= tolerance) {
        return (bounds, 0);
    }
    let mut segments: Vec<Segment> = (0..pairs.len())
        .filter(|&k| bounds[k] > tolerance && !flag(sensitive, pairs[k].0) && !flag(sensitive, pairs[k].1))
        .map(|k| {
            let (i, j) = pairs[k];
            Segment {
                pair: k,
                t: vec![0.0, 1.0],
                score: vec![scores[i], scores[j]],
                sensitive: vec![flag(sensitive, i), flag(sensitive, j)],
            }
        })
        .collect();
    let mut used = 0;
    for _ in 0..MAX_BISECTIONS {
        // the sub-intervals still above the tolerance, largest bound first, within the budget
        let mut wanted: Vec<(f64, usize, usize)> = segments
            .iter()
            .enumerate()
            .filter(|(_, s)| s.score.iter().all(|&x| x <= tolerance))
            .flat_map(|(n, s)| (1..s.t.len()).filter(|&k| s.calm(k)).map(move |k| (s.step(k), n, k)))
            .filter(|&(b, _, _)| b > tolerance)
            .collect();
        wanted.sort_by(|a, b| b.0.total_cmp(&a.0).then((a.1, a.2).cmp(&(b.1, b.2))));
        wanted.truncate(budget - used);
        if wanted.is_empty() {
            break;
        }
        let at: Vec<(usize, f64)> =
            wanted.iter().map(|&(_, n, k)| (n, 0.5 * (segments[n].t[k - 1] + segments[n].t[k]))).collect();
        let points: Vec<Vec<f64>> = at
            .iter()
            .map(|&(n, t)| {
                let (i, j) = pairs[segments[n].pair];
                unit[i].iter().zip(&unit[j]).map(|(a, b)| a + t * (b - a)).collect()
            })
            .collect();
        let seen = look(&points);
        used += points.len();
        for (&(n, t), (score, sens)) in at.iter().zip(seen) {
            let s = &mut segments[n];
            let k = s.t.partition_point(|&x| x < t);
            s.t.insert(k, t);
            s.score.insert(k, if score.is_nan() { f64::INFINITY } else { score });
            s.sensitive.insert(k, sens);
        }
    }
    for s in &segments {
        bounds[s.pair] = s.bound();
    }
    (bounds, used)
}

#[cfg(test)]
mod tests {
    use super::{between_candidates, line_pairs, resolve, MAX_BISECTIONS};

    /// A line of candidates at u = 0, 0.5, 1 whose scores come from `f`: the pairs'
    /// bounds after looking between them, and the points looked at.
    fn line(f: &dyn Fn(f64) -> f64, tolerance: f64, budget: usize) -> (Vec<f64>, usize) {
        let unit = vec![vec![0.0], vec![0.5], vec![1.0]];
        let scores: Vec<f64> = unit.iter().map(|u| f(u[0])).collect();
        let mut look = |pts: &[Vec<f64>]| pts.iter().map(|u| (f(u[0]), false)).collect();
        resolve((&scores, &[false; 3], &[]), &[(0, 1), (1, 2)], &unit, tolerance, budget, &mut look)
    }

    /// An error that falls smoothly by 16× from one candidate to the next (1e-3 · 16^(−2u)
    /// on [0, 0.5]) has a bound of 1.6e-2 by the rule between the candidates, above 5e-3;
    /// one bisection gives steps of 4× (bound 4e-3) and settles it: the pair's bound is the
    /// larger score times that step, and the flat pair beside it (1e-3 · 16^(−1) throughout
    /// [0.5, 1]) is not looked at.
    #[test]
    fn a_smooth_fall_between_neighbours_is_resolved() {
        let f = |u: f64| 1e-3 * 16f64.powf(-2.0 * u.min(0.5));
        let (b, used) = line(&f, 5e-3, 100);
        assert_eq!(used, 1);
        assert!((b[0] - 1e-3 * 4.0).abs() < 1e-12, "{b:?}");
        assert!((b[1] - 1e-3 / 16.0).abs() < 1e-15, "{b:?}");
    }

    /// A peak between two candidates (1e-4 and 1e-3, a bound of 1e-2 by the rule; a narrow
    /// bump to 2e-2 at u = 0.25 between them) is found by the bisection: its score above
    /// the tolerance makes the pair's bound at least the peak, and no further point is
    /// looked at in that segment.
    #[test]
    fn a_peak_between_neighbours_is_found() {
        let f = |u: f64| {
            if (u - 0.25).abs() < 0.01 {
                2e-2
            } else if u < 0.5 {
                1e-4
            } else {
                1e-3
            }
        };
        // the pair (0, 0.5) reads 1e-4 and 1e-3: bound 1e-2 > 5e-3
        let (b, used) = line(&f, 5e-3, 100);
        assert_eq!(used, 1, "one midpoint, at the peak");
        assert!(b[0] >= 2e-2, "{b:?}");
    }

    /// The bisection stops after `MAX_BISECTIONS`: a jump at the first candidate (1e-3
    /// there, 1e-4 at any point after it) stays above the tolerance however close the
    /// points come, after one point per bisection; a budget caps the points in all.
    #[test]
    fn the_bisection_is_bounded() {
        let f = |u: f64| if u == 0.0 { 1e-3 } else { 1e-4 };
        let unit = vec![vec![0.0], vec![1.0]];
        let mut look = |pts: &[Vec<f64>]| pts.iter().map(|u| (f(u[0]), false)).collect();
        let (b, used) = resolve((&[1e-3, 1e-4], &[false; 2], &[]), &[(0, 1)], &unit, 5e-3, 100, &mut look);
        assert_eq!(used, MAX_BISECTIONS);
        assert!((b[0] - 1e-2).abs() < 1e-12, "{b:?}");
        let (_, capped) = resolve((&[1e-3, 1e-4], &[false; 2], &[]), &[(0, 1)], &unit, 5e-3, 2, &mut look);
        assert_eq!(capped, 2);
    }

    /// Nothing is looked at between candidates where the model amplifies changes of the
    /// load at either end: there the pair keeps the rule's bound (1e-3 · 10).
    #[test]
    fn amplifying_neighbours_are_not_bisected() {
        let mut never = |_: &[Vec<f64>]| -> Vec<(f64, bool)> { panic!("looked between candidates") };
        let unit = vec![vec![0.0], vec![1.0]];
        let (b, used) = resolve((&[1e-3, 1e-4], &[true, false], &[]), &[(0, 1)], &unit, 5e-3, 100, &mut never);
        assert_eq!(used, 0);
        assert!((b[0] - 1e-2).abs() < 1e-12, "{b:?}");
    }

    /// Nothing is looked at where a candidate's score is above the tolerance (the basis is
    /// rejected at that candidate) or where the bound between the candidates already meets it.
    #[test]
    fn nothing_is_looked_at_without_need() {
        let mut never = |_: &[Vec<f64>]| -> Vec<(f64, bool)> { panic!("looked between candidates") };
        let unit = vec![vec![0.0], vec![1.0]];
        let (b, used) = resolve((&[1e-4, 6e-3], &[false; 2], &[]), &[(0, 1)], &unit, 5e-3, 100, &mut never);
        assert_eq!(used, 0);
        assert!((b[0] - 6e-3 * 60.0).abs() < 1e-12, "{b:?}");
        let (b, used) = resolve((&[1e-3, 2e-3], &[false; 2], &[]), &[(0, 1)], &unit, 5e-3, 100, &mut never);
        assert_eq!(used, 0);
        assert!((b[0] - 4e-3).abs() < 1e-15, "{b:?}");
    }

    fn between(e: &[f64], sensitive: &[bool]) -> f64 {
        between_candidates(e, sensitive, &[], &line_pairs(e.len()))
    }

    /// A flat estimate is its value; a rising one is held to its largest value times the
    /// last step ratio (1.1 × 1.1 / 1.0 → 1.21 between the last two); a jump between two
    /// neighbours counts in full (1e-3 next to 1e-4 bounds the gap by 1e-2); a failed
    /// estimate, a zero one and no estimates at all are ∞.
    #[test]
    fn the_bound_between_candidates_follows_the_neighbours() {
        let calm = [false; 3];
        assert_eq!(between(&[2e-4, 2e-4, 2e-4], &calm), 2e-4);
        assert!((between(&[1.0, 1.0, 1.1], &calm) - 1.21).abs() < 1e-12);
        assert!((between(&[1e-4, 1e-3, 1e-4], &calm) - 1e-2).abs() < 1e-15);
        assert!(between(&[1e-4, f64::INFINITY], &calm).is_infinite());
        assert!(between(&[1e-4, f64::NAN], &calm).is_infinite());
        assert!(between(&[1e-4, 0.0], &calm).is_infinite());
        assert!(between(&[], &calm).is_infinite());
    }

    /// Between two sensitive candidates a jump counts with its larger value (1e-3, not
    /// 1e-2); a pair with one calm candidate keeps the ratio (1e-4 next to 1e-3: 1e-2);
    /// a failed estimate is ∞ whatever the sensitivity.
    #[test]
    fn sensitive_neighbours_are_not_extrapolated() {
        assert_eq!(between(&[1e-4, 1e-3, 1e-4], &[true; 3]), 1e-3);
        assert!((between(&[1e-4, 1e-3, 1e-4], &[false, true, true]) - 1e-2).abs() < 1e-15);
        assert!(between(&[1e-4, f64::INFINITY], &[true; 2]).is_infinite());
    }

    /// In a box the bound runs over the given pairs only: 1e-4 and 1e-3 that are not
    /// neighbours do not bound each other (1.1e-4 · 1.1 between 0 and 2, 1.1e-3 · 1.1
    /// between 1 and 3).
    #[test]
    fn the_bound_runs_over_the_pairs() {
        let e = [1e-4, 1e-3, 1.1e-4, 1.1e-3];
        let b = between_candidates(&e, &[false; 4], &[], &[(0, 2), (1, 3)]);
        assert!((b - 1.1e-3 * 1.1).abs() < 1e-15, "{b}");
    }

    /// A pair with a settled candidate (its full run in the snapshots, its estimate the
    /// basis's truncation there, 1e-7) counts with its larger value, 1e-3, not 1e-3 · 1e4;
    /// the other pairs keep the ratio (1e-3 next to 2e-3: 4e-3).
    #[test]
    fn a_settled_candidate_bounds_its_pairs_by_the_larger_value() {
        let e = [1e-7, 1e-3, 2e-3];
        let pairs = [(0, 1), (1, 2)];
        assert!((between_candidates(&e, &[false; 3], &[], &pairs[..1]) - 10.0).abs() < 1e-9);
        assert_eq!(between_candidates(&e, &[false; 3], &[true, false, false], &pairs[..1]), 1e-3);
        let b = between_candidates(&e, &[false; 3], &[true, false, false], &pairs);
        assert!((b - 4e-3).abs() < 1e-15, "{b}");
    }
}
