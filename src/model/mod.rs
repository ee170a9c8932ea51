//! Model files: parse, validate (errors name the file, the field and the problem) and build
//! the physical system.

mod check;
pub mod schema;
pub mod shared;
mod toml_errors;

use crate::error::{Error, Result, Text};
use crate::limits::Limits;
use crate::linalg::kkt::LinearSolverKind;
use crate::physics::loads::Load;
use crate::physics::masses::PointMass;
use crate::physics::system::{BeamBody, FlexibleSystem, Joint, Probe, Rayleigh};
use crate::solver::generalized_alpha::IntegratorParams;
use crate::solver::parameters::{Parameters, Scaling};
use schema::*;
use std::path::{Path, PathBuf};
use toml_errors::entry_error;
pub use toml_errors::with_field_line_from_file;
pub(crate) use toml_errors::{parse_toml, with_field_line};

/// Sizes of a model's system (see [`Model::sizes`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sizes {
    pub n_dof: f64,
    pub n_constraints: f64,
    pub n_elements: f64,
    pub n_probes: f64,
    /// the values all probes record at an instant: x and y of each, and one for each
    /// strain and curvature series
    pub n_probe_values: f64,
}

/// Which runs [`Model::admit`] checks parameters for: full runs (`simulate`, `statics`,
/// `modes`) or reduced ones (`online`, `sweep`, `validate`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Runs {
    Full,
    Reduced,
}

/// How far from the model file's value a body property's parameter may lie before a run
/// warns that a factor may have been meant ([`Model::property_warnings`]): two orders of
/// magnitude, beyond what a study of a material around its nominal value spans, and below
/// the distance of a factor near 1 from any modulus (1e6–1e11 Pa) or density (≥ 100 kg/m³).
pub const FACTOR_LIKE: f64 = 100.0;

/// Whether a property's ratio to the file's value lies beyond [`FACTOR_LIKE`] either way.
pub fn far_from(ratio: f64) -> bool {
    !(1.0 / FACTOR_LIKE..=FACTOR_LIKE).contains(&ratio)
}

/// A validated model file.
#[derive(Clone, Debug)]
pub struct Model {
    pub path: PathBuf,
    /// the file's text, stored with every result
    pub text: String,
    pub file: ModelFile,
    bodies: Vec<BeamBody>,
    joints: Vec<Joint>,
    loads: Vec<Load>,
    masses: Vec<PointMass>,
    probes: Vec<Probe>,
    /// the physics, assembled at the first [`Model::physics`] call ([`shared`])
    physics: std::sync::OnceLock<SharedPhysics>,
    /// the resource bounds of every stage that runs this model ([`crate::limits`])
    pub limits: Limits,
}

impl Model {
    /// [`Model::load_with`] the environment's bounds or the defaults.
    pub fn load(path: impl AsRef<Path>) -> Result<Model> {
        Model::load_with(path, Limits::from_env_or_defaults())
    }

