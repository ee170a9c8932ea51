//! The hashes a basis file carries: `content_hash` over what the basis is (so an edited file
//! or a copied fingerprint is refused) and `settings_hash` over the pipeline settings that
//! trained it (so a stale basis is flagged).

use crate::reduction::Basis;
use sha2::{Digest, Sha256};

/// What the content hash covers.
pub struct HashInput<'a> {
    pub basis: &'a Basis,
    pub singular_values: &'a [f64],
    pub energy: &'a [f64],
    pub block_modes: &'a [usize],
    pub block_values: &'a [usize],
    pub reduced_dofs: &'a [usize],
    pub model_fingerprint: &'a str,
    pub settings_hash: &'a str,
}

/// SHA-256 (hex) of the basis content: every part prefixed by its name and shape, floats as
/// little-endian IEEE bytes, so equal content gives equal hashes on every machine.
pub fn content_hash(c: &HashInput) -> String {
    let mut h = Sha256::new();
    let mut part = |name: &str, shape: &[usize], bytes: &mut dyn Iterator<Item = [u8; 8]>| {
        h.update((name.len() as u64).to_le_bytes());
        h.update(name.as_bytes());
        h.update((shape.len() as u64).to_le_bytes());
        for &d in shape {
            h.update((d as u64).to_le_bytes());
        }
        for b in bytes {
            h.update(b);
        }
    };
    let b = c.basis;
    let f = |v: &f64| v.to_le_bytes();
    let u = |v: &usize| (*v as u64).to_le_bytes();
    let modes = b.modes.as_standard_layout();
    part("modes", &[modes.nrows(), modes.ncols()], &mut modes.iter().map(f));
    part("reference", &[b.reference.len()], &mut b.reference.iter().map(f));
    part("singular_values", &[c.singular_values.len()], &mut c.singular_values.iter().map(f));
    part("energy", &[c.energy.len()], &mut c.energy.iter().map(f));
    part("block_modes", &[c.block_modes.len()], &mut c.block_modes.iter().map(u));
    part("block_values", &[c.block_values.len()], &mut c.block_values.iter().map(u));
    part("reduced_dofs", &[c.reduced_dofs.len()], &mut c.reduced_dofs.iter().map(u));
    part("kept_dofs", &[b.kept.len()], &mut b.kept.iter().map(u));
    if let Some(vl) = &b.multiplier_modes {
        let vl = vl.as_standard_layout();
        part("multiplier_modes", &[vl.nrows(), vl.ncols()], &mut vl.iter().map(f));
    }
    part("multiplier_scale", &[], &mut std::iter::once(b.multiplier_scale.to_le_bytes()));
    part("n_pod_modes", &[], &mut std::iter::once((b.n_pod_modes as u64).to_le_bytes()));
    if let Some(hy) = &b.hyper {
        part("hyper/elements", &[hy.elements.len()], &mut hy.elements.iter().map(u));
        part("hyper/weights", &[hy.weights.len()], &mut hy.weights.iter().map(f));
        part("hyper/tolerance", &[], &mut std::iter::once(hy.tolerance.to_le_bytes()));
        part("hyper/training_residual", &[], &mut std::iter::once(hy.training_residual.to_le_bytes()));
        part("hyper/n_training", &[], &mut std::iter::once((hy.n_training as u64).to_le_bytes()));
    }
    for (name, text) in [
        ("variant", b.variant.name()),
        ("snapshots", b.snapshots.name()),
        ("model_fingerprint", c.model_fingerprint),
        ("settings_hash", c.settings_hash),
    ] {
        h.update((name.len() as u64).to_le_bytes());
        h.update(name.as_bytes());
        h.update((text.len() as u64).to_le_bytes());
        h.update(text.as_bytes());
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// SHA-256 (hex) of a pipeline's `[train]` and `[reduction]` tables in canonical form (the
/// parsed values as JSON): comments, layout and number spelling do not change it, any
/// setting that changes the basis does. A pipeline's own is
/// `crate::pipeline::Pipeline::settings_hash`.
pub fn settings_hash<P: serde::Serialize>(
    train: &impl serde::Serialize,
    reduction: &impl serde::Serialize,
    parameters: &std::collections::BTreeMap<String, P>,
) -> String {
    // without a [parameters] box the hash is the one of files written before it existed
    let json = if parameters.is_empty() {
        serde_json::json!({ "train": train, "reduction": reduction })
    } else {
        serde_json::json!({ "train": train, "reduction": reduction, "parameters": parameters })
    };
    Sha256::digest(json.to_string().as_bytes()).iter().map(|b| format!("{b:02x}")).collect()
}
