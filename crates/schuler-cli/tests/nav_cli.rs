//! `schuler nav` through the binary: bad input names file, line and field and never
//! panics; output rate, time window and TOML configuration behave as documented.

use assert_cmd::Command;
use predicates::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

/// A stationary-looking KF-GINS log at 200 Hz: `n` lines from t = 100.000 s, level
/// and at rest (dvel = -g dt on z), with `edit(line_index, line)` applied.
fn kf_gins_log(n: usize, edit: impl Fn(usize, String) -> String) -> String {
    let mut s = String::new();
    for k in 0..n {
        let t = 100.0 + k as f64 * 0.005;
        let line = format!(
            "{t:.3} 1.2e-7 -3.0e-8 2.9e-7 1.0e-6 -2.0e-6 {:.9e}",
            -9.80 * 0.005
        );
        writeln!(s, "{}", edit(k, line)).expect("string write");
    }
    s
}

fn nav(dir: &Path, imu_text: &str, extra: &[&str]) -> assert_cmd::assert::Assert {
    let imu = dir.join("imu.txt");
    std::fs::write(&imu, imu_text).expect("write log");
    Command::cargo_bin("schuler")
        .expect("binary")
        .arg("nav")
        .arg("--imu")
        .arg(&imu)
        .args(["--init-pos", "45,7,100", "--init-att", "0,0,0", "--out"])
        .arg(dir.join("out"))
        .args(extra)
        .assert()
}

/// Runs `nav` on a log with one defect and checks the error names `imu.txt:LINE` and
/// the field, exits non-zero, and does not panic.
fn rejects(edit: impl Fn(usize, String) -> String, line: usize, field: &str, reason: &str) {
    let dir = tempfile::tempdir().expect("tempdir");
    nav(dir.path(), &kf_gins_log(400, edit), &[])
        .failure()
        .stderr(predicate::str::contains(format!("imu.txt:{line}")))
        .stderr(predicate::str::contains(field))
        .stderr(predicate::str::contains(reason))
        .stderr(predicate::str::contains("panicked").not());
}

#[test]
fn truncated_line_is_an_error() {
    // Line 300 (index 299) loses its last two columns.
    rejects(
        |k, l| {
            if k == 299 {
                l.split(' ').take(5).collect::<Vec<_>>().join(" ")
            } else {
                l
            }
        },
        300,
        "",
        "expected 7 columns, found 5",
    );
}

#[test]
fn non_numeric_field_is_an_error() {
    rejects(
        |k, l| {
            if k == 250 {
                l.replace("-2.0e-6", "abc")
            } else {
                l
            }
        },
        251,
        "field dvel_y",
        "abc",
    );
}

#[test]
fn nan_is_an_error() {
    rejects(
        |k, l| {
            if k == 350 {
                l.replace("2.9e-7", "NaN")
            } else {
                l
            }
        },
        351,
        "field dtheta_z",
        "",
    );
}

#[test]
fn time_going_backwards_is_an_error() {
    rejects(
        |k, l| {
            if k == 320 {
                l.replacen("101.600", "101.000", 1)
            } else {
                l
            }
        },
        321,
        "field t",
        "",
    );
}

#[test]
fn repeated_time_is_an_error() {
    rejects(
        |k, l| {
            if k == 330 {
                l.replacen("101.650", "101.645", 1)
            } else {
                l
            }
        },
        331,
        "field t",
        "",
    );
}

/// Rates where increments are expected: dvel holds -9.8 m/s^2, implying 200 g at 200
/// Hz, and the gyro columns rates too; the error names the reading that fits.
#[test]
fn rates_in_an_increment_file_are_an_error() {
    rejects(
        |_, l| {
            l.replace(&format!("{:.9e}", -9.80 * 0.005), "-9.8")
                .replace("1.2e-7 -3.0e-8 2.9e-7", "2.4e-5 -6.0e-6 5.8e-5")
        },
        1,
        "dvel",
        "look like rates, not increments",
    );
    // Accelerometer rates beside gyro increments: refused, with the numbers.
    rejects(
        |_, l| l.replace(&format!("{:.9e}", -9.80 * 0.005), "-9.8"),
        1,
        "dvel",
        "median specific force is 199.9 g, above the 50 g",
    );
}

