//! The norms an estimate is made of, over the whole run and up to the end of each fifth of
//! it: the estimator's `η_raw = ‖X_r − X⁺‖_F / ‖X⁺‖_F` and its displacement form
//! `‖X_r − X⁺‖_F / ‖X⁺ − X₀‖_F` from reduced coordinates, and the true errors `validate`
//! measures, `rel_error = ‖X_r − X_full‖_F / ‖X_full‖_F` and `displacement_error =
//! ‖X_r − X_full‖_F / ‖X_full − X₀‖_F` (X₀ the initial configuration, the same at every
//! instant).
//!
//! With orthonormal `V` and `V⁺` (galerkin, constraint-preserving, block bases) the norms
//! need no full-size reconstruction: with `M = V⁺ᵀV` and `d = x_ref − x₀`,
//!
//! ```text
//!     ‖V q − V⁺ q⁺‖² = ‖M q − q⁺‖² + qᵀ(I − MᵀM) q,
//!     ‖x_ref + V⁺ q⁺‖² = ‖x_ref‖² + 2 (V⁺ᵀx_ref)·q⁺ + ‖q⁺‖²,
//!     ‖x_ref + V⁺ q⁺ − x₀‖² = ‖V⁺ᵀd + q⁺‖² + (‖d‖² − ‖V⁺ᵀd‖²),
//! ```
//!
//! the last two by expanding the square (`V⁺ᵀV⁺ = I`; the constant `‖d‖² − ‖V⁺ᵀd‖²` formed
//! once as `‖d − V⁺V⁺ᵀd‖²`). The displacement norm keeps the in-span part as one square: expanded like the configuration's, `‖d‖² + 2 (V⁺ᵀd)·q⁺ +
//! ‖q⁺‖²` would cancel where the motion is small against the configuration, and read the
//! rounding of `‖d‖²` as motion. Its out-of-span part `‖d‖² − ‖V⁺ᵀd‖²` is the same at every
//! instant.
//!
//! Where neither run has moved beyond the coordinates' resolution (the Newton tolerance
//! `tol · L`), the displacement measures have nothing to divide by: [`against_motion`].

pub use super::RawByFifth;
use super::{ByFifth, FIFTHS};
use crate::reduction::{Basis, Variant};
use ndarray::{Array1, Array2, ArrayView1, Axis};

/// The number of instants `..end` up to the end of fifth `i` (0-based) of a run of `nt`
/// instants (at least one).
pub fn fifth_end(nt: usize, i: usize) -> usize {
    ((nt as f64 * (i + 1) as f64 / FIFTHS as f64).round() as usize).clamp(1, nt)
}

/// `η_raw` of the whole run from the reduced coordinates `q` (r × n_t) of `basis` and `qp`
/// (r⁺ × n_t) of `enriched`, both with orthonormal columns and the same reference.
pub fn raw_estimate_reduced(basis: &Basis, enriched: &Basis, q: &Array2<f64>, qp: &Array2<f64>) -> f64 {
    raw_estimate_by_time(basis, enriched, q, qp)[FIFTHS - 1]
}

/// `η_raw` (relative) over the instants up to the end of each fifth of the run: [`raw_by_time`]'s
/// `relative`.
pub fn raw_estimate_by_time(basis: &Basis, enriched: &Basis, q: &Array2<f64>, qp: &Array2<f64>) -> ByFifth {
    raw_by_time(basis, enriched, q, qp, enriched.reference.view(), 0.0).relative
}

/// `η_raw` in both measures over the instants up to the end of each fifth of the run (the
/// last entry is the whole run's), as [`rel_error_by_time`] and
/// [`displacement_error_by_time`] split the true errors; `x0` is the initial configuration
/// X₀ (n_dof) and `resolution` the coordinates' ([`displacement_ratio`]). ∞ when the shapes
/// differ. An estimator that reads many runs of one basis pair projects once
/// ([`NormProjection`]).
pub fn raw_by_time(
    basis: &Basis,
    enriched: &Basis,
    q: &Array2<f64>,
    qp: &Array2<f64>,
    x0: ArrayView1<f64>,
    resolution: f64,
) -> RawByFifth {
    NormProjection::new(basis, enriched, x0).raw_by_time(basis, enriched, q, qp, x0, resolution)
}

