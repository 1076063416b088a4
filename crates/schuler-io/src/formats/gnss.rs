//! GNSS and barometer logs: small files (one line per fix or reading), read whole.
//! Fields are separated by spaces, tabs, commas or semicolons; blank lines and
//! `#`/`%` comments are skipped everywhere; line numbers in errors count every line of
//! the file (1-based), and every problem is an [`InputError`] naming the file, the
//! line and the field.
//!
//! # Position logs ([`read_gnss_log`], `schuler nav --gnss`)
//! The format is told by the content ([`GnssFormat::Auto`]) or given
//! (`--gnss-format`): NMEA 0183 sentences (`$GPGGA,...`, see [`super::nmea`]), an
//! RTKLIB solution file whose `%` header names its columns (`.pos`, see
//! [`super::rtklib`]), else text, whose first data line tells the layout: a header if
//! its first field is not a number.
//! - **KF-GINS text**: `t lat lon h std_n std_e std_d` [s, deg, deg, m, m, m, m], 7
//!   columns, or 13 with `vn ve vd std_vn std_ve std_vd` [m/s] after them, or 4
//!   (`t lat lon h`) with the standard deviations of `--gnss-std`. The 13-column
//!   layout is a receiver's position *and* velocity, and its velocities are used as
//!   velocity aiding.
//! - **CSV with a header**, as `schuler simulate` writes `gnss.csv`: fields separated
//!   as the header's are (its first comma, semicolon or tab, else blanks), every data
//!   line with as many fields as the header, columns found by name (ASCII
//!   case-insensitive, blanks and double quotes around a name ignored) in any order.
//!   Required: `t` (or `time`), `lat_deg`, `lon_deg`, `h_m`; `std_n_m`, `std_e_m`,
//!   `std_d_m` all three or none (then `--gnss-std`); a missing column is an error
//!   naming it and the header's line. Other columns are ignored and not parsed, with
//!   two named on purpose:
//!   - `outlier` (0 or 1) is checked and kept in [`GnssRecord::outlier`] but never
//!     drops a fix: it is the simulator's *truth* (1 where it injected a jump), not a
//!     receiver's quality flag, and a navigator that dropped flagged fixes would be
//!     handed the answer it is tested on; the filter's gate has to find them.
//!   - the velocity columns (`vn_mps ve_mps vd_mps std_vn_mps std_ve_mps std_vd_mps`)
//!     are not read as velocity aiding here: a CSV's velocities are used only when
//!     the file is also named as the velocity log (`--gnss-vel gnss.csv`,
//!     [`merge_velocity`]), so that it navigates as its `gnss.txt` twin. The
//!     simulator writes them only when the scenario measures velocity
//!     (`gnss.velocity_std`; it once wrote the exact velocity with standard deviations
//!     of 0 without it).
//!
//!   So `gnss.csv` gives the same fixes as `gnss.txt` (the simulator writes the same
//!   numbers in both), and the same navigation.
//!
//! A file that gives no standard deviations for a fix (4 columns, a CSV without them,
//! NMEA without GST, RTKLIB without `sdn sde sdu`) takes those of `--gnss-std`
//! ([`GnssReadOptions::default_std`]); without it, that is an error naming the file,
//! the line and the flag.
//!
//! # Velocity logs ([`merge_velocity`], `schuler nav --gnss-vel`)
//! - **Text**: `t vn ve vd [std_vn std_ve std_vd]` [s, m/s], 4 or 7 columns (as
//!   gnss-ins-sim writes beside its positions).
//! - **CSV with a header**: `t` (or `time`), `vn_mps`, `ve_mps`, `vd_mps` required;
//!   `std_vn_mps`, `std_ve_mps`, `std_vd_mps` all three or none; other columns ignored
//!   (so the simulator's `gnss.csv` is a velocity log too).
//!
//! A position log given as a velocity log is refused, never read as velocities. The
//! structure decides where it can:
//! - a CSV header must name the velocity columns (the error says so when it names a
//!   position log's `lat_deg`, `lon_deg`, `h_m` instead);
//! - 13 text columns are the position-and-velocity layout; a velocity log has 4 or 7.
//!
//! Four and seven text columns are also the shapes of position logs (`t lat lon h
//! [std_n std_e std_d]`), which no count or range can tell apart (latitudes and
//! longitudes in degrees are plausible speeds in m/s), so there the values decide
//! against the position fixes the velocities are matched to: a text row whose `vn ve
//! vd` repeat the latitude and longitude [deg] of the fix at the same time within
//! 0.001° and its height [m] within 100 m is a position row, and the file is refused at
//! that line. A velocity would have to equal the vehicle's own coordinates to 1 mm/s in
//! both horizontal axes; a position log is caught even from another receiver on the
//! same vehicle (metres apart; 0.001° of latitude is 111 m). The rule applies to every
//! text row matched to a fix, whatever its column count.
//!
//! # Barometer logs ([`read_baro`], `schuler nav --baro`)
//! `baro.csv` as `schuler simulate` writes it (`t,h_m,outlier`) or headerless `t h`.

use super::error::{InputError, InputErrorKind, in_domain};
use super::lines::{Delimiter, data_lines, fields, read_lines_whole};
use crate::named::Named;
use nalgebra::Vector3;
use schuler::domain;
use schuler::earth::Geodetic;
use schuler::filter::GnssFix;
use std::path::Path;

const POS_FIELDS: [&str; 13] = [
    "time", "lat", "lon", "h", "std_n", "std_e", "std_d", "vn", "ve", "vd", "std_vn", "std_ve",
    "std_vd",
];
const VEL_FIELDS: [&str; 7] = ["time", "vn", "ve", "vd", "std_vn", "std_ve", "std_vd"];

/// The columns a position CSV must name (the time first).
const CSV_POS: [&str; 4] = ["t", "lat_deg", "lon_deg", "h_m"];
/// The position standard deviations a position CSV may name, all three or none.
const CSV_POS_STD: [&str; 3] = ["std_n_m", "std_e_m", "std_d_m"];
/// The columns a velocity CSV must name (the time first).
const CSV_VEL: [&str; 4] = ["t", "vn_mps", "ve_mps", "vd_mps"];
/// The velocity standard deviations a velocity CSV may name, all three or none.
const CSV_VEL_STD: [&str; 3] = ["std_vn_mps", "std_ve_mps", "std_vd_mps"];
/// The simulator's truth flag in a position CSV (see the module doc).
const CSV_OUTLIER: &str = "outlier";

/// A velocity text row repeating the matched fix's latitude and longitude within this
/// [deg] ...
const SAME_ANGLE_DEG: f64 = 1e-3;
/// ... and its height within this [m] is a position row (see the module doc).
const SAME_HEIGHT_M: f64 = 100.0;

