//! Vehicle aiding logs, small text files read whole (whitespace or commas between
//! fields, `#`/`%` comments, an optional header line starting with a letter):
//!
//! - rest intervals (`--zupt`): `t0 t1` per line, the vehicle at rest from `t0` to
//!   `t1` [s], intervals in time order and apart;
//! - odometer (`--odometer`): `t speed` [s, m/s], the forward speed of the wheel
//!   (negative when reversing);
//! - dual-antenna GNSS (`--dual-antenna`): `t heading std [pitch pitch_std]` [s, deg],
//!   the baseline's heading from true north (clockwise) and optionally its pitch.

use super::error::{InputError, InputErrorKind, in_domain};
use super::gnss::numeric_rows;
use schuler::domain;
use schuler::filter::HeadingReading;
use std::path::Path;

/// Numbered rows `(line, values)` of a vehicle log: read from a file, or given in
/// memory (the Python package's arrays, the row's 1-based index as its line), each
/// value finite and the first column's times increasing.
pub type Rows = Vec<(u64, Vec<f64>)>;

/// Fields of a rest-interval line, as errors name them.
pub const REST_FIELDS: [&str; 2] = ["t0", "t1"];
/// Fields of an odometer line.
pub const ODOMETER_FIELDS: [&str; 2] = ["time", "speed"];
/// Fields of a dual-antenna line.
pub const HEADING_FIELDS: [&str; 5] = ["time", "heading", "std_heading", "pitch", "std_pitch"];

/// Read rest intervals `(t0, t1)`, each `t1 > t0` and `t0` after the previous `t1`.
pub fn read_rest_intervals(path: &Path) -> Result<Vec<(f64, f64)>, InputError> {
    let rows = numeric_rows(path, &REST_FIELDS, &[2], true)?;
    rest_intervals(path, &REST_FIELDS, rows)
}

/// Rest intervals of `rows` (`t0 t1` [s]) of the log `path`, checked as
/// [`read_rest_intervals`] checks them; errors name the fields `names`.
pub fn rest_intervals(
    path: &Path,
    names: &[&str; 2],
    rows: Rows,
) -> Result<Vec<(f64, f64)>, InputError> {
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(rows.len());
    for (n, v) in rows {
        let (t0, t1) = (v[0], v[1]);
        if t1 <= t0 {
            return Err(InputError::new(
                InputErrorKind::NotANumber,
                path,
                n,
                Some(names[1]),
                format!("the interval ends ({t1}) before it starts ({t0})"),
            ));
        }
        if let Some(&(_, prev)) = out.last()
            && t0 < prev
        {
            return Err(InputError::new(
                InputErrorKind::TimeNotIncreasing,
                path,
                n,
                Some(names[0]),
                format!("the interval starts ({t0}) inside the previous one (to {prev})"),
            ));
        }
        out.push((t0, t1));
    }
    Ok(out)
}

/// Read odometer speeds `(t, speed)`.
pub fn read_odometer(path: &Path) -> Result<Vec<(f64, f64)>, InputError> {
    let rows = numeric_rows(path, &ODOMETER_FIELDS, &[2], true)?;
    odometer_readings(path, &ODOMETER_FIELDS, rows)
}

/// Odometer speeds of `rows` (`t speed` [s, m/s]) of the log `path`, each speed in
/// its domain; errors name the fields `names`.
pub fn odometer_readings(
    path: &Path,
    names: &[&str; 2],
    rows: Rows,
) -> Result<Vec<(f64, f64)>, InputError> {
    rows.into_iter()
        .map(|(n, v)| Ok((v[0], in_domain(path, n, names[1], &domain::SPEED, v[1])?)))
        .collect()
}

/// Read dual-antenna headings (3 or 5 columns), angles converted to radians.
pub fn read_heading(path: &Path) -> Result<Vec<HeadingReading>, InputError> {
    let rows = numeric_rows(path, &HEADING_FIELDS, &[3, 5], true)?;
    heading_readings(path, &HEADING_FIELDS, rows)
}

/// Dual-antenna headings of `rows` (`t heading std [pitch pitch_std]` [s, deg]) of the
/// log `path`: each angle in its domain, converted to radians, the heading wrapped into
/// (-180°, 180°]; errors name the fields `names`.
pub fn heading_readings(
    path: &Path,
    names: &[&str; 5],
    rows: Rows,
) -> Result<Vec<HeadingReading>, InputError> {
    rows.into_iter()
        .map(|(n, v)| {
            let angle = |k: usize, d: &domain::Domain| in_domain(path, n, names[k], d, v[k]);
            Ok(HeadingReading {
                t: v[0],
                heading: schuler::rotation::wrap_pi(angle(1, &domain::HEADING)?),
                heading_std: angle(2, &domain::ANGLE_STD)?,
                pitch: match v.len() {
                    5 => Some((angle(3, &domain::PITCH)?, angle(4, &domain::ANGLE_STD)?)),
                    _ => None,
                },
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::formats::temp_file as file;

    #[test]
    fn reads_each_layout_with_or_without_a_header() {
        let f = file("t0,t1\n0,60\n# a comment\n120.5 130\n");
        assert_eq!(
            read_rest_intervals(f.path()).expect("reads"),
            vec![(0.0, 60.0), (120.5, 130.0)]
        );
        let f = file("1.0 3.5\n1.1,-0.5\n");
        assert_eq!(
            read_odometer(f.path()).expect("reads"),
            vec![(1.0, 3.5), (1.1, -0.5)]
        );
        let f = file("t,heading_deg,std_deg\n1 350 0.1\n2 10 0.1 -2 0.2\n");
        let h = read_heading(f.path()).expect("reads");
        assert!((h[0].heading - (-10f64).to_radians()).abs() < 1e-15);
        assert!(h[0].pitch.is_none());
        assert!(
            h[1].pitch
                .is_some_and(|(p, s)| (p + 2f64.to_radians()).abs() < 1e-15
                    && (s - 0.2f64.to_radians()).abs() < 1e-15)
        );
    }

    #[test]
    fn errors_name_file_line_and_field() {
        let rest = [
            ("0 60\n50 70\n", ":2: field t0", "inside the previous"),
            ("0 60\n80 70\n", ":2: field t1", "before it starts"),
            ("0 60 3\n", ":1:", "columns"),
        ];
        for (text, at, what) in rest {
            let f = file(text);
            let e = read_rest_intervals(f.path()).expect_err(text).to_string();
            assert!(e.contains(at) && e.contains(what), "{text:?}: {e}");
        }
        let f = file("1 2\n2 x\n");
        let e = read_odometer(f.path()).expect_err("bad").to_string();
        assert!(
            e.contains(":2: field speed") && e.contains("not a number"),
            "{e}"
        );
        let f = file("1 2\n1 3\n");
        let e = read_odometer(f.path()).expect_err("bad").to_string();
        assert!(e.contains(":2: field time"), "{e}");
        let f = file("1 90 -0.1\n");
        let e = read_heading(f.path()).expect_err("bad").to_string();
        assert!(
            e.contains(":1: field std_heading") && e.contains("positive"),
            "{e}"
        );
        let f = file("1 90 0.1 2\n");
        let e = read_heading(f.path()).expect_err("bad").to_string();
        assert!(e.contains(":1:") && e.contains("columns"), "{e}");
    }
}
