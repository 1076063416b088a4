//! The header of a RINEX observation file: what the reader keeps of it, read one
//! labelled line at a time (so that the header records of a flag 3 or 4 event update
//! it the same way).

use super::codes::{MAX_CODES_PER_SYSTEM, ObsCode, ObsCodes, slot};
use super::fields::{blank, cols, decimal, integer, trim};
use crate::formats::InputError;
use crate::formats::error::{InputErrorKind, quote_field};
use crate::formats::rinex::header_label;
use chrono::{NaiveDate, NaiveDateTime, NaiveTime};
use nalgebra::Vector3;
use schuler::gnss::{Sat, System};
use std::path::Path;
use std::sync::Arc;

/// A RINEX (or Hatanaka) format version, `3.04` as major 3, minor 4.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct Version {
    /// 2, 3 or 4 for RINEX; 1 or 3 for Hatanaka's compact RINEX.
    pub major: u8,
    /// The hundredths (`2.11` → 11, `3.04` → 4).
    pub minor: u8,
}

/// The time scale of an observation file's epochs (`TIME OF FIRST OBS`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeSystem {
    /// GPS time.
    Gps,
    /// GLONASS time: UTC(SU) + 3 h.
    Glonass,
    /// Galileo system time (steered to GPS time).
    Galileo,
    /// BeiDou time: GPS time − 14 s.
    BeiDou,
    /// QZSS time (steered to GPS time).
    Qzss,
    /// NavIC time (steered to GPS time).
    Navic,
}

/// The antenna reference point's offset from the marker [m].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AntennaDelta {
    /// Up.
    pub height: f64,
    /// East.
    pub east: f64,
    /// North.
    pub north: f64,
}

/// What the reader keeps of an observation file's header.
#[derive(Debug, Clone, PartialEq)]
pub struct ObsHeader {
    /// `RINEX VERSION / TYPE`: 2.xx, 3.0x or 4.0x.
    pub version: Version,
    /// The compact RINEX (Hatanaka) version when the file is compressed (1.0 or 3.0).
    pub crinex: Option<Version>,
    /// `MARKER NAME`, trimmed (empty when absent).
    pub marker_name: String,
    /// `APPROX POSITION XYZ`: the marker's approximate position, ECEF [m].
    pub approx_position: Option<Vector3<f64>>,
    /// `ANTENNA: DELTA H/E/N` [m].
    pub antenna_delta: Option<AntennaDelta>,
    /// The observation codes of each system, RINEX 2's mapped (see the `codes`
    /// module), in the order of the file's columns.
    pub codes: Arc<ObsCodes>,
    /// RINEX 2's `# / TYPES OF OBSERV` as written (`C1`, `P2`…); empty for RINEX 3
    /// and 4.
    pub rinex2_codes: Vec<String>,
    /// The time scale of the epochs.
    pub time_system: TimeSystem,
    /// `TIME OF FIRST OBS`, in [`Self::time_system`].
    pub time_of_first_obs: Option<NaiveDateTime>,
    /// `INTERVAL` [s].
    pub interval: Option<f64>,
    /// `LEAP SECONDS`: GPS time − UTC [s] when the file says.
    pub leap_seconds: Option<i32>,
    /// `GLONASS SLOT / FRQ #`: each GLONASS slot's frequency channel (−7…+6).
    pub glonass_channels: Vec<(u8, i8)>,
    /// Divisors of `SYS / SCALE FACTOR` per system and column (empty: none).
    pub(crate) divisors: [Vec<f64>; System::ALL.len()],
}

impl ObsHeader {
    /// The observation codes of `system`'s columns.
    pub fn codes_of(&self, system: System) -> &[ObsCode] {
        self.codes.of(system)
    }

    /// The number of columns a satellite of `system` has in the data records.
    pub(crate) fn columns(&self, system: System) -> usize {
        self.codes.of(system).len()
    }

