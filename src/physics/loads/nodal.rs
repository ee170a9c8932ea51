//! The form a load on a few coordinates is lowered to; the kinds' files import it,
//! [`super`] re-exports it.

pub use crate::physics::joints::NodeIndex;
pub use crate::solver::parameters::Scaling;

/// Reads a global coordinate (or velocity) by its index.
pub type Read<'a> = &'a dyn Fn(usize) -> f64;

/// A load on a few global coordinates, at amplitude factor `factor` and time `t`, in the
/// sign of the model's force `g = … − Q_ext`. `q` and `v` read a coordinate and its rate
/// (only those of [`NodalLoad::dofs`] are read; `v` only by a load that
/// [`NodalLoad::has_damping`]).
pub trait NodalLoad: std::fmt::Debug + Send + Sync {
    /// The coordinates it acts on and depends on.
    fn dofs(&self) -> &[usize];
    fn scaling(&self) -> &Scaling;
    /// Calls `add(dof, value)` with its contributions `−Q_ext` to `g`.
    fn add_force(&self, factor: f64, t: f64, q: Read, v: Read, add: &mut dyn FnMut(usize, f64));
    /// Whether `−Q_ext` depends on the coordinates ([`Self::add_stiffness`] adds something).
    fn has_stiffness(&self) -> bool {
        false
    }
    /// Calls `add(row dof, column dof, value)` with the entries of `∂(−Q_ext)/∂q`.
    fn add_stiffness(&self, _factor: f64, _t: f64, _q: Read, _v: Read, _add: &mut dyn FnMut(usize, usize, f64)) {}
    /// Whether `−Q_ext` depends on the velocities (a damper: [`Self::add_damping`] adds
    /// something).
    fn has_damping(&self) -> bool {
        false
    }
    /// Calls `add(row dof, column dof, value)` with the entries of `∂(−Q_ext)/∂q̇`.
    fn add_damping(&self, _factor: f64, _t: f64, _q: Read, _v: Read, _add: &mut dyn FnMut(usize, usize, f64)) {}
    /// Whether [`Self::add_stiffness`] gives each entry and its mirror by the same
    /// operations (symmetric to the bit), so that the iteration matrix stays symmetric.
    fn symmetric(&self) -> bool {
        true
    }
    /// For a load stored in the system (a spring): its potential energy `V(q)` and rate
    /// `V̇ = ∇V · q̇` at the factor `factor`; `None` for an external load, whose power counts
    /// as external work.
    fn stored_energy(&self, _factor: f64, _q: Read, _v: Read) -> Option<(f64, f64)> {
        None
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::NodalLoad;

    /// A global vector of coordinates or velocities.
    pub type Dense = Vec<f64>;

    /// `g` of `load` at `(q, v)` over all coordinates.
    fn force(load: &dyn NodalLoad, q: &[f64], v: &[f64]) -> Dense {
        let mut g = vec![0.0; q.len()];
        load.add_force(1.0, 0.0, &|d| q[d], &|d| v[d], &mut |d, x| g[d] += x);
        g
    }

    /// Checks `add_stiffness` against central differences of `add_force` in `q`, and
    /// `add_damping` against those in `v` (relative 1e-6: the difference's truncation error
    /// is O(h²) = 1e-14 relative, its round-off ~1e-16/h).
    pub fn check_jacobians(load: &dyn NodalLoad, q: &[f64], v: &[f64]) {
        let n = q.len();
        let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
        load.add_stiffness(1.0, 0.0, &|d| q[d], &|d| v[d], &mut |r, col, x| k[r * n + col] += x);
        if load.has_damping() {
            load.add_damping(1.0, 0.0, &|d| q[d], &|d| v[d], &mut |r, col, x| c[r * n + col] += x);
        }
        let h = 1e-7;
        let scale = k.iter().chain(&c).fold(0.0_f64, |m, x| m.max(x.abs()));
        for &col in load.dofs() {
            for (wrt, jac) in [(0, &k), (1, &c)] {
                let (mut plus, mut minus) = ([q.to_vec(), v.to_vec()], [q.to_vec(), v.to_vec()]);
                plus[wrt][col] += h;
                minus[wrt][col] -= h;
                let (gp, gm) = (force(load, &plus[0], &plus[1]), force(load, &minus[0], &minus[1]));
                for r in 0..n {
                    let fd = (gp[r] - gm[r]) / (2.0 * h);
                    let want = jac[r * n + col];
                    assert!((fd - want).abs() <= 1e-6 * scale, "∂g[{r}]/∂{}[{col}]: {fd} vs {want}", ["q", "v"][wrt]);
                }
            }
        }
    }
}
