//! u-blox UBX logs (`.ubx`): what a u-blox receiver writes to its port, read as
//! [`LogRecord`]s.
//!
//! | message | record | module |
//! |---|---|---|
//! | NAV-PVT | [`LogRecord::Gnss`] (3-D or GNSS + DR fixes with `gnssFixOK`) | [`nav`] |
//! | NAV-ATT | [`LogRecord::Reference`]: attitude, with the same epoch's NAV-PVT position and velocity | [`nav`] |
//! | ESF-RAW, ESF-MEAS | [`LogRecord::Imu`], one stream each, FRD | [`esf`] |
//! | RXM-RAWX | [`LogRecord::Raw`] | [`rxm`] |
//! | RXM-SFRBX | [`LogRecord::Ephemeris`] from GPS L1 C/A subframes 1–3 | [`lnav`] |
//!
//! Every other UBX message, and the NMEA sentences and RTCM 3 frames receivers
//! interleave, is counted in a stream of kind [`StreamKind::Other`] (`NAV-SAT`,
//! `NMEA`, `RTCM3`). Framing and checksums: `frame.rs`.
//!
//! **Clock.** GPS seconds of week (continuing past 604 800 s across a rollover) from
//! the first week the log gives (RXM-RAWX `week`, or NAV-PVT's UTC date with `iTOW`).
//! NAV-PVT and NAV-ATT are at their `iTOW`. The IMU streams count their own sensor
//! time tags ([`esf`]); each is tied to GPS time at the first NAV-PVT that follows one
//! of its samples, as `iTOW − (newest sample time)`: u-blox writes the sensor
//! messages as they come and NAV-PVT after its epoch is solved, so the tie is good to
//! the receiver's output latency (tens of ms), not better. Samples are held until
//! their stream is tied (at most [`MAX_HELD`]); a log without any NAV-PVT gives its IMU
//! samples on the sensor clock ([`TimeScale::Device`]).
//!
//! **Bad input.** A frame whose checksum fails right after a valid frame is refused,
//! naming its byte offset and message (`ESF-RAW at byte offset 1234: checksum …`);
//! so is a payload too short for its message's layout. A frame cut by the end of the
//! file is reported ([`UbxReport::truncated_tail`]), not refused: receiver logs often
//! end inside a frame. Bytes that begin no frame (a logger's text header) are skipped
//! and counted ([`UbxReport::unknown_bytes`]). [`UbxOptions::skip_corrupt_frames`]
//! skips and counts corrupt frames instead of refusing them, for serial captures with
//! known dropouts.
//!
//! **Why our own decoder and not the `ublox` crate (0.10, MIT).** Measured on this
//! machine: the crate adds `ublox_derive` with `syn` 1 (a second `syn` beside the
//! workspace's `syn` 2), `bitflags`, `num-traits`; its release build took 3.5 min of
//! wall time under the shared load, against none for a decoder whose layouts fit in
//! this module; it needs a protocol version chosen at compile time (NAV-PVT and
//! RXM-RAWX differ between its `proto14`/`proto23`/`proto27`/`proto31` features), its
//! GPS subframe interpretation sits behind a further feature and crate
//! (`gnss-protos`), and its parser reports a bad checksum or a cut frame without the
//! byte offset the refusal must name. Speed was not the deciding point: both read far
//! above the 50 MB/s the issue asks (see the report of issue 32 and `benches/ubx.rs`).

pub mod esf;
pub(crate) mod frame;
mod le;
pub mod lnav;
pub mod nav;
pub mod rxm;

use super::{LogItem, LogReader, LogRecord, ReferenceSample, Stream, StreamKind, TimeScale};
use crate::formats::InputError;
use crate::formats::error::InputErrorKind;
use crate::formats::error::cannot_read;
use frame::{Piece, Scanner};
use schuler::imu::ImuSample;
use std::collections::{HashMap, VecDeque};
use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