    /// The name of column `i` of `system` as the file writes it: RINEX 2's two
    /// characters (`P2`), else the RINEX 3 code (`C1C`).
    pub fn column_name(&self, system: System, i: usize) -> String {
        match self.rinex2_codes.get(i) {
            Some(c) => c.clone(),
            None => self
                .codes
                .of(system)
                .get(i)
                .map_or_else(|| format!("observation {}", i + 1), ToString::to_string),
        }
    }
}

/// Reads header lines into an [`ObsHeader`].
#[derive(Debug)]
pub(crate) struct HeaderBuilder {
    header: ObsHeader,
    /// The file's system letter (`RINEX VERSION / TYPE`, column 41).
    file_system: u8,
    /// Whether the time system was given by `TIME OF FIRST OBS`.
    time_system_given: bool,
    /// RINEX 2: the count of `# / TYPES OF OBSERV` still to come on continuations.
    rinex2_pending: usize,
    /// RINEX 3: the system and count of `SYS / # / OBS TYPES` still to come.
    rinex3_pending: Option<(System, usize)>,
    rinex3_lists: [Option<Vec<ObsCode>>; System::ALL.len()],
    /// `SYS / SCALE FACTOR`: (system, divisor, codes or all when empty).
    scale_factors: Vec<(System, f64, Vec<ObsCode>)>,
    scale_pending: Option<usize>,
    glonass_pending: usize,
    version_seen: bool,
    types_changed: bool,
}

/// An error in header line `line` of `path`, naming `field`.
fn error(path: &Path, line: u64, field: &str, message: impl Into<String>) -> InputError {
    InputError::new(InputErrorKind::Header, path, line, Some(field), message)
}

impl HeaderBuilder {
    /// A builder for a new file, whose first line is the version line.
    pub(crate) fn new(crinex: Option<Version>) -> Self {
        Self::from_header(ObsHeader {
            version: Version { major: 0, minor: 0 },
            crinex,
            marker_name: String::new(),
            approx_position: None,
            antenna_delta: None,
            codes: Arc::default(),
            rinex2_codes: Vec::new(),
            time_system: TimeSystem::Gps,
            time_of_first_obs: None,
            interval: None,
            leap_seconds: None,
            glonass_channels: Vec::new(),
            divisors: Default::default(),
        })
    }

    /// A builder that updates `header` with the header records of an event.
    pub(crate) fn from_header(header: ObsHeader) -> Self {
        let version_seen = header.version.major != 0;
        Self {
            header,
            file_system: b'G',
            time_system_given: version_seen,
            rinex2_pending: 0,
            rinex3_pending: None,
            rinex3_lists: Default::default(),
            scale_factors: Vec::new(),
            scale_pending: None,
            glonass_pending: 0,
            version_seen,
            types_changed: false,
        }
    }

