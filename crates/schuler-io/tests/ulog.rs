//! The PX4 ULog reader on PX4/pyulog's test logs (tests/data/ulog, see its README) and
//! on small logs written here byte by byte after the ULog file format, whose records
//! are known in closed form. The counts asserted for the real logs are pyulog 1.3.0's
//! (message counts of each topic, dropouts), the ecosystem's own decoder; the values
//! are compared one by one with pyulog's by `pyulog_check.py` in `.ci/run`.

use schuler_io::formats::error::InputErrorKind;
use schuler_io::logs::ulog::UlogReader;
use schuler_io::logs::{LogItem, LogReader, LogRecord, StreamKind, TimeScale};
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/ulog")
        .join(name)
}

/// Every item of `path`, with the reader after the end.
fn read_all(path: &Path) -> (Vec<LogItem>, UlogReader) {
    let mut r = UlogReader::open(path).expect("opens");
    let items: Vec<LogItem> = r.by_ref().map(|i| i.expect("reads")).collect();
    (items, r)
}

/// Records per stream name.
fn count(items: &[LogItem], r: &UlogReader, name: &str) -> usize {
    items
        .iter()
        .filter(|i| r.streams()[i.stream].name == name)
        .count()
}

// ---- A ULog writer for hand-made logs ----------------------------------------------

struct Writer(Vec<u8>);

impl Writer {
    fn new(start_us: u64) -> Self {
        let mut b = vec![b'U', b'L', b'o', b'g', 0x01, 0x12, 0x35, 1];
        b.extend_from_slice(&start_us.to_le_bytes());
        Writer(b)
    }
    fn msg(&mut self, kind: u8, payload: &[u8]) -> usize {
        let at = self.0.len();
        self.0
            .extend_from_slice(&u16::try_from(payload.len()).expect("size").to_le_bytes());
        self.0.push(kind);
        self.0.extend_from_slice(payload);
        at
    }
    fn format(&mut self, text: &str) {
        self.msg(b'F', text.as_bytes());
    }
    fn add(&mut self, multi_id: u8, id: u16, name: &str) {
        let mut p = vec![multi_id];
        p.extend_from_slice(&id.to_le_bytes());
        p.extend_from_slice(name.as_bytes());
        self.msg(b'A', &p);
    }
    fn data(&mut self, id: u16, payload: &[u8]) -> usize {
        let mut p = id.to_le_bytes().to_vec();
        p.extend_from_slice(payload);
        self.msg(b'D', &p)
    }
}

const SENSOR_COMBINED: &str = "sensor_combined:uint64_t timestamp;float[3] gyro_rad;\
uint32_t gyro_integral_dt;int32_t accelerometer_timestamp_relative;\
float[3] accelerometer_m_s2;uint32_t accelerometer_integral_dt;uint8_t[4] _padding0;";

const GPS: &str = "vehicle_gps_position:uint64_t timestamp;uint64_t time_utc_usec;\
int32_t lat;int32_t lon;int32_t alt;int32_t alt_ellipsoid;float s_variance_m_s;float eph;\
float epv;float vel_n_m_s;float vel_e_m_s;float vel_d_m_s;uint8_t fix_type;bool vel_ned_valid;";

fn imu_payload(t_us: u64, dt_us: u32, gyro: [f32; 3], accel: [f32; 3]) -> Vec<u8> {
    let mut p = t_us.to_le_bytes().to_vec();
    gyro.iter()
        .for_each(|g| p.extend_from_slice(&g.to_le_bytes()));
    p.extend_from_slice(&dt_us.to_le_bytes());
    p.extend_from_slice(&0i32.to_le_bytes());
    accel
        .iter()
        .for_each(|a| p.extend_from_slice(&a.to_le_bytes()));
    p.extend_from_slice(&dt_us.to_le_bytes());
    p
}

