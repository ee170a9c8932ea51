//! Names of the rows of coordinate and multiplier arrays, written as `/labels/*` into every
//! file that holds coordinates or multipliers (result, basis, snapshot files):
//!
//! ```text
//! /labels/body              (n_b)    body names, in model-file order
//! /labels/dof               (n_dof)  "crank node 3 x'": body, node within the body, coordinate
//! /labels/dof_body          (n_dof)  index into /labels/body
//! /labels/dof_node          (n_dof)  node within its body (0 = "start", n_elements = "end")
//! /labels/dof_coordinate    (n_dof)  0 x, 1 y, 2 x', 3 y' (position m, slope 1)
//! /labels/multiplier        (n_c)    "joint 0 (ground_pin crank node 0) x"
//! /labels/multiplier_joint  (n_c)    the model file's joints[j] each row belongs to
//! ```
//!
//! The rows follow [`crate::physics::system::FlexibleSystem::new`]: coordinates node by node,
//! body after body, `(x, y, x', y')` per node; constraint rows as
//! [`crate::physics::joints::lower`] orders them, the joints that hold a node to the ground
//! first, then those that couple bodies, each in file order (a unit test checks the labels
//! against the assembled constraint rows).

use super::attrs::Labelled;
use crate::model::Model;
use crate::physics::joints::lower;
use crate::physics::system::NodeId;
use hdf5::types::VarLenUnicode;
use ndarray::Array1;

/// Names of the four coordinates of a node.
pub use crate::physics::joints::COORDINATES;

/// The row names of one model.
#[derive(Clone, Debug, PartialEq)]
pub struct Labels {
    pub bodies: Vec<String>,
    /// per coordinate: (body, node within the body, coordinate 0..4)
    pub dofs: Vec<(usize, usize, usize)>,
    /// per constraint row: (joint index in the model file, text)
    pub multipliers: Vec<(usize, String)>,
}

impl Labels {
    pub fn of(model: &Model) -> Labels {
        let bodies = model.bodies();
        let dofs = bodies
            .iter()
            .enumerate()
            .flat_map(|(b, body)| (0..=body.n_elements).flat_map(move |k| (0..4).map(move |c| (b, k, c))))
            .collect();
        let node = |(b, k): NodeId| format!("{} node {k}", bodies[b].name);
        let first_node = model.first_nodes();
        let first = |(b, k): NodeId| 4 * (first_node[b] + k);
        let joints = model.joints();
        let multipliers = lower(joints, &first)
            .into_iter()
            .map(|(j, row)| (j, format!("joint {j} ({}) {}", joints[j].describe(&node), row.component)))
            .collect();
        Labels { bodies: bodies.iter().map(|b| b.name.clone()).collect(), dofs, multipliers }
    }

    /// "crank node 3 x'" for each coordinate.
    pub fn dof_names(&self) -> Vec<String> {
        self.dofs.iter().map(|&(b, k, c)| format!("{} node {k} {}", self.bodies[b], COORDINATES[c])).collect()
    }

    /// Writes `/labels` into `f`.
    pub fn write(&self, f: &hdf5::File) -> hdf5::Result<()> {
        self.write_labelled(f, None)
    }

    /// Writes `/labels` into `f`, each dataset labelled as it is created when `labelled` is
    /// given ([`Labelled`]).
    pub fn write_labelled(&self, f: &hdf5::File, mut labelled: Option<&mut Labelled>) -> hdf5::Result<()> {
        let g = f.create_group("labels")?;
        let mut done = |name: &str, d: hdf5::Dataset| match labelled.as_deref_mut() {
            Some(l) => l.label(&format!("labels/{name}"), &d),
            None => Ok(()),
        };
        let text = |v: &mut dyn Iterator<Item = &str>| -> hdf5::Result<Vec<VarLenUnicode>> {
            v.map(|s| s.parse::<VarLenUnicode>().map_err(|e| hdf5::Error::from(format!("label `{s}`: {e:?}"))))
                .collect()
        };
        let idx = |v: &mut dyn Iterator<Item = usize>| Array1::from_iter(v.map(|i| i as u64));
        let index = |g: &hdf5::Group, name: &str, v: &mut dyn Iterator<Item = usize>| {
            g.new_dataset_builder().with_data(&idx(v)).create(name)
        };
        // the string datasets through write_strings: a conversion buffer of their size, not 1 MiB
        done("body", super::h5_text::write_strings(&g, "body", &text(&mut self.bodies.iter().map(|s| s.as_str()))?)?)?;
        let dof_names = self.dof_names();
        done("dof", super::h5_text::write_strings(&g, "dof", &text(&mut dof_names.iter().map(|s| s.as_str()))?)?)?;
        done("dof_body", index(&g, "dof_body", &mut self.dofs.iter().map(|d| d.0))?)?;
        done("dof_node", index(&g, "dof_node", &mut self.dofs.iter().map(|d| d.1))?)?;
        done("dof_coordinate", index(&g, "dof_coordinate", &mut self.dofs.iter().map(|d| d.2))?)?;
        let names = text(&mut self.multipliers.iter().map(|m| m.1.as_str()))?;
        done("multiplier", super::h5_text::write_strings(&g, "multiplier", &names)?)?;
        done("multiplier_joint", index(&g, "multiplier_joint", &mut self.multipliers.iter().map(|m| m.0))?)?;
        Ok(())
    }
}

