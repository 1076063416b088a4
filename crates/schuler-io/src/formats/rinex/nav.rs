//! RINEX navigation files: the broadcast ephemerides of GPS, Galileo, BeiDou and QZSS,
//! streamed one record at a time, and the header's ionosphere coefficients.
//!
//! Versions (RINEX 2.11, 3.05 and 4.02 specifications, IGS/RTCM-SC104):
//! - **2.x**: a GPS file (type `N`), records of 8 lines (`I2,5I3,F5.1,3D19.12` then
//!   `3X,4D19.12`); GLONASS (`G`) and SBAS (`H`) files are recognised and their
//!   records skipped (GLONASS orbits may come later).
//! - **3.0x**: single or mixed (`M`) files whose records begin with the satellite
//!   (`G01 2020 06 25 …`, then `4X,4D19.12`); G, E, C, J records are read, R, S and I
//!   records skipped up to the next record.
//! - **4.0x**: records introduced by `> EPH G01 LNAV`; LNAV (G, J), INAV and FNAV (E),
//!   D1 and D2 (C) are read; CNAV, CNV1–3, FDMA, SBAS and NavIC messages, `STO` and `EOP`
//!   records are skipped; `> ION … LNAV` records (GPS Klobuchar) update
//!   [`NavReader::klobuchar`].
//!
//! Numbers are 19 characters wide with Fortran's `D` exponent accepted. Times are
//! converted to [`GpsTime`]: Galileo's as written (RINEX aligns them to GPS weeks),
//! BeiDou's from BDT (+14 s). A toe whose week disagrees with toc by whole weeks
//! (a 10-bit week, a toe written across a week's end) is moved to the week nearest toc.
//!
//! Errors name the file, the line and the field (`sqrtA`, `toe`, `e`, …): a record
//! cut short, a number that is not one, a value outside its domain (√A ≤ 0, e ∉ [0,1)),
//! a version other than 2, 3 or 4.

use std::collections::BTreeMap;
use std::io::BufRead;
use std::path::{Path, PathBuf};

use schuler::gnss::atmosphere::Klobuchar;
use schuler::gnss::time::WEEK_S;
use schuler::gnss::{Ephemeris, EphemerisStore, GpsTime, Kepler, NavMessage, Sat, System};

use super::header_label;
use crate::formats::InputError;
use crate::formats::error::{InputErrorKind, quote_field};
use crate::formats::gps_time::{TimeScale, week_sow};
use crate::formats::lines::{LineReadError, LineReader, cannot_read, too_long};

/// Lines of a file with a one-line look-ahead, each with its 1-based number.
pub(crate) struct PeekLines {
    path: PathBuf,
    reader: LineReader<Box<dyn BufRead + Send>>,
    pending: Option<(u64, Vec<u8>)>,
}

impl PeekLines {
    /// The lines of `input`, read as file `path`.
    pub(crate) fn new(path: &Path, input: Box<dyn BufRead + Send>) -> Self {
        Self {
            path: path.to_path_buf(),
            reader: LineReader::new(input),
            pending: None,
        }
    }

    /// The file's name, for errors.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// The next line and its number; `None` at the end.
    pub(crate) fn next_line(&mut self) -> Result<Option<(u64, Vec<u8>)>, InputError> {
        if let Some(p) = self.pending.take() {
            return Ok(Some(p));
        }
        match self.reader.next_line() {
            Ok(true) => Ok(Some((
                self.reader.at().line_no,
                self.reader.line().to_vec(),
            ))),
            Ok(false) => Ok(None),
            Err(LineReadError::Io(e)) => Err(cannot_read(&self.path, &e)),
            Err(LineReadError::TooLong) => Err(too_long(&self.path, self.reader.at().line_no)),
        }
    }

    /// The next line without taking it.
    pub(crate) fn peek(&mut self) -> Result<Option<&[u8]>, InputError> {
        if self.pending.is_none() {
            self.pending = self.next_line()?;
        }
        Ok(self.pending.as_ref().map(|(_, l)| l.as_slice()))
    }

    /// The number of the last line taken (or peeked).
    pub(crate) fn line_no(&self) -> u64 {
        self.reader.at().line_no
    }
}

/// Bytes `start..start + width` of `line` (fewer at its end; empty past it).
pub(crate) fn slice(line: &[u8], start: usize, width: usize) -> &[u8] {
    let end = (start + width).min(line.len());
    line.get(start..end).unwrap_or(&[])
}

/// A fixed-width field's text, trimmed; `None` when blank or absent.
pub(crate) fn field_text(line: &[u8], start: usize, width: usize) -> Option<&[u8]> {
    let f = slice(line, start, width).trim_ascii();
    (!f.is_empty()).then_some(f)
}

/// A number in Fortran's notation (`0.1D+02`, `-.5E-3`, `12`) parsed as f64; an error
/// naming `path:line` and `name` when it is not one or not finite.
pub(crate) fn fortran_f64(
    text: &[u8],
    path: &Path,
    line: u64,
    name: &str,
) -> Result<f64, InputError> {
    let bad = |kind, what: &str| {
        InputError::new(
            kind,
            path,
            line,
            Some(name),
            format!("{what}: {}", quote_field(text)),
        )
    };
    let mut buf = [0u8; 32];
    if text.len() > buf.len() {
        return Err(bad(InputErrorKind::NotANumber, "not a number"));
    }
    for (b, &t) in buf.iter_mut().zip(text) {
        *b = if t == b'D' || t == b'd' { b'E' } else { t };
    }
    let s = std::str::from_utf8(&buf[..text.len()])
        .map_err(|_| bad(InputErrorKind::NotANumber, "not a number"))?;
    let x: f64 = s
        .parse()
        .map_err(|_| bad(InputErrorKind::NotANumber, "not a number"))?;
    if !x.is_finite() {
        return Err(bad(InputErrorKind::NotFinite, "not finite"));
    }
    Ok(x)
}

/// An integer field (a date's part, a count); an error naming the field otherwise.
pub(crate) fn int_field(
    text: &[u8],
    path: &Path,
    line: u64,
    name: &str,
) -> Result<i64, InputError> {
    std::str::from_utf8(text)
        .ok()
        .and_then(|s| s.trim().parse().ok())
        .ok_or_else(|| {
            InputError::new(
                InputErrorKind::NotANumber,
                path,
                line,
                Some(name),
                format!("not an integer: {}", quote_field(text)),
            )
        })
}

