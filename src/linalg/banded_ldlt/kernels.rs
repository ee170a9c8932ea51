//! The kernels of [`super::BandedLdlt`]: the band `LDLᵀ` factorization without pivoting
//! and its substitutions, monomorphized for the common half-bandwidths (the pivot checks
//! are the module doc's of [`super`]).

/// A coordinate pivot must keep at least this fraction of its diagonal entry (a smaller one
/// means `S₁₁` is nearly singular or indefinite there), a constraint pivot this fraction of
/// the constraint scale.
pub(super) const PIVOT_RATIO: f64 = 1e-8;

/// `LDLᵀ` without pivoting of a symmetric band matrix in place: `A(i, j)`, `0 ≤ i − j ≤ b`,
/// at `ab[j (b+1) + i − j]`; on return `D` on the diagonal and `L` (unit diagonal not
/// stored) below. Right-looking: for column j, `d_j = a_jj`, `l_ij = a_ij/d_j`, and
/// `a_ik −= l_ij d_j l_kj` for `j < k ≤ i ≤ j + b`. Returns false, leaving `ab` spoilt, as
/// soon as a pivot fails the checks of the module doc (`is_dof[j]` tells which sign row j
/// needs; `cons_min` is the smallest constraint pivot magnitude accepted).
/// `diag` (n entries) is scratch for the diagonal before the updates, against which a
/// coordinate pivot is checked.
pub fn band_ldlt(ab: &mut [f64], n: usize, b: usize, is_dof: &[bool], cons_min: f64, diag: &mut [f64]) -> bool {
    for (j, d) in diag[..n].iter_mut().enumerate() {
        *d = ab[j * (b + 1)];
    }
    let diag: &[f64] = diag;
    // monomorphized for the common half-bandwidths, as band_lu
    macro_rules! dispatch {
        ($($k:literal)*) => {
            match b {
                $($k => band_ldlt_impl::<$k>(ab, n, b, is_dof, cons_min, diag),)*
                _ => band_ldlt_impl::<0>(ab, n, b, is_dof, cons_min, diag),
            }
        };
    }
    dispatch!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16)
}

fn band_ldlt_impl<const B: usize>(
    ab: &mut [f64],
    n: usize,
    b: usize,
    is_dof: &[bool],
    cons_min: f64,
    diag: &[f64],
) -> bool {
    let ld = b + 1;
    let mut w = [0.0_f64; 64];
    let mut l = [0.0_f64; 64];
    let mut wv = vec![0.0; if b > 64 { b } else { 0 }];
    let mut lv = vec![0.0; if b > 64 { b } else { 0 }];
    // the next pivot as computed by the last column's update, held in a register: the
    // chain from pivot to pivot (divide, scale, update) is what bounds this loop, and
    // reading the pivot back from memory would add a store-to-load round trip to it
    let mut next_pivot = None;
    for j in 0..n {
        let km = b.min(n - 1 - j);
        let (head, rest) = ab.split_at_mut((j + 1) * ld);
        let col = &mut head[j * ld..(j + 1) * ld];
        let d = next_pivot.take().unwrap_or(col[0]);
        let ok = if is_dof[j] { d.is_finite() && d > PIVOT_RATIO * diag[j] } else { d.is_finite() && d < -cons_min };
        if !ok {
            return false;
        }
        let inv = 1.0 / d;
        if B != 0 && km == B {
            // w (the column before scaling) and l as values, not through the scratch arrays:
            // stored one by one and reloaded two at a time by the vectorized update, they
            // stall on store-to-load forwarding (a fifth of this function's time)
            let w: [f64; B] = std::array::from_fn(|r| col[1 + r]);
            let l: [f64; B] = std::array::from_fn(|r| w[r] * inv);
            col[1..=B].copy_from_slice(&l);
            // the value the update below gives entry (j+1, j+1), the same operation
            next_pivot = Some(rest[0] - l[0] * w[0]);
            // column j+1+k holds rows j+1+k..: entry (j+1+i, j+1+k) at k ld + i − k
            for k in 0..B {
                let wk = w[k];
                let tgt = &mut rest[k * ld..k * ld + B - k];
                for i in k..B {
                    tgt[i - k] -= l[i] * wk;
                }
            }
        } else {
            let (w, l): (&mut [f64], &mut [f64]) =
                if b > 64 { (&mut wv[..km], &mut lv[..km]) } else { (&mut w[..km], &mut l[..km]) };
            for r in 0..km {
                w[r] = col[1 + r];
                l[r] = w[r] * inv;
                col[1 + r] = l[r];
            }
            for k in 0..km {
                let wk = w[k];
                let tgt = &mut rest[k * ld..k * ld + km - k];
                for i in k..km {
                    tgt[i - k] -= l[i] * wk;
                }
            }
        }
    }
    true
}

