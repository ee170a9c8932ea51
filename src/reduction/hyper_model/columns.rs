//! The columns of `V` a sampled element sees (at most two runs), and where its upper
//! triangle lies in the row-major r × r tangent.

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
