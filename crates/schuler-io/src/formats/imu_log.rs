//! Streaming IMU log readers: KF-GINS text and CSV, to [`ImuSample`]s in the vehicle's
//! FRD axes.
//!
//! # Formats
//! - **KF-GINS text** (also the awesome-gins-datasets IMU files): one sample per line,
//!   7 numbers separated by blanks (spaces or tabs, repeated) or one comma or semicolon
//!   (with optional blanks around it): `t` [s, GPS seconds of week], `dtheta_x y z` [rad],
//!   `dvel_x y z` [m/s], body axes FRD. Each line holds the increments over
//!   `(t_prev, t]`, `t_prev` the previous line's time. With [`ImuLayout::Rates`] the
//!   same columns are read as angular rate `w_x y z` [rad/s] and specific force
//!   `f_x y z` [m/s²].
//! - **Text in another column order** ([`ImuReadOptions::columns`], `--imu-columns`):
//!   the same separators, the columns named by the caller (`t,fx,fy,fz,wx,wy,wz`, `_`
//!   for a column to skip, a last `...` for further columns to ignore); the names say
//!   rates or increments (see [`super::imu_columns`]).
//! - **CSV** (our native format): a header row, then rows with as many fields as the
//!   header, separated by the header's delimiter (a comma, or a semicolon as written
//!   where the comma is the decimal mark; a decimal comma in a number is refused). A
//!   header of blank-separated names heads rows read as text. Columns are found by name (see [`super::imu_columns`] for
//!   every name and unit recognised): `t` (or `time`, `timestamp`), then either
//!   increments `dtheta_x, dtheta_y, dtheta_z, dvel_x, dvel_y, dvel_z` [rad, m/s] or
//!   rates `w_x, w_y, w_z, f_x, f_y, f_z` [rad/s, m/s²], or common names such as
//!   `gyro_x`, `acc_x`, `gx_dps`, `ax_g`. Order is free, other columns are ignored (and
//!   not parsed), missing ones are an error naming them and listing what is
//!   recognised. A header with both sets reads increments unless the options say
//!   rates. With [`ImuReadOptions::columns`] the header line is skipped and the columns
//!   are the caller's. Quoted data fields are not supported.
//!
//! Every sample is checked against the physical domains of [`schuler::domain`]: an
//! interval longer than a minute (a gap would be integrated as free fall), an angular
//! rate or a specific force no sensor reads. Such a line stops the reading with an
//! [`InputErrorKind::OutOfDomain`] naming it and its columns.
//!
//! In all, blank lines and lines whose first non-blank byte is `#` or `%` are skipped,
//! a UTF-8 byte-order mark and `\r\n` line ends are accepted, and line numbers in
//! errors count every line of the file (1-based).
//!
//! # Units, time and axes
//! The gyro and accelerometer columns are in [`ImuReadOptions::gyro_unit`] and
//! [`ImuReadOptions::accel_unit`] (or a unit written in the header's names; SI by
//! default), converted to SI on reading. The time column is in seconds or in integer
//! ticks of [`ImuReadOptions::time_unit`] (ms, µs, ns; integers are converted exactly
//! to whole seconds and a fraction, so 19-digit UNIX nanoseconds keep their
//! resolution), then [`ImuReadOptions::time_offset`] is added: every time the reader
//! reports, checks or compares with the window is on that clock. Each sample's
//! increments are then turned by [`ImuReadOptions::c_vs`] from the IMU's axes into the
//! vehicle's FRD axes.
//!
//! # Time and increments
//! A sample's `dt = t - t_prev`. The first sample of a file has no predecessor: it gets
//! `dt` = the nominal interval, and navigation starts **at** the first sample's time
//! (its state is the initial state at `t`), so that sample's increment is never
//! integrated. With a time window the first yielded sample usually has a predecessor
//! (skipped) and gets its true `dt`; navigation starting at it does not integrate it
//! either.
//!
//! Rates are converted to increments explicitly: a rate sample tagged `t` is taken as
//! the mean rate over `(t_prev, t]`, so `dtheta = w * dt` and `dvel = f * dt`
//! (rectangular rule; the first sample uses the nominal `dt`).
//!
//! # Checks
//! Every problem is an [`InputError`] naming the file, the line and the field, never a
//! panic; the first error ends the iteration.
//! - wrong column count, empty or non-numeric field, NaN or ±Inf (also overflow);
//! - time going backwards or repeating (both times and lines named);
//! - values a sensor on the Earth cannot read, with the flags that probably read the
//!   file right (see [`ImuReadOptions::check_layout`] and
//!   [`super::imu_plausibility`]);
//! - options that contradict each other or the header (`--gyro-unit deg/s` with
//!   `--imu-layout increments`, `--accel-unit g` with a column `acc_x_mps2`);
//! - a line over 64 KiB (bounds memory on a file without newlines).
//!
//! Gaps (an interval longer than [`GAP_FACTOR`] nominal intervals) are not errors:
//! the sample is yielded with its true `dt` and the gap counted in a [`GapReport`].
//!
//! # Nominal interval
//! Given by the caller ([`ImuReadOptions::nominal_dt`]) or estimated as the median of
//! the first up to [`LOOKAHEAD_INTERVALS`] intervals. The reader parses that many
//! samples ahead at construction (about 13 KiB), so memory stays constant.
//!
//! # Speed
//! Lines are read into one reused buffer with `read_until`, fields split by hand and
//! parsed with `fast-float2`; nothing is allocated per line.

use std::collections::VecDeque;
use std::fmt;
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use nalgebra::{Matrix3, Vector3};
use schuler::domain;
use schuler::imu::ImuSample;

use super::error::{InputError, InputErrorKind, quote_field};
use super::imu_columns::{
    AccelUnit, ColumnSpec, Declared, GyroUnit, INCREMENT_NAMES, Plan, PlanError, RATE_NAMES,
    SLOT_TIME, TimeUnit, UNUSED, default_plan, plan, recognise,
};
use super::imu_plausibility::{Reading, Sensor};
use super::lines::{LineReadError, LineReader, MAX_LINE_BYTES, is_blank, is_skippable};
use super::lines_ahead::{Lines, LinesAhead, Parsed};

/// Standard gravity g₀ [m/s²] (CGPM 1901), the yardstick of the layout check.
pub const STANDARD_GRAVITY: f64 = 9.806_65;

/// Intervals parsed ahead at construction to estimate the nominal interval and check
/// the layout (201 samples).
pub const LOOKAHEAD_INTERVALS: usize = 200;

/// An interval longer than this many nominal intervals counts as a gap.
pub const GAP_FACTOR: f64 = 2.0;

/// Fewest lookahead intervals for the layout check to run; below it the check is
/// skipped (a median of fewer samples says too little).
pub const LAYOUT_CHECK_MIN_INTERVALS: usize = 10;

/// Which text format a log is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ImuFormat {
    /// Decide from the first non-comment line: a number first means KF-GINS text,
    /// anything else a CSV header.
    #[default]
    Auto,
    /// KF-GINS / awesome-gins-datasets: 7 numeric columns, no header.
    KfGinsText,
    /// CSV with a header naming the columns.
    Csv,
}

/// Whether a log's six sensor columns hold increments or rates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImuLayout {
    /// Angle increments [rad] and velocity increments [m/s] over `(t_prev, t]`.
    Increments,
    /// Angular rate [rad/s] and specific force [m/s²], each the mean over `(t_prev, t]`.
    Rates,
}

impl fmt::Display for ImuLayout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Increments => "increments",
            Self::Rates => "rates",
        })
    }
}

/// How to read an IMU log.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuReadOptions {
    /// The file format.
    pub format: ImuFormat,
    /// The layout; `None`: as the units or column names say, else increments for
    /// KF-GINS text and the header's columns for CSV.
    pub layout: Option<ImuLayout>,
    /// The column order of a file without a header (or whose header is to be skipped).
    pub columns: Option<ColumnSpec>,
    /// Unit of the gyro columns; `None`: as the header's names say, else SI.
    pub gyro_unit: Option<GyroUnit>,
    /// Unit of the accelerometer columns; `None`: as the header's names say, else SI.
    pub accel_unit: Option<AccelUnit>,
    /// Unit of the time column; `None`: as the header's name says, else seconds.
    pub time_unit: Option<TimeUnit>,
    /// Added to every time after the unit conversion [s].
    pub time_offset: f64,
    /// `c_vs`, the DCM from the IMU's axes to the vehicle's FRD axes applied to every
    /// sample; `None`: the IMU's axes are FRD.
    pub c_vs: Option<Matrix3<f64>>,
    /// Nominal sample interval [s]; `None`: median of the first intervals.
    pub nominal_dt: Option<f64>,
    /// Skip samples with `t < t_start` [s, the reader's clock], checking only their
    /// time.
    pub t_start: Option<f64>,
    /// Stop at the first sample with `t > t_end` [s, the reader's clock].
    pub t_end: Option<f64>,
    /// Reject logs whose first samples a sensor on the Earth cannot read (default on;
    /// turn off for free fall, centrifuges, rockets and other starts outside
    /// [`super::imu_plausibility`]'s bounds).
    pub check_layout: bool,
}

impl Default for ImuReadOptions {
    fn default() -> Self {
        Self {
            format: ImuFormat::Auto,
            layout: None,
            columns: None,
            gyro_unit: None,
            accel_unit: None,
            time_unit: None,
            time_offset: 0.0,
            c_vs: None,
            nominal_dt: None,
            t_start: None,
            t_end: None,
            check_layout: true,
        }
    }
}

impl ImuReadOptions {
    /// The declarations about the sensor columns.
    fn declared(&self) -> Declared {
        Declared {
            layout: self.layout,
            gyro: self.gyro_unit,
            accel: self.accel_unit,
            time: self.time_unit,
        }
    }
}

/// Gaps met so far: intervals longer than [`GAP_FACTOR`] nominal intervals ending at a
/// yielded sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GapReport {
    /// Number of gaps.
    pub count: u64,
    /// Longest gap [s] (0 if none).
    pub longest_s: f64,
    /// Time [s] of the sample ending the longest gap.
    pub longest_at_t: Option<f64>,
    /// Time [s] of the sample ending the first gap.
    pub first_at_t: Option<f64>,
    /// Threshold [s]: an interval longer than this is a gap.
    pub threshold_s: f64,
}

impl GapReport {
    /// Whether no gap was met.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Counts a gap of `dt` [s] ending at the sample at `t`.
    pub fn record(&mut self, t: f64, dt: f64) {
        self.count += 1;
        if self.first_at_t.is_none() {
            self.first_at_t = Some(t);
        }
        if dt > self.longest_s {
            self.longest_s = dt;
            self.longest_at_t = Some(t);
        }
    }
}

