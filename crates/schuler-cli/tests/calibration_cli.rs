//! Self-calibration through the command line (issue 33): the 20-minute drive of
//! `examples/drive.toml` (two turns, a climb, speed changes; antenna at (0.5, 0, −1) m)
//! with its GNSS stamped 80 ms early, navigated told a zero lever arm and no offset,
//! both estimated: the run prints each estimate with its standard deviation, says
//! which ones the motion did not observe, and prints the flags to use next time.
//! (Two turns in 20 minutes observe a lever arm to decimetres only: the library's
//! calibration tests drive a city for the centimetres.)

use std::path::Path;

use crate::common;
use common::simulate;

/// The drive of `examples/drive.toml` with `time_offset = "80 ms"` in its `[gnss]`.
fn late_drive(dir: &Path) -> std::path::PathBuf {
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/drive.toml");
    let text = std::fs::read_to_string(example).expect("drive.toml");
    let text = text.replace("[gnss]\n", "[gnss]\ntime_offset = \"80 ms\"\n");
    let config = dir.join("late.toml");
    std::fs::write(&config, text).expect("write");
    simulate(&config, dir)
}

/// The numbers of a printed `a ± b` list.
fn values(line: &str) -> Vec<(f64, f64)> {
    let body = line.split(": ").nth(1).expect("values");
    let body = body
        .split(" m (")
        .next()
        .expect("lever")
        .split(" s (")
        .next()
        .expect("time");
    body.split(", ")
        .map(|p| {
            let (a, b) = p.split_once(" ± ").expect("a ± b");
            (a.parse().expect("value"), b.parse().expect("std"))
        })
        .collect()
}

#[test]
fn nav_estimates_the_lever_arm_and_the_time_offset_and_says_what_it_saw() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = late_drive(dir.path());
    let out = dir.path().join("out");
    let run = assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--imu"])
        .arg(sim.join("imu.txt"))
        .arg("--gnss")
        .arg(sim.join("gnss.csv"))
        .arg("--gnss-vel")
        .arg(sim.join("gnss.csv"))
        .args(["--init-pos", "45.07,7.68,245", "--init-att", "0,0,10"])
        .args(["--imu-grade", "tactical", "--output-rate", "1"])
        .args(["--estimate-lever-arm", "--estimate-gnss-time-offset"])
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let stdout = String::from_utf8_lossy(&run.get_output().stdout).into_owned();
    println!("{stdout}");
    let line = |start: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with(start))
            .unwrap_or_else(|| panic!("no line `{start}` in\n{stdout}"))
            .to_owned()
    };
    let lever = values(&line("lever arm estimated: "));
    let tau = values(&line("GNSS time offset estimated: "));
    // The truth inside 3 standard deviations of each estimate (a consistent filter's
    // estimate is there with probability 99.7 %).
    for ((v, sd), truth) in lever.iter().zip([0.5, 0.0, -1.0]) {
        assert!(
            (v - truth).abs() < 3.0 * sd,
            "lever arm {v} ± {sd} against {truth}"
        );
    }
    let (v, sd) = tau[0];
    assert!((v - 0.08).abs() < 3.0 * sd, "offset {v} ± {sd}");
    // The report plots each estimate and writes its history once a second: a
    // constant's variance never grows in a Kalman filter (its transition row is the
    // identity, it has no process noise, an update only lowers it), so each σ column
    // is non-increasing (to the covariance update's rounding, 1e-12 relative) down to
    // the σ the run printed at its end (that is the update after the last second's
    // row; to its printed decimals).
    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    assert!(html.contains("Self-calibration") && html.contains("from the motion alone"));
    let csv = std::fs::read_to_string(out.join("report/calibration.csv")).expect("csv");
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| {
            // An empty field: no value (the motion alone knows nothing at the start).
            l.split(',')
                .map(|v| {
                    if v.is_empty() {
                        f64::NAN
                    } else {
                        v.parse().expect("number")
                    }
                })
                .collect()
        })
        .collect();
    assert!(rows.len() > 1000, "{} rows", rows.len());
    for (k, (_, printed_sd)) in lever.iter().chain(&tau).enumerate() {
        let (col, scale, half) = match k {
            3 => (2 + 3 * k, 1e3, 0.5e-4 * 1.001),
            _ => (2 + 3 * k, 1.0, 0.5e-3 * 1.001),
        };
        for w in rows.windows(2) {
            assert!(w[1][0] > w[0][0]);
            assert!(w[1][col] <= w[0][col] * (1.0 + 1e-12), "{k}: {w:?}");
        }
        let last = rows.last().expect("rows")[col] / scale;
        assert!(
            *printed_sd <= last + half,
            "{k}: printed {printed_sd}, last row {last}"
        );
    }
    let next = line("use next time: ");
    assert!(
        next.contains("--lever-arm ") && next.contains("--gnss-time-offset "),
        "{next}"
    );
}

#[test]
fn calibration_flags_are_checked() {
    let dir = tempfile::tempdir().expect("tempdir");
    let imu = dir.path().join("imu.txt");
    std::fs::write(&imu, "").expect("write");
    let gnss = dir.path().join("gnss.txt");
    std::fs::write(&gnss, "1 45 7 100 1 1 1\n").expect("write");
    for (flags, says) in [
        (vec!["--estimate-lever-arm=-1 m"], "--estimate-lever-arm"),
        (
            vec!["--estimate-gnss-time-offset", "90 s"],
            "GNSS time offset",
        ),
        (
            vec!["--gnss-time-offset-walk", "0.001"],
            "give --estimate-gnss-time-offset",
        ),
    ] {
        let run = assert_cmd::Command::cargo_bin("schuler")
            .expect("binary")
            .args(["nav", "--imu"])
            .arg(&imu)
            .arg("--gnss")
            .arg(&gnss)
            .args(["--init-pos", "45,7,100", "--init-att", "0,0,0"])
            .args(&flags)
            .arg("--out")
            .arg(dir.path().join("out"))
            .assert()
            .failure();
        let err = String::from_utf8_lossy(&run.get_output().stderr).into_owned();
        assert!(err.contains(says), "{flags:?}: {err}");
    }
}
