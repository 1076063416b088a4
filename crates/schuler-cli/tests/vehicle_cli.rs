//! `schuler nav` with vehicle aiding, end to end, on `schuler simulate`'s output for the
//! example drive (examples/drive.toml: a tactical IMU at 200 Hz in a car that waits
//! 60 s, then drives 20 m/s with turns and a climb; GNSS at 1 Hz with a 60-s outage
//! from 400 s). The odometer, rest and dual-antenna logs are made here from the
//! simulator's truth.nav with seeded noise (schuler::sim::vehicle); the errors come
//! from `schuler compare` against truth.nav.

use crate::common;
use schuler::earth::Geodetic;
use schuler::filter::Baseline;
use schuler::nav::NavState;
use schuler::rotation::Euler;
use schuler::sim::vehicle::{HeadingSimulator, OdometerModel, OdometerSimulator, rest_intervals};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The simulated drive and its vehicle logs, made once: `drive/` holds `imu.txt`,
/// `gnss.txt`, `baro.csv`, `truth.nav`, `odometer.txt` (10 Hz, 0.3 % scale error,
/// 0.05 m/s noise), `rest.txt` (the wait) and `heading.txt` (1 Hz, 0.1°, baseline 90°
/// to the right).
fn drive() -> &'static Path {
    static DIR: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    &DIR.get_or_init(|| {
        let dir = tempfile::tempdir().expect("tempdir");
        // Named as examples/drive_nav.toml expects its files.
        let sim = dir.path().join("drive");
        std::fs::rename(common::simulate_drive(dir.path()), &sim).expect("rename");
        let truth: Vec<NavState> = common::read_rows(&sim.join("truth.nav"))
            .iter()
            .map(|r| {
                NavState::new(
                    r[1],
                    Geodetic::from_degrees(r[2], r[3], r[4]),
                    nalgebra::Vector3::new(r[5], r[6], r[7]),
                    Euler::from_degrees(r[8], r[9], r[10]),
                )
            })
            .collect();
        let mut odo = OdometerSimulator::new(
            OdometerModel {
                scale: 0.003,
                noise: 0.05,
            },
            1,
        );
        let mut heading = HeadingSimulator::new(BASELINE, 0.1f64.to_radians(), None, 1);
        let (mut odometer, mut headings) = (String::from("t,speed\n"), String::new());
        for (i, s) in truth.iter().enumerate() {
            if i % 20 == 0 {
                let speed = (s.q_bn.inverse() * s.v_n).x;
                writeln!(odometer, "{},{}", s.t, odo.reading(speed)).expect("string");
            }
            if i % 200 == 0
                && let Some(r) = heading.reading(s)
            {
                writeln!(
                    headings,
                    "{} {} {}",
                    r.t,
                    r.heading.to_degrees(),
                    r.heading_std.to_degrees()
                )
                .expect("string");
            }
        }
        let rests: String = rest_intervals(&truth, 1e-9, 1.0)
            .iter()
            .map(|(a, b)| format!("{a} {b}\n"))
            .collect();
        assert_eq!(rests.lines().count(), 1, "{rests}");
        for (name, text) in [
            ("odometer.txt", odometer),
            ("heading.txt", headings),
            ("rest.txt", rests),
        ] {
            std::fs::write(sim.join(name), text).expect("write");
        }
        (dir, sim)
    })
    .1
}

const BASELINE: Baseline = Baseline {
    yaw: std::f64::consts::FRAC_PI_2,
    pitch: 0.0,
};

/// `schuler nav` on the drive into `out` with `extra` flags; its stdout.
fn nav(out: &Path, extra: &[&str]) -> String {
    let d = drive();
    let o = assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--imu"])
        .arg(d.join("imu.txt"))
        .arg("--gnss")
        .arg(d.join("gnss.txt"))
        .args(["--init-pos", "45.07,7.68,245", "--init-att", "0,0,10"])
        .args(["--lever-arm", "0.5,0,-1", "--imu-grade", "tactical"])
        .args(["--output-rate", "10", "--out"])
        .arg(out)
        .args(extra)
        .current_dir(d)
        .assert()
        .success();
    String::from_utf8_lossy(&o.get_output().stdout).into_owned()
}

/// `schuler compare`'s statistics of `out/nav.txt` against the truth, the drive's
/// outage given: (max horizontal error in the outage [m], yaw RMS [deg]).
fn errors(out: &Path) -> (f64, f64) {
    let cmp = out.join("cmp");
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .arg("compare")
        .arg(out.join("nav.txt"))
        .arg(drive().join("truth.nav"))
        .args(["--outages", "400-460", "--out"])
        .arg(&cmp)
        .assert()
        .success();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(cmp.join("compare.json")).expect("json"))
            .expect("parse");
    let outage = json["outages"][0]["max_horizontal_m"]
        .as_f64()
        .expect("outage");
    let yaw = json["statistics"]["yaw_deg"]["rms"]
        .as_f64()
        .unwrap_or(f64::NAN);
    (outage, yaw)
}