impl fmt::Display for GapReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} gap(s) longer than {} s",
            self.count, self.threshold_s
        )?;
        if let (Some(first), Some(longest_at)) = (self.first_at_t, self.longest_at_t) {
            write!(
                f,
                "; first ending at t = {first}, longest {} s ending at t = {longest_at}",
                self.longest_s
            )?;
        }
        Ok(())
    }
}

/// A cloneable handle on a reader's count of bytes consumed, for a progress bar on
/// another thread or after the reader has moved into an iterator chain.
#[derive(Debug, Clone)]
pub struct ProgressCounter(Arc<AtomicU64>);

impl ProgressCounter {
    /// Bytes consumed so far (a recent value).
    pub fn bytes(&self) -> u64 {
        self.0.load(Ordering::Relaxed)
    }
}

/// How a line's fields map to slots (0 time, 1–3 gyro, 4–6 accelerometer).
#[derive(Clone)]
struct Columns {
    /// Separated by [`Self::delim`] only (CSV), else by blanks, commas or semicolons
    /// (text).
    csv: bool,
    /// The CSV's field delimiter (`,` or `;`, told by the header).
    delim: u8,
    /// Column i's slot, or [`UNUSED`].
    slot_of_col: Vec<u8>,
    /// The columns' names, for messages.
    names: Vec<String>,
    /// The time's column.
    time_col: usize,
    /// Whether a line may hold further columns, ignored.
    trailing: bool,
    /// Whether the columns are not KF-GINS's seven in slot order.
    mapped: bool,
}

impl Columns {
    /// Parses `line`'s time (`time_only`) or all its columns into `out` (in slot
    /// order); returns where the time lies.
    #[inline]
    fn parse(&self, line: &[u8], time_only: bool, out: &mut [f64; 7]) -> Result<Span, FieldError> {
        let mut span = (0, 0);
        if self.csv {
            parse_csv_line(
                line,
                &self.slot_of_col,
                self.delim,
                (time_only, self.trailing),
                out,
                &mut span,
            )?;
        } else {
            let ncols = if time_only {
                self.time_col + 1
            } else {
                self.slot_of_col.len()
            };
            let slots = &self.slot_of_col;
            if self.mapped {
                parse_text_line::<true>(line, slots, ncols, self.trailing, out, &mut span)?;
            } else {
                parse_text_line::<false>(line, slots, ncols, false, out, &mut span)?;
            }
        }
        Ok(span)
    }

    /// KF-GINS text: 7 columns in slot order, named canonically for `layout`.
    fn kf_gins(layout: ImuLayout) -> Self {
        let names = match layout {
            ImuLayout::Increments => INCREMENT_NAMES,
            ImuLayout::Rates => RATE_NAMES,
        };
        Self {
            csv: false,
            delim: b',',
            slot_of_col: (0..7).collect(),
            names: names.iter().map(|&n| n.to_owned()).collect(),
            time_col: 0,
            trailing: false,
            mapped: false,
        }
    }
}

/// The delimiter of a header line: the first comma or semicolon it holds, else none
/// (the names and the data are separated by blanks, as in text).
fn header_delimiter(line: &[u8]) -> Option<u8> {
    line.iter().copied().find(|&b| is_mark(b))
}

/// The column names of a header line separated by `delim` (or by blanks without one):
/// each trimmed of blanks and of one pair of double quotes.
fn header_names(line: &[u8], delim: Option<u8>) -> Vec<String> {
    let split: Box<dyn Iterator<Item = &[u8]>> = match delim {
        Some(d) => Box::new(line.split(move |&b| b == d)),
        None => Box::new(line.split(|&b| is_blank(b)).filter(|f| !f.is_empty())),
    };
    split
        .map(|raw| {
            let text = String::from_utf8_lossy(raw);
            let text = text.trim_matches([' ', '\t']);
            let text = text
                .strip_prefix('"')
                .and_then(|s| s.strip_suffix('"'))
                .unwrap_or(text);
            text.trim().to_owned()
        })
        .collect()
}

/// A field-level parse failure, before the file and names are attached.
#[derive(Debug, Clone, Copy, PartialEq)]
enum FieldError {
    Columns {
        found: usize,
    },
    Empty {
        col: usize,
    },
    NotANumber {
        col: usize,
        start: usize,
        end: usize,
    },
    NotFinite {
        col: usize,
        start: usize,
        end: usize,
    },
}

/// One parsed line: time (on the reader's clock) and the six sensor values as written
/// (not yet scaled).
#[derive(Debug, Clone, Copy)]
struct Record {
    t: f64,
    v: [f64; 6],
    /// The 1-based line it was read from.
    line: u64,
}

/// Whether a comma or a semicolon: the separators of text lines besides blanks.
#[inline]
fn is_mark(b: u8) -> bool {
    b == b',' || b == b';'
}

#[inline]
fn skip_blanks(line: &[u8], mut pos: usize) -> usize {
    while pos < line.len() && is_blank(line[pos]) {
        pos += 1;
    }
    pos
}

/// Parses a number at `line[start..]` that ends at a blank, a comma, a semicolon or the
/// line end;
/// returns it and the index just past it.
#[inline]
fn parse_number(line: &[u8], start: usize, col: usize) -> Result<(f64, usize), FieldError> {
    let rest = &line[start..];
    match fast_float2::parse_partial::<f64, _>(rest) {
        Ok((v, n)) if n > 0 && rest.get(n).is_none_or(|&b| is_blank(b) || is_mark(b)) => {
            if v.is_finite() {
                Ok((v, start + n))
            } else {
                Err(FieldError::NotFinite {
                    col,
                    start,
                    end: start + n,
                })
            }
        }
        _ => Err(FieldError::NotANumber {
            col,
            start,
            end: start,
        }),
    }
}

/// Text format: skips one separator (blanks, at most one comma or semicolon, blanks).
#[inline]
fn skip_text_separator(line: &[u8], pos: usize) -> usize {
    let pos = skip_blanks(line, pos);
    if pos < line.len() && is_mark(line[pos]) {
        skip_blanks(line, pos + 1)
    } else {
        pos
    }
}

/// Text format: end of the field starting at `start` (next blank, comma, semicolon or
/// line end).
fn text_field_end(line: &[u8], start: usize) -> usize {
    line[start..]
        .iter()
        .position(|&b| is_blank(b) || is_mark(b))
        .map_or(line.len(), |n| start + n)
}

/// Text format: number of fields on a line (an empty field between two commas or
/// semicolons counts).
fn count_text_fields(line: &[u8]) -> usize {
    let mut n = 0;
    let mut pos = skip_blanks(line, 0);
    while pos < line.len() {
        n += 1;
        if !is_mark(line[pos]) {
            pos = text_field_end(line, pos);
        }
        pos = skip_text_separator(line, pos);
    }
    n
}

/// Where the time field of the line just parsed lies (`start..end`).
type Span = (usize, usize);

/// Text format: parses the first `ncols` columns of `slots` (each column's slot, or
/// [`UNUSED`] to skip it; with `MAPPED` false column i is slot i, KF-GINS's fast path)
/// into `out`, the time's span into `time`, and with `ncols == slots.len()` and not
/// `trailing` checks that nothing follows. A trailing separator is accepted.
#[inline]
fn parse_text_line<const MAPPED: bool>(
    line: &[u8],
    slots: &[u8],
    ncols: usize,
    trailing: bool,
    out: &mut [f64; 7],
    time: &mut Span,
) -> Result<(), FieldError> {
    let mut pos = skip_blanks(line, 0);
    for col in 0..ncols.min(slots.len()) {
        // `col` < 7 without a map: KF-GINS text has 7 slots.
        let slot = if MAPPED { slots[col] } else { col as u8 };
        if MAPPED && slot == UNUSED && pos < line.len() {
            let end = if is_mark(line[pos]) {
                pos
            } else {
                text_field_end(line, pos)
            };
            pos = skip_text_separator(line, end);
            continue;
        }
        let res = if pos >= line.len() {
            Err(FieldError::Columns { found: col })
        } else if is_mark(line[pos]) {
            Err(FieldError::Empty { col })
        } else {
            parse_number(line, pos, col)
        };
        match res {
            Ok((v, end)) => {
                out[usize::from(slot)] = v;
                if slot == SLOT_TIME {
                    *time = (pos, end);
                }
                pos = skip_text_separator(line, end);
            }
            Err(e) => return Err(text_error(line, slots.len(), trailing, e)),
        }
    }
    if ncols == slots.len() && !trailing && pos < line.len() {
        return Err(FieldError::Columns {
            found: count_text_fields(line),
        });
    }
    Ok(())
}

/// Whether `found` columns are wrong where `expected` (or more, with `trailing`) are due.
fn wrong_count(found: usize, expected: usize, trailing: bool) -> bool {
    found < expected || (found > expected && !trailing)
}

/// Text format: a wrong column count outranks a bad field; fills in a bad field's end.
#[cold]
fn text_error(line: &[u8], expected: usize, trailing: bool, e: FieldError) -> FieldError {
    let found = count_text_fields(line);
    if wrong_count(found, expected, trailing) {
        return FieldError::Columns { found };
    }
    match e {
        FieldError::NotANumber { col, start, .. } => FieldError::NotANumber {
            col,
            start,
            end: text_field_end(line, start),
        },
        other => other,
    }
}

/// CSV: number of fields (delimiters + 1).
fn count_csv_fields(line: &[u8], delim: u8) -> usize {
    line.iter().filter(|&&b| b == delim).count() + 1
}

/// CSV: the field at `start` trimmed of blanks: `(start, end)`.
fn csv_field_bounds(line: &[u8], start: usize, delim: u8) -> (usize, usize) {
    let end = line[start..]
        .iter()
        .position(|&b| b == delim)
        .map_or(line.len(), |n| start + n);
    let s = skip_blanks(line, start).min(end);
    let mut e = end;
    while e > s && is_blank(line[e - 1]) {
        e -= 1;
    }
    (s, e)
}