/// What [`raw_by_time`] projects for a pair of orthonormal bases, the same for every run:
/// `M = V⁺ᵀV`, `V⁺ᵀx_ref`, `‖x_ref‖²`, `V⁺ᵀ(x_ref − x₀)` and `‖x_ref − x₀‖²`. Built once, it
/// makes an estimate's norms cost O(r r⁺ n_t) instead of O(n_dof r r⁺) per run (the part
/// that grew with the mesh). `None` inside for whole-system bases (not orthonormal: each
/// run is reconstructed).
pub struct NormProjection {
    orthonormal: Option<Projected>,
}

struct Projected {
    m: Array2<f64>,
    /// the enriched basis's configuration norms
    config: ConfigurationNorms,
}

/// The constants of the configuration and displacement norms of `x = x_ref + V z` from the
/// reduced coordinates of an orthonormal `V` (module documentation): `‖x‖² = ‖x_ref‖² +
/// 2 (Vᵀx_ref)·z + ‖z‖²` and `‖x − x₀‖² = ‖Vᵀd + z‖² + (‖d‖² − ‖Vᵀd‖²)`, `d = x_ref − x₀`.
pub struct ConfigurationNorms {
    vtx: Array1<f64>,
    xr2: f64,
    /// `Vᵀd`
    vts: Array1<f64>,
    /// `‖d − V Vᵀd‖²` (= `‖d‖² − ‖Vᵀd‖²`), the shift's part outside the span of `V`
    outside2: f64,
    /// rows of `V`: a displacement at the resolution in every coordinate has `n_dof res²`
    n_dof: usize,
}

impl ConfigurationNorms {
    pub fn new(basis: &Basis, x0: ArrayView1<f64>) -> Self {
        let (v, xr) = (&basis.modes, &basis.reference);
        let shift = xr - &x0;
        let vts = v.t().dot(&shift);
        // from the residual itself: ‖d‖² − ‖Vᵀd‖² would cancel where d lies nearly in the
        // span (raw snapshots: d = −x₀), at ε‖d‖², far above a resolution-sized motion
        let outside = &shift - &v.dot(&vts);
        let outside2 = outside.dot(&outside);
        ConfigurationNorms { vtx: v.t().dot(xr), xr2: xr.dot(xr), vts, outside2, n_dof: v.nrows() }
    }

    /// `‖x‖²` and `‖x − x₀‖²` at one instant `z` whose `‖z‖²` is `z2`.
    pub fn at(&self, z: ArrayView1<f64>, z2: f64) -> (f64, f64) {
        let moved2: f64 = self.vts.iter().zip(z).map(|(s, z)| (s + z) * (s + z)).sum();
        (self.xr2 + 2.0 * self.vtx.dot(&z) + z2, moved2 + self.outside2)
    }

    /// [`Self::at`] at every instant (column) of `z`, whose squared norms are `z2`.
    fn per_instant(&self, z: &Array2<f64>, z2: &Array1<f64>) -> (Array1<f64>, Array1<f64>) {
        let moved = z + &self.vts.view().insert_axis(Axis(1));
        (self.xr2 + 2.0 * self.vtx.dot(z) + z2, moved.mapv(|v| v * v).sum_axis(Axis(0)) + self.outside2)
    }

    /// The coordinates of the configurations these norms are of.
    pub fn n_dof(&self) -> usize {
        self.n_dof
    }
}

impl NormProjection {
    pub fn new(basis: &Basis, enriched: &Basis, x0: ArrayView1<f64>) -> Self {
        if basis.variant == Variant::WholeSystem {
            return NormProjection { orthonormal: None };
        }
        NormProjection {
            orthonormal: Some(Projected {
                m: enriched.modes.t().dot(&basis.modes), // r⁺ × r
                config: ConfigurationNorms::new(enriched, x0),
            }),
        }
    }