fn gps_payload(t_us: u64, utc_us: u64, lat_e7: i32, lon_e7: i32, h_mm: i32, fix: u8) -> Vec<u8> {
    let mut p = t_us.to_le_bytes().to_vec();
    p.extend_from_slice(&utc_us.to_le_bytes());
    for v in [lat_e7, lon_e7, h_mm - 30_000, h_mm] {
        p.extend_from_slice(&v.to_le_bytes());
    }
    for v in [0.25f32, 1.5, 2.5, 1.0, -2.0, 0.5] {
        p.extend_from_slice(&v.to_le_bytes());
    }
    p.push(fix);
    p.push(1);
    p
}

/// A log of `n` IMU samples every `spacing_us` integrating `dt_us`, and a GPS fix.
fn hand_made(n: u64, spacing_us: u64, dt_us: u32) -> (Writer, Vec<usize>) {
    let mut w = Writer::new(1_000_000);
    w.format(SENSOR_COMBINED);
    w.format(GPS);
    w.add(0, 0, "sensor_combined");
    w.add(0, 1, "vehicle_gps_position");
    let mut at = Vec::new();
    for k in 1..=n {
        let t = 1_000_000 + k * spacing_us;
        at.push(w.data(
            0,
            &imu_payload(t, dt_us, [0.5, -0.25, 0.125], [1.0, 2.0, -9.75]),
        ));
        if k == 3 {
            // 2023-11-14 22:13:20 UTC at device time 1 s + 3 spacings.
            w.data(
                1,
                &gps_payload(
                    t,
                    1_700_000_000_000_000,
                    473_977_420,
                    85_455_940,
                    500_000,
                    3,
                ),
            );
            w.msg(b'O', &40u16.to_le_bytes());
        }
    }
    (w, at)
}

fn write(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).expect("write");
    p
}

/// The hand-made log's records in closed form: increments are rate × interval (the
/// f32 values are exact binary fractions, so equality is exact), times are GPS
/// seconds of week 2288 (UNIX 1 700 000 000 + 18 leap seconds, see `bag::clock`),
/// the fix's position 1e-7 deg and mm scaled, its standard deviations eph and epv.
#[test]
fn a_hand_made_log_reads_in_closed_form() {
    let dir = tempfile::tempdir().expect("dir");
    let (w, _) = hand_made(40, 4000, 4000);
    let path = write(&dir, "made.ulg", &w.0);
    let (items, r) = read_all(&path);
    assert_eq!(r.time_scale(), TimeScale::GpsSecondsOfWeek { week: 2288 });
    let sow_fix = 2.0 * 86_400.0 + 80_000.0 + 18.0;
    let imu: Vec<_> = items
        .iter()
        .filter_map(|i| match &i.record {
            LogRecord::Imu(s) => Some(s),
            _ => None,
        })
        .collect();
    assert_eq!(imu.len(), 40);
    let s = imu[2];
    assert_eq!(s.t, sow_fix);
    assert_eq!(s.dt, 0.004);
    assert_eq!(
        s.dtheta.as_slice(),
        [0.5 * 0.004, -0.25 * 0.004, 0.125 * 0.004]
    );
    assert_eq!(s.dvel.as_slice(), [0.004, 2.0 * 0.004, -9.75 * 0.004]);
    // One spacing (4 ms) earlier: integer µs divided by 10⁶, which is 252 817.996 to
    // the double's rounding (3e-11 s here).
    assert!((imu[1].t - (sow_fix - 0.004)).abs() < 1e-10, "{}", imu[1].t);
    let fix = items
        .iter()
        .find_map(|i| match &i.record {
            LogRecord::Gnss(f) => Some(f),
            _ => None,
        })
        .expect("a fix");
    assert_eq!(fix.t, sow_fix);
    assert_eq!(fix.pos.lat, (473_977_420.0f64 / 1e7).to_radians());
    assert_eq!(fix.pos.h, 500.0);
    assert_eq!(fix.pos_std.as_slice(), [1.5, 1.5, 2.5]);
    let (v, sv) = fix.vel.expect("velocity");
    assert_eq!(
        (v.as_slice(), sv.as_slice()),
        ([1.0, -2.0, 0.5].as_slice(), [0.25; 3].as_slice())
    );
    let rep = r.report();
    assert_eq!((rep.dropouts, rep.dropout_total_s), (1, 0.04));
    assert_eq!((rep.imu_gaps, rep.imu_incomplete), (0, 0));
    let kinds: Vec<_> = r
        .streams()
        .iter()
        .map(|s| (s.name.as_str(), s.kind))
        .collect();
    assert_eq!(
        kinds,
        [
            ("sensor_combined", StreamKind::Imu),
            ("vehicle_gps_position", StreamKind::Gnss)
        ]
    );
    // Same file, same records, bit for bit.
    assert_eq!(read_all(&path).0, items);
}

