//! ROS 2 bag tests that need the Python `mcap` and `mcap-ros2-support` packages (an
//! MCAP/CDR implementation we did not write): `.ci/run` installs them in a virtual
//! environment (`scripts/requirements-bag.txt`) and sets `SCHULER_BAG_PYTHON` to its
//! interpreter. Without the variable these tests return at once (a fresh clone needs
//! only the Rust toolchain); with it, a Python that does not work fails them.
//!
//! - `scripts/write_test_bag.py` writes the committed `tests/data/ros2_bag/drive.mcap`
//!   again byte for byte from the scenario;
//! - the 18-minute example drive (200 Hz, 219,846 IMU messages) in lz4 chunks of
//!   256 KiB, read by `nav --bag`, gives the text logs' trajectory;
//! - an uncompressed rosbag2 directory (metadata.yaml + .mcap) reads as the file does;
//! - IMU covariances become the filter's ARW and VRW;
//! - `--out-bag` read back by the Python packages: topics, types, stamps, frames,
//!   positions and attitude.

mod common;

use common::bag::{data, max_digits_apart, nav_bag, nav_text, simulate_scenario};
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The Python interpreter of `.ci/run`'s virtual environment, or `None` (the test
/// then returns: it is not part of the fresh-clone suite).
fn python() -> Option<PathBuf> {
    match std::env::var_os("SCHULER_BAG_PYTHON") {
        Some(p) => Some(PathBuf::from(p)),
        None => {
            eprintln!("SCHULER_BAG_PYTHON is not set: this bag test runs in .ci/run");
            None
        }
    }
}

/// A repository script.
fn script(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scripts")
        .join(name)
}

/// `write_test_bag.py sim out` with `extra`, which must succeed.
fn write_bag(python: &Path, sim: &Path, out: &Path, extra: &[&str]) {
    let status = Command::new(python)
        .arg(script("write_test_bag.py"))
        .arg(sim)
        .arg(out)
        .args(extra)
        .status()
        .expect("run python");
    assert!(status.success(), "write_test_bag.py failed: {status}");
}

#[test]
fn the_committed_bag_is_written_again_byte_for_byte() {
    let Some(py) = python() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = simulate_scenario(dir.path());
    let out = dir.path().join("drive.mcap");
    write_bag(&py, &sim, &out, &["--odometer-rate", "10"]);
    assert!(
        std::fs::read(&out).expect("written")
            == std::fs::read(data().join("drive.mcap")).expect("committed"),
        "scripts/write_test_bag.py no longer writes tests/data/ros2_bag/drive.mcap: \
         regenerate it (tests/data/README.md) or find what changed"
    );
}

/// `bag_cli.rs`'s `bag_gives_the_text_logs_trajectory` over 18 minutes at 200 Hz
/// with turns, a climb and a 60-s outage (61 NO_FIX messages), from lz4 chunks. The
/// inputs differ by 1 ulp where they differ (the reasons given there), and 23,000
/// filter updates (GNSS, barometer, odometer) carry those differences into the state:
/// measured 3 units of the last digit in attitude (3e-9 deg = 5e-11 rad, while
/// accelerating at 78 s), 1 elsewhere. Bound: 5 units (5e-9 deg, 5e-11 deg ≈ 6 µm,
/// 5 µm/s), a millionth of what any test of accuracy here resolves.
#[test]
fn the_example_drive_from_lz4_chunks_gives_the_text_trajectory() {
    let Some(py) = python() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = common::simulate_drive(dir.path());
    common::bag::write_odometer(&sim, 10.0);
    let bag = dir.path().join("drive.mcap");
    let chunk = (256 * 1024).to_string();
    write_bag(
        &py,
        &sim,
        &bag,
        &[
            "--odometer-rate",
            "10",
            "--compression",
            "lz4",
            "--chunk-size",
            &chunk,
        ],
    );
    let (text, out) = (dir.path().join("text"), dir.path().join("bag"));
    nav_text(&sim, &text).success();
    let a = nav_bag(&bag, &out, &[]).success();
    let err = String::from_utf8_lossy(&a.get_output().stderr).into_owned();
    assert!(err.contains("1039 GNSS fixes (61 NO_FIX skipped"), "{err}");
    let digits = max_digits_apart(&text.join("nav.txt"), &out.join("nav.txt"));
    assert!(digits <= 5.0, "{digits} units of the last digit apart");
}