    /// [`raw_by_time`] of the runs `q` (of `basis`) and `qp` (of `enriched`), the pair this
    /// projection was built for.
    pub fn raw_by_time(
        &self,
        basis: &Basis,
        enriched: &Basis,
        q: &Array2<f64>,
        qp: &Array2<f64>,
        x0: ArrayView1<f64>,
        resolution: f64,
    ) -> RawByFifth {
        let nt = qp.ncols();
        if q.ncols() != nt || nt == 0 {
            return RawByFifth::INFINITE;
        }
        // per instant: ‖x_r − x⁺‖², ‖x⁺‖², ‖x⁺ − x₀‖²
        let (diff2, norm2, disp2): (Array1<f64>, Array1<f64>, Array1<f64>) = match &self.orthonormal {
            None => {
                // V is not orthonormal: reconstruct x_ref + V q of both
                let (a, b) = (basis.reconstruct_columns(q.view()), enriched.reconstruct_columns(qp.view()));
                let moved = &b - &x0.insert_axis(Axis(1));
                (
                    (&a - &b).mapv(|v| v * v).sum_axis(Axis(0)),
                    b.mapv(|v| v * v).sum_axis(Axis(0)),
                    moved.mapv(|v| v * v).sum_axis(Axis(0)),
                )
            }
            Some(p) => {
                let mq = p.m.dot(q);
                let q2 = q.mapv(|v| v * v).sum_axis(Axis(0));
                let mq2 = mq.mapv(|v| v * v).sum_axis(Axis(0));
                let d = (&mq - qp).mapv(|v| v * v).sum_axis(Axis(0)) + (&q2 - &mq2).mapv(|v| v.max(0.0));
                let qp2 = qp.mapv(|v| v * v).sum_axis(Axis(0));
                let (norm, disp) = p.config.per_instant(qp, &qp2);
                (d, norm, disp)
            }
        };
        let upto = |per_instant: &Array1<f64>, end: usize| per_instant.slice(ndarray::s![..end]).sum().max(0.0);
        RawByFifth::from_sums(nt, enriched.modes.nrows(), resolution, |displacement, end| {
            (upto(&diff2, end), upto(if displacement { &disp2 } else { &norm2 }, end))
        })
    }
}

impl RawByFifth {
    /// Both measures up to the end of each fifth of a run of `nt` instants of `n_dof`
    /// coordinates, from `sums(displacement, end)`: the squared distance and the squared
    /// norm (the configuration's, or with `displacement` the motion's) summed over the
    /// instants `..end`. The displacement measure has the floor of [`displacement_ratio`].
    pub fn from_sums(nt: usize, n_dof: usize, resolution: f64, sums: impl Fn(bool, usize) -> (f64, f64)) -> Self {
        RawByFifth {
            relative: std::array::from_fn(|i| {
                let (d, n) = sums(false, fifth_end(nt, i));
                d.sqrt() / n.sqrt()
            }),
            displacement: std::array::from_fn(|i| {
                let end = fifth_end(nt, i);
                let (d, n) = sums(true, end);
                displacement_ratio(d, n, end * n_dof, resolution)
            }),
        }
    }
}

/// `‖a − b‖_F` and `‖b‖_F`, summed in the arrays' logical order (rows, then columns)
/// whatever their memory layout (a full run keeps its coordinates column-major, a reduced
/// one row-major), so that the same two runs always give the same bits.
pub fn distance_and_norm(a: &Array2<f64>, b: &Array2<f64>) -> (f64, f64) {
    assert_eq!(a.dim(), b.dim(), "arrays of one shape");
    let (mut d, mut n) = (0.0, 0.0);
    for (x, y) in a.iter().zip(b.iter()) {
        d += (x - y) * (x - y);
        n += y * y;
    }
    (d.sqrt(), n.sqrt())
}

/// `rel_error` of `a` against `b` over the instants `..k`, for the end of each fifth of
/// the run: `‖A[:, ..k] − B[:, ..k]‖_F / ‖B[:, ..k]‖_F`.
pub fn rel_error_by_time(a: &Array2<f64>, b: &Array2<f64>) -> ByFifth {
    let nt = b.ncols();
    let (mut diff, mut norm) = (Array1::<f64>::zeros(nt), Array1::<f64>::zeros(nt));
    for k in 0..nt {
        diff[k] = a.column(k).iter().zip(b.column(k)).map(|(x, y)| (x - y) * (x - y)).sum::<f64>();
        norm[k] = b.column(k).iter().map(|y| y * y).sum::<f64>();
    }
    std::array::from_fn(|i| {
        let end = fifth_end(nt, i);
        (diff.slice(ndarray::s![..end]).sum() / norm.slice(ndarray::s![..end]).sum()).sqrt()
    })
}