    /// Reads one header line (number `n`); `Ok(true)` at `END OF HEADER`.
    pub(crate) fn line(&mut self, path: &Path, n: u64, line: &[u8]) -> Result<bool, InputError> {
        let text = String::from_utf8_lossy(line);
        let (content, label) = header_label(&text);
        let c = content.as_bytes();
        if !self.version_seen && label != "RINEX VERSION / TYPE" {
            return Err(error(
                path,
                n,
                "RINEX VERSION / TYPE",
                format!("not a RINEX observation file: first record is {:?}", label),
            ));
        }
        let number = |a: usize, b: usize| -> Result<Option<f64>, InputError> {
            decimal(cols(c, a, b)).map_err(|()| {
                error(
                    path,
                    n,
                    label,
                    format!("not a number: {}", quote_field(cols(c, a, b))),
                )
            })
        };
        let int = |a: usize, b: usize| -> Result<Option<i64>, InputError> {
            integer(cols(c, a, b)).map_err(|()| {
                error(
                    path,
                    n,
                    label,
                    format!("not an integer: {}", quote_field(cols(c, a, b))),
                )
            })
        };
        match label {
            "RINEX VERSION / TYPE" => self.version(path, n, c)?,
            "MARKER NAME" => self.header.marker_name = content.trim().to_owned(),
            "APPROX POSITION XYZ" => {
                if let (Some(x), Some(y), Some(z)) =
                    (number(0, 14)?, number(14, 28)?, number(28, 42)?)
                {
                    self.header.approx_position = Some(Vector3::new(x, y, z));
                }
            }
            "ANTENNA: DELTA H/E/N" => {
                let h = number(0, 14)?.unwrap_or(0.0);
                let e = number(14, 28)?.unwrap_or(0.0);
                let north = number(28, 42)?.unwrap_or(0.0);
                self.header.antenna_delta = Some(AntennaDelta {
                    height: h,
                    east: e,
                    north,
                });
            }
            "# / TYPES OF OBSERV" => self.rinex2_types(path, n, c, int(0, 6)?)?,
            "SYS / # / OBS TYPES" => self.rinex3_types(path, n, c)?,
            "SYS / SCALE FACTOR" => self.scale_factor(path, n, c)?,
            "TIME OF FIRST OBS" => self.first_obs(path, n, c)?,
            "INTERVAL" => self.header.interval = number(0, 10)?,
            "LEAP SECONDS" => {
                self.header.leap_seconds = int(0, 6)?.and_then(|v| i32::try_from(v).ok());
            }
            "GLONASS SLOT / FRQ #" => self.glonass(path, n, c)?,
            "END OF HEADER" => return Ok(true),
            _ => {}
        }
        Ok(false)
    }

    /// `RINEX VERSION / TYPE`: F9.2, the file type `O` at column 21, the system at 41.
    fn version(&mut self, path: &Path, n: u64, c: &[u8]) -> Result<(), InputError> {
        const LABEL: &str = "RINEX VERSION / TYPE";
        let version = parse_version(cols(c, 0, 9)).ok_or_else(|| {
            error(
                path,
                n,
                LABEL,
                format!("no version: {}", quote_field(cols(c, 0, 9))),
            )
        })?;
        if !matches!(version.major, 2..=4) {
            return Err(error(
                path,
                n,
                LABEL,
                format!(
                    "RINEX version {}.{:02} is not supported (2.xx, 3.0x and 4.0x are)",
                    version.major, version.minor
                ),
            ));
        }
        if cols(c, 20, 21) != b"O" {
            return Err(error(
                path,
                n,
                LABEL,
                format!(
                    "not an observation file (file type {})",
                    quote_field(cols(c, 20, 21))
                ),
            ));
        }
        self.header.version = version;
        self.file_system = cols(c, 40, 41).first().copied().unwrap_or(b' ');
        self.version_seen = true;
        Ok(())
    }

    /// RINEX 2's `# / TYPES OF OBSERV`: I6 count, then nine (4X, A2) codes a line.
    fn rinex2_types(
        &mut self,
        path: &Path,
        n: u64,
        c: &[u8],
        count: Option<i64>,
    ) -> Result<(), InputError> {
        const LABEL: &str = "# / TYPES OF OBSERV";
        if let Some(count) = count {
            let count = usize::try_from(count)
                .ok()
                .filter(|&k| k <= MAX_CODES_PER_SYSTEM)
                .ok_or_else(|| {
                    error(
                        path,
                        n,
                        LABEL,
                        format!("{count} observation types (at most {MAX_CODES_PER_SYSTEM})"),
                    )
                })?;
            self.header.rinex2_codes.clear();
            self.rinex2_pending = count;
            self.types_changed = true;
        } else if self.rinex2_pending == 0 {
            return Err(error(
                path,
                n,
                LABEL,
                "a continuation line with no list to continue",
            ));
        }
        for i in 0..9 {
            if self.rinex2_pending == 0 {
                break;
            }
            let code = trim(cols(c, 6 * i + 6, 6 * i + 12));
            if code.is_empty() {
                return Err(error(
                    path,
                    n,
                    LABEL,
                    format!("{} more observation types announced", self.rinex2_pending),
                ));
            }
            let code = String::from_utf8_lossy(code).into_owned();
            if ObsCode::from_rinex2(&code, System::Gps).is_none() {
                return Err(error(
                    path,
                    n,
                    &code,
                    format!("unknown RINEX 2 observation code {code:?} in {LABEL}"),
                ));
            }
            self.header.rinex2_codes.push(code);
            self.rinex2_pending -= 1;
        }
        Ok(())
    }

