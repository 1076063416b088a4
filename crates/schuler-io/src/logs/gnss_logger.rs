//! Android GnssLogger text logs (`.txt`): raw GNSS measurements, the phone's GNSS
//! fixes, its IMU and its own attitude, as [`LogRecord`]s.
//!
//! The file is comment lines (`# …`), among them one header per record type giving
//! its columns (`# Raw,utcTimeMillis,TimeNanos,…`), then comma-separated rows whose
//! first field names their type. Columns are found by the header's names, so every
//! GnssLogger version reads (1.4's `Fix,Provider,Latitude,…,(UTC)TimeInMs` as 3.0's
//! `Fix,Provider,LatitudeDegrees,…,UnixTimeMillis,…,elapsedRealtimeNanos,…`). A row of
//! a type the reader uses must have exactly its header's number of fields; a garbled
//! value is refused with `file:line: field NAME`. Rows of other types (`Mag`,
//! `Status`, `Nav`, `Agc`, …, and fixes of providers other than GPS) are listed as
//! streams and not parsed; blank lines and lines with an empty type are skipped.
//!
//! Records:
//! - `Raw` rows → one [`RawEpoch`] per receiver epoch (rows sharing `TimeNanos` and
//!   `FullBiasNanos`), built as `raw.rs` says; an epoch is emitted when the next
//!   epoch's first row (or the end of the file) is met, so it comes one epoch late in
//!   file order. Rows without a valid measurement are skipped and counted by reason;
//!   a change of `HardwareClockDiscontinuityCount` is counted and marks every phase of
//!   that epoch as slipped.
//! - `Fix` rows of the `GPS` provider → [`GnssFix`]: Android's `AccuracyMeters` is the
//!   radius of 68 % horizontal confidence; for a circular normal error of σ per axis
//!   that radius is `σ·√(−2 ln 0.32) = 1.51 σ`, so σ_N = σ_E = accuracy / 1.51.
//!   `VerticalAccuracyMeters` (68 %, one dimension: σ) is σ_D; without it σ_D is the
//!   horizontal radius itself. Height: Android's altitude is above the WGS 84
//!   ellipsoid. Velocity, when the speed and its accuracy are given with a bearing (or
//!   a speed of 0): north `s cos β`, east `s sin β`, σ of each
//!   `√(σ_s² + (s·σ_β)²)`; Android has no vertical speed, so down is 0 with σ
//!   [`UNMEASURED_VD_STD`] (the NMEA reader's choice: no information).
//! - `UncalGyro`/`UncalAccel` (preferred, the sensors without the phone's bias
//!   removal: a filter estimates the biases itself), else `Gyro`/`Accel` →
//!   [`ImuSample`]s paired as `imu.rs` says, at the gyro's rate.
//!   Axes: Android's device frame is x right, y up the screen, z out of the screen;
//!   the body is FRD with **forward = +y, right = +x, down = −z** (the top of the
//!   phone ahead, its screen up when it lies flat): `(F, R, D) = (y, x, −z)`.
//! - `OrientationDeg` (`yawDeg, rollDeg, pitchDeg`, Android's
//!   `SensorManager.getOrientation` of the rotation vector: azimuth, pitch and roll of
//!   the device→world (x east, y magnetic north, z up) rotation
//!   `R = R_z(−azimuth)·R_x(−pitch)·R_y(roll)`) → a [`ReferenceSample`] attitude,
//!   FRD to NED: `C_bn = S·R·S` with `S` the swap of the first two axes and the
//!   negation of the third. Its yaw is from magnetic north (no declination applied).
//!
//! Time ([`TimeScale::GpsSecondsOfWeek`], the week of the first timed row): a raw
//! epoch's time is the receiver's GPS time; a fix's `UnixTimeMillis` is UTC, plus the
//! leap seconds in force ([`crate::bag::clock::LEAP_SECONDS`]). The sensors' stamps
//! are `elapsedRealtimeNanos`, the phone's clock since boot, mapped to GPS time by an
//! offset taken from the best tie the log has: (1) `Raw` rows' `ChipsetElapsedRealtimeNanos`
//! (the same instant as the epoch's GPS time; Android 12 on), (2) else a GPS fix's
//! `elapsedRealtimeNanos` with its `UnixTimeMillis`, (3) else the first sensor row's
//! `utcTimeMillis` (the phone's wall clock, good to milliseconds). [`open`] reads the
//! file once ahead for the first tie (and which IMU types it holds); every later tie of
//! the same kind updates the offset, so the phone clock's drift (tens of ppm) is
//! followed; increments' `dt` always come from the sensor's own stamps.
//!
//! [`open`]: GnssLoggerReader::open
//! [`UNMEASURED_VD_STD`]: crate::formats::nmea::UNMEASURED_VD_STD

mod imu;
mod raw;

pub use imu::PairingCounts;