#[test]
fn an_uncompressed_rosbag2_directory_reads_as_the_file() {
    let Some(py) = python() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = simulate_scenario(dir.path());
    let bag_dir = dir.path().join("rosbag2_drive");
    std::fs::create_dir(&bag_dir).expect("dir");
    write_bag(
        &py,
        &sim,
        &bag_dir.join("rosbag2_drive_0.mcap"),
        &["--odometer-rate", "10", "--compression", "none"],
    );
    std::fs::write(
        bag_dir.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  \
         relative_file_paths:\n    - rosbag2_drive_0.mcap\n",
    )
    .expect("metadata");
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    nav_bag(&data().join("drive.mcap"), &a, &[]).success();
    nav_bag(&bag_dir, &b, &[]).success();
    assert_eq!(
        std::fs::read(a.join("nav.txt")).expect("a"),
        std::fs::read(b.join("nav.txt")).expect("b")
    );
}

/// One sample's standard deviations σ_ω, σ_f in the IMU messages are white noise of
/// density σ·√dt: with σ_ω = N/√0.01 s for N = 0.15 deg/√h and σ_f likewise for
/// 0.1 m/s/√h, the run equals the text run with `--arw 0.15 deg/sqrt(h) --vrw 0.1
/// m/s/sqrt(h)`, up to the bag's interval being the median of stamp differences
/// (0.01 s within 1e-9 relative at 3.5e5 s): nav.txt within 2 units of its last digit.
#[test]
fn imu_covariances_set_the_noise_model() {
    let Some(py) = python() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = simulate_scenario(dir.path());
    let bag = dir.path().join("cov.mcap");
    let arw = 0.15f64.to_radians() / 60.0;
    let vrw = 0.1 / 60.0;
    let (gyro, accel) = ((arw / 0.1).to_string(), (vrw / 0.1).to_string());
    write_bag(
        &py,
        &sim,
        &bag,
        &[
            "--odometer-rate",
            "10",
            "--gyro-std",
            &gyro,
            "--accel-std",
            &accel,
        ],
    );
    let (text, out) = (dir.path().join("text"), dir.path().join("bag"));
    let noise = ["--arw", "0.15 deg/sqrt(h)", "--vrw", "0.1 m/s/sqrt(h)"];
    common::bag::nav_text_with(&sim, &text, &noise).success();
    let a = nav_bag(&bag, &out, &[]).success();
    let err = String::from_utf8_lossy(&a.get_output().stderr).into_owned();
    assert!(
        err.contains("ARW 0.1500 deg/sqrt(h), VRW 0.1000 m/s/sqrt(h)"),
        "{err}"
    );
    let digits = max_digits_apart(&text.join("nav.txt"), &out.join("nav.txt"));
    assert!(digits <= 2.0, "{digits} units of the last digit apart");
    // Without the covariances (the committed bag) the tactical grade's noise runs,
    // which differs.
    let other = dir.path().join("other");
    nav_bag(&data().join("drive.mcap"), &other, &[]).success();
    assert!(max_digits_apart(&other.join("nav.txt"), &out.join("nav.txt")) > 100.0);
}

/// The decoded messages of `bag`, one JSON object each, by the Python packages.
fn read_with_python(py: &Path, bag: &Path) -> Vec<serde_json::Value> {
    let out = Command::new(py)
        .arg(script("read_result_bag.py"))
        .arg(bag)
        .output()
        .expect("run python");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .expect("utf-8")
        .lines()
        .map(|l| serde_json::from_str(l).expect("json"))
        .collect()
}