    /// RINEX 3's `SYS / # / OBS TYPES`: A1 system, I3 count at columns 4–6, then 13
    /// (1X, A3) codes a line; continuations have a blank system.
    fn rinex3_types(&mut self, path: &Path, n: u64, c: &[u8]) -> Result<(), InputError> {
        const LABEL: &str = "SYS / # / OBS TYPES";
        let letter = cols(c, 0, 1).first().copied().unwrap_or(b' ');
        let (system, mut pending) = if letter != b' ' {
            let system = System::from_letter(char::from(letter)).ok_or_else(|| {
                error(
                    path,
                    n,
                    LABEL,
                    format!("unknown system {}", quote_field(&[letter])),
                )
            })?;
            let count = integer(cols(c, 3, 6))
                .ok()
                .flatten()
                .and_then(|k| usize::try_from(k).ok())
                .filter(|&k| k <= MAX_CODES_PER_SYSTEM)
                .ok_or_else(|| {
                    error(
                        path,
                        n,
                        LABEL,
                        format!(
                            "observation type count {} (1 to {MAX_CODES_PER_SYSTEM})",
                            quote_field(cols(c, 3, 6))
                        ),
                    )
                })?;
            self.rinex3_lists[slot(system)] = Some(Vec::with_capacity(count));
            self.types_changed = true;
            (system, count)
        } else {
            self.rinex3_pending.filter(|&(_, k)| k > 0).ok_or_else(|| {
                error(
                    path,
                    n,
                    LABEL,
                    "a continuation line with no list to continue",
                )
            })?
        };
        for i in 0..13 {
            if pending == 0 {
                break;
            }
            let text = cols(c, 7 + 4 * i, 10 + 4 * i);
            let code = std::str::from_utf8(text)
                .ok()
                .and_then(ObsCode::new)
                .ok_or_else(|| {
                    let shown = String::from_utf8_lossy(trim(text)).into_owned();
                    let field = if shown.is_empty() {
                        LABEL
                    } else {
                        shown.as_str()
                    };
                    error(
                        path,
                        n,
                        field,
                        format!(
                            "unknown observation code {} for {} in {LABEL}",
                            quote_field(text),
                            system.letter()
                        ),
                    )
                })?;
            if let Some(list) = self.rinex3_lists[slot(system)].as_mut() {
                list.push(code);
            }
            pending -= 1;
        }
        self.rinex3_pending = Some((system, pending));
        Ok(())
    }