/// CSV: parses the used columns of a row into `out` by `slot_of_col`, the time's span
/// into `time`. With `time_only`, parses the time column and stops there (no column
/// count check); with `trailing`, further columns are allowed.
#[inline]
fn parse_csv_line(
    line: &[u8],
    slot_of_col: &[u8],
    delim: u8,
    (time_only, trailing): (bool, bool),
    out: &mut [f64; 7],
    time: &mut Span,
) -> Result<(), FieldError> {
    let len = line.len();
    let ncols = slot_of_col.len();
    let fail = |e| Err(csv_error(line, delim, ncols, trailing, e));
    // Start of the current field; `len + 1` once the line has no more fields.
    let mut pos = 0;
    for (col, &slot) in slot_of_col.iter().enumerate() {
        if pos > len {
            return fail(FieldError::Columns { found: col });
        }
        let wanted = if time_only {
            slot == SLOT_TIME
        } else {
            slot != UNUSED
        };
        let next = if wanted {
            let start = skip_blanks(line, pos);
            if start >= len || line[start] == delim {
                return fail(FieldError::Empty { col });
            }
            let (v, end) = match parse_number(line, start, col) {
                Ok(ok) => ok,
                Err(e) => return fail(e),
            };
            let after = skip_blanks(line, end);
            if after < len && line[after] != delim {
                return fail(FieldError::NotANumber {
                    col,
                    start,
                    end: start,
                });
            }
            out[usize::from(slot)] = v;
            if slot == SLOT_TIME {
                *time = (start, end);
                if time_only {
                    return Ok(());
                }
            }
            after
        } else {
            line[pos..]
                .iter()
                .position(|&b| b == delim)
                .map_or(len, |n| pos + n)
        };
        pos = next + 1;
    }
    if pos <= len && !trailing {
        return Err(FieldError::Columns {
            found: count_csv_fields(line, delim),
        });
    }
    Ok(())
}

/// CSV: a wrong column count outranks a bad field; fills in a bad field's bounds.
#[cold]
fn csv_error(line: &[u8], delim: u8, ncols: usize, trailing: bool, e: FieldError) -> FieldError {
    let found = count_csv_fields(line, delim);
    if wrong_count(found, ncols, trailing) {
        return FieldError::Columns { found };
    }
    match e {
        FieldError::NotANumber { col, start, .. } => {
            let (start, end) = csv_field_bounds(line, start, delim);
            FieldError::NotANumber { col, start, end }
        }
        other => other,
    }
}

/// An integer with an optional sign that fits an `i64` (time stamps in ticks).
fn parse_integer(field: &[u8]) -> Option<i64> {
    let (negative, digits) = match field.first() {
        Some(b'-') => (true, &field[1..]),
        Some(b'+') => (false, &field[1..]),
        _ => (false, field),
    };
    if digits.is_empty() || !digits.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let n = digits.iter().try_fold(0i64, |n, &d| {
        n.checked_mul(10)?.checked_add(i64::from(d - b'0'))
    })?;
    Some(if negative { -n } else { n })
}

/// The time [s] of a stamp `value` written as `field` in `unit`, plus `offset` [s].
/// Integer ticks are split into whole seconds and a fraction, the offset added to the
/// whole seconds first, so nanoseconds since 1970 keep their resolution.
fn stamp_seconds(field: &[u8], value: f64, unit: TimeUnit, offset: f64) -> f64 {
    if unit == TimeUnit::S {
        return if offset == 0.0 { value } else { value + offset };
    }
    let k = unit.ticks_per_second();
    match parse_integer(field) {
        // Both parts are exact in f64 (|n / k| < 2^53); the fraction rounds once.
        Some(n) => (n.div_euclid(k) as f64 + offset) + n.rem_euclid(k) as f64 / k as f64,
        None => value / k as f64 + offset,
    }
}

/// Median of `values` (sorted in place); `None` if empty.
pub(super) fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_unstable_by(f64::total_cmp);
    let n = values.len();
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    })
}

/// A lazy, constant-memory reader of an IMU log, yielding increments in the vehicle's
/// FRD axes.
///
/// Iterating yields `Ok(sample)` per data line in the time window, or one `Err` and
/// then nothing.
pub struct ImuReader<R> {
    lines: Lines<R>,
    path: PathBuf,
    format: ImuFormat,
    columns: Columns,
    layout: ImuLayout,
    /// How the columns are read (for the plausibility check).
    plan: Plan,
    /// The columns' units to SI: gyro, accelerometer.
    to_si: (f64, f64),
    /// The time column's unit and the offset added [s].
    clock: (TimeUnit, f64),
    /// IMU axes to vehicle FRD.
    c_vs: Option<Matrix3<f64>>,
    nominal_dt: f64,
    t_start: Option<f64>,
    t_end: Option<f64>,
    /// Samples parsed at construction, not yet yielded.
    lookahead: VecDeque<Record>,
    /// Time and line of the last parsed record (monotonic check).
    last: Option<(f64, u64)>,
    /// Time of the last record handed to the window logic (for `dt`).
    prev_t: Option<f64>,
    /// Whether a record with `t >= t_start` has been met.
    reached_start: bool,
    /// Line of the first data line (0 before it is read).
    first_data_line: u64,
    /// Whether the format was detected as CSV (for a hint in header errors).
    csv_auto_detected: bool,
    gaps: GapReport,
    finished: bool,
}

impl ImuReader<File> {
    /// Opens the file at `path` (read in large blocks, no `BufReader` needed) and reads its
    /// first samples (see [`ImuReader::new`]).
    pub fn open(path: &Path, options: &ImuReadOptions) -> Result<Self, InputError> {
        let file = File::open(path).map_err(|e| {
            InputError::new(
                InputErrorKind::Io,
                path,
                0,
                None,
                format!("cannot open: {e}"),
            )
        })?;
        Self::new(file, path, options)
    }
}

impl<R: Read + Send + 'static> ImuReader<R> {
    /// The rest of the log read, and its fields parsed, on a helper thread
    /// ([`LinesAhead`]); the samples, errors and gaps are the same, in the same
    /// order, while this reader's checks and conversions run on the thread that
    /// iterates. Dropping the reader does not wait for the helper.
    pub fn read_ahead(mut self) -> std::io::Result<Self> {
        let Lines::Here(lines) =
            std::mem::replace(&mut self.lines, Lines::Ahead(LinesAhead::ended()))
        else {
            return Ok(self);
        };
        let columns = self.columns.clone();
        let parse = move |line: &[u8]| {
            let mut values = [0.0; 7];
            let time_span = columns.parse(line, false, &mut values).ok()?;
            Some(Parsed { values, time_span })
        };
        self.lines = Lines::Ahead(LinesAhead::spawn(lines, parse)?);
        Ok(self)
    }
}

impl<R: Read> ImuReader<R> {
    /// Wraps `input` (named `path` in errors, e.g. `<stdin>`), reads the CSV header if
    /// any and the first up to [`LOOKAHEAD_INTERVALS`] + 1 samples, fixes the nominal
    /// interval and runs the plausibility check.
    ///
    /// Any reader will do, standard input too: the lines are read in large blocks.
    pub fn new(
        input: R,
        path: impl Into<PathBuf>,
        options: &ImuReadOptions,
    ) -> Result<Self, InputError> {
        let path = path.into();
        check_options(&path, options)?;
        let mut reader = Self {
            lines: Lines::Here(LineReader::new(input)),
            path,
            format: options.format,
            columns: Columns::kf_gins(ImuLayout::Increments),
            layout: ImuLayout::Increments,
            plan: Plan::kf_gins(ImuLayout::Increments),
            to_si: (1.0, 1.0),
            clock: (TimeUnit::S, options.time_offset),
            c_vs: options.c_vs,
            nominal_dt: f64::NAN,
            t_start: options.t_start,
            t_end: options.t_end,
            lookahead: VecDeque::with_capacity(LOOKAHEAD_INTERVALS + 1),
            last: None,
            prev_t: None,
            reached_start: options.t_start.is_none(),
            first_data_line: 0,
            csv_auto_detected: false,
            gaps: GapReport::default(),
            finished: false,
        };
        let first_is_data = reader.read_first_line(options)?;
        if first_is_data {
            let record = reader.parse_current(false)?;
            reader.lookahead.push_back(record);
        }
        while reader.lookahead.len() <= LOOKAHEAD_INTERVALS {
            match reader.read_record(false)? {
                Some(record) => reader.lookahead.push_back(record),
                None => break,
            }
        }
        reader.settle_nominal_dt(options.nominal_dt)?;
        if options.check_layout {
            reader.check_layout()?;
        }
        reader.gaps.threshold_s = GAP_FACTOR * reader.nominal_dt;
        Ok(reader)
    }

    /// Reads up to the first content line, decides the format and the columns (reading
    /// a CSV header, or skipping it for [`ImuReadOptions::columns`]); whether that line
    /// is data.
    fn read_first_line(&mut self, options: &ImuReadOptions) -> Result<bool, InputError> {
        loop {
            if !self.next_line()? {
                return Err(self.error(InputErrorKind::NoData, 0, None, "holds no IMU samples"));
            }
            if !is_skippable(self.lines.line()) {
                break;
            }
        }
        if self.format == ImuFormat::Auto {
            let line = self.lines.line();
            let start = skip_blanks(line, 0);
            // A non-finite number is still a number: a text file, with a bad line 1.
            let not_a_number = matches!(
                parse_number(line, start, 0),
                Err(FieldError::NotANumber { .. })
            );
            self.format = if not_a_number {
                self.csv_auto_detected = true;
                ImuFormat::Csv
            } else {
                ImuFormat::KfGinsText
            };
        }
        let headed = self.format == ImuFormat::Csv;
        // A header without commas or semicolons names blank-separated columns: the
        // rows are then read as text.
        let delim = header_delimiter(self.lines.line());
        let csv = headed && delim.is_some();
        let declared = options.declared();
        let (plan, names, trailing) = match (&options.columns, headed) {
            (Some(spec), _) => {
                let names = spec.names().to_vec();
                // Whatever is wrong is in the options, not in the file.
                let plan = plan(&names, spec.columns(), &declared, "--imu-columns").map_err(|e| {
                    PlanError {
                        in_header: false,
                        ..e
                    }
                });
                (plan, names, spec.trailing())
            }
            (None, true) => {
                let names = header_names(self.lines.line(), delim);
                let cols = names
                    .iter()
                    .map(|n| recognise(n))
                    .collect::<Result<Vec<_>, _>>()
                    .map_err(|m| self.plan_error(PlanError::header(None, m)))?;
                let plan = plan(&names, &cols, &declared, "the header");
                (plan, names, false)
            }
            (None, false) => {
                let plan = default_plan(&declared);
                let names = Vec::new();
                (plan, names, false)
            }
        };
        let plan = plan.map_err(|e| self.plan_error(e))?;
        let delim = if csv { delim } else { None };
        self.apply_plan(&plan, options, delim, names, trailing);
        Ok(!headed)
    }

    /// Takes `plan` with the columns' `names` (empty: KF-GINS's), the rows separated
    /// by `delim` (CSV) or as text (none).
    fn apply_plan(
        &mut self,
        plan: &Plan,
        options: &ImuReadOptions,
        delim: Option<u8>,
        names: Vec<String>,
        trailing: bool,
    ) {
        self.layout = plan.layout;
        self.to_si = (plan.gyro.to_si(), plan.accel.to_si());
        self.clock = (plan.time, options.time_offset);
        self.columns = if names.is_empty() {
            Columns::kf_gins(plan.layout)
        } else {
            Columns {
                csv: delim.is_some(),
                delim: delim.unwrap_or(b','),
                slot_of_col: plan.slot_of_col.clone(),
                names,
                time_col: plan.time_col,
                trailing,
                mapped: true,
            }
        };
        self.plan = plan.clone();
    }

