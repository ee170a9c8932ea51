//! Modes for what engineers read: a POD basis enriched until the outputs of its training
//! snapshots — the strains and curvatures the probes record — are reproduced.
//!
//! A POD keeps the directions of most energy in the coordinates; a strain or a curvature
//! is a first or second derivative along the beam, carried by directions of tiny energy
//! (a stiff link's stretch, a root's bending wave) that an energy tolerance drops long
//! before it drops anything a position shows. So, per block of the basis,
//!
//! ```text
//!     P x = x_ref + V Vᵀ (x − x_ref)                       (the projected snapshot)
//!     e_oj = |y_o(P x_j) − y_o(x_j)| / max(range_o, floor_o)
//!     while max_oj e_oj > T:
//!         w_j = max_o e_oj                                 (the snapshot's worst output)
//!         u   = leading left singular vector of R_b diag(w), R = (I − V Vᵀ)(X − x_ref)
//!         V  ← [V, u ⊥ V]                                  (in the block's rows)
//! ```
//!
//! with `o` over the outputs that read the block's rows, `range_o` the output's range over
//! the snapshots and `floor_o` its resolution (below it nothing is read). The weight puts
//! the new direction where the outputs are worst; its leading singular vector is the
//! direction that removes the most of that weighted residual at once (a residual snapshot
//! of its own fixes one snapshot and can spoil others: tried on a two-link arm, 14
//! directions did not bring the root strain within 1e-3 of its range where 8 weighted ones
//! did). The added columns are orthonormal to the block's modes, so `V` stays orthonormal
//! and block-diagonal, and every reduction and ECSW treat them as modes like the others.
//! Nothing here knows what an output is: the caller gives the coordinates each output
//! reads and a function of them.

use super::basis::Trained;
use crate::error::{Error, Result};
use ndarray::{s, Array1, Array2, ArrayView1, ArrayView2, Axis};

/// One scalar output of the coordinates: it reads the coordinates `dofs` (in this order).
#[derive(Clone, Debug)]
pub struct Output {
    /// the caller's name for it, what `eval` is given
    pub id: usize,
    pub dofs: Vec<usize>,
    /// differences below this are not read (the output's resolution, > 0)
    pub floor: f64,
}

/// The outputs a basis must reproduce and how to evaluate them: `eval(id, values)` is
/// the output of that `id` at the coordinate values `values` (its `dofs`, in order).
pub struct Outputs<'a> {
    pub outputs: Vec<Output>,
    pub eval: &'a (dyn Fn(usize, &[f64]) -> f64 + Sync),
}

/// When to stop adding modes to a block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stop {
    /// when every output of the block is reproduced within this fraction of its range
    Tolerance(f64),
    /// after this many more (the error estimator's richer basis), or when nothing is left
    More(usize),
}

/// Power iterations for the leading singular vector: the direction only has to remove much
/// of the weighted residual, not be the exact singular vector; started from the worst
/// snapshot's residual, a few iterations settle it.
const POWER_ITERATIONS: usize = 12;

/// A new direction whose part outside the block's span is below this fraction of its size
/// adds nothing the block does not hold (round-off).
const NEW_DIRECTION: f64 = 1e-10;