/// The most records held back while an IMU stream waits for its tie to GPS time.
pub const MAX_HELD: usize = 500_000;
/// A gap between two samples of an IMU stream longer than this [s] restarts it (no
/// sample spans the gap).
pub const MAX_IMU_GAP_S: f64 = 0.5;

/// How the reader treats corrupt frames.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct UbxOptions {
    /// Skip (and count) a frame whose checksum fails instead of refusing the file.
    pub skip_corrupt_frames: bool,
}

/// A frame cut by the end of the input.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Truncation {
    /// Byte offset of its sync word.
    pub offset: u64,
    /// Its message name, when its header was complete (`RXM-RAWX`).
    pub name: Option<String>,
    /// Bytes present and bytes the frame needs.
    pub have: usize,
    /// See `have`.
    pub need: usize,
}

/// What the reader skipped or could not use, for `inspect` and the user.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct UbxReport {
    /// Bytes that began no frame.
    pub unknown_bytes: u64,
    /// A frame cut by the end of the input.
    pub truncated_tail: Option<Truncation>,
    /// Corrupt frames skipped ([`UbxOptions::skip_corrupt_frames`]).
    pub corrupt_frames: u64,
    /// NAV-PVT messages without a usable fix.
    pub pvt_without_fix: u64,
    /// SFRBX messages not decoded (not GPS L1 C/A LNAV).
    pub sfrbx_not_decoded: u64,
    /// RAWX measurements of unknown systems or signals.
    pub rawx_skipped: u64,
    /// IMU stream restarts at gaps longer than [`MAX_IMU_GAP_S`] or at time tags that
    /// go back.
    pub imu_restarts: u64,
    /// IMU samples left out because no NAV-PVT followed them to tie their clock to GPS
    /// time.
    pub imu_untied: u64,
}

/// The name u-blox gives a message, `UBX-cc-ii` (hex) for one not listed.
pub fn message_name(class: u8, id: u8) -> String {
    let known = match (class, id) {
        (0x01, 0x01) => "NAV-POSECEF",
        (0x01, 0x02) => "NAV-POSLLH",
        (0x01, 0x03) => "NAV-STATUS",
        (0x01, 0x04) => "NAV-DOP",
        (0x01, 0x05) => "NAV-ATT",
        (0x01, 0x06) => "NAV-SOL",
        (0x01, 0x07) => "NAV-PVT",
        (0x01, 0x11) => "NAV-VELECEF",
        (0x01, 0x12) => "NAV-VELNED",
        (0x01, 0x20) => "NAV-TIMEGPS",
        (0x01, 0x21) => "NAV-TIMEUTC",
        (0x01, 0x22) => "NAV-CLOCK",
        (0x01, 0x30) => "NAV-SVINFO",
        (0x01, 0x35) => "NAV-SAT",
        (0x01, 0x36) => "NAV-COV",
        (0x01, 0x43) => "NAV-SIG",
        (0x01, 0x61) => "NAV-EOE",
        (0x02, 0x13) => "RXM-SFRBX",
        (0x02, 0x14) => "RXM-MEASX",
        (0x02, 0x15) => "RXM-RAWX",
        (0x04, _) => "INF",
        (0x05, 0x00) => "ACK-NAK",
        (0x05, 0x01) => "ACK-ACK",
        (0x0A, 0x04) => "MON-VER",
        (0x0A, 0x09) => "MON-HW",
        (0x10, 0x02) => "ESF-MEAS",
        (0x10, 0x03) => "ESF-RAW",
        (0x10, 0x10) => "ESF-STATUS",
        (0x10, 0x14) => "ESF-ALG",
        (0x10, 0x15) => "ESF-INS",
        (0x28, 0x00) => "HNR-PVT",
        (0x28, 0x01) => "HNR-ATT",
        (0x28, 0x02) => "HNR-INS",
        _ => return format!("UBX-{class:02X}-{id:02X}"),
    };
    known.to_owned()
}

