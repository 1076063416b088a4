//! The UBX reader on real receiver logs (tests/data/ubx, provenance in its README):
//! counts, decoded values, a single-point position from the log's own raw
//! measurements and broadcast subframes against the receiver's NAV-PVT, the IMU's
//! axes and clock, and truncated or garbled input.

use schuler::earth::Geodetic;
use schuler::filter::GnssFix;
use schuler::gnss::spp::{SppConfig, solve};
use schuler::gnss::{C, EphemerisStore, RawEpoch, Sat, Signal, System};
use schuler::imu::ImuSample;
use schuler_io::formats::InputError;
use schuler_io::logs::ubx::{UbxOptions, UbxReader, UbxReport};
use schuler_io::logs::{LogItem, LogReader, LogRecord, ReferenceSample, StreamKind, TimeScale};
use std::io::Read;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/ubx")
        .join(name)
}

/// The decompressed bytes of a committed log.
fn bytes(name: &str) -> Vec<u8> {
    let raw = std::fs::read(data(name)).expect("read");
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(raw.as_slice())
        .read_to_end(&mut out)
        .expect("gunzip");
    out
}

/// Everything a reader gives, with its streams, counts and report.
struct Log {
    items: Vec<LogItem>,
    names: Vec<(String, StreamKind, u64)>,
    report: UbxReport,
    scale: TimeScale,
}

impl Log {
    fn of(mut r: UbxReader) -> Result<Self, InputError> {
        let items = r.by_ref().collect::<Result<Vec<_>, _>>()?;
        let names = r
            .streams()
            .iter()
            .zip(r.counts())
            .map(|(s, &n)| (s.name.clone(), s.kind, n))
            .collect();
        Ok(Self {
            items,
            names,
            report: r.report().clone(),
            scale: r.time_scale(),
        })
    }

    fn count(&self, name: &str) -> u64 {
        self.names.iter().find(|n| n.0 == name).map_or(0, |n| n.2)
    }

    fn stream_name(&self, item: &LogItem) -> &str {
        &self.names[item.stream].0
    }

    fn fixes(&self) -> Vec<&GnssFix> {
        self.items
            .iter()
            .filter_map(|i| match &i.record {
                LogRecord::Gnss(f) => Some(f),
                _ => None,
            })
            .collect()
    }

    fn epochs(&self) -> Vec<&RawEpoch> {
        self.items
            .iter()
            .filter_map(|i| match &i.record {
                LogRecord::Raw(e) => Some(e),
                _ => None,
            })
            .collect()
    }

    fn imu(&self, stream: &str) -> Vec<&ImuSample> {
        self.items
            .iter()
            .filter(|i| self.stream_name(i) == stream)
            .filter_map(|i| match &i.record {
                LogRecord::Imu(s) => Some(s),
                _ => None,
            })
            .collect()
    }
}

fn read(name: &str) -> Log {
    Log::of(UbxReader::open(&data(name)).expect("open")).expect("read")
}

fn from_bytes(b: Vec<u8>, options: UbxOptions) -> Result<Log, InputError> {
    let n = b.len() as u64;
    Log::of(UbxReader::new(
        Path::new("mem.ubx"),
        Box::new(std::io::Cursor::new(b)),
        n,
        options,
    ))
}

const ROVER: &str = "f9p_rover_rawx_sfrbx.ubx.gz";
const M8U: &str = "neo_m8u_esf.ubx.gz";
const F9_TRUNC: &str = "f9_esf_nav_att_truncated.ubx.gz";

