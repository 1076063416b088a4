//! The error every format reader returns: where (file, line, field) and what.

use std::fmt;
use std::path::{Path, PathBuf};

/// What went wrong while reading an input file; the data a caller may branch on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum InputErrorKind {
    /// The file could not be opened or read.
    Io,
    /// A line holds more or fewer columns than the format (or the header) says.
    ColumnCount,
    /// A field is empty or is not a decimal number.
    NotANumber,
    /// A field parses as NaN or ±Inf (including overflow such as `1e999`).
    NotFinite,
    /// The time column does not strictly increase (backwards or repeated).
    TimeNotIncreasing,
    /// A CSV header lacks columns the reader needs, or is malformed.
    Header,
    /// The file holds no data line.
    NoData,
    /// A line is longer than the reader's bound (see the reader's docs).
    LineTooLong,
    /// The values are not what the file was read as: IMU samples no sensor on the
    /// Earth reads as declared (rates where increments are expected, units or columns
    /// mistaken), or a GNSS position log given as a velocity log.
    LayoutMismatch,
    /// A value is outside its physical domain ([`schuler::domain`]): a latitude
    /// beyond the pole, an angular rate no gyro reads, a gap no integration step spans.
    OutOfDomain,
    /// A reader option (nominal interval, time window) is invalid, or the file holds
    /// too little data to establish what the reader needs.
    Usage,
}

/// An input error naming the file, the 1-based line (0: the file as a whole), the
/// field or column when one is to blame, and a message.
///
/// Displays as `IMU.txt:1234: field dvel_y: not a number: "abc"`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct InputError {
    /// The file, as the caller named it (`<stdin>` for standard input).
    pub path: PathBuf,
    /// 1-based line number; 0 when the error concerns the file as a whole.
    pub line: u64,
    /// The field (column name) at fault, if any.
    pub field: Option<String>,
    /// What went wrong, for a human.
    pub message: String,
    /// What went wrong, for a program.
    pub kind: InputErrorKind,
}

impl InputError {
    /// A new error at `path:line` with an optional field.
    pub fn new(
        kind: InputErrorKind,
        path: &Path,
        line: u64,
        field: Option<&str>,
        message: impl Into<String>,
    ) -> Self {
        Self {
            path: path.to_path_buf(),
            line,
            field: field.map(str::to_owned),
            message: message.into(),
            kind,
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if self.line > 0 {
            write!(f, ":{}", self.line)?;
        }
        if let Some(field) = &self.field {
            write!(f, ": field {field}")?;
        }
        write!(f, ": {}", self.message)
    }
}

/// The error of a file that cannot be opened or read: `PATH: cannot read: reason`.
pub(crate) fn cannot_read(path: &Path, e: &std::io::Error) -> InputError {
    InputError::new(
        InputErrorKind::Io,
        path,
        0,
        None,
        format!("cannot read: {e}"),
    )
}

/// `value` (in `domain`'s display unit) in SI if it is within `domain`; else an
/// [`InputErrorKind::OutOfDomain`] error naming `path`, `line` and `field`.
pub fn in_domain(
    path: &Path,
    line: u64,
    field: &str,
    domain: &schuler::domain::Domain,
    value: f64,
) -> Result<f64, InputError> {
    domain.check_in_unit(value).map_err(|e| {
        InputError::new(
            InputErrorKind::OutOfDomain,
            path,
            line,
            Some(field),
            e.to_string(),
        )
    })
}

/// A field's text for an error message: lossy UTF-8 (invalid bytes become U+FFFD), at
/// most 40 characters, quoted, control characters escaped (`"abc"`, `"a\u{1}"`).
pub(crate) fn quote_field(bytes: &[u8]) -> String {
    const MAX_CHARS: usize = 40;
    let text = String::from_utf8_lossy(bytes);
    let mut shown: String = text.chars().take(MAX_CHARS).collect();
    let cut = shown.len() < text.len();
    if cut {
        shown.push('…');
    }
    format!("{shown:?}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_file_line_and_field() {
        let e = InputError::new(
            InputErrorKind::NotANumber,
            Path::new("IMU.txt"),
            1234,
            Some("dvel_y"),
            format!("not a number: {}", quote_field(b"abc")),
        );
        assert_eq!(
            e.to_string(),
            r#"IMU.txt:1234: field dvel_y: not a number: "abc""#
        );
    }

    #[test]
    fn display_without_line_or_field() {
        let e = InputError::new(
            InputErrorKind::Io,
            Path::new("a.txt"),
            0,
            None,
            "cannot open",
        );
        assert_eq!(e.to_string(), "a.txt: cannot open");
    }

    #[test]
    fn quote_field_bounds_and_escapes() {
        let long = [b'x'; 100];
        let q = quote_field(&long);
        assert!(q.chars().count() <= 43, "{q}");
        assert_eq!(quote_field(b"a\"b\x01\xff"), "\"a\\\"b\\u{1}\u{fffd}\"");
    }
}
