//! HDF5 input and output.
pub mod atomic;
pub mod attrs;
pub mod basis_check;
pub mod basis_content;
pub mod basis_file;
pub mod basis_hash;
pub mod basis_layout;
pub mod estimator_file;
pub mod h5;
pub mod h5_text;
pub mod labels;
pub mod modes_file;
pub mod output;
pub mod parameter_space_file;
pub mod result_file;
pub mod result_read;
pub mod timing_file;
