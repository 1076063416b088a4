//! RINEX observation files (2.xx, 3.0x, 4.0x; plain, gzip or Hatanaka-compressed):
//! epochs of pseudorange, carrier phase, Doppler and signal strength, read as a stream.
//!
//! [`ObsReader`] reads the header once ([`ObsHeader`]: version, marker, approximate
//! position, antenna offset, the observation codes of each system, time system, first
//! epoch, interval, leap seconds, GLONASS channels), then yields one [`Epoch`] at a time:
//! its time (GPS week and second, and the calendar time as written), flag, receiver
//! clock offset, and per satellite the observations present, each naming its code by
//! an index into the header's list for that system. Memory is bounded whatever the
//! file's length: one epoch, at most [`MAX_SATS_PER_EPOCH`] satellites and
//! [`MAX_CODES_PER_SYSTEM`] codes per system, lines of at most
//! [`crate::formats::MAX_LINE_BYTES`].
//!
//! Records (RINEX 2.11 tables A2/A3, RINEX 3.05 and 4.01 table A2/A3):
//! - **2.xx**: an epoch line ` yy mm dd hh mm ss.sssssss  f nnn` with up to 12
//!   satellites, continued on lines of 32 blanks and 12 more, the clock offset (F12.9)
//!   in columns 69–80; then per satellite the observations 5 to a line, each 16 columns
//!   (F14.3, loss-of-lock indicator, signal strength).
//! - **3.0x, 4.0x**: an epoch line `> yyyy mm dd hh mm ss.sssssss  f nnn` with the
//!   clock offset (F15.12) in columns 42–56; then one line per satellite, its
//!   identifier and its system's observations, 16 columns each.
//!
//! Epoch flags 0 (ok), 1 (power failure before this epoch) and 6 (cycle slips: the
//! satellites' values are slip counts, not measurements) carry satellites; flags 2–5
//! are events followed by `nnn` special records, header records that update the
//! header ([`ObsReader::header`]) for the epochs after them. Times are those of the
//! header's time system; [`Epoch::week`] and [`Epoch::sow`] are GPS time: BeiDou time
//! plus 14 s, GLONASS time minus 3 h plus the leap seconds, Galileo, QZSS and NavIC
//! time as they are.
//!
//! Errors name the file, the line and the field: the observation code (`C1C`, RINEX
//! 2's `P2`), the header label, `epoch`, `satellite` or `clock offset`. An epoch with
//! fewer satellite records than its count, a value that is no number, an unknown
//! observation code, an epoch earlier than the one before, an unsupported version:
//! each stops the stream with its error. (One leniency: a RINEX 2 file may end
//! without the last lines of its last satellite's record, which are blank when an
//! editor dropped them with the file's trailing blank lines.)

mod codes;
mod fields;
mod header;
mod records;
#[cfg(test)]
mod tests;

pub use codes::{MAX_CODES_PER_SYSTEM, ObsCode, ObsCodes, ObsKind};
pub use header::{AntennaDelta, ObsHeader, TimeSystem, Version};

use super::hatanaka::Decompressor;
use crate::formats::InputError;
use crate::formats::error::InputErrorKind;
use crate::formats::lines::{LineReadError, LineReader, cannot_read, too_long};
use chrono::NaiveDateTime;
use header::HeaderBuilder;
use schuler::gnss::Sat;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Most satellites an epoch may hold (RINEX writes the count as I3; every system
/// together has fewer than 160 satellites in orbit).
pub const MAX_SATS_PER_EPOCH: usize = 256;

/// The flag of an epoch (RINEX 2.11 table A2, 3.05 table A3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EpochFlag {
    /// 0: observations.
    Ok,
    /// 1: observations after a power failure between the previous epoch and this one.
    PowerFailure,
    /// 2: the antenna starts moving (event).
    MovingAntenna,
    /// 3: a new site occupation (event; header records follow).
    NewSite,
    /// 4: header records follow (event).
    HeaderRecords,
    /// 5: an external event (its time is the event's).
    ExternalEvent,
    /// 6: cycle slip records: the values are slip counts, not observations.
    CycleSlips,
}

impl EpochFlag {
    /// The flag of digit `d`.
    pub(crate) fn from_digit(d: u8) -> Option<EpochFlag> {
        Some(match d {
            b'0' => EpochFlag::Ok,
            b'1' => EpochFlag::PowerFailure,
            b'2' => EpochFlag::MovingAntenna,
            b'3' => EpochFlag::NewSite,
            b'4' => EpochFlag::HeaderRecords,
            b'5' => EpochFlag::ExternalEvent,
            b'6' => EpochFlag::CycleSlips,
            _ => return None,
        })
    }

