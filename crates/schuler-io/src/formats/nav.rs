//! Navigation results and truths as files: KF-GINS navigation text or schuler's
//! `nav.csv`, read whole into [`NavRecord`]s.
//!
//! A file may be KF-GINS navigation text (11 columns: `week sow lat lon h vn ve vd
//! roll pitch yaw`, degrees, metres, m/s; as schuler's `nav.txt`, KF-GINS's
//! `KF_GINS_Navresult.nav` and the data sets' `truth.nav`) or schuler's `nav.csv` (a
//! header naming at least `t_sow,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,roll_deg,
//! pitch_deg,yaw_deg`, in any order, other columns ignored; the time may be named `t`,
//! as in `schuler simulate`'s `truth.csv`). Every value is checked in its physical
//! domain ([`schuler::domain`]); longitudes in 0..360 are wrapped. The format is told by the
//! first data line: a header starts with a letter. Fields are separated by spaces,
//! tabs, commas or semicolons (a CSV's as its header's are); blank lines and `#`/`%`
//! comments are skipped. The time is the second of week; in a KF-GINS file a later week continues
//! it (`sow + 604800 (week - first week)`), so a rollover inside a file is no step, but
//! the weeks of two files are not compared (schuler writes week 0 where it knows none).
//! [`NavReader`] reads a file an epoch at a time; [`read_nav`] reads it whole (80
//! bytes per epoch).

use super::error::{InputError, InputErrorKind, cannot_read, in_domain, quote_field};
use super::gps_time::WeekClock;
use super::lines::{Delimiter, MAX_LINE_BYTES, fields, is_skippable, too_long};
use nalgebra::Vector3;
use schuler::analysis::errors::NavRecord;
use schuler::earth::Geodetic;
use schuler::rotation::Euler;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

/// The layouts [`read_nav`] tells apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NavFormat {
    /// KF-GINS navigation text, 11 columns, no header.
    KfGins,
    /// CSV with a header naming the columns (schuler's `nav.csv`).
    Csv,
}

impl NavFormat {
    /// The name used in the report.
    pub fn name(self) -> &'static str {
        match self {
            NavFormat::KfGins => "kf-gins",
            NavFormat::Csv => "csv",
        }
    }
}

/// KF-GINS column names, in file order.
const KF_GINS_FIELDS: [&str; 11] = [
    "week", "sow", "lat", "lon", "h", "vn", "ve", "vd", "roll", "pitch", "yaw",
];

/// CSV columns read, in [`NavRecord`] order after time.
const CSV_FIELDS: [&str; 10] = [
    "t_sow",
    "lat_deg",
    "lon_deg",
    "h_m",
    "vn_mps",
    "ve_mps",
    "vd_mps",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
];

/// The other name of the CSV time column, `t_sow`: `schuler simulate`'s truth.csv.
const TIME_ALIAS: &str = "t";

/// Names of the values a data line gives, in [`NavRecord`] order, as a KF-GINS
/// line's errors name them.
const KF_GINS_VALUES: [&str; 10] = [
    "sow", "lat", "lon", "h", "vn", "ve", "vd", "roll", "pitch", "yaw",
];

/// Field `field` of line `n` parsed from `text`: a finite number.
fn number(path: &Path, n: u64, field: &str, text: &str) -> Result<f64, InputError> {
    let at = |kind, msg: String| InputError::new(kind, path, n, Some(field), msg);
    let x: f64 = text.parse().map_err(|_| {
        at(
            InputErrorKind::NotANumber,
            format!("not a number: {}", quote_field(text.as_bytes())),
        )
    })?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(at(
            InputErrorKind::NotFinite,
            format!("not finite: {}", quote_field(text.as_bytes())),
        ))
    }
}

