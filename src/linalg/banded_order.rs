//! The row order of the symmetric band `LDLᵀ` ([`super::banded_ldlt`]): the KKT matrix's
//! coordinates by reverse Cuthill–McKee, each constraint row behind all its coordinates.

use super::banded::reverse_cuthill_mckee;
use super::kkt_pattern::KktPattern;

/// An order of the KKT rows (`order[new] = old`) with every constraint row behind all its
/// coordinates and a small half-bandwidth: the coordinates by reverse Cuthill–McKee (or
/// its reverse, whichever ends with the smaller band), then each constraint row inserted,
/// behind its last coordinate, at the place that widens the band least (a row put inside
/// the span of an element widens it by one; the first free gap after its coordinates
/// costs nothing).
pub fn quasi_definite_order(pattern: &KktPattern) -> Vec<usize> {
    let nd = pattern.n_dof;
    let adj = super::banded::adjacency(pattern);
    // coordinates alone; a constraint couples its coordinates as an element does
    let mut dof_adj: Vec<Vec<usize>> =
        adj[..nd].iter().map(|a| a.iter().copied().filter(|&j| j < nd).collect()).collect();
    for row in &pattern.constraint_rows {
        for &(i, _) in row {
            dof_adj[i].extend(row.iter().map(|&(j, _)| j).filter(|&j| j != i));
        }
    }
    for a in dof_adj.iter_mut() {
        a.sort_unstable();
        a.dedup();
    }
    let rcm = reverse_cuthill_mckee(&dof_adj);
    let forward = insert_constraints(&adj, nd, rcm.clone());
    let backward = insert_constraints(&adj, nd, rcm.into_iter().rev().collect());
    if bandwidth(&adj, &backward) < bandwidth(&adj, &forward) {
        backward
    } else {
        forward
    }
}

fn positions(n: usize, order: &[usize]) -> Vec<usize> {
    let mut pos = vec![usize::MAX; n];
    for (p, &o) in order.iter().enumerate() {
        pos[o] = p;
    }
    pos
}

/// Half-bandwidth of `order` over the rows it holds.
fn bandwidth(adj: &[Vec<usize>], order: &[usize]) -> usize {
    let pos = positions(adj.len(), order);
    let mut band = 0;
    for &i in order {
        for &j in &adj[i] {
            if pos[j] != usize::MAX {
                band = band.max(pos[i].abs_diff(pos[j]));
            }
        }
    }
    band
}

/// Inserts the constraint rows `nd..` into the coordinate order `order` (see
/// [`quasi_definite_order`]).
fn insert_constraints(adj: &[Vec<usize>], nd: usize, mut order: Vec<usize>) -> Vec<usize> {
    let n = adj.len();
    for row in nd..n {
        let pos = positions(n, &order);
        let placed: Vec<usize> = adj[row].iter().map(|&d| pos[d]).collect();
        let (Some(&last), Some(&first)) = (placed.iter().max(), placed.iter().min()) else {
            order.push(row);
            continue;
        };
        let band = bandwidth(adj, &order);
        // reach[p]: the farthest position coupled to the row at position p
        let reach: Vec<usize> = order
            .iter()
            .enumerate()
            .map(|(p, &i)| adj[i].iter().map(|&j| pos[j]).filter(|&q| q != usize::MAX).fold(p, usize::max))
            .collect();
        // inserting at position p moves every row from p on by one: a coupling across p
        // grows by one
        let widened = |p: usize| {
            let across = (p.saturating_sub(band)..p).filter(|&i| reach[i] >= p).map(|i| reach[i] - i + 1).max();
            band.max(across.unwrap_or(0)).max(p - first)
        };
        let best = (last + 1..=(last + 2 * band + 2).min(order.len()))
            .min_by_key(|&p| (widened(p), p))
            .expect("a non-empty range");
        order.insert(best, row);
    }
    order
}
