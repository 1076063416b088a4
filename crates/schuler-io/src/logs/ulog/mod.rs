//! PX4 ULog (`.ulg`, and `.ulg.gz`): a streaming reader of the topics schuler uses
//! (see [`topics`]), after the ULog file format of the PX4 developer guide
//! ("ULog File Format": header, definitions `F` `I` `M` `P` `Q`, data `A` `R` `D` `L`
//! `C` `S` `O`, flag bits `B` and appended data).
//!
//! Our own reader rather than a crate: `yule_log` 0.4 (MIT, the maintained streaming
//! one) read PX4/pyulog's `sample.ulg` at 11 MB/s on the project's machine, pulls in
//! `regex`, `env_logger` and `jiff` (18 crates, 100 s of CPU to build), and prints
//! format lines to standard output; `px4-ulog` and `ulog-rs` are unmaintained or
//! early. The format is small (about 500 lines here), and our own keeps errors in the
//! project's shape: file, byte offset (in [`InputError::line`]) and field.
//!
//! Reading: [`UlogReader::open`] reads the file once ahead as far as the first 3-D GNSS
//! fix with a UTC time (the data messages of other topics skipped without decoding),
//! to tie the autopilot's clock to GPS time ([`clock`]); then it streams every record
//! in file order. Streams are the logged topics, one per subscription (`name`, or
//! `name[i]` for instance `i` > 0). What the log says about itself (dropouts, log
//! messages, gaps of the IMU stream) is in [`UlogReader::report`].
//!
//! Refused, with the byte offset: a file that does not start with the ULog magic, a
//! message cut short by the end of the file, a message type that is no letter, a data
//! message for a subscription never announced or of a size its format does not allow,
//! a sync message with wrong magic bytes, a topic schuler uses lacking a field it needs,
//! and an IMU stream that is not continuous: when the median of the first
//! [`CONTINUITY_SAMPLES`] ratios of integration interval to sample spacing is below
//! [`MIN_COVERAGE`], the log was written by a logging profile that keeps one sample in
//! several (the others' increments are lost), and strapdown integration of it would be
//! wrong; the error ([`InputErrorKind::LayoutMismatch`]) says so.

/// The device-to-GPS clock, shared with the DataFlash reader ([`crate::logs::clock`]).
pub use crate::logs::clock;
pub mod container;
pub mod format;
pub mod topics;

use crate::formats::InputError;
use crate::formats::error::InputErrorKind;
use crate::logs::{LogItem, LogReader, LogRecord, Stream, TimeScale};
use clock::{Clock, GpsTie};
use container::{Container, Frame, SYNC_MAGIC, error_at, printable};
use format::{Format, Layout, parse_format};
use std::collections::{BTreeMap, HashMap, VecDeque};
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};
use topics::{Decoded, Decoder, Skip};

/// IMU samples whose spacing the continuity check looks at (their median).
pub const CONTINUITY_SAMPLES: usize = 16;

/// Below this median ratio of integration interval to sample spacing the IMU stream is
/// not continuous (a full-rate log has ratios near 1; a decimated profile's, such as
/// 4 ms integrated every 10 ms, 0.4 or less).
pub const MIN_COVERAGE: f64 = 0.5;

/// Items held at most while the continuity of the IMU stream is undecided (a stream
/// of fewer samples is decided on those it has).
const MAX_HELD: usize = 1 << 16;

/// A spacing longer than this many integration intervals is a gap of the IMU stream.
const GAP_FACTOR: f64 = 1.5;