use super::{LogItem, LogReader, LogRecord, ReferenceSample, Stream, StreamKind, TimeScale};
use crate::bag::clock::{GPS_EPOCH_UNIX, leap_seconds_at};
use crate::formats::InputError;
use crate::formats::MAX_LINE_BYTES;
use crate::formats::error::InputErrorKind;
use crate::formats::nmea::UNMEASURED_VD_STD;
use nalgebra::{Matrix3, Vector3};
use raw::{RawRow, Skip, WEEK_NS};
use schuler::earth::Geodetic;
use schuler::filter::GnssFix;
use schuler::gnss::RawEpoch;
use schuler::imu::ImuSample;
use schuler::rotation::Euler;
use std::collections::{HashMap, VecDeque};
use std::io::{BufRead, Cursor, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The radius of 68 % probability of a circular normal error over its σ per axis,
/// `√(−2 ln 0.32)`.
const R68_OVER_SIGMA: f64 = 1.509_596_1;

/// An integer field's admissible values.
type Bounds = std::ops::RangeInclusive<i64>;
/// Any value (a count only compared).
const ANY: Bounds = i64::MIN..=i64::MAX;
/// Nanosecond clocks (`TimeNanos`, `ReceivedSvTimeNanos`, `elapsedRealtimeNanos`):
/// ±1e18 ns (31 years), so that sums of a few of them stay within `i64` (9.2e18).
const CLOCK_NS: Bounds = -1_000_000_000_000_000_000..=1_000_000_000_000_000_000;
/// `FullBiasNanos`: ±3e18 ns (GPS time reaches 3e18 ns in 2075).
const FULL_BIAS_NS: Bounds = -3_000_000_000_000_000_000..=3_000_000_000_000_000_000;
/// UNIX milliseconds up to 4e12 (year 2096), so that their GPS nanoseconds fit `i64`.
const UNIX_MS: Bounds = 0..=4_000_000_000_000;
/// Small counts and identifiers (`Svid`, `ConstellationType`, `LeapSecond`).
const SMALL: Bounds = -1_000..=1_000;
/// The largest `BiasNanos` or `TimeOffsetNanos` read [ns] (a second: a receiver's
/// sub-nanosecond bias or offset, never near it).
const MAX_SUB_NS: f64 = 1e9;

/// What the reader skipped or met, for a report.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct GnssLoggerStats {
    /// Raw rows whose state gives no unambiguous measurement (no code lock, time of
    /// week unknown, millisecond ambiguity).
    pub raw_invalid_state: u64,
    /// Raw rows of SBAS, an unknown constellation, or GLONASS without its slot.
    pub raw_unsupported_satellite: u64,
    /// Raw rows whose carrier frequency is no band of their system.
    pub raw_unknown_frequency: u64,
    /// Raw rows whose pseudorange is outside (0, 100 000 km).
    pub raw_implausible: u64,
    /// Raw rows repeating a satellite and signal of their epoch.
    pub raw_duplicates: u64,
    /// Epochs left with no measurement (not emitted).
    pub raw_empty_epochs: u64,
    /// Changes of `HardwareClockDiscontinuityCount` between epochs.
    pub clock_discontinuities: u64,
    /// Fixes of providers other than GPS (fused, network), not used.
    pub other_provider_fixes: u64,
    /// Blank lines and lines of an empty type.
    pub blank_lines: u64,
    /// The accelerometer/gyro pairing's leftovers.
    pub pairing: PairingCounts,
}

/// How the sensors' `elapsedRealtimeNanos` is tied to GPS time (see the module's doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClockTie {
    /// `Raw` rows' `ChipsetElapsedRealtimeNanos`.
    RawChipset,
    /// GPS fixes' `elapsedRealtimeNanos` and `UnixTimeMillis`.
    GpsFix,
    /// The first sensor row's wall clock (`utcTimeMillis`).
    WallClock,
}

/// Where the text comes from; read twice (once ahead, see [`GnssLoggerReader::open`]).
#[derive(Clone)]
enum Source {
    File(PathBuf),
    Bytes(Arc<[u8]>),
}

impl Source {
    fn reader(&self) -> Result<Box<dyn BufRead + Send>, InputError> {
        match self {
            Source::File(p) => crate::formats::rinex::open(p),
            Source::Bytes(b) => Ok(Box::new(Cursor::new(Arc::clone(b)))),
        }
    }
    fn size(&self) -> u64 {
        match self {
            Source::File(p) => std::fs::metadata(p).map_or(0, |m| m.len()),
            Source::Bytes(b) => b.len() as u64,
        }
    }
}

/// A row split at its commas, with its line number.
struct Row<'a> {
    fields: Vec<&'a str>,
    line: u64,
}

/// Column positions of the record types the reader parses.
#[derive(Debug, Clone, Default)]
struct Headers {
    raw: Option<RawCols>,
    fix: Option<FixCols>,
    sensor: HashMap<String, SensorCols>,
    orientation: Option<OrientCols>,
    /// Every header's column count, by type.
    width: HashMap<String, usize>,
}

#[derive(Debug, Clone)]
struct RawCols {
    time_nanos: usize,
    full_bias: usize,
    bias: usize,
    time_offset: usize,
    leap: Option<usize>,
    discontinuity: Option<usize>,
    svid: usize,
    state: usize,
    sv_time: usize,
    sv_time_unc: usize,
    cn0: usize,
    prr: usize,
    prr_unc: usize,
    adr_state: usize,
    adr: usize,
    adr_unc: Option<usize>,
    freq: Option<usize>,
    constellation: usize,
    code_type: Option<usize>,
    chipset: Option<usize>,
}

#[derive(Debug, Clone)]
struct FixCols {
    provider: usize,
    lat: usize,
    lon: usize,
    alt: usize,
    speed: Option<usize>,
    accuracy: usize,
    bearing: Option<usize>,
    time: usize,
    speed_acc: Option<usize>,
    bearing_acc: Option<usize>,
    ern: Option<usize>,
    vertical_acc: Option<usize>,
}

#[derive(Debug, Clone)]
struct SensorCols {
    utc: usize,
    ern: Option<usize>,
    xyz: [usize; 3],
}

#[derive(Debug, Clone)]
struct OrientCols {
    utc: usize,
    ern: Option<usize>,
    yaw: usize,
    roll: usize,
    pitch: usize,
}

/// The record types read as IMU, and the column names of their axes.
const SENSORS: [(&str, [&str; 3]); 4] = [
    (
        "UncalGyro",
        [
            "UncalGyroXRadPerSec",
            "UncalGyroYRadPerSec",
            "UncalGyroZRadPerSec",
        ],
    ),
    (
        "UncalAccel",
        ["UncalAccelXMps2", "UncalAccelYMps2", "UncalAccelZMps2"],
    ),
    (
        "Gyro",
        ["GyroXRadPerSec", "GyroYRadPerSec", "GyroZRadPerSec"],
    ),
    ("Accel", ["AccelXMps2", "AccelYMps2", "AccelZMps2"]),
];