    /// The format read (never [`ImuFormat::Auto`]).
    pub fn format(&self) -> ImuFormat {
        self.format
    }

    /// The layout read.
    pub fn layout(&self) -> ImuLayout {
        self.layout
    }

    /// The nominal sample interval [s], given or estimated.
    pub fn nominal_dt(&self) -> f64 {
        self.nominal_dt
    }

    /// Gaps met so far (see [`GapReport`]); complete once the iteration has ended.
    pub fn gaps(&self) -> GapReport {
        self.gaps
    }

    /// Bytes consumed from the input so far (including the lookahead).
    pub fn bytes_read(&self) -> u64 {
        self.lines.at().bytes
    }

    /// A handle on the byte count that outlives borrows of the reader.
    pub fn progress(&self) -> ProgressCounter {
        ProgressCounter(std::sync::Arc::clone(&self.lines.at().progress))
    }

    fn error(
        &self,
        kind: InputErrorKind,
        line: u64,
        field: Option<&str>,
        message: impl Into<String>,
    ) -> InputError {
        InputError::new(kind, &self.path, line, field, message)
    }

    /// The error of a plan: at the header's line if the header is at fault, else of
    /// the options (line 0).
    fn plan_error(&self, e: PlanError) -> InputError {
        if !e.in_header {
            return self.error(InputErrorKind::Usage, 0, e.field.as_deref(), e.message);
        }
        let detected = if self.csv_auto_detected && e.message.contains("lacks") {
            "; this line was taken for a CSV header because its first field is not a number"
        } else {
            ""
        };
        self.error(
            InputErrorKind::Header,
            self.lines.at().line_no,
            e.field.as_deref(),
            format!("{}{detected}", e.message),
        )
    }

    /// Advances to the next line; `Ok(false)` at the end.
    fn next_line(&mut self) -> Result<bool, InputError> {
        match self.lines.next_line() {
            Ok(more) => Ok(more),
            Err(LineReadError::Io(e)) => Err(self.error(
                InputErrorKind::Io,
                self.lines.at().line_no + 1,
                None,
                format!("read failed: {e}"),
            )),
            Err(LineReadError::TooLong) => Err(self.error(
                InputErrorKind::LineTooLong,
                self.lines.at().line_no,
                None,
                format!("line longer than {MAX_LINE_BYTES} bytes (is this a text IMU log?)"),
            )),
        }
    }

    /// Name of column `col` (0-based) for messages.
    fn column_name(&self, col: usize) -> &str {
        &self.columns.names[col]
    }

    /// Name of the time column.
    fn time_name(&self) -> &str {
        self.column_name(self.columns.time_col)
    }

    #[cold]
    fn field_error(&self, e: FieldError) -> InputError {
        let line_no = self.lines.at().line_no;
        let line = self.lines.line();
        let expected = self.columns.slot_of_col.len();
        match e {
            FieldError::Columns { found } => self.error(
                InputErrorKind::ColumnCount,
                line_no,
                None,
                if self.columns.trailing {
                    format!("expected at least {expected} columns, found {found}")
                } else {
                    format!("expected {expected} columns, found {found}")
                },
            ),
            FieldError::Empty { col } => self.error(
                InputErrorKind::NotANumber,
                line_no,
                Some(self.column_name(col)),
                "empty field",
            ),
            FieldError::NotANumber { col, start, end } => self.error(
                InputErrorKind::NotANumber,
                line_no,
                Some(self.column_name(col)),
                format!("not a number: {}", quote_field(&line[start..end])),
            ),
            FieldError::NotFinite { col, start, end } => self.error(
                InputErrorKind::NotFinite,
                line_no,
                Some(self.column_name(col)),
                format!("not finite: {}", quote_field(&line[start..end])),
            ),
        }
    }

    /// Parses the current line's time (`time_only`) or all its columns into `out`;
    /// returns the time on the reader's clock.
    #[inline]
    fn parse_fields(&self, time_only: bool, out: &mut [f64; 7]) -> Result<f64, FieldError> {
        let line = self.lines.line();
        // Parsed ahead (all the fields, so the time too), else here.
        let span = match self.lines.parsed() {
            Some(p) => {
                *out = p.values;
                p.time_span
            }
            None => self.columns.parse(line, time_only, out)?,
        };
        match self.clock {
            (TimeUnit::S, 0.0) => Ok(out[0]),
            (unit, offset) => Ok(stamp_seconds(&line[span.0..span.1], out[0], unit, offset)),
        }
    }

    /// Parses the current line (a data line) into a record and checks its time
    /// against the previous one. With `time_only`, only the time is parsed unless
    /// it reaches `t_start`.
    #[inline]
    fn parse_current(&mut self, time_only: bool) -> Result<Record, InputError> {
        let mut out = [0.0; 7];
        let parsed = match self.parse_fields(time_only, &mut out) {
            Ok(t) if time_only && self.t_start.is_some_and(|s| t >= s) => {
                self.parse_fields(false, &mut out)
            }
            other => other,
        };
        let t = match parsed {
            Ok(t) => t,
            Err(e) => return Err(self.field_error(e)),
        };
        let line_no = self.lines.at().line_no;
        if let Some((t_prev, line_prev)) = self.last
            && t <= t_prev
        {
            let what = if t == t_prev {
                format!("time repeats: t = {t} also at line {line_prev}")
            } else {
                format!("time goes backwards: t = {t} after t = {t_prev} at line {line_prev}")
            };
            return Err(self.error(
                InputErrorKind::TimeNotIncreasing,
                line_no,
                Some(self.time_name()),
                what,
            ));
        }
        if self.last.is_none() {
            self.first_data_line = line_no;
        }
        self.last = Some((t, line_no));
        Ok(Record {
            t,
            v: [out[1], out[2], out[3], out[4], out[5], out[6]],
            line: line_no,
        })
    }

    /// Reads up to the next data line and parses it; `Ok(None)` at the end.
    #[inline]
    fn read_record(&mut self, time_only: bool) -> Result<Option<Record>, InputError> {
        loop {
            if !self.next_line()? {
                return Ok(None);
            }
            if is_skippable(self.lines.line()) {
                continue;
            }
            return self.parse_current(time_only).map(Some);
        }
    }

    /// Intervals between the lookahead samples [s] (all > 0 by the monotonic check).
    fn lookahead_intervals(&self) -> Vec<f64> {
        self.lookahead
            .iter()
            .zip(self.lookahead.iter().skip(1))
            .map(|(a, b)| b.t - a.t)
            .collect()
    }

    fn settle_nominal_dt(&mut self, given: Option<f64>) -> Result<(), InputError> {
        if let Some(dt) = given {
            self.nominal_dt = dt;
            return Ok(());
        }
        let mut intervals = self.lookahead_intervals();
        match median(&mut intervals) {
            Some(dt) => {
                self.nominal_dt = dt;
                Ok(())
            }
            None => Err(self.error(
                InputErrorKind::Usage,
                0,
                None,
                "only one sample: cannot estimate the sample interval; give it explicitly \
                 (nominal_dt, e.g. --imu-rate)",
            )),
        }
    }

    /// Rejects a log whose first samples no sensor on the Earth reads, naming the check
    /// and the flags that probably read it right ([`super::imu_plausibility`]). Needs
    /// [`LAYOUT_CHECK_MIN_INTERVALS`].
    fn check_layout(&self) -> Result<(), InputError> {
        if self.lookahead.len() <= LAYOUT_CHECK_MIN_INTERVALS {
            return Ok(());
        }
        let ticks = self.clock.0.ticks_per_second() as f64;
        let readings: Vec<Reading> = self
            .lookahead
            .iter()
            .zip(self.lookahead.iter().skip(1))
            .map(|(a, b)| Reading {
                // In the declared unit (× 1 for seconds): the check tries others.
                dt: (b.t - a.t) * ticks,
                gyro: Vector3::new(b.v[0], b.v[1], b.v[2]),
                accel: Vector3::new(b.v[3], b.v[4], b.v[5]),
            })
            .collect();
        let Err(finding) =
            super::imu_plausibility::check(&readings, &self.plan, self.columns.trailing)
        else {
            return Ok(());
        };
        let first_line = self.first_data_line;
        let last_line = self.last.map_or(first_line, |(_, line)| line);
        Err(self.error(
            InputErrorKind::LayoutMismatch,
            first_line,
            Some(&self.sensor_field(finding.sensor)),
            format!("lines {first_line}-{last_line} {}", finding.message),
        ))
    }

    /// Checks a sample of line `line` against the physical domains: its interval (the
    /// nominal one for the first sample, which the fuzz found could be 5e307 s), its
    /// angular rate and its specific force.
    #[inline]
    fn check_domain(&self, s: &ImuSample, line: u64) -> Result<(), InputError> {
        let checks = [
            (Sensor::Time, &domain::IMU_INTERVAL, s.dt),
            (Sensor::Gyro, &domain::ANGULAR_RATE, s.dtheta.norm() / s.dt),
            (Sensor::Accel, &domain::SPECIFIC_FORCE, s.dvel.norm() / s.dt),
        ];
        for (sensor, d, value) in checks {
            if let Err(e) = d.check(value) {
                return Err(self.domain_error(sensor, line, e));
            }
        }
        Ok(())
    }

    #[cold]
    fn domain_error(&self, sensor: Sensor, line: u64, e: domain::DomainError) -> InputError {
        let what = match sensor {
            Sensor::Time => format!("the time jumps: {e}"),
            _ => e.to_string(),
        };
        self.error(
            InputErrorKind::OutOfDomain,
            line,
            Some(&self.sensor_field(sensor)),
            what,
        )
    }

    /// The columns of a sensor, for messages: `dvel (columns 5-7)` in text, the names in
    /// CSV.
    fn sensor_field(&self, sensor: Sensor) -> String {
        let (slots, prefix) = match (sensor, self.layout) {
            (Sensor::Time, _) => return self.time_name().to_owned(),
            (Sensor::Gyro, ImuLayout::Increments) => (1..=3, "dtheta"),
            (Sensor::Gyro, ImuLayout::Rates) => (1..=3, "w"),
            (Sensor::Accel, ImuLayout::Increments) => (4..=6, "dvel"),
            (Sensor::Accel, ImuLayout::Rates) => (4..=6, "f"),
        };
        let cols: Vec<usize> = (0..self.columns.slot_of_col.len())
            .filter(|&i| slots.contains(&self.columns.slot_of_col[i]))
            .collect();
        if self.columns.csv {
            let names: Vec<&str> = cols.iter().map(|&i| self.column_name(i)).collect();
            return names.join(", ");
        }
        match cols[..] {
            [a, b, c] if b == a + 1 && c == a + 2 => {
                format!("{prefix} (columns {}-{})", a + 1, c + 1)
            }
            _ => {
                let numbers: Vec<String> = cols.iter().map(|i| (i + 1).to_string()).collect();
                format!("{prefix} (columns {})", numbers.join(", "))
            }
        }
    }
}