/// What a log says about itself, and what the reader left out.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UlogReport {
    /// The file format version (header byte 7).
    pub version: u8,
    /// The logger's start [µs, device clock].
    pub start_us: u64,
    /// Appended data sections the flag bits announce.
    pub appended_sections: usize,
    /// Dropout messages: the logger lost data (its buffer overflowed).
    pub dropouts: u32,
    /// Their total duration [s].
    pub dropout_total_s: f64,
    /// The longest one [s].
    pub dropout_longest_s: f64,
    /// Log text messages (`L` and tagged `C`).
    pub log_messages: u32,
    /// Of those, warnings and worse (level ≤ 4, syslog levels).
    pub log_warnings: u32,
    /// Parameter messages (`P`, `Q`).
    pub parameters: u32,
    /// Messages of a type this reader does not know (a letter; skipped).
    pub unknown_messages: u32,
    /// Sync messages.
    pub syncs: u32,
    /// The text information messages (`char[]` values of `I`: `sys_name`, `ver_hw`…).
    pub info: BTreeMap<String, String>,
    /// The GNSS fix that tied the device clock to GPS time, if any.
    pub gps_tie: Option<GpsTie>,
    /// GNSS messages without a 3-D fix (no record).
    pub gnss_without_fix: u32,
    /// IMU samples without accelerometer data or with a zero interval (no record).
    pub imu_incomplete: u32,
    /// Reference samples not valid (zero quaternion, invalid velocity; no record).
    pub reference_invalid: u32,
    /// Gaps of the IMU stream (spacing > 1.5 integration intervals) and their total
    /// uncovered time [s].
    pub imu_gaps: u32,
    /// Total time the IMU stream does not cover [s].
    pub imu_gap_s: f64,
}

/// One subscription (`A` message).
struct Sub {
    stream: usize,
    name: String,
    decoder: Decoder,
    min_size: usize,
    size: usize,
}

/// The continuity check of the IMU stream and its gap count.
#[derive(Default)]
struct Continuity {
    /// (device µs, interval [s]) of the first samples, until decided.
    first: Vec<(u64, f64)>,
    decided: bool,
    last_us: Option<u64>,
}

/// A streaming reader of a PX4 ULog file.
pub struct UlogReader {
    path: PathBuf,
    c: Container<Box<dyn Read>>,
    size: u64,
    consumed: std::rc::Rc<std::cell::Cell<u64>>,
    formats: HashMap<String, Format>,
    subs: Vec<Option<Sub>>,
    streams: Vec<Stream>,
    stream_ids: HashMap<(String, u8), usize>,
    gnss_topic: Option<String>,
    clock: Clock,
    /// Only look for the GPS tie (the pass ahead).
    tie_only: bool,
    imu: Continuity,
    held: VecDeque<LogItem>,
    failed: bool,
    report: UlogReport,
}

/// Counts the bytes read from the file (progress of a gzip file).
struct Counting<R> {
    r: R,
    n: std::rc::Rc<std::cell::Cell<u64>>,
}

impl<R: Read> Read for Counting<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let k = self.r.read(buf)?;
        self.n.set(self.n.get() + k as u64);
        Ok(k)
    }
}

impl UlogReader {
    /// Opens `path` (plain or gzip, told by its first bytes), reads ahead for the GPS
    /// tie and stands at the first message.
    pub fn open(path: &Path) -> Result<Self, InputError> {
        let tie = {
            let mut ahead = Self::open_pass(path, true)?;
            ahead.find_tie()?
        };
        let mut r = Self::open_pass(path, false)?;
        r.clock = Clock::new(r.c.start_us, tie);
        r.report.gps_tie = tie;
        Ok(r)
    }

    fn open_pass(path: &Path, tie_only: bool) -> Result<Self, InputError> {
        let io =
            |e: std::io::Error| InputError::new(InputErrorKind::Io, path, 0, None, e.to_string());
        let mut file = std::fs::File::open(path).map_err(io)?;
        let size = file.metadata().map_err(io)?.len();
        let mut magic = [0u8; 2];
        let gz = file.read(&mut magic).map_err(io)? == 2 && magic == [0x1f, 0x8b];
        std::io::Seek::rewind(&mut file).map_err(io)?;
        let consumed = std::rc::Rc::new(std::cell::Cell::new(0));
        let counting = Counting {
            r: file,
            n: consumed.clone(),
        };
        let source: Box<dyn Read> = if gz {
            Box::new(BufReader::with_capacity(
                1 << 20,
                flate2::read::MultiGzDecoder::new(BufReader::with_capacity(1 << 16, counting)),
            ))
        } else {
            Box::new(BufReader::with_capacity(1 << 20, counting))
        };
        let c = Container::open(source, path)?;
        let report = UlogReport {
            version: c.version,
            start_us: c.start_us,
            ..UlogReport::default()
        };
        Ok(Self {
            path: path.to_path_buf(),
            c,
            size,
            consumed,
            formats: HashMap::new(),
            subs: Vec::new(),
            streams: Vec::new(),
            stream_ids: HashMap::new(),
            gnss_topic: None,
            clock: Clock::Device,
            tie_only,
            imu: Continuity::default(),
            held: VecDeque::new(),
            failed: false,
            report,
        })
    }