/// Reads the file's lines: numbering, the length bound, UTF-8, progress.
struct Lines {
    path: PathBuf,
    input: Box<dyn BufRead + Send>,
    buf: Vec<u8>,
    line: u64,
    bytes: u64,
}

impl Lines {
    fn new(path: &Path, input: Box<dyn BufRead + Send>) -> Self {
        Self {
            path: path.to_path_buf(),
            input,
            buf: Vec::new(),
            line: 0,
            bytes: 0,
        }
    }

    /// The next line without its end, or `None` at the end of the file.
    fn next_line(&mut self) -> Result<Option<(u64, &str)>, InputError> {
        self.buf.clear();
        let n = (&mut self.input)
            .take(MAX_LINE_BYTES + 1)
            .read_until(b'\n', &mut self.buf)
            .map_err(|e| self.err(InputErrorKind::Io, None, format!("cannot read: {e}")))?;
        if n == 0 {
            return Ok(None);
        }
        self.line += 1;
        self.bytes += n as u64;
        if n as u64 > MAX_LINE_BYTES {
            return Err(self.err(
                InputErrorKind::LineTooLong,
                None,
                format!("line longer than {MAX_LINE_BYTES} bytes (not a GnssLogger text file?)"),
            ));
        }
        while matches!(self.buf.last(), Some(b'\n' | b'\r')) {
            self.buf.pop();
        }
        let line = self.line;
        std::str::from_utf8(&self.buf)
            .map(|s| Some((line, s)))
            .map_err(|_| {
                InputError::new(
                    InputErrorKind::NotANumber,
                    &self.path,
                    line,
                    None,
                    "not UTF-8 text (not a GnssLogger text file?)",
                )
            })
    }

    fn err(&self, kind: InputErrorKind, field: Option<&str>, msg: impl Into<String>) -> InputError {
        InputError::new(kind, &self.path, self.line, field, msg)
    }
}

/// A header line's record type and column names (`# Raw,utcTimeMillis,…`), if it is one.
fn header_of(line: &str) -> Option<(&str, Vec<&str>)> {
    let body = line.strip_prefix('#')?.trim();
    let cols: Vec<&str> = body.split(',').map(str::trim).collect();
    let kind = cols[0];
    (cols.len() > 1 && !kind.is_empty() && kind.bytes().all(|b| b.is_ascii_alphanumeric()))
        .then_some((kind, cols))
}

impl Headers {
    /// Takes one header line; `Err` names a column the reader needs and the header lacks.
    fn take(&mut self, kind: &str, cols: &[&str]) -> Result<(), String> {
        let find = |names: &[&str]| cols.iter().position(|c| names.contains(c));
        let need = |names: &[&str]| {
            find(names).ok_or_else(|| format!("the {kind} header has no column {}", names[0]))
        };
        self.width.insert(kind.to_owned(), cols.len());
        match kind {
            "Raw" => {
                self.raw = Some(RawCols {
                    time_nanos: need(&["TimeNanos"])?,
                    full_bias: need(&["FullBiasNanos"])?,
                    bias: need(&["BiasNanos"])?,
                    time_offset: need(&["TimeOffsetNanos"])?,
                    leap: find(&["LeapSecond"]),
                    discontinuity: find(&["HardwareClockDiscontinuityCount"]),
                    svid: need(&["Svid"])?,
                    state: need(&["State"])?,
                    sv_time: need(&["ReceivedSvTimeNanos"])?,
                    sv_time_unc: need(&["ReceivedSvTimeUncertaintyNanos"])?,
                    cn0: need(&["Cn0DbHz"])?,
                    prr: need(&["PseudorangeRateMetersPerSecond"])?,
                    prr_unc: need(&["PseudorangeRateUncertaintyMetersPerSecond"])?,
                    adr_state: need(&["AccumulatedDeltaRangeState"])?,
                    adr: need(&["AccumulatedDeltaRangeMeters"])?,
                    adr_unc: find(&["AccumulatedDeltaRangeUncertaintyMeters"]),
                    freq: find(&["CarrierFrequencyHz"]),
                    constellation: need(&["ConstellationType"])?,
                    code_type: find(&["CodeType"]),
                    chipset: find(&["ChipsetElapsedRealtimeNanos"]),
                })
            }
            "Fix" => {
                self.fix = Some(FixCols {
                    provider: need(&["Provider"])?,
                    lat: need(&["LatitudeDegrees", "Latitude"])?,
                    lon: need(&["LongitudeDegrees", "Longitude"])?,
                    alt: need(&["AltitudeMeters", "Altitude"])?,
                    speed: find(&["SpeedMps", "Speed"]),
                    accuracy: need(&["AccuracyMeters", "Accuracy"])?,
                    bearing: find(&["BearingDegrees"]),
                    time: need(&["UnixTimeMillis", "(UTC)TimeInMs"])?,
                    speed_acc: find(&["SpeedAccuracyMps"]),
                    bearing_acc: find(&["BearingAccuracyDegrees"]),
                    ern: find(&["elapsedRealtimeNanos"]),
                    vertical_acc: find(&["VerticalAccuracyMeters"]),
                })
            }
            "OrientationDeg" => {
                self.orientation = Some(OrientCols {
                    utc: need(&["utcTimeMillis"])?,
                    ern: find(&["elapsedRealtimeNanos"]),
                    yaw: need(&["yawDeg"])?,
                    roll: need(&["rollDeg"])?,
                    pitch: need(&["pitchDeg"])?,
                })
            }
            _ => {
                if let Some((_, axes)) = SENSORS.iter().find(|(k, _)| *k == kind) {
                    let cols = SensorCols {
                        utc: need(&["utcTimeMillis"])?,
                        ern: find(&["elapsedRealtimeNanos"]),
                        xyz: [need(&[axes[0]])?, need(&[axes[1]])?, need(&[axes[2]])?],
                    };
                    self.sensor.insert(kind.to_owned(), cols);
                }
            }
        }
        Ok(())
    }
}