/// `displacement_error` of `a` against `b` over the instants `..k`, for the end of each
/// fifth of the run: `‖A[:, ..k] − B[:, ..k]‖_F / ‖B[:, ..k] − X₀‖_F`, with the initial
/// configuration `x0` subtracted from every column of `B`.
///
/// A run that has not moved more than `resolution` (the coordinates' resolution, the
/// Newton tolerance `tol · L`) in root mean square over those instants has no displacement
/// to measure against: ∞ where the two runs differ by more than that, else NaN. Without
/// the floor a run at rest divided one solver's noise by the other's (the pendulum at
/// λ = 0 read 28).
pub fn displacement_error_by_time(a: &Array2<f64>, b: &Array2<f64>, x0: ArrayView1<f64>, resolution: f64) -> ByFifth {
    let nt = b.ncols();
    let (mut diff, mut norm) = (Array1::<f64>::zeros(nt), Array1::<f64>::zeros(nt));
    for k in 0..nt {
        diff[k] = a.column(k).iter().zip(b.column(k)).map(|(x, y)| (x - y) * (x - y)).sum::<f64>();
        norm[k] = b.column(k).iter().zip(x0.iter()).map(|(y, o)| (y - o) * (y - o)).sum::<f64>();
    }
    std::array::from_fn(|i| {
        let end = fifth_end(nt, i);
        let (d, n) = (diff.slice(ndarray::s![..end]).sum(), norm.slice(ndarray::s![..end]).sum());
        displacement_ratio(d, n, end * b.nrows(), resolution)
    })
}

/// `(d2 / n2)^½`, a distance over a displacement from their squared sums over `values`
/// coordinate values, where the displacement is above the coordinates' `resolution` in root
/// mean square ([`against_motion`]: ∞ where only the distance is, NaN where neither is).
pub fn displacement_ratio(d2: f64, n2: f64, values: usize, resolution: f64) -> f64 {
    // the squared norm of `values` coordinate values each at the resolution
    let floor = values as f64 * resolution * resolution;
    against_motion(n2 > floor, d2 > floor, || (d2 / n2).sqrt())
}

/// The coordinates' resolution of `run`: its Newton tolerance in length units, `tol · L`
/// (`length` the model's length scale, `L`).
pub fn resolution(run: &crate::rom::run::ReducedRun, length: f64) -> f64 {
    run.result.settings.params.tolerance * length
}

/// An error measured against a motion (its definition lives with the quantities, which
/// measure against ranges the same way).
pub use crate::rom::quantities::against_motion;

#[cfg(test)]
mod tests {
    use super::*;

    /// A Galerkin basis of `modes` about `reference`, without hyper-reduction.
    fn galerkin(modes: Array2<f64>, reference: Array1<f64>) -> Basis {
        Basis {
            variant: Variant::Galerkin,
            snapshots: crate::reduction::SnapshotKind::Reference,
            reference,
            n_pod_modes: modes.ncols(),
            modes,
            kept: vec![],
            multiplier_modes: None,
            multiplier_scale: 1.0,
            hyper: None,
        }
    }