fn f64s(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

/// Each topic of the result bag: its type, CDR, one message per nav.csv row, stamped
/// at the row's time and logged at the same instant, in its frame.
fn check_stamps_and_frames(msgs: &[serde_json::Value], rows: &[Vec<f64>]) {
    let on = |topic: &str| -> Vec<&serde_json::Value> {
        msgs.iter().filter(|m| m["topic"] == topic).collect()
    };
    for (topic, ty) in [
        ("/schuler/odometry", "nav_msgs/msg/Odometry"),
        ("/schuler/fix", "sensor_msgs/msg/NavSatFix"),
        ("/schuler/gyro_bias", "geometry_msgs/msg/Vector3Stamped"),
        ("/schuler/accel_bias", "geometry_msgs/msg/Vector3Stamped"),
    ] {
        let m = on(topic);
        assert_eq!(m.len(), rows.len(), "{topic}");
        for (x, r) in m.iter().zip(rows) {
            assert_eq!(
                (x["type"].as_str(), x["encoding"].as_str()),
                (Some(ty), Some("cdr"))
            );
            let t = x["sec"].as_f64().expect("sec") + x["nanosec"].as_f64().expect("ns") * 1e-9;
            assert!((t - r[0]).abs() <= 1e-6, "{topic} stamp {t} vs {}", r[0]);
            let log = x["log_time"].as_u64().expect("log time");
            assert_eq!(
                log,
                x["sec"].as_u64().expect("sec") * 1_000_000_000
                    + x["nanosec"].as_u64().expect("ns")
            );
            let frame = if topic == "/schuler/odometry" {
                "map"
            } else {
                "base_link"
            };
            assert_eq!(x["frame_id"], frame, "{topic}");
        }
    }
}

/// `--out-bag` as another implementation reads it: four topics of the named types,
/// CDR, one message per nav.csv epoch each, stamped (sec, nanosec) at the epoch's time
/// and logged at the same instant; frames map/base_link; the fix at nav.csv's position
/// (its last digits: 1e-11 deg, 1 µm); the odometry's position the ENU of nav.csv's
/// ECEF position from the first epoch's (3 µm: the printed ECEF's 1 µm on three
/// axes); a unit quaternion whose heading at the start is 90° − yaw (base_link's x
/// north-east of the map's x = east, REP 103/105); symmetric covariances.
#[test]
fn the_result_bag_reads_back_in_python() {
    let Some(py) = python() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let result = dir.path().join("result.mcap");
    nav_bag(
        &data().join("drive.mcap"),
        &out,
        &["--out-bag", result.to_str().expect("utf-8")],
    )
    .success();
    let text = std::fs::read_to_string(out.join("nav.csv")).expect("nav.csv");
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
        .collect();
    let msgs = read_with_python(&py, &result);
    assert_eq!(msgs.len(), 4 * rows.len());
    check_stamps_and_frames(&msgs, &rows);
    let on = |topic: &str| -> Vec<&serde_json::Value> {
        msgs.iter().filter(|m| m["topic"] == topic).collect()
    };
    let r0 = Vector3::new(rows[0][10], rows[0][11], rows[0][12]);
    let (sp, cp) = rows[0][1].to_radians().sin_cos();
    let (sl, cl) = rows[0][2].to_radians().sin_cos();
    let c0 = Matrix3::new(-sl, cl, 0.0, -sp * cl, -sp * sl, cp, cp * cl, cp * sl, sp);
    for (x, r) in on("/schuler/fix").iter().zip(&rows) {
        assert!((x["latitude"].as_f64().expect("lat") - r[1]).abs() <= 1e-11);
        assert!((x["longitude"].as_f64().expect("lon") - r[2]).abs() <= 1e-11);
        assert!((x["altitude"].as_f64().expect("alt") - r[3]).abs() <= 1e-6);
        let c = f64s(&x["position_covariance"]);
        assert!(c[0] > 0.0 && c[4] > 0.0 && c[8] > 0.0 && (c[1] - c[3]).abs() < 1e-15);
    }
    for (x, r) in on("/schuler/odometry").iter().zip(&rows) {
        assert_eq!(x["child_frame_id"], "base_link");
        let p = Vector3::from_vec(f64s(&x["position"]));
        let enu = c0 * (Vector3::new(r[10], r[11], r[12]) - r0);
        assert!((p - enu).norm() < 3e-6, "{p} vs {enu}");
        let q = f64s(&x["orientation"]);
        assert!((q.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-12);
        let cov = f64s(&x["pose_covariance"]);
        for i in 0..6 {
            assert!(cov[i * 7] > 0.0);
            for j in 0..6 {
                assert!(
                    (cov[i * 6 + j] - cov[j * 6 + i]).abs() <= 1e-12 * cov[i * 7].max(cov[j * 7])
                );
            }
        }
    }
    let first = on("/schuler/odometry")[0];
    let q = f64s(&first["orientation"]);
    let rot = UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]));
    let x_enu = rot * Vector3::x();
    let heading_from_east = x_enu.y.atan2(x_enu.x).to_degrees();
    assert!(
        (heading_from_east - (90.0 - rows[0][9])).abs() < 1e-8,
        "{heading_from_east} vs 90 - {}",
        rows[0][9]
    );
}