/// Field parsing with `file:line: field NAME` errors.
struct Parse<'a> {
    path: &'a Path,
    header: &'a [String],
}

impl Parse<'_> {
    fn name(&self, i: usize) -> &str {
        self.header.get(i).map_or("?", String::as_str)
    }
    fn err(&self, row: &Row, i: usize, kind: InputErrorKind, msg: String) -> InputError {
        InputError::new(kind, self.path, row.line, Some(self.name(i)), msg)
    }
    fn text<'r>(&self, row: &Row<'r>, i: usize) -> &'r str {
        row.fields.get(i).map_or("", |s| s.trim())
    }
    fn opt_f64(&self, row: &Row, i: usize) -> Result<Option<f64>, InputError> {
        let s = self.text(row, i);
        if s.is_empty() {
            return Ok(None);
        }
        let v: f64 = s.parse().map_err(|_| {
            self.err(
                row,
                i,
                InputErrorKind::NotANumber,
                format!("not a number: {s:?}"),
            )
        })?;
        if !v.is_finite() {
            return Err(self.err(
                row,
                i,
                InputErrorKind::NotFinite,
                format!("not finite: {s:?}"),
            ));
        }
        Ok(Some(v))
    }
    fn f64(&self, row: &Row, i: usize) -> Result<f64, InputError> {
        self.opt_f64(row, i)?
            .ok_or_else(|| self.err(row, i, InputErrorKind::NotANumber, "empty".to_owned()))
    }
    /// An integer written as one (a count of nanoseconds written with an exponent has
    /// lost its last digits to a spreadsheet's rounding, and is refused) within
    /// `range` (bounds that keep every sum of nanoseconds within `i64`).
    fn opt_i64(&self, row: &Row, i: usize, range: Bounds) -> Result<Option<i64>, InputError> {
        let s = self.text(row, i);
        if s.is_empty() {
            return Ok(None);
        }
        let v: i64 = s.parse().map_err(|_| {
            self.err(
                row,
                i,
                InputErrorKind::NotANumber,
                format!("not an integer: {s:?} (a count written in full is needed; a spreadsheet's rounding loses digits)"),
            )
        })?;
        if !range.contains(&v) {
            return Err(self.err(
                row,
                i,
                InputErrorKind::OutOfDomain,
                format!("{v} outside {}..={}", range.start(), range.end()),
            ));
        }
        Ok(Some(v))
    }
    fn i64(&self, row: &Row, i: usize, range: Bounds) -> Result<i64, InputError> {
        self.opt_i64(row, i, range)?
            .ok_or_else(|| self.err(row, i, InputErrorKind::NotANumber, "empty".to_owned()))
    }
    /// A real number within ±`bound`.
    fn f64_within(&self, row: &Row, i: usize, bound: f64) -> Result<Option<f64>, InputError> {
        let v = self.opt_f64(row, i)?;
        if let Some(x) = v
            && x.abs() > bound
        {
            return Err(self.err(
                row,
                i,
                InputErrorKind::OutOfDomain,
                format!("{x} beyond ±{bound}"),
            ));
        }
        Ok(v)
    }
    fn u32(&self, row: &Row, i: usize) -> Result<u32, InputError> {
        let v = self.i64(row, i, ANY)?;
        u32::try_from(v).map_err(|_| {
            self.err(
                row,
                i,
                InputErrorKind::OutOfDomain,
                format!("not a bit field: {v}"),
            )
        })
    }
}

/// GPS time [ns since the GPS epoch] of UNIX time `ms` [ms, UTC].
fn unix_ms_to_gps_ns(ms: i64) -> i64 {
    let leap = leap_seconds_at(ms.div_euclid(1000));
    (ms - GPS_EPOCH_UNIX * 1000 + leap * 1000).saturating_mul(1_000_000)
}

/// GPS − UTC [s] at GPS time `gps_ns`.
fn leap_at_gps_ns(gps_ns: i64) -> i64 {
    let unix = gps_ns.div_euclid(1_000_000_000) + GPS_EPOCH_UNIX;
    leap_seconds_at(unix - leap_seconds_at(unix))
}

/// The ahead-reading of [`GnssLoggerReader::open`]: the first timed row, the first tie
/// of each kind, the IMU types present.
#[derive(Debug, Default)]
struct Scan {
    first_gps_ns: Option<i64>,
    raw_tie: Option<i64>,
    fix_tie: Option<i64>,
    wall_tie: Option<i64>,
    types: Vec<String>,
}

/// Android's device axes (x right, y up the screen, z out of it) as FRD.
fn device_to_frd(v: [f64; 3]) -> Vector3<f64> {
    Vector3::new(v[1], v[0], -v[2])
}

/// The FRD→NED attitude of Android's azimuth, pitch and roll [deg] (module doc).
fn orientation_to_euler(azimuth: f64, pitch: f64, roll: f64) -> Euler {
    let rz = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), -azimuth.to_radians());
    let rx = nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), -pitch.to_radians());
    let ry = nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), roll.to_radians());
    let r = (rz * rx * ry).into_inner();
    let s = Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0);
    Euler::from_dcm(&(s * r * s))
}

/// The reader (see the module's doc).
pub struct GnssLoggerReader {
    path: PathBuf,
    lines: Lines,
    size: u64,
    headers: Headers,
    names: HashMap<String, Vec<String>>,
    streams: Vec<Stream>,
    stream_of: HashMap<String, usize>,
    week: i64,
    tie: ClockTie,
    offset_ns: i64,
    gyro_type: Option<&'static str>,
    accel_type: Option<&'static str>,
    pairer: imu::Pairer,
    epoch: Option<((i64, i64), RawEpoch, bool)>,
    last_discontinuity: Option<i64>,
    queue: VecDeque<LogItem>,
    stats: GnssLoggerStats,
    done: bool,
}