/// A gap longer than two sample intervals is a warning with the count, not an error.
#[test]
fn gaps_are_counted_in_a_warning() {
    let dir = tempfile::tempdir().expect("tempdir");
    // Drop lines 301..=305 and 351..=352: two gaps.
    let text: String = kf_gins_log(400, |_, l| l)
        .lines()
        .enumerate()
        .filter(|(k, _)| !(300..305).contains(k) && !(350..352).contains(k))
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    nav(dir.path(), &text, &[])
        .success()
        .stderr(predicate::str::contains("warning"))
        .stderr(predicate::str::contains("2 gap(s)"));
}

/// `--output-rate 10` on a 200 Hz log writes one epoch per 0.1 s, plus the start; the
/// time window starts at the first sample at or after `--start`.
#[test]
fn output_rate_and_window() {
    let dir = tempfile::tempdir().expect("tempdir");
    nav(
        dir.path(),
        &kf_gins_log(400, |_, l| l),
        &["--output-rate", "10", "--start", "100.5", "--end", "101.5"],
    )
    .success();
    let txt = std::fs::read_to_string(dir.path().join("out/nav.txt")).expect("nav.txt");
    let times: Vec<f64> = txt
        .lines()
        .map(|l| l.split(' ').nth(1).expect("sow").parse().expect("number"))
        .collect();
    assert_eq!(times.first(), Some(&100.5));
    assert_eq!(times.last(), Some(&101.5));
    assert_eq!(times.len(), 11, "{times:?}");
    let csv = std::fs::read_to_string(dir.path().join("out/nav.csv")).expect("nav.csv");
    // The KF-GINS columns first, then ECEF position and wander azimuth (issue 6).
    assert!(csv.starts_with(
        "t_sow,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg,\
         x_ecef_m,y_ecef_m,z_ecef_m,wander_azimuth_deg\n"
    ));
    assert_eq!(csv.lines().count(), 12);
    // Every nav.txt line has the 11 KF-GINS columns.
    assert!(txt.lines().all(|l| l.split(' ').count() == 11));
}

/// The same options from a TOML file, with paths relative to it.
#[test]
fn toml_config() {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join("imu.txt"), kf_gins_log(100, |_, l| l)).expect("log");
    std::fs::write(
        dir.path().join("nav.toml"),
        "imu = \"imu.txt\"\ninit_pos = [45.0, 7.0, 100.0]\ninit_att = [0.0, 0.0, 90.0]\n\
         output_rate = 20.0\nout = \"res\"\nearth = \"sphere\"\n",
    )
    .expect("config");
    Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--config"])
        .arg(dir.path().join("nav.toml"))
        .assert()
        .success();
    let txt = std::fs::read_to_string(dir.path().join("res/nav.txt")).expect("nav.txt");
    // 100 samples span 100.000..100.495 s: 20 Hz slots 100.00, 100.05, ..., 100.45.
    assert_eq!(txt.lines().count(), 10);
    let yaw: f64 = txt
        .lines()
        .next()
        .and_then(|l| l.split(' ').nth(10))
        .expect("yaw")
        .parse()
        .expect("number");
    assert!((yaw - 90.0).abs() < 1e-9);
}

/// Missing or malformed options are errors that say what to give.
#[test]
fn option_errors_are_clear() {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join("imu.txt"), kf_gins_log(50, |_, l| l)).expect("log");
    Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--imu"])
        .arg(dir.path().join("imu.txt"))
        .args(["--init-pos", "45,7,100"])
        .assert()
        .failure()
        .stderr(predicate::str::contains("--init-att ROLL,PITCH,YAW"));
    Command::cargo_bin("schuler")
        .expect("binary")
        .args([
            "nav",
            "--init-pos",
            "45,7",
            "--init-att",
            "0,0,0",
            "--imu",
            "x",
        ])
        .assert()
        .failure()
        .stderr(predicate::str::contains(
            "expected three comma-separated numbers",
        ));
    Command::cargo_bin("schuler")
        .expect("binary")
        .args([
            "nav",
            "--init-pos",
            "45,7,0",
            "--init-att",
            "0,0,0",
            "--imu",
        ])
        .arg(dir.path().join("missing.txt"))
        .assert()
        .failure()
        .stderr(predicate::str::contains("missing.txt"));
}