/// Numbers of data lines, each with its 1-based line number.
type Rows = Vec<(u64, Vec<f64>)>;

/// The position log formats [`read_gnss_log`] reads (`--gnss-format`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GnssFormat {
    /// Told by the content: NMEA sentences, an RTKLIB `%` column header, else text.
    #[default]
    Auto,
    /// KF-GINS text (4, 7 or 13 columns) or CSV with a header.
    Text,
    /// NMEA 0183 sentences: GGA, RMC, VTG, GST.
    Nmea,
    /// An RTKLIB solution file (`.pos`, rnx2rtkp or RTKPOST output).
    Rtklib,
}

impl Named for GnssFormat {
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (
            Self::Auto,
            "auto",
            "Told by the content: NMEA sentences, an RTKLIB `%` column header, else text",
        ),
        (
            Self::Text,
            "text",
            "KF-GINS text (4, 7 or 13 columns) or CSV with a header",
        ),
        (
            Self::Nmea,
            "nmea",
            "NMEA 0183 sentences: GGA, RMC, VTG, GST",
        ),
        (
            Self::Rtklib,
            "rtklib",
            "An RTKLIB solution file (`.pos`, rnx2rtkp or RTKPOST output)",
        ),
    ];
}

/// Solution quality levels, worst first (`--gnss-min-quality`): RTKLIB's `Q` and
/// NMEA GGA's fix quality mapped onto one scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GnssQuality {
    /// Single point positioning (RTKLIB Q 5; GGA 1, 7 manual, 8 simulator).
    #[default]
    Single,
    /// Differential code positioning (RTKLIB Q 3 SBAS, 4 DGPS; GGA 2 DGPS, 3 PPS).
    Dgps,
    /// Carrier phase with float ambiguities, or PPP (RTKLIB Q 2, 6; GGA 5).
    Float,
    /// Carrier phase with fixed ambiguities (RTKLIB Q 1; GGA 4).
    Fix,
}

impl Named for GnssQuality {
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (
            Self::Single,
            "single",
            "Single point positioning (RTKLIB Q 5; GGA 1, 7 manual, 8 simulator)",
        ),
        (
            Self::Dgps,
            "dgps",
            "Differential code positioning (RTKLIB Q 3 SBAS, 4 DGPS; GGA 2 DGPS, 3 PPS)",
        ),
        (
            Self::Float,
            "float",
            "Carrier phase with float ambiguities, or PPP (RTKLIB Q 2, 6; GGA 5)",
        ),
        (
            Self::Fix,
            "fix",
            "Carrier phase with fixed ambiguities (RTKLIB Q 1; GGA 4)",
        ),
    ];
}

/// How [`read_gnss_log`] reads a position log.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssReadOptions {
    /// The format, or [`GnssFormat::Auto`].
    pub format: GnssFormat,
    /// Position standard deviations north, east, down [m] for fixes the file gives
    /// none (`--gnss-std`).
    pub default_std: Option<Vector3<f64>>,
    /// Fixes of a lower quality are dropped (RTKLIB and NMEA files).
    pub min_quality: GnssQuality,
    /// Horizontal velocity standard deviation [m/s] where a format gives velocity
    /// without one (NMEA speed and course, RTKLIB without `sdvn sdve sdvu`).
    pub vel_std: f64,
}

impl Default for GnssReadOptions {
    fn default() -> Self {
        Self {
            format: GnssFormat::Auto,
            default_std: None,
            min_quality: GnssQuality::Single,
            vel_std: 0.1,
        }
    }
}

/// A position log as read: the fixes and what the reader has to say about the file.
#[derive(Debug, Clone, PartialEq)]
pub struct GnssLog {
    /// The fixes in time order.
    pub fixes: Vec<GnssFix>,
    /// The format read (never [`GnssFormat::Auto`]).
    pub format: GnssFormat,
    /// Warnings for the user (sentences skipped, fixes dropped, time assumptions).
    pub warnings: Vec<String>,
}

/// `bytes` as text (a leading UTF-8 byte-order mark dropped), or an error naming the
/// line of the first byte that is not UTF-8.
pub(crate) fn utf8_text(path: &Path, bytes: Vec<u8>) -> Result<String, InputError> {
    let text = String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let line = e.as_bytes()[..at].iter().filter(|&&b| b == b'\n').count() as u64 + 1;
        InputError::new(
            InputErrorKind::NotANumber,
            path,
            line,
            None,
            "not UTF-8 text",
        )
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_owned(),
        None => text,
    })
}

/// The whole text of a small log (a leading UTF-8 byte-order mark dropped).
fn read_text(path: &Path) -> Result<String, InputError> {
    utf8_text(path, read_lines_whole(path)?)
}

/// Whether the first data line is a CSV header: its first field is not a number.
fn is_header(l: &str) -> bool {
    fields(l).next().is_some_and(|f| f.parse::<f64>().is_err())
}

/// Field `name` of line `n` parsed from `text`: a finite number, and positive if `name`
/// is a standard deviation (starts with `std`; `std_hint` is then added to the error).
pub(crate) fn parse_field(
    path: &Path,
    n: u64,
    name: &str,
    text: &str,
    std_hint: &str,
) -> Result<f64, InputError> {
    let x: f64 = text.parse().map_err(|_| {
        InputError::new(
            InputErrorKind::NotANumber,
            path,
            n,
            Some(name),
            format!("not a number: {text:?}"),
        )
    })?;
    if !x.is_finite() {
        return Err(InputError::new(
            InputErrorKind::NotFinite,
            path,
            n,
            Some(name),
            format!("not finite: {text:?}"),
        ));
    }
    if name.starts_with("std") && x <= 0.0 {
        return Err(InputError::new(
            InputErrorKind::NotANumber,
            path,
            n,
            Some(name),
            format!("a standard deviation must be positive, got {text}{std_hint}"),
        ));
    }
    Ok(x)
}

/// Checks that time `t` of line `n` (field `name`) comes after `prev`, the previous
/// row's time.
pub(crate) fn check_time(
    path: &Path,
    n: u64,
    name: &str,
    t: f64,
    prev: Option<f64>,
) -> Result<(), InputError> {
    match prev {
        Some(p) if t <= p => Err(InputError::new(
            InputErrorKind::TimeNotIncreasing,
            path,
            n,
            Some(name),
            format!("time {t} does not increase (previous {p})"),
        )),
        _ => Ok(()),
    }
}

/// The error of a file without a data line.
pub(crate) fn no_data(path: &Path) -> InputError {
    InputError::new(InputErrorKind::NoData, path, 0, None, "no data line")
}

/// A warning `N what` for each count `(N, what)` that is not 0.
pub(crate) fn count_warnings(counts: &[(usize, String)]) -> Vec<String> {
    counts
        .iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, what)| format!("{n} {what}"))
        .collect()
}

