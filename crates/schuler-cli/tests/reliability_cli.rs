//! Bad samples deep in a log (issue "Reliability"): a solution that stops being a
//! number ends the run with an error naming the time, every file written stays whole
//! and holds no NaN; leaving the physical envelope is warned about.

mod common;

/// The drive9min IMU log with the x velocity increments of `rows` replaced by `dv`.
fn corrupted(dir: &std::path::Path, rows: std::ops::Range<usize>, dv: &str) -> std::path::PathBuf {
    let text = String::from_utf8(common::unxz(
        &common::test_data("drive9min").join("IMU.txt.xz"),
    ))
    .expect("utf-8");
    let lines: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if rows.contains(&i) {
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

/// `schuler nav` of the drive9min log with the velocity increments of `rows` set to
/// `dv` into `dir/out` (the layout check off, to reach the navigation).
fn nav_with(
    dir: &std::path::Path,
    rows: std::ops::Range<usize>,
    dv: &str,
) -> assert_cmd::assert::Assert {
    let imu = corrupted(dir, rows, dv);
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
/// ended "final: lat NaN" with exit 0): refused by the reader as a specific force no
/// accelerometer reads, naming the line and columns; nav.txt up to there whole-lined
/// without a NaN.
#[test]
fn a_huge_increment_stops_the_run_without_writing_nan() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = nav_with(dir.path(), 5000..5001, "1e20").failure();
    let out = dir.path().join("out");
    let stderr = String::from_utf8_lossy(&o.get_output().stderr).into_owned();
    assert!(
        stderr.contains(
            "IMU.txt:5001: field dvel (columns 5-7): specific force 1.0197162129781313e21 g \
             is outside [0, 10000] g"
        ),
        "{stderr}"
    );
    let nav = std::fs::read_to_string(out.join("nav.txt")).expect("nav.txt");
    assert!(nav.ends_with('\n') && !nav.to_lowercase().contains("nan"));
    assert!(nav.lines().all(|l| l.split_whitespace().count() == 11));
}

/// Five rows with velocity increments of 400 m/s (4100 g at 100 Hz, within an
/// accelerometer's range): the solution flies off at Mach 6, the run warns with the time and still
/// finishes.
#[test]
fn leaving_the_envelope_is_warned_and_the_run_finishes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = nav_with(dir.path(), 5000..5005, "400").success();
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

/// Flags outside their physical domain (issue "Reliability": `--init-vel 3,1e20,0`,
/// a longitude of 400, a height of -1e7 m, `--gyro-bias-std 1e308`, which ran into
/// NaN or an absurd answer) are refused before any output, naming the flag.
#[test]
fn flags_outside_their_domain_are_refused_by_name() {
    let dir = tempfile::tempdir().expect("tempdir");
    let imu = corrupted(dir.path(), 0..0, "");
    let gnss = common::test_data("drive9min").join("GNSS.txt");
    let nav = |pos: &str, vel: &str, extra: &[&str]| {
        let o = assert_cmd::Command::cargo_bin("schuler")
            .expect("binary")
            .args(["nav", "--imu"])
            .arg(&imu)
            .args(["--init-pos", pos, "--init-vel", vel, "--init-att", "0,0,10"])
            .args(extra)
            .arg("--out")
            .arg(dir.path().join("out"))
            .assert()
            .failure();
        String::from_utf8_lossy(&o.get_output().stderr).into_owned()
    };
    let pos = "45.0712345678,7.6812345678,245";
    let cases = [
        (
            nav(pos, "3,1e20,0", &[]),
            "--init-vel (start.state.v_n): speed 1e20 m/s is outside",
        ),
        (
            nav("45,400,245", "0,0,0", &[]),
            "--init-pos: longitude 400 deg is outside [-180, 360] deg",
        ),
        (
            nav("45,7,-1e7", "0,0,0", &[]),
            "--init-pos: height -10000000 m is outside [-12000, 100000000] m",
        ),
        (
            nav(
                pos,
                "0,0,0",
                &[
                    "--gnss",
                    &gnss.to_string_lossy(),
                    "--gyro-bias-std",
                    "1e308 deg/h",
                ],
            ),
            "--gyro-bias-std (filter.integration.noise.gyro_bias): noise",
        ),
    ];
    for (stderr, want) in cases {
        assert!(stderr.contains(want), "{want:?} not in {stderr}");
    }
    assert!(!dir.path().join("out").join("nav.txt").exists());
}

/// A stream without line ends (`/dev/zero`, the reproducer, which grew to
/// 10 GB in 8 s) given as any text input ends with an error naming the file, after at
/// most one line's bound (64 KiB) or a configuration's (16 MiB), well within the
/// minute the timeout allows.
#[test]
fn a_stream_without_line_ends_is_refused_by_every_reader() {
    let dir = tempfile::tempdir().expect("tempdir");
    let imu = corrupted(dir.path(), 0..0, "");
    let imu = imu.to_string_lossy();
    let gnss = common::test_data("drive9min").join("GNSS.txt");
    let gnss = gnss.to_string_lossy();
    let zero = "/dev/zero";
    let base = [
        "nav",
        "--imu",
        &imu,
        "--init-pos",
        "45,7,245",
        "--init-att",
        "0,0,10",
    ];
    let runs: [(Vec<&str>, &str); 6] = [
        (
            [&base[..], &["--gnss", zero]].concat(),
            "line longer than 64 KiB",
        ),
        (
            [&base[..], &["--gnss", &gnss, "--truth", zero]].concat(),
            "line longer than 64 KiB",
        ),
        (
            [&base[..], &["--gnss", &gnss, "--baro", zero]].concat(),
            "line longer than 64 KiB",
        ),
        (vec!["nav", "--config", zero], "longer than 16 MiB"),
        (vec!["simulate", "--config", zero], "longer than 16 MiB"),
        (vec!["compare", zero, zero], "line longer than 64 KiB"),
    ];
    for (args, want) in runs {
        let o = assert_cmd::Command::cargo_bin("schuler")
            .expect("binary")
            .args(&args)
            .arg("--out")
            .arg(dir.path().join("out"))
            .timeout(std::time::Duration::from_secs(60))
            .assert()
            .failure();
        let stderr = String::from_utf8_lossy(&o.get_output().stderr).into_owned();
        assert!(
            stderr.contains(zero) && stderr.contains(want),
            "{args:?}: {stderr}"
        );
    }
}
