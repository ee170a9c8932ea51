//! The physics of a model, assembled once per loaded model (so once per command) and
//! shared, read only, by every reduced model and check that needs it, on any thread.

use super::{Model, SharedPhysics};
use crate::error::Result;
use crate::linalg::kkt::LinearSolverKind;
use std::sync::Arc;

impl SharedPhysics {
    /// The model's length scale `L`: coordinates resolve to `tol · L` at Newton tolerance `tol`.
    pub fn length_scale(&self) -> f64 {
        crate::solver::model::ParametricModel::length_scale(&*self.sys)
    }

    /// Assembles the system of `model`, closes the joints of its initial state and takes the
    /// bodies' initial velocities there.
    pub fn assemble(model: &Model) -> Result<Self> {
        let mut sys = model.system(LinearSolverKind::Banded);
        let mut x0 = sys.initial_state();
        sys.make_consistent(&mut x0).map_err(|e| e.at_time_in(0.0, "initial joint projection"))?;
        let v0 = sys.initial_velocity(&x0);
        Ok(SharedPhysics { sys: Arc::new(sys), x0: Arc::new(x0), v0: Arc::new(v0) })
    }
}

impl Model {
    /// The model's physics, assembled at the first call and shared from then on (a clone
    /// of the model shares it too).
    pub fn physics(&self) -> Result<&SharedPhysics> {
        if let Some(p) = self.physics.get() {
            return Ok(p);
        }
        let built = SharedPhysics::assemble(self)?;
        // another thread may have won the race: either value is the same physics
        let _ = self.physics.set(built);
        Ok(self.physics.get().expect("set above"))
    }
}