/// What the warning of the fixes dropped by `--gnss-min-quality` says after its count.
pub(crate) fn below_quality(min: GnssQuality) -> String {
    format!("fixes below --gnss-min-quality {} dropped", min.name())
}

/// The error of a log without a fix to use, with the `warnings` that say why.
pub(crate) fn no_usable_fix(path: &Path, warnings: &[String]) -> InputError {
    if warnings.is_empty() {
        return no_data(path);
    }
    InputError::new(
        InputErrorKind::NoData,
        path,
        0,
        None,
        format!("no usable fix ({})", warnings.join("; ")),
    )
}

/// The standard deviations of a fix at line `n` that gives none: `default` (the
/// `--gnss-std` flag), or an error naming the file, the line, `field` and the flag.
pub(crate) fn default_std(
    path: &Path,
    n: u64,
    field: &str,
    default: Option<Vector3<f64>>,
) -> Result<Vector3<f64>, InputError> {
    default.ok_or_else(|| {
        InputError::new(
            InputErrorKind::Usage,
            path,
            n,
            Some(field),
            "the file gives no position standard deviations for this fix: give them with \
             --gnss-std N,E,D [m]",
        )
    })
}

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
) -> Result<Rows, InputError> {
    let text = read_text(path)?;
    let lines = data_lines(&text)
        .filter(|&(n, l)| !(header && n == 1 && l.starts_with(|c: char| c.is_ascii_alphabetic())));
    text_rows(path, lines, names, counts, &|k| {
        format!("{k} columns, expected {counts:?}")
    })
}

/// [`numeric_rows`] on given lines; `wrong_count(k)` is the message for a line of `k`
/// columns, `k` not in `counts`.
fn text_rows<'a>(
    path: &Path,
    lines: impl Iterator<Item = (u64, &'a str)>,
    names: &[&str],
    counts: &[usize],
    wrong_count: &dyn Fn(usize) -> String,
) -> Result<Rows, InputError> {
    let mut rows: Rows = Vec::new();
    for (n, l) in lines {
        let v = text_row(path, (n, l), names, counts, wrong_count)?;
        check_time(path, n, names[0], v[0], rows.last().map(|r| r.1[0]))?;
        rows.push((n, v));
    }
    if rows.is_empty() {
        return Err(no_data(path));
    }
    Ok(rows)
}

/// The values of headerless line `n` (text `l`), whose field count must be one of
/// `counts` (else `wrong_count` says why), each parsed as the field `names` names.
fn text_row(
    path: &Path,
    (n, l): (u64, &str),
    names: &[&str],
    counts: &[usize],
    wrong_count: &dyn Fn(usize) -> String,
) -> Result<Vec<f64>, InputError> {
    let fields: Vec<&str> = fields(l).collect();
    if !counts.contains(&fields.len()) {
        return Err(InputError::new(
            InputErrorKind::ColumnCount,
            path,
            n,
            None,
            wrong_count(fields.len()),
        ));
    }
    fields
        .iter()
        .zip(names)
        .map(|(f, name)| parse_field(path, n, name, f, ""))
        .collect()
}

/// A CSV log's header line: the column names as written, each trimmed of blanks and
/// double quotes, and how its fields are separated.
struct CsvHeader<'a> {
    path: &'a Path,
    /// 1-based line number of the header.
    line: u64,
    names: Vec<String>,
    delimiter: Delimiter,
}

impl<'a> CsvHeader<'a> {
    /// The header in line `line` (text `l`) of `path`.
    fn parse(path: &'a Path, line: u64, l: &str) -> Self {
        let delimiter = Delimiter::of_header(l);
        let names = delimiter
            .split(l)
            .into_iter()
            .map(|name| {
                let name = name
                    .strip_prefix('"')
                    .and_then(|s| s.strip_suffix('"'))
                    .unwrap_or(name);
                name.trim().to_owned()
            })
            .collect();
        Self {
            path,
            line,
            names,
            delimiter,
        }
    }

    /// A header error with `message`.
    fn error(&self, field: Option<&str>, message: String) -> InputError {
        InputError::new(InputErrorKind::Header, self.path, self.line, field, message)
    }

    /// The column named `name` (ASCII case-insensitive; `t` also as `time`), if any; a
    /// name given twice is an error.
    fn find(&self, name: &str) -> Result<Option<usize>, InputError> {
        let aliases: &[&str] = if name == "t" { &["t", "time"] } else { &[name] };
        self.find_any(name, aliases)
    }

    /// The column holding `name` under any of `aliases` (ASCII case-insensitive), if
    /// any; two columns holding it (the same name twice, or two of its aliases) are an
    /// error naming both.
    fn find_any(&self, name: &str, aliases: &[&str]) -> Result<Option<usize>, InputError> {
        let found: Vec<usize> = (0..self.names.len())
            .filter(|&i| {
                aliases
                    .iter()
                    .any(|a| self.names[i].eq_ignore_ascii_case(a))
            })
            .collect();
        match found[..] {
            [] => Ok(None),
            [col] => Ok(Some(col)),
            [a, b, ..] => Err(self.error(
                Some(name),
                format!("column appears twice (columns {} and {})", a + 1, b + 1),
            )),
        }
    }

    /// Where each of `names` is, or an error naming every missing one; `what` says what
    /// needs them, `hint` is added to the error.
    fn require(&self, names: &[&str], what: &str, hint: &str) -> Result<Vec<usize>, InputError> {
        let mut cols = Vec::with_capacity(names.len());
        let mut missing = Vec::new();
        for &name in names {
            match self.find(name)? {
                Some(c) => cols.push(c),
                None => missing.push(name),
            }
        }
        if missing.is_empty() {
            return Ok(cols);
        }
        // None found but perhaps the time: the line may not be meant as a header.
        let taken = if missing.len() + 1 >= names.len() {
            format!(
                "; line {} was taken for a CSV header because its first field is not a \
                 number (a header names the columns)",
                self.line
            )
        } else {
            String::new()
        };
        Err(self.error(
            (missing.len() == 1).then_some(missing[0]),
            format!(
                "the header lacks column{} {} ({what} needs {}; other columns are ignored){hint}{taken}",
                if missing.len() == 1 { "" } else { "s" },
                missing.join(", "),
                names.join(", "),
            ),
        ))
    }

    /// The columns of `names` (index, name), all of them or none (an error naming the
    /// missing ones when the header names only some); `what` says what they are.
    fn all_or_none<'n>(
        &self,
        names: &[&'n str],
        what: &str,
    ) -> Result<Vec<(usize, &'n str)>, InputError> {
        let mut found = Vec::new();
        let mut missing = Vec::new();
        for &name in names {
            match self.find(name)? {
                Some(c) => found.push((c, name)),
                None => missing.push(name),
            }
        }
        if !found.is_empty() && !missing.is_empty() {
            return Err(self.error(
                Some(missing[0]),
                format!(
                    "the header names {} but not {}: {what} gives its standard deviations \
                     all three or none",
                    found
                        .iter()
                        .map(|(_, name)| *name)
                        .collect::<Vec<_>>()
                        .join(", "),
                    missing.join(", ")
                ),
            ));
        }
        Ok(found)
    }