/// Validates the caller's options.
fn check_options(path: &Path, o: &ImuReadOptions) -> Result<(), InputError> {
    let bad = |field: &str, message: String| {
        Err(InputError::new(
            InputErrorKind::Usage,
            path,
            0,
            Some(field),
            message,
        ))
    };
    if let Some(dt) = o.nominal_dt
        && !(dt.is_finite() && dt > 0.0)
    {
        return bad(
            "nominal_dt",
            format!("nominal sample interval must be > 0 s, got {dt}"),
        );
    }
    for (name, t) in [
        ("t_start", o.t_start),
        ("t_end", o.t_end),
        ("time_offset", Some(o.time_offset)),
    ] {
        if let Some(t) = t
            && !t.is_finite()
        {
            return bad(name, format!("must be finite, got {t}"));
        }
    }
    if let (Some(s), Some(e)) = (o.t_start, o.t_end)
        && s > e
    {
        return bad("t_start", format!("window start {s} is after its end {e}"));
    }
    if let Some(c) = &o.c_vs
        && !((c.transpose() * c - Matrix3::identity()).amax() < 1e-9 && c.determinant() > 0.0)
    {
        return bad("c_vs", format!("not a rotation: {c}"));
    }
    Ok(())
}

impl<R: Read> std::iter::FusedIterator for ImuReader<R> {}

impl<R: Read> Iterator for ImuReader<R> {
    type Item = Result<ImuSample, InputError>;

    #[inline]
    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if self.finished {
                return None;
            }
            let record = match self.lookahead.pop_front() {
                Some(record) => record,
                None => match self.read_record(!self.reached_start) {
                    Ok(Some(record)) => record,
                    Ok(None) => {
                        self.finished = true;
                        return None;
                    }
                    Err(e) => {
                        self.finished = true;
                        return Some(Err(e));
                    }
                },
            };
            let t = record.t;
            let had_prev = self.prev_t.is_some();
            let dt = self.prev_t.map_or(self.nominal_dt, |t_prev| t - t_prev);
            self.prev_t = Some(t);
            if !self.reached_start {
                if self.t_start.is_some_and(|s| t < s) {
                    continue;
                }
                self.reached_start = true;
            }
            if self.t_end.is_some_and(|e| t > e) {
                self.finished = true;
                return None;
            }
            if had_prev && dt > self.gaps.threshold_s {
                self.gaps.record(t, dt);
            }
            // SI factors times dt for rates; exactly 1 for SI increments.
            let per = match self.layout {
                ImuLayout::Increments => 1.0,
                ImuLayout::Rates => dt,
            };
            let v = record.v;
            let sample = ImuSample {
                t,
                dt,
                dtheta: Vector3::new(v[0], v[1], v[2]) * (self.to_si.0 * per),
                dvel: Vector3::new(v[3], v[4], v[5]) * (self.to_si.1 * per),
            };
            if let Err(e) = self.check_domain(&sample, record.line) {
                self.finished = true;
                return Some(Err(e));
            }
            return Some(Ok(match &self.c_vs {
                Some(c_vs) => sample.rotated(c_vs),
                None => sample,
            }));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::fmt::Write as _;

    const PATH: &str = "IMU.txt";

