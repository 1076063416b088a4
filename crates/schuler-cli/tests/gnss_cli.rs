//! `schuler gnss` on station 0759 of GEONET (RTKLIB's test data: RINEX 2.10
//! observations and GPS broadcast ephemerides of 2005-04-02, 00:00–01:00 GPST).
//!
//! Reference: the RINEX header's `APPROX POSITION XYZ` (no independent coordinate of
//! 0759 was found in RTKLIB's test directory; GSI's F3 solution was not at hand). teqc
//! writes it from the receiver's own navigation solution, so it is itself a metre-level
//! value: the bounds below are loose, for single-frequency SPP with broadcast orbits
//! and clocks (SA off since 2000; broadcast orbit and clock ≈ 1–2 m URE), Klobuchar
//! (removes about half the ionosphere: metres left near solar-cycle decline, 2005) and
//! C/A code noise of a geodetic receiver (< 1 m). Horizontal RMS < 5 m; vertical RMS
//! < 10 m (the vertical DOP is about twice the horizontal and the residual ionosphere
//! and troposphere go mostly into height).

use assert_cmd::Command;
use schuler::analysis::errors::NavRecord;
use schuler::earth::{EarthModel, Wgs84, c_ne};
use schuler_io::formats::gnss::{GnssReadOptions, read_gnss_log};
use schuler_io::formats::nav::read_nav;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/rinex_obs")
        .join(name)
}

/// The header's APPROX POSITION XYZ of 0759.
const REFERENCE_ECEF: [f64; 3] = [-3976219.5082, 3382372.5671, 3652512.9849];
/// 2005-04-02 00:00 GPST, a Saturday: second 6·86 400 of the GPS week.
const SOW0: f64 = 518_400.0;

/// Horizontal and vertical RMS [m] of positions about [`REFERENCE_ECEF`].
fn rms_from_reference<'a>(records: impl Iterator<Item = &'a NavRecord>) -> (f64, f64) {
    let r0 = nalgebra::Vector3::from(REFERENCE_ECEF);
    let p0 = Wgs84.ecef_to_geodetic(&r0);
    let c_en = c_ne(p0.lat, p0.lon).transpose();
    let (mut h2, mut v2, mut n) = (0.0, 0.0, 0usize);
    for r in records {
        let d = c_en * (Wgs84.geodetic_to_ecef(&r.pos) - r0);
        h2 += d.x * d.x + d.y * d.y;
        v2 += d.z * d.z;
        n += 1;
    }
    assert!(n > 0, "no positions");
    ((h2 / n as f64).sqrt(), (v2 / n as f64).sqrt())
}

#[test]
fn gsi_0759_single_point_positions() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let assert = Command::cargo_bin("schuler")
        .expect("binary")
        .args(["gnss", "--gnss-obs"])
        .arg(data("07590920.05o.gz"))
        .arg("--gnss-nav")
        .arg(data("07590920.05n.gz"))
        .arg("--out")
        .arg(&out)
        .args(["--elevation-mask", "10"])
        .assert()
        .success();
    let stdout = String::from_utf8_lossy(&assert.get_output().stdout).to_string();
    assert!(stdout.contains("120 epochs"), "{stdout}");

    let (_, records) = read_nav(&out.join("nav.txt")).expect("nav.txt reads back");
    // 120 epochs of 7 to 9 satellites: every one should solve.
    assert!(records.len() >= 114, "{} of 120 solved", records.len());
    let (_, csv) = read_nav(&out.join("nav.csv")).expect("nav.csv reads back");
    assert_eq!(csv.len(), records.len());

    let (h_rms, v_rms) = rms_from_reference(records.iter());
    eprintln!("0759: horizontal RMS {h_rms:.2} m, vertical RMS {v_rms:.2} m");
    assert!(h_rms < 5.0, "horizontal RMS {h_rms} m");
    assert!(v_rms < 10.0, "vertical RMS {v_rms} m");

    let log = read_gnss_log(&out.join("solution.pos"), &GnssReadOptions::default())
        .expect("solution.pos reads back");
    assert_eq!(log.fixes.len(), records.len());
    for (f, r) in log.fixes.iter().zip(&records) {
        assert!((f.t - r.t_sow).abs() < 1e-3, "{} vs {}", f.t, r.t_sow);
        let d = Wgs84.geodetic_to_ecef(&f.pos) - Wgs84.geodetic_to_ecef(&r.pos);
        assert!(d.norm() < 1e-3, "pos differs by {} m", d.norm());
        assert!(f.pos_std.iter().all(|s| *s > 0.0 && *s < 50.0));
    }

    let sats = std::fs::read_to_string(out.join("satellites.csv")).expect("satellites.csv");
    let used = sats.lines().filter(|l| l.contains(",used,")).count();
    assert!(used >= 5 * records.len(), "{used} satellite rows used");
}