    /// Rows of numbers after the header: each line with as many fields as the header
    /// names, the columns `cols` (index, name for errors) parsed in their order
    /// (checked as [`parse_field`] does, `std_hint` added to a standard deviation's
    /// error), the first one the time, which must increase.
    fn rows<'l>(
        &self,
        lines: impl Iterator<Item = (u64, &'l str)>,
        cols: &[(usize, &str)],
        std_hint: &str,
    ) -> Result<Rows, InputError> {
        let mut rows: Rows = Vec::new();
        for (n, l) in lines {
            let v = self.row(n, l, cols, std_hint)?;
            check_time(self.path, n, cols[0].1, v[0], rows.last().map(|r| r.1[0]))?;
            rows.push((n, v));
        }
        if rows.is_empty() {
            return Err(no_data(self.path));
        }
        Ok(rows)
    }

    /// The values of the columns `cols` of line `n` (text `l`), which must have as
    /// many fields as the header names.
    fn row(
        &self,
        n: u64,
        l: &str,
        cols: &[(usize, &str)],
        std_hint: &str,
    ) -> Result<Vec<f64>, InputError> {
        let fields = self.delimiter.split(l);
        if fields.len() != self.names.len() {
            return Err(InputError::new(
                InputErrorKind::ColumnCount,
                self.path,
                n,
                None,
                format!(
                    "{} columns, the header (line {}) names {}",
                    fields.len(),
                    self.line,
                    self.names.len()
                ),
            ));
        }
        cols.iter()
            .map(|&(c, name)| parse_field(self.path, n, name, fields[c], std_hint))
            .collect()
    }
}

/// One fix of a GNSS position log, with its line and what the filter does not use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssRecord {
    /// 1-based line number in the file.
    pub line: u64,
    /// The fix.
    pub fix: GnssFix,
    /// A CSV's `outlier` column: the simulator's truth flag, never used to drop the fix
    /// (see the module doc); `None` where the file has no such column.
    pub outlier: Option<bool>,
}

/// A CSV's `outlier` flag of line `n`: 0 or 1 (`None` where the file has no such
/// column).
fn outlier_flag(path: &Path, n: u64, x: Option<f64>) -> Result<Option<bool>, InputError> {
    match x {
        None => Ok(None),
        Some(x) if x == 0.0 || x == 1.0 => Ok(Some(x == 1.0)),
        Some(x) => Err(InputError::new(
            InputErrorKind::NotANumber,
            path,
            n,
            Some(CSV_OUTLIER),
            format!("the outlier flag is 0 or 1, got {x}"),
        )),
    }
}