    /// The reduced-coordinate norms equal the full-coordinate ones for nested orthonormal
    /// bases and for bases that are not nested (random rotations of a 3-column basis).
    #[test]
    fn reduced_norms_match_full_reconstruction() {
        let n = 7;
        let nt = 4;
        let a =
            Array2::from_shape_fn((n, 5), |(i, j)| ((i * 5 + j) as f64 * 0.37).sin() + if i == j { 2.0 } else { 0.0 });
        let (qf, _) = crate::linalg::lapack::QR::qr(&a).unwrap();
        let vp = qf.slice(ndarray::s![.., ..5]).to_owned();
        let reference = Array1::from_shape_fn(n, |i| 0.1 * i as f64 + 1.0);
        let mk = |modes: Array2<f64>| galerkin(modes, reference.clone());
        let plus = mk(vp.clone());

        // nested (first 3 columns) and not nested (mixing columns 2..5)
        let nested = vp.slice(ndarray::s![.., ..3]).to_owned();
        let mixed = {
            let (q, _) = crate::linalg::lapack::QR::qr(
                &(&vp.slice(ndarray::s![.., 1..4]) + &(0.3 * &qf.slice(ndarray::s![.., 4..5]))),
            )
            .unwrap();
            q
        };
        for small in [nested, mixed] {
            let b = mk(small);
            let q = Array2::from_shape_fn((b.n_reduced(), nt), |(i, k)| (i as f64 + 1.0) * (k as f64 * 0.5).cos());
            let qp = Array2::from_shape_fn((5, nt), |(i, k)| (i as f64 - 1.0) * (k as f64 * 0.3).sin());
            let (x1, x2) = (b.reconstruct_columns(q.view()), plus.reconstruct_columns(qp.view()));
            let want = (&x1 - &x2).mapv(|v| v * v).sum().sqrt() / x2.mapv(|v| v * v).sum().sqrt();
            let got = raw_estimate_reduced(&b, &plus, &q, &qp);
            assert!((got - want).abs() < 1e-12 * want.max(1.0), "{got} vs {want}");
            // the displacement form against X₀, an initial configuration off the reference
            // (and outside the span of V⁺): ‖X_r − X⁺‖ / ‖X⁺ − X₀‖ reconstructed in full
            let x0 = Array1::from_shape_fn(n, |i| 1.0 + 0.1 * i as f64 + 0.05 * (i as f64 * 1.3).sin());
            let moved = &x2 - &x0.view().insert_axis(Axis(1));
            let want_d = (&x1 - &x2).mapv(|v| v * v).sum().sqrt() / moved.mapv(|v| v * v).sum().sqrt();
            let both = raw_by_time(&b, &plus, &q, &qp, x0.view(), 0.0);
            assert!(
                (both.displacement[4] - want_d).abs() < 1e-12 * want_d.max(1.0),
                "{} vs {want_d}",
                both.displacement[4]
            );
            assert_eq!(both.relative[4], got);
            // and by fifth: the first two instants (the first fifth of four instants is one)
            for (i, end) in [(0, 1), (2, 2), (4, 4)] {
                assert_eq!(fifth_end(nt, i), end);
                let s = ndarray::s![.., ..end];
                let w = (&x1.slice(s) - &x2.slice(s)).mapv(|v| v * v).sum().sqrt()
                    / moved.slice(s).mapv(|v| v * v).sum().sqrt();
                assert!(
                    (both.displacement[i] - w).abs() < 1e-12 * w.max(1.0),
                    "fifth {i}: {} vs {w}",
                    both.displacement[i]
                );
            }
        }
    }

    /// The displacement form of the estimate when the motion is small against the
    /// reference's distance from X₀ (here 1e3 against 1e-7 per instant): the expanded
    /// square `‖d‖² + 2 (V⁺ᵀd)·q⁺ + ‖q⁺‖²` rounds at ε · 1e6 ≈ 2e-10 and reads noise; the
    /// in-span square reads the closed form `√e · c / √(Σ_{k<e} (1e-7 k)²)` (the runs
    /// differ by `c` in one coordinate at every instant). Where the enriched run does not
    /// move beyond the resolution the measure is undefined (NaN), or ∞ where the reduced
    /// run differs by more than it.
    #[test]
    fn displacement_estimate_of_a_small_motion_far_from_the_reference() {
        let (n, nt, c) = (6, 10, 1e-9);
        let eye = Array2::from_shape_fn((n, 3), |(i, j)| if i == j { 1.0 } else { 0.0 });
        // x₀ is zero in the modes' coordinates, so x_ref + V q⁺ − x₀ is exact there
        let x0 = Array1::from_shape_fn(n, |i| if i < 3 { 0.0 } else { 2.0 + i as f64 });
        let reference = &x0 + &Array1::from_shape_fn(n, |i| if i == 0 { 1e3 } else { 0.0 });
        let b = galerkin(eye, reference);
        let qp = Array2::from_shape_fn((3, nt), |(i, k)| [-1e3, 1e-7 * k as f64, 0.0][i]);
        let q = Array2::from_shape_fn((3, nt), |(i, k)| qp[[i, k]] + if i == 2 { c } else { 0.0 });
        let got = raw_by_time(&b, &b, &q, &qp, x0.view(), 1e-12).displacement;
        for (i, g) in got.iter().enumerate() {
            let e = fifth_end(nt, i);
            let travel2: f64 = (0..e).map(|k| (1e-7 * k as f64).powi(2)).sum();
            let want = (e as f64).sqrt() * c / travel2.sqrt();
            assert!((g - want).abs() < 1e-12 * want, "fifth {i}: {g} vs {want}");
        }
        let still = Array2::from_shape_fn((3, nt), |(i, _)| [-1e3, 0.0, 0.0][i]);
        assert!(raw_by_time(&b, &b, &still, &still, x0.view(), 1e-12).displacement[4].is_nan());
        assert!(raw_by_time(&b, &b, &(&still + 1e-6), &still, x0.view(), 1e-12).displacement[4].is_infinite());
    }