    /// Whether an event (flags 2–5): no satellites, special records instead.
    pub fn is_event(self) -> bool {
        matches!(
            self,
            EpochFlag::MovingAntenna
                | EpochFlag::NewSite
                | EpochFlag::HeaderRecords
                | EpochFlag::ExternalEvent
        )
    }

    /// Whether the epoch's values are measurements (flags 0 and 1).
    pub fn has_measurements(self) -> bool {
        matches!(self, EpochFlag::Ok | EpochFlag::PowerFailure)
    }
}

/// One observation of one satellite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Obs {
    /// The index of its code in the epoch's [`ObsCodes`] list for the satellite's system.
    pub code: u8,
    /// The value: pseudorange [m], phase [cycles], Doppler [Hz], signal strength
    /// [dB-Hz for `DBHZ`], scale factors of the header applied.
    pub value: f64,
    /// The loss-of-lock indicator (0–7; bit 0: lost lock, a cycle slip possible),
    /// `None` when blank.
    pub lli: Option<u8>,
    /// The signal strength indicator (1–9; 0 unknown), `None` when blank.
    pub ssi: Option<u8>,
}

/// Where a satellite's observations are in [`Epoch`]'s list.
#[derive(Debug, Clone, Copy, PartialEq)]
struct SatSpan {
    sat: Sat,
    start: u32,
    end: u32,
}

/// One epoch of a RINEX observation file.
#[derive(Debug, Clone, PartialEq)]
pub struct Epoch {
    /// GPS week (continuous, no rollover) of the epoch in GPS time.
    pub week: i64,
    /// GPS second of week [s].
    pub sow: f64,
    /// The epoch as written, in [`ObsHeader::time_system`] (the previous epoch's for an
    /// event whose time fields are blank; see [`Self::time_given`]).
    pub time: NaiveDateTime,
    /// Whether the record gave its time (an event's may be blank).
    pub time_given: bool,
    /// The epoch flag.
    pub flag: EpochFlag,
    /// The receiver clock offset [s], when the file gives it.
    pub clock_offset: Option<f64>,
    /// The codes the observations' indices refer to (the header's when the epoch was
    /// read).
    pub codes: Arc<ObsCodes>,
    /// The special records of an event (flags 2–5), each its first 80 characters.
    pub records: Vec<String>,
    sats: Vec<SatSpan>,
    obs: Vec<Obs>,
}

impl Default for Epoch {
    fn default() -> Self {
        Self {
            week: 0,
            sow: 0.0,
            time: NaiveDateTime::default(),
            time_given: false,
            flag: EpochFlag::Ok,
            clock_offset: None,
            codes: Arc::default(),
            records: Vec::new(),
            sats: Vec::new(),
            obs: Vec::new(),
        }
    }
}

impl Epoch {
    /// The number of satellites.
    pub fn len(&self) -> usize {
        self.sats.len()
    }

    /// Whether no satellite (an event, or an epoch of none).
    pub fn is_empty(&self) -> bool {
        self.sats.is_empty()
    }

    /// Each satellite with its observations, in the file's order.
    pub fn sats(&self) -> impl Iterator<Item = SatObs<'_>> {
        self.sats.iter().map(|s| self.view(s))
    }

    /// Satellite `sat`'s observations, if the epoch has it.
    pub fn sat(&self, sat: Sat) -> Option<SatObs<'_>> {
        self.sats
            .iter()
            .find(|s| s.sat == sat)
            .map(|s| self.view(s))
    }

    fn view(&self, s: &SatSpan) -> SatObs<'_> {
        SatObs {
            sat: s.sat,
            obs: &self.obs[s.start as usize..s.end as usize],
            codes: self.codes.of(s.sat.system),
        }
    }

    /// Empties it for reuse, keeping its allocations.
    fn clear(&mut self) {
        self.sats.clear();
        self.obs.clear();
        self.records.clear();
        self.clock_offset = None;
    }
}

/// One satellite's observations in an epoch.
#[derive(Debug, Clone, Copy)]
pub struct SatObs<'a> {
    /// The satellite.
    pub sat: Sat,
    /// Its observations (blank fields left out), in the order of its system's codes.
    pub obs: &'a [Obs],
    codes: &'a [ObsCode],
}

