//! HDF5 input and output.
pub mod h5;
pub mod result_file;
pub mod basis_file;
pub mod estimator_file;