/// What a message gives.
fn kind_of(class: u8, id: u8) -> StreamKind {
    match (class, id) {
        (0x01, 0x07) => StreamKind::Gnss,
        (0x01, 0x05) => StreamKind::Reference,
        (0x10, 0x02) | (0x10, 0x03) => StreamKind::Imu,
        (0x02, 0x15) => StreamKind::Raw,
        (0x02, 0x13) => StreamKind::Ephemeris,
        _ => StreamKind::Other,
    }
}

/// One IMU stream's clock: its samples' sensor time on a continuous count, and its
/// tie to GPS time.
#[derive(Debug, Clone)]
struct ImuClock {
    stream: usize,
    tick_s: f64,
    assembler: esf::Assembler,
    last_tag: Option<u32>,
    /// Sensor time of the last sample [s], continuous.
    device_s: f64,
    /// GPS time − sensor time [s], once tied.
    offset: Option<f64>,
}

/// A record held until its stream's clock is tied; IMU samples are on the sensor
/// clock until then.
#[derive(Debug)]
enum Held {
    Ready(LogItem),
    Imu { clock: usize, sample: ImuSample },
}

/// Streaming reader of a UBX log.
pub struct UbxReader {
    path: PathBuf,
    scanner: Scanner<Box<dyn Read + Send>>,
    size: u64,
    options: UbxOptions,
    streams: Vec<Stream>,
    counts: Vec<u64>,
    index: HashMap<(u8, u8), usize>,
    other: HashMap<&'static str, usize>,
    held: VecDeque<Held>,
    imu: Vec<ImuClock>,
    rawx: rxm::RawxDecoder,
    lnav: lnav::Collector,
    last_pvt: Option<nav::NavPvt>,
    /// The current GPS week and the first one met.
    week: Option<u32>,
    week0: Option<u32>,
    ubx_frames: u64,
    /// The payload being decoded (a buffer kept across frames).
    payload: Vec<u8>,
    report: UbxReport,
    done: bool,
}

impl UbxReader {
    /// Opens the log at `path` (gunzipped when it begins with gzip's magic bytes).
    pub fn open(path: &Path) -> Result<Self, InputError> {
        Self::open_with(path, UbxOptions::default())
    }

    /// As [`UbxReader::open`], with options.
    pub fn open_with(path: &Path, options: UbxOptions) -> Result<Self, InputError> {
        let io = |e: std::io::Error| cannot_read(path, &e);
        let file = File::open(path).map_err(io)?;
        let size = file.metadata().map_err(io)?.len();
        let mut buffered = BufReader::with_capacity(1 << 16, file);
        let gzipped = std::io::BufRead::fill_buf(&mut buffered)
            .map_err(io)?
            .starts_with(&[0x1f, 0x8b]);
        let input: Box<dyn Read + Send> = if gzipped {
            Box::new(flate2::bufread::MultiGzDecoder::new(buffered))
        } else {
            Box::new(buffered)
        };
        Ok(Self::new(path, input, size, options))
    }

    /// A reader of `input`, named `path` in errors; `size` is the input's length for
    /// [`LogReader::progress`].
    pub fn new(path: &Path, input: Box<dyn Read + Send>, size: u64, options: UbxOptions) -> Self {
        Self {
            path: path.to_path_buf(),
            scanner: Scanner::new(input),
            size,
            options,
            streams: Vec::new(),
            counts: Vec::new(),
            index: HashMap::new(),
            other: HashMap::new(),
            held: VecDeque::new(),
            imu: Vec::new(),
            rawx: rxm::RawxDecoder::default(),
            lnav: lnav::Collector::default(),
            last_pvt: None,
            week: None,
            week0: None,
            ubx_frames: 0,
            payload: Vec::new(),
            report: UbxReport::default(),
            done: false,
        }
    }

    /// Messages met per stream, in the order of [`LogReader::streams`].
    pub fn counts(&self) -> &[u64] {
        &self.counts
    }

    /// What was skipped or could not be used so far.
    pub fn report(&self) -> &UbxReport {
        &self.report
    }

