//! NMEA 0183 logs as GNSS position logs (`schuler nav --gnss FILE.nmea`).
//!
//! Sentences are parsed, checksums verified, by the `nmea` crate (AeroRust); any
//! talker (`$GP`, `$GN`, `$GL`, `$GA`, `$GB`, `$BD`, `$GQ`, ...) is read and proprietary
//! sentences (`$P...`) and the other types are ignored. Of each epoch (the sentences
//! sharing one UTC time of day):
//! - **GGA** gives the position: latitude, longitude and the ellipsoidal height,
//!   `altitude above mean sea level + geoid separation` (fields 9 and 11; a missing
//!   separation is taken as 0, with a warning: the altitude is then used as the
//!   ellipsoidal height). Fix quality 0 (no fix) and 6 (dead reckoning: not a GNSS
//!   measurement, and the navigator's own estimate fed back to it) are skipped and
//!   counted; the others map onto [`GnssQuality`] for `--gnss-min-quality`.
//! - **GST** gives the standard deviations of latitude, longitude and altitude [m]
//!   (north, east, down) when present and positive, else `--gnss-std` applies.
//! - **RMC** gives the date, and the velocity when its status is valid (`A` or `D`):
//!   north `s cos c`, east `s sin c` from the speed over ground `s` [knots] and the
//!   true course `c` (a speed of 0 with an empty course is a velocity of 0). Without a
//!   valid RMC speed and course, a **VTG** of the epoch gives them (a VTG carries no
//!   time: it belongs to the epoch of the nearest sentence that does, by line). NMEA
//!   has no vertical speed: the down velocity is 0 with a standard deviation of
//!   [`UNMEASURED_VD_STD`], so the update constrains the horizontal velocity only; the
//!   horizontal ones take `--gnss-vel-std`.
//!
//! Time is GPS seconds of week, continued across week rollovers from the first fix's
//! week: the RMC date and the UTC time of day plus the leap seconds in force that day
//! (the leap-second table of `gps_time.rs`: 18 s since 2017-01-01). An epoch without
//! its own RMC takes the date of the last dated epoch (or the first one, for epochs
//! before it), a day later or earlier where the time of day has wrapped past midnight.
//! A log without any RMC date gives UTC seconds of day, continued across midnight, with
//! a warning.
//!
//! A bad sentence (checksum mismatch, malformed field, not ASCII, a GGA with a fix but
//! no position) is counted and skipped, never fatal; epochs whose time does not
//! increase are skipped the same way; the counts come back as warnings naming the
//! first bad line.

use super::error::InputError;
use super::gnss::{
    GnssFormat, GnssLog, GnssQuality, GnssReadOptions, below_quality, count_warnings, default_std,
    fix_in_domain, no_usable_fix, position_in_domain,
};
use super::gps_time::{DAY_S, TimeScale, WeekClock, week_sow};
use ::nmea::ParseResult;
use ::nmea::sentences::FixType;
use chrono::{NaiveDate, NaiveTime, Timelike};
use nalgebra::Vector3;
use schuler::filter::GnssFix;
use std::path::Path;

/// One knot [m/s] (1852 m per hour).
const KNOT: f64 = 1852.0 / 3600.0;

/// Standard deviation [m/s] given to the down velocity of an NMEA fix, which NMEA does
/// not measure: large enough to carry no information to the filter (its weight is
/// 1e-6 of a 0.1-m/s measurement's), so the velocity update is horizontal.
pub const UNMEASURED_VD_STD: f64 = 100.0;

/// Half a day [µs]: a time of day this much before the previous one has passed midnight.
const HALF_DAY_US: i64 = 43_200_000_000;

/// A GGA sentence's content.
#[derive(Debug, Clone, Copy)]
struct Gga {
    line: u64,
    quality: Option<FixType>,
    lat: Option<f64>,
    lon: Option<f64>,
    altitude: Option<f64>,
    separation: Option<f64>,
}

/// An RMC sentence's content.
#[derive(Debug, Clone, Copy)]
struct Rmc {
    date: Option<NaiveDate>,
    valid: bool,
    speed_kn: Option<f64>,
    course_deg: Option<f64>,
}

/// What a sentence the reader uses says.
#[derive(Debug, Clone, Copy)]
enum Data {
    Gga(Gga),
    Rmc(Rmc),
    /// VTG: speed over ground [knots] and true course [deg].
    Vtg(Option<f64>, Option<f64>),
    /// GST: standard deviations of latitude, longitude and altitude [m].
    Gst([Option<f64>; 3]),
}