#[test]
fn rover_log_counts_and_first_fix() {
    let r = read(ROVER);
    // Counts as pyubx2 1.4.0 reads the same bytes. NMEA: 3727 `$…` runs of printable
    // bytes ending in CR LF; three are torn by serial dropouts (`$$GNRMC`, `$ $GNRMC`,
    // a GGA cut by an RMC), and pyubx2 drops the RMC inside the torn GGA with it (3726).
    assert_eq!(r.count("NAV-PVT"), 455);
    assert_eq!(r.count("RXM-RAWX"), 2);
    assert_eq!(r.count("RXM-SFRBX"), 686);
    assert_eq!(r.count("NMEA"), 3727);
    // The torn sentences and frames of the serial dropouts: 1992 bytes that begin
    // nothing, under 1 % of the file.
    assert_eq!(r.report.unknown_bytes, 1992);
    // The excerpt ends 37 bytes into a NAV-PVT frame (100 bytes with its header).
    let t = r.report.truncated_tail.clone().expect("cut");
    assert_eq!(
        (t.offset, t.name.as_deref(), t.have, t.need),
        (299_912, Some("NAV-PVT"), 37, 100)
    );
    assert_eq!(r.scale, TimeScale::GpsSecondsOfWeek { week: 2049 });
    let fixes = r.fixes();
    assert_eq!(fixes.len() as u64 + r.report.pvt_without_fix, 455);
    // The first NAV-PVT as pyubx2 prints it: iTOW 231467750 ms, lat 28.7341825°,
    // lon −13.8668829°, height 50 609 mm, hAcc 241 mm.
    let f = fixes[0];
    assert_eq!(f.t, 231_467.75);
    assert!((f.pos.lat.to_degrees() - 28.734_182_5).abs() < 1e-12);
    assert!((f.pos.lon.to_degrees() + 13.866_882_9).abs() < 1e-12);
    assert_eq!(f.pos.h, 50.609);
    assert_eq!(f.pos_std.x, 0.241);
    // Same input, same output, bit for bit.
    assert_eq!(read(ROVER).items, r.items);
}

/// The NAV-PVT of the epoch at `t` [s].
fn fix_at(r: &Log, t: f64) -> &GnssFix {
    r.fixes()
        .into_iter()
        .min_by(|a, b| (a.t - t).abs().total_cmp(&(b.t - t).abs()))
        .expect("fixes")
}

#[test]
fn spp_from_the_logs_own_subframes_matches_its_nav_pvt() {
    let r = read(ROVER);
    let mut store = EphemerisStore::new();
    for i in &r.items {
        if let LogRecord::Ephemeris(e) = &i.record {
            assert_eq!(e.sat.system, System::Gps);
            assert!(e.is_healthy(), "{}", e.sat);
            // A GPS orbit: √A ≈ 5153.7 √m (26 560 km), e < 0.03.
            assert!(
                (e.kepler.sqrt_a - 5153.7).abs() < 5.0,
                "{}",
                e.kepler.sqrt_a
            );
            assert!(e.kepler.e < 0.03);
            store.push((**e).clone());
        }
    }
    let sats: Vec<String> = store.sats().map(|s| s.to_string()).collect();
    assert_eq!(sats, ["G10", "G16", "G21", "G25", "G29", "G31"]);
    let epoch = r.epochs()[0];
    // GPS only (the log's complete subframes are GPS's); no broadcast ionosphere
    // decoded, so Klobuchar is off and SppConfig's model term (5 m)² covers it. Mask
    // 5°: three of the six satellites are between 6° and 8° (the default 10° would
    // leave three).
    let config = SppConfig {
        signals: vec![(System::Gps, vec![Signal::new(System::Gps, '1', 'C')])],
        elevation_mask: 5f64.to_radians(),
        ..SppConfig::default()
    };
    let sol = solve(epoch, &store, None, &config, None).expect("solution");
    assert_eq!(sol.used.len(), 6);
    let pvt = fix_at(&r, epoch.t.sow);
    assert!((pvt.t - epoch.t.sow).abs() < 0.01);
    let (dn, de, dd) = ned_difference(&sol.geodetic, &pvt.pos);
    let horizontal = dn.hypot(de);
    println!(
        "SPP − NAV-PVT: north {dn:.2} m, east {de:.2} m, down {dd:.2} m; clock {:.1} m",
        sol.clock_of(System::Gps).unwrap()
    );
    // Bounds: a 6-satellite L1 C/A solution without any ionosphere model (vertical
    // delay of a few metres, mostly in the height) against the receiver's own
    // (dual-frequency, ionosphere-free) fix: 10 m horizontally, 15 m vertically.
    assert!(horizontal < 10.0, "horizontal {horizontal} m");
    assert!(dd.abs() < 15.0, "vertical {dd} m");
    // The receiver clock: the F9P steers its clock to GPS time within a millisecond.
    assert!(sol.clock_of(System::Gps).unwrap().abs() < 1e-3 * C);
}