impl GnssLoggerReader {
    /// Opens a GnssLogger file (gzip-compressed or not). Reads it once ahead, whole,
    /// for the week of its first timed row, the tie of the phone's clock to GPS time
    /// and the IMU types it holds (bounded memory: one line at a time), then streams.
    pub fn open(path: &Path) -> Result<Self, InputError> {
        Self::with_source(path, Source::File(path.to_path_buf()))
    }

    /// A reader of `bytes` (a whole log in memory), `path` naming it in errors.
    pub fn from_bytes(path: &Path, bytes: Vec<u8>) -> Result<Self, InputError> {
        Self::with_source(path, Source::Bytes(bytes.into()))
    }

    fn with_source(path: &Path, source: Source) -> Result<Self, InputError> {
        let scan = Self::scan(path, source.reader()?)?;
        let first = scan.first_gps_ns.ok_or_else(|| {
            InputError::new(
                InputErrorKind::NoData,
                path,
                0,
                None,
                "no timed row (Raw, Fix of the GPS provider, or sensor) in the file",
            )
        })?;
        let (tie, offset_ns) = match (scan.raw_tie, scan.fix_tie, scan.wall_tie) {
            (Some(o), _, _) => (ClockTie::RawChipset, o),
            (None, Some(o), _) => (ClockTie::GpsFix, o),
            (None, None, o) => (ClockTie::WallClock, o.unwrap_or(0)),
        };
        let has = |t: &str| scan.types.iter().any(|s| s == t);
        let pick = |a: &'static str, b: &'static str| {
            if has(a) {
                Some(a)
            } else if has(b) {
                Some(b)
            } else {
                None
            }
        };
        Ok(Self {
            path: path.to_path_buf(),
            lines: Lines::new(path, source.reader()?),
            size: source.size(),
            headers: Headers::default(),
            names: HashMap::new(),
            streams: Vec::new(),
            stream_of: HashMap::new(),
            week: first.div_euclid(WEEK_NS),
            tie,
            offset_ns,
            gyro_type: pick("UncalGyro", "Gyro"),
            accel_type: pick("UncalAccel", "Accel"),
            pairer: imu::Pairer::default(),
            epoch: None,
            last_discontinuity: None,
            queue: VecDeque::new(),
            stats: GnssLoggerStats::default(),
            done: false,
        })
    }

    /// What was skipped or met so far.
    pub fn stats(&self) -> GnssLoggerStats {
        let mut s = self.stats.clone();
        s.pairing = self.pairer.counts;
        s
    }

    /// How the sensors' clock is tied to GPS time.
    pub fn clock_tie(&self) -> ClockTie {
        self.tie
    }

    /// The reading ahead: headers, the first timed row, ties, types present.
    fn scan(path: &Path, input: Box<dyn BufRead + Send>) -> Result<Scan, InputError> {
        let mut lines = Lines::new(path, input);
        let mut headers = Headers::default();
        let mut names = HashMap::new();
        let mut scan = Scan::default();
        while let Some((line_no, line)) = lines.next_line()? {
            if line.starts_with('#') {
                take_header(&mut headers, &mut names, line, path, line_no)?;
                continue;
            }
            let kind = line.split(',').next().unwrap_or("");
            if kind.is_empty() {
                continue;
            }
            if !scan.types.iter().any(|t| t == kind) {
                scan.types.push(kind.to_owned());
            }
            let need_time = scan.first_gps_ns.is_none();
            let row = Row {
                fields: line.split(',').collect(),
                line: line_no,
            };
            match kind {
                "Raw" if need_time || scan.raw_tie.is_none() => {
                    let r = parse_raw(&headers, &names, path, &row)?;
                    let gps = r.gps_ns_int() - r.bias_nanos.round() as i64;
                    scan.first_gps_ns.get_or_insert(gps);
                    if let Some(c) = r.chipset_elapsed_realtime_nanos {
                        scan.raw_tie = Some(gps - c);
                    }
                }
                "Fix" if need_time || scan.fix_tie.is_none() => {
                    if let Some(f) = parse_fix(&headers, &names, path, &row)? {
                        scan.first_gps_ns.get_or_insert(f.gps_ns);
                        if let Some(e) = f.ern {
                            scan.fix_tie.get_or_insert(f.gps_ns - e);
                        }
                    }
                }
                k if (need_time || scan.wall_tie.is_none())
                    && (headers.sensor.contains_key(k) || k == "OrientationDeg") =>
                {
                    let (utc, ern) = parse_stamp(&headers, &names, path, &row, k)?;
                    let gps = unix_ms_to_gps_ns(utc);
                    scan.first_gps_ns.get_or_insert(gps);
                    if let Some(e) = ern {
                        scan.wall_tie.get_or_insert(gps - e);
                    }
                }
                _ => {}
            }
        }
        Ok(scan)
    }

    fn stream(&mut self, name: &str, kind: StreamKind) -> usize {
        if let Some(&i) = self.stream_of.get(name) {
            return i;
        }
        self.streams.push(Stream {
            name: name.to_owned(),
            kind,
        });
        self.stream_of
            .insert(name.to_owned(), self.streams.len() - 1);
        self.streams.len() - 1
    }

    /// Seconds of the log's week of GPS time `gps_ns`.
    fn t_of(&self, gps_ns: i64) -> f64 {
        (i128::from(gps_ns) - i128::from(self.week) * i128::from(WEEK_NS)) as f64 * 1e-9
    }

    fn push(&mut self, stream: usize, record: LogRecord) {
        self.queue.push_back(LogItem { stream, record });
    }

    /// Emits the epoch being gathered, if any.
    fn flush_epoch(&mut self) {
        if let Some((_, epoch, _)) = self.epoch.take() {
            if epoch.measurements.is_empty() {
                self.stats.raw_empty_epochs += 1;
            } else {
                let s = self.stream("Raw", StreamKind::Raw);
                self.push(s, LogRecord::Raw(epoch));
            }
        }
    }