/// A sentence with its line and UTC time of day [µs] (a VTG's is its epoch's).
#[derive(Debug, Clone, Copy)]
struct Sentence {
    line: u64,
    tod: Option<i64>,
    data: Data,
}

/// The sentences of one epoch (one UTC time of day).
#[derive(Debug, Clone, Copy)]
struct Epoch {
    tod: i64,
    gga: Option<Gga>,
    rmc: Option<Rmc>,
    vtg: Option<(Option<f64>, Option<f64>)>,
    gst: Option<[Option<f64>; 3]>,
}

/// What the reader skipped, for the warnings.
#[derive(Debug, Default)]
struct Counts {
    bad: usize,
    first_bad: Option<(u64, String)>,
    not_sentences: usize,
    no_fix: usize,
    dead_reckoning: usize,
    below_quality: usize,
    no_separation: usize,
    not_increasing: usize,
    without_gga: usize,
}

impl Counts {
    /// Count a bad sentence at `line`, for `reason`.
    fn bad(&mut self, line: u64, reason: String) {
        self.bad += 1;
        self.first_bad.get_or_insert((line, reason));
    }

    /// The warnings for the user.
    fn warnings(&self, min_quality: GnssQuality) -> Vec<String> {
        let mut w = Vec::new();
        if let Some((line, reason)) = &self.first_bad {
            w.push(format!(
                "{} bad NMEA sentences skipped (checksum, malformed field or a position out \
                 of range; the first at line {line}: {reason})",
                self.bad
            ));
        }
        w.extend(count_warnings(&[
            (
                self.not_sentences,
                "lines that are not NMEA sentences ignored".to_owned(),
            ),
            (
                self.no_fix,
                "GGA epochs without a fix (quality 0) skipped".to_owned(),
            ),
            (
                self.dead_reckoning,
                "GGA epochs of dead reckoning (quality 6) skipped".to_owned(),
            ),
            (self.below_quality, below_quality(min_quality)),
            (
                self.no_separation,
                "GGA sentences without a geoid separation: their altitude is taken as the \
                 ellipsoidal height"
                    .to_owned(),
            ),
            (
                self.not_increasing,
                "epochs whose time does not increase skipped".to_owned(),
            ),
            (
                self.without_gga,
                "epochs without a GGA sentence (no height) not used".to_owned(),
            ),
        ]));
        w
    }
}

/// A UTC time of day in microseconds.
fn micros(t: NaiveTime) -> i64 {
    i64::from(t.num_seconds_from_midnight()) * 1_000_000 + i64::from(t.nanosecond() / 1000)
}

/// Why the NMEA parser refused a sentence, in the user's words: a malformed field or
/// checksum rather than the parser's internals (`Parsing Error: Error { input: ..,
/// code: OneOf }`).
fn bad_sentence(e: &::nmea::Error) -> String {
    use ::nmea::Error as E;
    match e {
        E::ParsingError(_) => "a malformed or missing field".to_owned(),
        E::ChecksumMismatch { calculated, found } => {
            format!("checksum {found:02X} where the sentence's bytes give {calculated:02X}")
        }
        E::SentenceLength(n) => format!("{n} characters, longer than a sentence"),
        E::ParameterLength { .. } => "a field longer than its format allows".to_owned(),
        E::Utf8Decoding | E::ASCII => "characters that are not ASCII".to_owned(),
        other => other.to_string(),
    }
}

/// A sentence the reader uses, parsed from `l` (line `line`): `Ok(None)` for the types
/// it ignores, `Err(reason)` for a bad one.
fn parse_sentence(line: u64, l: &str) -> Result<Option<Sentence>, String> {
    let used = matches!(l.get(3..6), Some("GGA" | "RMC" | "VTG" | "GST"));
    if !used || l.as_bytes().get(1) == Some(&b'P') {
        return Ok(None);
    }
    let f = |x: Option<f32>| x.map(f64::from);
    let (tod, data) = match ::nmea::parse_str(l).map_err(|e| bad_sentence(&e))? {
        ParseResult::GGA(g) => (
            g.fix_time,
            Data::Gga(Gga {
                line,
                quality: g.fix_type,
                lat: g.latitude,
                lon: g.longitude,
                altitude: f(g.altitude),
                separation: f(g.geoid_separation),
            }),
        ),
        ParseResult::RMC(r) => (
            r.fix_time,
            Data::Rmc(Rmc {
                date: r.fix_date,
                valid: r.status_of_fix != ::nmea::sentences::rmc::RmcStatusOfFix::Invalid,
                speed_kn: f(r.speed_over_ground),
                course_deg: f(r.true_course),
            }),
        ),
        ParseResult::VTG(v) => (None, Data::Vtg(f(v.speed_over_ground), f(v.true_course))),
        ParseResult::GST(g) => (g.time, Data::Gst([f(g.lat_sd), f(g.long_sd), f(g.alt_sd)])),
        _ => return Ok(None),
    };
    Ok(Some(Sentence {
        line,
        tod: tod.map(micros),
        data,
    }))
}