    fn stream_of(&mut self, class: u8, id: u8) -> usize {
        if let Some(&i) = self.index.get(&(class, id)) {
            return i;
        }
        let i = self.push_stream(message_name(class, id), kind_of(class, id));
        self.index.insert((class, id), i);
        i
    }

    fn other_stream(&mut self, name: &'static str) -> usize {
        if let Some(&i) = self.other.get(name) {
            return i;
        }
        let i = self.push_stream(name.to_owned(), StreamKind::Other);
        self.other.insert(name, i);
        i
    }

    fn push_stream(&mut self, name: String, kind: StreamKind) -> usize {
        self.streams.push(Stream { name, kind });
        self.counts.push(0);
        self.streams.len() - 1
    }

    fn error(&self, offset: u64, name: &str, message: String) -> InputError {
        InputError::new(
            InputErrorKind::LayoutMismatch,
            &self.path,
            0,
            Some(name),
            format!("at byte offset {offset}: {message}"),
        )
    }

    /// GPS seconds on the reader's clock of time of week `tow` [s] in the current week.
    fn gps_t(&self, tow: f64) -> f64 {
        match (self.week, self.week0) {
            (Some(w), Some(w0)) => (f64::from(w) - f64::from(w0)) * 604_800.0 + tow,
            _ => tow,
        }
    }

    fn set_week(&mut self, week: u32) {
        self.week = Some(week);
        self.week0.get_or_insert(week);
    }

    fn emit(&mut self, stream: usize, record: LogRecord) {
        self.held.push_back(Held::Ready(LogItem { stream, record }));
    }

    /// Reads pieces until a record can be released or the input ends.
    fn advance(&mut self) -> Result<(), InputError> {
        loop {
            if self.front_ready() {
                return Ok(());
            }
            if self.held.len() > MAX_HELD {
                return Err(InputError::new(
                    InputErrorKind::Usage,
                    &self.path,
                    0,
                    Some("ESF-RAW/ESF-MEAS"),
                    format!(
                        "no NAV-PVT within {MAX_HELD} records after the first IMU sample: \
                         the sensor time tags cannot be tied to GPS time"
                    ),
                ));
            }
            let piece = self.scanner.next_piece().map_err(|e| {
                InputError::new(
                    InputErrorKind::Io,
                    &self.path,
                    0,
                    None,
                    format!("cannot read: {e}"),
                )
            })?;
            match piece {
                Piece::End => {
                    self.finish()?;
                    return Ok(());
                }
                Piece::Ubx {
                    offset,
                    class,
                    id,
                    start,
                    len,
                } => {
                    self.ubx_frames += 1;
                    let stream = self.stream_of(class, id);
                    self.counts[stream] += 1;
                    let mut payload = std::mem::take(&mut self.payload);
                    payload.clear();
                    payload.extend_from_slice(self.scanner.payload(start, len));
                    let decoded = self.message(offset, class, id, stream, &payload);
                    self.payload = payload;
                    decoded?;
                }
                Piece::Nmea { .. } => {
                    let s = self.other_stream("NMEA");
                    self.counts[s] += 1;
                }
                Piece::Rtcm { .. } => {
                    let s = self.other_stream("RTCM3");
                    self.counts[s] += 1;
                }
                Piece::Unknown { len, .. } => self.report.unknown_bytes += len as u64,
                Piece::TruncatedUbx {
                    offset,
                    class,
                    id,
                    have,
                    need,
                } => {
                    self.report.truncated_tail = Some(Truncation {
                        offset,
                        name: (have >= 6).then(|| message_name(class, id)),
                        have,
                        need,
                    });
                }
                Piece::BadChecksum {
                    offset,
                    class,
                    id,
                    len,
                } => {
                    if self.options.skip_corrupt_frames {
                        self.report.corrupt_frames += 1;
                        self.scanner.skip_false_sync();
                    } else {
                        return Err(self.error(
                            offset,
                            &message_name(class, id),
                            format!(
                                "the checksum of this {len}-byte frame does not match \
                                 its bytes (the file is garbled here)"
                            ),
                        ));
                    }
                }
            }
        }
    }