    /// What the log has said about itself so far (all of it once the iterator ended).
    pub fn report(&self) -> &UlogReport {
        &self.report
    }

    /// The pass ahead: the first GNSS message with a 3-D fix and a UTC time.
    fn find_tie(&mut self) -> Result<Option<GpsTie>, InputError> {
        while let Some(frame) = self.c.next_frame()? {
            if let Some((_, Decoded::Gnss { us, utc_us, fix })) = self.message(frame)?
                && fix.is_some()
                && let Some(tie) = GpsTie::new(us, utc_us)
            {
                return Ok(Some(tie));
            }
        }
        Ok(None)
    }

    /// Takes in one message; a decoded data message with its stream index.
    fn message(&mut self, frame: Frame) -> Result<Option<(usize, Decoded)>, InputError> {
        let Frame { kind, offset } = frame;
        let p = self.c.payload();
        let short = |need: usize, what: &str| -> Result<(), InputError> {
            if p.len() < need {
                Err(self.c.garbled(
                    offset,
                    None,
                    format!(
                        "{what} message of {} bytes, at least {need} expected",
                        p.len()
                    ),
                ))
            } else {
                Ok(())
            }
        };
        match kind {
            b'D' => {
                short(2, "data")?;
                let id = usize::from(u16::from_le_bytes([p[0], p[1]]));
                let Some(sub) = self.subs.get(id).and_then(Option::as_ref) else {
                    return Err(self.c.garbled(
                        offset,
                        Some("msg_id"),
                        format!("data for msg_id {id}, which no ADD_LOGGED_MSG announced"),
                    ));
                };
                if self.tie_only && !matches!(sub.decoder, Decoder::Gnss(_)) {
                    return Ok(None);
                }
                let data = &p[2..];
                if data.len() < sub.min_size || data.len() > sub.size {
                    return Err(self.c.garbled(
                        offset,
                        Some(&sub.name),
                        format!(
                            "data message of {} bytes for topic {}, whose format has {} \
                             ({} without trailing padding)",
                            data.len(),
                            sub.name,
                            sub.size,
                            sub.min_size
                        ),
                    ));
                }
                Ok(sub.decoder.decode(data).map(|d| (sub.stream, d)))
            }
            b'F' => {
                let text = String::from_utf8_lossy(p);
                let f =
                    parse_format(&text).map_err(|e| self.c.garbled(offset, Some("format"), e))?;
                self.formats.insert(f.name.clone(), f);
                Ok(None)
            }
            b'A' => {
                short(3, "ADD_LOGGED_MSG")?;
                let multi_id = p[0];
                let id = usize::from(u16::from_le_bytes([p[1], p[2]]));
                let name = String::from_utf8_lossy(&p[3..]).into_owned();
                self.subscribe(offset, multi_id, id, name)?;
                Ok(None)
            }
            b'R' => {
                short(2, "REMOVE_LOGGED_MSG")?;
                let id = usize::from(u16::from_le_bytes([p[0], p[1]]));
                if let Some(s) = self.subs.get_mut(id) {
                    *s = None;
                }
                Ok(None)
            }
            b'I' => {
                short(1, "INFO")?;
                let n = usize::from(p[0]);
                short(1 + n, "INFO")?;
                let key = String::from_utf8_lossy(&p[1..1 + n]);
                if let Some((ty, name)) = key.split_once(' ')
                    && ty.starts_with("char[")
                {
                    let value = String::from_utf8_lossy(&p[1 + n..]);
                    let value = value.trim_end_matches('\0').to_owned();
                    self.report.info.insert(name.to_owned(), value);
                }
                Ok(None)
            }
            b'M' => {
                short(2, "INFO_MULTIPLE")?;
                Ok(None)
            }
            b'P' | b'Q' => {
                short(2, "PARAMETER")?;
                self.report.parameters += 1;
                Ok(None)
            }
            b'L' | b'C' => {
                let need = if kind == b'L' { 9 } else { 11 };
                short(need, "LOGGING")?;
                self.report.log_messages += 1;
                // Levels are ASCII digits '0'..'7' (syslog): ≤ '4' is a warning or worse.
                if p[0] <= b'4' {
                    self.report.log_warnings += 1;
                }
                Ok(None)
            }
            b'S' => {
                if p.len() < 8 || p[..8] != SYNC_MAGIC {
                    return Err(self.c.garbled(
                        offset,
                        Some("sync_magic"),
                        "sync message without the sync magic bytes: the file is garbled",
                    ));
                }
                self.report.syncs += 1;
                Ok(None)
            }
            b'O' => {
                short(2, "DROPOUT")?;
                let s = f64::from(u16::from_le_bytes([p[0], p[1]])) / 1000.0;
                self.report.dropouts += 1;
                self.report.dropout_total_s += s;
                self.report.dropout_longest_s = self.report.dropout_longest_s.max(s);
                Ok(None)
            }
            k if k.is_ascii_alphabetic() => {
                self.report.unknown_messages += 1;
                Ok(None)
            }
            k => Err(self.c.garbled(
                offset,
                Some("msg_type"),
                format!(
                    "message type {} is no ULog message type: the file is garbled",
                    printable(k)
                ),
            )),
        }
    }