    /// `SYS / SCALE FACTOR`: A1 system, I4 factor, I2 count (blank: every type), then
    /// twelve (1X, A3) codes; continuations have a blank system.
    fn scale_factor(&mut self, path: &Path, n: u64, c: &[u8]) -> Result<(), InputError> {
        const LABEL: &str = "SYS / SCALE FACTOR";
        let letter = cols(c, 0, 1).first().copied().unwrap_or(b' ');
        if letter != b' ' {
            let system = System::from_letter(char::from(letter))
                .ok_or_else(|| error(path, n, LABEL, "unknown system"))?;
            let factor = integer(cols(c, 2, 6)).ok().flatten();
            let factor = match factor {
                Some(f @ (1 | 10 | 100 | 1000)) => f as f64,
                _ => {
                    return Err(error(
                        path,
                        n,
                        LABEL,
                        format!("factor {} (1, 10, 100 or 1000)", quote_field(cols(c, 2, 6))),
                    ));
                }
            };
            let count = integer(cols(c, 8, 10)).ok().flatten().unwrap_or(0).max(0) as usize;
            self.scale_factors.push((system, factor, Vec::new()));
            self.scale_pending = Some(count.min(MAX_CODES_PER_SYSTEM));
        }
        let Some(mut pending) = self.scale_pending else {
            return Err(error(
                path,
                n,
                LABEL,
                "a continuation line with no list to continue",
            ));
        };
        let Some((system, _, list)) = self.scale_factors.last_mut() else {
            return Ok(());
        };
        for i in 0..12 {
            if pending == 0 {
                break;
            }
            let text = cols(c, 11 + 4 * i, 14 + 4 * i);
            let code = std::str::from_utf8(text)
                .ok()
                .and_then(ObsCode::new)
                .ok_or_else(|| {
                    error(
                        path,
                        n,
                        LABEL,
                        format!(
                            "unknown observation code {} for {}",
                            quote_field(text),
                            system.letter()
                        ),
                    )
                })?;
            list.push(code);
            pending -= 1;
        }
        self.scale_pending = Some(pending);
        Ok(())
    }

    /// `TIME OF FIRST OBS`: 5I6, F13.7, 5X, A3 time system.
    fn first_obs(&mut self, path: &Path, n: u64, c: &[u8]) -> Result<(), InputError> {
        const LABEL: &str = "TIME OF FIRST OBS";
        let bad = || {
            error(
                path,
                n,
                LABEL,
                format!("not a date and time: {}", quote_field(cols(c, 0, 43))),
            )
        };
        let mut f = [0i64; 5];
        for (i, v) in f.iter_mut().enumerate() {
            *v = integer(cols(c, 6 * i, 6 * i + 6))
                .ok()
                .flatten()
                .ok_or_else(bad)?;
        }
        let sec = decimal(cols(c, 30, 43)).ok().flatten().ok_or_else(bad)?;
        self.header.time_of_first_obs = Some(date_time(f, sec).ok_or_else(bad)?);
        let system = trim(cols(c, 48, 51));
        if !system.is_empty() {
            self.header.time_system = match system {
                b"GPS" => TimeSystem::Gps,
                b"GLO" => TimeSystem::Glonass,
                b"GAL" => TimeSystem::Galileo,
                b"BDT" => TimeSystem::BeiDou,
                b"QZS" => TimeSystem::Qzss,
                b"IRN" => TimeSystem::Navic,
                other => {
                    return Err(error(
                        path,
                        n,
                        LABEL,
                        format!("unknown time system {}", quote_field(other)),
                    ));
                }
            };
            self.time_system_given = true;
        }
        Ok(())
    }

    /// `GLONASS SLOT / FRQ #`: I3 count, then eight (1X, A3, 1X, I2) a line.
    fn glonass(&mut self, path: &Path, n: u64, c: &[u8]) -> Result<(), InputError> {
        const LABEL: &str = "GLONASS SLOT / FRQ #";
        if let Ok(Some(count)) = integer(cols(c, 0, 3)) {
            self.header.glonass_channels.clear();
            self.glonass_pending = usize::try_from(count).unwrap_or(0).min(64);
        }
        for i in 0..8 {
            if self.glonass_pending == 0 {
                break;
            }
            let sat_text = cols(c, 4 + 7 * i, 7 + 7 * i);
            if blank(sat_text) {
                break;
            }
            let sat = std::str::from_utf8(sat_text)
                .ok()
                .and_then(Sat::parse)
                .filter(|s| s.system == System::Glonass);
            let channel = integer(cols(c, 8 + 7 * i, 10 + 7 * i)).ok().flatten();
            match (sat, channel) {
                (Some(sat), Some(k)) if (-7..=13).contains(&k) => {
                    self.header.glonass_channels.push((sat.prn, k as i8));
                }
                _ => {
                    return Err(error(
                        path,
                        n,
                        LABEL,
                        format!(
                            "not a slot and channel: {}",
                            quote_field(cols(c, 4 + 7 * i, 10 + 7 * i))
                        ),
                    ));
                }
            }
            self.glonass_pending -= 1;
        }
        Ok(())
    }

