//! HDF5 input and output.
pub mod atomic;
pub mod h5;
pub mod output;
pub mod result_file;
pub mod basis_file;
pub mod basis_check;
pub mod estimator_file;