    /// A run against the same run shifted by a known displacement field: X_f(t_k) = X₀ + k u
    /// (‖u‖ = 0.5) and X_r = X_f + c w (‖w‖ = 1, the same at every instant). In closed form,
    /// over the instants 0 … e − 1,
    ///
    /// ```text
    ///     displacement_error = √e · c / (0.5 √(Σ_{k<e} k²)),    Σ_{k<e} k² = (e − 1) e (2e − 1) / 6,
    /// ```
    ///
    /// while rel_error divides by ‖X_f‖, which holds X₀ (‖X₀‖ ≈ 12 against a travel of 4.5)
    /// at every instant, and reads less.
    #[test]
    fn displacement_error_of_a_shifted_run_is_the_closed_form() {
        let (n, nt, c) = (6, 10, 1e-3);
        let x0 = Array1::from_shape_fn(n, |i| 2.0 + i as f64);
        let u = Array1::from_shape_fn(n, |i| [0.3, 0.4, 0.0, 0.0, 0.0, 0.0][i]);
        let w = Array1::from_shape_fn(n, |i| if i == 2 { 1.0 } else { 0.0 });
        let full = Array2::from_shape_fn((n, nt), |(i, k)| x0[i] + k as f64 * u[i]);
        let reduced = Array2::from_shape_fn((n, nt), |(i, k)| full[[i, k]] + c * w[i]);
        let got = displacement_error_by_time(&reduced, &full, x0.view(), 1e-10);
        for (i, g) in got.iter().enumerate() {
            let e = fifth_end(nt, i) as f64;
            let want = e.sqrt() * c / (0.5 * ((e - 1.0) * e * (2.0 * e - 1.0) / 6.0).sqrt());
            // X₀ + k u − X₀ and X_f + c w − X_f round at the last digits of X₀ and X_f (≈ 10)
            assert!((g - want).abs() < 1e-11 * want, "fifth {i}: {g} vs {want}");
        }
        let rel = rel_error_by_time(&reduced, &full);
        assert!(rel[4] < got[4] / 2.0, "rel_error {} against displacement_error {}", rel[4], got[4]);
        // a run that has not moved has no displacement to measure against, nor one that
        // moved less than the resolution (the pendulum at λ = 0 read 28 without the floor)
        let still = Array2::from_shape_fn((n, nt), |(i, _)| x0[i]);
        assert!(displacement_error_by_time(&still, &still, x0.view(), 1e-10)[4].is_nan());
        assert!(displacement_error_by_time(&(&still + 1e-3), &still, x0.view(), 1e-10)[4].is_infinite());
        let noise = |a: f64| Array2::from_shape_fn((n, nt), |(i, k)| x0[i] + a * ((i * nt + k) as f64).sin());
        assert!(displacement_error_by_time(&noise(3e-11), &noise(-2e-11), x0.view(), 1e-10)[4].is_nan());
        assert!(displacement_error_by_time(&noise(1e-9), &noise(-2e-11), x0.view(), 1e-10)[4].is_infinite());
        // one resolved: a displacement of 1e-9 per coordinate against a resolution of 1e-10
        let moved = displacement_error_by_time(&noise(1.1e-9), &noise(1e-9), x0.view(), 1e-10)[4];
        assert!((moved - 0.1).abs() < 1e-6, "{moved}");
    }

