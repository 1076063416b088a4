//! SP3 precise orbit files (versions c and d; IGS/NGS "The Extended Standard Product 3
//! Orbit Format (SP3-d)", 2016): satellite positions (and velocities) with clocks at
//! regular epochs, streamed one epoch at a time.
//!
//! Positions are written in km, clocks in µs, velocities in dm/s and clock rates in
//! 1e-4 µs/s; they come out in m, s, m/s and s/s. A position of 0.000000 (in any
//! coordinate) and a clock of 999999.999999 or more mean "unknown" (SP3-d §2) and come
//! out as `None`. Epochs are converted to GPS time from the file's time system (`%c`
//! line): GPS and GAL as written, TAI − 19 s, BDT + 14 s, UTC and GLONASS time (UTC +
//! 3 h) with the leap seconds of that date.
//!
//! Errors name the file, the line and the field (`x`, `clock`, `epoch`, …).

use std::io::BufRead;
use std::path::Path;

use nalgebra::Vector3;
use schuler::gnss::{GpsTime, Sat};

use crate::formats::InputError;
use crate::formats::error::{InputErrorKind, quote_field};
use crate::formats::gps_time::{date_of_week, leap_seconds};
use crate::formats::rinex::nav::{PeekLines, calendar, field_text, fortran_f64, int_field, slice};

/// An SP3 file's header: what a reader of the orbits needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Sp3Header {
    /// The version letter (`c`, `d`; `a` and `b` read the same).
    pub version: char,
    /// Whether velocity lines follow the positions (`V` flag).
    pub has_velocities: bool,
    /// The first epoch, in GPS time.
    pub start: GpsTime,
    /// The number of epochs the header announces.
    pub epochs: u64,
    /// The epoch interval [s].
    pub interval_s: f64,
    /// The satellites the header lists.
    pub sats: Vec<Sat>,
    /// The coordinate system (`IGS14`, `IGb08`, `ITRF2`, …).
    pub coordinate_system: String,
    /// The orbit type (`FIT`, `HLM`, `BHN`, …).
    pub orbit_type: String,
    /// The agency (`IGS`, `IAC`, `GRGS`, …).
    pub agency: String,
    /// The time system of the epochs as written (`GPS`, `GAL`, `BDT`, `UTC`, …).
    pub time_system: String,
}

/// One satellite at one epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sp3Sat {
    /// The satellite.
    pub sat: Sat,
    /// ECEF position of its centre of mass [m] (unless the file says otherwise), when
    /// known.
    pub r_e: Option<Vector3<f64>>,
    /// Clock offset [s], when known.
    pub clock_s: Option<f64>,
    /// Velocity [m/s], when the file has velocities and it is known.
    pub v_e: Option<Vector3<f64>>,
    /// Clock rate [s/s], when given.
    pub clock_rate: Option<f64>,
    /// Whether the orbit is flagged predicted (column 80 `P`) or a manoeuvre (79 `M`).
    pub predicted_or_manoeuvre: bool,
}

/// One epoch: its time and its satellites.
#[derive(Debug, Clone, PartialEq)]
pub struct Sp3Epoch {
    /// The epoch in GPS time.
    pub t: GpsTime,
    /// The satellites given at it, in file order.
    pub sats: Vec<Sp3Sat>,
}

/// A streaming SP3 reader: an iterator of epochs.
pub struct Sp3Reader {
    lines: PeekLines,
    header: Sp3Header,
    /// Seconds to add to a written epoch to make it GPS time, or `None` for UTC-based
    /// scales (`Some(offset)` of the scale from UTC: 0 or 3 h) that need leap seconds.
    scale: Scale,
    failed: bool,
}

/// How a file's epochs become GPS time.
#[derive(Debug, Clone, Copy)]
enum Scale {
    /// Add a constant [s].
    Offset(f64),
    /// UTC plus a constant [s]: subtract it, add the leap seconds of the date.
    Utc(f64),
}

/// The "unknown clock" value [µs] and above.
const BAD_CLOCK_US: f64 = 999_999.0;

impl Sp3Reader {
    /// Opens `path` (gzip-compressed or not) and reads its header.
    pub fn open(path: &Path) -> Result<Self, InputError> {
        Self::new(path, crate::formats::rinex::open(path)?)
    }

    /// Reads the header of `input`, named `path` in errors.
    pub fn new(path: &Path, input: Box<dyn BufRead + Send>) -> Result<Self, InputError> {
        let mut lines = PeekLines::new(path, input);
        let (header, scale) = read_header(&mut lines)?;
        Ok(Self {
            lines,
            header,
            scale,
            failed: false,
        })
    }

