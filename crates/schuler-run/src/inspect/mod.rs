//! `schuler inspect FILE…`: what a device log holds before anyone navigates it, read
//! in one streaming pass in constant memory (nothing of the log is kept but running
//! sums, the first [`stats::MEDIAN_SPACINGS`] spacings of each stream, and histograms).
//!
//! Per stream: its kind, records, mean rate and jitter (the standard deviation of
//! the spacing), time span, gaps longer than five median spacings; GNSS quality
//! (fixes, median σ); raw GNSS (epochs, satellites); the IMU's units and axes as the
//! data show them ([`imu`]); and the `schuler nav` command line that would navigate
//! the log ([`command`]).
//!
//! `inspect --json` prints [`Inspection`] as serde serializes it: the schema
//! `schuler-inspect/1`, whose keys are the fields' names documented here (times in
//! seconds on the log's clock, lengths in metres, rates in Hz).

pub mod command;
pub mod imu;
pub mod notes;
pub mod stats;

use anyhow::Result;
use schuler_io::bag::input::Kind;
use schuler_io::logs::{LogFormat, LogReader, LogRecord, StreamKind, TimeScale, detect};
use serde::Serialize;
use stats::{LogMedian, Timing, TimingSummary};
use std::path::Path;

/// The `schema` value of `inspect --json`.
pub const SCHEMA: &str = "schuler-inspect/1";

/// What one log holds.
#[derive(Debug, Clone, Serialize)]
pub struct Inspection {
    /// [`SCHEMA`].
    pub schema: &'static str,
    /// The file as given.
    pub path: String,
    /// The format's key (`ulog`, `ros1-bag`, `mcap`, `ubx`, `dataflash`, `gnss-logger`).
    pub format: &'static str,
    /// The format's name.
    pub format_name: &'static str,
    /// The clock of the times: `gps-seconds-of-week` (with `week`), `device` (seconds
    /// since the device booted), `bag-stamps` (a bag's log time, seconds).
    pub time_scale: &'static str,
    /// The GPS week of a `gps-seconds-of-week` clock.
    pub week: Option<u32>,
    /// Every stream, in the order the log first has it.
    pub streams: Vec<StreamInfo>,
    /// What the reader says of the file (dropouts, a truncated tail, skipped bytes).
    pub notes: Vec<String>,
    /// The command line that navigates the log (argument by argument), if it can be
    /// navigated.
    pub command: Option<Vec<String>>,
    /// Why there is no command line, or what to know about it.
    pub command_note: Option<String>,
}

/// One stream.
#[derive(Debug, Clone, Serialize)]
pub struct StreamInfo {
    /// Its name in the log (`sensor_combined`, `ESF-RAW`, `IMU[0]`, `/imu/data`).
    pub name: String,
    /// `imu`, `gnss`, `baro`, `raw`, `ephemeris`, `reference`, `gnss-velocity`,
    /// `odometry` or `other`.
    pub kind: &'static str,
    /// The bag message type, for a bag's topic.
    pub message_type: Option<String>,
    /// Records (for a stream schuler does not read, messages when the reader counts them).
    pub timing: TimingSummary,
    /// IMU streams: units and axes from the data.
    pub imu: Option<imu::ImuSummary>,
    /// GNSS streams: fix quality.
    pub gnss: Option<GnssSummary>,
    /// Raw GNSS streams: epochs and satellites.
    pub raw: Option<RawSummary>,
    /// The device's own solution: which parts it holds.
    pub reference: Option<ReferenceSummary>,
}

/// A GNSS stream's quality.
#[derive(Debug, Clone, Default, Serialize)]
pub struct GnssSummary {
    /// Fixes.
    pub fixes: u64,
    /// Of those with a velocity.
    pub with_velocity: u64,
    /// Median horizontal σ per axis, `√((σ_N² + σ_E²)/2)` [m].
    pub median_horizontal_std_m: Option<f64>,
    /// Median vertical σ [m].
    pub median_vertical_std_m: Option<f64>,
    /// The first fix: time [s], latitude and longitude [deg], height [m].
    pub first: Option<[f64; 4]>,
    /// Its velocity north, east, down [m/s], if it has one.
    pub first_velocity: Option<[f64; 3]>,
}

