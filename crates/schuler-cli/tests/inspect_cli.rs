//! `schuler inspect` on every device log the repository holds (`tests/data/ulog`,
//! `ubx`, `dataflash`, `gnss_logger`, `ros1_bag`, `ros2_bag`): it names the streams
//! the readers' own tests count, prints the `schuler nav` line for those with an IMU
//! and GNSS, and that line runs; `--json` parses with the documented keys; a
//! truncated or garbage file is refused naming it. `nav --log` on the simulated logs
//! (the DataFlash circle, the ROS 2 drive) navigates against their truth.

use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data")
        .join(name)
}

fn schuler() -> assert_cmd::Command {
    assert_cmd::Command::cargo_bin("schuler").expect("binary")
}

/// `inspect --json FILE`'s one object.
fn inspect_json(file: &Path) -> serde_json::Value {
    let out = schuler()
        .args(["inspect", "--json"])
        .arg(file)
        .assert()
        .success();
    let v: serde_json::Value =
        serde_json::from_slice(&out.get_output().stdout).expect("inspect --json parses");
    v.as_array()
        .expect("an array")
        .first()
        .expect("one object")
        .clone()
}

/// The stream named `name` of an inspection.
fn stream<'a>(v: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    v["streams"]
        .as_array()
        .expect("streams")
        .iter()
        .find(|s| s["name"] == name)
        .unwrap_or_else(|| panic!("no stream {name} in {v:#}"))
}