    /// Whether the front of the held records may be released.
    fn front_ready(&self) -> bool {
        match self.held.front() {
            None => false,
            Some(Held::Ready(_)) => true,
            Some(Held::Imu { clock, .. }) => self.imu[*clock].offset.is_some(),
        }
    }

    /// At the end of the input: IMU streams never tied keep the sensor clock when the
    /// log gives no GPS time at all; otherwise their samples are left out.
    fn finish(&mut self) -> Result<(), InputError> {
        self.done = true;
        self.report.rawx_skipped = self.rawx.skipped;
        if self.ubx_frames == 0 {
            return Err(InputError::new(
                InputErrorKind::NoData,
                &self.path,
                0,
                None,
                format!(
                    "no UBX frame in {} bytes: not a u-blox log",
                    self.scanner.consumed()
                ),
            ));
        }
        let device_clock = self.week0.is_none() && self.last_pvt.is_none();
        for c in &mut self.imu {
            if c.offset.is_none() && device_clock {
                c.offset = Some(0.0);
            }
        }
        let imu = &self.imu;
        let before = self.held.len();
        self.held.retain(|h| match h {
            Held::Imu { clock, .. } => imu[*clock].offset.is_some(),
            Held::Ready(_) => true,
        });
        self.report.imu_untied += (before - self.held.len()) as u64;
        Ok(())
    }

    /// Decodes one UBX message into held records.
    fn message(
        &mut self,
        offset: u64,
        class: u8,
        id: u8,
        stream: usize,
        p: &[u8],
    ) -> Result<(), InputError> {
        let short = |need: usize, what: &str| {
            self.error(
                offset,
                &message_name(class, id),
                format!("payload of {} bytes, {what} needs {need}", p.len()),
            )
        };
        match (class, id) {
            (0x01, 0x07) => {
                if p.len() < nav::NAV_PVT_MIN_LEN {
                    return Err(short(nav::NAV_PVT_MIN_LEN, "NAV-PVT"));
                }
                let pvt = nav::NavPvt::decode(p);
                if let Some(w) = pvt.gps_week() {
                    self.set_week(w);
                }
                let t = self.gps_t(f64::from(pvt.itow_ms) / 1e3);
                self.tie_imu(t);
                if pvt.is_fix() {
                    self.emit(stream, LogRecord::Gnss(pvt.fix(t)));
                } else {
                    self.report.pvt_without_fix += 1;
                }
                self.last_pvt = Some(pvt);
            }
            (0x01, 0x05) => {
                if p.len() < nav::NAV_ATT_LEN {
                    return Err(short(nav::NAV_ATT_LEN, "NAV-ATT"));
                }
                let att = nav::NavAtt::decode(p);
                let same = self.last_pvt.filter(|pvt| pvt.itow_ms == att.itow_ms);
                let t = self.gps_t(f64::from(att.itow_ms) / 1e3);
                self.emit(
                    stream,
                    LogRecord::Reference(ReferenceSample {
                        t,
                        pos: same.map(|p| p.pos),
                        v_n: same.map(|p| p.v_n),
                        att: Some(att.att),
                    }),
                );
            }
            (0x10, 0x03) => {
                if p.len() < 4 || !(p.len() - 4).is_multiple_of(8) {
                    return Err(self.error(
                        offset,
                        "ESF-RAW",
                        format!("payload of {} bytes is not 4 + 8n", p.len()),
                    ));
                }
                let c = self.clock_of(stream, esf::STAG_TICK_S);
                for d in esf::raw_blocks(p) {
                    self.imu_datum(c, d);
                }
            }
            (0x10, 0x02) => {
                if p.len() < 8 {
                    return Err(short(8, "ESF-MEAS"));
                }
                let (n, calib) = esf::meas_layout(p);
                let need = 8 + 4 * n + if calib { 4 } else { 0 };
                if p.len() != need {
                    return Err(short(need, &format!("ESF-MEAS with {n} measurements")));
                }
                let c = self.clock_of(stream, 1e-3);
                for d in esf::meas_data(p) {
                    self.imu_datum(c, d);
                }
            }
            (0x02, 0x15) => {
                if p.len() < rxm::RAWX_HEADER {
                    return Err(short(rxm::RAWX_HEADER, "RXM-RAWX"));
                }
                let h = rxm::header(p);
                let need = rxm::RAWX_HEADER + rxm::RAWX_BLOCK * usize::from(h.num_meas);
                if p.len() != need {
                    return Err(short(
                        need,
                        &format!("RXM-RAWX with numMeas {}", h.num_meas),
                    ));
                }
                if h.week > 0 {
                    self.set_week(u32::from(h.week));
                }
                let epoch = self.rawx.epoch(p);
                self.report.rawx_skipped = self.rawx.skipped;
                self.emit(stream, LogRecord::Raw(epoch));
            }
            (0x02, 0x13) => match lnav::gps_subframe(p) {
                Some((prn, sf)) => {
                    if let Some(eph) = self.lnav.push(prn, sf, self.week) {
                        self.emit(stream, LogRecord::Ephemeris(Box::new(eph)));
                    }
                }
                None => self.report.sfrbx_not_decoded += 1,
            },
            _ => {}
        }
        Ok(())
    }

