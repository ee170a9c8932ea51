//! One-dimensional datasets of variable-length UTF-8 strings (`/labels/dof`, …), written with
//! a type-conversion buffer sized to the data.
//!
//! Why not `new_dataset_builder().with_data(..)`: writing variable-length strings needs a
//! type conversion (memory `char*` → the file's global-heap references), and HDF5 1.10's
//! `H5Dwrite` then takes a conversion buffer of the transfer property list's size, 1 MiB by
//! default (`H5Pset_buffer`), zero-filled (`calloc`) on every call and, past HDF5's free-list
//! limit, handed back to the system. hdf5-metno writes with the default transfer list, so
//! the three label datasets of a result file cost three fresh, page-faulted, zeroed MiB:
//! ~11 % of the CPU of a whole `flexrom simulate` of the pendulum (perf, docs/process-speed.md).
//! Here the buffer holds the data, `n · 32` bytes (one conversion strip); the bytes in the file are the same.

use hdf5::types::VarLenUnicode;
use hdf5_sys::h5d::H5Dwrite;
use hdf5_sys::h5p::{H5Pclose, H5Pcreate, H5Pset_buffer};
use hdf5_sys::h5s::H5S_ALL;

/// Conversion-buffer bytes per string: at least the larger of the two element sizes, the
/// memory `char*` (8) and the file's reference (4 + address size + 4 = 16 with HDF5's 8-byte
/// addresses, 24 with the largest, 16-byte ones).
const ELEMENT_BYTES: usize = 32;

/// Creates the dataset `name` (shape `n`) in `g`, writes `values` into it and returns it.
pub fn write_strings(g: &hdf5::Group, name: &str, values: &[VarLenUnicode]) -> hdf5::Result<hdf5::Dataset> {
    let ds = g.new_dataset::<VarLenUnicode>().shape(values.len()).create(name)?;
    if values.is_empty() {
        return Ok(ds);
    }
    let mem = hdf5::Datatype::from_type::<VarLenUnicode>()?;
    let bytes = values.len() * ELEMENT_BYTES;
    hdf5::sync::sync(|| {
        // SAFETY: plain calls into HDF5 under hdf5-metno's library lock (`sync`). The ids are
        // live: `ds` and `mem` are owned here, the property list is created and closed here.
        // `buf` points to `values.len()` contiguous `VarLenUnicode`s (each one `char*` to a
        // NUL-terminated string, the layout `mem` describes, as hdf5-metno's own writer passes
        // them) that outlive the call; HDF5 only reads them.
        unsafe {
            let xfer = hdf5::h5check(H5Pcreate(*hdf5::globals::H5P_DATASET_XFER))?;
            let r =
                hdf5::h5check(H5Pset_buffer(xfer, bytes, std::ptr::null_mut(), std::ptr::null_mut())).and_then(|_| {
                    hdf5::h5check(H5Dwrite(ds.id(), mem.id(), H5S_ALL, H5S_ALL, xfer, values.as_ptr().cast()))
                });
            H5Pclose(xfer);
            r.map(|_| ())
        }
    })?;
    Ok(ds)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Strings of several lengths (empty, multi-byte UTF-8, long) read back equal, through
    /// the crate's own reader; an empty list gives an empty dataset.
    #[test]
    fn strings_read_back_equal() {
        let d = tempfile::tempdir().unwrap();
        let f = hdf5::File::create(d.path().join("s.h5")).unwrap();
        let long = "x".repeat(5000);
        let words = ["", "beam node 0 x'", "joint 0 (pin a – b) y", long.as_str()];
        let values: Vec<VarLenUnicode> = words.iter().map(|s| s.parse().unwrap()).collect();
        write_strings(&f, "s", &values).unwrap();
        write_strings(&f, "none", &[]).unwrap();
        let back = f.dataset("s").unwrap().read_1d::<VarLenUnicode>().unwrap();
        assert_eq!(back.iter().map(|v| v.as_str()).collect::<Vec<_>>(), words);
        assert_eq!(f.dataset("none").unwrap().shape(), vec![0]);
    }
}