/// Solves `A x = rhs` in place with the factors of [`band_ldlt`]: `L y = rhs`, `D z = y`,
/// `Lᵀ x = z`.
pub fn band_ldlt_solve(ab: &[f64], n: usize, b: usize, x: &mut [f64]) {
    macro_rules! dispatch {
        ($($k:literal)*) => {
            match b {
                $($k => band_ldlt_solve_impl::<$k>(ab, n, b, x),)*
                _ => band_ldlt_solve_impl::<0>(ab, n, b, x),
            }
        };
    }
    dispatch!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16)
}

fn band_ldlt_solve_impl<const B: usize>(ab: &[f64], n: usize, b: usize, x: &mut [f64]) {
    // Row-oriented substitutions that carry the last b solved values in a window of
    // registers (`win`): the column-oriented form (`x[j+1..j+b] −= l x_j`) stores each
    // entry and reloads it, two at a time, one row later, across two stores, and stalls on
    // store-to-load forwarding at every row. The operations and their order are those of
    // the column form, so the bits are the same: row i subtracts the terms of columns
    // j = i−b, …, i−1 in that order, and only the last waits for the row just solved.
    let ld = b + 1;
    // L y = rhs: y_i = rhs_i − Σ_{j = i−b}^{i−1} L(i, j) y_j, L(i, j) at ab[j ld + i − j]
    let full = if B != 0 { B.min(n) } else { n };
    for i in 0..full {
        let mut acc = x[i];
        for j in i.saturating_sub(b)..i {
            acc -= ab[j * ld + i - j] * x[j];
        }
        x[i] = acc;
    }
    if B != 0 && n > B {
        // win[m] = y_{i−B+m}
        let mut win: [f64; B] = std::array::from_fn(|m| x[m]);
        for i in B..n {
            let mut acc = x[i];
            for m in 0..B {
                acc -= ab[(i - B + m) * ld + B - m] * win[m];
            }
            x[i] = acc;
            win = std::array::from_fn(|m| if m + 1 < B { win[m + 1] } else { acc });
        }
    }
    // D z = y and Lᵀ x = z: x_j = y_j / d_j − Σ_{r=1}^{b} L(j+r, j) x_{j+r}
    let short = if B != 0 { n.min(B) } else { n };
    for j in (n - short..n).rev() {
        let km = b.min(n - 1 - j);
        let l = &ab[j * ld + 1..j * ld + 1 + km];
        let s: f64 = x[j + 1..j + 1 + km].iter().zip(l).map(|(a, m)| a * m).sum();
        x[j] = x[j] / ab[j * ld] - s;
    }
    if B != 0 && n > B {
        // win[m] = x_{j+1+m}
        let mut win: [f64; B] = std::array::from_fn(|m| x[n - B + m]);
        for j in (0..n - B).rev() {
            let l: &[f64; B] = (&ab[j * ld + 1..j * ld + 1 + B]).try_into().expect("length B");
            // x_{j+1}, just solved, enters last: the terms of the rows further down do not
            // wait for it (two partial sums, the chain from row to row one multiply-add)
            let (mut s0, mut s1) = (0.0, 0.0);
            let mut r = 1;
            while r + 1 < B {
                s0 += win[r] * l[r];
                s1 += win[r + 1] * l[r + 1];
                r += 2;
            }
            if r < B {
                s0 += win[r] * l[r];
            }
            let xj = x[j] / ab[j * ld] - (s0 + s1) - win[0] * l[0];
            x[j] = xj;
            win = std::array::from_fn(|m| if m == 0 { xj } else { win[m - 1] });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The textbook column-oriented `LDLᵀ` and substitutions (the form the doc comments
    /// state, with no register windows or carried pivots), as the reference the kernels
    /// must match to the bit.
    fn reference_factor_and_solve(ab: &mut [f64], n: usize, b: usize, x: &mut [f64]) {
        let ld = b + 1;
        for j in 0..n {
            let km = b.min(n - 1 - j);
            let inv = 1.0 / ab[j * ld];
            let w: Vec<f64> = (0..km).map(|r| ab[j * ld + 1 + r]).collect();
            let l: Vec<f64> = w.iter().map(|w| w * inv).collect();
            ab[j * ld + 1..j * ld + 1 + km].copy_from_slice(&l);
            for k in 0..km {
                for i in k..km {
                    ab[(j + 1 + k) * ld + i - k] -= l[i] * w[k];
                }
            }
        }
        for j in 0..n {
            let km = b.min(n - 1 - j);
            for r in 0..km {
                x[j + 1 + r] -= ab[j * ld + 1 + r] * x[j];
            }
        }
        for j in 0..n {
            x[j] /= ab[j * ld];
        }
        for j in (0..n).rev() {
            let km = b.min(n - 1 - j);
            let l = &ab[j * ld + 1..j * ld + 1 + km];
            let (head, tail) = x.split_at_mut(j + 1);
            let (xj, t) = (&mut head[j], &tail[..km]);
            // the kernel's order: the odd and the even terms from the second on in two
            // sums, then the first term (the general path: one sum in order)
            let s = if km == b && (1..=16).contains(&b) {
                let (mut s0, mut s1) = (0.0, 0.0);
                let mut r = 1;
                while r + 1 < b {
                    s0 += t[r] * l[r];
                    s1 += t[r + 1] * l[r + 1];
                    r += 2;
                }
                if r < b {
                    s0 += t[r] * l[r];
                }
                *xj -= s0 + s1;
                t[0] * l[0]
            } else {
                t.iter().zip(l).map(|(a, m)| a * m).sum()
            };
            *xj -= s;
        }
    }

    /// Factors and solutions of [`band_ldlt`] and [`band_ldlt_solve`] equal the reference
    /// to the bit, for half-bandwidths with a monomorphized kernel (1, 2, 7, 16), without
    /// one (17, 23), and matrices shorter than their band: the rewritten kernels compute
    /// the same operations in the same order. Matrix: symmetric, diagonally dominant,
    /// entries from a fixed sequence.
    #[test]
    fn kernels_match_the_column_oriented_reference_to_the_bit() {
        for b in [1, 2, 7, 16, 17, 23] {
            for n in [b / 2 + 1, b + 1, 3 * b + 5, 60] {
                let ld = b + 1;
                let mut ab: Vec<f64> = (0..n * ld)
                    .map(|s| if s % ld == 0 { 10.0 + 2.0 * b as f64 } else { ((s * 7919) % 97) as f64 / 97.0 - 0.5 })
                    .collect();
                for j in 0..n {
                    for r in n - j..ld {
                        ab[j * ld + r] = 0.0; // outside the matrix
                    }
                }
                let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 0.1).collect();
                let (mut ab_ref, mut x_ref) = (ab.clone(), rhs.clone());
                reference_factor_and_solve(&mut ab_ref, n, b, &mut x_ref);
                let mut diag = vec![0.0; n];
                assert!(band_ldlt(&mut ab, n, b, &vec![true; n], 0.0, &mut diag), "b {b} n {n}");
                let mut x = rhs.clone();
                band_ldlt_solve(&ab, n, b, &mut x);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&ab), bits(&ab_ref), "factors, b {b} n {n}");
                assert_eq!(bits(&x), bits(&x_ref), "solution, b {b} n {n}");
            }
        }
    }
}
