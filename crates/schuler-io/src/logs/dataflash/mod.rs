//! ArduPilot DataFlash logs (`.bin`, and `.bin.gz`): a streaming reader of the
//! messages schuler uses, after ArduPilot's `AP_Logger` format (`LogStructure.h`: the
//! `FMT` messages define every message; see [`container`] and [`format`]).
//!
//! | message | record | stream |
//! |---|---|---|
//! | `IMU` | [`LogRecord::Imu`] | `IMU[i]` per instance `i` (`IMU`, `IMU2`, `IMU3` in old logs) |
//! | `GPS` with its `GPA` | [`LogRecord::Gnss`] | `GPS[i]` (`GPS`) |
//! | `BARO` | [`LogRecord::Baro`] | `BARO[i]` |
//! | `XKF1` core 0 (`NKF1` of EKF2 in old logs) | [`LogRecord::Reference`] | `XKF1[0]` |
//!
//! Every other message type, and every other EKF core, is a stream of kind
//! [`StreamKind::Other`] under its name (`FMT`, `PARM`, `XKF1[1]`). Streams of a type
//! with an instance column (`FMTU` unit `#`) are named `NAME[i]` as pymavlink names
//! them; others `NAME`.
//!
//! **Conversions** ([`records`]):
//! - IMU: the message holds the INS's latest (low-pass filtered) rates `GyrX..Z`
//!   [rad/s] and specific force `AccX..Z` [m/s²] in ArduPilot's body frame, which is
//!   FRD. They become increments over the spacing of the stream's `TimeUS`:
//!   `dθ = ω·dt`, `dv = f·dt`, `dt = TimeUS_k − TimeUS_(k−1)` (the message has no
//!   integration interval of its own; `GHz`/`AHz` are the sensors' rates, not the
//!   logging rate). This is exact for rates constant over the interval; at the logging
//!   rates of `INS_LOG`/`LOG_BITMASK` (25–400 Hz) it integrates a filtered and
//!   decimated signal, good for navigation of a smooth vehicle, not for vibration.
//!   The first sample of each instance, and a sample whose spacing is not positive or
//!   longer than [`MAX_IMU_GAP_S`], only starts the stream (no record;
//!   [`DataflashReport::imu_restarts`]).
//! - GNSS: `GPS` messages with `Status` ≥ 3 (3-D fix or better), each completed by
//!   the `GPA` of the same instance and `TimeUS` that ArduPilot writes right after it:
//!   position `Lat`, `Lng` with the height `AEl` above the ellipsoid where `GPA` has it
//!   (ArduPilot 4.5 on), else `Alt` above mean sea level (counted in
//!   [`DataflashReport::gnss_msl_height`]: the geoid's height, tens of metres, stays in
//!   it); standard deviations `HAcc`, `HAcc`, `VAcc`; velocity north, east, down
//!   `Spd·cos GCrs`, `Spd·sin GCrs`, `VZ` with `SAcc` on each axis (down: 0 with
//!   [`crate::formats::nmea::UNMEASURED_VD_STD`] when `VV` says it is not measured).
//!   A fix without its `GPA`, or with `HAcc` or `VAcc` 0 (unknown), gives no record
//!   ([`DataflashReport::gnss_without_accuracy`]); `SAcc` 0 gives a fix without velocity.
//! - Barometer: `BARO.Alt`, ArduPilot's barometric altitude **relative to the
//!   ground calibration at boot** (0 m where the autopilot started, not above the
//!   ellipsoid nor mean sea level): a barometer bias state must absorb the start's
//!   height.
//! - Reference: `XKF1` of EKF3 core 0 (`C` = 0): attitude `Roll`, `Pitch`, `Yaw` [deg],
//!   velocity `VN`, `VE`, `VD`, and, once an `ORGN` message of type 0 has given the EKF
//!   origin, position `PN`, `PE`, `PD` from that origin as ArduPilot turns it into a
//!   location ([`records::offset_location`]; the height above mean sea level, as the
//!   origin's). Before an origin the reference has no position.
//!
//! **Clock.** GPS seconds of week through the first `GPS` message with a 3-D fix and a
//! week (`GWk` > 0), found by a pass ahead: `gps_µs = GWk·604 800·10⁶ + GMS·10³` pairs
//! with its `TimeUS`, and [`crate::logs::clock::Clock`] (shared with the ULog reader)
//! maps every `TimeUS` by that one offset. ArduPilot stamps `GPS.TimeUS` when the
//! receiver's message is taken in, so the tie is good to the receiver's output latency
//! (tens of ms), not better. A log without such a fix is on the device clock
//! ([`TimeScale::Device`], seconds since boot).
//!
//! **Bad input** ([`container`]): a log not beginning with `A3 95`, a missing header
//! or an undefined message type (away from the log's end), an `FMT` whose format
//! characters are unknown or do not add up to its length, a type schuler reads that
//! lacks a column it needs, and a negative time are refused naming the byte offset
//! (in [`InputError::line`]) and the field; a message cut by the end of the log, and
//! garbage in its last 528 bytes, end it and are reported
//! ([`DataflashReport::ending`]).
//!
//! Our own reader: no maintained Rust crate reads DataFlash (the format is small, and
//! ours keeps errors in the project's shape).

