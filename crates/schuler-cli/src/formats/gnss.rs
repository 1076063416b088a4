//! GNSS logs in the KF-GINS text format: `t lat lon h std_n std_e std_d` (degrees,
//! metres), optionally followed by `vn ve vd std_vn std_ve std_vd`; and velocity logs
//! `t vn ve vd [std_vn std_ve std_vd]` (as gnss-ins-sim writes beside them). GNSS logs
//! are small (one line per fix), so they are read whole.

use super::error::{InputError, InputErrorKind};
use nalgebra::Vector3;
use schuler::earth::Geodetic;
use schuler::filter::GnssFix;
use std::path::Path;

const POS_FIELDS: [&str; 13] = [
    "time", "lat", "lon", "h", "std_n", "std_e", "std_d", "vn", "ve", "vd", "std_vn", "std_ve",
    "std_vd",
];
const VEL_FIELDS: [&str; 7] = ["time", "vn", "ve", "vd", "std_vn", "std_ve", "std_vd"];

/// Numbers of each data line (blank lines and `#`/`%` comments skipped, and with
/// `header` a first line that starts with a letter), with their 1-based line numbers;
/// checks column counts (one of `counts`), finiteness, positive standard deviations
/// (fields named `std*`) and increasing time (the first column). Small logs only: the
/// file is read whole.
pub(crate) fn numeric_rows(
    path: &Path,
    names: &[&str],
    counts: &[usize],
    header: bool,
) -> Result<Vec<(u64, Vec<f64>)>, InputError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        InputError::new(
            InputErrorKind::Io,
            path,
            0,
            None,
            format!("cannot read: {e}"),
        )
    })?;
    let mut rows: Vec<(u64, Vec<f64>)> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let n = i as u64 + 1;
        let l = line.trim();
        if l.is_empty()
            || l.starts_with('#')
            || l.starts_with('%')
            || (header && n == 1 && l.starts_with(|c: char| c.is_ascii_alphabetic()))
        {
            continue;
        }
        let fields: Vec<&str> = l
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|f| !f.is_empty())
            .collect();
        if !counts.contains(&fields.len()) {
            return Err(InputError::new(
                InputErrorKind::ColumnCount,
                path,
                n,
                None,
                format!("{} columns, expected {counts:?}", fields.len()),
            ));
        }
        let mut v = Vec::with_capacity(fields.len());
        for (k, f) in fields.iter().enumerate() {
            let x: f64 = f.parse().map_err(|_| {
                InputError::new(
                    InputErrorKind::NotANumber,
                    path,
                    n,
                    Some(names[k]),
                    format!("not a number: {f:?}"),
                )
            })?;
            if !x.is_finite() {
                return Err(InputError::new(
                    InputErrorKind::NotFinite,
                    path,
                    n,
                    Some(names[k]),
                    format!("not finite: {f:?}"),
                ));
            }
            if names[k].starts_with("std") && x <= 0.0 {
                return Err(InputError::new(
                    InputErrorKind::NotANumber,
                    path,
                    n,
                    Some(names[k]),
                    format!("a standard deviation must be positive, got {f}"),
                ));
            }
            v.push(x);
        }
        if let Some((_, prev)) = rows.last()
            && v[0] <= prev[0]
        {
            return Err(InputError::new(
                InputErrorKind::TimeNotIncreasing,
                path,
                n,
                Some("time"),
                format!("time {} does not increase (previous {})", v[0], prev[0]),
            ));
        }
        rows.push((n, v));
    }
    if rows.is_empty() {
        return Err(InputError::new(
            InputErrorKind::NoData,
            path,
            0,
            None,
            "no data line",
        ));
    }
    Ok(rows)
}

/// Read a GNSS position log (7 or 13 columns).
pub fn read_gnss(path: &Path) -> Result<Vec<GnssFix>, InputError> {
    let rows = numeric_rows(path, &POS_FIELDS, &[7, 13], false)?;
    let mut fixes = Vec::with_capacity(rows.len());
    for (n, v) in rows {
        if !(-90.0..=90.0).contains(&v[1]) {
            return Err(InputError::new(
                InputErrorKind::NotANumber,
                path,
                n,
                Some("lat"),
                format!("latitude {} is outside [-90, 90]", v[1]),
            ));
        }
        fixes.push(GnssFix {
            t: v[0],
            pos: Geodetic::from_degrees(v[1], v[2], v[3]),
            pos_std: Vector3::new(v[4], v[5], v[6]),
            vel: (v.len() == 13).then(|| {
                (
                    Vector3::new(v[7], v[8], v[9]),
                    Vector3::new(v[10], v[11], v[12]),
                )
            }),
        });
    }
    Ok(fixes)
}

