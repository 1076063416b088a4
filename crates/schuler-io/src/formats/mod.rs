//! File formats at the edge of the CLI: streaming readers that turn text logs into
//! library types, with errors that name the file, the line and the field.
//!
//! Readers work on any [`std::io::BufRead`] (a file behind a 1 MiB
//! [`std::io::BufReader`], or standard input), yield one item at a time and hold a
//! bounded amount of memory whatever the length of the log.

pub mod error;
pub mod gnss;
mod gps_time;
pub mod imu_columns;
pub mod imu_log;
pub mod imu_plausibility;
pub mod kf_gins_config;
mod lines;
mod lines_ahead;
pub mod nav;
pub mod nmea;
pub mod rinex;
pub mod rtklib;
pub mod sensor_errors;
pub mod sp3;
pub mod vehicle;

pub use error::InputError;
pub use imu_log::{ImuFormat, ImuLayout, ImuReadOptions, ImuReader};
pub use lines::{MAX_CONFIG_BYTES, MAX_LINE_BYTES, read_config_text, read_lines_whole};

/// A temporary file holding `text`, for the readers' tests.
#[cfg(test)]
pub(crate) fn temp_file(text: &str) -> tempfile::NamedTempFile {
    let f = tempfile::NamedTempFile::new().expect("temp");
    std::fs::write(f.path(), text).expect("write");
    f
}