/// The values of KF-GINS line `n` (time, lat, lon [deg], h, vn, ve, vd, roll, pitch,
/// yaw [deg]): 11 columns, a whole week >= 0, the time of week continued by `clock`
/// from the file's first week.
fn kf_gins_values(
    path: &Path,
    n: u64,
    l: &str,
    clock: &mut WeekClock,
) -> Result<[f64; 10], InputError> {
    let fields: Vec<&str> = fields(l).collect();
    if fields.len() != KF_GINS_FIELDS.len() {
        return Err(InputError::new(
            InputErrorKind::ColumnCount,
            path,
            n,
            None,
            format!(
                "{} columns, expected 11 (week sow lat lon h vn ve vd roll pitch yaw)",
                fields.len()
            ),
        ));
    }
    let mut x = [0.0; 11];
    for (k, f) in fields.iter().enumerate() {
        x[k] = number(path, n, KF_GINS_FIELDS[k], f)?;
    }
    let week = x[0];
    if week < 0.0 || week.fract() != 0.0 {
        return Err(InputError::new(
            InputErrorKind::NotANumber,
            path,
            n,
            Some("week"),
            format!("a GPS week is a whole number >= 0, got {}", fields[0]),
        ));
    }
    let mut v = [0.0; 10];
    v[0] = clock.seconds(week as i64, x[1]);
    v[1..].copy_from_slice(&x[2..]);
    Ok(v)
}

/// Where a CSV header's columns are: its delimiter, its column count and the index of
/// each of [`CSV_FIELDS`].
type CsvColumns = (Delimiter, usize, [usize; 10]);

/// The values of CSV line `n` in [`CSV_FIELDS`] order, from a line with as many
/// fields as the header names (`columns`).
fn csv_values(path: &Path, n: u64, l: &str, columns: &CsvColumns) -> Result<[f64; 10], InputError> {
    let fields = columns.0.split(l);
    if fields.len() != columns.1 {
        return Err(InputError::new(
            InputErrorKind::ColumnCount,
            path,
            n,
            None,
            format!("{} columns, the header names {}", fields.len(), columns.1),
        ));
    }
    let mut v = [0.0; 10];
    for (k, &i) in columns.2.iter().enumerate() {
        v[k] = number(path, n, CSV_FIELDS[k], fields[i])?;
    }
    Ok(v)
}

/// The record of line `n`'s values `v` after checking the latitude range and that the
/// time comes after `prev`'s; `names` name the values in errors.
fn record(
    path: &Path,
    n: u64,
    v: [f64; 10],
    names: &[&str; 10],
    prev_t: Option<f64>,
) -> Result<NavRecord, InputError> {
    let at = |field: &str, kind, msg: String| InputError::new(kind, path, n, Some(field), msg);
    // Every value in its physical domain: a height of 1e308 or a longitude of 7680 deg
    // is a corrupt line, not an error of thousands of kilometres to report.
    use schuler::domain as d;
    let domains: [&d::Domain; 10] = [
        &d::TIME,
        &d::LATITUDE,
        &d::LONGITUDE,
        &d::HEIGHT,
        &d::SPEED,
        &d::SPEED,
        &d::SPEED,
        &d::HEADING,
        &d::PITCH,
        &d::HEADING,
    ];
    for (k, domain) in domains.iter().enumerate() {
        in_domain(path, n, names[k], domain, v[k])?;
    }
    let lon = d::wrap_longitude(v[2].to_radians())
        .map_err(|e| at(names[2], InputErrorKind::OutOfDomain, e.to_string()))?;
    if let Some(prev) = prev_t
        && v[0] <= prev
    {
        return Err(at(
            names[0],
            InputErrorKind::TimeNotIncreasing,
            format!("time {} does not increase (previous {prev})", v[0]),
        ));
    }
    Ok(NavRecord {
        t_sow: v[0],
        pos: Geodetic::new(v[1].to_radians(), lon, v[3]),
        v_n: Vector3::new(v[4], v[5], v[6]),
        att: Euler::from_degrees(v[7], v[8], v[9]),
    })
}

