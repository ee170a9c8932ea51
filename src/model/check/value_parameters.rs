//! The parameters that set a part's value rather than multiply a load: a spring's stiffness
//! and a point mass (`stiffness = { value, parameter }`, `mass = { value, parameter }`). A
//! checked one has a parameter name, a positive value (the run's factor is `μ/value`), and a
//! name that no load's or drive's `scaled`, no body property and no other kind of part
//! takes; parts of one kind may share it at one value.

use crate::error::Result;
use crate::model::schema::PropertySpec;
use crate::model::Model;
use crate::physics::loads::Load;
use crate::solver::parameters::{is_parameter_name, Scaling, LOAD_SCALE};

/// The kind of part a value parameter sets.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum ValueKind {
    SpringStiffness,
    PointMass,
}

impl ValueKind {
    fn noun(self) -> &'static str {
        match self {
            ValueKind::SpringStiffness => "a spring's stiffness",
            ValueKind::PointMass => "a point mass",
        }
    }
}

impl Model {
    /// The parameter `spec` (at `field`, e.g. `springs[0].stiffness`) names, with its file
    /// value, or `None` for a plain number: checked as the module documentation says,
    /// against the bodies, loads, springs and point masses checked before it.
    pub(super) fn value_parameter(
        &self,
        field: &str,
        spec: &PropertySpec,
        kind: ValueKind,
    ) -> Result<Option<(String, f64)>> {
        let Some(name) = spec.parameter() else { return Ok(None) };
        let (at_name, at_value) = (format!("{field}.parameter"), format!("{field}.value"));
        let value = spec.value();
        self.value_parameter_name(&at_name, name)?;
        if !(value > 0.0 && value.is_finite()) {
            return Err(self.err(
                at_value,
                format!("must be positive for a parameter (it is the value the parameter replaces), got {value}"),
            ));
        }
        if self.is_body_property(name) {
            return Err(self.err(
                at_name,
                format!("`{name}` is also a body's Young's modulus or density: give {} a name of its own", kind.noun()),
            ));
        }
        for (k, load) in self.loads.iter().enumerate() {
            match (load, load.scaling()) {
                (Load::Spring(_) | Load::TorsionalSpring(_), Scaling::Property { name: n, file }) if n == name => {
                    self.same_value(kind, ValueKind::SpringStiffness, (&at_name, &at_value), name, (value, *file))?;
                }
                (_, Scaling::Named(n)) if n == name => {
                    return Err(self.err(at_name, format!("`{name}` also scales loads[{k}]: a load's parameter multiplies it, this one is a value; give them different names")));
                }
                _ => {}
            }
        }
        let mut drives = self.joints.iter().enumerate().filter_map(|(k, j)| j.kind().drive_scaling().map(|s| (k, s)));
        if let Some((k, _)) = drives.find(|(_, s)| matches!(s, Scaling::Named(n) if n == name)) {
            return Err(self.err(at_name, format!("`{name}` also scales joints[{k}]'s motion: a drive's parameter multiplies it, this one is a value; give them different names")));
        }
        for m in self.masses.iter().filter(|m| m.parameter.as_deref() == Some(name)) {
            self.same_value(kind, ValueKind::PointMass, (&at_name, &at_value), name, (value, m.mass))?;
        }
        Ok(Some((name.to_string(), value)))
    }

    /// Refuses, at `field`, a name that cannot be a value parameter's: not a parameter name,
    /// or the load scale (a value parameter is a value, the load scale a factor).
    pub(super) fn value_parameter_name(&self, field: &str, name: &str) -> Result<()> {
        if is_parameter_name(name) && name != LOAD_SCALE {
            return Ok(());
        }
        Err(self.err(field, format!("`{name}` is not a parameter name: use letters, digits and `_`, starting with a letter (and not `{LOAD_SCALE}`, the load scale)")))
    }

    /// Whether `name` is a body's Young's modulus or density parameter (bodies checked so far).
    pub(super) fn is_body_property(&self, name: &str) -> bool {
        let named = |n: &Option<String>| n.as_deref() == Some(name);
        self.bodies.iter().any(|b| named(&b.youngs_modulus_parameter) || named(&b.density_parameter))
    }

    /// Refuses a value parameter that an earlier part of another kind takes, or of the same
    /// kind at another value.
    fn same_value(
        &self,
        kind: ValueKind,
        other: ValueKind,
        (at_name, at_value): (&str, &str),
        name: &str,
        (value, theirs): (f64, f64),
    ) -> Result<()> {
        if kind != other {
            return Err(
                self.err(at_name, format!("`{name}` is also {}: give {} a name of its own", other.noun(), kind.noun()))
            );
        }
        if value != theirs {
            return Err(self.err(
                at_value,
                format!(
                    "is {value}, but {} gives the parameter `{name}` the value {theirs}: a parameter has one value",
                    other.noun()
                ),
            ));
        }
        Ok(())
    }
}