/// A CSV position log's columns to read (place, name) and its outlier column's place.
type PositionCols = (Vec<(usize, &'static str)>, Option<usize>);

/// The columns a CSV position log's header `h` gives (time, position, and the
/// standard deviations if any), and the place of its outlier column if it has one.
fn csv_position_cols(h: &CsvHeader) -> Result<PositionCols, InputError> {
    let mut cols: Vec<(usize, &str)> = h
        .require(&CSV_POS, "a GNSS position log", "")?
        .into_iter()
        .zip(CSV_POS)
        .collect();
    cols.extend(h.all_or_none(&CSV_POS_STD, "a position log")?);
    let outlier = h.find(CSV_OUTLIER)?;
    if let Some(c) = outlier {
        cols.push((c, CSV_OUTLIER));
    }
    Ok((cols, outlier))
}

/// The position of latitude, longitude [deg] and height [m] after the checks of
/// [`schuler::domain`] (a longitude of 0-360 wrapped); else which of the three (0, 1,
/// 2) is out of its domain, and why.
pub fn position_in_domain(
    lat_deg: f64,
    lon_deg: f64,
    h: f64,
) -> Result<Geodetic, (usize, domain::DomainError)> {
    let lat = domain::LATITUDE
        .check_in_unit(lat_deg)
        .map_err(|e| (0, e))?;
    let lon = domain::wrap_longitude(lon_deg.to_radians()).map_err(|e| (1, e))?;
    let h = domain::HEIGHT.check(h).map_err(|e| (2, e))?;
    Ok(Geodetic { lat, lon, h })
}

/// `fix` (read from line `n` of `path`) if every value it carries is within its
/// physical domain ([`schuler::session::Aid::out_of_domain`]), else the error naming
/// the line and the field.
pub(crate) fn fix_in_domain(path: &Path, n: u64, fix: GnssFix) -> Result<GnssFix, InputError> {
    match schuler::session::Aid::Gnss(fix).out_of_domain() {
        None => Ok(fix),
        Some((field, e)) => Err(InputError::new(
            InputErrorKind::OutOfDomain,
            path,
            n,
            Some(field),
            e.to_string(),
        )),
    }
}

/// The record of line `n`'s values `v` (`t lat lon h [std_n std_e std_d [vn ve vd
/// std_vn std_ve std_vd]]`) after checking the position's domain (the fields named
/// `pos_names` in the error); `default_std` where `v` gives no standard deviations.
fn gnss_record(
    path: &Path,
    n: u64,
    v: &[f64],
    outlier: Option<bool>,
    (pos_names, std_name): ([&str; 3], &str),
    std: Option<Vector3<f64>>,
) -> Result<GnssRecord, InputError> {
    let pos = position_in_domain(v[1], v[2], v[3]).map_err(|(i, e)| {
        InputError::new(
            InputErrorKind::OutOfDomain,
            path,
            n,
            Some(pos_names[i]),
            e.to_string(),
        )
    })?;
    let pos_std = match v.get(4..7) {
        Some(s) => Vector3::new(s[0], s[1], s[2]),
        None => default_std(path, n, std_name, std)?,
    };
    // The standard deviations and the velocity, named as the text layout does.
    for (k, x) in pos_std.iter().enumerate() {
        in_domain(path, n, POS_FIELDS[4 + k], &domain::POSITION_STD, *x)?;
    }
    for (k, x) in v.iter().enumerate().skip(7) {
        let d = if k < 10 {
            &domain::SPEED
        } else {
            &domain::VELOCITY_STD
        };
        in_domain(path, n, POS_FIELDS[k], d, *x)?;
    }
    let fix = GnssFix {
        t: v[0],
        pos,
        pos_std,
        vel: (v.len() == 13).then(|| {
            (
                Vector3::new(v[7], v[8], v[9]),
                Vector3::new(v[10], v[11], v[12]),
            )
        }),
    };
    Ok(GnssRecord {
        line: n,
        fix,
        outlier,
    })
}

/// Read a GNSS position log of text (KF-GINS text, 4, 7 or 13 columns, or CSV with a
/// header; see the module doc) with each fix's line and outlier flag; `default_std`
/// [m] for fixes the file gives no standard deviations.
pub fn read_text_records(
    path: &Path,
    default_std: Option<Vector3<f64>>,
) -> Result<Vec<GnssRecord>, InputError> {
    let mut records = Vec::new();
    for_each_text_record(path, default_std, |r| records.push(r))?;
    Ok(records)
}

/// [`read_text_records`] one record at a time, each handed to `sink` as its line is
/// read, so that memory is bounded by a line whatever the log's length. The first
/// error in the file's order is returned.
pub fn for_each_text_record(
    path: &Path,
    default_std: Option<Vector3<f64>>,
    mut sink: impl FnMut(GnssRecord),
) -> Result<(), InputError> {
    type Csv<'a> = (CsvHeader<'a>, PositionCols);
    let (mut first, mut csv, mut prev): (bool, Option<Csv>, Option<f64>) = (true, None, None);
    super::lines::for_each_data_line(path, |n, l| {
        if std::mem::take(&mut first) && is_header(l) {
            let h = CsvHeader::parse(path, n, l);
            let cols = csv_position_cols(&h)?;
            csv = Some((h, cols));
            return Ok(());
        }
        // `t lat lon h [std_n std_e std_d [vn ve vd std_vn std_ve std_vd]]`, the
        // outlier flag, and the names errors give the time, position and std fields.
        let (v, outlier, (t_name, names)) = match &csv {
            None => {
                let v = text_row(path, (n, l), &POS_FIELDS, &[4, 7, 13], &|k| {
                    format!("{k} columns, expected [4, 7, 13]")
                })?;
                (v, None, (POS_FIELDS[0], (["lat", "lon", "h"], "std_n")))
            }
            Some((h, (cols, outlier))) => {
                let mut v = h.row(n, l, cols, "")?;
                let flag = outlier_flag(path, n, outlier.and_then(|_| v.pop()))?;
                let names = (["lat_deg", "lon_deg", "h_m"], "std_n_m");
                (v, flag, (cols[0].1, names))
            }
        };
        check_time(path, n, t_name, v[0], prev)?;
        prev = Some(v[0]);
        sink(gnss_record(path, n, &v, outlier, names, default_std)?);
        Ok(())
    })?;
    match prev {
        Some(_) => Ok(()),
        None => Err(no_data(path)),
    }
}

/// Read a GNSS position log of text (KF-GINS text or CSV with a header, see the
/// module doc) that gives its standard deviations, with each fix's line and outlier
/// flag.
pub fn read_gnss_records(path: &Path) -> Result<Vec<GnssRecord>, InputError> {
    read_text_records(path, None)
}

/// Read a GNSS position log of text that gives its standard deviations (KF-GINS text,
/// 7 or 13 columns, or CSV with a header; see the module doc): the fixes in time
/// order, with velocity where the 13-column layout gives it.
pub fn read_gnss(path: &Path) -> Result<Vec<GnssFix>, InputError> {
    Ok(read_gnss_records(path)?
        .into_iter()
        .map(|r| r.fix)
        .collect())
}

/// Whether `line` (trimmed) is an NMEA 0183 sentence: `$`, a talker and sentence
/// type of five upper-case letters or digits, a comma.
pub(crate) fn is_nmea_sentence(line: &[u8]) -> bool {
    line.len() > 7
        && line[0] == b'$'
        && line[1..6]
            .iter()
            .all(|b| b.is_ascii_uppercase() || b.is_ascii_digit())
        && line[6] == b','
}

/// The format of a position log by its content: NMEA if one of its first 200 lines
/// is a sentence, RTKLIB if a `%` line before its first data line names RTKLIB's
/// position columns, else text.
fn detect(bytes: &[u8]) -> GnssFormat {
    let lines = || {
        bytes
            .split(|&b| b == b'\n')
            .take(200)
            .map(<[u8]>::trim_ascii)
    };
    if lines().any(is_nmea_sentence) {
        return GnssFormat::Nmea;
    }
    for l in lines() {
        if l.is_empty() || l.starts_with(b"#") {
            continue;
        }
        if !l.starts_with(b"%") {
            break;
        }
        if super::rtklib::is_column_header(&String::from_utf8_lossy(l)) {
            return GnssFormat::Rtklib;
        }
    }
    GnssFormat::Text
}

/// The format `format` names, or with [`GnssFormat::Auto`] the one the start of the
/// file `path` shows ([`detect`] on its first 200 lines, at most 1 MiB).
pub fn format_of(path: &Path, format: GnssFormat) -> Result<GnssFormat, InputError> {
    if format != GnssFormat::Auto {
        return Ok(format);
    }
    let file = std::fs::File::open(path).map_err(|e| super::lines::cannot_read(path, &e))?;
    let mut head = Vec::new();
    std::io::Read::read_to_end(&mut std::io::Read::take(file, 1 << 20), &mut head)
        .map_err(|e| super::lines::cannot_read(path, &e))?;
    Ok(detect(head.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&head)))
}

/// Read a GNSS position log of any format (the module doc; `opts.format`, or told by
/// the content): the fixes in time order, with velocity where the format gives it,
/// and the reader's warnings.
pub fn read_gnss_log(path: &Path, opts: &GnssReadOptions) -> Result<GnssLog, InputError> {
    let bytes = read_lines_whole(path)?;
    let format = match opts.format {
        GnssFormat::Auto => detect(&bytes),
        f => f,
    };
    match format {
        GnssFormat::Nmea => super::nmea::read_nmea(path, &bytes, opts),
        GnssFormat::Rtklib => super::rtklib::read_rtklib(path, &utf8_text(path, bytes)?, opts),
        GnssFormat::Auto | GnssFormat::Text => Ok(GnssLog {
            fixes: read_text_records(path, opts.default_std)?
                .into_iter()
                .map(|r| r.fix)
                .collect(),
            format: GnssFormat::Text,
            warnings: Vec::new(),
        }),
    }
}