pub mod container;
pub mod format;
pub mod records;

use super::clock::Clock;
use super::{LogItem, LogReader, LogRecord, ReferenceSample, Stream, StreamKind, TimeScale};
use crate::formats::InputError;
use crate::formats::error::InputErrorKind;
use crate::formats::nmea::UNMEASURED_VD_STD;
use container::{Container, Ending, FMT_TYPE, Message, error_at};
use nalgebra::Vector3;
use records::{Decoded, Decoder, Gpa, Gps, Role};
use schuler::earth::Geodetic;
use schuler::filter::GnssFix;
use schuler::imu::ImuSample;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

/// An IMU stream's spacing longer than this [s] restarts it (no sample spans it).
pub const MAX_IMU_GAP_S: f64 = 0.5;

/// The `GPS` message that tied the autopilot's clock to GPS time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DataflashTie {
    /// Its `TimeUS` [µs since boot].
    pub device_us: u64,
    /// Its GPS week.
    pub week: u32,
    /// Its milliseconds of week.
    pub ms: u32,
}

/// What the reader met, skipped or could not use.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DataflashReport {
    /// Messages read, `FMT` included.
    pub messages: u64,
    /// `FMT` messages.
    pub formats: u64,
    /// How the log ended: a cut message or garbage in its last bytes.
    pub ending: Ending,
    /// The fix that tied the clock to GPS time.
    pub gps_tie: Option<DataflashTie>,
    /// `GPS` messages without a 3-D fix (no record).
    pub gnss_without_fix: u64,
    /// Fixes without a `GPA` or with unknown accuracies (no record).
    pub gnss_without_accuracy: u64,
    /// Fixes whose height is above mean sea level (no `AEl`).
    pub gnss_msl_height: u64,
    /// IMU stream starts and restarts (first samples, gaps, time going back).
    pub imu_restarts: u64,
    /// Reference samples before the EKF origin was known (given without position).
    pub reference_without_origin: u64,
}

/// One stream: a message type and instance.
struct StreamState {
    /// The instance value (`None` for a type without an instance column).
    instance: Option<i64>,
    /// Index into `streams`.
    index: usize,
    /// The IMU's last time [µs].
    last_us: Option<u64>,
}

/// What the reader knows of a message type.
#[derive(Default)]
struct TypeState {
    decoder: Option<Decoder>,
    streams: Vec<StreamState>,
}

/// A `GPS` message waiting for its `GPA`.
struct Pending {
    instance: Option<i64>,
    stream: usize,
    gps: Gps,
}

/// A streaming reader of an ArduPilot DataFlash log.
pub struct DataflashReader {
    path: PathBuf,
    c: Container<Box<dyn Read>>,
    size: u64,
    consumed: std::rc::Rc<std::cell::Cell<u64>>,
    types: Vec<TypeState>,
    streams: Vec<Stream>,
    clock: Clock,
    /// Only look for the GPS tie (the pass ahead).
    tie_only: bool,
    first_us: Option<u64>,
    pending: Vec<Pending>,
    origin: Option<(f64, f64, f64)>,
    failed: bool,
    report: DataflashReport,
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

impl DataflashReader {
    /// Opens `path` (plain or gzip, told by its first bytes), reads ahead for the GPS
    /// tie and stands at the first message.
    pub fn open(path: &Path) -> Result<Self, InputError> {
        let (tie, first_us) = {
            let mut ahead = Self::open_pass(path, true)?;
            let tie = ahead.find_tie()?;
            if ahead.report.messages == 0 {
                return Err(error_at(
                    InputErrorKind::NoData,
                    path,
                    0,
                    None,
                    "the log holds no complete message",
                ));
            }
            (tie, ahead.first_us)
        };
        let mut r = Self::open_pass(path, false)?;
        if let Some(t) = tie {
            let gps_us = u64::from(t.week) * 604_800_000_000 + u64::from(t.ms) * 1000;
            r.clock = Clock::from_gps_us(first_us.unwrap_or(t.device_us), t.device_us, gps_us);
        }
        r.report.gps_tie = tie;
        Ok(r)
    }