    /// The header, once every line is read (`line_no` names the last, for errors).
    pub(crate) fn finish(mut self, path: &Path, line_no: u64) -> Result<ObsHeader, InputError> {
        let h = &mut self.header;
        if self.rinex2_pending > 0 || self.rinex3_pending.is_some_and(|(_, k)| k > 0) {
            return Err(error(
                path,
                line_no,
                if h.version.major == 2 {
                    "# / TYPES OF OBSERV"
                } else {
                    "SYS / # / OBS TYPES"
                },
                "the list of observation types ends before its count",
            ));
        }
        if !self.time_system_given {
            h.time_system = match self.file_system {
                b'R' => TimeSystem::Glonass,
                b'E' => TimeSystem::Galileo,
                b'C' => TimeSystem::BeiDou,
                b'J' => TimeSystem::Qzss,
                b'I' => TimeSystem::Navic,
                _ => TimeSystem::Gps,
            };
        }
        if self.types_changed {
            let mut codes = ObsCodes::default();
            if h.version.major == 2 {
                for system in System::ALL {
                    let list = h
                        .rinex2_codes
                        .iter()
                        .filter_map(|c| ObsCode::from_rinex2(c, system))
                        .collect();
                    codes.set(system, list);
                }
            } else {
                let old = Arc::clone(&h.codes);
                for system in System::ALL {
                    let list = match self.rinex3_lists[slot(system)].take() {
                        Some(list) => list,
                        None => old.of(system).to_vec(),
                    };
                    codes.set(system, list);
                }
            }
            h.codes = Arc::new(codes);
        }
        if h.codes.is_empty() {
            return Err(error(
                path,
                line_no,
                if h.version.major == 2 {
                    "# / TYPES OF OBSERV"
                } else {
                    "SYS / # / OBS TYPES"
                },
                "the header declares no observation types",
            ));
        }
        if !self.scale_factors.is_empty() {
            for system in System::ALL {
                let columns = h.codes.of(system);
                let mut divisors = vec![1.0; columns.len()];
                for (s, factor, list) in &self.scale_factors {
                    if *s != system {
                        continue;
                    }
                    for (d, code) in divisors.iter_mut().zip(columns) {
                        if list.is_empty() || list.contains(code) {
                            *d = *factor;
                        }
                    }
                }
                h.divisors[slot(system)] = if divisors.iter().all(|&d| d == 1.0) {
                    Vec::new()
                } else {
                    divisors
                };
            }
        }
        Ok(self.header)
    }
}

/// A version field (`     3.04`, `2`, `1.0`).
pub(crate) fn parse_version(field: &[u8]) -> Option<Version> {
    let text = std::str::from_utf8(trim(field)).ok()?;
    let (major, minor) = text.split_once('.').unwrap_or((text, ""));
    let major: u8 = major.parse().ok()?;
    let minor: u8 = match minor.len() {
        0 => 0,
        1 => minor.parse::<u8>().ok()? * 10,
        2 => minor.parse().ok()?,
        _ => return None,
    };
    Some(Version { major, minor })
}

