//! Errors as Python exceptions: `SchulerError` (a `ValueError`) for what the library
//! or the options refuse, and its subclass `InputError` for bad input data, carrying
//! the file (or array), the 1-based line (or row) and the field, as the CLI names them.

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use schuler_io::formats::InputError as ReadError;

pyo3::create_exception!(
    _schuler,
    SchulerError,
    PyValueError,
    "A value schuler refuses: an option, a configuration, a session's state."
);
pyo3::create_exception!(
    _schuler,
    InputError,
    SchulerError,
    "Bad input data; `path`, `line` (1-based; 0: the file as a whole) and `field` say where."
);

/// The Python exception for `e`: an [`InputError`] with `path`, `line`, `field` and
/// `kind` attributes when a reader's error is in its chain, a `TypeError` for options
/// that are not the CLI's flags, else a [`SchulerError`]; the message is the whole
/// chain, as the CLI prints it.
pub fn to_py(py: Python<'_>, e: anyhow::Error) -> PyErr {
    let msg = format!("{e:#}");
    if let Some(c) = e.downcast_ref::<clap::Error>() {
        return PyTypeError::new_err(c.render().to_string().trim().to_owned());
    }
    match e.chain().find_map(|c| c.downcast_ref::<ReadError>()) {
        Some(r) => input_error(py, msg, r),
        None => SchulerError::new_err(msg),
    }
}

/// An [`InputError`] exception with the reader error's place as attributes.
pub fn input_error(py: Python<'_>, msg: String, r: &ReadError) -> PyErr {
    let err = InputError::new_err(msg);
    let v = err.value(py);
    let set = || -> PyResult<()> {
        v.setattr("path", r.path.display().to_string())?;
        v.setattr("line", r.line)?;
        v.setattr("field", r.field.clone())?;
        v.setattr("kind", format!("{:?}", r.kind))
    };
    match set() {
        Ok(()) => err,
        Err(e) => e,
    }
}

/// `anyhow::Result` into `PyResult`.
pub trait IntoPy<T> {
    /// The result with its error as a Python exception ([`to_py`]).
    fn py_err(self, py: Python<'_>) -> PyResult<T>;
}

impl<T, E: Into<anyhow::Error>> IntoPy<T> for Result<T, E> {
    fn py_err(self, py: Python<'_>) -> PyResult<T> {
        self.map_err(|e| to_py(py, e.into()))
    }
}