/// Samples integrating 4 ms every 20 ms (a decimated logging profile) are refused as
/// unusable for strapdown, with an error naming the stream.
#[test]
fn a_decimated_imu_stream_is_refused() {
    let dir = tempfile::tempdir().expect("dir");
    let (w, _) = hand_made(40, 20_000, 4000);
    let path = write(&dir, "decimated.ulg", &w.0);
    let mut r = UlogReader::open(&path).expect("opens");
    let e = r.by_ref().find_map(Result::err).expect("refused");
    assert_eq!(e.kind, InputErrorKind::LayoutMismatch);
    assert_eq!(e.field.as_deref(), Some("sensor_combined"));
    assert!(e.message.contains("not continuous"), "{e}");
    assert!(e.message.contains("unusable for strapdown"), "{e}");
    assert!(
        e.to_string().contains("4.0 ms") && e.to_string().contains("20.0 ms"),
        "{e}"
    );
    assert!(r.next().is_none());
}

/// A file cut inside a message, and one whose message type byte is garbled, are
/// refused with the byte offset of the message at fault (in `line`, and in words).
#[test]
fn truncated_and_garbled_files_are_refused_with_the_offset() {
    let dir = tempfile::tempdir().expect("dir");
    let (w, at) = hand_made(40, 4000, 4000);
    // Cut 10 bytes into the 21st IMU message.
    let cut = write(&dir, "cut.ulg", &w.0[..at[20] + 10]);
    let e = UlogReader::open(&cut)
        .and_then(|r| r.collect::<Result<Vec<_>, _>>())
        .expect_err("truncated");
    assert_eq!(e.line, at[20] as u64);
    assert!(e.message.contains("truncated"), "{e}");
    assert!(
        e.to_string()
            .starts_with(&format!("{}:{}: byte {}", cut.display(), at[20], at[20])),
        "{e}"
    );
    // A type byte that is no letter.
    let mut bad = w.0.clone();
    bad[at[30] + 2] = 0x9c;
    let garbled = write(&dir, "garbled.ulg", &bad);
    let e = UlogReader::open(&garbled)
        .and_then(|r| r.collect::<Result<Vec<_>, _>>())
        .expect_err("garbled");
    assert_eq!(
        (e.line, e.field.as_deref()),
        (at[30] as u64, Some("msg_type"))
    );
    assert!(
        e.message.contains("0x9c") && e.message.contains("garbled"),
        "{e}"
    );
    // A data message of a size the format does not allow (its size field grown by 9,
    // the next message's header swallowed): names the topic.
    let mut bad = w.0.clone();
    bad[at[10]] += 9;
    let e = UlogReader::open(&write(&dir, "size.ulg", &bad))
        .and_then(|r| r.collect::<Result<Vec<_>, _>>())
        .expect_err("size");
    assert_eq!(
        (e.line, e.field.as_deref()),
        (at[10] as u64, Some("sensor_combined"))
    );
    // Not a ULog file at all.
    let e = UlogReader::open(&write(&dir, "text.ulg", b"hello, world, this is text"))
        .err()
        .expect("not ULog");
    assert_eq!(e.kind, InputErrorKind::Header);
}