    fn clock_of(&mut self, stream: usize, tick_s: f64) -> usize {
        if let Some(i) = self.imu.iter().position(|c| c.stream == stream) {
            return i;
        }
        self.imu.push(ImuClock {
            stream,
            tick_s,
            assembler: esf::Assembler::default(),
            last_tag: None,
            device_s: 0.0,
            offset: None,
        });
        self.imu.len() - 1
    }

    /// One datum of IMU clock `c`; a completed sample is held as an increment over the
    /// time since the stream's previous sample.
    fn imu_datum(&mut self, c: usize, d: esf::Datum) {
        let clock = &mut self.imu[c];
        let Some(s) = clock.assembler.push(d) else {
            return;
        };
        let Some(last) = clock.last_tag.replace(s.tag) else {
            return;
        };
        let dt = esf::tag_delta(s.tag, last) as f64 * clock.tick_s;
        if dt <= 0.0 || dt > MAX_IMU_GAP_S {
            self.report.imu_restarts += 1;
            clock.device_s += dt.max(0.0);
            return;
        }
        clock.device_s += dt;
        let sample = ImuSample::from_mean_rates(clock.device_s, dt, s.w, s.f);
        self.held.push_back(Held::Imu { clock: c, sample });
    }

    /// Ties every IMU stream with a sample but no tie yet to GPS time `t`.
    fn tie_imu(&mut self, t: f64) {
        for c in &mut self.imu {
            if c.offset.is_none() && c.last_tag.is_some() {
                c.offset = Some(t - c.device_s);
            }
        }
    }
}

impl Iterator for UbxReader {
    type Item = Result<LogItem, InputError>;

    fn next(&mut self) -> Option<Self::Item> {
        if !self.front_ready()
            && !self.done
            && let Err(e) = self.advance()
        {
            self.done = true;
            self.held.clear();
            return Some(Err(e));
        }
        match self.held.pop_front()? {
            Held::Ready(item) => Some(Ok(item)),
            Held::Imu { clock, mut sample } => {
                let c = &self.imu[clock];
                sample.t += c.offset.unwrap_or(0.0);
                Some(Ok(LogItem {
                    stream: c.stream,
                    record: LogRecord::Imu(sample),
                }))
            }
        }
    }
}

impl LogReader for UbxReader {
    fn streams(&self) -> &[Stream] {
        &self.streams
    }

    fn time_scale(&self) -> TimeScale {
        match self.week0 {
            Some(week) => TimeScale::GpsSecondsOfWeek { week },
            None => TimeScale::Device,
        }
    }

    fn progress(&self) -> (u64, u64) {
        (self.scanner.consumed(), self.size)
    }
}