    /// The header.
    pub fn header(&self) -> &Sp3Header {
        &self.header
    }

    fn err(&self, kind: InputErrorKind, line: u64, field: &str, msg: String) -> InputError {
        InputError::new(kind, self.lines.path(), line, Some(field), msg)
    }

    /// The epoch line `line` (number `n`) as GPS time.
    fn epoch(&self, n: u64, line: &[u8]) -> Result<GpsTime, InputError> {
        let path = self.lines.path();
        let int = |s: usize, w: usize| int_field(slice(line, s, w), path, n, "epoch");
        let ymdhm = [
            int(3, 4)?,
            int(8, 2)?,
            int(11, 2)?,
            int(14, 2)?,
            int(17, 2)?,
        ];
        let sec = match field_text(line, 20, 11) {
            Some(t) => fortran_f64(t, path, n, "epoch")?,
            None => 0.0,
        };
        let t = calendar(ymdhm, sec, path, n)?;
        Ok(match self.scale {
            Scale::Offset(dt) => t.add_s(dt),
            Scale::Utc(from_utc) => {
                let utc = t.add_s(-from_utc);
                let leap =
                    date_of_week(utc.week, utc.sow).map_or(0.0, |(date, _)| leap_seconds(date));
                utc.add_s(leap)
            }
        })
    }

    /// The next epoch; `None` at `EOF` or the end of the file.
    fn next_epoch(&mut self) -> Result<Option<Sp3Epoch>, InputError> {
        let (n, line) = loop {
            match self.lines.next_line()? {
                None => return Ok(None),
                Some((_, l)) if l.starts_with(b"EOF") => return Ok(None),
                Some((_, l)) if l.trim_ascii().is_empty() || l.starts_with(b"/*") => {}
                Some((n, l)) if l.first() == Some(&b'*') => break (n, l),
                Some((n, l)) => {
                    return Err(self.err(
                        InputErrorKind::ColumnCount,
                        n,
                        "epoch",
                        format!("expected an epoch line ('*'): {}", quote_field(&l)),
                    ));
                }
            }
        };
        let t = self.epoch(n, &line)?;
        let mut sats: Vec<Sp3Sat> = Vec::new();
        while let Some(next) = self.lines.peek()? {
            match next.first() {
                Some(b'P') => {
                    let (n, l) = self.lines.next_line()?.unwrap_or_default();
                    sats.push(self.position_line(n, &l)?);
                }
                Some(b'V') => {
                    let (n, l) = self.lines.next_line()?.unwrap_or_default();
                    self.velocity_line(n, &l, &mut sats)?;
                }
                Some(b'E') if next.starts_with(b"EP") || next.starts_with(b"EV") => {
                    self.lines.next_line()?;
                }
                _ => break,
            }
        }
        Ok(Some(Sp3Epoch { t, sats }))
    }

    /// The satellite of a `P`/`V` line.
    fn sat(&self, n: u64, line: &[u8]) -> Result<Sat, InputError> {
        let id = slice(line, 1, 3);
        std::str::from_utf8(id)
            .ok()
            .and_then(Sat::parse)
            .ok_or_else(|| {
                self.err(
                    InputErrorKind::NotANumber,
                    n,
                    "satellite",
                    format!("not a satellite: {}", quote_field(id)),
                )
            })
    }

    /// Three coordinates and a clock-like value from columns 5–60 of line `n`
    /// (`F14.6` each); a blank clock reads as unknown.
    fn four(&self, n: u64, line: &[u8], names: [&str; 4]) -> Result<[Option<f64>; 4], InputError> {
        let mut out = [None; 4];
        for (k, (o, name)) in out.iter_mut().zip(names).enumerate() {
            *o = match field_text(line, 4 + 14 * k, 14) {
                Some(t) => Some(fortran_f64(t, self.lines.path(), n, name)?),
                None if k == 3 => None,
                None => {
                    return Err(self.err(
                        InputErrorKind::ColumnCount,
                        n,
                        name,
                        format!("truncated line: {name} is missing"),
                    ));
                }
            };
        }
        Ok(out)
    }

    /// A position line.
    fn position_line(&self, n: u64, line: &[u8]) -> Result<Sp3Sat, InputError> {
        let sat = self.sat(n, line)?;
        let [x, y, z, c] = self.four(n, line, ["x", "y", "z", "clock"])?;
        let (x, y, z) = (x.unwrap_or(0.0), y.unwrap_or(0.0), z.unwrap_or(0.0));
        let known = x != 0.0 && y != 0.0 && z != 0.0;
        let flags = slice(line, 78, 2);
        Ok(Sp3Sat {
            sat,
            r_e: known.then(|| Vector3::new(x, y, z) * 1e3),
            clock_s: c.filter(|&c| c < BAD_CLOCK_US).map(|c| c * 1e-6),
            v_e: None,
            clock_rate: None,
            predicted_or_manoeuvre: flags.contains(&b'M') || flags.contains(&b'P'),
        })
    }

