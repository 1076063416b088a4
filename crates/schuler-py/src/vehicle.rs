//! The vehicle aids from numpy columns: rest intervals, odometer speeds and
//! dual-antenna headings, with the CLI's columns and units (the files of `--zupt`,
//! `--odometer`, `--dual-antenna`), checked and converted by the CLI readers' own code
//! ([`schuler_io::formats::vehicle`]); errors name the array, the 1-based row and the
//! column.

use crate::arrays::rows;
use numpy::ndarray::ArrayView1;
use schuler::filter::HeadingReading;
use schuler_io::formats::InputError;
use schuler_io::formats::vehicle::{heading_readings, odometer_readings, rest_intervals};
use schuler_run::aided::vehicle::GivenVehicle;
use std::path::Path;

/// Columns of rest intervals: start and end [s].
pub const REST: [&str; 2] = ["t0_s", "t1_s"];
/// Columns of odometer readings: time [s], forward speed [m/s].
pub const ODOMETER: [&str; 2] = ["t_s", "speed_mps"];
/// Columns of dual-antenna headings: time [s], heading from true north and its standard
/// deviation [deg], optionally the baseline's pitch and its standard deviation [deg].
pub const HEADING: [&str; 5] = [
    "t_s",
    "heading_deg",
    "heading_std_deg",
    "pitch_deg",
    "pitch_std_deg",
];

/// Where the readings come from, for errors: `<KIND array>`, or `<KIND push>` for one
/// reading pushed into a session.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// Columns of a table.
    Array,
    /// One pushed reading.
    Push,
}

impl Source {
    fn name(self, kind: &str) -> String {
        match self {
            Source::Array => format!("<{kind} array>"),
            Source::Push => format!("<{kind} push>"),
        }
    }
}

/// Rest intervals of columns [`REST`].
pub fn rests(cols: &[ArrayView1<'_, f64>], src: Source) -> Result<Vec<(f64, f64)>, InputError> {
    let what = src.name("rest");
    rest_intervals(Path::new(&what), &REST, rows(&what, &REST, &[2], cols)?)
}

/// Odometer readings of columns [`ODOMETER`].
pub fn odometer(cols: &[ArrayView1<'_, f64>], src: Source) -> Result<Vec<(f64, f64)>, InputError> {
    let what = src.name("odometer");
    odometer_readings(
        Path::new(&what),
        &ODOMETER,
        rows(&what, &ODOMETER, &[2], cols)?,
    )
}

/// Dual-antenna headings of columns [`HEADING`] (3, or 5 with the pitch).
pub fn headings(
    cols: &[ArrayView1<'_, f64>],
    src: Source,
) -> Result<Vec<HeadingReading>, InputError> {
    let what = src.name("heading");
    heading_readings(
        Path::new(&what),
        &HEADING,
        rows(&what, &HEADING, &[3, 5], cols)?,
    )
}

/// The vehicle readings given as columns (`None`: not given).
pub fn given(
    rest: Option<&[ArrayView1<'_, f64>]>,
    odometer_cols: Option<&[ArrayView1<'_, f64>]>,
    heading: Option<&[ArrayView1<'_, f64>]>,
) -> Result<GivenVehicle, InputError> {
    Ok(GivenVehicle {
        rests: rest.map(|c| rests(c, Source::Array)).transpose()?,
        odometer: odometer_cols
            .map(|c| odometer(c, Source::Array))
            .transpose()?,
        headings: heading.map(|c| headings(c, Source::Array)).transpose()?,
    })
}