    /// Reads and checks the model file at `path`; every run of it keeps to `limits`.
    pub fn load_with(path: impl AsRef<Path>, limits: Limits) -> Result<Model> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Model::from_text_with(&text, path, limits)
    }

    /// [`Model::from_text_with`] the environment's bounds or the defaults.
    pub fn from_text(text: &str, path: impl AsRef<Path>) -> Result<Model> {
        Model::from_text_with(text, path, Limits::from_env_or_defaults())
    }

    /// Checks a model file's `text` (`path` names it in messages).
    pub fn from_text_with(text: &str, path: impl AsRef<Path>, limits: Limits) -> Result<Model> {
        let path = path.as_ref();
        let file: ModelFile = parse_toml(text, path).map_err(|e| entry_error(text, path).unwrap_or(e))?;
        let mut model = Model {
            path: path.to_path_buf(),
            text: text.to_string(),
            file,
            bodies: vec![],
            joints: vec![],
            loads: vec![],
            masses: vec![],
            probes: vec![],
            physics: std::sync::OnceLock::new(),
            limits,
        };
        model.check()?;
        Ok(model)
    }

    fn err(&self, field: impl Into<String>, problem: impl Into<crate::error::Text>) -> Error {
        Error::input(&self.path, toml_errors::field_with_line(&self.text, &field.into()), problem)
    }

    /// SHA-256 of the model's canonical form: the parsed file as JSON, without the free
    /// `description`. Comments, layout, key order and number spelling do not change it;
    /// any change of geometry, material, mesh, joints, loads, probes or time settings does.
    pub fn fingerprint(&self) -> String {
        use sha2::{Digest, Sha256};
        let mut canonical = self.file.clone();
        canonical.description.clear();
        let json = serde_json::to_string(&canonical).expect("the schema serializes");
        Sha256::digest(json.as_bytes()).iter().map(|b| format!("{b:02x}")).collect()
    }

    /// Each body's first node in the global numbering (SPEC §1: node after node, body after
    /// body); a node's first coordinate is `4 (first[b] + k)`.
    pub fn first_nodes(&self) -> Vec<usize> {
        self.bodies()
            .iter()
            .scan(0, |n, body| {
                let first = *n;
                *n += body.n_elements + 1;
                Some(first)
            })
            .collect()
    }

    /// The model's parameters, each once: those its loads and then its drives are scaled by
    /// (`scaled = true` is [`crate::solver::parameters::LOAD_SCALE`]) in file order, the
    /// springs' stiffnesses that are parameters among the loads, then the bodies' Young's
    /// moduli and densities that are parameters, in the order of the bodies, then the point
    /// masses that are.
    pub fn parameter_names(&self) -> Vec<&str> {
        let drives = self.joints.iter().filter_map(|j| j.kind().drive_scaling());
        let scaled = self.loads.iter().map(|l| l.scaling()).chain(drives).filter_map(|s| s.parameter());
        let mut names: Vec<&str> = Vec::new();
        for name in scaled.chain(self.properties().map(|p| p.0)) {
            if !names.contains(&name) {
                names.push(name);
            }
        }
        names
    }

    /// The properties that are parameters (a value, not a factor), each as (its name, what
    /// it sets with its unit, the model file's value): bodies' Young's moduli and densities,
    /// springs' stiffnesses, then point masses.
    fn properties(&self) -> impl Iterator<Item = (&str, &'static str, f64)> {
        let bodies = self.bodies.iter().flat_map(|b| {
            let e =
                b.youngs_modulus_parameter.as_deref().map(|n| (n, "Young's modulus (Pa)", b.section.youngs_modulus));
            let rho = b.density_parameter.as_deref().map(|n| (n, "density (kg/m³)", b.section.density));
            e.into_iter().chain(rho)
        });
        let springs = self.loads.iter().filter_map(|l| match (l, l.scaling()) {
            (Load::Spring(_), Scaling::Property { name, file }) => {
                Some((name.as_str(), "spring stiffness (N/m)", *file))
            }
            (Load::TorsionalSpring(_), Scaling::Property { name, file }) => {
                Some((name.as_str(), "torsional spring stiffness (N m/rad)", *file))
            }
            _ => None,
        });
        let masses = self.masses.iter().filter_map(|m| m.parameter.as_deref().map(|n| (n, "point mass (kg)", m.mass)));
        bodies.chain(springs).chain(masses)
    }

    /// What `name` sets when it is a property, e.g. "Young's modulus (Pa)", "density
    /// (kg/m³)", "spring stiffness (N/m)" or "point mass (kg)" (a value, not a factor), or
    /// `None`.
    pub fn property_parameter(&self, name: &str) -> Option<&'static str> {
        self.properties().find(|p| p.0 == name).map(|p| p.1)
    }

    /// The model file's value of the property the parameter `name` sets (a body's
    /// `youngs_modulus` or `density`, a spring's `stiffness`, a point's `mass = { value, … }`),
    /// or `None` when `name` is no property.
    pub fn property_value(&self, name: &str) -> Option<f64> {
        self.properties().find(|p| p.0 == name).map(|p| p.2)
    }

    /// Warnings for body properties set far from the model file's value, more than
    /// [`FACTOR_LIKE`] times above or below it: such a value is most often a factor meant
    /// (`--param E=0.5` for half the modulus), while the parameter is the value itself. One
    /// warning per parameter, at the first of `points` where it is far; none for a value that
    /// is not positive, which [`Self::check_parameters`] refuses with its own error.
    pub fn property_warnings<'a>(&self, points: impl IntoIterator<Item = &'a Parameters>) -> Vec<String> {
        let (mut out, mut warned) = (Vec::new(), Vec::new());
        for mu in points {
            for (name, x) in mu.named() {
                let Some(file) = self.property_value(name) else { continue };
                if x > 0.0 && far_from(x / file) && !warned.contains(&name) {
                    warned.push(name);
                    out.push(self.factor_like(name, &crate::error::show_number(x), file));
                }
            }
        }
        out
    }

    /// The warning of [`Self::property_warnings`] for the parameter `name` given as `given`.
    pub fn factor_like(&self, name: &str, given: &str, file: f64) -> String {
        let what = self.property_parameter(name).unwrap_or("property");
        format!(
            "{}: {name} = {given} is far from the model file's value {}: it sets the {what} itself, not a factor of it",
            self.path.display(),
            crate::error::show_number(file)
        )
    }

    /// `mu` with every body property that is a parameter set: where `mu` does not set one,
    /// at the model file's value (what a run then uses), so that a check against a box or
    /// its candidates reads the value the run has.
    pub fn with_property_values(&self, mu: &Parameters) -> Parameters {
        self.properties().fold(mu.clone(), |m, (name, _, value)| match m.get(name) {
            Some(_) => m,
            None => m.with(name, value),
        })
    }

    /// Refuses parameters the model does not have (a `--param` misspelt, or one of another
    /// model), and a Young's modulus that is not positive: the error names the model file
    /// and the parameters it has.
    pub fn check_parameters(&self, mu: &Parameters) -> Result<()> {
        if let Some(problem) = mu.named().find_map(|(name, _)| self.unknown_parameter(name)) {
            return Err(Error::usage(format!("{}: {problem}", self.path.display())));
        }
        for (name, value) in mu.named() {
            if let Some(what) = self.property_parameter(name).filter(|_| !(value > 0.0)) {
                return Err(Error::usage(format!(
                    "{}: parameter {name} is a {what} and must be positive, got {value}",
                    self.path.display()
                )));
            }
        }
        Ok(())
    }

    /// The warning for load scales other than 1 on a model none of whose loads is `scaled =
    /// true`: they change nothing, and a run would read as at another load.
    pub fn load_scale_warning(&self, mut scales: impl Iterator<Item = f64>) -> Option<Text> {
        let why = self.unscaled_load_scale()?;
        let x = scales.find(|&x| x != 1.0)?;
        Some(Text::new(format!("{}: the load scale {x} is given, but ", self.path.display())).append(why))
    }

    /// What every front end (the command line, Python) checks of the parameters of the runs
    /// it is about to make, and what it warns of, in one place: each point's parameters are
    /// the model's and its properties positive ([`Self::check_parameters`]); a load scale the
    /// model's loads do not take is refused for reduced runs ([`Self::refuse_load_scale`])
    /// and warned of for full ones ([`Self::load_scale_warning`]); properties far from the
    /// file's values are warned of ([`Self::property_warnings`]). Returns the warnings.
    pub fn admit(&self, points: &[Parameters], runs: Runs) -> Result<Vec<Text>> {
        for mu in points {
            self.check_parameters(mu)?;
        }
        let scales = points.iter().map(Parameters::scale);
        let mut warnings = Vec::new();
        match runs {
            Runs::Reduced => self.refuse_load_scale(scales)?,
            Runs::Full => warnings.extend(self.load_scale_warning(scales)),
        }
        warnings.extend(self.property_warnings(points).into_iter().map(Text::from));
        Ok(warnings)
    }

    /// [`Self::load_scale_warning`] as an error: a reduced run at a load scale that changes
    /// nothing would read as outside its basis's training (λ = 1) though it is not.
    pub fn refuse_load_scale(&self, scales: impl Iterator<Item = f64>) -> Result<()> {
        match self.load_scale_warning(scales) {
            Some(w) => Err(Error::Usage(w)),
            None => Ok(()),
        }
    }

    /// Why a load scale λ means nothing to this model (no load is `scaled = true`), or
    /// `None` when some load is.
    pub fn unscaled_load_scale(&self) -> Option<Text> {
        let names = self.parameter_names();
        if names.contains(&crate::solver::parameters::LOAD_SCALE) {
            return None;
        }
        Some(if names.is_empty() {
            Text::new("no load of the model is scaled (`scaled = true`), so it would change nothing")
        } else {
            let why = "no load of the model is `scaled = true`, so it would change nothing; its parameters are";
            Text::new(format!("{why} {}", names.join(", "))).clause(
                " (set them with ",
                "param",
                Some("NAME=VALUE"),
                ")",
            )
        })
    }

    /// Why `name` is not a parameter of this model (the parameters it has), or `None` when
    /// it is one.
    pub fn unknown_parameter(&self, name: &str) -> Option<String> {
        let names = self.parameter_names();
        if names.contains(&name) {
            return None;
        }
        let have = if names.is_empty() {
            "none: no load is scaled, no body's property is a parameter".to_string()
        } else {
            names.join(", ")
        };
        // the closest name, as clap suggests a flag (Jaro similarity above 0.7)
        let close = names
            .iter()
            .map(|n| (strsim::jaro(name, n), n))
            .filter(|(s, _)| *s > 0.7)
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(String::new(), |(_, n)| format!("; did you mean `{n}`?"));
        Some(format!("the model has no parameter `{name}` (its parameters: {have}){close}"))
    }

    /// Integrator parameters from the `[time]` table.
    pub fn integrator_params(&self) -> IntegratorParams {
        self.params_from(&self.file.time).expect("validated at load")
    }

    /// Builds the physical system with the given linear solver.
    pub fn system(&self, solver: LinearSolverKind) -> FlexibleSystem {
        let damping = self
            .file
            .damping
            .as_ref()
            .map_or(Rayleigh::default(), |d| Rayleigh { mass: d.mass, stiffness: d.stiffness });
        FlexibleSystem::new(
            self.bodies.clone(),
            &self.joints,
            &self.loads,
            &self.masses,
            self.probes.clone(),
            damping,
            solver,
        )
    }

    /// Whether runs start from the static equilibrium of their loads at t = 0 (`[initial]
    /// static = true`) rather than from the undeformed state.
    pub fn starts_static(&self) -> bool {
        self.file.initial.as_ref().is_some_and(|i| i.r#static)
    }

    /// The sizes of the system this model builds, from the file alone (nothing is
    /// assembled), as floats so that estimates from them cannot overflow.
    pub fn sizes(&self) -> Sizes {
        let n_elements: f64 = self.bodies.iter().map(|b| b.n_elements as f64).sum();
        let n_dof = 4.0 * self.bodies.iter().map(|b| b.n_elements as f64 + 1.0).sum::<f64>();
        // rows do not depend on where a node's coordinates sit
        let n_constraints = self.joints.iter().map(|j| j.kind().rows(&|_| 0).len() as f64).sum();
        let sections: usize = self.probes.iter().map(|p| p.strain as usize + p.curvature as usize).sum();
        let n_probes = self.probes.len() as f64;
        Sizes { n_dof, n_constraints, n_elements, n_probes, n_probe_values: 2.0 * n_probes + sections as f64 }
    }

    /// Refuses a full run of `n_steps` whose arrays (plus, with `dense`, the dense LU of
    /// the KKT matrix) would not fit the memory bound ([`crate::limits`]).
    pub fn check_full_run_memory(&self, n_steps: usize, dense: bool) -> Result<()> {
        let z = self.sizes();
        let nt = n_steps as f64 + 1.0;
        // q and q̇, multipliers, probe values, t
        let arrays = 8.0 * nt * (2.0 * z.n_dof + z.n_constraints + z.n_probe_values + 1.0);
        let system = z.n_elements * crate::limits::BYTES_PER_ELEMENT;
        let n_kkt = z.n_dof + z.n_constraints;
        let lu = if dense { 2.0 * 8.0 * n_kkt * n_kkt } else { 0.0 };
        let what = format!(
            "a full run of {} steps × {} coordinates{}",
            n_steps,
            z.n_dof,
            if dense { format!(" with a dense {n_kkt} × {n_kkt} LU") } else { String::new() }
        );
        self.limits.check_memory(&what, arrays + system + lu)
    }

    /// The validated bodies, in file order (node `k` of body `b` is global node
    /// Σ_{c<b}(n_elements_c + 1) + k; labels in src/io/labels.rs).
    pub fn bodies(&self) -> &[BeamBody] {
        &self.bodies
    }

    /// The validated joints, in file order, nodes resolved.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// The validated point masses, in file order.
    pub fn masses(&self) -> &[PointMass] {
        &self.masses
    }

    /// The validated loads, in file order (springs among them).
    pub fn loads(&self) -> &[Load] {
        &self.loads
    }

    pub fn probe_names(&self) -> Vec<String> {
        self.probes.iter().map(|p| p.name.clone()).collect()
    }

    /// The names of the probes that record strain, and of those that record curvature.
    pub fn section_names(&self) -> [Vec<String>; 2] {
        let names = |f: fn(&Probe) -> bool| self.probes.iter().filter(|p| f(p)).map(|p| p.name.clone()).collect();
        [names(|p| p.strain), names(|p| p.curvature)]
    }

    /// The keys `quantity:probe` of every probe quantity, in the order runs report them
    /// (every probe's position, then the strains, then the curvatures).
    pub fn quantity_keys(&self) -> Vec<String> {
        let [strains, curvatures] = self.section_names();
        let keys = |q: &'static str, names: Vec<String>| names.into_iter().map(move |n| format!("{q}:{n}"));
        keys("position", self.probe_names())
            .chain(keys("strain", strains))
            .chain(keys("curvature", curvatures))
            .collect()
    }

    /// The validated probes, in file order (element, ξ, what each records).
    pub fn probes(&self) -> &[Probe] {
        &self.probes
    }
}