/// A velocity log's rows as `t vn ve vd [std_vn std_ve std_vd]`, and whether the file
/// is headerless text (whose rows [`merge_velocity`] checks against the fixes).
fn read_velocity(path: &Path) -> Result<(Rows, bool), InputError> {
    let text = read_text(path)?;
    let mut lines = data_lines(&text).peekable();
    let header = match lines.peek() {
        Some(&(n, l)) if is_header(l) => {
            lines.next();
            CsvHeader::parse(path, n, l)
        }
        _ => {
            let rows = text_rows(path, lines, &VEL_FIELDS, &[4, 7], &|k| {
                if k == 13 {
                    "13 columns: the layout of a GNSS position log with velocity (t lat lon h \
                     std_n std_e std_d vn ve vd std_vn std_ve std_vd), not of a velocity log \
                     (t vn ve vd [std_vn std_ve std_vd], 4 or 7 columns); give it as the \
                     position log, whose velocity columns are then used"
                        .to_owned()
                } else {
                    format!("{k} columns, expected [4, 7]")
                }
            })?;
            return Ok((rows, true));
        }
    };
    let position = ["lat_deg", "lon_deg", "h_m"]
        .iter()
        .filter_map(|name| header.find(name).ok().flatten())
        .count()
        > 0;
    let hint = if position {
        "; it names a position log's lat_deg, lon_deg or h_m: this is a GNSS position log, \
         not a velocity log"
    } else {
        ""
    };
    let mut cols: Vec<(usize, &str)> = header
        .require(&CSV_VEL, "a GNSS velocity log", hint)?
        .into_iter()
        .zip(CSV_VEL)
        .collect();
    cols.extend(header.all_or_none(&CSV_VEL_STD, "a velocity log")?);
    let rows = header.rows(
        lines,
        &cols,
        " (schuler simulate writes 0, exact velocities, when the scenario sets no \
         gnss.velocity_std)",
    )?;
    Ok((rows, false))
}