/// Adds output modes to each block of `trained` (`blocks`: the rows each block's modes live
/// on, without kept coordinates; one entry for a basis without blocks) from snapshots `x`
/// (n × m, uncentred), first `seed`'s columns (orthogonalized into the block: the
/// error estimator's basis takes the basis's own output modes), then until `stop`. Returns
/// how many were added to each block; `trained.output_modes` counts them.
pub fn add_output_modes(
    trained: &mut Trained,
    blocks: &[Vec<usize>],
    x: ArrayView2<f64>,
    outputs: &Outputs,
    seed: &[Array2<f64>],
    stop: Stop,
) -> Result<Vec<usize>> {
    if let Stop::Tolerance(t) = stop {
        if !(t.is_finite() && t > 0.0 && t < 1.0) {
            return Err(Error::usage(format!("the probe-mode tolerance must lie in (0, 1), got {t}")));
        }
    }
    if blocks.len() != trained.block_modes.len() {
        return Err(Error::usage(format!(
            "{} row sets for a basis of {} blocks",
            blocks.len(),
            trained.block_modes.len()
        )));
    }
    let centred = &x - &trained.basis.reference.view().insert_axis(Axis(1));
    let exact = outputs_at(outputs, &|d, j| x[[d, j]], x.ncols());
    // the centred snapshots projected on the whole basis, once: a block's new modes change
    // its own rows only, so each block goes on from what the blocks before it left
    let modes = &trained.basis.modes;
    let mut projected = modes.dot(&modes.t().dot(&centred));
    let mut columns: Vec<Array2<f64>> = (0..blocks.len()).map(|b| block_columns(trained, blocks, b)).collect();
    let mut added = vec![0; blocks.len()];
    for (b, rows) in blocks.iter().enumerate() {
        let reads: Vec<usize> =
            (0..outputs.outputs.len()).filter(|&o| outputs.outputs[o].dofs.iter().any(|d| rows.contains(d))).collect();
        if reads.is_empty() {
            continue;
        }
        let mut block = BlockState::new(rows, centred.view(), &columns[b], &mut projected);
        for s in seed.get(b).map(|a| a.columns().into_iter().map(|c| c.to_owned()).collect()).unwrap_or(Vec::new()) {
            if block.push(s.view()) {
                added[b] += 1;
            }
        }
        let budget = match stop {
            Stop::Tolerance(_) => rows.len().min(x.ncols()),
            Stop::More(k) => k,
        };
        for _ in 0..budget {
            let errors = block.errors(trained, outputs, &reads, &exact);
            let worst = errors.iter().copied().fold(0.0, f64::max);
            if matches!(stop, Stop::Tolerance(t) if worst <= t) || worst == 0.0 {
                break;
            }
            let direction = block.weighted_direction(&errors);
            if !block.push(direction.view()) {
                break;
            }
            added[b] += 1;
        }
        columns[b] = block.v;
    }
    write_columns(trained, blocks, &columns, &added);
    Ok(added)
}

/// The columns of block `b` of the basis (its POD and output modes), on the block's rows.
pub fn block_columns(trained: &Trained, blocks: &[Vec<usize>], b: usize) -> Array2<f64> {
    let widths: Vec<usize> = trained.block_modes.iter().zip(&trained.output_modes).map(|(p, o)| p + o).collect();
    let c0: usize = widths[..b].iter().sum();
    trained.basis.modes.slice(s![.., c0..c0 + widths[b]]).select(Axis(0), &blocks[b])
}

/// The output modes of block `b` (its last `output_modes[b]` columns), on the block's rows.
pub fn output_columns(trained: &Trained, blocks: &[Vec<usize>], b: usize) -> Array2<f64> {
    let all = block_columns(trained, blocks, b);
    let k = trained.output_modes[b];
    all.slice(s![.., all.ncols() - k..]).to_owned()
}

/// `y_o` of every output at every snapshot `j` (`value(d, j)`: coordinate `d` of snapshot `j`).
fn outputs_at(outputs: &Outputs, value: &dyn Fn(usize, usize) -> f64, m: usize) -> Array2<f64> {
    let mut y = Array2::zeros((outputs.outputs.len(), m));
    for (o, out) in outputs.outputs.iter().enumerate() {
        let mut vals = vec![0.0; out.dofs.len()];
        for j in 0..m {
            for (v, &d) in vals.iter_mut().zip(&out.dofs) {
                *v = value(d, j);
            }
            y[[o, j]] = (outputs.eval)(out.id, &vals);
        }
    }
    y
}

