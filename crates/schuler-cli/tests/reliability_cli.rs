//! Bad samples deep in a log (issue "Reliability"): a solution that stops being a
//! number ends the run with an error naming the time, every file written stays whole
//! and holds no NaN; leaving the physical envelope is warned about.

mod common;

/// The drive9min IMU log with one row's velocity increments replaced by `dv`.
fn corrupted(dir: &std::path::Path, row: usize, dv: &str) -> std::path::PathBuf {
    let text = String::from_utf8(common::unxz(
        &common::test_data("drive9min").join("IMU.txt.xz"),
    ))
    .expect("utf-8");
    let lines: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == row {
                let mut f: Vec<&str> = l.split_whitespace().collect();
                f[4] = dv;
                f.join(" ")
            } else {
                l.to_string()
            }
        })
        .collect();
    let path = dir.join("IMU.txt");
    std::fs::write(&path, lines.join("\n") + "\n").expect("write");
    path
}

/// `schuler nav` of the drive9min log with one row's velocity increment `dv` into
/// `dir/out` (the layout check off, to reach the navigation).
fn nav_with(dir: &std::path::Path, dv: &str) -> assert_cmd::assert::Assert {
    let imu = corrupted(dir, 5000, dv);
    assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--no-layout-check", "--imu"])
        .arg(&imu)
        .args([
            "--init-pos",
            "45.0712345678,7.6812345678,245",
            "--init-att",
            "0,0,10",
        ])
        .args(["--output-rate", "10", "--out"])
        .arg(dir.join("out"))
        .assert()
}

/// One row with a velocity increment of 1e20 m/s (the reproducer, which
/// ended "final: lat NaN" with exit 0): an error naming the time; nav.txt whole-lined
/// without a NaN.
#[test]
fn a_huge_increment_stops_the_run_without_writing_nan() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = nav_with(dir.path(), "1e20").failure();
    let out = dir.path().join("out");
    let stderr = String::from_utf8_lossy(&o.get_output().stderr).into_owned();
    assert!(
        stderr.contains("the solution is not finite at t = 50.1 s"),
        "{stderr}"
    );
    let nav = std::fs::read_to_string(out.join("nav.txt")).expect("nav.txt");
    assert!(nav.ends_with('\n') && !nav.to_lowercase().contains("nan"));
    assert!(nav.lines().all(|l| l.split_whitespace().count() == 11));
}

/// One row with a velocity increment of 2 km/s: the solution flies off at Mach 6, the
/// run warns with the time and still finishes.
#[test]
fn leaving_the_envelope_is_warned_and_the_run_finishes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = nav_with(dir.path(), "2000").success();
    let stderr = String::from_utf8_lossy(&o.get_output().stderr).into_owned();
    assert!(
        stderr.contains("at t = 50.1 s the solution left the physical envelope: speed"),
        "{stderr}"
    );
}

/// A GNSS log on another clock (the rover: the IMU's clock started at 0, the
/// GNSS log used UNIX time): no fix falls inside the IMU's span; the run says so with
/// both spans and the offset that aligns their starts, and fails.
#[test]
fn gnss_on_another_clock_is_an_error_with_the_offset() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = common::test_data("drive9min");
    let imu = dir.path().join("IMU.txt");
    std::fs::write(&imu, common::unxz(&data.join("IMU.txt.xz"))).expect("write");
    let unix: String = std::fs::read_to_string(data.join("GNSS.txt"))
        .expect("read")
        .lines()
        .map(|l| {
            let (t, rest) = l.trim().split_once(char::is_whitespace).expect("columns");
            let t: f64 = t.parse().expect("time");
            format!("{} {rest}\n", t + 1_764_000_000.0)
        })
        .collect();
    let gnss = dir.path().join("GNSS_unix.txt");
    std::fs::write(&gnss, unix).expect("write");
    let o = assert_cmd::Command::cargo_bin("schuler")
        .expect("binary")
        .args(["nav", "--imu"])
        .arg(&imu)
        .arg("--gnss")
        .arg(&gnss)
        .args([
            "--init-pos",
            "45.0712345678,7.6812345678,245",
            "--init-att",
            "0,0,10",
        ])
        .args(["--no-report", "--out"])
        .arg(dir.path().join("out"))
        .assert()
        .failure();
    let stderr = String::from_utf8_lossy(&o.get_output().stderr).into_owned();
    assert!(
        stderr.contains("no fix falls inside the IMU's span"),
        "{stderr}"
    );
    assert!(stderr.contains("the GNSS fixes t = 1764000000"), "{stderr}");
    assert!(
        stderr.contains("An offset of -1763999999.99 s on the GNSS stamps"),
        "{stderr}"
    );
}