impl<'a> SatObs<'a> {
    /// The observation of `code`, if present.
    pub fn get(&self, code: ObsCode) -> Option<&'a Obs> {
        let i = self.codes.iter().position(|&c| c == code)?;
        self.obs.iter().find(|o| usize::from(o.code) == i)
    }

    /// The code of observation `o`.
    pub fn code(&self, o: &Obs) -> ObsCode {
        self.codes[usize::from(o.code)]
    }

    /// Each observation with its code.
    pub fn iter(&self) -> impl Iterator<Item = (ObsCode, &'a Obs)> + 'a {
        let codes = self.codes;
        self.obs
            .iter()
            .map(move |o| (codes[usize::from(o.code)], o))
    }

    /// The first present observation of `kind` on `band` whose attribute comes first
    /// in `attributes` (`"CWPX"`: C/A, then Y-code…), for a choice of signal.
    pub fn first(&self, kind: ObsKind, band: u8, attributes: &str) -> Option<(ObsCode, &'a Obs)> {
        attributes.chars().find_map(|a| {
            self.iter()
                .find(|(c, _)| c.kind() == kind && c.band() == band && c.attribute() == a)
        })
    }
}

/// The lines of a RINEX observation file: as they are, or expanded from Hatanaka's
/// compact form.
pub(crate) enum Source<R> {
    /// Plain text (`held`: the current line is still to be handed out).
    Plain { lines: LineReader<R>, held: bool },
    /// Compact RINEX.
    Crx(Box<Decompressor<R>>),
}

impl<R: Read> Source<R> {
    /// The next line and its number; `None` at the end.
    pub(crate) fn next(&mut self, path: &Path) -> Result<Option<(&[u8], u64)>, InputError> {
        match self {
            Source::Plain { lines, held } => {
                if !std::mem::take(held) {
                    match lines.next_line() {
                        Ok(true) => {}
                        Ok(false) => return Ok(None),
                        Err(e) => return Err(line_error(path, lines, e)),
                    }
                }
                Ok(Some((lines.line(), lines.at().line_no)))
            }
            Source::Crx(d) => d.next_line(path),
        }
    }

    /// The line [`Self::next`] handed out last, again.
    pub(crate) fn current(&self) -> (&[u8], u64) {
        match self {
            Source::Plain { lines, .. } => (lines.line(), lines.at().line_no),
            Source::Crx(d) => d.current(),
        }
    }
}

/// The error of a failed line read.
pub(crate) fn line_error<R: Read>(
    path: &Path,
    lines: &LineReader<R>,
    e: LineReadError,
) -> InputError {
    match e {
        LineReadError::Io(e) => cannot_read(path, &e),
        LineReadError::TooLong => too_long(path, lines.at().line_no),
    }
}

/// A streaming reader of a RINEX observation file: the header at once, then one
/// [`Epoch`] per call.
pub struct ObsReader<R> {
    source: Source<R>,
    path: PathBuf,
    header: ObsHeader,
    /// The last epoch's time as written, GPS week and second, for an event without one.
    last_time: (NaiveDateTime, i64, f64),
    /// The GPS week and second of the last epoch with satellites (times must not go back).
    last_data: Option<(i64, f64)>,
    failed: bool,
}

impl ObsReader<Box<dyn std::io::BufRead + Send>> {
    /// Opens the file at `path` (gzip told by its magic bytes, Hatanaka by its first
    /// line) and reads its header.
    pub fn open(path: &Path) -> Result<Self, InputError> {
        ObsReader::new(super::open(path)?, path)
    }
}