/// One block during enrichment: its modes on its rows, the residual of its rows, and the
/// snapshots projected on the whole basis.
struct BlockState<'p> {
    rows: Vec<usize>,
    /// the block's columns on its rows (n_b × k)
    v: Array2<f64>,
    /// the centred snapshots of the block's rows (n_b × m)
    c: Array2<f64>,
    /// (I − V Vᵀ) c on the block's rows
    residual: Array2<f64>,
    /// the centred snapshots projected on the whole basis (n × m): the other blocks' and
    /// the kept coordinates' rows do not change here
    projected: &'p mut Array2<f64>,
}

impl<'p> BlockState<'p> {
    fn new(rows: &[usize], centred: ArrayView2<f64>, v: &Array2<f64>, projected: &'p mut Array2<f64>) -> Self {
        let c = centred.select(Axis(0), rows);
        let residual = &c - &v.dot(&v.t().dot(&c));
        BlockState { rows: rows.to_vec(), v: v.clone(), c, residual, projected }
    }

    /// Appends `u` orthogonalized against the block's columns (twice, for round-off) when
    /// something of it is left; updates the residual and the projected snapshots.
    fn push(&mut self, u: ArrayView1<f64>) -> bool {
        let size = u.dot(&u).sqrt();
        let mut w = u.to_owned();
        for _ in 0..2 {
            let coef = self.v.t().dot(&w);
            w -= &self.v.dot(&coef);
        }
        let left = w.dot(&w).sqrt();
        if !(size > 0.0 && left > NEW_DIRECTION * size) {
            return false;
        }
        w /= left;
        let coef = w.dot(&self.c);
        for (i, &d) in self.rows.iter().enumerate() {
            self.projected.row_mut(d).scaled_add(w[i], &coef);
        }
        let along = w.dot(&self.residual);
        for (i, mut r) in self.residual.outer_iter_mut().enumerate() {
            r.scaled_add(-w[i], &along);
        }
        self.v.push_column(w.view()).expect("rows agree");
        true
    }

    /// The worst error of the outputs `reads` at each snapshot, over the output's range.
    fn errors(&self, trained: &Trained, outputs: &Outputs, reads: &[usize], exact: &Array2<f64>) -> Array1<f64> {
        let m = self.c.ncols();
        let reference = &trained.basis.reference;
        let mut worst = Array1::zeros(m);
        let mut vals = Vec::new();
        for &o in reads {
            let out = &outputs.outputs[o];
            let y = exact.row(o);
            let (lo, hi) = y.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
            let scale = (hi - lo).max(out.floor);
            for j in 0..m {
                vals.clear();
                vals.extend(out.dofs.iter().map(|&d| reference[d] + self.projected[[d, j]]));
                let e = ((outputs.eval)(out.id, &vals) - y[j]).abs();
                let e = if e <= out.floor { 0.0 } else { e / scale };
                worst[j] = f64::max(worst[j], if e.is_nan() { f64::INFINITY } else { e });
            }
        }
        worst
    }

    /// The leading left singular vector of `R diag(w)` by power iteration from the worst
    /// snapshot's residual.
    fn weighted_direction(&self, w: &Array1<f64>) -> Array1<f64> {
        let w = w.mapv(|v| if v.is_finite() { v } else { f64::MAX.sqrt() });
        let weighted = &self.residual * &w.view().insert_axis(Axis(0));
        let worst = w.iter().enumerate().fold(0, |k, (j, &v)| if v > w[k] { j } else { k });
        let mut u = weighted.column(worst).to_owned();
        for _ in 0..POWER_ITERATIONS {
            let next = weighted.dot(&weighted.t().dot(&u));
            let n = next.dot(&next).sqrt();
            if !(n > 0.0 && n.is_finite()) {
                break;
            }
            u = next / n;
        }
        u
    }
}