    fn open_pass(path: &Path, tie_only: bool) -> Result<Self, InputError> {
        let io = |e: std::io::Error| error_at(InputErrorKind::Io, path, 0, None, e);
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
            Box::new(flate2::read::MultiGzDecoder::new(BufReader::with_capacity(
                1 << 16,
                counting,
            )))
        } else {
            Box::new(counting)
        };
        Ok(Self {
            path: path.to_path_buf(),
            c: Container::new(source, path),
            size,
            consumed,
            types: (0..256).map(|_| TypeState::default()).collect(),
            streams: Vec::new(),
            clock: Clock::Device,
            tie_only,
            first_us: None,
            pending: Vec::new(),
            origin: None,
            failed: false,
            report: DataflashReport::default(),
        })
    }

    /// What the reader has met so far (all of it once the iterator has ended).
    pub fn report(&self) -> &DataflashReport {
        &self.report
    }

    /// The pass ahead: the first `GPS` message with a 3-D fix and a week, and the
    /// first time of the log.
    fn find_tie(&mut self) -> Result<Option<DataflashTie>, InputError> {
        while let Some(m) = self.c.next_message()? {
            self.report.messages += 1;
            if m.ty == FMT_TYPE {
                self.types[usize::from(self.c.body()[0])].decoder = None;
                continue;
            }
            if self.first_us.is_none()
                && let Some(t) = self.c.format(m.ty).and_then(records::TimeField::of)
            {
                self.first_us = t.us(self.c.body());
            }
            let is_gps = self
                .c
                .format(m.ty)
                .is_some_and(|f| records::role_of(&f.name) == Role::Gps);
            if !is_gps {
                continue;
            }
            if let Some((_, Decoded::Gps(g))) = self.decode(m)?
                && g.status >= 3
                && g.week > 0
                && let (Ok(week), Ok(ms)) = (u32::try_from(g.week), u32::try_from(g.ms))
            {
                return Ok(Some(DataflashTie {
                    device_us: g.us,
                    week,
                    ms,
                }));
            }
        }
        Ok(None)
    }

    /// Decodes message `m` with its type's decoder (made at the type's first message,
    /// after its `FMTU`), and finds or makes its stream.
    fn decode(&mut self, m: Message) -> Result<Option<(usize, Decoded)>, InputError> {
        if m.ty == FMT_TYPE {
            // A (re)definition: the type's decoder is made anew from it.
            self.types[usize::from(self.c.body()[0])].decoder = None;
        }
        let Some(f) = self.c.format(m.ty) else {
            return Ok(None);
        };
        let ts = &mut self.types[usize::from(m.ty)];
        let body = self.c.body();
        let instance = f.instance_field().map(|i| i.int(body).unwrap_or(-1));
        let decoder = match &ts.decoder {
            Some(d) => d,
            None => {
                let d = Decoder::new(f).map_err(|(field, e)| {
                    error_at(
                        InputErrorKind::LayoutMismatch,
                        &self.path,
                        m.offset,
                        Some(&field),
                        e,
                    )
                })?;
                ts.decoder.insert(d)
            }
        };
        let stream = match ts.streams.iter().find(|s| s.instance == instance) {
            Some(s) => s.index,
            None => {
                let role = records::role_of(&f.name);
                let kind = match role {
                    Role::Imu => StreamKind::Imu,
                    Role::Gps => StreamKind::Gnss,
                    Role::Baro => StreamKind::Baro,
                    Role::Ekf if instance.unwrap_or(0) == 0 => StreamKind::Reference,
                    _ => StreamKind::Other,
                };
                let name = match instance {
                    Some(i) => format!("{}[{i}]", f.name),
                    None => f.name.clone(),
                };
                self.streams.push(Stream { name, kind });
                let index = self.streams.len() - 1;
                ts.streams.push(StreamState {
                    instance,
                    index,
                    last_us: None,
                });
                index
            }
        };
        // Other streams are listed, not decoded; GPA and ORGN serve the others.
        if self.streams[stream].kind == StreamKind::Other
            && !matches!(decoder, Decoder::Gpa { .. } | Decoder::Origin { .. })
        {
            return Ok(None);
        }
        let decoded = decoder.decode(&f.name, body).map_err(|field| {
            error_at(
                InputErrorKind::OutOfDomain,
                &self.path,
                m.offset,
                Some(&field),
                format!("{field} is negative"),
            )
        })?;
        Ok(decoded.map(|d| (stream, d)))
    }