/// North, east, down of `a` from `b` [m] (small differences, spherical radius).
fn ned_difference(a: &Geodetic, b: &Geodetic) -> (f64, f64, f64) {
    let r = 6_371_000.0;
    (
        (a.lat - b.lat) * r,
        (a.lon - b.lon) * r * b.lat.cos(),
        b.h - a.h,
    )
}

#[test]
fn doppler_is_positive_for_an_approaching_satellite() {
    // Between the two RAWX epochs the pseudorange of each satellite changes at
    // ρ̇ + c·(clock drift), and ρ̇ = −λ·D when D is positive for an approaching
    // satellite: (ΔP/Δt + λ·D̄) is then the same for every satellite.
    let r = read(ROVER);
    let e = r.epochs();
    let dt = e[1].t.diff_s(e[0].t);
    assert!((dt - 4.125).abs() < 1e-9);
    let l1 = Signal::new(System::Gps, '1', 'C');
    let mut common = Vec::new();
    let mut flipped = Vec::new();
    for m0 in e[0].measurements.iter().filter(|m| m.signal == l1) {
        let Some(m1) = e[1].get(m0.sat, l1) else {
            continue;
        };
        let (Some(p0), Some(p1)) = (m0.pseudorange, m1.pseudorange) else {
            continue;
        };
        let lambda = m0.wavelength().unwrap();
        let d = 0.5 * (m0.doppler.unwrap() + m1.doppler.unwrap());
        common.push((p1 - p0) / dt + lambda * d);
        flipped.push((p1 - p0) / dt - lambda * d);
    }
    let spread = |v: &[f64]| {
        v.iter().copied().fold(f64::MIN, f64::max) - v.iter().copied().fold(f64::MAX, f64::min)
    };
    assert!(common.len() >= 6);
    // Code noise of ~0.5 m over 4 s, and D̄ for a Doppler that drifts ~0.5 Hz/s: 1 m/s.
    assert!(spread(&common) < 1.0, "{common:?}");
    assert!(spread(&flipped) > 100.0, "{flipped:?}");
}

#[test]
fn rawx_values_as_written() {
    // The first measurement of the first epoch as pyubx2 prints it: G16 L1 C/A,
    // prMes 21710092.657786787, cpMes 114087299.40239549, doMes 1721.470458984375,
    // locktime 44124, cno 43, prStd 3, cpStd 2, doStd 6, trkStat 0b0111.
    let r = read(ROVER);
    let e = r.epochs()[0];
    assert_eq!(e.t.week, 2049);
    assert_eq!(e.t.sow, 231_471.124);
    let m = e
        .get(
            Sat::new(System::Gps, 16),
            Signal::new(System::Gps, '1', 'C'),
        )
        .unwrap();
    assert_eq!(m.pseudorange, Some(21_710_092.657_786_787));
    assert_eq!(m.carrier_phase, Some(114_087_299.402_395_49));
    assert_eq!(m.doppler, Some(1_721.470_458_984_375));
    assert_eq!(m.cn0, Some(43.0));
    assert_eq!(m.pseudorange_std, Some(0.08));
    assert_eq!(m.carrier_phase_std, Some(0.008));
    assert_eq!(m.doppler_std, Some(0.128));
    let lock = m.lock.unwrap();
    assert_eq!(lock.lock_time_ms, Some(44_124));
    assert!(!lock.half_cycle);
    // L2 CL measurements of the F9P are there too.
    assert!(e.measurements.iter().any(|m| m.signal.rinex() == "2L"));
}

