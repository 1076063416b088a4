//! `schuler allan` end to end: a static log simulated by `schuler simulate` (2 h at
//! 100 Hz, white noise and Gauss–Markov biases set per triad) gives back the simulated
//! terms within the printed intervals, and its `imu_noise.toml` runs `schuler nav
//! --config` and changes its filter; short and moving logs are named in the error or
//! the warning; the log in a device's layout, read with the layout flags, gives the
//! same table.

use crate::common;
use assert_cmd::Command;
use predicates::prelude::*;
use std::path::{Path, PathBuf};

/// The simulated terms, in the units `schuler allan` prints them in.
const ARW_DEG_SQRT_H: f64 = 0.05;
const GYRO_GM_DEG_H: f64 = 1.0;
const GYRO_T_S: f64 = 100.0;
const VRW_M_S_SQRT_H: f64 = 0.02;
const ACCEL_GM_UG: f64 = 20.0;
const ACCEL_T_S: f64 = 60.0;

fn scenario() -> String {
    format!(
        r#"seed = 11
earth = "wgs84"

[start]
time = 0.0
position = ["45 deg", "7 deg", "100 m"]
attitude = ["0 deg", "0 deg", "30 deg"]

[[motion]]
type = "hold"
duration = "2 h"

[imu]
rate_hz = 100

[imu.gyro]
random_walk = "{ARW_DEG_SQRT_H} deg/sqrt(h)"
instability = "{GYRO_GM_DEG_H} deg/h"
correlation_time = "{GYRO_T_S} s"
turn_on = "2 deg/h"

[imu.accel]
random_walk = "{VRW_M_S_SQRT_H} m/s/sqrt(h)"
instability = "{ACCEL_GM_UG} ug"
correlation_time = "{ACCEL_T_S} s"
turn_on = "100 ug"

[gnss]
rate_hz = 1
position_std = ["0.5 m", "0.5 m", "1 m"]
"#
    )
}

fn schuler() -> Command {
    Command::cargo_bin("schuler").expect("binary")
}

/// `schuler simulate` of [`scenario`] into `dir/sim`.
fn simulate(dir: &Path) -> PathBuf {
    let config = dir.join("static.toml");
    std::fs::write(&config, scenario()).expect("write scenario");
    common::simulate(&config, dir)
}

/// A printed cell `v [lo, hi]` of `row`'s `k`-th term (after the axis name).
fn term(row: &str, k: usize) -> (f64, f64, f64) {
    let cleaned = row.replace(['[', ']', ','], " ");
    let nums: Vec<f64> = cleaned
        .split_whitespace()
        .skip(1)
        .map(|x| x.parse().expect("number"))
        .collect();
    (nums[3 * k], nums[3 * k + 1], nums[3 * k + 2])
}

/// The rows of the table under the line starting with `title`, then of the triad
/// whose header starts with `triad`: the three axes'.
fn rows<'a>(out: &'a str, title: &str, triad: &str) -> Vec<&'a str> {
    let lines: Vec<&str> = out.lines().collect();
    let start = lines
        .iter()
        .position(|l| l.starts_with(title))
        .expect("table title");
    let header = start
        + lines[start..]
            .iter()
            .position(|l| l.trim_start().starts_with(triad))
            .expect("triad header");
    lines[header + 1..header + 4].to_vec()
}

/// Checks `truth` against a printed `(v, lo, hi)`: inside the 95 % interval widened to
/// 99.7 % (by 3/1.96 on its side), so that the 18 checks pass together for any seed
/// with a calibrated interval; prints whether it is inside the 95 % one too.
fn check(what: &str, (v, lo, hi): (f64, f64, f64), truth: f64) {
    let inside = truth >= lo && truth <= hi;
    println!("{what}: {v} [{lo}, {hi}], truth {truth}, inside: {inside}");
    let widen = 3.0 / 1.96;
    assert!(
        truth >= v - widen * (v - lo) && truth <= v + widen * (hi - v),
        "{what}: {v} [{lo}, {hi}] vs {truth}"
    );
}

