//! Gravity `ρA g` on every element (SPEC §1): a constant body force, so a model assembles it
//! once into the constant part `g₀` of its forces, split by what multiplies it — fixed, the
//! load scale, a named parameter — and, for the bodies whose density is a parameter, by that
//! parameter as well (their weight scales with their mass).

use crate::physics::element::BeamElement;
use crate::physics::masses::Lumped;
use crate::physics::parts::BeamBody;
use crate::solver::parameters::Scaling;

/// Gravity as the model file gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct Gravity {
    /// m/s², y up
    pub g: [f64; 2],
    pub scaled: Scaling,
}

/// The assembled weight `Q_g` in parts: `fixed + λ scaled + Σ μ_name named_name`.
#[derive(Clone, Debug, Default)]
pub struct WeightParts {
    pub fixed: Vec<f64>,
    pub scaled: Vec<f64>,
    pub named: Vec<(String, Vec<f64>)>,
}

impl WeightParts {
    fn zeros(n: usize) -> Self {
        WeightParts { fixed: vec![0.0; n], scaled: vec![0.0; n], named: Vec::new() }
    }

    /// The vector a load with `scaled` adds to.
    fn part(&mut self, scaled: &Scaling, n: usize) -> &mut Vec<f64> {
        match scaled {
            Scaling::Fixed => &mut self.fixed,
            Scaling::LoadScale => &mut self.scaled,
            Scaling::Named(name) => {
                let i = match self.named.iter().position(|(n, _)| n == name) {
                    Some(i) => i,
                    None => {
                        self.named.push((name.clone(), vec![0.0; n]));
                        self.named.len() - 1
                    }
                };
                &mut self.named[i].1
            }
            // the model file gives gravity `scaled = true | false | "name"` only
            Scaling::Property { .. } => unreachable!("gravity scaled by a property"),
        }
    }
}

/// The weight of the bodies whose density is the parameter `parameter`, or of the point
/// masses it sets, at the file's value `density` (kg/m³, or kg for point masses): at μ it
/// scales by `μ/density`.
#[derive(Clone, Debug)]
pub struct DensityWeight {
    pub parameter: String,
    pub density: f64,
    pub parts: WeightParts,
}

/// The weight of every body: `plain` for the bodies whose density is no parameter, one
/// [`DensityWeight`] per density parameter for the others.
#[derive(Clone, Debug)]
pub struct Weight {
    pub plain: WeightParts,
    pub by_density: Vec<DensityWeight>,
}

/// Assembles the weight of `gravities` on the elements `elements` (body, 8 dofs), with one
/// element prototype per body at the file's values, and on the point masses `lumped`
/// (position coordinates, kg: `m g`, in the plain group, or in their parameter's when a
/// parameter sets the mass).
pub fn assemble(
    gravities: &[&Gravity],
    bodies: &[BeamBody],
    elements: &[(usize, [usize; 8])],
    prototypes: &[BeamElement],
    lumped: &[Lumped],
    n_dof: usize,
) -> Weight {
    let mut by_density: Vec<DensityWeight> = Vec::new();
    let by_body = bodies.iter().filter_map(|b| b.density_parameter.as_deref().map(|n| (n, b.section.density)));
    let by_mass = lumped.iter().filter_map(|&(_, m, name)| name.map(|n| (n, m)));
    for (name, value) in by_body.chain(by_mass) {
        if !by_density.iter().any(|d| d.parameter == name) {
            by_density.push(DensityWeight {
                parameter: name.to_string(),
                density: value,
                parts: WeightParts::zeros(n_dof),
            });
        }
    }
    let mut plain = WeightParts::zeros(n_dof);
    for gravity in gravities {
        for (b, dofs) in elements {
            // a body whose density is a parameter weighs in its own group
            let group = match &bodies[*b].density_parameter {
                None => &mut plain,
                Some(name) => &mut by_density.iter_mut().find(|d| &d.parameter == name).expect("listed above").parts,
            };
            let target = group.part(&gravity.scaled, n_dof);
            let qg = prototypes[*b].gravity_force(gravity.g);
            for i in 0..8 {
                target[dofs[i]] += qg[i];
            }
        }
        for &([x, y], m, name) in lumped {
            let group = match name {
                None => &mut plain,
                Some(name) => &mut by_density.iter_mut().find(|d| d.parameter == name).expect("listed above").parts,
            };
            let target = group.part(&gravity.scaled, n_dof);
            target[x] += m * gravity.g[0];
            target[y] += m * gravity.g[1];
        }
    }
    Weight { plain, by_density }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::element::Section;

    fn body(density_parameter: Option<&str>) -> BeamBody {
        let section = Section { density: 2700.0, area: 1e-4, inertia: 1e-9, youngs_modulus: 7e10 };
        BeamBody {
            name: "b".into(),
            start: [0.0; 2],
            angle: 0.0,
            length: 1.0,
            n_elements: 1,
            section,
            youngs_modulus_parameter: None,
            density_parameter: density_parameter.map(str::to_string),
            velocity: [0.0; 2],
            angular_velocity: 0.0,
        }
    }

    /// The total vertical weight of a body is −ρ A L g (the sum of the position entries).
    #[test]
    fn weight_splits_by_scaling_and_density_parameter() {
        let bodies = [body(None), body(Some("rho"))];
        let protos: Vec<_> = bodies.iter().map(|b| BeamElement::new(1.0, b.section)).collect();
        let elements = [(0, std::array::from_fn(|i| i)), (1, std::array::from_fn(|i| 8 + i))];
        let (g1, g2) = (
            Gravity { g: [0.0, -9.81], scaled: Scaling::LoadScale },
            Gravity { g: [0.0, -1.0], scaled: Scaling::Named("tilt".into()) },
        );
        let w = assemble(&[&g1, &g2], &bodies, &elements, &protos, &[], 16);
        let weight_y = |v: &[f64], first: usize| v[first + 1] + v[first + 5];
        let rho_a = 2700.0 * 1e-4;
        assert!((weight_y(&w.plain.scaled, 0) + rho_a * 9.81).abs() < 1e-12);
        assert!((weight_y(&w.plain.named[0].1, 0) + rho_a).abs() < 1e-12);
        assert_eq!(weight_y(&w.plain.scaled, 8), 0.0);
        let d = &w.by_density[0];
        assert_eq!((d.parameter.as_str(), d.density), ("rho", 2700.0));
        assert!((weight_y(&d.parts.scaled, 8) + rho_a * 9.81).abs() < 1e-12);
        assert!(d.parts.fixed.iter().all(|x| *x == 0.0));
    }
}
