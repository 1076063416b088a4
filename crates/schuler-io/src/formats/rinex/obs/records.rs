//! The data records of RINEX observation files: epoch lines, satellite lists and the
//! 16-column observation fields of versions 2 (five to a line) and 3/4 (one line per
//! satellite).

use super::codes::slot;
use super::fields::{blank, cols, decimal, integer};
use super::header::{ObsHeader, TimeSystem, date_time};
use super::{Epoch, EpochFlag, MAX_SATS_PER_EPOCH, Obs, SatSpan, Source};
use crate::formats::InputError;
use crate::formats::error::{InputErrorKind, quote_field};
use crate::formats::gps_time::{TimeScale, leap_seconds, week_sow};
use chrono::{NaiveDateTime, Timelike};
use schuler::gnss::{Sat, System};
use std::io::Read;
use std::path::Path;

/// Satellites on a RINEX 2 epoch line (and on each continuation line).
const SATS_PER_LINE_V2: usize = 12;
/// Observations on a RINEX 2 observation line.
const OBS_PER_LINE_V2: usize = 5;
/// Characters of an observation field: F14.3, loss of lock, signal strength.
const FIELD: usize = 16;
/// Characters of a special record kept (a header line's 80).
const RECORD_CHARS: usize = 80;

fn err(
    kind: InputErrorKind,
    path: &Path,
    n: u64,
    field: &str,
    msg: impl Into<String>,
) -> InputError {
    InputError::new(kind, path, n, Some(field), msg)
}

/// What an epoch line says.
struct EpochLine {
    time: Option<NaiveDateTime>,
    flag: EpochFlag,
    count: usize,
    clock: Option<f64>,
}

/// The next line that is not blank; `None` at the end of the file.
fn next_nonblank<'s, R: Read>(
    source: &'s mut Source<R>,
    path: &Path,
) -> Result<Option<(&'s [u8], u64)>, InputError> {
    loop {
        // A loop over `source.next` that returns its borrow needs the check first.
        let blank_line = match source.next(path)? {
            None => return Ok(None),
            Some((line, _)) => blank(line),
        };
        if !blank_line {
            break;
        }
    }
    // The non-blank line is held by the reader: hand it out again.
    Ok(Some(source.current()))
}

/// Parses the fields common to both versions: date and time (year, month, day, hour,
/// minute as text slices, seconds), flag and count.
#[allow(clippy::too_many_arguments)]
fn epoch_fields(
    path: &Path,
    n: u64,
    line: &[u8],
    date: [(usize, usize); 5],
    sec: (usize, usize),
    flag_col: usize,
    count: (usize, usize),
    two_digit_year: bool,
) -> Result<EpochLine, InputError> {
    let bad = |what: &str, text: &[u8]| {
        err(
            InputErrorKind::NotANumber,
            path,
            n,
            "epoch",
            format!("{what}: {}", quote_field(text)),
        )
    };
    let flag_text = cols(line, flag_col, flag_col + 1);
    let flag = match flag_text {
        [] | [b' '] => EpochFlag::Ok,
        [d] => EpochFlag::from_digit(*d).ok_or_else(|| bad("epoch flag not 0 to 6", flag_text))?,
        _ => EpochFlag::Ok,
    };
    let count_text = cols(line, count.0, count.1);
    let count = integer(count_text)
        .map_err(|()| bad("satellite count not a number", count_text))?
        .unwrap_or(0);
    let count = usize::try_from(count)
        .ok()
        .filter(|&k| k <= MAX_SATS_PER_EPOCH || flag.is_event())
        .ok_or_else(|| {
            err(
                InputErrorKind::OutOfDomain,
                path,
                n,
                "epoch",
                format!("{count} satellites (at most {MAX_SATS_PER_EPOCH} an epoch)"),
            )
        })?;
    let time_text = cols(line, date[0].0, sec.1);
    let time = if flag.is_event() && blank(time_text) {
        None
    } else {
        let mut f = [0i64; 5];
        for (v, &(a, b)) in f.iter_mut().zip(&date) {
            *v = integer(cols(line, a, b))
                .ok()
                .flatten()
                .ok_or_else(|| bad("not a date and time", time_text))?;
        }
        if two_digit_year {
            f[0] += if f[0] < 80 { 2000 } else { 1900 };
        }
        let s = decimal(cols(line, sec.0, sec.1))
            .ok()
            .flatten()
            .ok_or_else(|| bad("not a date and time", time_text))?;
        Some(date_time(f, s).ok_or_else(|| bad("not a date and time", time_text))?)
    };
    Ok(EpochLine {
        time,
        flag,
        count,
        clock: None,
    })
}

/// The clock offset field of an epoch line [s].
fn clock(path: &Path, n: u64, text: &[u8]) -> Result<Option<f64>, InputError> {
    decimal(text).map_err(|()| {
        err(
            InputErrorKind::NotANumber,
            path,
            n,
            "clock offset",
            format!("not a number: {}", quote_field(text)),
        )
    })
}