    fn on_raw(&mut self, row: &Row) -> Result<(), InputError> {
        let r = parse_raw(&self.headers, &self.names, &self.path, row)?;
        let gps = r.gps_ns_int() - r.bias_nanos.round() as i64;
        if self.tie == ClockTie::RawChipset
            && let Some(c) = r.chipset_elapsed_realtime_nanos
        {
            self.offset_ns = gps - c;
        }
        let key = (r.time_nanos, r.full_bias_nanos);
        if self.epoch.as_ref().is_none_or(|(k, _, _)| *k != key) {
            self.flush_epoch();
            let broke = match (self.last_discontinuity, r.discontinuity) {
                (Some(a), Some(b)) => a != b,
                _ => false,
            };
            if broke {
                self.stats.clock_discontinuities += 1;
            }
            if r.discontinuity.is_some() {
                self.last_discontinuity = r.discontinuity;
            }
            let epoch = RawEpoch {
                t: r.receive_time(),
                measurements: Vec::new(),
            };
            self.epoch = Some((key, epoch, broke));
        }
        let leap = r.leap_second.unwrap_or_else(|| leap_at_gps_ns(gps));
        let (_, epoch, broke) = self.epoch.as_mut().expect("an epoch is open");
        match raw::measurement(&r, leap, *broke) {
            Ok(m) => {
                if epoch.get(m.sat, m.signal).is_some() {
                    self.stats.raw_duplicates += 1;
                } else {
                    epoch.measurements.push(m);
                }
            }
            Err(Skip::State) => self.stats.raw_invalid_state += 1,
            Err(Skip::Satellite) => self.stats.raw_unsupported_satellite += 1,
            Err(Skip::Frequency) => self.stats.raw_unknown_frequency += 1,
            Err(Skip::Implausible) => self.stats.raw_implausible += 1,
        }
        Ok(())
    }

    fn on_fix(&mut self, row: &Row) -> Result<(), InputError> {
        let Some(f) = parse_fix(&self.headers, &self.names, &self.path, row)? else {
            self.stats.other_provider_fixes += 1;
            let provider = row.fields.get(1).map_or("", |s| s.trim());
            self.stream(&format!("Fix[{provider}]"), StreamKind::Other);
            return Ok(());
        };
        if self.tie == ClockTie::GpsFix
            && let Some(e) = f.ern
        {
            self.offset_ns = f.gps_ns - e;
        }
        let fix = GnssFix {
            t: self.t_of(f.gps_ns),
            ..f.fix
        };
        let s = self.stream("Fix", StreamKind::Gnss);
        self.push(s, LogRecord::Gnss(fix));
        Ok(())
    }

    /// The sensor clock's stamp `ern` (or the row's wall clock) as GPS ns.
    fn sensor_gps_ns(&self, utc_ms: i64, ern: Option<i64>) -> i64 {
        match ern {
            Some(e) => e + self.offset_ns,
            None => unix_ms_to_gps_ns(utc_ms),
        }
    }

    fn on_sensor(&mut self, row: &Row, kind: &str, gyro: bool) -> Result<(), InputError> {
        let cols = self.headers.sensor[kind].clone();
        let names = &self.names[kind];
        let p = Parse {
            path: &self.path,
            header: names,
        };
        let utc = p.i64(row, cols.utc, UNIX_MS)?;
        let ern = cols.ern.map(|i| p.i64(row, i, CLOCK_NS)).transpose()?;
        let v = [
            p.f64(row, cols.xyz[0])?,
            p.f64(row, cols.xyz[1])?,
            p.f64(row, cols.xyz[2])?,
        ];
        let stamp = ern.unwrap_or_else(|| unix_ms_to_gps_ns(utc));
        let mut out = Vec::new();
        let v = device_to_frd(v);
        let res = if gyro {
            self.pairer.gyro(stamp, v, &mut out)
        } else {
            self.pairer.accel(stamp, v, &mut out)
        };
        res.map_err(|e| {
            InputError::new(
                InputErrorKind::TimeNotIncreasing,
                &self.path,
                row.line,
                Some(if cols.ern.is_some() {
                    "elapsedRealtimeNanos"
                } else {
                    "utcTimeMillis"
                }),
                format!(
                    "{kind} stamp {} ns after {} ns: not increasing",
                    e.t_ns, e.previous_ns
                ),
            )
        })?;
        if out.is_empty() {
            return Ok(());
        }
        let name = format!(
            "{}+{}",
            self.gyro_type.unwrap_or("Gyro"),
            self.accel_type.unwrap_or("Accel")
        );
        let s = self.stream(&name, StreamKind::Imu);
        for p in out {
            let gps = if ern.is_some() {
                p.t_ns + self.offset_ns
            } else {
                p.t_ns
            };
            let sample = ImuSample {
                t: self.t_of(gps),
                dt: p.dt_ns as f64 * 1e-9,
                dtheta: p.dtheta,
                dvel: p.dvel,
            };
            self.push(s, LogRecord::Imu(sample));
        }
        Ok(())
    }

    fn on_orientation(&mut self, row: &Row) -> Result<(), InputError> {
        let cols = self
            .headers
            .orientation
            .clone()
            .expect("checked by the caller");
        let p = Parse {
            path: &self.path,
            header: &self.names["OrientationDeg"],
        };
        let utc = p.i64(row, cols.utc, UNIX_MS)?;
        let ern = cols.ern.map(|i| p.i64(row, i, CLOCK_NS)).transpose()?;
        let att = orientation_to_euler(
            p.f64(row, cols.yaw)?,
            p.f64(row, cols.pitch)?,
            p.f64(row, cols.roll)?,
        );
        let t = self.t_of(self.sensor_gps_ns(utc, ern));
        let s = self.stream("OrientationDeg", StreamKind::Reference);
        self.push(
            s,
            LogRecord::Reference(ReferenceSample {
                t,
                pos: None,
                v_n: None,
                att: Some(att),
            }),
        );
        Ok(())
    }