    /// The next item to hand out, reading messages as needed; `None` at the end.
    fn step(&mut self) -> Result<Option<LogItem>, InputError> {
        loop {
            let Some(m) = self.c.next_message()? else {
                self.report.gnss_without_accuracy += self.pending.len() as u64;
                self.pending.clear();
                self.report.ending = self.c.ending.clone();
                self.report.formats = self.c.fmt_count;
                return Ok(None);
            };
            self.report.messages += 1;
            let Some((stream, decoded)) = self.decode(m)? else {
                continue;
            };
            let ty = usize::from(m.ty);
            let t = |us: u64, c: &Clock| c.seconds(us);
            let record = match decoded {
                Decoded::Imu { us, gyr, acc } => {
                    let s = self.types[ty]
                        .streams
                        .iter_mut()
                        .find(|s| s.index == stream)
                        .expect("the stream decode found");
                    let last = s.last_us.replace(us);
                    let dt = match last {
                        Some(l) if us > l && (us - l) as f64 * 1e-6 <= MAX_IMU_GAP_S => {
                            (us - l) as f64 / 1e6
                        }
                        _ => {
                            self.report.imu_restarts += 1;
                            continue;
                        }
                    };
                    LogRecord::Imu(ImuSample {
                        t: t(us, &self.clock),
                        dt,
                        dtheta: gyr * dt,
                        dvel: acc * dt,
                    })
                }
                Decoded::Gps(gps) => {
                    let instance = self.instance_of(ty, stream);
                    if let Some(i) = self.pending.iter().position(|p| p.instance == instance) {
                        self.pending.swap_remove(i);
                        self.report.gnss_without_accuracy += 1;
                    }
                    if gps.status < 3 {
                        self.report.gnss_without_fix += 1;
                    } else {
                        self.pending.push(Pending {
                            instance,
                            stream,
                            gps,
                        });
                    }
                    continue;
                }
                Decoded::Gpa(gpa) => {
                    let instance = self.instance_of(ty, stream);
                    let Some(i) = self
                        .pending
                        .iter()
                        .position(|p| p.instance == instance && p.gps.us == gpa.us)
                    else {
                        continue;
                    };
                    let p = self.pending.swap_remove(i);
                    match self.fix(&p.gps, &gpa) {
                        Some(fix) => {
                            return Ok(Some(LogItem {
                                stream: p.stream,
                                record: LogRecord::Gnss(fix),
                            }));
                        }
                        None => {
                            self.report.gnss_without_accuracy += 1;
                            continue;
                        }
                    }
                }
                Decoded::Baro { us, h } => LogRecord::Baro {
                    t: t(us, &self.clock),
                    h,
                },
                Decoded::Ekf { us, att, v_n, p_n } => {
                    let pos = self
                        .origin
                        .map(|(lat, lon, alt)| records::offset_location(lat, lon, alt, &p_n));
                    if pos.is_none() {
                        self.report.reference_without_origin += 1;
                    }
                    LogRecord::Reference(ReferenceSample {
                        t: t(us, &self.clock),
                        pos,
                        v_n: Some(v_n),
                        att: Some(att),
                    })
                }
                Decoded::Origin { ty, lat, lon, alt } => {
                    if ty == 0 {
                        self.origin = Some((lat, lon, alt));
                    }
                    continue;
                }
            };
            return Ok(Some(LogItem { stream, record }));
        }
    }

    /// The instance of stream `stream` of type `ty`.
    fn instance_of(&self, ty: usize, stream: usize) -> Option<i64> {
        self.types[ty]
            .streams
            .iter()
            .find(|s| s.index == stream)
            .and_then(|s| s.instance)
    }

    /// The fix of `gps` completed by its `gpa`; `None` when an accuracy is unknown.
    fn fix(&mut self, gps: &Gps, gpa: &Gpa) -> Option<GnssFix> {
        if !(gpa.hacc > 0.0 && gpa.vacc > 0.0) {
            return None;
        }
        let h = match gpa.ellipsoid_h {
            Some(h) => h,
            None => {
                self.report.gnss_msl_height += 1;
                gps.alt
            }
        };
        let vel = (gpa.sacc > 0.0).then(|| {
            if gpa.vv {
                (gps.v_n, Vector3::repeat(gpa.sacc))
            } else {
                (
                    Vector3::new(gps.v_n.x, gps.v_n.y, 0.0),
                    Vector3::new(gpa.sacc, gpa.sacc, UNMEASURED_VD_STD),
                )
            }
        });
        Some(GnssFix {
            t: self.clock.seconds(gps.us),
            pos: Geodetic::from_degrees(gps.lat, gps.lon, h),
            pos_std: Vector3::new(gpa.hacc, gpa.hacc, gpa.vacc),
            vel,
        })
    }
}

impl Iterator for DataflashReader {
    type Item = Result<LogItem, InputError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed || self.tie_only {
            return None;
        }
        match self.step() {
            Ok(item) => item.map(Ok),
            Err(e) => {
                self.failed = true;
                Some(Err(e))
            }
        }
    }
}

impl LogReader for DataflashReader {
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