/// A calendar date and time of day in a system's time scale, as the GPS week and
/// second of week of the same clock reading; an error naming `path:line` and the
/// field "epoch" when it is not a valid date.
pub(crate) fn calendar(
    ymdhm: [i64; 5],
    sec: f64,
    path: &Path,
    line: u64,
) -> Result<GpsTime, InputError> {
    let [y, mo, d, h, mi] = ymdhm;
    let date = u32::try_from(mo)
        .ok()
        .zip(u32::try_from(d).ok())
        .and_then(|(mo, d)| chrono::NaiveDate::from_ymd_opt(i32::try_from(y).ok()?, mo, d));
    let ok_time = (0..24).contains(&h) && (0..60).contains(&mi) && (0.0..61.0).contains(&sec);
    match date {
        Some(date) if ok_time && y >= 1980 => {
            let sod = (h * 3600 + mi * 60) as f64 + sec;
            let (week, sow) = week_sow(date, sod, TimeScale::Gpst);
            Ok(GpsTime::new(week, sow))
        }
        _ => Err(InputError::new(
            InputErrorKind::OutOfDomain,
            path,
            line,
            Some("epoch"),
            format!("not a date and time: {y:04}-{mo:02}-{d:02} {h:02}:{mi:02}:{sec:06.3}"),
        )),
    }
}

/// The header of a navigation file: what the readers use of it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NavHeader {
    /// The format's version (2.11, 3.04, 4.01, …).
    pub version: f64,
    /// The file type's letter (`N`; `G` and `H` for RINEX 2 GLONASS and SBAS files).
    pub file_type: char,
    /// The system letter of a RINEX 3/4 file (`M` for mixed); `G` for RINEX 2 `N`.
    pub system: char,
    /// GPS's Klobuchar coefficients (`ION ALPHA`/`ION BETA`, `IONOSPHERIC CORR`
    /// `GPSA`/`GPSB`), when the header gives both halves.
    pub klobuchar: Option<Klobuchar>,
    /// BeiDou's Klobuchar-form coefficients (`BDSA`/`BDSB`), when given.
    pub beidou_klobuchar: Option<Klobuchar>,
    /// GPST − UTC [s] (`LEAP SECONDS`), when given.
    pub leap_seconds: Option<i64>,
    /// `TIME SYSTEM CORR` lines (and RINEX 2's `DELTA-UTC`, as `GPUT`).
    pub time_corrections: Vec<TimeCorrection>,
}

/// One time-system correction of the header: `a0 + a1·(t − t_ref)` [s] between two
/// scales (RINEX 3.05 §5.3: `GAGP` Galileo−GPS, `GPUT` GPS−UTC, `BDUT`, …).
#[derive(Debug, Clone, PartialEq)]
pub struct TimeCorrection {
    /// The four-letter kind (`GAGP`, `GPUT`, `BDUT`, …).
    pub kind: String,
    /// Offset [s].
    pub a0: f64,
    /// Rate [s/s].
    pub a1: f64,
    /// Reference second of week.
    pub t_ref_sow: f64,
    /// Reference week (in the scale's own count).
    pub week: i64,
}

/// The major version of a file, which decides the record layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Layout {
    V2,
    V3,
    V4,
}

/// A streaming reader of a RINEX navigation file: an iterator of ephemerides.
pub struct NavReader {
    lines: PeekLines,
    header: NavHeader,
    layout: Layout,
    klobuchar: Option<Klobuchar>,
    skipped: BTreeMap<String, u64>,
    failed: bool,
}

/// The names of a Keplerian record's 31 values, in file order (the first line's three
/// clock terms, then seven lines of four), for GPS/QZSS; Galileo and BeiDou rename a
/// few ([`field_name`]).
const NAMES: [&str; 31] = [
    "af0",
    "af1",
    "af2",
    "IODE",
    "Crs",
    "Delta_n",
    "M0",
    "Cuc",
    "e",
    "Cus",
    "sqrtA",
    "toe",
    "Cic",
    "OMEGA0",
    "Cis",
    "i0",
    "Crc",
    "omega",
    "OMEGA_DOT",
    "IDOT",
    "L2_codes",
    "week",
    "L2P_flag",
    "accuracy",
    "health",
    "TGD",
    "IODC",
    "transmission_time",
    "fit_interval",
    "spare",
    "spare",
];

/// Values a record must carry (the clock's af0 to the orbit's IDOT, and the week);
/// the others read as 0 when blank.
fn required(i: usize) -> bool {
    i <= 19 || i == 21
}

/// The name of value `i` of a record of `system`.
fn field_name(system: System, i: usize) -> &'static str {
    match (system, i) {
        (System::Galileo, 3) => "IODnav",
        (System::Galileo, 20) => "data_sources",
        (System::Galileo, 23) => "SISA",
        (System::Galileo, 25) => "BGD_E5a_E1",
        (System::Galileo, 26) => "BGD_E5b_E1",
        (System::Galileo, 28) => "spare",
        (System::BeiDou, 3) => "AODE",
        (System::BeiDou, 20) => "spare",
        (System::BeiDou, 24) => "SatH1",
        (System::BeiDou, 25) => "TGD1",
        (System::BeiDou, 26) => "TGD2",
        (System::BeiDou, 28) => "AODC",
        _ => NAMES[i],
    }
}

impl NavReader {
    /// Opens `path` (gzip-compressed or not) and reads its header.
    pub fn open(path: &Path) -> Result<Self, InputError> {
        Self::new(path, super::open(path)?)
    }

    /// Reads the header of `input`, named `path` in errors.
    pub fn new(path: &Path, input: Box<dyn BufRead + Send>) -> Result<Self, InputError> {
        let mut lines = PeekLines::new(path, input);
        let header = read_header(&mut lines)?;
        let layout = match header.version as i64 {
            2 => Layout::V2,
            3 => Layout::V3,
            _ => Layout::V4,
        };
        Ok(Self {
            lines,
            klobuchar: header.klobuchar,
            header,
            layout,
            skipped: BTreeMap::new(),
            failed: false,
        })
    }