#[test]
fn fits_the_simulated_noise_and_feeds_nav() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = simulate(dir.path());
    let out_dir = dir.path().join("allan");
    let assert = schuler()
        .arg("allan")
        .arg(sim.join("imu.txt"))
        .arg("--out")
        .arg(&out_dir)
        .assert()
        .success();
    let out = String::from_utf8_lossy(&assert.get_output().stdout).into_owned();
    let stderr = String::from_utf8_lossy(&assert.get_output().stderr).into_owned();
    println!("{out}");
    assert!(!stderr.contains("warning"), "{stderr}");
    let filter = "Filter model";
    for (triad, n, s, t) in [
        ("gyro", ARW_DEG_SQRT_H, GYRO_GM_DEG_H, GYRO_T_S),
        ("accelerometer", VRW_M_S_SQRT_H, ACCEL_GM_UG, ACCEL_T_S),
    ] {
        for (axis, row) in rows(&out, filter, triad).iter().enumerate() {
            check(&format!("{triad} {axis} N"), term(row, 0), n);
            check(
                &format!("{triad} {axis} Gauss-Markov sigma"),
                term(row, 1),
                s,
            );
            check(&format!("{triad} {axis} T"), term(row, 2), t);
        }
    }
    // The IEEE fit's white noise too (the Gauss-Markov bias, outside its model, sits
    // where the white noise no longer dominates).
    for (triad, n) in [("gyro", ARW_DEG_SQRT_H), ("accelerometer", VRW_M_S_SQRT_H)] {
        for (axis, row) in rows(&out, "IEEE Std 952", triad).iter().enumerate() {
            check(&format!("{triad} {axis} IEEE N"), term(row, 0), n);
        }
    }
    for f in ["allan.csv", "allan.svg", "imu_noise.toml"] {
        assert!(out_dir.join(f).is_file(), "{f}");
    }
    let csv = std::fs::read_to_string(out_dir.join("allan.csv")).expect("csv");
    assert!(csv.starts_with("tau_s,m,gyro_x_rad_s,gyro_x_lo_rad_s,gyro_x_hi_rad_s"));
    // round(10^(k/10)) up to a tenth of 7200 s at 100 Hz: 1, 2, 3, 4, 5, 6, 8, 10 in
    // the first decade (repeats merged), ten a decade after, to m = 63096 (631 s).
    assert_eq!(csv.lines().count(), 1 + 46, "header and 46 cluster times");
    let noise = std::fs::read_to_string(out_dir.join("imu_noise.toml")).expect("toml");
    println!("{noise}");
    let table: toml::Table = toml::from_str(&noise).expect("TOML");
    let aiding = table["aiding"].as_table().expect("[aiding]");
    for key in [
        "arw",
        "vrw",
        "gyro_bias_instability",
        "accel_bias_instability",
        "bias_corr_time",
    ] {
        assert!(aiding.contains_key(key), "{key} in {noise}");
    }
    nav_reads_the_noise_file(dir.path(), &sim, &out_dir.join("imu_noise.toml"));
    device_layout_reads_alike(dir.path(), &sim.join("imu.txt"), &csv);
}