/// A count from the "vehicle updates:" line.
fn count(stdout: &str, what: &str) -> u64 {
    stdout
        .lines()
        .find(|l| l.starts_with("vehicle updates:"))
        .and_then(|l| {
            l.split([':', ','])
                .map(str::trim)
                .find(|p| p.ends_with(what))
                .and_then(|p| p.split(' ').next())
                .and_then(|n| n.parse().ok())
        })
        .unwrap_or(0)
}

#[test]
fn nhc_odometer_and_zupt_shrink_the_outage_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let gnss_only = dir.path().join("gnss");
    nav(&gnss_only, &[]);
    let aided = dir.path().join("vehicle");
    let out = nav(
        &aided,
        &[
            "--nhc",
            "--odometer",
            "odometer.txt",
            "--odometer-scale-std",
            "1 %",
            "--zupt",
            "rest.txt",
            "--zaru",
        ],
    );
    let (a, b) = (errors(&gnss_only).0, errors(&aided).0);
    println!(
        "{out}60-s outage, max horizontal error: GNSS only {a:.2} m, with the car's aids {b:.2} m"
    );
    // The wait is 60 s: a ZUPT (and ZARU) every 0.1 s; NHC every 0.1 s and an odometer
    // reading every 0.1 s over the 1100 s of data after the first sample.
    assert!((595..=601).contains(&count(&out, "zero-velocity")), "{out}");
    assert!((595..=601).contains(&count(&out, "zero-rate")), "{out}");
    assert!(
        count(&out, "NHC") > 10_000 && count(&out, "odometer") > 10_000,
        "{out}"
    );
    // A tactical IMU drifts a few metres in 60 s; held to its heading error (~0.02°)
    // times the 1200 m driven, and the odometer's residual scale, it stays well
    // under a metre.
    assert!(b * 3.0 < a && b < 1.0, "{b} vs {a}");
    // The odometer reading at t = 0 precedes the first processed sample.
    let rejected = std::fs::read_to_string(aided.join("rejected.csv")).expect("rejected.csv");
    assert!(
        rejected.contains("0,odometer,before the IMU data"),
        "{rejected}"
    );
}

#[test]
fn detected_rests_and_a_dual_antenna_heading_work_end_to_end() {
    let dir = tempfile::tempdir().expect("tempdir");
    let detect = dir.path().join("detect");
    let out = nav(&detect, &["--zupt-detect"]);
    // The 60-s wait, less the detector's 1-s window; never while driving (the speed
    // guard: constant-speed legs look like rest to the IMU).
    let n = count(&out, "zero-velocity");
    println!("{out}");
    assert!((580..=600).contains(&n), "{n}");
    let rejected = std::fs::read_to_string(detect.join("rejected.csv")).expect("rejected.csv");
    assert!(!rejected.contains("zupt"), "{rejected}");
    let heading = dir.path().join("heading");
    let out = nav(
        &heading,
        &[
            "--dual-antenna",
            "heading.txt",
            "--dual-antenna-baseline-yaw",
            "90",
        ],
    );
    let gnss_only = dir.path().join("gnss");
    nav(&gnss_only, &[]);
    let (with, without) = (errors(&heading).1, errors(&gnss_only).1);
    println!("{out}yaw RMS: GNSS only {without:.4}°, with the dual antenna {with:.4}°");
    assert!(count(&out, "heading") >= 1090, "{out}");
    // 0.1° readings every second: the yaw error stays within a few hundredths.
    assert!(with < 0.05, "{with}");
}

/// The documented example config, beside the drive's files, runs as written.
#[test]
fn the_example_config_runs() {
    let d = drive();
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/drive_nav.toml");
    let config = d.parent().expect("parent").join("drive_nav.toml");
    std::fs::copy(&example, &config).expect("copy");
    let o = assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--config"])
        .arg(&config)
        .assert()
        .success();
    let out = String::from_utf8_lossy(&o.get_output().stdout).into_owned();
    println!("{out}");
    for what in ["zero-velocity", "zero-rate", "NHC", "odometer"] {
        assert!(count(&out, what) > 500, "{what}: {out}");
    }
    assert!(d.join("nav/nav.txt").is_file());
}