/// The sentences of a log the reader uses, in line order, each VTG given the time of
/// the nearest sentence (by line) that has one.
fn sentences(bytes: &[u8], counts: &mut Counts) -> Vec<Sentence> {
    let mut out: Vec<Sentence> = Vec::new();
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = i as u64 + 1;
        let raw = raw.trim_ascii();
        let raw = if line == 1 {
            raw.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(raw)
        } else {
            raw
        };
        if raw.is_empty() || raw.starts_with(b"#") {
            continue;
        }
        if !raw.starts_with(b"$") {
            counts.not_sentences += 1;
            continue;
        }
        let parsed = std::str::from_utf8(raw)
            .map_err(|_| "not ASCII text".to_owned())
            .and_then(|l| parse_sentence(line, l));
        match parsed {
            Ok(Some(s)) => out.push(s),
            Ok(None) => {}
            Err(reason) => counts.bad(line, reason),
        }
    }
    // A VTG's epoch: the nearest timed sentence before or after it.
    let mut before: Vec<Option<(u64, i64)>> = Vec::with_capacity(out.len());
    let mut last = None;
    for s in &out {
        last = s.tod.map(|t| (s.line, t)).or(last);
        before.push(last);
    }
    let mut after = None;
    for (k, s) in out.iter_mut().enumerate().rev() {
        if s.tod.is_some() {
            after = s.tod.map(|t| (s.line, t));
        } else if matches!(s.data, Data::Vtg(..)) {
            let d = |x: Option<(u64, i64)>| x.map(|(l, t)| (l.abs_diff(s.line), t));
            s.tod = match (d(before[k]), d(after)) {
                (Some((db, tb)), Some((da, ta))) => Some(if da < db { ta } else { tb }),
                (b, a) => b.or(a).map(|(_, t)| t),
            };
        }
    }
    out
}

/// The epochs of `sentences`: those with the same time of day among the last four
/// epochs are one (the first sentence of each type kept). A GGA without a time is a
/// fix without one: counted as no fix when its quality is 0, else as bad.
fn epochs(sentences: &[Sentence], counts: &mut Counts) -> Vec<Epoch> {
    let mut out: Vec<Epoch> = Vec::new();
    for s in sentences {
        let Some(tod) = s.tod else {
            if let Data::Gga(g) = s.data {
                match g.quality {
                    Some(FixType::Invalid) | None => counts.no_fix += 1,
                    _ => counts.bad(s.line, "a GGA with a fix has no time".to_owned()),
                }
            }
            continue;
        };
        let start = out.len().saturating_sub(4);
        let k = match out[start..].iter().rposition(|e| e.tod == tod) {
            Some(k) => start + k,
            None => {
                out.push(Epoch {
                    tod,
                    gga: None,
                    rmc: None,
                    vtg: None,
                    gst: None,
                });
                out.len() - 1
            }
        };
        let e = &mut out[k];
        match s.data {
            Data::Gga(g) => {
                e.gga.get_or_insert(g);
            }
            Data::Rmc(r) => {
                e.rmc.get_or_insert(r);
            }
            Data::Vtg(s, c) => {
                e.vtg.get_or_insert((s, c));
            }
            Data::Gst(sd) => {
                e.gst.get_or_insert(sd);
            }
        }
    }
    out
}

