//! The structure of a basis file, checked on the open file before any dataset is read:
//! hard links only (no soft, external or user-defined ones), no external or virtual
//! storage, a bounded depth and number of links, and the right type for each dataset.

use crate::error::{Error, Result};
use hdf5::types::{FloatSize, TypeDescriptor};
use std::path::Path;

/// Datasets read as `f64` (the basis proper); anything else than 8-byte floats is refused.
const FLOAT_DATASETS: [&str; 6] = [
    "basis/modes",
    "basis/reference",
    "basis/singular_values",
    "basis/energy",
    "basis/multiplier_modes",
    "hyper/weights",
];
/// Datasets read as indices; floating-point ones are refused.
const INDEX_DATASETS: [&str; 5] =
    ["basis/block_modes", "basis/block_values", "basis/reduced_dofs", "basis/kept_dofs", "hyper/elements"];
/// Links deeper than this, or more than [`MAX_LINKS`] of them, are not a basis file.
const MAX_DEPTH: usize = 8;
const MAX_LINKS: usize = 10_000;

/// Refuses anything but hard links, external or virtual storage, and datasets of the wrong
/// type. Runs on the open file before any dataset is read.
pub fn check_file(f: &hdf5::File, path: &Path) -> Result<()> {
    let mut seen = 0;
    walk(f, "", 0, &mut seen, path)?;
    for name in FLOAT_DATASETS.iter().chain(INDEX_DATASETS.iter()) {
        if !f.link_exists(name) {
            continue;
        }
        let Ok(d) = f.dataset(name) else { return Err(Error::input(path, *name, "is not a dataset")) };
        let ty = d
            .dtype()
            .and_then(|t| t.to_descriptor())
            .map_err(|e| Error::input(path, *name, format!("has an unreadable type: {e}")))?;
        let float = FLOAT_DATASETS.contains(name);
        match (&ty, float) {
            (TypeDescriptor::Float(FloatSize::U8), true) => {}
            (_, true) => {
                return Err(Error::input(
                    path,
                    *name,
                    format!("has type {}; it must hold 8-byte floats (f64)", describe(&ty)),
                ))
            }
            (TypeDescriptor::Unsigned(_) | TypeDescriptor::Integer(_), false) => {}
            (_, false) => {
                return Err(Error::input(
                    path,
                    *name,
                    format!("has type {}; it must hold integer indices", describe(&ty)),
                ))
            }
        }
    }
    Ok(())
}

fn describe(t: &TypeDescriptor) -> String {
    match t {
        TypeDescriptor::Integer(s) => format!("{}-byte signed integer", *s as usize),
        TypeDescriptor::Unsigned(s) => format!("{}-byte unsigned integer", *s as usize),
        TypeDescriptor::Float(s) => format!("{}-byte float", *s as usize),
        other => format!("{other}"),
    }
}

/// Visits every link under `prefix`: only hard links; datasets stored in the file itself.
fn walk(g: &hdf5::Group, prefix: &str, depth: usize, seen: &mut usize, path: &Path) -> Result<()> {
    let here = if prefix.is_empty() { "/" } else { prefix };
    if depth > MAX_DEPTH {
        return Err(Error::input(
            path,
            here,
            format!("is nested deeper than {MAX_DEPTH} groups: not a flexrom basis file"),
        ));
    }
    let links = g
        .links(hdf5::IndexType::Name, hdf5::IterationOrder::Native)
        .map_err(|e| Error::input(path, here, format!("cannot list its links: {e}")))?;
    for (name, info) in links {
        let full = if prefix.is_empty() { name.clone() } else { format!("{prefix}/{name}") };
        *seen += 1;
        if *seen > MAX_LINKS {
            return Err(Error::input(
                path,
                "(file)",
                format!("holds more than {MAX_LINKS} links: not a flexrom basis file"),
            ));
        }
        if info.link_type != hdf5::LinkType::Hard {
            let kind =
                if info.link_type == hdf5::LinkType::Soft { "a soft link" } else { "an external or user-defined link" };
            return Err(Error::input(
                path,
                &full,
                format!("is {kind}; a basis file must hold its data itself (hard links only)"),
            ));
        }
        if let Ok(sub) = g.group(&name) {
            walk(&sub, &full, depth + 1, seen, path)?;
        } else if let Ok(d) = g.dataset(&name) {
            let dcpl =
                d.dcpl().map_err(|e| Error::input(path, &full, format!("cannot read its storage properties: {e}")))?;
            if !dcpl.external().is_empty() {
                return Err(Error::input(
                    path,
                    &full,
                    "is stored in an external file; a basis file must hold its data itself",
                ));
            }
            if matches!(dcpl.layout(), hdf5::dataset::Layout::Virtual) {
                return Err(Error::input(
                    path,
                    &full,
                    "is a virtual dataset (data in other files); a basis file must hold its data itself",
                ));
            }
        }
    }
    Ok(())
}