    /// The header.
    pub fn header(&self) -> &NavHeader {
        &self.header
    }

    /// GPS's Klobuchar coefficients: the header's, or those of the latest RINEX 4
    /// `ION … LNAV` record read so far.
    pub fn klobuchar(&self) -> Option<Klobuchar> {
        self.klobuchar
    }

    /// The records skipped so far, counted by kind (`GLONASS`, `SBAS`, `NavIC`,
    /// `E CNAV`, `STO`, …).
    pub fn skipped(&self) -> &BTreeMap<String, u64> {
        &self.skipped
    }

    fn skip(&mut self, kind: String) {
        *self.skipped.entry(kind).or_default() += 1;
    }

    fn err(&self, kind: InputErrorKind, line: u64, field: Option<&str>, msg: String) -> InputError {
        InputError::new(kind, self.lines.path(), line, field, msg)
    }

    /// The next ephemeris, or `None` at the end of the file.
    fn next_ephemeris(&mut self) -> Result<Option<Ephemeris>, InputError> {
        while let Some((n, line)) = self.lines.next_line()? {
            if line.trim_ascii().is_empty() {
                continue;
            }
            let found = match self.layout {
                Layout::V2 => self.v2_record(n, line)?,
                Layout::V3 => self.v3_record(n, line)?,
                Layout::V4 => self.v4_record(n, line)?,
            };
            if found.is_some() {
                return Ok(found);
            }
        }
        Ok(None)
    }

    /// A RINEX 2 record beginning with `line` (number `n`).
    fn v2_record(&mut self, n: u64, line: Vec<u8>) -> Result<Option<Ephemeris>, InputError> {
        if self.header.file_type != 'N' {
            // GLONASS and SBAS records: the first line and three more.
            let kind = if self.header.file_type == 'G' {
                "GLONASS"
            } else {
                "SBAS"
            };
            for _ in 0..3 {
                self.lines.next_line()?;
            }
            self.skip(kind.to_owned());
            return Ok(None);
        }
        let prn = int_field(slice(&line, 0, 2), self.lines.path(), n, "PRN")?;
        let sat = u8::try_from(prn)
            .ok()
            .filter(|&p| p > 0)
            .map(|p| Sat::new(System::Gps, p))
            .ok_or_else(|| {
                self.err(
                    InputErrorKind::NotANumber,
                    n,
                    Some("PRN"),
                    format!("not a PRN: {prn}"),
                )
            })?;
        let int = |s: usize, name| int_field(slice(&line, s, 3), self.lines.path(), n, name);
        let yy = int(2, "epoch")?;
        let year = if yy < 80 {
            2000 + yy
        } else if yy < 100 {
            1900 + yy
        } else {
            yy
        };
        let ymdhm = [
            year,
            int(5, "epoch")?,
            int(8, "epoch")?,
            int(11, "epoch")?,
            int(14, "epoch")?,
        ];
        let sec = match field_text(&line, 17, 5) {
            Some(t) => fortran_f64(t, self.lines.path(), n, "epoch")?,
            None => 0.0,
        };
        let toc = calendar(ymdhm, sec, self.lines.path(), n)?;
        let values = self.values(sat, n, &line, 22, 3)?;
        self.build(sat, NavMessage::Lnav, toc, &values).map(Some)
    }

    /// A RINEX 3 record beginning with `line` (number `n`).
    fn v3_record(&mut self, n: u64, line: Vec<u8>) -> Result<Option<Ephemeris>, InputError> {
        let letter = line.first().copied().unwrap_or(b' ') as char;
        let system = System::from_letter(letter).filter(|_| letter != ' ');
        let message = match system {
            Some(System::Gps | System::Qzss) => Some(NavMessage::Lnav),
            Some(System::Galileo) => Some(NavMessage::Inav), // refined by its data sources
            Some(System::BeiDou) => Some(NavMessage::D1),    // D2 for the GEOs, below
            _ => None,
        };
        let (Some(system), Some(message)) = (system, message) else {
            // A system whose records are skipped (R, S, I), or a stray line.
            let kind = match system {
                Some(System::Glonass) => "GLONASS".to_owned(),
                Some(System::Sbas) => "SBAS".to_owned(),
                Some(System::Navic) => "NavIC".to_owned(),
                _ => {
                    return Err(self.err(
                        InputErrorKind::ColumnCount,
                        n,
                        Some("satellite"),
                        format!("not the start of a record: {}", quote_field(&line)),
                    ));
                }
            };
            self.skip_continuations()?;
            self.skip(kind);
            return Ok(None);
        };
        let sat = self.sat_at(&line, n, system)?;
        let message = if message == NavMessage::D1 && sat_is_geo(sat) {
            NavMessage::D2
        } else {
            message
        };
        let eph = self.v3_body(sat, message, n, &line)?;
        Ok(Some(eph))
    }

    /// The satellite named in columns 1–3 of a record's first line, of `system`.
    fn sat_at(&self, line: &[u8], n: u64, system: System) -> Result<Sat, InputError> {
        std::str::from_utf8(slice(line, 0, 3))
            .ok()
            .and_then(Sat::parse)
            .filter(|s| s.system == system)
            .ok_or_else(|| {
                self.err(
                    InputErrorKind::NotANumber,
                    n,
                    Some("satellite"),
                    format!("not a satellite: {}", quote_field(slice(line, 0, 3))),
                )
            })
    }

    /// A RINEX 3/4 Keplerian record's epoch and values, from its first line on.
    fn v3_body(
        &mut self,
        sat: Sat,
        message: NavMessage,
        n: u64,
        line: &[u8],
    ) -> Result<Ephemeris, InputError> {
        let path = self.lines.path();
        let int = |s: usize, w: usize| int_field(slice(line, s, w), path, n, "epoch");
        let ymdhm = [
            int(4, 4)?,
            int(9, 2)?,
            int(12, 2)?,
            int(15, 2)?,
            int(18, 2)?,
        ];
        let sec = int(21, 2)? as f64;
        let mut toc = calendar(ymdhm, sec, path, n)?;
        if sat.system == System::BeiDou {
            toc = toc.add_s(schuler::gnss::time::GPST_MINUS_BDT_S);
        }
        let values = self.values(sat, n, line, 23, 4)?;
        let mut message = message;
        if sat.system == System::Galileo && self.layout == Layout::V3 {
            // RINEX 3.04 Table A8: data-source bit 1 (F/NAV E5a-I) marks an F/NAV record.
            message = if (values.v[20] as u32) & 2 != 0 {
                NavMessage::Fnav
            } else {
                NavMessage::Inav
            };
        }
        self.build(sat, message, toc, &values)
    }