    /// Takes in `ADD_LOGGED_MSG` (`multi_id`, `msg_id`, topic `name`).
    fn subscribe(
        &mut self,
        offset: u64,
        multi_id: u8,
        id: usize,
        name: String,
    ) -> Result<(), InputError> {
        let layout =
            Layout::of(&name, &self.formats).map_err(|e| self.c.garbled(offset, Some(&name), e))?;
        // The GNSS topic: `vehicle_gps_position` if the log defines it (the autopilot's
        // selected or blended receiver), else `sensor_gps` (PX4 1.14 on may log only
        // the receivers). Formats come before any subscription.
        let gnss = self
            .gnss_topic
            .get_or_insert_with(|| {
                if self.formats.contains_key("vehicle_gps_position") {
                    "vehicle_gps_position".to_owned()
                } else {
                    "sensor_gps".to_owned()
                }
            })
            .clone();
        let decoder = Decoder::new(&name, multi_id, &layout, &gnss).map_err(|(field, e)| {
            error_at(
                InputErrorKind::LayoutMismatch,
                &self.path,
                offset,
                Some(&field),
                e,
            )
        })?;
        let key = (name.clone(), multi_id);
        let stream = match self.stream_ids.get(&key) {
            Some(&s) => s,
            None => {
                self.streams.push(Stream {
                    name: if multi_id == 0 {
                        name.clone()
                    } else {
                        format!("{name}[{multi_id}]")
                    },
                    kind: decoder.kind(),
                });
                self.stream_ids.insert(key, self.streams.len() - 1);
                self.streams.len() - 1
            }
        };
        if self.subs.len() <= id {
            self.subs.resize_with(id + 1, || None);
        }
        self.subs[id] = Some(Sub {
            stream,
            name,
            decoder,
            min_size: layout.min_size,
            size: layout.size,
        });
        Ok(())
    }