/// `schuler nav --gnss-obs OBS --gnss-nav NAV` (tight coupling) on the same file: the
/// station's real pseudoranges (RINEX 2.10, no Doppler) with a simulated tactical IMU
/// at rest at the station (`schuler simulate`, a hold), started at the reference.
/// The filter sees the same measurements with the same model and weights as the
/// single-point solution above, so it is held to the same bounds (H < 5 m, V < 10 m)
/// after its first ten minutes (the clock and the errors settling).
#[test]
fn gsi_0759_tightly_coupled_at_rest() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p0 = Wgs84.ecef_to_geodetic(&nalgebra::Vector3::from(REFERENCE_ECEF));
    let (lat, lon, h) = (p0.lat.to_degrees(), p0.lon.to_degrees(), p0.h);
    let scenario = format!(
        "seed = 3\nearth = \"wgs84\"\n\n[start]\ntime = {}\nposition = [\"{lat:.9} deg\", \
         \"{lon:.9} deg\", \"{h:.3} m\"]\nattitude = [\"0 deg\", \"0 deg\", \"0 deg\"]\n\n\
         [[motion]]\ntype = \"hold\"\nduration = \"3630 s\"\n\n[imu]\npreset = \"tactical\"\n\
         rate_hz = 100\n",
        SOW0 - 10.0
    );
    let sc = dir.path().join("rest.toml");
    std::fs::write(&sc, scenario).expect("scenario");
    let sim = dir.path().join("sim");
    Command::cargo_bin("schuler")
        .expect("binary")
        .args(["simulate", "--config"])
        .arg(&sc)
        .arg("--out")
        .arg(&sim)
        .assert()
        .success();
    let out = dir.path().join("nav");
    Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--imu"])
        .arg(sim.join("imu.txt"))
        .arg("--init-pos")
        .arg(format!("{lat:.9},{lon:.9},{h:.3}"))
        .args(["--init-att", "0,0,0", "--output-rate", "1", "--gnss-obs"])
        .arg(data("07590920.05o.gz"))
        .arg("--gnss-nav")
        .arg(data("07590920.05n.gz"))
        .args(["--elevation-mask", "10", "--out"])
        .arg(&out)
        .assert()
        .success();
    let (_, records) = read_nav(&out.join("nav.txt")).expect("nav.txt reads back");
    let settled: Vec<_> = records.iter().filter(|r| r.t_sow >= SOW0 + 600.0).collect();
    assert!(
        settled.len() > 2900,
        "{} epochs after the first ten minutes",
        settled.len()
    );
    let (h_rms, v_rms) = rms_from_reference(settled.into_iter());
    eprintln!("0759 tightly coupled: horizontal RMS {h_rms:.2} m, vertical RMS {v_rms:.2} m");
    assert!(h_rms < 5.0, "horizontal RMS {h_rms} m");
    assert!(v_rms < 10.0, "vertical RMS {v_rms} m");
    // Whatever the gate refused is a single satellite's measurement.
    let rejected = std::fs::read_to_string(out.join("rejected.csv")).unwrap_or_default();
    for line in rejected.lines().skip(1) {
        assert!(line.contains("pseudorange G"), "{line}");
    }
}