/// A raw GNSS stream.
#[derive(Debug, Clone, Default, Serialize)]
pub struct RawSummary {
    /// Epochs.
    pub epochs: u64,
    /// Measurements (satellite and signal) in all.
    pub measurements: u64,
    /// Mean and largest number of satellites per epoch.
    pub satellites_mean: f64,
    /// See `satellites_mean`.
    pub satellites_max: u64,
}

/// The device's own solution.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ReferenceSummary {
    /// Samples with a position.
    pub with_position: u64,
    /// With a velocity.
    pub with_velocity: u64,
    /// With an attitude.
    pub with_attitude: u64,
    /// The first attitude at or after the log's first GNSS fix: time [s], roll,
    /// pitch, yaw [deg] (the start the suggested command takes from the device).
    pub first_attitude: Option<[f64; 4]>,
}

/// The running state of one stream.
#[derive(Default)]
struct Acc {
    timing: Timing,
    imu: Option<imu::ImuAcc>,
    gnss: Option<(GnssSummary, LogMedian, LogMedian)>,
    raw: Option<RawSummary>,
    reference: Option<ReferenceSummary>,
}

impl Acc {
    /// Takes in a record; `first_fix` the time of the log's first GNSS fix, if met.
    fn add(&mut self, record: &LogRecord, first_fix: Option<f64>) {
        if let Some(t) = record.t() {
            self.timing.add(t);
        }
        match record {
            LogRecord::Imu(s) => self.imu.get_or_insert_with(Default::default).add(s),
            LogRecord::Gnss(f) => {
                let (g, h, v) = self.gnss.get_or_insert_with(Default::default);
                g.fixes += 1;
                g.with_velocity += u64::from(f.vel.is_some());
                h.add(((f.pos_std.x.powi(2) + f.pos_std.y.powi(2)) / 2.0).sqrt());
                v.add(f.pos_std.z);
                if g.first.is_none() {
                    let p = f.pos;
                    g.first = Some([f.t, p.lat.to_degrees(), p.lon.to_degrees(), p.h]);
                    g.first_velocity = f.vel.map(|(v, _)| [v.x, v.y, v.z]);
                }
            }
            LogRecord::Raw(e) => {
                let r = self.raw.get_or_insert_with(Default::default);
                let mut sats: Vec<_> = e.measurements.iter().map(|m| m.sat).collect();
                sats.sort_unstable();
                sats.dedup();
                r.epochs += 1;
                r.measurements += e.measurements.len() as u64;
                r.satellites_max = r.satellites_max.max(sats.len() as u64);
                r.satellites_mean += (sats.len() as f64 - r.satellites_mean) / r.epochs as f64;
            }
            LogRecord::Reference(s) => {
                let r = self.reference.get_or_insert_with(Default::default);
                r.with_position += u64::from(s.pos.is_some());
                r.with_velocity += u64::from(s.v_n.is_some());
                r.with_attitude += u64::from(s.att.is_some());
                if r.first_attitude.is_none()
                    && let (Some(a), Some(t0)) = (s.att, first_fix)
                    && s.t >= t0
                {
                    let d = |x: f64| x.to_degrees();
                    r.first_attitude = Some([s.t, d(a.roll), d(a.pitch), d(a.heading_0_2pi())]);
                }
            }
            LogRecord::Baro { .. } | LogRecord::Ephemeris(_) => {}
        }
    }

    fn finish(self, name: String, kind: &'static str) -> StreamInfo {
        StreamInfo {
            name,
            kind,
            message_type: None,
            timing: self.timing.finish(),
            imu: self.imu.map(imu::ImuAcc::finish),
            gnss: self.gnss.map(|(mut g, h, v)| {
                g.median_horizontal_std_m = h.median();
                g.median_vertical_std_m = v.median();
                g
            }),
            raw: self.raw,
            reference: self.reference,
        }
    }
}

/// The name of a stream kind in the inspection.
pub fn kind_name(kind: StreamKind) -> &'static str {
    match kind {
        StreamKind::Imu => "imu",
        StreamKind::Gnss => "gnss",
        StreamKind::Baro => "baro",
        StreamKind::Raw => "raw",
        StreamKind::Ephemeris => "ephemeris",
        StreamKind::Reference => "reference",
        StreamKind::Other => "other",
    }
}