    /// The estimate over prefixes of the run: zero while the two runs agree; non-decreasing
    /// when the distance per instant grows and the norm per instant is constant (then each
    /// prefix value is the RMS of a growing sequence); the last is the whole run's.
    #[test]
    fn estimate_by_time_follows_a_growing_error() {
        let (n, nt) = (4, 20);
        let eye = Array2::from_shape_fn((n, n), |(i, j)| if i == j { 1.0 } else { 0.0 });
        let mk = |modes: Array2<f64>| galerkin(modes, Array1::zeros(n));
        let (b, plus) = (mk(eye.clone()), mk(eye));
        // X⁺ rotates at unit norm; X_r lags it by nothing for 8 instants, then by a growing angle
        let lag = |k: usize| if k < 8 { 0.0 } else { 0.01 * (k - 7) as f64 };
        let qp = Array2::from_shape_fn((n, nt), |(i, k)| match i {
            0 => (0.1 * k as f64).cos(),
            1 => (0.1 * k as f64).sin(),
            _ => 0.0,
        });
        let q = Array2::from_shape_fn((n, nt), |(i, k)| match i {
            0 => (0.1 * k as f64 - lag(k)).cos(),
            1 => (0.1 * k as f64 - lag(k)).sin(),
            _ => 0.0,
        });
        let by = raw_estimate_by_time(&b, &plus, &q, &qp);
        assert_eq!(&by[..2], &[0.0, 0.0], "{by:?}");
        assert!(by.windows(2).all(|w| w[1] >= w[0]) && by[4] > by[2], "{by:?}");
        let whole = (&q - &qp).mapv(|v| v * v).sum().sqrt() / qp.mapv(|v| v * v).sum().sqrt();
        assert!((by[4] - whole).abs() < 1e-14, "{} vs {whole}", by[4]);
        assert_eq!(by[4], raw_estimate_reduced(&b, &plus, &q, &qp));
    }

    /// The distance and the norm are the Frobenius ones (3-4-5 numbers), and the same bits
    /// for row- and column-major copies of the same arrays (the full run keeps q
    /// column-major, a file or a reduced run row-major).
    #[test]
    fn distance_and_norm_do_not_depend_on_the_layout() {
        let b = ndarray::array![[3.0, 0.0], [0.0, 4.0]];
        assert_eq!(distance_and_norm(&Array2::zeros((2, 2)), &b), (5.0, 5.0));
        let b = Array2::from_shape_fn((7, 33), |(i, k)| (0.3 * i as f64 + 0.17 * k as f64).sin() * 1e3);
        let a = Array2::from_shape_fn((7, 33), |(i, k)| b[[i, k]] + 1e-3 * ((i * k) as f64).cos());
        let f = |x: &Array2<f64>| {
            let mut y = Array2::zeros(ndarray::ShapeBuilder::f(x.dim()));
            y.assign(x);
            y
        };
        let (af, bf) = (f(&a), f(&b));
        assert!(af.as_slice().is_none() && af.t().as_slice().is_some(), "column-major copy");
        let bits = |(d, n): (f64, f64)| (d.to_bits(), n.to_bits());
        assert_eq!(bits(distance_and_norm(&a, &b)), bits(distance_and_norm(&af, &bf)));
        assert_eq!(bits(distance_and_norm(&a, &b)), bits(distance_and_norm(&af, &b)));
    }

    /// rel_error over growing prefixes; the last one is the whole run's.
    #[test]
    fn rel_error_by_time_ends_with_the_whole_run() {
        let b = Array2::from_shape_fn((3, 10), |(i, k)| 1.0 + i as f64 + k as f64);
        let a = Array2::from_shape_fn((3, 10), |(i, k)| b[[i, k]] + if k >= 8 { 0.5 } else { 0.0 });
        let r = rel_error_by_time(&a, &b);
        assert_eq!(r.len(), 5);
        assert!(r[..4].iter().all(|&v| v == 0.0), "{r:?}");
        let whole = (&a - &b).mapv(|v| v * v).sum().sqrt() / b.mapv(|v| v * v).sum().sqrt();
        assert!((r[4] - whole).abs() < 1e-15);
    }
}
