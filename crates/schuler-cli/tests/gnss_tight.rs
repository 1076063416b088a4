//! `schuler nav --gnss-obs OBS --gnss-nav NAV` (tight coupling, issue 31) on station
//! 0759 of GEONET (RTKLIB's test data, 2005-04-02 00:00–01:00 GPST, 30-s epochs):
//! the station's real pseudoranges with a simulated tactical IMU at rest at the
//! station (`schuler simulate`, a hold), started at the header's position.
//!
//! Reference and bounds as `gnss_cli.rs` (single-point positions of the same file):
//! the header's `APPROX POSITION XYZ`, itself a metre-level receiver solution;
//! horizontal RMS < 5 m, vertical RMS < 10 m. The filter sees the same measurements
//! with the same model and weights, so it is held to the same bounds, after its first
//! ten minutes (the clock and the errors settling from a 1-m prior).

use assert_cmd::Command;
use schuler::earth::{EarthModel, Wgs84, c_ne};
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

#[test]
fn gsi_0759_tightly_coupled_at_rest() {
    let dir = tempfile::tempdir().expect("tempdir");
    let r0 = nalgebra::Vector3::from(REFERENCE_ECEF);
    let p0 = Wgs84.ecef_to_geodetic(&r0);
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
    let assert = Command::cargo_bin("schuler")
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
    let stdout = String::from_utf8_lossy(&assert.get_output().stdout).to_string();
    println!("{stdout}");
    let (_, records) = read_nav(&out.join("nav.txt")).expect("nav.txt reads back");
    let c_en = c_ne(p0.lat, p0.lon).transpose();
    let (mut h2, mut v2, mut n) = (0.0, 0.0, 0usize);
    for r in records.iter().filter(|r| r.t_sow >= SOW0 + 600.0) {
        let d = c_en * (Wgs84.geodetic_to_ecef(&r.pos) - r0);
        h2 += d.x * d.x + d.y * d.y;
        v2 += d.z * d.z;
        n += 1;
    }
    assert!(n > 2900, "{n} epochs after the first ten minutes");
    let (h_rms, v_rms) = ((h2 / n as f64).sqrt(), (v2 / n as f64).sqrt());
    println!("tightly coupled 0759: horizontal RMS {h_rms:.2} m, vertical {v_rms:.2} m");
    assert!(h_rms < 5.0, "horizontal RMS {h_rms} m");
    assert!(v_rms < 10.0, "vertical RMS {v_rms} m");
    // The refused measurements carry their satellite.
    let rejected = std::fs::read_to_string(out.join("rejected.csv")).unwrap_or_default();
    for line in rejected.lines().skip(1) {
        assert!(
            line.contains("pseudorange") || line.contains("range_rate"),
            "{line}"
        );
    }
}