/// Our reader's values of one message (the fields it decodes), each with its index in
/// `read_ros1_bag.py`'s list (which also holds the IMU's orientation and the twist's
/// angular part, which our decoder skips), and the frame.
fn our_values(type_name: &str, data: &[u8]) -> Option<(Vec<(usize, f64)>, String)> {
    let (from, v, frame) = our_decoded(type_name, data)?;
    let at = |i: usize| {
        if type_name.ends_with("TwistWithCovarianceStamped") && i >= 3 {
            i + 3
        } else {
            from + i
        }
    };
    Some((
        v.into_iter().enumerate().map(|(i, x)| (at(i), x)).collect(),
        frame,
    ))
}

/// The values our decoder gives, the index of the first in rosbags' list, the frame.
fn our_decoded(type_name: &str, data: &[u8]) -> Option<(usize, Vec<f64>, String)> {
    use schuler_io::bag::messages::{
        Decode, Encoding, FluidPressure, Imu, NavSatFix, Odometry, TfMessage, TwistStamped,
    };
    let e = Encoding::Ros1;
    let short = type_name.replace("/msg/", "/");
    let decoded = match short.as_str() {
        "sensor_msgs/Imu" => {
            let m = Imu::decode_in(e, data).expect("imu");
            let v = [
                &m.angular_velocity[..],
                &m.angular_velocity_covariance,
                &m.linear_acceleration,
                &m.linear_acceleration_covariance,
            ]
            .concat();
            (13, v, m.header.frame_id)
        }
        "sensor_msgs/NavSatFix" => {
            let m = NavSatFix::decode_in(e, data).expect("fix");
            let mut v = vec![
                f64::from(m.status),
                f64::from(m.service),
                m.latitude,
                m.longitude,
                m.altitude,
            ];
            v.extend(m.position_covariance);
            v.push(f64::from(m.position_covariance_type));
            (0, v, m.header.frame_id)
        }
        "geometry_msgs/TwistWithCovarianceStamped" => {
            let m = TwistStamped::decode_in(e, data).expect("twist");
            // linear, then (after the angular part) the covariance.
            let mut v = m.linear.to_vec();
            v.extend(m.covariance);
            (0, v, m.header.frame_id)
        }
        "sensor_msgs/FluidPressure" => {
            let m = FluidPressure::decode_in(e, data).expect("pressure");
            (0, vec![m.fluid_pressure, m.variance], m.header.frame_id)
        }
        "nav_msgs/Odometry" => {
            let m = Odometry::decode_in(e, data).expect("odometry");
            let v = [
                &m.position[..],
                &m.orientation,
                &m.pose_covariance,
                &m.linear,
                &m.angular,
                &m.twist_covariance,
            ]
            .concat();
            (0, v, m.header.frame_id)
        }
        "tf2_msgs/TFMessage" => {
            let m = TfMessage::decode_in(e, data).expect("tf");
            let mut v = Vec::new();
            for t in &m.transforms {
                v.extend(t.translation);
                v.extend(t.rotation);
            }
            let frame = m.transforms[0].header.frame_id.clone();
            (0, v, frame)
        }
        _ => return None,
    };
    Some(decoded)
}

