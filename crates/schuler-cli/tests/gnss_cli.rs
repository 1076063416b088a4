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

    let r0 = nalgebra::Vector3::from(REFERENCE_ECEF);
    let p0 = Wgs84.ecef_to_geodetic(&r0);
    let c_en = c_ne(p0.lat, p0.lon).transpose();
    let (mut h2, mut v2) = (0.0, 0.0);
    for r in &records {
        let d = c_en * (Wgs84.geodetic_to_ecef(&r.pos) - r0);
        h2 += d.x * d.x + d.y * d.y;
        v2 += d.z * d.z;
    }
    let n = records.len() as f64;
    let (h_rms, v_rms) = ((h2 / n).sqrt(), (v2 / n).sqrt());
    eprintln!("0759: horizontal RMS {h_rms:.2} m, vertical RMS {v_rms:.2} m over {n} epochs");
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
