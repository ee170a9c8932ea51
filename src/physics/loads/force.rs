//! A force `F f(t)` at a node, on its position coordinates (`f = 1` without a function): a
//! dead load, the same whatever the node's position, so it has no stiffness.

use super::nodal::{NodalLoad, NodeIndex, Read, Scaling};
use crate::physics::parts::NodeId;
use crate::physics::time_function::TimeFunction;

/// A force on a node, as the model file gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct Force {
    pub node: NodeId,
    /// `F` in N, in the global frame
    pub value: [f64; 2],
    pub function: Option<TimeFunction>,
    pub scaled: Scaling,
}

impl Force {
    /// The force on the global position coordinates of its node.
    pub fn lower(&self, first: NodeIndex) -> NodalForce {
        let d = first(self.node);
        NodalForce { dofs: [d, d + 1], value: self.value, function: self.function.clone(), scaled: self.scaled.clone() }
    }
}

/// [`Force`] on global coordinates.
#[derive(Clone, Debug)]
pub struct NodalForce {
    /// the node's `x` and `y`
    dofs: [usize; 2],
    value: [f64; 2],
    function: Option<TimeFunction>,
    scaled: Scaling,
}

impl NodalLoad for NodalForce {
    fn dofs(&self) -> &[usize] {
        &self.dofs
    }

    fn scaling(&self) -> &Scaling {
        &self.scaled
    }

    fn add_force(&self, factor: f64, t: f64, _q: Read, _v: Read, add: &mut dyn FnMut(usize, f64)) {
        let ft = factor * self.function.as_ref().map_or(1.0, |func| func.eval(t));
        add(self.dofs[0], -ft * self.value[0]);
        add(self.dofs[1], -ft * self.value[1]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dead_load_on_the_position_coordinates() {
        let f = Force { node: (0, 2), value: [1.0, -2.0], function: None, scaled: Scaling::LoadScale };
        let nodal = f.lower(&|(_, k)| 4 * k);
        assert_eq!(nodal.dofs(), &[8, 9]);
        let mut g = [0.0; 12];
        nodal.add_force(1.5, 0.3, &|_| f64::NAN, &|_| f64::NAN, &mut |d, v| g[d] += v);
        // g carries −Q: −1.5 · (1, −2); the coordinates are not read (NaN would show)
        assert_eq!(&g[8..10], &[-1.5, 3.0]);
        assert!(!nodal.has_stiffness());
    }
}