    /// Reads lines until at least one item is queued or the file ends.
    fn fill(&mut self) -> Result<(), InputError> {
        while self.queue.is_empty() && !self.done {
            let Some((line_no, line)) = self.lines.next_line()? else {
                self.done = true;
                self.flush_epoch();
                self.pairer.finish();
                break;
            };
            let line = line.to_owned();
            if line.starts_with('#') {
                take_header(
                    &mut self.headers,
                    &mut self.names,
                    &line,
                    &self.path,
                    line_no,
                )?;
                continue;
            }
            let fields: Vec<&str> = line.split(',').collect();
            let kind = fields[0].trim();
            if kind.is_empty() {
                self.stats.blank_lines += 1;
                continue;
            }
            let row = Row {
                fields,
                line: line_no,
            };
            let kind = kind.to_owned();
            if kind == "Raw" {
                self.on_raw(&row)?;
            } else if kind == "Fix" {
                self.on_fix(&row)?;
            } else if Some(kind.as_str()) == self.gyro_type
                && self.headers.sensor.contains_key(&kind)
            {
                self.check_width(&row, &kind)?;
                self.on_sensor(&row, &kind, true)?;
            } else if Some(kind.as_str()) == self.accel_type
                && self.headers.sensor.contains_key(&kind)
            {
                self.check_width(&row, &kind)?;
                self.on_sensor(&row, &kind, false)?;
            } else if kind == "OrientationDeg" && self.headers.orientation.is_some() {
                self.check_width(&row, &kind)?;
                self.on_orientation(&row)?;
            } else {
                self.stream(&kind, StreamKind::Other);
            }
        }
        Ok(())
    }

    fn check_width(&self, row: &Row, kind: &str) -> Result<(), InputError> {
        check_width(&self.headers, &self.path, row, kind)
    }
}

/// Takes a header line into `headers` and `names`.
fn take_header(
    headers: &mut Headers,
    names: &mut HashMap<String, Vec<String>>,
    line: &str,
    path: &Path,
    line_no: u64,
) -> Result<(), InputError> {
    if let Some((kind, cols)) = header_of(line) {
        headers
            .take(kind, &cols)
            .map_err(|m| InputError::new(InputErrorKind::Header, path, line_no, None, m))?;
        names.insert(
            kind.to_owned(),
            cols.iter().map(|s| (*s).to_owned()).collect(),
        );
    }
    Ok(())
}

/// A row of a type the reader parses must have its header's number of fields.
fn check_width(headers: &Headers, path: &Path, row: &Row, kind: &str) -> Result<(), InputError> {
    let Some(&w) = headers.width.get(kind) else {
        return Err(InputError::new(
            InputErrorKind::Header,
            path,
            row.line,
            None,
            format!("a {kind} row before any `# {kind},…` header line"),
        ));
    };
    if row.fields.len() != w {
        return Err(InputError::new(
            InputErrorKind::ColumnCount,
            path,
            row.line,
            None,
            format!(
                "{} fields where the {kind} header has {w} (a truncated or garbled line)",
                row.fields.len()
            ),
        ));
    }
    Ok(())
}

/// A `Raw` row's values.
fn parse_raw(
    headers: &Headers,
    names: &HashMap<String, Vec<String>>,
    path: &Path,
    row: &Row,
) -> Result<RawRow, InputError> {
    check_width(headers, path, row, "Raw")?;
    let c = headers
        .raw
        .as_ref()
        .expect("a Raw header, checked by width");
    let p = Parse {
        path,
        header: &names["Raw"],
    };
    let opt_i = |i: Option<usize>, b: Bounds| {
        i.map(|i| p.opt_i64(row, i, b))
            .transpose()
            .map(Option::flatten)
    };
    Ok(RawRow {
        time_nanos: p.i64(row, c.time_nanos, CLOCK_NS)?,
        full_bias_nanos: p.i64(row, c.full_bias, FULL_BIAS_NS)?,
        bias_nanos: p.f64_within(row, c.bias, MAX_SUB_NS)?.unwrap_or(0.0),
        time_offset_nanos: p.f64_within(row, c.time_offset, MAX_SUB_NS)?.unwrap_or(0.0),
        leap_second: opt_i(c.leap, SMALL)?,
        discontinuity: opt_i(c.discontinuity, ANY)?,
        svid: p.i64(row, c.svid, SMALL)?,
        constellation: p.i64(row, c.constellation, SMALL)?,
        state: p.u32(row, c.state)?,
        received_sv_time_nanos: p.i64(row, c.sv_time, CLOCK_NS)?,
        received_sv_time_uncertainty_nanos: p.f64(row, c.sv_time_unc)?,
        cn0: p.f64(row, c.cn0)?,
        pseudorange_rate: p.f64(row, c.prr)?,
        pseudorange_rate_uncertainty: p.f64(row, c.prr_unc)?,
        adr_state: p.u32(row, c.adr_state)?,
        adr: p.opt_f64(row, c.adr)?.unwrap_or(0.0),
        adr_uncertainty: c.adr_unc.map(|i| p.opt_f64(row, i)).transpose()?.flatten(),
        carrier_frequency: c.freq.map(|i| p.opt_f64(row, i)).transpose()?.flatten(),
        code_type: c
            .code_type
            .and_then(|i| p.text(row, i).chars().next())
            .filter(char::is_ascii_alphabetic),
        chipset_elapsed_realtime_nanos: opt_i(c.chipset, CLOCK_NS)?,
    })
}

/// A GPS-provider fix, its GPS time and its `elapsedRealtimeNanos`.
struct ParsedFix {
    fix: GnssFix,
    gps_ns: i64,
    ern: Option<i64>,
}