/// Add the velocities of a velocity log (text of 4 or 7 columns or CSV with a header,
/// see the module doc; `default_std` [m/s] where the file gives none) to the fixes at
/// the same times (within 1 µs). Returns the number of velocity epochs without a
/// position fix (not used). A text row that repeats its fix's latitude, longitude and
/// height is a position row and an error (the module doc gives the rule).
pub fn merge_velocity(
    fixes: &mut [GnssFix],
    path: &Path,
    default_std: f64,
) -> Result<usize, InputError> {
    let (rows, text) = read_velocity(path)?;
    let mut unmatched = 0;
    let mut j = 0;
    for (n, v) in rows {
        while j < fixes.len() && fixes[j].t < v[0] - 1e-6 {
            j += 1;
        }
        if j < fixes.len() && (fixes[j].t - v[0]).abs() <= 1e-6 {
            if text {
                check_not_position(path, n, &v, &fixes[j])?;
            }
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

/// The module doc's rule: a velocity text row `v` (line `n`) whose `vn ve vd` repeat
/// the latitude and longitude [deg] of `fix` within [`SAME_ANGLE_DEG`] and its height
/// within [`SAME_HEIGHT_M`] is a position row.
fn check_not_position(path: &Path, n: u64, v: &[f64], fix: &GnssFix) -> Result<(), InputError> {
    let (lat, lon, h) = (
        fix.pos.lat.to_degrees(),
        fix.pos.lon.to_degrees(),
        fix.pos.h,
    );
    let d_lon = (v[2] - lon + 180.0).rem_euclid(360.0) - 180.0;
    if (v[1] - lat).abs() <= SAME_ANGLE_DEG
        && d_lon.abs() <= SAME_ANGLE_DEG
        && (v[3] - h).abs() <= SAME_HEIGHT_M
    {
        return Err(InputError::new(
            InputErrorKind::LayoutMismatch,
            path,
            n,
            None,
            format!(
                "vn ve vd = {} {} {} repeat the latitude, longitude [deg] and height [m] of \
                 the position fix at t = {} ({lat:.9} {lon:.9} {h:.3}): this is a GNSS \
                 position log (t lat lon h std_n std_e std_d), not a velocity log (t vn ve \
                 vd [std_vn std_ve std_vd])",
                v[1], v[2], v[3], fix.t
            ),
        ));
    }
    Ok(())
}

/// Names of a barometer header's time column (any case).
const BARO_TIME_NAMES: [&str; 3] = ["t", "time", "timestamp"];
/// Names of a barometer header's height column [m] (any case).
const BARO_HEIGHT_NAMES: [&str; 6] = ["h_m", "h", "height", "height_m", "alt", "altitude"];

/// The time and height columns a barometer header names: each once (a name given
/// twice, or two of its names, is refused rather than one of them read).
fn baro_columns(header: &CsvHeader) -> Result<[usize; 2], InputError> {
    let t = header.find_any("t", &BARO_TIME_NAMES)?;
    let h = header.find_any("h", &BARO_HEIGHT_NAMES)?;
    match (t, h) {
        (Some(t), Some(h)) => Ok([t, h]),
        _ => Err(header.error(
            None,
            format!(
                "a barometer header names its time ({}) and its height in metres ({}); \
                 this one names {}",
                BARO_TIME_NAMES.join(", "),
                BARO_HEIGHT_NAMES.join(", "),
                header.names.join(", ")
            ),
        )),
    }
}

/// Read a barometer log: a CSV whose header names the time and the height columns in
/// any order (as `schuler simulate`'s `baro.csv`, `t,h_m[,outlier]`; other columns,
/// the simulator's outlier truth among them, are not read), or headerless `t h` rows.
/// Returns `(t, h)` pairs in time order.
pub fn read_baro(path: &Path) -> Result<Vec<(f64, f64)>, InputError> {
    let text = read_text(path)?;
    let mut lines = data_lines(&text).peekable();
    let header = match lines.peek() {
        Some(&(n, l)) if is_header(l) => {
            lines.next();
            let header = CsvHeader::parse(path, n, l);
            let columns = baro_columns(&header)?;
            Some((header, columns))
        }
        _ => None,
    };
    let mut out: Vec<(f64, f64)> = Vec::new();
    for (n, l) in lines {
        let [t, h] = match &header {
            // As many fields as the header names, the two read by their names.
            Some((header, [tc, hc])) => {
                let v = header.row(n, l, &[(*tc, "time"), (*hc, "h")], "")?;
                [v[0], v[1]]
            }
            None => {
                let f: Vec<&str> = fields(l).collect();
                if f.len() < 2 {
                    return Err(InputError::new(
                        InputErrorKind::ColumnCount,
                        path,
                        n,
                        None,
                        format!("{} fields, expected t and h", f.len()),
                    ));
                }
                [
                    parse_field(path, n, "time", f[0], "")?,
                    parse_field(path, n, "h", f[1], "")?,
                ]
            }
        };
        let h = in_domain(path, n, "h", &domain::HEIGHT, h)?;
        check_time(path, n, "time", t, out.last().map(|p| p.0))?;
        out.push((t, h));
    }
    if out.is_empty() {
        return Err(no_data(path));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::formats::temp_file as file;

    #[test]
    fn format_and_quality_names_are_listed_as_serde_reads_them() {
        use crate::named::check_listing;
        use GnssFormat::{Auto, Nmea, Rtklib, Text};
        check_listing(&[Auto, Text, Nmea, Rtklib]);
        use GnssQuality::{Dgps, Fix, Float, Single};
        check_listing(&[Single, Dgps, Float, Fix]);
    }

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

    /// The simulator's header, written by `schuler simulate` (commands/simulate.rs).
    const SIM_HEADER: &str = "t,lat_deg,lon_deg,h_m,std_n_m,std_e_m,std_d_m,vn_mps,ve_mps,vd_mps,std_vn_mps,std_ve_mps,std_vd_mps,outlier";

    #[test]
    fn reads_the_simulators_csv_by_its_header_as_the_text_twin() {
        // Velocity stds 0 (a scenario without gnss.velocity_std): not read as positions.
        let csv = file(&format!(
            "{SIM_HEADER}\n1,45.5,7.25,100.125,0.5,0.5,1,1.5,-2,0.25,0,0,0,0\n\
             2,45.50001,7.25001,100.5,0.5,0.5,1,1.5,-2,0.25,0,0,0,1\n"
        ));
        let txt = file("1 45.5 7.25 100.125 0.5 0.5 1\n2 45.50001 7.25001 100.5 0.5 0.5 1\n");
        let records = read_gnss_records(csv.path()).expect("reads the CSV");
        assert_eq!(
            records.iter().map(|r| r.fix).collect::<Vec<_>>(),
            read_gnss(txt.path()).expect("reads the text")
        );
        assert!(records.iter().all(|r| r.fix.vel.is_none()));
        assert_eq!(
            records
                .iter()
                .map(|r| (r.line, r.outlier))
                .collect::<Vec<_>>(),
            vec![(2, Some(false)), (3, Some(true))]
        );
        // Order free, names case-insensitive and quoted, `time` for `t`, other columns
        // ignored and not parsed, comments before the header.
        let csv = file(
            "# from elsewhere\n\"LON_DEG\", lat_deg ,h_m,std_n_m,std_e_m,std_d_m,time,note\n\
             7.25,45.5,100.125,0.5,0.5,1,1,abc\n",
        );
        let records = read_gnss_records(csv.path()).expect("reads");
        assert_eq!(records[0].fix, read_gnss(txt.path()).expect("reads")[0]);
        assert_eq!((records[0].line, records[0].outlier), (3, None));
    }

    #[test]
    fn a_csv_header_error_names_the_line_and_the_column() {
        let cases = [
            (
                "t,lat_deg,lon_deg,std_n_m,std_e_m,std_d_m\n1,45,7,1,1,1\n",
                ":1: field h_m: the header lacks column h_m (a GNSS position log needs t, \
                 lat_deg, lon_deg, h_m; other columns are ignored)",
            ),
            (
                "# c\nt,lat,lon,h_m,std_n_m,std_e_m,std_d_m\n",
                ":2: the header lacks columns lat_deg, lon_deg (",
            ),
            (
                "t lat lon h std_n std_e std_d\n",
                "was taken for a CSV header because its first field is not a number",
            ),
            (
                "t,lat_deg,lon_deg,h_m,std_n_m,std_e_m,std_d_m,time\n",
                ":1: field t: column appears twice (columns 1 and 8)",
            ),
            (
                &format!("{SIM_HEADER}\n1,45,7,100,1,1,1,0,0,0,0,0,0\n"),
                ":2: 13 columns, the header (line 1) names 14",
            ),
            (
                &format!("{SIM_HEADER}\n1,45,7,100,1,1,1,0,0,0,0,0,0,2\n"),
                ":2: field outlier: the outlier flag is 0 or 1, got 2",
            ),
            (
                &format!("{SIM_HEADER}\n1,45,7,,1,1,1,0,0,0,0,0,0,0\n"),
                ":2: field h_m: not a number: \"\"",
            ),
            (
                &format!("{SIM_HEADER}\n1,95,7,1,1,1,1,0,0,0,0,0,0,0\n"),
                ":2: field lat_deg: latitude 95 deg is outside",
            ),
            (
                &format!(
                    "{SIM_HEADER}\n2,45,7,1,1,1,1,0,0,0,0,0,0,0\n1,45,7,1,1,1,1,0,0,0,0,0,0,0\n"
                ),
                ":3: field t: time 1 does not increase",
            ),
            (&format!("{SIM_HEADER}\n"), "no data line"),
        ];
        for (text, want) in cases {
            let f = file(text);
            let e = read_gnss(f.path()).expect_err(text);
            let shown = e.to_string();
            assert!(
                shown.starts_with(&f.path().display().to_string()) && shown.contains(want),
                "{text:?}: {shown}"
            );
        }
    }

    #[test]
    fn velocity_logs_by_header_and_text() {
        let pos = "1 45.5 7.25 100 0.5 0.5 1\n2 45.50001 7.25001 100 0.5 0.5 1\n";
        // The simulator's CSV as a velocity log: its velocity columns by name.
        let mut fixes = read_gnss(file(pos).path()).expect("reads");
        let csv = file(&format!(
            "{SIM_HEADER}\n1,45.5,7.25,100,0.5,0.5,1,1.5,-2,0.25,0.05,0.05,0.1,0\n"
        ));
        assert_eq!(
            merge_velocity(&mut fixes, csv.path(), 0.3).expect("merge"),
            0
        );
        assert_eq!(
            fixes[0].vel,
            Some((Vector3::new(1.5, -2.0, 0.25), Vector3::new(0.05, 0.05, 0.1)))
        );
        assert!(fixes[1].vel.is_none());
        // Without standard deviations: the default.
        let csv = file("vd_mps,ve_mps,vn_mps,t\n0.25,-2,1.5,2\n");
        assert_eq!(
            merge_velocity(&mut fixes, csv.path(), 0.3).expect("merge"),
            0
        );
        assert_eq!(
            fixes[1].vel,
            Some((Vector3::new(1.5, -2.0, 0.25), Vector3::repeat(0.3)))
        );
        // A 7-column text velocity log is still one.
        let txt = file("1 30.5 114.3 -0.5 0.05 0.05 0.1\n2 0 0 0 0.05 0.05 0.1\n");
        assert_eq!(
            merge_velocity(&mut fixes, txt.path(), 0.3).expect("merge"),
            0
        );
        assert_eq!(fixes[0].vel.map(|(v, _)| v.y), Some(114.3));
    }

    #[test]
    fn a_position_log_is_never_read_as_velocities() {
        let pos = "# fixes\n1 45.5 7.25 100 0.5 0.5 1\n2 45.50001 7.25001 100.5 0.5 0.5 1\n";
        let cases = [
            // The position log itself (7 columns): line 2 is its first fix.
            (
                pos.to_owned(),
                ":2: vn ve vd = 45.5 7.25 100 repeat the latitude, longitude [deg] and height \
                 [m] of the position fix at t = 1",
            ),
            // Another receiver's positions, metres away, only from the second fix on.
            (
                "1 0 0 0\n2 45.50003 7.24998 98 0.5 0.5 1\n".to_owned(),
                ":2: vn ve vd = 45.50003 7.24998 98 repeat",
            ),
            // Longitude across the antimeridian's numbers.
            (
                "1 45.5 367.25 100\n".to_owned(),
                ":1: vn ve vd = 45.5 367.25 100 repeat",
            ),
            (
                "1 45.5 7.25 100 0.5 0.5 1 0 0 0 0.1 0.1 0.1\n".to_owned(),
                ":1: 13 columns: the layout of a GNSS position log with velocity",
            ),
            (
                "t,lat_deg,lon_deg,h_m,std_n_m,std_e_m,std_d_m\n1,45.5,7.25,100,0.5,0.5,1\n"
                    .to_owned(),
                ":1: the header lacks columns vn_mps, ve_mps, vd_mps (a GNSS velocity log \
                 needs t, vn_mps, ve_mps, vd_mps; other columns are ignored); it names a \
                 position log's lat_deg",
            ),
            (
                format!("{SIM_HEADER}\n1,45.5,7.25,100,0.5,0.5,1,1.5,-2,0.25,0,0,0,0\n"),
                ":2: field std_vn_mps: a standard deviation must be positive, got 0 (schuler \
                 simulate writes 0",
            ),
            (
                "t,vn_mps,ve_mps,vd_mps,std_vn_mps\n1,0,0,0,0.1\n".to_owned(),
                ":1: field std_ve_mps: the header names std_vn_mps but not std_ve_mps, \
                 std_vd_mps",
            ),
        ];
        for (text, want) in cases {
            let mut fixes = read_gnss(file(pos).path()).expect("reads");
            let f = file(&text);
            let e = merge_velocity(&mut fixes, f.path(), 0.1).expect_err(&text);
            let shown = e.to_string();
            assert!(
                shown.starts_with(&f.path().display().to_string()) && shown.contains(want),
                "{text:?}: {shown}"
            );
        }
        let mut fixes = read_gnss(file(pos).path()).expect("reads");
        let e = merge_velocity(&mut fixes, file(pos).path(), 0.1).expect_err("position");
        assert_eq!(e.kind, InputErrorKind::LayoutMismatch);
        // A real velocity log at the same numbers in another unit would need a speed
        // of 45 m/s north, 7 m/s east and 100 m/s down: a fast dive, but not the fix's
        // own coordinates to 0.001, so it is read.
        let v = file("1 45.6 7.25 100\n");
        assert_eq!(
            merge_velocity(&mut fixes, v.path(), 0.1).expect("a velocity"),
            0
        );
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
        // The header's order is honoured (it used to be ignored: column 2 was read as
        // the height whatever the header said), with a byte-order mark in front.
        let f = file("\u{feff}pressure_pa;Altitude;Time\n101000;100.5;0.1\n101001;100.7;0.2\n");
        assert_eq!(
            read_baro(f.path()).expect("reads"),
            vec![(0.1, 100.5), (0.2, 100.7)]
        );
        let f = file("t,pressure_pa\n0.1,101000\n");
        let e = read_baro(f.path()).expect_err("no height").to_string();
        assert!(e.contains(":1: a barometer header names its time"), "{e}");
    }

    #[test]
    fn four_columns_take_the_default_std_and_any_separator_works() {
        let std = Some(Vector3::new(0.5, 0.6, 1.5));
        let four = file("# t lat lon h\n1\t45.5;7.25, 100\n\n2 45.5 7.25 101\n");
        let records = read_text_records(four.path(), std).expect("reads");
        assert_eq!(records.len(), 2);
        assert_eq!(
            records[0].fix.pos,
            Geodetic::from_degrees(45.5, 7.25, 100.0)
        );
        assert_eq!(records[1].fix.pos_std, Vector3::new(0.5, 0.6, 1.5));
        assert_eq!(records[1].line, 4);
        let e = read_gnss(four.path()).expect_err("no std").to_string();
        assert!(
            e.ends_with(
                ":2: field std_n: the file gives no position standard deviations for \
                         this fix: give them with --gnss-std N,E,D [m]"
            ),
            "{e}"
        );
        // A CSV with semicolons and no standard deviations; one with only some of them.
        let csv = file("t;lat_deg;lon_deg;h_m\n1;45.5;7.25;100\n");
        let r = read_text_records(csv.path(), std).expect("reads");
        assert_eq!(r[0].fix, records[0].fix);
        let e = read_gnss(csv.path()).expect_err("no std").to_string();
        assert!(e.contains(":2: field std_n_m: the file gives no"), "{e}");
        let csv = file("t;lat_deg;lon_deg;h_m;std_e_m\n1;45.5;7.25;100;1\n");
        let e = read_text_records(csv.path(), std)
            .expect_err("some")
            .to_string();
        assert!(
            e.contains(":1: field std_n_m: the header names std_e_m but not std_n_m, std_d_m"),
            "{e}"
        );
        // The baro log with tabs and a comment before its header.
        let baro = file("# sensor\nt\th_m\n0.1\t100.5\n");
        assert_eq!(read_baro(baro.path()).expect("reads"), vec![(0.1, 100.5)]);
    }

    #[test]
    fn the_format_is_told_by_the_content() {
        let opts = GnssReadOptions {
            default_std: Some(Vector3::repeat(1.0)),
            ..GnssReadOptions::default()
        };
        let cases = [
            ("1 45 7 100\n", GnssFormat::Text),
            ("% matlab comment\n1 45 7 100\n", GnssFormat::Text),
            (
                "% (lat/lon/height=WGS84/ellipsoidal)\n%  GPST latitude(deg) longitude(deg) \
                 height(m)\n2000 1.0 45 7 100\n",
                GnssFormat::Rtklib,
            ),
            (
                "\u{1}\u{2}binary\n$GPGGA,000001,4504.2,N,00740.8,E,1,8,1.0,200.0,M,0.0,M,,*44\n",
                GnssFormat::Nmea,
            ),
        ];
        for (text, want) in cases {
            let log = read_gnss_log(file(text).path(), &opts).expect(text);
            assert_eq!((log.format, log.fixes.len()), (want, 1), "{text:?}");
        }
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
            (
                "1 45 400 100 0.5 0.5 1\n",
                "field lon",
                "longitude 400 deg is outside",
            ),
            (
                "1 45 7 -1e7 0.5 0.5 1\n",
                "field h",
                "height -10000000 m is outside",
            ),
            (
                "1 45 7 1e12 0.5 0.5 1\n",
                "field h",
                "outside [-12000, 100000000] m",
            ),
        ];
        for (text, at, what) in cases {
            let f = file(text);
            let e = read_gnss(f.path()).expect_err(text).to_string();
            assert!(e.contains(at) && e.contains(what), "{text:?}: {e}");
        }
    }
}