/// The same log as a device writes it (integer millisecond stamps, semicolons,
/// specific force in g before angular rate in deg/s), read with the IMU layout flags,
/// gives the same Allan table as the KF-GINS-format file. The unit round trips cost a
/// few ulp; the intervals from millisecond stamps differ from the decimal seconds' by
/// up to an ulp of t (1e-12 s of 0.01 s), and gravity's share of each velocity
/// increment moves by that fraction: seen up to 1e-10 of a deviation, bound 1e-9.
fn device_layout_reads_alike(dir: &Path, imu: &Path, canonical: &str) {
    let text = std::fs::read_to_string(imu).expect("imu.txt");
    let mut device = String::from("# time [ms]; f [g]; w [deg/s]\n");
    let mut t_prev = None;
    for line in text.lines() {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|f| f.parse().expect("number"))
            .collect();
        let dt = t_prev.map_or(0.01, |p| v[0] - p);
        t_prev = Some(v[0]);
        let ms = (v[0] * 1000.0).round() as i64;
        let g = schuler::units::G0;
        let d = std::f64::consts::PI / 180.0;
        let (f, w) = (
            [v[4], v[5], v[6]].map(|x| x / dt / g),
            [v[1], v[2], v[3]].map(|x| x / dt / d),
        );
        device.push_str(&format!(
            "{ms};{:e};{:e};{:e};{:e};{:e};{:e}\n",
            f[0], f[1], f[2], w[0], w[1], w[2]
        ));
    }
    let file = dir.join("device.csv");
    std::fs::write(&file, device).expect("write");
    let out = dir.join("allan-device");
    schuler()
        .arg("allan")
        .arg(&file)
        .args([
            "--imu-columns",
            "t,fx,fy,fz,wx,wy,wz",
            "--gyro-unit",
            "deg/s",
        ])
        .args(["--accel-unit", "g", "--imu-time-unit", "ms", "--out"])
        .arg(&out)
        .assert()
        .success();
    let csv = std::fs::read_to_string(out.join("allan.csv")).expect("csv");
    assert_eq!(csv.lines().count(), canonical.lines().count());
    for (a, b) in csv.lines().zip(canonical.lines()).skip(1) {
        for (x, y) in a.split(',').zip(b.split(',')) {
            let (x, y): (f64, f64) = (x.parse().expect("x"), y.parse().expect("y"));
            assert!((x - y).abs() <= 1e-9 * y.abs(), "{a}\n{b}");
        }
    }
}

/// `schuler nav` reads the fitted noise file: it runs, and its filter differs from the
/// grade default's.
fn nav_reads_the_noise_file(dir: &Path, sim: &Path, noise_file: &Path) {
    let nav = |name: &str, config: Option<&Path>| {
        let out = dir.join(name);
        let mut cmd = schuler();
        cmd.arg("nav");
        if let Some(c) = config {
            cmd.arg("--config").arg(c);
        }
        cmd.arg("--imu")
            .arg(sim.join("imu.txt"))
            .arg("--gnss")
            .arg(sim.join("gnss.txt"))
            .args([
                "--init-pos",
                "45,7,100",
                "--init-att",
                "0,0,30",
                "--end",
                "300",
                "--no-report",
                "--out",
            ])
            .arg(&out)
            .assert()
            .success();
        std::fs::read_to_string(out.join("std.txt")).expect("std.txt")
    };
    let with = nav("nav_allan", Some(noise_file));
    let without = nav("nav_grade", None);
    assert_ne!(with, without, "the noise keys change the filter");
}

/// A short log is refused naming the file; a log that turns is warned about.
#[test]
fn short_and_moving_logs_are_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    let line = |k: usize, wz: f64| {
        let dt = 0.01;
        format!(
            "{} {} {} {} {} {} {}\n",
            k as f64 * dt,
            1e-7 * ((k * 7919) % 13) as f64,
            -1e-7 * ((k * 104_729) % 11) as f64,
            wz * dt,
            1e-5 * ((k * 31) % 7) as f64,
            0.0,
            -9.8 * dt
        )
    };
    let allan = |file: &Path, extra: &[&str]| {
        schuler()
            .arg("allan")
            .arg(file)
            .args(extra)
            .arg("--out")
            .arg(dir.path())
            .assert()
    };
    let says = |a: &str, b: &str| predicate::str::contains(a).and(predicate::str::contains(b));
    let short = dir.path().join("short.txt");
    std::fs::write(&short, (1..=500).map(|k| line(k, 0.0)).collect::<String>()).expect("write");
    allan(&short, &[])
        .failure()
        .stderr(says("short.txt", "too few to tell the noise terms apart"));
    // 200 s with a turn at 5 deg/s for 2 s.
    let moving = dir.path().join("moving.txt");
    let text: String = (1..=20_000)
        .map(|k| {
            line(
                k,
                if (9000..9200).contains(&k) {
                    0.0873
                } else {
                    0.0
                },
            )
        })
        .collect();
    std::fs::write(&moving, text).expect("write");
    allan(&moving, &["--max-tau", "1 min"])
        .failure()
        .stderr(says(
            "moving.txt",
            "too short for a longest cluster time of 60.0 s",
        ));
    allan(&moving, &[]).success().stderr(says(
        "warning: ",
        "moving.txt: motion in 1 of the 10-s blocks",
    ));
}