/// Reads a RINEX 2 epoch into `epoch` (time as written, flag, clock, satellites,
/// records); the number of its epoch line, or `None` at the end of the file.
pub(crate) fn read_v2<R: Read>(
    source: &mut Source<R>,
    path: &Path,
    header: &ObsHeader,
    epoch: &mut Epoch,
) -> Result<Option<u64>, InputError> {
    let Some((line, n)) = next_nonblank(source, path)? else {
        return Ok(None);
    };
    let mut head = epoch_fields(
        path,
        n,
        line,
        [(1, 3), (4, 6), (7, 9), (10, 12), (13, 15)],
        (15, 26),
        28,
        (29, 32),
        true,
    )?;
    if head.flag.is_event() {
        return finish_event(source, path, n, head, epoch);
    }
    head.clock = clock(path, n, cols(line, 68, 80))?;
    sat_list(path, n, line, 32, head.count.min(SATS_PER_LINE_V2), epoch)?;
    while epoch.sats.len() < head.count {
        let (line, m) = source
            .next(path)?
            .ok_or_else(|| truncated(path, n, head.count, epoch.sats.len(), "the file ends"))?;
        let k = (head.count - epoch.sats.len()).min(SATS_PER_LINE_V2);
        sat_list(path, m, line, 32, k, epoch)?;
    }
    set_head(epoch, &head);
    let columns = header.rinex2_codes.len();
    let lines_per_sat = columns.div_ceil(OBS_PER_LINE_V2).max(1);
    for s in 0..epoch.sats.len() {
        let sat = epoch.sats[s].sat;
        let start = epoch.obs.len();
        for l in 0..lines_per_sat {
            let Some((line, m)) = source.next(path)? else {
                // The last satellite's last lines, blank, may have been dropped with
                // the file's trailing blank lines: nothing is lost.
                if l > 0 && s + 1 == epoch.sats.len() {
                    break;
                }
                return Err(truncated(path, n, head.count, s, "the file ends"));
            };
            let first = l * OBS_PER_LINE_V2;
            let last = (first + OBS_PER_LINE_V2).min(columns);
            let parsed = parse_fields(
                path,
                m,
                line,
                0,
                first..last,
                header,
                sat.system,
                &mut epoch.obs,
            );
            if let Err(e) = parsed {
                return Err(if looks_like_epoch_v2(line) {
                    truncated(
                        path,
                        n,
                        head.count,
                        s,
                        &format!("line {m} is the next epoch"),
                    )
                } else {
                    e
                });
            }
        }
        epoch.sats[s].start = start as u32;
        epoch.sats[s].end = epoch.obs.len() as u32;
    }
    Ok(Some(n))
}

/// Reads a RINEX 3 or 4 epoch into `epoch`; the number of its epoch line, or `None`
/// at the end of the file.
pub(crate) fn read_v3<R: Read>(
    source: &mut Source<R>,
    path: &Path,
    header: &ObsHeader,
    epoch: &mut Epoch,
) -> Result<Option<u64>, InputError> {
    let Some((line, n)) = next_nonblank(source, path)? else {
        return Ok(None);
    };
    if line.first() != Some(&b'>') {
        return Err(err(
            InputErrorKind::ColumnCount,
            path,
            n,
            "epoch",
            format!(
                "expected an epoch record ('>'), found {} (more satellites than the epoch before announced?)",
                quote_field(cols(line, 0, 20))
            ),
        ));
    }
    let mut head = epoch_fields(
        path,
        n,
        line,
        [(2, 6), (7, 9), (10, 12), (13, 15), (16, 18)],
        (18, 29),
        31,
        (32, 35),
        false,
    )?;
    if head.flag.is_event() {
        return finish_event(source, path, n, head, epoch);
    }
    head.clock = clock(path, n, cols(line, 41, 56))?;
    set_head(epoch, &head);
    for s in 0..head.count {
        let Some((line, m)) = source.next(path)? else {
            return Err(truncated(path, n, head.count, s, "the file ends"));
        };
        if line.first() == Some(&b'>') {
            return Err(truncated(
                path,
                n,
                head.count,
                s,
                &format!("line {m} is the next epoch"),
            ));
        }
        let sat = satellite(path, m, cols(line, 0, 3))?;
        let columns = header.columns(sat.system);
        if columns == 0 {
            return Err(err(
                InputErrorKind::Header,
                path,
                m,
                "satellite",
                format!("{sat}: the header declares no observation types for its system"),
            ));
        }
        let start = epoch.obs.len();
        parse_fields(
            path,
            m,
            line,
            3,
            0..columns,
            header,
            sat.system,
            &mut epoch.obs,
        )?;
        epoch.sats.push(SatSpan {
            sat,
            start: start as u32,
            end: epoch.obs.len() as u32,
        });
    }
    Ok(Some(n))
}

/// Copies an epoch line's time, flag and clock into `epoch`.
fn set_head(epoch: &mut Epoch, head: &EpochLine) {
    epoch.flag = head.flag;
    epoch.clock_offset = head.clock;
    epoch.time_given = head.time.is_some();
    if let Some(t) = head.time {
        epoch.time = t;
    }
}