/// Inspects the log at `path` (its format told by content).
pub fn inspect(path: &Path) -> Result<Inspection> {
    use schuler_io::logs::{dataflash, gnss_logger, ubx, ulog};
    let format = detect(path)?;
    let mut out = match format {
        LogFormat::Ulog => {
            let mut r = ulog::UlogReader::open(path)?;
            let mut i = inspect_log(path, format, &mut r)?;
            i.notes = notes::ulog(r.report());
            i
        }
        LogFormat::Ubx => {
            let mut r = ubx::UbxReader::open(path)?;
            let mut i = inspect_log(path, format, &mut r)?;
            i.notes = notes::ubx(r.report());
            for (s, &n) in i.streams.iter_mut().zip(r.counts()) {
                if s.kind == "other" {
                    s.timing.records = n;
                }
            }
            i
        }
        LogFormat::Dataflash => {
            let mut r = dataflash::DataflashReader::open(path)?;
            let mut i = inspect_log(path, format, &mut r)?;
            i.notes = notes::dataflash(r.report());
            i
        }
        LogFormat::GnssLogger => {
            let mut r = gnss_logger::GnssLoggerReader::open(path)?;
            let mut i = inspect_log(path, format, &mut r)?;
            i.notes = notes::gnss_logger(r.clock_tie(), &r.stats());
            i
        }
        LogFormat::Ros1Bag | LogFormat::Mcap => inspect_bag(path, format)?,
    };
    let (command, note) = command::suggest(path, &out);
    out.command = command;
    out.command_note = note;
    Ok(out)
}

/// One pass over a device log's records.
fn inspect_log<R: LogReader>(path: &Path, format: LogFormat, reader: &mut R) -> Result<Inspection> {
    let mut accs: Vec<Acc> = Vec::new();
    let mut first_fix = None;
    for item in reader.by_ref() {
        let item = item?;
        if accs.len() <= item.stream {
            accs.resize_with(item.stream + 1, Acc::default);
        }
        if let (LogRecord::Gnss(f), None) = (&item.record, first_fix) {
            first_fix = Some(f.t);
        }
        accs[item.stream].add(&item.record, first_fix);
    }
    let streams = reader
        .streams()
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let acc = if i < accs.len() {
                std::mem::take(&mut accs[i])
            } else {
                Acc::default()
            };
            acc.finish(s.name.clone(), kind_name(s.kind))
        })
        .collect();
    let (time_scale, week) = match reader.time_scale() {
        TimeScale::GpsSecondsOfWeek { week } => ("gps-seconds-of-week", Some(week)),
        TimeScale::Device => ("device", None),
    };
    Ok(Inspection {
        schema: SCHEMA,
        path: path.display().to_string(),
        format: format.key(),
        format_name: format.name(),
        time_scale,
        week,
        streams,
        notes: Vec::new(),
        command: None,
        command_note: None,
    })
}

/// One pass over a bag: each topic's timing by log time.
fn inspect_bag(path: &Path, format: LogFormat) -> Result<Inspection> {
    // By the topic's place; its name kept to meet the scan's summaries.
    let mut timings: Vec<Option<(String, Timing)>> = Vec::new();
    let topics = schuler_io::bag::info::scan(path, |m| {
        if timings.len() <= m.topic_index {
            timings.resize_with(m.topic_index + 1, || None);
        }
        let (_, timing) =
            timings[m.topic_index].get_or_insert_with(|| (m.topic.name.clone(), Timing::default()));
        timing.add(m.log_time as f64 * 1e-9);
        Ok(())
    })?;
    let streams = topics
        .iter()
        .map(|t| {
            let timing = timings
                .iter_mut()
                .flatten()
                .find(|(name, _)| *name == t.topic.name)
                .map(|(_, x)| std::mem::take(x))
                .unwrap_or_default();
            StreamInfo {
                name: t.topic.name.clone(),
                kind: match Kind::of_type(&t.topic.type_name) {
                    Some(Kind::Imu) => "imu",
                    Some(Kind::Gnss) => "gnss",
                    Some(Kind::GnssVel) => "gnss-velocity",
                    Some(Kind::Baro) => "baro",
                    Some(Kind::Odometry) => "odometry",
                    None => "other",
                },
                message_type: Some(t.topic.type_name.clone()),
                timing: timing.finish(),
                imu: None,
                gnss: None,
                raw: None,
                reference: None,
            }
        })
        .collect();
    Ok(Inspection {
        schema: SCHEMA,
        path: path.display().to_string(),
        format: format.key(),
        format_name: format.name(),
        time_scale: "bag-stamps",
        week: None,
        streams,
        notes: Vec::new(),
        command: None,
        command_note: None,
    })
}