    /// The 31 values of a Keplerian record whose first line (number `n`) is `first`,
    /// values starting at column `col0` there and at `cont` on the 7 continuation lines.
    fn values(
        &mut self,
        sat: Sat,
        n: u64,
        first: &[u8],
        col0: usize,
        cont: usize,
    ) -> Result<Values, InputError> {
        let mut out = [0.0; 31];
        let mut at = [n; 31];
        let path = self.lines.path().to_path_buf();
        let mut put = |i: usize, line: &[u8], ln: u64, start: usize| -> Result<(), InputError> {
            let name = field_name(sat.system, i);
            at[i] = ln;
            match field_text(line, start, 19) {
                Some(t) => out[i] = fortran_f64(t, &path, ln, name)?,
                None if required(i) => {
                    return Err(InputError::new(
                        InputErrorKind::ColumnCount,
                        &path,
                        ln,
                        Some(name),
                        format!("truncated record of {sat}: field {name} is missing"),
                    ));
                }
                None => {}
            }
            Ok(())
        };
        for k in 0..3 {
            put(k, first, n, col0 + 19 * k)?;
        }
        let mut last = n;
        for row in 0..7 {
            // A continuation line begins with blanks where a record's first line has
            // its PRN (RINEX 2, `I2`) or its system letter (RINEX 3 and 4).
            let blank_at = if self.layout == Layout::V2 { 1 } else { 0 };
            let next_is_continuation = self
                .lines
                .peek()?
                .is_some_and(|l| l.get(blank_at) == Some(&b' '));
            let taken = if next_is_continuation {
                self.lines.next_line()?
            } else {
                None
            };
            let (ln, line) = taken.unwrap_or((last, Vec::new()));
            last = ln;
            for k in 0..4 {
                put(3 + 4 * row + k, &line, ln, cont + 19 * k)?;
            }
        }
        Ok(Values { v: out, line: at })
    }

    /// The ephemeris of `sat` from its record's values (checked for their domains).
    fn build(
        &self,
        sat: Sat,
        message: NavMessage,
        toc: GpsTime,
        values: &Values,
    ) -> Result<Ephemeris, InputError> {
        let v = &values.v;
        let domain = |i: usize, msg: String| {
            let name = field_name(sat.system, i);
            self.err(InputErrorKind::OutOfDomain, values.line[i], Some(name), msg)
        };
        if v[10] <= 0.0 {
            return Err(domain(10, format!("√A must be positive, got {}", v[10])));
        }
        if !(0.0..1.0).contains(&v[8]) {
            return Err(domain(
                8,
                format!("eccentricity must be in [0, 1), got {}", v[8]),
            ));
        }
        if !(0.0..=WEEK_S).contains(&v[11]) {
            return Err(domain(11, format!("not a second of week: {}", v[11])));
        }
        if !(0.0..1e5).contains(&v[21]) {
            return Err(domain(21, format!("not a week number: {}", v[21])));
        }
        let week = v[21] as i64;
        let mut toe = if sat.system == System::BeiDou {
            GpsTime::from_bdt(week, v[11])
        } else {
            GpsTime::new(week, v[11])
        };
        let weeks_off = (toe.diff_s(toc) / WEEK_S).round();
        if weeks_off != 0.0 {
            toe = toe.add_s(-weeks_off * WEEK_S);
        }
        let count = |x: f64| {
            if x.is_finite() && x > 0.0 {
                x.min(u32::MAX as f64) as u32
            } else {
                0
            }
        };
        Ok(Ephemeris {
            sat,
            message,
            toc,
            af0: v[0],
            af1: v[1],
            af2: v[2],
            toe,
            kepler: Kepler {
                crs: v[4],
                delta_n: v[5],
                m0: v[6],
                cuc: v[7],
                e: v[8],
                cus: v[9],
                sqrt_a: v[10],
                toe_sow: v[11],
                cic: v[12],
                omega0: v[13],
                cis: v[14],
                i0: v[15],
                crc: v[16],
                omega: v[17],
                omega_dot: v[18],
                i_dot: v[19],
            },
            iode: count(v[3]),
            iodc: match sat.system {
                System::Galileo => 0,
                System::BeiDou => count(v[28]),
                _ => count(v[26]),
            },
            health: count(v[24]),
            data_source: if sat.system == System::Galileo {
                count(v[20])
            } else {
                0
            },
            accuracy_m: v[23],
            group_delays: match sat.system {
                System::Galileo | System::BeiDou => [v[25], v[26]],
                _ => [v[25], 0.0],
            },
            // GPS's fit interval in hours (RINEX 3.05 Table A6); QZSS writes a flag there.
            fit_interval_s: if sat.system == System::Gps {
                v[28] * 3600.0
            } else {
                0.0
            },
        })
    }

    /// Takes the continuation lines (those beginning with a blank) after a record's
    /// first line.
    fn skip_continuations(&mut self) -> Result<(), InputError> {
        while let Some(l) = self.lines.peek()? {
            if l.first() != Some(&b' ') {
                break;
            }
            self.lines.next_line()?;
        }
        Ok(())
    }

    /// Takes the lines up to the next `>` record start (RINEX 4).
    fn skip_to_next_marker(&mut self) -> Result<(), InputError> {
        while let Some(l) = self.lines.peek()? {
            if l.first() == Some(&b'>') {
                break;
            }
            self.lines.next_line()?;
        }
        Ok(())
    }