/// Every message of the ROS 1 bag `bag` our reader decodes, compared with what the
/// `rosbags` package decodes: the same messages (topic, type, md5sum, index within the
/// topic, log time), and each value the same 64 bits (both decode the same bytes: no
/// tolerance); returns the messages compared. Each topic's order is compared (the
/// index), not the order across topics: we read in file order, rosbags in log-time
/// order through the index, and messages of two topics logged at the same time (the
/// /tf_static that write_test_ros1_bag.py writes with the first IMU message) may come
/// in either order.
fn same_as_rosbags(py: &Path, bag: &Path) -> usize {
    use schuler_io::bag::container::BagStream;
    let out = Command::new(py)
        .arg(script("read_ros1_bag.py"))
        .arg(bag)
        .output()
        .expect("run python");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // rosbags' messages by topic and index.
    let mut theirs: std::collections::HashMap<(String, u64), serde_json::Value> =
        String::from_utf8(out.stdout)
            .expect("utf-8")
            .lines()
            .map(|l| {
                let t: serde_json::Value = serde_json::from_str(l).expect("json");
                let key = (
                    t["topic"].as_str().expect("topic").to_owned(),
                    t["index"].as_u64().expect("index"),
                );
                (key, t)
            })
            .collect();
    let mut stream = BagStream::open(bag).expect("open");
    let mut k = 0;
    while let Some(()) = stream
        .next_with(|m| {
            let Some((ours, frame)) = our_values(&m.topic.type_name, m.data) else {
                return Ok(());
            };
            let what = format!("{} message {}", m.topic.name, m.index);
            let t = theirs
                .remove(&(m.topic.name.clone(), m.index))
                .unwrap_or_else(|| panic!("{what}: not among rosbags' messages"));
            k += 1;
            assert_eq!(
                t["type"]
                    .as_str()
                    .map(|s| s.replace("/msg/", "/"))
                    .as_deref(),
                Some(m.topic.type_name.as_str()),
                "{what}"
            );
            assert_eq!(t["md5sum"], m.topic.md5sum.as_str(), "{what}");
            assert_eq!(t["log_time"].as_u64(), Some(m.log_time), "{what}");
            assert_eq!(t["frame_id"], frame.as_str(), "{what}");
            let bits: Vec<u64> = t["bits"]
                .as_array()
                .expect("bits")
                .iter()
                .map(|b| b.as_u64().expect("u64"))
                .collect();
            assert_eq!(ours.last().map(|(i, _)| i + 1), Some(bits.len()), "{what}");
            for (i, x) in ours {
                assert_eq!(x.to_bits(), bits[i], "{what}: value {i}");
            }
            Ok(())
        })
        .expect("read")
    {}
    assert!(
        theirs.is_empty(),
        "{} of rosbags' messages not read by ours",
        theirs.len()
    );
    k
}

/// robot_localization's test2.bag (rosbag's own bz2 chunks) and its first 5 s in
/// uncompressed, bz2 and lz4 chunks: 6121 and 501 messages, every value as rosbags
/// reads it.
#[test]
fn the_ros1_reader_agrees_with_rosbags_value_by_value() {
    let Some(py) = python() else { return };
    let data = common::test_data("ros1_bag");
    assert_eq!(same_as_rosbags(&py, &data.join("test2.bag")), 6121);
    let dir = tempfile::tempdir().expect("tempdir");
    let none = dir.path().join("test2_first5s_none.bag");
    std::fs::write(&none, common::unxz(&data.join("test2_first5s_none.bag.xz"))).expect("write");
    for path in [
        none,
        data.join("test2_first5s_bz2.bag"),
        data.join("test2_first5s_lz4.bag"),
    ] {
        assert_eq!(same_as_rosbags(&py, &path), 501, "{}", path.display());
    }
}

/// `write_test_ros1_bag.py sim out` with `extra`, which must succeed.
fn write_ros1_bag(python: &Path, sim: &Path, out: &Path, extra: &[&str]) {
    let status = Command::new(python)
        .arg(script("write_test_ros1_bag.py"))
        .arg(sim)
        .arg(out)
        .args(extra)
        .status()
        .expect("run python");
    assert!(status.success(), "write_test_ros1_bag.py failed: {status}");
}

