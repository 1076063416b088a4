//! Device logs (PX4 ULog, ROS 1 bags, u-blox UBX, Android GnssLogger, ArduPilot
//! DataFlash) read into one kind of record, so that `nav --log` and `inspect` treat
//! every format alike.
//!
//! A reader of a device log is an iterator of [`LogItem`]s in file order (each
//! stream in time order; streams interleaved as the device wrote them), together with
//! the table of the streams it has met ([`LogReader::streams`]). Conversions happen
//! at the edge, in the reader:
//! - time: [`LogRecord::t`] is on the run's clock, GPS seconds of week when the log
//!   ties its clock to GPS time (a GNSS message carrying week and time of week, or
//!   UTC plus leap seconds), else the device's own clock in seconds; the reader says
//!   which in [`LogReader::time_scale`];
//! - IMU: increments over `(t - dt, t]` in the IMU's own axes turned to FRD (forward,
//!   right, down) when the format defines its axes (PX4 and ArduPilot body frames are
//!   FRD; Android's device frame is x right, y up the screen, z out of the screen),
//!   SI units (rad, m/s);
//! - GNSS fixes: WGS 84 geodetic position, NED velocity, 1-σ standard deviations;
//! - raw GNSS: [`RawEpoch`], the same type the RINEX reader gives, so that the
//!   tightly coupled filter takes a receiver's or a phone's measurements as it takes a
//!   RINEX file's.

pub mod clock;
pub mod dataflash;
pub mod detect;
pub mod gnss_logger;
pub mod ubx;
pub mod ulog;

pub use detect::{LogFormat, detect};

use nalgebra::Vector3;
use schuler::earth::Geodetic;
use schuler::filter::GnssFix;
use schuler::gnss::Ephemeris;
use schuler::gnss::RawEpoch;
use schuler::imu::ImuSample;
use schuler::rotation::Euler;

/// One record of a device log, in the library's types and units.
#[derive(Debug, Clone, PartialEq)]
pub enum LogRecord {
    /// An IMU sample (increments, FRD axes).
    Imu(ImuSample),
    /// A GNSS fix, with its velocity when the message carries one.
    Gnss(GnssFix),
    /// A barometric height above the WGS 84 ellipsoid or above mean sea level, as the
    /// device gives it [m] (a barometer bias state absorbs the difference).
    Baro {
        /// Time [s].
        t: f64,
        /// Height [m].
        h: f64,
    },
    /// One epoch of raw GNSS measurements.
    Raw(RawEpoch),
    /// A broadcast ephemeris decoded from the navigation data the receiver logged.
    Ephemeris(Box<Ephemeris>),
    /// The device's own navigation solution (its onboard filter), as a reference
    /// to show beside schuler's.
    Reference(ReferenceSample),
}

impl LogRecord {
    /// The time of the record on the run's clock [s]; `None` for an ephemeris
    /// (it has its own times of clock and ephemeris).
    pub fn t(&self) -> Option<f64> {
        match self {
            LogRecord::Imu(s) => Some(s.t),
            LogRecord::Gnss(f) => Some(f.t),
            LogRecord::Baro { t, .. } => Some(*t),
            LogRecord::Raw(e) => Some(e.t.sow),
            LogRecord::Ephemeris(_) => None,
            LogRecord::Reference(r) => Some(r.t),
        }
    }
}

/// The device's own solution at one time; each part present when the log holds it
/// (PX4 logs attitude and position in separate topics).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceSample {
    /// Time [s].
    pub t: f64,
    /// Position (WGS 84).
    pub pos: Option<Geodetic>,
    /// Velocity north, east, down [m/s].
    pub v_n: Option<Vector3<f64>>,
    /// Attitude, body (FRD) to NED.
    pub att: Option<Euler>,
}

/// What kind of data a stream holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StreamKind {
    /// IMU samples.
    Imu,
    /// GNSS fixes.
    Gnss,
    /// Barometric heights.
    Baro,
    /// Raw GNSS measurements.
    Raw,
    /// Broadcast navigation data.
    Ephemeris,
    /// The device's own solution.
    Reference,
    /// A stream the log holds that schuler does not use (listed by `inspect`).
    Other,
}

/// One stream of a log: a ULog topic and instance, a bag topic, a UBX message class
/// and id, a GnssLogger record type, a DataFlash message type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stream {
    /// The name the format gives it (`sensor_combined`, `sensor_accel[1]`,
    /// `/imu/data`, `ESF-RAW`, `Raw`, `IMU[0]`).
    pub name: String,
    /// What it holds.
    pub kind: StreamKind,
}

/// A record and the index of its stream in [`LogReader::streams`].
#[derive(Debug, Clone, PartialEq)]
pub struct LogItem {
    /// Index into the reader's stream table.
    pub stream: usize,
    /// The record.
    pub record: LogRecord,
}

/// The clock of a log's records.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeScale {
    /// GPS seconds of week (week rollovers inside the log continue past 604 800 s).
    GpsSecondsOfWeek {
        /// The GPS week of the first record.
        week: u32,
    },
    /// The device's own clock [s] (time since boot), not tied to GPS.
    Device,
}

/// A streaming reader of a device log: an iterator of items plus what it has met.
pub trait LogReader: Iterator<Item = Result<LogItem, crate::formats::InputError>> {
    /// The streams met so far (all of them once the iterator has ended; formats
    /// whose header lists its streams, such as ULog, know them from the start).
    fn streams(&self) -> &[Stream];
    /// The clock the record times are on.
    fn time_scale(&self) -> TimeScale;
    /// Bytes read so far and the file's size, for progress.
    fn progress(&self) -> (u64, u64);
}

/// Opens the log at `path`, of `format` ([`detect`]), as its reader; `None` for a ROS
/// bag, which [`crate::bag`] reads.
pub fn open_reader(
    path: &std::path::Path,
    format: LogFormat,
) -> Result<Option<Box<dyn LogReader>>, crate::formats::InputError> {
    Ok(Some(match format {
        LogFormat::Ulog => Box::new(ulog::UlogReader::open(path)?),
        LogFormat::Ubx => Box::new(ubx::UbxReader::open(path)?),
        LogFormat::Dataflash => Box::new(dataflash::DataflashReader::open(path)?),
        LogFormat::GnssLogger => Box::new(gnss_logger::GnssLoggerReader::open(path)?),
        LogFormat::Ros1Bag | LogFormat::Mcap => return Ok(None),
    }))
}