    /// A RINEX 4 record introduced by `line` (number `n`): `> EPH G01 LNAV`,
    /// `> ION G01 LNAV`, `> STO …`, `> EOP …`.
    fn v4_record(&mut self, n: u64, line: Vec<u8>) -> Result<Option<Ephemeris>, InputError> {
        if line.first() != Some(&b'>') {
            return Err(self.err(
                InputErrorKind::ColumnCount,
                n,
                Some("record"),
                format!("expected a record's '>' line: {}", quote_field(&line)),
            ));
        }
        let text = String::from_utf8_lossy(&line);
        let mut words = text[1..].split_whitespace();
        let kind = words.next().unwrap_or("").to_owned();
        let sat_word = words.next().unwrap_or("").to_owned();
        let msg = words.next().unwrap_or("").to_owned();
        let sat = Sat::parse(&sat_word);
        let message = match (sat.map(|s| s.system), msg.as_str()) {
            (Some(System::Gps | System::Qzss), "LNAV") => Some(NavMessage::Lnav),
            (Some(System::Galileo), "INAV") => Some(NavMessage::Inav),
            (Some(System::Galileo), "FNAV") => Some(NavMessage::Fnav),
            (Some(System::BeiDou), "D1") => Some(NavMessage::D1),
            (Some(System::BeiDou), "D2") => Some(NavMessage::D2),
            _ => None,
        };
        match (kind.as_str(), sat, message) {
            ("EPH", Some(sat), Some(message)) => {
                let Some((n1, first)) = self.lines.next_line()? else {
                    return Err(self.err(
                        InputErrorKind::ColumnCount,
                        n,
                        Some("af0"),
                        format!("truncated record of {sat}: it ends after its '>' line"),
                    ));
                };
                let in_line = self.sat_at(&first, n1, sat.system)?;
                if in_line != sat {
                    return Err(self.err(
                        InputErrorKind::LayoutMismatch,
                        n1,
                        Some("satellite"),
                        format!("the record of {sat} holds {in_line}"),
                    ));
                }
                self.v3_body(sat, message, n1, &first).map(Some)
            }
            ("ION", Some(sat), _) if sat.system == System::Gps && msg == "LNAV" => {
                self.klobuchar = Some(self.v4_klobuchar()?);
                self.skip_to_next_marker()?;
                Ok(None)
            }
            _ => {
                let label = if kind == "EPH" {
                    let sys = sat.map_or('?', |s| s.system.letter());
                    format!("EPH {sys} {msg}")
                } else {
                    kind
                };
                self.skip_to_next_marker()?;
                self.skip(label);
                Ok(None)
            }
        }
    }

    /// The eight coefficients of a RINEX 4 `ION … LNAV` record (after its `>` line):
    /// epoch and α0–α2, then α3, β0–β2, then β3 and the region flag.
    fn v4_klobuchar(&mut self) -> Result<Klobuchar, InputError> {
        let mut v = [0.0; 8];
        let names = [
            "alpha0", "alpha1", "alpha2", "alpha3", "beta0", "beta1", "beta2", "beta3",
        ];
        let spots: [(usize, usize); 8] = [
            (0, 23),
            (0, 42),
            (0, 61),
            (1, 4),
            (1, 23),
            (1, 42),
            (1, 61),
            (2, 4),
        ];
        let mut lines = Vec::new();
        for _ in 0..3 {
            match self.lines.peek()? {
                Some(l) if l.first() != Some(&b'>') => lines.push(self.lines.next_line()?),
                _ => break,
            }
        }
        for (i, &(row, col)) in spots.iter().enumerate() {
            let (ln, line) = match lines.get(row) {
                Some(Some((ln, l))) => (*ln, l.as_slice()),
                _ => (self.lines.line_no(), &[][..]),
            };
            let t = field_text(line, col, 19).ok_or_else(|| {
                self.err(
                    InputErrorKind::ColumnCount,
                    ln,
                    Some(names[i]),
                    format!("truncated ION record: {} is missing", names[i]),
                )
            })?;
            v[i] = fortran_f64(t, self.lines.path(), ln, names[i])?;
        }
        Ok(Klobuchar {
            alpha: [v[0], v[1], v[2], v[3]],
            beta: [v[4], v[5], v[6], v[7]],
        })
    }
}

/// A Keplerian record's 31 values and the line each was read from.
struct Values {
    v: [f64; 31],
    line: [u64; 31],
}

/// Whether a BeiDou GEO (D2 message in RINEX 3, which does not say).
fn sat_is_geo(sat: Sat) -> bool {
    sat.system == System::BeiDou && matches!(sat.prn, 1..=5 | 59..=63)
}

impl Iterator for NavReader {
    type Item = Result<Ephemeris, InputError>;

    /// The next ephemeris; after an error, `None`.
    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        let r = self.next_ephemeris();
        if r.is_err() {
            self.failed = true;
        }
        r.transpose()
    }
}

/// Reads a whole navigation file into a store; with its header and the Klobuchar
/// coefficients (the header's, or a RINEX 4 file's last `ION` record's).
pub fn read_store(
    path: &Path,
) -> Result<(NavHeader, Option<Klobuchar>, EphemerisStore), InputError> {
    let mut reader = NavReader::open(path)?;
    let mut store = EphemerisStore::new();
    for eph in reader.by_ref() {
        store.push(eph?);
    }
    Ok((reader.header().clone(), reader.klobuchar(), store))
}

