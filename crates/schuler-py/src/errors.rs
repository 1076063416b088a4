//! Errors as Python exceptions: `SchulerError` (a `ValueError`) for what the library
//! or the options refuse, and its subclass `InputError` for bad input data, carrying
//! the file (or array), the 1-based line (or row) and the field, as the CLI names them.

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use schuler_io::formats::InputError as ReadError;
use schuler_run::flat_options::UnknownOption;

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
/// that are not the CLI's, else a [`SchulerError`]; the message is the whole
/// chain, as the CLI prints it, with the options named as keywords
/// ([`keyword_names`]).
pub fn to_py(py: Python<'_>, e: anyhow::Error) -> PyErr {
    let msg = keyword_names(&format!("{e:#}"));
    if let Some(c) = e.downcast_ref::<clap::Error>() {
        return PyTypeError::new_err(c.render().to_string().trim().to_owned());
    }
    if e.downcast_ref::<UnknownOption>().is_some() {
        return PyTypeError::new_err(msg);
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

/// `msg` with each flag named as its keyword: `--auto-latitude` as `auto_latitude`
/// (the application layer's checks name the option as the CLI spells it).
pub fn keyword_names(msg: &str) -> String {
    let mut out = String::with_capacity(msg.len());
    let mut rest = msg;
    while let Some(i) = rest.find("--") {
        let (before, after) = rest.split_at(i);
        out.push_str(before);
        let name_len = after[2..]
            .find(|c: char| !(c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'))
            .unwrap_or(after.len() - 2);
        let name = &after[2..2 + name_len];
        let at_word_start =
            before.is_empty() || !before.ends_with(|c: char| c.is_alphanumeric() || c == '-');
        if at_word_start && name.starts_with(|c: char| c.is_ascii_lowercase()) {
            out.push_str(&name.replace('-', "_"));
        } else {
            out.push_str(&after[..2 + name_len]);
        }
        rest = &after[2 + name_len..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::keyword_names;

    #[test]
    fn flags_are_named_as_keywords() {
        assert_eq!(
            keyword_names("--auto-latitude must be below 90; give --imu-axes or --imu-rotation"),
            "auto_latitude must be below 90; give imu_axes or imu_rotation"
        );
        // What is not a flag stays: an em-rule, a path, a negative number.
        for s in ["a -- b", "x--y", "file--2.txt", "--5", "ends with --"] {
            assert_eq!(keyword_names(s), s);
        }
    }
}