/// Reads an event's special records into `epoch`.
fn finish_event<R: Read>(
    source: &mut Source<R>,
    path: &Path,
    n: u64,
    head: EpochLine,
    epoch: &mut Epoch,
) -> Result<Option<u64>, InputError> {
    set_head(epoch, &head);
    for i in 0..head.count {
        let Some((line, _)) = source.next(path)? else {
            return Err(err(
                InputErrorKind::ColumnCount,
                path,
                n,
                "epoch",
                format!(
                    "truncated event: {} special records announced, the file ends after {i}",
                    head.count
                ),
            ));
        };
        let line = cols(line, 0, RECORD_CHARS);
        epoch
            .records
            .push(String::from_utf8_lossy(line).into_owned());
    }
    Ok(Some(n))
}

/// The error of an epoch (line `n`) whose satellite records stop after `got` of `count`.
fn truncated(path: &Path, n: u64, count: usize, got: usize, why: &str) -> InputError {
    err(
        InputErrorKind::ColumnCount,
        path,
        n,
        "epoch",
        format!("truncated epoch: {count} satellites announced, {why} after {got}"),
    )
}

/// Whether `line` has the shape of a RINEX 2 epoch line (` yy mm dd hh mm ss.sssssss  f`).
fn looks_like_epoch_v2(line: &[u8]) -> bool {
    line.len() >= 29
        && [0, 3, 6, 9, 12, 15].iter().all(|&i| line[i] == b' ')
        && line[18] == b'.'
        && line[28].is_ascii_digit()
}

/// Satellite identifier `text` (`G05`, ` 5`).
fn satellite(path: &Path, n: u64, text: &[u8]) -> Result<Sat, InputError> {
    std::str::from_utf8(text)
        .ok()
        .and_then(Sat::parse)
        .ok_or_else(|| {
            err(
                InputErrorKind::NotANumber,
                path,
                n,
                "satellite",
                format!("not a satellite: {}", quote_field(text)),
            )
        })
}

/// Appends the `k` satellites of `line` from column `from` (three characters each).
fn sat_list(
    path: &Path,
    n: u64,
    line: &[u8],
    from: usize,
    k: usize,
    epoch: &mut Epoch,
) -> Result<(), InputError> {
    for i in 0..k {
        let sat = satellite(path, n, cols(line, from + 3 * i, from + 3 * i + 3))?;
        epoch.sats.push(SatSpan {
            sat,
            start: 0,
            end: 0,
        });
    }
    Ok(())
}

/// Parses observation columns `columns` of `system` from `line`, whose first field
/// starts at `offset`, appending the present ones to `out`.
#[allow(clippy::too_many_arguments)]
#[inline]
fn parse_fields(
    path: &Path,
    n: u64,
    line: &[u8],
    offset: usize,
    columns: std::ops::Range<usize>,
    header: &ObsHeader,
    system: System,
    out: &mut Vec<Obs>,
) -> Result<(), InputError> {
    let first = columns.start;
    let divisors = &header.divisors[slot(system)];
    for i in columns {
        let a = offset + (i - first) * FIELD;
        if a >= line.len() {
            break;
        }
        let field = cols(line, a, a + FIELD);
        let bad = |what: &str, text: &[u8]| {
            err(
                InputErrorKind::NotANumber,
                path,
                n,
                &header.column_name(system, i),
                format!("{what}: {}", quote_field(text)),
            )
        };
        let value = cols(field, 0, 14);
        let Some(mut value) = decimal(value).map_err(|()| bad("not a number", value))? else {
            continue;
        };
        if let Some(&d) = divisors.get(i) {
            value /= d;
        }
        let indicator = |k: usize, what: &str| match cols(field, k, k + 1) {
            [] | [b' '] => Ok(None),
            [d @ b'0'..=b'9'] => Ok(Some(d - b'0')),
            t => Err(bad(what, t)),
        };
        out.push(Obs {
            code: i as u8,
            value,
            lli: indicator(14, "loss-of-lock indicator not a digit")?,
            ssi: indicator(15, "signal strength not a digit")?,
        });
    }
    Ok(())
}

/// GPS week and second of `t`, a time of `header`'s time system.
pub(crate) fn gps_time(t: NaiveDateTime, header: &ObsHeader) -> (i64, f64) {
    let date = t.date();
    let sod = f64::from(t.num_seconds_from_midnight()) + f64::from(t.nanosecond()) * 1e-9;
    let offset = match header.time_system {
        TimeSystem::Gps | TimeSystem::Galileo | TimeSystem::Qzss | TimeSystem::Navic => 0.0,
        TimeSystem::BeiDou => 14.0,
        TimeSystem::Glonass => {
            let leap = header
                .leap_seconds
                .map_or_else(|| leap_seconds(date), f64::from);
            leap - 3.0 * 3600.0
        }
    };
    week_sow(date, sod + offset, TimeScale::Gpst)
}