impl<R: Read> ObsReader<R> {
    /// Reads the header from `input`, named `path` in errors.
    pub fn new(input: R, path: &Path) -> Result<Self, InputError> {
        let mut lines = LineReader::new(input);
        match lines.next_line() {
            Ok(true) => {}
            Ok(false) => {
                return Err(InputError::new(
                    InputErrorKind::NoData,
                    path,
                    0,
                    None,
                    "empty file: no RINEX header",
                ));
            }
            Err(e) => return Err(line_error(path, &lines, e)),
        }
        let first = String::from_utf8_lossy(lines.line()).into_owned();
        let (content, label) = super::header_label(&first);
        let (mut source, crinex) = if label == "CRINEX VERS   / TYPE" {
            let version = header::parse_version(fields::cols(content.as_bytes(), 0, 9));
            let d = Decompressor::new(lines, version, path)?;
            (Source::Crx(Box::new(d)), version)
        } else {
            (Source::Plain { lines, held: true }, None)
        };
        let mut builder = HeaderBuilder::new(crinex);
        let mut last = 0;
        loop {
            let Some((line, n)) = source.next(path)? else {
                return Err(InputError::new(
                    InputErrorKind::Header,
                    path,
                    last,
                    Some("END OF HEADER"),
                    "the header has no END OF HEADER",
                ));
            };
            last = n;
            if builder.line(path, n, line)? {
                break;
            }
        }
        let header = builder.finish(path, last)?;
        if let (Some(c), Source::Crx(d)) = (crinex, &mut source) {
            let matching = (c.major == 1 && header.version.major == 2)
                || (c.major == 3 && header.version.major >= 3);
            if !matching {
                return Err(InputError::new(
                    InputErrorKind::Header,
                    path,
                    1,
                    Some("CRINEX VERS   / TYPE"),
                    format!(
                        "compact RINEX {}.{} does not hold RINEX {}.{:02}",
                        c.major, c.minor, header.version.major, header.version.minor
                    ),
                ));
            }
            d.set_layout(&header);
        }
        let start = header.time_of_first_obs.unwrap_or_default();
        Ok(Self {
            source,
            path: path.to_path_buf(),
            header,
            last_time: (start, 0, 0.0),
            last_data: None,
            failed: false,
        })
    }

    /// The source of lines, for the decompressor's tests.
    #[cfg(test)]
    pub(crate) fn source_for_test(&mut self) -> &mut Source<R> {
        &mut self.source
    }

    /// The header, updated by the header records of the events read so far.
    pub fn header(&self) -> &ObsHeader {
        &self.header
    }

    /// Reads the next epoch into `epoch` (reusing its allocations); `Ok(false)` at the
    /// end of the file. After an error the reader yields nothing more.
    pub fn read_epoch(&mut self, epoch: &mut Epoch) -> Result<bool, InputError> {
        if self.failed {
            return Ok(false);
        }
        let r = self.read(epoch);
        if r.is_err() {
            self.failed = true;
        }
        r
    }

    fn read(&mut self, epoch: &mut Epoch) -> Result<bool, InputError> {
        epoch.clear();
        epoch.codes = Arc::clone(&self.header.codes);
        let path = &self.path;
        let line_no = if self.header.version.major == 2 {
            records::read_v2(&mut self.source, path, &self.header, epoch)?
        } else {
            records::read_v3(&mut self.source, path, &self.header, epoch)?
        };
        let Some(line_no) = line_no else {
            return Ok(false);
        };
        if epoch.time_given {
            let (week, sow) = records::gps_time(epoch.time, &self.header);
            epoch.week = week;
            epoch.sow = sow;
        } else {
            (epoch.time, epoch.week, epoch.sow) = self.last_time;
        }
        if epoch.flag.is_event() {
            self.apply_records(epoch, line_no)?;
        } else {
            if let Some(last) = self.last_data
                && (epoch.week, epoch.sow) < last
            {
                return Err(InputError::new(
                    InputErrorKind::TimeNotIncreasing,
                    path,
                    line_no,
                    Some("epoch"),
                    format!(
                        "epoch {} is earlier than the one before (GPS week {} {:.7} s)",
                        epoch.time, last.0, last.1
                    ),
                ));
            }
            self.last_data = Some((epoch.week, epoch.sow));
        }
        self.last_time = (epoch.time, epoch.week, epoch.sow);
        Ok(true)
    }

    /// Applies an event's header records (line `line_no` is its epoch line's).
    fn apply_records(&mut self, epoch: &Epoch, line_no: u64) -> Result<(), InputError> {
        if epoch.records.is_empty() {
            return Ok(());
        }
        let mut builder = HeaderBuilder::from_header(self.header.clone());
        for (i, record) in epoch.records.iter().enumerate() {
            builder.line(&self.path, line_no + 1 + i as u64, record.as_bytes())?;
        }
        self.header = builder.finish(&self.path, line_no)?;
        if let Source::Crx(d) = &mut self.source {
            d.set_layout(&self.header);
        }
        Ok(())
    }
}

impl<R: Read> Iterator for ObsReader<R> {
    type Item = Result<Epoch, InputError>;

    fn next(&mut self) -> Option<Self::Item> {
        let mut epoch = Epoch::default();
        match self.read_epoch(&mut epoch) {
            Ok(true) => Some(Ok(epoch)),
            Ok(false) => None,
            Err(e) => Some(Err(e)),
        }
    }
}