/// A navigation file read one epoch at a time (either layout, told by its first data
/// line), checking column counts, numbers, finiteness, latitude range, whole weeks and
/// strictly increasing time; errors name the file, line and field. It holds one line,
/// so a truth of any length streams in constant memory. After an error it ends.
#[derive(Debug)]
pub struct NavReader {
    path: PathBuf,
    reader: BufReader<std::fs::File>,
    buf: Vec<u8>,
    n: u64,
    format: Option<NavFormat>,
    csv_columns: CsvColumns,
    clock: WeekClock,
    prev_t: Option<f64>,
    ended: bool,
}

impl NavReader {
    /// Opens `path`.
    pub fn open(path: &Path) -> Result<Self, InputError> {
        let file = std::fs::File::open(path).map_err(|e| cannot_read(path, &e))?;
        Ok(Self {
            path: path.to_path_buf(),
            reader: BufReader::with_capacity(1 << 16, file),
            buf: Vec::new(),
            n: 0,
            format: None,
            csv_columns: (Delimiter::Blanks, 0, [0; 10]),
            clock: WeekClock::default(),
            prev_t: None,
            ended: false,
        })
    }

    /// The layout, once the first data line is read.
    pub fn format(&self) -> Option<NavFormat> {
        self.format
    }

    /// The next epoch, `None` at the end of the file.
    fn next_record(&mut self) -> Result<Option<NavRecord>, InputError> {
        let path = self.path.as_path();
        loop {
            self.buf.clear();
            if (&mut self.reader)
                .take(MAX_LINE_BYTES)
                .read_until(b'\n', &mut self.buf)
                .map_err(|e| cannot_read(path, &e))?
                == 0
            {
                return Ok(None);
            }
            self.n += 1;
            let n = self.n;
            if self.buf.last() != Some(&b'\n') && self.buf.len() as u64 == MAX_LINE_BYTES {
                return Err(too_long(path, n));
            }
            let text = if n == 1 {
                self.buf.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&self.buf)
            } else {
                &self.buf
            };
            let l = std::str::from_utf8(text)
                .map_err(|_| {
                    InputError::new(InputErrorKind::NotANumber, path, n, None, "not UTF-8 text")
                })?
                .trim();
            if is_skippable(l.as_bytes()) {
                continue;
            }
            let fmt = match self.format {
                Some(f) => f,
                None if l.starts_with(|c: char| c.is_ascii_alphabetic() || c == '"') => {
                    self.csv_columns = csv_header(path, n, l)?;
                    self.format = Some(NavFormat::Csv);
                    continue;
                }
                None => *self.format.insert(NavFormat::KfGins),
            };
            let (v, names) = match fmt {
                NavFormat::KfGins => (
                    kf_gins_values(path, n, l, &mut self.clock)?,
                    &KF_GINS_VALUES,
                ),
                NavFormat::Csv => (csv_values(path, n, l, &self.csv_columns)?, &CSV_FIELDS),
            };
            let r = record(path, n, v, names, self.prev_t)?;
            self.prev_t = Some(r.t_sow);
            return Ok(Some(r));
        }
    }
}

impl Iterator for NavReader {
    type Item = Result<NavRecord, InputError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.ended {
            return None;
        }
        let r = self.next_record().transpose();
        if !matches!(r, Some(Ok(_))) {
            self.ended = true;
        }
        r
    }
}

/// The error of a file without a data line.
fn no_data(path: &Path) -> InputError {
    InputError::new(InputErrorKind::NoData, path, 0, None, "no data line")
}

/// Reads a navigation file whole ([`NavReader`]'s checks; 80 bytes per epoch).
pub fn read_nav(path: &Path) -> Result<(NavFormat, Vec<NavRecord>), InputError> {
    let mut reader = NavReader::open(path)?;
    let rows = (&mut reader).collect::<Result<Vec<NavRecord>, InputError>>()?;
    match reader.format() {
        Some(f) if !rows.is_empty() => Ok((f, rows)),
        _ => Err(no_data(path)),
    }
}

/// Checks a navigation file through to its end without keeping it (as [`read_nav`]
/// would refuse it); its layout and number of epochs.
pub fn check_nav(path: &Path) -> Result<(NavFormat, u64), InputError> {
    let mut reader = NavReader::open(path)?;
    let mut epochs = 0u64;
    for r in &mut reader {
        r?;
        epochs += 1;
    }
    match reader.format() {
        Some(f) if epochs > 0 => Ok((f, epochs)),
        _ => Err(no_data(path)),
    }
}

