//! `schuler align` and `schuler nav --align` through the binary, on a log the
//! simulator's sensor model makes from the exact increments of a base at rest.

use assert_cmd::Command;
use predicates::prelude::*;
use schuler::earth::{EarthModel, Geodetic, Wgs84};
use schuler::imu::ImuSample;
use schuler::rotation::Euler;
use schuler::sim::imu_model::ImuSimulator;
use schuler::sim::sensor_spec::{ImuSpec, Preset};
use schuler_io::output::write_imu_text;
use std::path::{Path, PathBuf};

const TRUE_ATT: [f64; 3] = [1.0, -0.5, 60.0];

/// A navigation-grade log at rest at 100 Hz, `seconds` long, starting at t = 1000 s.
fn log_at_rest(dir: &Path, lat_deg: f64, seconds: f64) -> PathBuf {
    let pos = Geodetic::from_degrees(lat_deg, 10.0, 100.0);
    let c_nb = Euler::from_degrees(TRUE_ATT[0], TRUE_ATT[1], TRUE_ATT[2])
        .to_dcm()
        .transpose();
    let w_b = c_nb * Wgs84.w_ie_n(pos.lat);
    let f_b = -(c_nb * Wgs84.gravity_n(pos.lat, pos.h));
    let spec = ImuSpec {
        rate_hz: 100.0,
        preset: Some(Preset::Navigation),
        gyro: Default::default(),
        accel: Default::default(),
        g_sensitivity: None,
        vibration: Vec::new(),
    };
    let mut sim = ImuSimulator::new(spec.model().expect("preset"), 5);
    let dt = 0.01;
    let samples = (1..=(seconds * 100.0) as usize).map(|k| {
        sim.measure(&ImuSample::from_mean_rates(
            1000.0 + k as f64 * dt,
            dt,
            w_b,
            f_b,
        ))
    });
    let path = dir.join("imu.txt");
    write_imu_text(&path, samples, 17).expect("write log");
    path
}

fn schuler() -> Command {
    Command::cargo_bin("schuler").expect("binary")
}

#[test]
fn align_writes_the_json_the_issue_names_and_reaches_the_truth() {
    let dir = tempfile::tempdir().expect("tempdir");
    let imu = log_at_rest(dir.path(), 45.0, 860.0);
    let out = dir.path().join("out");
    schuler()
        .args(["align", "--imu"])
        .arg(&imu)
        .args([
            "--pos",
            "45,10,100",
            "--coarse",
            "190s",
            "--fine",
            "670 s",
            "--out",
        ])
        .arg(&out)
        .assert()
        .success()
        .stdout(predicate::str::contains("coarse |").and(predicate::str::contains("fine   |")))
        .stdout(predicate::str::contains("not observable at rest"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("align.json")).expect("json"))
            .expect("parse");
    for key in [
        "roll_deg",
        "pitch_deg",
        "yaw_deg",
        "roll_std_deg",
        "pitch_std_deg",
        "yaw_std_deg",
        "t_end",
    ] {
        assert!(json[key].is_f64(), "{key}: {}", json[key]);
    }
    for key in ["gyro_bias_dph", "accel_bias_mgal"] {
        assert_eq!(json[key].as_array().map(Vec::len), Some(3), "{key}");
    }
    assert!((json["t_end"].as_f64().expect("t_end") - 1860.0).abs() < 1e-6);
    // Within 4 reported sigma of the truth (a single run; the Monte-Carlo test in the
    // library checks the sigmas themselves).
    for (i, name) in ["roll", "pitch", "yaw"].into_iter().enumerate() {
        let v = json[format!("{name}_deg")].as_f64().expect("angle");
        let s = json[format!("{name}_std_deg")].as_f64().expect("std");
        let err = (v - TRUE_ATT[i] + 180.0).rem_euclid(360.0) - 180.0;
        assert!(err.abs() < 4.0 * s, "{name}: {v} vs {} ± {s}", TRUE_ATT[i]);
    }
    assert!(out.join("align_convergence.csv").is_file());
    let svg = std::fs::read_to_string(out.join("align_convergence.svg")).expect("svg");
    assert!(svg.contains("t since start [s]") && svg.contains("arcsec"));
}

#[test]
fn nav_aligns_first_and_starts_navigating_at_the_end_of_alignment() {
    let dir = tempfile::tempdir().expect("tempdir");
    let imu = log_at_rest(dir.path(), 45.0, 960.0);
    let out = dir.path().join("nav");
    schuler()
        .args(["nav", "--align", "--imu"])
        .arg(&imu)
        .args(["--init-pos", "45,10,100", "--output-rate", "1", "--out"])
        .arg(&out)
        .assert()
        .success();
    let nav = std::fs::read_to_string(out.join("nav.txt")).expect("nav.txt");
    let first: Vec<f64> = nav
        .lines()
        .next()
        .expect("a line")
        .split_whitespace()
        .map(|x| x.parse().expect("number"))
        .collect();
    assert!((first[1] - 1860.0).abs() < 1e-6, "starts at {}", first[1]);
    assert!(out.join("align.json").is_file());
    // 100 s at rest after a fine alignment: metres at most (Schuler-limited drift).
    let last: Vec<f64> = nav
        .lines()
        .last()
        .expect("a line")
        .split_whitespace()
        .map(|x| x.parse().expect("number"))
        .collect();
    let dn = (last[2] - 45.0).to_radians() * 6.37e6;
    assert!(dn.abs() < 5.0, "north drift {dn} m");
}

#[test]
fn polar_gyrocompassing_is_refused_and_bad_options_name_the_flag() {
    let dir = tempfile::tempdir().expect("tempdir");
    let imu = log_at_rest(dir.path(), 89.8, 300.0);
    schuler()
        .args(["align", "--imu"])
        .arg(&imu)
        .args(["--pos", "89.8,10,100", "--coarse", "100s", "--fine", "200s"])
        .assert()
        .failure()
        .stderr(
            predicate::str::contains("cannot find north")
                .and(predicate::str::contains("--heading")),
        );
    schuler()
        .args(["align", "--imu"])
        .arg(&imu)
        .args([
            "--pos",
            "89.8,10,100",
            "--coarse",
            "100s",
            "--fine",
            "200s",
            "--heading",
            "60,0.5",
        ])
        .assert()
        .success();
    for (flag, value, needle) in [
        ("--coarse", "-5s", "--coarse"),
        ("--fine", "5 m/s", "--fine"),
        ("--heading", "north", "--heading"),
        ("--max-heading-std", "0", "--max-heading-std"),
    ] {
        schuler()
            .args(["align", "--imu"])
            .arg(&imu)
            .args(["--pos", "45,10,100", flag, value])
            .assert()
            .failure()
            .stderr(
                predicate::str::contains(needle).and(predicate::str::contains("panicked").not()),
            );
    }
    schuler()
        .args(["align", "--imu"])
        .arg(&imu)
        .args(["--pos", "45,10,100"])
        .assert()
        .failure()
        .stderr(predicate::str::contains("the alignment stages need").and(
            predicate::str::contains("shorten the stages with --coarse and --fine"),
        ));
}