    /// A velocity line, attached to its satellite's position of this epoch.
    fn velocity_line(&self, n: u64, line: &[u8], sats: &mut [Sp3Sat]) -> Result<(), InputError> {
        let sat = self.sat(n, line)?;
        let [x, y, z, c] = self.four(n, line, ["vx", "vy", "vz", "clock_rate"])?;
        let (x, y, z) = (x.unwrap_or(0.0), y.unwrap_or(0.0), z.unwrap_or(0.0));
        let Some(s) = sats.iter_mut().rev().find(|s| s.sat == sat) else {
            return Err(self.err(
                InputErrorKind::LayoutMismatch,
                n,
                "satellite",
                format!("a velocity of {sat} without its position line"),
            ));
        };
        let known = x != 0.0 || y != 0.0 || z != 0.0;
        s.v_e = known.then(|| Vector3::new(x, y, z) * 0.1);
        s.clock_rate = c.filter(|&c| c < BAD_CLOCK_US).map(|c| c * 1e-10);
        Ok(())
    }
}

impl Iterator for Sp3Reader {
    type Item = Result<Sp3Epoch, InputError>;

    /// The next epoch; after an error, `None`.
    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        let r = self.next_epoch();
        if r.is_err() {
            self.failed = true;
        }
        r.transpose()
    }
}

