//! The columns of `V` a sampled element sees (at most two runs) and the packed-row kernels
//! that add one element's `Gₑ` and rank-one terms to the hyper-reduced tangent on them.

/// The columns of `V` an element sees: the runs `a` and `b` (`b` empty when one will do).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Cols {
    pub(super) a: (usize, usize),
    pub(super) b: (usize, usize),
}

impl Cols {
    /// The nonzero columns of `ve` (ne × r): from the first to the last one, less the
    /// longest run of zero columns between them.
    pub(super) fn of(ve: ndarray::ArrayView2<f64>) -> Cols {
        let nz: Vec<usize> = (0..ve.ncols()).filter(|&c| ve.column(c).iter().any(|&x| x != 0.0)).collect();
        let (Some(&first), Some(&last)) = (nz.first(), nz.last()) else {
            return Cols { a: (0, 0), b: (0, 0) };
        };
        let gap = nz.windows(2).max_by_key(|w| w[1] - w[0]).filter(|w| w[1] - w[0] > 1);
        match gap {
            Some(w) => Cols { a: (first, w[0] + 1), b: (w[1], last + 1) },
            None => Cols { a: (first, last + 1), b: (last + 1, last + 1) },
        }
    }

    pub(super) fn n1(&self) -> usize {
        self.a.1 - self.a.0
    }

    pub(super) fn len(&self) -> usize {
        self.n1() + self.b.1 - self.b.0
    }

    /// The global columns, in local order.
    pub(super) fn iter(&self) -> impl Iterator<Item = usize> {
        (self.a.0..self.a.1).chain(self.b.0..self.b.1)
    }

    /// Local row `l` of the packed upper triangle in the row-major r × r matrix: its first
    /// piece starts on the diagonal at `at` and has `len` entries; the second, when
    /// `len2 > 0`, starts at `at2` and takes the next `len2` packed entries.
    #[inline(always)]
    pub(super) fn row(&self, l: usize, r: usize) -> (usize, usize, usize, usize) {
        let (n1, n2) = (self.n1(), self.b.1 - self.b.0);
        if l < n1 {
            let i = self.a.0 + l;
            (i * r + i, n1 - l, i * r + self.b.0, n2)
        } else {
            let i = self.b.0 + l - n1;
            (i * r + i, n1 + n2 - l, 0, 0)
        }
    }
}

/// `o += a g + c u` (a row of the tangent: one element's `Gₑ` row and rank-one term).
#[inline(always)]
pub(super) fn add_row(o: &mut [f64], g: &[f32], u: &[f64], a: f64, c: f64) {
    for ((o, &x), &v) in o.iter_mut().zip(g).zip(u) {
        *o += a * f64::from(x) + c * v;
    }
}

/// `acc += a Gₑ + b u uᵀ` on the element's columns `c`: one pass per row (the packed rows
/// of `Gₑ`, upper triangle, follow each other).
#[inline(always)]
pub(super) fn add_element(acc: &mut [f64], c: &Cols, r: usize, g: &[f32], u: &[f64], a: f64, b: f64) {
    let me = c.len();
    let mut p = 0;
    for l in 0..me {
        let (at, len, at2, len2) = c.row(l, r);
        add_row(&mut acc[at..at + len], &g[p..p + len], &u[l..l + len], a, b * u[l]);
        if len2 > 0 {
            add_row(&mut acc[at2..at2 + len2], &g[p + len..p + len + len2], &u[me - len2..me], a, b * u[l]);
        }
        p += len + len2;
    }
}

/// [`add_row`] for two elements at once.
#[inline(always)]
pub(super) fn add_row_pair(o: &mut [f64], g: (&[f32], &[f32]), u: (&[f64], &[f64]), a: (f64, f64), c: (f64, f64)) {
    let rows = g.0.iter().zip(g.1).zip(u.0.iter().zip(u.1));
    for (o, ((&x1, &x2), (&v1, &v2))) in o.iter_mut().zip(rows) {
        *o += (a.0 * f64::from(x1) + c.0 * v1) + (a.1 * f64::from(x2) + c.1 * v2);
    }
}