/// Bad vehicle inputs: an error naming the file, line and field (or the flag), no
/// panic.
#[test]
fn bad_vehicle_inputs_name_file_line_and_field() {
    use predicates::prelude::PredicateBooleanExt as _;
    let dir = tempfile::tempdir().expect("tempdir");
    let file = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).expect("write");
        p.to_str().expect("utf-8").to_owned()
    };
    let odo = file("odo.txt", "t,speed\n1.0,3.0\n1.1,abc\n");
    let rest = file("rest.txt", "0 60\n50 70\n");
    let head = file("head.txt", "1 90 0.1\n2 91 -0.1\n");
    let good_rest = file("good_rest.txt", "0 60\n");
    let good_odo = file("good_odo.txt", "1 3\n");
    let cases: Vec<(Vec<&str>, String)> = vec![
        (vec!["--odometer", &odo], format!("{odo}:3: field speed")),
        (vec!["--zupt", &rest], format!("{rest}:2: field t0")),
        (
            vec!["--dual-antenna", &head],
            format!("{head}:2: field std_heading"),
        ),
        (vec!["--nhc", "--nhc-std", "-0.1 m/s"], "--nhc-std".into()),
        (vec!["--nhc-std", "0.1 m/s"], "--nhc-std needs --nhc".into()),
        (
            vec!["--zupt", &good_rest, "--zupt-std", "0 m/s"],
            "--zupt-std: velocity standard deviation 0 m/s is outside".into(),
        ),
        (
            vec!["--odometer", &good_odo, "--odometer-std", "2 deg"],
            "--odometer-std".into(),
        ),
        (vec!["--mounting-angles", "1,2"], "--mounting-angles".into()),
        (vec!["--zaru"], "--zaru needs".into()),
    ];
    for (extra, needle) in cases {
        assert_cmd::Command::cargo_bin("schuler")
            .expect("binary")
            .args(["nav", "--imu", "missing-imu.txt"])
            .args(["--init-pos", "45,7,100", "--init-att", "0,0,0", "--out"])
            .arg(dir.path().join("out"))
            .args(&extra)
            .assert()
            .failure()
            .stderr(
                predicates::str::contains(needle.as_str())
                    .and(predicates::str::contains("panicked").not()),
            );
    }
}

/// `--estimate-mounting`: the drive's IMU turned in the car by 2° of pitch and 3° of
/// yaw (its increments rotated, `x_b = C_bv x_v`), the filter told nothing: with the
/// NHC and the odometer the printed mounting comes back within the 0.2°.
#[test]
fn the_mounting_is_estimated_from_the_constraints() {
    let d = drive();
    let dir = tempfile::tempdir().expect("tempdir");
    let q_bv = Euler::from_degrees(0.0, 2.0, 3.0).to_quaternion();
    let turned: String = common::read_rows(&d.join("imu.txt"))
        .iter()
        .map(|r| {
            let w = q_bv * nalgebra::Vector3::new(r[1], r[2], r[3]);
            let f = q_bv * nalgebra::Vector3::new(r[4], r[5], r[6]);
            format!(
                "{} {:e} {:e} {:e} {:e} {:e} {:e}\n",
                r[0], w.x, w.y, w.z, f.x, f.y, f.z
            )
        })
        .collect();
    let imu = dir.path().join("imu_turned.txt");
    std::fs::write(&imu, turned).expect("write");
    // The IMU's own attitude at the start: the car's turned by the mounting.
    let start = Euler::from_quaternion(
        &(Euler::from_degrees(0.0, 0.0, 10.0).to_quaternion() * q_bv.inverse()),
    );
    let o = assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--imu"])
        .arg(&imu)
        .arg("--gnss")
        .arg(d.join("gnss.txt"))
        .args(["--init-pos", "45.07,7.68,245", "--init-att"])
        .arg(format!(
            "{},{},{}",
            start.roll.to_degrees(),
            start.pitch.to_degrees(),
            start.yaw.to_degrees()
        ))
        .args([
            "--lever-arm",
            "0.5,0,-1",
            "--imu-grade",
            "tactical",
            "--nhc",
        ])
        .arg("--odometer")
        .arg(d.join("odometer.txt"))
        .args([
            "--estimate-mounting",
            "--no-report",
            "--output-rate",
            "1",
            "--out",
        ])
        .arg(dir.path().join("out"))
        .assert()
        .success();
    let stdout = String::from_utf8_lossy(&o.get_output().stdout).into_owned();
    let line = stdout
        .lines()
        .find(|l| l.starts_with("mounting estimated"))
        .unwrap_or_else(|| panic!("no mounting line: {stdout}"));
    let number = |after: &str| -> f64 {
        let rest = &line[line.find(after).expect("field") + after.len()..];
        rest.split_whitespace()
            .next()
            .expect("value")
            .parse()
            .expect("number")
    };
    let (pitch, yaw) = (number("pitch "), number("yaw "));
    eprintln!("{line}");
    assert!(
        (pitch - 2.0).abs() < 0.2 && (yaw - 3.0).abs() < 0.2,
        "{line}"
    );
}