/// Writes `/labels` of the model whose file text is `model_text` (as stored with a result
/// or basis): parsed again, which is cheap beside the run it labels. A text that does not
/// parse (it did when the run started) writes no labels rather than failing the write.
pub fn write_labels_of_text(f: &hdf5::File, model_text: &str, model_path: &str) -> hdf5::Result<()> {
    write_labels_of_text_labelled(f, model_text, model_path, None)
}

/// [`write_labels_of_text`], each dataset labelled as it is created when `labelled` is given.
pub fn write_labels_of_text_labelled(
    f: &hdf5::File,
    model_text: &str,
    model_path: &str,
    labelled: Option<&mut Labelled>,
) -> hdf5::Result<()> {
    match Model::from_text(model_text, model_path) {
        Ok(m) => Labels::of(&m).write_labelled(f, labelled),
        Err(_) => Ok(()),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::linalg::kkt::LinearSolverKind;
    use crate::solver::model::ParametricModel;

    /// A clamp, a pin listed before a ground pin (pins' rows come last): every joint kind
    /// and the reordering; and a probe (for tests of result files, io::result_file).
    pub(crate) const CLAMPED: &str = r#"
        [time]
        t_end = 0.1
        dt = 0.01
        rho_inf = 0.8
        [[bodies]]
        name = "beam"
        start = [0.0, 0.0]
        angle = 0.0
        length = 1.0
        elements = 2
        density = 7800.0
        area = 1e-4
        inertia = 1e-9
        youngs_modulus = 2e11
        [[bodies]]
        name = "link"
        start = [1.0, 0.0]
        angle = 0.0
        length = 1.0
        elements = 3
        density = 7800.0
        area = 1e-4
        inertia = 1e-9
        youngs_modulus = 2e11
        [[joints]]
        type = "clamp"
        body = "beam"
        node = "start"
        [[joints]]
        type = "pin"
        a = { body = "beam", node = "end" }
        b = { body = "link", node = 0 }
        [[joints]]
        type = "ground_pin"
        body = "link"
        node = "end"
        [[probes]]
        name = "mid"
        body = "link"
        node = 1
    "#;

    /// The labels name exactly the coordinates each assembled constraint row couples:
    /// one unit coefficient on the named node's coordinate (ground pins, clamps), or +1 on
    /// the first and −1 on the second named node's (pins).
    #[test]
    fn labels_match_the_assembled_constraint_rows() {
        let root = env!("CARGO_MANIFEST_DIR");
        let clamped = Model::from_text(CLAMPED, "clamped.toml").unwrap();
        let l = Labels::of(&clamped);
        assert_eq!(l.multipliers[4].1, "joint 2 (ground_pin link node 3) x");
        assert_eq!(l.multipliers[7].1, "joint 1 (pin beam node 2 – link node 0) y");
        for name in ["clamped", "fourbar", "pendulum", "double_pendulum"] {
            let model = match name {
                "clamped" => clamped.clone(),
                _ => Model::load(format!("{root}/data/models/{name}.toml")).unwrap(),
            };
            let sys = model.system(LinearSolverKind::Banded);
            let l = Labels::of(&model);
            assert_eq!(l.dofs.len(), sys.n_dof(), "{name}");
            assert_eq!(l.multipliers.len(), sys.constraints.len(), "{name}");
            let names = l.dof_names();
            for (row, (c, (j, text))) in sys.constraints.iter().zip(&l.multipliers).enumerate() {
                assert!(text.starts_with(&format!("joint {j} (")), "{name} row {row}: {text}");
                // "joint j (kind A node k[ – B node m]) coord"
                let coord = text.rsplit(' ').next().unwrap();
                let inner = &text[text.find('(').unwrap() + 1..text.rfind(')').unwrap()];
                let nodes: Vec<&str> = inner.split_once(' ').unwrap().1.split(" – ").collect();
                assert_eq!(nodes.len(), c.terms.len(), "{name} row {row}: {text}");
                for ((dof, coef), (k, n)) in c.terms.iter().zip(nodes.iter().enumerate()) {
                    assert_eq!(names[*dof], format!("{n} {coord}"), "{name} row {row}");
                    assert_eq!(*coef, if k == 0 { 1.0 } else { -1.0 }, "{name} row {row}");
                }
            }
        }
    }
}