/// The assembled system (banded KKT solver), its consistent initial state `x₀` and the
/// bodies' initial velocities `v₀` there.
#[derive(Clone)]
pub struct SharedPhysics {
    pub sys: std::sync::Arc<FlexibleSystem>,
    pub x0: std::sync::Arc<Vec<f64>>,
    pub v0: std::sync::Arc<Vec<f64>>,
}

impl std::fmt::Debug for SharedPhysics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SharedPhysics({} coordinates)", self.x0.len())
    }
}

#[cfg(test)]
mod tests {
    use super::{Model, Runs};
    use crate::solver::parameters::Parameters;

    /// A pendulum under gravity that is not `scaled`: a load scale changes nothing.
    const UNSCALED: &str = "[time]\nt_end = 0.1\ndt = 0.01\nrho_inf = 1.0\n\
        [[bodies]]\nname = \"beam\"\nstart = [0.0, 0.0]\nangle = 0.0\nlength = 1.0\nelements = 2\n\
        density = 7800.0\narea = 1e-4\ninertia = 1e-9\nyoungs_modulus = { value = 2e11, parameter = \"E\" }\n\
        [[joints]]\ntype = \"ground_pin\"\nbody = \"beam\"\nnode = \"start\"\n\
        [[loads]]\ntype = \"gravity\"\ng = [0.0, -9.81]\nscaled = false\n";