/// PX4/pyulog's `sample_log_small.ulg` (a Cube Orange in 2021, PX4 1.12): the counts of
/// pyulog, 1-e7-degree GNSS, one 30-ms dropout, and the clock tied to GPS time by the
/// first 3-D fix (UTC 2021-04-21 06:30:58.6, GPS week 2154).
#[test]
fn pyulog_sample_log_small() {
    let (items, r) = read_all(&data("sample_log_small.ulg.gz"));
    assert_eq!(r.time_scale(), TimeScale::GpsSecondsOfWeek { week: 2154 });
    assert_eq!(count(&items, &r, "sensor_combined"), 1298);
    assert_eq!(count(&items, &r, "vehicle_gps_position"), 32);
    assert_eq!(count(&items, &r, "vehicle_air_data"), 120);
    assert_eq!(count(&items, &r, "vehicle_attitude"), 1298);
    let rep = r.report();
    assert_eq!((rep.dropouts, rep.dropout_total_s), (1, 0.03));
    let tie = rep.gps_tie.expect("tied");
    assert_eq!(tie.utc_us, 1_618_986_658_600_345);
    assert_eq!(tie.leap_s, 18);
    // Instances 1 and 2 of the multi-instance sensors are listed, not decoded.
    let other = r
        .streams()
        .iter()
        .find(|s| s.name == "sensor_accel[2]")
        .expect("listed");
    assert_eq!(other.kind, StreamKind::Other);
    // Every IMU record in FRD increments with sensible sizes: a vehicle at rest or
    // moving gently, |Δv| ≈ g·dt.
    for i in &items {
        if let LogRecord::Imu(s) = &i.record {
            let g = s.dvel.norm() / s.dt;
            assert!((5.0..15.0).contains(&g), "specific force {g} at {}", s.t);
        }
    }
}

/// PX4/pyulog's `sample_px4_events.ulg` (PX4 1.15 SITL, 2024): `sensor_gps` with
/// degrees and metres as doubles and `timestamp_sample`; the EKF's own solution.
#[test]
fn pyulog_sample_px4_events() {
    let (items, r) = read_all(&data("sample_px4_events.ulg.gz"));
    assert!(matches!(r.time_scale(), TimeScale::GpsSecondsOfWeek { .. }));
    assert_eq!(count(&items, &r, "sensor_combined"), 7783);
    assert_eq!(count(&items, &r, "vehicle_global_position"), 109);
    let fixes: Vec<_> = items
        .iter()
        .filter_map(|i| match &i.record {
            LogRecord::Gnss(f) => Some(f),
            _ => None,
        })
        .collect();
    assert!(!fixes.is_empty());
    // PX4's SITL world is at Zurich's airfield: 47.39° N, 8.55° E.
    for f in fixes {
        assert!(
            (f.pos.lat.to_degrees() - 47.397).abs() < 0.01,
            "{:?}",
            f.pos
        );
        assert!((f.pos.lon.to_degrees() - 8.546).abs() < 0.01, "{:?}", f.pos);
    }
}

/// PX4/pyulog's `sample_appended_multiple.ulg`: data appended in several sections
/// after the flag bits' offsets; pyulog's counts.
#[test]
fn pyulog_sample_appended_multiple() {
    let (items, r) = read_all(&data("sample_appended_multiple.ulg.gz"));
    assert!(r.report().appended_sections >= 1);
    assert_eq!(count(&items, &r, "sensor_combined"), 2373);
    assert_eq!(count(&items, &r, "vehicle_attitude"), 306);
    assert_eq!(r.time_scale(), TimeScale::Device);
}

/// PX4/pyulog's `sample_logging_tagged_and_default_params.ulg`: tagged log messages
/// (`C`) and default parameters (`Q`) are taken in; the information messages read.
#[test]
fn pyulog_sample_logging_tagged_and_default_params() {
    let (items, r) = read_all(&data("sample_logging_tagged_and_default_params.ulg.gz"));
    assert_eq!(count(&items, &r, "sensor_combined"), 2028);
    let rep = r.report();
    assert_eq!(rep.info.get("ver_hw").map(String::as_str), Some("PX4_SITL"));
    // pyulog: 4 log messages, 3 of them tagged.
    assert_eq!(rep.log_messages, 7);
    assert_eq!(rep.unknown_messages, 0);
}