/// The time of each epoch [s] (the module doc), and whether the log had a date (GPS
/// seconds of week) or not (UTC seconds of day).
fn epoch_times(epochs: &[Epoch]) -> (Vec<f64>, bool) {
    let date_of = |e: &Epoch| e.rmc.and_then(|r| r.date);
    let Some(first) = epochs.iter().find_map(|e| date_of(e).map(|d| (d, e.tod))) else {
        let mut days = 0.0;
        let mut prev: Option<i64> = None;
        let t = epochs
            .iter()
            .map(|e| {
                if prev.is_some_and(|p| e.tod < p - HALF_DAY_US) {
                    days += 1.0;
                }
                prev = Some(e.tod);
                days * DAY_S + e.tod as f64 * 1e-6
            })
            .collect();
        return (t, false);
    };
    let mut reference = first;
    let mut clock = WeekClock::default();
    let t = epochs
        .iter()
        .map(|e| {
            if let Some(d) = date_of(e) {
                reference = (d, e.tod);
            }
            let (d, tod_ref) = reference;
            let date = if e.tod - tod_ref > HALF_DAY_US {
                d.pred_opt().unwrap_or(d)
            } else if tod_ref - e.tod > HALF_DAY_US {
                d.succ_opt().unwrap_or(d)
            } else {
                d
            };
            let (week, sow) = week_sow(date, e.tod as f64 * 1e-6, TimeScale::Utc);
            clock.seconds(week, sow)
        })
        .collect();
    (t, true)
}

/// The velocity north, east, down [m/s] of an epoch and its standard deviations
/// (`std` horizontally): from a valid RMC, else from a VTG (the module doc).
fn velocity(e: &Epoch, std: f64) -> Option<(Vector3<f64>, Vector3<f64>)> {
    let speed_course = |s: Option<f64>, c: Option<f64>| match (s, c) {
        (Some(s), Some(c)) => Some((s, c.to_radians())),
        (Some(0.0), None) => Some((0.0, 0.0)),
        _ => None,
    };
    let rmc = e.rmc.filter(|r| r.valid);
    let (s, c) = rmc
        .and_then(|r| speed_course(r.speed_kn, r.course_deg))
        .or_else(|| e.vtg.and_then(|(s, c)| speed_course(s, c)))?;
    let v = s * KNOT;
    Some((
        Vector3::new(v * c.cos(), v * c.sin(), 0.0),
        Vector3::new(std, std, UNMEASURED_VD_STD),
    ))
}

/// The fix of epoch `e` at time `t`, or `None` (counted) when it has none to give.
fn fix(
    path: &Path,
    e: &Epoch,
    t: f64,
    opts: &GnssReadOptions,
    counts: &mut Counts,
) -> Result<Option<GnssFix>, InputError> {
    let Some(gga) = e.gga else {
        counts.without_gga += usize::from(e.rmc.is_some());
        return Ok(None);
    };
    let level = match gga.quality {
        None | Some(FixType::Invalid) => {
            counts.no_fix += 1;
            return Ok(None);
        }
        Some(FixType::Estimated) => {
            counts.dead_reckoning += 1;
            return Ok(None);
        }
        Some(FixType::Gps | FixType::Manual | FixType::Simulation) => GnssQuality::Single,
        Some(FixType::DGps | FixType::Pps) => GnssQuality::Dgps,
        Some(FixType::FloatRtk) => GnssQuality::Float,
        Some(FixType::Rtk) => GnssQuality::Fix,
    };
    if level < opts.min_quality {
        counts.below_quality += 1;
        return Ok(None);
    }
    let (Some(lat), Some(lon), Some(altitude)) = (gga.lat, gga.lon, gga.altitude) else {
        counts.bad(gga.line, "a GGA with a fix lacks its position".to_owned());
        return Ok(None);
    };
    let separation = gga.separation.unwrap_or_else(|| {
        counts.no_separation += 1;
        0.0
    });
    let pos = match position_in_domain(lat, lon, altitude + separation) {
        Ok(pos) => pos,
        Err((_, e)) => {
            counts.bad(gga.line, format!("a GGA position out of range: {e}"));
            return Ok(None);
        }
    };
    let sd = e.gst.unwrap_or([None; 3]);
    let pos_std = match sd {
        [Some(n), Some(east), Some(d)] if n > 0.0 && east > 0.0 && d > 0.0 => {
            Vector3::new(n, east, d)
        }
        _ => default_std(path, gga.line, "GST", opts.default_std)?,
    };
    let fix = GnssFix {
        t,
        pos,
        pos_std,
        vel: velocity(e, opts.vel_std),
    };
    // Out of its domain, a fix is a bad sentence: counted and skipped like one.
    match fix_in_domain(path, gga.line, fix) {
        Ok(fix) => Ok(Some(fix)),
        Err(e) => {
            counts.bad(
                gga.line,
                format!(
                    "a fix out of range: {}: {}",
                    e.field.unwrap_or_default(),
                    e.message
                ),
            );
            Ok(None)
        }
    }
}