#[test]
fn m8u_imu_axes_rates_and_clocks() {
    let r = read(M8U);
    assert_eq!(r.count("ESF-RAW"), 29);
    assert_eq!(r.count("ESF-MEAS"), 58);
    assert_eq!(r.count("NAV-PVT"), 3);
    // gpsd's text header before the first frame.
    assert!(r.report.unknown_bytes > 500, "{}", r.report.unknown_bytes);
    let raw = r.imu("ESF-RAW");
    let meas = r.imu("ESF-MEAS");
    // 29 messages of 10 samples; the first sample of a stream has no interval.
    assert_eq!(raw.len() + r.report.imu_untied as usize, 289);
    assert!(!raw.is_empty() && !meas.is_empty());
    // Tick of ESF-RAW: its samples are 100 Hz (256 ticks), and the span of the ESF-RAW
    // stream measured in ticks equals the span of ESF-MEAS in its milliseconds over
    // the same messages to 0.5 % (the receiver writes both for the same sensor reads).
    let span = |v: &[&ImuSample]| v.last().unwrap().t - v.first().unwrap().t;
    let mean_dt = span(&raw) / (raw.len() - 1) as f64;
    assert!((mean_dt - 0.01).abs() < 1e-4, "{mean_dt}");
    let ratio = (span(&raw) / (raw.len() - 1) as f64) / (span(&meas) / (meas.len() - 1) as f64);
    assert!((ratio - 0.1).abs() < 0.1 * 5e-3, "{ratio}");
    // At rest: the specific force in FRD points up, −g on z; its size is g to the
    // uncompensated MEMS accelerometer's bias (0.3 m/s²); the gyro reads its bias
    // (under 1°/s).
    for v in [&raw, &meas] {
        let n = v.len() as f64;
        let f = v
            .iter()
            .map(|s| s.dvel / s.dt)
            .sum::<nalgebra::Vector3<f64>>()
            / n;
        let w = v
            .iter()
            .map(|s| s.dtheta / s.dt)
            .sum::<nalgebra::Vector3<f64>>()
            / n;
        assert!(f.z < -9.0 && f.x.abs() < 1.0 && f.y.abs() < 1.0, "{f:?}");
        assert!((f.norm() - 9.81).abs() < 0.3, "{}", f.norm());
        assert!(w.norm() < 1f64.to_radians(), "{w:?}");
    }
    // Tied to GPS time: the IMU's times fall near the NAV-PVT epochs'.
    if let Some(f) = r.fixes().first() {
        assert!((raw[0].t - f.t).abs() < 3.0, "{} vs {}", raw[0].t, f.t);
    }
    assert!(matches!(r.scale, TimeScale::GpsSecondsOfWeek { .. }));
    for v in [&raw, &meas] {
        assert!(v.windows(2).all(|w| w[1].t > w[0].t));
    }
}

