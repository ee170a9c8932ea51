//! flexrom's errors as Python exceptions, with the command line's one-line messages:
//!
//! ```text
//! FlexromError                 every error of flexrom
//! ├── ModelError               bad input: a model or pipeline file, a value, an output path
//! ├── BasisMismatchError       a basis file missing, damaged, or not of this model/pipeline
//! └── SolverError              a run failed: Newton, a singular matrix, a blow-up
//! ```
//!
//! Ctrl-C is `KeyboardInterrupt`, as everywhere in Python.

use flexrom::error::Spelling;
use flexrom::Error;
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyUserWarning};
use pyo3::prelude::*;

create_exception!(_flexrom, FlexromError, PyException, "Every error of flexrom.");
create_exception!(_flexrom, ModelError, FlexromError, "Bad input: a model or pipeline file, a value, an output path.");
create_exception!(
    _flexrom,
    BasisMismatchError,
    FlexromError,
    "A basis file missing, damaged, or trained for another model or pipeline."
);
create_exception!(_flexrom, SolverError, FlexromError, "A run failed: Newton, a singular matrix, a blow-up.");
create_exception!(
    _flexrom,
    FlexromWarning,
    PyUserWarning,
    "A run outside the training range, an estimate over the tolerance, a value that looks like a factor."
);

/// The command line's options that no Python call takes: the bounds come from the
/// `FLEXROM_MAX_*` environment variables (which the messages name beside them), and a
/// blow-up always fails.
const NOT_KEYWORDS: [&str; 4] = ["max_memory", "max_steps", "max_elements", "allow_blowup"];

/// How a Python call writes an option the library names by its key ([`Error::render`]): as
/// its keyword argument, `load_scale=`, with the value after the `=`; a named parameter
/// (`param`, `NAME=VALUE`) is a keyword argument of its own name; a clause naming an option
/// Python does not have is left out.
struct Keywords;

impl Spelling for Keywords {
    fn option(&self, key: &str, value: Option<&str>) -> Option<String> {
        match (key, value) {
            ("param", Some(assignment)) => Some(assignment.to_string()),
            _ => (!NOT_KEYWORDS.contains(&key)).then(|| format!("{key}={}", value.unwrap_or(""))),
        }
    }
}

/// A library line (a warning, a text that names options) as a Python call's user reads it.
pub fn said(line: &impl flexrom::error::Said) -> String {
    line.said(&Keywords)
}

/// The exception of a library error.
pub fn to_py(e: Error) -> PyErr {
    let msg = e.render(&Keywords);
    match root(&e) {
        Error::Interrupted => pyo3::exceptions::PyKeyboardInterrupt::new_err(msg),
        Error::NewtonFailed { .. } | Error::LinearSolve { .. } | Error::BlowUp { .. } | Error::Numerical { .. } => {
            SolverError::new_err(msg)
        }
        Error::Input { .. } | Error::Io { .. } | Error::Usage(_) | Error::Option { .. } | Error::Resource(_) => {
            ModelError::new_err(msg)
        }
        _ => FlexromError::new_err(msg),
    }
}

/// The error of reading a basis against a model: bad input there is a basis that does not
/// fit (or is missing, or damaged).
pub fn basis_error(e: Error) -> PyErr {
    match root(&e) {
        Error::Input { .. } | Error::Hdf5 { .. } | Error::Io { .. } => BasisMismatchError::new_err(e.to_string()),
        _ => to_py(e),
    }
}

/// A `ModelError` with `msg`.
pub fn model_error(msg: &str) -> PyErr {
    ModelError::new_err(msg.to_string())
}

/// The error under a stage's context (the kind decides the exception).
fn root(e: &Error) -> &Error {
    match e {
        Error::Stage { source, .. } | Error::Hinted { source, .. } | Error::Context { source, .. } => root(source),
        other => other,
    }
}

pub fn add(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("FlexromError", py.get_type::<FlexromError>())?;
    m.add("ModelError", py.get_type::<ModelError>())?;
    m.add("BasisMismatchError", py.get_type::<BasisMismatchError>())?;
    m.add("SolverError", py.get_type::<SolverError>())?;
    Ok(())
}