/// Read an NMEA 0183 log (`bytes`, the content of `path`) as GNSS fixes (the module
/// doc), with the reader's warnings.
pub fn read_nmea(path: &Path, bytes: &[u8], opts: &GnssReadOptions) -> Result<GnssLog, InputError> {
    let mut counts = Counts::default();
    let sentences = sentences(bytes, &mut counts);
    let epochs = epochs(&sentences, &mut counts);
    let (times, dated) = epoch_times(&epochs);
    let mut fixes: Vec<GnssFix> = Vec::new();
    for (e, t) in epochs.iter().zip(times) {
        if fixes.last().is_some_and(|f| t <= f.t) {
            counts.not_increasing += usize::from(e.gga.is_some());
            continue;
        }
        fixes.extend(fix(path, e, t, opts, &mut counts)?);
    }
    let mut warnings = counts.warnings(opts.min_quality);
    if fixes.is_empty() {
        return Err(no_usable_fix(path, &warnings));
    }
    if !dated {
        warnings.push(
            "no RMC date: times are UTC seconds of day (continued across midnight), not GPS \
             seconds of week; --gnss-time-offset shifts them onto the IMU's clock"
                .to_owned(),
        );
    }
    Ok(GnssLog {
        fixes,
        format: GnssFormat::Nmea,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::error::InputErrorKind;
    use schuler::earth::Geodetic;

    /// `body` with its NMEA checksum: `$body*hh`.
    fn sentence(body: &str) -> String {
        let x = body.bytes().fold(0u8, |c, b| c ^ b);
        format!("${body}*{x:02X}")
    }

    fn read(text: &str, opts: &GnssReadOptions) -> Result<GnssLog, InputError> {
        read_nmea(Path::new("log.nmea"), text.as_bytes(), opts)
    }

    fn with_std() -> GnssReadOptions {
        GnssReadOptions {
            default_std: Some(Vector3::new(1.0, 2.0, 3.0)),
            ..GnssReadOptions::default()
        }
    }

    #[test]
    fn gga_rmc_gst_make_a_fix_in_gps_time() {
        // 2020-12-27 (a Sunday) 00:00:10 UTC = week 2138, 28 s GPST.
        let log = [
            sentence("GPRMC,000010.00,A,4504.2000,N,00740.8000,E,10.0,90.0,271220,,,A"),
            sentence("GPGGA,000010.00,4504.2000,N,00740.8000,E,4,12,0.7,200.0,M,47.5,M,,"),
            sentence("GPGST,000010.00,1.0,0.5,0.4,10.0,0.02,0.03,0.05"),
        ]
        .join("\r\n");
        let got = read(&log, &GnssReadOptions::default()).expect("reads");
        assert_eq!(got.format, GnssFormat::Nmea);
        assert!(got.warnings.is_empty(), "{:?}", got.warnings);
        let f = got.fixes[0];
        assert_eq!(f.t, 28.0);
        let want = Geodetic::from_degrees(45.07, 7.68, 247.5);
        assert!((f.pos.lat - want.lat).abs() < 1e-12 && (f.pos.lon - want.lon).abs() < 1e-12);
        assert!((f.pos.h - 247.5).abs() < 1e-4, "{}", f.pos.h);
        assert!((f.pos_std - Vector3::new(0.02, 0.03, 0.05)).norm() < 1e-7);
        let (v, s) = f.vel.expect("RMC velocity");
        assert!(
            (v - Vector3::new(0.0, 10.0 * KNOT, 0.0)).norm() < 1e-5,
            "{v}"
        );
        assert_eq!(s, Vector3::new(0.1, 0.1, UNMEASURED_VD_STD));
    }

    #[test]
    fn bad_sentences_and_no_fix_epochs_are_counted_never_fatal() {
        let good = sentence("GNGGA,120000.0,4504.2,N,00740.8,E,1,8,1.0,200.0,M,47.5,M,,");
        let mut bad_sum = sentence("GNGGA,120001.0,4504.2,N,00740.8,E,1,8,1.0,200.0,M,47.5,M,,");
        bad_sum.replace_range(bad_sum.len() - 2.., "00");
        let log = [
            good,
            bad_sum,
            sentence("GNGGA,120002.0,4504.2,N,00740.8,E,x,8,1.0,200.0,M,47.5,M,,"),
            sentence("GNGGA,120003.0,,,,,0,00,99.99,,,,,,"),
            sentence("GNGGA,120004.0,4504.2,N,00740.8,E,6,8,1.0,200.0,M,,M,,"),
            sentence("GNGGA,120005.0,4504.2,N,00740.8,E,1,8,1.0,200.0,M,,M,,"),
            sentence("GNGSV,1,1,00"),
            "garbage".to_owned(),
            sentence("PUBX,00,junk"),
            sentence("GNGGA,120006.0,4504.2,N,00740.8,E,1,8,1.0,9999999999.0,M,47.5,M,,"),
        ]
        .join("\n");
        let got = read(&log, &with_std()).expect("reads");
        assert_eq!(got.fixes.len(), 2);
        assert_eq!((got.fixes[0].t, got.fixes[1].t), (43_200.0, 43_205.0));
        assert_eq!(got.fixes[1].pos.h, 200.0);
        assert!(
            got.fixes
                .iter()
                .all(|f| f.pos_std == Vector3::new(1.0, 2.0, 3.0))
        );
        let w = got.warnings.join("\n");
        for want in [
            "3 bad NMEA sentences skipped (checksum, malformed field or a position out of \
             range; the first at line 2: checksum 00 where the sentence's bytes give 71)",
            "1 lines that are not NMEA sentences ignored",
            "1 GGA epochs without a fix (quality 0) skipped",
            "1 GGA epochs of dead reckoning (quality 6) skipped",
            "1 GGA sentences without a geoid separation",
            "no RMC date: times are UTC seconds of day",
        ] {
            assert!(w.contains(want), "{want:?} not in\n{w}");
        }
    }

    #[test]
    fn vtg_takes_the_nearest_epoch_and_dates_carry_over_midnight() {
        // VTG before RMC (Quectel's order), an epoch without RMC after midnight.
        let log = [
            sentence("GPVTG,0.0,T,,M,1.0,N,1.9,K,A"),
            sentence("GPRMC,235959.0,A,4504.2,N,00740.8,E,,,261220,,,A"),
            sentence("GPGGA,235959.0,4504.2,N,00740.8,E,2,8,1.0,200.0,M,0.0,M,,"),
            sentence("GPGSV,1,1,00"),
            sentence("GPVTG,90.0,T,,M,2.0,N,3.7,K,A"),
            sentence("GPGGA,000000.0,4504.2,N,00740.8,E,2,8,1.0,200.0,M,0.0,M,,"),
        ]
        .join("\n");
        let got = read(&log, &with_std()).expect("reads");
        // Saturday 2020-12-26 23:59:59 UTC = 17 s into week 2138 (GPST); then 18 s.
        assert_eq!((got.fixes[0].t, got.fixes[1].t), (17.0, 18.0));
        let v0 = got.fixes[0].vel.expect("VTG").0;
        let v1 = got.fixes[1].vel.expect("VTG").0;
        assert!((v0 - Vector3::new(KNOT, 0.0, 0.0)).norm() < 1e-6, "{v0}");
        assert!(
            (v1 - Vector3::new(0.0, 2.0 * KNOT, 0.0)).norm() < 1e-6,
            "{v1}"
        );
    }

    #[test]
    fn quality_filter_and_missing_std_error() {
        let log = [
            sentence("GPGGA,000001,4504.2,N,00740.8,E,1,8,1.0,200.0,M,0.0,M,,"),
            sentence("GPGGA,000002,4504.2,N,00740.8,E,5,8,1.0,200.0,M,0.0,M,,"),
            sentence("GPGGA,000003,4504.2,N,00740.8,E,4,8,1.0,200.0,M,0.0,M,,"),
        ]
        .join("\n");
        let opts = GnssReadOptions {
            min_quality: GnssQuality::Float,
            ..with_std()
        };
        let got = read(&log, &opts).expect("reads");
        assert_eq!(got.fixes.len(), 2);
        assert!(
            got.warnings
                .iter()
                .any(|w| w == "1 fixes below --gnss-min-quality float dropped")
        );
        let e = read(&log, &GnssReadOptions::default()).expect_err("no std");
        assert_eq!(
            e.to_string(),
            "log.nmea:1: field GST: the file gives no position standard deviations for this \
             fix: give them with --gnss-std N,E,D [m]"
        );
        let e = read("$GPGSV,1,1,00*79\n", &with_std()).expect_err("no fix");
        assert_eq!(e.kind, InputErrorKind::NoData);
    }
}