/// Runs the inspection's command line (its `--out` in `dir`), returning its stdout.
fn run_command(v: &serde_json::Value, dir: &Path) -> String {
    let args: Vec<String> = v["command"]
        .as_array()
        .unwrap_or_else(|| panic!("no command: {v:#}"))
        .iter()
        .map(|a| a.as_str().expect("text").to_owned())
        .collect();
    assert_eq!(&args[..2], ["schuler", "nav"]);
    let out = schuler()
        .args(&args[1..])
        .args(["--no-report", "--output-rate", "10", "--out"])
        .arg(dir)
        .assert();
    let o = out.get_output();
    assert!(
        o.status.success(),
        "{args:?} failed:\n{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A stream expected: name, kind, records.
type Expected = (&'static str, &'static str, u64);

/// Each committed log: its format, streams of the kinds the readers give (the counts
/// are those of the readers' own tests and the data READMEs: `test2.bag` holds 3061
/// IMU messages, `synthetic_circle.bin` 10 s of 100-Hz IMU less its first sample,
/// GNSS at 5 Hz from its first 3-D fix at 1.1 s), and a command line exactly for
/// the logs with IMU samples and GNSS fixes that overlap.
#[test]
fn inspect_names_the_streams_of_every_log() {
    let cases: [(&str, &str, &[Expected], bool); 12] = [
        (
            "ulog/sample_log_small.ulg.gz",
            "ulog",
            &[
                ("sensor_combined", "imu", 1298),
                ("vehicle_gps_position", "gnss", 32),
                ("vehicle_air_data", "baro", 120),
            ],
            true,
        ),
        (
            "ulog/sample_px4_events.ulg.gz",
            "ulog",
            &[
                ("sensor_combined", "imu", 7783),
                ("vehicle_global_position", "reference", 109),
            ],
            true,
        ),
        (
            "ulog/sample_appended_multiple.ulg.gz",
            "ulog",
            &[("sensor_combined", "imu", 2373)],
            false,
        ),
        (
            "ulog/sample_logging_tagged_and_default_params.ulg.gz",
            "ulog",
            &[("sensor_combined", "imu", 2028)],
            true,
        ),
        (
            "ubx/neo_m8u_esf.ubx.gz",
            "ubx",
            &[("ESF-RAW", "imu", 289), ("NAV-PVT", "gnss", 3)],
            true,
        ),
        (
            "ubx/f9_esf_nav_att_truncated.ubx.gz",
            "ubx",
            &[
                ("ESF-RAW", "imu", 869),
                ("NAV-ATT", "reference", 9),
                ("RXM-RAWX", "raw", 69),
            ],
            true,
        ),
        (
            "ubx/f9p_rover_rawx_sfrbx.ubx.gz",
            "ubx",
            &[("NAV-PVT", "gnss", 455), ("RXM-RAWX", "raw", 2)],
            false,
        ),
        (
            "dataflash/synthetic_circle.bin.gz",
            "dataflash",
            &[
                ("IMU[0]", "imu", 999),
                ("GPS[0]", "gnss", 45),
                ("XKF1[0]", "reference", 100),
            ],
            true,
        ),
        (
            "dataflash/pymavlink_test.bin.gz",
            "dataflash",
            &[
                ("IMU", "imu", 44),
                ("GPS", "gnss", 5),
                ("NKF1", "reference", 24),
            ],
            true,
        ),
        (
            "gnss_logger/pixel7_2023_11_07.txt.gz",
            "gnss-logger",
            &[("Fix", "gnss", 94), ("Raw", "raw", 31)],
            false,
        ),
        (
            "ros1_bag/test2.bag",
            "ros1-bag",
            &[
                ("/imu/data", "imu", 3061),
                ("/jackal_velocity_controller/odom", "odometry", 3060),
            ],
            false,
        ),
        (
            "ros2_bag/drive.mcap",
            "mcap",
            &[("/imu/data", "imu", 9422), ("/gnss/fix", "gnss", 95)],
            true,
        ),
    ];
    for (file, format, streams, navigable) in cases {
        let v = inspect_json(&data(file));
        assert_eq!(v["schema"], "schuler-inspect/1", "{file}");
        assert_eq!(v["format"], format, "{file}");
        for &(name, kind, records) in streams {
            let s = stream(&v, name);
            assert_eq!(s["kind"], kind, "{file} {name}");
            assert_eq!(s["timing"]["records"], records, "{file} {name}");
        }
        assert_eq!(v["command"].is_array(), navigable, "{file}: {v:#}");
        assert!(v["command_note"].is_string(), "{file}");
        // The table names the same streams and the line.
        let out = schuler().arg("inspect").arg(data(file)).assert().success();
        let text = String::from_utf8_lossy(&out.get_output().stdout).into_owned();
        for &(name, _, _) in streams {
            assert!(text.contains(name), "{file}: {text}");
        }
        assert_eq!(
            text.contains("navigate with: schuler nav --log "),
            navigable,
            "{text}"
        );
    }
}

/// What the JSON tells of the data, against what the data sets are: the simulated
/// circle's IMU at exactly 100 Hz (its stamps are exact: no jitter, no gap) with
/// |f| = √(9.81² + 0.5²) plus noise; sample_log_small's one 30-ms dropout shows as a
/// gap of its IMU stream; its fixes' σ as PX4's eph/epv give them.
#[test]
fn inspect_json_holds_the_documented_fields() {
    let v = inspect_json(&data("dataflash/synthetic_circle.bin.gz"));
    assert_eq!(v["time_scale"], "gps-seconds-of-week");
    assert_eq!(v["week"], 2300);
    let imu = stream(&v, "IMU[0]");
    let t = &imu["timing"];
    assert!(
        (t["rate_hz"].as_f64().expect("rate") - 100.0).abs() < 1e-6,
        "{t}"
    );
    assert!(t["jitter_s"].as_f64().expect("jitter") < 1e-6, "{t}");
    assert_eq!(t["gaps"]["count"], 0);
    let f = imu["imu"]["mean_specific_force"].as_f64().expect("force");
    // 9.8227 m/s² for the noise-free force; the script's noise moves the mean by
    // well under 0.05 m/s².
    assert!((f - 9.81f64.hypot(0.5)).abs() < 0.05, "{f}");
    assert_eq!(imu["imu"]["continuous_increments"], true);
    let g = stream(&v, "GPS[0]");
    assert_eq!(g["gnss"]["fixes"], 45);
    assert!(g["gnss"]["median_horizontal_std_m"].is_number());
    let px4 = inspect_json(&data("ulog/sample_log_small.ulg.gz"));
    let imu = stream(&px4, "sensor_combined");
    assert_eq!(imu["timing"]["gaps"]["count"], 1, "{imu:#}");
    assert_eq!(
        imu["imu"]["gravity_axis"]
            .as_str()
            .map(|g| g.starts_with("+z")),
        Some(true)
    );
    assert!(
        px4["notes"]
            .as_array()
            .expect("notes")
            .iter()
            .any(|n| n.as_str().is_some_and(|n| n.contains("dropout")))
    );
    // Several files: one object each, in order.
    let out = schuler()
        .args(["inspect", "--json"])
        .arg(data("ubx/neo_m8u_esf.ubx.gz"))
        .arg(data("ros2_bag/drive.mcap"))
        .assert()
        .success();
    let all: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).expect("json");
    let formats: Vec<&str> = all
        .as_array()
        .expect("array")
        .iter()
        .map(|x| x["format"].as_str().expect("format"))
        .collect();
    assert_eq!(formats, ["ubx", "mcap"]);
}

/// The printed command line runs, on every log that has one.
#[test]
fn the_printed_command_lines_run() {
    for file in [
        "ulog/sample_log_small.ulg.gz",
        "ulog/sample_px4_events.ulg.gz",
        "ubx/neo_m8u_esf.ubx.gz",
        "ubx/f9_esf_nav_att_truncated.ubx.gz",
        "dataflash/pymavlink_test.bin.gz",
        "dataflash/synthetic_circle.bin.gz",
    ] {
        let dir = tempfile::tempdir().expect("tempdir");
        let v = inspect_json(&data(file));
        let out = run_command(&v, dir.path());
        assert!(out.contains("integrated"), "{file}: {out}");
        assert!(dir.path().join("nav.txt").is_file(), "{file}");
    }
}

/// The three numbers after `label` in the line of the comparison with the device's
/// solution, as printed.
fn numbers_after(text: &str, label: &str) -> Vec<f64> {
    let line = text
        .lines()
        .find(|l| l.starts_with("against the device's own solution"))
        .unwrap_or_else(|| panic!("no comparison in {text}"));
    let at = line
        .find(label)
        .unwrap_or_else(|| panic!("no {label} in {line}"));
    line[at + label.len()..]
        .split_whitespace()
        .take(3)
        .map(|x| x.parse().expect("number"))
        .collect()
}

/// `synthetic_circle.bin` (scripts/write_test_dataflash.py) holds the circle's exact
/// state in XKF1 (its heights above mean sea level, the fixes' 48.2 m below their
/// ellipsoidal ones): the run from the printed line meets it within the fixes'
/// noise (σ 1.2 m horizontally, smoothed over 45 fixes by a filter whose IMU is the
/// truth plus small noise: centimetres), velocity within 1 cm/s, attitude within
/// 0.1° (its yaw is observable from the turn); reference.csv holds a row per XKF1
/// sample inside the run.
#[test]
fn nav_log_meets_the_simulated_circles_truth() {
    let dir = tempfile::tempdir().expect("tempdir");
    let v = inspect_json(&data("dataflash/synthetic_circle.bin.gz"));
    let out = run_command(&v, dir.path());
    let pos = numbers_after(&out, "position N/E/D ");
    assert!(pos[0] < 0.05 && pos[1] < 0.05, "{out}");
    assert!((pos[2] - 48.2).abs() < 0.1, "{out}");
    let vel = numbers_after(&out, "velocity ");
    assert!(vel.iter().all(|&x| x < 0.01), "{out}");
    let att = numbers_after(&out, "roll/pitch/yaw ");
    assert!(att.iter().all(|&x| x < 0.1), "{out}");
    let csv = std::fs::read_to_string(dir.path().join("reference.csv")).expect("reference.csv");
    let mut lines = csv.lines();
    assert!(lines.next().expect("header").starts_with("t,d_north_m"));
    assert_eq!(lines.count(), 88);
}

/// A ROS bag given to `--log` runs as `--bag`: the same trajectory, byte for byte.
#[test]
fn nav_log_on_a_bag_is_nav_bag() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bag = data("ros2_bag/drive.mcap");
    let flags = [
        "--init",
        "gnss",
        "--imu-grade",
        "consumer-mems",
        "--no-report",
        "--output-rate",
        "10",
        "--end",
        "345650",
    ];
    for (flag, out) in [("--log", "a"), ("--bag", "b")] {
        schuler()
            .args(["nav", flag])
            .arg(&bag)
            .args(flags)
            .arg("--out")
            .arg(dir.path().join(out))
            .assert()
            .success();
    }
    let read = |d: &str| std::fs::read(dir.path().join(d).join("nav.txt")).expect("nav.txt");
    assert_eq!(read("a"), read("b"));
}