/// The header, up to `END OF HEADER`.
fn read_header(lines: &mut PeekLines) -> Result<NavHeader, InputError> {
    let path = lines.path().to_path_buf();
    let header_err = |n: u64, field: &str, msg: String| {
        InputError::new(InputErrorKind::Header, &path, n, Some(field), msg)
    };
    let mut h = NavHeader::default();
    let mut halves: BTreeMap<String, [f64; 4]> = BTreeMap::new();
    let mut seen_version = false;
    loop {
        let Some((n, raw)) = lines.next_line()? else {
            return Err(header_err(
                lines.line_no(),
                "END OF HEADER",
                "the header never ends (no END OF HEADER line)".into(),
            ));
        };
        let text = String::from_utf8_lossy(&raw);
        let (content, label) = header_label(&text);
        let content = content.as_bytes();
        if !seen_version {
            if label != "RINEX VERSION / TYPE" {
                return Err(header_err(
                    n,
                    "RINEX VERSION / TYPE",
                    "not a RINEX file: its first line is not RINEX VERSION / TYPE".into(),
                ));
            }
            let v_text = field_text(content, 0, 9).unwrap_or(b"");
            h.version = fortran_f64(v_text, &path, n, "version")?;
            if !(2.0..5.0).contains(&h.version) {
                return Err(header_err(
                    n,
                    "version",
                    format!("RINEX version {} is not 2, 3 or 4", h.version),
                ));
            }
            h.file_type = slice(content, 20, 1).first().copied().unwrap_or(b' ') as char;
            h.system = slice(content, 40, 1).first().copied().unwrap_or(b' ') as char;
            let nav = if h.version < 3.0 {
                matches!(h.file_type, 'N' | 'G' | 'H')
            } else {
                h.file_type == 'N'
            };
            if !nav {
                return Err(header_err(
                    n,
                    "file type",
                    format!("not a navigation file: type {:?}", h.file_type),
                ));
            }
            if h.version < 3.0 {
                h.system = match h.file_type {
                    'N' => 'G',
                    'G' => 'R',
                    _ => 'S',
                };
            }
            seen_version = true;
            continue;
        }
        let num = |start: usize, width: usize, name: &str| -> Result<f64, InputError> {
            match field_text(content, start, width) {
                Some(t) => fortran_f64(t, &path, n, name),
                None => Ok(0.0),
            }
        };
        match label {
            "END OF HEADER" => break,
            "ION ALPHA" | "ION BETA" => {
                let mut c = [0.0; 4];
                for (k, x) in c.iter_mut().enumerate() {
                    *x = num(2 + 12 * k, 12, label)?;
                }
                let key = if label == "ION ALPHA" { "GPSA" } else { "GPSB" };
                halves.insert(key.into(), c);
            }
            "IONOSPHERIC CORR" => {
                let kind = String::from_utf8_lossy(slice(content, 0, 4))
                    .trim()
                    .to_owned();
                let mut c = [0.0; 4];
                for (k, x) in c.iter_mut().enumerate() {
                    *x = num(5 + 12 * k, 12, &format!("IONOSPHERIC CORR {kind}"))?;
                }
                halves.insert(kind, c);
            }
            "LEAP SECONDS" => {
                let t = field_text(content, 0, 6).unwrap_or(b"");
                h.leap_seconds = Some(int_field(t, &path, n, "LEAP SECONDS")?);
            }
            "TIME SYSTEM CORR" => {
                let kind = String::from_utf8_lossy(slice(content, 0, 4))
                    .trim()
                    .to_owned();
                let name = format!("TIME SYSTEM CORR {kind}");
                h.time_corrections.push(TimeCorrection {
                    a0: num(5, 17, &name)?,
                    a1: num(22, 16, &name)?,
                    t_ref_sow: num(38, 7, &name)?,
                    week: num(45, 5, &name)? as i64,
                    kind,
                });
            }
            "DELTA-UTC: A0,A1,T,W" => {
                let name = "DELTA-UTC";
                h.time_corrections.push(TimeCorrection {
                    a0: num(3, 19, name)?,
                    a1: num(22, 19, name)?,
                    t_ref_sow: num(41, 9, name)?,
                    week: num(50, 9, name)? as i64,
                    kind: "GPUT".into(),
                });
            }
            _ => {}
        }
    }
    let pair = |a: &str, b: &str| match (halves.get(a), halves.get(b)) {
        (Some(&alpha), Some(&beta)) => Some(Klobuchar { alpha, beta }),
        _ => None,
    };
    h.klobuchar = pair("GPSA", "GPSB");
    h.beidou_klobuchar = pair("BDSA", "BDSB");
    Ok(h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::temp_file;
    use proptest::prelude::*;

    fn data(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../tests/data/orbits")
            .join(name)
    }

    /// A reader of `text`, named `t.rnx` in errors.
    fn reader(text: &str) -> Result<NavReader, InputError> {
        let bytes = text.as_bytes().to_vec();
        NavReader::new(Path::new("t.rnx"), Box::new(std::io::Cursor::new(bytes)))
    }

    /// Every ephemeris of `text`, or the first error.
    fn read(text: &str) -> Result<Vec<Ephemeris>, InputError> {
        reader(text)?.collect()
    }

    fn header_line(content: &str, label: &str) -> String {
        format!("{content:<60}{label}\n")
    }

    /// A RINEX 3.04 mixed file's header.
    fn v3_header() -> String {
        header_line(
            "     3.04           N: GNSS NAV DATA    M: MIXED",
            "RINEX VERSION / TYPE",
        ) + &header_line("", "END OF HEADER")
    }

    /// G02's record of brdc1820.10n (2010-07-01 00:00) in RINEX 3 layout.
    const G02_V3: &str = "\
G02 2010 07 01 00 00 00 2.691089175640D-04 3.183231456205D-12 0.000000000000D+00
     8.500000000000D+01 4.143750000000D+01 5.255575974420D-09 1.657721674120D+00
     2.322718501091D-06 9.606978041120D-03 6.174668669701D-06 5.153597391130D+03
     3.456000000000D+05-5.587935447693D-09-1.274587197640D+00 1.676380634308D-07
     9.393491506110D-01 2.499375000000D+02 3.097399039490D+00-8.387849526060D-09
    -2.321525263690D-11 1.000000000000D+00 1.590000000000D+03 0.000000000000D+00
     2.000000000000D+00 0.000000000000D+00-1.722946763039D-08 8.500000000000D+01
     3.384180000000D+05 4.000000000000D+00
";

    #[test]
    fn rinex2_gps_file_with_its_header() {
        let (header, klob, store) = read_store(&data("brdc1820.10n.gz")).unwrap();
        assert_eq!(header.version, 2.0);
        assert_eq!((header.file_type, header.system), ('N', 'G'));
        assert_eq!(header.leap_seconds, Some(15));
        let k = klob.unwrap();
        assert_eq!(k.alpha, [0.4657e-08, 0.1490e-07, -0.5960e-07, -0.1192e-06]);
        assert_eq!(k.beta, [0.8192e+05, 0.8192e+05, -0.6554e+05, -0.5243e+06]);
        let utc = &header.time_corrections[0];
        assert_eq!(
            (utc.kind.as_str(), utc.week, utc.t_ref_sow),
            ("GPUT", 566, 503_808.0)
        );
        assert_eq!(utc.a0, -0.838190317154e-08);
        // 421 records of 8 lines after an 8-line header.
        assert_eq!(store.len(), 421);
        let g02 = &store.of(Sat::new(System::Gps, 2))[0];
        assert_eq!(g02.af0, 0.269108917564e-03);
        assert_eq!(g02.kepler.sqrt_a, 0.515359739113e+04);
        assert_eq!(g02.kepler.omega_dot, -0.838784952606e-08);
        assert_eq!(g02.group_delays, [-0.172294676304e-07, 0.0]);
        assert_eq!((g02.iode, g02.iodc, g02.health), (85, 85, 0));
        assert_eq!(g02.fit_interval_s, 4.0 * 3600.0);
        assert_eq!(g02.toc, GpsTime::new(1590, 345_600.0));
        assert_eq!(g02.toe, GpsTime::new(1590, 345_600.0));
        // SVN49 (G01) is read, and marked unhealthy.
        assert_eq!(store.of(Sat::new(System::Gps, 1))[0].health, 63);
    }

    #[test]
    fn rinex3_mixed_file_skips_glonass_and_sbas() {
        let mut r = NavReader::open(&data("MOJN00DNK_R_20201770000_01D_MN_subset.rnx.gz")).unwrap();
        let h = r.header().clone();
        assert_eq!((h.version, h.file_type, h.system), (3.05, 'N', 'M'));
        assert_eq!(h.leap_seconds, Some(18));
        assert_eq!(h.time_corrections.len(), 3);
        assert_eq!(h.time_corrections[0].kind, "GAGP");
        assert_eq!(h.klobuchar.unwrap().alpha[0], 4.6566e-09);
        let mut count: BTreeMap<(char, NavMessage), usize> = BTreeMap::new();
        let mut c05 = None;
        for e in r.by_ref() {
            let e = e.unwrap();
            *count.entry((e.sat.system.letter(), e.message)).or_default() += 1;
            if e.sat == Sat::new(System::BeiDou, 5) && c05.is_none() {
                c05 = Some(e);
            }
        }
        let want = [
            (('C', NavMessage::D1), 318),
            (('C', NavMessage::D2), 26),
            (('E', NavMessage::Inav), 139),
            (('E', NavMessage::Fnav), 139),
            (('G', NavMessage::Lnav), 240),
            (('J', NavMessage::Lnav), 20),
        ];
        assert_eq!(count, want.into_iter().collect());
        assert_eq!(r.skipped().get("GLONASS"), Some(&6));
        assert_eq!(r.skipped().get("SBAS"), Some(&6));
        // BeiDou's times are BDT: C05's 2020-06-24 22:00:00 BDT (a Wednesday of GPS
        // week 2111) is 338414 s GPST; its toe, 338400 s of BDT week 755, the same.
        let c05 = c05.unwrap();
        assert_eq!(c05.toc, GpsTime::new(2111, 338_414.0));
        assert_eq!(c05.toe, GpsTime::new(2111, 338_414.0));
        assert_eq!(c05.kepler.toe_sow, 338_400.0);
    }

    #[test]
    fn rinex4_records_by_message() {
        let mut r = NavReader::open(&data("KMS300DNK_R_20221591000_01H_MN.rnx.gz")).unwrap();
        assert_eq!(r.header().version, 4.0);
        assert_eq!(r.klobuchar(), None);
        let mut count: BTreeMap<(char, NavMessage), usize> = BTreeMap::new();
        for e in r.by_ref() {
            let e = e.unwrap();
            *count.entry((e.sat.system.letter(), e.message)).or_default() += 1;
        }
        let want = [
            (('C', NavMessage::D1), 33),
            (('C', NavMessage::D2), 3),
            (('E', NavMessage::Inav), 55),
            (('E', NavMessage::Fnav), 53),
            (('G', NavMessage::Lnav), 30),
            (('J', NavMessage::Lnav), 1),
        ];
        assert_eq!(count, want.into_iter().collect());
        let skipped: Vec<(&str, u64)> = r.skipped().iter().map(|(k, v)| (k.as_str(), *v)).collect();
        assert_eq!(
            skipped,
            [
                ("EPH R FDMA", 24),
                ("EPH S SBAS", 158),
                ("ION", 2),
                ("STO", 3)
            ]
        );
        // The GPS ION record (G29 LNAV, 09:59:48).
        let k = r.klobuchar().unwrap();
        assert_eq!(
            k.alpha,
            [
                1.024454832077e-08,
                2.235174179077e-08,
                -5.960464477539e-08,
                -1.192092895508e-07
            ]
        );
        assert_eq!(k.beta, [9.6256e4, 1.31072e5, -6.5536e4, -5.89824e5]);
    }

    #[test]
    fn fortran_exponents_and_rinex3_layout() {
        let e = read(&(v3_header() + G02_V3)).unwrap();
        assert_eq!(e.len(), 1);
        assert_eq!(e[0].kepler.e, 9.606978041120e-03);
        assert_eq!(e[0].sat, Sat::new(System::Gps, 2));
        let shown = e[0].orbit_at(e[0].toe).r_e / 1e3;
        // The same orbit as the RINEX 2 file's (orbit.rs checks it against the SP3).
        assert!((shown.x + 14_889.16).abs() < 0.01, "{shown}");
    }

    #[test]
    fn a_truncated_record_names_the_missing_field() {
        // The record cut after its third orbit line, then the next record.
        let cut: String = G02_V3.lines().take(4).map(|l| format!("{l}\n")).collect();
        let text = v3_header() + &cut + G02_V3;
        let e = read(&text).unwrap_err();
        assert_eq!(e.kind, InputErrorKind::ColumnCount);
        assert_eq!((e.line, e.field.as_deref()), (6, Some("i0")), "{e}");
        assert!(
            e.to_string()
                .starts_with("t.rnx:6: field i0: truncated record of G02"),
            "{e}"
        );
        // At the end of the file.
        let e = read(&(v3_header() + &cut)).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("i0"), "{e}");
        // A line cut inside a field's columns.
        let short = G02_V3.replacen(" 5.153597391130D+03", "", 1);
        let e = read(&(v3_header() + &short)).unwrap_err();
        assert_eq!((e.line, e.field.as_deref()), (5, Some("sqrtA")), "{e}");
    }

    #[test]
    fn a_garbled_number_names_its_field() {
        let bad = G02_V3.replacen("3.456000000000D+05", "3.456000x00000D+05", 1);
        let e = read(&(v3_header() + &bad)).unwrap_err();
        assert_eq!(e.kind, InputErrorKind::NotANumber);
        assert_eq!((e.line, e.field.as_deref()), (6, Some("toe")), "{e}");
        assert!(e.message.contains("3.456000x00000D+05"), "{e}");
        let bad = G02_V3.replacen("9.606978041120D-03", "1.606978041120D+00", 1);
        let e = read(&(v3_header() + &bad)).unwrap_err();
        assert_eq!(
            (e.kind, e.line, e.field.as_deref()),
            (InputErrorKind::OutOfDomain, 5, Some("e"))
        );
        let bad = G02_V3.replacen(" 5.153597391130D+03", "-5.153597391130D+03", 1);
        let e = read(&(v3_header() + &bad)).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("sqrtA"), "{e}");
        let bad = G02_V3.replacen("G02 2010 07 01", "G02 2010 13 01", 1);
        let e = read(&(v3_header() + &bad)).unwrap_err();
        assert_eq!((e.line, e.field.as_deref()), (3, Some("epoch")), "{e}");
        let bad = G02_V3.replacen(" 2.691089175640D-04", "                NaN", 1);
        let e = read(&(v3_header() + &bad)).unwrap_err();
        assert_eq!(
            (e.kind, e.field.as_deref()),
            (InputErrorKind::NotFinite, Some("af0"))
        );
    }

    #[test]
    fn header_errors() {
        let v5 = header_line(
            "     5.00           N: GNSS NAV DATA    M",
            "RINEX VERSION / TYPE",
        ) + &header_line("", "END OF HEADER");
        let e = read(&v5).unwrap_err();
        assert_eq!(
            (e.kind, e.line, e.field.as_deref()),
            (InputErrorKind::Header, 1, Some("version"))
        );
        assert!(e.message.contains("not 2, 3 or 4"), "{e}");
        let obs = header_line(
            "     3.04           OBSERVATION DATA    M",
            "RINEX VERSION / TYPE",
        );
        let e = read(&obs).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("file type"), "{e}");
        let e = read("G02 2010 07 01 00 00 00\n").unwrap_err();
        assert_eq!(e.field.as_deref(), Some("RINEX VERSION / TYPE"), "{e}");
        let unended = header_line(
            "     3.04           N: GNSS NAV DATA    M",
            "RINEX VERSION / TYPE",
        );
        let e = read(&unended).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("END OF HEADER"), "{e}");
        let bad_ion = header_line(
            "     2.11           N: GPS NAV DATA",
            "RINEX VERSION / TYPE",
        ) + &header_line(
            "    0.4657D-08  0.1490D-0x -0.5960D-07 -0.1192D-06",
            "ION ALPHA",
        );
        let e = read(&bad_ion).unwrap_err();
        assert_eq!((e.line, e.field.as_deref()), (2, Some("ION ALPHA")), "{e}");
        let missing = NavReader::open(Path::new("/no/such/brdc.rnx"))
            .err()
            .unwrap();
        assert_eq!(missing.kind, InputErrorKind::Io);
    }

    #[test]
    fn rinex2_glonass_files_are_skipped_with_a_count() {
        let text = header_line(
            "     2.11           G: GLONASS NAV DATA",
            "RINEX VERSION / TYPE",
        ) + &header_line("", "END OF HEADER")
            + " 1 10  7  1  0 15  0.0 0.1D-03 0.1D-08 0.3D+05\n"
            + "    0.1D+05 0.1D+01 0.1D-08 0.0D+00\n".repeat(3).as_str()
            + " 2 10  7  1  0 15  0.0 0.1D-03 0.1D-08 0.3D+05\n"
            + "    0.1D+05 0.1D+01 0.1D-08 0.0D+00\n".repeat(3).as_str();
        let mut r = reader(&text).unwrap();
        assert_eq!(r.by_ref().count(), 0);
        assert_eq!(r.skipped().get("GLONASS"), Some(&2));
    }

    #[test]
    fn a_file_on_disk_gzipped_or_not() {
        let f = temp_file(&(v3_header() + G02_V3));
        let (_, _, store) = read_store(f.path()).unwrap();
        assert_eq!(store.len(), 1);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..3000)) {
            let input = Box::new(std::io::Cursor::new(bytes));
            if let Ok(r) = NavReader::new(Path::new("x"), input) {
                for _ in r.take(100) {}
            }
        }

        #[test]
        fn spoilt_records_never_panic(
            cut in 0usize..700,
            byte in any::<u8>(),
            at in 0usize..700,
            v in 0usize..3,
        ) {
            let head = [v3_header(), header_line("     4.01           N: GNSS NAV DATA    M", "RINEX VERSION / TYPE") + &header_line("", "END OF HEADER"), header_line("     2.11           N: GPS NAV DATA", "RINEX VERSION / TYPE") + &header_line("", "END OF HEADER")];
            let body = match v {
                0 => G02_V3.to_owned(),
                1 => format!("> EPH G02 LNAV\n{G02_V3}> ION G02 LNAV\n    2022 06 08 09 59 48 1.0E-08 2.2E-08\n"),
                _ => G02_V3.replacen("G02 2010", " 2 10", 1),
            };
            let mut bytes = (head[v].clone() + &body + &body).into_bytes();
            let n = bytes.len();
            bytes[n.min(at + head[v].len()).min(n - 1)] = byte;
            bytes.truncate(head[v].len() + cut.min(n));
            let input = Box::new(std::io::Cursor::new(bytes));
            if let Ok(r) = NavReader::new(Path::new("x"), input) {
                for _ in r.take(100) {}
            }
        }
    }
}