    /// The next item to hand out, reading messages as needed; `None` at the end.
    fn step(&mut self) -> Result<Option<LogItem>, InputError> {
        loop {
            if self.imu.decided
                && let Some(item) = self.held.pop_front()
            {
                return Ok(Some(item));
            }
            let next = self.c.next_frame()?;
            self.report.appended_sections = self.c.appended_sections;
            let Some(frame) = next else {
                if !self.imu.decided {
                    self.decide_continuity(self.c.position())?;
                    continue;
                }
                return Ok(None);
            };
            let Some((stream, decoded)) = self.message(frame)? else {
                continue;
            };
            let record = match decoded {
                Decoded::Record { us, mut record } => {
                    topics::set_time(&mut record, self.clock.seconds(us));
                    record
                }
                Decoded::Gnss { us, fix, .. } => match fix {
                    Some(mut f) => {
                        f.t = self.clock.seconds(us);
                        LogRecord::Gnss(f)
                    }
                    None => {
                        self.report.gnss_without_fix += 1;
                        continue;
                    }
                },
                Decoded::Imu { us, dt, mut sample } => {
                    self.imu_sample(frame.offset, us, dt)?;
                    sample.t = self.clock.seconds(us);
                    LogRecord::Imu(sample)
                }
                Decoded::Skipped(Skip::ImuIncomplete) => {
                    self.report.imu_incomplete += 1;
                    continue;
                }
                Decoded::Skipped(Skip::ReferenceInvalid) => {
                    self.report.reference_invalid += 1;
                    continue;
                }
            };
            let item = LogItem { stream, record };
            // Items pass at once but between the first IMU sample and the decision.
            if (self.imu.decided || self.imu.first.is_empty()) && self.held.is_empty() {
                return Ok(Some(item));
            }
            self.held.push_back(item);
            if self.imu.first.len() > CONTINUITY_SAMPLES || self.held.len() > MAX_HELD {
                self.decide_continuity(frame.offset)?;
            }
        }
    }

    /// Takes in an IMU sample at device time `us` with interval `dt` [s]: its time
    /// must increase; before the continuity decision it is kept for it, after it a
    /// spacing of more than 1.5 intervals counts as a gap.
    fn imu_sample(&mut self, offset: u64, us: u64, dt: f64) -> Result<(), InputError> {
        if let Some(last) = self.imu.last_us {
            if us <= last {
                return Err(error_at(
                    InputErrorKind::TimeNotIncreasing,
                    &self.path,
                    offset,
                    Some("sensor_combined.timestamp"),
                    format!("IMU time {us} µs after {last} µs: not increasing"),
                ));
            }
            let spacing = (us - last) as f64 * 1e-6;
            if self.imu.decided && spacing > GAP_FACTOR * dt {
                self.report.imu_gaps += 1;
                self.report.imu_gap_s += spacing - dt;
            }
        }
        self.imu.last_us = Some(us);
        if !self.imu.decided {
            self.imu.first.push((us, dt));
        }
        Ok(())
    }

    /// Decides whether the IMU stream is continuous, from its first samples.
    fn decide_continuity(&mut self, offset: u64) -> Result<(), InputError> {
        self.imu.decided = true;
        let first = std::mem::take(&mut self.imu.first);
        let mut ratios: Vec<f64> = first
            .windows(2)
            .map(|w| w[1].1 / ((w[1].0 - w[0].0) as f64 * 1e-6))
            .collect();
        if ratios.is_empty() {
            return Ok(());
        }
        ratios.sort_by(f64::total_cmp);
        let median = ratios[ratios.len() / 2];
        if median < MIN_COVERAGE {
            let spacing: Vec<f64> = first
                .windows(2)
                .map(|w| (w[1].0 - w[0].0) as f64 * 1e-3)
                .collect();
            let dt_ms = first[first.len() / 2].1 * 1e3;
            let mut sorted = spacing.clone();
            sorted.sort_by(f64::total_cmp);
            return Err(error_at(
                InputErrorKind::LayoutMismatch,
                &self.path,
                offset,
                Some("sensor_combined"),
                format!(
                    "the IMU stream is not continuous: its samples integrate over {dt_ms:.1} \
                     ms but are {:.1} ms apart (median of the first {}), so the logging \
                     profile kept one sample in several and the others' increments are \
                     lost; unusable for strapdown integration (log sensor_combined at its \
                     full rate, e.g. SDLOG_PROFILE with 'high rate' or 'debug')",
                    sorted[sorted.len() / 2],
                    spacing.len()
                ),
            ));
        }
        Ok(())
    }
}

impl Iterator for UlogReader {
    type Item = Result<LogItem, InputError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        match self.step() {
            Ok(item) => item.map(Ok),
            Err(e) => {
                self.failed = true;
                self.held.clear();
                Some(Err(e))
            }
        }
    }
}

impl LogReader for UlogReader {
    fn streams(&self) -> &[Stream] {
        &self.streams
    }

    fn time_scale(&self) -> TimeScale {
        self.clock.scale()
    }

    fn progress(&self) -> (u64, u64) {
        (self.consumed.get(), self.size)
    }
}