#[test]
fn fusion_attitude_and_a_truncated_tail() {
    let r = read(F9_TRUNC);
    let t = r
        .report
        .truncated_tail
        .clone()
        .expect("the file ends inside a frame");
    assert_eq!(t.offset + t.have as u64, 160_000);
    assert!(t.have < t.need);
    println!("truncated tail: {t:?}");
    let refs: Vec<&ReferenceSample> = r
        .items
        .iter()
        .filter_map(|i| match &i.record {
            LogRecord::Reference(x) => Some(x),
            _ => None,
        })
        .collect();
    assert_eq!(refs.len() as u64, r.count("NAV-ATT"));
    // The first NAV-ATT as pyubx2 prints it: iTOW 21:38:32 UTC of 2019-11-26 (GPS
    // second 250 730 of week 2081, 18 leap seconds), roll 0.0, pitch −2.73287°,
    // heading 158.3933°.
    let a = refs[0].att.unwrap();
    assert_eq!(a.roll, 0.0);
    assert!((a.pitch.to_degrees() + 2.732_87).abs() < 1e-9);
    assert!((a.yaw.to_degrees() - 158.3933).abs() < 1e-9);
    assert_eq!(refs[0].t, 250_730.0);
    // Merged with the same epoch's NAV-PVT position.
    assert!(refs.iter().any(|x| x.pos.is_some()));
    for x in refs.iter().filter_map(|x| x.pos) {
        assert!((x.lat.to_degrees() - 37.394_8).abs() < 1e-3);
    }
    assert!(!r.imu("ESF-RAW").is_empty());
}

/// The offset of the `n`-th frame of `class`, `id` in `b` (a sync-word search; the
/// committed logs hold no false sync word before the frames used).
fn nth_frame(b: &[u8], class: u8, id: u8, n: usize) -> usize {
    b.windows(4)
        .enumerate()
        .filter(|(_, w)| *w == [0xB5, 0x62, class, id])
        .nth(n)
        .expect("frame")
        .0
}

fn fletcher(bytes: &[u8]) -> [u8; 2] {
    let (mut a, mut b) = (0u8, 0u8);
    for &x in bytes {
        a = a.wrapping_add(x);
        b = b.wrapping_add(a);
    }
    [a, b]
}

#[test]
fn garbled_frames_are_refused_with_offset_and_message() {
    let clean = bytes(ROVER);
    let at = nth_frame(&clean, 0x01, 0x07, 10);
    let mut garbled = clean.clone();
    garbled[at + 6 + 30] ^= 0x40;
    let e = from_bytes(garbled.clone(), UbxOptions::default())
        .err()
        .expect("refused");
    assert_eq!(e.field.as_deref(), Some("NAV-PVT"));
    assert!(e.message.contains(&format!("byte offset {at}")), "{e}");
    println!("{e}");
    // With skip_corrupt_frames the frame is counted and the rest read.
    let r = from_bytes(
        garbled,
        UbxOptions {
            skip_corrupt_frames: true,
        },
    )
    .expect("read");
    assert_eq!(r.report.corrupt_frames, 1);
    assert_eq!(r.count("NAV-PVT"), 454);
    // A RAWX whose numMeas disagrees with its length, checksum made valid.
    let at = nth_frame(&clean, 0x02, 0x15, 0);
    let mut bad = clean.clone();
    bad[at + 6 + 11] -= 1;
    let len = usize::from(u16::from_le_bytes([bad[at + 4], bad[at + 5]]));
    let ck = fletcher(&bad[at + 2..at + 6 + len]);
    bad[at + 6 + len..at + 8 + len].copy_from_slice(&ck);
    let e = from_bytes(bad, UbxOptions::default())
        .err()
        .expect("refused");
    assert_eq!(e.field.as_deref(), Some("RXM-RAWX"));
    assert!(e.message.contains(&format!("byte offset {at}")), "{e}");
    // A file that is no UBX log at all.
    let e = from_bytes(b"hello, world\n".repeat(100), UbxOptions::default())
        .err()
        .expect("refused");
    assert!(e.message.contains("no UBX frame"), "{e}");
    // Cut inside a frame: read, the cut reported.
    let cut = clean[..nth_frame(&clean, 0x02, 0x15, 0) + 100].to_vec();
    let r = from_bytes(cut, UbxOptions::default()).expect("read");
    let t = r.report.truncated_tail.expect("reported");
    assert_eq!(t.name.as_deref(), Some("RXM-RAWX"));
    assert_eq!(t.have, 100);
}