/// The drive of `drive.mcap` written by rosbags as a ROS 1 bag whose IMU frame is
/// rolled −90° and yawed 90° from base_link in /tf_static (the IMU's vectors turned
/// into that frame by the script, with numpy): `nav --bag` takes the mounting from
/// the transform tree and gives the MCAP bag's trajectory. The two inputs differ by
/// the rounding of the turn there and back (the quaternion of cos/sin of 45°: ~1e-16
/// relative on each rate), which the filter carries as the 1-ulp input differences
/// of `the_example_drive_from_lz4_chunks_gives_the_text_trajectory`: bound 5 units of
/// nav.txt's last digit. Every value of the written bag is also read as rosbags
/// reads it; bz2, lz4 and uncompressed chunks give the same bits; the mounting given
/// by hand as well is refused beside --base-frame and overrides the tree otherwise
/// (the same mounting given by hand gives the same trajectory).
#[test]
fn a_ros1_bag_with_the_imu_turned_in_tf_static_gives_the_mcap_trajectory() {
    let Some(py) = python() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    let sim = simulate_scenario(dir.path());
    let turn = ["--odometer-rate", "10", "--imu-rpy=-90,0,90"];
    let mut runs = Vec::new();
    for compression in ["bz2", "lz4", "none"] {
        let bag = dir.path().join(format!("drive_{compression}.bag"));
        write_ros1_bag(
            &py,
            &sim,
            &bag,
            &[&turn[..], &["--compression", compression]].concat(),
        );
        let out = dir.path().join(compression);
        let a = nav_bag(&bag, &out, &[]).success();
        let err = String::from_utf8_lossy(&a.get_output().stderr).into_owned();
        assert!(
            err.contains("IMU mounting from /tf_static: imu_link in base_link (FLU)"),
            "{err}"
        );
        runs.push((bag, out));
    }
    assert!(same_as_rosbags(&py, &runs[0].0) > 9422);
    let mcap = dir.path().join("mcap");
    nav_bag(&data().join("drive.mcap"), &mcap, &[]).success();
    let digits = max_digits_apart(&mcap.join("nav.txt"), &runs[0].1.join("nav.txt"));
    assert!(digits <= 5.0, "{digits} units of the last digit apart");
    for (_, out) in &runs[1..] {
        assert_eq!(
            std::fs::read(out.join("nav.txt")).expect("nav"),
            std::fs::read(runs[0].1.join("nav.txt")).expect("nav")
        );
    }
    let bag = &runs[0].0;
    let out = dir.path().join("both");
    let a = nav_bag(
        bag,
        &out,
        &["--base-frame", "base_link", "--imu-axes", "FLU"],
    )
    .failure();
    let err = String::from_utf8_lossy(&a.get_output().stderr).into_owned();
    assert!(
        err.contains("--base-frame base_link takes the IMU's mounting"),
        "{err}"
    );
    // The same mounting by hand: imu_link = Rz(90°) Rx(−90°) from base_link (FLU)
    // puts the IMU's x to the left, y down and z back (LDB), which overrides the tree
    // with a warning and gives the trajectory the tree gave (bound as above).
    let by_hand = dir.path().join("by_hand");
    let a = nav_bag(bag, &by_hand, &["--imu-axes", "LDB"]).success();
    let err = String::from_utf8_lossy(&a.get_output().stderr).into_owned();
    assert!(
        err.contains("override /tf_static's mounting in base_link"),
        "{err}"
    );
    let digits = max_digits_apart(&mcap.join("nav.txt"), &by_hand.join("nav.txt"));
    assert!(digits <= 5.0, "{digits} units of the last digit apart");
    let a = nav_bag(bag, &out, &["--base-frame", "odom"]).failure();
    let err = String::from_utf8_lossy(&a.get_output().stderr).into_owned();
    assert!(err.contains("frame odom is not above imu_link"), "{err}");
}
