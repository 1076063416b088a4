//! The ArduPilot DataFlash reader on pymavlink's test log and on the synthetic log of
//! `scripts/write_test_dataflash.py` (tests/data/dataflash, see its README), and on
//! small logs written here byte by byte after the format (ArduPilot `LogStructure.h`),
//! whose records are known in closed form. The message counts asserted for the two
//! committed logs are pymavlink 2.4.50's (`DFReader`), the ecosystem's own decoder;
//! `pymavlink_check.py` in `.ci/run` compares every value with pymavlink's.

use proptest::prelude::*;
use schuler_io::formats::error::InputErrorKind;
use schuler_io::logs::dataflash::DataflashReader;
use schuler_io::logs::{LogItem, LogReader, LogRecord, StreamKind, TimeScale};
use std::io::Read;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/dataflash")
        .join(name)
}

fn gunzip(name: &str) -> Vec<u8> {
    let mut bytes = Vec::new();
    flate2::read::GzDecoder::new(std::fs::File::open(data(name)).expect("test data"))
        .read_to_end(&mut bytes)
        .expect("gzip");
    bytes
}

/// Every item of `path`, with the reader after the end.
fn read_all(path: &Path) -> (Vec<LogItem>, DataflashReader) {
    let mut r = DataflashReader::open(path).expect("opens");
    let items: Vec<LogItem> = r.by_ref().map(|i| i.expect("reads")).collect();
    (items, r)
}

/// Records per stream name.
fn count(items: &[LogItem], r: &DataflashReader, name: &str) -> usize {
    items
        .iter()
        .filter(|i| r.streams()[i.stream].name == name)
        .count()
}

fn write(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).expect("write");
    p
}

// ---- A DataFlash writer for hand-made logs ----------------------------------------

/// The size of a format character's value.
fn size(ch: char) -> usize {
    match ch {
        'b' | 'B' | 'M' => 1,
        'h' | 'H' | 'c' | 'C' => 2,
        'i' | 'I' | 'f' | 'e' | 'E' | 'L' | 'n' => 4,
        'q' | 'Q' | 'd' => 8,
        'N' => 16,
        _ => 64,
    }
}

fn padded(s: &str, n: usize) -> Vec<u8> {
    let mut b = s.as_bytes().to_vec();
    b.resize(n, 0);
    b
}

struct Writer(Vec<u8>);