/// A `Fix` row of the GPS provider (`None` for other providers, not parsed further).
fn parse_fix(
    headers: &Headers,
    names: &HashMap<String, Vec<String>>,
    path: &Path,
    row: &Row,
) -> Result<Option<ParsedFix>, InputError> {
    check_width(headers, path, row, "Fix")?;
    let c = headers
        .fix
        .as_ref()
        .expect("a Fix header, checked by width");
    let p = Parse {
        path,
        header: &names["Fix"],
    };
    if !p.text(row, c.provider).eq_ignore_ascii_case("gps") {
        return Ok(None);
    }
    let (lat, lon) = (p.f64(row, c.lat)?, p.f64(row, c.lon)?);
    if lat.abs() > 90.0 {
        return Err(p.err(
            row,
            c.lat,
            InputErrorKind::OutOfDomain,
            format!("latitude {lat}° beyond a pole"),
        ));
    }
    if lon.abs() > 360.0 {
        return Err(p.err(
            row,
            c.lon,
            InputErrorKind::OutOfDomain,
            format!("longitude {lon}°"),
        ));
    }
    let alt = p.f64(row, c.alt)?;
    let acc = p.f64(row, c.accuracy)?;
    if acc <= 0.0 {
        return Err(p.err(
            row,
            c.accuracy,
            InputErrorKind::OutOfDomain,
            format!("accuracy {acc} m is not > 0"),
        ));
    }
    let opt = |i: Option<usize>| {
        i.map(|i| p.opt_f64(row, i))
            .transpose()
            .map(Option::flatten)
    };
    let sigma_h = acc / R68_OVER_SIGMA;
    let sigma_v = opt(c.vertical_acc)?.filter(|v| *v > 0.0).unwrap_or(acc);
    let vel = match (opt(c.speed)?, opt(c.bearing)?, opt(c.speed_acc)?) {
        (Some(s), bearing, Some(sacc)) if sacc > 0.0 && (bearing.is_some() || s == 0.0) => {
            let b = bearing.unwrap_or(0.0).to_radians();
            let bacc = opt(c.bearing_acc)?.unwrap_or(0.0).to_radians();
            let sn = sacc.hypot(s * bacc);
            Some((
                Vector3::new(s * b.cos(), s * b.sin(), 0.0),
                Vector3::new(sn, sn, UNMEASURED_VD_STD),
            ))
        }
        _ => None,
    };
    let gps_ns = unix_ms_to_gps_ns(p.i64(row, c.time, UNIX_MS)?);
    let ern = c
        .ern
        .map(|i| p.opt_i64(row, i, CLOCK_NS))
        .transpose()?
        .flatten();
    Ok(Some(ParsedFix {
        fix: GnssFix {
            t: 0.0,
            pos: Geodetic::new(lat.to_radians(), lon.to_radians(), alt),
            pos_std: Vector3::new(sigma_h, sigma_h, sigma_v),
            vel,
        },
        gps_ns,
        ern,
    }))
}

/// A sensor or orientation row's `utcTimeMillis` and `elapsedRealtimeNanos`.
fn parse_stamp(
    headers: &Headers,
    names: &HashMap<String, Vec<String>>,
    path: &Path,
    row: &Row,
    kind: &str,
) -> Result<(i64, Option<i64>), InputError> {
    check_width(headers, path, row, kind)?;
    let (utc, ern) = match headers.sensor.get(kind) {
        Some(c) => (c.utc, c.ern),
        None => {
            let c = headers.orientation.as_ref().expect("an orientation header");
            (c.utc, c.ern)
        }
    };
    let p = Parse {
        path,
        header: &names[kind],
    };
    Ok((
        p.i64(row, utc, UNIX_MS)?,
        ern.map(|i| p.i64(row, i, CLOCK_NS)).transpose()?,
    ))
}

impl Iterator for GnssLoggerReader {
    type Item = Result<LogItem, InputError>;

    fn next(&mut self) -> Option<Self::Item> {
        if let Err(e) = self.fill() {
            self.done = true;
            self.queue.clear();
            return Some(Err(e));
        }
        self.queue.pop_front().map(Ok)
    }
}

impl LogReader for GnssLoggerReader {
    fn streams(&self) -> &[Stream] {
        &self.streams
    }
    fn time_scale(&self) -> TimeScale {
        TimeScale::GpsSecondsOfWeek {
            week: u32::try_from(self.week).unwrap_or(0),
        }
    }
    fn progress(&self) -> (u64, u64) {
        (self.lines.bytes, self.size.max(self.lines.bytes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_phone_heads_where_its_top_points() {
        // Lying flat, top toward the east: yaw 90°, level.
        let e = orientation_to_euler(90.0, 0.0, 0.0);
        assert!((e.yaw - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert!(e.roll.abs() < 1e-12 && e.pitch.abs() < 1e-12);
        // Top edge tilted 10° toward the ground (Android's positive pitch): nose down.
        let e = orientation_to_euler(0.0, 10.0, 0.0);
        assert!((e.pitch + 10f64.to_radians()).abs() < 1e-12);
        // The DCM of the Euler angles maps the device's top (+y, forward) where
        // Android's rotation sends it: north-east-down of (sin az cos p, cos az cos p, −sin p)
        // in east-north-up.
        let (az, p, r) = (30f64, 20f64, -15f64);
        let e = orientation_to_euler(az, p, r);
        let fwd_ned = e.to_dcm() * Vector3::x();
        let (a, pp) = (az.to_radians(), p.to_radians());
        let expect = Vector3::new(a.cos() * pp.cos(), a.sin() * pp.cos(), pp.sin());
        assert!((fwd_ned - expect).amax() < 1e-12, "{fwd_ned} vs {expect}");
    }

    #[test]
    fn axes_and_leap_seconds() {
        assert_eq!(device_to_frd([1.0, 2.0, 3.0]), Vector3::new(2.0, 1.0, -3.0));
        // 2023-11-07 23:43:14 UTC is GPS 1383435812 s (18 leap seconds).
        assert_eq!(
            unix_ms_to_gps_ns(1_699_400_594_000),
            1_383_435_812_000_000_000
        );
        assert_eq!(leap_at_gps_ns(1_383_435_812_000_000_000), 18);
        // 2016-06-30: 17.
        assert_eq!(leap_at_gps_ns(1_151_357_185_397_178_048), 17);
    }
}