/// Add the velocities of a velocity log (4 or 7 columns; `default_std` [m/s] where the
/// file gives none) to the fixes at the same times (within 1 µs). Returns the number
/// of velocity epochs without a position fix (not used).
pub fn merge_velocity(
    fixes: &mut [GnssFix],
    path: &Path,
    default_std: f64,
) -> Result<usize, InputError> {
    let rows = numeric_rows(path, &VEL_FIELDS, &[4, 7], false)?;
    let mut unmatched = 0;
    let mut j = 0;
    for (_, v) in rows {
        while j < fixes.len() && fixes[j].t < v[0] - 1e-6 {
            j += 1;
        }
        if j < fixes.len() && (fixes[j].t - v[0]).abs() <= 1e-6 {
            let std = if v.len() == 7 {
                Vector3::new(v[4], v[5], v[6])
            } else {
                Vector3::repeat(default_std)
            };
            fixes[j].vel = Some((Vector3::new(v[1], v[2], v[3]), std));
        } else {
            unmatched += 1;
        }
    }
    Ok(unmatched)
}

/// Read a barometer log: `baro.csv` as `schuler simulate` writes it (header
/// `t,h_m[,outlier]`; the outlier flag, the simulator's truth, is not read) or headerless
/// `t h` rows. Returns `(t, h)` pairs in time order.
pub fn read_baro(path: &Path) -> Result<Vec<(f64, f64)>, InputError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        InputError::new(
            InputErrorKind::Io,
            path,
            0,
            None,
            format!("cannot read: {e}"),
        )
    })?;
    let mut out: Vec<(f64, f64)> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let n = i as u64 + 1;
        let l = line.trim();
        if l.is_empty()
            || l.starts_with('#')
            || (n == 1 && l.starts_with(|c: char| c.is_ascii_alphabetic()))
        {
            continue;
        }
        let fields: Vec<&str> = l
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|f| !f.is_empty())
            .collect();
        if fields.len() < 2 {
            return Err(InputError::new(
                InputErrorKind::ColumnCount,
                path,
                n,
                None,
                "expected t and h",
            ));
        }
        let mut v = [0.0; 2];
        for (k, name) in ["time", "h"].iter().enumerate() {
            v[k] = fields[k]
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    InputError::new(
                        InputErrorKind::NotANumber,
                        path,
                        n,
                        Some(name),
                        format!("not a finite number: {:?}", fields[k]),
                    )
                })?;
        }
        if let Some(&(t, _)) = out.last()
            && v[0] <= t
        {
            return Err(InputError::new(
                InputErrorKind::TimeNotIncreasing,
                path,
                n,
                Some("time"),
                format!("time {} does not increase (previous {t})", v[0]),
            ));
        }
        out.push((v[0], v[1]));
    }
    if out.is_empty() {
        return Err(InputError::new(
            InputErrorKind::NoData,
            path,
            0,
            None,
            "no data line",
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::formats::temp_file as file;

    #[test]
    fn reads_both_layouts_and_merges_velocity() {
        let f = file(
            "# comment\n1.0 45 7 100 0.5 0.5 1.0\n2.0 45.00001 7 100 0.5 0.5 1.0 1 2 3 0.1 0.1 0.2\n",
        );
        let mut fixes = read_gnss(f.path()).expect("reads");
        assert_eq!(fixes.len(), 2);
        assert!(fixes[0].vel.is_none() && fixes[1].vel.is_some());
        let v = file("1.0 4 5 6\n1.5 0 0 0\n");
        assert_eq!(
            merge_velocity(&mut fixes, v.path(), 0.05).expect("merge"),
            1
        );
        assert_eq!(fixes[0].vel.map(|(v, s)| (v.x, s.x)), Some((4.0, 0.05)));
    }

    #[test]
    fn reads_the_simulators_baro_csv_and_names_bad_fields() {
        let f = file("t,h_m,outlier\n0.1,100.5,0\n0.2,100.7,1\n");
        assert_eq!(
            read_baro(f.path()).expect("reads"),
            vec![(0.1, 100.5), (0.2, 100.7)]
        );
        let f = file("t,h_m,outlier\n0.1,abc,0\n");
        let e = read_baro(f.path()).expect_err("bad").to_string();
        assert!(e.contains(":2: field h"), "{e}");
    }

    #[test]
    fn errors_name_line_and_field() {
        let cases = [
            ("1 45 7 100 0.5 0.5\n", "1:", "columns"),
            ("1 45 7 abc 0.5 0.5 1\n", "field h", "not a number"),
            ("1 45 7 100 0.5 -0.5 1\n", "field std_e", "positive"),
            (
                "2 45 7 100 0.5 0.5 1\n1 45 7 100 0.5 0.5 1\n",
                ":2: field time",
                "increase",
            ),
            ("1 95 7 100 0.5 0.5 1\n", "field lat", "outside"),
        ];
        for (text, at, what) in cases {
            let f = file(text);
            let e = read_gnss(f.path()).expect_err(text).to_string();
            assert!(e.contains(at) && e.contains(what), "{text:?}: {e}");
        }
    }
}