/// The calendar time of year, month, day, hour, minute `f` and second `sec`; `None`
/// when out of range (seconds up to 61, a leap second).
pub(crate) fn date_time(f: [i64; 5], sec: f64) -> Option<NaiveDateTime> {
    let [y, mo, d, h, mi] = f;
    let date = NaiveDate::from_ymd_opt(
        i32::try_from(y).ok()?,
        u32::try_from(mo).ok()?,
        u32::try_from(d).ok()?,
    )?;
    if !(0..24).contains(&h) || !(0..60).contains(&mi) || !(0.0..61.0).contains(&sec) {
        return None;
    }
    let whole = sec.floor();
    let nanos = ((sec - whole) * 1e9).round() as u32;
    let (whole, nanos) = if nanos >= 1_000_000_000 {
        (whole + 1.0, 0)
    } else {
        (whole, nanos)
    };
    let time = if whole >= 60.0 {
        NaiveTime::from_hms_nano_opt(h as u32, mi as u32, 59, nanos + 1_000_000_000)?
    } else {
        NaiveTime::from_hms_nano_opt(h as u32, mi as u32, whole as u32, nanos)?
    };
    Some(NaiveDateTime::new(date, time))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(lines: &[(&str, &str)]) -> Result<ObsHeader, InputError> {
        let mut b = HeaderBuilder::new(None);
        let path = Path::new("t.rnx");
        for (i, (content, label)) in lines.iter().enumerate() {
            let line = format!("{content:<60}{label}");
            if b.line(path, i as u64 + 1, line.as_bytes())? {
                return b.finish(path, i as u64 + 1);
            }
        }
        panic!("no END OF HEADER");
    }

    #[test]
    fn a_rinex2_header() {
        let h = read(&[
            (
                "     2.11           OBSERVATION DATA    M (MIXED)",
                "RINEX VERSION / TYPE",
            ),
            ("AJAC", "MARKER NAME"),
            (
                "  4696989.6880   723994.1970  4239678.3040",
                "APPROX POSITION XYZ",
            ),
            (
                "        0.1050        0.0000        0.0000",
                "ANTENNA: DELTA H/E/N",
            ),
            (
                "    10    L1    L2    C1    C2    P1    P2    D1    D2    S1",
                "# / TYPES OF OBSERV",
            ),
            ("          S2", "# / TYPES OF OBSERV"),
            ("    30.0000", "INTERVAL"),
            ("    18", "LEAP SECONDS"),
            (
                "  2021    12    21     0     0    0.0000000     GPS",
                "TIME OF FIRST OBS",
            ),
            ("", "END OF HEADER"),
        ])
        .unwrap();
        assert_eq!(
            h.version,
            Version {
                major: 2,
                minor: 11
            }
        );
        assert_eq!(h.marker_name, "AJAC");
        assert_eq!(
            h.approx_position,
            Some(Vector3::new(4696989.688, 723994.197, 4239678.304))
        );
        assert_eq!(h.antenna_delta.unwrap().height, 0.105);
        assert_eq!(h.rinex2_codes.len(), 10);
        let gps: Vec<String> = h
            .codes_of(System::Gps)
            .iter()
            .map(ToString::to_string)
            .collect();
        assert_eq!(
            gps,
            [
                "L1C", "L2W", "C1C", "C2X", "C1W", "C2W", "D1C", "D2W", "S1C", "S2W"
            ]
        );
        assert_eq!(h.codes_of(System::Glonass)[5].to_string(), "C2P");
        assert_eq!((h.interval, h.leap_seconds), (Some(30.0), Some(18)));
        assert_eq!(h.time_system, TimeSystem::Gps);
        assert_eq!(
            h.time_of_first_obs.unwrap().to_string(),
            "2021-12-21 00:00:00"
        );
    }

    #[test]
    fn a_rinex3_header() {
        let h = read(&[
            (
                "     3.04           OBSERVATION DATA    M: MIXED",
                "RINEX VERSION / TYPE",
            ),
            (
                "G   12 C1C L1C S1C C2S L2S S2S C2W L2W S2W C5Q L5Q S5Q",
                "SYS / # / OBS TYPES",
            ),
            (
                "E   15 C1C L1C S1C C5Q L5Q S5Q C6C L6C S6C C7Q L7Q S7Q C8Q",
                "SYS / # / OBS TYPES",
            ),
            ("       L8Q S8Q", "SYS / # / OBS TYPES"),
            ("E 1000   1 L1C", "SYS / SCALE FACTOR"),
            (
                " 22 R01  1 R02 -4 R03  5 R04  6 R05  1 R06 -4 R07  5 R08  6",
                "GLONASS SLOT / FRQ #",
            ),
            ("    R09 -2", "GLONASS SLOT / FRQ #"),
            (
                "  2021    12    21     0     0    0.0000000     GAL",
                "TIME OF FIRST OBS",
            ),
            ("", "END OF HEADER"),
        ])
        .unwrap();
        assert_eq!(h.version, Version { major: 3, minor: 4 });
        assert_eq!(h.codes_of(System::Galileo).len(), 15);
        assert_eq!(h.codes_of(System::Galileo)[14].to_string(), "S8Q");
        assert!(h.codes_of(System::Glonass).is_empty());
        assert_eq!(h.time_system, TimeSystem::Galileo);
        assert_eq!(h.glonass_channels[..3], [(1, 1), (2, -4), (3, 5)]);
        assert_eq!(h.glonass_channels.len(), 9);
        assert_eq!(h.divisors[slot(System::Galileo)][1], 1000.0);
        assert!(h.divisors[slot(System::Gps)].is_empty());
    }

    #[test]
    fn header_errors_name_the_line_and_field() {
        let e = read(&[
            (
                "     3.04           OBSERVATION DATA    M: MIXED",
                "RINEX VERSION / TYPE",
            ),
            ("G    2 C1C Q1C", "SYS / # / OBS TYPES"),
        ])
        .unwrap_err();
        assert_eq!((e.line, e.field.as_deref()), (2, Some("Q1C")));
        let e = read(&[
            (
                "     2.11           OBSERVATION DATA    G",
                "RINEX VERSION / TYPE",
            ),
            ("     2    C1    T1", "# / TYPES OF OBSERV"),
        ])
        .unwrap_err();
        assert_eq!(e.field.as_deref(), Some("T1"));
        let e = read(&[(
            "     5.00           OBSERVATION DATA    G",
            "RINEX VERSION / TYPE",
        )])
        .unwrap_err();
        assert_eq!(e.field.as_deref(), Some("RINEX VERSION / TYPE"));
        assert!(e.message.contains("not supported"), "{e}");
        let e = read(&[(
            "     3.04           NAVIGATION DATA     G",
            "RINEX VERSION / TYPE",
        )])
        .unwrap_err();
        assert!(e.message.contains("not an observation file"), "{e}");
        let e = read(&[("G", "MARKER NAME")]).unwrap_err();
        assert_eq!(e.line, 1);
        let e = read(&[
            (
                "     3.04           OBSERVATION DATA    M: MIXED",
                "RINEX VERSION / TYPE",
            ),
            ("", "END OF HEADER"),
        ])
        .unwrap_err();
        assert!(e.message.contains("no observation types"), "{e}");
    }

    #[test]
    fn versions_and_times() {
        assert_eq!(
            parse_version(b"     2"),
            Some(Version { major: 2, minor: 0 })
        );
        assert_eq!(parse_version(b"1.0"), Some(Version { major: 1, minor: 0 }));
        assert_eq!(
            parse_version(b"  2.10"),
            Some(Version {
                major: 2,
                minor: 10
            })
        );
        assert_eq!(parse_version(b"x"), None);
        assert_eq!(date_time([2021, 2, 30, 0, 0], 0.0), None);
        assert_eq!(date_time([2021, 2, 3, 24, 0], 0.0), None);
        let leap = date_time([2016, 12, 31, 23, 59], 60.5).unwrap();
        assert_eq!(leap.to_string(), "2016-12-31 23:59:60.500");
    }
}