/// The delimiter and column count of a CSV header and where each of [`CSV_FIELDS`] is.
fn csv_header(path: &Path, n: u64, l: &str) -> Result<CsvColumns, InputError> {
    let delimiter = Delimiter::of_header(l);
    let names: Vec<&str> = delimiter
        .split(l)
        .into_iter()
        .map(|s| s.trim_matches('"').trim())
        .collect();
    let mut index = [0usize; 10];
    for (k, want) in CSV_FIELDS.iter().enumerate() {
        // `schuler simulate`'s truth.csv names its time `t` (the scenario's clock, not a
        // second of week); its other columns are these.
        let alias = (k == 0).then_some(TIME_ALIAS);
        let found = names.iter().position(|h| h == want);
        let found = found.or_else(|| alias.and_then(|a| names.iter().position(|h| *h == a)));
        index[k] = found.ok_or_else(|| {
            InputError::new(
                InputErrorKind::Header,
                path,
                n,
                Some(want),
                format!(
                    "the header lacks column {want} (needs {}; the time may be named \
                     {TIME_ALIAS})",
                    CSV_FIELDS.join(",")
                ),
            )
        })?;
    }
    Ok((delimiter, names.len(), index))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(text: &[u8]) -> tempfile::NamedTempFile {
        let f = tempfile::NamedTempFile::new().expect("temp");
        std::fs::write(f.path(), text).expect("write");
        f
    }

    #[test]
    fn a_week_rollover_inside_a_file_continues_the_time() {
        let f = file(b"2299 604799.5 45 7 100 0 0 0 0 0 10\n2300 0.5 45 7 100 0 0 0 0 0 10\n");
        let (format, rows) = read_nav(f.path()).expect("reads");
        assert_eq!(format, NavFormat::KfGins);
        assert_eq!(rows[1].t_sow, 604_800.5);
        let f = file(b"0 1.0 45 7 100 0 0 0 0 0 10\n0.5 2.0 45 7 100 0 0 0 0 0 10\n");
        let e = read_nav(f.path()).expect_err("half a week").to_string();
        assert!(
            e.contains(":2: field week: a GPS week is a whole number"),
            "{e}"
        );
    }

    #[test]
    fn any_separator_and_comments() {
        let text =
            b"# truth\n0\t1.0;45;7;100;0;0;0;0;0;10\n\n0, 2.0, 45, 7, 100, 0, 0, 0, 0, 0, 10\n";
        let (format, rows) = read_nav(file(text).path()).expect("reads");
        assert_eq!(format, NavFormat::KfGins);
        assert_eq!((rows[0].t_sow, rows[1].t_sow), (1.0, 2.0));
        let csv =
            b"% semicolons\nt_sow;lat_deg;lon_deg;h_m;vn_mps;ve_mps;vd_mps;roll_deg;pitch_deg;\
                    yaw_deg\n1;45;7;100;0;0;0;0;0;10\n";
        let (format, csv_rows) = read_nav(file(csv).path()).expect("reads");
        assert_eq!(format, NavFormat::Csv);
        assert_eq!(csv_rows[0], rows[0]);
        let tabs = b"t_sow\tlat_deg\tlon_deg\th_m\tvn_mps\tve_mps\tvd_mps\troll_deg\tpitch_deg\t\
                     yaw_deg\n1\t45\t7\t100\t0\t0\t0\t0\t0\t10\n";
        assert_eq!(read_nav(file(tabs).path()).expect("reads").1, csv_rows);
    }

    #[test]
    fn invalid_utf8_names_its_line() {
        let f = file(b"0 1.0 45 7 100 0 0 0 0 0 10\n0 2.0 45 7 1\xff0 0 0 0 0 0 10\n");
        let e = read_nav(f.path()).expect_err("not text").to_string();
        assert!(e.contains(":2: not UTF-8 text"), "{e}");
    }
}