/// Garbage and truncated files are refused, the error naming the file, by `inspect`
/// and by `nav --log`; `--log` refuses the text IMU log's flags and `--imu` beside it.
#[test]
fn bad_files_are_refused_naming_them() {
    let dir = tempfile::tempdir().expect("tempdir");
    let junk = dir.path().join("junk.bin");
    std::fs::write(&junk, b"hello\x00\x01\x02 not a log").expect("write");
    let cut = dir.path().join("cut.ulg.gz");
    let whole = std::fs::read(data("ulog/sample_log_small.ulg.gz")).expect("read");
    std::fs::write(&cut, &whole[..20_000]).expect("write");
    let bag = dir.path().join("cut.bag");
    let whole = std::fs::read(data("ros1_bag/test2.bag")).expect("read");
    std::fs::write(&bag, &whole[..30_000]).expect("write");
    for (file, says) in [
        (&junk, "not a device log"),
        (&cut, "deflate"),
        (&bag, "truncated"),
    ] {
        for args in [
            vec!["inspect"],
            vec!["nav", "--init", "gnss", "--no-report", "--log"],
        ] {
            let out = schuler()
                .args(&args)
                .arg(file)
                .current_dir(dir.path())
                .assert()
                .failure();
            let err = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
            assert!(
                err.contains(&file.display().to_string()) && err.contains(says),
                "{args:?}: {err}"
            );
        }
    }
    let log = data("dataflash/synthetic_circle.bin.gz");
    let out = schuler()
        .args(["nav", "--init", "gnss", "--gyro-unit", "deg/s", "--log"])
        .arg(&log)
        .current_dir(dir.path())
        .assert()
        .failure();
    let err = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(err.contains("--gyro-unit does not apply to --log"), "{err}");
    let out = schuler()
        .args(["nav", "--init", "gnss", "--imu-stream", "IMU[7]", "--log"])
        .arg(&log)
        .current_dir(dir.path())
        .assert()
        .failure();
    let err = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(
        err.contains("IMU[7]") && err.contains("IMU[0], IMU[1]"),
        "{err}"
    );
}