    fn reader<'a>(
        input: &'a str,
        options: &ImuReadOptions,
    ) -> Result<ImuReader<&'a [u8]>, InputError> {
        ImuReader::new(input.as_bytes(), PATH, options)
    }

    /// All samples, or the first error whether from construction or iteration.
    fn read_all(input: &str, options: &ImuReadOptions) -> Result<Vec<ImuSample>, InputError> {
        reader(input, options)?.collect()
    }

    fn read_err(input: &str, options: &ImuReadOptions) -> InputError {
        match read_all(input, options) {
            Ok(samples) => panic!("expected an error, read {} samples", samples.len()),
            Err(e) => e,
        }
    }

    fn text() -> ImuReadOptions {
        ImuReadOptions {
            format: ImuFormat::KfGinsText,
            ..ImuReadOptions::default()
        }
    }

    /// A KF-GINS text log of `n` stationary samples at `rate_hz`, starting at `t0`,
    /// with z-down specific force `-g` written as increments (`-g dt`) or rates (`-g`).
    fn stationary_text(n: usize, rate_hz: f64, t0: f64, layout: ImuLayout) -> String {
        let dt = 1.0 / rate_hz;
        let mut s = String::new();
        for i in 0..n {
            let t = t0 + i as f64 * dt;
            let k = match layout {
                ImuLayout::Increments => dt,
                ImuLayout::Rates => 1.0,
            };
            let w = 7.292115e-5 * k;
            let fz = -9.8 * k;
            // Small deterministic wobble, as a real sensor would show.
            let wob = 1e-3 * k * ((i % 7) as f64 - 3.0);
            writeln!(
                s,
                "{t:.6} {w:e} {:e} {:e} {wob:e} {:e} {fz:e}",
                -w,
                0.5 * w,
                -wob
            )
            .expect("writing to a String cannot fail");
        }
        s
    }

    /// What a reader yields: each sample's bits, or the error's text.
    fn transcript<R: Read>(
        reader: Result<ImuReader<R>, InputError>,
    ) -> Vec<Result<[u64; 8], String>> {
        let reader = match reader {
            Ok(r) => r,
            Err(e) => return vec![Err(e.to_string())],
        };
        reader
            .map(|s| {
                s.map(|s| {
                    let (a, b) = (s.dtheta, s.dvel);
                    [s.t, s.dt, a.x, a.y, a.z, b.x, b.y, b.z].map(f64::to_bits)
                })
                .map_err(|e| e.to_string())
            })
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// Read ahead ([`ImuReader::read_ahead`]), a log gives the samples and the error
        /// it gives read here, bit for bit and at the same line: 2,000 to 5,000 lines
        /// (several blocks) of KF-GINS text or CSV, in seconds or milliseconds, with a
        /// window, and one line spoilt (a comment, a bad or missing field, a time going
        /// back, a blank line, an overlong field) anywhere after the first samples.
        #[test]
        fn read_ahead_yields_what_is_read_here(
            n in 2_000usize..5_000,
            csv in any::<bool>(),
            millis in any::<bool>(),
            window in any::<bool>(),
            spoil_at in 300usize..5_000,
            spoil in 0usize..7,
        ) {
            let body = stationary_text(n, 200.0, 10.0, ImuLayout::Increments);
            let mut lines: Vec<String> = body.lines().map(str::to_owned).collect();
            if let Some(line) = lines.get_mut(spoil_at) {
                *line = match spoil {
                    0 => format!("# {line}"),
                    1 => line.replacen(' ', " x", 2),
                    2 => line.rsplit_once(' ').map_or("", |x| x.0).to_owned(),
                    3 => line.replacen("1", "0", 1),
                    4 => String::new(),
                    5 => format!("{line} {}", "9".repeat(400)),
                    _ => line.clone(),
                };
            }
            let mut text = String::new();
            if csv {
                text.push_str("t,wx,wy,wz,fx,fy,fz\n");
            }
            for line in &lines {
                let line = if csv { line.replace(' ', ",") } else { line.clone() };
                let line = if millis {
                    let sep = if csv { ',' } else { ' ' };
                    match line.split_once(sep).map(|(t, rest)| (t.parse::<f64>(), rest)) {
                        Some((Ok(t), rest)) => format!("{:.3}{sep}{rest}", t * 1e3),
                        _ => line.clone(),
                    }
                } else {
                    line
                };
                text.push_str(&line);
                text.push('\n');
            }
            let options = ImuReadOptions {
                format: if csv { ImuFormat::Csv } else { ImuFormat::KfGinsText },
                time_unit: millis.then_some(TimeUnit::Ms),
                t_start: window.then_some(12.0),
                t_end: window.then_some(28.0),
                ..ImuReadOptions::default()
            };
            let here = || ImuReader::new(std::io::Cursor::new(text.clone().into_bytes()), PATH, &options);
            let ahead = here().map(|r| r.read_ahead().expect("helper thread"));
            prop_assert_eq!(transcript(ahead), transcript(here()));
        }
    }

    #[test]
    fn good_text_file_parses_to_exact_values() {
        let input = "# KF-GINS IMU file\n\
                     % matlab-style comment\n\
                     \n\
                     456789.000 0.001 -0.002 3e-4 0.0049 -0.0051 -0.049\r\n\
                     456789.005\t0.0011\t-0.0021  3.1e-4\t\t0.00491 -0.00511 -0.0491\n\
                     \x20 456789.010 0.1 0.2 0.3 4 5 6   \n";
        let samples = read_all(input, &text()).expect("good file");
        assert_eq!(samples.len(), 3);
        let s = &samples[1];
        assert_eq!(s.t, 456789.005);
        assert_eq!(s.dt, 456789.005 - 456789.000);
        assert_eq!(s.dtheta, Vector3::new(0.0011, -0.0021, 3.1e-4));
        assert_eq!(s.dvel, Vector3::new(0.00491, -0.00511, -0.0491));
        assert_eq!(samples[2].dvel, Vector3::new(4.0, 5.0, 6.0));
        // First sample: no predecessor, dt = nominal (median of the two intervals).
        let r = reader(input, &text()).expect("good file");
        let nominal = r.nominal_dt();
        assert_eq!(
            nominal,
            0.5 * ((456789.005 - 456789.0) + (456789.010 - 456789.005))
        );
        assert_eq!(samples[0].dt, nominal);
        assert_eq!(samples[0].dtheta, Vector3::new(0.001, -0.002, 3e-4));
    }

    #[test]
    fn comma_and_blank_separators_read_alike() {
        let blanks = "1.0 0.1 0.2 0.3 0.4 0.5 0.6\n1.5\t0.1 0.2\t 0.3 0.4 0.5 0.6\n";
        let commas = "1.0,0.1,0.2,0.3,0.4,0.5,0.6\n1.5, 0.1 ,0.2,\t0.3,0.4,0.5,0.6,\n";
        let a = read_all(blanks, &text()).expect("blanks");
        let b = read_all(commas, &text()).expect("commas");
        assert_eq!(a, b);
        assert_eq!(a[1].dvel, Vector3::new(0.4, 0.5, 0.6));
        let semicolons = "1.0;0.1;0.2;0.3;0.4;0.5;0.6\n1.5 ; 0.1;0.2;0.3;0.4;0.5;0.6;\n";
        assert_eq!(read_all(semicolons, &text()).expect("semicolons"), a);
    }

    /// Issue 21's reproducers: one row with a huge finite increment, or a clock jump of
    /// 1e9 s, used to be integrated into NaN or a position 1e36 m away; each is refused
    /// naming its line and columns.
    #[test]
    fn out_of_domain_rows_are_refused_by_line() {
        let opts = text();
        let good = stationary_text(40, 200.0, 100.0, ImuLayout::Increments);
        // The log with field `col` of data rows `rows` replaced by `f(old value)`.
        let edit = |rows: std::ops::RangeFrom<usize>, col: usize, f: &dyn Fn(f64) -> f64| {
            let mut out = String::new();
            for (i, line) in good.lines().enumerate() {
                let mut v: Vec<f64> = line
                    .split_whitespace()
                    .map(|x| x.parse().expect("number"))
                    .collect();
                if rows.contains(&i) {
                    v[col] = f(v[col]);
                }
                let v: Vec<String> = v.iter().map(f64::to_string).collect();
                writeln!(out, "{}", v.join(" ")).expect("writing to a String cannot fail");
            }
            out
        };
        let kind = InputErrorKind::OutOfDomain;
        let e = read_err(&edit(30.., 1, &|_| 1e6), &opts);
        assert_err(&e, 31, Some("dtheta (columns 2-4)"), kind, "angular rate");
        let e = read_err(&edit(30.., 4, &|_| 1e20), &opts);
        assert_err(&e, 31, Some("dvel (columns 5-7)"), kind, "specific force");
        let e = read_err(&edit(30.., 0, &|t| t + 1e9), &opts);
        assert_err(&e, 31, Some("t"), kind, "the time jumps");
        // The fuzz's find: a first stamp of -1e308 made the nominal interval (the
        // first sample's) 5e307 s, which was not checked.
        let e = read_err(
            "-1e308 0 0 0 0 0 -0.098\n0.02 0 0 0 0 0 -0.098\n0.03 0 0 0 0 0 -0.098\n",
            &opts,
        );
        assert_err(&e, 1, Some("t"), kind, "IMU sample interval");
    }

    /// The same two samples under a header delimited by commas, by semicolons, and by
    /// blanks read alike; a decimal comma under a semicolon header is refused by name.
    #[test]
    fn header_delimiters_read_alike() {
        let rows = |sep: &str| {
            let header = [
                "t", "dvel_x", "dvel_y", "dvel_z", "dtheta_x", "dtheta_y", "dtheta_z",
            ];
            let r1 = ["1.0", "0.4", "0.5", "0.6", "0.1", "0.2", "0.3"];
            let r2 = ["1.5", "0.4", "0.5", "0.6", "0.1", "0.2", "0.3"];
            [header, r1, r2].map(|r| r.join(sep)).join("\n")
        };
        let opts = ImuReadOptions::default();
        let commas = read_all(&rows(","), &opts).expect("commas");
        assert_eq!(commas[1].dtheta, Vector3::new(0.1, 0.2, 0.3));
        assert_eq!(commas[1].dvel, Vector3::new(0.4, 0.5, 0.6));
        assert_eq!(read_all(&rows(";"), &opts).expect("semicolons"), commas);
        assert_eq!(read_all(&rows(" \t "), &opts).expect("blanks"), commas);
        let decimal_comma = rows(";").replace("0.5", "0,5");
        let e = read_err(&decimal_comma, &opts);
        assert_err(&e, 2, Some("dvel_y"), InputErrorKind::NotANumber, "\"0,5\"");
    }

    #[test]
    fn auto_detects_text_and_csv() {
        let t = reader(
            "# c\n1 0 0 0 0 0 0\n2 0 0 0 0 0 0\n",
            &ImuReadOptions::default(),
        )
        .expect("text");
        assert_eq!(t.format(), ImuFormat::KfGinsText);
        let c = reader(
            "t,dtheta_x,dtheta_y,dtheta_z,dvel_x,dvel_y,dvel_z\n1,0,0,0,0,0,0\n2,0,0,0,0,0,0\n",
            &ImuReadOptions::default(),
        )
        .expect("csv");
        assert_eq!(c.format(), ImuFormat::Csv);
        assert_eq!(c.layout(), ImuLayout::Increments);
    }

    fn assert_err(e: &InputError, line: u64, field: Option<&str>, kind: InputErrorKind, msg: &str) {
        assert_eq!(
            (e.line, e.field.as_deref(), e.kind),
            (line, field, kind),
            "{e}"
        );
        assert!(e.message.contains(msg), "{e}");
        assert_eq!(e.path, Path::new(PATH));
    }

    /// Two good lines under a comment: a bad third data line is line 4.
    const GOOD_HEAD: &str = "# header\n1 0 0 0 0 0 0\n2 0 0 0 0 0 0\n";

    /// Each kind of bad text line, after [`GOOD_HEAD`], names line 4, its field and
    /// what is wrong.
    #[test]
    fn bad_text_lines_name_line_and_field() {
        use InputErrorKind::{ColumnCount, NotANumber, NotFinite, TimeNotIncreasing};
        let cases: [(&str, Option<&str>, InputErrorKind, &str); 10] = [
            (
                "3 0 0 0 0",
                None,
                ColumnCount,
                "expected 7 columns, found 5",
            ),
            ("3 0 0 0 0 0 0 9", None, ColumnCount, "found 8"),
            ("3 0 0 0 0 abc 0", Some("dvel_y"), NotANumber, "\"abc\""),
            ("3 0 0 0 0 1.2.3 0", Some("dvel_y"), NotANumber, "\"1.2.3\""),
            ("3,0,,0,0,0,0", Some("dtheta_y"), NotANumber, "empty field"),
            ("3 0 0 NaN 0 0 0", Some("dtheta_z"), NotFinite, "\"NaN\""),
            ("3 0 0 0 -inf 0 0", Some("dvel_x"), NotFinite, "\"-inf\""),
            (
                "3 1e999 0 0 0 0 0",
                Some("dtheta_x"),
                NotFinite,
                "\"1e999\"",
            ),
            ("x3 0 0 0 0 0 0", Some("t"), NotANumber, "\"x3\""),
            (
                "1.5 0 0 0 0 0 0",
                Some("t"),
                TimeNotIncreasing,
                "t = 1.5 after t = 2 at line 3",
            ),
        ];
        for (bad, field, kind, msg) in cases {
            let input = format!("{GOOD_HEAD}{bad}\n5 0 0 0 0 0 0\n");
            let e = read_err(&input, &text());
            assert_err(&e, 4, field, kind, msg);
        }
    }

    /// A time repeated from the line before names that line; the whole message reads
    /// `file:line: field NAME: ...`.
    #[test]
    fn a_repeated_time_names_the_earlier_line_and_the_message_reads_whole() {
        let e = read_err(&format!("{GOOD_HEAD}2 0 0 0 0 0 0\n"), &text());
        assert_err(
            &e,
            4,
            Some("t"),
            InputErrorKind::TimeNotIncreasing,
            "t = 2 also at line 3",
        );
        let e = read_err(&format!("{GOOD_HEAD}3 0 0 0 0 abc 0\n"), &text());
        assert_eq!(
            e.to_string(),
            r#"IMU.txt:4: field dvel_y: not a number: "abc""#
        );
    }

    #[test]
    fn errors_after_the_lookahead_come_from_the_iterator() {
        let mut input = stationary_text(500, 200.0, 100.0, ImuLayout::Increments);
        input.push_str("103 0 0 0 0 0\n");
        let mut r = reader(&input, &text()).expect("first 201 lines are good");
        let mut n = 0;
        let e = loop {
            match r.next() {
                Some(Ok(_)) => n += 1,
                Some(Err(e)) => break e,
                None => panic!("no error"),
            }
        };
        assert_eq!(n, 500);
        assert_err(
            &e,
            501,
            None,
            InputErrorKind::ColumnCount,
            "expected 7 columns, found 6",
        );
        assert!(r.next().is_none(), "the first error ends the iteration");
    }

    #[test]
    fn auto_detection_explains_itself() {
        let e = read_err("nan 0 0 0 0 0 0\n", &ImuReadOptions::default());
        assert_err(&e, 1, Some("t"), InputErrorKind::NotFinite, "\"nan\"");
        let e = read_err("# c\nabc 0 0 0 0 0 0\n", &ImuReadOptions::default());
        assert_err(
            &e,
            2,
            None,
            InputErrorKind::Header,
            "first field is not a number",
        );
    }

    #[test]
    fn empty_and_single_sample_files() {
        let e = read_err("# nothing\n\n", &text());
        assert_eq!(e.kind, InputErrorKind::NoData);
        let e = read_err("1 0 0 0 0 0 0\n", &text());
        assert_eq!(e.kind, InputErrorKind::Usage);
        let one = ImuReadOptions {
            nominal_dt: Some(0.01),
            ..text()
        };
        let s = read_all("1 0 0 0 0 0 0\n", &one).expect("nominal given");
        assert_eq!(s[0].dt, 0.01);
        let bad = ImuReadOptions {
            nominal_dt: Some(-1.0),
            ..text()
        };
        assert_eq!(
            read_err("1 0 0 0 0 0 0\n", &bad).field.as_deref(),
            Some("nominal_dt")
        );
    }

    #[test]
    fn gaps_are_counted_not_errors() {
        let mut input = String::new();
        let mut t = 10.0;
        for i in 0..400 {
            t += match i {
                100 => 0.05,
                250 => 0.021,
                300 => 0.02, // exactly 2 nominal intervals: not a gap
                _ => 0.01,
            };
            writeln!(input, "{t:.3} 0 0 0 0 0 -0.098").expect("String");
        }
        let options = ImuReadOptions {
            nominal_dt: Some(0.01),
            ..text()
        };
        let mut r = reader(&input, &options).expect("good");
        let samples: Vec<_> = r
            .by_ref()
            .collect::<Result<_, _>>()
            .expect("gaps are no error");
        assert_eq!(samples.len(), 400);
        assert!((samples[100].dt - 0.05).abs() < 1e-9, "true dt kept");
        let gaps = r.gaps();
        assert_eq!(gaps.count, 2);
        assert!((gaps.longest_s - 0.05).abs() < 1e-9);
        assert_eq!(gaps.longest_at_t, Some(samples[100].t));
        assert_eq!(gaps.first_at_t, Some(samples[100].t));
        assert_eq!(gaps.threshold_s, 0.02);
        assert!(
            gaps.to_string().starts_with("2 gap(s) longer than 0.02 s"),
            "{gaps}"
        );
        assert_eq!(r.bytes_read(), input.len() as u64);
    }

    #[test]
    fn rates_in_an_increment_file_are_detected() {
        let rates = stationary_text(300, 200.0, 1000.0, ImuLayout::Rates);
        let e = read_err(&rates, &text());
        assert_eq!(e.kind, InputErrorKind::LayoutMismatch, "{e}");
        assert_eq!(e.line, 1);
        assert_eq!(e.field.as_deref(), Some("dvel (columns 5-7)"));
        assert!(
            e.message
                .contains("lines 1-201 look like rates, not increments"),
            "{e}"
        );
        assert!(e.message.contains("--imu-layout rates"), "{e}");
        // Read as declared rates, the same file is fine and converts to increments.
        let as_rates = ImuReadOptions {
            layout: Some(ImuLayout::Rates),
            ..text()
        };
        let s = read_all(&rates, &as_rates).expect("rates");
        assert!((s[10].dvel.z - (-9.8 * s[10].dt)).abs() < 1e-12);
        // The check can be turned off.
        let unchecked = ImuReadOptions {
            check_layout: false,
            ..text()
        };
        assert!(read_all(&rates, &unchecked).is_ok());
    }

    #[test]
    fn increments_declared_as_rates_are_detected() {
        let increments = stationary_text(300, 200.0, 1000.0, ImuLayout::Increments);
        assert!(read_all(&increments, &text()).is_ok());
        let as_rates = ImuReadOptions {
            layout: Some(ImuLayout::Rates),
            ..text()
        };
        let e = read_err(&increments, &as_rates);
        assert_eq!(e.kind, InputErrorKind::LayoutMismatch, "{e}");
        assert_eq!(e.field.as_deref(), Some("f (columns 5-7)"));
        assert!(e.message.contains("look like increments, not rates"), "{e}");
    }

    #[test]
    fn layout_check_is_silent_at_one_hertz() {
        // At dt = 1 s both readings agree: nothing to reject either way.
        let s = stationary_text(30, 1.0, 0.0, ImuLayout::Rates);
        assert!(read_all(&s, &text()).is_ok());
        let as_rates = ImuReadOptions {
            layout: Some(ImuLayout::Rates),
            ..text()
        };
        assert!(read_all(&s, &as_rates).is_ok());
    }

    #[test]
    fn csv_with_rates_converts_to_increments() {
        let input = "# our CSV\n\
                     f_z, label, \"TIME\" ,w_x,w_y,w_z,f_x,f_y\n\
                     -9.8,a,100.00,0.01,0.02,0.03,0.1,0.2\n\
                     -9.7,b,100.01,0.02,0.04,0.06,0.2,0.4\n\
                     -9.6,,100.03,0.03,0.06,0.09,0.3,0.6\n";
        let options = ImuReadOptions {
            format: ImuFormat::Csv,
            ..ImuReadOptions::default()
        };
        let r = reader(input, &options).expect("header has the rate set");
        assert_eq!(r.layout(), ImuLayout::Rates);
        let nominal = r.nominal_dt();
        let s: Vec<_> = r.collect::<Result<_, _>>().expect("good");
        assert_eq!(s.len(), 3);
        let dt = 100.01 - 100.00;
        assert_eq!(s[1].dt, dt);
        assert_eq!(s[1].dtheta, Vector3::new(0.02 * dt, 0.04 * dt, 0.06 * dt));
        assert_eq!(s[1].dvel, Vector3::new(0.2 * dt, 0.4 * dt, -9.7 * dt));
        assert_eq!(s[2].dt, 100.03 - 100.01);
        assert_eq!(s[0].dt, nominal);
        assert_eq!(s[0].dvel.z, -9.8 * nominal);
    }

    #[test]
    fn csv_with_increments_in_free_order() {
        let input = "dvel_z,dvel_y,dvel_x,dtheta_z,dtheta_y,dtheta_x,t,extra\n\
                     6,5,4,3,2,1,0.5,x\n\
                     6.5,5.5,4.5,3.5,2.5,1.5,1.0,y\n";
        let s = read_all(input, &ImuReadOptions::default()).expect("good");
        assert_eq!(s[1].t, 1.0);
        assert_eq!(s[1].dtheta, Vector3::new(1.5, 2.5, 3.5));
        assert_eq!(s[1].dvel, Vector3::new(4.5, 5.5, 6.5));
    }

    #[test]
    fn csv_errors_name_columns() {
        let e = read_err(
            "t,dtheta_x,dtheta_y,dtheta_z,dvel_x\n1,0,0,0,0\n",
            &ImuReadOptions::default(),
        );
        assert_err(
            &e,
            1,
            None,
            InputErrorKind::Header,
            "lacks column(s) dvel_y, dvel_z for increments",
        );
        let rates = ImuReadOptions {
            layout: Some(ImuLayout::Rates),
            ..ImuReadOptions::default()
        };
        let e = read_err("t,w_x,w_y,f_x,f_y,f_z\n", &rates);
        assert_err(
            &e,
            1,
            None,
            InputErrorKind::Header,
            "lacks column(s) w_z for rates",
        );
        let e = read_err(
            "t,w_x,w_y,w_z,f_x,f_y,f_z,w_y\n",
            &ImuReadOptions::default(),
        );
        assert_err(
            &e,
            1,
            Some("w_y"),
            InputErrorKind::Header,
            "columns 3 and 8",
        );
        let head = "time,w_x,w_y,w_z,f_x,f_y,f_z,note\n1,0,0,0,0,0,9.8,a\n2,0,0,0,0,0,9.8,b\n";
        let cases: [(&str, Option<&str>, InputErrorKind, &str); 6] = [
            (
                "3,0,0,0,0,0",
                None,
                InputErrorKind::ColumnCount,
                "expected 8 columns, found 6",
            ),
            (
                "3,0,0,0,0,0,9.8,c,d",
                None,
                InputErrorKind::ColumnCount,
                "found 9",
            ),
            (
                "3,0,0,0,0,9 8,9.8,c",
                Some("f_y"),
                InputErrorKind::NotANumber,
                "\"9 8\"",
            ),
            (
                "3,0,0,0,0, ,9.8,c",
                Some("f_y"),
                InputErrorKind::NotANumber,
                "empty field",
            ),
            (
                "3,0,0,0,0,0,inf,c",
                Some("f_z"),
                InputErrorKind::NotFinite,
                "\"inf\"",
            ),
            (
                "2,0,0,0,0,0,9.8,c",
                Some("time"),
                InputErrorKind::TimeNotIncreasing,
                "t = 2 also at line 3",
            ),
        ];
        for (bad, field, kind, msg) in cases {
            let e = read_err(&format!("{head}{bad}\n"), &ImuReadOptions::default());
            assert_err(&e, 4, field, kind, msg);
        }
    }

    #[test]
    fn csv_rates_declared_but_increments_written() {
        let mut input = String::from("t,w_x,w_y,w_z,f_x,f_y,f_z\n");
        for i in 0..100 {
            writeln!(input, "{},0,0,0,0,0,{}", f64::from(i) * 0.005, -9.8 * 0.005).expect("String");
        }
        let e = read_err(&input, &ImuReadOptions::default());
        assert_eq!(e.kind, InputErrorKind::LayoutMismatch);
        assert_eq!(e.field.as_deref(), Some("f_x, f_y, f_z"));
        assert!(e.message.contains("lines 2-101"), "{e}");
    }

    #[test]
    fn text_read_as_rates() {
        let input = "1.0 0.1 0.2 0.3 1 2 9\n1.5 0.1 0.2 0.3 1 2 9\n";
        let options = ImuReadOptions {
            layout: Some(ImuLayout::Rates),
            ..text()
        };
        let s = read_all(input, &options).expect("good");
        assert_eq!(s[1].dt, 0.5);
        assert_eq!(s[1].dtheta, Vector3::new(0.05, 0.1, 0.15));
        assert_eq!(s[1].dvel, Vector3::new(0.5, 1.0, 4.5));
        let e = read_err("1 0 0 0 0 0 0\n2 0 0 0 0 x 0\n", &options);
        assert_eq!(e.field.as_deref(), Some("f_y"));
    }

    #[test]
    fn time_window() {
        let mut input = stationary_text(1000, 100.0, 0.0, ImuLayout::Increments);
        // Past the lookahead and before the start: only the time is looked at.
        input = input.replacen("3.000000 ", "3.000000 garbage ", 1);
        let window = ImuReadOptions {
            t_start: Some(5.0),
            t_end: Some(7.0),
            ..text()
        };
        let mut r = reader(&input, &window).expect("good");
        let s: Vec<_> = r
            .by_ref()
            .collect::<Result<_, _>>()
            .expect("garbage skipped");
        assert_eq!(s.first().map(|s| s.t), Some(5.0));
        assert_eq!(s.last().map(|s| s.t), Some(7.0));
        assert_eq!(s.len(), 201);
        assert!(
            (s[0].dt - 0.01).abs() < 1e-12,
            "true dt from the skipped predecessor"
        );
        assert!(r.bytes_read() < input.len() as u64, "stops after t_end");
        // Time is still checked before the start.
        let backwards = input.replacen("4.000000 ", "3.500000 ", 1);
        let e = read_err(&backwards, &window);
        assert_err(
            &e,
            401,
            Some("t"),
            InputErrorKind::TimeNotIncreasing,
            "t = 3.5 after t = 3.99",
        );
        // A bad field inside the window is still an error.
        let bad = input.replacen("6.000000 ", "6.000000 x ", 1);
        assert_eq!(read_err(&bad, &window).line, 601);
        let empty = ImuReadOptions {
            t_start: Some(50.0),
            ..text()
        };
        assert_eq!(read_all(&input, &empty).map(|s| s.len()), Ok(0));
        let inverted = ImuReadOptions {
            t_start: Some(7.0),
            t_end: Some(5.0),
            ..text()
        };
        assert_eq!(read_err(&input, &inverted).kind, InputErrorKind::Usage);
    }

    #[test]
    fn csv_window_skips_by_time_column() {
        let mut input = String::from("x,t,dtheta_x,dtheta_y,dtheta_z,dvel_x,dvel_y,dvel_z\n");
        for i in 0..400 {
            let junk = if i == 300 { "junk" } else { "0" };
            writeln!(input, "a,{},{junk},0,0,0,0,-0.049", f64::from(i) * 0.005).expect("String");
        }
        let window = ImuReadOptions {
            t_start: Some(1.6),
            ..ImuReadOptions::default()
        };
        let s = read_all(&input, &window).expect("junk before the window is not parsed");
        assert_eq!(s.len(), 80);
        assert_eq!(s[0].t, 1.6);
    }

    /// A device's text file: accelerometer first in g, gyro in deg/s, a counter to
    /// skip, integer nanoseconds from 0 put on GPS time, and a last column ignored.
    #[test]
    fn text_in_another_order_with_units_and_clock() {
        let input = "7,0,0.5,-0.25,-1.0,10.0,-20.0,30.0,x\n\
                     8,5000000,0.5,-0.25,-1.0,10.0,-20.0,30.0,y\n\
                     9,10000000,0.5,-0.25,-1.0,10.0,-20.0,30.0,z\n";
        let options = ImuReadOptions {
            columns: Some(ColumnSpec::parse("_,t,fx,fy,fz,wx,wy,wz,...").expect("spec")),
            gyro_unit: Some(GyroUnit::DegPerSecond),
            accel_unit: Some(AccelUnit::G),
            time_unit: Some(TimeUnit::Ns),
            time_offset: 345600.0,
            check_layout: false,
            ..ImuReadOptions::default()
        };
        let r = reader(input, &options).expect("good");
        assert_eq!(
            (r.format(), r.layout()),
            (ImuFormat::KfGinsText, ImuLayout::Rates)
        );
        let s: Vec<_> = r.collect::<Result<_, _>>().expect("good");
        assert_eq!(s[1].t, 345600.005);
        assert_eq!(s[1].dt, 345600.005 - 345600.0);
        let dt = s[1].dt;
        let deg = std::f64::consts::PI / 180.0;
        assert_eq!(s[1].dtheta, Vector3::new(10.0, -20.0, 30.0) * (deg * dt));
        assert_eq!(
            s[1].dvel,
            Vector3::new(0.5, -0.25, -1.0) * (STANDARD_GRAVITY * dt)
        );
        // Errors name the spec's columns, and a short line is "at least".
        let bad = input.replace("8,5000000,0.5", "8,5000000,0.5x");
        assert_err(
            &read_err(&bad, &options),
            2,
            Some("fx"),
            InputErrorKind::NotANumber,
            "\"0.5x\"",
        );
        let short = input.replace(",y", "").replace(",30.0\n9", "\n9");
        assert_err(
            &read_err(&short, &options),
            2,
            None,
            InputErrorKind::ColumnCount,
            "expected at least 8 columns, found 7",
        );
    }

    /// A unit `--imu-columns` leaves open is the options' fault, not the file's.
    #[test]
    fn an_ambiguous_spec_is_a_usage_error() {
        let ambiguous = ImuReadOptions {
            columns: Some(ColumnSpec::parse("t,gx_deg,gy_deg,gz_deg,ax,ay,az").expect("spec")),
            ..text()
        };
        let e = read_err("1 0 0 0 0 0 0\n", &ambiguous);
        assert_err(
            &e,
            0,
            Some("gx_deg"),
            InputErrorKind::Usage,
            "give --gyro-unit deg or --gyro-unit deg/s",
        );
    }

    /// Nanoseconds since 1970 (19 digits, beyond f64's 2^53) keep their resolution
    /// when an offset brings them near zero.
    #[test]
    fn integer_stamps_are_exact() {
        assert_eq!(
            stamp_seconds(b"1730147509121814120", 1.73e18, TimeUnit::Ns, -1730147509.0),
            0.12181412
        );
        assert_eq!(stamp_seconds(b"-1500", -1500.0, TimeUnit::Ms, 0.0), -1.5);
        assert_eq!(stamp_seconds(b"12.5", 12.5, TimeUnit::Ms, 1.0), 1.0125);
        assert_eq!(stamp_seconds(b"12.5", 12.5, TimeUnit::S, 0.0), 12.5);
        assert_eq!(parse_integer(b"+12"), Some(12));
        assert_eq!(parse_integer(b"1e3"), None);
        assert_eq!(
            parse_integer(b"1234567890123456789"),
            Some(1234567890123456789)
        );
        assert_eq!(parse_integer(b"12345678901234567890"), None);
    }

    /// A CSV header of common names with units, in another order, and the header of a
    /// device the reader does not know, replaced by `--imu-columns`.
    #[test]
    fn csv_common_names_and_replaced_headers() {
        let input = "timestamp_ns,ax_g,ay_g,az_g,gx_dps,gy_dps,gz_dps,temp\n\
                     1000000000,0,0,-1,0,0,90,20\n\
                     1010000000,0,0,-1,0,0,90,20\n";
        let r = reader(input, &ImuReadOptions::default()).expect("recognised");
        assert_eq!(r.layout(), ImuLayout::Rates);
        let s: Vec<_> = r.collect::<Result<_, _>>().expect("good");
        assert_eq!(s[1].t, 1.01);
        assert!((s[1].dtheta.z - 90f64.to_radians() * s[1].dt).abs() < 1e-15);
        assert_eq!(s[1].dvel.z, -STANDARD_GRAVITY * s[1].dt);
        let unknown = "state,stamp,scaledAccelX,scaledAccelY,scaledAccelZ,scaledGyroX,scaledGyroY,scaledGyroZ\n\
                       S,1000000000,0,0,-1,0,0,0.1\n\
                       S,1010000000,0,0,-1,0,0,0.1\n";
        let e = read_err(unknown, &ImuReadOptions::default());
        assert_err(
            &e,
            1,
            None,
            InputErrorKind::Header,
            "recognised: time t, time, timestamp",
        );
        assert!(e.message.contains("--imu-columns"), "{e}");
        let named = ImuReadOptions {
            columns: Some(ColumnSpec::parse("_,t,fx,fy,fz,wx,wy,wz").expect("spec")),
            accel_unit: Some(AccelUnit::G),
            time_unit: Some(TimeUnit::Ns),
            ..ImuReadOptions::default()
        };
        let s = read_all(unknown, &named).expect("header skipped");
        assert_eq!((s.len(), s[1].t), (2, 1.01));
        assert_eq!(s[1].dtheta.z, 0.1 * s[1].dt);
        // Options that contradict each other or the header.
        let contradiction = ImuReadOptions {
            gyro_unit: Some(GyroUnit::Rad),
            ..ImuReadOptions::default()
        };
        let e = read_err(input, &contradiction);
        assert_err(
            &e,
            0,
            Some("imu_layout"),
            InputErrorKind::Usage,
            "the names of the header say rates, --gyro-unit rad says increments",
        );
        let e = read_err(
            "1 0 0 0 0 0 0\n",
            &ImuReadOptions {
                layout: Some(ImuLayout::Increments),
                ..contradiction.clone()
            },
        );
        assert_eq!(e.kind, InputErrorKind::Usage);
        let e = read_err(
            input,
            &ImuReadOptions {
                accel_unit: Some(AccelUnit::MetrePerSecond2),
                ..ImuReadOptions::default()
            },
        );
        assert_err(
            &e,
            0,
            Some("accel_unit"),
            InputErrorKind::Usage,
            "contradicts the column \"ax_g\" of the header",
        );
    }

    /// An IMU mounted RBD: its samples come out in the vehicle's FRD axes.
    #[test]
    fn axes_turn_every_sample() {
        let rbd: schuler::imu::axes::SensorAxes = "RBD".parse().expect("right-handed");
        let input = "1 0.1 0.2 0.3 0.4 0.5 0.6\n2 0.1 0.2 0.3 0.4 0.5 0.6\n";
        let options = ImuReadOptions {
            c_vs: Some(rbd.c_vs()),
            ..text()
        };
        let s = read_all(input, &options).expect("good");
        assert_eq!(s[1].dtheta, Vector3::new(-0.2, 0.1, 0.3));
        assert_eq!(s[1].dvel, Vector3::new(-0.5, 0.4, 0.6));
        let mirror = ImuReadOptions {
            c_vs: Some(Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0))),
            ..text()
        };
        assert_eq!(read_err(input, &mirror).field.as_deref(), Some("c_vs"));
    }

    #[test]
    fn open_reads_files_and_reports_progress() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("IMU.txt");
        let body = stationary_text(50, 100.0, 1.0, ImuLayout::Increments);
        std::fs::write(&path, &body).expect("write");
        let r = ImuReader::open(&path, &ImuReadOptions::default()).expect("open");
        let progress = r.progress();
        assert_eq!(r.count(), 50);
        assert_eq!(progress.bytes(), body.len() as u64);
        let missing = dir.path().join("none.txt");
        let e = ImuReader::open(&missing, &ImuReadOptions::default())
            .err()
            .expect("missing");
        assert_eq!(e.kind, InputErrorKind::Io);
        assert!(e.to_string().contains("none.txt: cannot open"), "{e}");
    }

    proptest! {
        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2000)) {
            for format in [ImuFormat::Auto, ImuFormat::KfGinsText, ImuFormat::Csv] {
                for check_layout in [false, true] {
                    let options = ImuReadOptions { format, check_layout, ..ImuReadOptions::default() };
                    if let Ok(r) = ImuReader::new(&bytes[..], PATH, &options) {
                        for s in r.flatten() {
                            prop_assert!(s.dt > 0.0 && s.t.is_finite());
                        }
                    }
                }
            }
        }

        #[test]
        fn near_valid_lines_never_panic(
            lines in proptest::collection::vec(
                proptest::collection::vec(
                    prop_oneof![
                        Just("1".to_owned()), Just("".to_owned()), Just("nan".to_owned()),
                        Just(",".to_owned()), Just(" ".to_owned()), Just("t".to_owned()),
                        Just("dvel_x".to_owned()), Just("-1e400".to_owned()),
                        (0.0..100.0f64).prop_map(|x| x.to_string()),
                    ],
                    0..10,
                ),
                0..30,
            ),
            start in proptest::option::of(0.0..100.0f64),
        ) {
            let input: String = lines.iter().map(|l| l.join(",") + "\n").collect();
            let options = ImuReadOptions { t_start: start, ..ImuReadOptions::default() };
            if let Ok(r) = reader(&input, &options) {
                for s in r.flatten() {
                    prop_assert!(s.dt > 0.0);
                }
            }
        }

        #[test]
        fn written_values_read_back_bit_exact(
            // Within the domains: at most 70 rad/s and 7 g over the 0.25-s steps.
            rows in proptest::collection::vec(prop::array::uniform6(-10.0..10.0f64), 2..50),
            comma in any::<bool>(),
        ) {
            let sep = if comma { "," } else { "\t" };
            let mut input = String::new();
            for (i, v) in rows.iter().enumerate() {
                let fields: Vec<String> = v.iter().map(f64::to_string).collect();
                writeln!(input, "{}{sep}{}", 1000.0 + i as f64 * 0.25, fields.join(sep))
                    .expect("String");
            }
            let options = ImuReadOptions { check_layout: false, ..text() };
            let s = read_all(&input, &options).expect("good");
            for (sample, v) in s.iter().zip(&rows) {
                prop_assert_eq!(sample.dtheta, Vector3::new(v[0], v[1], v[2]));
                prop_assert_eq!(sample.dvel, Vector3::new(v[3], v[4], v[5]));
            }
        }
    }
}