/// Rebuilds `trained`'s modes with each block's columns `columns[b]` on its rows, in block
/// order, then the kept coordinates' unit columns.
fn write_columns(trained: &mut Trained, blocks: &[Vec<usize>], columns: &[Array2<f64>], added: &[usize]) {
    if added.iter().all(|&a| a == 0) {
        return;
    }
    let n = trained.basis.modes.nrows();
    let r: usize = columns.iter().map(|c| c.ncols()).sum();
    let kept = trained.basis.kept.len();
    let mut v = Array2::zeros((n, r + kept));
    let mut c0 = 0;
    for (rows, cols) in blocks.iter().zip(columns) {
        for (i, &d) in rows.iter().enumerate() {
            v.slice_mut(s![d, c0..c0 + cols.ncols()]).assign(&cols.row(i));
        }
        c0 += cols.ncols();
    }
    let old = &trained.basis.modes;
    let old_r = old.ncols() - kept;
    v.slice_mut(s![.., r..]).assign(&old.slice(s![.., old_r..]));
    trained.basis.modes = v;
    trained.basis.n_pod_modes = r;
    for (o, a) in trained.output_modes.iter_mut().zip(added) {
        *o += a;
    }
    trained.basis.set_kept_columns();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reduction::basis::{BasisSpec, SnapshotKind, Variant};
    use crate::reduction::basis_train::train_plain;
    use crate::reduction::ModeRule;

    /// Snapshots of two directions, one of amplitude 1 and one of amplitude 1e-7, and an
    /// output that reads only the small one (as a stiff link's strain reads its stretch):
    /// a one-mode POD reproduces the snapshots to 1e-7 relative but the output not at all
    /// (its error equals its range); one output mode brings it to round-off and keeps V
    /// orthonormal; `More(1)` on a basis that already holds it adds nothing.
    #[test]
    fn an_output_the_pod_misses_gets_its_mode() {
        let (n, m) = (6, 40);
        let big = Array1::from(vec![1.0, 1.0, 0.0, 0.0, 1.0, 1.0]) / 2.0;
        let small = Array1::from(vec![0.0, 0.0, 1.0, -1.0, 0.0, 0.0]) / 2f64.sqrt();
        let x = Array2::from_shape_fn((n, m), |(i, j)| {
            let t = j as f64 / m as f64;
            (6.0 * t).sin() * big[i] + 1e-7 * (11.0 * t).cos() * small[i]
        });
        let spec = BasisSpec {
            variant: Variant::Galerkin,
            snapshots: SnapshotKind::Raw,
            modes: ModeRule::Count(1),
            multiplier_scale: 1.0,
            blocks: vec![],
            stabilization: None,
        };
        let mut t = train_plain(x.view(), Array2::zeros((0, m)).view(), &[], Array1::zeros(n).view(), &spec).unwrap();
        // the output: the difference of coordinates 2 and 3 (the small direction's reading)
        let eval = |_: usize, v: &[f64]| v[0] - v[1];
        let outputs = Outputs { outputs: vec![Output { id: 0, dofs: vec![2, 3], floor: 1e-16 }], eval: &eval };
        let blocks = vec![(0..n).collect::<Vec<_>>()];
        let added = add_output_modes(&mut t, &blocks, x.view(), &outputs, &[], Stop::Tolerance(1e-6)).unwrap();
        assert_eq!(added, vec![1]);
        assert_eq!((t.output_modes.clone(), t.basis.n_pod_modes), (vec![1], 2));
        let v = &t.basis.modes;
        assert!((v.t().dot(v) - Array2::<f64>::eye(2)).iter().all(|e| e.abs() < 1e-12), "VᵀV = I");
        assert!((v.column(1).dot(&small).abs() - 1.0).abs() < 1e-9, "the new mode is the small direction");
        let again = add_output_modes(&mut t, &blocks, x.view(), &outputs, &[], Stop::More(1)).unwrap();
        assert_eq!(again, vec![0], "nothing is left to add");
    }
}