/// The header, up to the line before the first epoch.
fn read_header(lines: &mut PeekLines) -> Result<(Sp3Header, Scale), InputError> {
    let path = lines.path().to_path_buf();
    let header_err = |n: u64, field: &str, msg: String| {
        InputError::new(InputErrorKind::Header, &path, n, Some(field), msg)
    };
    let Some((n, first)) = lines.next_line()? else {
        return Err(header_err(
            0,
            "version",
            "empty file: not an SP3 orbit".into(),
        ));
    };
    let version = slice(&first, 1, 1).first().copied().unwrap_or(b' ') as char;
    if first.first() != Some(&b'#') || !matches!(version, 'a'..='d') {
        return Err(header_err(
            n,
            "version",
            format!(
                "not an SP3 file (a, b, c or d): {}",
                quote_field(slice(&first, 0, 3))
            ),
        ));
    }
    let has_velocities = slice(&first, 2, 1) == b"V";
    let epochs = field_text(&first, 32, 7).map_or(Ok(0), |t| int_field(t, &path, n, "epochs"))?;
    let text =
        |l: &[u8], s: usize, w: usize| String::from_utf8_lossy(slice(l, s, w)).trim().to_owned();
    let mut header = Sp3Header {
        version,
        has_velocities,
        start: GpsTime::new(0, 0.0),
        epochs: u64::try_from(epochs).unwrap_or(0),
        interval_s: 0.0,
        sats: Vec::new(),
        coordinate_system: text(&first, 46, 5),
        orbit_type: text(&first, 52, 3),
        agency: text(&first, 56, 4),
        time_system: "GPS".into(),
    };
    // The start epoch is read from line 1 once the `%c` line has given the time system.
    let mut start: Option<(u64, Vec<u8>)> = Some((n, first));
    let mut seen_percent_c = false;
    let mut sat_count: Option<usize> = None;
    while let Some(l) = lines.peek()? {
        if l.first() == Some(&b'*') || l.starts_with(b"EOF") {
            break;
        }
        let Some((n, l)) = lines.next_line()? else {
            break;
        };
        if l.starts_with(b"##") {
            let t = field_text(&l, 24, 14).unwrap_or(b"0");
            header.interval_s = fortran_f64(t, &path, n, "interval")?;
        } else if l.starts_with(b"+") && !l.starts_with(b"++") {
            if sat_count.is_none() {
                let t = field_text(&l, 1, 5).unwrap_or(b"");
                sat_count =
                    Some(usize::try_from(int_field(t, &path, n, "satellites")?).unwrap_or(0));
            }
            for k in 0..17 {
                let id = slice(&l, 9 + 3 * k, 3);
                if header.sats.len() >= sat_count.unwrap_or(0) {
                    break;
                }
                let s = std::str::from_utf8(id)
                    .ok()
                    .and_then(Sat::parse)
                    .ok_or_else(|| {
                        header_err(
                            n,
                            "satellites",
                            format!("not a satellite: {}", quote_field(id)),
                        )
                    })?;
                header.sats.push(s);
            }
        } else if l.starts_with(b"%c") && !seen_percent_c {
            seen_percent_c = true;
            let ts = text(&l, 9, 3);
            if !ts.is_empty() && !ts.starts_with("cc") {
                header.time_system = ts;
            }
        }
    }
    let scale = match header.time_system.as_str() {
        "GPS" | "GAL" | "QZS" | "IRN" => Scale::Offset(0.0),
        "TAI" => Scale::Offset(-19.0),
        "BDT" | "BDS" => Scale::Offset(schuler::gnss::time::GPST_MINUS_BDT_S),
        "UTC" => Scale::Utc(0.0),
        "GLO" => Scale::Utc(3.0 * 3600.0),
        other => {
            return Err(header_err(
                2,
                "time system",
                format!("unknown time system {other:?}"),
            ));
        }
    };
    if let Some((n, first)) = start.take() {
        let int = |s: usize, w: usize| int_field(slice(&first, s, w), &path, n, "start");
        let ymdhm = [
            int(3, 4)?,
            int(8, 2)?,
            int(11, 2)?,
            int(14, 2)?,
            int(17, 2)?,
        ];
        let sec =
            field_text(&first, 20, 11).map_or(Ok(0.0), |t| fortran_f64(t, &path, n, "start"))?;
        let t = calendar(ymdhm, sec, &path, n)?;
        header.start = match scale {
            Scale::Offset(dt) => t.add_s(dt),
            Scale::Utc(from) => {
                let utc = t.add_s(-from);
                let leap = date_of_week(utc.week, utc.sow).map_or(0.0, |(d, _)| leap_seconds(d));
                utc.add_s(leap)
            }
        };
    }
    Ok((header, scale))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use schuler::gnss::System;
    use std::path::PathBuf;

    fn data(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../tests/data/orbits")
            .join(name)
    }

    fn reader(text: &str) -> Result<Sp3Reader, InputError> {
        let input = Box::new(std::io::Cursor::new(text.as_bytes().to_vec()));
        Sp3Reader::new(Path::new("o.sp3"), input)
    }

    /// A two-satellite SP3-d file with velocities, one epoch.
    const SMALL: &str = "\
#dV2020  6 25  0  0  0.00000000       1 ORBIT IGS14 FIT  TST
## 2111 345600.00000000   900.00000000 59025 0.0000000000000
+    2   G01E11  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0
++         0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0
%c M  cc GPS ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc
%c cc cc ccc ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc
%f  1.2500000  1.025000000  0.00000000000  0.000000000000000
%i    0    0    0    0      0      0      0      0         0
/* a comment
*  2020  6 25  0  0  0.00000000
PG01  18392.619117   7490.690408 -17846.346485    -12.500000
VG01  -1234.567890  20000.000000      0.000001     -5.000000
PE11  11344.933153 -19282.775418  13781.610630 999999.999999                   P
EOF
";

    #[test]
    fn igs_final_orbit() {
        let mut r = Sp3Reader::open(&data("igs15904.sp3.gz")).unwrap();
        let h = r.header().clone();
        assert_eq!((h.version, h.has_velocities), ('c', false));
        assert_eq!(h.start, GpsTime::new(1590, 345_600.0));
        assert_eq!((h.epochs, h.interval_s, h.sats.len()), (96, 900.0, 32));
        assert_eq!(
            (h.coordinate_system.as_str(), h.agency.as_str()),
            ("IGS05", "IGS")
        );
        assert_eq!(h.time_system, "GPS");
        let first = r.next().unwrap().unwrap();
        assert_eq!(first.t, h.start);
        assert_eq!(first.sats.len(), 32);
        let g01 = first.sats[0];
        assert_eq!(g01.sat, Sat::new(System::Gps, 1));
        let want = Vector3::new(18_392_619.117, 7_490_690.408, -17_846_346.485);
        assert!((g01.r_e.unwrap() - want).norm() < 1e-6);
        assert_eq!(g01.clock_s, None);
        assert!((first.sats[1].clock_s.unwrap() - 269.108_429e-6).abs() < 1e-15);
        let rest: Vec<Sp3Epoch> = r.map(Result::unwrap).collect();
        assert_eq!(rest.len(), 95);
        assert_eq!(rest[94].t, GpsTime::new(1590, 345_600.0 + 95.0 * 900.0));
    }

    #[test]
    fn multi_gnss_orbit() {
        let r = Sp3Reader::open(&data("Sta21114_hourly_noR.sp3.gz")).unwrap();
        assert_eq!(r.header().sats.len(), 121);
        assert_eq!(r.header().version, 'd');
        let epochs: Vec<Sp3Epoch> = r.map(Result::unwrap).collect();
        assert_eq!(epochs.len(), 25);
        let c01 = epochs[0].sats[0];
        assert_eq!(c01.sat, Sat::new(System::BeiDou, 1));
        assert!((c01.clock_s.unwrap() + 387.166_264e-6).abs() < 1e-15);
    }

    #[test]
    fn velocities_flags_and_missing_clocks() {
        let mut r = reader(SMALL).unwrap();
        assert!(r.header().has_velocities);
        let sats = [Sat::new(System::Gps, 1), Sat::new(System::Galileo, 11)];
        assert_eq!(r.header().sats, sats);
        let e = r.next().unwrap().unwrap();
        assert!(r.next().is_none());
        let g01 = e.sats[0];
        assert!((g01.clock_s.unwrap() + 12.5e-6).abs() < 1e-18);
        let v = g01.v_e.unwrap();
        assert!(
            (v - Vector3::new(-123.456_789, 2_000.0, 1e-7)).norm() < 1e-9,
            "{v}"
        );
        assert!((g01.clock_rate.unwrap() + 5e-10).abs() < 1e-20);
        assert!(!g01.predicted_or_manoeuvre);
        assert_eq!(e.sats[1].clock_s, None);
        assert!(e.sats[1].predicted_or_manoeuvre);
    }

    #[test]
    fn time_systems() {
        let scales = [
            ("GPS", 0.0),
            ("GAL", 0.0),
            ("TAI", -19.0),
            ("BDT", 14.0),
            ("UTC", 18.0),
            ("GLO", 18.0 - 10_800.0),
        ];
        for (ts, dt) in scales {
            let text = SMALL.replacen("cc GPS", &format!("cc {ts}"), 1);
            let r = reader(&text).unwrap();
            assert_eq!(r.header().start, GpsTime::new(2111, 345_600.0 + dt), "{ts}");
        }
        let e = reader(&SMALL.replacen("cc GPS", "cc XYZ", 1))
            .err()
            .unwrap();
        assert_eq!(e.field.as_deref(), Some("time system"), "{e}");
    }

    #[test]
    fn errors_name_line_and_field() {
        let e = reader("#eP2020\n").err().unwrap();
        let got = (e.kind, e.line, e.field.as_deref());
        assert_eq!(got, (InputErrorKind::Header, 1, Some("version")));
        let bad = SMALL.replacen("7490.690408", "7490.69O408", 1);
        let e = reader(&bad).unwrap().next().unwrap().unwrap_err();
        let got = (e.kind, e.line, e.field.as_deref());
        assert_eq!(got, (InputErrorKind::NotANumber, 11, Some("y")));
        assert_eq!(
            e.to_string(),
            "o.sp3:11: field y: not a number: \"7490.69O408\""
        );
        let cut = SMALL.replacen("   7490.690408 -17846.346485    -12.500000", "", 1);
        let e = reader(&cut).unwrap().next().unwrap().unwrap_err();
        assert_eq!(
            (e.kind, e.field.as_deref()),
            (InputErrorKind::ColumnCount, Some("y"))
        );
        let bad = SMALL.replacen("*  2020  6 25  0  0", "*  2020  6 35  0  0", 1);
        let e = reader(&bad).unwrap().next().unwrap().unwrap_err();
        assert_eq!((e.line, e.field.as_deref()), (10, Some("epoch")), "{e}");
        let bad = SMALL.replacen("PG01", "PX01", 1);
        let e = reader(&bad).unwrap().next().unwrap().unwrap_err();
        assert_eq!(e.field.as_deref(), Some("satellite"), "{e}");
        let bad = SMALL.replacen("VG01", "VG02", 1);
        let e = reader(&bad).unwrap().next().unwrap().unwrap_err();
        assert_eq!(e.kind, InputErrorKind::LayoutMismatch, "{e}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2000)) {
            let input = Box::new(std::io::Cursor::new(bytes));
            if let Ok(r) = Sp3Reader::new(Path::new("x"), input) {
                for _ in r.take(100) {}
            }
        }

        #[test]
        fn spoilt_files_never_panic(cut in 0usize..1200, byte in any::<u8>(), at in 0usize..1200) {
            let mut bytes = SMALL.as_bytes().to_vec();
            let n = bytes.len();
            bytes[at.min(n - 1)] = byte;
            bytes.truncate(cut.min(n));
            let input = Box::new(std::io::Cursor::new(bytes));
            if let Ok(r) = Sp3Reader::new(Path::new("x"), input) {
                for _ in r.take(100) {}
            }
        }
    }
}