    /// The front ends' one check: λ ≠ 1 on a model without scaled loads is refused for
    /// reduced runs and a warning for full ones; a property far from the file's value warns;
    /// a parameter the model lacks, or a property not positive, is refused for both.
    #[test]
    fn admit_refuses_what_every_front_end_refuses_and_warns_alike() {
        let model = Model::from_text(UNSCALED, "m.toml").unwrap();
        let scaled = [Parameters::load_scale(2.0)];
        assert!(model.admit(&scaled, Runs::Reduced).is_err());
        let w = model.admit(&scaled, Runs::Full).unwrap();
        assert!(w.len() == 1 && w[0].to_string().contains("the load scale 2 is given"), "{w:?}");
        // the named parameters' option as the command line spells it, and as the library's text
        let cli = w[0].render(&crate::error::cli_flag);
        assert!(cli.ends_with("its parameters are E (set them with --param NAME=VALUE)"), "{cli}");
        assert!(w[0].to_string().ends_with("(set them with param = NAME=VALUE)"), "{}", w[0]);
        // 0.5 is 4e11 times below the file's 2e11 (more than FACTOR_LIKE): a factor meant
        let far = [Parameters::load_scale(1.0).with("E", 0.5)];
        let w = model.admit(&far, Runs::Reduced).unwrap();
        assert!(w.len() == 1 && w[0].to_string().contains("far from the model file's value"), "{w:?}");
        for bad in [Parameters::load_scale(1.0).with("F", 1.0), Parameters::load_scale(1.0).with("E", 0.0)] {
            assert!(model.admit(std::slice::from_ref(&bad), Runs::Full).is_err(), "{bad:?}");
        }
    }
}