impl Writer {
    fn new() -> Self {
        let mut w = Writer(Vec::new());
        w.fmt(128, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns");
        w
    }
    fn msg(&mut self, ty: u8, body: &[u8]) -> usize {
        let at = self.0.len();
        self.0.extend_from_slice(&[0xA3, 0x95, ty]);
        self.0.extend_from_slice(body);
        at
    }
    fn fmt(&mut self, ty: u8, name: &str, format: &str, labels: &str) {
        let len = 3 + format.chars().map(size).sum::<usize>();
        let mut b = vec![ty, u8::try_from(len).expect("len")];
        b.extend(padded(name, 4));
        b.extend(padded(format, 16));
        b.extend(padded(labels, 64));
        self.msg(128, &b);
    }
    /// An `FMTU` (type 129) giving type `ty` the unit string `units`.
    fn fmtu(&mut self, ty: u8, units: &str) {
        let mut b = 0u64.to_le_bytes().to_vec();
        b.push(ty);
        b.extend(padded(units, 16));
        b.extend(padded("", 16));
        self.msg(129, &b);
    }
}

/// Little-endian bytes of values.
macro_rules! le {
    ($($v:expr),* $(,)?) => {{
        let mut b: Vec<u8> = Vec::new();
        $(b.extend_from_slice(&$v.to_le_bytes());)*
        b
    }};
}

const IMU: &str = "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ";
const GPS: &str = "TimeUS,I,Status,GMS,GWk,Lat,Lng,Alt,Spd,GCrs,VZ";
const GPA: &str = "TimeUS,I,HAcc,VAcc,SAcc,VV,AEl";
const XKF1: &str = "TimeUS,C,Roll,Pitch,Yaw,VN,VE,VD,PN,PE,PD";

/// A log of formats (types 129 `FMTU`, 130 `IMU`, 131 `GPS`, 132 `GPA`, 133 `BARO`,
/// 134 `XKF1`, 135 `ORGN`, 136 `PARM`) and their units.
fn formats() -> Writer {
    let mut w = Writer::new();
    w.fmt(129, "FMTU", "QBNN", "TimeUS,FmtType,UnitIds,MultIds");
    w.fmt(130, "IMU", "QBffffff", IMU);
    w.fmt(131, "GPS", "QBBIHLLefff", GPS);
    w.fmt(132, "GPA", "QBCCCBe", GPA);
    w.fmt(133, "BARO", "QBf", "TimeUS,I,Alt");
    w.fmt(134, "XKF1", "QBccCffffff", XKF1);
    w.fmt(135, "ORGN", "QBLLe", "TimeUS,Type,Lat,Lng,Alt");
    w.fmt(136, "PARM", "QNf", "TimeUS,Name,Value");
    for (ty, u) in [
        (130, "s#EEEooo"),
        (131, "s#-s-DUmnhn"),
        (132, "s#mmn-m"),
        (133, "s#m"),
        (134, "s#ddhnnnmmm"),
    ] {
        w.fmtu(ty, u);
    }
    w
}

fn imu(w: &mut Writer, us: u64, inst: u8, g: [f32; 3], a: [f32; 3]) -> usize {
    let mut b = le!(us);
    b.push(inst);
    b.extend(le!(g[0], g[1], g[2], a[0], a[1], a[2]));
    w.msg(130, &b)
}

/// A GPS fix at `us` and week 2288, `ms` of week, at 47.5°, 8.25°, 500 m AMSL moving
/// 3 m/s north-east (course 45°) and 0.5 m/s down; its GPA with the ellipsoid height.
fn fix(w: &mut Writer, us: u64, ms: u32, status: u8, ael_cm: i32) {
    let mut b = le!(us);
    b.extend([0, status]);
    b.extend(le!(ms, 2288u16, 475_000_000i32, 82_500_000i32, 50_000i32));
    b.extend(le!(3.0f32, 45.0f32, 0.5f32));
    w.msg(131, &b);
    let mut b = le!(us);
    b.push(0);
    b.extend(le!(150u16, 250u16, 40u16));
    b.push(1);
    b.extend(le!(ael_cm));
    w.msg(132, &b);
}

/// Three IMU samples 10 ms apart integrate to rate × 10 ms (exact binary fractions:
/// the equalities are exact but for the spacing, 0.01 s, and products with it, which
/// are the same double operations the reader does); the GPS fix ties 2288/
/// 172 800 000 ms to its TimeUS, so every time is GPS seconds of week; the fix's
/// height is AEl; the XKF1 position is its origin's offset.
#[test]
fn a_hand_made_log_reads_in_closed_form() {
    let dir = tempfile::tempdir().expect("dir");
    let mut w = formats();
    let g = [0.5f32, -0.25, 0.125];
    let a = [1.0f32, 2.0, -9.75];
    for k in 0..3u64 {
        imu(&mut w, 5_000_000 + k * 10_000, 0, g, a);
    }
    fix(&mut w, 5_020_000, 172_800_000, 3, 55_000);
    let mut b = le!(5_030_000u64);
    b.push(0);
    b.extend(le!(1.5f32));
    w.msg(133, &b);
    let mut b = le!(5_040_000u64);
    b.push(0);
    b.extend(le!(475_000_000i32, 82_500_000i32, 50_000i32));
    w.msg(135, &b);
    let mut b = le!(5_050_000u64);
    b.push(0);
    b.extend(le!(-1050i16, 250i16, 27_000u16));
    b.extend(le!(1.0f32, -2.0f32, 0.5f32, 1000.0f32, 0.0f32, -10.0f32));
    w.msg(134, &b);
    let path = write(&dir, "made.bin", &w.0);
    let (items, r) = read_all(&path);
    assert_eq!(r.time_scale(), TimeScale::GpsSecondsOfWeek { week: 2288 });
    let sow = |us: u64| 172_800.0 + (us as f64 - 5_020_000.0) / 1e6;
    let imus: Vec<_> = items
        .iter()
        .filter_map(|i| match &i.record {
            LogRecord::Imu(s) => Some(s),
            _ => None,
        })
        .collect();
    assert_eq!(imus.len(), 2, "the first sample starts the stream");
    assert_eq!(imus[1].t, 172_800.0);
    assert!((imus[0].t - sow(5_010_000)).abs() < 1e-10);
    let dt = 10_000.0 / 1e6;
    assert_eq!(imus[0].dt, dt);
    assert_eq!(
        imus[0].dtheta.as_slice(),
        [0.5 * dt, -0.25 * dt, 0.125 * dt]
    );
    assert_eq!(imus[0].dvel.as_slice(), [dt, 2.0 * dt, -9.75 * dt]);
    let fix = items
        .iter()
        .find_map(|i| match &i.record {
            LogRecord::Gnss(f) => Some(f),
            _ => None,
        })
        .expect("a fix");
    assert_eq!(fix.t, 172_800.0);
    assert_eq!(fix.pos.lat, 47.5f64.to_radians());
    assert_eq!(fix.pos.lon, (82_500_000.0 * 1e-7f64).to_radians());
    assert_eq!(fix.pos.h, 550.0, "AEl, not the MSL Alt");
    assert_eq!(fix.pos_std.as_slice(), [1.5, 1.5, 2.5]);
    let (v, sv) = fix.vel.expect("velocity");
    let c = 45f64.to_radians();
    assert_eq!(v.as_slice(), [3.0 * c.cos(), 3.0 * c.sin(), 0.5]);
    assert_eq!(sv.as_slice(), [0.4; 3]);
    let baro = items.iter().find_map(|i| match i.record {
        LogRecord::Baro { t, h } => Some((t, h)),
        _ => None,
    });
    assert_eq!(baro, Some((172_800.01, 1.5)));
    let reference = items
        .iter()
        .find_map(|i| match &i.record {
            LogRecord::Reference(r) => Some(r),
            _ => None,
        })
        .expect("a reference");
    let att = reference.att.expect("attitude");
    assert_eq!(
        (att.roll, att.pitch, att.yaw),
        (
            (-1050.0 * 0.01f64).to_radians(),
            2.5f64.to_radians(),
            (270.0f64 - 360.0).to_radians()
        )
    );
    let pos = reference.pos.expect("the origin came first");
    // 1000 m north on ArduPilot's sphere (6 378 100 m): 8.983e-3 deg; 10 m up.
    let deg = 1000.0 / (6_378_100.0 * std::f64::consts::PI / 180.0);
    assert!((pos.lat.to_degrees() - 47.5 - deg).abs() < 1e-12);
    assert_eq!(pos.h, 510.0);
    let kinds: Vec<_> = r
        .streams()
        .iter()
        .map(|s| (s.name.as_str(), s.kind))
        .filter(|s| s.1 != StreamKind::Other)
        .collect();
    assert_eq!(
        kinds,
        [
            ("IMU[0]", StreamKind::Imu),
            ("GPS[0]", StreamKind::Gnss),
            ("BARO[0]", StreamKind::Baro),
            ("XKF1[0]", StreamKind::Reference),
        ]
    );
    let rep = r.report();
    assert_eq!(rep.imu_restarts, 1);
    assert_eq!(rep.gnss_msl_height, 0);
    assert_eq!(rep.ending, Default::default());
}

/// pymavlink's `tests/test.BIN` (ArduPlane SITL, 2017): the old message set (IMU and
/// IMU2, GPS without instance, EKF2's NKF1), a log cut inside its last message. The
/// counts are pymavlink's: 45 IMU, 45 IMU2 (each stream's first sample starts it),
/// 5 GPS with 5 GPA, all 3-D fixes with MSL heights, 8 BARO, 24 NKF1, 2 ORGN.
#[test]
fn pymavlinks_test_log_reads() {
    let (items, r) = read_all(&data("pymavlink_test.bin.gz"));
    assert_eq!(r.time_scale(), TimeScale::GpsSecondsOfWeek { week: 1973 });
    assert_eq!(count(&items, &r, "IMU"), 44);
    assert_eq!(count(&items, &r, "IMU2"), 44);
    assert_eq!(count(&items, &r, "GPS"), 5);
    assert_eq!(count(&items, &r, "BARO"), 8);
    assert_eq!(count(&items, &r, "NKF1"), 24);
    let rep = r.report();
    assert_eq!(rep.gnss_msl_height, 5);
    assert_eq!(rep.gnss_without_accuracy, 0);
    let tie = rep.gps_tie.expect("tied");
    assert_eq!(
        (tie.device_us, tie.week, tie.ms),
        (81_855_471, 1973, 6_448_000)
    );
    let cut = rep.ending.truncated.clone().expect("cut at the end");
    assert_eq!(cut.offset + cut.have as u64, 65_536);
    assert!(cut.have < cut.need);
    // The first fix is at its GMS: 6 448 000 ms is 6448 s into week 1973.
    let first_fix = items.iter().find_map(|i| match &i.record {
        LogRecord::Gnss(f) => Some(f.t),
        _ => None,
    });
    assert_eq!(first_fix, Some(6448.0));
    assert!(
        r.streams()
            .iter()
            .any(|s| s.name == "PARM" && s.kind == StreamKind::Other)
    );
}

/// The synthetic log (scripts/write_test_dataflash.py): 1000 IMU messages per instance
/// every 10 ms, 50 GPS (5 without a fix, one whose GPA has no AEl), 100 BARO, 100
/// XKF1 per core (core 0 the reference, the 19 before ORGN without position). Times
/// are GPS seconds of week 2300 from GMS = 345 600 000 + (TimeUS − 60 s)/1000.
#[test]
fn the_synthetic_log_reads() {
    let (items, r) = read_all(&data("synthetic_circle.bin.gz"));
    assert_eq!(r.time_scale(), TimeScale::GpsSecondsOfWeek { week: 2300 });
    assert_eq!(count(&items, &r, "IMU[0]"), 999);
    assert_eq!(count(&items, &r, "IMU[1]"), 999);
    assert_eq!(count(&items, &r, "GPS[0]"), 45);
    assert_eq!(count(&items, &r, "BARO[0]"), 100);
    assert_eq!(count(&items, &r, "XKF1[0]"), 100);
    assert_eq!(count(&items, &r, "XKF1[1]"), 0);
    let rep = r.report();
    assert_eq!(
        (
            rep.gnss_without_fix,
            rep.gnss_msl_height,
            rep.reference_without_origin
        ),
        (5, 1, 19)
    );
    assert_eq!(rep.imu_restarts, 2);
    let kind = |n: &str| r.streams().iter().find(|s| s.name == n).map(|s| s.kind);
    assert_eq!(kind("XKF1[1]"), Some(StreamKind::Other));
    assert_eq!(kind("GPA[0]"), Some(StreamKind::Other));
    // The IMU at TimeUS 61 s is 1 s after the log's zero: 345 601 s of week.
    let t = items.iter().find_map(|i| match &i.record {
        LogRecord::Imu(s) if s.t >= 345_601.0 => Some(s.t),
        _ => None,
    });
    assert_eq!(t, Some(345_601.0));
}

#[test]
fn a_file_that_is_no_dataflash_log_is_refused_at_byte_0() {
    let dir = tempfile::tempdir().expect("dir");
    let path = write(&dir, "x.bin", b"ULog\x01\x12\x35 and more");
    let e = DataflashReader::open(&path).err().expect("refused");
    assert_eq!((e.kind, e.line), (InputErrorKind::Header, 0));
    assert!(e.message.contains("not a DataFlash log"), "{e}");
    let empty = write(&dir, "empty.bin", b"");
    let e = DataflashReader::open(&empty).err().expect("refused");
    assert_eq!(e.kind, InputErrorKind::NoData);
}

/// Writes a fault into a log; its byte offset.
type Fault = Box<dyn Fn(&mut Writer) -> usize>;

/// Padding after a fault, so that it lies more than 528 bytes before the end.
fn pad(w: &mut Writer) {
    for k in 0..40u64 {
        let mut b = le!(k);
        b.extend(padded("P", 16));
        b.extend(le!(1.0f32));
        w.msg(136, &b);
    }
}

/// Garbled bytes away from the end are refused naming their byte offset and what is
/// wrong: a missing header, a type no FMT defined, an FMT with an unknown character or
/// a wrong length, and a message schuler reads that lacks a column.
#[test]
fn garbled_logs_are_refused_naming_offset_and_field() {
    let dir = tempfile::tempdir().expect("dir");
    let cases: Vec<(&str, Fault)> = vec![
        (
            "header",
            Box::new(|w: &mut Writer| {
                let at = imu(w, 1, 0, [0.0; 3], [0.0; 3]);
                w.0[at + 1] = 0x00;
                at
            }),
        ),
        ("msg_type", Box::new(|w: &mut Writer| w.msg(200, &[0; 8]))),
        (
            "FMT.Format",
            Box::new(|w: &mut Writer| {
                let at = w.0.len();
                w.fmt(140, "BAD", "Qx", "TimeUS,X");
                at
            }),
        ),
        (
            "FMT.Length",
            Box::new(|w: &mut Writer| {
                let at = w.0.len();
                w.fmt(140, "BAD", "Qf", "TimeUS,X");
                w.0[at + 4] = 40;
                at
            }),
        ),
        (
            "IMU.GyrX",
            Box::new(|w: &mut Writer| {
                w.fmt(141, "IMU2", "Qf", "TimeUS,GyrY");
                w.msg(141, &le!(1u64, 0.0f32))
            }),
        ),
    ];
    for (field, make) in cases {
        let mut w = formats();
        pad(&mut w);
        let at = make(&mut w);
        pad(&mut w);
        let path = write(&dir, "bad.bin", &w.0);
        let e = DataflashReader::open(&path)
            .and_then(|r| r.collect::<Result<Vec<_>, _>>())
            .err()
            .unwrap_or_else(|| panic!("{field}: refused"));
        let want = if field == "IMU.GyrX" {
            "IMU2.GyrX"
        } else {
            field
        };
        assert_eq!((e.field.as_deref(), e.line), (Some(want), at as u64), "{e}");
        assert!(e.to_string().contains(&format!("byte {at}")), "{e}");
    }
}

/// A message cut by the end of the log ends it: reported with its offset and name.
#[test]
fn a_cut_last_message_is_reported_not_refused() {
    let dir = tempfile::tempdir().expect("dir");
    let mut w = formats();
    imu(&mut w, 1_000, 0, [0.0; 3], [0.0; 3]);
    imu(&mut w, 2_000, 0, [0.0; 3], [0.0; 3]);
    let at = imu(&mut w, 3_000, 0, [0.0; 3], [0.0; 3]);
    w.0.truncate(at + 10);
    let path = write(&dir, "cut.bin", &w.0);
    let (items, r) = read_all(&path);
    assert_eq!(items.len(), 1);
    assert_eq!(r.time_scale(), TimeScale::Device);
    let cut = r.report().ending.truncated.clone().expect("cut");
    assert_eq!(
        (cut.offset, cut.name.as_deref(), cut.have, cut.need),
        (at as u64, Some("IMU"), 10, 36)
    );
}

/// Every item of `bytes` read as a log, or the error that ended it; never a panic.
fn read_bytes(
    dir: &tempfile::TempDir,
    bytes: &[u8],
) -> (
    Vec<LogItem>,
    TimeScale,
    Option<schuler_io::formats::InputError>,
) {
    let path = write(dir, "p.bin", bytes);
    let mut r = match DataflashReader::open(&path) {
        Ok(r) => r,
        Err(e) => return (Vec::new(), TimeScale::Device, Some(e)),
    };
    let mut items = Vec::new();
    for i in r.by_ref() {
        match i {
            Ok(i) => items.push(i),
            Err(e) => return (items, r.time_scale(), Some(e)),
        }
    }
    (items, r.time_scale(), None)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// A log cut anywhere after its first message reads without error (the cut
    /// message is its end) and gives a prefix of the whole log's records when the cut
    /// leaves the clock's tie in; cut inside its first message it holds no complete
    /// message and is refused as such.
    #[test]
    fn a_log_cut_anywhere_reads_a_prefix(frac in 0.0f64..1.0) {
        let bytes = gunzip("pymavlink_test.bin.gz");
        let dir = tempfile::tempdir().expect("dir");
        let (full, scale, _) = read_bytes(&dir, &bytes);
        let cut = ((bytes.len() as f64 * frac) as usize).max(1);
        let (items, s, err) = read_bytes(&dir, &bytes[..cut]);
        // The first message is the FMT describing FMT: byte 4 is its length (89).
        if cut < usize::from(bytes[4]) {
            prop_assert_eq!(err.map(|e| e.kind), Some(InputErrorKind::NoData));
            prop_assert!(items.is_empty());
            return Ok(());
        }
        prop_assert!(err.is_none(), "{:?}", err);
        prop_assert!(items.len() <= full.len());
        if s == scale {
            // A fix whose GPA was cut off gives no record, so the prefix still holds.
            let n = items.len();
            prop_assert_eq!(&items[..], &full[..n]);
        }
    }

    /// A byte changed anywhere gives records or an error naming a byte offset inside
    /// the log, never a panic.
    #[test]
    fn a_garbled_byte_never_panics(frac in 0.0f64..1.0, value in any::<u8>()) {
        let mut bytes = gunzip("synthetic_circle.bin.gz");
        let at = ((bytes.len() as f64 * frac) as usize).min(bytes.len() - 1);
        bytes[at] = value;
        let dir = tempfile::tempdir().expect("dir");
        let (_, _, err) = read_bytes(&dir, &bytes);
        if let Some(e) = err {
            prop_assert!(e.line <= bytes.len() as u64, "{}", e);
            prop_assert!(e.line <= at as u64 || e.field.is_some(), "{}", e);
        }
    }
}
